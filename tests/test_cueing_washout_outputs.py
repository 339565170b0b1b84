"""stewart.cueing.washout's outputs against hand results: a sustained acceleration below the
tilt limits gives the pitch ``-asin(a_x^low / g)`` in the final pose (the low-pass's step
response in closed form) and, once the translation has washed out, the specific force
``k a``; a sinusoid's specific force is ``k (H_t(jw) + L(jw))`` times it, from the transfer
functions written out by hand (the gain alone in the pass band's low end); and the CLI's
reference CSV and report are the Python API's. Gains, cut-offs, rate and angle limits are
read from :class:`WashoutParams`, never typed in."""

import json
import math
import os

import numpy as np
import pytest

from cli_run import call

from stewart import Platform
from stewart.cueing import VehicleLog, WashoutParams, read_log, vestibular, washout
from stewart.model.params import PlatformParams

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(ROOT, "examples", "cueing")


@pytest.fixture(scope="module")
def simulator():
    plat = Platform(PlatformParams.preset("motion_simulator"))
    return plat, WashoutParams.for_platform(plat)


def _low_pass_step(params: WashoutParams, t: np.ndarray) -> np.ndarray:
    """The unit step response of the tilt low-pass ``w^2 / (s^2 + 2 w s + w^2)`` (critically
    damped): ``1 - (1 + w t) exp(-w t)`` (a double pole, by partial fractions)."""
    assert params.tilt_damping == 1.0, "the closed form is the critically damped one"
    w = params.tilt_cutoff
    return 1.0 - (1.0 + w * t) * np.exp(-w * t)


def test_sustained_acceleration_pitches_the_pose_by_the_arcsine_of_the_low_passed_force(simulator):
    """A braking-like step ``a`` held from t = 0 for 60 s. Tilt coordination's pitch in the
    final pose (after the limiter, which must not act) is ``-asin(k a L_step(t) / g)`` at
    every sample; the step is small enough that neither the rate limit nor the angle limit
    is reached (asserted from the hand result), so the washout's pose must equal it. After
    the translation has washed out (its slowest pole, the break frequency, decays as
    exp(-0.2 t): 6e-6 at 60 s) the platform's specific force along x is ``k a``."""
    plat, params = simulator
    k, g = params.translation_gain[0], params.gravity
    dt, a = 0.02, 1.5
    t = np.arange(0.0, 60.0, dt)
    log = VehicleLog(t, np.tile([a, 0.0, g], (len(t), 1)), np.zeros((len(t), 3)), name="step")
    want = -np.arcsin(k * a * _low_pass_step(params, t) / g)
    # below both limits by hand, so that the hand result is the whole story
    assert np.max(np.abs(want)) < params.tilt_max_angle
    assert np.max(np.abs(np.diff(want))) / dt < 0.9 * params.tilt_rate_limit
    result = washout(log, plat, params)
    assert result.inside and not result.limiting.active.any()
    home = plat.home_pose
    # lsim of a step held from the first sample is exact up to the matrix exponential:
    # 4.6e-16 rad reached (1.2e-15 before), bound 3e-14
    np.testing.assert_allclose(result.poses[:, 4] - home[4], want, rtol=0, atol=3e-14)
    np.testing.assert_array_equal(result.poses[:, [3, 5]], np.tile(home[[3, 5]], (len(t), 1)))
    # the sustained force is felt through the tilt: -g sin(theta) = k a
    f, _ = vestibular.platform_signals(result.poses[-2:-1], np.zeros((1, 6)), np.zeros((1, 6)), g)
    assert f[0, 0] == pytest.approx(k * a, rel=3e-13)  # reached 6.1e-15 (low-pass settled to 1e-23)
    # ... with the translation back home (exp(-0.2 * 60) of a few cm, 3e-7 m; 5.2e-7 m reached):
    # 2e-5 m bound
    assert abs(result.poses[-1, 0] - home[0]) < 2e-5


def _hand_response(params: WashoutParams, w: float) -> complex:
    """``H_t(jw) + L(jw)`` from the module docstring's formulas: the x axis' third-order
    high-pass (second order times ``s / (s + w_b)``) plus the tilt low-pass (small angles:
    ``-g sin(-asin(L a / g)) = L a``)."""
    s = 1j * w
    wt, zt, wb = params.translation_cutoff[0], params.translation_damping, params.translation_break_frequency
    assert params.translation_order == 3
    high = s**2 / (s**2 + 2 * zt * wt * s + wt**2) * s / (s + wb)
    wc, zc = params.tilt_cutoff, params.tilt_damping
    return high + wc**2 / (s**2 + 2 * zc * wc * s + wc**2)


