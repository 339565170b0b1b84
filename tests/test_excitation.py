"""Excitation trajectories: the Fourier series and its derivatives, the leg accelerations,
and the designed excitation checked on grids the optimizer never saw."""

import dataclasses
import json

import numpy as np
import pytest
from cli_outputs import check_excitation_csv

import stewart
from stewart.io import csvfile
from stewart.model import kinematics
from stewart.cli import main
from stewart.identification.base_parameters import base_parameters
from stewart.identification.excitation import Limits, condition_number, design_excitation
from stewart.motion.trajectory import FourierTrajectory, SampledTrajectory
from stewart.motion.trajectory import load as load_trajectory
from stewart.studies.workspace import reachability

#: A short design: few harmonics, samples, starts and iterations (seconds, not minutes).
SMALL = dict(period=4.0, harmonics=3, samples=40, starts=2, max_iterations=25, seed=1)
#: Limits of the small design: the force limit binds (the platform's weight alone needs
#: about 20 N a leg).
FORCE_LIMIT = 26.0
#: Central-difference step [s] and the dense check grid (times the optimizer never used).
STEP = 1e-5
DENSE = 4001


@pytest.fixture(scope="module")
def plat():
    params = stewart.PlatformParams.preset("narayan2017").replace(
        viscous_friction=[20.0, 25.0, 30.0, 20.0, 25.0, 30.0], coulomb_friction=[1.0, 0.5, 1.5, 1.0, 0.5, 1.5])
    return stewart.Platform(params)


@pytest.fixture(scope="module")
def design(plat):
    return design_excitation(plat, force_limit=FORCE_LIMIT, **SMALL)


def _random_series(plat, seed=3, harmonics=4, period=2.5):
    rng = np.random.default_rng(seed)
    scale = np.array([0.01, 0.01, 0.01, 0.03, 0.03, 0.03])[:, None]
    return FourierTrajectory(plat.home_pose, period, scale * rng.normal(size=(6, harmonics)),
                             scale * rng.normal(size=(6, harmonics)))


def _central(function, t, h=STEP):
    return (function(t + h) - function(t - h)) / (2 * h)


def test_fourier_series_rates_are_its_derivatives(plat):
    traj = _random_series(plat)
    t = np.linspace(0.05, 2.45, 41)
    x, xd, xdd = traj.sample(t)
    # central differences' truncation and rounding: reached 1.2e-9 and 1.1e-8
    np.testing.assert_allclose(_central(lambda s: traj.sample(s)[0], t), xd, rtol=0, atol=5e-8)
    np.testing.assert_allclose(_central(lambda s: traj.sample(s)[1], t), xdd, rtol=0, atol=5e-7)
    # The series' mean velocity is zero: the pose returns after a period.
    np.testing.assert_allclose(traj.sample(0.0)[0], traj.sample(traj.period)[0], atol=1e-15, rtol=2e-13)  # reached 1/98 of it


def test_leg_accelerations_are_derivatives_of_the_leg_velocities(plat):
    traj = _random_series(plat)
    t = np.linspace(0.05, 2.45, 41)
    x, xd, xdd = traj.sample(t)
    expected = _central(lambda s: kinematics.leg_velocities(plat.params, *traj.sample(s)[:2]), t)
    got = kinematics.leg_accelerations(plat.params, x, xd, xdd)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-8 * np.max(np.abs(expected)))  # reached 1/8 of it
    assert got.shape == (41, 6) and kinematics.leg_accelerations(plat.params, x[0], xd[0], xdd[0]).shape == (6,)


def test_fourier_trajectory_holds_its_start_at_rest_outside_its_duration(plat):
    traj = _random_series(plat)
    x, xd, xdd = traj.sample(np.array([-1.0, traj.duration + 1.0]))
    np.testing.assert_allclose(x, np.vstack([traj.series(0.0)[0]] * 2), rtol=1e-15, atol=0)  # batch vs one row
    assert not xd.any() and not xdd.any()


