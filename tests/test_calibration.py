"""Kinematic calibration (stewart.calibration): the estimates against a simulated built
machine at the rate their standard errors promise (with the noise the fit assumes, and with
a tracker's noise it does not at stated standard deviations three times too large or
small), measured poses at the stroke ends, a fit that does not converge, the held-out pose
error, the named unidentifiable combinations against their hand derivation, the designed
poses against random ones, and the command line. (The residuals and Jacobians themselves:
test_calibration_geometry.py.)"""

import json
import re

import numpy as np
import pytest
from cli_outputs import check_calibration_poses
from cli_run import run as _run

import stewart
from stewart.calibration import (
    CalibrationData,
    UnidentifiableError,
    calibrate,
    geometry,
    perturbed_geometry,
    simulate_measurements,
)
from stewart.calibration.design import design_poses, observability
from stewart.calibration.validation import pose_errors
from stewart.cli import main

NOMINAL = stewart.PlatformParams.preset("narayan2017")
# The campaign: +-1 mm per joint coordinate, +-2 mm per offset; a 10 um tracker, a 1 um encoder.
POSITION_STD, ANGLE_STD, LENGTH_STD = 1e-5, 1e-4, 1e-6


@pytest.fixture(scope="module")
def designed():
    return design_poses(NOMINAL, 30, seed=1)


#: The half-widths of the box of random poses about home [m, rad], per preset.
_BOXES = {"narayan2017": [0.02] * 3 + [0.2] * 3, "motion_simulator": [0.2] * 6}


def _random_poses(n, seed, nominal=NOMINAL):
    rng = np.random.default_rng(seed)
    home = stewart.home_pose(nominal)
    poses = home + rng.uniform(-1, 1, (4 * n, 6)) * np.array(_BOXES[nominal.name])
    return poses[stewart.reachability(nominal, poses).ok][:n]


def _hand_rotation(psi, theta, phi):
    """``R = Rz(psi) Ry(theta) Rx(phi)`` written out element by element (Z-Y-X Euler angles),
    independent of stewart.calibration.geometry and the kernel."""
    cz, sz, cy, sy, cx, sx = np.cos(psi), np.sin(psi), np.cos(theta), np.sin(theta), np.cos(phi), np.sin(phi)
    return np.array([[cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx],
                     [sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx],
                     [-sy, cy * sx, cy * cx]])


def _hand_leg_lengths(params, poses):
    """Leg lengths ``|t + R p_i - b_i|`` built by hand with numpy (:func:`_hand_rotation`) at the
    poses ``(x, y, z, psi, theta, phi)``."""
    out = []
    for x, y, z, psi, theta, phi in np.atleast_2d(poses):
        rot = _hand_rotation(psi, theta, phi)
        legs = [np.array([x, y, z]) + rot @ p - b for b, p in zip(params.base_points, params.platform_points)]
        out.append([np.sqrt(leg @ leg) for leg in legs])
    return np.array(out)


def test_readings_and_residuals_against_a_hand_built_leg():
    """The encoder reading is the hand-built leg's length less its offset (e = |l| - delta),
    for simulated measurements, the nominal's designed campaign and encoder_readings; the
    model's residual ``e + delta - |l|`` of readings off by a known amount is that amount
    (reached 7.8e-17 m, one rounding of the 0.3 m lengths; bound 2e-15 m)."""
    built = perturbed_geometry(NOMINAL, seed=5)
    poses = _random_poses(8, 9)
    want = _hand_leg_lengths(built, poses) - built.leg_length_offsets
    assert np.ptp(built.leg_length_offsets) > 1e-3  # the offsets matter at this bound
    data = simulate_measurements(built, poses, length_std=0.0, position_std=0.0, angle_std=0.0)
    np.testing.assert_allclose(data.readings, want, rtol=0, atol=2e-15)
    np.testing.assert_allclose(stewart.encoder_readings(built, poses), want, rtol=0, atol=2e-15)
    shift = np.linspace(-1e-3, 1e-3, 6)
    residuals = geometry.leg_residuals(geometry.parameter_vector(built), poses, want + shift)
    np.testing.assert_allclose(residuals, np.tile(shift, (len(poses), 1)), rtol=0, atol=2e-15)


def test_calibration_residuals_are_the_hand_built_legs(designed):
    """The calibration's RMS residual per leg, before and after, is that of the measured
    reading plus the offset less the hand-built leg's length at the measured pose, with the
    nominal and with the calibrated geometry (relative difference reached 5e-13 where the
    residual, 1e-5 m, is the difference of 0.3 m lengths; bound 2e-11); after, it is the
    encoders' and tracker's noise, not the millimetres of the build."""
    truth = perturbed_geometry(NOMINAL, seed=11)
    data = simulate_measurements(truth, designed.poses, seed=1)
    result = calibrate(NOMINAL, data)
    np.testing.assert_array_equal(result.poses, data.poses)
    for params, rms in ((NOMINAL, result.rms_before), (result.params, result.rms_after)):
        residual = data.readings + params.leg_length_offsets - _hand_leg_lengths(params, data.poses)
        np.testing.assert_allclose(rms, np.sqrt(np.mean(residual**2, axis=0)), rtol=2e-11, atol=0)
    # before: the build's millimetres (0.3-2.8 mm reached); after: the tracker's 1e-5 m and
    # 1e-4 rad noise (1.1e-5 m reached, bound 3e-5 m)
    assert np.max(result.rms_before) > 5e-4 and np.max(result.rms_after) < 3e-5


def test_estimates_lie_within_their_standard_errors_at_the_expected_rate(designed):
    """Over 12 built machines and campaigns with the noise the fit assumes, the share of the
    42 estimates within 2 standard errors of the truth is that of a normal distribution,
    95.4 % (a binomial spread of ~1 % were the estimates independent; a machine's 42 are
    correlated, so the band is wider: the whitened test below is the sharp one)."""
    within = []
    for seed in range(12):
        truth = perturbed_geometry(NOMINAL, seed=100 + seed)
        data = simulate_measurements(truth, designed.poses, position_std=POSITION_STD, angle_std=ANGLE_STD,
                                     length_std=LENGTH_STD, seed=seed)
        result = calibrate(NOMINAL, data, position_std=POSITION_STD, angle_std=ANGLE_STD, length_std=LENGTH_STD)
        within.append(np.abs(result.estimates - geometry.parameter_vector(truth)) <= 2 * result.standard_errors)
        # s^2 is chi^2_dof / dof (dof = 138): s spreads by 1 / sqrt(2 dof) = 0.06; within 3.3 of it
        assert abs(result.sigma - 1.0) < 3.3 / np.sqrt(2 * result.dof)
    share = np.mean(within)
    print(f"calibration: {100 * share:.1f} % of {np.size(within)} estimates within 2 standard errors")
    assert 0.92 <= share <= 0.985


