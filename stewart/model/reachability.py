"""Which poses the platform can reach: the one test used before a simulation, a trajectory
optimization and the command line's ``ik``, ``id`` and ``fd``, and from which the workspace
studies (:mod:`stewart.studies.workspace`) are built.

A pose is reachable when

* every leg length is finite (a pose like ``z = 1e308`` overflows) and lies within
  ``params.leg_length_limits`` (when the set has limits);
* the platform is above the base: its lowest point, the lowest spherical joint or, when
  ``params.plate_radius`` is set, the lowest point of its plate's rim (a disc of that radius
  about the z axis of {P}, lying on the spherical joints: in the plane of {P} through the
  highest of them), lies above the base plane, the horizontal plane through the highest
  universal joint, by more than nothing or by ``params.base_clearance`` (when set);
* ``J_C`` (eq. 5) is well conditioned: its condition number, with the rotational columns
  divided by the platform radius so that it does not depend on the units, is at most
  :data:`CONDITION_LIMIT` (the actuator forces that hold a load grow with it). Its
  inverse, ``sigma_min / sigma_max`` of that unit-free ``J_C``, is the **singularity
  margin** reported per pose (:attr:`Reachability.margin`): the local conditioning index
  of Gosselin & Angeles (1991), 1 for an isotropic pose, 0 at a singularity;
* every universal joint is within ``params.universal_joint_max_angle`` and every
  spherical joint within ``params.spherical_joint_max_angle`` (when set): the angle
  between the leg and the joint's neutral axis, the leg's direction at the home pose,
  fixed in {B} for a universal joint and in {P} for a spherical joint (so a joint is
  centred in its range at home, as it is mounted);
* no two legs, taken as the segments ``B_i P_i``, come closer than
  ``params.leg_diameter`` (when set), axis to axis;
* no leg passes through the platform's plate (when ``params.plate_radius`` is set): a leg
  whose base joint lies above the plate's plane crosses that plane once, and must do so
  outside the plate, farther than ``plate_radius`` plus half the ``leg_diameter`` from its
  centre. With the joints in the plate's plane that is any leg rising above the plate; the
  legs' interference with the plate right at their own joints is the spherical joints'
  cone's to bound;
* the ZYX Euler angles are regular: ``|cos theta|`` is at least ``1 / CONDITION_LIMIT``
  (``T`` of eq. 18 is singular at ``theta = +-90 deg``);
* ``det J_C`` has the sign of the assembly mode the platform is in (by default the home
  pose's). ``det J_C`` is continuous, so a pose where it has the other sign is separated
  from the platform by a singularity (``det J_C = 0``): it belongs to another assembly
  mode and cannot be reached without passing one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import arguments, kinematics
from .params import platform_params
from .params import PlatformParams

__all__ = ["WorkspaceError", "Reachability", "reachability", "outside_message", "axis_excursions", "assembly_mode", "margins", "CONDITION_LIMIT",
           "FLAG_NAMES", "joint_angles", "neutral_axes", "segment_distances", "FLAGS", "limits_in_force", "base_gaps",
           "plate_crossings", "jacobian_margins"]

#: Largest unit-free condition number of ``J_C`` (and of the Euler-angle map) accepted.
CONDITION_LIMIT = 1e3

LEG_TOO_SHORT = 1
LEG_TOO_LONG = 2
BELOW_BASE = 4
SINGULAR = 8
EULER_SINGULAR = 16
OTHER_ASSEMBLY_MODE = 32
OUT_OF_RANGE = 64
UNIVERSAL_JOINT_LIMIT = 128
SPHERICAL_JOINT_LIMIT = 256
LEG_COLLISION = 512
LEG_THROUGH_PLATE = 1024

#: The 15 pairs of legs whose clearance is checked, ``(i, j)`` with ``i < j``.
LEG_PAIRS = np.array([(i, j) for i in range(6) for j in range(i + 1, 6)])


class WorkspaceError(ValueError):
    """A pose, a target or a trajectory lies outside the workspace.

    ``rows`` are the offending rows (for a trajectory, the sample indices), ``times`` their
    times when known, and ``reachability`` the full :class:`Reachability`.
    """

    def __init__(self, message: str, reachability: "Reachability", times=None):
        super().__init__(message)
        self.reachability = reachability
        self.rows = np.flatnonzero(~reachability.ok).tolist()
        self.times = None if times is None else [float(times[r]) for r in self.rows]


@dataclass(frozen=True)
class Reachability:
    """Per-row result of :func:`reachability`.

    ``flags`` holds one integer per pose, a sum of the problem bits (0 for a reachable
    pose); ``lengths`` the leg lengths; ``condition`` the unit-free condition number of
    ``J_C`` (inf where it is singular or undefined); ``universal_angles`` and
    ``spherical_angles`` the joint angles from their neutral axes ``(N, 6)`` [rad];
    ``clearance`` the smallest distance between two leg axes [m] and ``closest_legs``
    the index into :data:`LEG_PAIRS` of that pair (both None unless the parameters set
    ``leg_diameter``); ``base_gap`` the height of the platform's lowest point above the base
    plane [m] (:func:`base_gaps`); ``plate_crossings`` ``(N, 6)`` the distance from the plate's
    centre at which each leg crosses the plate's plane, NaN for a leg below it
    (:func:`plate_crossings`; None unless the parameters set ``plate_radius``); ``params`` the
    parameter set checked.
    """

    flags: np.ndarray
    lengths: np.ndarray
    condition: np.ndarray
    limits: tuple[float, float] | None
    universal_angles: np.ndarray | None = None
    spherical_angles: np.ndarray | None = None
    clearance: np.ndarray | None = None
    closest_legs: np.ndarray | None = None
    base_gap: np.ndarray | None = None
    plate_crossings: np.ndarray | None = None
    params: PlatformParams | None = None

    @property
    def ok(self) -> np.ndarray:
        return self.flags == 0

    @property
    def margin(self) -> np.ndarray:
        """The singularity margin ``1 / condition`` per pose: the inverse condition number
        of the unit-free ``J_C``, in [0, 1] (1 isotropic, 0 singular)."""
        return 1.0 / self.condition

    def _reason(self, bit: int, row: int) -> str:
        lengths = self.lengths[row]
        if bit == OUT_OF_RANGE:
            return "the pose is out of numeric range (its leg lengths overflow)"
        if bit == LEG_TOO_SHORT:
            legs = np.flatnonzero(lengths < self.limits[0]).tolist()
            return (f"leg(s) {legs} shorter than the minimum length {self.limits[0]:g} m "
                    f"({', '.join(f'{lengths[i]:.6g}' for i in legs)} m)")
        if bit == LEG_TOO_LONG:
            legs = np.flatnonzero(lengths > self.limits[1]).tolist()
            return (f"leg(s) {legs} longer than the maximum length {self.limits[1]:g} m "
                    f"({', '.join(f'{lengths[i]:.6g}' for i in legs)} m)")
        if bit in (UNIVERSAL_JOINT_LIMIT, SPHERICAL_JOINT_LIMIT):
            kind = "universal" if bit == UNIVERSAL_JOINT_LIMIT else "spherical"
            angles, limit = getattr(self, f"{kind}_angles")[row], getattr(self.params, f"{kind}_joint_max_angle")
            legs = np.flatnonzero(angles > limit).tolist()
            return (f"{kind} joint(s) {legs} beyond their cone half-angle {limit:g} rad "
                    f"({', '.join(f'{angles[i]:.4g}' for i in legs)} rad)")
        if bit == LEG_COLLISION:
            i, j = LEG_PAIRS[self.closest_legs[row]]
            return (f"legs {i} and {j} collide: their axes are {self.clearance[row]:.4g} m apart, less than "
                    f"the leg diameter {self.params.leg_diameter:g} m")
        if bit == BELOW_BASE:
            part = "its plate" if self.params.plate_radius is not None else "its lowest spherical joint"
            need = (f"less than the base clearance {self.params.base_clearance:g} m"
                    if self.params.base_clearance is not None else "not above it")
            return (f"the platform is not above the base: {part} is at a height of {self.base_gap[row]:.4g} m over "
                    f"the base plane, {need}")
        if bit == LEG_THROUGH_PLATE:
            legs = np.flatnonzero(self._through_plate(row)).tolist()
            return (f"leg(s) {legs} pass through the platform's plate: they cross its plane "
                    f"{', '.join(f'{self.plate_crossings[row, i]:.4g}' for i in legs)} m from its centre, within "
                    f"its radius {self.params.plate_radius:g} m{self._leg_radius_words()}")
        if bit == SINGULAR:
            return f"J_C is singular or nearly so (condition number {self.condition[row]:.3g} > {CONDITION_LIMIT:g})"
        if bit == EULER_SINGULAR:
            return "theta = +-90 deg, where the Euler angles are singular"
        return "det J_C has the other sign: the pose is in another assembly mode, beyond a singularity"

    def _through_plate(self, row) -> np.ndarray:
        return _through_plate(self.plate_crossings[row], self.params)

    def _leg_radius_words(self) -> str:
        return "" if self.params.leg_diameter is None else f" plus the legs' radius {_leg_radius(self.params):g} m"

    def reasons(self, row: int) -> list[str]:
        """Human sentences for the problems of one row."""
        return [self._reason(bit, row) for bit in FLAGS if self.flags[row] & bit]

    def message(self, what: str = "pose", times=None) -> str:
        """One line: how many rows are outside, and for each kind of problem the first row
        (or time) where it occurs and how many rows share it."""
        return outside_message(self.flags, FLAGS, self._reason, what, times)


#: The flags of :attr:`Reachability.flags`, in the order their counts are reported.
FLAGS = (OUT_OF_RANGE, LEG_TOO_SHORT, LEG_TOO_LONG, BELOW_BASE, SINGULAR, EULER_SINGULAR, OTHER_ASSEMBLY_MODE,
         UNIVERSAL_JOINT_LIMIT, SPHERICAL_JOINT_LIMIT, LEG_COLLISION, LEG_THROUGH_PLATE)
#: The name of each flag in reports (a workspace study's exclusions, the washout limiter's bounds).
FLAG_NAMES = {OUT_OF_RANGE: "out_of_range", LEG_TOO_SHORT: "leg_too_short", LEG_TOO_LONG: "leg_too_long",
              BELOW_BASE: "below_base", SINGULAR: "singular", EULER_SINGULAR: "euler_singular",
              OTHER_ASSEMBLY_MODE: "other_assembly_mode", UNIVERSAL_JOINT_LIMIT: "universal_joint_limit",
              SPHERICAL_JOINT_LIMIT: "spherical_joint_limit", LEG_COLLISION: "leg_collision",
              LEG_THROUGH_PLATE: "leg_through_plate"}


def limits_in_force(params: PlatformParams) -> str:
    """The limits :func:`reachability` applies to ``params``, in words, for the maps and figures
    of a study: the stroke, the joints' cone half-angles, the leg diameter, the plate and the
    base clearance (or "none" for each the parameters leave out), besides the platform above
    the base and the conditioning."""
    params = platform_params(params)
    stroke = params.leg_length_limits
    cones = [f"{name} {np.degrees(angle):.0f} deg" for name, angle in
             (("universal", params.universal_joint_max_angle), ("spherical", params.spherical_joint_max_angle))
             if angle is not None]
    return (f"stroke {f'{stroke[0]:g}-{stroke[1]:g} m' if stroke else 'unlimited'}; joint cones "
            f"{', '.join(cones) if cones else 'unlimited'}; legs "
            f"{f'{params.leg_diameter:g} m thick' if params.leg_diameter is not None else 'of no thickness'}; plate "
            f"{f'of radius {params.plate_radius:g} m' if params.plate_radius is not None else 'not checked'}; base "
            f"clearance {f'{params.base_clearance:g} m' if params.base_clearance is not None else 'none'}")


def _platform_radius(params: PlatformParams) -> float:
    points = params.platform_points
    return float(np.max(np.sqrt(np.sum((points - points.mean(axis=0)) ** 2, axis=1))))


def assembly_mode(platform, pose) -> float:
    """The sign of ``det J_C`` at ``pose``: +1 or -1 (0 at a singularity)."""
    platform_params(platform, "platform")
    with np.errstate(all="ignore"):
        jac = kinematics.jacobian(platform, pose)
        return float(np.nan_to_num(np.sign(np.linalg.det(jac))))



def outside_message(flags, bits, reason, what: str = "pose", times=None) -> str:
    """One line for per-row problem ``flags``: how many rows are outside, and for each of the
    ``bits`` in turn the first row (or time, ``times``) where it occurs, in the words of
    ``reason(bit, row)``, and how many rows share it."""
    bad = np.flatnonzero(flags != 0)
    if bad.size == 0:
        return f"every {what} is reachable"
    parts = []
    for bit in bits:
        rows = np.flatnonzero(flags & bit)
        if rows.size:
            where = f"t = {float(times[rows[0]]):.4g} s" if times is not None else f"row {rows[0]}"
            more = f" and {rows.size - 1} more" if rows.size > 1 else ""
            parts.append(f"{reason(bit, rows[0])} at {where}{more}")
    return f"{bad.size} of {len(flags)} {what}(s) outside the workspace: " + "; ".join(parts)


def reachability(platform, poses, *, mode: float | None = None, name: str = "poses") -> Reachability:
    """Check ``poses`` (``(6,)`` or ``(N, 6)``) against the workspace of ``platform`` (a
    :class:`~stewart.Platform` or :class:`~stewart.PlatformParams`).

    ``mode`` is the sign of ``det J_C`` of the assembly mode the poses must lie in
    (default: the home pose's, see :func:`assembly_mode`). Returns a :class:`Reachability`
    with one row per pose.
    """
    from .platform import as_platform

    plat = as_platform(platform)
    x = np.atleast_2d(arguments.states(name, poses))
    if np.iscomplexobj(x):
        raise ValueError(f"{name}: expected real poses")
    if mode is None:
        mode = assembly_mode(plat, plat.home_pose)
    neutral = neutral_axes(plat)
    # (no pose: one empty block)
    blocks = [_block(plat, x[i:i + _BLOCK], mode, neutral) for i in range(0, max(len(x), 1), _BLOCK)]
    parts = {key: np.concatenate([b[key] for b in blocks]) if blocks[0][key] is not None else None
             for key in blocks[0]}
    return Reachability(**parts, limits=plat.params.leg_length_limits, params=plat.params)


def axis_excursions(platform, limit: float = 1.0) -> np.ndarray:
    """How far the platform moves from home along each pose axis, alone, before a pose leaves
    the workspace: the smaller of the two directions, ``(6,)`` [m, m, m, rad, rad, rad],
    on a grid of 2000 steps with :func:`reachability`."""
    from .platform import as_platform

    plat = as_platform(platform)
    home = plat.home_pose
    steps = np.linspace(0.0, limit, 2001)[1:]  # 0.5 mm / 0.5 mrad resolution
    out = np.empty(6)
    for k in range(6):
        sides = []
        for sign in (1.0, -1.0):
            poses = np.tile(home, (len(steps), 1))
            poses[:, k] += sign * steps
            ok = reachability(plat, poses).ok
            sides.append(steps[np.argmin(ok)] - steps[0] if not np.all(ok) else limit)
        out[k] = min(sides)
    return out


_BLOCK = 50_000  # poses checked at a time (bounds the memory of long trajectories)


def neutral_axes(plat) -> np.ndarray:
    """The joints' neutral axes: the unit leg vectors at the home pose (in {B}, and equally
    in {P}, whose orientation at home is the identity), ``(6, 3)``."""
    return plat.jacobian(plat.home_pose)[:, :3]


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The angle between unit vectors, ``atan2(|a x b|, a . b)`` (accurate near 0 and pi)."""
    normal = np.cross(a, b)
    return np.arctan2(np.sqrt(_dot(normal, normal)), _dot(a, b))


