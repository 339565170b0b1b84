"""Stiffness, natural frequencies and compliance of a platform whose legs are axial springs.

Each leg is a spring of stiffness ``k_i`` [N/m] (optionally with a damper ``c_i`` [N s/m])
preloaded to hold the platform and its payload at the pose ``x``: its force is
``tau_i = tau_s,i(x) + k_i (L_i(x) - L_i) - c_i Ldot_i`` with the static forces
``tau_s = inverse_dynamics(x, 0, 0)`` (Lopes & Pires 2011, eqs. 1-2). The total potential
``U`` (the preloaded springs and gravity, eq. 72) is stationary at ``x``; its Hessian in the
pose coordinates ``q = [x, y, z, psi, theta, phi]`` is, exactly (no differences),

    K_q = J_E^T (diag(k) J_E + dtau_s/dx),       J_E = J_C T   (eqs. 4, 5, 18),

where ``dtau_s/dx`` is the exact Jacobian of the static forces
(:meth:`stewart.Platform.static_force_derivatives`). ``J_E^T diag(k) J_E`` is the elastic
term; ``J_E^T dtau_s/dx = T^T R_x`` with ``R_x = d(G - J_C^T tau)/dx`` at fixed ``tau`` holds
the preload's geometric term ``-d(J_C^T)/dx . tau`` and gravity's own term ``dG/dx``
(the Cartesian stiffness of Gosselin 1990 is the first alone; with no preload the second
vanishes).
``R_x`` is the partial of the residual of the equation of motion, so
``K_q = T^T R_x + J_E^T k J_E`` is the Hessian of ``U`` wherever ``J_C^T tau_s = G``.

Small motions obey ``M_t dxi'' + C_t dxi' + K_t dxi = 0`` in the twist coordinates
``dxi = T dq = [dp; dtheta]`` (a small translation of {P}'s origin and a small rotation vector,
both in {B}), with the symmetric twist-space mass matrix ``M_t`` (eqs. 19, 39, 51, 61, 69,
legs included), ``K_t = T^-T K_q T^-1 = J_C^T (diag(k) J_C + dtau_s/dx T^-1)`` and
``C_t = J_C^T diag(c) J_C``. The modes are those of the generalized eigenproblem
``K_t phi = w^2 M_t phi`` (the same frequencies as in pose coordinates, since ``T`` is
invertible away from ``theta = +-90 deg``), the damping ratios those of the quadratic
eigenproblem ``(s^2 M_t + s C_t + K_t) phi = 0``. Each pose's stiffness and undamped modes are
computed in compiled code (``stewart/_modes.pxi``: the generated ``modal_stiffness``,
:meth:`stewart.Platform.modal_stiffness`, and LAPACK's ``dsygv``); the damping ratios and the
compliance in numpy.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from . import arguments, conditions
from .compiled import UNSTABLE, modal_terms
from .errors import SingularityError, UnstableError, row_list
from .fields import leg_coefficients
from .kinematics import rotation, twist_transform

__all__ = ["Modes", "MOTION_AXES", "leg_coefficients", "stiffness_matrix", "modes", "compliance",
           "lowest_frequency", "modal_metrics"]

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


def _radius(platform) -> float:
    """The platform's radius: the largest distance of a spherical joint from {P}'s origin."""
    points = platform.params.platform_points
    return float(np.max(np.sqrt(np.sum(points * points, axis=1))))


def _stiffnesses(platform, stiffness) -> np.ndarray | float:
    """:func:`leg_coefficients` of ``stiffness``, or the parameters' ``leg_stiffness`` for None
    (``ValueError`` if they have none); one positive finite float as it is, the stiffness of every
    leg (:func:`~stewart.model.compiled.modal_terms` takes it so)."""
    if type(stiffness) is float and math.isfinite(stiffness) and stiffness > 0.0:
        return stiffness
    if stiffness is None:
        stiffness = platform.params.leg_stiffness
        if stiffness is None:
            raise ValueError("stiffness: none given, and the parameters have no leg_stiffness (N/m)")
        return stiffness
    return leg_coefficients("stiffness", stiffness, positive=True)


def _dampings(platform, damping) -> np.ndarray | None:
    """:func:`leg_coefficients` of ``damping``, or the parameters' ``leg_damping`` for None."""
    if damping is None:
        return platform.params.leg_damping
    return leg_coefficients("damping", damping, positive=False)


#: {status code: condition} of the compiled model (:data:`stewart.model.conditions.CONDITIONS`).
_CONDITIONS = {condition.code: condition for condition in conditions.CONDITIONS.values()}


