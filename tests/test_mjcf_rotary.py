"""The MuJoCo export of rotary rigs (:func:`stewart.to_mjcf` of a
:class:`~stewart.RotaryParams`, ``stewart export-mjcf --preset simrig100``): the text and its
errors without MuJoCo; with MuJoCo (skipped without it), the compiled model against the
parameters and the independent oracle of tests/rotary_oracle.py, and MuJoCo's dynamics
against :class:`~stewart.RotaryPlatform`'s: accelerations at random states of random
asymmetric rigs (MuJoCo's rigid-body accelerations, and its own under the tight soft
constraints) and an open-loop replay of our inverse dynamics."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import rotary_oracle as oracle
import stewart
from stewart.cli import EXIT_USAGE, main
from stewart.io import mjcf
from test_rotary import random_rig

PRESET = "simrig100"
RIGS = {"simrig100": stewart.RotaryParams.preset(PRESET), "desktop_servo": stewart.RotaryParams.preset("desktop_servo"),
        "asymmetric": random_rig(7)}


def random_states(params, seed, n=4):
    """n states near the rig's home whose poses every crank reaches, their translations,
    rates and accelerations scaled by the rig's crank length (0.1 m: up to 20 mm and 0.05 rad
    off home)."""
    rng = np.random.default_rng(seed)
    home = stewart.RotaryPlatform(params).home
    scale = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0]) * (params.crank_length / 0.1 - 1.0) + 1.0
    rows = []
    while len(rows) < n:
        x = home + scale * np.concatenate([rng.uniform(-0.02, 0.02, 3), rng.uniform(-0.05, 0.05, 3)])
        if oracle.crank_angles(params, x) is not None:
            rows.append((x, scale * rng.normal(scale=0.3, size=6), scale * rng.normal(scale=2.0, size=6)))
    return [np.array(a) for a in zip(*rows)]


def test_text_and_file(tmp_path):
    rig = stewart.RotaryPlatform.preset(PRESET)
    path = tmp_path / "rig.xml"
    text = stewart.to_mjcf(rig, path)
    assert path.read_text() == text == stewart.to_mjcf(rig.params)
    assert text.count('type="hinge"') == 6 and text.count('type="ball"') == 6 and text.count("<freejoint") == 1
    assert text.count("<connect ") == 6 and text.count("<motor ") == 6 and text.count('<key name="home"') == 1
    assert text.count('ctrlrange="-107.55 107.55"') == 6  # 2.39 N m x 50 x 0.9 at the crank
    assert 'ctrlrange' not in stewart.to_mjcf(rig.params.replace(motor_torque_limit=None))


@pytest.mark.parametrize("kwargs, field", [({"solver": "fast"}, "solver"), ({"pose": [0, 0, 1]}, "pose"),
                                           ({"pose": [0, 0, np.nan, 0, 0, 0]}, "pose"),
                                           ({"pose": [0, 0, 2.0, 0, 0, 0]}, "pose")])
def test_errors_name_the_argument(kwargs, field):
    with pytest.raises(ValueError, match=f"^{field}: "):
        stewart.to_mjcf(stewart.RotaryParams.preset(PRESET), **kwargs)


def test_unreachable_pose_names_the_cranks():
    with pytest.raises(ValueError, match=r"^pose: .*crank"):
        stewart.to_mjcf(stewart.RotaryParams.preset(PRESET), pose=[0.3, 0, 0.45, 0, 0, 0])


def test_joint_coordinates_refuse_bad_input():
    rig = stewart.RotaryPlatform.preset(PRESET)
    with pytest.raises(ValueError, match="^rig: expected a stewart.RotaryParams"):
        mjcf.joint_positions(stewart.PlatformParams.preset("narayan2017"), rig.home)
    with pytest.raises(ValueError, match="^x: "):
        mjcf.joint_positions(rig, rig.home[:5])
    with pytest.raises(ValueError, match="^x: .*crank"):
        mjcf.joint_positions(rig, rig.home + [0, 0, 1.0, 0, 0, 0])
    with pytest.raises(ValueError, match="^pose: "):
        mjcf.joint_positions(rig, rig.home, pose=[np.inf] * 6)
    with pytest.raises(ValueError, match="^xd: "):
        mjcf.joint_velocities(rig, rig.home, [0.0] * 7)


def test_cli_export(tmp_path, capsys):
    params = stewart.RotaryParams.preset(PRESET)
    out = tmp_path / "rig.xml"
    main(["export-mjcf", "--preset", PRESET, "--output", str(out), "--solver", "tight"])
    assert out.read_text() == stewart.to_mjcf(params, solver="tight")
    assert f"wrote {out}: MuJoCo model of rotary rig {PRESET} (preset)" in capsys.readouterr().out
    saved = tmp_path / "rotary.toml"
    RIGS["asymmetric"].save(saved)
    pose = stewart.RotaryPlatform(RIGS["asymmetric"]).home + [0.01, 0, 0, 0, 0.02, 0]
    main(["export-mjcf", "--params", str(saved), "--pose", *map(str, pose)])
    assert capsys.readouterr().out == stewart.to_mjcf(RIGS["asymmetric"], pose=pose)
    broken = tmp_path / "broken.toml"
    broken.write_text(saved.read_text().replace("crank_length = ", "crank_length = -"))
    assert "crank_length = -" in broken.read_text()
    for argv, flag in [(["--preset", PRESET, "--output", str(tmp_path / "missing" / "r.xml")], "--output"),
                       (["--preset", PRESET, "--pose", "0.3", "0", "0.45", "0", "0", "0"], "--pose: "),
                       (["--params", str(saved), "--pose", "0", "0", "5", "0", "0", "0"], "--pose: "),
                       (["--params", str(broken)], "--params")]:
        with pytest.raises(SystemExit) as exc:
            main(["export-mjcf", *argv])
        assert exc.value.code == EXIT_USAGE
        err = capsys.readouterr().err
        assert f"error: {flag}" in err and len(err.strip().splitlines()) == 1, err


# ------------------------------------------------------------------------ with MuJoCo

def _compiled(params, pose=None, solver="tight"):
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(stewart.to_mjcf(params, pose=pose, solver=solver))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return mujoco, model, data


def _tips(params, alpha):
    """The crank tips c_i of the crank angles ``alpha``, by hand."""
    k = np.cross(params.motor_axes, params.crank_zero)
    return params.base_points + params.crank_length * (np.cos(alpha)[:, None] * params.crank_zero
                                                       + np.sin(alpha)[:, None] * k)


@pytest.mark.parametrize("name", list(RIGS))
def test_model_is_the_rig(name):
    """At a pose off home: the hinges' axes, angles and the crank tips from the oracle's crank
    angles; masses, centres of mass, each crank's moment about its motor axis (its
    ``crank_inertia``), each rod's transverse moment about its centre of mass and the
    platform's tensor, against the parameters; the loops close at the assembly pose."""
    params = RIGS[name]
    home = stewart.RotaryPlatform(params).home
    x = home + np.array([0.004, -0.003, 0.002, 0.02, -0.015, 0.01]) * (params.crank_length / 0.1)
    mujoco, model, data = _compiled(params, x)
    alpha = oracle.crank_angles(params, x)
    rot = oracle.rotation(x[3:])
    joints = x[:3] + params.platform_points @ rot.T
    tips = _tips(params, alpha)
    body = {n: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n)
            for n in ["platform"] + [f"{part}{i}" for part in ("crank", "rod") for i in range(6)]}

    def tensor_in_base(b):
        frame = data.ximat[b].reshape(3, 3)
        return frame @ np.diag(model.body_inertia[b]) @ frame.T

    scale = np.max(np.abs(params.base_points))
    assert data.xipos[body["platform"]] == pytest.approx(x[:3] + rot @ params.platform_com_in_model, abs=1e-15)
    assert model.body_mass[body["platform"]] == params.platform_mass
    np.testing.assert_allclose(tensor_in_base(body["platform"]), rot @ params.platform_inertia_tensor @ rot.T,
                               rtol=0, atol=1e-14 * np.max(params.platform_inertia_tensor))
    assert data.qpos[[5 * i for i in range(6)]] == pytest.approx(alpha, abs=1e-14)
    assert data.sensordata[7:13] == pytest.approx(alpha, abs=1e-14)
    for i in range(6):
        a, u = params.motor_axes[i], (tips[i] - params.base_points[i]) / params.crank_length
        hinge = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"motor{i}")
        assert data.xaxis[hinge] == pytest.approx(a, abs=1e-15)
        assert data.xanchor[hinge] == pytest.approx(params.base_points[i], abs=1e-15 * scale)
        crank, rod = body[f"crank{i}"], body[f"rod{i}"]
        assert model.body_mass[crank] == params.crank_mass and model.body_mass[rod] == params.rod_mass
        assert data.xipos[crank] == pytest.approx(params.base_points[i] + params.crank_com_distance * u, abs=1e-15)
        arm = data.xipos[crank] - params.base_points[i]  # parallel axes to the motor axis
        about_axis = a @ tensor_in_base(crank) @ a + params.crank_mass * (arm @ arm - (arm @ a) ** 2)
        assert about_axis == pytest.approx(params.crank_inertia, rel=1e-14)
        along = (joints[i] - tips[i]) / params.rod_length
        assert data.xpos[rod] == pytest.approx(tips[i], abs=1e-15)
        assert data.xipos[rod] == pytest.approx(tips[i] + params.rod_com_distance * along, abs=1e-15)
        transverse = np.eye(3) - np.outer(along, along)
        np.testing.assert_allclose(tensor_in_base(rod), params.rod_inertia * transverse, rtol=0,
                                   atol=2 * mjcf.MOMENT_FLOOR + 1e-15 * params.rod_inertia)
    assert np.max(np.abs(data.efc_pos)) < 1e-15  # the loops close at the assembly pose
    assert data.nefc == 18  # the three rows of each loop, no crank at its limit
    limits = params.crank_angle_limits
    assert np.all(model.jnt_range[model.jnt_type == mujoco.mjtJoint.mjJNT_HINGE] == limits)
    data.qpos[5] = limits[1] + 0.01  # the limits bound the crank angle itself (the hinge's ref)
    mujoco.mj_forward(model, data)
    assert data.nefc == 19 and data.efc_pos[-1] == pytest.approx(-0.01, abs=1e-15)


