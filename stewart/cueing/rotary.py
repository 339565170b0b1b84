"""Cueing on rotary rigs (issue 40, 6-RSS): what the cueing runs need of a
:class:`~stewart.RotaryPlatform` beside a :class:`~stewart.Platform` (:func:`as_rig`): the
poses' check (:func:`check_poses`: the crank angles within ``crank_angle_limits`` and every
crank within its reach, :data:`REACH_MIN`), the rig's free excursion along each pose axis
(:func:`axis_excursions`, the MPC's default box) and its motor limits (:func:`motor_limits`).

:func:`check_poses` is the rotary workspace's own check
(:func:`stewart.model.rotary_reachability.reachability`: crank angles, rod-crank angles, both
ball-joint cones about the joints' neutral axes at home, base clearance, conditioning and
assembly mode) with the cueing's reach floor :data:`REACH_MIN` on top: one check, the
workspace's, for every pose a cueing run writes.

The reach of crank i is ``s_i = sin^2(delta_i)`` (codegen/rotary.py ``crank_geometry``): 1 with
the rod along the crank tip's motion, 0 where the rod is tangent to the tip's circle, the edge
of the crank's reach, where ``J_alpha`` is singular and the motor holds no load. Every pose a
cueing run writes keeps ``s_i >= REACH_MIN`` (the rod at least ``asin(sqrt(REACH_MIN))`` =
5.7 deg off that tangent), the MPC's plans ``REACH_MARGIN`` over the horizon. The values come from
the generated :meth:`~stewart.RotaryPlatform.cueing_rows`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import rotary_reachability as workspace
from ..model.errors import WrongTypeError
from ..model.platform import as_platform
from ..model.reachability import outside_message
from ..model.rotary import RotaryPlatform
from ..model.rotary_params import RotaryParams

__all__ = ["as_rig", "rotary_rig", "is_rotary", "check_poses", "CrankCheck", "axis_excursions", "motor_limits", "home",
           "REACH_MIN", "REACH_MARGIN", "CRANK_ANGLE_LIMIT", "CRANK_REACH", "FLAG_NAMES",
           "TORQUE_PER_STATIC", "SPEED_DEFAULT"]

#: The least reach ``sin^2(delta)`` of every crank at every pose written (sin(delta) >= 0.1).
REACH_MIN = 0.01
#: The least reach over the MPC's horizon (sin(delta) >= 0.2), a margin the plan keeps where it can.
REACH_MARGIN = 0.04
#: :attr:`CrankCheck.flags` bits: those of the rotary workspace
#: (:data:`stewart.model.rotary_reachability.FLAGS`) and :data:`CRANK_REACH`, a crank that
#: reaches the pose but nearer the edge of its reach than :data:`REACH_MIN`.
CRANK_ANGLE_LIMIT = workspace.CRANK_ANGLE_LIMIT
CRANK_REACH = 65536
FLAG_NAMES = {**workspace.FLAG_NAMES, CRANK_REACH: "crank_reach"}
#: Without ``motor_torque_limit``: this many times the largest static torque at home.
TORQUE_PER_STATIC = 2.0
#: Without ``motor_speed_limit``: one radian per second per radian of crank-angle range (or 2 pi rad/s).
SPEED_DEFAULT = 2 * np.pi


def rotary_rig(value):
    """``value`` as a :class:`~stewart.RotaryPlatform` when it is one or a
    :class:`~stewart.RotaryParams` (compiled), else None (a linear platform, for
    :func:`~stewart.model.platform.as_platform`)."""
    if isinstance(value, RotaryPlatform):
        return value
    if isinstance(value, RotaryParams):
        return RotaryPlatform(value)
    return None


def as_rig(value, name: str = "platform"):
    """``value`` as a compiled rig: a :class:`~stewart.RotaryPlatform` (:func:`rotary_rig`) or
    a :class:`~stewart.Platform` (:func:`~stewart.model.platform.as_platform`, whose
    :class:`~stewart.WrongTypeError` names ``name``)."""
    rig = rotary_rig(value)
    if rig is not None:
        return rig
    try:
        return as_platform(value, name)
    except WrongTypeError:
        raise WrongTypeError(f"{name}: expected a stewart.Platform or stewart.RotaryPlatform, got "
                             f"{type(value).__name__}") from None


def is_rotary(rig) -> bool:
    return isinstance(rig, RotaryPlatform)


def home(rig) -> np.ndarray:
    """The rig's home pose (:attr:`~stewart.RotaryPlatform.home`, :attr:`~stewart.Platform.home_pose`)."""
    return rig.home if is_rotary(rig) else rig.home_pose


