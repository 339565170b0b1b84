"""Inverse dynamics by the Newton-Euler method, in numpy: an independent check of the model.

This module shares nothing with :mod:`stewart.oracles.reference` (the generalized-momentum model
of Lopes & Pires 2011) beyond the basic kinematics (rotation ``R``, Euler-rate map
``J_A``). It follows the Newton-Euler approach of Do & Yang (1988, "Inverse dynamic
analysis and simulation of a platform type of robot", J. Robotic Systems 5(3)) and
Dasgupta & Mruthyunjaya (1998, "A Newton-Euler formulation for the inverse dynamics of
the Stewart platform manipulator", Mech. Mach. Theory 33(8)): every body is a rigid body
with its own Newton and Euler equations, the joints exchange forces, and the actuator
forces come out of the platform's six equations.

Conventions (those of the model): {B} z up, gravity ``g_vec = -g e_z``;
``x = [px, py, pz, psi, theta, phi]``, ``R = Rz(psi) Ry(theta) Rx(phi)``; platform twist
``[v; omega] = T xdot``, ``T = blockdiag(E, J_A)``, and twist acceleration
``[a; alpha] = T xddot + Tdot xdot`` with ``Tdot`` from the analytic derivative of
``J_A``.

Per leg i, with ``r_i = R p_i``, ``l_i = p + r_i - b_i = L_i u_i``:

* joint P_i: ``v_P = v + omega x r``, ``a_P = a + alpha x r + omega x (omega x r)``;
* leg rates: ``Ldot = u . v_P``, ``udot = (v_P - Ldot u) / L``,
  ``uddot = (a_P - Lddot u - 2 Ldot udot) / L``. In the paper's model the leg does not
  spin about its axis, so its angular velocity is ``omega_l = u x udot`` (eq. 29 of the
  paper) and, since ``udot x udot = 0``, its angular acceleration is
  ``alpha_l = u x uddot``. With ``universal_joint_axes`` the leg turns with its joint:
  the joint angles q1 about the base-fixed axis ``a`` and q2 about the cross axis
  ``y = a x u / |a x u|`` (``z = u x y``) give ``omega_l = q1' a + q2' y``, and from
  ``udot = omega_l x u = q1' |a x u| y - q2' z``: ``q1' = udot . y / |a x u|``,
  ``q2' = -udot . z``. The cross axis turns with the first, ``ydot = q1' a x y``, so
  ``alpha_l = q1'' a + q2'' y + q1' q2' a x y``, with ``q1''``, ``q2''`` read off
  ``alpha_l x u = uddot - omega_l x (omega_l x u)`` in the same way;
* centres of mass: cylinder ``c = b + b_C u``, ``a_C = b_C uddot``; piston
  ``s = p + r - b_S u``, ``a_S = a_P - b_S uddot``;
* the cylinder hangs from the base by a universal joint at B_i (a force ``f_B`` and a
  moment ``n_B = mu n`` about ``n = a x y``, the direction neither joint axis turns
  about; in the paper's model, where no axis is given, a moment about the leg axis), the piston slides in the cylinder (the actuator force
  ``tau u`` on the piston plus transverse constraint forces and moments, no axial
  friction), and the piston meets the platform at a spherical joint at P_i (a force
  only: ``f_P`` on the platform, ``-f_P`` on the leg).

Moment balance of the whole leg (cylinder + piston) about the fixed point B_i::

    l x (-f_P) + b_C u x m_C g_vec + (L - b_S) u x m_S g_vec + n_B
        = sum over the two parts of [I alpha_l + omega_l x I omega_l + (c - b) x m a]

with the leg inertia in {B} ``I = I_t (E - u u^T) + I_a u u^T`` (paper's model) or
``I = e diag(I_a, I_yy, I_zz) e^T`` in the leg frame ``e = (u, y, z)`` (with joint axes).
In the paper's model every term but the universal joint's moment ``n_B`` is
perpendicular to ``u`` (``omega_l`` and ``alpha_l`` are, and ``omega_l x I omega_l = 0``
for axisymmetric legs), so ``n_B = 0``. With joint axes the balance's component along
``u`` gives ``mu = k . u / n . u`` (``n . u = -|a x u|``, zero only in the gimbal lock),
where ``k`` is the right-hand side less the weights' moments. Either way the rest of the
balance gives the component of ``f_P`` perpendicular to the leg. The piston's axial force
balance ``u . (-f_P) + tau + m_S u . g_vec = m_S u . a_S`` gives its axial component, so
``-f_P = f0 - tau u``: ``f0`` known from the motion. The base force follows from the
leg's Newton equation ``f_B - f_P + (m_C + m_S) g_vec = m_C a_C + m_S a_S``.

Finally the platform's Newton equation for its centre of mass ``p + c``, ``c = R c_P``,
and its Euler equation about the platform origin,

    m_P (a_c - g_vec) = sum_i f_P,i,   a_c = a + alpha x c + omega x (omega x c),
    I_P alpha + omega x I_P omega + c x m_P (a_c - g_vec) = sum_i r_i x f_P,i,
    I_P = R I_P,{P} R^T (the full tensor about the centre of mass),

with ``f_P,i = tau_i u_i - f0_i`` are six linear equations ``J_C^T tau = w`` in the
actuator forces (``J_C`` rows ``[u_i, r_i x u_i]``), solved per state.

The paper's model (no ``universal_joint_axes``) needs axisymmetric legs (``I_yy == I_zz``
for cylinder and piston): with ``I_yy != I_zz`` a non-spinning leg needs an axial moment
``omega_l x I omega_l`` that no joint of the model supplies, and the paper's frame {C_i}
turns about the leg as it swings, so the paper's generalized-momentum model is not the
dynamics of a rigid-body system and no Newton-Euler formulation reproduces it. Such
parameters raise ``ValueError``; with joint axes every leg inertia is allowed.
"""

