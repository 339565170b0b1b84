"""Workspace studies: the reachable set of a family of poses (translational, orientation, a
2-D slice), estimated on a grid or by sampling, chunk by chunk on the execution engine
(:mod:`stewart.studies.execution`), from the reachability test of
:mod:`stewart.model.reachability`, or for a rotary rig (a :class:`~stewart.RotaryParams` or
:class:`~stewart.RotaryPlatform`) that of :mod:`stewart.model.rotary_reachability`."""

from __future__ import annotations

import sys
from dataclasses import dataclass

import numpy as np

from ..model.kinematics import POSE_AXES
from ..model import arguments, kinematics
from ..model.params import platform_params
from ..model.params import PlatformParams
from ..model.platform import as_platform
from ..model import rotary_reachability
from ..model.rotary_params import RotaryParams
from ..model.stiffness import leg_coefficients, modal_metrics
from ..model.reachability import (
    BELOW_BASE,
    CONDITION_LIMIT,
    EULER_SINGULAR,
    FLAG_NAMES,
    FLAGS,
    LEG_COLLISION,
    LEG_THROUGH_PLATE,
    LEG_TOO_LONG,
    LEG_TOO_SHORT,
    OTHER_ASSEMBLY_MODE,
    OUT_OF_RANGE,
    SINGULAR,
    SPHERICAL_JOINT_LIMIT,
    UNIVERSAL_JOINT_LIMIT,
    Reachability,
    WorkspaceError,
    assembly_mode,
    joint_angles,
    margins,
    limits_in_force,
    reachability,
    segment_distances,
)
from . import execution
from .execution import Peak

__all__ = [
    "Workspace", "WorkspaceJob", "translational_workspace", "orientation_workspace", "position_bounds", "Slice",
    "workspace_slice", "KINDS", "CHUNK_SIZE", "study_job", "from_partials",
    # the reachability test the studies are built from (stewart.model.reachability)
    "WorkspaceError", "Reachability", "reachability", "CONDITION_LIMIT", "assembly_mode", "joint_angles", "margins",
    "segment_distances",
]
#: The coordinates a workspace varies, and their unit, by kind.
KINDS = {"translational": (POSE_AXES[:3], "m"), "orientation": (POSE_AXES[3:], "rad")}

#: Poses checked per chunk (one task of :mod:`stewart.studies.execution`).
CHUNK_SIZE = 20_000


def _params(platform):
    """The parameters of ``platform``: a rotary rig's (:class:`~stewart.RotaryParams`, or an
    object whose ``params`` is one) or a linear platform's (:func:`platform_params`)."""
    if isinstance(getattr(platform, "params", None), RotaryParams):
        return platform.params
    return platform if isinstance(platform, RotaryParams) else platform_params(platform, "platform")


def _family(params):
    """``(reachability, FLAGS, FLAG_NAMES, limits_in_force)`` of the family of ``params``."""
    if isinstance(params, RotaryParams):
        r = rotary_reachability
        return r.reachability, r.FLAGS, r.FLAG_NAMES, r.limits_in_force
    return reachability, FLAGS, FLAG_NAMES, limits_in_force


def _model(platform):
    """The compiled model of ``platform``: a :class:`~stewart.RotaryPlatform` for a rotary rig."""
    params = _params(platform)
    if isinstance(params, RotaryParams):
        from ..model.rotary import RotaryPlatform

        return platform if isinstance(platform, RotaryPlatform) else RotaryPlatform(params)
    return as_platform(platform)


def _home(model) -> np.ndarray:
    return model.home if isinstance(model.params, RotaryParams) else model.home_pose


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

    With legs of ``stiffness`` [N/m] (:mod:`stewart.model.stiffness`), ``frequency_min`` [Hz] is
    the lowest natural frequency over the reachable samples, at ``frequency_min_pose``, and
    ``compliance_max`` [m/N] the largest translational compliance at {P}'s origin, at
    ``compliance_max_pose``; ``unheld`` counts the reachable samples the preloaded legs cannot
    hold (left out of both). Without a stiffness they are NaN, None and 0.
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
    stiffness: np.ndarray | None = None
    frequency_min: float = float("nan")
    frequency_min_pose: np.ndarray | None = None
    compliance_max: float = float("nan")
    compliance_max_pose: np.ndarray | None = None
    unheld: int = 0

    @property
    def axes(self) -> tuple[str, str, str]:
        return KINDS[self.kind][0]

    @property
    def unit(self) -> str:
        return KINDS[self.kind][1]

    def summary(self) -> dict:
        """Plain-Python form (for JSON); the modal metrics are None without a stiffness."""
        out = {key: getattr(self, key) for key in self.__dataclass_fields__}
        if self.stiffness is None:  # no modal metrics: None, not NaN (JSON has no NaN)
            out.update(frequency_min=None, compliance_max=None)
        for key in ("fixed", "region", "bounding_box", "margin_min_pose", "stiffness", "frequency_min_pose",
                    "compliance_max_pose"):
            out[key] = None if out[key] is None else np.asarray(out[key]).tolist()
        out.update(axes=list(self.axes), unit=self.unit, clipped=list(self.clipped))
        return out


