"""MPC cueing and the washout on rotary rigs (issue 40): every reference holds the motors' torque
and speed limits, the crank-angle limits and the cranks' reach, checked by the independent
oracle (tests/rotary_oracle.py: crank angles by atan2 and acos, torques by virtual power), and
the ball-joint cones, rod-crank angles and base clearance, checked by numpy geometry
(tests/test_rotary_workspace.py ``_geometry``); the compiled step's rotary rows against a
reference formulation (the oracle and the geometry, affine in the inputs, and their central
differences); the generated cueing_rows against the oracle and the geometry; the API and the
command line's bad input."""

from dataclasses import replace

import numpy as np
import pytest
import rotary_oracle as oracle
from cli_run import call
from test_cueing_limits import random_log
from test_rotary_workspace import _geometry

import stewart
from stewart.cueing import MPCParams, VehicleLog, WashoutParams, mpc, planner, read_log, washout
from stewart.cueing import rotary as crank
from stewart.model import rotary_reachability as rr

LOG = "examples/cueing/hard_braking.csv"


@pytest.fixture(scope="module")
def rig():
    return stewart.RotaryPlatform.preset("simrig100")


def geometry_slacks(p, poses):
    """Per pose, by numpy geometry on the oracle's crank angles (joints centred at home): the
    least slack of the crank-joint cone, the platform-joint cone, the rod-crank angle limits, the
    base clearance and the crank pins' tilt (rad, rad, rad, m, rad; +inf where the parameters set
    no limit)."""
    home = stewart.RotaryPlatform(p).home
    out = np.full((len(poses), 5), np.inf)
    for k, x in enumerate(poses):
        _, fold, cj, pj, heights, tilt = _geometry(p, x, home)
        fold, cj, pj = (np.arccos(np.clip(c, -1, 1)) for c in (fold, cj, pj))
        if p.crank_joint_max_angle is not None:
            out[k, 0] = np.min(p.crank_joint_max_angle - cj)
        if p.platform_joint_max_angle is not None:
            out[k, 1] = np.min(p.platform_joint_max_angle - pj)
        if p.rod_crank_angle_limits is not None:
            out[k, 2] = np.min(np.minimum(fold - p.rod_crank_angle_limits[0], p.rod_crank_angle_limits[1] - fold))
        out[k, 3] = np.min(heights) - np.max(p.base_points[:, 2]) - (p.base_clearance or 0.0)
        if p.crank_pin_max_tilt is not None:
            out[k, 4] = np.min(p.crank_pin_max_tilt - np.abs(np.arcsin(tilt)))
    return out


def oracle_reach(p, x):
    """sin^2(delta_i) = 1 - (C / rho)^2 of each crank (codegen/rotary.py's loop equation, here
    from the parameters alone)."""
    R = oracle.rotation(x[3:])
    out = np.empty(6)
    for i in range(6):
        e = x[:3] + R @ p.platform_points[i] - p.base_points[i]
        h = p.crank_zero[i]
        k = np.cross(p.motor_axes[i], h)
        A, B = 2 * p.crank_length * e @ h, 2 * p.crank_length * e @ k
        C = e @ e + p.crank_length ** 2 - p.rod_length ** 2
        out[i] = 1.0 - C ** 2 / (A ** 2 + B ** 2)
    return out


def every_limit(rig):
    """``rig`` with every joint limit set (wide), so that every row of the compiled step is bounded."""
    return stewart.RotaryPlatform(rig.params.replace(rod_crank_angle_limits=(0.3, 2.8), base_clearance=0.3,
                                                     crank_pin_max_tilt=np.radians(40.0)))


def geometry_joints(p, x):
    """The joints of ``RotaryPlatform.cueing_rows`` at ``x`` by numpy geometry (joints centred at
    home): the rod-crank, crank-joint and platform-joint cosines, the platform joints' heights
    and the sines of the rods' tilts out of the cranks' planes ``(30,)``."""
    return np.concatenate(_geometry(p, x, stewart.RotaryPlatform(p).home)[1:])