from __future__ import annotations

import numpy as np

from ..model import arguments, conditions
from .frames import euler_rate_jacobian, rotation
from ..model.params import platform_params
from ..model.params import PlatformParams
from ..model.results import JointReactions

__all__ = ["JointReactions", "inverse_dynamics", "joint_reactions"]


def _euler_rate_jacobian_dot(x: np.ndarray, xd: np.ndarray) -> np.ndarray:
    """``d/dt J_A`` for ``J_A = [[0, -s psi, c psi c theta], [0, c psi, s psi c theta],
    [1, 0, -s theta]]`` (eq. 8), differentiated analytically."""
    cps, sps = np.cos(x[..., 3]), np.sin(x[..., 3])
    cth, sth = np.cos(x[..., 4]), np.sin(x[..., 4])
    dps, dth = xd[..., 3], xd[..., 4]
    zero = np.zeros_like(cps * dps)
    rows = [
        [zero, -cps * dps, -sps * cth * dps - cps * sth * dth],
        [zero, -sps * dps, cps * cth * dps - sps * sth * dth],
        [zero, zero, -cth * dth],
    ]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def _matvec(mat: np.ndarray, vec: np.ndarray) -> np.ndarray:
    return np.einsum("...ij,...j->...i", mat, vec)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.sum(a * b, axis=-1)


def _leg_inertia_times(inertia: np.ndarray, frame: tuple, vec: np.ndarray) -> np.ndarray:
    """``e diag(inertia) e^T vec`` in the leg frame ``e`` (columns ``frame``)."""
    return sum(moment * _dot(e, vec)[..., None] * e for moment, e in zip(inertia, frame))


