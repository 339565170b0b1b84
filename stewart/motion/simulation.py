"""Simulation of the platform under control: :func:`simulate` and :class:`SimulationResult`.

The closed loop — compiled forward dynamics, controller, saturation and friction — is
integrated either by a fixed-step RK4 loop that runs entirely in compiled code, or by
scipy's adaptive DOP853. Before the run, the reference is checked against the
workspace (:mod:`stewart.studies.workspace`); during it, leg stroke limits stop the run; after
it, the result says whether the run succeeded (:attr:`SimulationResult.outcome`).
"""

from __future__ import annotations

import signal
import threading
import time
from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

from ..model import arguments
from ..model.compiled import ClosedLoop, Outcome
from .control import PID, Actuators, Controller
from ..model.reachability import WorkspaceError
from .mechanism import Linear, mechanism
from .simulation_result import OUTCOMES, SimulationInterrupted, SimulationResult

__all__ = ["simulate", "SimulationResult", "SimulationInterrupted", "WorkspaceError", "MAX_STEPS",
           "MAX_ADAPTIVE_STEPS", "MIN_DT", "MAX_SHORT_EVALUATIONS", "DEFAULT_TOLERANCE", "OUTCOMES"]

#: Most RK4 steps a run may take unless ``max_steps`` allows more (1000 s at 1 kHz; the
#: buffers of a run take about 600 bytes per step).
MAX_STEPS = 1_000_000
#: Most steps the adaptive solver may take unless ``max_steps`` allows more: this many, or
#: four per report time ``dt`` if that is more (a smooth 5 s move under PID takes about
#: 5500; a stiff loop would otherwise run for hours).
MAX_ADAPTIVE_STEPS = 20_000
#: Smallest step ``dt`` accepted [s]; the adaptive solver gives up on steps shorter than this
#: (:data:`MAX_SHORT_EVALUATIONS`): no machine's closed loop has time constants below it.
MIN_DT = 1e-9
#: Most evaluations of the closed loop the adaptive solver may spend on steps shorter than
#: :data:`MIN_DT` (the run's last step to its end, or to a report time before an undefined
#: state, may be that short; ten steps' worth is not).
MAX_SHORT_EVALUATIONS = 120
#: Default final tracking tolerance: (position error [m], Euler-angle error [rad]).
DEFAULT_TOLERANCE = (1e-3, 1e-2)

_RK4_CHUNK = 2000  # steps between checks for Ctrl-C and progress updates


class _Progress:
    """A tqdm bar over simulated time: rate-limited, never running backwards."""

    def __init__(self, enabled: bool, total: float):
        from tqdm.auto import tqdm

        self.reached = 0.0
        self.bar = tqdm(total=total, disable=not enabled, unit="s", desc="simulate", mininterval=0.25,
                        bar_format="{desc}: {percentage:3.0f}%|{bar}| t = {n:.3f}/{total:.3f} s "
                                   "[{elapsed}<{remaining}]")

    def update(self, t: float) -> None:
        if t > self.reached:
            self.bar.update(t - self.reached)
            self.reached = t

    def close(self) -> None:
        self.bar.close()


class _Interrupt:
    """Turns the first Ctrl-C during a run into a flag checked between chunks of RK4 steps
    and after each adaptive step (a second Ctrl-C interrupts at once)."""

    def __init__(self):
        self.requested = False
        self.previous = None

    def _handle(self, signum, frame):
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self.previous = signal.signal(signal.SIGINT, self._handle)
        return self

    def __exit__(self, *exc):
        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)
        return False


def _seconds(name: str, value) -> float:
    """A real, finite number of seconds; refuses timedeltas, strings, booleans and arrays."""
    if isinstance(value, (bool, np.bool_, np.timedelta64, np.datetime64)) or not isinstance(
            value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name}: expected a number of seconds, got {type(value).__name__} {value!r}")
    try:
        out = float(value)
    except OverflowError:
        raise ValueError(f"{name}: {value!r} is too large") from None
    if not np.isfinite(out):
        raise ValueError(f"{name}: must be finite, got {out}")
    return out