def test_condition_number_is_invariant_to_column_scaling():
    rng = np.random.default_rng(0)
    matrix = rng.normal(size=(50, 4))
    scaled = matrix * np.array([1e-6, 1.0, 1e4, 3.0])
    assert condition_number(scaled) == pytest.approx(condition_number(matrix), rel=1e-14)  # reached 1.5e-16
    # Orthogonal columns of any lengths: 1. A zero column: not identifiable, inf.
    q = np.linalg.qr(matrix)[0] * np.array([2.0, 5.0, 0.1, 7.0])
    assert condition_number(q) == pytest.approx(1.0, rel=1e-14)  # reached 2.2e-16
    assert condition_number(np.column_stack([matrix, np.zeros(50)])) == np.inf
    # A batch (..., m, r): each matrix's own, as numpy's cond of its normalized columns.
    zeroed = matrix * np.array([1.0, 1.0, 0.0, 1.0])
    batch = condition_number(np.stack([[matrix, scaled], [q, zeroed]]))
    expected = [np.linalg.cond(m / np.linalg.norm(m, axis=0)) for m in (matrix, scaled, q)]
    assert batch.shape == (2, 2) and batch[1, 1] == np.inf
    np.testing.assert_allclose(batch.ravel()[:3], expected, rtol=1e-14)  # reached 0 (both SVDs)


def test_limit_slacks_by_hand():
    """The relative slack of each kind of limit at two states, worked by hand: lengths 1 to 2 m
    (half the stroke 0.5 m), 0.4 m/s, 2 m/s^2, 100 N and a singularity margin of 0.2."""
    lim = Limits((1.0, 2.0), 0.4, 2.0, 100.0, 0.2)
    lengths = np.array([[1.5, 1.2, 1.9, 1.5, 1.5, 1.5], [1.1, 1.5, 1.5, 1.5, 1.5, 1.95]])
    rates = np.array([[0.1, -0.3, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.5, 0.0]])
    accelerations = np.array([[0.0, 0.0, -1.5, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]])
    forces = np.array([[10.0, -20.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, -150.0]])
    slack = lim.slack(lengths, rates, accelerations, forces, np.array([0.3, 0.1]))
    # stroke: the nearest end 0.1 m (1.9 m) and 0.05 m (1.95 m) away, over 0.5 m
    np.testing.assert_allclose(slack, [[0.2, 1 - 0.3 / 0.4, 1 - 1.5 / 2.0, 1 - 20 / 100, 0.3 / 0.2 - 1],
                                       [0.1, 1 - 0.5 / 0.4, 1 - 1.0 / 2.0, 1 - 150 / 100, 0.1 / 0.2 - 1]],
                               rtol=1e-14, atol=1e-15)  # reached 8.3e-16


def test_the_optimizer_sees_a_state_where_the_model_is_undefined_as_breaking_the_limits(plat):
    """SLSQP needs finite constraint values: at a state where the forces are undefined (the
    platform in the base plane, J_C singular) the force limit is broken, with the same value as
    a limit broken by overflow (a finite force over a limit of 5e-324 N, at the home pose)."""
    from stewart.identification.excitation import _Problem, _Series

    series = _Series(1, 4.0, np.ones(6), rest=False)  # one harmonic, x = centre + a sin(pi t / 2)
    centre = plat.home_pose * [1, 1, 0, 1, 1, 1]
    amplitudes = np.zeros((6, series.width))
    amplitudes[2, 0] = plat.home_pose[2]  # z from 0 at t = 0 to home at t = 1 s
    problem = _Problem(plat, base_parameters(plat), Limits((0.0, 1.0), 1e3, 1e5, 5e-324, 1e-3), series, centre,
                       np.array([0.0, 1.0]), plat.params.inertial_vector())
    _, slack, ok = problem.evaluate(amplitudes.reshape(1, -1))
    np.testing.assert_allclose(problem.series.states(centre, amplitudes.reshape(1, -1), np.array([0.0, 1.0]))[0][0],
                               [centre, plat.home_pose], atol=1e-16)
    undefined, overflowed = slack[0, :, 3]
    assert undefined < 0 and undefined == overflowed and not ok[0]


def test_the_optimizer_derivatives_are_those_of_its_values(plat):
    """The forward differences SLSQP gets for the objective and the 60 constraint slacks (12
    samples, 5 limits) against central differences of the values, 18 variables of a 3-harmonic
    series that starts at rest (reached 1.3e-5 and 3.5e-5, relative to the norms: forward
    differences are first order)."""
    from stewart.identification.excitation import _Problem, _Series, limits

    bounds = limits(plat, plat.home_pose, force_limit=FORCE_LIMIT)
    stroke = bounds.lengths[1] - bounds.lengths[0]
    radius = np.max(np.linalg.norm(plat.params.platform_points, axis=1))
    series = _Series(3, 4.0, np.array([stroke] * 3 + [stroke / radius] * 3) / 3, True)
    problem = _Problem(plat, base_parameters(plat), bounds, series, plat.home_pose, np.arange(12) / 3.0,
                       plat.params.inertial_vector())
    z = 0.05 * np.random.default_rng(2).normal(size=6 * series.width)
    steps = 1e-5 * np.eye(len(z))
    central = np.array([(problem.constraints(z + e) - problem.constraints(z - e)) / 2e-5 for e in steps]).T
    slope = np.array([(problem.objective(z + e) - problem.objective(z - e)) / 2e-5 for e in steps])
    assert np.linalg.norm(problem.constraints_jacobian(z) - central) <= 1e-3 * np.linalg.norm(central)
    assert np.linalg.norm(problem.objective_gradient(z) - slope) <= 1e-3 * np.linalg.norm(slope)


