"""Identification: exact recovery of the base parameters from exact states, standard errors
that cover the true values over repeated noisy runs, predictions on a held-out run at the
noise level, a parameter file that reproduces the estimates, and bad data refused."""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pytest

from stewart import ConvergenceError, NonAxisymmetricLegWarning, Platform, PlatformParams
from stewart.cli import main
from stewart.identification.identify import (Measurements, differentiate, estimate, excitation_condition, identify,
                                             synthetic_measurements, validation)

NOISE_LENGTH = 1e-6   # m, a linear encoder's
NOISE_FORCE = 0.2     # N, a load cell's
RATE = 500.0          # samples per second
CUTOFF = 8.0          # Hz: a few times the trajectories' highest frequency (1.9 Hz)


class Sines:
    """A sum of sines about the home pose in each pose coordinate, exact derivatives."""

    def __init__(self, home, seed, duration=10.0, scale=1.0, axes=range(6)):
        rng = np.random.default_rng(seed)
        mask = np.zeros((6, 1))
        mask[list(axes)] = 1.0
        self.amp = scale * mask * np.array([0.01, 0.01, 0.01, 0.05, 0.05, 0.05])[:, None] * rng.uniform(0.3, 1, (6, 4))
        self.w = 2 * np.pi * np.array([0.3, 0.7, 1.1, 1.7]) * rng.uniform(0.9, 1.1, 4)
        self.phase = rng.uniform(0, 2 * np.pi, (6, 4))
        self.home, self.duration = home, duration

    def sample(self, t):
        ph = np.asarray(t)[:, None, None] * self.w + self.phase
        return (self.home + (self.amp * np.sin(ph)).sum(-1), (self.amp * self.w * np.cos(ph)).sum(-1),
                (-self.amp * self.w ** 2 * np.sin(ph)).sum(-1))


def machine(seed=0):
    """The seed paper's platform with a payload the prior does not know, and friction."""
    rng = np.random.default_rng(seed)
    params = PlatformParams.preset("narayan2017").with_payload(0.5, [0.01, -0.005, 0.02], [0.01, 0.015, 0.012])
    return Platform(params.replace(viscous_friction=rng.uniform(5, 20, 6), coulomb_friction=rng.uniform(1, 3, 6)))


PRIOR = Platform.preset("narayan2017")


def test_exact_states_recover_the_base_parameters(figures):
    true = machine()
    traj = Sines(PRIOR.home_pose, 1)
    t = np.arange(0, traj.duration, 1 / 250)
    x, xd, xdd = traj.sample(t)
    result = estimate(PRIOR, x, xd, xdd, true.actuator_forces(x, xd, xdd))
    beta = result.base.values(true.params.inertial_vector())
    err = np.max(np.abs(result.estimates - beta) / (np.abs(beta) + 1e-6 * np.max(np.abs(beta))))
    figures("identification from exact states: base parameters, relative", err, 5e-9)  # reached 9.2e-11