def _tolerance(tolerance) -> tuple[float, float]:
    try:
        pos, ang = (float(v) for v in np.broadcast_to(np.asarray(tolerance, dtype=float), (2,)))
    except (TypeError, ValueError):
        raise ValueError(f"tolerance: expected (position [m], angle [rad]), got {tolerance!r}") from None
    if not (pos > 0 and ang > 0):
        raise ValueError(f"tolerance: both parts must be > 0, got ({pos}, {ang})")
    return pos, ang


def simulate(
    platform,
    trajectory,
    controller=None,
    *,
    duration: float | None = None,
    dt: float = 1e-3,
    method: str = "rk4",
    actuators: Actuators | None = None,
    feedforward: Callable | None = None,
    x0=None,
    xd0=None,
    progress: bool = False,
    rtol: float = 1e-9,
    atol: float = 1e-12,
    tolerance=DEFAULT_TOLERANCE,
    max_steps: int | None = None,
    check_workspace: bool = True,
) -> SimulationResult:
    """Simulate ``platform`` following ``trajectory`` under ``controller``.

    ``platform`` is a linear machine (:class:`stewart.Platform` or its
    :class:`~stewart.PlatformParams`) or a rotary rig (:class:`stewart.RotaryPlatform` or its
    :class:`~stewart.RotaryParams`, issue 40). For a rotary rig the loop's joints are the
    cranks: the PID acts on the crank angles (the reference's from the generated
    ``crank_angles`` and ``crank_rates``) with motor torques [N m] as output, computed torque
    is the rig's generated ``inverse_dynamics`` with the same pose-space feedback, the
    actuators' ``force_limit`` is the motors' torque limit (default: the rig's
    ``motor_torque_limit``) and their friction acts at the crank rates (default: none); the
    result's ``lengths``, ``leg_velocities`` and ``forces`` hold the crank angles, crank
    rates and motor torques (also as ``crank_angles``, ``crank_rates`` and ``torques``), and
    the run stops when a crank leaves ``crank_angle_limits`` or cannot reach the pose.

    ``trajectory`` has ``sample(t) -> (x, xdot, xddot)`` and ``duration``
    (:mod:`stewart.motion.trajectory`); its output is checked (shapes, dtype, finiteness) before
    any compiled code runs. ``controller`` is a :class:`~stewart.motion.control.PID` (default:
    :meth:`PID.tuned`), :class:`~stewart.motion.control.ComputedTorque` or
    :class:`~stewart.motion.control.OpenLoop`. ``feedforward(t) -> (N, 6)`` forces are added to
    the controller's output. The run starts at ``x0``/``xd0`` (default: the trajectory's
    start, at its velocity) and lasts ``duration`` (default: the trajectory's).

    ``actuators`` (:class:`~stewart.motion.control.Actuators`, default ``Actuators()``) saturate
    the commanded forces and take the legs' friction from them, by default the platform's
    own friction parameters.

    The PID starts bumpless: its integral holds the static leg forces of the start pose
    (inverse dynamics at rest, less the feed-forward), so the legs carry the platform's
    weight from ``t = 0``.

    ``method="rk4"`` integrates with classic fixed-step RK4 (step ``dt`` >= :data:`MIN_DT`)
    in compiled code; ``method="adaptive"`` steps scipy's ``DOP853`` (with ``rtol``
    and ``atol``) and reports at every ``dt``. A run longer than
    ``max_steps`` steps (default :data:`MAX_STEPS` for RK4) is refused before it starts;
    the adaptive solver stops with outcome ``"failed"`` after ``max_steps`` steps (default
    :data:`MAX_ADAPTIVE_STEPS` or four per report time, whichever is more), or once its steps
    stay shorter than :data:`MIN_DT` (a closed loop too stiff for any machine: gains of
    ``1e300``), within a fraction of a second.

    With ``check_workspace`` (the default) the start pose and the reference at every
    sample of the run are checked with :func:`stewart.model.reachability.reachability` (in the
    assembly mode of the start pose) first, and :class:`~stewart.model.reachability.WorkspaceError`
    (a ``ValueError``) is raised, naming the times and problems, when one lies outside.

    The run stops early at a leg stroke limit, a singular state or a non-finite state.
    The result's ``outcome``, ``ok`` and ``problems`` also report a change of assembly
    mode or a passage through ``theta = +-90 deg``, a final tracking error above
    ``tolerance = (position [m], angle [rad])`` (norms of the final position and
    Euler-angle errors) and commanded forces above ``actuators.force_limit``.
    ``progress=True`` draws a progress bar on stderr. Ctrl-C stops the run between chunks
    of RK4 steps or after an adaptive step, and raises :class:`SimulationInterrupted`
    holding the result so far.
    """
    run = _checked_run(platform, trajectory, controller, duration=duration, dt=dt, method=method,
                       actuators=actuators, feedforward=feedforward, x0=x0, xd0=xd0, rtol=rtol, atol=atol,
                       tolerance=tolerance, max_steps=max_steps)
    loop, series, y = _set_up(run, check_workspace)
    bar = _Progress(progress, run.duration)
    wall = time.perf_counter()
    with _Interrupt() as interrupt:
        integrate = _run_rk4 if run.method == "rk4" else _run_adaptive
        end = integrate(loop, run, series, y, bar, interrupt)
        end = _last_row(loop, run, series, end)
    wall = time.perf_counter() - wall
    bar.close()
    result = _result(run, series, end, wall, interrupt.requested, bar.reached)
    _judge(result, run.rig, run.actuators, run.tolerance, interrupt.requested)
    if interrupt.requested:
        raise SimulationInterrupted(result)
    return result


