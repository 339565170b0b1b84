"""stewart.cueing: washout filters against their transfer functions, the vestibular model
against its published constants, the platform's perceived gravity by hand, the shipped
maneuvers inside motion_simulator's workspace, and the CLI's one-line errors."""

import math
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from cli_run import call

import stewart.cueing
from stewart.cueing import VehicleLog, WashoutParams, read_log, vestibular, washout
from stewart.cueing.log import RATE_TOLERANCE
from stewart.cueing.classical import filters, reference_poses
from stewart.model.params import PlatformParams
from stewart.motion.trajectory import SampledTrajectory

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(ROOT, "examples", "cueing")
MANEUVERS = ["double_lane_change", "hard_braking", "constant_radius_turn", "slalom", "takeoff_roll"]
W = np.logspace(-3, 3, 400)


def _relative(a, b):
    return np.max(np.abs(a - b) / np.abs(b))


@pytest.mark.parametrize("order", [2, 3])
def test_washout_frequency_responses_match_transfer_functions(order):
    p = WashoutParams(translation_cutoff=(0.8, 1.3, 2.1), translation_damping=0.7, translation_order=order,
                      translation_break_frequency=0.35, rotation_cutoff=(0.9, 1.1, 0.5), rotation_damping=0.8,
                      tilt_cutoff=1.7, tilt_damping=0.9)
    fs = filters(p)
    s = 1j * W
    for i, axis in enumerate("xyz"):
        wn = p.translation_cutoff[i]
        hp = s**2 / (s**2 + 2 * 0.7 * wn * s + wn**2) * (s / (s + 0.35) if order == 3 else 1.0)
        assert _relative(signal.freqresp(fs[f"translation_{axis}"], W)[1], hp) <= 5e-14  # reached 5.3e-16 over all
        assert _relative(signal.freqresp(fs[f"position_{axis}"], W)[1], hp / s**2) <= 5e-14
        wr = p.rotation_cutoff[i]
        hr = s**2 / (s**2 + 2 * 0.8 * wr * s + wr**2)
        assert _relative(signal.freqresp(fs[f"rotation_{axis}"], W)[1], hr) <= 5e-14
        assert _relative(signal.freqresp(fs[f"angle_{axis}"], W)[1], hr / s) <= 5e-14
    lp = 1.7**2 / (s**2 + 2 * 0.9 * 1.7 * s + 1.7**2)
    assert _relative(signal.freqresp(fs["tilt"], W)[1], lp) <= 5e-14


def _step(t):
    u = np.ones((len(t), 3))
    u[0] = 0.0
    return u


def test_otolith_step_response_young_meiry_1968():
    # Young & Meiry 1968: K = 0.4, tau_a = 13.2 s, tau_L = 5.33 s, tau_S = 0.66 s; step response
    # K [1 + (ta - tL)/(tL - tS) exp(-t/tL) + (ta - tS)/(tS - tL) exp(-t/tS)] by partial fractions
    k, ta, tl, ts = 0.4, 13.2, 5.33, 0.66
    t = np.arange(0, 40, 1e-3)
    got = vestibular.perceive(t, _step(t), np.zeros((len(t), 3))).f[:, 0]
    s = np.maximum(t - 0.5e-3, 0.0)  # the sampled step rises over the first interval: centred half a step late
    want = k * (1 + (ta - tl) / (tl - ts) * np.exp(-s / tl) + (ta - ts) / (ts - tl) * np.exp(-s / ts))
    assert np.max(np.abs(got - want)[1:]) <= 1e-6 * k  # reached 2.5e-7 k (the step's first interval)
    # the steady state is K: at 40 s the closed form is still 9.3e-4 K above it (its exp(-t/tau_L) term)
    assert got[-1] == pytest.approx(k, rel=2e-3)


