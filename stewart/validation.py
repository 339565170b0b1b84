"""Self-check of the model for one parameter set: the checks behind ``stewart validate``.

:func:`run` evaluates, over random states scattered around the home pose, the worst
disagreement of the compiled kernel (:class:`stewart.Platform`) with

* the numeric reference model (:mod:`stewart.reference`): inverse and forward dynamics,
  ``M``, ``V xdot`` and ``G``;
* the independent Newton-Euler formulation (:mod:`stewart.newton_euler`);
* itself: forward dynamics of the inverse dynamics gives back ``xddot``;
* physics: the power balance ``dE/dt = tau . Ldot`` with the mechanical energy
  :func:`energy` written out from the bodies, conservation of energy over 1 s of motion
  with ``tau = 0``, a symmetric positive-definite twist-space mass matrix ``M T^-1``,
  and the static balance of the Newton-Euler joint forces.

The physics checks and the Newton-Euler comparison need axisymmetric legs (I_yy == I_zz);
for other parameters they are replaced by one failing check that says so.
:func:`format_report` renders the checks as a table.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import kinematics, newton_euler, reference
from .params import PlatformParams
from .platform import Platform

__all__ = ["Check", "run", "format_report", "energy", "energy_drift", "statics_residuals", "random_states"]

#: Complex-step size for exact first derivatives.
_STEP = 1e-30


class Check(NamedTuple):
    """One check: its worst figure over the states tried, the bound, and ``worst <= bound``."""

    name: str
    worst: float
    bound: float
    passed: bool


def _check(name: str, worst: float, bound: float) -> Check:
    worst = float(worst)
    return Check(name, worst, float(bound), bool(worst <= bound))


def random_states(params: PlatformParams, n: int, rng: np.random.Generator):
    """``n`` poses around home (within 8% of the home height and 0.2 rad), with rates and
    accelerations of matching scale: ``(x, xd, xdd)``, each ``(n, 6)``."""
    home = kinematics.home_pose(params)
    scale = home[2]
    sigma = np.array([0.04 * scale] * 3 + [0.1] * 3)
    x = home + rng.uniform(-2, 2, size=(n, 6)) * sigma
    xd = rng.normal(size=(n, 6)) * np.array([0.2 * scale] * 3 + [0.5] * 3)
    xdd = rng.normal(size=(n, 6)) * np.array([2 * scale] * 3 + [5.0] * 3)
    return x, xd, xdd


def energy(params: PlatformParams, x, xd) -> np.ndarray:
    """Kinetic plus potential energy (J) of platform, cylinders and pistons, ``(...)``.

    Written out from the bodies: platform ``m_P v^2/2 + omega . I_P omega / 2``, cylinder
    centre of mass at ``b_i + b_C u_i``, piston centre of mass at ``p + R p_i - b_S u_i``,
    leg angular velocity ``u x udot`` (eq. 29) with inertia ``I_t (E - u u^T) + I_a u u^T``
    (axisymmetric legs), potential ``g`` times the mass-weighted heights (eq. 72).
    Analytic operations only, so complex-step derivatives apply.
    """
    x = np.asarray(x)
    xd = np.asarray(xd)
    rot = kinematics.rotation(x)
    omega = np.einsum("...ij,...j->...i", kinematics.euler_rate_jacobian(x), xd[..., 3:])
    arms = np.einsum("...jk,ik->...ij", rot, params.platform_points)
    legs = x[..., None, :3] + arms - params.base_points
    lengths = np.sqrt(np.sum(legs * legs, axis=-1))[..., None]
    units = legs / lengths
    leg_dot = xd[..., None, :3] + np.cross(omega[..., None, :], arms)
    length_dot = np.sum(units * leg_dot, axis=-1)[..., None]
    unit_dot = (leg_dot - units * length_dot) / lengths

    vel = xd[..., :3]
    body_omega = np.einsum("...ji,...j->...i", rot, omega)  # omega in {P}
    kinetic = 0.5 * params.platform_mass * np.sum(vel * vel, axis=-1)
    kinetic = kinetic + 0.5 * np.sum(params.platform_inertia * body_omega * body_omega, axis=-1)
    cyl_vel = params.cylinder_com_distance * unit_dot
    pis_vel = leg_dot - params.piston_com_distance * unit_dot
    kinetic = kinetic + 0.5 * params.cylinder_mass * np.sum(cyl_vel * cyl_vel, axis=(-1, -2))
    kinetic = kinetic + 0.5 * params.piston_mass * np.sum(pis_vel * pis_vel, axis=(-1, -2))
    leg_omega = np.cross(units, unit_dot)
    along = np.sum(leg_omega * units, axis=-1)
    axial = params.cylinder_inertia[0] + params.piston_inertia[0]
    transverse = params.cylinder_inertia[1] + params.piston_inertia[1]
    kinetic = kinetic + 0.5 * np.sum(
        transverse * (np.sum(leg_omega * leg_omega, axis=-1) - along**2) + axial * along**2, axis=-1
    )
    heights = (
        params.platform_mass * x[..., 2]
        + params.cylinder_mass
        * np.sum(params.base_points[:, 2] + params.cylinder_com_distance * units[..., 2], axis=-1)
        + params.piston_mass
        * np.sum(x[..., None, 2] + arms[..., 2] - params.piston_com_distance * units[..., 2], axis=-1)
    )
    return kinetic + params.gravity * heights


def _relative(got, want) -> float:
    """Worst error per state, relative to the largest entry of that state's ``want``
    (exact zeros compare absolutely, so a zero ``G`` must come out zero)."""
    got = np.asarray(got).reshape(len(got), -1)
    want = np.asarray(want).reshape(len(want), -1)
    scale = np.max(np.abs(want), axis=1, keepdims=True)
    scale = np.where(scale > 0.0, scale, 1.0)
    return float(np.max(np.abs(got - want) / scale))


def _kernel_vs_reference(params, plat, x, xd, xdd) -> list[Check]:
    tau = reference.inverse_dynamics(params, x, xd, xdd)
    bound = 1e-10
    return [
        _check("kernel vs reference: inverse dynamics", _relative(plat.inverse_dynamics(x, xd, xdd), tau), bound),
        _check(
            "kernel vs reference: forward dynamics",
            _relative(plat.forward_dynamics(x, xd, tau), reference.forward_dynamics(params, x, xd, tau)),
            bound,
        ),
        _check("kernel vs reference: mass matrix M", _relative(plat.mass_matrix(x), reference.mass_matrix(params, x)), bound),
        _check(
            "kernel vs reference: V xdot",
            _relative(plat.coriolis_vector(x, xd), reference.coriolis_vector(params, x, xd)),
            bound,
        ),
        _check("kernel vs reference: gravity G", _relative(plat.gravity_vector(x), reference.gravity_vector(params, x)), bound),
    ]


def _power_balance(params, plat, x, xd, xdd) -> float:
    tau = plat.inverse_dynamics(x, xd, xdd)
    de_dt = energy(params, x + 1j * _STEP * xd, xd + 1j * _STEP * xdd).imag / _STEP
    power = tau * kinematics.leg_velocities(params, x, xd)
    return float(np.max(np.abs(de_dt - power.sum(axis=-1)) / np.sum(np.abs(power), axis=-1)))


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
    through the base; ``inf`` if the motion reaches a near-singular pose."""
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
    if np.max(np.linalg.cond(kinematics.jacobian(free, poses))) > 1e6:
        return float("inf")
    energies = energy(free, poses, rates)
    return float(np.max(np.abs(energies - energies[0])) / np.max(np.abs(energies)))