@dataclass(frozen=True)
class _Run:
    """The checked arguments of one run (see :func:`simulate`)."""

    rig: Linear  # the mechanism (stewart.motion.mechanism): Linear or Rotary
    trajectory: object
    controller: Controller
    actuators: Actuators
    feedforward: Callable | None
    method: str
    dt: float
    duration: float
    steps: int  # report intervals: the run has steps + 1 samples
    budget: int
    tolerance: tuple[float, float]
    rtol: float
    atol: float
    x0: np.ndarray
    xd0: np.ndarray

    @property
    def platform(self):
        """The compiled model: a :class:`stewart.Platform` or :class:`stewart.RotaryPlatform`."""
        return self.rig.platform

    @property
    def limits(self) -> tuple[float, float]:
        """The joint limits: leg lengths (none: ``(0, inf)``) or crank angles (none: ``(-inf, inf)``)."""
        return self.rig.limits

    def references(self, times) -> tuple[np.ndarray, np.ndarray]:
        """``([x_r, xdot_r, xddot_r] (N, 18), feed-forward forces (N, 6))`` at ``times``,
        checked (a rotary rig's reference rows with the crank angles and rates,
        :meth:`~stewart.motion.mechanism.Rotary.reference_rows`)."""
        x_r, xd_r, xdd_r = arguments.sampled("trajectory", self.trajectory, times)
        if self.feedforward is None:
            ff = np.zeros((len(times), 6))
        else:
            try:
                ff = np.asarray(self.feedforward(times), dtype=float)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"feedforward: must return forces of shape (N, 6): {exc}") from None
        if ff.shape != (len(times), 6) or not np.all(np.isfinite(ff)):
            raise ValueError("feedforward: must return finite forces of shape (N, 6) for N times")
        # Copies: the user's array may be a read-only view (np.broadcast_to), which the
        # compiled loop cannot take.
        rows = self.rig.reference_rows(np.hstack([x_r, xd_r, xdd_r]))
        return np.ascontiguousarray(rows), np.array(ff, dtype=float, order="C")