def _tracker_campaign(truth, poses, scale, seed):
    """Pose measurements of ``truth`` at ``poses`` with noise the fit is not told of: the
    tracker's position noise ``scale[0]`` times POSITION_STD per coordinate, its orientation
    noise a small rotation of {P} about the axes of {B} of ``scale[1]`` times ANGLE_STD per
    axis (not noise on the Euler angles, which the fit assumes), and ``scale[2]`` times
    LENGTH_STD on the encoders."""
    from scipy.spatial.transform import Rotation

    from stewart.model.kinematics import rotation

    rng = np.random.default_rng(seed)
    readings = stewart.leg_lengths(truth, poses) - truth.leg_length_offsets
    readings = readings + rng.normal(0.0, scale[2] * LENGTH_STD, readings.shape)
    turned = Rotation.from_rotvec(rng.normal(0.0, scale[1] * ANGLE_STD, (len(poses), 3))).as_matrix() @ rotation(poses)
    measured = np.column_stack([poses[:, :3] + rng.normal(0.0, scale[0] * POSITION_STD, (len(poses), 3)),
                                Rotation.from_matrix(turned).as_euler("ZYX")])  # R = Rz(psi) Ry(theta) Rx(phi)
    assert np.allclose(rotation(measured), turned, rtol=0, atol=2e-14)  # reached 4.6e-16
    return CalibrationData(readings, poses=measured, source="tracker")


@pytest.mark.parametrize("preset, seed, true, holds", [
    ("narayan2017", 300, (1 / 3, 1 / 3, 1 / 3), True), ("narayan2017", 400, (3.0, 3.0, 3.0), True),
    ("motion_simulator", 500, (3.0, 3.0, 3.0), True), ("narayan2017", 600, (1.0, 0.1, 1.0), True),
    ("motion_simulator", 700, (1.0, 0.1, 1.0), False)])
def test_the_covariance_holds_on_tracker_noise_the_fit_did_not_assume(preset, seed, true, holds):
    """The reported covariance is s^2 (J^T J)^-1: it scales with the a-posteriori variance
    factor s^2, so it holds when the true standard deviations are all a third of or three
    times those given (s near 1/3 or 3) and the tracker's orientation noise is a rotation, not
    the Euler-angle noise the fit assumes. With their ratio off (the issue's 10 um / 10 urad
    tracker with the default --pose-std 1e-5 1e-4) the weights are wrong and s^2 cannot make
    up for it: on narayan2017 the covariance still holds within the tolerance below, on
    motion_simulator it is too small (91 % of the estimates within 2 standard errors, like the
    issue's 92 %), as the calibration page says.

    Over 20 built machines of 150 poses, the estimates' errors whitened by the reported
    covariance, z = L^-1 (estimate - truth) with L L^T the covariance, are n = 840 N(0, 1)
    draws when it is right, independent but for each case's estimated s (s^2 off by
    sqrt(2 / dof), 4.8 %, common to its 42): the mean z^2 is 1 with a standard deviation
    sqrt(2 / n + 2 / (dof cases)) = 0.050, asserted within 4 of it; the share with |z| <= 2
    is binomial, 95.45 %, with sqrt(p (1 - p) / n + (4 phi(2))^2 / (2 dof cases)) = 0.73 %,
    asserted within 3.5. Standard errors 1.2 times too large or small put the mean z^2 at
    0.69 or 1.44, and 2 times at 0.25 or 4 with 99.99 % or 68 % within 2. The marginal
    coverage of the reported standard errors, the share of |error| <= 2 standard errors, is
    of correlated estimates (a case's 42 move together): its standard deviation is at most
    that of 20 cases, 4.7 %, asserted within 3 of them (alone, it would not see standard
    errors 2 times too large: the whitened checks do)."""
    nominal = stewart.PlatformParams.preset(preset)
    poses = _random_poses(150, 9, nominal)
    whitened, marginal, sigma = [], [], []
    for case in range(20):
        truth = perturbed_geometry(nominal, seed=seed + case)
        result = calibrate(nominal, _tracker_campaign(truth, poses, true, seed=seed + case),
                           position_std=POSITION_STD, angle_std=ANGLE_STD, length_std=LENGTH_STD)
        error = result.estimates - geometry.parameter_vector(truth)
        whitened.append(np.linalg.solve(np.linalg.cholesky(result.covariance), error))
        marginal.append(np.abs(error) <= 2 * result.standard_errors)
        sigma.append(result.sigma)
    np.testing.assert_allclose(result.standard_errors, np.sqrt(np.diag(result.covariance)), rtol=0)
    within, mean_square, share = np.mean(np.abs(whitened) <= 2), np.mean(np.square(whitened)), np.mean(marginal)
    print(f"calibration, {preset}, true stds {np.round(true, 3)} x those given: s {min(sigma):.3f}-{max(sigma):.3f}; "
          f"whitened errors {100 * within:.1f} % within 2, mean z^2 {mean_square:.3f}; {100 * share:.1f} % of the "
          f"estimates within 2 standard errors (cases {100 * np.min(np.mean(marginal, axis=1)):.0f}-"
          f"{100 * np.max(np.mean(marginal, axis=1)):.0f} %)")
    if true[0] == true[1] == true[2]:
        assert 0.8 * true[0] < min(sigma) and max(sigma) < 1.2 * true[0]
    cases, n, p = len(whitened), np.size(whitened), 0.9545
    scale = 2.0 / (result.dof * cases)  # the variance of s^2 / sigma^2 over the cases' mean
    tolerance = 4.0 * np.sqrt(2.0 / n + scale)
    if not holds:
        assert mean_square > 1.0 + tolerance
        return
    assert abs(mean_square - 1.0) <= tolerance
    # d share / d s = 4 phi(2): the share within 2 of the cases' s^2 spread
    assert abs(within - p) <= 3.5 * np.sqrt(p * (1 - p) / n + (4 * 0.05399) ** 2 * scale / 4)
    assert abs(share - p) <= 3.0 * np.sqrt(p * (1 - p) / cases)


@pytest.mark.parametrize("name, value", [("position_std", 1e200), ("length_std", 1e-170), ("angle_std", -1e-4),
                                         ("length_std", 0.0)])
def test_a_standard_deviation_whose_square_is_no_weight_is_an_error_naming_it(designed, name, value):
    data = simulate_measurements(NOMINAL, designed.poses)
    with pytest.raises(ValueError, match=f"^{name}: must be a positive number whose square is a finite, nonzero"):
        calibrate(NOMINAL, data, **{name: value})


