"""Which poses the platform can reach: the one test used before a simulation and by the
command line's ``ik``, ``id`` and ``fd``, and the workspaces built from it.

A pose is reachable when

* every leg length is finite (a pose like ``z = 1e308`` overflows) and lies within
  ``params.leg_length_limits`` (when the set has limits);
* every spherical joint lies above the highest universal joint (the platform is above the base);
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

import sys

from . import _checks, execution, kinematics
from .execution import Peak
from .params import PlatformParams

__all__ = [
    "WorkspaceError", "Reachability", "reachability", "CONDITION_LIMIT", "joint_angles", "segment_distances",
    "Workspace", "WorkspaceJob", "translational_workspace", "orientation_workspace", "position_bounds", "Slice",
    "workspace_slice",
]

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
    ``leg_diameter``); ``params`` the parameter set checked.
    """

    flags: np.ndarray
    lengths: np.ndarray
    condition: np.ndarray
    limits: tuple[float, float] | None
    universal_angles: np.ndarray | None = None
    spherical_angles: np.ndarray | None = None
    clearance: np.ndarray | None = None
    closest_legs: np.ndarray | None = None
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
            return "the platform is not above the base"
        if bit == SINGULAR:
            return f"J_C is singular or nearly so (condition number {self.condition[row]:.3g} > {CONDITION_LIMIT:g})"
        if bit == EULER_SINGULAR:
            return "theta = +-90 deg, where the Euler angles are singular"
        return "det J_C has the other sign: the pose is in another assembly mode, beyond a singularity"

    def reasons(self, row: int) -> list[str]:
        """Human sentences for the problems of one row."""
        return [self._reason(bit, row) for bit in _BITS if self.flags[row] & bit]

    def message(self, what: str = "pose", times=None) -> str:
        """One line: how many rows are outside, and for each kind of problem the first row
        (or time) where it occurs and how many rows share it."""
        bad = np.flatnonzero(~self.ok)
        if bad.size == 0:
            return f"every {what} is reachable"
        parts = []
        for bit in _BITS:
            rows = np.flatnonzero(self.flags & bit)
            if rows.size:
                where = f"t = {float(times[rows[0]]):.4g} s" if times is not None else f"row {rows[0]}"
                more = f" and {rows.size - 1} more" if rows.size > 1 else ""
                parts.append(f"{self._reason(bit, rows[0])} at {where}{more}")
        return f"{bad.size} of {len(self.flags)} {what}(s) outside the workspace: " + "; ".join(parts)


_BITS = (OUT_OF_RANGE, LEG_TOO_SHORT, LEG_TOO_LONG, BELOW_BASE, SINGULAR, EULER_SINGULAR, OTHER_ASSEMBLY_MODE,
         UNIVERSAL_JOINT_LIMIT, SPHERICAL_JOINT_LIMIT, LEG_COLLISION)


def _platform_radius(params: PlatformParams) -> float:
    points = params.platform_points
    return float(np.max(np.sqrt(np.sum((points - points.mean(axis=0)) ** 2, axis=1))))


def assembly_mode(platform, pose) -> float:
    """The sign of ``det J_C`` at ``pose``: +1 or -1 (0 at a singularity)."""
    with np.errstate(all="ignore"):
        return float(np.nan_to_num(np.sign(np.linalg.det(kinematics.jacobian(_params(platform), pose)))))


def _params(platform) -> PlatformParams:
    params = getattr(platform, "params", platform)
    if not isinstance(params, PlatformParams):
        raise ValueError(f"platform: expected a stewart.Platform or PlatformParams, got {type(platform).__name__}")
    return params