class _Terms(NamedTuple):
    """The compiled loop's results (:func:`stewart.model.compiled.modal_terms`) at ``(N, 6)`` poses, with
    ``good`` the rows that did not fail and ``one`` whether a single pose was given."""

    x: np.ndarray
    stiffness: np.ndarray
    jacobian: np.ndarray
    mass: np.ndarray
    frequencies: np.ndarray
    shapes: np.ndarray
    good: np.ndarray | None  # None: every row
    one: bool


def _terms(platform, function: str, x, k, return_mask: bool, stable: bool = True) -> _Terms:
    """The stiffness and modes at the pose(s) ``x`` from the compiled loop. A row where the model
    is undefined raises :class:`~stewart.SingularityError` naming ``function`` and the condition
    (``euler_singular`` at ``theta = +-90 deg``, where ``T^-1`` is undefined), and with ``stable``
    one the legs cannot hold :class:`~stewart.model.errors.UnstableError`; with ``return_mask``
    they are left out of ``good`` instead."""
    try:  # a C-contiguous float64 array of one or N poses as it is (the C checks that each is finite)
        stiff, jac, mass, freqs, shapes, status, failures = modal_terms(platform.kernel, x, k)
    except ValueError:  # anything else, checked and converted (ValueError naming x)
        x = np.ascontiguousarray(arguments.states("x", x))
        stiff, jac, mass, freqs, shapes, status, failures = modal_terms(platform.kernel, x, k)
    one = x.ndim == 1
    poses = x.reshape(-1, 6)
    if not failures:
        return _Terms(poses, stiff, jac, mass, freqs, shapes, None, one)
    failed = (status != 0) & ((status != UNSTABLE) | stable)
    if not return_mask and failed.any():
        arguments.finite_states("x", poses[0] if one else poses)  # names a row that is not finite
        rows = np.flatnonzero(failed).tolist()
        code = int(status[rows[0]])
        if code == UNSTABLE:
            where = "" if one else f" at row(s) {row_list(rows)}"
            raise UnstableError(f"{function}: the preloaded legs cannot hold the pose{where}: the stiffness is "
                                "not positive definite (the preload buckles the platform); stiffer legs or a "
                                "smaller load", rows=rows)
        condition = _CONDITIONS[code]
        raise SingularityError.at_rows(function, condition.name, condition.message, rows, not one)
    return _Terms(poses, stiff, jac, mass, freqs, shapes, ~failed, one)


def _shaped(terms: _Terms, result, return_mask: bool):
    """``result`` (a batch) as one pose's if ``terms`` are of one pose, with the mask if asked."""
    if terms.one:
        result = result[0]
    return (result, _mask(terms)) if return_mask else result


def _mask(terms: _Terms):
    """The rows that did not fail: a bool for one pose, else ``(N,)``."""
    good = np.ones(len(terms.x), bool) if terms.good is None else terms.good
    return bool(good[0]) if terms.one else good


def stiffness_matrix(platform, x, stiffness=None, *, coordinates: str = "pose", return_mask: bool = False):
    """The stiffness at the pose(s) ``x`` of the platform on legs of ``stiffness`` [N/m] (one
    value or one per leg, each > 0), preloaded to hold it there: the Hessian of the potential
    ``K_q = J_E^T (diag(k) J_E + dtau_s/dx)`` in the pose coordinates ``[x, y, z, psi, theta,
    phi]`` (``coordinates="pose"``, units N/m, N/rad, N m/rad), or ``K_t = T^-T K_q T^-1`` in the
    twist coordinates ``[dp; dtheta]`` of {B} (``coordinates="twist"``); shape ``(..., 6, 6)``.
    See the module docstring; exact, symmetric to round-off (not symmetrized). It is given where
    the legs cannot hold the pose too (it is not positive definite there)."""
    k = _stiffnesses(platform, stiffness)
    if coordinates not in ("pose", "twist"):
        raise ValueError(f"coordinates: expected 'pose' or 'twist', got {coordinates!r}")
    terms = _terms(platform, "stiffness_matrix", x, k, return_mask, stable=False)
    result = terms.stiffness
    if coordinates == "pose":
        transform = twist_transform(terms.x if terms.good is None else np.where(terms.good[:, None], terms.x, 0.0))
        result = np.swapaxes(transform, -1, -2) @ result @ transform
    return _shaped(terms, result, return_mask)


