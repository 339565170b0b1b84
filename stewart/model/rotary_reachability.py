"""Which poses a rotary rig (6-RSS, issue 40) can reach: the test the workspace studies
(:mod:`stewart.studies.workspace`) and the arms study (:mod:`stewart.studies.rotary_arms`) apply
to a :class:`~stewart.RotaryPlatform`, as :mod:`stewart.model.reachability` is for the linear
machines. Every per-pose quantity comes from the generated C
(:meth:`~stewart.RotaryPlatform.joint_cosines`, :meth:`~stewart.RotaryPlatform.jacobian`).

A pose is reachable when

* every crank reaches it in its assembly mode (``crank_branch``): the loop of each leg has a
  root there (else ``out_of_reach``);
* every crank angle lies within ``params.crank_angle_limits`` (when set);
* every rod-crank angle, at the crank tip between the crank and the rod, lies within
  ``params.rod_crank_angle_limits`` (when set): a rod folding back over its crank (angle 0) or
  stretched straight out of it (pi) is a singular, unusable pose;
* every ball joint lies within its cone, ``params.crank_joint_max_angle`` at the crank tips and
  ``params.platform_joint_max_angle`` on the platform (when set): the angle between the rod and
  the joint's neutral axis, the rod's direction at the home pose, fixed in the crank and in {P};
* every rod's tilt out of its crank's plane of motion lies within ``params.crank_pin_max_tilt``
  (when set): the misalignment of a rod end on a pin parallel to the motor axis;
* the platform is above the base: its lowest joint lies above the base plane (the horizontal
  plane through the highest motor point ``b_i``) by more than nothing or by
  ``params.base_clearance`` (when set), as for the linear machines;
* ``J_alpha`` is well conditioned: its unit-free condition number at most
  :data:`~stewart.model.reachability.CONDITION_LIMIT`
  (:func:`~stewart.model.reachability.jacobian_margins`), and ``det J_alpha`` has the sign of the
  home pose's (a pose of the other sign lies beyond a singularity, in another assembly mode of
  the platform);
* the ZYX Euler angles are regular (``|cos theta| >= 1 / CONDITION_LIMIT``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import arguments
from .reachability import (
    BELOW_BASE,
    CONDITION_LIMIT,
    EULER_SINGULAR,
    OTHER_ASSEMBLY_MODE,
    OUT_OF_RANGE,
    SINGULAR,
    jacobian_margins,
    outside_message,
)
from .rotary_params import RotaryParams

__all__ = ["RotaryReachability", "reachability", "limits_in_force", "axis_range", "base_plane", "FLAGS", "FLAG_NAMES",
           "OUT_OF_REACH", "CRANK_ANGLE_LIMIT", "ROD_CRANK_ANGLE_LIMIT", "CRANK_JOINT_LIMIT", "PLATFORM_JOINT_LIMIT",
           "CRANK_PIN_LIMIT"]

OUT_OF_REACH = 2048
CRANK_ANGLE_LIMIT = 4096
ROD_CRANK_ANGLE_LIMIT = 8192
CRANK_JOINT_LIMIT = 16384
PLATFORM_JOINT_LIMIT = 32768
CRANK_PIN_LIMIT = 131072  # (65536 is stewart.cueing.rotary.CRANK_REACH)

#: The flags of :attr:`RotaryReachability.flags`, in the order their counts are reported.
FLAGS = (OUT_OF_RANGE, OUT_OF_REACH, CRANK_ANGLE_LIMIT, ROD_CRANK_ANGLE_LIMIT, CRANK_JOINT_LIMIT,
         PLATFORM_JOINT_LIMIT, CRANK_PIN_LIMIT, BELOW_BASE, SINGULAR, EULER_SINGULAR, OTHER_ASSEMBLY_MODE)
#: The name of each flag in reports (a workspace study's exclusions).
FLAG_NAMES = {OUT_OF_RANGE: "out_of_range", OUT_OF_REACH: "out_of_reach", CRANK_ANGLE_LIMIT: "crank_angle_limit",
              ROD_CRANK_ANGLE_LIMIT: "rod_crank_angle_limit", CRANK_JOINT_LIMIT: "crank_joint_limit",
              PLATFORM_JOINT_LIMIT: "platform_joint_limit", CRANK_PIN_LIMIT: "crank_pin_limit",
              BELOW_BASE: "below_base", SINGULAR: "singular",
              EULER_SINGULAR: "euler_singular", OTHER_ASSEMBLY_MODE: "other_assembly_mode"}


def _degrees(limits) -> str:
    return f"{np.degrees(limits[0]):.4g} to {np.degrees(limits[1]):.4g} deg"


def limits_in_force(params: RotaryParams) -> str:
    """The limits :func:`reachability` applies to ``params``, in words, for the maps and
    figures of a study (or "none"/"unlimited" for each the parameters leave out), besides the
    cranks' reach, the platform above the base and the conditioning."""
    cones = [f"{name} {np.degrees(angle):.4g} deg" for name, angle in
             (("crank", params.crank_joint_max_angle), ("platform", params.platform_joint_max_angle))
             if angle is not None]
    crank, fold = params.crank_angle_limits, params.rod_crank_angle_limits
    clearance, tilt = params.base_clearance, params.crank_pin_max_tilt
    pins = f"; crank pins' tilt {np.degrees(tilt):.4g} deg" if tilt is not None else ""
    return (f"crank angles {_degrees(crank) if crank else 'unlimited'}; rod-crank angles "
            f"{_degrees(fold) if fold else 'unlimited'}; ball-joint cones {', '.join(cones) if cones else 'unlimited'}"
            f"{pins}; base clearance {f'{clearance:g} m' if clearance is not None else 'none'}")