def test_point_data_recovers_the_geometry_and_fixes_the_gauge_of_one_target(designed):
    truth = perturbed_geometry(NOMINAL, seed=7)
    offsets = [[0.0, 0.0, 0.02], [0.05, 0.0, 0.02], [0.0, 0.05, 0.02]]
    data = simulate_measurements(truth, designed.poses, target_offsets=offsets, seed=3)
    result = calibrate(NOMINAL, data)
    z = (result.estimates - geometry.parameter_vector(truth)) / result.standard_errors
    # 95.4 % of normal z within 2, binomially 3.2 % over 42 (0.85 is 3.2 of it below); |z| >= 5
    # has odds 42 * 5.7e-7 = 2.4e-5
    assert np.mean(np.abs(z) <= 2) >= 0.85 and np.max(np.abs(z)) < 5
    assert result.rms_after[-1] < 3 * POSITION_STD < result.rms_before[-1]
    # One target: {P} may turn about it; the base points and offsets do not depend on that gauge.
    single = simulate_measurements(truth, designed.poses, target_offsets=offsets[:1], seed=3)
    result = calibrate(NOMINAL, single)
    # the fit reaches the noise: s near 1 (chi^2 on 51 dof, spread 1 / sqrt(2 dof) = 0.1; within
    # 3.3 of it; reached 1.04 of it) and the target's RMS distance that of a 1e-5 m tracker
    assert abs(result.sigma - 1.0) < 3.3 / np.sqrt(2 * result.dof)
    assert result.rms_after[-1] < 3 * POSITION_STD < result.rms_before[-1]
    invariant = np.r_[0:18, 36:42]
    z = (result.estimates - geometry.parameter_vector(truth))[invariant] / result.standard_errors[invariant]
    assert np.max(np.abs(z)) < 5
    arms = NOMINAL.platform_points - offsets[0]
    turn = np.sum(np.cross(arms, result.params.platform_points - NOMINAL.platform_points), axis=0)
    assert np.max(np.abs(turn)) < 5e-17  # reached 1.7e-18 m^2 (terms of 1e-4 m^2 that cancel)


def test_held_out_pose_error_falls_from_millimetres_to_the_noise(designed):
    truth = perturbed_geometry(NOMINAL, seed=11)
    result = calibrate(NOMINAL, simulate_measurements(truth, designed.poses, seed=1))
    held = simulate_measurements(truth, _random_poses(20, 5), position_std=1e-12, angle_std=1e-12, seed=2)
    before, after = (np.sqrt(np.mean(pose_errors(p, held)["position"] ** 2)) for p in (NOMINAL, result.params))
    print(f"held-out RMS position error: {1e6 * before:.0f} um nominal, {1e6 * after:.2f} um calibrated")
    assert before > 5e-4 and after < POSITION_STD


def test_held_out_errors_are_the_distance_and_angle_the_measurements_were_moved_by():
    """pose_errors of readings taken at known poses (the hand-built legs) against measurements
    moved from them by known amounts: the position error is the length of the shift, the
    orientation error the angle of a rotation (scipy's rotation vector, on every axis, from
    0.1 to 20 mrad) of the measured {P} relative to the true one; for point data, the distance
    each measured target was moved, for two targets at their offsets (the hand-built
    ``t + R c``). The errors are those of forward kinematics from the readings, which solves
    them to its own tolerance: reached 3.0e-14 m and 2.5e-14 rad from the measured poses as
    the guess, 2.0e-13 m from the nominal's guess for point data (bounds 2e-12 and 1e-11)."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(8)
    poses = _random_poses(6, 4)
    readings = _hand_leg_lengths(NOMINAL, poses)
    shift = rng.normal(size=(6, 3)) * np.array([1e-4, 1e-3, 5e-3, 2e-2, 3e-4, 1e-5])[:, None]
    turn = rng.normal(size=(6, 3))
    turn *= np.array([1e-4, 2e-2, 3e-3, 5e-4, 1e-2, 1e-3])[:, None] / np.linalg.norm(turn, axis=1)[:, None]
    measured_rotation = np.array([_hand_rotation(*p[3:]) for p in poses]) @ Rotation.from_rotvec(turn).as_matrix()
    measured = np.column_stack([poses[:, :3] + shift, Rotation.from_matrix(measured_rotation).as_euler("ZYX")])
    errors = pose_errors(NOMINAL, CalibrationData(readings, poses=measured))
    np.testing.assert_allclose(errors["position"], np.linalg.norm(shift, axis=1), rtol=0, atol=2e-12)
    np.testing.assert_allclose(errors["orientation"], np.linalg.norm(turn, axis=1), rtol=0, atol=2e-12)

    offsets = np.array([[0.0, 0.0, 0.02], [0.05, -0.01, 0.02]])
    targets = np.array([0, 1, 1, 0, 1, 0])
    points = np.array([p[:3] + _hand_rotation(*p[3:]) @ offsets[t] for p, t in zip(poses, targets)])
    errors = pose_errors(NOMINAL, CalibrationData(readings, points=points + shift, targets=targets,
                                                  target_offsets=offsets))
    assert set(errors) == {"position"}
    np.testing.assert_allclose(errors["position"], np.linalg.norm(shift, axis=1), rtol=0, atol=1e-11)


def _hand_calibration(beyond=()):
    """A Calibration written by hand, no fit: 12 poses, the k-th parameter's estimate
    0.1 (k + 1) mm above the nominal with the standard error 0.01 (k + 1) mm, RMS residuals of
    k um before and k / 10 um after for leg k, s = 1.1 on 30 degrees of freedom."""
    from stewart.calibration import Calibration, Identifiability

    nominal = np.concatenate([NOMINAL.base_points.ravel(), NOMINAL.platform_points.ravel(), NOMINAL.leg_length_offsets])
    step = 1e-4 * np.arange(1, 43)
    return Calibration(
        nominal=NOMINAL, params=geometry.with_parameters(NOMINAL, nominal + step), kind="poses",
        estimates=nominal + step, covariance=np.diag((step / 10) ** 2),
        identifiability=Identifiability(np.ones(42), 1234.5, (), np.zeros((42, 0))),
        rms_before=1e-6 * np.arange(6.0), rms_after=1e-7 * np.arange(6.0), sigma=1.1, dof=30,
        poses=np.tile(stewart.home_pose(NOMINAL), (12, 1)), evaluations=7, beyond_stroke=beyond)


def test_the_parameter_table_and_summary_hold_each_parameters_values():
    """The text table [mm] and the JSON summary of a hand-written calibration: each row its
    parameter's nominal (the preset's joints, in the order base, platform, offsets), estimate,
    change and standard error, to the table's 4 decimals."""
    result = _hand_calibration()
    lines = result.table().splitlines()
    assert lines[0].split() == ["parameter", "nominal", "estimate", "change", "std", "err", "[mm]"]
    assert len(lines) == 43
    nominal_mm = 1e3 * np.concatenate([NOMINAL.base_points.ravel(), NOMINAL.platform_points.ravel(), np.zeros(6)])
    k = np.arange(1, 43)
    names = [f"{part}[{i}].{a}" for part in ("base_points", "platform_points") for i in range(6) for a in "xyz"] + \
        [f"leg_length_offsets[{i}]" for i in range(6)]
    assert [line.split()[0] for line in lines[1:]] == names
    table = np.array([[float(v) for v in line.split()[1:]] for line in lines[1:]])
    np.testing.assert_allclose(table, np.column_stack([nominal_mm, nominal_mm + 0.1 * k, 0.1 * k, 0.01 * k]),
                               rtol=0, atol=5.1e-5)
    summary = json.loads(json.dumps(result.summary()))
    assert {key: summary[key] for key in ("kind", "measurements", "condition_number", "sigma", "dof",
                                          "function_evaluations", "beyond_stroke")} == {
        "kind": "poses", "measurements": 12, "condition_number": 1234.5, "sigma": 1.1, "dof": 30,
        "function_evaluations": 7, "beyond_stroke": []}
    assert [p["name"] for p in summary["parameters"]] == names
    np.testing.assert_allclose([[p["nominal"], p["estimate"], p["standard_error"]] for p in summary["parameters"]],
                               np.column_stack([nominal_mm, nominal_mm + 0.1 * k, 0.01 * k]) / 1e3, rtol=1e-14,
                               atol=1e-18)
    assert summary["rms_before"] == {f"L{i}": pytest.approx(1e-6 * i, rel=1e-15) for i in range(6)}
    assert summary["rms_after"] == {f"L{i}": pytest.approx(1e-7 * i, rel=1e-15) for i in range(6)}


