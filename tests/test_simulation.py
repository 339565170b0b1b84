"""Simulation and control: convergence of the integrator, tracking, stroke limits, export."""

import dataclasses
import re
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings, strategies as st

import stewart
import stewart.motion.simulation
from interrupt import press_ctrl_c_after
from stewart._kernel import Mode
from stewart.model.kinematics import jacobian
from stewart.model.presets import narayan2017_target_pose
from stewart.motion.control import leg_masses
from stewart.oracles import reference


@pytest.fixture(scope="module")
def plat():
    return stewart.Platform.preset("narayan2017")


@pytest.fixture(scope="module")
def move(plat):
    return stewart.PointToPoint(plat.home_pose, narayan2017_target_pose(), 5.0)


def test_computed_torque_on_the_general_model(general_params, figures):
    """A platform with legs that turn with their joints and an off-centre payload: the
    simulation and the controller run its kernel, and its forces are the general reference's."""
    plat = stewart.Platform(general_params)
    target = plat.home_pose + np.array([0.1, -0.05, 0.05, 0.1, -0.05, 0.08]) * plat.home_pose[2]
    move = stewart.PointToPoint(plat.home_pose, target, 1.0)
    run = stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), dt=1e-3)
    assert run.completed
    figures(f"general model, computed torque: max tracking error / home height ({general_params.name})",
            np.max(np.abs(run.tracking_error[:, :3])) / plat.home_pose[2], 2e-10)  # reached 7.5e-12
    x, xd, xdd = move.sample(run.t)
    want = stewart.oracles.reference.inverse_dynamics(general_params, x, xd, xdd)
    figures(f"general model, computed torque: forces vs the reference's inverse dynamics ({general_params.name})",
            np.max(np.abs(run.forces - want)) / np.max(np.abs(want)), 2e-7)  # reached 7.1e-9: the feedback


def test_profiles_start_and_end_at_rest_and_integrate():
    start, goal = np.zeros(6), np.arange(1.0, 7.0)
    for profile in ("sinusoidal", "quintic"):
        traj = stewart.PointToPoint(start, goal, 2.0, profile)
        t = np.linspace(0, 2, 20001)
        x, xd, xdd = traj.sample(t)
        np.testing.assert_allclose(x[0], start, atol=1e-15)
        np.testing.assert_allclose(x[-1], goal, rtol=0, atol=1e-14)  # reached 0: a few ulp of the 6 m goal
        for arr in (xd, xdd):
            np.testing.assert_allclose(arr[[0, -1]], 0.0, atol=1e-13)  # reached 1/43 of it
        # The rates are the derivatives of the path (trapezoid rule on a fine grid).
        np.testing.assert_allclose(x[0] + np.cumsum((xd[1:] + xd[:-1]) / 2 * 1e-4, axis=0)[-1], goal, rtol=5e-13)  # reached 8.6e-15
        np.testing.assert_allclose(np.sum((xdd[1:] + xdd[:-1]) / 2 * 1e-4, axis=0), 0.0, atol=1e-13)  # reached 1/38 of it
    # The sinusoidal profile's velocity peaks at mid-move at twice the mean.
    _, xd, _ = stewart.PointToPoint(start, goal, 2.0).sample(1.0)
    np.testing.assert_allclose(xd, 2 * goal / 2.0, rtol=1e-15)  # reached 0


def test_pid_starts_bumpless(plat):
    """The PID's integral starts at the static leg forces of the start pose, so the legs
    carry the platform from t = 0 and it does not drop."""
    hold = stewart.PointToPoint(plat.home_pose, plat.home_pose, 1.0)
    run = stewart.simulate(plat, hold, duration=1.0)
    assert run.ok, run.problems
    static = stewart.oracles.reference.inverse_dynamics(plat.params, plat.home_pose, np.zeros(6), np.zeros(6))
    np.testing.assert_allclose(run.forces[0], static, rtol=5e-14)  # reached 1.3e-15
    assert np.all(np.abs(static) > 1.0)  # the legs do carry the weight
    np.testing.assert_allclose(run.x, np.broadcast_to(plat.home_pose, run.x.shape), rtol=0, atol=5e-15)  # reached 1.2e-16


def test_pid_integral_removes_an_offset(plat, figures):
    """Starting 2 mm low (held there by the bumpless integral), the PID's integral action
    moves the platform to the reference and settles on the static forces of the home pose."""
    hold = stewart.PointToPoint(plat.home_pose, plat.home_pose, 1.0)
    x0 = plat.home_pose - [0, 0, 0.002, 0, 0, 0]
    run = stewart.simulate(plat, hold, duration=6.0, x0=x0, xd0=np.zeros(6))
    assert run.ok, run.problems
    error = np.linalg.norm(run.tracking_error[:, :3], axis=1)
    figures("PID from a 2 mm offset: final position error [m]", error[-1], 5e-15)  # reached 1.3e-16
    static = stewart.oracles.reference.inverse_dynamics(plat.params, plat.home_pose, np.zeros(6), np.zeros(6))
    np.testing.assert_allclose(run.forces[-1], static, rtol=5e-12)  # reached 9.6e-14


def test_computed_torque_tracks_the_move(plat, move, figures):
    run = stewart.simulate(plat, move, stewart.ComputedTorque.tuned())
    assert run.completed
    figures("computed torque: max tracking error over the move [m]", np.max(np.abs(run.tracking_error[:, :3])), 1e-11)  # reached 2.3e-13
    # The forces are the inverse dynamics of the reference (the model is exact) and the feedback on
    # the tracking error: relative to the largest force, reached 1.8e-10.
    x, xd, xdd = move.sample(run.t)
    tau = plat.inverse_dynamics(x, xd, xdd)
    np.testing.assert_allclose(run.forces, tau, rtol=0, atol=1e-8 * np.max(np.abs(tau)))