def test_canal_step_response_telban_cardullo_2005():
    # Telban & Cardullo 2005: tau_L = 5.73 s, tau_S = 0.005 s, tau_a = 80 s; step response of
    # tau_a tau_L s^2 / ((tau_a s+1)(tau_L s+1)(tau_S s+1)) as a sum of residues
    ta, tl, ts = 80.0, 5.73, 0.005
    t = np.arange(0, 30, 2e-4)
    got = vestibular.perceive(t, np.zeros((len(t), 3)), _step(t)).w[:, 2]
    poles = [-1 / ta, -1 / tl, -1 / ts]
    s = np.maximum(t - 1e-4, 0.0)  # the sampled step, centred half a step late
    want = sum((p / ts) / np.prod([p - q for q in poles if q != p]) * np.exp(p * s) for p in poles)
    assert np.max(np.abs(got - want)[1:]) <= 1e-4  # reached 6.5e-5 (the step's first interval vs tau_S)
    # after the short time constant the perception is near 1 and decays with tau_L (and tau_a):
    # the closed form's peak is 1 - 6.5e-3 (tau_S / tau_L and tau_L / tau_a below 1)
    assert np.max(got) == pytest.approx(1.0, abs=0.01)


def test_static_tilt_is_gravity_rotated():
    g = 9.81
    phi, theta, psi = 0.1, -0.05, 0.3
    pose = np.array([[0.0, 0.0, 1.5, psi, theta, phi]])
    f, w = vestibular.platform_signals(pose, np.zeros((1, 6)), np.zeros((1, 6)), g)
    # gravity's reaction [0, 0, g] of {B} in the frame R = Rz Ry Rx: g * (third row of R)
    want = g * np.array([-math.sin(theta), math.cos(theta) * math.sin(phi), math.cos(theta) * math.cos(phi)])
    np.testing.assert_allclose(f[0], want, rtol=0, atol=1e-14)  # reached 0; a few ulp of g
    np.testing.assert_array_equal(w[0], 0.0)


def test_platform_rotation_rate_in_its_frame():
    # pure roll rate at a yawed pose: the platform feels it about its own x axis
    pose = np.array([[0, 0, 1.5, 0.7, 0.0, 0.2]])
    xd = np.array([[0, 0, 0, 0, 0, 0.3]])
    _, w = vestibular.platform_signals(pose, xd, np.zeros((1, 6)))
    np.testing.assert_allclose(w[0], [0.3, 0, 0], rtol=0, atol=1e-15)  # reached 5.6e-17


def test_maneuvers_are_reproduced(tmp_path):
    subprocess.run([sys.executable, os.path.join(EXAMPLES, "make_maneuvers.py"), str(tmp_path)], check=True,
                   capture_output=True)
    made_names = sorted(path.stem for path in tmp_path.glob("*.csv"))
    assert made_names == sorted(MANEUVERS + ["racing_lap"])
    for name in made_names:
        made, shipped = (np.loadtxt(path, delimiter=",", skiprows=2) for path in
                         (tmp_path / f"{name}.csv", os.path.join(EXAMPLES, f"{name}.csv")))
        # to the files' ten significant digits: a value on a rounding tie may print either way
        # with another numpy's sin and cos
        np.testing.assert_allclose(made, shipped, rtol=1e-9, atol=0, err_msg=name)


def _washout_setup(preset):
    from stewart import Platform

    plat = Platform(PlatformParams.preset(preset))
    return plat, WashoutParams.for_platform(plat)


@pytest.fixture(scope="module")
def simulator():
    return _washout_setup("motion_simulator")


@pytest.fixture(scope="module")
def paper_platform():
    return _washout_setup("narayan2017")