def test_the_stroke_warning_names_the_worst_leg_and_counts_the_significant_ones():
    """The one-line warning of legs past the stroke (0.19-0.38 m), written by hand: 3 legs of
    2 measurements, the worst 3 mm past (3000 um, with its row, leg, length and 250 um
    uncertainty), 2 of them past by more than 3 standard uncertainties; none past, no warning;
    none significant, all within their uncertainty."""
    from stewart.calibration import StrokeExcess

    assert _hand_calibration().stroke_warning() is None
    beyond = (StrokeExcess(30, 5, 0.383, 0.38, 3e-3, 2.5e-4), StrokeExcess(12, 0, 0.1899, 0.19, 1e-4, 3e-5),
              StrokeExcess(30, 4, 0.3801, 0.38, 1e-4, 2.5e-4))
    result = _hand_calibration(beyond)
    assert result.stroke_warning() == (
        "with the calibrated geometry 3 leg(s) of 2 measurement(s) lie past the stroke 0.19-0.38 m, by up to 3000 um "
        "(row 30, leg 5, 0.383 m, standard uncertainty 250 um); 2 of them by more than 3 standard uncertainties: the "
        "leg_length_limits given may not be the built machine's, or those rows are wrong")
    assert json.loads(json.dumps(result.summary()))["beyond_stroke"][1] == {
        "row": 12, "leg": 0, "length": 0.1899, "limit": 0.19, "excess": 1e-4, "uncertainty": 3e-5}
    within = _hand_calibration((StrokeExcess(7, 2, 0.38001, 0.38, 1e-5, 2e-5),))
    assert within.stroke_warning() == (
        "with the calibrated geometry 1 leg(s) of 1 measurement(s) lie past the stroke 0.19-0.38 m, by up to 10 um "
        "(row 7, leg 2, 0.38001 m, standard uncertainty 20 um); all within their uncertainty")


def test_the_figures_plot_the_residuals_changes_with_two_standard_errors_and_held_out_errors(tmp_path, monkeypatch):
    """The figures of a hand-written calibration hold its numbers: the RMS residual bars of leg
    k, k um before and k / 10 um after; per part (base, platform, offsets) the k-th
    parameter's change, 0.1 k mm, with error bars of 2 standard errors, 0.02 k mm; the held-out
    errors in um and urad with their RMS in the legend."""
    pytest.importorskip("matplotlib")
    import matplotlib.figure

    from stewart.calibration.figures import plot_calibration

    figures = []  # the figures as saved (not drawn: a second of rendering the test does not need)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda fig, path, **k: figures.append((fig, path)))
    held = {"nominal": {"position": np.array([3e-4, 4e-4]), "orientation": np.array([1e-3, 1e-3])},
            "calibrated": {"position": np.array([3e-6, 4e-6]), "orientation": np.array([2e-5, 1e-5])}}
    paths = plot_calibration(_hand_calibration(), tmp_path / "figs", held)
    names = ("calibration_residuals.png", "calibration_estimates.png", "calibration_held_out.png")
    assert paths == [str(tmp_path / "figs" / name) for name in names]
    assert [str(path) for _, path in figures] == paths
    residuals, estimates, held_out = (fig for fig, _ in figures)
    bars = [[bar.get_height() for bar in container] for container in residuals.axes[0].containers]
    np.testing.assert_allclose(bars, [np.arange(6.0), np.arange(6.0) / 10], rtol=1e-12)
    k = np.arange(1, 43)
    for ax, part in zip(estimates.axes, (slice(0, 18), slice(18, 36), slice(36, 42))):
        (bar,) = ax.containers
        np.testing.assert_allclose(bar.lines[0].get_ydata(), 0.1 * k[part], rtol=1e-9)
        segments = np.array(bar.lines[2][0].get_segments())  # each bar from y - yerr to y + yerr
        np.testing.assert_allclose(segments[:, :, 1], np.column_stack([0.08 * k[part], 0.12 * k[part]]), rtol=1e-9)
    for ax, kind, unit in zip(held_out.axes, ("position", "orientation"), ("um", "urad")):
        for line, label in zip(ax.get_lines(), ("nominal", "calibrated")):
            np.testing.assert_allclose(line.get_ydata(), 1e6 * held[label][kind], rtol=1e-12)
            rms = np.sqrt(np.mean((1e6 * held[label][kind]) ** 2))
            assert line.get_label() == f"{label} geometry (RMS {rms:.3g} {unit})"


def test_translations_alone_leave_each_legs_joints_undetermined_together():
    """With R = I for every pose, l_i = t + p_i - b_i: moving b_i and p_i by the same vector
    changes nothing, 18 combinations, and nothing else. With the tracker's angle noise
    (1e-4 rad, all that turns the measured poses) some remain beyond its condition limit."""
    poses = stewart.home_pose(NOMINAL) + np.random.default_rng(0).uniform(-0.02, 0.02, (30, 6)) * [1, 1, 1, 0, 0, 0]
    with pytest.raises(UnidentifiableError, match="parameter combination.*turn the platform"):
        calibrate(NOMINAL, simulate_measurements(NOMINAL, poses))
    with pytest.raises(UnidentifiableError, match="18 parameter combination.*turn the platform") as info:
        calibrate(NOMINAL, simulate_measurements(NOMINAL, poses, angle_std=0.0))
    ident = info.value.identifiability
    assert ident.condition == np.inf and len(ident.combinations) == 18
    # the message names the first three and counts the other 15 (docs/calibration.md)
    assert str(info.value) == (
        f"simulated measurements: the measurements cannot determine 18 parameter combination(s), e.g. "
        f"{'; '.join(ident.combinations[:3])}; and 15 more; measure poses that also turn the platform about all "
        "three axes (these only translate it)")
    expected = np.zeros((42, 18))
    for i in range(6):
        for a in range(3):
            expected[3 * i + a, 3 * i + a] = expected[18 + 3 * i + a, 3 * i + a] = 1.0
    _same_span(ident.directions, expected, 2e-7)  # reached 4.2e-9
    pairs = {frozenset(c.split(" + 1 ")) for c in ident.combinations}
    assert pairs == {frozenset((f"base_points[{i}].{a}", f"platform_points[{i}].{a}")) for i in range(6) for a in "xyz"}