@dataclass(frozen=True)
class WorkspaceJob(execution.ModelJob):
    """The per-chunk work of a workspace study (an :mod:`stewart.studies.execution` job):
    ``job(chunk)`` builds the chunk's poses (uniform random ones from ``chunk.rng()``, or the
    grid's cells ``chunk.start`` to ``chunk.stop``), checks them with :func:`reachability`
    against the compiled model, built once per process
    (:class:`~stewart.studies.execution.ModelJob`), and returns counts, sums and peaks,
    never the poses; with a leg ``stiffness``, the modal metrics of the reachable poses
    (:func:`stewart.model.stiffness.modal_metrics`) too."""

    params: PlatformParams | RotaryParams
    kind: str
    fixed: np.ndarray
    region: np.ndarray
    resolution: int  # grid points per axis; 0 for random samples
    stiffness: np.ndarray | None = None

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
        check, flags = _family(self.params)[0](self.platform, poses), _family(self.params)[1]
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
            excluded=np.array([np.count_nonzero(check.flags & bit) for bit in flags]),
        )
        if self.stiffness is not None:
            frequency, compliance = np.full(len(poses), np.nan), np.full(len(poses), np.nan)
            rows = np.flatnonzero(check.ok)
            held = np.ones(0, bool)
            if rows.size:
                frequency[rows], compliance[rows], held = modal_metrics(self.platform, poses[rows], self.stiffness)
            part["unheld"] = int(np.count_nonzero(~held))
            # Peaks of -frequency and compliance: the lowest frequency and the largest compliance.
            part["modal"] = Peak.of(np.column_stack([-frequency, compliance]), poses, chunk.start)
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
    arr = arguments.reals(name, value)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected 3 finite numbers, got {np.asarray(value).tolist()}")
    return arr


def _region(name: str, value) -> np.ndarray:
    """A box ``(3, 2)`` of finite, ordered bounds whose volume (and so each width) is a finite
    double; ``ValueError`` naming ``name`` otherwise."""
    arr = arguments.reals(name, value)
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
    the height where a spherical joint meets the highest universal joint; of a rotary rig
    (:class:`~stewart.RotaryParams`), at any orientation, the balls of radius ``crank_length +
    rod_length + |p_i|`` about ``b_i``, above the base plane less the nearest joint's ``|p_i|``."""
    return _position_bounds(_params(params), orientation)


def _position_bounds(params, orientation) -> np.ndarray:
    """:func:`position_bounds` of the converted ``params``; of a rotary rig, whatever the
    orientation, leg ``i`` reaches the ball of radius ``crank_length + rod_length + |p_i|``
    about ``b_i``, above the height where the platform joint nearest {P}'s origin meets the
    highest motor point."""
    orientation = _three("orientation", orientation)
    if isinstance(params, RotaryParams):
        arm = np.linalg.norm(params.platform_points, axis=1)
        reach = (params.crank_length + params.rod_length + arm)[:, None]
        box = np.column_stack([np.max(params.base_points - reach, axis=0),
                               np.min(params.base_points + reach, axis=0)])
        box[2, 0] = max(box[2, 0], np.max(params.base_points[:, 2]) - np.min(arm))
        return box
    if params.leg_length_limits is None:
        raise ValueError("region: the parameters have no leg_length_limits; give the region to sample")
    reach = params.leg_length_limits[1]
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


def study_job(params, kind, fixed, region, samples, grid, stiffness=None) -> tuple[WorkspaceJob, int]:
    """The job of a workspace study and its number of poses: with :func:`from_partials`, the
    seam through which :mod:`stewart.studies.sweep` runs the workspaces of many designs."""
    if (samples is None) == (grid is None):
        raise ValueError("samples, grid: give exactly one (random samples, or grid points per axis)")
    resolution = 0 if grid is None else arguments.count("grid", grid, 1000)
    total = resolution ** 3 if grid is not None else arguments.count("samples", samples, 10 ** 12)
    stiffness = _stiffness(params, stiffness)
    return WorkspaceJob(params, kind, fixed, region, resolution, stiffness), total