def test_pid_tracks_the_move_and_settles(plat, move):
    run = stewart.simulate(plat, move, duration=6.0)
    assert run.completed
    assert np.max(np.abs(run.tracking_error[:, :3])) < 1e-3  # reached 1.6e-4 m
    assert np.linalg.norm(run.tracking_error[-1, :3]) < 2e-8  # reached 6.9e-10 m


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
    figures("RK4 order: error ratio when halving dt (|ratio - 16|)", np.max(np.abs(np.subtract(ratios, 16))), 2.0)  # reached 9.1e-01


@pytest.mark.slow
@pytest.mark.parametrize("controller, dt", [("computed torque", 1e-3), ("PID", 2.5e-4)])
def test_adaptive_agrees_with_rk4(plat, move, controller, dt):
    """Over the first 0.5 s: the PID's start-up transient and a tenth of the move. The two
    integrators agree to 2e-14 in the states over 0.5 s as over 1 s (the bound is 1e-9), so
    a wrong stage time or controller call, which shows from the first steps, fails either."""
    ctrl = stewart.ComputedTorque.tuned() if controller == "computed torque" else stewart.PID.tuned(plat)
    rk4 = stewart.simulate(plat, move, ctrl, duration=0.5, dt=dt)
    adaptive = stewart.simulate(plat, move, ctrl, duration=0.5, dt=dt, method="adaptive", rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(adaptive.x, rk4.x, rtol=0, atol=1e-11)  # reached 1.8e-13
    # Forces amplify velocity differences by the PID's Kd (~1e4 N s/m) during the initial
    # fast transient; compare them once it has died out.
    late = rk4.t > 0.05
    np.testing.assert_allclose(adaptive.forces[late], rk4.forces[late], rtol=0, atol=2e-7 * np.max(np.abs(rk4.forces)))  # reached 5.6e-09


@pytest.mark.slow
@pytest.mark.parametrize("method", ["rk4", "adaptive"])
def test_stroke_limit_stops_the_run_with_its_reason(plat, method):
    """Under computed torque, which DOP853 integrates in a twelfth of the time it takes for
    the default PID's fast leg mode (test_adaptive_agrees_with_rk4 runs that one)."""
    low = plat.home_pose.copy()
    low[2] = 0.15  # below the 0.19 m minimum leg length
    move_down = stewart.PointToPoint(plat.home_pose, low, 3.0)
    controller = stewart.ComputedTorque.tuned()
    with pytest.raises(stewart.WorkspaceError, match=r"shorter than the minimum length 0.19 m .* at t = 1\.") as info:
        stewart.simulate(plat, move_down, controller, method=method)
    first = info.value.times[0]
    assert np.min(plat.leg_lengths(move_down.sample(first)[0])) < 0.19
    assert np.min(plat.leg_lengths(move_down.sample(first - 1e-3)[0])) >= 0.19
    run = stewart.simulate(plat, move_down, controller, method=method, check_workspace=False)
    assert not run.completed and run.outcome == "failed" and run.exit_code == 4 and not run.ok
    assert "reached its minimum length 0.19 m" in run.reason
    leg = run.stopped_leg
    # RK4 stops on the step past the stroke (2.5e-5 m reached); DOP853 at its event's root (0)
    assert run.lengths[-1, leg] == pytest.approx(0.19, abs=1e-4 if method == "rk4" else 1e-14)
    assert np.all(run.lengths[:-1] >= 0.19)
    assert run.t[-1] < 3.0 and f"t = {run.t[-1]:.4f} s" in run.reason


def test_saturation_and_friction(plat, move):
    limit = 21.0
    run = stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), actuators=stewart.Actuators(force_limit=limit))
    assert np.max(np.abs(run.forces)) == limit  # clipped to it
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