def test_weighted_least_squares_against_numpy(figures):
    """estimate() against the two-step weighted least squares written out with numpy's lstsq
    (QR, not the normal equations): an ordinary solve, each leg weighted by the inverse RMS of
    its residual, the covariance s^2 (A_w^T A_w)^-1; exact states, load cells of six different
    noise levels (the weighted and the ordinary solutions differ by about 10 standard errors)."""
    true = machine()
    traj = Sines(PRIOR.home_pose, 1)
    t = np.arange(0, traj.duration, 1 / 100)
    x, xd, xdd = traj.sample(t)
    sigma = np.array([0.05, 0.1, 0.2, 0.4, 0.8, 1.6])
    forces = true.actuator_forces(x, xd, xdd) + sigma * np.random.default_rng(5).standard_normal((len(t), 6))
    result = estimate(PRIOR, x, xd, xdd, forces)
    base = result.base
    A = base.reduce(PRIOR.regressor(x, xd, xdd))
    stack, f = A.reshape(-1, base.rank), forces.ravel()
    ordinary = np.linalg.lstsq(stack, f, rcond=None)[0]
    weights = np.tile(1.0 / np.sqrt(np.mean((forces - A @ ordinary) ** 2, axis=0)), len(t))
    weighted = np.linalg.lstsq(stack * weights[:, None], f * weights, rcond=None)[0]
    residual = (f - stack @ weighted) * weights
    covariance = (np.linalg.inv((stack * weights[:, None]).T @ (stack * weights[:, None]))
                  * (residual @ residual / (len(f) - base.rank)))
    errors = np.sqrt(np.diag(covariance))
    figures("identification: estimates vs numpy weighted least squares, in standard errors",
            np.max(np.abs(result.estimates - weighted) / errors), 1e-8)  # reached 1.7e-10
    figures("identification: standard errors vs numpy weighted least squares, relative",
            np.max(np.abs(result.standard_errors / errors - 1.0)), 1e-11)  # reached 2.4e-13
    rms = np.sqrt(np.mean((forces - A @ weighted) ** 2, axis=0))
    figures("identification: residual RMS per leg vs numpy, relative", np.max(np.abs(result.residual_rms / rms - 1.0)),
            1e-12)  # reached 2.6e-14
    np.testing.assert_allclose(result.residual_rms, sigma, rtol=0.05)  # the noise added: 3.5 % off at most
    # the condition number: that of the stacked regressor with its columns in units of their scale
    cond = np.linalg.cond(stack / base.scale)
    figures("identification: condition numbers vs numpy's cond, relative",
            np.maximum(abs(result.condition_number / cond - 1.0), abs(excitation_condition(base, stack) / cond - 1.0)),
            1e-11)  # reached 1.5e-13


#: Worst error of each filter's pose, rate and acceleration against the exact ones, relative to
#: their peaks (reached 7.4e-7, 2.0e-4, 1.6e-4 for savgol; 2.1e-5, 1.8e-4, 1.5e-3 for butterworth,
#: whose end transients reached 0.16 in the accelerations when one window was dropped).
FILTER_ERRORS = {"savgol": (3e-5, 5e-3, 5e-3), "butterworth": (5e-4, 5e-3, 3e-2)}


@pytest.mark.parametrize("name", sorted(FILTER_ERRORS))
def test_filters_differentiate_the_poses(name, figures):
    """Exact leg lengths at 500 Hz with an 8 Hz cut-off: the window spans 63 samples (500 / 8,
    rounded to odd); savgol drops one window at either end and butterworth three. What is left
    against the sum of sines' exact derivatives, and the forces of the same samples."""
    true = machine()
    traj = Sines(PRIOR.home_pose, 1)
    data = synthetic_measurements(true, traj, rate=RATE)
    poses = PRIOR.forward_kinematics(data.lengths, PRIOR.home_pose, encoder=True)
    x, xd, xdd, forces = differentiate(data, poses, filter=name, cutoff=CUTOFF)
    drop = {"savgol": 63, "butterworth": 189}[name]
    assert len(x) == len(data.t) - 2 * drop and np.array_equal(forces, data.forces[drop:-drop])
    exact = traj.sample(data.t[drop:-drop])
    for label, got, want, peak, bound in zip(("pose", "rate", "acceleration"), (x, xd, xdd), exact,
                                             (traj.amp.sum(axis=1), *(np.max(np.abs(v), axis=0) for v in exact[1:])),
                                             FILTER_ERRORS[name]):
        figures(f"identification: {name} filter's {label}, relative to its peak",
                np.max(np.abs(got - want) / peak), bound)


@pytest.mark.parametrize("name, least", [("savgol", 3 * 63), ("butterworth", 7 * 63)])
def test_filters_need_the_samples_they_drop_and_a_window(name, least):
    """At 500 Hz with an 8 Hz cut-off (a window of 63 samples), savgol drops one window at either
    end and butterworth three: a log needs those and one window more."""
    data = synthetic_measurements(machine(), Sines(PRIOR.home_pose, 1, duration=(least - 1) / RATE), rate=RATE)
    poses = PRIOR.forward_kinematics(data.lengths, PRIOR.home_pose, encoder=True)
    assert len(data.t) == least and len(differentiate(data, poses, filter=name, cutoff=CUTOFF)[0]) == 63
    short = Measurements(data.t[:-1], data.lengths[:-1], data.forces[:-1])
    with pytest.raises(ValueError, match=rf"^measurements: too few samples \({least - 1}\) for the filter window of 63 "):
        differentiate(short, poses[:-1], filter=name, cutoff=CUTOFF)


