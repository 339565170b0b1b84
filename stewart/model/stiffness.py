"""Stiffness, natural frequencies and compliance of a platform whose legs are axial springs.

Each leg is a spring of stiffness ``k_i`` [N/m] (optionally with a damper ``c_i`` [N s/m])
preloaded to hold the platform and its payload at the pose ``x``: its force is
``tau_i = tau_s,i(x) + k_i (L_i(x) - L_i) - c_i Ldot_i`` with the static forces
``tau_s = inverse_dynamics(x, 0, 0)`` (Lopes & Pires 2011, eqs. 1-2). The total potential
``U`` (the preloaded springs and gravity, eq. 72) is stationary at ``x``; its Hessian in the
pose coordinates ``q = [x, y, z, psi, theta, phi]`` is, exactly (no differences),

    K_q = J_E^T (diag(k) J_E + dtau_s/dx),       J_E = J_C T   (eqs. 4, 5, 18),

where ``dtau_s/dx`` is the exact Jacobian of the static forces
(:meth:`stewart.Platform.inverse_dynamics_derivatives`). ``J_E^T diag(k) J_E`` is the elastic
term; ``J_E^T dtau_s/dx = T^T R_x`` with ``R_x = d(G - J_C^T tau)/dx`` at fixed ``tau`` holds
the preload's geometric term ``-d(J_C^T)/dx . tau`` and gravity's own term ``dG/dx``
(Gosselin 1990 and Klimchik 2011 keep the first only; with no preload it is ``J^T k J``).
``R_x`` is the partial of the residual of the equation of motion, so
``K_q = T^T R_x + J_E^T k J_E`` is the Hessian of ``U`` wherever ``J_C^T tau_s = G``.

Small motions obey ``M_t d(xi)/dt + C_t xi + K_t dxi = 0`` in the twist coordinates
``dxi = T dq = [dp; dtheta]`` (a small translation of {P}'s origin and a small rotation vector,
both in {B}), with the symmetric twist-space mass matrix ``M_t`` (eqs. 19, 39, 51, 61, 69,
legs included), ``K_t = T^-T K_q T^-1 = J_C^T (diag(k) J_C + dtau_s/dx T^-1)`` and
``C_t = J_C^T diag(c) J_C``. The modes are those of the generalized eigenproblem
``K_t phi = w^2 M_t phi`` (the same frequencies as in pose coordinates, since ``T`` is
invertible away from ``theta = +-90 deg``), the damping ratios those of the quadratic
eigenproblem ``(s^2 M_t + s C_t + K_t) phi = 0``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.linalg import lapack

from . import arguments, conditions
from .errors import SingularityError, UnstableError, row_list

__all__ = ["Modes", "MOTION_AXES", "leg_coefficients", "stiffness_matrix", "modes", "compliance",
           "lowest_frequency", "largest_compliance"]

#: The axes of a mode shape or compliance, in the order of a twist ``[dp; dtheta]`` in {B}.
MOTION_AXES = ("translation along x", "translation along y", "translation along z",
               "rotation about x", "rotation about y", "rotation about z")


class Modes(NamedTuple):
    """The undamped modes of a spring-legged platform at one pose or a batch
    (:meth:`stewart.Platform.modes`).

    ``frequencies`` [Hz] ascending, shape ``(..., 6)``; ``shapes[..., :, j]`` the mode shape of
    frequency ``j`` as a twist ``[dp (m); dtheta (rad)]`` of {P} in {B} (:data:`MOTION_AXES`),
    mass-normalized (``phi^T M_t phi = 1``); ``damping_ratios`` ``(..., 6)`` of the same modes
    from the damped eigenproblem (``None`` without dampers); ``length`` [m] the platform's
    radius, the scale that weighs rotations against translations in :meth:`motions`."""

    frequencies: np.ndarray
    shapes: np.ndarray
    damping_ratios: np.ndarray | None
    length: float

    def participation(self) -> np.ndarray:
        """Each mode's share of each axis of :data:`MOTION_AXES`, ``(..., 6 axes, 6 modes)``,
        columns summing to 1: the squares of ``[dp; length * dtheta]``, normalized."""
        scaled = self.shapes * np.array([1.0, 1.0, 1.0, self.length, self.length, self.length])[:, None]
        squares = scaled * scaled
        return squares / np.sum(squares, axis=-2, keepdims=True)

    def motions(self) -> list:
        """The dominant motion of each mode (the axis of :data:`MOTION_AXES` with the largest
        :meth:`participation`): a list of six names for one pose, a list of lists for a batch."""
        dominant = np.argmax(np.nan_to_num(self.participation(), nan=-1.0), axis=-2)
        names = np.array(MOTION_AXES, dtype=object)[dominant]
        return names.tolist()


def leg_coefficients(name: str, value, *, positive: bool) -> np.ndarray:
    """``value`` (one number, or one per leg) as six finite floats, each > 0 (``positive``) or
    >= 0; ``ValueError`` naming ``name`` otherwise."""
    arr = arguments.reals(name, value)
    if arr.shape not in ((), (1,), (6,)):
        raise ValueError(f"{name}: expected one value or one per leg (6), got shape {arr.shape}")
    arr = np.broadcast_to(arr, (6,)).astype(float)
    bad = ~np.isfinite(arr) | ((arr <= 0.0) if positive else (arr < 0.0))
    if bad.any():
        raise ValueError(f"{name}: must be finite and {'> 0' if positive else '>= 0'} on every leg, "
                         f"got {arr.tolist()}")
    return arr


def _radius(platform) -> float:
    """The platform's radius: the largest distance of a spherical joint from {P}'s origin."""
    points = platform.params.platform_points
    return float(np.max(np.sqrt(np.sum(points * points, axis=1))))


def _inverse_euler_rates(x: np.ndarray) -> np.ndarray:
    """``J_A^-1`` (eq. 8 inverted): maps the angular velocity in {B} to ``[psi', theta', phi']``,
    shape ``(..., 3, 3)``; finite where ``cos theta != 0``."""
    sps, cps = np.sin(x[..., 3]), np.cos(x[..., 3])
    with np.errstate(divide="ignore", invalid="ignore"):
        sec = 1.0 / np.cos(x[..., 4])
    tth, zero = np.tan(x[..., 4]), np.zeros_like(sps)
    rows = [[tth * cps, tth * sps, zero + 1.0], [-sps, cps, zero], [cps * sec, sps * sec, zero]]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def _static_terms(platform, function: str, x, return_mask: bool):
    """``(x, J_C, dtau_s/dx, ok)`` at the pose(s) ``x``: the static forces' exact Jacobian from
    the compiled kernel, ``ok`` ``(N,)`` the rows where the model is defined (all, or
    :class:`~stewart.SingularityError` naming ``function``, without ``return_mask``)."""
    x = arguments.states("x", x)
    zero = np.zeros(6)
    try:
        (tau, dtau_dx, _, _), ok = platform.inverse_dynamics_derivatives(x, zero, zero, return_mask=True) \
            if return_mask else (platform.inverse_dynamics_derivatives(x, zero, zero), True)
    except SingularityError as exc:
        raise SingularityError(str(exc).replace("inverse_dynamics_derivatives", function, 1),
                               rows=exc.rows, condition=exc.condition) from None
    if not return_mask:
        conditions.check(function, x, conditions.euler_codes(x))
    ok = np.reshape(ok, (-1,)) & (conditions.euler_codes(x) == conditions.Status.OK)
    jac = platform.jacobian(np.where(ok[:, None], x, platform.home_pose).reshape(x.shape))
    return x, jac, dtau_dx, ok


def _twist_stiffness(x, jac, dtau_dx, k) -> np.ndarray:
    """``K_t = J_C^T (diag(k) J_C + dtau_s/dx T^-1)`` (module docstring), unsymmetrized."""
    inner = k[:, None] * jac
    inner[..., :3] += dtau_dx[..., :3]
    inner[..., 3:] += dtau_dx[..., 3:] @ _inverse_euler_rates(x)
    return np.swapaxes(jac, -1, -2) @ inner


def stiffness_matrix(platform, x, stiffness, *, coordinates: str = "pose", return_mask: bool = False):
    """The stiffness at the pose(s) ``x`` of the platform on legs of ``stiffness`` [N/m] (one
    value or one per leg, each > 0), preloaded to hold it there: the Hessian of the potential
    ``K_q = J_E^T (diag(k) J_E + dtau_s/dx)`` in the pose coordinates ``[x, y, z, psi, theta,
    phi]`` (``coordinates="pose"``, units N/m, N/rad, N m/rad), or ``K_t = T^-T K_q T^-1`` in the
    twist coordinates ``[dp; dtheta]`` of {B} (``coordinates="twist"``); shape ``(..., 6, 6)``.
    See the module docstring; exact, symmetric to round-off (not symmetrized)."""
    k = leg_coefficients("stiffness", stiffness, positive=True)
    if coordinates not in ("pose", "twist"):
        raise ValueError(f"coordinates: expected 'pose' or 'twist', got {coordinates!r}")
    x, jac, dtau_dx, ok = _static_terms(platform, "stiffness_matrix", x, return_mask)
    if coordinates == "pose":
        from .kinematics import twist_transform

        jac_e = jac @ twist_transform(np.where(ok[:, None], x, 0.0).reshape(x.shape))
        result = np.swapaxes(jac_e, -1, -2) @ (k[:, None] * jac_e + dtau_dx)
    else:
        with np.errstate(invalid="ignore"):
            result = _twist_stiffness(x, jac, dtau_dx, k)
    return (result, ok if x.ndim == 2 else bool(ok[0])) if return_mask else result


def _whitened(platform, x, jac, dtau_dx, k, good):
    """``(K_t symmetrized, M_t)`` ``(N, 6, 6)`` with the rows not ``good`` replaced by identities
    (so that batched linear algebra runs on them)."""
    safe = np.where(good[:, None], x.reshape(-1, 6), platform.home_pose)
    mass = platform.twist_mass_matrix(safe)
    with np.errstate(invalid="ignore"):
        stiff = _twist_stiffness(safe, jac.reshape(-1, 6, 6), np.nan_to_num(dtau_dx.reshape(-1, 6, 6)), k)
    stiff = 0.5 * (stiff + np.swapaxes(stiff, -1, -2))
    stiff[~good], mass[~good] = np.eye(6), np.eye(6)
    return stiff, mass


def _unstable(function: str, lowest: np.ndarray, good: np.ndarray, batch: bool, return_mask: bool) -> np.ndarray:
    """``good`` without the rows whose lowest eigenvalue ``lowest`` (of the stiffness, or of the
    generalized eigenproblem) is not positive,
    or :class:`~stewart.model.errors.UnstableError` naming them (without ``return_mask``)."""
    unstable = good & ~(lowest > 0.0)
    if unstable.any() and not return_mask:
        rows = np.flatnonzero(unstable).tolist()
        where = f" at row(s) {row_list(rows)}" if batch else ""
        raise UnstableError(f"{function}: the preloaded legs cannot hold the pose{where}: the stiffness is not "
                            "positive definite (the preload buckles the platform); stiffer legs or a smaller load",
                            rows=rows)
    return good & ~unstable


def _eigen(stiff: np.ndarray, mass: np.ndarray, vectors: bool):
    """Eigenvalues ``w^2`` (ascending, ``(N, 6)``) and mass-normalized eigenvectors (columns) of
    ``K phi = w^2 M phi``: LAPACK's ``dsygv`` for one matrix, else the batched ``eigh`` of
    ``L^-1 K L^-T`` with ``M = L L^T``."""
    if len(stiff) == 1:
        values, shapes, info = lapack.dsygv(stiff[0], mass[0], jobz="V" if vectors else "N")
        if info == 0:
            return values[None], shapes[None] if vectors else None
    low_inv = np.linalg.inv(np.linalg.cholesky(mass))
    whitened = low_inv @ stiff @ np.swapaxes(low_inv, -1, -2)
    if not vectors:
        return np.linalg.eigvalsh(whitened), None
    values, vecs = np.linalg.eigh(whitened)
    return values, np.swapaxes(low_inv, -1, -2) @ vecs


def _damping_ratios(values: np.ndarray, shapes: np.ndarray, c: np.ndarray, jac: np.ndarray) -> np.ndarray:
    """The damping ratio of each undamped mode from the quadratic eigenproblem, solved in the
    modal coordinates: ``A = [[0, I], [-W^2, -Phi^T C_t Phi]]``; each pair of eigenvalues ``s``
    belongs to the mode that dominates its displacement part, and gives
    ``zeta = -(s1 + s2) / (2 sqrt(s1 s2))`` (``-Re s / |s|`` for a complex pair)."""
    n = len(values)
    damper = np.swapaxes(jac, -1, -2) @ (c[:, None] * jac)
    modal = np.swapaxes(shapes, -1, -2) @ damper @ shapes
    state = np.zeros((n, 12, 12))
    state[:, :6, 6:] = np.eye(6)
    state[:, 6:, :6] = -values[:, :, None] * np.eye(6)
    state[:, 6:, 6:] = -modal
    roots, vecs = np.linalg.eig(state)
    weight = np.abs(vecs[:, :6, :]) ** 2                           # (n, mode, root)
    owner = np.argmax(weight, axis=1)                              # (n, root)
    ratios = np.full((n, 6), np.nan)
    for mode in range(6):
        mine = owner == mode
        paired = np.sum(mine, axis=1) == 2
        pick = np.argsort(~mine, axis=1, kind="stable")[:, :2]    # the two roots of this mode
        s = np.take_along_axis(roots, pick, axis=1)
        product, total = np.real(s[:, 0] * s[:, 1]), np.real(s[:, 0] + s[:, 1])
        with np.errstate(invalid="ignore", divide="ignore"):
            ratios[:, mode] = np.where(paired, -total / (2.0 * np.sqrt(product)), np.nan)
    return ratios


def _modal(platform, function, x, stiffness, damping, return_mask, vectors):
    """The undamped eigenvalues, shapes, damping ratios and mask at ``x`` (see :func:`modes`)."""
    k = leg_coefficients("stiffness", stiffness, positive=True)
    c = None if damping is None else leg_coefficients("damping", damping, positive=False)
    x, jac, dtau_dx, ok = _static_terms(platform, function, x, return_mask)
    stiff, mass = _whitened(platform, x, jac, dtau_dx, k, ok)
    values, shapes = _eigen(stiff, mass, vectors)
    good = _unstable(function, values[:, 0], ok, x.ndim == 2, return_mask)
    ratios = None if c is None else _damping_ratios(values, shapes, c, jac.reshape(-1, 6, 6))
    return x, values, shapes, ratios, good


def modes(platform, x, stiffness, damping=None, *, return_mask: bool = False):
    """The natural frequencies and mode shapes (:class:`Modes`) at the pose(s) ``x`` of the
    platform on legs of ``stiffness`` [N/m] (each > 0) preloaded to hold it there, with
    ``damping`` [N s/m] (each >= 0) the damping ratios; one value or one per leg each.

    :class:`~stewart.SingularityError` where the model is undefined (a singular ``J_C``,
    ``theta = +-90 deg``), :class:`~stewart.model.errors.UnstableError` where the stiffness is
    not positive definite (the preload buckles the legs: the pose cannot be held); with
    ``return_mask`` those rows are NaN and ``(modes, ok)`` is returned."""
    x, values, shapes, ratios, good = _modal(platform, "modes", x, stiffness, damping, return_mask, True)
    with np.errstate(invalid="ignore"):
        freqs = np.sqrt(values) / (2.0 * np.pi)
    freqs[~good], shapes[~good] = np.nan, np.nan
    if ratios is not None:
        ratios[~good] = np.nan
    one = x.ndim == 1
    result = Modes(freqs[0] if one else freqs, shapes[0] if one else shapes,
                   None if ratios is None else ratios[0] if one else ratios, _radius(platform))
    return (result, bool(good[0]) if one else good) if return_mask else result


def lowest_frequency(platform, x, stiffness, *, return_mask: bool = False):
    """The lowest natural frequency [Hz] at the pose(s) ``x`` (:func:`modes` without the
    shapes), shape ``(...)``."""
    x, values, _, _, good = _modal(platform, "lowest_frequency", x, stiffness, None, return_mask, False)
    with np.errstate(invalid="ignore"):
        lowest = np.where(good, np.sqrt(values[:, 0]) / (2.0 * np.pi), np.nan)
    one = x.ndim == 1
    result = lowest[0] if one else lowest
    return (result, bool(good[0]) if one else good) if return_mask else result


def compliance(platform, x, stiffness, point=None, *, return_mask: bool = False):
    """The Cartesian compliance at the pose(s) ``x`` of the platform on preloaded legs of
    ``stiffness`` [N/m]: the matrix ``(..., 6, 6)`` that maps a small wrench ``[f (N); m (N m)]``
    applied at ``point`` (in {P}, m; default {P}'s origin) to the small displacement
    ``[dp (m); dtheta (rad)]`` of that point and of the platform, all in {B}:
    ``A K_t^-1 A^T`` with ``A = [[I, -[r]x], [0, I]]``, ``r = R point``. Errors as :func:`modes`."""
    k = leg_coefficients("stiffness", stiffness, positive=True)
    point = np.zeros(3) if point is None else arguments.reals("point", point)
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise ValueError(f"point: expected three finite coordinates in {{P}} (m), got {point.tolist()}")
    x, jac, dtau_dx, ok = _static_terms(platform, "compliance", x, return_mask)
    stiff, _ = _whitened(platform, x, jac, dtau_dx, k, ok)
    good = _unstable("compliance", np.linalg.eigvalsh(stiff)[:, 0], ok, x.ndim == 2, return_mask)
    from .kinematics import rotation

    arm = rotation(np.where(good[:, None], x.reshape(-1, 6), 0.0)) @ point
    shift = np.broadcast_to(np.eye(6), stiff.shape).copy()
    shift[:, 0, 4], shift[:, 0, 5] = arm[:, 2], -arm[:, 1]
    shift[:, 1, 3], shift[:, 1, 5] = -arm[:, 2], arm[:, 0]
    shift[:, 2, 3], shift[:, 2, 4] = arm[:, 1], -arm[:, 0]
    result = shift @ np.linalg.solve(stiff, np.swapaxes(shift, -1, -2))
    result[~good] = np.nan
    one = x.ndim == 1
    result = result[0] if one else result
    return (result, bool(good[0]) if one else good) if return_mask else result


def largest_compliance(platform, x, stiffness, point=None, *, return_mask: bool = False):
    """The largest translational compliance [m/N] at ``point`` (:func:`compliance`): the
    deflection of that point under a unit force in its weakest direction, the largest
    eigenvalue of the compliance's translational block; shape ``(...)``."""
    result = compliance(platform, x, stiffness, point, return_mask=return_mask)
    matrix = result[0] if return_mask else result
    largest = np.linalg.eigvalsh(np.nan_to_num(matrix[..., :3, :3]))[..., -1]
    largest = np.where(np.isnan(matrix[..., 0, 0]), np.nan, largest)
    return (largest[()], result[1]) if return_mask else largest[()]