def test_one_set_of_leg_lengths_names_each_offset_with_its_joints():
    """Every pose with the same readings is one pose: among what it cannot determine, each
    leg's offset traded against its base joint along the leg, (delta_i, b_i) = (1, -u_i)."""
    pose = stewart.home_pose(NOMINAL) + [0.005, 0, 0, 0, 0.05, 0]
    with pytest.raises(UnidentifiableError, match="at least 7 distinct poses") as info:
        calibrate(NOMINAL, simulate_measurements(NOMINAL, np.tile(pose, (10, 1)), position_std=0.0, angle_std=0.0,
                                                 length_std=0.0))
    directions = info.value.identifiability.directions
    units = stewart.leg_unit_vectors(NOMINAL, pose)
    for i in range(6):
        trade = np.zeros(42)
        trade[36 + i], trade[3 * i:3 * i + 3] = 1.0, -units[i]
        coefficients = np.linalg.lstsq(directions, trade, rcond=None)[0]
        assert np.max(np.abs(directions @ coefficients - trade)) < 1e-13  # reached 8.9e-16


def test_distinct_poses_too_close_together_ask_for_poses_spread_over_the_workspace():
    """Ten distinct poses that turn the platform (by up to 5 mrad about each axis) but stay
    within 0.5 mm and 5 mrad of home: too close together to tell the parameters apart (a
    condition number past 1e5), neither one pose repeated nor translations alone."""
    rng = np.random.default_rng(0)
    poses = stewart.home_pose(NOMINAL) + rng.uniform(-1, 1, (10, 6)) * np.array([5e-4] * 3 + [5e-3] * 3)
    assert np.ptp(poses[:, 3:], axis=0).min() > 5e-3
    with pytest.raises(UnidentifiableError, match=r"parameter combination.*; measure more poses spread over the "
                       r"workspace's positions and orientations \(stewart calibration-poses"):
        calibrate(NOMINAL, simulate_measurements(NOMINAL, poses, position_std=0.0, angle_std=0.0, length_std=0.0))


def test_a_parameter_nothing_depends_on_is_named_alone_without_a_warning():
    """Columns a, b = -2 a, c = 0 and d: c changes no residual, and a + 0.5 b (or b + 2 a)
    neither, by hand; the zero column is left unscaled, not divided by its zero norm (no
    RuntimeWarning, an error here)."""
    import warnings

    from stewart.calibration.identifiability import identifiability

    a, d = np.random.default_rng(0).normal(size=(2, 20))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ident = identifiability(np.column_stack([a, -2 * a, np.zeros(20), d]), ["a", "b", "c", "d"])
    assert ident.condition == np.inf and not ident.identifiable
    assert "c" in ident.combinations and len(ident.combinations) == 2
    assert {"a + 0.5 b", "b + 2 a"} & set(ident.combinations)
    _same_span(ident.directions, np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.5, 0.0, 0.0]]).T, 1e-14)  # reached 3.3e-16


@pytest.mark.parametrize("others, more", [(5, ""), (6, " (+1 more)"), (8, " (+3 more)")])
def test_a_long_combination_shows_its_six_largest_terms_and_counts_the_rest(others, more):
    """Column p_n = sum_i w_i p_i of n others: the one combination is p_n - sum_i w_i p_i,
    written from whichever parameter leads it (coefficient 1), its others largest first with
    their signs, five of them and how many more."""
    from stewart.calibration.identifiability import identifiability

    columns = np.random.default_rng(1).normal(size=(30, others))
    weights = np.array([0.5, -1.5, 2.0, -0.25, 3.0, 0.75, -1.1, 1.25])[:others]  # no two terms alike (nor 1)
    names = [f"p{i}" for i in range(others + 1)]
    (combination,) = identifiability(np.column_stack([columns, columns @ weights]), names).combinations
    direction = np.append(-weights, 1.0)
    lead = names.index(combination.split()[0])
    direction = direction / direction[lead]
    rest = sorted((i for i in range(others + 1) if i != lead), key=lambda i: -abs(direction[i]))
    terms = [f"{'+' if direction[i] > 0 else '-'} {abs(direction[i]):.3g} {names[i]}" for i in rest[:5]]
    assert combination == " ".join([names[lead], *terms]) + more


def _same_span(a, b, tolerance):
    """The columns of ``a`` and ``b`` span the same space (to ``tolerance``)."""
    assert a.shape == b.shape
    qa, qb = np.linalg.qr(a)[0], np.linalg.qr(b)[0]
    assert np.max(np.abs(qa @ (qa.T @ qb) - qb)) < tolerance


def test_designed_poses_are_better_conditioned_than_random_ones(designed):
    """The design's condition number against random reachable poses of the same box."""
    print(f"calibration poses: condition number {designed.designed['condition']:.0f} designed, "
          f"{designed.random['condition']:.0f} random (O1 {designed.designed['O1']:.4f} against "
          f"{designed.random['O1']:.4f})")
    assert designed.designed["condition"] < 0.8 * designed.random["condition"]
    assert designed.designed["O1"] > designed.random["O1"]
    assert observability(NOMINAL, designed.poses) == designed.designed
    assert np.all(stewart.reachability(NOMINAL, designed.poses).ok)
    # the nominal's readings: the hand-built legs' lengths (no offsets); reached 5.6e-17 m
    assert not np.any(NOMINAL.leg_length_offsets)
    np.testing.assert_allclose(designed.readings, _hand_leg_lengths(NOMINAL, designed.poses), rtol=0, atol=2e-15)


def test_observability_indices_against_a_direct_svd():
    """O1, the condition number and O4 (Sun & Hollerbach 2008; Nahvi & Hollerbach 1996) of
    the identification Jacobian (the 6 K rows of K poses) whose columns are scaled to a sum of
    squares of K (a pose's six rows' sum averaging 1), from numpy's SVD: O1 the geometric mean
    of the singular values over sqrt(6 K), sigma_max / sigma_min, sigma_min^2 / sigma_max
    (reached 2.9e-14 relative; bound 1e-12). Fewer than 7 poses leave the 42 parameters
    undetermined: O1 = O4 = 0 and an infinite condition number."""
    poses = _random_poses(10, 6)
    jacobian = geometry.leg_jacobian(geometry.parameter_vector(NOMINAL), poses).reshape(60, 42)
    jacobian = jacobian * np.sqrt(10 / np.sum(jacobian**2, axis=0))
    sv = np.linalg.svd(jacobian, compute_uv=False)
    want = {"O1": np.prod(sv ** (1 / 42)) / np.sqrt(60), "condition": sv[0] / sv[-1], "O4": sv[-1] ** 2 / sv[0]}
    got = observability(NOMINAL, poses)
    assert set(got) == set(want)
    np.testing.assert_allclose([got[k] for k in want], list(want.values()), rtol=1e-12)
    assert observability(NOMINAL, poses[:6]) == {"O1": 0.0, "condition": np.inf, "O4": 0.0}


def test_each_designed_pose_is_the_one_that_raises_log_det_most():
    """The greedy design against the criterion of the module docstring computed directly: at
    each step, of the candidates not yet chosen, the one whose rows J_c maximize
    ``log det(M + eps I + J_c^T J_c)`` (numpy's slogdet of the 42 x 42 matrix, eps = 1e-6),
    ``M`` the information of those chosen; not the matrix determinant lemma the design uses.
    With eps = 1e-5 the choice differs by the eighth pose."""
    from stewart.calibration.design import _greedy, _scaled_rows

    rows = _scaled_rows(NOMINAL, _random_poses(40, 2))
    information, want = 1e-6 * np.eye(42), []
    for _ in range(10):
        gain = [-np.inf if c in want else np.linalg.slogdet(information + r.T @ r)[1] for c, r in enumerate(rows)]
        want.append(int(np.argmax(gain)))
        information = information + rows[want[-1]].T @ rows[want[-1]]
    assert _greedy(rows, 10, False) == want


