"""Simulation of the platform under control: :func:`simulate` and :class:`SimulationResult`.

The closed loop — compiled forward dynamics, controller, saturation and friction — is
integrated either by a fixed-step RK4 loop that runs entirely in compiled code, or by
scipy's adaptive ``solve_ivp``. Leg stroke limits (``params.leg_length_limits``) are
events that stop the run and say why.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from . import _checks
from ._kernel import status_message
from ._simulate import ClosedLoop, Outcome
from .control import PID, Actuators, ComputedTorque, OpenLoop
from .platform import Platform

__all__ = ["simulate", "SimulationResult"]

_MODES = {OpenLoop: 0, PID: 1, ComputedTorque: 2}


@dataclass
class SimulationResult:
    """Time series of one run, sampled every ``dt`` (legs are indexed 0-5 as in arrays).

    ``forces`` are the actuator forces after saturation (what an actuator must deliver);
    friction, when modelled, is subtracted from them before they act on the legs.
    """

    t: np.ndarray
    x: np.ndarray
    xd: np.ndarray
    reference: np.ndarray
    reference_velocity: np.ndarray
    lengths: np.ndarray
    leg_velocities: np.ndarray
    forces: np.ndarray
    completed: bool
    reason: str
    wall_time: float
    method: str
    stopped_leg: int | None = None
    metadata: dict = field(default_factory=dict)

    @property
    def tracking_error(self) -> np.ndarray:
        """``reference - x`` at every sample, ``(N, 6)``."""
        return self.reference - self.x

    def summary(self) -> dict:
        """Peak force per leg, final pose error, RMS tracking error (position and angle)
        and wall time against simulated time."""
        err = self.tracking_error
        return {
            "peak_force": np.max(np.abs(self.forces), axis=0),
            "final_position_error": float(np.linalg.norm(err[-1, :3])),
            "final_angle_error": float(np.linalg.norm(err[-1, 3:])),
            "rms_position_error": float(np.sqrt(np.mean(np.sum(err[:, :3] ** 2, axis=1)))),
            "rms_angle_error": float(np.sqrt(np.mean(np.sum(err[:, 3:] ** 2, axis=1)))),
            "simulated_time": float(self.t[-1] - self.t[0]),
            "wall_time": self.wall_time,
        }

    def _columns(self):
        pose = ["x", "y", "z", "psi", "theta", "phi"]
        cols = [("t", self.t[:, None])]
        cols += [
            (pose, self.x),
            ([f"{p}_dot" for p in pose], self.xd),
            ([f"{p}_ref" for p in pose], self.reference),
            ([f"{p}_dot_ref" for p in pose], self.reference_velocity),
            ([f"L{i}" for i in range(6)], self.lengths),
            ([f"L{i}_dot" for i in range(6)], self.leg_velocities),
            ([f"force{i}" for i in range(6)], self.forces),
        ]
        names = []
        for name, _ in cols:
            names += [name] if isinstance(name, str) else name
        return names, np.hstack([arr for _, arr in cols])

    def to_csv(self, path) -> None:
        """Write every series as columns of a CSV file (SI units), with a header line."""
        names, data = self._columns()
        np.savetxt(path, data, delimiter=",", header=",".join(names), comments="", fmt="%.10g")

    def to_npz(self, path) -> None:
        """Write every series and the run's outcome to a compressed ``.npz`` file."""
        np.savez_compressed(
            path, t=self.t, x=self.x, xd=self.xd, reference=self.reference,
            reference_velocity=self.reference_velocity, lengths=self.lengths,
            leg_velocities=self.leg_velocities, forces=self.forces,
            completed=self.completed, reason=self.reason, method=self.method,
        )


def _reason(outcome: int, t: float, leg: int, params) -> str:
    if outcome == Outcome.STOP_FINISHED:
        return "completed"
    if outcome == Outcome.STOP_LEG_SHORT:
        return f"leg {leg} reached its minimum length {params.leg_length_limits[0]:g} m at t = {t:.4f} s"
    if outcome == Outcome.STOP_LEG_LONG:
        return f"leg {leg} reached its maximum length {params.leg_length_limits[1]:g} m at t = {t:.4f} s"
    if outcome == Outcome.STOP_NONFINITE:
        return f"the state became non-finite at t = {t:.4f} s"
    return f"{status_message(outcome)} at t = {t:.4f} s"