@pytest.mark.parametrize("name", list(RIGS))
def test_home_keyframe_closes_the_loops_and_holds_the_rig(name):
    """The keyframe ``home`` of a model assembled elsewhere: the platform at home, the
    loops closed to rounding, and its ``ctrl`` (our static torques) holds the rig there:
    MuJoCo's accelerations at rest vanish within the constraints' regularisation."""
    params = RIGS[name]
    rig = stewart.RotaryPlatform(params)
    x = rig.home + np.array([0.004, -0.003, 0.002, 0.02, -0.015, 0.01]) * (params.crank_length / 0.1)
    mujoco, model, data = _compiled(params, x)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    assert np.max(np.abs(data.efc_pos)) < 1e-15 * params.rod_length / 0.1
    assert data.qpos[-7:-4] == pytest.approx(rig.home[:3], abs=0) and data.qpos[-4:] == pytest.approx([1, 0, 0, 0])
    assert data.ctrl == pytest.approx(rig.inverse_dynamics(rig.home, np.zeros(6), np.zeros(6)), rel=1e-15)
    xdd = _accelerations(mujoco, model, data, rig.home, np.zeros(6))
    assert np.max(np.abs(xdd["rigid"])) < 1e-12 * params.gravity


def _accelerations(mujoco, model, data, x, xd) -> dict:
    """The platform's ``xdd`` in MuJoCo at the state in ``data``: ``"soft"`` MuJoCo's own
    ``qacc``; ``"rigid"`` MuJoCo's model with the six loop closures held exactly,
    ``[M J^T; J 0] [qacc; f] = [tau - bias; -J' qvel]`` (``J' qvel`` the two sites' relative
    acceleration at ``qacc = 0``), as tests/test_mjcf.py's linear machines."""
    soft = mjcf.pose_accelerations(x, xd, data.qacc)
    nv = model.nv
    mass = np.zeros((nv, nv))
    mujoco.mj_fullM(model, data, mass)
    forces = data.qfrc_actuator + data.qfrc_passive - data.qfrc_bias
    data.qacc[:] = 0.0
    mujoco.mj_rnePostConstraint(model, data)
    jac, bias = np.zeros((18, nv)), np.zeros(18)
    for i in range(6):
        for site, sign in ((f"rod_end{i}", 1.0), (f"joint{i}", -1.0)):
            sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
            jacp, acc = np.zeros((3, nv)), np.zeros(6)
            mujoco.mj_jacSite(model, data, jacp, None, sid)
            mujoco.mj_objectAcceleration(model, data, mujoco.mjtObj.mjOBJ_SITE, sid, acc, 0)
            jac[3 * i:3 * i + 3] += sign * jacp
            bias[3 * i:3 * i + 3] += sign * acc[3:]
    kkt = np.block([[mass, jac.T], [jac, np.zeros((18, 18))]])
    rigid = np.linalg.solve(kkt, np.concatenate([forces, -bias]))[:nv]
    return {"soft": soft, "rigid": mjcf.pose_accelerations(x, xd, rigid), "qacc": rigid}