@pytest.mark.parametrize("arguments, message", [
    ({"count": 6}, "count: 42 parameters need at least 7 poses (6 legs each), got 6"),
    ({"rotation": 0.0}, "rotation: must be a positive finite number, got 0.0"),
    ({"translation": -0.01}, "translation: must be a positive finite number, got -0.01"),
    ({"translation": 0.0}, "translation: must be a positive finite number, got 0.0"),
    ({"centre": np.zeros((2, 6))}, "centre: expected one pose, got shape (2, 6)"),
])
def test_design_arguments_out_of_range_are_errors_naming_them(arguments, message):
    with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
        design_poses(NOMINAL, **{"count": 7, **arguments})


def test_a_box_with_too_few_reachable_poses_is_an_error_saying_how_many():
    """A box 1 cm and 0.01 rad wide centred 10.5 cm above home, near the top of the stroke:
    of the 40 x 7 = 280 candidates for 7 poses only a few are reachable, fewer than the twice
    7 the design needs, though at least the 7 it would pick (so it is the count that refuses)."""
    centre = stewart.home_pose(NOMINAL) + [0.0, 0.0, 0.105, 0.0, 0.0, 0.0]
    with pytest.raises(ValueError, match=r"^centre, translation, rotation: only (\d+) of 280 random poses in the box "
                                         r"are reachable; need 14 \(move the centre or shrink the box\)$") as info:
        design_poses(NOMINAL, 7, centre=centre, translation=0.01, rotation=0.01)
    assert 7 <= int(re.search(r"only (\d+) of", str(info.value)).group(1)) < 14


def test_offsets_flow_through_forward_kinematics_files_and_identification(tmp_path):
    built = NOMINAL.replace(leg_length_offsets=[1e-3, -2e-3, 0.0, 5e-4, 0.0, 3e-3])
    pose = stewart.home_pose(NOMINAL) + [0.01, -0.005, 0.01, 0.05, -0.03, 0.1]
    readings = stewart.encoder_readings(built, pose)
    # the hand-built legs less the offsets (reached 5.6e-17 m, bound 2e-15 m); the poses back
    # from them to 2.0e-15 (Newton's last step lands at round-off, under its 1e-12 stop)
    np.testing.assert_allclose(readings, _hand_leg_lengths(built, pose)[0] - built.leg_length_offsets, rtol=0,
                               atol=2e-15)
    assert np.max(np.abs(stewart.forward_kinematics(built, readings, encoder=True) - pose)) < 1e-13
    for name in ("p.toml", "p.json"):
        built.save(tmp_path / name)
        assert stewart.PlatformParams.load(tmp_path / name) == built
    assert "leg_length_offsets" not in NOMINAL.to_dict()
    from stewart.identification import identify

    log = identify.Measurements(np.arange(20) / 100, np.tile(readings, (20, 1)), np.zeros((20, 6)))
    assert np.max(np.abs(identify._poses(stewart.Platform(built), log) - pose)) < 1e-13  # reached 2.0e-15
    simulated = identify.synthetic_measurements(built, stewart.PointToPoint(pose, pose, 0.1), rate=100)
    # the same kernel call on the pose the trajectory holds exactly: bit for bit
    np.testing.assert_array_equal(simulated.lengths, np.tile(readings, (11, 1)))
    main(["ik", "--params", str(tmp_path / "p.toml"), "--pose", *(str(float(v)) for v in pose), "--csv", str(tmp_path / "ik.csv")])
    np.testing.assert_allclose(np.loadtxt(tmp_path / "ik.csv", delimiter=",", skiprows=2), readings, rtol=1e-11)


# ---- the command line ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def campaign(tmp_path_factory, designed):
    folder = tmp_path_factory.mktemp("calibration")
    truth = perturbed_geometry(NOMINAL, seed=21)
    simulate_measurements(truth, designed.poses, seed=1).to_csv(folder / "meas.csv")
    simulate_measurements(truth, _random_poses(10, 3), seed=2).to_csv(folder / "held.csv")
    NOMINAL.save(folder / "nominal.toml")
    return folder, truth


@pytest.mark.slow
def test_calibrate_writes_the_parameters_report_and_figures(campaign, capsys):
    folder, truth = campaign
    code, out, err = _run(["calibrate", str(folder / "meas.csv"), "--params", str(folder / "nominal.toml"),
                           "--output", str(folder / "cal.toml"), "--report", str(folder / "r.json"),
                           "--plot", str(folder / "figs"), "--validate", str(folder / "held.csv")], capsys)
    assert code == 0, err
    calibrated = stewart.PlatformParams.load(folder / "cal.toml")
    report = json.loads((folder / "r.json").read_text())
    estimates = np.array([p["estimate"] for p in report["parameters"]])
    np.testing.assert_array_equal(estimates, geometry.parameter_vector(calibrated))
    errors = np.array([p["standard_error"] for p in report["parameters"]])
    assert np.max(np.abs(estimates - geometry.parameter_vector(truth)) / errors) < 5
    assert report["validation"]["calibrated_rms_position"] < 0.1 * report["validation"]["nominal_rms_position"]
    assert sorted(p.name for p in (folder / "figs").iterdir()) == [
        "calibration_estimates.png", "calibration_held_out.png", "calibration_residuals.png"]
    assert "held-out" in out


def _at_the_stroke_end(excess):
    """A pose, raised and tilted from home, where the nominal's longest leg is ``excess`` [m]
    past its maximum length."""
    from scipy.optimize import brentq

    home, up = stewart.home_pose(NOMINAL), np.array([0.01, 0.0, 1.0, 0.0, 0.05, 0.0])
    high = NOMINAL.leg_length_limits[1]
    return home + up * brentq(lambda a: np.max(stewart.leg_lengths(NOMINAL, home + a * up)) - high - excess, 0, 0.3)


@pytest.mark.parametrize("excess", [4e-5, 3e-3])
def test_measured_poses_past_the_nominal_stroke_are_calibrated_and_judged_after_the_fit(
        campaign, designed, tmp_path, capsys, excess):
    """A pose whose nominal leg is 40 um past the stroke (the built machine, whose legs are
    shorter there, inside it) is calibrated like any other, exit 0, its calibrated length
    within its uncertainty of the stroke; one 3 mm past (the built machine past its stated
    stroke too) also, with a warning naming the leg, how far past and its uncertainty, and in
    the report. A pose past by more than 5 % of the stroke is refused (test_bad_measurements)."""
    folder, truth = campaign
    pose = _at_the_stroke_end(excess)
    assert not stewart.reachability(NOMINAL, pose).ok[0]
    simulate_measurements(truth, np.vstack([designed.poses, pose]), seed=1).to_csv(tmp_path / "m.csv")
    code, out, err = _run(["calibrate", str(tmp_path / "m.csv"), "--report", str(tmp_path / "r.json")], capsys)
    assert code == 0, err
    report = json.loads((tmp_path / "r.json").read_text())
    beyond = report["beyond_stroke"]
    true_length = stewart.leg_lengths(truth, pose)
    assert {e["row"] for e in beyond} <= {30}
    for e in beyond:
        assert e["limit"] == NOMINAL.leg_length_limits[1]
        assert abs(e["length"] - true_length[e["leg"]]) < 3 * e["uncertainty"]
    if excess < 1e-3:
        assert all(e["excess"] < 3 * e["uncertainty"] for e in beyond)
        assert not beyond or "all within their uncertainty" in err
    else:
        assert max(e["excess"] for e in beyond) > 1e-3
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"stewart calibrate: warning: {tmp_path / 'm.csv'}: with the "
                                                       "calibrated geometry")
        assert "past the stroke 0.19-0.38 m" in lines[0] and "by more than 3 standard uncertainties" in lines[0]