def _checked_run(platform, trajectory, controller, *, duration, dt, method, actuators, feedforward, x0, xd0,
                 rtol, atol, tolerance, max_steps) -> _Run:
    """The arguments of :func:`simulate` checked, with their defaults filled in; each
    problem raises ``ValueError`` naming its argument."""
    rig = mechanism(platform)
    platform = rig.platform
    arguments.trajectory("trajectory", trajectory)
    if controller is None:
        controller = PID.tuned(platform)
    if not isinstance(controller, Controller):
        raise ValueError(f"controller: expected a stewart.PID, ComputedTorque or OpenLoop instance, "
                         f"got {controller!r:.80}")
    actuators = rig.default_actuators() if actuators is None else actuators
    if not isinstance(actuators, Actuators):
        raise ValueError(f"actuators: expected a stewart.Actuators, got {type(actuators).__name__}")
    if method not in ("rk4", "adaptive"):
        raise ValueError(f"method: expected 'rk4' or 'adaptive', got {method!r}")
    dt = _seconds("dt", dt)
    if not dt >= MIN_DT:
        raise ValueError(f"dt: must be a step of at least {MIN_DT:g} s, got {dt!r}")
    duration = _seconds("duration", trajectory.duration if duration is None else duration)
    if not duration >= dt:
        raise ValueError(f"duration: must be at least one step dt = {dt:g} s, got {duration!r}")
    for name, value in (("rtol", rtol), ("atol", atol)):
        if not (isinstance(value, (int, float, np.floating)) and np.isfinite(value) and value > 0):
            raise ValueError(f"{name}: must be a positive number, got {value!r}")
    tolerance = _tolerance(tolerance)
    budget = MAX_STEPS if method == "rk4" else max(MAX_ADAPTIVE_STEPS, 4 * int(min(duration / dt, MAX_STEPS)))
    if max_steps is not None:
        if isinstance(max_steps, (bool, np.bool_)) or not isinstance(max_steps, (int, np.integer)) or max_steps < 1:
            raise ValueError(f"max_steps: expected a positive integer, got {max_steps!r}")
        budget = int(max_steps)
    steps = duration / dt
    if method == "rk4" and steps > budget:
        raise ValueError(f"dt, duration: {duration:g} s at dt = {dt:g} s is {steps:.3g} steps, more than the "
                         f"budget of {budget} (pass max_steps= to allow it)")
    if method == "adaptive" and steps > MAX_STEPS:
        raise ValueError(f"dt, duration: {steps:.3g} report times, more than {MAX_STEPS}; use a larger dt")
    start_ref = arguments.sampled("trajectory", trajectory, 0.0)
    x0 = start_ref[0] if x0 is None else arguments.states("x0", x0)
    xd0 = start_ref[1] if xd0 is None else arguments.states("xd0", xd0)
    if x0.shape != (6,) or xd0.shape != (6,) or np.iscomplexobj(x0) or np.iscomplexobj(xd0):
        raise ValueError("x0, xd0: expected one real state each, shape (6,)")
    return _Run(rig, trajectory, controller, actuators, feedforward, method, dt, duration,
                max(1, int(round(steps))), budget, tolerance, rtol, atol, x0, xd0)


@dataclass
class _Series:
    """The output rows of a run, one per sample time: the loop state ``[x, xdot, integral]``,
    commanded forces, leg lengths and leg rates. The reference and feed-forward are
    sampled at ``grid``: every ``dt`` for the adaptive solver, every ``dt / 2`` for RK4."""

    times: np.ndarray
    refs: np.ndarray
    feedforward: np.ndarray
    states: np.ndarray
    commanded: np.ndarray
    lengths: np.ndarray
    rates: np.ndarray


def _set_up(run: _Run, check_workspace: bool) -> tuple[ClosedLoop, _Series, np.ndarray]:
    """The compiled closed loop, the empty output rows with the sampled reference, and the
    starting loop state (the controller's starting integral included); the workspace is
    checked first when asked for."""
    dt, steps = run.dt, run.steps
    times = np.arange(steps + 1) * dt
    grid = np.arange(2 * steps + 1) * (dt / 2) if run.method == "rk4" else times
    refs, ff = run.references(grid)
    if check_workspace:
        every = 2 if run.method == "rk4" else 1  # the poses at the output samples
        run.rig.check_workspace(run.x0, refs[::every, :6], times)
    loop = run.rig.loop(*run.controller.loop_settings(), run.actuators)
    n = steps + 1
    series = _Series(times, refs, ff, np.zeros((n, 18)), *(np.zeros((n, 6)) for _ in range(3)))
    y = np.concatenate([run.x0, run.xd0, run.controller.initial_integral(run.platform, run.x0, ff[0])])
    return loop, series, y


