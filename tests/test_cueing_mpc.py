"""MPC cueing (stewart.cueing.planner): the rider's signals and their Jacobians against
the independent numpy implementation, the vestibular sections against the transfer
functions, one step's QP against a dense solver, the linearized force constraint against
the exact inverse dynamics, convergence to the vehicle's perception as the horizon grows,
and the closed loop within every limit on shipped maneuvers."""

import os
from dataclasses import replace

import numpy as np
import pytest
from cli_run import call
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

import stewart
from stewart.cueing import MPCParams, VehicleLog, horizon, mpc, planner, read_log, vestibular
from stewart.motion.trajectory import SampledTrajectory

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


def test_rider_signals_against_platform_signals(simulator):
    """The prediction's signals (Platform.rider_signals) against vestibular.platform_signals, their
    Jacobians against Richardson differences of it."""
    rng = np.random.default_rng(3)
    x, v, u = rng.normal(size=(3, 8, 6)) * [[0.2] * 3 + [0.4] * 3]
    assert simulator.params.gravity == 9.81
    y, dx, dv, du = simulator.rider_signals(x, v, u)
    f, w = vestibular.platform_signals(x, v, u, 9.81)
    assert np.max(np.abs(y - np.column_stack([f, w]))) < 1e-14  # reached 1.1e-16
    for arg, jac in ((0, dx), (1, dv), (2, du)):
        def signals(value, arg=arg):
            args = [x, v, u]
            args[arg] = value
            return np.column_stack(vestibular.platform_signals(*args, 9.81))
        for j in range(6):
            # Richardson's h^4 truncation and rounding: reached 3.5e-12 on entries up to 10
            assert np.max(np.abs(_richardson(signals, [x, v, u][arg], j) - jac[:, :, j])) < 3e-10


def test_joint_cosines_against_reachability(simulator):
    """The cone constraints' cosines against stewart.model.reachability.joint_angles, their
    gradients against Richardson differences."""
    from stewart.model.reachability import joint_angles, neutral_axes

    p = simulator.params
    x = simulator.home_pose + np.random.default_rng(4).normal(size=(6, 6)) * 0.08
    neutral = neutral_axes(simulator)
    cos, grad = simulator.joint_cosines(x, neutral)
    universal, spherical = joint_angles(p, x)
    assert np.max(np.abs(cos - np.cos(np.concatenate([universal, spherical], axis=1)))) < 1e-14  # reached 2.2e-16
    for j in range(6):
        numeric = _richardson(lambda y: np.cos(np.concatenate(joint_angles(p, y), axis=1)), x, j)
        assert np.max(np.abs(numeric - grad[:, :, j])) < 5e-11  # reached 6.3e-13 (Richardson's error)


def test_vestibular_sections_match_transfer_functions():
    states = horizon.VestibularStates()
    w = np.logspace(-3, 3, 200)
    for channel, tf in ((0, vestibular.otolith()), (3, vestibular.canal())):
        _, expected = signal.freqresp(tf, w)
        got = np.array([states.C[channel] @ np.linalg.solve(1j * s * np.eye(states.n) - states.A, states.B[:, channel])
                        for s in w])
        assert np.max(np.abs(got - expected) / np.abs(expected)) < 5e-11  # reached 8.6e-13
    ad, bd = states.discrete(0.05)
    ref = signal.cont2discrete((states.A, states.B, states.C, np.zeros((6, 6))), 0.05, method="zoh")
    assert np.max(np.abs(ad - ref[0])) < 1e-14 and np.max(np.abs(bd - ref[1])) < 1e-14


def _qp(platform, **settings):
    params = MPCParams.for_platform(platform, **settings)
    return planner.CueingQP(platform, params, 0.01)


def _soft_qp_kkt(H, q, rows, lo, hi, soft, u, active=1e-9):
    """The KKT conditions of ``min u^T H u / 2 + q^T u + SOFT_WEIGHT/2 sum_soft dist(r_i,
    [lo_i, hi_i])^2 / n_i`` (``r = rows u``, ``n_i = a_i H^-1 a_i^T`` for row ``a_i``: the
    violation in the cost's metric, as DAQP's soft constraints weigh it) subject to ``lo <= r
    <= hi`` on the other rows, at ``u``: ``(infeasibility, stationarity, wrong sign)``, the
    hard rows' largest excess, the largest residual of the cost's gradient less the hard rows
    within ``active`` of a bound (multipliers by least squares), and the largest multiplier
    of the wrong sign. The cost is convex: where all three vanish, ``u`` is its minimum."""
    r = rows @ u
    metric = np.einsum("ij,ji->i", rows, np.linalg.solve(H, rows.T))
    violation = np.where(r > hi, r - hi, np.where(r < lo, r - lo, 0.0))
    is_soft = np.zeros(len(r), bool)
    is_soft[soft] = True
    gradient = H @ u + q + rows.T @ np.where(is_soft, planner.SOFT_WEIGHT / metric * violation, 0.0)
    at_hi, at_lo = ~is_soft & (np.abs(r - hi) <= active), ~is_soft & (np.abs(r - lo) <= active)
    act = np.flatnonzero(at_hi | at_lo)
    lam = np.linalg.lstsq(rows[act].T, -gradient, rcond=None)[0]
    bound = at_hi[act] != at_lo[act]  # an inequality (an equality's multiplier has either sign)
    wrong = np.concatenate([-lam[bound & at_hi[act]], lam[bound & at_lo[act]], [0.0]])
    return (float(np.max(np.maximum(r - hi, lo - r)[~is_soft])), float(np.max(np.abs(rows[act].T @ lam + gradient))),
            float(np.max(wrong)))


