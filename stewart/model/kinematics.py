"""Kinematics of the 6-UPS platform, batched over a leading axis.

Every function takes one pose ``x = [x, y, z, psi, theta, phi]`` of shape ``(6,)`` or a
batch ``(N, 6)`` and returns the matching shape. The orientation is ZYX Euler,
``R = Rz(psi) Ry(theta) Rx(phi)`` (Lopes & Pires 2011, eqs. 3 and 8). Per state, the
mathematics is the generated C model's (the derivation in ``codegen/kinematics.py``, through
the compiled kernel of the parameters: :class:`stewart.Platform`'s methods of the same names);
the functions here keep the signatures that take a parameter set, and import the compiled
extension when first called. :func:`home_pose` alone is numpy, a one-off search per call
that needs no compiled model. A zero-length leg where a unit vector is needed, or a result that
overflows, raises :class:`~stewart.SingularityError`. The functions of the orientation alone
(:func:`rotation`, :func:`euler_rate_jacobian`, :func:`twist_transform`) take a complex pose
as a complex step, from the generated partials; the others take real poses (complex-step
derivatives of them take the oracles' own numpy kinematics, :mod:`stewart.oracles.frames`).
"""

from __future__ import annotations

import numpy as np

from . import arguments, conditions
from .errors import ConvergenceError
from .params import platform_params
from .params import TOLERANCE, PlatformParams

#: The coordinates of a pose, in the order of a state: the position of {P}'s origin in {B}
#: and the ZYX Euler angles (eq. 3). Every table, file and plot names them so.
POSE_AXES = ("x", "y", "z", "psi", "theta", "phi")
#: The unit of each coordinate of :data:`POSE_AXES`.
POSE_UNITS = ("m", "m", "m", "rad", "rad", "rad")
#: The names of the pose rates and accelerations in files (``x_dot``, ..., ``phi_ddot``).
POSE_RATES = tuple(f"{a}_dot" for a in POSE_AXES)
POSE_ACCELERATIONS = tuple(f"{a}_ddot" for a in POSE_AXES)

__all__ = [
    "POSE_RATES",
    "POSE_ACCELERATIONS",
    "POSE_AXES",
    "POSE_UNITS",
    "rotation",
    "euler_rate_jacobian",
    "twist_transform",
    "leg_vectors",
    "leg_lengths",
    "leg_length_expressions",
    "leg_unit_vectors",
    "jacobian",
    "euler_jacobian",
    "leg_velocities",
    "leg_accelerations",
    "home_pose",
    "check_universal_joint_axes",
    "forward_kinematics",
    "encoder_readings",
]


#: The reference geometry whose compiled kernel evaluates what does not depend on the parameters
#: (the rotation, ``J_A``): any platform's gives the same values.
_ANY_PLATFORM = "narayan2017"

#: The last kernel built for a parameter set, ``(params, kernel)``, replaced whole (a kernel costs
#: some 25 us to build, as much as a call; callers repeat the same parameters).
_last = (None, None)


def _kernel_of(params):
    """The compiled model (:class:`stewart.model.compiled.Kernel`) of ``params`` (a
    :class:`~stewart.PlatformParams`, or a :class:`~stewart.Platform`, whose own kernel it is),
    built once for the last parameter set asked for."""
    global _last
    kernel = getattr(params, "kernel", None)
    if kernel is not None and isinstance(getattr(params, "params", None), PlatformParams):
        return kernel
    params = platform_params(params)
    last_params, kernel = _last
    if last_params is not params:
        from .compiled import Kernel

        kernel = Kernel(params)
        _last = (params, kernel)
    return kernel


def _geometry_free():
    """A kernel for the functions that do not depend on the parameters."""
    kernel = _last[1]
    return _kernel_of(PlatformParams.preset(_ANY_PLATFORM)) if kernel is None else kernel


#: The largest imaginary part of a complex pose, which is taken as a complex step (below it the
#: first-order expansion is exact in double precision: its error is of the order of the square).
COMPLEX_STEP_LIMIT = 1e-8


def _stepped(function, x) -> np.ndarray:
    """``function`` (a kernel's method of a state that depends on the Euler angles alone; with
    ``partials=True`` its value and its partials along them) at the poses ``x``. A complex pose
    ``x + i h`` is a complex step (|h| at most :data:`COMPLEX_STEP_LIMIT`): ``f(x) + i sum_k
    df/de_k h_k``, its first-order expansion, which is what a complex-step derivative reads."""
    x = arguments.states("x", x, allow_complex=True)
    if not np.iscomplexobj(x):
        return function(x)
    step = x.imag[..., 3:]
    if not np.all(np.abs(step) <= COMPLEX_STEP_LIMIT):
        raise ValueError(f"x: a complex pose is taken as a complex step x + i h with |h| <= {COMPLEX_STEP_LIMIT:g}, "
                         f"got |h| up to {np.max(np.abs(step)):.3g}")
    value, *partials = function(np.ascontiguousarray(x.real), partials=True)
    return value + 1j * sum(partial * step[..., k, None, None] for k, partial in enumerate(partials))


