"""The derivative methods of Platform (inverse and forward dynamics, the RK4 step): central
differences of the primal methods, the identities between them, batch against single
calls, the step against the simulator's, and the error contract."""

import numpy as np
import pytest

import stewart
from stewart.model.platform import ForwardDynamicsDerivatives, InverseDynamicsDerivatives, StepDerivatives

from conftest import random_params


def _states(platform, rng, n):
    home = platform.home_pose
    x = home + rng.uniform(-1, 1, (n, 6)) * np.array([0.05 * home[2]] * 3 + [0.15] * 3)
    xd = rng.normal(size=(n, 6)) * np.array([0.2 * home[2]] * 3 + [0.5] * 3)
    xdd = rng.normal(size=(n, 6)) * np.array([2 * home[2]] * 3 + [5.0] * 3)
    return x, xd, xdd


def _central(f, inputs, which, h=1e-6):
    """d f / d inputs[which] (columns) by central differences with step h max(1, |input|)."""
    columns = []
    for k in range(6):
        step = h * max(1.0, abs(inputs[which][k]))
        plus = [np.array(a, dtype=float) for a in inputs]
        minus = [np.array(a, dtype=float) for a in inputs]
        plus[which][k] += step
        minus[which][k] -= step
        columns.append((np.concatenate(f(*plus)) - np.concatenate(f(*minus))) / (2 * step))
    return np.stack(columns, axis=-1)


def _same(got, want):
    """Equal to round-off: the compiler may contract the same operations into fused
    multiply-adds differently in different functions (-march=native)."""
    np.testing.assert_allclose(got, want, rtol=0, atol=8 * np.finfo(float).eps * np.max(np.abs(want)))


def _close(got, want, tol=1e-6):
    """Relative to the largest entry: central differences with h = 1e-6 carry their truncation
    and rounding (the default bound, 1e-6: 3.4e-8 reached on the dynamics' Jacobians, 1.4e-8 on
    the RK4 step's B)."""
    assert np.max(np.abs(got - want)) <= tol * np.max(np.abs(want)), np.max(np.abs(got - want))


PLATFORMS = {
    "narayan2017": lambda: stewart.Platform.preset("narayan2017"),
    "random, general legs": lambda: stewart.Platform(random_params(np.random.default_rng(7), axisymmetric=False)),
}


@pytest.fixture(params=sorted(PLATFORMS))
def platform(request):
    return PLATFORMS[request.param]()


@pytest.mark.parametrize("forward", [False, True], ids=["inverse", "forward"])
def test_dynamics_derivatives_match_central_differences(platform, forward):
    rng = np.random.default_rng(11)
    x, xd, xdd = _states(platform, rng, 3)
    third = platform.inverse_dynamics(x, xd, xdd) if forward else xdd
    primal = platform.forward_dynamics if forward else platform.inverse_dynamics
    derivatives = platform.forward_dynamics_derivatives if forward else platform.inverse_dynamics_derivatives
    for i in range(3):
        inputs = (x[i], xd[i], third[i])
        result = derivatives(*inputs)
        assert isinstance(result, ForwardDynamicsDerivatives if forward else InverseDynamicsDerivatives)
        _same(result[0], primal(*inputs))
        for which, jac in enumerate(result[1:]):
            assert jac.shape == (6, 6)
            _close(jac, _central(lambda *a: (primal(*a),), inputs, which))


def test_identities_between_the_jacobians(platform):
    """dxdd/dtau = M^-1 J_C^T, dtau/dxdd = J_C^-T M, and the implicit-function round trip
    dxdd/dx = -(dtau/dxdd)^-1 dtau/dx."""
    rng = np.random.default_rng(13)
    x, xd, xdd = _states(platform, rng, 4)
    inv = platform.inverse_dynamics_derivatives(x, xd, xdd)
    fwd = platform.forward_dynamics_derivatives(x, xd, inv.tau)
    M, JC = platform.mass_matrix(x), platform.jacobian(x)
    np.testing.assert_allclose(fwd.xdd, xdd, rtol=5e-14, atol=5e-14 * np.abs(xdd).max())  # reached 1/50 of it
    eye = np.broadcast_to(np.eye(6), (4, 6, 6))
    np.testing.assert_allclose(inv.dtau_dxdd @ fwd.dxdd_dtau, eye, atol=5e-14, rtol=5e-11)  # reached 1/69 of it
    np.testing.assert_allclose(M @ fwd.dxdd_dtau, np.swapaxes(JC, -1, -2), atol=1e-15 * np.abs(JC).max(), rtol=5e-14)  # reached 1/62 of it
    np.testing.assert_allclose(np.swapaxes(JC, -1, -2) @ inv.dtau_dxdd, M, atol=2e-14 * np.abs(M).max(), rtol=2e-11)  # reached 1/56 of it
    for got, d_tau in ((fwd.dxdd_dx, inv.dtau_dx), (fwd.dxdd_dxd, inv.dtau_dxd)):
        want = -np.linalg.solve(inv.dtau_dxdd, d_tau)
        _close(got, want, 5e-13)  # no differences here: reached 1.1e-14