@dataclass(frozen=True)
class RotaryReachability:
    """Per-row result of :func:`reachability`: ``flags`` one integer per pose, a sum of the
    problem bits of :data:`FLAGS` (0 for a reachable pose); ``crank_angles``, ``rod_crank_angles``,
    ``crank_joint_angles`` and ``platform_joint_angles`` ``(N, 6)`` [rad] (NaN where a crank
    cannot reach the pose); ``crank_pin_tilts`` ``(N, 6)`` [rad] each rod's tilt out of its
    crank's plane of motion (signed along the motor axis); ``base_gap`` ``(N,)`` [m] the height
    of the lowest platform joint over the base plane (:func:`base_plane`); ``condition`` the
    unit-free condition number of ``J_alpha`` (inf where it is singular or undefined);
    ``params`` the parameter set checked."""

    flags: np.ndarray
    crank_angles: np.ndarray
    rod_crank_angles: np.ndarray
    crank_joint_angles: np.ndarray
    platform_joint_angles: np.ndarray
    crank_pin_tilts: np.ndarray
    base_gap: np.ndarray
    condition: np.ndarray
    params: RotaryParams

    @property
    def ok(self) -> np.ndarray:
        return self.flags == 0

    @property
    def margin(self) -> np.ndarray:
        """The singularity margin ``1 / condition`` per pose, in [0, 1]."""
        return 1.0 / self.condition

    def _reason(self, bit: int, row: int) -> str:
        p = self.params

        def outside(values, lo, hi, what, unit="rad"):
            legs = np.flatnonzero(~((values >= lo) & (values <= hi))).tolist()
            return f"{what} {legs} ({', '.join(f'{values[i]:.4g}' for i in legs)} {unit})"

        if bit == OUT_OF_RANGE:
            return "the pose is out of numeric range"
        if bit == OUT_OF_REACH:
            return "a crank cannot reach the pose in its assembly mode (crank_branch)"
        if bit == CRANK_ANGLE_LIMIT:
            lo, hi = p.crank_angle_limits
            return outside(self.crank_angles[row], lo, hi, f"outside the crank angle limits {_degrees((lo, hi))}: crank(s)")
        if bit == ROD_CRANK_ANGLE_LIMIT:
            lo, hi = p.rod_crank_angle_limits
            return outside(self.rod_crank_angles[row], lo, hi,
                           f"outside the rod-crank angle limits {_degrees((lo, hi))}: leg(s)")
        if bit in (CRANK_JOINT_LIMIT, PLATFORM_JOINT_LIMIT):
            kind = "crank" if bit == CRANK_JOINT_LIMIT else "platform"
            limit = getattr(p, f"{kind}_joint_max_angle")
            return outside(getattr(self, f"{kind}_joint_angles")[row], 0.0, limit,
                           f"beyond the {kind} ball-joint cone half-angle {limit:g} rad: joint(s)")
        if bit == CRANK_PIN_LIMIT:
            limit = p.crank_pin_max_tilt
            return outside(self.crank_pin_tilts[row], -limit, limit,
                           f"a rod tilted out of its crank's plane beyond crank_pin_max_tilt {limit:g} rad: leg(s)")
        if bit == BELOW_BASE:
            need = f"less than the base clearance {p.base_clearance:g} m" if p.base_clearance is not None else \
                "not above it"
            return f"the platform is not above the base: its lowest joint is {self.base_gap[row]:.4g} m over it, {need}"
        if bit == SINGULAR:
            return f"J_alpha is singular or nearly so (condition number {self.condition[row]:.3g} > {CONDITION_LIMIT:g})"
        if bit == EULER_SINGULAR:
            return "theta = +-90 deg, where the Euler angles are singular"
        return "det J_alpha has the other sign: the pose is in another assembly mode, beyond a singularity"

    def reasons(self, row: int) -> list[str]:
        """Human sentences for the problems of one row."""
        return [self._reason(bit, row) for bit in FLAGS if self.flags[row] & bit]

    def message(self, what: str = "pose", times=None) -> str:
        """One line: how many rows are outside, and for each kind of problem the first row
        (or time) where it occurs and how many rows share it."""
        return outside_message(self.flags, FLAGS, self._reason, what, times)