def test_design_lowers_the_condition_number(design):
    assert design.feasible and not design.problems
    assert np.isfinite(design.condition) and design.condition < design.initial_condition
    assert design.starts == SMALL["starts"]


def test_design_condition_number_is_that_of_the_stacked_base_regressor(plat, design):
    base = base_parameters(plat)
    assert design.base_names == tuple(base.names)
    t = np.arange(SMALL["samples"]) * SMALL["period"] / SMALL["samples"]
    x, xd, xdd = design.trajectory.sample(t)
    stacked = base.reduce(plat.regressor(x, xd, xdd)).reshape(-1, len(base.names))
    normalized = stacked / np.linalg.norm(stacked, axis=0)
    assert design.condition == pytest.approx(np.linalg.cond(normalized), rel=5e-14)  # reached 6.6e-16


def test_design_is_periodic_and_starts_at_rest(design):
    traj = design.trajectory
    start, end = traj.series(0.0), traj.series(traj.period)
    for a, b in zip(start, end):
        np.testing.assert_allclose(a, b, atol=1e-14, rtol=1e-9)  # reached 1/35 of it
    np.testing.assert_allclose(start[0], traj.centre, atol=2e-15, rtol=2e-10)  # reached 1/36 of it
    np.testing.assert_allclose(start[1], 0.0, atol=2e-15)  # reached 1/31 of it
    np.testing.assert_allclose(start[2], 0.0, atol=1e-14)  # reached 1/47 of it
    assert traj.starts_at_rest


def test_design_held_every_limit_at_its_samples_before_the_check(plat, design):
    """The optimizer sees the limits at its 40 samples only, and a start it leaves outside them
    is scaled back in there: the amplitudes before the dense grid's scaling (the design's over
    its ``scaled``) hold every limit at those samples (to SLSQP's 1e-6), with the leg rates from
    the kinematics and the forces from the platform's own model (with its friction)."""
    traj = design.trajectory
    before = FourierTrajectory(traj.centre, traj.period, traj.sine / design.scaled, traj.cosine / design.scaled)
    x, xd, xdd = before.sample(np.arange(SMALL["samples"]) * SMALL["period"] / SMALL["samples"])
    slack = design.limits.slack(plat.leg_lengths(x), kinematics.leg_velocities(plat.params, x, xd),
                                kinematics.leg_accelerations(plat.params, x, xd, xdd),
                                plat.actuator_forces(x, xd, xdd), reachability(plat, x).margin)
    assert np.min(slack) >= -1e-6 and reachability(plat, x).ok.all()
    assert design.scaled < 1.0  # the dense grid found the limits overstepped between the samples


def test_design_keeps_every_limit_on_a_dense_grid(plat, design):
    """The limits at 4001 times (the optimizer saw 40), with the leg rates taken by central
    differences of the leg lengths, not by the package's kinematics."""
    traj, lim = design.trajectory, design.limits
    t = np.linspace(0.0, traj.period, DENSE)
    x, xd, xdd = traj.sample(t)
    lengths = plat.leg_lengths(x)
    rates = _central(lambda s: plat.leg_lengths(traj.series(s)[0]), t)
    accelerations = (plat.leg_lengths(traj.series(t + 1e-4)[0]) - 2 * lengths
                     + plat.leg_lengths(traj.series(t - 1e-4)[0])) / 1e-8
    low, high = plat.params.leg_length_limits
    stroke = high - low
    assert np.all(lengths >= low + 0.05 * stroke) and np.all(lengths <= high - 0.05 * stroke)
    assert lim.lengths == pytest.approx((low + 0.05 * stroke, high - 0.05 * stroke), rel=1e-15, abs=0)
    assert lim.leg_velocity == pytest.approx(stroke, rel=1e-15) and lim.leg_acceleration == pytest.approx(10 * stroke, rel=1e-15)
    assert np.max(np.abs(rates)) <= lim.leg_velocity
    assert np.max(np.abs(accelerations)) <= lim.leg_acceleration * (1 + 1e-6)
    forces = plat.actuator_forces(x, xd, xdd)
    assert np.max(np.abs(forces)) <= FORCE_LIMIT
    check = reachability(plat, x)
    assert check.ok.all()
    centre_margin = reachability(plat, traj.centre).margin[0]
    assert np.min(check.margin) >= 0.5 * centre_margin
    # The motion is substantial: some limit is close to binding.
    assert max(np.max(np.abs(forces)) / FORCE_LIMIT, np.max(np.abs(rates)) / lim.leg_velocity,
               (np.max(lengths) - low) / stroke) > 0.5