def _owners(weights: np.ndarray) -> np.ndarray:
    """The mode of each of the 12 roots ``(n, 12)`` from their weights on the modes ``(n, 12, 6)``,
    two roots a mode: greedily, the largest weight of a root not yet given to a mode not yet
    holding two. Where each root's largest weight is on a different mode from all but one
    other root's, that is its largest; where modes are repeated (equal frequencies: the roots'
    eigenvectors mix them arbitrarily), it is one of the balanced choices, which may give a mode
    a repeated root twice (:func:`_damping_ratios` tells that from a pair)."""
    n = len(weights)
    rows = np.arange(n)
    w = weights.copy()
    owner = np.zeros((n, 12), int)
    held = np.zeros((n, 6), int)
    for _ in range(12):
        root, mode = np.divmod(np.argmax(w.reshape(n, -1), axis=1), 6)
        owner[rows, root] = mode
        held[rows, mode] += 1
        w[rows, root, :] = -1.0                                   # the root is given
        w = np.where((held == 2)[:, None, :], -1.0, w)            # the mode holds two
    return owner


#: Least relative distance of a mode's two real roots for their pair's ratio: nearer, they may be
#: one repeated root given to the mode twice (:func:`_damping_ratios`).
DISTINCT_ROOTS = 1e-6


def _damping_ratios(values: np.ndarray, shapes: np.ndarray, c: np.ndarray, jac: np.ndarray) -> np.ndarray:
    """The damping ratio of each undamped mode from the quadratic eigenproblem, solved in the
    modal coordinates: ``A = [[0, I], [-W^2, -D]]``, ``D = Phi^T C_t Phi``. Two roots go to each
    mode (:func:`_owners`: those whose eigenvectors it dominates), and its ratio is
    ``zeta = -(s1 + s2) / (2 sqrt(s1 s2))`` (``-Re s / |s|`` for a complex pair), which with
    ``sqrt(s1 s2)`` gives back the roots. Where the two are not a pair (a complex root and not its
    conjugate, or two real roots nearer than :data:`DISTINCT_ROOTS`: a repeated mode's repeated
    root given to it twice) each root gives its own ratio, that of the scalar quadratic
    ``m s^2 + c s + k = 0`` of the displacement part ``eta`` of its eigenvector (``m = eta^H
    eta``, ``c = eta^H D eta``, ``k = eta^H W^2 eta``), ``c / (2 sqrt(k m))``, the same for
    each root of a mode where ``D`` is diagonal, and the mode the mean of its two."""
    n = len(values)
    damper = np.swapaxes(jac, -1, -2) @ (c[:, None] * jac)
    modal = np.swapaxes(shapes, -1, -2) @ damper @ shapes
    state = np.zeros((n, 12, 12))
    state[:, :6, 6:] = np.eye(6)
    state[:, 6:, :6] = -values[:, :, None] * np.eye(6)
    state[:, 6:, 6:] = -modal
    roots, vecs = np.linalg.eig(state)
    eta = np.swapaxes(vecs[:, :6, :], -1, -2)                     # (n, root, mode)
    power = np.abs(eta) ** 2
    m = np.sum(power, axis=-1)
    k = np.sum(power * values[:, None, :], axis=-1)
    d = np.real(np.einsum("nri,nij,nrj->nr", eta.conj(), modal, eta))
    with np.errstate(invalid="ignore", divide="ignore"):  # the rows that failed (all zero), NaN after
        own = d / (2.0 * np.sqrt(k * m))
        owner = _owners(power / m[..., None])
    ratios = np.zeros((n, 6))
    for mode in range(6):
        pick = np.argsort(owner != mode, axis=1, kind="stable")[:, :2]  # its two roots, in order
        s = np.take_along_axis(roots, pick, axis=1)
        real = (s.imag == 0).all(axis=1)
        pair = np.where(real, np.abs(s[:, 0] - s[:, 1]) > DISTINCT_ROOTS * np.abs(s[:, 0]),
                        (s[:, 0].imag != 0) & (s[:, 1] == s[:, 0].conj()))
        product, total = np.real(s[:, 0] * s[:, 1]), np.real(s[:, 0] + s[:, 1])
        with np.errstate(invalid="ignore", divide="ignore"):
            ratios[:, mode] = np.where(pair, -total / (2.0 * np.sqrt(product)),
                                       np.take_along_axis(own, pick, axis=1).mean(axis=1))
    return ratios


