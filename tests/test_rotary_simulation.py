"""Simulation and control of rotary rigs (issue 40): ``stewart.simulate`` on a
``RotaryPlatform`` against the independent model of tests/rotary_oracle.py (its energy, its
torques, an RK4 of its dynamics written here), computed torque's convergence at RK4 order, the
outcomes (saturation, crank limits and reach, non-finite, interruption), the files and the
command line."""

import csv

import numpy as np
import pytest

import stewart
import rotary_oracle as oracle
from cli_run import call
from interrupt import press_ctrl_c_after
from stewart.model.compiled import Mode, RotaryLoop
from stewart.motion.mechanism import DEFAULT_TARGETS
from test_rotary import random_rig

H = 1e-30  # complex step

RIG = random_rig(0)  # simrig100 made asymmetric: tilted axes, two reversed, payload off-centre


class Sway:
    """A smooth reference about ``centre``: ``centre + amplitude sin(w t)`` on every axis."""

    def __init__(self, centre, amplitude, frequency_hz, duration):
        self.centre, self.amplitude = np.asarray(centre), np.asarray(amplitude)
        self.w, self.duration = 2 * np.pi * frequency_hz, duration

    def sample(self, t):
        t = np.asarray(t, dtype=float)[..., None]
        s, c = np.sin(self.w * t), np.cos(self.w * t)
        return (self.centre + self.amplitude * s, self.w * self.amplitude * c, -self.w ** 2 * self.amplitude * s)


def _oracle_forward_dynamics(rig, x, xd, tau):
    """xdd from the oracle's torques, affine in xdd: tau = A xdd + b."""
    b = oracle.torques(rig, x, xd, np.zeros(6))
    A = np.column_stack([oracle.torques(rig, x, xd, e) - b for e in np.eye(6)])
    return np.linalg.solve(A, tau - b)


def _energy(rig, states):
    return np.array([oracle.energy(rig, s[:6], s[6:12], oracle.crank_angles(rig, s[:6])) for s in states])


def _simpson(values, dt):
    """Composite Simpson over an even number of intervals."""
    assert (len(values) - 1) % 2 == 0
    return dt / 3 * (values[0] + values[-1] + 4 * values[1:-1:2].sum() + 2 * values[2:-1:2].sum())


def test_power_balance_over_a_run_under_a_torque_schedule(figures):
    """Open loop under a torque schedule (the torques holding the start pose plus swings of 20 N m):
    the bodies' energy of the oracle changes by the motors' work, E(T) - E(0) = int tau . alpha'
    dt (Simpson on the samples); the work is a tenth of the energy's range, so flipping a
    torque's sign or losing a body's term fails."""
    rig = stewart.RotaryPlatform(RIG)
    x0 = rig.home + [0.01, -0.005, 0.0, 0.02, -0.01, 0.015]
    hold = rig.inverse_dynamics(x0, np.zeros(6), np.zeros(6))
    phase = np.arange(6)

    def schedule(t):
        return hold + 20.0 * np.sin(2 * np.pi * 3.0 * np.asarray(t)[:, None] + phase)

    move = stewart.PointToPoint(x0, x0, 0.2)
    run = stewart.simulate(rig, move, stewart.OpenLoop(), dt=5e-4, feedforward=schedule, check_workspace=False)
    assert run.completed and run.rotary, run.reason
    assert np.all(np.abs(run.torques) < rig.params.motor_torque_limit)  # no saturation: the schedule acts
    energy = _energy(RIG, np.hstack([run.x, run.xd]))
    work = _simpson(np.sum(run.torques * run.crank_rates, axis=1), 5e-4)
    assert abs(work) > 1.0  # J: the motors do work
    figures("rotary simulate: energy change against the motors' work (relative)",
            abs(energy[-1] - energy[0] - work) / abs(work), 1e-9)  # reached 7.3e-11 (Simpson's error at 0.5 ms)
    # The crank angles and rates of the run are the oracle's at its states.
    angles = np.array([oracle.crank_angles(RIG, x) for x in run.x])
    rates = np.array([oracle.crank_rates(RIG, x, xd) for x, xd in zip(run.x, run.xd)])
    figures("rotary simulate: crank angles and rates against the oracle",
            max(np.max(np.abs(run.crank_angles - angles)), np.max(np.abs(run.crank_rates - rates))),
            1e-13)  # reached 3.1e-15