def joint_angles(params: PlatformParams, poses) -> tuple[np.ndarray, np.ndarray]:
    """The universal- and spherical-joint angles [rad] at ``poses`` (``(6,)`` or ``(N, 6)``),
    each ``(..., 6)``: the angle between leg ``i`` and its joints' neutral axis (the leg's
    direction at the home pose, fixed in {B} for the universal joint and in {P} for the
    spherical joint)."""
    from .platform import as_platform

    plat = as_platform(params, "params")
    x = arguments.states("poses", poses)
    return _joint_angles(plat.leg_unit_vectors(x), plat.rotation(x), neutral_axes(plat))


def _joint_angles(units, rotations, neutral):
    # The spherical joint's neutral axis n_i is fixed in {P}: in {B} it is R n_i.
    return _angle(units, neutral), _angle(units, np.einsum("...jk,ik->...ij", rotations, neutral))


def segment_distances(p0, p1, q0, q1) -> np.ndarray:
    """The smallest distance between the segments ``[p0, p1]`` and ``[q0, q1]`` (arrays
    ``(..., 3)``, segments of positive length), batched over the leading axes.

    The squared distance between ``p0 + s (p1 - p0)`` and ``q0 + t (q1 - q0)`` is a convex
    quadratic on the square ``0 <= s, t <= 1``: its minimum is the stationary point when
    that lies inside, else on an edge of the square, where it is the distance from an end
    point of one segment to the other segment.
    """
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a, e, b, c, f = _dot(d1, d1), _dot(d2, d2), _dot(d1, d2), _dot(d1, r), _dot(d2, r)
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = a * e - b * b
        s = (b * f - c * e) / denom
        t = (a * f - b * c) / denom
        inside = (denom > 1e-12 * a * e) & (s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)
        gap = r + s[..., None] * d1 - t[..., None] * d2
        best = np.where(inside, _dot(gap, gap), np.inf)
    for point, start, direction, length in ((p0, q0, d2, e), (p1, q0, d2, e), (q0, p0, d1, a), (q1, p0, d1, a)):
        along = np.clip(_dot(point - start, direction) / length, 0, 1)
        gap = point - start - along[..., None] * direction
        best = np.minimum(best, _dot(gap, gap))
    return np.sqrt(best)


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Row-wise dot products over the last axis (of length 3)."""
    return np.einsum("...k,...k->...", u, v)


#: Below this margin :func:`_margin` takes the SVD instead of the Gram matrix's eigenvalues.
_GRAM_MARGIN_FLOOR = 1e-2


def _margin(jac: np.ndarray) -> np.ndarray:
    """``sigma_min / sigma_max`` of a batch of 6x6 matrices (0 where non-finite).

    From the eigenvalues of the Gram matrix ``J^T J`` (``sigma^2``; numpy's batched
    ``eigvalsh`` of a symmetric 6x6 costs about half its ``svd``): their absolute error is
    about ``eps lambda_max``, so the margin's relative error is about ``eps / margin^2``,
    1e-12 at most above :data:`_GRAM_MARGIN_FLOOR`; the matrices below it (near a
    singularity, where that error would grow) take the SVD, accurate to round-off there too.
    """
    out = np.zeros(len(jac))
    finite = np.all(np.isfinite(jac), axis=(1, 2))
    if finite.any():
        rows = jac[finite]
        with np.errstate(all="ignore"):
            values = np.linalg.eigvalsh(np.swapaxes(rows, 1, 2) @ rows)
            margin = np.sqrt(np.maximum(values[:, 0], 0.0) / values[:, -1])
        close = ~(margin >= _GRAM_MARGIN_FLOOR)  # NaN (J = 0) too
        if close.any():
            sv = np.linalg.svd(rows[close], compute_uv=False)
            with np.errstate(invalid="ignore"):
                margin[close] = sv[:, -1] / sv[:, 0]
        out[finite] = np.nan_to_num(margin)
    return out


def jacobian_margins(jac: np.ndarray, platform_points: np.ndarray) -> np.ndarray:
    """The singularity margin ``sigma_min / sigma_max`` of Jacobians in the twist ``jac``
    ``(N, 6, 6)`` (``J_C``, or a rotary rig's ``J_alpha``), their rotational columns divided by
    the radius of ``platform_points`` (the largest distance from their centroid) so that it does
    not depend on the units: 0 where a matrix is not finite (:func:`margins`)."""
    points = np.asarray(platform_points, dtype=float)
    radius = float(np.max(np.sqrt(np.sum((points - points.mean(axis=0)) ** 2, axis=1))))
    scaled = np.array(jac, dtype=float)
    with np.errstate(all="ignore"):
        scaled[..., 3:] /= radius
    return _margin(scaled)


def margins(platform, poses) -> np.ndarray:
    """The singularity margin (:attr:`Reachability.margin`) alone of ``poses`` ``(N, 6)``,
    without the other checks of :func:`reachability`: the same values, for callers that
    need only the margin (the excitation's finite differences)."""
    from .platform import as_platform

    plat = as_platform(platform)
    with np.errstate(all="ignore"):
        jac = plat.jacobian(np.atleast_2d(poses), return_mask=True)[0]
        jac[..., 3:] /= _platform_radius(plat.params)
        return 1.0 / (1.0 / _margin(jac))


def _block(plat, x: np.ndarray, mode: float, neutral: np.ndarray) -> dict:
    params = plat.params
    lengths = plat.leg_lengths(x, return_mask=True)[0]
    flags = np.where(np.all(np.isfinite(lengths), axis=1), 0, OUT_OF_RANGE)
    limits = params.leg_length_limits
    if limits is not None:
        flags |= np.where(np.any(lengths < limits[0], axis=1), LEG_TOO_SHORT, 0)
        flags |= np.where(np.any(lengths > limits[1], axis=1), LEG_TOO_LONG, 0)
    rotations = plat.rotation(x)
    gap = _base_gaps(params, x, rotations, plat.leg_vectors(x))
    clearance = params.base_clearance
    flags |= np.where(~(gap > 0.0) if clearance is None else ~(gap >= clearance), BELOW_BASE, 0)
    with np.errstate(all="ignore"):
        jac = plat.jacobian(x, return_mask=True)[0]
        units = jac[..., :3].copy()
        universal, spherical = _joint_angles(units, rotations, neutral)
        jac[..., 3:] /= _platform_radius(params)
        det = np.linalg.det(np.nan_to_num(jac))
        condition = 1.0 / _margin(jac)
    flags |= np.where(~(condition <= CONDITION_LIMIT), SINGULAR, 0)
    flags |= np.where(np.abs(np.cos(x[:, 4])) < 1.0 / CONDITION_LIMIT, EULER_SINGULAR, 0)
    flags |= np.where(np.sign(det) * mode < 0, OTHER_ASSEMBLY_MODE, 0)
    for angles, limit, bit in ((universal, params.universal_joint_max_angle, UNIVERSAL_JOINT_LIMIT),
                               (spherical, params.spherical_joint_max_angle, SPHERICAL_JOINT_LIMIT)):
        if limit is not None:
            flags |= np.where(np.any(~(angles <= limit), axis=1), bit, 0)
    clearance = closest = crossings = None
    if params.leg_diameter is not None:
        ends = params.base_points + lengths[..., None] * units  # P_i = B_i + L_i u_i
        i, j = LEG_PAIRS.T
        with np.errstate(all="ignore"):
            pairs = segment_distances(params.base_points[i], ends[:, i], params.base_points[j], ends[:, j])
        closest = np.argmin(np.nan_to_num(pairs, nan=-1.0), axis=1)
        clearance = pairs[np.arange(len(x)), closest]
        flags |= np.where(~(clearance >= params.leg_diameter), LEG_COLLISION, 0)
    if params.plate_radius is not None:
        crossings = _plate_crossings(params, x, rotations)
        flags |= np.where(np.any(_through_plate(crossings, params), axis=1), LEG_THROUGH_PLATE, 0)
    return dict(flags=flags, lengths=lengths, condition=condition, universal_angles=universal,
                spherical_angles=spherical, clearance=clearance, closest_legs=closest, base_gap=gap,
                plate_crossings=crossings)


def _through_plate(crossings: np.ndarray, params: PlatformParams) -> np.ndarray:
    """The legs of :func:`plate_crossings` ``crossings`` that pass through the plate (NaN, a leg
    below it: False)."""
    return crossings < params.plate_radius + _leg_radius(params)


def _plate_height(params: PlatformParams) -> float:
    """The height of the plate's plane in {P}: that of the highest spherical joint."""
    return float(np.max(params.platform_points[:, 2]))


def _leg_radius(params: PlatformParams) -> float:
    return 0.0 if params.leg_diameter is None else 0.5 * params.leg_diameter


def base_gaps(params, poses) -> np.ndarray:
    """The height [m] of the platform's lowest point above the base plane (the horizontal
    plane through the highest universal joint) at ``poses`` (``(6,)`` or ``(N, 6)``) of
    ``params`` (a :class:`~stewart.PlatformParams` or :class:`~stewart.Platform`): of the lowest spherical
    joint, ``(b_i + l_i)_z`` (eq. 26), and with ``params.plate_radius`` ``r`` of the lowest
    point of the plate's rim, ``c_z - r sin(tilt)`` with ``c`` the plate's centre and
    ``sin(tilt) = |e_z x R^T e_z| = sqrt(1 - (R e_z)_z^2)`` (the rim's lowest point lies along the
    plate's steepest descent); ``(...)``."""
    x = arguments.states("poses", poses)
    rows = np.atleast_2d(x)
    with np.errstate(all="ignore"):
        gaps = _base_gaps(platform_params(params), rows, kinematics.rotation(rows), kinematics.leg_vectors(params, rows))
    return arguments.finite_result("base_gaps", gaps[0] if x.ndim == 1 else gaps, x)


def _base_gaps(params: PlatformParams, x: np.ndarray, rot: np.ndarray, legs: np.ndarray) -> np.ndarray:
    heights = legs[..., 2] + params.base_points[:, 2]  # of P_i = b_i + l_i
    lowest = np.min(heights, axis=1)
    if params.plate_radius is not None:
        tilt = np.hypot(rot[:, 2, 0], rot[:, 2, 1])  # sine of the plate's tilt: |e_z x R^T e_z|
        centre = x[:, 2] + rot[:, 2, 2] * _plate_height(params)
        lowest = np.minimum(lowest, centre - params.plate_radius * tilt)
    return lowest - np.max(params.base_points[:, 2])


def plate_crossings(params, poses) -> np.ndarray:
    """Where each leg's axis ``B_i P_i`` crosses the plane of the platform's plate (the plane of
    {P} through its highest spherical joint), at ``poses`` (``(6,)`` or ``(N, 6)``) of ``params``
    (a :class:`~stewart.PlatformParams` or :class:`~stewart.Platform`): the distance [m] from the
    plate's centre of the crossing point, ``(..., 6)``, NaN for a leg that stays below the plane
    (its base joint below it). In {P}, with heights measured from the plate's plane, the leg runs
    from its joint ``p_i`` (``p_iz <= 0``) to ``b_i' = R^T (b_i - p)``; when ``b_i'`` lies on or
    above the plane it crosses at ``p_i + s (b_i' - p_i)``, ``s = p_iz / (p_iz - b_iz')``
    (``s = 0`` when both lie in it)."""
    x = arguments.states("poses", poses)
    rows = np.atleast_2d(x)
    with np.errstate(all="ignore"):
        crossings = _plate_crossings(platform_params(params), rows, kinematics.rotation(rows))
    crossings = crossings[0] if x.ndim == 1 else crossings
    arguments.finite_result("plate_crossings", np.where(np.isnan(crossings), 0.0, crossings), x)  # NaN: below
    return crossings


def _plate_crossings(params: PlatformParams, x: np.ndarray, rot: np.ndarray) -> np.ndarray:
    plane = np.array([0.0, 0.0, _plate_height(params)])
    joints = params.platform_points - plane
    bases = np.einsum("nkj,nik->nij", rot, params.base_points[None, :, :] - x[:, None, :3]) - plane  # R^T (b_i - p)
    rise = bases[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        drop = joints[:, 2] - rise
        s = np.where(drop < 0.0, joints[:, 2] / drop, 0.0)
    point = joints + s[..., None] * (bases - joints)
    distance = np.hypot(point[..., 0], point[..., 1])
    return np.where(rise >= 0.0, distance, np.nan)
