"""stewart.cueing.limiter: the washout's limiter brings a 30 g sensor glitch back into the
workspace on both presets (exit 0, the closed loop inside too, the report naming where), its
scale rises and falls within the Hann envelope's analytic rate bounds so that the reference's
rates change no more than the washout's own plus those terms, it leaves the shipped maneuvers
bit for bit as they were (tests/test_cueing.py), and off it gives today's refusal."""

import json
import math
import os
import re
from dataclasses import replace

import numpy as np
import pytest

from cli_run import call

from stewart import Platform, reachability
from stewart.cueing import VehicleLog, WashoutParams, read_log, washout
from stewart.cueing.classical import reference_poses
from stewart.model.params import PlatformParams

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(ROOT, "examples", "cueing")
PRESETS = ["narayan2017", "motion_simulator"]
G = 9.81


def _glitch(log: VehicleLog, axis: int, at: float) -> VehicleLog:
    """``log`` with a 30 g spike of five samples added to specific force ``axis`` at ``at`` s."""
    f = log.f.copy()
    k = int(round(at / log.dt))
    f[k:k + 5, axis] += 30 * G
    return VehicleLog(log.t, f, log.w, name=f"{log.name} with a glitch")


def _at_rest(seconds=10.0, dt=0.01) -> VehicleLog:
    n = int(round(seconds / dt))
    return VehicleLog(np.arange(n) * dt, np.tile([0.0, 0.0, G], (n, 1)), np.zeros((n, 3)), name="at rest")


@pytest.fixture(scope="module")
def platforms():
    out = {}
    for preset in PRESETS:
        plat = Platform(PlatformParams.preset(preset))
        out[preset] = plat, WashoutParams.for_platform(plat)
    return out


@pytest.mark.parametrize("preset", PRESETS)
def test_glitch_is_limited_into_the_workspace_and_reported(tmp_path, preset):
    log = tmp_path / "glitch.csv"
    _glitch(_at_rest(), 0, 2.0).to_csv(log)
    ref, report = tmp_path / "ref.csv", tmp_path / "r.json"
    run = call("cueing", str(log), "--preset", preset, "--simulate", "--output", str(ref), "--report", str(report))
    assert run.returncode == 0, run.stderr
    assert "limiter: scaled the excursion from home" in run.stdout
    plat = Platform(PlatformParams.preset(preset))
    poses = np.loadtxt(ref, delimiter=",", skiprows=2)[:, 1:7]
    check = reachability(plat, poses)
    assert check.ok.all()
    assert np.max(check.lengths) <= plat.params.leg_length_limits[1]
    r = json.loads(report.read_text())
    assert r["ok"] and r["simulation"]["outcome"] == "completed" and r["settings"]["limiter"]["enabled"] is True
    limiter = r["limiter"]
    assert limiter["limited"] and 0 < limiter["min_scale"] < 0.6 and limiter["max_shift"]["x"] > 0.05
    (span,) = limiter["intervals"]  # one stretch, from the ramp before the need to the ramp after
    assert span["start_s"] < 2.0 < span["at_s"] < span["end_s"] < 4.0
    assert span["min_scale"] == limiter["min_scale"] and span["limits"]
    assert set(span["limits"]) <= {"leg_too_long", "spherical_joint_limit", "universal_joint_limit"}
    assert limiter["limited_s"] == pytest.approx(span["end_s"] - span["start_s"] + 0.01, abs=1e-14)  # reached 0


@pytest.mark.parametrize("preset", PRESETS)
def test_glitch_without_the_limiter_is_refused(platforms, preset):
    plat, params = platforms[preset]
    result = washout(_glitch(_at_rest(), 0, 2.0), plat, replace(params, limiter_enabled=False))
    assert result.limiting is None and "limiter" not in result.report()
    assert not result.inside and result.exit_code == 3
    assert np.max(result.reachability.lengths) > plat.params.leg_length_limits[1]
    assert "the reference leaves the workspace" in result.problems[0]
    assert "longer than the maximum length" in result.problems[0]