def base_plane(params: RotaryParams) -> float:
    """The base plane's height [m] in {B}: the horizontal plane through the highest motor point
    ``b_i``, above which the platform's joints stay (by ``base_clearance``, when set)."""
    return float(np.max(params.base_points[:, 2]))


def _rig(platform):
    from .rotary import RotaryPlatform

    if isinstance(platform, RotaryPlatform):
        return platform
    if isinstance(platform, RotaryParams):
        return RotaryPlatform(platform)
    raise ValueError(f"platform: expected a stewart.RotaryPlatform or RotaryParams, got {type(platform).__name__}")


def assembly_mode(platform, pose=None) -> float:
    """The sign of ``det J_alpha`` at ``pose`` (default: the rig's home): +1 or -1 (0 at a
    singularity)."""
    rig = _rig(platform)
    return float(np.sign(np.linalg.det(rig.jacobian(rig.home if pose is None else pose))))


_BLOCK = 50_000  # poses checked at a time


def reachability(platform, poses, *, mode: float | None = None, reference=None,
                 name: str = "poses") -> RotaryReachability:
    """Check ``poses`` (``(6,)`` or ``(N, 6)``) against the workspace of the rotary rig
    ``platform`` (a :class:`~stewart.RotaryPlatform` or :class:`~stewart.RotaryParams`).
    ``reference`` is the pose the rig is mounted at, where its ball joints are centred (default:
    its home; :meth:`~stewart.RotaryPlatform.joint_cosines`); ``mode`` the sign of ``det J_alpha``
    of the poses' assembly mode (default: the reference pose's). Returns a
    :class:`RotaryReachability`, one row per pose."""
    rig = _rig(platform)
    x = np.atleast_2d(arguments.states(name, poses))
    if np.iscomplexobj(x):
        raise ValueError(f"{name}: expected real poses")
    reference = rig.home if reference is None else _pose("reference", reference)
    mode = assembly_mode(rig, reference) if mode is None else mode
    blocks = [_block(rig, x[i:i + _BLOCK], mode, reference) for i in range(0, max(len(x), 1), _BLOCK)]
    parts = {key: np.concatenate([b[key] for b in blocks]) for key in blocks[0]}
    return RotaryReachability(**parts, params=rig.params)


def _pose(name: str, value) -> np.ndarray:
    pose = arguments.states(name, value)
    if pose.ndim != 1:
        raise ValueError(f"{name}: expected one pose (6,), got shape {pose.shape}")
    return pose