def assert_holds_every_limit(result, rig, every=1):
    """The reference's poses, rates and accelerations (every ``every``-th sample) within the
    motors' torque and speed limits, the crank-angle limits and the reach, by the oracle, and
    within the cones, rod-crank angles and base clearance, by numpy geometry."""
    p = rig.params
    assert result.inside and not result.beyond_limits, result.problems
    lo, hi = p.crank_angle_limits
    for k in range(0, len(result.poses), every):
        x, xd, xdd = result.poses[k], result.velocities[k], result.accelerations[k]
        alpha = oracle.crank_angles(p, x)
        assert alpha is not None, k
        assert np.all((alpha >= lo) & (alpha <= hi)), (k, alpha)
        assert np.all(oracle_reach(p, x) >= crank.REACH_MIN), k
        assert np.all(np.abs(oracle.crank_rates(p, x, xd)) <= p.motor_speed_limit), k
        assert np.all(np.abs(oracle.torques(p, x, xd, xdd)) <= p.motor_torque_limit), k
    slacks = geometry_slacks(p, result.poses[::every])
    assert np.all(slacks[:, [0, 1, 2, 4]] >= 0.0) and np.all(slacks[:, 3] > 0.0), np.min(slacks, axis=0)


def test_mpc_on_a_braking_log_holds_every_limit_by_the_oracle(rig):
    result = mpc(LOG, rig)
    assert result.solver["qp_failures"] == 0 and result.solver["qp_levels"]["brake"] == 0
    assert set(result.peaks) == {"crank_speed", "torque"}
    assert result.limits == {"crank_speed": pytest.approx(2 * np.pi), "torque": 107.55}
    # the plan works the rig: the braking cue costs torque well above the static
    static = np.max(np.abs(oracle.torques(rig.params, rig.home, np.zeros(6), np.zeros(6))))
    assert result.peaks["torque"] > 2 * static
    assert_holds_every_limit(result, rig, every=3)


def test_mpc_holds_a_tight_torque_limit(rig):
    """A torque limit the braking cue would pass binds: the plan keeps it, sample by sample."""
    tight = rig.params.replace(motor_torque_limit=30.0)
    free = mpc(LOG, rig).peaks["torque"]
    assert free > 30.0
    result = mpc(LOG, tight)
    assert result.peaks["torque"] <= 30.0
    assert_holds_every_limit(result, stewart.RotaryPlatform(tight), every=2)


@pytest.mark.parametrize("seed", [0, 1])
def test_random_logs_on_simrig100(rig, seed):
    """(The random-log sweep of tests/test_cueing_limits.py runs these on simrig100 too.)"""
    result = mpc(random_log(seed), rig)
    assert_holds_every_limit(result, rig, every=5)


@pytest.mark.parametrize("path", sorted(__import__("glob").glob("examples/cueing/*.csv")))
def test_washout_holds_every_limit_on_the_shipped_logs(rig, path):
    """Every limit of the rotary workspace, the cones included, by numpy geometry: the limiter
    scales the washout back within them (on the racing lap the crank-joint cones bind)."""
    result = washout(path, rig)
    assert result.exit_code == 0, result.problems
    assert_holds_every_limit(result, rig, every=4)
    if "racing_lap" in path:
        assert any("crank_joint_limit" in span["limits"] for span in result.limiting.intervals())


#: The crank pins' tilt limit [deg] of the tight test: simrig100's rods lean 17.8 deg out of
#: the cranks' planes at home, the braking plan tilts them to 27.8 deg.
PIN_TILT = 24.0
#: Joint limits near the braking log's motion on simrig100: (the limit's parameters, the
#: column of :func:`geometry_slacks` it binds).
TIGHT_JOINTS = {"cones": (dict(crank_joint_max_angle=np.radians(21.0), platform_joint_max_angle=np.radians(9.0)),
                          (0, 1)),
                "rod_crank": (dict(rod_crank_angle_limits=(np.radians(80.0), np.radians(118.0))), (2,)),
                "clearance": (dict(base_clearance=0.438), (3,)),
                "pin": (dict(crank_pin_max_tilt=np.radians(PIN_TILT)), (4,))}