def _joint_motion(axes: np.ndarray, u: np.ndarray, u_dot: np.ndarray, u_ddot: np.ndarray):
    """The leg frame ``(u, y, z)`` and the leg's angular velocity and acceleration as its
    universal joint turns (module docstring), and ``n = a x y`` with ``n . u``."""
    across = np.cross(axes, u)
    size = np.sqrt(_dot(across, across))[..., None]
    y = across / size
    z = np.cross(u, y)
    rate1 = _dot(u_dot, y)[..., None] / size
    rate2 = -_dot(u_dot, z)[..., None]
    omega = rate1 * axes + rate2 * y
    normal = np.cross(axes, y)
    turning = u_ddot - np.cross(omega, np.cross(omega, u)) - rate1 * rate2 * np.cross(normal, u)
    alpha = _dot(turning, y)[..., None] / size * axes - _dot(turning, z)[..., None] * y + rate1 * rate2 * normal
    return (u, y, z), omega, alpha, normal


def _solve(params: PlatformParams, x, xd, xdd) -> JointReactions:
    params = platform_params(params)
    axes = params.universal_joint_axes
    if axes is None and not params.is_axisymmetric:
        raise ValueError(
            "params: the Newton-Euler formulation of the paper's model needs axisymmetric legs (I_yy == I_zz for "
            f"cylinder_inertia {params.cylinder_inertia.tolist()} and piston_inertia "
            f"{params.piston_inertia.tolist()}); the paper's no-spin leg model is not a "
            "rigid-body system otherwise (give universal_joint_axes for legs that turn with their joints)"
        )
    x = arguments.states("x", x)
    xd = arguments.states("xd", xd)
    xdd = arguments.states("xdd", xdd)
    arguments.same_batch(x=x, xd=xd, xdd=xdd)

    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        g_vec = np.array([0.0, 0.0, -params.gravity])
        m_p, m_c, m_s = params.platform_mass, params.cylinder_mass, params.piston_mass
        b_c, b_s = params.cylinder_com_distance, params.piston_com_distance

        # Platform twist and twist acceleration (eq. 18 and its derivative).
        rot = rotation(x)
        j_a = euler_rate_jacobian(x)
        vel = xd[..., :3]
        omega = _matvec(j_a, xd[..., 3:])
        acc = xdd[..., :3]
        alpha = _matvec(j_a, xdd[..., 3:]) + _matvec(_euler_rate_jacobian_dot(x, xd), xd[..., 3:])

        # Per leg (a leg axis of length 6 before the vector axis).
        arms = np.einsum("...jk,ik->...ij", rot, params.platform_points)  # r_i = R p_i
        om = omega[..., None, :]
        al = alpha[..., None, :]
        legs = x[..., None, :3] + arms - params.base_points
        length_sq = _dot(legs, legs)
        length = np.sqrt(length_sq)[..., None]
        u = legs / length
        v_p = vel[..., None, :] + np.cross(om, arms)
        a_p = acc[..., None, :] + np.cross(al, arms) + np.cross(om, np.cross(om, arms))
        l_dot = _dot(u, v_p)[..., None]
        u_dot = (v_p - l_dot * u) / length
        l_ddot = _dot(u_dot, v_p)[..., None] + _dot(u, a_p)[..., None]
        u_ddot = (a_p - l_ddot * u - 2.0 * l_dot * u_dot) / length
        if axes is None:
            omega_leg = np.cross(u, u_dot)
            alpha_leg = np.cross(u, u_ddot)
        else:
            frame, omega_leg, alpha_leg, normal = _joint_motion(axes, u, u_dot, u_ddot)
        a_cyl = b_c * u_ddot
        a_pis = a_p - b_s * u_ddot

        # Rate of change of the leg's angular momentum about B_i (Euler + transport terms).
        inertia_sum = params.cylinder_inertia + params.piston_inertia

        def leg_inertia_times(vec):
            if axes is not None:
                return _leg_inertia_times(inertia_sum, frame, vec)
            along = _dot(u, vec)[..., None] * u
            return inertia_sum[1] * (vec - along) + inertia_sum[0] * along

        h_dot = (
            leg_inertia_times(alpha_leg)
            + np.cross(omega_leg, leg_inertia_times(omega_leg))
            + np.cross(b_c * u, m_c * a_cyl)
            + np.cross((length - b_s) * u, m_s * a_pis)
        )
        weight_moment = np.cross(b_c * u, m_c * g_vec) + np.cross((length - b_s) * u, m_s * g_vec)
        # l x (-f_P) + n_B = h_dot - weight_moment: n_B takes the part along u, and the
        # rest gives the transverse part of -f_P.
        k = h_dot - weight_moment
        if axes is None:
            base_moment = np.zeros_like(k)
        else:
            base_moment = (_dot(k, u) / _dot(normal, u))[..., None] * normal
        transverse = np.cross((k - base_moment) / length, u)
        # Piston axial balance: u.(-f_P) = m_S u.(a_S - g_vec) - tau.
        f0 = transverse + m_s * _dot(u, a_pis - g_vec)[..., None] * u

        # Platform: J_C^T tau = [m_P (a_c - g_vec) + sum f0;
        #                        I_P alpha + omega x I_P omega + c x m_P (a_c - g_vec) + sum r x f0].
        com = np.zeros(3) if params.platform_com is None else params.platform_com
        com_arm = _matvec(rot, com)
        a_com = acc + np.cross(alpha, com_arm) + np.cross(omega, np.cross(omega, com_arm))
        inertia_p = rot @ params.platform_inertia_tensor @ np.swapaxes(rot, -1, -2)
        euler = _matvec(inertia_p, alpha) + np.cross(omega, _matvec(inertia_p, omega))
        force = m_p * (a_com - g_vec)
        wrench = np.concatenate(
            [force + f0.sum(axis=-2), euler + np.cross(com_arm, force) + np.cross(arms, f0).sum(axis=-2)], axis=-1
        )
        jac = np.concatenate([u, np.cross(arms, u)], axis=-1)  # J_C, row i = [u_i, r_i x u_i]
        # The checks of the model's inverse dynamics, in its order: the legs, then J_C.
        locked = None if axes is None else np.cross(axes, legs)
        legs_codes = conditions.leg_codes(length_sq, None, None if axes is None else _dot(locked, locked))
        conditions.check("joint_reactions", x, legs_codes,
                         lambda rows: conditions.jacobian_codes(jac.reshape(-1, 6, 6)[rows]))
        tau = np.linalg.solve(np.swapaxes(jac, -1, -2), wrench[..., None])[..., 0]

        on_platform = tau[..., None] * u - f0  # f_P
        base = m_c * a_cyl + m_s * a_pis - (m_c + m_s) * g_vec + on_platform
    return arguments.finite_result("joint_reactions", JointReactions(tau, base, on_platform, base_moment), x)


def joint_reactions(params: PlatformParams, x, xd, xdd) -> JointReactions:
    """Actuator forces and joint forces for the motion ``(x, xdot, xddot)``, by Newton-Euler.

    ``x``, ``xd``, ``xdd``: one state ``(6,)`` or a batch ``(N, 6)`` of Euler-angle poses,
    rates and accelerations. Returns :class:`JointReactions` ``(tau, base, platform)``
    with shapes ``(..., 6)``, ``(..., 6, 3)`` and ``(..., 6, 3)``, forces in {B} (see the
    module docstring for the equations), and the universal joints' moments ``base_moment``
    ``(..., 6, 3)``. Raises ``ValueError`` naming ``params`` for non-axisymmetric legs in
    the paper's model (no ``universal_joint_axes``), and :class:`~stewart.SingularityError` where ``J_C`` is singular.
    """
    return _solve(params, x, xd, xdd)


def inverse_dynamics(params: PlatformParams, x, xd, xdd) -> np.ndarray:
    """Actuator forces ``tau`` (..., 6) by Newton-Euler; equals the model's
    ``J_C^-T (M xddot + V xdot + G)`` for axisymmetric legs, and for any legs with
    ``universal_joint_axes``."""
    return _solve(params, x, xd, xdd).tau