def _at_state(mujoco, model, data, rig, x, xd, torque):
    data.qpos[:] = mjcf.joint_positions(rig, x)
    data.qvel[:] = mjcf.joint_velocities(rig, x, xd)
    data.ctrl[:] = torque
    mujoco.mj_forward(model, data)


@pytest.mark.parametrize("name", list(RIGS))
def test_joint_coordinates_keep_the_loops_closed(name, figures):
    """At random states, MuJoCo's loop closures hold at the ``qpos`` and ``qvel`` of
    :func:`stewart.io.mjcf.joint_positions` and :func:`~stewart.io.mjcf.joint_velocities`,
    its hinges read the oracle's crank angles and rates, its platform moves at the state's
    twist, and the rods do not spin about their axes."""
    params = RIGS[name]
    rig = stewart.RotaryPlatform(params)
    mujoco, model, data = _compiled(params)
    xs, xds, _ = random_states(params, 3, n=4)
    gap = slip = angle = rate = twist_error = spin = 0.0
    for x, xd in zip(xs, xds):
        _at_state(mujoco, model, data, rig, x, xd, np.zeros(6))
        speed = np.linalg.norm(xd)
        gap = max(gap, np.max(np.abs(data.efc_pos)) / params.rod_length)
        omega = oracle.angular_velocity(x[3:], xd[3:])
        ends = xd[:3] + np.cross(omega, params.platform_points @ oracle.rotation(x[3:]).T)
        slip = max(slip, np.max(np.abs(data.efc_vel)) / np.max(np.linalg.norm(ends, axis=1)))
        angle = max(angle, np.max(np.abs(data.sensordata[7:13] - oracle.crank_angles(params, x))))
        rates = oracle.crank_rates(params, x, xd)
        rate = max(rate, np.max(np.abs(data.sensordata[13:19] - rates)) / np.max(np.abs(rates)))
        velocity = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_XBODY, model.nbody - 1, velocity, 0)
        twist_error = max(twist_error, np.max(np.abs(velocity - np.concatenate([omega, xd[:3]]))) / speed)
        for i in range(6):
            rod = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"rod{i}")
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_XBODY, rod, velocity, 0)
            spin = max(spin, abs(velocity[:3] @ data.xmat[rod].reshape(3, 3)[:, 0]) / speed)
    figures(f"MuJoCo rotary export {name}: loop gap at joint_positions [/d]", gap, 2e-14)  # reached 9.7e-16
    figures(f"MuJoCo rotary export {name}: loop gap rate at joint_velocities [m/s / rod end speed]", slip, 1e-13)  # reached 4.0e-15
    figures(f"MuJoCo rotary export {name}: crank angles vs oracle [rad]", angle, 2e-14)  # reached 7.5e-16
    figures(f"MuJoCo rotary export {name}: crank rates vs oracle [/max crank rate]", rate, 1e-14)  # reached 3.9e-16
    figures(f"MuJoCo rotary export {name}: platform twist [/|xd|]", twist_error, 1e-14)  # reached 1.8e-16
    figures(f"MuJoCo rotary export {name}: rod spin [rad/s / |xd|]", spin, 1e-13)  # reached 3.5e-15