def test_standard_errors_cover_the_true_values_over_repeated_runs(figures):
    true = machine()
    traj = Sines(PRIOR.home_pose, 2)
    inside, total = 0, 0
    for seed in range(12):
        data = synthetic_measurements(true, traj, rate=RATE, noise_length=NOISE_LENGTH, noise_force=NOISE_FORCE,
                                      seed=seed)
        result = identify(PRIOR, data, cutoff=CUTOFF)
        z = (result.estimates - result.base.values(true.params.inertial_vector())) / result.standard_errors
        inside += int(np.sum(np.abs(z) <= 2.0))
        total += len(z)
    # ~95.4 % within 2 standard errors for Gaussian errors: over 312 estimates at most 9 % outside,
    # and at least 0.5 % (4 sigma of the binomial either way)
    outside = 1.0 - inside / total
    figures("identification: fraction of estimates over 2 standard errors off, 12 noisy runs", outside, 0.09)  # reached 5.8e-02
    assert outside >= 0.005, f"standard errors too large: only {outside:.3f} of the estimates over 2 of them off"


def test_prediction_on_a_held_out_run_and_the_parameter_file(tmp_path, figures):
    true = machine()
    data = synthetic_measurements(true, Sines(PRIOR.home_pose, 3, duration=30.0, scale=1.5), rate=RATE, noise_length=NOISE_LENGTH,
                                  noise_force=NOISE_FORCE, seed=1)
    held = synthetic_measurements(true, Sines(PRIOR.home_pose, 4), rate=RATE, noise_length=NOISE_LENGTH,
                                  noise_force=NOISE_FORCE, seed=2)
    result = identify(PRIOR, data, cutoff=CUTOFF)
    _, predicted, measured, rms = validation(result, PRIOR, held, cutoff=CUTOFF)
    # the noise level: the true parameters' prediction through the same measurement pipeline
    exact = dataclasses.replace(result, estimates=result.base.values(true.params.inertial_vector()))
    _, _, _, floor = validation(exact, PRIOR, held, cutoff=CUTOFF)
    figures("identification: held-out RMS error above the true model's (same pipeline), relative",
            np.max(rms / floor) - 1.0, 0.05)  # reached 1.3e-03
    assert np.max(floor) < 1.5 * NOISE_FORCE  # the force noise, and the differentiated length noise
    params = result.params()
    params.save(tmp_path / "identified.toml")
    # Without joint axes the legs' I_yy and I_zz are identified apart (result.params gives no
    # warning for that), so the file of the identified machine loads with the warning.
    assert params.cylinder_inertia[1] != params.cylinder_inertia[2]
    with pytest.warns(NonAxisymmetricLegWarning, match="I_yy != I_zz"):
        loaded = Platform.from_file(tmp_path / "identified.toml")
    err = np.max(np.abs(result.base.values(loaded.params.inertial_vector()) - result.estimates)
                 / np.maximum(np.abs(result.estimates), 1e-9))
    figures("identification: parameter file's base values vs the estimates", err, 1e-12)  # reached 1.7e-14