def _with_friction(plat):
    """``plat`` with its own viscous and Coulomb friction, different in each leg."""
    return stewart.Platform(plat.params.replace(viscous_friction=[20.0, 30.0, 40.0, 50.0, 60.0, 70.0],
                                                coulomb_friction=[0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
                                                coulomb_velocity=0.01))


def test_the_loop_loses_the_platforms_own_friction(plat, move, figures):
    """Open loop, fed the forces Platform.actuator_forces gives for a move (inverse dynamics
    plus each leg's own friction), a machine with per-leg friction follows the move: the
    loop loses what the legs lose, by default. The same forces without friction do not."""
    machine = _with_friction(plat)

    def forces(t):
        return machine.actuator_forces(*move.sample(t))

    run = stewart.simulate(machine, move, stewart.OpenLoop(), feedforward=forces, duration=1.0)
    error = np.max(np.abs(run.x - run.reference))
    assert run.ok and np.max(np.abs(machine.friction_forces(run.x, run.xd))) > 1.0
    figures("simulate: open loop on actuator_forces with per-leg friction, pose error", error, 5e-12)  # reached 9.7e-14
    free = stewart.simulate(machine, move, stewart.OpenLoop(), feedforward=forces, duration=1.0,
                            actuators=stewart.Actuators(viscous=0.0, coulomb=0.0))
    assert np.max(np.abs(free.x - free.reference)) > 1e6 * error
    # The same friction given to the actuators of the platform without it: the same run.
    given = stewart.Actuators(viscous=machine.params.viscous_friction, coulomb=machine.params.coulomb_friction,
                              coulomb_velocity=0.01)
    assert np.array_equal(stewart.simulate(plat, move, stewart.OpenLoop(), feedforward=forces, duration=1.0,
                                           actuators=given).x, run.x)


def test_computed_torque_adds_back_the_platforms_own_friction(plat, move, figures):
    """On a machine with per-leg friction, computed torque adds its model's friction back
    at the measured leg rates: it tracks as exactly as without friction, and commands what
    Platform.actuator_forces gives along the move. Legs that lose twice the model's
    friction leave the difference to the feedback, which then lags."""
    machine = _with_friction(plat)
    run = stewart.simulate(machine, move, stewart.ComputedTorque.tuned(), duration=1.0)
    error = np.max(np.abs(run.tracking_error[:, :3]))
    assert run.ok and np.max(np.abs(machine.friction_forces(run.x, run.xd))) > 1.0
    figures("computed torque with per-leg friction: max tracking error [m]", error, 1e-11)  # reached 2.2e-13
    expected = machine.actuator_forces(*move.sample(run.t))
    np.testing.assert_allclose(run.commanded_forces, expected, rtol=0, atol=2e-8 * np.max(np.abs(expected)))  # reached 4.0e-10
    doubled = stewart.Actuators(viscous=2 * np.array(machine.params.viscous_friction),
                                coulomb=2 * np.array(machine.params.coulomb_friction))
    lagging = stewart.simulate(machine, move, stewart.ComputedTorque.tuned(), duration=1.0, actuators=doubled)
    assert np.max(np.abs(lagging.tracking_error[:, :3])) > 1e3 * error


def test_results_export(tmp_path, plat, move):
    run = stewart.simulate(plat, move, duration=0.5)
    run.to_csv(tmp_path / "run.csv")
    run.to_npz(tmp_path / "run.npz")
    table = np.genfromtxt(tmp_path / "run.csv", delimiter=",", names=True)
    np.testing.assert_allclose(table["t"], run.t, rtol=1e-14)  # reached 2.0e-16
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
    np.testing.assert_allclose(traj.sample(t)[0], x, atol=1e-15, rtol=5e-15)  # reached 1/110 of it
    np.testing.assert_allclose(traj.sample(2.55)[0], move.sample(2.55)[0], atol=5e-8, rtol=5e-10)  # reached 1/73 of it
    run = stewart.simulate(plat, traj, stewart.ComputedTorque.tuned())
    assert run.completed and np.max(np.abs(run.tracking_error)) < 1e-11  # reached 2.8e-13
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
    with pytest.raises(ValueError, match="kp: must be finite and >= 0"):
        stewart.PID(kp=-1.0, ki=0.0, kd=0.0)
    with pytest.raises(ValueError, match="force_limit: must be > 0"):
        stewart.Actuators(force_limit=0.0)
    with pytest.raises(ValueError, match="duration: must be a positive"):
        stewart.PointToPoint(np.zeros(6), np.ones(6), 0.0)


def _leg_masses(params, x):
    """Each actuator's effective mass at ``x`` from the numeric reference: the diagonal of
    ``J_C^-T M_t J_C^-1`` with the reference's twist mass matrix and the numpy leg Jacobian."""
    inverse = np.linalg.inv(jacobian(params, x))
    return np.diag(inverse.T @ reference.twist_mass_matrix(params, x) @ inverse)


def test_tuned_pid_puts_each_legs_poles_at_the_bandwidth(plat):
    """A leg of effective mass m under PID has the closed-loop characteristic polynomial
    ``m s^3 + Kd s^2 + Kp s + Ki``; the tuned gains make it ``m (s + w)^3``, ``w = 2 pi f``, with
    ``f`` the one given or the documented default: 2.5 Hz for narayan2017, 5 Hz for a platform
    of no preset. The masses from the numeric reference."""
    custom = stewart.Platform(plat.params.replace(name="custom"))
    for platform, bandwidth, pid in ((plat, 2.5, stewart.PID.tuned(plat)), (plat, 0.8, stewart.PID.tuned(plat, 0.8)),
                                     (custom, 5.0, stewart.PID.tuned(custom))):
        m, w = _leg_masses(platform.params, platform.home_pose), 2 * np.pi * bandwidth
        polynomial = np.outer([3 * w, 3 * w**2, w**3], np.ones(6))  # m (s + w)^3 / m, after s^3
        np.testing.assert_allclose(np.stack([pid.kd, pid.kp, pid.ki]) / m, polynomial, rtol=2e-14)  # reached 4.4e-16
    with pytest.raises(ValueError, match=r"^x: expected one pose, shape \(6,\), got \(2, 6\)$"):
        leg_masses(plat, np.stack([plat.home_pose, plat.home_pose]))


def test_tuned_computed_torque_is_critically_damped():
    """Under the tuned gains the error dynamics ``e'' + Kd e' + Kp e = 0`` are ``(s + w)^2 e = 0``,
    ``w = 2 pi f``, ``f`` 5 Hz by default (the gains to the last bit of ``w``)."""
    for bandwidth, gains in ((5.0, stewart.ComputedTorque.tuned()), (0.3, stewart.ComputedTorque.tuned(0.3))):
        w = 2 * np.pi * bandwidth
        np.testing.assert_allclose(np.stack([gains.kd, gains.kp]), np.outer([2 * w, w**2], np.ones(6)), rtol=1e-15)


@pytest.mark.parametrize("bandwidth, message", [
    (0.0, "must be positive, got 0.0"),
    (-1.0, "must be positive, got -1.0"),
    (1e300, r"1e\+300 Hz is too high: the gains overflow"),
])
def test_a_bandwidth_out_of_range_is_named(plat, bandwidth, message):
    for tune in (lambda f: stewart.PID.tuned(plat, f), stewart.ComputedTorque.tuned):
        with pytest.raises(ValueError, match=f"^bandwidth_hz: {message}$"):
            tune(bandwidth)


def test_gains_are_one_value_or_one_per_leg():
    """One number (a scalar or a sequence of one) is every leg's gain; six are one per leg;
    other shapes name the gain."""
    one = stewart.PID(kp=[400.0], ki=(20.0,), kd=np.array([30.0]))
    np.testing.assert_array_equal(np.stack([one.kp, one.ki, one.kd]), np.outer([400.0, 20.0, 30.0], np.ones(6)))
    legs = np.arange(1.0, 7.0)
    np.testing.assert_array_equal(stewart.ComputedTorque(kp=legs, kd=2 * legs).kd, 2 * legs)
    for bad in ([1.0, 2.0], np.ones((1, 6)), np.ones(7)):
        shape = re.escape(str(np.shape(bad)))
        with pytest.raises(ValueError, match=rf"^kp: expected one value or one per leg \(6\), got shape {shape}$"):
            stewart.PID(kp=bad, ki=0.0, kd=0.0)


def test_each_law_gives_the_loop_six_gains_per_leg():
    """``loop_settings``: the law and its gains ``(kp, ki, kd)``, six per leg, those the law does
    not use zero; the controllers are immutable."""
    for controller, mode, gains in ((stewart.PID(1.0, 2.0, 3.0), Mode.PID, [1.0, 2.0, 3.0]),
                                    (stewart.ComputedTorque(4.0, 5.0), Mode.COMPUTED_TORQUE, [4.0, 0.0, 5.0]),
                                    (stewart.OpenLoop(), Mode.OPEN_LOOP, [0.0, 0.0, 0.0])):
        loop = controller.loop_settings()
        assert loop[0] == mode and [g.shape for g in loop[1:]] == [(6,)] * 3
        np.testing.assert_array_equal(np.stack(loop[1:]), np.outer(gains, np.ones(6)))
        with pytest.raises(dataclasses.FrozenInstanceError):
            controller.kp = 0.0


class _GainsOf(stewart.motion.control.Controller):
    """A law of the compiled loop whose gains are whatever it is given (the loop checks them)."""

    label = "gains as given"

    def __init__(self, kp, ki, kd):
        self.gains = (kp, ki, kd)

    def loop_settings(self):
        return (Mode.PID, *self.gains)


@pytest.mark.parametrize("gains, message", [
    ((np.ones(5), np.zeros(6), np.zeros(6)), r"kp: expected 6 values, one per leg, got shape \(5,\)"),
    ((np.ones(6), np.zeros(7), np.zeros(6)), r"ki: expected 6 values, one per leg, got shape \(7,\)"),
    ((np.ones(6), np.zeros(6), 30.0), r"kd: expected 6 values, one per leg, got shape \(\)"),
    ((np.ones(6), np.zeros(6), [30.0] * 5 + [np.nan]), r"kd: expected finite values, got \[30.0, .*, nan\]"),
])
def test_the_loop_checks_each_gain_vector(plat, move, gains, message):
    """The compiled loop takes six gains a leg from any law, or names the gain it cannot take
    (a short vector was read past its end, a long one cut, a NaN passed on)."""
    with pytest.raises(ValueError, match=f"^{message}$"):
        stewart.simulate(plat, move, _GainsOf(*gains), dt=1e-3)
    tuned = stewart.PID.tuned(plat)
    pid = stewart.PID(tuned.kp, 0.0, tuned.kd)  # no integral: _GainsOf's start (zero) is PID's
    ours, theirs = (stewart.simulate(plat, move, law, dt=1e-3) for law in (pid, _GainsOf(pid.kp, pid.ki, pid.kd)))
    np.testing.assert_array_equal(ours.x, theirs.x)


def test_pid_bumpless_integral_leg_by_leg(plat):
    """``Ki I = tau_static(x0) - feedforward(0)`` on each leg with ``Ki > 0`` (the static forces of
    the numeric reference); zero on a leg with ``Ki = 0`` and on one whose ``Ki`` is too small for
    ``I`` to be a float, with no warning."""
    x0 = plat.home_pose + [0.01, 0.0, -0.01, 0.0, 0.02, 0.0]
    feedforward = np.array([1.0, -2.0, 3.0, 0.5, 0.0, -1.0])
    ki = np.array([0.0, 1e-320, 2.0, 30.0, 400.0, 5000.0])
    static = reference.inverse_dynamics(plat.params, x0, np.zeros(6), np.zeros(6)) - feedforward
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        integral = stewart.PID(kp=1.0, ki=ki, kd=1.0).initial_integral(plat, x0, feedforward)
    np.testing.assert_array_equal(integral[:2], 0.0)
    np.testing.assert_allclose(ki[2:] * integral[2:], static[2:], rtol=5e-14)  # reached 1.6e-15


# The move of issue 9: to theta = 90 deg, through a singularity of J_C on the way.
ISSUE_TARGET = [0, 0, 0.278, 0, 1.5707963, 0]


def _det_signs(plat, poses):
    """Signs of det J_C from the numpy kinematics (independent of the compiled kernel)."""
    return np.sign(np.linalg.det(stewart.jacobian(plat.params, poses)))


def test_a_move_beyond_a_singularity_is_refused_before_the_run(plat):
    # Without the preset's joint cones and plate, which the move leaves first.
    plat = stewart.Platform(plat.params.replace(universal_joint_max_angle=None, spherical_joint_max_angle=None,
                                                plate_radius=None))
    move = stewart.PointToPoint(plat.home_pose, ISSUE_TARGET, 5.0)
    with pytest.raises(stewart.WorkspaceError, match=r"^trajectory: \d+ of 5001 reference pose") as info:
        stewart.simulate(plat, move)
    message = str(info.value)
    assert "another assembly mode" in message and "theta = +-90 deg" in message
    # The first time named is where the reference leaves the workspace: det J_C changes
    # sign soon after (its condition number grows without bound near the crossing).
    signs = _det_signs(plat, move.sample(np.arange(5001) * 1e-3)[0])
    crossing = np.argmax(signs != signs[0]) * 1e-3
    assert info.value.times[0] < crossing < info.value.times[0] + 0.05
    assert isinstance(info.value, ValueError)


def test_a_run_that_leaves_its_assembly_mode_fails(plat):
    """Forced past the check, PID ends in another assembly mode (the old 'completed' run)
    and computed torque tracks through the singularity with meganewton forces."""
    move = stewart.PointToPoint(plat.home_pose, ISSUE_TARGET, 5.0)
    run = stewart.simulate(plat, move, check_workspace=False)
    assert run.completed and not run.ok and run.outcome == "failed" and run.exit_code == 4
    signs = _det_signs(plat, run.x)
    flip = np.argmax(signs != signs[0])
    assert flip > 0 and f"left its assembly mode (det J_C changed sign) at t = {run.t[flip]:.4f} s" in run.problems[0]
    assert any("final tracking error" in p for p in run.problems)
    ct = stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), check_workspace=False,
                          actuators=stewart.Actuators(force_limit=1000.0))
    assert not ct.ok and any("exceeded the actuator limit 1000 N" in p for p in ct.problems)
    free = stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), check_workspace=False)
    # Meganewtons on a 6.8 kg plate: the exact model tracks (to 4e-12 m), so its forces are the
    # numpy reference's inverse dynamics of the reference move, whose peak on the 1 ms samples is
    # 2.27 MN (at t = 3.984 s); the feedback on the tracking error adds 6.3e-7 of it.
    x, xd, xdd = move.sample(free.t)
    peak = np.max(np.abs(stewart.oracles.reference.inverse_dynamics(plat.params, x, xd, xdd)))
    assert peak > 1e6
    np.testing.assert_allclose(np.max(np.abs(free.commanded_forces)), peak, rtol=1e-5)
    assert not free.ok