@pytest.mark.parametrize("preset", PRESETS)
def test_limited_rates_stay_continuous(platforms, preset):
    """A glitch in a sustained turn (tilt held, so a scale that jumped would jump the pose):
    the scale's rate and second derivative within the Hann envelope's bounds ``2 D / T`` and
    ``2 pi D / T^2`` for a drop ``D`` over ``T = ramp_time``; the velocity's change per sample
    within the washout's own plus what those allow, ``(2 pi D / T^2 |e| + 4 D / T |v|) dt``;
    the scale never above any pose's need, and the poses outside the limited stretch the
    washout's own."""
    plat, params = platforms[preset]
    log = _glitch(read_log(os.path.join(EXAMPLES, "constant_radius_turn.csv")), 1, 6.0)
    free = washout(log, plat, replace(params, limiter_enabled=False))
    result = washout(log, plat, params)
    assert not free.inside and result.inside
    lim = result.limiting
    s, dt, ramp = lim.scale, log.dt, params.limiter_ramp_time
    drop = 1.0 - np.min(s)
    assert 0.2 < drop < 0.8 and np.all(s <= lim.need)
    assert np.max(np.abs(np.diff(s))) / dt <= 2 * drop / ramp
    assert np.max(np.abs(np.diff(s, 2))) / dt**2 <= 2 * math.pi * drop / ramp**2
    excursion = np.max(np.abs(free.poses - plat.home_pose), axis=0)
    allowed = (2 * math.pi * drop / ramp**2 * excursion + 4 * drop / ramp * np.max(np.abs(free.velocities), axis=0))
    jumps = np.abs(np.diff(result.velocities, axis=0)) - np.abs(np.diff(free.velocities, axis=0))
    assert np.all(jumps <= allowed * dt)
    # the limited poses keep the margin: stretched by 1 + margin from home, still inside
    home, stretch = plat.home_pose, 1.0 + params.limiter_margin
    assert reachability(plat, home + stretch * (result.poses - home)).ok.all()
    assert not reachability(plat, home + 1.02 * stretch * (result.poses - home)).ok.all()
    untouched = s == 1.0
    assert untouched.sum() > 0.5 * len(s)
    np.testing.assert_array_equal(result.poses[untouched], free.poses[untouched])


def test_limiter_settings_from_toml(tmp_path):
    path = tmp_path / "w.toml"
    path.write_text("[limiter]\nenabled = false\nmargin = 0.25\nramp_time = 2.0\n")
    params = WashoutParams.load(path)
    assert (params.limiter_enabled, params.limiter_margin, params.limiter_ramp_time) == (False, 0.25, 2.0)
    assert params.to_dict()["limiter"] == {"enabled": False, "margin": 0.25, "ramp_time": 2.0}
    assert WashoutParams().to_dict()["limiter"] == {"enabled": True, "margin": 0.1, "ramp_time": 1.0}
    for body, message in (("enabled = 1", "limiter.enabled: must be true or false"),
                          ("margin = -0.1", "limiter.margin: must be a number >= 0"),
                          ("margin = true", "limiter.margin: must be a number >= 0"),
                          ("ramp_time = 0.0", "limiter.ramp_time: must be a number > 0"),
                          ("ramp = 1.0", "[limiter] ramp: unknown setting")):
        path.write_text(f"[limiter]\n{body}\n")
        for platform in (None, PlatformParams.preset("narayan2017")):  # the file named either way
            with pytest.raises(ValueError, match="^" + re.escape(f"{path}: ") + ".*" + re.escape(message)):
                WashoutParams.load(path, platform)


def test_no_limiter_is_the_washouts_switch(tmp_path):
    run = call("cueing", os.path.join(EXAMPLES, "hard_braking.csv"), "--method", "mpc", "--no-limiter",
               "--output", str(tmp_path / "ref.csv"))
    assert run.returncode == 2 and "--no-limiter: the limiter is the washout's" in run.stderr, run.stderr