def test_motor_friction_takes_its_power(figures):
    """Viscous and Coulomb friction on the cranks (--viscous, --coulomb): the energy changes by
    the work of the torques less the friction's, (tau - F_v alpha' - F_c tanh(alpha' / v_c)) .
    alpha'; the friction takes a third of the work, so a wrong sign fails."""
    rig = stewart.RotaryPlatform(RIG)
    x0 = rig.home
    hold = rig.inverse_dynamics(x0, np.zeros(6), np.zeros(6))
    law = dict(viscous=20.0, coulomb=0.5, coulomb_velocity=0.2)

    def schedule(t):
        return hold + 20.0 * np.sin(2 * np.pi * 3.0 * np.asarray(t)[:, None] + np.arange(6))

    run = stewart.simulate(rig, stewart.PointToPoint(x0, x0, 0.2), stewart.OpenLoop(), dt=5e-4, feedforward=schedule,
                           actuators=stewart.Actuators(**law), check_workspace=False)
    assert run.completed, run.reason
    energy = _energy(RIG, np.hstack([run.x, run.xd]))
    rate = run.crank_rates
    loss = law["viscous"] * rate + law["coulomb"] * np.tanh(rate / law["coulomb_velocity"])
    lost = _simpson(np.sum(loss * rate, axis=1), 5e-4)
    work = _simpson(np.sum(run.torques * rate, axis=1), 5e-4)
    assert lost > 0.2 * abs(work)
    figures("rotary simulate: energy change against the work less the motors' friction (relative)",
            abs(energy[-1] - energy[0] - (work - lost)) / abs(work), 1e-9)  # reached 1.8e-10 (Simpson's error at 0.5 ms)


def test_adaptive_and_rk4_agree():
    """DOP853 (rtol 1e-10) and RK4 at 1 ms on desktop_servo's default move under PID."""
    rig = stewart.RotaryPlatform.preset("desktop_servo")
    move = stewart.PointToPoint(rig.home, rig.home + DEFAULT_TARGETS["desktop_servo"], 1.0)
    fixed = stewart.simulate(rig, move, dt=1e-3)
    adaptive = stewart.simulate(rig, move, dt=1e-3, method="adaptive", rtol=1e-10, atol=1e-13)
    assert fixed.ok and adaptive.ok and adaptive.rotary
    # RK4's own error at 1 ms (against RK4 at 0.5 ms): 2.3e-10 of the excursion, 1.9e-7 of the torques
    # (2.4e-10 and 2.0e-7 against DOP853)
    assert np.max(np.abs(fixed.x - adaptive.x)) < 1e-9 * np.max(np.abs(fixed.x - rig.home))
    assert np.max(np.abs(fixed.torques - adaptive.torques)) < 1e-6 * np.max(np.abs(fixed.torques))


def test_energy_is_conserved_without_torque_and_gravity(figures):
    """Zero torque and no gravity: the rig coasts from a push and its energy stays (RK4 at 0.5 ms)."""
    params = RIG.replace(gravity=0.0)
    rig = stewart.RotaryPlatform(params)
    x0 = rig.home
    run = stewart.simulate(rig, stewart.PointToPoint(x0, x0, 0.2), stewart.OpenLoop(), dt=5e-4,
                           xd0=[0.05, -0.03, 0.04, 0.2, -0.1, 0.15], check_workspace=False)
    assert run.completed, run.reason
    energy = _energy(params, np.hstack([run.x, run.xd]))
    assert energy[0] > 1.0
    figures("rotary simulate: energy drift without torque or gravity, 0.2 s (relative)",
            np.max(np.abs(energy - energy[0])) / energy[0], 1e-13)  # reached 3.1e-15