def test_tolerance_decides_between_completed_and_inaccurate(plat, move):
    loose = stewart.PID.tuned(plat, bandwidth_hz=1.0)
    run = stewart.simulate(plat, move, loose, duration=2.5)  # stopped mid-move, still lagging
    err = move.sample(2.5)[0] - run.x[-1]
    position, angle = np.linalg.norm(err[:3]), np.linalg.norm(err[3:])
    assert position > 1e-4
    ok = stewart.simulate(plat, move, loose, duration=2.5, tolerance=(1.01 * position, 1.01 * angle))
    assert ok.ok and ok.outcome == "completed" and ok.exit_code == 0
    bad = stewart.simulate(plat, move, loose, duration=2.5, tolerance=(0.99 * position, 1.01 * angle))
    assert bad.outcome == "inaccurate" and bad.exit_code == 5 and bad.completed
    assert f"final tracking error {position:.3g} m" in bad.problems[0]
    for tolerance in (0.0, (1e-3, -1.0), "tight", (np.nan, 1.0)):
        with pytest.raises(ValueError, match="^tolerance: "):
            stewart.simulate(plat, move, tolerance=tolerance)


class _Broken:
    """A trajectory whose sample(t) returns the wrong thing."""

    duration = 1.0

    def __init__(self, make):
        self.make = make

    def sample(self, t):
        home = np.array([0.0015, -0.0005, 0.278, 0, 0, 0])
        return self.make(np.zeros((np.size(t), 6)) + home if np.ndim(t) else home, np.size(t))