@pytest.mark.parametrize("kind", TIGHT_JOINTS)
def test_mpc_holds_tight_joint_limits(rig, kind):
    """Each kind of joint limit, tightened until the braking cue on simrig100 (as it is) would
    pass it, binds: the plan keeps every sample within it by numpy geometry, and comes within a
    hundredth of it (a row of the wrong sign or gradient would let the plan through, or hold it
    far from the limit)."""
    values, columns = TIGHT_JOINTS[kind]
    free = geometry_slacks(rig.params.replace(**values), mpc(LOG, rig).poses)
    assert np.min(free[:, columns]) < 0.0  # the cue as planned without the limit passes it
    tight = stewart.RotaryPlatform(rig.params.replace(**values))
    result = mpc(LOG, tight)
    assert result.exit_code == 0 and result.solver["qp_levels"]["brake"] == 0, (result.problems, result.solver)
    assert_holds_every_limit(result, tight)
    slack = np.min(geometry_slacks(tight.params, result.poses)[:, columns])
    assert 0.0 <= slack < 0.01 * (0.1 if kind == "clearance" else 1.0), slack


def test_washout_holds_the_cranks(rig):
    """The washout's limiter brings a hard log back within the crank angles and reach."""
    log = read_log(LOG)
    hard = VehicleLog(log.t, log.f * np.array([3.0, 3.0, 1.0]), log.w, "hard braking x3")
    unlimited = washout(hard, rig, replace(WashoutParams.for_platform(rig), limiter_enabled=False))
    assert not unlimited.inside
    result = washout(hard, rig)
    assert result.limiting.report()["limited"]
    assert result.inside
    p = rig.params
    for x in result.poses[::4]:
        alpha = oracle.crank_angles(p, x)
        assert alpha is not None and np.all(np.abs(alpha) <= p.crank_angle_limits[1])
        assert np.all(oracle_reach(p, x) >= crank.REACH_MIN)


def test_cueing_rows_against_the_oracle(rig):
    p = rig.params
    rng = np.random.default_rng(3)
    x = rig.home + np.concatenate([rng.uniform(-0.03, 0.03, 3), rng.uniform(-0.1, 0.1, 3)])
    xd = rng.uniform(-0.5, 0.5, 6)
    rows = rig.cueing_rows(x, xd)
    np.testing.assert_allclose(rows.alpha, oracle.crank_angles(p, x), rtol=0, atol=1e-13)
    np.testing.assert_allclose(rows.ad, oracle.crank_rates(p, x, xd), rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(rows.reach, oracle_reach(p, x), rtol=1e-12)
    h = 1e-6
    for name, f in (("JP", lambda y: oracle.crank_angles(p, y)), ("dad_dx", lambda y: oracle.crank_rates(p, y, xd)),
                    ("dreach_dx", lambda y: oracle_reach(p, y))):
        fd = np.column_stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(6)])
        np.testing.assert_allclose(getattr(rows, name), fd, rtol=0, atol=2e-8 * np.max(np.abs(fd))), name
    # the joints, centred at home and at another reference, against numpy geometry
    np.testing.assert_allclose(rows.joints, geometry_joints(p, x), rtol=0, atol=1e-14)
    reference = rig.home + np.concatenate([rng.uniform(-0.02, 0.02, 3), rng.uniform(-0.05, 0.05, 3)])
    joints = np.concatenate(_geometry(p, x, reference)[1:])
    np.testing.assert_allclose(rig.cueing_rows(x, xd, reference).joints, joints, rtol=0, atol=1e-14)
    # their gradient against the geometry's five-point differences (2.3e-11 off at h = 3e-5)
    f, h = (lambda y: geometry_joints(p, y)), 3e-5  # noqa: E731
    fd = np.column_stack([(8 * (f(x + h * e) - f(x - h * e)) - (f(x + 2 * h * e) - f(x - 2 * h * e))) / (12 * h)
                          for e in np.eye(6)])
    np.testing.assert_allclose(rows.djoints_dx, fd, rtol=0, atol=1e-10)