def test_a_fit_that_runs_out_of_evaluations_is_an_error_never_a_result(designed, monkeypatch, tmp_path, capsys):
    """The real solver held to 2 evaluations of the residuals (the fit from the nominal takes 6)
    stops without converging (status 0): calibrate raises ConvergenceError naming the data and
    the solver's message, and stewart calibrate exits 4 (the run failed) with that one line."""
    import scipy.optimize

    solve = scipy.optimize.least_squares
    statuses = []

    def starved(*args, **options):
        result = solve(*args, **{**options, "max_nfev": 2})
        statuses.append(result.status)
        return result

    monkeypatch.setattr(scipy.optimize, "least_squares", starved)
    data = simulate_measurements(perturbed_geometry(NOMINAL, seed=11), designed.poses, seed=1)
    with pytest.raises(stewart.ConvergenceError, match=r"^simulated measurements: the least squares did not "
                       r"converge: The maximum number of function evaluations is exceeded\. \(2 evaluations, "
                       r"status 0\); no calibration$"):
        calibrate(NOMINAL, data)
    data.to_csv(tmp_path / "m.csv")
    code, out, err = _run(["calibrate", str(tmp_path / "m.csv"), "--report", str(tmp_path / "r.json")], capsys)
    assert statuses == [0, 0] and code == 4 and not (tmp_path / "r.json").exists()
    assert err.strip().splitlines() == [f"stewart calibrate: error: {tmp_path / 'm.csv'}: the least squares did "
                                        "not converge: The maximum number of function evaluations is exceeded. (2 "
                                        "evaluations, status 0); no calibration"]


def test_point_data_whose_poses_do_not_converge_is_an_error_never_a_result(designed, monkeypatch):
    """Point data's poses are solved by Gauss-Newton at each parameter vector: held to one
    iteration whose step must be exactly zero (two reach 1e-12 from the last poses on this data;
    whether the first alone does depends on the last bits of the fit's path) they do not converge
    at the estimate, and calibrate raises ConvergenceError instead of reporting a fit on poses that
    are not the least-squares ones; with the iterations it has, the same data calibrates."""
    from stewart.calibration import fit

    data = simulate_measurements(perturbed_geometry(NOMINAL, seed=7), designed.poses,
                                 target_offsets=[[0.0, 0.0, 0.02], [0.05, 0.0, 0.02], [0.0, 0.05, 0.02]], seed=3)
    assert calibrate(NOMINAL, data).sigma < 1.2
    monkeypatch.setattr(fit, "_POSE_ITERATIONS", 1)
    monkeypatch.setattr(fit, "_POSE_TOLERANCE", 0.0)
    with pytest.raises(stewart.ConvergenceError, match=r"^simulated measurements: the platform's poses at the "
                       r"estimate did not converge in 1 Gauss-Newton iterations; no calibration$"):
        calibrate(NOMINAL, data)


def test_a_measured_pose_outside_the_workspace_is_refused_saying_why():
    """Refused before the fit: a pose 20 cm above home, its legs 48 cm, past the stroke (0.19-
    0.38 m) widened by 5 % of it, 0.0095 m, to 0.3895 m, says so and how it was widened; home
    mirrored below the base (the same leg lengths, all within the stroke) says it is below the
    base and in the other assembly mode, and nothing of the stroke."""
    poses = np.vstack([_random_poses(12, 1), stewart.home_pose(NOMINAL)])
    start = "measurements: 1 of 13 measured pose(s) outside the workspace: "
    poses[-1, 2] += 0.2
    with pytest.raises(stewart.WorkspaceError, match=re.escape(start) + r"leg\(s\) \[0, 1, 2, 3, 4, 5\] longer "
                       r"than the maximum length 0.3895 m \(0.48[0-9., ]+ m\) at row 12 \(the stroke 0.19-0.38 m "
                       r"widened by 0.05 of it, 0.0095 m, for the built machine's geometry errors: check the rows, the "
                       r"file and its units\)$"):
        calibrate(NOMINAL, CalibrationData(_hand_leg_lengths(NOMINAL, poses), poses=poses))
    poses[-1, 2] = -stewart.home_pose(NOMINAL)[2]
    with pytest.raises(stewart.WorkspaceError, match=re.escape(start) + "the platform is not above the base: .* at "
                       "row 12; det J_C has the other sign: the pose is in another assembly mode, beyond a "
                       "singularity at row 12$"):
        calibrate(NOMINAL, CalibrationData(_hand_leg_lengths(NOMINAL, poses), poses=poses))


def test_point_data_past_the_nominal_stroke_names_the_first_row_of_its_pose(designed):
    """Point data's poses come from the readings (3 targets a pose): a pose whose nominal legs
    are 1.4-4.1 mm past the stroke is calibrated, and its legs past it with the calibrated
    geometry name the pose's first row, 90 of 93, within their uncertainty of the truth. Each
    is the reading plus the calibrated offset, past the maximum by that less the limit, with
    the uncertainty of a sum of independent terms: the reading's (the encoder's 1 um scaled
    by s) and the offset's (its variance in the covariance), largest excess first."""
    truth = perturbed_geometry(NOMINAL, seed=21)
    offsets = [[0.0, 0.0, 0.02], [0.05, 0.0, 0.02], [0.0, 0.05, 0.02]]
    pose = _at_the_stroke_end(3e-3)
    data = simulate_measurements(truth, np.vstack([designed.poses, pose]), target_offsets=offsets, seed=3)
    result = calibrate(NOMINAL, data)
    true_length = stewart.leg_lengths(truth, pose)
    assert result.beyond_stroke and {e.row for e in result.beyond_stroke} == {90}
    assert all(abs(e.length - true_length[e.leg]) < 3 * e.uncertainty for e in result.beyond_stroke)
    legs = [e.leg for e in result.beyond_stroke]
    length = data.readings[90, legs] + result.params.leg_length_offsets[legs]
    variance = (result.sigma * LENGTH_STD) ** 2 + np.diag(result.covariance)[36:][legs]
    np.testing.assert_allclose([[e.length, e.excess, e.uncertainty] for e in result.beyond_stroke],
                               np.column_stack([length, length - 0.38, np.sqrt(variance)]), rtol=1e-12, atol=0)
    assert all(e.limit == 0.38 for e in result.beyond_stroke) and np.all(np.diff(length) <= 0)