def test_one_step_qp_against_its_kkt_conditions(simulator):
    """Braking held over the horizon from a platform already moving back pushes the plan
    onto its limits; the step's solution meets the KKT conditions of the same
    soft-constrained QP, written here, and a nudge of it does not."""
    qp = _qp(simulator, steps=5, duration=0.5)
    vehicle = np.tile([-3.0, 0.0, 9.81, 0.0, 0.0, 0.0], (qp.n, 1))
    z0 = np.zeros(qp.vestibular.n)
    x0, v0 = qp.home + [-0.3, 0, 0, 0, 0, 0], np.array([-0.6, 0, 0, 0, 0.03, 0])
    H, q, M, lo, hi, _, _ = qp.condensed(x0, v0, z0, vehicle)
    u, _, _, info = qp.solve(x0, v0, z0, vehicle)
    assert info["level"] == "plan" and info["tightened"] == 0
    assert info["exitflag"] == 2  # DAQP: optimal with soft constraints violated
    soft = np.flatnonzero(qp.levels["plan"] == planner.SOFT)
    rest = np.arange(qp.rows["rest"].start, qp.rows["rest"].stop)  # hard, lo = hi: equalities
    assert np.all(qp.levels["plan"][rest] == planner.HARD) and np.all(lo[rest] == hi[rest])
    scaled, low, high = M / qp.row_scale[:, None], lo / qp.row_scale, hi / qp.row_scale
    r = scaled[soft] @ u.ravel()
    assert np.any((r < low[soft]) | (r > high[soft]))  # soft limits bind
    scale = max(np.max(np.abs(q)), np.max(np.abs(H @ u.ravel())))
    infeasible, stationary, wrong = _soft_qp_kkt(H, q, scaled, low, high, soft, u.ravel())
    # reached: infeasibility 2.2e-16 to 7e-16 (the active rows solved to rounding), stationarity
    # 1.1e-10 of the gradient's scale (DAQP's primal tolerance 1e-6 on the rows), no multiplier
    # of the wrong sign
    assert infeasible <= 5e-14 and stationary <= 1e-8 * scale and wrong <= 1e-8 * scale
    nudged = u.ravel() + 1e-6 * np.random.default_rng(0).normal(size=u.size)
    assert _soft_qp_kkt(H, q, scaled, low, high, soft, nudged)[1] > 1e-5 * scale


def test_a_soft_limit_is_overstepped_by_its_documented_share():
    """One soft row of a random strictly convex QP, solved with the steps' settings: a plan whose
    unconstrained optimum oversteps the row by delta oversteps it by delta / (1 + SOFT_WEIGHT),
    whatever the row's scale (the penalty of stewart.cueing.planner's docstring)."""
    import daqp

    rng = np.random.default_rng(4)
    factor = rng.normal(size=(8, 8))
    H, q = factor @ factor.T + np.eye(8), rng.normal(size=8)
    free = np.linalg.solve(H, -q)
    for scale in (1e-3, 1.0, 1e3):
        row = scale * rng.normal(size=8)
        delta = 0.5 * scale
        bound = row @ free - delta
        u, _, exitflag, _ = daqp.solve(H, q, row[None, :], np.array([bound]), np.array([-1e30]),
                                       np.array([planner.SOFT], dtype=np.intc), **planner.SOLVER_SETTINGS)
        assert exitflag in planner.SOLVED
        # reached 3.8e-10 (DAQP's solution of the one soft row; 5.4e-11 on another machine)
        np.testing.assert_allclose(row @ u - bound, delta / (1.0 + planner.SOFT_WEIGHT), rtol=1e-8)


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