def test_compiled_rotary_step_against_the_oracle(rig):
    """The step's rows from rest-held linearization (no last plan): the present sample's torque
    rows exact in u_0 (the oracle's torques at random u_0, affine); the next sample's crank
    angles, rates and reaches at u = 0 the oracle's at x0 + dt v0, their columns in u_0 its
    central differences (the legs rows are linear in u_0 up to second order in dt^2)."""
    p = rig.params
    qp = planner.CueingQP(rig, MPCParams.for_platform(rig), 0.01)
    rng = np.random.default_rng(5)
    x0 = rig.home + np.concatenate([rng.uniform(-0.02, 0.02, 3), rng.uniform(-0.05, 0.05, 3)])
    v0 = rng.uniform(-0.2, 0.2, 6)
    z0 = np.zeros(qp.vestibular.n)
    qp.step.forget()
    H, q, M, lo, hi, S, d = qp.condensed(x0, v0, z0, np.tile([0, 0, 9.81, 0, 0, 0], (qp.n, 1)))
    act, legs = qp.rows["actuators"], qp.rows["legs"]
    for _ in range(3):
        u = np.zeros(6 * qp.n)
        u[:6] = rng.uniform(-3, 3, 6)
        tau = oracle.torques(p, x0, v0, u[:6])
        # lo <= M u <= hi is -limit - value <= M u <= limit - value: value = tau - M u
        value = qp.torque - hi[act]
        np.testing.assert_allclose(M[act] @ u + value, tau, rtol=1e-11, atol=1e-11 * np.max(np.abs(tau)))
    x1, v1 = x0 + 0.01 * v0, v0
    exact = np.concatenate([oracle.crank_angles(p, x1), oracle.crank_rates(p, x1, v1), oracle_reach(p, x1),
                            geometry_joints(p, x1)])
    np.testing.assert_allclose(qp.step.legs_constant, exact, rtol=1e-12, atol=1e-13)
    h = 1e-3
    def legs_at(u0):
        y, w = x1 + 0.5e-4 * u0, v1 + 0.01 * u0
        return np.concatenate([oracle.crank_angles(p, y), oracle.crank_rates(p, y, w), oracle_reach(p, y),
                               geometry_joints(p, y)])
    fd = np.column_stack([(legs_at(h * e) - legs_at(-h * e)) / (2 * h) for e in np.eye(6)])
    np.testing.assert_allclose(M[legs][:, :6], fd, rtol=0, atol=1e-7 * np.max(np.abs(fd)))
    # the exact next values are the oracle's
    np.testing.assert_allclose(qp.next_values(x0, v0, np.zeros(6)), exact, rtol=1e-12, atol=1e-13)