class _End(NamedTuple):
    """How an integration ended: its last output row, the outcome (``STOP_*`` or a kernel
    status), the leg at a stroke limit (else -1), the state there, and the limit of the
    adaptive solver that stopped it, if one did (:data:`_BUDGET` or :data:`_SHORT_STEPS`)."""

    last: int
    outcome: int
    leg: int
    y: np.ndarray
    limit: str | None = None


def _run_rk4(loop: ClosedLoop, run: _Run, series: _Series, y: np.ndarray, bar, interrupt) -> _End:
    """Integrate with compiled fixed-step RK4, in chunks of steps with Ctrl-C and progress
    between them; fills the output rows up to the step where the run stopped."""
    lo, hi = run.limits
    done, outcome, leg = 0, Outcome.STOP_FINISHED, -1
    while done < run.steps and outcome == Outcome.STOP_FINISHED and not interrupt.requested:
        outcome, done, leg = loop.rk4(y, series.refs, series.feedforward, run.dt, done,
                                      min(run.steps, done + _RK4_CHUNK), lo, hi, series.states,
                                      series.commanded, series.lengths, series.rates)
        bar.update(done * run.dt)
    return _End(done, outcome, leg, y)


def _last_row(loop: ClosedLoop, run: _Run, series: _Series, end: _End) -> _End:
    """Write the final state's row (dropping the step that diverged, if any)."""
    last, y = end.last, end.y
    if not np.all(np.isfinite(y)):
        last, y = last - 1, series.states[last - 1].copy()
    ref_last, ff_last = (a[0] for a in run.references(series.times[last:last + 1]))
    series.states[last] = y
    _, series.commanded[last], series.lengths[last], series.rates[last], _ = loop.derivative(y, ref_last, ff_last)
    return end._replace(last=last, y=y)


def _result(run: _Run, series: _Series, end: _End, wall: float, interrupted: bool, reached: float) -> SimulationResult:
    """The run's series up to its last row, with why it ended (not yet judged)."""
    rows = slice(0, end.last + 1)
    times, limit = series.times, run.actuators.force_limit
    ref_x, ref_xd, _ = arguments.sampled("trajectory", run.trajectory, times[rows])
    params = run.platform.params
    result = SimulationResult(
        t=times[rows], x=series.states[rows, :6], xd=series.states[rows, 6:12], reference=ref_x,
        reference_velocity=ref_xd, lengths=series.lengths[rows], leg_velocities=series.rates[rows],
        forces=np.clip(series.commanded[rows], -limit, limit), commanded_forces=series.commanded[rows].copy(),
        completed=end.outcome == Outcome.STOP_FINISHED and end.limit is None and not interrupted,
        reason=run.rig.reason(end.outcome, times[end.last], end.leg),
        wall_time=wall, method=run.method, stopped_leg=None if end.leg < 0 else int(end.leg),
        metadata={"dt": run.dt, "platform": params.name or "unnamed", "controller": run.controller.label,
                  "tolerance": run.tolerance, "force_limit": limit.tolist(), "kind": run.rig.kind},
    )
    if end.limit == _BUDGET:
        result.reason = (f"the adaptive solver used its budget of {run.budget} steps before t = {reached:.4g} s "
                         f"(results up to t = {times[end.last]:.4f} s kept; the closed loop is too stiff: check the "
                         "gains, or raise the step budget)")
    elif end.limit == _SHORT_STEPS:
        result.reason = (f"the adaptive solver's steps fell below {MIN_DT:g} s after t = {times[end.last]:.4f} s "
                         "(the closed loop is too stiff for any machine: check the gains)")
    if interrupted:
        result.reason = f"interrupted at t = {times[end.last]:.4f} s"
    return result


