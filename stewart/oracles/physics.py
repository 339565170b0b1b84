"""The model's checks shared by ``stewart validate`` (:mod:`stewart.oracles.validation`) and the
test suite: random states around home, the error measure, and the physics the compiled
kernel must obey.

* :func:`random_states` — the states every comparison runs over;
* :func:`relative_error` — the one measure of disagreement between two results;
* :func:`complex_step_jacobians` — Jacobians of a complex-capable function by complex
  step, and with it the derivative oracle of the kernel's Jacobians, built on the numeric
  reference :mod:`stewart.oracles.reference` (not on the kernel):
  :func:`reference_inverse_dynamics_jacobians`, :func:`reference_forward_dynamics_jacobians`
  and :func:`reference_rk4_jacobians` of the RK4 step :func:`reference_rk4_step`;
* :func:`energy` — the mechanical energy written out from the bodies (section 3), and with
  it :func:`power_balance` (``dE/dt = tau . Ldot``) and :func:`energy_drift` (conservation
  with ``tau = 0``);
* :func:`twist_mass_matrix_figures` — ``M = M_t T`` and the definiteness of ``M_t``;
* :func:`statics_residuals` — the static balance of the Newton-Euler joint forces.

(The arguments of the public functions are checked by :mod:`stewart.model.arguments`; these are
checks of the model.)
"""

from __future__ import annotations

import numpy as np

from ..model import kinematics
from . import frames, newton_euler, reference
from ..model import reachability
from ..model.params import platform_params
from ..model.params import PlatformParams
from ..model.platform import Platform
from ..model.sampling import random_states

__all__ = ["random_states", "relative_error", "energy", "power_balance", "energy_drift", "statics_residuals",
           "twist_mass_matrix_figures", "complex_step_jacobians", "reference_inverse_dynamics_jacobians",
           "reference_forward_dynamics_jacobians", "reference_rk4_step", "reference_rk4_jacobians", "COMPLEX_STEP"]

#: Complex-step size for exact first derivatives.
COMPLEX_STEP = 1e-30


def energy(params: PlatformParams, x, xd) -> np.ndarray:
    """Kinetic plus potential energy (J) of platform, cylinders and pistons, ``(...)``.

    Written out from the bodies: platform ``m_P v_G^2/2 + omega . I_P omega / 2`` with the
    centre of mass at ``p + R c`` and the full tensor ``I_P`` in {P}, cylinder centre of
    mass at ``b_i + b_C u_i``, piston centre of mass at ``p + R p_i - b_S u_i``, potential
    ``g`` times the mass-weighted heights (eq. 72). Legs: without ``universal_joint_axes``,
    angular velocity ``u x udot`` (eq. 29) with inertia ``I_t (E - u u^T) + I_a u u^T``
    (axisymmetric legs) or the principal moments in the frames of eqs. 44-47; with them, the leg frame ``e = (u, y, z)``,
    ``y = a x u / |a x u|``, turns at ``omega = (e_k x edot_k) / 2`` (summed over k) and the
    energy is ``sum_k I_k (omega . e_k)^2 / 2``. Analytic operations only, so complex-step
    derivatives apply.
    """
    return _energy(platform_params(params), x, xd)