def test_long_horizon_reproduces_a_slow_small_maneuver(simulator):
    """No position or velocity weights, limits far away, the log's future known, intervals
    of one sample: the perceived error falls as the horizon grows (0.1, 0.4, 0.8 s), to a
    few per cent of the signal."""
    t = np.arange(0, 4.0, 0.02)
    fx = 0.3 * np.sin(2 * np.pi * 0.5 * t) * np.minimum(t, 1.0)
    log = VehicleLog(t, np.column_stack([fx, 0 * t, 9.81 + 0 * t]), np.zeros((len(t), 3)), "slow")
    wide = replace(simulator.params, leg_length_limits=(0.5, 3.0))
    errors = []
    for steps in (5, 20, 40):
        params = MPCParams(duration=0.02 * steps, steps=steps, preview=True, position=0.0, velocity=0.0,
                           acceleration=1e-3, box=(10.0,) * 6, force=1e6, leg_velocity=10.0, tilt_rate=1.0)
        result = mpc(log, wide, params)
        assert result.ok and result.solver["qp_failures"] == 0
        errors.append(result.metrics["perceived_error_rms"]["fx"])
    scale = np.sqrt(np.mean(vestibular.vehicle(log).f[:, 0] ** 2))
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.5 * errors[0] and errors[2] < 0.05 * scale


@pytest.fixture(scope="module")
def shipped(simulator):
    """``shipped(name)``: MPC with its default settings and the closed loop on the shipped
    maneuver ``name``, planned once for the tests below that read it (tests/conftest.py's
    XDIST_GROUPS keeps them on one worker). The plan and its metrics are those of ``mpc``
    without ``simulate``: the closed loop runs after the plan and only adds to the result."""
    runs = {}

    def run(name):
        if name not in runs:
            runs[name] = mpc(os.path.join(EXAMPLES, f"{name}.csv"), simulator, simulate=True)
        return runs[name]

    return run


def _platform_limits(plat) -> dict:
    """The MPC's default limits from the platform's parameters (MPCParams.for_platform's
    documentation, docs/cueing): the force twice the largest static leg force, which inverse
    dynamics at home at rest gives, and the leg speed one stroke (``leg_length_limits``) per
    second. The static forces are checked against statics by hand: at rest the legs' forces
    along their unit vectors balance the weight of the moving body."""
    q, home = plat.params, plat.home_pose
    static = plat.inverse_dynamics(home, np.zeros(6), np.zeros(6))
    # the legs push up the platform's weight and part of their own (pistons and cylinders hang
    # between the joints): m_p g <= sum f_i u_i,z <= (m_p + 6 m_piston + 6 m_cylinder) g, and
    # no net horizontal force (reached 2.7e-12 N, 1.9e-16 of the weight; bound 1e-14 of it)
    push = np.sum(static[:, None] * stewart.leg_unit_vectors(q, home), axis=0)
    weight = q.platform_mass * q.gravity
    assert weight <= push[2] <= (q.platform_mass + 6 * q.piston_mass + 6 * q.cylinder_mass) * q.gravity
    assert np.max(np.abs(push[:2])) <= 1e-14 * weight
    lo, hi = q.leg_length_limits
    return {"leg_velocity": 1.0 * (hi - lo), "force": 2.0 * float(np.max(np.abs(static)))}


@pytest.mark.parametrize("name", ["hard_braking", "double_lane_change"])
def test_closed_loop_stays_within_limits(simulator, shipped, name):
    result = shipped(name)
    assert result.ok, result.problems
    assert result.solver["qp_failures"] == 0
    limits = _platform_limits(simulator)
    assert result.limits == pytest.approx(limits, rel=1e-15, abs=0)  # the same arithmetic: reached 0
    # and the pose box 0.9 of the free excursion along each axis (for_platform's documentation)
    from stewart.model.reachability import axis_excursions

    np.testing.assert_allclose(result.params.box, 0.9 * axis_excursions(simulator), rtol=1e-15, atol=0)
    _, speeds = simulator.leg_rates(result.simulation.x, result.simulation.xd)
    assert np.max(np.abs(speeds)) <= limits["leg_velocity"]
    assert np.max(np.abs(result.simulation.forces)) <= limits["force"]
    lengths = simulator.leg_lengths(result.simulation.x)
    lo, hi = simulator.params.leg_length_limits
    assert lengths.min() >= lo and lengths.max() <= hi
    # the reference is the plan itself: its samples are the MPC's states
    x, v, a = result.reference.sample(result.t)
    # the spline's knots: reached 2.8e-17 m and 2e-31 (a pose's rounding is 2.2e-16 near 1 m)
    assert np.max(np.abs(x - result.poses)) < 2e-15 and np.max(np.abs(v - result.velocities)) < 2e-15


def test_mpc_beats_washout_on_the_braking_and_lane_change_channels(simulator, shipped):
    """The maneuvers' main channel (fx, fy): MPC's perceived error below washout's."""
    from stewart.cueing import washout

    for name, channel in (("hard_braking", "fx"), ("double_lane_change", "fy")):
        log = read_log(os.path.join(EXAMPLES, f"{name}.csv"))
        a = shipped(name).metrics["perceived_error_rms"][channel]
        b = washout(log, simulator).metrics["perceived_error_rms"][channel]
        assert a < b, (name, a, b)


