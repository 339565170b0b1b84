"""MPC cueing keeps the platform's limits by construction (stewart.cueing.planner): on
random realistic logs (steps and ramps of specific force up to 1 g, sustained tilt
coordination, rate spikes, rough flight; 50 to 1000 Hz) and on a car's lane change ended by
hard braking that stops abruptly, on both presets, the reference MPC writes holds the stroke,
leg speed, actuator forces and joint cones by the library's own exact check, the tilt rate
wherever no step had to yield it, and the closed loop stays within its stroke, leg speed and
force limits. A longer
sweep of the same logs runs in make test-cueing-sweep."""

import os

import numpy as np
import pytest
from cli_run import call

import stewart
from stewart.cueing import VehicleLog, mpc, planner
from stewart.model.reachability import reachability

G = 9.81
#: Seeds of the random logs make test runs; STEWART_CUEING_SWEEP=N runs N more (the sweep).
SEEDS = range(int(os.environ.get("STEWART_CUEING_SWEEP", "0")) or 4)
PRESETS = ("narayan2017", "motion_simulator")


@pytest.fixture(scope="module")
def platforms():
    return {name: stewart.Platform.preset(name) for name in PRESETS}


def _smooth(s):
    s = np.clip(s, 0.0, 1.0)
    return s ** 3 * (10.0 - 15.0 * s + 6.0 * s ** 2)


def _pulse(t, start, duration, ramp_in, ramp_out):
    """1 from ``start`` for ``duration`` seconds, in and out over the ramps (0: a step)."""
    rise = _smooth((t - start) / ramp_in) if ramp_in > 0 else (t >= start).astype(float)
    end = start + duration
    return rise - (_smooth((t - end) / ramp_out) if ramp_out > 0 else (t >= end).astype(float))


def random_log(seed: int) -> VehicleLog:
    """A vehicle's log from ``seed``: one to three of a step or ramp of specific force up to
    1 g along any axis (each end abrupt or ramped), a sustained longitudinal or lateral demand
    (tilt coordination), a rate spike up to 2 rad/s of 20 to 200 ms, and rough flight
    (band-limited noise in every channel); at 50, 100, 200 or 1000 Hz (1000 Hz logs 1 s long,
    the others 3 s)."""
    rng = np.random.default_rng(seed)
    rate = float(rng.choice([50.0, 100.0, 200.0, 1000.0]))
    duration = 1.0 if rate > 200 else 3.0
    t = np.arange(int(round(duration * rate)) + 1) / rate
    f, w = np.zeros((len(t), 3)), np.zeros((len(t), 3))
    f[:, 2] = G
    knots = np.arange(0.0, duration + 0.2, 0.1)
    for kind in rng.choice(["force", "tilt", "spike", "rough"], size=rng.integers(1, 4)):
        start = rng.uniform(0.0, 0.6 * duration)
        if kind == "force":
            ramps = [rng.choice([0.0, rng.uniform(0.0, 1.0)]) for _ in range(2)]
            f[:, rng.integers(0, 3)] += rng.uniform(-G, G) * _pulse(t, start, rng.uniform(0.2, duration), *ramps)
        elif kind == "tilt":
            f[:, rng.integers(0, 2)] += rng.uniform(-5.0, 5.0) * _pulse(t, start, duration, rng.uniform(0.1, 0.5), 0.0)
        elif kind == "spike":
            w[:, rng.integers(0, 3)] += rng.uniform(-2.0, 2.0) * _pulse(t, start, rng.uniform(0.02, 0.2), 0.0, 0.0)
        else:
            scale = rng.uniform(0.2, 2.0)
            for j in range(3):
                f[:, j] += scale * np.interp(t, knots, rng.normal(size=len(knots)))
                w[:, j] += 0.1 * scale * np.interp(t, knots, rng.normal(size=len(knots)))
    return VehicleLog(t, f, w, f"random log {seed} ({rate:g} Hz)")