def modes(platform, x, stiffness=None, damping=None, *, return_mask: bool = False):
    """The natural frequencies and mode shapes (:class:`Modes`) at the pose(s) ``x`` of the
    platform on legs of ``stiffness`` [N/m] (each > 0) preloaded to hold it there, with
    ``damping`` [N s/m] (each >= 0) the damping ratios; one value or one per leg each, by
    default the parameters' ``leg_stiffness`` (``ValueError`` without one) and ``leg_damping``
    (no damping ratios without one); so for every function here.

    :class:`~stewart.SingularityError` where the model is undefined (a singular ``J_C``,
    ``theta = +-90 deg``), :class:`~stewart.model.errors.UnstableError` where the stiffness is
    not positive definite (the preload buckles the legs: the pose cannot be held); with
    ``return_mask`` those rows are NaN and ``(modes, ok)`` is returned."""
    k = _stiffnesses(platform, stiffness)
    c = _dampings(platform, damping)
    terms = _terms(platform, "modes", x, k, return_mask)
    ratios = None
    if c is not None:
        omega = 2.0 * np.pi * np.nan_to_num(terms.frequencies)
        ratios = _damping_ratios(omega * omega, np.nan_to_num(terms.shapes), c, np.nan_to_num(terms.jacobian))
        if terms.good is not None:
            ratios[~terms.good] = np.nan
    if terms.one:
        result = Modes(terms.frequencies[0], terms.shapes[0], None if ratios is None else ratios[0], _radius(platform))
    else:
        result = Modes(terms.frequencies, terms.shapes, ratios, _radius(platform))
    return (result, _mask(terms)) if return_mask else result


def lowest_frequency(platform, x, stiffness=None, *, return_mask: bool = False):
    """The lowest natural frequency [Hz] at the pose(s) ``x`` (:func:`modes` without the
    shapes), shape ``(...)``."""
    terms = _terms(platform, "lowest_frequency", x, _stiffnesses(platform, stiffness), return_mask)
    return _shaped(terms, terms.frequencies[:, 0], return_mask)


def _point(point) -> np.ndarray:
    """``point`` (in {P}, m; None: the origin) as three finite numbers; ``ValueError`` otherwise."""
    point = np.zeros(3) if point is None else arguments.reals("point", point)
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise ValueError(f"point: expected three finite coordinates in {{P}} (m), got {point.tolist()}")
    return point


def _compliances(terms: _Terms, point: np.ndarray, good: np.ndarray) -> np.ndarray:
    """``A K_t^-1 A^T`` ``(N, 6, 6)`` at the rows ``good`` of ``terms`` (NaN elsewhere): see
    :func:`compliance`."""
    stiff = np.where(good[:, None, None], terms.stiffness, np.eye(6))
    arm = rotation(np.where(good[:, None], terms.x, 0.0)) @ point
    shift = np.broadcast_to(np.eye(6), stiff.shape).copy()
    shift[:, 0, 4], shift[:, 0, 5] = arm[:, 2], -arm[:, 1]
    shift[:, 1, 3], shift[:, 1, 5] = -arm[:, 2], arm[:, 0]
    shift[:, 2, 3], shift[:, 2, 4] = arm[:, 1], -arm[:, 0]
    result = shift @ np.linalg.solve(stiff, np.swapaxes(shift, -1, -2))
    result[~good] = np.nan
    return result


def compliance(platform, x, stiffness=None, point=None, *, return_mask: bool = False):
    """The Cartesian compliance at the pose(s) ``x`` of the platform on preloaded legs of
    ``stiffness`` [N/m]: the matrix ``(..., 6, 6)`` that maps a small wrench ``[f (N); m (N m)]``
    applied at ``point`` (in {P}, m; default {P}'s origin) to the small displacement
    ``[dp (m); dtheta (rad)]`` of that point and of the platform, all in {B}:
    ``A K_t^-1 A^T`` with ``A = [[I, -[r]x], [0, I]]``, ``r = R point``. Errors as :func:`modes`."""
    k = _stiffnesses(platform, stiffness)
    point = _point(point)
    terms = _terms(platform, "compliance", x, k, return_mask)
    good = np.ones(len(terms.x), bool) if terms.good is None else terms.good
    return _shaped(terms, _compliances(terms, point, good), return_mask)


def modal_metrics(platform, x, stiffness=None, point=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The workspace metrics of the modes at the poses ``x`` ``(N, 6)`` in one pass: the lowest
    natural frequency [Hz] (:func:`modes`), the largest translational compliance [m/N] at
    ``point`` (the deflection under a unit force in the weakest direction, the largest
    eigenvalue of the translational block of :func:`compliance`), both NaN where the model is
    undefined or the legs cannot hold the pose, and the mask of the poses where they are given."""
    point = _point(point)
    terms = _terms(platform, "modal_metrics", x, _stiffnesses(platform, stiffness), True)
    good = np.ones(len(terms.x), bool) if terms.good is None else terms.good
    translational = _compliances(terms, point, good)[:, :3, :3]
    largest = np.linalg.eigvalsh(np.where(good[:, None, None], translational, 0.0))[:, -1]
    return terms.frequencies[:, 0], np.where(good, largest, np.nan), good
