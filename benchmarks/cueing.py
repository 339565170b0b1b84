"""MPC cueing's time per step: the receding horizon of :func:`stewart.cueing.mpc` at 100 Hz
with a 1 s horizon (10 intervals) on ``motion_simulator``, over shipped maneuvers. A step is
everything between a new log sample and the new command: linearize about the last plan,
condense, solve the QP (DAQP). The target is faster than real time with room to spare: a
median of 2 ms (one core; the run's BLAS on one thread).

A round plans one maneuver (in turn) and times the yardstick in short calls beside it: its
value is the plan's median step over the yardstick's median call, times the yardstick's
reference cost (:mod:`stewart.cli.interleaved`)."""

from __future__ import annotations

import itertools
import pathlib

import numpy as np

import stewart
from stewart.cli import bench
from stewart.cli.interleaved import REFERENCE, SelfTimed, Target, time_calls
from stewart.cueing import MPCParams, planner, read_log

from .report import target_table

#: The most milliseconds a step's median may take.
STEP_MS = 2.0
TARGET = Target(STEP_MS, True)
#: The maneuvers timed, from examples/cueing/, one a round.
MANEUVERS = ("hard_braking", "double_lane_change")
EXAMPLES = pathlib.Path(__file__).resolve().parent.parent / "examples" / "cueing"
#: Calls of the yardstick a round times one by one.
YARDSTICK_CALLS = 101


def figures(preset: str = "motion_simulator", rounds: bench.Rounds | None = None) -> dict:
    rounds = rounds or bench.Rounds()
    plat = stewart.Platform.preset(preset)
    params = MPCParams.for_platform(plat)
    logs = {name: read_log(EXAMPLES / f"{name}.csv") for name in MANEUVERS}
    out = {"preset": preset, "horizon_s": params.duration, "steps": params.steps, "maneuvers": {}}
    step, qp = [], []
    turn = itertools.cycle(MANEUVERS)

    def plan() -> float:
        name = next(turn)
        run = planner.plan(logs[name], plat, params)
        out["maneuvers"][name] = {"rate_hz": 1.0 / logs[name].dt, "samples": len(logs[name].t),
                                  "failures": run.failures}
        step.append(run.step_time)
        qp.append(run.solve_time)
        return float(np.median(run.step_time))

    def yardstick() -> float:
        rounds.one()
        return float(np.median([time_calls(rounds.one, 1) for _ in range(YARDSTICK_CALLS)]))

    rounds.add("step_median_ms", [SelfTimed(plan), SelfTimed(yardstick)],
               lambda s, y: s / y * REFERENCE.seconds * 1e3, target=TARGET, min_rounds=len(MANEUVERS))
    out.update(bench.figures_of(rounds.measure()))
    step, qp = np.concatenate(step), np.concatenate(qp)
    out.update(step_max_ms=float(np.max(step) * 1e3), qp_median_ms=float(np.median(qp) * 1e3), steps_timed=len(step))
    return out


def rows(fig: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, figure, spread, target, verdict) rows."""
    what = f"MPC cueing step ({fig['preset']}, 100 Hz, {fig['horizon_s']:g} s horizon in {fig['steps']} intervals)"
    return [bench.measure_row(what + ", median", "step_median_ms", bench.as_measurement(fig, "step_median_ms"), 1.0,
                              "ms", ".2f", TARGET),
            ("MPC cueing step, max (as measured)", f"{fig['step_max_ms']:.1f} ms", "", "", ""),
            ("MPC cueing step, the QP solver's own time, median (as measured)", f"{fig['qp_median_ms']:.2f} ms", "",
             "", "")]


def format_rows(fig: dict) -> str:
    return target_table(rows(fig))


if __name__ == "__main__":
    print(format_rows(figures()))