@pytest.mark.parametrize("w, amplitude, dt, seconds, bound", [
    # the pass band's low end, the tilt carries it (|H_t + L - 1| = 6.7e-2): reached 2.1e-6
    # (the small-angle sine and the start transient), bound 3e-5
    (0.05, 0.4, 0.1, 300.0, 3e-5),
    # between, where the break frequency shapes H_t (|H_t| = 2.3e-2): reached 1.3e-5,
    # bound 3e-4 (a 10 % error in the break frequency moves it by 5e-4)
    (0.5, 1.0, 0.02, 80.0, 3e-4),
    # high, the translation carries it (|H_t + L - 1| = 0.32): reached 1.1e-3 (the spline's
    # acceleration at w dt = 0.04), bound 6e-3, well below the 1 - |H| gap
    (20.0, 3.0, 0.002, 8.0, 6e-3),
])
def test_specific_force_is_the_gain_times_the_filters_response(simulator, w, amplitude, dt, seconds, bound):
    """A sinusoidal force ``A sin(w t)`` along x: once the start transient has decayed, the
    platform's specific force (from the reference's poses and spline rates) is the steady
    state ``k |H| A sin(w t + arg H)`` of the hand-written ``H = H_t + L``; the perceived force
    (otoliths, linear) is ``k`` times the vehicle's perceived force but for ``k (H - 1)`` of it,
    at the low frequencies (the tilt channel's band)."""
    plat, params = simulator
    k, g = params.translation_gain[0], params.gravity
    t = np.arange(0.0, seconds, dt)
    f = np.zeros((len(t), 3))
    f[:, 0], f[:, 2] = amplitude * np.sin(w * t), g
    result = washout(VehicleLog(t, f, np.zeros((len(t), 3)), name="sine"), plat, params)
    assert result.inside and not result.limiting.active.any()
    h = _hand_response(params, w)
    want = k * amplitude * np.abs(h) * np.sin(w * t + np.angle(h))
    got, _ = vestibular.platform_signals(result.poses, result.velocities, result.accelerations, g)
    # after five of the slowest pole's time constants (1 / w_b = 5 s; the tilt's at low w)
    # and away from the spline's clamped end (zero velocity at the last sample)
    keep = (t > 0.5 * seconds) & (t < 0.85 * seconds)
    error = np.max(np.abs(got[keep, 0] - want[keep])) / (k * amplitude)
    print(f"washout's specific force at {w} rad/s against k (H_t + L): {error:.2e} of k A")
    assert error < bound
    if w < 1:
        # the perceived force (the otoliths are linear, O) is k times the vehicle's but for
        # k (H - 1) O a: its amplitude is |H - 1| of k times the vehicle's perceived amplitude
        perceived = np.max(np.abs(result.platform.f[keep, 0] - k * result.vehicle.f[keep, 0]))
        perceived /= k * np.max(np.abs(result.vehicle.f[keep, 0]))
        print(f"perceived against k times the vehicle's: {perceived:.4e}, |H - 1| = {abs(h - 1):.4e}")
        assert perceived == pytest.approx(abs(h - 1), rel=2e-3)  # reached < 1e-4 (the sampled peak)


def test_cli_reference_and_report_are_the_apis(simulator, tmp_path):
    """``stewart cueing LOG --output --report`` in-process: the CSV's columns are the API's
    time, poses, rates and accelerations (written with 17 significant digits: bit for bit),
    and the report's numbers are the API's report."""
    plat, params = simulator
    path = os.path.join(EXAMPLES, "hard_braking.csv")
    run = call("cueing", path, "--output", tmp_path / "ref.csv", "--report", tmp_path / "r.json")
    assert run.returncode == 0, run.stderr
    result = washout(read_log(path), plat, params)
    data = np.loadtxt(tmp_path / "ref.csv", delimiter=",", comments="#", skiprows=1)
    want = np.column_stack([result.t, result.poses, result.velocities, result.accelerations])
    np.testing.assert_array_equal(data, want)
    report = json.loads((tmp_path / "r.json").read_text())
    expected = json.loads(json.dumps(result.report()))
    assert report == expected
    # and the API's numbers are those of the reference it wrote, not only self-consistent
    assert report["peak_excursion"]["theta"] == np.max(np.abs(result.poses[:, 4] - result.poses[0, 4]))
    assert report["settings"]["tilt"]["rate_limit"] == pytest.approx(math.degrees(params.tilt_rate_limit), rel=1e-15)
    log = np.loadtxt(path, delimiter=",", comments="#", skiprows=1)  # the log's own times
    # the interval is the mean step, against the first step here: reached 0
    assert report["duration_s"] == log[-1, 0] - log[0, 0] and report["dt_s"] == pytest.approx(log[1, 0] - log[0, 0],
                                                                                             rel=1e-12)