def test_reference_file_gives_the_plan_back(simulator, tmp_path):
    """The reference CSV read by stewart simulate --trajectory (poses and rates: a Hermite
    spline) is the MPC's motion: constant acceleration between samples, the plan's."""
    log = read_log(os.path.join(EXAMPLES, "hard_braking.csv"))
    keep = log.t <= 2.0
    result = mpc(type(log)(log.t[keep], log.f[keep], log.w[keep]), simulator)
    result.to_csv(tmp_path / "ref.csv")
    trajectory = SampledTrajectory.from_csv(tmp_path / "ref.csv")
    mid = 0.5 * (result.t[1:] + result.t[:-1])
    x, v, a = trajectory.sample(mid)
    h = 0.5 * np.diff(result.t)[:, None]
    u = result.accelerations[:-1]
    # the file's 17 digits and the Hermite spline's rounding: reached 9.8e-15 (relative),
    # 3.2e-14 and 2.2e-16; bounds ~100 times those
    assert np.max(np.abs(a - u)) < 1e-12 * max(1.0, np.max(np.abs(u)))
    assert np.max(np.abs(v - (result.velocities[:-1] + h * u))) < 3e-12
    assert np.max(np.abs(x - (result.poses[:-1] + h * result.velocities[:-1] + 0.5 * h * h * u))) < 2e-14


def test_cli_mpc_report_plot_and_closed_loop(tmp_path):
    """stewart cueing --method mpc on the first 2.5 s of the braking: the report names the
    method, the time per step, the limits and peaks, the closed loop's outcome and peaks;
    the written reference is the report's motion; the figures exist."""
    import json
    log = read_log(os.path.join(EXAMPLES, "hard_braking.csv"))
    short = tmp_path / "braking.csv"
    keep = log.t <= 2.5
    type(log)(log.t[keep], log.f[keep], log.w[keep]).to_csv(short)
    pytest.importorskip("matplotlib")
    run = call("cueing", short, "--method", "mpc", "--simulate", "--output", tmp_path / "ref.csv",
               "--report", tmp_path / "r.json", "--plot", tmp_path / "figs")
    assert run.returncode == 0, run.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["method"] == "mpc" and report["ok"] and report["preview"] is False
    assert 0 < report["solve_time_s"]["median"] <= report["solve_time_s"]["max"]
    assert report["qp_failures"] == 0
    # the limits are the platform's (the command's default preset, motion_simulator)
    # reached 0 (the same arithmetic, through the JSON)
    assert report["limits"] == pytest.approx(_platform_limits(stewart.Platform.preset("motion_simulator")), rel=1e-15)
    assert report["peak_force"] <= report["limits"]["force"]
    assert report["peak_leg_velocity"] <= report["limits"]["leg_velocity"]
    sim = report["simulation"]
    assert sim["outcome"] == "completed" and max(sim["peak_force"]) <= report["limits"]["force"]
    assert sim["peak_leg_velocity"] <= report["limits"]["leg_velocity"]
    assert report["perceived_error_rms"]["fx"] > 0 and set(sim["perceived_error_rms"]) == set(vestibular.CHANNELS)
    ref = np.genfromtxt(tmp_path / "ref.csv", delimiter=",", names=True)
    assert len(ref) == int(keep.sum())
    for name in ("cueing_perceived.png", "cueing_reference.png"):
        assert (tmp_path / "figs" / name).stat().st_size > 10_000


def test_no_feasible_motion_is_reported_not_written(simulator, tmp_path):
    """A force limit below the static load: no motion holds it. Every step brakes within the
    forces (held by construction) and the platform falls out of the workspace; the report says
    so (the brake steps, the exact check of the reference), the exit code is 3 and the CLI
    writes no reference."""
    log = read_log(os.path.join(EXAMPLES, "hard_braking.csv"))
    keep = log.t <= 1.0
    short = type(log)(log.t[keep], log.f[keep], log.w[keep], "short")
    static = np.max(simulator.inverse_dynamics(simulator.home_pose, np.zeros(6), np.zeros(6)))
    result = mpc(short, simulator, MPCParams.for_platform(simulator, force=0.5 * static))
    assert result.exit_code == 3 and not result.ok and not result.inside
    assert result.peaks["force"] <= 0.5 * static
    assert result.solver["qp_levels"]["brake"] > 0, result.solver
    assert any("no plan held the machine's limits" in p for p in result.problems), result.problems
    short.to_csv(tmp_path / "short.csv")
    (tmp_path / "c.toml").write_text(f"[limits]\nforce = {0.5 * static}\n")
    run = call("cueing", tmp_path / "short.csv", "--method", "mpc", "--cueing", tmp_path / "c.toml",
               "--output", tmp_path / "ref.csv")
    assert run.returncode == 3 and "no plan held" in run.stderr and "Traceback" not in run.stderr, run.stderr
    assert not (tmp_path / "ref.csv").exists()