@pytest.mark.parametrize("name", list(RIGS))
def test_accelerations_match(name, figures):
    """At random states under random torques (within the motors' limits), MuJoCo's
    accelerations against :meth:`~stewart.RotaryPlatform.forward_dynamics`, and under our
    :meth:`~stewart.RotaryPlatform.inverse_dynamics` torques against the states' own
    accelerations: MuJoCo's rigid-body accelerations agree to round-off (the same mechanics);
    its own ``qacc`` under the tight soft constraints differ by their regularisation."""
    params = RIGS[name]
    rig = stewart.RotaryPlatform(params)
    # Without MuJoCo's clamping of ctrl to the torque limits, which our dynamics do not have.
    mujoco, model, data = _compiled(params.replace(motor_torque_limit=None))
    xs, xds, xdds = random_states(params, 5, n=4)
    limit = params.motor_torque_limit
    torques = np.random.default_rng(2).uniform(-0.5, 0.5, (len(xs), 6)) * limit
    worst = {"fd": 0.0, "id": 0.0, "soft": 0.0}
    for x, xd, xdd, torque in zip(xs, xds, xdds, torques):
        ours = rig.forward_dynamics(x, xd, torque)
        _at_state(mujoco, model, data, rig, x, xd, torque)
        result = _accelerations(mujoco, model, data, x, xd)
        worst["fd"] = max(worst["fd"], np.max(np.abs(result["rigid"] - ours)) / np.max(np.abs(ours)))
        worst["soft"] = max(worst["soft"], np.max(np.abs(result["soft"] - ours)) / np.max(np.abs(ours)))
        _at_state(mujoco, model, data, rig, x, xd, rig.inverse_dynamics(x, xd, xdd))
        result = _accelerations(mujoco, model, data, x, xd)
        worst["id"] = max(worst["id"], np.max(np.abs(result["rigid"] - xdd)) / np.max(np.abs(xdd)))
    figures(f"MuJoCo rotary export {name}: rigid-body xdd vs forward_dynamics", worst["fd"], 5e-13)  # reached 1.0e-14
    figures(f"MuJoCo rotary export {name}: rigid-body xdd under inverse_dynamics vs xdd", worst["id"], 1e-11)  # reached 1.7e-13
    figures(f"MuJoCo rotary export {name}: soft (tight) xdd vs forward_dynamics", worst["soft"], 0.2)  # reached 1.7e-2