def test_defaults_are_the_cited_ones(simulator):
    """The tests above read the gains and limits from WashoutParams; the defaults themselves
    are the sources': the tilt rate limit 3 deg/s, the roll threshold of Telban & Cardullo
    (2005, table 2) that Reid & Nahon (1985) hold tilt coordination below; the tilt angle
    limit at most 10 deg and half the platform's smaller roll or pitch excursion
    (for_platform's documentation); gravity 9.81 m/s^2, the logs' (examples/cueing)."""
    plat, params = simulator
    assert params.tilt_rate_limit == WashoutParams().tilt_rate_limit == math.radians(3.0)
    assert params.tilt_rate_limit == vestibular.THRESHOLDS["wx"]
    from stewart.model.reachability import axis_excursions

    excursions = axis_excursions(plat)
    assert params.tilt_max_angle == pytest.approx(min(math.radians(10.0), 0.5 * min(excursions[3:5])), rel=1e-15)
    assert params.gravity == 9.81 and read_log(os.path.join(EXAMPLES, "hard_braking.csv")).f[0, 2] == 9.81


def test_figures_plot_each_channel_and_pose_axis_in_its_panel(simulator, tmp_path, monkeypatch):
    """CueingResult.plot: each perceived channel's panel (fx, fy, fz down the left, wx, wy, wz
    down the right) holds the vehicle's and the reference's perceived signal; the reference's
    figure holds the position from home of x, y, z [m] above and the angles from home of psi,
    theta, phi [deg] below, each its own pose column."""
    pytest.importorskip("matplotlib")
    import matplotlib.figure

    plat, params = simulator
    t = np.arange(0.0, 3.0, 0.02)
    f = np.column_stack([np.sin(t), 0.5 * np.sin(2 * t), 9.81 + 0.3 * np.sin(3 * t)])
    w = np.column_stack([0.1 * np.sin(t), 0.05 * np.sin(1.5 * t), 0.2 * np.sin(0.7 * t)])
    result = washout(VehicleLog(t, f, w, name="sines"), plat, params)
    figures = []  # (not rendered: the CLI's test checks the files)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda fig, *a, **k: figures.append(fig))
    paths = result.plot(tmp_path)
    assert [os.path.basename(p) for p in paths] == ["cueing_perceived.png", "cueing_reference.png"]
    perceived, reference = figures
    for j, name in enumerate(("fx", "fy", "fz", "wx", "wy", "wz")):
        ax = perceived.axes[2 * (j % 3) + j // 3]  # a 3 x 2 grid, row by row
        assert name in ax.get_ylabel()
        lines = {line.get_label(): line.get_ydata() for line in ax.get_lines()}
        np.testing.assert_array_equal(lines["vehicle"], result.vehicle.channels[:, j])
        np.testing.assert_array_equal(lines["reference"], result.platform.channels[:, j])
    positions, angles = reference.axes
    d = result.poses - result.poses[0]
    assert np.max(np.abs(d), axis=0).min() > 0  # every axis moves: no panel could pass empty
    for ax, columns, factor in ((positions, range(3), 1.0), (angles, range(3, 6), 180 / math.pi)):
        lines = {line.get_label(): line.get_ydata() for line in ax.get_lines()}
        assert sorted(lines) == sorted(("x", "y", "z") if factor == 1.0 else ("psi", "theta", "phi"))
        for k, name in zip(columns, ("x", "y", "z", "psi", "theta", "phi")[columns[0]:]):
            np.testing.assert_allclose(lines[name], d[:, k] * factor, rtol=1e-15, atol=0)
