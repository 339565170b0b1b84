"""What :func:`stewart.simulate` needs of each family of mechanisms: the linear machines
(:class:`stewart.Platform`: legs, leg lengths, forces in N) and the rotary rigs
(:class:`stewart.RotaryPlatform`, issue 40: cranks, crank angles, motor torques in N m).

:func:`mechanism` gives the one of a platform argument; each holds its compiled closed loop
(:class:`~stewart.model.compiled.ClosedLoop` or :class:`~stewart.model.compiled.RotaryLoop`,
the same loop on the legs or the cranks), its joint limits, the workspace check of a run, the
words of its reports and the names of its series (CSV columns, figures)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.compiled import ClosedLoop, Outcome, RotaryLoop, rotary_status_message, status_message
from ..model.errors import WrongTypeError
from ..model.platform import Platform, as_platform
from ..model.params import PlatformParams
from ..model.reachability import WorkspaceError, assembly_mode, reachability
from ..model.rotary import RotaryPlatform
from ..model.rotary_params import RotaryParams
from .control import Actuators

__all__ = ["Linear", "Rotary", "mechanism", "CrankReach"]


#: The move of ``stewart simulate`` on each rotary preset without ``--target``, as the offset of
#: its target from :attr:`Rotary.home` (m, rad): in ``--move-time`` (5 s, as the seed paper's
#: move of the linear machines), every axis at once, within the cranks' reach and angle limits.
DEFAULT_TARGETS = {
    "simrig100": (0.03, -0.02, 0.03, 0.05, -0.04, 0.06),
    "desktop_servo": (0.008, -0.006, 0.008, 0.08, -0.06, 0.1),
}


class Linear:
    """A linear machine's legs: lengths [m], rates [m/s], forces [N]."""

    kind = "linear"
    joint, coordinate, rate, effort, actor = "leg", "length", "leg rate", "force", "leg"
    coordinate_unit, rate_unit, effort_unit = "m", "m/s", "N"
    #: The CSV columns' stems of the joint coordinates, their rates and the efforts.
    columns = ("L", "L{}_dot", "force")
    jacobian_name = "J_C"
    #: The pose ``stewart simulate`` moves to without ``--target`` (none: the user gives one).
    default_target = None

    def __init__(self, platform: Platform):
        self.platform = platform

    @property
    def params(self):
        return self.platform.params

    @property
    def home(self) -> np.ndarray:
        return self.platform.home_pose

    @property
    def limits(self) -> tuple[float, float]:
        """The joint coordinate's limits (none: ``(-inf, inf)``; legs ``(0, inf)``)."""
        return self.params.leg_length_limits or (0.0, np.inf)

    def default_actuators(self) -> Actuators:
        return Actuators()

    def reference_rows(self, rows: np.ndarray) -> np.ndarray:
        """The compiled loop's reference rows from ``[x_r, xd_r, xdd_r]`` ``(N, 18)``: those."""
        return rows

    def loop(self, mode, kp, ki, kd, actuators: Actuators):
        """The compiled closed loop: the legs lose the actuators' friction; computed torque adds
        back the model's own (the platform's parameters, Actuators' defaults)."""
        params = self.params
        return ClosedLoop(self.platform.kernel, mode, kp, ki, kd, actuators.force_limit, actuators.friction(params),
                          Actuators().friction(params))

    def reason(self, outcome: int, t: float, index: int) -> str:
        """Why a run of the compiled loop ended (``index``: the leg at a limit)."""
        lo, hi = self.limits
        if outcome == Outcome.STOP_FINISHED:
            return "completed"
        if outcome in (Outcome.STOP_LEG_SHORT, Outcome.STOP_LEG_LONG):
            side, bound = ("minimum", lo) if outcome == Outcome.STOP_LEG_SHORT else ("maximum", hi)
            return (f"{self.joint} {index} reached its {side} {self.coordinate} {bound:g} {self.coordinate_unit} "
                    f"at t = {t:.4f} s")
        if outcome == Outcome.STOP_NONFINITE:
            return f"the state became non-finite at t = {t:.4f} s"
        return f"{self.message(outcome)} at t = {t:.4f} s"

    def message(self, status: int) -> str:
        return status_message(status)

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """The joint Jacobian at the poses ``x`` (NaN where undefined)."""
        return self.platform.jacobian(x, return_mask=True)[0]

    def check_workspace(self, x0: np.ndarray, poses: np.ndarray, times: np.ndarray) -> None:
        """:class:`WorkspaceError` naming the first problems when the start pose or a reference
        pose lies outside the workspace (in the assembly mode of the start pose)."""
        platform = self.platform
        mode = assembly_mode(platform, x0)
        start = reachability(platform, x0, mode=mode, name="x0")
        if not start.ok[0]:
            raise WorkspaceError("x0: the start pose is outside the workspace: " + "; ".join(start.reasons(0)), start)
        check = reachability(platform, poses, mode=mode, name="trajectory")
        if not check.ok.all():
            raise WorkspaceError("trajectory: " + check.message("reference pose", times), check, times)