def _move(rig, t):
    """A 1 s move of the rig about its home: each coordinate a sine of its own frequency (0.7
    to 1.5 Hz), up to 20 mm and 0.06 rad (translations scaled by the crank length / 0.1 m);
    the pose, its rates and accelerations at the times ``t``."""
    params = rig.params
    scale = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0]) * (params.crank_length / 0.1 - 1.0) + 1.0
    amp = scale * np.array([0.02, -0.015, 0.015, 0.05, -0.04, 0.06])
    w, phase = 2 * np.pi * np.array([1.0, 1.3, 0.7, 0.9, 1.1, 1.5]), np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5])
    t = np.asarray(t, dtype=float)[..., None]
    return (rig.home + amp * (np.sin(w * t + phase) - np.sin(phase)), amp * w * np.cos(w * t + phase),
            -amp * w * w * np.sin(w * t + phase))


#: Bounds of the replay: against our replay, position [m] and angle [rad], against the move
#: [m], the loops' gap [m]; reached 2.9e-8, 6.6e-8, 3.0e-7, 1.1e-9 (simrig100) and 3.9e-9,
#: 1.9e-8, 5.1e-9, 2.6e-10 (desktop_servo).
REPLAY_BOUNDS = {"simrig100": (1e-6, 2e-6, 1e-5, 3e-8), "desktop_servo": (1e-7, 5e-7, 1e-7, 1e-8)}