_SETTING = st.one_of(st.none(), st.booleans(), st.integers(-3, 30), st.floats(allow_nan=True, allow_infinity=True),
                     st.text(max_size=3), st.lists(st.floats(-2, 2), max_size=7))


@settings(max_examples=200, deadline=None)
@given(values=st.fixed_dictionaries({}, optional={
    name: _SETTING for name in ("duration", "steps", "preview", "specific_force", "angular_velocity", "position",
                                "velocity", "acceleration", "force", "margin", "leg_velocity", "stroke_margin",
                                "tilt_rate", "box")}))
def test_fuzz_mpc_settings_are_valid_or_a_named_value_error(values):
    """Any values of the settings: MPCParams takes them, or raises one ValueError naming the
    setting (section.key) it refuses."""
    try:
        params = MPCParams(**values)
    except ValueError as exc:
        assert any(f".{name}:" in str(exc) for name in values), str(exc)
        return
    for name in ("duration", "force", "leg_velocity", "tilt_rate"):
        value = getattr(params, name)
        assert value is None or (np.isfinite(value) and value > 0)
    assert params.steps >= 2 and 0 <= params.margin < 1
    for name in ("specific_force", "angular_velocity", "position", "velocity", "acceleration"):
        assert np.all(np.isfinite(getattr(params, name)))


@settings(max_examples=4, deadline=None)
@given(scale=st.floats(0.0, 1.5), seed=st.integers(0, 2**16))
def test_fuzz_mpc_is_within_limits_or_says_so(simulator, scale, seed):
    """A random smooth log: MPC's reference is finite and either inside every limit with exit
    0, or reported beyond them with exit 3 (never NaN, never a silent success)."""
    rng = np.random.default_rng(seed)
    t = np.arange(151) * 0.02
    f = np.column_stack([scale * 9.81 * np.sin(rng.uniform(0.2, 3) * t) for _ in range(3)]) + [0, 0, 9.81]
    w = np.column_stack([scale * np.sin(rng.uniform(0.2, 3) * t) for _ in range(3)])
    result = mpc(VehicleLog(t, f, w, name="random"), simulator)
    assert np.all(np.isfinite(result.poses)) and np.all(np.isfinite(result.accelerations))
    within = result.inside and not result.beyond_limits
    assert result.exit_code == (0 if within else 3)
    assert within or result.problems


def test_settings_file_round_trips_through_the_report(tmp_path):
    """A settings file giving every key (none at its default): MPCParams.load reads each into
    its field (the tilt rate from deg/s into rad/s), and to_dict, the report's ``settings``,
    gives the file's sections and values back."""
    import tomllib

    text = ("[horizon]\nduration = 0.6\nsteps = 4\npreview = true\n\n"
            "[weights]\nspecific_force = [1.0, 2.0, 3.0]\nangular_velocity = [0.5, 0.25, 0.125]\n"
            "position = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]\nvelocity = [0.02, 0.02, 0.02, 0.03, 0.03, 0.03]\n"
            "acceleration = [0.002, 0.002, 0.002, 0.004, 0.004, 0.004]\n\n"
            "[limits]\nforce = 5000.0\nmargin = 0.2\nleg_velocity = 0.5\nstroke_margin = 0.02\ntilt_rate = 4.0\n"
            "box = [0.1, 0.1, 0.1, 0.2, 0.2, 0.2]\n")
    path = tmp_path / "m.toml"
    path.write_text(text)
    params = MPCParams.load(path)
    assert (params.duration, params.steps, params.preview, params.force) == (0.6, 4, True, 5000.0)
    assert params.tilt_rate == pytest.approx(4.0 * np.pi / 180, rel=1e-15)
    assert params.box == (0.1, 0.1, 0.1, 0.2, 0.2, 0.2) and params.source == str(path)
    written = params.to_dict()
    assert written["limits"].pop("tilt_rate") == pytest.approx(4.0, rel=1e-15)
    wanted = tomllib.loads(text)
    del wanted["limits"]["tilt_rate"]
    assert written == wanted


def test_step_times_are_the_wall_times_of_the_steps(simulator):
    """Plan.step_time: each step's wall time covers its QP solver's own time, and the steps
    together take no longer than the whole run, timed here around it."""
    import time

    t = np.arange(25) * 0.02
    log = VehicleLog(t, np.column_stack([2.0 * np.sin(3 * t), 0 * t, 9.81 + 0 * t]), np.zeros((len(t), 3)), "short")
    start = time.perf_counter()
    run = planner.plan(log, simulator, MPCParams.for_platform(simulator))
    wall = time.perf_counter() - start
    assert run.failures == 0 and np.all(run.step_time > 0)
    assert np.all(run.step_time >= run.solve_time)
    assert np.sum(run.step_time) <= wall