def step_end_log(rate: float = 100.0) -> VehicleLog:
    """A car at 25 m/s: a double lane change (a full sine of lateral acceleration, +-4 m/s^2,
    from 1 s to 6 s, yaw rate ay / v), then braking at 7 m/s^2 (0.25 s onset) to rest, where
    the braking ends at once and the log's pitch rate jolts (2 rad/s nose up for 0.15 s).
    The old design (the box and the rest hard, the platform's limits soft, the tilt rate
    following the vehicle's) planned 4.6 % beyond the force limit of motion_simulator here."""
    v = 25.0
    t = np.arange(int(round(11.0 * rate)) + 1) / rate
    ay = 4.0 * np.sin(2 * np.pi * (t - 1.0) / 2.5) * ((t >= 1.0) & (t < 6.0))
    stop = 6.0 + v / 7.0
    ax = -7.0 * _smooth((t - 6.0) / 0.25) * (t < stop)
    wy = -2.0 * _pulse(t, stop, 0.15, 0.0, 0.0)
    zero = np.zeros_like(t)
    return VehicleLog(t, np.column_stack([ax, ay, zero + G]), np.column_stack([zero, wy, ay / v]), "step end")


def assert_within_limits(result, platform):
    """The reference within every limit by the exact check mpc runs and, recomputed here, by
    the library's exact kinematics and inverse dynamics; the tilt rate within its band at every
    sample when no step yielded it; the closed loop (when run) inside its limits."""
    assert result.inside and not result.beyond_limits, result.problems
    assert result.solver["qp_failures"] == 0 and result.solver["qp_levels"]["brake"] == 0, result.solver
    limits = result.limits
    assert np.all(reachability(platform, result.poses).ok)
    _, speeds = platform.leg_rates(result.poses, result.velocities)
    assert np.max(np.abs(speeds)) <= limits["leg_velocity"]
    forces = platform.inverse_dynamics(result.poses, result.velocities, result.accelerations)
    assert np.max(np.abs(forces)) <= limits["force"]
    if result.solver["qp_levels"]["tilt"] == 0:
        # the roll and pitch rates after each step, against the band of the vehicle's rates then
        vehicle = result.log.w[:-1, [1, 0]]
        rates = result.velocities[1:, [4, 5]]
        slack = result.params.tilt_rate * (1.0 + 1e-5)
        assert np.all(rates >= np.minimum(vehicle, 0.0) - slack) and np.all(rates <= np.maximum(vehicle, 0.0) + slack)
    if result.simulation is not None:  # (its actuators may saturate at the limit: a problem noted, not a failure)
        sim = result.simulation
        assert sim.completed, result.problems
        lengths = platform.leg_lengths(sim.x)
        lo, hi = platform.params.leg_length_limits
        assert lengths.min() >= lo and lengths.max() <= hi
        assert np.max(np.abs(sim.forces)) <= limits["force"]
        assert result.simulation_peaks["leg_velocity"] <= limits["leg_velocity"]


@pytest.mark.parametrize("seed", SEEDS)
def test_random_logs_give_references_within_every_limit(platforms, seed):
    """Each random log on one preset (by the seed's parity), the closed loop run too."""
    platform = platforms[PRESETS[seed % 2]]
    assert_within_limits(mpc(random_log(seed), platform, simulate=True), platform)


@pytest.mark.parametrize("seed", SEEDS[:2] if len(SEEDS) == 4 else SEEDS)
def test_random_logs_on_simrig100_give_references_within_every_limit(seed):
    """The same random logs on the rotary sim-racing rig: every pose within the rig's workspace
    (crank angles, reach, rod-crank angles, ball-joint cones, base clearance), every crank rate
    and motor torque within its limit (tests/test_cueing_rotary.py checks them by the oracle and
    numpy geometry)."""
    from stewart.cueing import rotary

    rig = stewart.RotaryPlatform.preset("simrig100")
    result = mpc(random_log(seed), rig)
    assert result.inside and not result.beyond_limits, result.problems
    assert result.solver["qp_failures"] == 0 and result.solver["qp_levels"]["brake"] == 0, result.solver
    assert np.all(rotary.check_poses(rig, result.poses).ok)
    assert np.all(np.abs(rig.crank_rates(result.poses, result.velocities)) <= rig.params.motor_speed_limit)
    torques = rig.inverse_dynamics(result.poses, result.velocities, result.accelerations)
    assert np.all(np.abs(torques) <= rig.params.motor_torque_limit)


def test_step_end_on_narayan2017(platforms):
    platform = platforms["narayan2017"]
    assert_within_limits(mpc(step_end_log(), platform, simulate=True), platform)