def test_calibration_poses_writes_a_campaign_calibrate_reads(tmp_path, capsys):
    code, out, _ = _run(["calibration-poses", "--count", "12", "--csv", str(tmp_path / "d.csv"), "--no-progress"],
                        capsys)
    assert code == 0 and "12 random poses" in out
    data = CalibrationData.from_csv(tmp_path / "d.csv")
    assert data.kind == "poses" and len(data.readings) == 12
    # the file is design_poses' with the same arguments (the command's default preset,
    # narayan2017, and seed 0)
    check_calibration_poses(out, design_poses(NOMINAL, 12, seed=0), 12, tmp_path / "d.csv")


def test_calibration_poses_prints_design_poses_with_the_same_arguments(capsys):
    """Every argument reaches design_poses: the listing printed without --csv (12 digits)
    and the observability indexes (4 digits) are design_poses' with the same preset, count,
    centre, box and seed."""
    centre = stewart.home_pose(NOMINAL) + [0.002, 0.0, -0.005, 0.0, 0.01, 0.0]
    code, out, _ = _run(["calibration-poses", "--preset", "narayan2017", "--count", "8", "--seed", "3",
                         "--centre", *(repr(float(v)) for v in centre), "--translation", "0.02",
                         "--rotation", "0.15", "--no-progress"], capsys)
    assert code == 0
    want = design_poses(NOMINAL, 8, centre=centre, translation=0.02, rotation=0.15, seed=3)
    check_calibration_poses(out, want, 8)


@pytest.mark.parametrize("edit, code, start", [
    (lambda rows: rows.replace(rows.splitlines()[3].split(",")[2], "nan", 1), 2, "{file}: line 4, column 3"),
    (lambda rows: "\n".join(rows.splitlines()[:6]), 2, "{file}: too few measurements: 24 equations for 42"),
    (lambda rows: rows.replace(rows.splitlines()[3].split(",")[2], "0.9", 1), 3,
     "{file}: 1 of 30 measured pose(s) outside the workspace: leg(s) [0, 1, 2, 3, 4, 5] longer than the maximum "
     "length 0.3895 m"),
    (lambda rows: rows.replace("x,y,z", "px,py,pz").replace(",psi,theta,phi", ""), 2, "{file}: "),
    (lambda rows: rows.replace("psi,theta,phi,", ""), 2, "{file}: line 1: the header has 9"),
])
def test_bad_measurements_are_one_line_errors(campaign, tmp_path, capsys, edit, code, start):
    folder, _ = campaign
    path = tmp_path / "bad.csv"
    path.write_text(edit((folder / "meas.csv").read_text()))
    got, _, err = _run(["calibrate", str(path)], capsys)
    lines = err.strip().splitlines()
    assert got == code and len(lines) == 1, err
    assert lines[0].startswith(f"stewart calibrate: error: {start.format(file=path)}"), lines[0]


def test_one_targets_offset_may_be_given_alone():
    """One target's offset as a vector (3,) is the offsets (1, 3): the same data as given so."""
    readings, points = np.full((4, 6), 0.3), np.zeros((4, 3))
    alone = CalibrationData(readings, points=points, target_offsets=[0.01, -0.02, 0.03])
    np.testing.assert_array_equal(alone.target_offsets, [[0.01, -0.02, 0.03]])
    np.testing.assert_array_equal(alone.targets, np.zeros(4, dtype=int))
    with pytest.raises(ValueError, match=r"^measurements: readings: expected 6 columns, got shape \(6,\)$"):
        CalibrationData(readings[0], points=points[:1], target_offsets=[0.0, 0.0, 0.02])


_TARGETS = "measurements: target: expected indices 0..1 of the 2 target offset(s) given, one per row"


@pytest.mark.parametrize("kind, targets, message", [
    ("points", [0, 1, 1], _TARGETS), ("points", [[0], [1], [1], [0]], _TARGETS), ("points", [0, 1, 2, 0], _TARGETS),
    ("points", [0, -1, 1, 0], _TARGETS), ("points", [0, 0.5, 1, 0], _TARGETS),
    ("rows", None, "measurements: points has 3 rows and readings 4"),
    ("poses", None, "measurements: poses has 5 rows and readings 4"),
    ("both", None, "measurements: give either poses or points"),
])
def test_measurements_that_do_not_fit_together_are_errors_saying_how(kind, targets, message):
    readings, offsets = np.full((4, 6), 0.3), [[0.0, 0.0, 0.02], [0.05, 0.0, 0.02]]
    given = {"points": {"points": np.zeros((4, 3)), "targets": targets, "target_offsets": offsets},
             "rows": {"points": np.zeros((3, 3)), "target_offsets": offsets},
             "poses": {"poses": np.zeros((5, 6))},
             "both": {"poses": np.zeros((4, 6)), "points": np.zeros((4, 3)), "target_offsets": offsets}}[kind]
    with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
        CalibrationData(readings, **given)


@pytest.mark.parametrize("kind, count, message", [
    ("poses", 4, "24 equations for 42 unknowns; measure at least 8 poses"),
    ("poses", 7, "42 equations for 42 unknowns; measure at least 8 poses"),
    ("one target", 10, "90 equations for 99 unknowns; measure at least 14 target measurements"),
    ("three targets", 4, "60 equations for 66 unknowns; measure at least 15 target measurements"),
])
def test_too_few_measurements_say_how_many_more(kind, count, message):
    """By hand: K poses give 6 K leg equations for the 42 parameters (7 poses, 42, are not
    more); one target a pose adds 3 equations and 6 unknowns (the pose), less the 3 turns about
    the target that the gauge fixes: 90 for 42 + 60 - 3 = 99 at K = 10, and 14 measurements of
    the target (102 > 99) suffice; three targets (no gauge) at K = 4, 24 + 36 = 60 for 42 + 24
    = 66, need 15 (69 > 66)."""
    poses = _random_poses(count, 3)
    offsets = {"poses": None, "one target": [[0.0, 0.0, 0.02]],
               "three targets": [[0.0, 0.0, 0.02], [0.05, 0.0, 0.02], [0.0, 0.05, 0.02]]}[kind]
    data = simulate_measurements(NOMINAL, poses, target_offsets=offsets)
    with pytest.raises(ValueError, match=f"^simulated measurements: too few measurements: {message}$"):
        calibrate(NOMINAL, data)


def test_point_data_without_target_offsets_says_which_flag(tmp_path, capsys, designed):
    simulate_measurements(NOMINAL, designed.poses[:10], target_offsets=[[0, 0, 0.02]]).to_csv(tmp_path / "p.csv")
    code, _, err = _run(["calibrate", str(tmp_path / "p.csv")], capsys)
    assert code == 2 and err.strip().endswith("need their targets' offsets in {P} (--target-offset X Y Z)")


def test_target_offsets_with_pose_data_are_an_error(campaign, capsys):
    folder, _ = campaign
    code, _, err = _run(["calibrate", str(folder / "meas.csv"), "--target-offset", "0", "0", "0.02"], capsys)
    assert code == 2 and err.startswith("stewart calibrate: error: --target-offset: ") and "holds poses" in err