def _rider_signals(x, v, a, gravity):
    """Eq. 8 written out, complex-safe for complex-step derivatives: ``f = R^T (a + g e_z)``
    and ``w = R^T J_A [psi', theta', phi']`` at {P}'s origin."""
    from stewart.oracles.frames import euler_rate_jacobian, rotation

    r = rotation(x)
    f = np.einsum("nji,nj->ni", r, a[:, :3] + np.array([0.0, 0.0, gravity]))
    w = np.einsum("nji,nj->ni", r, np.einsum("nij,nj->ni", euler_rate_jacobian(x), v[:, 3:]))
    return np.column_stack([f, w])


def _integrate(qp, x0, v0, z0, vehicle, u):
    """The prediction model of stewart.cueing.horizon's docstring, integrated here: per
    interval ``h`` the input ``u_k`` held (``p+ = p + h v + h^2/2 u``, ``v+ = v + h u``), the
    rider's signals at the interval's midpoint, and the vestibular error states advanced by
    the zero-order hold of ``(A, B)`` (scipy's ``cont2discrete``) under the platform's signals
    less the vehicle's. ``(N, 6)``, ``(N, 6)``, ``(N, nz)`` at the intervals' ends."""
    vs = qp.vestibular
    u = u.reshape(qp.n, 6)
    x, v, z = x0 + 0 * u[0], v0 + 0 * u[0], z0 + 0j * u[0, 0]
    xs, rates, zs = [], [], []
    hold = {h: signal.cont2discrete((vs.A, vs.B, np.eye(vs.n), np.zeros((vs.n, 6))), h, method="zoh")[:2]
            for h in set(qp.h)}
    for k, h in enumerate(qp.h):
        ad, bd = hold[h]
        y = _rider_signals((x + 0.5 * h * v + 0.125 * h * h * u[k])[None], (v + 0.5 * h * u[k])[None], u[k][None],
                           qp.params.gravity)[0]
        z = ad @ z + bd @ (y - vehicle[k])
        x, v = x + h * v + 0.5 * h * h * u[k], v + h * u[k]
        xs.append(x), rates.append(v), zs.append(z)
    return np.array(xs), np.array(rates), np.array(zs)


