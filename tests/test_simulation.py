"""Simulation and control: convergence of the integrator, tracking, stroke limits, export."""

import numpy as np
import pytest

import stewart
from stewart.presets import narayan2017_target_pose


@pytest.fixture(scope="module")
def plat():
    return stewart.Platform.preset("narayan2017")


@pytest.fixture(scope="module")
def move(plat):
    return stewart.PointToPoint(plat.home_pose, narayan2017_target_pose(), 5.0)


def test_profiles_start_and_end_at_rest_and_integrate():
    start, goal = np.zeros(6), np.arange(1.0, 7.0)
    for profile in ("sinusoidal", "quintic"):
        traj = stewart.PointToPoint(start, goal, 2.0, profile)
        t = np.linspace(0, 2, 20001)
        x, xd, xdd = traj.sample(t)
        np.testing.assert_allclose(x[0], start, atol=1e-15)
        np.testing.assert_allclose(x[-1], goal, atol=1e-12)
        for arr in (xd, xdd):
            np.testing.assert_allclose(arr[[0, -1]], 0.0, atol=1e-12)
        # The rates are the derivatives of the path (trapezoid rule on a fine grid).
        np.testing.assert_allclose(x[0] + np.cumsum((xd[1:] + xd[:-1]) / 2 * 1e-4, axis=0)[-1], goal, rtol=1e-7)
        np.testing.assert_allclose(np.sum((xdd[1:] + xdd[:-1]) / 2 * 1e-4, axis=0), 0.0, atol=1e-7)
    # The sinusoidal profile's velocity peaks at mid-move at twice the mean.
    _, xd, _ = stewart.PointToPoint(start, goal, 2.0).sample(1.0)
    np.testing.assert_allclose(xd, 2 * goal / 2.0)


def test_pid_starts_bumpless(plat):
    """The PID's integral starts at the static leg forces of the start pose, so the legs
    carry the platform from t = 0 and it does not drop."""
    hold = stewart.PointToPoint(plat.home_pose, plat.home_pose, 1.0)
    run = stewart.simulate(plat, hold, duration=1.0)
    assert run.ok, run.problems
    static = stewart.reference.inverse_dynamics(plat.params, plat.home_pose, np.zeros(6), np.zeros(6))
    np.testing.assert_allclose(run.forces[0], static, rtol=1e-9)
    assert np.all(np.abs(static) > 1.0)  # the legs do carry the weight
    np.testing.assert_allclose(run.x, np.broadcast_to(plat.home_pose, run.x.shape), rtol=0, atol=1e-9)


def test_pid_integral_removes_an_offset(plat, figures):
    """Starting 2 mm low (held there by the bumpless integral), the PID's integral action
    moves the platform to the reference and settles on the static forces of the home pose."""
    hold = stewart.PointToPoint(plat.home_pose, plat.home_pose, 1.0)
    x0 = plat.home_pose - [0, 0, 0.002, 0, 0, 0]
    run = stewart.simulate(plat, hold, duration=6.0, x0=x0, xd0=np.zeros(6))
    assert run.ok, run.problems
    error = np.linalg.norm(run.tracking_error[:, :3], axis=1)
    figures("PID from a 2 mm offset: final position error [m]", error[-1], 1e-7)
    static = stewart.reference.inverse_dynamics(plat.params, plat.home_pose, np.zeros(6), np.zeros(6))
    np.testing.assert_allclose(run.forces[-1], static, rtol=1e-4)


def test_computed_torque_tracks_the_move(plat, move, figures):
    run = stewart.simulate(plat, move, stewart.ComputedTorque.tuned())
    assert run.completed
    figures("computed torque: max tracking error over the move [m]", np.max(np.abs(run.tracking_error[:, :3])), 1e-6)
    # The forces are the inverse dynamics of the reference (the model is exact).
    x, xd, xdd = move.sample(run.t)
    np.testing.assert_allclose(run.forces, plat.inverse_dynamics(x, xd, xdd), rtol=1e-6, atol=1e-6)


