"""The CasADi functions over the compiled model and the minimum-effort move built on them."""

import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import stewart
import stewart.motion.optimize
from stewart.motion import casadi_functions
from stewart.model import kinematics
from stewart.oracles import frames
from stewart.oracles.physics import random_states, relative_error

ca = pytest.importorskip("casadi")

#: The seed paper's move: home to its target pose (Narayan Rao et al. 2017).
TARGET = np.array([0.04565, -0.0102, 0.192, -0.0863, 0.1046, 0.0960])
#: The move's per-leg force limit [N] (one leg reaches it).
FORCE_LIMIT = 60.0


@pytest.fixture(scope="module")
def plat():
    return stewart.Platform.preset("narayan2017")


def _jacobian(function, args, wrt):
    """The Jacobian CasADi takes of ``function`` (through its ``get_jacobian``) at ``args``."""
    symbols = [ca.MX.sym(f"a{k}", len(a)) for k, a in enumerate(args)]
    jac = ca.Function("jacobian_of_function", symbols, [ca.jacobian(function(*symbols), symbols[wrt])])
    return np.asarray(jac(*args))


def test_dynamics_functions_give_the_platforms_values_and_exact_jacobians(plat):
    x, xd, xdd = (a[0] for a in random_states(plat.params, 1, np.random.default_rng(5)))
    tau = plat.inverse_dynamics(x, xd, xdd)
    inverse, forward = casadi_functions.inverse_dynamics(plat), casadi_functions.forward_dynamics(plat)
    np.testing.assert_array_equal(np.asarray(inverse(x, xd, xdd)).ravel(), tau)
    np.testing.assert_array_equal(np.asarray(forward(x, xd, tau)).ravel(), plat.forward_dynamics(x, xd, tau))
    exact_id = plat.inverse_dynamics_derivatives(x, xd, xdd)
    exact_fd = plat.forward_dynamics_derivatives(x, xd, tau)
    for k in range(3):
        np.testing.assert_array_equal(_jacobian(inverse, (x, xd, xdd), k), exact_id[1 + k])
        np.testing.assert_array_equal(_jacobian(forward, (x, xd, tau), k), exact_fd[1 + k])


def test_rk4_step_function_is_the_platforms_step(plat):
    x, xd, xdd = (a[0] for a in random_states(plat.params, 1, np.random.default_rng(6)))
    tau, s = plat.inverse_dynamics(x, xd, xdd), np.concatenate([x, xd])
    step = casadi_functions.rk4_step(plat, 0.01)
    exact = plat.rk4_step(x, xd, tau, 0.01, jacobians=True)
    np.testing.assert_array_equal(np.asarray(step(s, tau)).ravel(), np.concatenate([exact.x, exact.xd]))
    np.testing.assert_array_equal(_jacobian(step, (s, tau), 0), exact.A)
    np.testing.assert_array_equal(_jacobian(step, (s, tau), 1), exact.B)
    with pytest.raises(ValueError, match="dt: must be > 0"):
        casadi_functions.rk4_step(plat, 0.0)


def test_a_batch_function_is_the_mapped_one_with_block_diagonal_jacobians(plat, simd_path):
    x, xd, xdd = random_states(plat.params, 5, np.random.default_rng(8))
    tau = plat.inverse_dynamics(x, xd, xdd)
    single, batch = casadi_functions.rk4_step(plat, 0.01), casadi_functions.rk4_step(plat, 0.01, 5)
    states, forces = ca.MX.sym("S", 12, 5), ca.MX.sym("U", 6, 5)
    outputs = {}
    for label, function in (("mapped", single.map(5)), ("batch", batch)):
        out = function(states, forces)
        jacobian = ca.jacobian(ca.vec(out), ca.vertcat(ca.vec(states), ca.vec(forces)))
        assert jacobian.sparsity().nnz() == 5 * (12 * 12 + 12 * 6)
        outputs[label] = [np.asarray(v) for v in ca.Function(f"{label}_step", [states, forces], [out, jacobian])(
            np.hstack([x, xd]).T, tau.T)]
    for mapped, batch_value in zip(outputs["mapped"], outputs["batch"]):
        np.testing.assert_array_equal(batch_value, mapped)


def test_leg_length_jacobian_against_complex_step(plat, figures):
    x = random_states(plat.params, 1, np.random.default_rng(7))[0][0]
    function = casadi_functions.leg_lengths(plat)
    np.testing.assert_array_equal(np.asarray(function(x)).ravel(), plat.leg_lengths(x))
    h = 1e-30
    columns = [frames.leg_lengths(plat.params, x + 1j * h * e).imag / h for e in np.eye(6)]
    figures("CasADi leg-length Jacobian J_C T vs complex step", relative_error(_jacobian(function, (x,), 0),
                                                                                np.column_stack(columns)), 2e-14)  # reached 3.4e-16