def reachability(platform, poses, *, mode: float | None = None, name: str = "poses") -> Reachability:
    """Check ``poses`` (``(6,)`` or ``(N, 6)``) against the workspace of ``platform`` (a
    :class:`~stewart.Platform` or :class:`~stewart.PlatformParams`).

    ``mode`` is the sign of ``det J_C`` of the assembly mode the poses must lie in
    (default: the home pose's, see :func:`assembly_mode`). Returns a :class:`Reachability`
    with one row per pose.
    """
    from .platform import Platform

    plat = platform if isinstance(platform, Platform) else Platform(_params(platform))
    x = np.atleast_2d(_checks.states(name, poses))
    if np.iscomplexobj(x):
        raise ValueError(f"{name}: expected real poses")
    if mode is None:
        mode = assembly_mode(plat, plat.home_pose)
    neutral = _neutral_axes(plat)
    # (no pose: one empty block)
    blocks = [_block(plat, x[i:i + _BLOCK], mode, neutral) for i in range(0, max(len(x), 1), _BLOCK)]
    parts = {key: np.concatenate([b[key] for b in blocks]) if blocks[0][key] is not None else None
             for key in blocks[0]}
    return Reachability(**parts, limits=plat.params.leg_length_limits, params=plat.params)


_BLOCK = 50_000  # poses checked at a time (bounds the memory of long trajectories)


def _neutral_axes(plat) -> np.ndarray:
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
    from .platform import Platform

    plat = Platform(_params(params))
    x = _checks.states("poses", poses)
    units = kinematics.leg_unit_vectors(plat.params, x)
    return _joint_angles(units, kinematics.rotation(x), _neutral_axes(plat))


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


def margins(platform, poses) -> np.ndarray:
    """The singularity margin (:attr:`Reachability.margin`) alone of ``poses`` ``(N, 6)``,
    without the other checks of :func:`reachability`: the same values, for callers that
    need only the margin (the excitation's finite differences)."""
    from .platform import Platform

    plat = platform if isinstance(platform, Platform) else Platform(_params(platform))
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
    # Height of each spherical joint, p_z + (R p_i)_z, with the last row of R (eq. 3).
    sth, cth = np.sin(x[:, 4:5]), np.cos(x[:, 4:5])
    sph, cph = np.sin(x[:, 5:6]), np.cos(x[:, 5:6])
    p = params.platform_points
    joint_heights = x[:, 2:3] - sth * p[:, 0] + cth * sph * p[:, 1] + cth * cph * p[:, 2]
    flags |= np.where(np.min(joint_heights, axis=1) <= np.max(params.base_points[:, 2]), BELOW_BASE, 0)
    with np.errstate(all="ignore"):
        jac = plat.jacobian(x, return_mask=True)[0]
        units = jac[..., :3].copy()
        universal, spherical = _joint_angles(units, kinematics.rotation(x), neutral)
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
    clearance = closest = None
    if params.leg_diameter is not None:
        ends = params.base_points + lengths[..., None] * units  # P_i = B_i + L_i u_i
        i, j = LEG_PAIRS.T
        with np.errstate(all="ignore"):
            pairs = segment_distances(params.base_points[i], ends[:, i], params.base_points[j], ends[:, j])
        closest = np.argmin(np.nan_to_num(pairs, nan=-1.0), axis=1)
        clearance = pairs[np.arange(len(x)), closest]
        flags |= np.where(~(clearance >= params.leg_diameter), LEG_COLLISION, 0)
    return dict(flags=flags, lengths=lengths, condition=condition, universal_angles=universal,
                spherical_angles=spherical, clearance=clearance, closest_legs=closest)


# ---------------------------------------------------------------------------- workspaces

#: The coordinates a workspace varies, and their unit, by kind.
KINDS = {"translational": (("x", "y", "z"), "m"), "orientation": (("psi", "theta", "phi"), "rad")}

#: Poses checked per chunk (one task of :mod:`stewart.execution`).
CHUNK_SIZE = 20_000

_NAMES = {OUT_OF_RANGE: "out_of_range", LEG_TOO_SHORT: "leg_too_short", LEG_TOO_LONG: "leg_too_long",
          BELOW_BASE: "below_base", SINGULAR: "singular", EULER_SINGULAR: "euler_singular",
          OTHER_ASSEMBLY_MODE: "other_assembly_mode", UNIVERSAL_JOINT_LIMIT: "universal_joint_limit",
          SPHERICAL_JOINT_LIMIT: "spherical_joint_limit", LEG_COLLISION: "leg_collision"}