@pytest.mark.parametrize("preset", ["paper_platform", "simulator"])
@pytest.mark.parametrize("name", MANEUVERS)
def test_shipped_maneuvers_stay_inside_unlimited(request, preset, name):
    """Each shipped maneuver's washout stays inside the limiter's margin on both presets:
    the limiter changes no pose, bit for bit."""
    plat, params = request.getfixturevalue(preset)
    log = read_log(os.path.join(EXAMPLES, f"{name}.csv"))
    result = washout(log, plat, params)
    assert result.inside, result.problems
    assert result.exit_code == 0
    assert not result.limiting.active.any() and result.report()["limiter"]["limited"] is False
    poses, parts = reference_poses(log, params, plat.home_pose)
    np.testing.assert_array_equal(result.poses, poses)
    # the pose's roll and pitch are the high-pass angles plus tilt coordination's (roll, pitch),
    # the translation the high-pass's: home + parts, to rounding (reached 0, bound 1e-15)
    home = plat.home_pose
    parts_pose = home + np.column_stack([parts["translation"], parts["angles"][:, 2],
                                         parts["angles"][:, 1] + parts["tilt"][:, 1],
                                         parts["angles"][:, 0] + parts["tilt"][:, 0]])
    np.testing.assert_allclose(result.poses, parts_pose, rtol=0, atol=1e-15)
    # tilt coordination's rate within WashoutParams' limit (3 deg/s, below the canals'
    # threshold), and its angle within the limit
    rate = np.abs(np.diff(parts["tilt"], axis=0)) / log.dt
    assert np.max(rate) <= params.tilt_rate_limit * (1 + 1e-12)
    assert np.max(np.abs(parts["tilt"])) <= params.tilt_max_angle
    # the tilt is -asin(a_x^low / g) (pitch) and asin(a_y^low / g) (roll), clipped to the angle
    # limit and followed at most at the rate limit (a rate limiter's definition, written out
    # here; the low-pass by lsim of the tilt filter): reached 0, bound 1e-15 rad (a few ulp of the
    # 0.17 rad limit)
    k, g = np.asarray(params.translation_gain), params.gravity
    acc = k * (log.f - [0.0, 0.0, g])
    low = [signal.lsim(filters(params)["tilt"], acc[:, i], log.t - log.t[0])[1] for i in (0, 1)]
    wanted = np.clip(np.column_stack([np.arcsin(low[1] / g), -np.arcsin(low[0] / g)]),
                     -params.tilt_max_angle, params.tilt_max_angle)
    step = params.tilt_rate_limit * log.dt
    by_hand = [wanted[0]]
    for target in wanted[1:]:
        by_hand.append(by_hand[-1] + np.clip(target - by_hand[-1], -step, step))
    np.testing.assert_allclose(parts["tilt"], by_hand, rtol=0, atol=1e-15)
    # the perceived error is the RMS of the perceived platform's minus the vehicle's (by hand)
    for j, channel in enumerate(("fx", "fy", "fz", "wx", "wy", "wz")):
        by_hand = math.sqrt(np.mean((result.platform.channels[:, j] - result.vehicle.channels[:, j]) ** 2))
        # reached 0; a bound of a few ulp
        assert result.metrics["perceived_error_rms"][channel] == pytest.approx(by_hand, rel=1e-14, abs=1e-300)
    # the reference starts at home, at rest (reached 0, bound 2e-15: a few ulp of the 1.08 m height)
    np.testing.assert_allclose(result.poses[0], plat.home_pose, rtol=0, atol=2e-15)
    np.testing.assert_allclose(result.velocities[0], 0.0, rtol=0, atol=2e-15)


def test_tilt_rate_is_limited():
    t = np.arange(0, 20, 0.01)
    f = np.tile([0.0, 0.0, 9.81], (len(t), 1))
    f[t >= 1, 0] = 4.0  # sustained acceleration: tilt coordination pitches nose up
    log = VehicleLog(t, f, np.zeros((len(t), 3)))
    params = WashoutParams(tilt_max_angle=math.radians(15))
    limit, k, g = params.tilt_rate_limit, params.translation_gain[0], params.gravity
    poses, parts = reference_poses(log, params, np.zeros(6))
    # in the pose, not only in the parts (no rotation rates in the log: the pitch is the tilt)
    np.testing.assert_array_equal(poses[:, 4], parts["tilt"][:, 1])
    rate = np.abs(np.diff(poses[:, 4])) / log.dt
    assert np.max(rate) <= limit * (1 + 1e-12)
    # the step asks for more than the limit, so the pitch ramps at exactly the limit (the
    # low-pass's steepest slope k a w / e / g = 0.11 rad/s > 0.052): 1 s of it at least (3.8 s)
    ramp = np.abs(rate - limit) <= 1e-9 * limit
    assert np.count_nonzero(ramp) >= round(1.0 / log.dt)
    # settles at -asin(gain * a / g) = -11.8 deg, within the 15 deg limit: after 19 s the
    # low-pass (w = 1.5 rad/s, critically damped) is within (1 + w t) exp(-w t) = 5e-11 of its
    # final value (1.3e-11 reached in the pitch, bound 1e-9)
    assert -math.asin(k * 4.0 / g) > -params.tilt_max_angle
    assert poses[-1, 4] == pytest.approx(-math.asin(k * 4.0 / g), rel=1e-9)