class _Progress:
    def __init__(self, enabled: bool, total: float):
        self.enabled, self.total, self.start = enabled, total, time.perf_counter()

    def update(self, t: float) -> None:
        if self.enabled:
            frac = min(1.0, t / self.total) if self.total > 0 else 1.0
            bar = "#" * int(30 * frac)
            sys.stderr.write(f"\r[simulate] |{bar:<30}| {100 * frac:5.1f}%  t = {t:7.3f} s  "
                             f"({time.perf_counter() - self.start:.1f} s wall)")
            sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")


def simulate(
    platform: Platform,
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
) -> SimulationResult:
    """Simulate ``platform`` following ``trajectory`` under ``controller``.

    ``trajectory`` has ``sample(t) -> (x, xdot, xddot)`` and ``duration``
    (:mod:`stewart.trajectory`). ``controller`` is a :class:`~stewart.control.PID`
    (default: :meth:`PID.tuned`), :class:`~stewart.control.ComputedTorque` or
    :class:`~stewart.control.OpenLoop`. ``feedforward(t) -> (N, 6)`` forces are added to
    the controller's output. The run starts at ``x0``/``xd0`` (default: the trajectory's
    start, at its velocity) and lasts ``duration`` (default: the trajectory's).

    ``method="rk4"`` integrates with classic fixed-step RK4 (step ``dt``) in compiled
    code; ``method="adaptive"`` uses ``scipy.integrate.solve_ivp`` (DOP853 with ``rtol``
    and ``atol``) and reports at every ``dt``. Either way the run stops early, with
    ``completed=False`` and a ``reason``, at a leg stroke limit, a singular state or a
    non-finite state. ``progress=True`` draws a progress bar on stderr.
    """
    if not isinstance(platform, Platform):
        raise ValueError(f"platform: expected a stewart.Platform, got {type(platform).__name__}")
    if controller is None:
        controller = PID.tuned(platform)
    if type(controller) not in _MODES:
        raise ValueError(f"controller: expected PID, ComputedTorque or OpenLoop, got {type(controller).__name__}")
    actuators = Actuators() if actuators is None else actuators
    duration = float(trajectory.duration if duration is None else duration)
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt: must be a positive step in seconds, got {dt}")
    if not (np.isfinite(duration) and duration >= dt):
        raise ValueError(f"duration: must be at least one step dt, got {duration}")
    if method not in ("rk4", "adaptive"):
        raise ValueError(f"method: expected 'rk4' or 'adaptive', got {method!r}")
    steps = int(round(duration / dt))

    start_ref = trajectory.sample(0.0)
    x0 = start_ref[0] if x0 is None else _checks.states("x0", x0)
    xd0 = start_ref[1] if xd0 is None else _checks.states("xd0", xd0)
    if x0.shape != (6,) or xd0.shape != (6,):
        raise ValueError("x0, xd0: expected one state each, shape (6,)")

    gains = {
        PID: lambda c: (c.kp, c.ki, c.kd),
        ComputedTorque: lambda c: (c.kp, np.zeros(6), c.kd),
        OpenLoop: lambda c: (np.zeros(6), np.zeros(6), np.zeros(6)),
    }[type(controller)](controller)
    loop = ClosedLoop(platform._kernel, _MODES[type(controller)], *gains, actuators.force_limit,
                      actuators.viscous, actuators.coulomb, actuators.coulomb_velocity)
    limits = platform.params.leg_length_limits or (0.0, np.inf)

    def references(times):
        x_r, xd_r, xdd_r = trajectory.sample(times)
        ff = np.zeros((len(times), 6)) if feedforward is None else np.asarray(feedforward(times), dtype=float)
        if ff.shape != (len(times), 6) or not np.all(np.isfinite(ff)):
            raise ValueError("feedforward: must return finite forces of shape (N, 6) for N times")
        return np.ascontiguousarray(np.hstack([x_r, xd_r, xdd_r])), np.ascontiguousarray(ff)

    times = np.arange(steps + 1) * dt
    n = steps + 1
    states = np.zeros((n, 18))
    forces, lengths, rates = (np.zeros((n, 6)) for _ in range(3))
    y = np.concatenate([x0, xd0, np.zeros(6)])
    bar = _Progress(progress, duration)
    wall = time.perf_counter()
    if method == "rk4":
        refs, ff = references(np.arange(2 * steps + 1) * (dt / 2))
        chunk = max(1, steps // 100) if progress else steps
        done, outcome, leg = 0, Outcome.STOP_FINISHED, -1
        while done < steps and outcome == Outcome.STOP_FINISHED:
            outcome, done, leg = loop.rk4(y, refs, ff, dt, done, min(steps, done + chunk), limits[0], limits[1],
                                          states, forces, lengths, rates)
            bar.update(done * dt)
        last = done
        ref_last, ff_last = refs[2 * last], ff[2 * last]
    else:
        last, outcome, leg, y = _adaptive(loop, references, y, times, limits, rtol, atol, states, forces,
                                          lengths, rates, bar)
        ref_last, ff_last = (a[0] for a in references(times[last:last + 1]))
    states[last] = y
    _, forces[last], lengths[last], rates[last], _ = loop.derivative(y, ref_last, ff_last)
    wall = time.perf_counter() - wall
    bar.close()

    rows = slice(0, last + 1)
    ref_x, ref_xd, _ = trajectory.sample(times[rows])
    return SimulationResult(
        t=times[rows], x=states[rows, :6], xd=states[rows, 6:12], reference=ref_x, reference_velocity=ref_xd,
        lengths=lengths[rows], leg_velocities=rates[rows], forces=forces[rows],
        completed=outcome == Outcome.STOP_FINISHED, reason=_reason(outcome, times[last], leg, platform.params),
        wall_time=wall, method=method, stopped_leg=None if leg < 0 else int(leg),
        metadata={"dt": dt, "controller": type(controller).__name__},
    )


class _KernelStop(Exception):
    """The model is undefined at a state the adaptive integrator asked for."""

    def __init__(self, status: int, t: float):
        super().__init__(status, t)
        self.status, self.t = status, t


def _adaptive(loop, references, y, times, limits, rtol, atol, states, forces, lengths, rates, bar):
    """Integrate with DOP853, reporting at ``times``; stroke limits are terminal events.

    Fills the output rows and returns ``(last row, outcome, leg, final state)``. A stroke
    limit adds a row at the event (its time written into ``times``); where the model is
    undefined (a kernel error), the run is integrated again up to the last report time
    before that point, and stops there.
    """
    from scipy.integrate import solve_ivp

    def evaluate(t, state):
        ref, ff = references(np.array([t]))
        return loop.derivative(np.ascontiguousarray(state), ref[0], ff[0])

    def rhs(t, state):
        ydot, _, _, _, status = evaluate(t, state)
        if status != 0:
            raise _KernelStop(status, t)
        bar.update(t)
        return ydot

    def leg_too_short(t, state):
        return np.min(evaluate(t, state)[2]) - limits[0]

    def leg_too_long(t, state):
        return limits[1] - np.max(evaluate(t, state)[2])

    for event in (leg_too_short, leg_too_long):
        event.terminal, event.direction = True, -1

    def run(report_times):
        return solve_ivp(rhs, (report_times[0], report_times[-1]), y, method="DOP853", t_eval=report_times,
                         rtol=rtol, atol=atol, events=[leg_too_short, leg_too_long])

    stop = None
    try:
        sol = run(times)
    except _KernelStop as exc:
        stop = exc
        earlier = times[times < exc.t]
        sol = run(earlier) if len(earlier) > 1 else None
    if sol is not None and sol.status < 0:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    count = 1 if sol is None else sol.y.shape[1]
    states[:count] = y if sol is None else sol.y.T
    for k in range(count):
        _, forces[k], lengths[k], rates[k], _ = evaluate(times[k], states[k])
    if stop is not None:
        return count - 1, stop.status, -1, np.ascontiguousarray(states[count - 1])
    if sol.status == 1:  # a stroke limit
        side = 0 if len(sol.t_events[0]) else 1
        y_stop = sol.y_events[side][0]
        at_stop = evaluate(sol.t_events[side][0], y_stop)[2]
        leg = int(np.argmin(at_stop) if side == 0 else np.argmax(at_stop))
        times[count] = sol.t_events[side][0]
        return count, Outcome.STOP_LEG_SHORT if side == 0 else Outcome.STOP_LEG_LONG, leg, np.ascontiguousarray(y_stop)
    return count - 1, Outcome.STOP_FINISHED, -1, np.ascontiguousarray(sol.y[:, -1])