def test_batch_matches_single_calls(platform, simd_path):
    rng = np.random.default_rng(14)
    x, xd, xdd = _states(platform, rng, 5)
    tau = platform.inverse_dynamics(x, xd, xdd)
    batches = (platform.inverse_dynamics_derivatives(x, xd, xdd),
               platform.forward_dynamics_derivatives(x, xd, tau),
               platform.rk4_step(x, xd, tau, 2e-3, jacobians=True))
    shapes = ((6,), (6, 6), (6, 6), (6, 6)), ((6,), (6, 6), (6, 6), (6, 6)), ((6,), (6,), (12, 12), (12, 6))
    for i in range(5):
        singles = (platform.inverse_dynamics_derivatives(x[i], xd[i], xdd[i]),
                   platform.forward_dynamics_derivatives(x[i], xd[i], tau[i]),
                   platform.rk4_step(x[i], xd[i], tau[i], 2e-3, jacobians=True))
        for batch, single, shape in zip(batches, singles, shapes):
            for b, s, sh in zip(batch, single, shape):
                assert b.shape == (5,) + sh and s.shape == sh
                np.testing.assert_array_equal(b[i], s)


def test_rk4_step_jacobians_match_central_differences(platform):
    rng = np.random.default_rng(15)
    x, xd, xdd = _states(platform, rng, 1)
    tau = platform.inverse_dynamics(x[0], xd[0], xdd[0])
    dt = 5e-3
    step = platform.rk4_step(x[0], xd[0], tau, dt, jacobians=True)
    assert isinstance(step, StepDerivatives)
    plain = platform.rk4_step(x[0], xd[0], tau, dt)
    _same(step.x, plain.x)
    _same(step.xd, plain.xd)
    f = lambda *a: tuple(platform.rk4_step(*a, dt))
    inputs = (x[0], xd[0], tau)
    _close(step.A, np.concatenate([_central(f, inputs, 0), _central(f, inputs, 1)], axis=1), 5e-9)  # reached 1.1e-10
    _close(step.B, _central(f, inputs, 2))


def test_rk4_step_is_the_simulators_open_loop_step():
    platform = stewart.Platform.preset("narayan2017")
    rng = np.random.default_rng(16)
    x, xd, xdd = _states(platform, rng, 1)
    tau = platform.inverse_dynamics(x[0], xd[0], xdd[0]) + rng.normal(size=6)
    dt = 2e-3
    trajectory = stewart.PointToPoint(x[0], x[0], duration=dt)
    run = stewart.simulate(platform, trajectory, stewart.OpenLoop(), dt=dt, duration=dt, x0=x[0], xd0=xd[0],
                           feedforward=lambda t: np.tile(tau, (np.size(t), 1)), check_workspace=False)
    step = platform.rk4_step(x[0], xd[0], tau, dt)
    _same(step.x, run.x[-1])
    _same(step.xd, run.xd[-1])


@pytest.mark.parametrize("dt", [0.0, -1e-3, np.inf, np.nan, "0.01", True, [1e-3]])
def test_rk4_step_refuses_a_bad_dt(dt):
    platform = stewart.Platform.preset("narayan2017")
    with pytest.raises(ValueError, match="dt"):
        platform.rk4_step(platform.home_pose, np.zeros(6), np.zeros(6), dt)


def test_errors_name_the_argument_and_the_singularity():
    platform = stewart.Platform.preset("narayan2017")
    home, zero = platform.home_pose, np.zeros(6)
    with pytest.raises(ValueError, match="xdd"):
        platform.inverse_dynamics_derivatives(home, zero, [np.nan] * 6)
    with pytest.raises(ValueError, match="tau"):
        platform.forward_dynamics_derivatives(home, zero, zero[:5])
    with pytest.raises(ValueError, match="xd"):
        platform.rk4_step(home, [np.inf] * 6, zero, 1e-3, jacobians=True)
    with pytest.raises(stewart.SingularityError, match="inverse_dynamics_derivatives"):
        platform.inverse_dynamics_derivatives(zero, zero, zero)
    tilted = home.copy()
    tilted[4] = np.pi / 2
    result, ok = platform.forward_dynamics_derivatives(np.stack([home, tilted]), zero, zero, return_mask=True)
    assert ok.tolist() == [True, False]
    assert all(np.isnan(part[1]).all() and np.isfinite(part[0]).all() for part in result)
    (x, xd, A, B), ok = platform.rk4_step(tilted, zero, zero, 1e-3, jacobians=True, return_mask=True)
    assert ok is False and np.isnan(A).all() and np.isnan(x).all()