def test_qp_rows_are_the_exact_model_at_the_last_plans_inputs(simulator):
    """Intervals of one log sample: the second step linearizes about the first step's plan
    shifted by one sample, a motion of the double integrator itself. At those inputs every
    row of the condensed QP is the exact value (the states by integration here, the
    vestibular states by simulation here, the legs rows by the exact kinematics and joint
    angles, the force rows by the inverse dynamics), and the rows' gradients are the exact
    derivatives (complex step through the integration here for the states, Richardson
    differences of the exact kinematics and dynamics along the states for the others)."""
    from stewart.model.reachability import joint_angles

    dt = 0.01
    qp = planner.CueingQP(simulator, MPCParams.for_platform(simulator, steps=5, duration=5 * dt), dt)
    n, home = qp.n, qp.home
    rng = np.random.default_rng(7)
    vehicle = np.array([3.0, -2.0, 9.81, 0.2, -0.3, 0.1]) + 0.5 * rng.normal(size=(n, 6))
    # a first plan from rest, then the state one sample along it
    u_first, x_first, v_first, _ = qp.solve(home, np.zeros(6), np.zeros(qp.vestibular.n), vehicle)
    x0, v0, z0 = x_first[1], v_first[1], 0.1 * rng.normal(size=qp.vestibular.n)
    u_lin = np.vstack([u_first[1:], u_first[-1:]]).ravel()
    assert np.max(np.abs(u_lin)) > 0.5  # a real motion to linearize about
    _, _, M, lo, _, S, d = qp.condensed(x0, v0, z0, vehicle)

    def states(u):
        s = np.einsum("kaj,j->ka", S, u) + d
        return s[:, :6] + home, s[:, 6:12], s[:, 12:]

    # the poses and rates: linear in u, exact for any u (reached 2.2e-16, bound 1e-14)
    for u in (u_lin, u_lin + rng.normal(size=6 * n)):
        x, v, _ = states(u)
        xi, vi, _ = _integrate(qp, x0, v0, z0, vehicle, u)
        assert np.max(np.abs(x - xi.real)) < 1e-14 and np.max(np.abs(v - vi.real)) < 1e-14
    # the vestibular states at u_lin and their derivatives by complex step: reached 5e-16 of
    # the states' size and 1.6e-15 of the derivatives'
    _, _, z = states(u_lin)
    zi = _integrate(qp, x0, v0, z0, vehicle, u_lin)[2].real
    assert np.max(np.abs(z - zi)) < 5e-14 * np.max(np.abs(zi))
    dz = np.array([_integrate(qp, x0, v0, z0, vehicle, u_lin + 1e-30j * e)[2].imag / 1e-30
                   for e in np.eye(6 * n)]).transpose(1, 2, 0)
    assert np.max(np.abs(S[:, 12:] - dz)) < 1e-13 * np.max(np.abs(dz))

    # the rows' values at u_lin and derivatives along random directions (Richardson, error ~h^4);
    # the rows are lo <= M u <= hi with lo = the limit less the row's constant: the limits by hand
    # from the settings' documentation (the machine's at the next sample; over the horizon the
    # stroke less stroke_margin, (1 - margin) of the leg speed and force, the cones less CONE_MARGIN)
    legs, force = qp.rows["legs"], qp.rows["force"]
    prm, pp = qp.params, simulator.params
    cones = np.repeat([pp.universal_joint_max_angle, pp.spherical_joint_max_angle], 6)
    next_low = np.concatenate([np.full(6, pp.leg_length_limits[0]), np.full(6, -prm.leg_velocity), np.cos(cones)])
    horizon_low = {"stroke": pp.leg_length_limits[0] + prm.stroke_margin, "speed": -(1 - prm.margin) * prm.leg_velocity,
                   "cones": np.tile(np.cos(cones - planner.CONE_MARGIN), n)}

    def exact(u):
        """The legs rows at the next sample (u_0 held over dt), the stroke, speed and cone rows
        at the intervals' ends, and the forces at their starts, from the library's exact
        kinematics, joint angles and inverse dynamics."""
        x, v, _ = states(u)
        u0 = u[:6]
        x1, v1 = x0 + dt * v0 + 0.5 * dt * dt * u0, v0 + dt * u0
        ends = np.vstack([x1, x]), np.vstack([v1, v])
        lengths, speeds = simulator.leg_rates(*ends)
        cosines = np.cos(np.concatenate(joint_angles(simulator.params, ends[0]), axis=1))
        starts = np.vstack([x0, x[:-1]]), np.vstack([v0, v[:-1]])
        forces = simulator.inverse_dynamics(*starts, u.reshape(n, 6))
        return (np.concatenate([lengths[0], speeds[0], cosines[0]]),
                np.column_stack([lengths[1:], speeds[1:], cosines[1:]]), forces.ravel())

    def linear(u):
        horizon = [(M[qp.rows[g]] @ u - (lo[qp.rows[g]] - horizon_low[g])).reshape(n, -1)
                   for g in ("stroke", "speed", "cones")]
        return M[legs] @ u - (lo[legs] - next_low), np.column_stack(horizon), \
            M[force] @ u - (lo[force] + (1 - prm.margin) * prm.force)

    # reached 2.2e-16 (m, m/s, cosines), 4.4e-16 and 2e-12 N (of forces up to 7e3 N)
    for got, want, bound in zip(linear(u_lin), exact(u_lin), (2e-14, 2e-14, 2e-10)):
        assert np.max(np.abs(got - want)) < bound
    for _ in range(2):
        direction = rng.normal(size=6 * n)

        def along(step):
            a, b = exact(u_lin + step * direction), exact(u_lin - step * direction)
            return [(p - m) / (2 * step) for p, m in zip(a, b)]
        numeric = [(4 * p - m) / 3 for p, m in zip(along(5e-3), along(1e-2))]
        slopes = [linear(direction)[k] - linear(np.zeros(6 * n))[k] for k in range(3)]
        for got, want in zip(slopes, numeric):
            assert np.max(np.abs(got - want)) < 1e-10 * np.max(np.abs(want))  # reached 2.5e-12 (rounding)