def _computed_torque_error(rig, move, dt):
    run = stewart.simulate(rig, move, stewart.ComputedTorque.tuned(2.0), dt=dt)
    assert run.ok, run.problems
    return np.max(np.abs(run.tracking_error))


def test_computed_torque_tracks_at_integration_error_and_converges_at_rk4_order(figures):
    """Computed torque on the exact model, started on a smooth feasible reference: the error is
    the integration's alone, and falls 16-fold as the step halves."""
    rig = stewart.RotaryPlatform(RIG)
    move = Sway(rig.home, [0.02, -0.015, 0.02, 0.04, -0.03, 0.05], 1.0, 1.0)
    errors = [_computed_torque_error(rig, move, dt) for dt in (4e-3, 2e-3, 1e-3)]
    figures("rotary computed torque: tracking error at dt = 1 ms [m, rad]", errors[-1], 1e-10)  # reached 5.1e-12
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 3.7) & (orders < 4.3)), orders


def test_pid_against_an_rk4_of_the_oracle(figures):
    """The PID on the crank angles from a start off the reference, against the same closed loop
    written here: the oracle's crank angles, rates and forward dynamics (from its torques), the
    torques saturated at motor_torque_limit, classic RK4. The gains saturate the motors at the
    start, so the saturation is checked too."""
    rig = stewart.RotaryPlatform(RIG)
    pid = stewart.PID.tuned(rig, 4.0)
    move = Sway(rig.home, [0.01, 0.01, -0.01, 0.02, 0.03, -0.02], 2.0, 0.02)
    x0 = rig.home + [0.004, -0.003, 0.005, -0.01, 0.008, 0.006]
    dt = 2e-3
    run = stewart.simulate(rig, move, pid, dt=dt, x0=x0, xd0=np.zeros(6))
    limit = RIG.motor_torque_limit

    def rhs(t, y):
        x, xd, integral = y[:6], y[6:12], y[12:]
        xr, xdr, _ = (a[0] for a in move.sample([t]))
        alpha, rate = oracle.crank_angles(RIG, x), oracle.crank_rates(RIG, x, xd)
        error = np.remainder(oracle.crank_angles(RIG, xr) - alpha + np.pi, 2 * np.pi) - np.pi
        torque = pid.kp * error + pid.ki * integral + pid.kd * (oracle.crank_rates(RIG, xr, xdr) - rate)
        return np.concatenate([xd, _oracle_forward_dynamics(RIG, x, xd, np.clip(torque, -limit, limit)), error]), torque

    y = np.concatenate([x0, np.zeros(6), oracle.torques(RIG, x0, np.zeros(6), np.zeros(6)) / pid.ki])
    states, torques = [], []
    for k in range(len(run.t)):
        t = k * dt
        k1, torque = rhs(t, y)
        states.append(y)
        torques.append(torque)
        if k == len(run.t) - 1:
            break
        k2 = rhs(t + dt / 2, y + dt / 2 * k1)[0]
        k3 = rhs(t + dt / 2, y + dt / 2 * k2)[0]
        k4 = rhs(t + dt, y + dt * k3)[0]
        y = y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    states, torques = np.array(states), np.array(torques)
    assert np.any(np.abs(torques) > limit)  # the saturation acts
    assert any(p.startswith("commanded torque ") and " N m on motor " in p for p in run.problems), run.problems
    figures("rotary PID against an RK4 of the oracle: pose (relative to its excursion)",
            np.max(np.abs(run.x - states[:, :6])) / np.max(np.abs(states[:, :6] - x0)), 1e-13)  # reached 3.0e-15
    figures("rotary PID against an RK4 of the oracle: commanded torques (relative)",
            np.max(np.abs(run.commanded_forces - torques)) / np.max(np.abs(torques)), 1e-12)  # reached 6.9e-15
    np.testing.assert_array_equal(run.torques, np.clip(run.commanded_forces, -limit, limit))