def _stiffness(params, stiffness):
    """The legs' stiffness of a study: ``stiffness`` checked, or the parameters' (a linear
    platform's ``leg_stiffness``); a rotary rig has no leg springs."""
    if isinstance(params, RotaryParams):
        if stiffness is not None:
            raise ValueError("stiffness: the modal metrics are the linear machines' (legs as springs); a rotary "
                             "rig has none")
        return None
    return params.leg_stiffness if stiffness is None else leg_coefficients("stiffness", stiffness, positive=True)


def _study(params, kind, fixed, region, complete, samples, grid, seed, chunk_size, client, progress,
           stiffness) -> Workspace:
    job, total = study_job(params, kind, fixed, region, samples, grid, stiffness)
    progress = sys.stderr.isatty() if progress is None else bool(progress)
    parts = execution.run(job, total, seed=None if grid is not None else seed, chunk_size=chunk_size,
                          client=client, progress=progress, desc=f"{kind} workspace")
    return from_partials(job, parts, total, complete, seed)


def from_partials(job: WorkspaceJob, parts: dict, total: int, complete: bool, seed) -> Workspace:
    """The :class:`Workspace` of the combined partials ``parts`` of ``job`` over ``total`` poses."""
    params, kind, fixed, region, resolution = job.params, job.kind, job.fixed, job.region, job.resolution
    grid = resolution or None
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
    modal = {}
    if job.stiffness is not None:
        peak, found = parts["modal"], parts["modal"].index >= 0
        modal = dict(stiffness=job.stiffness, unheld=parts["unheld"],
                     frequency_min=float(-peak.value[0]) if found[0] else nan,
                     frequency_min_pose=peak.state[0] if found[0] else None,
                     compliance_max=float(peak.value[1]) if found[1] else nan,
                     compliance_max_pose=peak.state[1] if found[1] else None)
    return Workspace(
        kind=kind, fixed=fixed, region=region, method="random" if grid is None else "grid", samples=total,
        reachable=count, volume=volume, volume_error=float(error), bounding_box=bbox, clipped=clipped,
        margin_min=float(-margin[0]) if count else nan, margin_mean=parts["margin_sum"] / count if count else nan,
        margin_max=float(margin[1]) if count else nan,
        margin_min_pose=parts["margin"].state[0] if count else None,
        excluded={_family(params)[2][bit]: int(n) for bit, n in zip(_family(params)[1], parts["excluded"]) if n},
        seed=None if grid is not None else int(seed), platform=params.name or "unnamed", **modal,
    )


def translational_workspace(platform, orientation=(0.0, 0.0, 0.0), *, region=None, samples=None, grid=None,
                            seed=0, chunk_size=CHUNK_SIZE, client=None, progress=None, stiffness=None) -> Workspace:
    """The constant-orientation workspace: the positions ``(x, y, z)`` [m] reachable at
    the ZYX Euler angles ``orientation`` [rad], by :func:`reachability`.

    ``region`` is the box ``[[x_lo, x_hi], [y_lo, y_hi], [z_lo, z_hi]]`` sampled (default
    :func:`position_bounds`, which holds the whole workspace). Give ``samples`` (uniform
    random poses drawn from ``seed``) or ``grid`` (points per axis, cell centres). The
    poses are checked in chunks of ``chunk_size`` by :func:`stewart.studies.execution.run`: on the
    local cores, or with ``client`` (a ``dask.distributed.Client``) on its cluster, with the
    same result. ``progress`` shows a bar with an ETA (default: when stderr is a terminal).
    With ``stiffness`` [N/m] (legs as preloaded springs, one value or one per leg; default the
    parameters' ``leg_stiffness``, if any) the lowest natural frequency and the largest
    compliance over the workspace are found too.
    Returns a :class:`Workspace`.
    """
    params = _params(platform)
    orientation = _three("orientation", orientation)
    complete = region is None
    region = _position_bounds(params, orientation) if complete else _region("region", region)
    return _study(params, "translational", orientation, region, complete, samples, grid, seed, chunk_size, client,
                  progress, stiffness)


def orientation_workspace(platform, position=None, *, region=None, samples=None, grid=None, seed=0,
                          chunk_size=CHUNK_SIZE, client=None, progress=None, stiffness=None) -> Workspace:
    """The orientation workspace: the ZYX Euler angles ``(psi, theta, phi)`` [rad]
    reachable at ``position`` [m] (default: the home pose's), by :func:`reachability`.

    ``region`` is the box of angles sampled (default :data:`ORIENTATION_REGION`, every
    orientation); the other arguments are those of :func:`translational_workspace`.
    The volume is measured in Euler-angle coordinates [rad^3].
    """
    params = _params(platform)
    position = (_home(_model(params)) if isinstance(params, RotaryParams) else kinematics.home_pose(params))[:3] \
        if position is None else _three("position", position)
    complete = region is None
    region = ORIENTATION_REGION if complete else _region("region", region)
    return _study(params, "orientation", position, region, complete, samples, grid, seed, chunk_size, client,
                  progress, stiffness)