@dataclass(frozen=True)
class CrankCheck:
    """:func:`check_poses` of a rotary rig: ``flags`` per pose (:data:`FLAG_NAMES` bits, 0 for a
    pose the rig can take), the crank angles ``alpha`` and reaches ``reach`` ``(N, 6)`` (NaN
    where a crank cannot reach), the angle ``limits`` (or None) and ``workspace``, the
    :class:`~stewart.model.rotary_reachability.RotaryReachability` of the poses (the angles of
    every joint, the base gap, the conditioning)."""

    flags: np.ndarray
    alpha: np.ndarray
    reach: np.ndarray
    limits: tuple | None
    workspace: workspace.RotaryReachability | None = None

    @property
    def ok(self) -> np.ndarray:
        return self.flags == 0

    def message(self, what: str = "pose", times=None) -> str:
        """One line: how many rows are outside and, per kind, the first (with its legs and
        angles)."""
        def reason(bit, row):
            if bit == CRANK_REACH:
                return f"crank out of its reach (sin^2 delta < {REACH_MIN:g})"
            return self.workspace._reason(bit, row)

        return outside_message(self.flags, (*workspace.FLAGS, CRANK_REACH), reason, what, times)


def check_poses(rig: RotaryPlatform, poses) -> CrankCheck:
    """The rotary rig's check of ``poses`` ``(N, 6)``: every limit of the rotary workspace
    (:func:`stewart.model.rotary_reachability.reachability`, the joints centred at home) and
    each crank at least :data:`REACH_MIN` within its reach."""
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    rows, ok = rig.cueing_rows(poses, np.zeros_like(poses), return_mask=True)
    space = workspace.reachability(rig, poses, name="poses")
    flags = np.asarray(space.flags, dtype=np.int64).copy()
    with np.errstate(invalid="ignore"):
        near_edge = ~np.asarray(ok, bool) | ~np.all(rows.reach >= REACH_MIN, axis=1)
    flags[near_edge & ((flags & (workspace.OUT_OF_REACH | workspace.OUT_OF_RANGE)) == 0)] |= CRANK_REACH
    return CrankCheck(flags, rows.alpha, rows.reach, rig.params.crank_angle_limits, space)


def motor_limits(rig: RotaryPlatform) -> tuple[np.ndarray, np.ndarray]:
    """The motors' torque [N m] and speed [rad/s] limits ``(6,)`` each: the parameters', or
    :data:`TORQUE_PER_STATIC` times the largest static torque at home and :data:`SPEED_DEFAULT`."""
    p = rig.params
    torque = p.motor_torque_limit
    if torque is None:
        static = rig.inverse_dynamics(rig.home, np.zeros(6), np.zeros(6))
        torque = np.full(6, TORQUE_PER_STATIC * float(np.max(np.abs(static))))
    speed = p.motor_speed_limit if p.motor_speed_limit is not None else np.full(6, SPEED_DEFAULT)
    return np.broadcast_to(np.asarray(torque, dtype=float), (6,)).copy(), \
        np.broadcast_to(np.asarray(speed, dtype=float), (6,)).copy()


def axis_excursions(rig: RotaryPlatform, tolerance: float = 1e-5) -> np.ndarray:
    """The free excursion from home along each pose axis ``(6,)`` [m, m, m, rad, rad, rad]
(within every limit :func:`check_poses` applies, the ball-joint cones included):
    the least over both directions of the largest step the rig takes with every pose between
    home and it passing :func:`check_poses` (checked on 64 points, then bisected)."""
    start = home(rig)
    out = np.empty(6)
    for axis in range(6):
        reach = 0.5 if axis < 3 else 1.0
        best = np.inf
        for sign in (1.0, -1.0):
            steps = reach * np.arange(1, 65) / 64
            poses = np.tile(start, (64, 1))
            poses[:, axis] += sign * steps
            ok = check_poses(rig, poses).ok
            if ok.all():
                best = min(best, reach)
                continue
            first = int(np.argmin(ok))
            lo, hi = (steps[first - 1] if first else 0.0), steps[first]
            while hi - lo > tolerance:
                mid = 0.5 * (lo + hi)
                pose = start.copy()
                pose[axis] += sign * mid
                lo, hi = (mid, hi) if check_poses(rig, pose).ok[0] else (lo, mid)
            best = min(best, lo)
        out[axis] = best
    return out