def _judge(result: SimulationResult, rig: Linear, actuators, tolerance, interrupted: bool) -> None:
    """Set ``outcome`` and ``problems`` from the run's series."""
    problems = {name: [] for name in OUTCOMES}
    if interrupted:
        problems["interrupted"].append(result.reason)
    elif not result.completed:
        problems["failed"].append(result.reason)
    # det J_C (J_alpha of a rotary rig) is continuous along the motion, so a sign change means
    # the platform passed a singularity into another assembly mode (checked at every sample: a
    # crossing between samples still changes the sign). Likewise a sign change of cos(theta) is
    # a passage through the Euler-angle singularity theta = +-90 deg.
    det = np.linalg.det(rig.jacobian(result.x))
    flips = np.flatnonzero(~(np.sign(det) == np.sign(det[0])))
    if flips.size:
        problems["failed"].append(
            f"the platform passed a singularity and left its assembly mode (det {rig.jacobian_name} changed sign) "
            f"at t = {result.t[flips[0]]:.4f} s")
    cos_theta = np.cos(result.x[:, 4])
    turns = np.flatnonzero(np.sign(cos_theta) != np.sign(cos_theta[0]))
    if turns.size:
        problems["failed"].append(f"theta passed +-90 deg (Euler-angle singularity) at t = {result.t[turns[0]]:.4f} s")
    s = result.summary()
    if result.completed and not (s["final_position_error"] <= tolerance[0] and s["final_angle_error"] <= tolerance[1]):
        problems["inaccurate"].append(
            f"final tracking error {s['final_position_error']:.3g} m, {s['final_angle_error']:.3g} rad is above "
            f"the tolerance {tolerance[0]:g} m, {tolerance[1]:g} rad")
    over = np.abs(result.commanded_forces) > actuators.force_limit
    if over.any():
        row, leg = np.argwhere(over)[0]
        share = over.any(axis=1).mean()
        unit = rig.effort_unit
        problems["saturated"].append(
            f"commanded {rig.effort} {result.commanded_forces[row, leg]:.6g} {unit} on {rig.actor} {leg} at "
            f"t = {result.t[row]:.4f} s "
            f"exceeded the actuator limit {actuators.force_limit[leg]:g} {unit} (saturated at {100 * share:.3g}% of "
            f"the samples; peak {np.max(np.abs(result.commanded_forces)):.4g} {unit})")
    result.problems = [p for name in OUTCOMES for p in problems[name]]
    failing = [name for name in OUTCOMES if problems[name]]
    result.outcome = "interrupted" if interrupted else (failing[0] if failing else "completed")


_EVENT_TOLERANCE = 4 * np.finfo(float).eps  # relative and absolute, in time, of a stroke limit


#: The limits of the adaptive solver's work (:class:`_Stop`): its step budget, and its
#: evaluations on steps shorter than MIN_DT.
_BUDGET, _SHORT_STEPS = "budget", "short steps"


class _Stop(Exception):
    """The adaptive solver asked for a state where the model is undefined (``status`` > 0,
    at time ``t``) or reached a limit of its work (``status`` :data:`_BUDGET` or
    :data:`_SHORT_STEPS`)."""

    def __init__(self, status, t: float):
        super().__init__(status, t)
        self.status, self.t = status, t