def test_bad_data_is_refused():
    true = machine()
    t = np.arange(0, 2, 1 / 250)
    good = synthetic_measurements(true, Sines(PRIOR.home_pose, 5, duration=2.0), rate=250)
    lengths = good.lengths.copy()
    lengths[7, 2] = np.nan
    with pytest.raises(ValueError, match=r"sample\(s\) \[7\] hold NaN"):
        Measurements(good.t, lengths, good.forces)
    backwards = good.t.copy()
    backwards[10] = backwards[8]
    with pytest.raises(ValueError, match="not increasing at sample 10"):
        Measurements(backwards, good.lengths, good.forces)
    with pytest.raises(ValueError, match="too few samples"):
        identify(PRIOR, Measurements(t[:20], good.lengths[:20], good.forces[:20]))
    still = synthetic_measurements(true, Sines(PRIOR.home_pose, 6, axes=[2]), rate=250)
    with pytest.raises(ValueError, match="does not excite every base parameter"):
        identify(PRIOR, still)
    with pytest.raises(ValueError, match=r"^cutoff: need 0 < cutoff < 125 Hz \(half the sampling rate\), got 200$"):
        identify(PRIOR, good, cutoff=200.0)  # sampled at 250 Hz
    with pytest.raises(ConvergenceError, match=r"^measurements: the leg lengths are not this platform's \(forward_kin"):
        identify(PRIOR, Measurements(good.t, np.full_like(good.lengths, 0.01), good.forces))  # 1 cm legs


def test_synthetic_log_samples_both_ends_of_the_trajectory():
    """A 2 s run at 250 Hz: 501 samples, from t = 0 to t = 2 s, 4 ms apart (500 steps over 2 s: the
    rate the measurements give, exactly); the encoder readings are the inverse kinematics' leg
    lengths less the leg length offsets."""
    true = Platform(machine().params.replace(leg_length_offsets=[1e-3, -2e-3, 0.0, 5e-4, 3e-3, -1e-3]))
    traj = Sines(PRIOR.home_pose, 5, duration=2.0)
    data = synthetic_measurements(true, traj, rate=250.0)
    assert len(data.t) == 501 and data.t[0] == 0.0 and data.t[-1] == 2.0 and data.rate == 250.0
    np.testing.assert_allclose(np.diff(data.t), 0.004, rtol=1e-12)  # reached 5.5e-14
    x = traj.sample(data.t)[0]
    np.testing.assert_allclose(data.lengths, true.leg_lengths(x) - true.params.leg_length_offsets, rtol=0, atol=1e-15)


def test_command_line(tmp_path, capsys):
    true = machine()
    for name, seed in (("run.csv", 3), ("held.csv", 4)):
        synthetic_measurements(true, Sines(PRIOR.home_pose, seed, duration=30.0, scale=1.5), rate=RATE, noise_length=NOISE_LENGTH,
                               noise_force=NOISE_FORCE, seed=seed).to_csv(tmp_path / name)
    main(["identify", str(tmp_path / "run.csv"), "--validate", str(tmp_path / "held.csv"),
          "--output", str(tmp_path / "id.toml"), "--report", str(tmp_path / "report.json"), "--cutoff", str(CUTOFF)])
    out = capsys.readouterr().out
    assert "platform.m + 6 piston.m" in out and "held-out run" in out
    # what it wrote is the Python API's identification of the same files
    result = identify(PRIOR, Measurements.from_csv(tmp_path / "run.csv"), cutoff=CUTOFF)
    rms = validation(result, PRIOR, Measurements.from_csv(tmp_path / "held.csv"), cutoff=CUTOFF)[3]
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["never_act"] == ["cylinder.m", "cylinder.Ixx", "piston.Ixx"]
    np.testing.assert_equal({k: v for k, v in report.items() if k != "validation"},
                            json.loads(json.dumps(result.summary())))
    assert report["validation"]["rms"] == rms.tolist() and max(rms) < 1.5 * NOISE_FORCE
    with warnings.catch_warnings():  # the legs' I_yy and I_zz are identified apart
        warnings.simplefilter("ignore", NonAxisymmetricLegWarning)
        written, api = Platform.from_file(tmp_path / "id.toml").params, result.params()
        np.testing.assert_array_equal(written.inertial_vector(), api.inertial_vector())
        np.testing.assert_array_equal(written.viscous_friction, api.viscous_friction)
        np.testing.assert_array_equal(written.coulomb_friction, api.coulomb_friction)
        assert written.replace(name=api.name) == api
    (tmp_path / "bad.csv").write_text("t,L0\n0,1\n")
    with pytest.raises(SystemExit) as exit_info:
        main(["identify", str(tmp_path / "bad.csv")])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("stewart identify: error: ") and len(err.strip().splitlines()) == 1