@dataclass(frozen=True)
class Workspace:
    """The reachable set of a 3-parameter family of poses, estimated on a grid or by sampling.

    ``kind`` is ``"translational"`` (positions ``x, y, z`` at the constant orientation
    ``fixed``) or ``"orientation"`` (ZYX Euler angles ``psi, theta, phi`` at the position
    ``fixed``); ``region`` the box ``(3, 2)`` sampled, in ``unit`` (m or rad).

    ``volume`` is the reachable volume [m^3, or rad^3 of Euler-angle space]:

    * by sampling (``method="random"``), the box volume times the reachable fraction of
      ``samples`` uniform poses; ``volume_error`` is the standard error of that Monte-Carlo
      estimate, ``V_box sqrt(p (1 - p) / N)``, which shrinks like ``1 / sqrt(N)``;
    * on a grid (``method="grid"``), the volume of the cells whose centre is reachable;
      ``volume_error`` is half the volume of the boundary cells (reachable cells with an
      unreachable face neighbour and vice versa): the discretization error when the
      boundary cuts each of them about in half, a deterministic estimate, not a statistical one.

    ``bounding_box`` ``(3, 2)`` spans the reachable samples (None if none is);
    ``clipped`` names the axes on which reachable samples come within a sample spacing of
    the faces of a region given by the caller (then the workspace may extend beyond it:
    widen the region); the default regions hold the whole workspace. ``margin_min``,
    ``margin_mean`` and ``margin_max`` are statistics of the singularity margin
    (:attr:`Reachability.margin`) over the reachable samples; ``margin_mean`` is the
    global conditioning index of Gosselin & Angeles (1991); ``margin_min_pose`` is the
    reachable pose closest to a singularity. ``excluded`` counts the
    samples each problem excludes (a sample may have several).
    """

    kind: str
    fixed: np.ndarray
    region: np.ndarray
    method: str
    samples: int
    reachable: int
    volume: float
    volume_error: float
    bounding_box: np.ndarray | None
    clipped: tuple[str, ...]
    margin_min: float
    margin_mean: float
    margin_max: float
    margin_min_pose: np.ndarray | None
    excluded: dict
    seed: int | None
    platform: str

    @property
    def axes(self) -> tuple[str, str, str]:
        return KINDS[self.kind][0]

    @property
    def unit(self) -> str:
        return KINDS[self.kind][1]

    def summary(self) -> dict:
        """Plain-Python form (for JSON)."""
        out = {key: getattr(self, key) for key in self.__dataclass_fields__}
        for key in ("fixed", "region", "bounding_box", "margin_min_pose"):
            out[key] = None if out[key] is None else np.asarray(out[key]).tolist()
        out.update(axes=list(self.axes), unit=self.unit, clipped=list(self.clipped))
        return out


@dataclass(frozen=True)
class WorkspaceJob:
    """The per-chunk work of a workspace study (an :mod:`stewart.execution` job):
    ``job(chunk)`` builds the chunk's poses (uniform random ones from ``chunk.rng()``, or the
    grid's cells ``chunk.start`` to ``chunk.stop``), checks them with :func:`reachability`
    and returns counts, sums and peaks, never the poses."""

    params: PlatformParams
    kind: str
    fixed: np.ndarray
    region: np.ndarray
    resolution: int  # grid points per axis; 0 for random samples

    def poses(self, chunk) -> np.ndarray:
        lo, hi = self.region[:, 0], self.region[:, 1]
        if self.resolution:
            cells = np.unravel_index(np.arange(chunk.start, chunk.stop), (self.resolution,) * 3)
            coords = lo + (hi - lo) * ((np.column_stack(cells) + 0.5) / self.resolution)  # within the region
        else:
            coords = lo + (hi - lo) * chunk.rng().random((chunk.size, 3))
        fixed = np.broadcast_to(self.fixed, (chunk.size, 3))
        return np.hstack([coords, fixed] if self.kind == "translational" else [fixed, coords])

    def __call__(self, chunk) -> dict:
        poses = self.poses(chunk)
        check = reachability(self.params, poses)
        ok = check.ok[:, None]
        coords = poses[:, :3] if self.kind == "translational" else poses[:, 3:]
        margin = np.where(ok, check.margin[:, None], np.nan)
        coords = np.where(ok, coords, np.nan)
        part = dict(
            count=int(ok.sum()),
            margin_sum=float(np.nansum(margin)),
            # Peaks of -margin, margin, -coords and coords over the reachable poses (NaN
            # elsewhere): the extremes with the poses where they occur.
            margin=Peak.of(np.hstack([-margin, margin]), poses, chunk.start),
            extent=Peak.of(np.hstack([-coords, coords]), poses, chunk.start),
            excluded=np.array([np.count_nonzero(check.flags & bit) for bit in _BITS]),
        )
        if self.resolution:
            # The reachable cells as bits of the whole grid: the chunks' bits are disjoint,
            # so adding the partials (as execution.combine does) sets each cell once.
            cells = np.zeros(self.resolution ** 3, dtype=bool)
            cells[chunk.start:chunk.stop] = ok[:, 0]
            part["cells"] = np.packbits(cells)
        return part