@pytest.mark.parametrize("make", [
    lambda x, n: (x[..., :5], x[..., :5], x[..., :5]),
    lambda x, n: (np.hstack([x, x[..., :1]]) if x.ndim == 2 else np.append(x, 0),) * 3,
    lambda x, n: (x[:-1], x[:-1], x[:-1]) if x.ndim == 2 else (x, x, x),
    lambda x, n: (x, x * np.nan, x),
    lambda x, n: (x, x + 0j, x),
    lambda x, n: (x, x),
    lambda x, n: (x, "fast", x),
    lambda x, n: (np.full(x.shape, None, dtype=object), x, x),
], ids=["5 columns", "7 columns", "fewer rows", "NaN", "complex", "two arrays", "string", "objects, not numbers"])
def test_trajectory_output_is_checked_before_the_compiled_loop(plat, make):
    with pytest.raises(ValueError, match="^trajectory: "):
        stewart.simulate(plat, _Broken(make), stewart.ComputedTorque.tuned(), duration=0.1)


def test_step_budget_and_time_arguments(plat, move):
    with pytest.raises(ValueError, match=r"^dt: must be a step of at least 1e-09 s, got 1e-12"):
        stewart.simulate(plat, move, dt=1e-12)
    with pytest.raises(ValueError, match=r"^dt: must be a step of at least .* got 5e-324"):
        stewart.simulate(plat, move, duration=1e-320, dt=5e-324)
    with pytest.raises(ValueError, match=r"^dt, duration: 5 s at dt = 1e-06 s is 5e\+06 steps, more than the budget "
                                         r"of 1000000 \(pass max_steps="):
        stewart.simulate(plat, move, dt=1e-6)
    with pytest.raises(ValueError, match=r"^dt, duration: 1\.8e\+305 report times, more than 1000000"):
        stewart.simulate(plat, move, duration=1.8e302, method="adaptive")
    with pytest.raises(ValueError, match="budget of 100 "):
        stewart.simulate(plat, move, duration=0.5, max_steps=100)
    assert stewart.simulate(plat, move, duration=0.5, max_steps=500).ok
    for name, value in (("dt", np.timedelta64(1, "ms")), ("duration", np.timedelta64(5, "s")), ("dt", True),
                        ("duration", "5"), ("dt", np.array([1e-3, 2e-3])), ("duration", 10**400)):
        with pytest.raises(ValueError, match=f"^{name}: "):
            stewart.simulate(plat, move, **{name: value})
    for value in (0, -3, 2.5, True, "10"):
        with pytest.raises(ValueError, match="^max_steps: expected a positive integer"):
            stewart.simulate(plat, move, max_steps=value)


