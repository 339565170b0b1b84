"""The oracles' own kinematics, in numpy, written out plainly and independently of the
compiled model (whose kinematics the derivation in ``codegen/`` generates): the rotation, the
Euler-rate map ``J_A`` and the twist transform ``T``, the leg vectors, lengths and ``J_C``,
and the legs' rates and accelerations (Lopes & Pires 2011, eqs. 3-8, 18, 25-27).

Every function takes one pose ``x = [x, y, z, psi, theta, phi]`` of shape ``(6,)`` or a batch
``(N, 6)`` and returns the matching shape. The functions use analytic operations only (no
``abs``/``norm``), so they also accept complex arrays, for exact complex-step derivatives
(:mod:`stewart.oracles.reference`, :mod:`stewart.oracles.physics`). A zero-length leg where a
unit vector is needed, or a result that overflows, raises :class:`~stewart.SingularityError`.
"""

from __future__ import annotations

import numpy as np

from ..model import arguments, conditions
from ..model.params import platform_params
from ..model.params import PlatformParams

__all__ = ["rotation", "euler_rate_jacobian", "twist_transform", "platform_points_in_base", "leg_vectors",
           "leg_lengths", "jacobian", "leg_velocities", "leg_accelerations"]


def rotation(x) -> np.ndarray:
    """``R = Rz(psi) Ry(theta) Rx(phi)`` (eq. 3), {P} in {B}, shape ``(..., 3, 3)``."""
    x = arguments.states("x", x, allow_complex=True)
    with np.errstate(over="ignore", invalid="ignore"):  # complex angles: cosh overflows
        cps, sps = np.cos(x[..., 3]), np.sin(x[..., 3])
        cth, sth = np.cos(x[..., 4]), np.sin(x[..., 4])
        cph, sph = np.cos(x[..., 5]), np.sin(x[..., 5])
        rows = [
            [cps * cth, cps * sth * sph - sps * cph, cps * sth * cph + sps * sph],
            [sps * cth, sps * sth * sph + cps * cph, sps * sth * cph - cps * sph],
            [-sth, cth * sph, cth * cph],
        ]
        rot = np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)
    return arguments.finite_result("rotation", rot, x)


def euler_rate_jacobian(x) -> np.ndarray:
    """``J_A`` of eq. 8: ``omega = J_A [psi', theta', phi']``, shape ``(..., 3, 3)``."""
    x = arguments.states("x", x, allow_complex=True)
    with np.errstate(over="ignore", invalid="ignore"):
        cps, sps = np.cos(x[..., 3]), np.sin(x[..., 3])
        cth, sth = np.cos(x[..., 4]), np.sin(x[..., 4])
        zero, one = np.zeros_like(cps), np.ones_like(cps)
        rows = [[zero, -sps, cps * cth], [zero, cps, sps * cth], [one, zero, -sth]]
        j_a = np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)
    return arguments.finite_result("euler_rate_jacobian", j_a, x)


def twist_transform(x) -> np.ndarray:
    """``T = blockdiag(I3, J_A)`` of eq. 18: the twist ``[v; omega] = T xdot``."""
    x = arguments.states("x", x, allow_complex=True)
    out = np.zeros(x.shape[:-1] + (6, 6), dtype=x.dtype)
    out[..., 0, 0] = out[..., 1, 1] = out[..., 2, 2] = 1.0
    out[..., 3:, 3:] = euler_rate_jacobian(x)
    return out


def platform_points_in_base(params: PlatformParams, x) -> np.ndarray:
    """``r_i = R p_i``: the platform's joints rotated into {B} (not translated), ``(..., 6, 3)``."""
    return np.einsum("...jk,ik->...ij", rotation(x), platform_params(params).platform_points)


def leg_vectors(params: PlatformParams, x) -> np.ndarray:
    """``l_i = p + R p_i - b_i`` (eq. 26), shape ``(..., 6, 3)``."""
    params = platform_params(params)
    x = arguments.states("x", x, allow_complex=True)
    with np.errstate(over="ignore", invalid="ignore"):
        return x[..., None, :3] + platform_points_in_base(params, x) - params.base_points