def test_undefined_states_give_nan_not_an_exception(plat):
    # Platform point 0 on base point 0: leg 0 has zero length.
    x = np.concatenate([np.asarray(plat.params.base_points[0]) - np.asarray(plat.params.platform_points[0]),
                        np.zeros(3)])
    assert np.all(np.isnan(np.asarray(casadi_functions.inverse_dynamics(plat)(x, np.zeros(6), np.zeros(6)))))
    assert np.all(np.isnan(_jacobian(casadi_functions.inverse_dynamics(plat), (x, np.zeros(6), np.zeros(6)), 0)))


@pytest.fixture(scope="module")
def move(plat):
    return stewart.motion.optimize.minimum_effort_move(plat, TARGET, 5.0, 20, force_limit=FORCE_LIMIT)


def test_minimum_effort_move_solves_within_its_limits(plat, move, figures):
    assert move.ok and move.status == "Solve_Succeeded" and move.iterations > 0
    assert move.x.shape == move.xd.shape == move.lengths.shape == (21, 6) and move.tau.shape == (20, 6)
    # the end nodes are fixed variables, which IPOPT holds as given: reached 0, a bound of a few ulp
    np.testing.assert_allclose(move.x[0], plat.home_pose, rtol=0, atol=1e-15)
    np.testing.assert_allclose(move.x[-1], TARGET, rtol=0, atol=1e-15)
    np.testing.assert_allclose(move.xd[[0, -1]], 0.0, rtol=0, atol=1e-15)
    low, high = plat.params.leg_length_limits
    # IPOPT keeps to its bounds within its bound_relax_factor (1e-8 of each bound): the legs reach
    # 1.0e-8 m past their stroke, a force 6.0e-7 N past the limit.
    assert np.all(move.lengths >= low - 1e-7) and np.all(move.lengths <= high + 1e-7)
    assert np.max(np.abs(move.tau)) <= FORCE_LIMIT + 1e-6
    assert move.effort == pytest.approx(np.sum(move.tau**2) * move.dt, rel=1e-14)  # reached 0
    # The nodes are linked by the compiled RK4 step under the interval's forces: to IPOPT's
    # tolerance (tol 1e-8), all it promises; its last Newton steps reach 1.6e-15.
    step = plat.rk4_step(move.x[:-1], move.xd[:-1], move.tau, move.dt)
    defect = np.max(np.abs(np.hstack(step) - np.hstack([move.x[1:], move.xd[1:]])))
    figures("optimized move: RK4 defects between nodes", defect, 1e-8)


def test_minimum_effort_move_is_physical(plat, move, figures):
    """The forces, held over an interval and integrated from its first node by an
    independent adaptive solver (DOP853), lead to the next node up to
    RK4's local error: halving RK4's step shrinks the difference at a rate only a
    discretization error has (1/32 asymptotically; a model error would not shrink)."""
    worst = 0.0
    for k, tau in enumerate(move.tau):
        def rate(_, s):
            return np.concatenate([s[6:], plat.forward_dynamics(s[:6], s[6:], tau)])

        start = np.concatenate([move.x[k], move.xd[k]])
        end = solve_ivp(rate, (0.0, move.dt), start, method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]
        half = plat.rk4_step(move.x[k], move.xd[k], tau, move.dt / 2)
        half = plat.rk4_step(half.x, half.xd, tau, move.dt / 2)
        shrink = np.max(np.abs(end[:6] - half.x)) / np.max(np.abs(end[:6] - move.x[k + 1]))
        worst = np.maximum(worst, shrink)
    figures("optimized move: interval error ratio, RK4 at dt/2 vs dt against DOP853", worst, 0.25)


def kkt_figures(plat, move, force_limit, active=1e-6):
    """``(stationarity, multipliers)`` of ``move`` as a solution of its NLP, from the compiled
    model's own RK4 Jacobians and ``J_C T`` rather than IPOPT's multipliers: the
    constraints are the defects ``s_(k+1) - step(s_k, tau_k) = 0`` over the inner nodes and
    the forces (the end nodes are fixed) and the inequalities ``g(w) <= 0`` within ``active``
    of their bound (forces at the limit, legs at the ends of their stroke, at the inner
    nodes). The multipliers solve ``grad f + J_eq^T mu + J_act^T lambda = 0`` in least squares;
    stationarity is its residual relative to ``|grad f|``, and a minimum has ``lambda >= 0``
    (no move off an active bound lowers the effort)."""
    n, dt = len(move.tau), move.dt
    low, high = plat.params.leg_length_limits
    step = plat.rk4_step(move.x[:-1], move.xd[:-1], move.tau, dt, jacobians=True)
    inner = 12 * (n - 1)
    size = inner + 6 * n

    def node(k):
        return slice(12 * (k - 1), 12 * k)

    def force(k):
        return slice(inner + 6 * k, inner + 6 * (k + 1))

    equality = np.zeros((n, 12, size))
    for k in range(n):
        if k + 1 < n:
            equality[k, :, node(k + 1)] = np.eye(12)
        if k > 0:
            equality[k, :, node(k)] = -step.A[k]
        equality[k, :, force(k)] = -step.B[k]
    active_rows = []
    for k, i in zip(*np.nonzero(np.abs(move.tau) > force_limit - active)):
        row = np.zeros(size)
        row[force(k)][i] = np.sign(move.tau[k, i])
        active_rows.append(row)
    lengths_by_pose = plat.jacobian(move.x) @ stewart.twist_transform(move.x)
    for k in range(1, n):
        for i in range(6):
            for sign, at_bound in ((-1.0, move.lengths[k, i] < low + active), (1.0, move.lengths[k, i] > high - active)):
                if at_bound:
                    row = np.zeros(size)
                    row[node(k)][:6] = sign * lengths_by_pose[k, i]
                    active_rows.append(row)
    gradient = np.zeros(size)
    gradient[inner:] = 2 * dt * move.tau.ravel()
    matrix = np.vstack([equality.reshape(12 * n, size), *active_rows]).T
    multipliers = np.linalg.lstsq(matrix, -gradient, rcond=None)[0]
    stationarity = np.linalg.norm(gradient + matrix @ multipliers) / np.linalg.norm(gradient)
    return stationarity, multipliers[12 * n:]


