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


def test_pid_holding_home_converges(plat, figures):
    """Starting at rest with an empty integrator, the platform sags under gravity and the
    PID's integral action brings it back to the home pose."""
    hold = stewart.PointToPoint(plat.home_pose, plat.home_pose, 1.0)
    run = stewart.simulate(plat, hold, duration=6.0)
    assert run.completed, run.reason
    error = np.linalg.norm(run.tracking_error[:, :3], axis=1)
    assert error[int(0.2 / 1e-3)] > 1e-5  # it did sag
    figures("PID hold: final position error [m]", error[-1], 1e-7)
    assert error[-1] < 1e-3 * error.max()


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
    where the asymptotic rate shows."""
    pid = stewart.PID.tuned(plat, bandwidth_hz=1.0)
    runs = [stewart.simulate(plat, move, pid, duration=0.5, dt=dt).x for dt in (2e-4, 1e-4, 5e-5, 2.5e-5)]
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
    run = stewart.simulate(plat, stewart.PointToPoint(plat.home_pose, low, 3.0), method=method)
    assert not run.completed
    assert "reached its minimum length 0.19 m" in run.reason
    leg = run.stopped_leg
    assert run.lengths[-1, leg] == pytest.approx(0.19, abs=1e-4 if method == "rk4" else 1e-9)
    assert np.all(run.lengths[:-1] >= 0.19)
    assert run.t[-1] < 3.0 and f"t = {run.t[-1]:.4f} s" in run.reason


def test_saturation_and_friction(plat, move):
    limit = 21.0
    run = stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), actuators=stewart.Actuators(force_limit=limit))
    assert np.max(np.abs(run.forces)) == pytest.approx(limit)
    assert np.max(np.abs(run.tracking_error[:, :3])) > 1e-4  # it can no longer follow exactly
    free = stewart.simulate(plat, move, stewart.ComputedTorque.tuned())
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
    assert str(data["reason"]) == "completed"


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
    with pytest.raises(ValueError, match="expected 7 columns"):
        stewart.SampledTrajectory.from_csv(path)


def test_bad_simulation_arguments(plat, move):
    with pytest.raises(ValueError, match="dt: must be a positive step"):
        stewart.simulate(plat, move, dt=-1.0)
    with pytest.raises(ValueError, match="controller: expected PID"):
        stewart.simulate(plat, move, "pid")
    with pytest.raises(ValueError, match="method: expected"):
        stewart.simulate(plat, move, method="euler")
    with pytest.raises(ValueError, match="kp: gains must be finite"):
        stewart.PID(kp=-1.0, ki=0.0, kd=0.0)
    with pytest.raises(ValueError, match="force_limit: must be > 0"):
        stewart.Actuators(force_limit=0.0)
    with pytest.raises(ValueError, match="duration: must be a positive"):
        stewart.PointToPoint(np.zeros(6), np.ones(6), 0.0)