def rotation(x) -> np.ndarray:
    """Orientation ``R = Rz(psi) Ry(theta) Rx(phi)`` of {P} in {B} (eq. 3), shape ``(..., 3, 3)``
    (:meth:`stewart.Platform.rotation`); of a complex pose, a complex step (:data:`COMPLEX_STEP_LIMIT`)."""
    return _stepped(_geometry_free().rotation, x)


def euler_rate_jacobian(x) -> np.ndarray:
    """``J_A`` of eq. 8: maps ``[psi', theta', phi']`` to the angular velocity in {B}
    (:meth:`stewart.Platform.euler_rate_jacobian`); of a complex pose, a complex step
    (:data:`COMPLEX_STEP_LIMIT`)."""
    return _stepped(_geometry_free().euler_rate_jacobian, x)


def twist_transform(x) -> np.ndarray:
    """``T = blockdiag(I3, J_A)`` of eq. 18: the twist ``[v; omega] = T xdot``; of a complex pose,
    a complex step (:data:`COMPLEX_STEP_LIMIT`)."""
    j_a = euler_rate_jacobian(x)
    out = np.zeros(j_a.shape[:-2] + (6, 6), dtype=j_a.dtype)
    out[..., 0, 0] = out[..., 1, 1] = out[..., 2, 2] = 1.0
    out[..., 3:, 3:] = j_a
    return out


def platform_points_in_base(params: PlatformParams, x) -> np.ndarray:
    """``r_i = R p_i``: the platform points rotated into {B} (not translated), ``(..., 6, 3)``."""
    return np.einsum("...jk,ik->...ij", rotation(x), platform_params(params).platform_points)


def leg_vectors(params: PlatformParams, x) -> np.ndarray:
    """Leg vectors ``l_i = p + R p_i - b_i`` of eq. 26, shape ``(..., 6, 3)``
    (:meth:`stewart.Platform.leg_vectors`)."""
    return _kernel_of(params).leg_vectors(x)


def leg_lengths(params: PlatformParams, x) -> np.ndarray:
    """Leg lengths ``|l_i|``, shape ``(..., 6)`` (:meth:`stewart.Platform.leg_lengths`)."""
    return _kernel_of(params).leg_lengths(x)


def leg_length_expressions(params: PlatformParams, x, ops) -> list:
    """The six leg lengths ``|p + R p_i - b_i|`` (eq. 26) as expressions of the pose ``x`` (six
    scalars: ``x[0]`` .. ``x[5]``) in the arithmetic of ``ops``, a module with ``cos``, ``sin``
    and ``sqrt``: CasADi's, for a symbolic framework that takes constraints as expressions only
    (acados's ``con_h``), or numpy's. The same mathematics as :func:`leg_lengths` (the compiled
    model's), written out once here for such frameworks, with the parameters as constants."""
    params = platform_params(params)
    cps, sps = ops.cos(x[3]), ops.sin(x[3])
    cth, sth = ops.cos(x[4]), ops.sin(x[4])
    cph, sph = ops.cos(x[5]), ops.sin(x[5])
    rot = ((cps * cth, cps * sth * sph - sps * cph, cps * sth * cph + sps * sph),
           (sps * cth, sps * sth * sph + cps * cph, sps * sth * cph - cps * sph),
           (-sth, cth * sph, cth * cph))
    lengths = []
    for joint, anchor in zip(params.platform_points.tolist(), params.base_points.tolist()):
        leg = [x[k] + sum(rot[k][j] * joint[j] for j in range(3)) - anchor[k] for k in range(3)]
        lengths.append(ops.sqrt(leg[0] * leg[0] + leg[1] * leg[1] + leg[2] * leg[2]))
    return lengths


def leg_unit_vectors(params: PlatformParams, x) -> np.ndarray:
    """Unit leg vectors ``l_i / |l_i|`` of eq. 25, shape ``(..., 6, 3)``; a zero-length leg
    raises :class:`~stewart.SingularityError` (:meth:`stewart.Platform.leg_unit_vectors`)."""
    return _kernel_of(params).leg_unit_vectors(x)


def jacobian(params: PlatformParams, x) -> np.ndarray:
    """Kinematic Jacobian ``J_C`` of eq. 5, ``Ldot = J_C [v; omega]``; row i is
    ``[u_i, (R p_i) x u_i]``. Shape ``(..., 6, 6)``; a zero-length leg raises
    :class:`~stewart.SingularityError` (:meth:`stewart.Platform.jacobian`)."""
    return _kernel_of(params).jacobian(x)