def test_pid_tracks_the_move_and_settles(plat, move):
    run = stewart.simulate(plat, move, duration=6.0)
    assert run.completed
    assert np.max(np.abs(run.tracking_error[:, :3])) < 1e-3
    assert np.linalg.norm(run.tracking_error[-1, :3]) < 1e-6


def test_rk4_converges_at_fourth_order(plat, move, figures):
    """PID closed loop (1 Hz tuning) over 0.5 s: halving dt divides the error by about 16.
    The error of step dt is estimated against the run at dt/2 (Richardson), so no exact
    solution is needed; the steps are small against the PID's fast leg mode (~700 1/s),
    where the asymptotic rate shows. The run starts 2 mm below the reference so that the
    error has a transient to converge on."""
    pid = stewart.PID.tuned(plat, bandwidth_hz=1.0)
    x0 = plat.home_pose - [0, 0, 0.002, 0, 0, 0]  # a start off the reference excites the fast mode
    runs = [stewart.simulate(plat, move, pid, duration=0.5, dt=dt, x0=x0).x for dt in (2e-4, 1e-4, 5e-5, 2.5e-5)]
    errors = [np.max(np.abs(a - b[::2])) for a, b in zip(runs, runs[1:])]
    ratios = [errors[0] / errors[1], errors[1] / errors[2]]
    figures("RK4 order: error ratio when halving dt (|ratio - 16|)", max(abs(r - 16) for r in ratios), 2.0)


@pytest.mark.parametrize("controller, dt", [("computed torque", 1e-3), ("PID", 2.5e-4)])
def test_adaptive_agrees_with_rk4(plat, move, controller, dt):
    ctrl = stewart.ComputedTorque.tuned() if controller == "computed torque" else stewart.PID.tuned(plat)
    rk4 = stewart.simulate(plat, move, ctrl, duration=1.0, dt=dt)
    adaptive = stewart.simulate(plat, move, ctrl, duration=1.0, dt=dt, method="adaptive", rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(adaptive.x, rk4.x, rtol=0, atol=1e-9)
    # Forces amplify velocity differences by the PID's Kd (~1e4 N s/m) during the initial
    # fast transient; compare them once it has died out.
    late = rk4.t > 0.05
    np.testing.assert_allclose(adaptive.forces[late], rk4.forces[late], rtol=0, atol=1e-6 * np.max(np.abs(rk4.forces)))


@pytest.mark.parametrize("method", ["rk4", "adaptive"])
def test_stroke_limit_stops_the_run_with_its_reason(plat, method):
    low = plat.home_pose.copy()
    low[2] = 0.15  # below the 0.19 m minimum leg length
    move_down = stewart.PointToPoint(plat.home_pose, low, 3.0)
    with pytest.raises(stewart.WorkspaceError, match=r"shorter than the minimum length 0.19 m .* at t = 1\.") as info:
        stewart.simulate(plat, move_down, method=method)
    first = info.value.times[0]
    assert np.min(plat.leg_lengths(move_down.sample(first)[0])) < 0.19
    assert np.min(plat.leg_lengths(move_down.sample(first - 1e-3)[0])) >= 0.19
    run = stewart.simulate(plat, move_down, method=method, check_workspace=False)
    assert not run.completed and run.outcome == "failed" and run.exit_code == 4 and not run.ok
    assert "reached its minimum length 0.19 m" in run.reason
    leg = run.stopped_leg
    assert run.lengths[-1, leg] == pytest.approx(0.19, abs=1e-4 if method == "rk4" else 1e-9)
    assert np.all(run.lengths[:-1] >= 0.19)
    assert run.t[-1] < 3.0 and f"t = {run.t[-1]:.4f} s" in run.reason


def test_saturation_and_friction(plat, move):
    limit = 21.0
    run = stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), actuators=stewart.Actuators(force_limit=limit))
    assert np.max(np.abs(run.forces)) == pytest.approx(limit)
    np.testing.assert_array_equal(run.forces, np.clip(run.commanded_forces, -limit, limit))
    # Computed torque commands the inverse dynamics of the reference until it saturates first.
    first = np.argmax(np.any(np.abs(run.commanded_forces) > limit, axis=1))
    x, xd, xdd = move.sample(run.t[first])
    assert np.max(np.abs(plat.inverse_dynamics(x, xd, xdd))) > limit
    # Saturated, it cannot follow: a leg reaches its stroke limit, the more severe outcome.
    assert run.outcome == "failed" and run.exit_code == 4 and "reached its minimum length" in run.problems[0]
    assert f"at t = {run.t[first]:.4f} s exceeded the actuator limit 21 N" in run.problems[1]
    short = stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), duration=1.0,
                             actuators=stewart.Actuators(force_limit=limit))
    assert short.outcome == "saturated" and short.exit_code == 6 and len(short.problems) == 1
    assert np.max(np.abs(run.tracking_error[:, :3])) > 1e-4  # it can no longer follow exactly
    free = stewart.simulate(plat, move, stewart.ComputedTorque.tuned())
    assert free.ok and free.outcome == "completed" and free.problems == []
    damped = stewart.simulate(plat, move, stewart.ComputedTorque.tuned(),
                              actuators=stewart.Actuators(viscous=200.0, coulomb=1.0))
    # Computed torque does not model the friction: the actuators push harder where legs move.
    moving = np.abs(free.leg_velocities) > 1e-3
    assert np.all(np.abs(damped.forces[moving] - free.forces[moving]) > 0)