@dataclass(frozen=True)
class CrankReach:
    """Which poses a rotary rig's cranks reach within their angle limits (the ``reachability``
    of a :class:`WorkspaceError` of a rotary run): ``ok`` per pose, the generated crank
    angles (NaN where a crank cannot reach the pose, ``reach`` False there), and
    :meth:`reason` of a pose."""

    ok: np.ndarray
    reach: np.ndarray
    angles: np.ndarray
    rig: RotaryPlatform
    poses: np.ndarray

    @classmethod
    def of(cls, rig: RotaryPlatform, poses: np.ndarray) -> "CrankReach":
        """The generated crank angles of ``poses`` (N, 6), checked against the reach of each crank
        in its branch and ``crank_angle_limits``."""
        angles, reach = rig.crank_angles(poses, return_mask=True)
        lo, hi = rig.params.crank_angle_limits or (-np.inf, np.inf)
        with np.errstate(invalid="ignore"):
            within = np.all((angles >= lo) & (angles <= hi), axis=1)
        return cls(reach & within, reach, angles, rig, poses)

    def reason(self, row: int) -> str:
        """Why pose ``row`` is out: the crank that cannot reach it, or those outside their limits."""
        if not self.reach[row]:
            return _unreachable(self.rig, self.poses[row])
        lo, hi = self.rig.params.crank_angle_limits
        return "; ".join(f"crank {i} at {np.degrees(a):.4g} deg, outside its limits [{np.degrees(lo):.4g}, "
                         f"{np.degrees(hi):.4g}] deg" for i, a in enumerate(self.angles[row]) if not lo <= a <= hi)

    def message(self, what: str, times: np.ndarray) -> str:
        rows = np.flatnonzero(~self.ok)
        first = rows[0]
        more = f" (and {rows.size - 1} more sample(s) up to t = {times[rows[-1]]:.4f} s)" if rows.size > 1 else ""
        return f"{what} at t = {times[first]:.4f} s: {self.reason(first)}{more}"


def _unreachable(rig: RotaryPlatform, pose: np.ndarray) -> str:
    """The message of the generated crank angles' error at one pose out of a crank's reach."""
    try:
        rig.crank_angles(pose)
    except ValueError as exc:  # SingularityError: "rotary crank_angles: crank i cannot reach the pose ..."
        return str(exc).partition(": ")[2] or str(exc)
    return "undefined"