def test_comparison_figure_shows_both_methods_on_one_time_axis(simulator, shipped, tmp_path, monkeypatch):
    """stewart.cueing.comparison.plot of the braking (MPC with its closed loop, washout without):
    per channel the vehicle's, washout's and MPC's perceived signals (MPC's achieved by the
    closed loop), below them each method's leg forces against the force limit +-F, all eight
    panels on one shared time axis, its tick labels on the bottom row only."""
    pytest.importorskip("matplotlib")
    import matplotlib.figure

    from stewart.cueing import comparison, washout

    m = shipped("hard_braking")
    w = washout(read_log(os.path.join(EXAMPLES, "hard_braking.csv")), simulator)
    figures = []  # (not rendered)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda fig, *a, **k: figures.append(fig))
    row = {"name": "hard_braking", "results": (w, m), "limits": m.limits}
    comparison.plot(row, "motion_simulator", str(tmp_path / "c.png"))
    (fig,) = figures
    axes = np.array(fig.axes).reshape(4, 2)
    for j, name in enumerate(vestibular.CHANNELS):
        ax = axes[j % 3, j // 3]
        lines = {line.get_label(): line.get_ydata() for line in ax.get_lines()}
        np.testing.assert_array_equal(lines["vehicle"], w.vehicle.channels[:, j])
        np.testing.assert_array_equal(lines["washout"], w.platform.channels[:, j])
        np.testing.assert_array_equal(lines["MPC"], m.achieved.channels[:, j])
    limit = m.limits["force"]
    for ax in axes[3]:
        levels = sorted(line.get_ydata()[0] for line in ax.get_lines() if len(set(line.get_ydata())) == 1)
        assert levels == [-limit, limit]
    forces = np.column_stack([line.get_ydata() for line in axes[3, 1].get_lines()[:6]])
    np.testing.assert_array_equal(forces, m.simulation.forces)
    for ax in axes.ravel():
        assert ax.get_shared_x_axes().joined(ax, axes[0, 0])
        assert any(label.get_visible() for label in ax.get_xticklabels()) == (ax in axes[3])


def test_qp_cost_is_the_documented_weighted_sum(simulator):
    """The condensed cost ``u^T H u / 2 + q^T u`` is, but for a constant, half the module
    docstring's ``sum_k h_k (|W_e C z_k|^2 + |W_p p_k|^2 + |W_v v_k|^2 + |W_u u_k|^2)``, each
    error over its perception threshold (vestibular.THRESHOLDS) or the pose box (per second,
    per second squared) and weighted by MPCParams' weights, written out here over the
    predicted states ``S u + d`` (themselves checked against an integration above)."""
    weights = dict(specific_force=(1.0, 2.0, 3.0), angular_velocity=(0.5, 0.7, 0.9), position=(0.1, 0.2, 0.3, 0.4, 0.5, 0.6),
                   velocity=(0.01, 0.02, 0.03, 0.04, 0.05, 0.06), acceleration=(1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3))
    qp = _qp(simulator, steps=4, duration=0.2, **weights)
    rng = np.random.default_rng(8)
    x0 = qp.home + 0.05 * rng.normal(size=6)
    v0, z0 = 0.1 * rng.normal(size=6), 0.1 * rng.normal(size=qp.vestibular.n)
    vehicle = np.array([1.0, -1.0, 9.81, 0.1, -0.1, 0.05]) + 0.2 * rng.normal(size=(qp.n, 6))
    H, q, _, _, _, S, d = qp.condensed(x0, v0, z0, vehicle)
    thresholds = np.array([vestibular.THRESHOLDS[c] for c in vestibular.CHANNELS])
    box = np.asarray(qp.params.box)

    def cost(u):
        s = np.einsum("kaj,j->ka", S, u) + d
        perceived = s[:, 12:] @ qp.vestibular.C.T / thresholds
        terms = (np.sum(np.concatenate([weights["specific_force"], weights["angular_velocity"]]) * perceived ** 2, 1)
                 + np.sum(np.array(weights["position"]) * (s[:, :6] / box) ** 2, 1)
                 + np.sum(np.array(weights["velocity"]) * (s[:, 6:12] / box) ** 2, 1)
                 + np.sum(np.array(weights["acceleration"]) * (u.reshape(qp.n, 6) / box) ** 2, 1))
        return np.sum(qp.h * terms)

    for _ in range(3):
        u = rng.normal(size=6 * qp.n)
        want = 0.5 * (cost(u) - cost(np.zeros_like(u)))
        assert abs(0.5 * u @ H @ u + q @ u - want) <= 1e-14 * cost(u)  # reached 1.3e-16 of the cost


@pytest.mark.parametrize("preview", [True, False])
def test_the_plan_leaves_rest_when_the_vehicles_signals_it_sees_do(simulator, preview):
    """A vehicle at rest until a step of specific force at T = 0.4 s (log samples 20 ms apart,
    four intervals of 0.1 s): the plan stays exactly at rest while every signal it predicts
    with is the rest's (nothing to cue, a zero cost at zero input) and moves at the first
    sample where one is not. With preview the signals are the log's at the intervals'
    midpoints, ``t_k + 0.05 ... t_k + 0.35`` s, interpolated between samples: the last
    midpoint passes the last rest sample (0.38 s) first at t_k = 0.04 s. Without preview the
    present value is held: the plan moves at T itself."""
    dt = 0.02
    t = np.arange(26) * dt
    f = np.tile([0.0, 0.0, 9.81], (len(t), 1))
    f[t >= 0.4 - dt / 2, 0] = 2.0
    log = VehicleLog(t, f, np.zeros((len(t), 3)), "step")
    run = planner.plan(log, simulator, MPCParams.for_platform(simulator, duration=0.4, steps=4, preview=preview))
    first = 2 if preview else 20
    assert np.all(run.u[:first] == 0.0) and np.all(run.x[:first + 1] == simulator.home_pose)
    assert np.max(np.abs(run.u[first])) > 1e-3