def test_loop_derivative_is_the_generated_functions_bit_for_bit(simd_path):
    """The loop's right-hand side at a state: the crank angles, rates and accelerations are the
    batch functions' bits (open loop: the feed-forward torques act as they are)."""
    rig = stewart.RotaryPlatform(RIG)
    rng = np.random.default_rng(3)
    x = rig.home + rng.uniform(-0.01, 0.01, 6)
    xd, ff = rng.normal(scale=0.2, size=6), rng.normal(scale=10.0, size=6)
    loop = RotaryLoop(rig.kernel, Mode.OPEN_LOOP, np.zeros(6), np.zeros(6), np.zeros(6), np.full(6, np.inf),
                      (np.zeros(6), np.zeros(6), 1e-3), (np.zeros(6), np.zeros(6), 1e-3))
    ydot, torque, alpha, rate, status = loop.derivative(np.concatenate([x, xd, np.zeros(6)]), np.zeros(30), ff)
    assert status == 0
    batch = np.vstack([x, x + 0.001, x])
    np.testing.assert_array_equal(ydot[6:12], rig.forward_dynamics(batch, np.vstack([xd] * 3), ff)[2])
    np.testing.assert_array_equal(alpha, rig.crank_angles(batch)[0])
    np.testing.assert_array_equal(rate, rig.crank_rates(batch, xd)[2])
    np.testing.assert_array_equal(torque, ff)


@pytest.mark.parametrize("name", ["simrig100", "desktop_servo"])
def test_default_moves_of_the_presets(name):
    """Each rotary preset's default move (5 s from home) runs under its tuned PID and under
    computed torque within its torque limit and to the default tolerance."""
    rig = stewart.RotaryPlatform.preset(name)
    target = rig.home + DEFAULT_TARGETS[name]
    move = stewart.PointToPoint(rig.home, target, 5.0)
    for controller in (None, stewart.ComputedTorque.tuned()):
        run = stewart.simulate(rig, move, controller, dt=2e-3)
        assert run.ok, (name, run.problems)
        assert np.max(np.abs(run.commanded_forces)) < rig.params.motor_torque_limit[0]
        assert np.ptp(run.crank_angles, axis=0).min() > 0.02  # every crank turns


def test_crank_limit_stops_the_run_and_the_workspace_check_refuses_it():
    rig = stewart.RotaryPlatform.preset("simrig100")
    high = rig.home + [0, 0, 0.2, 0, 0, 0]  # above the cranks' +60 deg
    move = stewart.PointToPoint(rig.home, high, 1.0)
    with pytest.raises(stewart.WorkspaceError, match=r"trajectory: reference pose at t = .*crank \d at .* deg, "
                                                     r"outside its limits \[-60, 60\] deg"):
        stewart.simulate(rig, move)
    with pytest.raises(stewart.WorkspaceError, match=r"^x0: the start pose is outside the workspace: crank 0 "
                                                     r"cannot reach the pose$"):
        stewart.simulate(rig, move, x0=rig.home + [0, 0, 0.2, 0, 0, 0])
    run = stewart.simulate(rig, move, stewart.ComputedTorque.tuned(), check_workspace=False,
                           actuators=stewart.Actuators(force_limit=np.inf))
    assert run.outcome == "failed" and run.exit_code == 4
    assert run.stopped_leg is not None
    assert f"crank {run.stopped_leg} reached its upper angle limit 60 deg" in run.reason
    alpha = rig.crank_angles(run.x[-1])
    assert alpha[run.stopped_leg] > np.radians(60) and np.all(rig.crank_angles(run.x[:-1]) <= np.radians(60))