def test_machine_csv_round_trips(plat, design, tmp_path):
    path = tmp_path / "excitation.csv"
    design.to_csv(path, plat, rate=200.0)
    columns = ["t", "x", "y", "z", "psi", "theta", "phi"] + [f"L{i}" for i in range(6)] \
        + [f"L{i}_dot" for i in range(6)]
    table = csvfile.read(path, columns)
    t = table[:, 0]
    np.testing.assert_allclose(np.diff(t), 1 / 200.0, rtol=5e-12)  # reached 6.7e-14
    assert t[-1] == pytest.approx(design.trajectory.duration, rel=1e-12)  # the file's 12 digits: reached 0
    x, xd, _ = design.trajectory.sample(t)
    np.testing.assert_allclose(table[:, 1:7], x, rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(table[:, 7:13], plat.leg_lengths(x), rtol=1e-11)
    np.testing.assert_allclose(table[:, 13:], _central(lambda s: plat.leg_lengths(design.trajectory.series(s)[0]), t),
                               atol=1e-9, rtol=1e-8)  # reached 1/40 of it
    # Read back as a trajectory: the spline through the rows follows the series.
    again = SampledTrajectory.from_csv(path)
    inner = np.linspace(0.0, design.trajectory.duration, 777)
    np.testing.assert_allclose(again.sample(inner)[0], design.trajectory.sample(inner)[0], atol=2e-9, rtol=2e-9)  # reached 1/44 of it


def test_machine_table_needs_two_to_1e8_samples(plat, design):
    """The 4 s design at 0.5 Hz: 2 samples, the rows at t = 0, 2 and 4 s; at 0.25 Hz one sample
    and at 1e8 Hz 4e8 are refused, naming the rate."""
    names, rows = design.machine_table(plat, 0.5)
    assert names[0] == "t" and rows[:, 0].tolist() == [0.0, 2.0, 4.0]
    np.testing.assert_allclose(rows[:, 1:7], design.trajectory.sample(rows[:, 0])[0], rtol=1e-15)
    with pytest.raises(ValueError, match=r"^rate: 0.25 Hz gives 1 samples over 4 s; need 2 to 1e8$"):
        design.machine_table(plat, 0.25)
    with pytest.raises(ValueError, match=r"^rate: 1e\+08 Hz gives 400000000 samples over 4 s; need 2 to 1e8$"):
        design.machine_table(plat, 1e8)


@pytest.mark.parametrize("suffix", ["toml", "json"])
def test_trajectory_file_round_trips_exactly(design, tmp_path, suffix):
    path = tmp_path / f"excitation.{suffix}"
    design.save(path)
    again = load_trajectory(path)
    assert isinstance(again, FourierTrajectory)
    t = np.linspace(-1, 5, 101)
    for a, b in zip(again.sample(t), design.trajectory.sample(t)):
        np.testing.assert_array_equal(a, b)


def test_simulator_follows_the_excitation(plat, design):
    run = stewart.simulate(plat, design.trajectory, stewart.ComputedTorque.tuned(5.0))
    assert run.ok, run.problems
    assert run.summary()["rms_position_error"] < 1e-10  # reached 2.7e-12 m


@pytest.mark.parametrize("change, message", [
    (dict(period=0.0), "period: must be a positive"),
    (dict(period="10"), "period:"),
    (dict(harmonics=1), "harmonics: a series that starts at rest needs at least 2"),
    (dict(harmonics=2.5), "harmonics: expected an integer"),
    (dict(samples=0), "samples: must be from 1"),
    (dict(samples=2), "samples: 2 samples give 12 equations"),
    (dict(starts=True), "starts: expected an integer"),
    (dict(seed=0.5), "seed: expected a whole number >= 0, got 0.5"),
    (dict(seed=-1), "seed: expected a whole number >= 0, got -1"),
    (dict(max_leg_velocity=-1.0), "max_leg_velocity: must be a positive"),
    (dict(max_leg_acceleration=np.nan), "max_leg_acceleration: must be a positive"),
    (dict(force_limit=0.0), "force_limit: must be a positive"),
    (dict(min_margin=1.5), "min_margin: must be below 1"),
    (dict(stroke_margin=0.6), "stroke_margin: must be from 0 to below 0.5"),
    (dict(centre=[0, 0, 0.25]), r"centre: expected shape \(6,\)"),
    (dict(centre=[0, 0, 0.5, 0, 0, 0]), "centre: "),
    (dict(force_limit=5.0), r"centre: the centre pose at rest is outside the limits \(actuator force\)"),
])
def test_bad_arguments_are_named(plat, change, message):
    with pytest.raises(ValueError, match=message) as info:
        design_excitation(plat, **{**SMALL, **change})
    assert "\n" not in str(info.value)


def test_fewest_samples_give_an_equation_per_base_parameter(plat):
    """Each design sample gives 6 equations (one per leg) and the platform has 26 base
    parameters (the hand count of test_base_parameters: 20 rigid-body parameters less 3 that
    never act and 3 lumps, and 2 friction parameters per leg): 4 samples (24 equations) are
    refused, 5 (30) pass on to the next check (here a force limit the centre pose breaks)."""
    with pytest.raises(ValueError, match="^samples: 4 samples give 24 equations for 26 base parameters"):
        design_excitation(plat, **{**SMALL, "samples": 4})
    with pytest.raises(ValueError, match="^centre: the centre pose at rest is outside the limits"):
        design_excitation(plat, **{**SMALL, "samples": 5, "force_limit": 5.0})
    # By default 20 samples per harmonic: 2 harmonics give 240 equations, too few for 260
    # parameters (the base parameters ten times over), 3 give 360.
    base = base_parameters(plat)
    wide = dataclasses.replace(base, names=base.names * 10)
    with pytest.raises(ValueError, match="^samples: 40 samples give 240 equations for 260 base parameters"):
        design_excitation(plat, period=4.0, harmonics=2, base=wide)
    with pytest.raises(ValueError, match="^centre: the centre pose at rest is outside the limits"):
        design_excitation(plat, period=4.0, harmonics=3, base=wide, force_limit=5.0)


def test_bad_trajectory_files_are_named(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('kind = "fourier"\nperiod = -1.0\ncentre = [0, 0, 0.3, 0, 0, 0]\nsine = [[0.0]]\ncosine = [[0.0]]\n')
    with pytest.raises(ValueError, match="bad.toml: period: must be a positive"):
        load_trajectory(path)
    path.write_text('kind = "spline"\n')
    with pytest.raises(ValueError, match="bad.toml: kind: expected 'fourier'"):
        load_trajectory(path)


def test_excitation_command_writes_files_the_simulator_reads(tmp_path, capsys):
    csv, toml = tmp_path / "exc.csv", tmp_path / "exc.toml"
    main(["excitation", "--period", "4", "--harmonics", "3", "--samples", "40", "--starts", "1",
          "--max-iterations", "15", "--rate", "100", "--csv", str(csv), "--output", str(toml), "--json",
          "--no-progress"])
    summary = json.loads(capsys.readouterr().out)
    assert summary["feasible"] and summary["exit_code"] == 0
    assert summary["condition"] < summary["initial_condition"]
    assert summary["files"] == [str(csv), str(toml)]
    traj = FourierTrajectory.load(toml)
    assert summary["peaks"]["leg_velocity"] <= summary["limits"]["leg_velocity"]
    check_excitation_csv(csv, traj, stewart.Platform.preset("narayan2017"), 100.0)  # the command's default preset
    main(["simulate", "--trajectory", str(toml), "--controller", "ct", "--no-progress"])
    assert "outcome: completed" in capsys.readouterr().out


@pytest.mark.parametrize("flags, message", [
    (["--harmonics", "1"], "--harmonics: a series that starts at rest needs at least 2"),
    (["--output", "exc.csv"], "--output exc.csv: give a .toml or .json file name"),
    (["--stroke-margin", "0.7"], "--stroke-margin: must be from 0 to below 0.5"),
    (["--min-margin", "2"], "--min-margin: must be below 1"),
])
def test_excitation_command_errors_name_the_flag(flags, message, capsys):
    with pytest.raises(SystemExit) as info:
        main(["excitation", *flags, "--starts", "1", "--max-iterations", "1"])
    assert info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err