def _block(rig, x: np.ndarray, mode: float, reference: np.ndarray) -> dict:
    p = rig.params
    joints, reached = rig.joint_cosines(x, reference, return_mask=True)
    reached = np.asarray(reached, bool)
    with np.errstate(all="ignore"):
        jac = rig.jacobian(x, return_mask=True)[0]
        margin = jacobian_margins(jac, p.platform_points)
        condition = 1.0 / margin
        det = np.linalg.det(np.nan_to_num(jac))
    angles = {key: np.arccos(np.clip(getattr(joints, key), -1.0, 1.0))
              for key in ("rod_crank", "crank_joint", "platform_joint")}
    gap = np.min(joints.platform_heights, axis=1) - base_plane(p)
    finite = np.all(np.isfinite(x), axis=1)
    flags = np.where(finite, 0, OUT_OF_RANGE) | np.where(finite & ~reached, OUT_OF_REACH, 0)
    checks = []
    if p.crank_angle_limits is not None:
        checks.append((joints.crank_angles, *p.crank_angle_limits, CRANK_ANGLE_LIMIT))
    if p.rod_crank_angle_limits is not None:
        checks.append((angles["rod_crank"], *p.rod_crank_angle_limits, ROD_CRANK_ANGLE_LIMIT))
    for key, limit, bit in (("crank_joint", p.crank_joint_max_angle, CRANK_JOINT_LIMIT),
                            ("platform_joint", p.platform_joint_max_angle, PLATFORM_JOINT_LIMIT)):
        if limit is not None:
            checks.append((angles[key], -np.inf, limit, bit))
    tilts = np.arcsin(np.clip(joints.pin_tilt_sines, -1.0, 1.0))
    if p.crank_pin_max_tilt is not None:
        checks.append((tilts, -p.crank_pin_max_tilt, p.crank_pin_max_tilt, CRANK_PIN_LIMIT))
    with np.errstate(invalid="ignore"):
        for values, lo, hi, bit in checks:
            flags |= np.where(reached & np.any(~((values >= lo) & (values <= hi)), axis=1), bit, 0)
        clearance = p.base_clearance
        flags |= np.where(reached & ~(gap > 0.0 if clearance is None else gap >= clearance), BELOW_BASE, 0)
        flags |= np.where(reached & ~(condition <= CONDITION_LIMIT), SINGULAR, 0)
        flags |= np.where(finite & (np.abs(np.cos(x[:, 4])) < 1.0 / CONDITION_LIMIT), EULER_SINGULAR, 0)
        flags |= np.where(reached & (np.sign(det) * mode < 0), OTHER_ASSEMBLY_MODE, 0)
    return dict(flags=flags, crank_angles=joints.crank_angles, rod_crank_angles=angles["rod_crank"],
                crank_joint_angles=angles["crank_joint"], platform_joint_angles=angles["platform_joint"],
                crank_pin_tilts=tilts, base_gap=gap, condition=condition)


def axis_range(platform, axis: int, *, start=None, reference=None, limit: float = np.pi / 2, step: float = 1e-3,
               tol: float = 1e-10) -> tuple[float, float]:
    """How far the rig moves from ``start`` (default: home) along the pose coordinate ``axis``
    (0-5: x, y, z [m], psi, theta, phi [rad]) alone, each way, within the workspace of
    :func:`reachability` (the joints centred at ``reference``, default home): ``(low, high)``, the ends of the reachable interval about ``start``,
    found on steps of ``step`` up to ``limit`` and then by bisection to ``tol``, so that the end
    is reachable and a point within ``tol`` beyond it is not (``+-limit`` if every step is)."""
    rig = _rig(platform)
    if isinstance(axis, (bool, np.bool_)) or not isinstance(axis, (int, np.integer)) or not 0 <= axis < 6:
        raise ValueError(f"axis: expected a pose coordinate index 0-5, got {axis!r}")
    for name, value in (("limit", limit), ("step", step), ("tol", tol)):
        if not arguments.real(name, value) > 0.0:
            raise ValueError(f"{name}: must be positive, got {value!r}")
    home = rig.home if start is None else _pose("start", start)
    reference = rig.home if reference is None else _pose("reference", reference)
    mode = assembly_mode(rig, reference)
    steps = np.arange(1, int(np.ceil(limit / step)) + 1) * step
    steps[-1] = limit
    ends = []
    for sign in (-1.0, 1.0):
        poses = np.tile(home, (len(steps), 1))
        poses[:, axis] += sign * steps
        ok = reachability(rig, poses, mode=mode, reference=reference).ok
        if ok.all():
            ends.append(sign * limit)
            continue
        first = int(np.argmin(ok))
        good, bad = (steps[first - 1] if first else 0.0), steps[first]
        while bad - good > tol:
            mid = 0.5 * (good + bad)
            pose = home.copy()
            pose[axis] += sign * mid
            if reachability(rig, pose, mode=mode, reference=reference).ok[0]:
                good = mid
            else:
                bad = mid
        ends.append(sign * good)
    return ends[0], ends[1]