def _energy(params: PlatformParams, x, xd) -> np.ndarray:
    """:func:`energy` of the converted ``params``."""
    x = np.asarray(x)
    xd = np.asarray(xd)
    rot = frames.rotation(x)
    omega = np.einsum("...ij,...j->...i", frames.euler_rate_jacobian(x), xd[..., 3:])
    arms = np.einsum("...jk,ik->...ij", rot, params.platform_points)
    legs = x[..., None, :3] + arms - params.base_points
    lengths = np.sqrt(np.sum(legs * legs, axis=-1))[..., None]
    units = legs / lengths
    leg_dot = xd[..., None, :3] + np.cross(omega[..., None, :], arms)
    length_dot = np.sum(units * leg_dot, axis=-1)[..., None]
    unit_dot = (leg_dot - units * length_dot) / lengths

    com = np.zeros(3) if params.platform_com is None else params.platform_com
    com_arm = np.einsum("...jk,k->...j", rot, com)
    vel = xd[..., :3] + np.cross(omega, com_arm)
    body_omega = np.einsum("...ji,...j->...i", rot, omega)  # omega in {P}
    kinetic = 0.5 * params.platform_mass * np.sum(vel * vel, axis=-1)
    kinetic = kinetic + 0.5 * np.einsum("...i,ij,...j->...", body_omega, params.platform_inertia_tensor, body_omega)
    cyl_vel = params.cylinder_com_distance * unit_dot
    pis_vel = leg_dot - params.piston_com_distance * unit_dot
    kinetic = kinetic + 0.5 * params.cylinder_mass * np.sum(cyl_vel * cyl_vel, axis=(-1, -2))
    kinetic = kinetic + 0.5 * params.piston_mass * np.sum(pis_vel * pis_vel, axis=(-1, -2))
    moments = params.cylinder_inertia + params.piston_inertia
    if params.universal_joint_axes is None and not params.is_axisymmetric:
        # The paper's legs (eq. 29) in its frames of eqs. 44-47 (first axis z).
        frame, _ = _leg_frames(np.array([0.0, 0.0, 1.0]), units, unit_dot)
        leg_omega = np.cross(units, unit_dot)
        kinetic = kinetic + 0.5 * sum(m * np.sum(np.sum(leg_omega * e, axis=-1) ** 2, axis=-1)
                                      for m, e in zip(moments, frame))
    elif params.universal_joint_axes is None:
        leg_omega = np.cross(units, unit_dot)
        along = np.sum(leg_omega * units, axis=-1)
        kinetic = kinetic + 0.5 * np.sum(
            moments[1] * (np.sum(leg_omega * leg_omega, axis=-1) - along**2) + moments[0] * along**2, axis=-1
        )
    else:
        frame, frame_dot = _leg_frames(params.universal_joint_axes, units, unit_dot)
        leg_omega = 0.5 * sum(np.cross(e, e_dot) for e, e_dot in zip(frame, frame_dot))
        kinetic = kinetic + 0.5 * sum(m * np.sum(np.sum(leg_omega * e, axis=-1) ** 2, axis=-1)
                                      for m, e in zip(moments, frame))
    heights = (
        params.platform_mass * (x[..., 2] + com_arm[..., 2])
        + params.cylinder_mass
        * np.sum(params.base_points[:, 2] + params.cylinder_com_distance * units[..., 2], axis=-1)
        + params.piston_mass
        * np.sum(x[..., None, 2] + arms[..., 2] - params.piston_com_distance * units[..., 2], axis=-1)
    )
    return kinetic + params.gravity * heights


def _leg_frames(axes: np.ndarray, units: np.ndarray, unit_dot: np.ndarray):
    """The leg frames ``(u, y, z)``, ``y = a x u / |a x u|``, ``z = u x y``, and their time
    derivatives, each ``(..., 6, 3)``, differentiated by hand from ``udot``."""
    across = np.cross(axes, units)
    across_dot = np.cross(axes, unit_dot)
    size = np.sqrt(np.sum(across * across, axis=-1))[..., None]
    size_dot = np.sum(across * across_dot, axis=-1)[..., None] / size
    y = across / size
    y_dot = across_dot / size - across * size_dot / size**2
    z = np.cross(units, y)
    z_dot = np.cross(unit_dot, y) + np.cross(units, y_dot)
    return (units, y, z), (unit_dot, y_dot, z_dot)


def relative_error(got, want) -> float:
    """Worst error over states (the first axis), each relative to the largest entry of that
    state's ``want`` (exact zeros compare absolutely, so a zero ``G`` must come out zero)."""
    got = np.asarray(got)
    want = np.asarray(want)
    got = got.reshape(len(got), -1)
    want = want.reshape(len(want), -1)
    scale = np.max(np.abs(want), axis=1, keepdims=True)
    scale = np.where(scale > 0.0, scale, 1.0)
    return float(np.max(np.abs(got - want) / scale))


def complex_step_jacobians(function, *args, step: float = COMPLEX_STEP) -> tuple[np.ndarray, ...]:
    """Jacobians of ``function(*args)`` with respect to each argument, by complex step:
    column ``j`` of the Jacobian for argument ``a`` is ``Im f(.., a + i h e_j, ..) / h``,
    exact to round-off for a holomorphic ``function`` (no subtractive cancellation).

    Each argument is one point ``(n,)`` or a batch ``(N, n)``; ``function`` takes batches
    ``(K, n)`` and returns ``(K, m)``. Returns one array per argument, ``(m, n)`` for one
    point or ``(N, m, n)`` for a batch: row = output, column = input. Each argument costs
    one call of ``function`` on the batch repeated ``n`` times, the other arguments real.
    """
    arrays = [np.asarray(a, dtype=float) for a in args]
    single = arrays[0].ndim == 1
    arrays = [a.reshape(-1, a.shape[-1]) for a in arrays]
    count = len(arrays[0])
    jacobians = []
    for k, arg in enumerate(arrays):
        width = arg.shape[-1]
        shifted = (arg[:, None, :] + 1j * step * np.eye(width)).reshape(-1, width)
        inputs = [shifted if j == k else np.repeat(a, width, axis=0) for j, a in enumerate(arrays)]
        out = np.asarray(function(*inputs)).imag.reshape(count, width, -1) / step
        jac = np.swapaxes(out, -1, -2)
        jacobians.append(jac[0] if single else jac)
    return tuple(jacobians)