@pytest.mark.parametrize("controller, xd0", [
    (stewart.PID(1e12, 0.0, 1e3), None),
    (stewart.PID(1e300, 1e300, 1e300), None),
    (stewart.ComputedTorque(1e300, 1e300), None),
    (None, [1e6, 0, 0, 0, 0, 0]),
], ids=["stiff PID", "PID 1e300", "computed torque 1e300", "huge initial velocity"])
def test_adaptive_solver_ends_with_a_failed_outcome(plat, move, controller, xd0):
    """Absurd gains or velocities end within the step budget, as a failed run."""
    run = stewart.simulate(plat, move, controller, method="adaptive", duration=0.5, max_steps=300,
                           x0=None if xd0 is None else plat.home_pose, xd0=xd0)
    assert not run.ok and run.outcome == "failed" and run.exit_code == 4, run.reason
    assert run.t[-1] < 0.5 and np.all(np.isfinite(run.x))


def test_wrong_arguments_name_themselves(plat, move):
    for controller in (stewart.PID, plat.params, "pid", 3.0, stewart.Actuators()):
        with pytest.raises(ValueError, match="^controller: expected a stewart.PID, ComputedTorque or OpenLoop"):
            stewart.simulate(plat, move, controller)
    with pytest.raises(ValueError, match="^platform: expected a stewart.Platform"):
        stewart.simulate(None, move)
    from_params = stewart.simulate(plat.params, move)  # a Platform's parameters are a platform too
    np.testing.assert_array_equal(from_params.x, stewart.simulate(plat, move).x)
    with pytest.raises(ValueError, match="^trajectory: expected an object with sample"):
        stewart.simulate(plat, np.zeros(6))
    with pytest.raises(ValueError, match="^actuators: expected a stewart.Actuators"):
        stewart.simulate(plat, move, actuators=100.0)


@pytest.mark.parametrize("method", ["rk4", "adaptive"])
def test_ctrl_c_returns_what_was_computed(plat, move, monkeypatch, method):
    """Ctrl-C during a run stops it at the next chunk of steps; the exception holds the
    run so far, which matches an uninterrupted run sample for sample."""
    duration = 5.0 if method == "rk4" else 0.3
    full = stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), duration=duration, method=method)
    press_ctrl_c_after(monkeypatch, 0.15)
    with pytest.raises(stewart.SimulationInterrupted) as info:
        stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), duration=duration, method=method)
    part = info.value.result
    assert isinstance(info.value, KeyboardInterrupt)
    assert part.outcome == "interrupted" and part.exit_code == 130 and not part.completed
    assert 0 < part.t[-1] < duration and part.reason == f"interrupted at t = {part.t[-1]:.4f} s"
    np.testing.assert_array_equal(part.x, full.x[:len(part.t)])
    np.testing.assert_array_equal(part.forces, full.forces[:len(part.t)])


def test_reachability_flags_each_problem(plat):
    from stewart.studies import workspace

    home = plat.home_pose
    below = home * [1, 1, -1, 1, 1, 1]  # mirrored under the base: legs within their stroke
    low = home - [0, 0, 0.2, 0, 0, 0]
    upright = home + [0, 0, 0, 0, np.pi / 2, 0]
    beyond = stewart.PointToPoint(home, ISSUE_TARGET, 5.0).sample(4.5)[0]
    check = stewart.reachability(plat, [home, below, low, upright, beyond])
    # Independent facts: lengths from the numpy kinematics, platform joints below the
    # base plane, det J_C of the other sign than at home.
    lengths = stewart.leg_lengths(plat.params, low)
    assert np.all(lengths < 0.19) and check.flags[2] & workspace.LEG_TOO_SHORT
    assert np.all((stewart.leg_lengths(plat.params, below) > 0.19) & (stewart.leg_lengths(plat.params, below) < 0.38))
    joints_z = below[2] + (stewart.rotation(below) @ plat.params.platform_points.T)[2]
    assert np.all(joints_z < 0) and check.flags[1] == workspace.BELOW_BASE | (check.flags[1] & ~workspace.BELOW_BASE)
    assert check.flags[1] & workspace.BELOW_BASE
    assert check.flags[3] & workspace.EULER_SINGULAR
    assert _det_signs(plat, beyond) != _det_signs(plat, home) and check.flags[4] & workspace.OTHER_ASSEMBLY_MODE
    assert check.ok.tolist() == [True, False, False, False, False]
    assert "row 2" in check.message() and "not above the base" in check.reasons(1)[0]
    with pytest.raises(ValueError, match="^poses: "):
        stewart.reachability(plat, [0, 0, np.nan, 0, 0, 0])
    huge = stewart.reachability(plat, [0, 0, 1e308, 0, 0, 0])
    assert huge.flags[0] & workspace.OUT_OF_RANGE and "out of numeric range" in huge.message()