def euler_jacobian(params: PlatformParams, x) -> np.ndarray:
    """Euler-angle Jacobian ``J_E = J_C T`` of eq. 4, ``Ldot = J_E xdot``."""
    return jacobian(params, x) @ twist_transform(x)


def leg_velocities(params: PlatformParams, x, xd) -> np.ndarray:
    """Leg extension rates ``Ldot = J_E xdot`` (eq. 4), shape ``(..., 6)``: those of
    :meth:`stewart.Platform.leg_rates`."""
    return _kernel_of(params).leg_rates(x, xd)[1]


def leg_accelerations(params: PlatformParams, x, xd, xdd) -> np.ndarray:
    """Leg extension accelerations ``Lddot``, shape ``(..., 6)``: the second time derivative of
    ``L_i = |l_i|`` (eq. 26), ``Lddot_i = u_i . a_i + (|v_i|^2 - Ldot_i^2) / L_i`` with the
    velocity ``v_i = p' + omega x r_i`` and acceleration ``a_i = p'' + alpha x r_i + omega x
    (omega x r_i)`` of the spherical joint ``P_i`` and ``Ldot_i = u_i . v_i`` (eq. 4)
    (:meth:`stewart.Platform.leg_accelerations`)."""
    return _kernel_of(params).leg_accelerations(x, xd, xdd)


def home_pose(params: PlatformParams, leg_length: float | None = None) -> np.ndarray:
    """The home pose: no rotation, {P}'s joint centroid above the base's, at the height
    where the mean leg length equals ``leg_length`` (in numpy: a one-off bisection on the
    legs' horizontal spans, which needs no compiled model).

    ``leg_length`` defaults to mid-stroke of ``params.leg_length_limits``; for a platform
    without limits, to the larger of the base's circumradius and sqrt(2) times the widest
    horizontal leg span at home (so no leg leans more than 45 degrees).
    """
    params = platform_params(params)
    offset = params.base_points.mean(axis=0) - params.platform_points.mean(axis=0)
    planar = params.platform_points[:, :2] + offset[:2] - params.base_points[:, :2]
    dz0 = params.platform_points[:, 2] - params.base_points[:, 2]
    reach = np.sqrt(np.sum(planar * planar, axis=1))
    if leg_length is None:
        if params.leg_length_limits is not None:
            leg_length = 0.5 * sum(params.leg_length_limits)
        else:
            centred = params.base_points - params.base_points.mean(axis=0)
            leg_length = max(float(np.max(np.sqrt(np.sum(centred * centred, axis=1)))), np.sqrt(2.0) * reach.max())
    leg_length = arguments.real("leg_length", leg_length)

    def mean_length(z: float) -> float:
        with np.errstate(over="ignore"):  # inf for lengths near the float limit: bisection still works
            return float(np.add.reduce(np.hypot(reach, z + dz0))) / len(reach)

    # Above the highest base joint, mean_length increases with z: bisect on it.
    lo = float(np.max(-dz0))
    if not np.isfinite(leg_length) or mean_length(lo) >= leg_length:
        raise ValueError(
            f"leg_length: {leg_length} m is too short to raise the platform above the base "
            f"(the legs span up to {reach.max():.6g} m horizontally at home)"
        )
    hi = lo + leg_length
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:  # converged to adjacent floats: further steps change nothing
            break
        if mean_length(mid) < leg_length:
            lo = mid
        else:
            hi = mid
    return np.array([offset[0], offset[1], 0.5 * (lo + hi), 0.0, 0.0, 0.0])


#: Most Newton iterations :func:`forward_kinematics` may be asked for.
MAX_ITERATIONS = 10_000


def check_universal_joint_axes(params: PlatformParams, home: np.ndarray | None = None) -> None:
    """``ValueError`` naming ``universal_joint_axes`` when a joint's first axis lies within
    :data:`stewart.model.params.TOLERANCE` radians of parallel to its leg at the home pose (the
    joint's gimbal lock); nothing for the paper's model. ``home`` defaults to
    :func:`home_pose`. (The check needs the home pose, so it runs here and in
    :class:`stewart.Platform`, not in :class:`PlatformParams`.)"""
    axes = platform_params(params).universal_joint_axes
    if axes is None:
        return
    units = leg_unit_vectors(params, home_pose(params) if home is None else home)
    sines = np.linalg.norm(np.cross(axes, units), axis=1) / np.linalg.norm(axes, axis=1)
    if np.any(sines <= TOLERANCE):
        i = int(np.argmin(sines))
        raise ValueError(
            f"universal_joint_axes: axis {i} is parallel to leg {i} at the home pose "
            "(the joint's gimbal lock); choose a first axis across the leg"
        )