def _grid_error(cells: np.ndarray, resolution: int, cell_volume: float) -> float:
    """Half the volume of the grid cells with a face neighbour of the other status."""
    grid = cells.reshape((resolution,) * 3)
    boundary = np.zeros_like(grid)
    for axis in range(3):
        differs = np.diff(grid, axis=axis)
        before = [slice(None)] * 3
        after = [slice(None)] * 3
        before[axis], after[axis] = slice(None, -1), slice(1, None)
        boundary[tuple(before)] |= differs
        boundary[tuple(after)] |= differs
    return 0.5 * cell_volume * int(boundary.sum())


def _three(name: str, value) -> np.ndarray:
    arr = _checks.reals(name, value)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected 3 finite numbers, got {np.asarray(value).tolist()}")
    return arr


def _region(name: str, value) -> np.ndarray:
    """A box ``(3, 2)`` of finite, ordered bounds whose volume (and so each width) is a finite
    double; ``ValueError`` naming ``name`` otherwise."""
    arr = _checks.reals(name, value)
    if arr.shape != (3, 2) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected 3 finite (low, high) pairs, got {np.asarray(value).tolist()}")
    empty = np.flatnonzero(~(arr[:, 1] > arr[:, 0]))
    if empty.size:
        raise ValueError(f"{name}: empty or inverted bounds on axis {int(empty[0])} (low {arr[empty[0], 0]:g} "
                         f">= high {arr[empty[0], 1]:g})")
    with np.errstate(over="ignore"):
        volume = np.prod(arr[:, 1] - arr[:, 0])
    if not np.isfinite(volume):
        raise ValueError(f"{name}: the box's volume overflows double precision, got {arr.tolist()}")
    return arr


def position_bounds(params: PlatformParams, orientation=(0.0, 0.0, 0.0)) -> np.ndarray:
    """A box ``(3, 2)`` [m] that holds every position reachable at ``orientation`` within
    the stroke limits: leg ``i`` reaches only the ball of radius ``L_max`` about
    ``b_i - R p_i``, so the positions lie in the intersection of the balls' boxes, above
    the height where a spherical joint meets the highest universal joint."""
    params = _params(params)
    if params.leg_length_limits is None:
        raise ValueError("region: the parameters have no leg_length_limits; give the region to sample")
    reach = params.leg_length_limits[1]
    orientation = _three("orientation", orientation)
    arms = kinematics.platform_points_in_base(params, np.r_[0.0, 0.0, 0.0, orientation])
    centres = params.base_points - arms
    box = np.column_stack([np.max(centres - reach, axis=0), np.min(centres + reach, axis=0)])
    box[2, 0] = max(box[2, 0], np.max(params.base_points[:, 2]) - np.min(arms[:, 2]))
    if not np.all(box[:, 1] > box[:, 0]):
        raise ValueError(f"orientation: no position is within the stroke limits at {orientation.tolist()}")
    return box


#: The default orientation region [rad], which holds every orientation once:
#: ``psi, phi`` in [-pi, pi], ``theta`` in [-pi/2, pi/2].
ORIENTATION_REGION = np.array([[-np.pi, np.pi], [-np.pi / 2, np.pi / 2], [-np.pi, np.pi]])