def test_limiter_keeps_a_sustained_excursion_inside(platforms):
    """Second-order translation at a low cut-off holds a braking's excursion (no return to
    neutral): the limiter holds the scale down for as long, and the reference is the
    washout's own again before the braking starts."""
    plat, params = platforms["motion_simulator"]
    params = replace(params, translation_gain=(1.0, 1.0, 1.0), translation_cutoff=(0.1, 0.1, 0.1),
                     translation_order=2)
    log = read_log(os.path.join(EXAMPLES, "hard_braking.csv"))
    result = washout(log, plat, params)
    assert result.inside and result.exit_code == 0
    free = reference_poses(log, params, plat.home_pose)[0]
    first = np.flatnonzero(result.limiting.active)[0]
    np.testing.assert_array_equal(result.poses[:first], free[:first])
    assert result.limiting.report()["limited_s"] > 1.0


def test_a_pose_the_ray_check_stepped_over_is_tightened(monkeypatch):
    """A workspace ``|x| <= 1`` with a gap at ``0.50 < x < 0.52`` that the ray's points step
    over: the poses sweeping through it are found by the final check and their need tightened
    until the limited reference avoids it; elsewhere it is untouched."""
    from stewart.cueing import limiter

    class Check:
        def __init__(self, poses):
            x = np.atleast_2d(poses)[:, 0]
            self.flags = np.where((np.abs(x) > 1.0) | ((x > 0.50) & (x < 0.52)), 2, 0)
            self.ok = self.flags == 0

    monkeypatch.setattr(limiter, "reachability", lambda platform, poses, name: Check(poses))
    t = np.arange(1001) * 0.01
    poses = np.zeros((len(t), 6))
    poses[:, 0] = 0.6 * np.sin(np.pi * t / 10.0) ** 2
    limited, lim = limiter.limit(t, poses, np.zeros(6), None, margin=0.1, ramp_time=1.0)
    assert lim.passes > 1 and Check(limited).ok.all()
    assert [span["limits"] for span in lim.intervals()] == [["leg_too_long"]]
    assert np.max(limited[:, 0]) <= 0.50
    np.testing.assert_array_equal(limited[lim.scale == 1.0], poses[lim.scale == 1.0])
    assert np.any(lim.scale == 1.0) and np.all(poses[lim.scale == 1.0, 0] < 0.5)


def test_the_scale_leaves_1_exactly_ramp_time_around_the_need(monkeypatch):
    """A workspace ``|x| <= 1`` and a reference at home but for five samples at ``x = 1.5``:
    the moving maximum spreads the need ``ramp_time / 2`` either side and the Hann window
    (all of its weights positive) as far again, so the scale is below 1 exactly within
    ``ramp_time`` of a sample that needs it, and 1, the washout's own pose, everywhere else;
    it reaches the need at the needing samples (a full Hann average of the spread maximum)."""
    from stewart.cueing import limiter

    class Check:
        def __init__(self, poses):
            self.flags = np.where(np.abs(np.atleast_2d(poses)[:, 0]) > 1.0, 2, 0)
            self.ok = self.flags == 0

    monkeypatch.setattr(limiter, "reachability", lambda platform, poses, name: Check(poses))
    dt, ramp = 0.01, 1.0
    t = np.arange(1001) * dt
    poses = np.zeros((len(t), 6))
    poses[500:505, 0] = 1.5
    limited, lim = limiter.limit(t, poses, np.zeros(6), None, margin=0.1, ramp_time=ramp)
    reach = round(ramp / dt)  # 100 samples
    assert np.array_equal(np.flatnonzero(lim.scale < 1.0), np.arange(500 - reach, 505 + reach))
    # the needing samples' scale is their need, 1 / (1.5 (1 + margin)) to the bisection's width:
    # reached 9.5e-7 below it (the bisection keeps the end inside)
    np.testing.assert_allclose(lim.scale[500:505], 1.0 / (1.5 * 1.1), rtol=1e-5)
    assert np.all(lim.scale <= lim.need) and Check(limited).ok.all()
    np.testing.assert_array_equal(limited[lim.scale == 1.0], poses[lim.scale == 1.0])