def encoder_readings(params: PlatformParams, x) -> np.ndarray:
    """The machine's encoder readings at ``x``: the true leg lengths ``|l_i|`` less
    ``params.leg_length_offsets``, shape ``(..., 6)``."""
    params = platform_params(params)
    return leg_lengths(params, x) - params.leg_length_offsets


def forward_kinematics(
    params: PlatformParams,
    lengths,
    guess=None,
    *,
    tol: float = 1e-12,
    max_iter: int = 50,
    encoder: bool = False,
) -> np.ndarray:
    """Pose(s) with the given leg lengths, by Newton-Raphson on ``L(x) = lengths``.

    ``lengths`` is ``(6,)`` or ``(N, 6)``: true leg lengths ``|l_i|``, or with ``encoder=True``
    a machine's encoder readings, to which ``params.leg_length_offsets`` are added. The iteration starts from ``guess`` (one pose,
    or one per row; default :func:`home_pose`) on the compiled model's leg lengths and uses ``J_E = J_C T``
    (eqs. 4, 5, 18; the compiled ``J_C`` and ``J_A``) as the Jacobian,
    halving a step that does not reduce the residual; a row stops where ``J_E`` is singular
    by the model's test for ``J_C`` (:func:`stewart.model.conditions.jacobian_codes`). Raises
    :class:`~stewart.model.errors.ConvergenceError` naming the rows that did not reach
    ``max|L(x) - lengths| <= tol * max(lengths)``. ``tol`` is a positive number and
    ``max_iter`` an int from 1 to 10000.
    """
    params = platform_params(params)
    lengths = arguments.states("lengths", lengths)
    if encoder:
        lengths = lengths + params.leg_length_offsets
    if np.any(lengths <= 0.0):
        raise ValueError("lengths: leg lengths must be positive")
    tol = arguments.real("tol", tol)
    if not tol > 0.0:
        raise ValueError(f"tol: must be positive, got {tol}")
    max_iter = arguments.count("max_iter", max_iter, MAX_ITERATIONS)
    target = np.atleast_2d(lengths)
    if guess is None:
        x = np.broadcast_to(home_pose(params), target.shape).copy()
    else:
        guess = arguments.states("guess", guess)
        if guess.ndim == 2 and guess.shape != target.shape:
            raise ValueError(f"guess: expected one pose or one per row of lengths {lengths.shape}, got {guess.shape}")
        x = np.broadcast_to(guess, target.shape).copy()
    scale = tol * target.max(axis=1)

    kernel = _kernel_of(params)

    def residual(poses, rows=slice(None)):
        out = np.full(poses.shape, np.inf)  # a trial step may leave the floats
        fine = np.isfinite(poses).all(axis=1)
        out[fine] = kernel.leg_lengths(poses[fine], return_mask=True)[0] - target[rows][fine]
        out[np.isnan(out)] = np.inf  # lengths that overflow
        return out

    res = residual(x)
    norm = np.max(np.abs(res), axis=1)
    active = ~(norm <= scale)
    for _ in range(max_iter):
        if not active.any():
            break
        idx = np.flatnonzero(active)
        jac, fine = kernel.jacobian(x[idx], return_mask=True)  # a zero-length leg: NaN, singular below
        jac = jac @ twist_transform(x[idx])
        singular = ~fine | (conditions.jacobian_codes(jac) != conditions.Status.OK)
        step = np.zeros((idx.size, 6))
        ok = ~singular
        step[ok] = np.linalg.solve(jac[ok], res[idx][ok][..., None])[..., 0]
        trial_norm = np.full(idx.size, np.inf)
        alpha = np.ones(idx.size)
        for _ in range(30):
            pending = ok & ~(trial_norm < norm[idx])
            if not pending.any():
                break
            alpha[pending & np.isfinite(trial_norm)] *= 0.5
            with np.errstate(over="ignore", invalid="ignore"):
                trial = x[idx] - alpha[:, None] * step
            trial_norm = np.max(np.abs(residual(trial, idx)), axis=1)
            trial_norm[~ok] = np.inf
        improved = ok & (trial_norm < norm[idx])
        rows = idx[improved]
        x[rows] = x[rows] - alpha[improved, None] * step[improved]
        res[rows] = residual(x[rows], rows)
        norm[rows] = np.max(np.abs(res[rows]), axis=1)
        active[idx[~improved]] = False
        active[rows] = ~(norm[rows] <= scale[rows])
    failed = np.flatnonzero(~(norm <= scale))
    if failed.size:
        worst = float(np.max(norm[failed]))
        raise ConvergenceError(
            f"forward_kinematics: no pose found for lengths in row(s) {failed[:10].tolist()}"
            f"{' ...' if failed.size > 10 else ''} (residual {worst:.3g} m after {max_iter} "
            "Newton iterations); the lengths may be unreachable or the guess too far",
            rows=failed,
        )
    return x[0] if lengths.ndim == 1 else x
