"""MPC cueing (stewart.cueing.predictive): the rider's signals and their Jacobians against
the independent numpy implementation, the vestibular sections against the transfer
functions, one step's QP against a dense solver, the linearized force constraint against
the exact inverse dynamics, and the closed loop within every limit on shipped maneuvers."""

import os
import numpy as np
import pytest
from scipy import optimize, signal

import stewart
from stewart.cueing import MPCParams, mpc, prediction, predictive, read_log, vestibular
from stewart.motion.trajectory import PiecewiseTrajectory

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(ROOT, "examples", "cueing")


@pytest.fixture(scope="module")
def simulator():
    return stewart.Platform.preset("motion_simulator")


def _richardson(f, x, j, h=1e-3):
    """d f / d x_j by Richardson-extrapolated central differences (error ~h^4)."""
    def central(step):
        a, b = x.copy(), x.copy()
        a[:, j] += step
        b[:, j] -= step
        return (f(a) - f(b)) / (2 * step)
    return (4 * central(h / 2) - central(h)) / 3


def test_signals_and_jacobians_against_platform_signals():
    rng = np.random.default_rng(3)
    x, v, u = rng.normal(size=(3, 8, 6)) * [[0.2] * 3 + [0.4] * 3]
    y, dx, dv, du = prediction.signals_and_jacobians(x, v, u, 9.81)
    f, w = vestibular.platform_signals(x, v, u, 9.81)
    assert np.max(np.abs(y - np.column_stack([f, w]))) < 1e-14
    for arg, jac in ((0, dx), (1, dv), (2, du)):
        def signals(value, arg=arg):
            args = [x, v, u]
            args[arg] = value
            return np.column_stack(vestibular.platform_signals(*args, 9.81))
        for j in range(6):
            assert np.max(np.abs(_richardson(signals, [x, v, u][arg], j) - jac[:, :, j])) < 1e-9


def test_vestibular_sections_match_transfer_functions():
    states = prediction.VestibularStates()
    w = np.logspace(-3, 3, 200)
    for channel, tf in ((0, vestibular.otolith()), (3, vestibular.canal())):
        _, expected = signal.freqresp(tf, w)
        got = np.array([states.C[channel] @ np.linalg.solve(1j * s * np.eye(states.n) - states.A, states.B[:, channel])
                        for s in w])
        assert np.max(np.abs(got - expected) / np.abs(expected)) < 1e-9
    ad, bd = states.discrete(0.05)
    ref = signal.cont2discrete((states.A, states.B, states.C, np.zeros((6, 6))), 0.05, method="zoh")
    assert np.max(np.abs(ad - ref[0])) < 1e-14 and np.max(np.abs(bd - ref[1])) < 1e-14


def _qp(platform, **settings):
    params = MPCParams.for_platform(platform, **settings)
    return predictive.CueingQP(platform, params, 0.01)


def test_one_step_qp_against_dense_solver(simulator, monkeypatch):
    """Braking held over the horizon pushes the plan onto its limits; OSQP (tight
    tolerances) against scipy's SLSQP on the same soft-constrained QP, dense."""
    monkeypatch.setitem(predictive.SOLVER_SETTINGS, "eps_abs", 1e-10)
    monkeypatch.setitem(predictive.SOLVER_SETTINGS, "eps_rel", 1e-10)
    monkeypatch.setitem(predictive.SOLVER_SETTINGS, "max_iter", 200000)
    qp = _qp(simulator, steps=4, duration=0.4)
    vehicle = np.tile([-6.0, 0.0, 9.81, 0.0, 0.0, 0.0], (qp.n, 1))
    z0 = np.zeros(qp.vestibular.n)
    x0, v0 = qp.home + [0.3, 0, 0, 0, 0, 0], np.array([-0.4, 0, 0, 0, 0.03, 0])
    H, q, M, lo, hi, _, _ = qp.condensed(x0, v0, z0, vehicle)
    u, *_ = qp.solve(x0, v0, z0, vehicle)
    nu, soft = 6 * qp.n, qp.soft
    scaled = M / qp.row_scale[:, None]
    lo_s, hi_s = lo / qp.row_scale, hi / qp.row_scale

    def cost(z):
        return 0.5 * z[:nu] @ H @ z[:nu] + q @ z[:nu] + 0.5 * predictive.SOFT_WEIGHT * z[nu:] @ z[nu:]

    def rows(z):
        r = scaled @ z[:nu]
        r[soft] -= z[nu:]
        return r
    hard = np.setdiff1d(np.arange(qp.m), soft)
    constraints = [{"type": "ineq", "fun": lambda z: rows(z)[soft] - lo_s[soft]},
                   {"type": "ineq", "fun": lambda z: hi_s[soft] - rows(z)[soft]},
                   {"type": "eq", "fun": lambda z: rows(z)[hard] - lo_s[hard]}]
    start = np.concatenate([u.ravel(), np.zeros(len(soft))]) * 0.5
    dense = optimize.minimize(cost, start, jac=lambda z: np.concatenate([H @ z[:nu] + q, predictive.SOFT_WEIGHT * z[nu:]]),
                              constraints=constraints, method="SLSQP", options={"ftol": 1e-14, "maxiter": 2000})
    assert dense.success, dense.message
    active = np.sum((rows(dense.x)[soft] <= lo_s[soft] + 1e-9) | (rows(dense.x)[soft] >= hi_s[soft] - 1e-9))
    assert active > 0  # the limits do bind
    assert np.max(np.abs(u.ravel() - dense.x[:nu])) <= 1e-6 * max(1.0, np.max(np.abs(dense.x[:nu])))