def test_compiled_rotary_step_over_the_horizon_against_a_reference(rig):
    """The horizon's rows (crank angles, rates, reaches at the intervals' ends, torques at their
    starts) of the held-state linearization, at random inputs, against a reference written
    here: the oracle's values at the linearization point plus its central-difference gradients
    times the predicted states' offsets from it (the states from the step's own condensed
    double integrator, checked against the integrator written out)."""
    rig = every_limit(rig)
    p = rig.params
    qp = planner.CueingQP(rig, MPCParams.for_platform(rig), 0.01)
    rng = np.random.default_rng(11)
    x0 = rig.home + np.concatenate([rng.uniform(-0.02, 0.02, 3), rng.uniform(-0.05, 0.05, 3)])
    v0 = rng.uniform(-0.1, 0.1, 6)
    qp.step.forget()
    _, _, M, lo, hi, _, _ = qp.condensed(x0, v0, np.zeros(qp.vestibular.n), np.tile([0, 0, 9.81, 0, 0, 0], (qp.n, 1)))
    n, h = qp.n, qp.h[0]
    u = rng.uniform(-0.5, 0.5, 6 * n)
    x, v = qp.step.states(u)
    # the double integrator written out
    xe, ve = [x0], [v0]
    for k in range(n):
        xe.append(xe[-1] + h * ve[-1] + 0.5 * h * h * u[6 * k:6 * k + 6])
        ve.append(ve[-1] + h * u[6 * k:6 * k + 6])
    np.testing.assert_allclose(x, xe, rtol=0, atol=1e-14)
    np.testing.assert_allclose(v, ve, rtol=0, atol=1e-14)
    xbar, vbar = x0 + h * v0, v0  # every interval's end, from the state held
    d = 1e-6
    def grad(f):
        return np.column_stack([(f(xbar + d * e) - f(xbar - d * e)) / (2 * d) for e in np.eye(6)])
    J, DA, DS, DJ = (grad(lambda y: oracle.crank_angles(p, y)), grad(lambda y: oracle.crank_rates(p, y, vbar)),
                     grad(lambda y: oracle_reach(p, y)), grad(lambda y: geometry_joints(p, y)))
    alpha, rate, reach = oracle.crank_angles(p, xbar), oracle.crank_rates(p, xbar, vbar), oracle_reach(p, xbar)
    joints = geometry_joints(p, xbar)
    # the cones rows' lower bounds per point: the reaches' margin, the joints' (-inf where unlimited)
    cone_low = qp.cone_cosines[:36]
    for k in range(1, n + 1):
        dx = x[k] - xbar
        for group, expected, low, size in (("stroke", alpha + J @ dx, qp.stroke[0], 6),
                                           ("speed", J @ v[k] + DA @ dx, -qp.speed_limit, 6),
                                           ("cones", np.concatenate([reach + DS @ dx, joints + DJ @ dx]), cone_low, 36)):
            rows = np.arange(qp.rows[group].start + size * (k - 1), qp.rows[group].start + size * k)
            finite = np.isfinite(lo[rows])
            rows, expected = rows[finite], expected[finite]
            low = np.broadcast_to(low, finite.shape)[finite]
            got = M[rows] @ u + (low - lo[rows])
            np.testing.assert_allclose(got, expected, rtol=0, atol=1e-7 * max(1.0, np.max(np.abs(expected)))), (group, k)
    # the torques at the intervals' starts: linearized at (x0, v0, 0)
    def torque_grad(which):
        def at(delta):
            args = [x0, v0, np.zeros(6)]
            args[which] = args[which] + delta
            return oracle.torques(p, *args)
        return np.column_stack([(at(d * e) - at(-d * e)) / (2 * d) for e in np.eye(6)])
    tau0 = oracle.torques(p, x0, v0, np.zeros(6))
    TX, TV, TU = torque_grad(0), torque_grad(1), torque_grad(2)
    for k in range(n):
        rows = np.arange(qp.rows["force"].start + 6 * k, qp.rows["force"].start + 6 * k + 6)
        expected = tau0 + TX @ (x[k] - x0) + TV @ (v[k] - v0) + TU @ u[6 * k:6 * k + 6]
        got = M[rows] @ u + (-qp.force_limit - lo[rows])
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-7 * np.max(np.abs(expected))), k