def test_a_crank_out_of_reach_stops_the_run():
    """Without angle limits the cranks turn until one cannot reach the pose: the generated crank
    angles' error, named in the outcome."""
    rig = stewart.RotaryPlatform(stewart.RotaryParams.preset("simrig100").replace(crank_angle_limits=None))
    high = rig.home + [0, 0, 0.3, 0, 0, 0]
    with pytest.raises(stewart.WorkspaceError, match=r"crank \d cannot reach the pose"):
        stewart.simulate(rig, stewart.PointToPoint(rig.home, high, 1.0))
    run = stewart.simulate(rig, stewart.PointToPoint(rig.home, high, 1.0), stewart.ComputedTorque.tuned(),
                           check_workspace=False, actuators=stewart.Actuators(force_limit=np.inf))
    assert run.outcome == "failed" and "cannot reach the pose at t = " in run.reason, run.reason


def test_non_finite_and_interrupted(monkeypatch):
    rig = stewart.RotaryPlatform.preset("simrig100")
    move = stewart.PointToPoint(rig.home, rig.home + DEFAULT_TARGETS["simrig100"], 1.0)
    run = stewart.simulate(rig, move, stewart.PID(kp=1e30, ki=0.0, kd=0.0), x0=rig.home + [0.01, 0, 0, 0, 0, 0],
                           actuators=stewart.Actuators(force_limit=np.inf))
    assert run.outcome == "failed" and run.exit_code == 4 and not run.completed
    press_ctrl_c_after(monkeypatch, 0.05)
    with pytest.raises(stewart.SimulationInterrupted) as caught:
        stewart.simulate(rig, stewart.PointToPoint(rig.home, rig.home, 20.0), dt=1e-3)
    assert caught.value.result.outcome == "interrupted" and caught.value.result.rotary


def test_bad_arguments_name_themselves():
    rig = stewart.RotaryPlatform.preset("simrig100")
    move = stewart.PointToPoint(rig.home, rig.home, 1.0)
    with pytest.raises(ValueError, match="^platform: expected a stewart.Platform or stewart.RotaryPlatform"):
        stewart.simulate("simrig100", move)
    with pytest.raises(ValueError, match="^dt: "):
        stewart.simulate(rig, move, dt=0.0)
    with pytest.raises(ValueError, match="^x0: "):
        stewart.simulate(rig, move, x0=[0, 0, np.nan, 0, 0, 0])
    run = stewart.simulate(stewart.RotaryParams.preset("simrig100"), move, dt=0.01)  # params compile
    assert run.ok and run.metadata["kind"] == "rotary"
    linear = stewart.simulate(stewart.Platform.preset("narayan2017"),
                              stewart.PointToPoint(stewart.Platform.preset("narayan2017").home_pose,
                                                   stewart.Platform.preset("narayan2017").home_pose, 0.05))
    with pytest.raises(AttributeError, match="^torques: a linear platform's run"):
        linear.torques


def test_csv_and_plots_name_crank_angles_and_torques(tmp_path):
    rig = stewart.RotaryPlatform.preset("desktop_servo")
    run = stewart.simulate(rig, stewart.PointToPoint(rig.home, rig.home + DEFAULT_TARGETS["desktop_servo"], 0.2),
                           dt=1e-3)
    run.to_csv(tmp_path / "run.csv")
    with open(tmp_path / "run.csv") as f:
        header = next(csv.reader(f))
    assert header[-18:] == ([f"alpha{i}" for i in range(6)] + [f"alpha{i}_dot" for i in range(6)]
                            + [f"torque{i}" for i in range(6)])
    data = np.loadtxt(tmp_path / "run.csv", delimiter=",", comments="#", skiprows=1)
    np.testing.assert_allclose(data[:, -18:-12], rig.crank_angles(run.x), rtol=1e-9, atol=1e-12)
    run.to_npz(tmp_path / "run.npz")
    with np.load(tmp_path / "run.npz") as npz:
        assert str(npz["kind"]) == "rotary"
        np.testing.assert_array_equal(npz["torques"], run.torques)
        np.testing.assert_array_equal(npz["crank_angles"], rig.crank_angles(run.x))
    pytest.importorskip("matplotlib")
    from stewart.io.plots import plot_run

    names = sorted(p.rsplit("/", 1)[-1] for p in map(str, plot_run(run, tmp_path, prefix="r")))
    assert names == ["r_crank_angles.png", "r_crank_rates.png", "r_error.png", "r_pose.png", "r_torques.png"]