def leg_lengths(params: PlatformParams, x) -> np.ndarray:
    """``|l_i| = sqrt(l_i . l_i)``, shape ``(..., 6)``."""
    legs = leg_vectors(params, x)
    with np.errstate(over="ignore", invalid="ignore"):
        return arguments.finite_result("leg_lengths", np.sqrt(np.sum(legs * legs, axis=-1)), x)


def jacobian(params: PlatformParams, x) -> np.ndarray:
    """``J_C`` of eq. 5, row i ``[u_i, (R p_i) x u_i]``, ``u_i = l_i / |l_i|`` (eq. 25); a
    zero-length leg raises :class:`~stewart.SingularityError`."""
    x = arguments.states("x", x, allow_complex=True)
    arms = platform_points_in_base(params, x)
    legs = leg_vectors(params, x)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        length_sq = np.sum(legs * legs, axis=-1)
        conditions.check("jacobian", x, conditions.leg_codes(length_sq))
        units = legs / np.sqrt(length_sq)[..., None]
        jac = np.concatenate([units, np.cross(arms, units)], axis=-1)
    return arguments.finite_result("jacobian", jac, x)


def leg_velocities(params: PlatformParams, x, xd) -> np.ndarray:
    """``Ldot = J_C T xdot`` (eqs. 4, 5, 18), shape ``(..., 6)``."""
    xd = arguments.states("xd", xd, allow_complex=True)
    with np.errstate(over="ignore", invalid="ignore"):
        rates = np.einsum("...ij,...j->...i", jacobian(params, x) @ twist_transform(x), xd)
    return arguments.finite_result("leg_velocities", rates, x)


def leg_accelerations(params: PlatformParams, x, xd, xdd) -> np.ndarray:
    """``Lddot_i = u_i . a_i + (|v_i|^2 - Ldot_i^2) / L_i``, the second time derivative of
    ``L_i = |l_i|`` (eq. 26), with the velocity ``v_i = p' + omega x r_i`` and acceleration
    ``a_i = p'' + alpha x r_i + omega x (omega x r_i)`` of the spherical joint ``P_i`` (eq. 27),
    ``omega = J_A e'`` and ``alpha = J_A e'' + J_A' e'`` (eq. 8, ``e = [psi, theta, phi]``),
    shape ``(..., 6)``."""
    params = platform_params(params)
    x, xd, xdd = (arguments.states(name, v) for name, v in (("x", x), ("xd", xd), ("xdd", xdd)))
    arms = platform_points_in_base(params, x)
    legs = leg_vectors(params, x)
    conditions.check("leg_accelerations", x, conditions.leg_codes(np.sum(legs * legs, axis=-1)))
    sps, cps = np.sin(x[..., 3]), np.cos(x[..., 3])
    sth, cth = np.sin(x[..., 4]), np.cos(x[..., 4])
    dps, dth, dph = xd[..., 3], xd[..., 4], xd[..., 5]
    j_a = euler_rate_jacobian(x)
    omega = np.einsum("...ij,...j->...i", j_a, xd[..., 3:])
    j_a_dot_rates = np.stack([
        -cps * dps * dth - sps * cth * dps * dph - cps * sth * dth * dph,
        -sps * dps * dth + cps * cth * dps * dph - sps * sth * dth * dph,
        -cth * dth * dph,
    ], axis=-1)
    alpha = np.einsum("...ij,...j->...i", j_a, xdd[..., 3:]) + j_a_dot_rates
    with np.errstate(over="ignore", invalid="ignore"):
        lengths = np.sqrt(np.sum(legs * legs, axis=-1))
        units = legs / lengths[..., None]
        turn = np.cross(omega[..., None, :], arms)
        velocity = xd[..., None, :3] + turn
        acceleration = (xdd[..., None, :3] + np.cross(alpha[..., None, :], arms)
                        + np.cross(omega[..., None, :], turn))
        rates = np.sum(units * velocity, axis=-1)
        result = (np.sum(units * acceleration, axis=-1)
                  + (np.sum(velocity * velocity, axis=-1) - rates * rates) / lengths)
    return arguments.finite_result("leg_accelerations", result, x)