def reference_inverse_dynamics_jacobians(params: PlatformParams, x, xd, xdd) -> tuple[np.ndarray, ...]:
    """``(dtau/dx, dtau/dxdot, dtau/dxddot)`` of the reference's inverse dynamics (eqs. 1-2,
    20) by complex step, ``(6, 6)`` or ``(N, 6, 6)``."""
    return complex_step_jacobians(lambda *a: reference.inverse_dynamics(params, *a), x, xd, xdd)


def reference_forward_dynamics_jacobians(params: PlatformParams, x, xd, tau) -> tuple[np.ndarray, ...]:
    """``(dxddot/dx, dxddot/dxdot, dxddot/dtau)`` of the reference's forward dynamics by
    complex step, ``(6, 6)`` or ``(N, 6, 6)``."""
    return complex_step_jacobians(lambda *a: reference.forward_dynamics(params, *a), x, xd, tau)


def reference_rk4_step(params: PlatformParams, x, xd, tau, dt: float) -> np.ndarray:
    """One classic RK4 step of ``y = [x; xdot]``, ``ydot = [xdot; xddot(x, xdot, tau)]``,
    under ``tau`` held constant over ``dt``, with the reference's forward dynamics: the new
    ``[x; xdot]``, ``(12,)`` or ``(N, 12)``. Complex inputs are carried through."""

    def rate(y):
        return np.concatenate([y[..., 6:], reference.forward_dynamics(params, y[..., :6], y[..., 6:], tau)], axis=-1)

    y = np.concatenate([x, xd], axis=-1)
    k1 = rate(y)
    k2 = rate(y + 0.5 * dt * k1)
    k3 = rate(y + 0.5 * dt * k2)
    k4 = rate(y + dt * k3)
    return y + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def reference_rk4_jacobians(params: PlatformParams, x, xd, tau, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` of :func:`reference_rk4_step` by complex step: ``A = d[x+; xdot+]/d[x; xdot]``
    ``(12, 12)`` and ``B = d[x+; xdot+]/dtau`` ``(12, 6)`` (a leading batch axis for a batch)."""
    d_x, d_xd, d_tau = complex_step_jacobians(
        lambda *a: reference_rk4_step(params, *a, dt), x, xd, tau
    )
    return np.concatenate([d_x, d_xd], axis=-1), d_tau


def power_balance(params: PlatformParams, x, xd, xdd, tau) -> float:
    """Worst ``|dE/dt - tau . Ldot| / sum |tau_i Ldot_i|`` over the states: the actuator
    forces ``tau`` that produce ``xdd`` must deliver the power the energy gains. ``dE/dt``
    is the complex-step derivative of :func:`energy` along ``(xd, xdd)``."""
    params = platform_params(params)
    h = COMPLEX_STEP
    de_dt = _energy(params, x + 1j * h * xd, xd + 1j * h * xdd).imag / h
    power = tau * frames.leg_velocities(params, x, xd)
    return float(np.max(np.abs(de_dt - power.sum(axis=-1)) / np.sum(np.abs(power), axis=-1)))


def twist_mass_matrix_figures(platform: Platform, x) -> tuple[float, float]:
    """``(mismatch, condition)`` of the kernel's twist-space mass matrix ``M_t`` (the kinetic
    energy's Hessian in twist space) over the poses ``x``: the worst error of ``M_t T``
    (eq. 18) relative to the mass matrix ``M``, and the worst condition number of ``M_t``
    (``inf`` where it is not positive definite)."""
    m_twist = platform.twist_mass_matrix(x)
    mismatch = relative_error(m_twist @ frames.twist_transform(x), platform.mass_matrix(x))
    eig = np.linalg.eigvalsh(m_twist)
    positive = eig[..., 0] > 0.0
    cond = np.where(positive, eig[..., -1] / np.where(positive, eig[..., 0], 1.0), np.inf)
    return mismatch, float(np.max(cond))


def _free_motion_start(params: PlatformParams, rng: np.random.Generator):
    """Home pose and a modest twist: in 1 s the platform moves 10% of its home height and
    turns 0.3 rad, far from singular poses."""
    home = kinematics.home_pose(params)
    direction = rng.normal(size=6)
    linear = direction[:3] / np.linalg.norm(direction[:3]) * 0.1 * home[2]
    angular = direction[3:] / np.linalg.norm(direction[3:]) * 0.3
    return home, np.concatenate([linear, angular])


def energy_drift(params: PlatformParams, seconds: float = 1.0, seed: int = 0) -> float:
    """Worst ``|E(t) - E(0)|`` over ``seconds`` of motion with ``tau = 0``, relative to the
    largest kinetic energy, integrating the compiled forward dynamics with DOP853
    (rtol 1e-12). The motion starts at home with a modest twist, in zero gravity (a copy of
    ``params`` with ``gravity=0``) so that the free platform coasts instead of falling
    through the base; ``inf`` if the motion comes closer to a singular pose than the
    workspace's design margin (:data:`stewart.model.reachability.CONDITION_LIMIT`)."""
    params = platform_params(params)
    from scipy.integrate import solve_ivp

    free = params.replace(gravity=0.0)
    plat = Platform(free)
    x0, xd0 = _free_motion_start(free, np.random.default_rng(seed))
    zero = np.zeros(6)

    def rhs(_t, state):
        return np.concatenate([state[6:], plat.forward_dynamics(state[:6], state[6:], zero)])

    scale = np.concatenate([np.abs(x0) + x0[2], np.abs(xd0) + np.linalg.norm(xd0)])
    sol = solve_ivp(
        rhs, (0.0, seconds), np.concatenate([x0, xd0]), method="DOP853", rtol=1e-12, atol=1e-14 * scale,
        t_eval=np.linspace(0.0, seconds, 201),
    )
    if not sol.success:
        return float("inf")
    poses, rates = sol.y[:6].T, sol.y[6:].T
    # A margin from singularity for a test motion, not a test of where the model is defined
    # (stewart.model.conditions): the workspace's design limit on the unit-free condition of J_C.
    if np.max(reachability.reachability(plat, poses).condition) > reachability.CONDITION_LIMIT:
        return float("inf")
    energies = _energy(free, poses, rates)
    return float(np.max(np.abs(energies - energies[0])) / np.max(np.abs(energies)))


def statics_residuals(params: PlatformParams, x) -> dict[str, float]:
    """Relative residuals of the static balance of the Newton-Euler joint forces at rest.

    Platform: the legs' forces carry its weight, ``sum f_P = m_P g e_z``, with no moment
    about its centre of mass (``platform_com``). Each leg: ``f_B - f_P - (m_C + m_S) g e_z = 0``, and the
    moments about B_i of ``-f_P`` at P_i and of the weights vanish. Scaled by the total
    weight (and the home height for moments)."""
    params = platform_params(params)
    rest = np.zeros_like(x)
    forces = newton_euler.joint_reactions(params, x, rest, rest)
    g = params.gravity
    m_c, m_s = params.cylinder_mass, params.piston_mass
    weight = g * (params.platform_mass + 6 * (m_c + m_s))
    if weight == 0.0:
        weight = 1.0
    length = kinematics.home_pose(params)[2]
    e_z = np.array([0.0, 0.0, 1.0])
    rot = frames.rotation(x)
    arms = np.einsum("...jk,ik->...ij", rot, params.platform_points - params.platform_com_in_model)
    legs = frames.leg_vectors(params, x)
    units = legs / np.linalg.norm(legs, axis=-1, keepdims=True)
    net = forces.platform.sum(axis=-2) - params.platform_mass * g * e_z
    moment = np.cross(arms, forces.platform).sum(axis=-2)
    leg_force = forces.base - forces.platform - (m_c + m_s) * g * e_z
    leg_moment = (
        np.cross(legs, -forces.platform)
        + np.cross(params.cylinder_com_distance * units, -m_c * g * e_z)
        + np.cross(legs - params.piston_com_distance * units, -m_s * g * e_z)
    )
    return {
        "platform force": float(np.max(np.abs(net)) / weight),
        "platform moment": float(np.max(np.abs(moment)) / (weight * length)),
        "leg force": float(np.max(np.abs(leg_force)) / weight),
        "leg moment about B_i": float(np.max(np.abs(leg_moment)) / (weight * length)),
    }