def _cli(*args):
    return call(*args)


def _write(path, text):
    path.write_text(text)
    return str(path)


HEADER = "t,fx,fy,fz,wx,wy,wz\n"


@pytest.mark.parametrize("body, message", [
    (HEADER + "0,0,0,9.81,0,0,0\n0.01,nan,0,9.81,0,0,0\n0.02,0,0,9.81,0,0,0\n", "line 3, column 2"),
    (HEADER + "0,0,0,9.81,0,0,0\n0.02,0,0,9.81,0,0,0\n0.01,0,0,9.81,0,0,0\n", "row 3: time goes backwards"),
    (HEADER + "0,0,0,9.81,0,0,0\n0.01,0,0,9.81,0,0,0\n0.03,0,0,9.81,0,0,0\n", "row 3: uneven sample rate"),
    ("t,ax,ay\n0,0,0\n0.01,0,0\n", "lacks fx"),
])
def test_cli_bad_logs_give_one_line_errors(tmp_path, body, message):
    log = _write(tmp_path / "log.csv", body)
    run = _cli("cueing", log, "--output", str(tmp_path / "ref.csv"))
    assert run.returncode == 2
    assert "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert message in run.stderr, run.stderr
    assert not (tmp_path / "ref.csv").exists()


def test_cli_negative_limit_and_mpc(tmp_path):
    cfg = _write(tmp_path / "c.toml", "[tilt]\nrate_limit = -3.0\n")
    log = os.path.join(EXAMPLES, "hard_braking.csv")
    run = _cli("cueing", log, "--cueing", cfg, "--output", str(tmp_path / "ref.csv"))
    assert run.returncode == 2 and "rate_limit: must be a number >= 0" in run.stderr, run.stderr
    assert "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1
    for body, message in (("[limits]\nforce = -1.0\n", "limits.force: must be a number > 0"),
                          ("[horizon]\nduration = 0.05\nsteps = 10\n", "horizon.duration: 0.05 s with 10 steps"),
                          ("[horizon]\nsteps = 1\n", "horizon.steps: must be an integer >= 2"),
                          ("[limits]\nmargin = 1.5\n", "limits.margin: must be below 1")):
        cfg = _write(tmp_path / "m.toml", body)
        run = _cli("cueing", log, "--method", "mpc", "--cueing", cfg, "--output", str(tmp_path / "ref.csv"))
        assert run.returncode == 2 and message in run.stderr, run.stderr
        assert "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert not (tmp_path / "ref.csv").exists()


def test_cli_reference_outside_workspace_has_its_own_exit_code(tmp_path):
    """Without the limiter (tests/test_washout_limiter.py brings this braking back inside)."""
    cfg = _write(tmp_path / "c.toml", "[translation]\ngain = 1.0\ncutoff = 0.1\norder = 2\n")
    log = os.path.join(EXAMPLES, "hard_braking.csv")
    run = _cli("cueing", log, "--cueing", cfg, "--no-limiter", "--output", str(tmp_path / "ref.csv"),
               "--report", str(tmp_path / "r.json"))
    assert run.returncode == 3, run.stderr
    assert "leaves the workspace" in run.stderr
    assert not (tmp_path / "ref.csv").exists()
    import json

    report = json.loads((tmp_path / "r.json").read_text())
    assert report["ok"] is False and report["inside_workspace"] is False and report["exit_code"] == 3