class Rotary(Linear):
    """A rotary rig's cranks: angles [rad], rates [rad/s], motor torques [N m] at the crank."""

    kind = "rotary"
    joint, coordinate, rate, effort, actor = "crank", "angle", "crank rate", "torque", "motor"
    coordinate_unit, rate_unit, effort_unit = "rad", "rad/s", "N m"
    columns = ("alpha", "alpha{}_dot", "torque")
    jacobian_name = "J_alpha"

    @property
    def home(self) -> np.ndarray:
        return self.platform.home

    @property
    def default_target(self) -> np.ndarray | None:
        """The target of a rotary preset's default move (:data:`DEFAULT_TARGETS` from
        :attr:`home`), else None."""
        offset = DEFAULT_TARGETS.get(self.params.name)
        return None if offset is None else self.home + offset

    @property
    def limits(self) -> tuple[float, float]:
        return self.params.crank_angle_limits or (-np.inf, np.inf)

    def default_actuators(self) -> Actuators:
        """The rig's motors: saturated at ``motor_torque_limit`` (none without it), no friction."""
        limit = self.params.motor_torque_limit
        return Actuators(force_limit=np.inf if limit is None else limit)

    def reference_rows(self, rows: np.ndarray) -> np.ndarray:
        """``[x_r, xd_r, xdd_r, alpha_r, alpha_dot_r]`` (30 columns, the loop's): the
        reference's crank angles and rates by the generated functions on the whole batch (NaN
        where a crank cannot reach it; the loop then reports the crank)."""
        x_r, xd_r = rows[:, :6], rows[:, 6:12]
        angles = self.platform.crank_angles(x_r, return_mask=True)[0]
        rates = self.platform.crank_rates(x_r, xd_r, return_mask=True)[0]
        return np.hstack([rows, angles, rates])

    def loop(self, mode, kp, ki, kd, actuators: Actuators):
        """The compiled rotary loop: the cranks lose the actuators' friction (none by default);
        computed torque adds back none (a rotary rig's parameters hold no friction)."""
        return RotaryLoop(self.platform.kernel, mode, kp, ki, kd, actuators.force_limit,
                          actuators.friction(self.params), Actuators().friction(self.params))

    def message(self, status: int) -> str:
        return rotary_status_message(status)

    def reason(self, outcome: int, t: float, index: int) -> str:
        if outcome in (Outcome.STOP_LEG_SHORT, Outcome.STOP_LEG_LONG):
            lo, hi = self.limits
            side, bound = ("lower", lo) if outcome == Outcome.STOP_LEG_SHORT else ("upper", hi)
            return (f"crank {index} reached its {side} angle limit {np.degrees(bound):.4g} deg "
                    f"({bound:.6g} rad) at t = {t:.4f} s")
        return super().reason(outcome, t, index)

    def check_workspace(self, x0: np.ndarray, poses: np.ndarray, times: np.ndarray) -> None:
        """:class:`WorkspaceError` naming the first problem when a crank cannot reach the start
        pose or a reference pose in its branch, or would leave ``crank_angle_limits`` there."""
        start = CrankReach.of(self.platform, x0[None, :])
        if not start.ok[0]:
            raise WorkspaceError("x0: the start pose is outside the workspace: " + start.reason(0), start)
        check = CrankReach.of(self.platform, poses)
        if not check.ok.all():
            raise WorkspaceError("trajectory: " + check.message("reference pose", times), check, times)


def mechanism(value, name: str = "platform") -> Linear:
    """The mechanism of a platform argument, converted once where it enters (a parameter set
    compiled): :class:`Rotary` of a :class:`stewart.RotaryPlatform` or :class:`stewart.RotaryParams`,
    :class:`Linear` of a :class:`stewart.Platform` or :class:`stewart.PlatformParams`
    (:func:`~stewart.model.platform.as_platform`); :class:`~stewart.WrongTypeError` naming
    ``name`` otherwise."""
    if isinstance(value, (RotaryPlatform, RotaryParams)):
        return Rotary(value if isinstance(value, RotaryPlatform) else RotaryPlatform(value))
    if isinstance(value, (Platform, PlatformParams)):
        return Linear(as_platform(value, name))
    raise WrongTypeError(f"{name}: expected a stewart.Platform or stewart.RotaryPlatform, got {type(value).__name__}")