def test_rotary_settings_for_each_preset():
    for name in ("simrig100", "desktop_servo"):
        r = stewart.RotaryPlatform.preset(name)
        s = MPCParams.for_platform(r)
        assert s.force == float(np.min(r.params.motor_torque_limit))
        assert s.leg_velocity == float(np.min(r.params.motor_speed_limit))
        excursion = crank.axis_excursions(r)
        np.testing.assert_allclose(s.box, 0.9 * excursion)
        for axis in range(6):  # the excursion's end is the first pose the rig refuses
            pose = r.home.copy()
            pose[axis] += excursion[axis]
            beyond = r.home.copy()
            beyond[axis] += excursion[axis] + 2e-5
            beyond_neg = r.home.copy()
            beyond_neg[axis] -= excursion[axis] + 2e-5
            assert crank.check_poses(r, pose).ok[0]
            assert not (crank.check_poses(r, beyond).ok[0] and crank.check_poses(r, beyond_neg).ok[0])


def test_api_bad_input(rig):
    with pytest.raises(TypeError, match="simulate"):
        mpc(LOG, rig, simulate="yes")
    with pytest.raises(TypeError, match="platform"):
        mpc(LOG, "simrig100")
    with pytest.raises(TypeError, match="params"):
        washout(LOG, rig, MPCParams())
    with pytest.raises(TypeError, match="progress"):
        mpc(LOG, rig.params, progress="yes")


def test_cli_mpc_on_simrig100_holds_the_cones(tmp_path):
    """On the command line the MPC's reference on the sim-racing rig, its 30 deg cones as they
    are, exits 0 and its report says so, within the motors' limits."""
    import json

    run = call("cueing", LOG, "--preset", "simrig100", "--method", "mpc", "--output", tmp_path / "ref.csv",
               "--report", tmp_path / "report.json")
    assert run.returncode == 0, run.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["ok"] and report["peak_torque"] <= report["limits"]["torque"]


def test_cli_serves_a_rotary_file(tmp_path):
    path = tmp_path / "rig.toml"
    stewart.RotaryParams.preset("desktop_servo").save(path)
    run = call("cueing", LOG, "--params", path, "--method", "mpc", "--output", tmp_path / "ref.csv",
               "--report", tmp_path / "report.json")
    assert run.returncode == 0, run.stderr
    import json
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["ok"] and report["peak_torque"] <= 1.08 and report["peak_crank_speed"] <= report["limits"]["crank_speed"]


@pytest.mark.parametrize("args, flag", [(("--cueing", "missing.toml"), "--cueing")])
def test_cli_bad_input_on_a_rotary_rig(tmp_path, args, flag):
    run = call("cueing", LOG, "--preset", "simrig100", "--output", tmp_path / "ref.csv", *args)
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and flag in lines[0], run.stderr


def test_cli_simulates_a_rotary_reference(tmp_path):
    """--simulate on a rotary rig: the washout's reference through the closed loop (computed
    torque on the exact model), tracked to 1e-8 m and rad, its crank speeds within the limit."""
    run = call("cueing", LOG, "--preset", "simrig100", "--method", "washout", "--simulate",
               "--output", tmp_path / "ref.csv", "--report", tmp_path / "report.json")
    assert run.returncode == 0, run.stderr
    import json
    report = json.loads((tmp_path / "report.json").read_text())
    sim = report["simulation"]
    assert sim["ok"] and 0.0 < sim["peak_crank_speed"] <= report["limits"]["crank_speed"]
    result = washout(LOG, stewart.RotaryPlatform.preset("simrig100"), simulate=True)
    achieved = np.column_stack([np.interp(result.t, result.simulation.t, result.simulation.x[:, j]) for j in range(6)])
    assert np.max(np.abs(achieved - result.poses)) < 1e-8
    # the achieved motion's crank rates by the oracle, against the compiled loop's
    k = len(result.simulation.t) // 2
    np.testing.assert_allclose(oracle.crank_rates(stewart.RotaryParams.preset("simrig100"),
                                                  result.simulation.x[k], result.simulation.xd[k]),
                               result.simulation.leg_velocities[k], rtol=1e-9, atol=1e-12)