def statics_residuals(params: PlatformParams, x) -> dict[str, float]:
    """Relative residuals of the static balance of the Newton-Euler joint forces at rest.

    Platform: the legs' forces carry its weight, ``sum f_P = m_P g e_z``, with no moment
    about its centre of mass. Each leg: ``f_B - f_P - (m_C + m_S) g e_z = 0``, and the
    moments about B_i of ``-f_P`` at P_i and of the weights vanish. Scaled by the total
    weight (and the home height for moments)."""
    rest = np.zeros_like(x)
    forces = newton_euler.joint_reactions(params, x, rest, rest)
    g = params.gravity
    m_c, m_s = params.cylinder_mass, params.piston_mass
    weight = g * (params.platform_mass + 6 * (m_c + m_s))
    if weight == 0.0:
        weight = 1.0
    length = kinematics.home_pose(params)[2]
    e_z = np.array([0.0, 0.0, 1.0])
    rot = kinematics.rotation(x)
    arms = np.einsum("...jk,ik->...ij", rot, params.platform_points)
    legs = kinematics.leg_vectors(params, x)
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


def run(params: PlatformParams, n_states: int = 200, seed: int = 0) -> list[Check]:
    """All checks for ``params`` over ``n_states`` random states around home (seeded)."""
    if not isinstance(params, PlatformParams):
        raise ValueError(f"params: expected a stewart.PlatformParams, got {type(params).__name__}")
    rng = np.random.default_rng(seed)
    plat = Platform(params)
    x, xd, xdd = random_states(params, n_states, rng)
    checks = _kernel_vs_reference(params, plat, x, xd, xdd)
    tau = plat.inverse_dynamics(x, xd, xdd)
    checks.append(_check("kernel: forward(inverse(xddot)) round trip", _relative(plat.forward_dynamics(x, xd, tau), xdd), 1e-9))

    m_twist = plat.mass_matrix(x) @ np.linalg.inv(kinematics.twist_transform(x))
    asym = np.max(np.abs(m_twist - np.swapaxes(m_twist, -1, -2)), axis=(-1, -2))
    checks.append(_check("twist mass matrix M T^-1: asymmetry", np.max(asym / np.max(np.abs(m_twist), axis=(-1, -2))), 1e-12))
    eig = np.linalg.eigvalsh(0.5 * (m_twist + np.swapaxes(m_twist, -1, -2)))
    cond = np.where(eig[:, 0] > 0.0, eig[:, -1] / np.where(eig[:, 0] > 0.0, eig[:, 0], 1.0), np.inf)
    checks.append(_check("twist mass matrix M T^-1: positive definite (condition)", np.max(cond), 1e12))

    if not params.is_axisymmetric:
        spread = np.concatenate([params.cylinder_inertia[1:], params.piston_inertia[1:]])
        mismatch = max(
            abs(params.cylinder_inertia[1] - params.cylinder_inertia[2]),
            abs(params.piston_inertia[1] - params.piston_inertia[2]),
        ) / np.max(spread)
        checks.append(
            Check("legs axisymmetric (I_yy == I_zz); physics checks skipped", float(mismatch), 0.0, False)
        )
        return checks

    checks.append(
        _check("kernel vs Newton-Euler: inverse dynamics", _relative(tau, newton_euler.inverse_dynamics(params, x, xd, xdd)), 1e-9)
    )
    checks.append(_check("power balance |dE/dt - tau.Ldot| / sum|tau_i Ldot_i|", _power_balance(params, plat, x, xd, xdd), 1e-9))
    try:
        drift = energy_drift(params, 1.0, seed)
        label = "energy drift over 1 s, tau = 0, zero gravity (DOP853)"
    except ImportError:
        drift, label = float("nan"), "energy drift over 1 s: not run, needs scipy"
    checks.append(_check(label, drift, 1e-8))
    for label, value in statics_residuals(params, x).items():
        checks.append(_check(f"statics: {label} balance (Newton-Euler)", value, 1e-12))
    return checks


def format_report(params: PlatformParams, checks: list[Check]) -> str:
    """The checks as a text table, with a header naming the parameter set and a verdict."""
    label = params.name or "unnamed parameter set"
    width = max([len(c.name) for c in checks] + [5])
    lines = [
        f"stewart validate: {label}",
        f"{'check':<{width}}  {'worst':>10}  {'bound':>8}  result",
        f"{'-' * width}  {'-' * 10}  {'-' * 8}  ------",
    ]
    for c in checks:
        lines.append(f"{c.name:<{width}}  {c.worst:10.3e}  {c.bound:8.0e}  {'ok' if c.passed else 'FAIL'}")
    failed = sum(not c.passed for c in checks)
    lines.append("")
    lines.append(
        f"all {len(checks)} checks passed" if not failed else f"{failed} of {len(checks)} checks FAILED"
    )
    return "\n".join(lines)