def test_cli_reference_feeds_simulate(tmp_path):
    log = os.path.join(EXAMPLES, "hard_braking.csv")
    ref = tmp_path / "ref.csv"
    run = _cli("cueing", log, "--output", str(ref), "--report", str(tmp_path / "r.json"))
    assert run.returncode == 0, run.stderr
    traj = SampledTrajectory.from_csv(ref)
    data = np.loadtxt(ref, delimiter=",", skiprows=2)
    # the Hermite spline's rates at its knots are the file's: reached 2.8e-17, bound 2e-15
    np.testing.assert_allclose(traj.sample(data[:, 0])[1], data[:, 7:13], rtol=0, atol=2e-15)
    run = _cli("simulate", "--preset", "motion_simulator", "--trajectory", str(ref), "--controller", "ct",
               "--dt", "0.002", "--json")
    assert run.returncode == 0, run.stderr


_FLOATS = st.floats(allow_nan=True, allow_infinity=True, width=64)


@settings(max_examples=60, deadline=None)
@given(n=st.integers(0, 6), rows=st.lists(st.lists(_FLOATS, min_size=7, max_size=7), min_size=0, max_size=6),
       ragged=st.booleans(), junk=st.sampled_from([None, {}, "abc", object()]))
def test_fuzz_vehicle_log_is_valid_or_a_named_value_error(n, rows, ragged, junk):
    """Any arrays give a log whose samples are finite and evenly spaced, or a ValueError
    naming the log; nothing else escapes."""
    data = np.array(rows, dtype=float).reshape(-1, 7)
    t = np.arange(len(data)) * 0.01 if n % 2 else data[:, 0]
    f, w = (data[:, 1:4][:, :2] if ragged else data[:, 1:4]), data[:, 4:7]
    for args in ((t, f, w), (junk, f, w), (t, junk, w)):
        try:
            log = VehicleLog(*args, name="fuzzed")
        except ValueError as exc:
            assert str(exc).startswith("fuzzed: ")
            continue
        assert np.all(np.isfinite(log.t)) and np.all(np.isfinite(log.f)) and np.all(np.isfinite(log.w))
        # the log's own test of an even rate (reached 1.7e-16 on these)
        assert np.allclose(np.diff(log.t), log.dt, rtol=RATE_TOLERANCE, atol=0)


@settings(max_examples=8, deadline=None)
@given(scale=st.floats(0.0, 3.0), seed=st.integers(0, 2**16))
def test_fuzz_washout_is_finite_and_limited_into_the_workspace(simulator, scale, seed):
    """A random smooth log of up to 3 g and 3 rad/s gives a finite reference that the limiter
    keeps inside the workspace; reported inside exactly when it is (never NaN, never a
    silent success)."""
    rng = np.random.default_rng(seed)
    t = np.arange(301) * 0.01
    f = np.column_stack([scale * 9.81 * np.sin(rng.uniform(0.2, 3) * t) for _ in range(3)]) + [0, 0, 9.81]
    w = np.column_stack([scale * np.sin(rng.uniform(0.2, 3) * t) for _ in range(3)])
    plat, params = simulator
    result = washout(VehicleLog(t, f, w, name="random"), plat, params)
    assert np.all(np.isfinite(result.poses))
    assert result.inside and not result.problems and result.exit_code == 0


