"""MPC cueing's compiled step (:class:`stewart.model.compiled.CueingStep`, through
:class:`stewart.cueing.planner.CueingQP`) against its anchor, the numpy formulation it
replaced (``benchmarks/cueing_anchor.py``): on shipped maneuvers, on both presets, step by step
from the anchor's own states (the same present state, last plan and warm start), the same QP
(H, f, rows and bounds) to round-off and the same plan to 1e-9 of the input, or, on a step
whose soft rows bind (DAQP's soft penalty of 1e6 makes the plan sensitive there), within the
change of the anchor's own plan when its data move by one unit in the last place."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

import daqp

import stewart
from benchmarks import cueing_anchor
from stewart.cueing import MPCParams, planner, read_log

EXAMPLES = pathlib.Path(__file__).resolve().parent.parent / "examples" / "cueing"
#: Every this many steps the QPs' data are compared (the plans at every step).
DATA_EVERY = 20


def round_off_sensitivity(anchor, data, sense, start, rng, trials=3):
    """The largest change of the anchor's plan when its QP's data (H, q and the rows, scaled as
    DAQP takes them) move by one unit in the last place, entry by entry at random."""
    H, q, M, lo, hi = data[:5]
    scale = 1.0 / anchor.row_scale
    rows = M * scale[:, None]
    upper = np.minimum(hi * scale - anchor._inset, 1e30)
    lower = np.maximum(lo * scale + anchor._inset, -1e30)
    settings = planner.SOLVER_SETTINGS
    base = daqp.solve(H, q, rows, upper, lower, sense, dual_start=start, **settings)[0]

    def ulp(a):
        return a * (1.0 + np.finfo(float).eps * rng.choice([-1.0, 1.0], a.shape))

    moved = []
    for _ in range(trials):
        Hp = ulp(H)
        u = daqp.solve(0.5 * (Hp + Hp.T), ulp(q), ulp(rows), upper, lower, sense, dual_start=start, **settings)[0]
        moved.append(np.max(np.abs(u - base)))
    return max(moved)


def relative(a, b):
    """The largest difference of ``a`` and ``b`` over the largest entry of ``b`` (1 if less)."""
    return np.max(np.abs(a - b)) / max(1.0, np.max(np.abs(b)))


@pytest.mark.parametrize("maneuver", ["hard_braking", "slalom"])
@pytest.mark.parametrize("preset", ["motion_simulator", "narayan2017"])
def test_the_compiled_step_builds_the_anchors_qp_and_plan(preset, maneuver, monkeypatch, figures):
    platform = stewart.Platform.preset(preset)
    params = MPCParams.for_platform(platform)
    log = read_log(EXAMPLES / f"{maneuver}.csv")
    compiled = planner.CueingQP(platform, params, log.dt)
    worst = {"H": 0.0, "q": 0.0, "rows": 0.0, "bounds": 0.0, "states": 0.0, "plan": 0.0, "sensitive": 0.0}
    steps = []
    rng = np.random.default_rng(0)

    class Twin(cueing_anchor.AnchorQP):
        """The anchor, each of whose steps the compiled step takes too, from the same state."""

        def solve(self, x0, v0, z0, vehicle):
            if self.last is None:
                compiled.step.forget()
            else:
                compiled.step.keep(self.last[3], self.last[1], self.last[2])
            compiled.multipliers = self.multipliers
            if len(steps) % DATA_EVERY == 0:
                want, got = self.condensed(x0, v0, z0, vehicle), compiled.condensed(x0, v0, z0, vehicle)
                for name, k in (("H", 0), ("q", 1), ("rows", 2), ("states", 5)):
                    worst[name] = max(worst[name], relative(got[k], want[k]))
                # the bounds, in units of each row's limit (a cone's infinite bound on both sides)
                for k in (3, 4):
                    finite = np.isfinite(want[k])
                    assert np.array_equal(finite, np.isfinite(got[k]))
                    worst["bounds"] = max(worst["bounds"], np.max(np.abs(got[k][finite] - want[k][finite])
                                                                  / compiled.row_scale[finite]))
                worst["states"] = max(worst["states"], relative(got[6], want[6]))
            start = self.multipliers
            u_c, _, _, info_c = compiled.solve(x0, v0, z0, vehicle)
            u_a, x_a, v_a, info_a = super().solve(x0, v0, z0, vehicle)
            assert info_c["level"] == info_a["level"] and info_c["tightened"] == info_a["tightened"]
            moved = np.max(np.abs(u_c - u_a)) / max(1.0, np.max(np.abs(u_a)))
            if moved <= 1e-9:
                worst["plan"] = max(worst["plan"], moved)
            else:  # soft rows bind: within what round-off of the anchor's own data moves its plan by
                assert info_a["exitflag"] == 2 and info_a["tightened"] == 0
                sensitivity = round_off_sensitivity(self, self.condensed(x0, v0, z0, vehicle),
                                                    self.levels[info_a["level"]], start, rng)
                worst["sensitive"] = max(worst["sensitive"], moved * max(1.0, np.max(np.abs(u_a))) / sensitivity)
            steps.append(info_a["level"])
            return u_a, x_a, v_a, info_a

    monkeypatch.setattr(cueing_anchor, "AnchorQP", Twin)
    run = cueing_anchor.plan(log, platform, params)
    assert run.failures == 0 and len(steps) == len(log.t)
    figures(f"H ({preset}, {maneuver})", worst["H"], 1e-13)            # reached 1.2e-15
    figures(f"q ({preset}, {maneuver})", worst["q"], 1e-13)            # reached 1.3e-15
    figures(f"rows ({preset}, {maneuver})", worst["rows"], 3e-14)      # reached 4.2e-16
    figures(f"bounds ({preset}, {maneuver})", worst["bounds"], 1e-13)  # reached 9.5e-16
    figures(f"states ({preset}, {maneuver})", worst["states"], 1e-13)  # reached 1.3e-15
    # reached 7.5e-13 where no soft row binds; 9.5e-10 on narayan2017's slalom, whose soft rows bind
    # on 150 of its 1201 steps (the plans there 1e-9 to 6e-9 apart, as far as one unit in the last
    # place of the anchor's own data moves its plan: 1e-9 to 4e-9)
    figures(f"plan ({preset}, {maneuver})", worst["plan"], 1e-9)
    figures(f"plan over the anchor's round-off ({preset}, {maneuver})", worst["sensitive"], 20.0)  # reached 4.6


@pytest.mark.parametrize("preset", ["motion_simulator", "narayan2017"])
def test_whole_runs_agree_with_the_anchors(preset, figures):
    """A whole maneuver planned by stewart.cueing.planner.plan (the vestibular states carried
    from step to step in C too) and by the anchor's loop: the same inputs, poses and levels."""
    platform = stewart.Platform.preset(preset)
    params = MPCParams.for_platform(platform)
    log = read_log(EXAMPLES / "hard_braking.csv")
    ours, anchor = planner.plan(log, platform, params), cueing_anchor.plan(log, platform, params)
    assert ours.level == anchor.level and ours.tightened == anchor.tightened and ours.failures == anchor.failures == 0
    figures(f"whole run's inputs ({preset})", np.max(np.abs(ours.u - anchor.u)) / np.max(np.abs(anchor.u)),
            1e-9)  # reached 5.3e-11
    figures(f"whole run's poses ({preset})", np.max(np.abs(ours.x - anchor.x)), 1e-12)  # reached 1.4e-14