def test_minimum_effort_move_is_optimal(plat, move, figures):
    """The first-order (KKT) conditions of the move's NLP hold at IPOPT's answer: the effort's
    gradient is a combination of the active constraints' gradients, with each active
    inequality's multiplier positive. The bound is IPOPT's own tolerance (tolerance=1e-8, on
    its scaled optimality error: the answer is only as stationary as IPOPT was asked to make
    it); the run reaches 1.2e-10, a solve stopped at tolerance=1e-3 2.5e-6 and one stopped
    after 8 iterations 0.36. Of the 31 active inequalities (one force at its limit, the rest
    legs at the end of their stroke), the least multiplier is 1.2 and the largest 150."""
    stationarity, multipliers = kkt_figures(plat, move, FORCE_LIMIT)
    figures("optimized move: KKT stationarity |grad f + J^T lambda| / |grad f|", stationarity, 1e-8)  # reached 1.2e-10
    assert len(multipliers) > 0 and np.all(multipliers > 0), multipliers


def test_casadis_own_model_finds_the_same_optimum(plat, move, figures):
    from benchmarks.peers import casadi_optimize

    states, forces, effort, stats, _ = casadi_optimize.minimum_effort_move(plat, TARGET, 5.0, 20, force_limit=FORCE_LIMIT)
    assert stats["success"]
    # Two solves of the same NLP agree only to IPOPT's tolerance (tol 1e-8 on the effort's
    # optimality; the forces, at a minimum, to about its square root): the bounds. The two
    # models agree to round-off, so IPOPT takes the same steps and reaches 1.3e-16 and 6.5e-15.
    figures("optimized move: effort, ours vs CasADi's own model", abs(effort - move.effort) / move.effort, 1e-9)
    figures("optimized move: forces, ours vs CasADi's own model", relative_error(forces, move.tau), 1e-5)


def test_unreachable_target_and_bad_arguments(plat):
    with pytest.raises(stewart.WorkspaceError, match="target: .*longer than the maximum length"):
        stewart.motion.optimize.minimum_effort_move(plat, [0, 0, 0.5, 0, 0, 0], 5.0)
    with pytest.raises(ValueError, match="duration: must be > 0"):
        stewart.motion.optimize.minimum_effort_move(plat, TARGET, -1.0)
    with pytest.raises(ValueError, match="force_limit: must be > 0"):
        stewart.motion.optimize.minimum_effort_move(plat, TARGET, 5.0, force_limit=0.0)
    with pytest.raises(ValueError, match="intervals: must be from 1"):
        stewart.motion.optimize.minimum_effort_move(plat, TARGET, 5.0, 0)


@pytest.mark.slow
def test_optimize_command(move, tmp_path, capsys):
    from cli_outputs import check_optimize_csv
    from test_cli import _one_error_line, _run

    target = [str(v) for v in TARGET]
    csv, figures_dir = tmp_path / "move.csv", tmp_path / "figs"
    code, out, _ = _run(["optimize", "--target", *target, "--intervals", "20", "--force-limit", str(FORCE_LIMIT),
                         "--csv", str(csv), "--plot", str(figures_dir), "--json"], capsys)
    summary = json.loads(out)
    assert code == 0 and summary["ok"] and summary["status"] == "Solve_Succeeded" and summary["exit_code"] == 0
    assert max(summary["peak_force"]) <= FORCE_LIMIT + 1e-6 and len(summary["files"]) == 3
    assert sorted(p.name for p in figures_dir.iterdir()) == ["optimize_forces.png", "optimize_legs.png"]
    check_optimize_csv(csv, move)
    code, _, err = _run(["optimize", "--target", "0", "0", "0.5", "0", "0", "0"], capsys)
    assert code == 3 and "longer than the maximum length" in _one_error_line(err, "optimize", "--target: ")
    code, out, err = _run(["optimize", "--target", *target, "--max-iterations", "2"], capsys)
    assert code == 4 and "IPOPT did not solve the problem (Maximum_Iterations_Exceeded)" in _one_error_line(
        err, "optimize", "")
    code, _, err = _run(["optimize"], capsys)
    assert code == 2 and "give --target" in _one_error_line(err, "optimize", "")