def test_results_export(tmp_path, plat, move):
    run = stewart.simulate(plat, move, duration=0.5)
    run.to_csv(tmp_path / "run.csv")
    run.to_npz(tmp_path / "run.npz")
    table = np.genfromtxt(tmp_path / "run.csv", delimiter=",", names=True)
    np.testing.assert_allclose(table["t"], run.t)
    np.testing.assert_allclose(table["force3"], run.forces[:, 3], rtol=1e-9)
    np.testing.assert_allclose(table["z_ref"], run.reference[:, 2], rtol=1e-9)
    data = np.load(tmp_path / "run.npz")
    np.testing.assert_array_equal(data["lengths"], run.lengths)
    assert str(data["reason"]) == "completed" and str(data["outcome"]) == "completed"
    assert str(data["platform"]) == "narayan2017" and str(data["controller"]) == "PID"
    assert "platform narayan2017, controller PID" in (tmp_path / "run.csv").read_text().splitlines()[1]


def test_sampled_trajectory_from_csv(tmp_path, plat, move):
    t = np.linspace(0, 5, 51)
    x, _, _ = move.sample(t)
    path = tmp_path / "path.csv"
    np.savetxt(path, np.column_stack([t, x]), delimiter=",", header="t,x,y,z,psi,theta,phi", comments="")
    traj = stewart.SampledTrajectory.from_csv(path)
    np.testing.assert_allclose(traj.sample(t)[0], x, atol=1e-15)
    np.testing.assert_allclose(traj.sample(2.55)[0], move.sample(2.55)[0], atol=1e-5)
    run = stewart.simulate(plat, traj, stewart.ComputedTorque.tuned())
    assert run.completed and np.max(np.abs(run.tracking_error)) < 1e-6
    path.write_text("t,x\n0,1\n")
    with pytest.raises(ValueError, match=r"path.csv: line 1: the header has 2 column\(s\) and lacks y, z"):
        stewart.SampledTrajectory.from_csv(path)


def test_bad_simulation_arguments(plat, move):
    with pytest.raises(ValueError, match="dt: must be a step of at least"):
        stewart.simulate(plat, move, dt=-1.0)
    with pytest.raises(ValueError, match="controller: expected a stewart.PID"):
        stewart.simulate(plat, move, "pid")
    with pytest.raises(ValueError, match="method: expected"):
        stewart.simulate(plat, move, method="euler")
    with pytest.raises(ValueError, match="kp: gains must be finite"):
        stewart.PID(kp=-1.0, ki=0.0, kd=0.0)
    with pytest.raises(ValueError, match="force_limit: must be > 0"):
        stewart.Actuators(force_limit=0.0)
    with pytest.raises(ValueError, match="duration: must be a positive"):
        stewart.PointToPoint(np.zeros(6), np.ones(6), 0.0)