def _run_adaptive(loop: ClosedLoop, run: _Run, series: _Series, y: np.ndarray, bar, interrupt) -> _End:
    """Integrate with DOP853 (``rtol``, ``atol``) one accepted step at a time, filling the
    output rows at the report times each step passes from its dense output.

    Ctrl-C, the step budget and steps shorter than :data:`MIN_DT` (more than
    :data:`MAX_SHORT_EVALUATIONS` evaluations less than ``MIN_DT`` after the last accepted
    time: scipy's own smallest step is relative to ``t``, about 1e-323 s at ``t = 0``) stop
    the run after the last accepted step. Where the model
    is undefined (a kernel error at a state a step tried), the solver keeps what it has
    reached and steps on only up to the last report time before the first such time, so the
    run ends there. A stroke limit is found in the step that crosses it by root-finding on
    the dense output, and adds a row at that time (written into ``series.times``).
    """
    from scipy.integrate import DOP853
    from scipy.optimize import brentq

    times = series.times
    evaluations, short = [0], [0]
    max_evaluations = 12 * run.budget  # DOP853 evaluates the right-hand side 12 times a step
    lo, hi = run.limits

    def evaluate(t, state):
        ref, ff = run.references(np.array([t]))
        return loop.derivative(np.ascontiguousarray(state), ref[0], ff[0])

    def rhs(t, state):
        evaluations[0] += 1
        if evaluations[0] > max_evaluations:
            raise _Stop(_BUDGET, t)
        if solver is not None and 0.0 <= t - solver.t < MIN_DT:  # a stage of a step shorter than about MIN_DT
            short[0] += 1
            if short[0] > MAX_SHORT_EVALUATIONS:
                raise _Stop(_SHORT_STEPS, t)
        ydot, _, _, _, status = evaluate(t, state)
        if status != 0:
            raise _Stop(status, t)
        bar.update(t)
        return ydot

    def margins(t, state):  # (leg above its minimum, leg below its maximum): a limit is crossed at <= 0
        lengths = evaluate(t, state)[2]
        return np.array([np.min(lengths) - lo, hi - np.max(lengths)])

    def record(k, state):
        series.states[k] = state
        _, series.commanded[k], series.lengths[k], series.rates[k], _ = evaluate(times[k], state)

    def stopped(outcome, limit=None):
        return _End(done, outcome, -1, np.ascontiguousarray(series.states[done]), limit)

    record(0, y)
    done, last = 0, len(times) - 1
    solver, first_step, undefined_from = None, None, np.inf
    with np.errstate(all="ignore"):  # a diverging state is reported as the outcome
        while done < last:
            try:
                if solver is None:
                    solver = DOP853(rhs, times[0], y.copy(), times[last], rtol=run.rtol, atol=run.atol,
                                    first_step=first_step)
                    before = margins(solver.t, solver.y)
                    continue
                solver.step()
            except _Stop as exc:
                if exc.status in (_BUDGET, _SHORT_STEPS):
                    return stopped(Outcome.STOP_FINISHED, limit=exc.status)
                # Step on only to the last report time before the model's first undefined state.
                undefined_from = min(undefined_from, exc.t)
                row = int(np.searchsorted(times, undefined_from)) - 1
                if row <= done:
                    return stopped(exc.status)
                target = times[row]
                if solver is None:
                    first_step = target - times[0]
                else:
                    solver.h_abs = target - solver.t
                continue
            if solver.status == "failed":  # the step size underflowed: the state is blowing up
                return stopped(Outcome.STOP_NONFINITE)
            try:  # DOP853's interpolant evaluates three more stages in the step
                dense = solver.dense_output()
            except _Stop as exc:
                limit = exc.status in (_BUDGET, _SHORT_STEPS)
                return stopped(Outcome.STOP_FINISHED if limit else exc.status, exc.status if limit else None)
            after = margins(solver.t, solver.y)
            crossed = np.flatnonzero((before >= 0) & (after <= 0))
            t_end = solver.t
            if crossed.size:  # the earliest stroke limit within the step
                stops = [brentq(lambda t, side=side: margins(t, dense(t))[side], solver.t_old, solver.t,
                                xtol=_EVENT_TOLERANCE, rtol=_EVENT_TOLERANCE) for side in crossed]
                side, t_end = crossed[int(np.argmin(stops))], min(stops)
            reached = min(last, int(np.searchsorted(times, t_end, side="right")) - 1)
            for k in range(done + 1, reached + 1):
                record(k, dense(times[k]))
            done = reached
            if crossed.size:
                return _stroke_limit(series, done + 1, t_end, dense(t_end), side, evaluate)
            if interrupt.requested:  # after each accepted step
                break
            before = after
    return stopped(Outcome.STOP_FINISHED)


def _stroke_limit(series: _Series, row: int, t: float, y: np.ndarray, side: int, evaluate) -> _End:
    """The end of an adaptive run at a stroke limit (``side`` 0: a leg at its minimum
    length, 1: at its maximum), reached at time ``t`` in state ``y``: its time goes into
    ``row``, the leg is the shortest or longest there."""
    lengths = evaluate(t, y)[2]
    leg = int(np.argmin(lengths) if side == 0 else np.argmax(lengths))
    series.times[row] = t
    outcome = Outcome.STOP_LEG_SHORT if side == 0 else Outcome.STOP_LEG_LONG
    return _End(row, outcome, leg, np.ascontiguousarray(y))