# ---------------------------------------------------------------- fuzzing simulate's arguments


def _mostly(good, odd):
    """Draws from ``good`` four times in five, so that most examples reach the run."""
    return st.tuples(st.integers(0, 4), good, odd).map(lambda t: t[2] if t[0] == 0 else t[1])


_ODD_NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 5e-324, 1e-320, 1e-9, 1e308, -1e-3]),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([None, "0.01", True, np.timedelta64(1, "ms"), np.array([1e-3]), np.float32(1e-3), [0.01]]),
)
_GAINS = st.one_of(st.floats(min_value=0, max_value=1e308), st.sampled_from([0.0, 1.0, 1e3, 1e300, 1e-300]))
_CONTROLLERS = _mostly(
    st.one_of(st.none(), st.builds(stewart.PID, _GAINS, _GAINS, _GAINS), st.builds(stewart.ComputedTorque, _GAINS, _GAINS),
              st.just(stewart.OpenLoop()), st.just(stewart.ComputedTorque.tuned())),
    st.sampled_from([stewart.PID, "pid", 1.0, np.zeros(6), stewart.Actuators()]),
)
_ARGUMENTS = {"platform", "trajectory", "controller", "dt", "duration", "method", "actuators", "x0", "xd0",
              "tolerance", "max_steps", "rtol", "atol", "dt, duration"}


@settings(max_examples=60, deadline=10_000, suppress_health_check=[HealthCheck.too_slow])
@given(
    controller=_CONTROLLERS,
    dt=_mostly(st.sampled_from([1e-3, 2e-3, 5e-3, 1e-2]), _ODD_NUMBERS),
    duration=_mostly(st.sampled_from([0.02, 0.05, 0.2, None]), _ODD_NUMBERS),
    method=_mostly(st.sampled_from(["rk4", "adaptive"]), st.sampled_from(["euler", None, 4])),
    tolerance=_mostly(st.just((1e-3, 1e-2)), _ODD_NUMBERS),
    max_steps=_mostly(st.sampled_from([None, 300, 10**6]), st.sampled_from([-3, 0, 2.5, "10", True])),
    force_limit=_mostly(st.sampled_from([np.inf, 25.0, 1e3]), st.floats(min_value=1e-300, max_value=1e308)),
    xd0=_mostly(st.none(), st.one_of(st.lists(st.floats(-1e6, 1e6), min_size=6, max_size=6),
                                     st.sampled_from([[np.nan] * 6, [1e308] * 6, [0.0] * 5, "fast"]))),
)
def test_fuzz_simulate_arguments(plat, move, controller, dt, duration, method, tolerance, max_steps, force_limit,
                                 xd0):
    """Any arguments: a result with a known outcome and a finite state, or a ValueError
    naming the argument; never a crash, a hang or another exception."""
    if method == "adaptive" and (max_steps is None or max_steps == 10**6):
        max_steps = 300  # the default budget is for real runs, too long for a fuzz test
    try:
        run = stewart.simulate(plat, move, controller, dt=dt, duration=duration, method=method,
                               tolerance=tolerance, max_steps=max_steps, xd0=xd0,
                               actuators=stewart.Actuators(force_limit=force_limit),
                               x0=None if xd0 is None else plat.home_pose)
    except stewart.SimulationInterrupted:
        raise
    except ValueError as exc:
        name = str(exc).split(":")[0]
        assert name in _ARGUMENTS, str(exc)
        event(f"refused: {name}")
        return
    event(f"ran: {run.outcome}")
    assert run.outcome in stewart.motion.simulation.OUTCOMES and run.outcome != "interrupted"
    assert run.ok == (run.outcome == "completed") and (run.problems == []) == run.ok
    assert np.all(np.isfinite(run.x)) and np.all(np.isfinite(run.t)) and len(run.t) == len(run.x) >= 1


def test_progress_bar_never_runs_backwards(plat, move, capsys):
    """The adaptive solver evaluates at times before the last accepted step; the bar
    shows the furthest time reached, ending at the full duration."""
    stewart.simulate(plat, move, method="adaptive", duration=0.3, progress=True)
    shown = [float(part.split("/")[0]) for part in capsys.readouterr().err.split("t = ")[1:]]
    assert shown == sorted(shown) and shown[-1] == pytest.approx(0.3, rel=1e-15)  # reached 0