@pytest.mark.slow
def test_step_end_on_motion_simulator_by_the_cli(platforms, tmp_path):
    """The issue's path: stewart cueing LOG --method mpc on motion_simulator with the defaults
    exits 0 and writes the reference, whose poses, rates and accelerations hold every limit."""
    import json

    step_end_log().to_csv(tmp_path / "step_end.csv")
    run = call("cueing", tmp_path / "step_end.csv", "--method", "mpc", "--preset", "motion_simulator",
               "--simulate", "--output", tmp_path / "ref.csv", "--report", tmp_path / "r.json")
    assert run.returncode == 0, run.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["peak_force"] <= report["limits"]["force"]
    assert report["peak_leg_velocity"] <= report["limits"]["leg_velocity"]
    ref = np.genfromtxt(tmp_path / "ref.csv", delimiter=",", names=True)
    columns = ref.dtype.names
    poses, rates, accelerations = (np.column_stack([ref[c] for c in columns[1 + 6 * k: 7 + 6 * k]]) for k in range(3))
    platform = platforms["motion_simulator"]
    assert np.all(reachability(platform, poses).ok)
    assert np.max(np.abs(platform.leg_rates(poses, rates)[1])) <= report["limits"]["leg_velocity"]
    assert np.max(np.abs(platform.inverse_dynamics(poses, rates, accelerations))) <= report["limits"]["force"]


def test_brake_step_holds_the_forces_when_no_plan_holds_the_legs(platforms):
    """A platform driven at a stroke end faster than any input can stop it within a sample: no
    level has a plan, and the brake step's forces are within the limit, exactly."""
    platform = platforms["motion_simulator"]
    qp = planner.CueingQP(platform, stewart.cueing.MPCParams.for_platform(platform), 0.01)
    lo, hi = platform.params.leg_length_limits
    x0 = qp.home.copy()
    while np.max(platform.leg_lengths(x0 + [0, 0, 0.001, 0, 0, 0])) < hi:  # up to the legs' longest
        x0[2] += 0.001
    v0 = np.array([0.0, 0.0, 0.6, 0.0, 0.0, 0.0])
    u, _, _, info = qp.solve(x0, v0, np.zeros(qp.vestibular.n), np.tile([0, 0, G, 0, 0, 0], (qp.n, 1)))
    assert info["level"] == "brake"
    force = platform.inverse_dynamics(x0, v0, u[0])
    assert np.max(np.abs(force)) <= qp.params.force
    assert np.abs(v0 + qp.dt * u[0])[2] < v0[2]  # it brakes


def test_next_sample_holds_where_the_linearization_passes_it(platforms, monkeypatch):
    """At 10 Hz (the first interval one sample long) from a pose 2 cm inside the stroke under a
    lateral demand of 8 m/s^2 towards it, the plan's linearized legs rows let its next sample
    pass the cones (or the leg speed); solved again with those rows tightened, the next sample
    holds the stroke, leg speed and cones by the exact kinematics. Without the tightening it
    does not."""
    platform = platforms["narayan2017"]

    def next_sample(tightenings):
        monkeypatch.setattr(planner, "TIGHTENINGS", tightenings)
        qp = planner.CueingQP(platform, stewart.cueing.MPCParams.for_platform(platform), 0.1)
        x0 = qp.home.copy()
        while platform.leg_lengths(x0 + [0, 1e-3, 0, 0, 0, 0]).max() < platform.params.leg_length_limits[1] - 0.02:
            x0[1] += 1e-3
        u, _, _, info = qp.solve(x0, np.zeros(6), np.zeros(qp.vestibular.n), np.tile([0, 8.0, G, 0, 0, 0], (qp.n, 1)))
        values = qp.next_values(x0, np.zeros(6), u[0])
        low, high = qp.next_limits
        return info, bool(np.all(values >= low) and np.all(values <= high))

    info, within = next_sample(planner.TIGHTENINGS)
    assert info["tightened"] >= 1 and within
    assert not next_sample(0)[1]


def test_rate_spike_on_motion_simulator(platforms):
    """A roll-rate spike of 1.93 rad/s for 0.17 s from 0.1 s, then a yaw-rate spike of 0.92
    rad/s for 0.12 s from 1.46 s, at 200 Hz (the old design, whose tilt rate followed the
    vehicle's, planned 1.9 % beyond the force limit here)."""
    t = np.arange(801) / 200.0
    w = np.zeros((len(t), 3))
    w[:, 0] = -1.93 * _pulse(t, 0.098, 0.166, 0.0, 0.0)
    w[:, 2] = 0.918 * _pulse(t, 1.456, 0.118, 0.0, 0.0)
    f = np.tile([0.0, 0.0, G], (len(t), 1))
    platform = platforms["motion_simulator"]
    assert_within_limits(mpc(VehicleLog(t, f, w, "rate spikes"), platform, simulate=True), platform)