# ---------------------------------------------------------------------------- the command line

def test_cli_default_move_of_a_rotary_preset(tmp_path):
    out = tmp_path / "run.csv"
    result = call("simulate", "--preset", "desktop_servo", "--dt", "0.002", "--csv", out, "--json")
    assert result.returncode == 0, result.stderr
    import json

    summary = json.loads(result.stdout)
    assert summary["outcome"] == "completed" and len(summary["peak_torque"]) == 6
    assert "peak_force" not in summary
    rig = stewart.RotaryPlatform.preset("desktop_servo")
    expected = stewart.simulate(rig, stewart.PointToPoint(rig.home, rig.home + DEFAULT_TARGETS["desktop_servo"], 5.0),
                                dt=2e-3)
    np.testing.assert_allclose(summary["peak_torque"], expected.summary()["peak_force"], rtol=1e-12)


def test_cli_rotary_parameter_file_saturation_exit_code(tmp_path):
    path = tmp_path / "rig.toml"
    stewart.RotaryParams.preset("simrig100").save(path)
    result = call("simulate", "--params", path, "--torque-limit", "25", "--move-time", "1", "--dt", "0.005",
                  "--tolerance", "1", "1")
    assert result.returncode == 6, result.stderr
    assert "outcome: saturated" in result.stdout and "N m on motor" in result.stdout
    assert "peak torque per motor [N m]: " in result.stdout


@pytest.mark.parametrize("args, message", [
    (["--preset", "simrig100", "--force-limit", "100"],
     "--force-limit: limits a linear platform's leg forces; a rotary rig takes --torque-limit"),
    (["--preset", "narayan2017", "--torque-limit", "100", "--target", "0", "0", "0.2", "0", "0", "0"],
     "--torque-limit: limits a rotary rig's motor torques; a linear platform takes --force-limit"),
    (["--preset", "simrig100", "--target", "0", "0", "0.9", "0", "0", "0"], "--target: "),
    (["--preset", "simrig100", "--torque-limit", "-1"], "argument --torque-limit: must be > 0"),
    (["--preset", "simrig100", "--dt", "0"], "argument --dt: "),
    (["--preset", "simrig100", "--bandwidth", "nan"], "argument --bandwidth: "),
    (["--preset", "simrig100", "--move-time", "0"], "argument --move-time: "),
    (["--preset", "simrig100", "--viscous", "-1"], "argument --viscous: "),
    (["--preset", "simrig100", "--coulomb", "x"], "argument --coulomb: "),
    (["--preset", "simrig100", "--duration", "0.0001", "--dt", "0.001"], "--duration: must be at least one step"),
])
def test_cli_bad_input(args, message):
    result = call("simulate", *args)
    lines = [line for line in result.stderr.strip().splitlines() if line.startswith("stewart simulate: error: ")]
    assert result.returncode in (2, 3), result.stderr
    assert len(lines) == 1 and message in lines[0], result.stderr  # argparse's usage above its own
    assert "Traceback" not in result.stderr


def test_cli_target_out_of_reach_is_a_workspace_error(tmp_path):
    result = call("simulate", "--preset", "simrig100", "--target", "0", "0", "0.9", "0", "0", "0")
    assert result.returncode == 3
    assert result.stderr.startswith("stewart simulate: error: --target: reference pose at t = ")
    assert "crank 0 at 60.04 deg, outside its limits [-60, 60] deg" in result.stderr
    path = tmp_path / "rig.toml"
    stewart.RotaryParams.preset("simrig100").replace(crank_angle_limits=None).save(path)
    result = call("simulate", "--params", path, "--target", "0", "0", "0.9", "0", "0", "0")
    assert result.returncode == 3 and "cannot reach the pose" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
