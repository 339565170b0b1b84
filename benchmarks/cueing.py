"""MPC cueing's time per step: the receding horizon of :func:`stewart.cueing.mpc` at 100 Hz
with a 1 s horizon (10 intervals) on ``motion_simulator``, over shipped maneuvers. A step is
everything between a new log sample and the new command: linearize about the last plan,
condense, solve the QP (DAQP). The target is faster than real time with room to spare: a
median of 2 ms (one core; the run's BLAS on one thread)."""

from __future__ import annotations

import pathlib

import numpy as np

import stewart
from stewart.cueing import MPCParams, predictive, read_log

from .report import target_table

#: The most milliseconds a step's median may take.
STEP_MS = 2.0
#: The maneuvers timed, from examples/cueing/.
MANEUVERS = ("hard_braking", "double_lane_change")
EXAMPLES = pathlib.Path(__file__).resolve().parent.parent / "examples" / "cueing"


def figures(preset: str = "motion_simulator") -> dict:
    plat = stewart.Platform.preset(preset)
    params = MPCParams.for_platform(plat)
    out = {"preset": preset, "horizon_s": params.duration, "steps": params.steps, "maneuvers": {}}
    step, qp = [], []
    for name in MANEUVERS:
        log = read_log(EXAMPLES / f"{name}.csv")
        run = predictive.plan(log, plat, params)
        out["maneuvers"][name] = {"rate_hz": 1.0 / log.dt, "samples": len(log.t), "failures": run.failures}
        step.append(run.step_time)
        qp.append(run.solve_time)
    step, qp = np.concatenate(step), np.concatenate(qp)
    out.update(step_median_ms=float(np.median(step) * 1e3), step_max_ms=float(np.max(step) * 1e3),
               qp_median_ms=float(np.median(qp) * 1e3), steps_timed=len(step))
    return out


def rows(fig: dict) -> list[tuple[str, str, str, str]]:
    """(measure, figure, target, met) rows."""
    ok = fig["step_median_ms"] <= STEP_MS
    what = f"MPC cueing step ({fig['preset']}, 100 Hz, {fig['horizon_s']:g} s horizon in {fig['steps']} intervals)"
    return [(what + ", median", f"{fig['step_median_ms']:.2f} ms", f"<= {STEP_MS:g} ms", "met" if ok else "MISSED"),
            ("MPC cueing step, max", f"{fig['step_max_ms']:.1f} ms", "", ""),
            ("MPC cueing step, the QP solver's own time, median", f"{fig['qp_median_ms']:.2f} ms", "", "")]


def format_rows(fig: dict) -> str:
    return target_table(rows(fig))


if __name__ == "__main__":
    print(format_rows(figures()))