def _study(params, kind, fixed, region, complete, samples, grid, seed, chunk_size, client, progress) -> Workspace:
    if (samples is None) == (grid is None):
        raise ValueError("samples, grid: give exactly one (random samples, or grid points per axis)")
    resolution = 0 if grid is None else _checks.count("grid", grid, 1000)
    total = resolution ** 3 if grid is not None else _checks.count("samples", samples, 10 ** 12)
    job = WorkspaceJob(params, kind, fixed, region, resolution)
    progress = sys.stderr.isatty() if progress is None else bool(progress)
    parts = execution.run(job, total, seed=None if grid is not None else seed, chunk_size=chunk_size,
                          client=client, progress=progress, desc=f"{kind} workspace")
    box_volume = float(np.prod(region[:, 1] - region[:, 0]))
    count = parts["count"]
    if grid is None:
        fraction = count / total
        volume, error = box_volume * fraction, box_volume * np.sqrt(fraction * (1 - fraction) / total)
    else:
        cell = box_volume / total
        cells = np.unpackbits(parts["cells"], count=total).astype(bool)
        volume, error = cell * count, _grid_error(cells, resolution, cell)
    extent, margin = parts["extent"].value, parts["margin"].value
    bbox = np.column_stack([-extent[:3], extent[3:]]) if count else None
    clipped = ()
    if count and not complete:
        # A sample within a cell's width (or the mean spacing of random samples) of a face.
        step = (region[:, 1] - region[:, 0]) / (resolution or np.cbrt(total))
        touches = (bbox[:, 0] <= region[:, 0] + step) | (bbox[:, 1] >= region[:, 1] - step)
        clipped = tuple(name for name, hit in zip(KINDS[kind][0], touches) if hit)
    nan = float("nan")
    return Workspace(
        kind=kind, fixed=fixed, region=region, method="random" if grid is None else "grid", samples=total,
        reachable=count, volume=volume, volume_error=float(error), bounding_box=bbox, clipped=clipped,
        margin_min=float(-margin[0]) if count else nan, margin_mean=parts["margin_sum"] / count if count else nan,
        margin_max=float(margin[1]) if count else nan,
        margin_min_pose=parts["margin"].state[0] if count else None,
        excluded={_NAMES[bit]: int(n) for bit, n in zip(_BITS, parts["excluded"]) if n},
        seed=None if grid is not None else int(seed), platform=params.name or "unnamed",
    )


def translational_workspace(platform, orientation=(0.0, 0.0, 0.0), *, region=None, samples=None, grid=None,
                            seed=0, chunk_size=CHUNK_SIZE, client=None, progress=None) -> Workspace:
    """The constant-orientation workspace: the positions ``(x, y, z)`` [m] reachable at
    the ZYX Euler angles ``orientation`` [rad], by :func:`reachability`.

    ``region`` is the box ``[[x_lo, x_hi], [y_lo, y_hi], [z_lo, z_hi]]`` sampled (default
    :func:`position_bounds`, which holds the whole workspace). Give ``samples`` (uniform
    random poses drawn from ``seed``) or ``grid`` (points per axis, cell centres). The
    poses are checked in chunks of ``chunk_size`` by :func:`stewart.execution.run`: on the
    local cores, or with ``client`` (a ``dask.distributed.Client``) on its cluster, with the
    same result. ``progress`` shows a bar with an ETA (default: when stderr is a terminal).
    Returns a :class:`Workspace`.
    """
    params = _params(platform)
    orientation = _three("orientation", orientation)
    complete = region is None
    region = position_bounds(params, orientation) if complete else _region("region", region)
    return _study(params, "translational", orientation, region, complete, samples, grid, seed, chunk_size, client, progress)


def orientation_workspace(platform, position=None, *, region=None, samples=None, grid=None, seed=0,
                          chunk_size=CHUNK_SIZE, client=None, progress=None) -> Workspace:
    """The orientation workspace: the ZYX Euler angles ``(psi, theta, phi)`` [rad]
    reachable at ``position`` [m] (default: the home pose's), by :func:`reachability`.

    ``region`` is the box of angles sampled (default :data:`ORIENTATION_REGION`, every
    orientation); the other arguments are those of :func:`translational_workspace`.
    The volume is measured in Euler-angle coordinates [rad^3].
    """
    params = _params(platform)
    position = kinematics.home_pose(params)[:3] if position is None else _three("position", position)
    complete = region is None
    region = ORIENTATION_REGION if complete else _region("region", region)
    return _study(params, "orientation", position, region, complete, samples, grid, seed, chunk_size, client, progress)