def test_linearized_force_is_exact_to_second_order(simulator):
    """The force rows of the condensed QP, linearized at rest, against the exact inverse
    dynamics along the planned states: the error falls 4x when the step halves."""
    qp = _qp(simulator, steps=5, duration=0.5)
    vehicle = np.tile([0.0, 0.0, 9.81, 0.0, 0.0, 0.0], (qp.n, 1))
    x0, v0 = qp.home.copy(), np.zeros(6)
    _, _, M, lo, hi, S, d = qp.condensed(x0, v0, np.zeros(qp.vestibular.n), vehicle)
    rows = qp.rows["force"]
    direction = np.random.default_rng(5).normal(size=6 * qp.n) * np.tile([1.0, 1.0, 1.0, 0.5, 0.5, 0.5], qp.n)
    errors = []
    for eps in (0.4, 0.2, 0.1):
        u = eps * direction
        states = np.einsum("kaj,j->ka", S, u) + d
        x = np.vstack([x0, states[:-1, :6] + qp.home])
        v = np.vstack([v0, states[:-1, 6:12]])
        exact = simulator.inverse_dynamics(x, v, u.reshape(qp.n, 6)).ravel()
        # rows are lo <= M u <= hi with lo = -limit - m: the linear force is M u + m
        linear = M[rows] @ u - (lo[rows] + qp.force_limit)
        errors.append(np.max(np.abs(exact - linear)))
    assert errors[0] > 1e-6  # a real nonlinearity, not round-off
    assert 3.5 < errors[0] / errors[1] < 4.5 and 3.5 < errors[1] / errors[2] < 4.5


@pytest.mark.parametrize("name", ["hard_braking", "double_lane_change"])
def test_closed_loop_stays_within_limits(simulator, name):
    result = mpc(os.path.join(EXAMPLES, f"{name}.csv"), simulator, simulate=True)
    assert result.ok, result.problems
    assert result.solver["qp_failures"] == 0
    limits = result.limits
    _, speeds = simulator.leg_rates(result.simulation.x, result.simulation.xd)
    assert np.max(np.abs(speeds)) <= limits["leg_velocity"]
    assert np.max(np.abs(result.simulation.forces)) <= limits["force"]
    lengths = simulator.leg_lengths(result.simulation.x)
    lo, hi = simulator.params.leg_length_limits
    assert lengths.min() >= lo and lengths.max() <= hi
    # the reference is the plan itself: its samples are the MPC's states
    x, v, a = result.reference.sample(result.t)
    assert np.max(np.abs(x - result.poses)) < 1e-12 and np.max(np.abs(v - result.velocities)) < 1e-12


def test_mpc_beats_washout_on_the_braking_and_take_off_channels(simulator):
    """The maneuvers' main channel (fx): MPC's perceived error below washout's."""
    from stewart.cueing import washout

    for name in ("hard_braking", "takeoff_roll"):
        log = read_log(os.path.join(EXAMPLES, f"{name}.csv"))
        a = mpc(log, simulator).metrics["perceived_error_rms"]["fx"]
        b = washout(log, simulator).metrics["perceived_error_rms"]["fx"]
        assert a < b, (name, a, b)


def test_piecewise_trajectory_is_constant_acceleration():
    t = np.array([0.0, 0.1, 0.2])
    x = np.zeros((3, 6))
    v = np.zeros((3, 6))
    a = np.zeros((3, 6))
    a[0, 0], a[1, 0] = 2.0, -1.0
    x[1, 0], v[1, 0] = 0.5 * 2.0 * 0.01, 0.2
    x[2, 0], v[2, 0] = x[1, 0] + 0.2 * 0.1 - 0.5 * 0.01, 0.1
    traj = PiecewiseTrajectory(t, x, v, a)
    pos, vel, acc = traj.sample(np.array([0.05, 0.15]))
    assert np.allclose(pos[:, 0], [0.5 * 2.0 * 0.05 ** 2, x[1, 0] + 0.2 * 0.05 - 0.5 * 0.05 ** 2], atol=1e-15)
    assert np.allclose(vel[:, 0], [0.1, 0.15], atol=1e-15) and np.allclose(acc[:, 0], [2.0, -1.0])
