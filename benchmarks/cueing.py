"""MPC cueing's time per step: the receding horizon of :func:`stewart.cueing.mpc` at 100 Hz
with a 1 s horizon (10 intervals, the joint cones and force rows) on ``motion_simulator``, and
on the rotary ``simrig100`` (its motor torques, crank angles, rates and reach, and every joint
limit of its workspace), over shipped maneuvers. A step is everything between a new log sample and the new command:
linearize about the last plan, condense, solve the QP (DAQP). Two targets: a median step of
at most 1 ms (one core; the run's BLAS on one thread), faster than real time with room to
spare, and at least twice as fast as the anchor, the same step linearized and condensed in
numpy (:mod:`benchmarks.cueing_anchor`, linear platforms only).

A round plans one maneuver (in turn) with each side. The median step's figure is the plan's
median step over the yardstick's median call (timed in short calls beside it), times the
yardstick's reference cost (:mod:`stewart.cli.interleaved`); the speed-up's is the anchor's
median step over the compiled step's, the two plans of the same maneuver timed in the same
round."""

from __future__ import annotations

import itertools
import pathlib

import numpy as np

import stewart
from stewart.cli import bench
from stewart.cli.interleaved import REFERENCE, SelfTimed, Target, time_calls
from stewart.cueing import MPCParams, planner, read_log
from stewart.model import rotary_presets

from . import cueing_anchor
from .report import target_table

#: The most milliseconds a step's median may take.
STEP_MS = 1.0
TARGET = Target(STEP_MS, True)
#: The least speed-up of the compiled step over the anchor's (the numpy step).
SPEEDUP = 2.0
SPEEDUP_TARGET = Target(SPEEDUP, False, "the numpy step (benchmarks/cueing_anchor.py)")
#: The maneuvers timed, from examples/cueing/, one a round.
MANEUVERS = ("hard_braking", "double_lane_change")
EXAMPLES = pathlib.Path(__file__).resolve().parent.parent / "examples" / "cueing"
#: Calls of the yardstick a round times one by one.
YARDSTICK_CALLS = 101


def figures(preset: str = "motion_simulator", rounds: bench.Rounds | None = None) -> dict:
    """The step's figures on the linear or rotary preset ``preset`` (the speed-up over the
    anchor on a linear one)."""
    rounds = rounds or bench.Rounds()
    rotary = preset in rotary_presets.presets()
    plat = stewart.RotaryPlatform.preset(preset) if rotary else stewart.Platform.preset(preset)
    params = MPCParams.for_platform(plat)
    logs = {name: read_log(EXAMPLES / f"{name}.csv") for name in MANEUVERS}
    out = {"preset": preset, "horizon_s": params.duration, "steps": params.steps, "maneuvers": {}}
    step, qp = [], []

    def side(plan, record: bool):
        """A side: the median step [s] of ``plan`` on the next maneuver (its own turn, so that the
        sides of a round plan the same one)."""
        turn = itertools.cycle(MANEUVERS)

        def run() -> float:
            name = next(turn)
            result = plan(logs[name], plat, params)
            if record:
                out["maneuvers"][name] = {"rate_hz": 1.0 / logs[name].dt, "samples": len(logs[name].t),
                                          "failures": result.failures}
                step.append(result.step_time)
                qp.append(result.solve_time)
            return float(np.median(result.step_time))
        return SelfTimed(run)

    def yardstick() -> float:
        rounds.one()
        return float(np.median([time_calls(rounds.one, 1) for _ in range(YARDSTICK_CALLS)]))

    rounds.add("step_median_ms", [side(planner.plan, True), SelfTimed(yardstick)],
               lambda s, y: s / y * REFERENCE.seconds * 1e3, target=TARGET, min_rounds=len(MANEUVERS))
    if not rotary:
        rounds.add("step_speedup", [side(planner.plan, False), side(cueing_anchor.plan, False)],
                   lambda s, a: a / s, target=SPEEDUP_TARGET, min_rounds=len(MANEUVERS))
    out.update(bench.figures_of(rounds.measure()))
    step, qp = np.concatenate(step), np.concatenate(qp)
    out.update(step_max_ms=float(np.max(step) * 1e3), qp_median_ms=float(np.median(qp) * 1e3), steps_timed=len(step))
    return out


def rows(fig: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, figure, spread, target, verdict) rows."""
    what = f"MPC cueing step ({fig['preset']}, 100 Hz, {fig['horizon_s']:g} s horizon in {fig['steps']} intervals)"
    out = [bench.measure_row(what + ", median", "step_median_ms", bench.as_measurement(fig, "step_median_ms"), 1.0,
                             "ms", ".2f", TARGET)]
    if "step_speedup" in fig:
        out.append(bench.measure_row("MPC cueing step, speed-up over the numpy step (benchmarks/cueing_anchor.py)",
                                     "step_speedup", bench.as_measurement(fig, "step_speedup"), 1.0, "x", ".2f",
                                     SPEEDUP_TARGET))
    return out + [(f"MPC cueing step ({fig['preset']}), max (as measured)", f"{fig['step_max_ms']:.1f} ms", "", "", ""),
                  (f"MPC cueing step ({fig['preset']}), the QP solver's own time, median (as measured)",
                   f"{fig['qp_median_ms']:.2f} ms", "", "", "")]


def format_rows(fig: dict) -> str:
    return target_table(rows(fig))


if __name__ == "__main__":
    print(format_rows(figures()))
    print(format_rows(figures("simrig100")))