@dataclass(frozen=True)
class Slice:
    """The singularity margin on a plane of poses: ``axes`` the two coordinates varied
    (``u`` along columns, ``v`` along rows, in ``unit``), ``at`` the third coordinate's name
    and value, ``fixed`` the orientation (translational slices) or position held;
    ``margin`` ``(len(v), len(u))`` is NaN where the pose is unreachable and ``flags`` the
    problem bits of :func:`reachability` there."""

    axes: tuple[str, str]
    unit: str
    u: np.ndarray
    v: np.ndarray
    at: tuple[str, float]
    fixed: np.ndarray
    margin: np.ndarray
    flags: np.ndarray
    platform: str


def _axes(value) -> tuple[str, tuple[int, int, int]]:
    """The kind of a pair of axis names and the indices of the pair and the third axis."""
    if isinstance(value, str):  # "xy", "x,z" or "psi,theta"
        value = value.replace(",", " ").split() if ("," in value or " " in value) else list(value)
    names = tuple(value) if isinstance(value, (list, tuple)) else ()
    for kind, (all_names, _) in KINDS.items():
        if len(names) == 2 and names[0] != names[1] and set(names) <= set(all_names):
            first, second = all_names.index(names[0]), all_names.index(names[1])
            return kind, (first, second, 3 - first - second)
    raise ValueError(f"axes: expected two of x, y, z or two of psi, theta, phi, got {value!r}")


def workspace_slice(platform, axes="xy", at=None, *, orientation=(0.0, 0.0, 0.0), position=None, region=None,
                    resolution=101) -> Slice:
    """The singularity margin over a plane of poses (:class:`Slice`).

    ``axes`` names two coordinates of one workspace (``"xy"``, ``("x", "z")``,
    ``("psi", "theta")`` ...); the third is held at ``at`` (default: the home pose's value).
    Translational slices hold ``orientation`` [rad], orientation slices ``position`` [m]
    (default: home). ``region`` ``(2, 2)`` bounds the two axes (default: those of
    :func:`position_bounds` or :data:`ORIENTATION_REGION`); ``resolution`` is the number
    of cell centres per axis.
    """
    params = _params(platform)
    kind, (first, second, third) = _axes(axes)
    home = kinematics.home_pose(params)
    if kind == "translational":
        fixed = _three("orientation", orientation)
        full = position_bounds(params, fixed) if region is None else None
        base = home[:3]
    else:
        fixed = home[:3] if position is None else _three("position", position)
        full = ORIENTATION_REGION if region is None else None
        base = np.zeros(3)
    if region is None:
        region = full[[first, second]]
    else:
        region = _checks.reals("region", region)
        if region.shape != (2, 2):
            raise ValueError(f"region: expected 2 (low, high) pairs for the axes {axes!r}, got shape {region.shape}")
        region = _region("region", np.vstack([region, [0.0, 1.0]]))[:2]
    at = float(base[third]) if at is None else _checks.real("at", at)
    n = _checks.count("resolution", resolution, 2000)
    u, v = ((lo + (hi - lo) * ((np.arange(n) + 0.5) / n)) for lo, hi in region)
    coords = np.empty((n * n, 3))
    vv, uu = np.meshgrid(v, u, indexing="ij")
    coords[:, first], coords[:, second], coords[:, third] = uu.ravel(), vv.ravel(), at
    fixed_rows = np.broadcast_to(fixed, (n * n, 3))
    poses = np.hstack([coords, fixed_rows] if kind == "translational" else [fixed_rows, coords])
    check = reachability(params, poses)
    margin = np.where(check.ok, check.margin, np.nan).reshape(n, n)
    names, unit = KINDS[kind]
    return Slice(axes=(names[first], names[second]), unit=unit, u=u, v=v, at=(names[third], at), fixed=fixed,
                 margin=margin, flags=check.flags.reshape(n, n), platform=params.name or "unnamed")