def test_metrics_against_hand_values():
    """stewart.cueing.metrics.compare on signals built to known answers: a Gaussian pulse and
    the same pulse 0.3 s later (delay 0.3 s, the cross-correlation's peak by symmetry), a
    signal and -2 times it plus a constant (correlation -1), constant channels (no
    correlation, no delay), and a platform rate above the yaw threshold for 0.25 s while the
    vehicle's is still (0.25 s of false cue)."""
    from stewart.cueing import metrics
    from stewart.cueing.vestibular import THRESHOLDS, Perceived

    dt = 0.01
    t = np.arange(1000) * dt
    pulse = lambda centre: np.exp(-(((t - centre) / 0.2) ** 2))  # noqa: E731
    wave = np.sin(2 * np.pi * 0.3 * t)
    yaw = np.where((t >= 2.0 - dt / 2) & (t < 2.25 - dt / 2), 2.0 * THRESHOLDS["wz"], 0.0)
    vehicle = Perceived(t, np.column_stack([pulse(3.0), wave, np.full_like(t, 9.81)]),
                        np.column_stack([0.1 * wave, 0 * t, 0 * t]))
    platform = Perceived(t, np.column_stack([pulse(3.3), -2.0 * wave + 0.5, np.full_like(t, 9.81)]),
                         np.column_stack([0 * t + 0.01, 0 * t, yaw]))
    m = metrics.compare(vehicle, platform)
    assert m["delay_s"]["fx"] == pytest.approx(0.3, abs=1e-12)
    assert m["delay_s"]["fz"] is None and m["delay_s"]["wx"] is None  # a constant signal has no lag
    assert m["correlation"]["fy"] == pytest.approx(-1.0, abs=1e-12)
    assert m["correlation"]["fx"] == pytest.approx(np.corrcoef(pulse(3.0), pulse(3.3))[0, 1], rel=1e-12)
    # either signal constant: no correlation (not NaN)
    assert m["correlation"]["fz"] is None and m["correlation"]["wx"] is None and m["correlation"]["wz"] is None
    # RMS of the difference: -3 sin + 0.5 has mean square 9/2 + 1/4 over whole periods (10 s of 0.3 Hz: 3)
    assert m["perceived_error_rms"]["fy"] == pytest.approx(math.sqrt(4.5 + 0.25), rel=1e-12)
    assert m["perceived_error_rms"]["fz"] == 0.0
    # 25 samples of yaw rate twice the threshold while the vehicle's is zero
    assert m["false_cue_s"]["wz"] == pytest.approx(0.25, abs=1e-12)
    assert m["false_cue_s"]["fz"] == 0.0 and m["false_cue_s"]["wy"] == 0.0


@pytest.mark.parametrize("degrees", [90.0, 120.0, -5.0])
def test_tilt_angle_limit_outside_0_to_90_degrees_is_refused(degrees):
    """tilt.max_angle in [0, 90) deg: a tilt of 90 deg or more (gravity no longer a forward
    force) or below 0 is a ValueError naming the setting and the value in degrees."""
    with pytest.raises(ValueError, match=r"^defaults: tilt\.max_angle: must be in \[0, 90\) deg, got ") as error:
        WashoutParams(tilt_max_angle=math.radians(degrees))
    assert float(str(error.value).rsplit(" ", 1)[1]) == pytest.approx(degrees, rel=1e-14)  # the radians' round trip
    assert WashoutParams(tilt_max_angle=math.radians(89.9)).tilt_max_angle == math.radians(89.9)


def test_the_washout_converts_its_platform_once_where_it_enters(conversions):
    """The rule of stewart.model for the runs of stewart.cueing: the washout converts its
    platform argument once, in stewart.cueing.runners, and compiles it once; the settings'
    defaults, the limiter, the report and the closed loop take the converted Platform."""
    log = read_log(os.path.join(EXAMPLES, "hard_braking.csv"))
    log = VehicleLog(log.t[:50], log.f[:50], log.w[:50], "start")
    count = conversions("stewart.cueing")
    result = stewart.cueing.washout(log, PlatformParams.preset("motion_simulator"), simulate=True)
    assert len(result.poses) == 50 and result.simulation.completed
    assert count == {"stewart.cueing.runners": 1, "compiled": 1}


def test_racing_lap_stays_within_its_grip():
    """The lap's car never exceeds the grip its docstring names: 14 m/s^2 cornering (to the
    interpolation between path samples), 6 m/s^2 traction, 12 m/s^2 braking; a flying lap."""
    lap = np.loadtxt(os.path.join(EXAMPLES, "racing_lap.csv"), delimiter=",", skiprows=2)
    t, ax, ay, fz, wz = lap[:, 0], lap[:, 1], lap[:, 2], lap[:, 3], lap[:, 6]
    assert np.all(np.diff(t) > 0) and 50.0 < t[-1] < 70.0
    assert -12.0 - 1e-6 <= ax.min() and ax.max() <= 6.0 + 1e-6
    assert 13.0 < np.abs(ay).max() <= 14.0 * 1.01
    speed = ay[np.abs(wz) > 0.05] / wz[np.abs(wz) > 0.05]  # ay = v^2 kappa, wz = v kappa
    assert speed.min() > 5.0 and speed.max() < 70.0
    assert np.count_nonzero(fz != 9.81) > 0 and np.abs(fz - 9.81).max() <= 2.5