@dataclass(frozen=True)
class Slice:
    """The singularity margin on a plane of poses: ``axes`` the two coordinates varied
    (``u`` along columns, ``v`` along rows, in ``unit``), ``at`` the third coordinate's name
    and value, ``fixed`` the orientation (translational slices) or position held;
    ``margin`` ``(len(v), len(u))`` is NaN where the pose is unreachable and ``flags`` the
    problem bits of :func:`reachability` there. With legs of ``stiffness`` [N/m], ``frequency``
    ``(len(v), len(u))`` is the lowest natural frequency [Hz] (NaN where the pose is unreachable
    or the preloaded legs cannot hold it); None without. ``limits`` names the limits in force
    (:func:`~stewart.model.reachability.limits_in_force`), which its figures print; ``jacobian``
    the matrix whose conditioning the margin measures (``J_C``, or a rotary rig's ``J_alpha``)."""

    axes: tuple[str, str]
    unit: str
    u: np.ndarray
    v: np.ndarray
    at: tuple[str, float]
    fixed: np.ndarray
    margin: np.ndarray
    flags: np.ndarray
    platform: str
    stiffness: np.ndarray | None = None
    frequency: np.ndarray | None = None
    limits: str = ""
    jacobian: str = "J_C"


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
                    resolution=101, stiffness=None) -> Slice:
    """The singularity margin over a plane of poses (:class:`Slice`).

    ``axes`` names two coordinates of one workspace (``"xy"``, ``("x", "z")``,
    ``("psi", "theta")`` ...); the third is held at ``at`` (default: the home pose's value).
    Translational slices hold ``orientation`` [rad], orientation slices ``position`` [m]
    (default: home). ``region`` ``(2, 2)`` bounds the two axes (default: those of
    :func:`position_bounds` or :data:`ORIENTATION_REGION`); ``resolution`` is the number
    of cell centres per axis. ``stiffness`` [N/m] (one value or one per leg; default the
    parameters' ``leg_stiffness``, if any) adds the lowest natural frequency on the preloaded
    leg springs.
    """
    plat = _model(platform)
    params = plat.params
    check_poses, _, _, limits = _family(params)
    kind, (first, second, third) = _axes(axes)
    home = _home(plat)
    if kind == "translational":
        fixed = _three("orientation", orientation)
        full = _position_bounds(params, fixed) if region is None else None
        base = home[:3]
    else:
        fixed = home[:3] if position is None else _three("position", position)
        full = ORIENTATION_REGION if region is None else None
        base = np.zeros(3)
    if region is None:
        region = full[[first, second]]
    else:
        region = arguments.reals("region", region)
        if region.shape != (2, 2):
            raise ValueError(f"region: expected 2 (low, high) pairs for the axes {axes!r}, got shape {region.shape}")
        region = _region("region", np.vstack([region, [0.0, 1.0]]))[:2]
    at = float(base[third]) if at is None else arguments.real("at", at)
    n = arguments.count("resolution", resolution, 2000)
    u, v = ((lo + (hi - lo) * ((np.arange(n) + 0.5) / n)) for lo, hi in region)
    coords = np.empty((n * n, 3))
    vv, uu = np.meshgrid(v, u, indexing="ij")
    coords[:, first], coords[:, second], coords[:, third] = uu.ravel(), vv.ravel(), at
    fixed_rows = np.broadcast_to(fixed, (n * n, 3))
    poses = np.hstack([coords, fixed_rows] if kind == "translational" else [fixed_rows, coords])
    stiffness = _stiffness(params, stiffness)
    check = check_poses(plat, poses)
    margin = np.where(check.ok, check.margin, np.nan).reshape(n, n)
    frequency = None
    if stiffness is not None:
        frequency = np.full(n * n, np.nan)
        rows = np.flatnonzero(check.ok)
        if rows.size:
            frequency[rows] = modal_metrics(plat, poses[rows], stiffness)[0]
        frequency = frequency.reshape(n, n)
    names, unit = KINDS[kind]
    return Slice(axes=(names[first], names[second]), unit=unit, u=u, v=v, at=(names[third], at), fixed=fixed,
                 margin=margin, flags=check.flags.reshape(n, n), platform=params.name or "unnamed",
                 stiffness=stiffness, frequency=frequency, limits=limits(params),
                 jacobian="J_alpha" if isinstance(params, RotaryParams) else "J_C")