def test_condition_check_agrees_with_the_svd(plat):
    """The workspace check flags exactly the poses whose unit-free condition number (by
    numpy's cond) exceeds the limit, along a move through a singularity, and its margin
    is the inverse of that condition number."""
    from stewart.studies import workspace

    poses = stewart.PointToPoint(plat.home_pose, ISSUE_TARGET, 5.0).sample(np.linspace(0, 5, 2001))[0]
    radius = np.max(np.linalg.norm(plat.params.platform_points - plat.params.platform_points.mean(axis=0), axis=1))
    jac = stewart.jacobian(plat.params, poses) / np.r_[np.ones(3), np.full(3, radius)]
    exact = np.linalg.cond(jac)
    check = stewart.reachability(plat, poses)
    flagged = (check.flags & workspace.SINGULAR) != 0
    assert flagged.any() and not flagged.all()
    np.testing.assert_array_equal(flagged, exact > workspace.CONDITION_LIMIT)
    np.testing.assert_allclose(check.margin, 1.0 / exact, rtol=5e-11)  # reached 1.3e-12


def test_compiled_loop_refuses_buffers_too_small(plat):
    from stewart._kernel import ClosedLoop

    no_friction = (np.zeros(6), np.zeros(6), 1e-3)
    loop = ClosedLoop(plat._kernel, 1, np.ones(6), np.zeros(6), np.ones(6), np.full(6, np.inf), no_friction, no_friction)
    y = np.concatenate([plat.home_pose, np.zeros(12)])
    out = [np.zeros((6, 18))] + [np.zeros((6, 6)) for _ in range(3)]
    refs = np.tile(np.concatenate([plat.home_pose, np.zeros(12)]), (11, 1))
    assert loop.rk4(y.copy(), refs, np.zeros((11, 6)), 1e-3, 0, 5, 0.0, np.inf, *out)[:2] == (0, 5)
    for bad_refs, bad_ff in ((refs[:10], np.zeros((11, 6))), (refs, np.zeros((9, 6))), (refs[:, :17].copy(), None)):
        with pytest.raises(ValueError, match="rk4: the buffers do not hold the steps asked for"):
            loop.rk4(y.copy(), bad_refs, np.zeros((11, 6)) if bad_ff is None else bad_ff, 1e-3, 0, 5, 0.0, np.inf,
                     *out)
    with pytest.raises(ValueError, match="rk4: the buffers"):
        loop.rk4(y.copy(), refs, np.zeros((11, 6)), 1e-3, 0, 7, 0.0, np.inf, *out)


@pytest.mark.parametrize("method", ["rk4", "adaptive"])
def test_a_model_error_ends_the_run_at_the_sample_before_it(plat, method):
    """The reference jumps at t = 0.2 s to a pose where leg 0 has zero length, so the PID's
    reference leg rates are undefined from then on: the run ends with the kernel's message
    at the last sample before 0.2 s, and its samples are those of the same run holding
    home throughout (the adaptive solver keeps what it reached, without starting over)."""
    home, p = plat.home_pose, plat.params
    degenerate = np.concatenate([p.base_points[0] - p.platform_points[0], np.zeros(3)])
    assert stewart.leg_lengths(p, degenerate)[0] == 0.0

    class Jump:
        duration = 0.5

        def sample(self, t):
            x = np.where((np.asarray(t) >= 0.2)[..., None], degenerate, home)
            return x, np.zeros_like(x), np.zeros_like(x)

    run = stewart.simulate(plat, Jump(), method=method, check_workspace=False)
    held = stewart.simulate(plat, stewart.PointToPoint(home, home, 0.5), method=method)
    assert run.outcome == "failed" and not run.completed
    assert run.reason == "a leg has zero length at t = 0.1990 s" and run.t[-1] == pytest.approx(0.199, rel=1e-14)  # reached 0
    if method == "rk4":  # the same steps
        np.testing.assert_array_equal(run.x, held.x[:len(run.t)])
    else:  # the step the solver shortened to end before the undefined state is integrated anew,
        # with other stages than the held run's: the two agree to DOP853's tolerance (rtol 1e-9)
        np.testing.assert_allclose(run.x, held.x[:len(run.t)], rtol=1e-9, atol=1e-12)


def test_feedforward_may_return_a_read_only_view(plat):
    """Open loop under the static forces of home, returned as a read-only broadcast view: the
    platform stays at rest (the forces hold it), as with a writable array."""
    hold = plat.inverse_dynamics(plat.home_pose, np.zeros(6), np.zeros(6))
    still = stewart.PointToPoint(plat.home_pose, plat.home_pose, 0.05)
    views = stewart.simulate(plat, still, stewart.OpenLoop(), feedforward=lambda t: np.broadcast_to(hold, (len(t), 6)))
    copies = stewart.simulate(plat, still, stewart.OpenLoop(), feedforward=lambda t: np.tile(hold, (len(t), 1)))
    np.testing.assert_array_equal(views.x, copies.x)
    assert np.max(np.abs(views.x - plat.home_pose)) < 1e-15  # reached 2.5e-17


def test_simulate_converts_its_platform_once_where_it_enters(conversions):
    """The rule of stewart.model: simulate converts its platform argument once, where it enters;
    the functions it calls inside the motion package take the converted Platform. A
    PlatformParams is compiled once; the motion package calls a converter once (the workspace
    check calls stewart.model.reachability's public functions, which convert their own
    argument)."""
    params = stewart.PlatformParams.preset("narayan2017")
    home = stewart.home_pose(params)
    move = stewart.PointToPoint(home, home + np.array([0.01, 0.0, 0.0, 0.0, 0.0, 0.0]), 0.1)
    controller = stewart.ComputedTorque.tuned(5.0)
    count = conversions("stewart.motion")
    result = stewart.simulate(params, move, controller, dt=0.01)
    assert result.completed
    assert count == {"stewart.motion.mechanism": 1, "compiled": 1}  # simulate's mechanism() of its argument