@pytest.mark.parametrize("name", list(REPLAY_BOUNDS))
def test_replay_of_our_torques(name, figures):
    """MuJoCo (tight settings: 0.1 ms RK4) driven open loop for 1 s by our inverse dynamics of
    a move (the torques at the middle of each step, held over it), against our own RK4 replay
    of the same held torques by :meth:`~stewart.RotaryPlatform.forward_dynamics`, and against
    the move. Both replays leave the move alike (the open-loop plant amplifies the torques'
    hold over each step: ours reaches 3.3e-7 m on simrig100); MuJoCo leaves ours by the
    regularisation of its soft loop closures, whose gap stays ~1e-9 m."""
    mujoco = pytest.importorskip("mujoco")
    rig = stewart.RotaryPlatform.preset(name)
    model = mujoco.MjModel.from_xml_string(
        stewart.to_mjcf(rig.params.replace(motor_torque_limit=None), solver="tight"))
    data = mujoco.MjData(model)
    dt = model.opt.timestep
    steps = int(round(1.0 / dt))
    x0, xd0, _ = _move(rig, 0.0)
    torques = rig.inverse_dynamics(*_move(rig, (np.arange(steps) + 0.5) * dt))
    data.qpos[:] = mjcf.joint_positions(rig, x0)
    data.qvel[:] = mjcf.joint_velocities(rig, x0, xd0)
    theirs, quats, gap = np.empty((steps, 3)), np.empty((steps, 4)), 0.0
    for k in range(steps):
        data.ctrl[:] = torques[k]
        mujoco.mj_step(model, data)
        theirs[k], quats[k] = data.qpos[-7:-4], data.qpos[-4:]
        gap = max(gap, np.max(np.abs(data.efc_pos)))
    x, xd, ours = x0.copy(), xd0.copy(), np.empty((steps, 6))
    for k in range(steps):
        f = lambda x, xd: rig.forward_dynamics(x, xd, torques[k])  # noqa: E731
        k1 = xd, f(x, xd)
        k2 = xd + dt / 2 * k1[1], f(x + dt / 2 * k1[0], xd + dt / 2 * k1[1])
        k3 = xd + dt / 2 * k2[1], f(x + dt / 2 * k2[0], xd + dt / 2 * k2[1])
        k4 = xd + dt * k3[1], f(x + dt * k3[0], xd + dt * k3[1])
        x = x + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        xd = xd + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        ours[k] = x
    move = _move(rig, (np.arange(steps) + 1) * dt)[0]
    # MuJoCo's orientation against ours (R = Rz(psi) Ry(theta) Rx(phi): intrinsic ZYX)
    relative = Rotation.from_euler("ZYX", ours[:, 3:]).inv() * Rotation.from_quat(np.roll(quats, -1, axis=1))
    angle = np.max(relative.magnitude())
    label = f"MuJoCo rotary export {name} (tight), 1 s replay of our torques"
    bounds = REPLAY_BOUNDS[name]
    figures(f"{label}: vs our open-loop replay, position [m]", np.max(np.abs(theirs - ours[:, :3])), bounds[0])
    figures(f"{label}: vs our open-loop replay, angle [rad]", angle, bounds[1])
    figures(f"{label}: vs the move, position [m]", np.max(np.abs(theirs - move[:, :3])), bounds[2])
    figures(f"{label}: loop gap [m]", gap, bounds[3])


def test_a_rig_that_cannot_reach_its_home_gets_no_keyframe():
    """Motor 0 moved out to 1.6 times its radius: no crank reaches the averaged home; the model
    assembled at a pose it reaches has no keyframe, and its comment names the crank."""
    params = stewart.RotaryParams.preset(PRESET)
    base = params.base_points.copy()
    base[0] *= 1.6
    params = params.replace(base_points=base)
    home = stewart.RotaryPlatform(params).home
    with pytest.raises(ValueError, match=r"^pose: .*crank 0 cannot reach"):
        stewart.to_mjcf(params)
    text = stewart.to_mjcf(params, pose=home + [0.02, 0, -0.09, 0, 0, 0])
    assert "<keyframe>" not in text and "no keyframe: home: " in text and "crank 0 cannot reach" in text
