"""The MuJoCo export (:func:`stewart.to_mjcf`, ``stewart export-mjcf``): the text and its
errors without MuJoCo; with MuJoCo (skipped without it), the compiled model against the
parameters, and MuJoCo's dynamics against ours: accelerations at single states (the
rigid-body accelerations of MuJoCo's model and MuJoCo's own under its tight soft
constraints) and an open-loop replay over 1 s."""

from __future__ import annotations

import pathlib
import sys

import numpy as np
import pytest

import stewart
from stewart.cli import bench
from stewart.oracles.physics import relative_error
from stewart.cli import EXIT_USAGE, main
from stewart.model.kinematics import leg_unit_vectors, rotation

ROOT = pathlib.Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

PRESET = "narayan2017"


def _general_params() -> stewart.PlatformParams:
    from benchmarks.peers.mujoco_model import general_variant

    return general_variant(stewart.PlatformParams.preset(PRESET))


def test_text_and_file(tmp_path):
    plat = stewart.Platform.preset(PRESET)
    path = tmp_path / "platform.xml"
    text = stewart.to_mjcf(plat, path)
    assert path.read_text() == text == stewart.to_mjcf(plat.params)
    assert text.count("<joint ") == 18 and text.count("<connect ") == 6 and text.count("<motor ") == 6


def test_visual_geometry_is_the_clearance_geometry():
    """The platform's disc is the plate the workspace checks, the legs' capsules as thick as
    ``leg_diameter``."""
    import xml.etree.ElementTree as ET

    params = stewart.PlatformParams.preset("motion_simulator")
    root = ET.fromstring(stewart.to_mjcf(params))
    plate = root.find(".//body[@name='platform']/geom")
    assert float(plate.get("size").split()[0]) == params.plate_radius == 1.2
    assert float(root.find(".//body[@name='cylinder0']/geom").get("size")) == params.leg_diameter / 2 == 0.08


@pytest.mark.parametrize("kwargs, field", [({"solver": "fast"}, "solver"), ({"pose": [0, 0, 1]}, "pose"),
                                           ({"pose": [0, 0, np.nan, 0, 0, 0]}, "pose")])
def test_errors_name_the_argument(kwargs, field):
    with pytest.raises(ValueError, match=f"^{field}: "):
        stewart.to_mjcf(stewart.PlatformParams.preset(PRESET), **kwargs)
    with pytest.raises(ValueError, match="^platform_or_params: "):
        stewart.to_mjcf("narayan2017")


def test_gimbal_lock_is_an_error():
    """A pose that turns a leg onto its joint's first axis cannot be assembled."""
    params = stewart.PlatformParams.preset(PRESET).with_universal_joints()
    home = stewart.home_pose(params)
    axes = params.universal_joint_axes.copy()
    axes[2] = leg_unit_vectors(params, home)[2] + 0.5 * axes[2]
    axes[2] /= np.linalg.norm(axes[2])
    params = params.replace(universal_joint_axes=axes)
    tip = params.base_points[2] + np.linalg.norm(stewart.leg_vectors(params, home)[2]) * axes[2]
    pose = np.concatenate([tip - params.platform_points[2], home[3:]])  # home is level: R = I
    with pytest.raises(ValueError, match=r"^pose: leg\(s\) \[2\] .*gimbal lock"):
        stewart.to_mjcf(params, pose=pose)


def test_cli_export(tmp_path, capsys):
    out = tmp_path / "p.xml"
    main(["export-mjcf", "--preset", PRESET, "--output", str(out), "--solver", "tight"])
    assert out.read_text() == stewart.to_mjcf(stewart.PlatformParams.preset(PRESET), solver="tight")
    assert str(out) in capsys.readouterr().out
    main(["export-mjcf", "--preset", PRESET])
    assert capsys.readouterr().out == stewart.to_mjcf(stewart.PlatformParams.preset(PRESET))
    params = stewart.PlatformParams.preset(PRESET)
    collapsed = params.base_points[0] - params.platform_points[0]  # leg 0 of zero length
    for argv, flag in [(["--output", str(tmp_path / "missing" / "p.xml")], "--output"),
                       (["--pose", *map(str, collapsed), "0", "0", "0"], "--pose"),
                       (["--params", str(tmp_path / "none.toml")], "--params")]:
        with pytest.raises(SystemExit) as exc:
            main(["export-mjcf", *argv])
        assert exc.value.code == EXIT_USAGE
        err = capsys.readouterr().err
        assert f"error: {flag}" in err and len(err.strip().splitlines()) == 1


# ------------------------------------------------------------------------ with MuJoCo

def _compiled(params, pose=None):
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(stewart.to_mjcf(params, pose=pose))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return mujoco, model, data


@pytest.mark.parametrize("general", [False, True], ids=["paper", "general"])
def test_model_is_the_platform(general):
    """Masses, centres of mass and inertia tensors in {B}, the joints' axes and the leg
    lengths of the compiled model against the parameters, at a pose off home."""
    params = _general_params() if general else stewart.PlatformParams.preset(PRESET)
    jointed = params if general else params.with_universal_joints()
    x = stewart.home_pose(params) + np.array([0.01, -0.005, 0.01, 0.05, -0.03, 0.04])
    mujoco, model, data = _compiled(params, x)
    rot = rotation(x)
    legs = stewart.leg_vectors(params, x)
    lengths = np.linalg.norm(legs, axis=1)
    units = legs / lengths[:, None]
    tips = params.base_points + legs
    body = {name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) for name in
            ["platform"] + [f"{part}{i}" for part in ("cylinder", "piston") for i in range(6)]}

    def tensor_in_base(b):
        frame = data.ximat[b].reshape(3, 3)
        return frame @ np.diag(model.body_inertia[b]) @ frame.T

    com = np.zeros(3) if params.platform_com is None else params.platform_com
    assert data.xipos[body["platform"]] == pytest.approx(x[:3] + rot @ com, abs=1e-15)
    assert model.body_mass[body["platform"]] == params.platform_mass
    tensor = params.platform_inertia_tensor
    np.testing.assert_allclose(tensor_in_base(body["platform"]), rot @ tensor @ rot.T, rtol=0,
                               atol=1e-14 * np.max(tensor))
    frames = np.stack([units, np.cross(jointed.universal_joint_axes, units)], axis=1)
    frames[:, 1] /= np.linalg.norm(frames[:, 1], axis=1, keepdims=True)
    for i in range(6):
        y, z = frames[i, 1], np.cross(units[i], frames[i, 1])
        leg_frame = np.stack([units[i], y, z], axis=1)
        for part, inertia, where in (("cylinder", params.cylinder_inertia,
                                      params.base_points[i] + params.cylinder_com_distance * units[i]),
                                     ("piston", params.piston_inertia,
                                      tips[i] - params.piston_com_distance * units[i])):
            b = body[f"{part}{i}"]
            assert data.xipos[b] == pytest.approx(where, abs=1e-15)
            expected = leg_frame @ np.diag(np.maximum(inertia, stewart.io.mjcf.MOMENT_FLOOR)) @ leg_frame.T
            np.testing.assert_allclose(tensor_in_base(b), expected, rtol=0, atol=1e-14 * max(inertia))
        first, second = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"u{i}{k}") for k in "ab")
        assert data.xaxis[first] == pytest.approx(jointed.universal_joint_axes[i], abs=1e-15)
        assert data.xaxis[second] == pytest.approx(y, abs=1e-15)
    assert data.sensordata[7:13] == pytest.approx(lengths, abs=1e-15)
    assert np.max(np.abs(data.efc_pos)) < 1e-15  # the ball joints close at the assembly pose


def test_massless_legs_and_any_name_compile():
    """Massless legs (written as :data:`stewart.io.mjcf.MOMENT_FLOOR`, MuJoCo refusing zero) keep
    the paper's dynamics; the name is quoted as XML."""
    pytest.importorskip("mujoco")
    from benchmarks.peers import mujoco_model

    params = stewart.PlatformParams.preset(PRESET).replace(
        cylinder_mass=0.0, cylinder_inertia=(0, 0, 0), piston_mass=0.0, piston_inertia=(0, 0, 0), name='a "b" <c> & d')
    _, model, _ = _compiled(params)
    assert model.names.startswith(b'stewart platform a "b" <c> & d')
    worst = mujoco_model.acceleration_differences(params, mujoco_model.on_random_axes(params),
                                                  stewart.Platform(params).inverse_dynamics, states=2, seed=1)
    assert worst["rigid"] < 1e-11  # reached 9.7e-13 (3.9e-13 elsewhere)


def test_joint_velocities_keep_the_ball_joints_closed():
    """MuJoCo's constraint velocities ``J qvel`` vanish at the velocities of
    :func:`stewart.io.mjcf.joint_velocities` and its platform velocity is the state's."""
    params = _general_params()
    x, xd, _ = bench.states(params, 1, seed=4)
    mujoco, model, data = _compiled(params, x[0])
    data.qvel[:] = stewart.io.mjcf.joint_velocities(params, x[0], xd[0])
    mujoco.mj_forward(model, data)
    scale = np.linalg.norm(xd[0])
    assert np.max(np.abs(data.efc_vel)) < 5e-15 * scale  # reached 9.1e-17 scale
    twist = np.zeros(6)
    mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_XBODY, model.nbody - 1, twist, 0)
    omega = stewart.euler_rate_jacobian(x[0]) @ xd[0, 3:]
    assert twist[:3] == pytest.approx(omega, abs=2e-15 * scale)  # reached 5.1e-17 scale
    assert twist[3:] == pytest.approx(xd[0, :3], abs=2e-15 * scale)  # reached 0


@pytest.mark.parametrize("general", [False, True], ids=["paper", "general"])
def test_accelerations_match(general, figures):
    """MuJoCo's accelerations at random states under our inverse-dynamics forces against the
    states' accelerations: the paper's model (axisymmetric legs, zero axial inertia in MuJoCo,
    random joint axes) and the general model (exact legs, non-axisymmetric legs, off-centre
    payload with a full tensor), each by its kernel. The rigid-body
    accelerations of MuJoCo's model agree to round-off; MuJoCo's own, under its tight soft
    constraints, within the constraints' regularisation (measured 1e-4 to 3e-3)."""
    pytest.importorskip("mujoco")
    from benchmarks.peers import mujoco_model

    if general:
        ours = params = _general_params()
        inverse = stewart.Platform(params).inverse_dynamics
    else:  # the paper's model, and MuJoCo's legs on random joint axes
        ours = stewart.PlatformParams.preset(PRESET)
        params = mujoco_model.on_random_axes(ours, seed=5)
        inverse = stewart.Platform(ours).inverse_dynamics
    worst = mujoco_model.acceleration_differences(ours, params, inverse, states=4, seed=11)
    label = "general model" if general else "paper model"
    figures(f"MuJoCo export, rigid-body xdd vs {label}", worst["rigid"], 1e-12)  # reached 7.4e-14
    figures(f"MuJoCo export, tight soft constraints, xdd vs {label}", worst["soft"], 1e-2)  # reached 2.6e-03


@pytest.mark.parametrize("general", [False, True], ids=["paper", "general"])
def test_replay_matches_at_tight_settings(general, figures):
    """MuJoCo driven open loop for 1 s by the forces of our computed-torque run of the demo's
    move (narayan2017, or its general variant), against our own forward dynamics driven by the
    same forces. Bounds: against our open-loop replay, 1e-8 m and 1e-8 rad (measured ~1e-10);
    against our closed-loop run, 1e-6 m (measured ~5e-8, the open-loop plant's own drift);
    the ball joints stay closed within 1e-7 m (measured ~1e-10)."""
    pytest.importorskip("mujoco")
    from benchmarks.peers import mujoco_model

    plat, run = mujoco_model.our_run(params=_general_params() if general else None)
    ours_ol = mujoco_model.our_open_loop(plat, run)
    fig = mujoco_model.replay(plat.params, run, "tight", duration=1.0, window=1.0, repeats=1, open_loop=ours_ol)
    ol, cl = fig["vs_our_open_loop_replay"], fig["vs_our_closed_loop_run"]
    label = f"MuJoCo export (tight), {'general' if general else 'paper'} model, 1 s"
    figures(f"{label}, vs our open-loop replay, position [m]", ol["max_position_difference_first_1s_m"], 1e-8)  # reached 1.1e-10
    figures(f"{label}, vs our open-loop replay, angle [rad]", ol["max_angle_difference_first_1s_rad"], 2e-9)  # reached 3.8e-11
    figures(f"{label}, vs our closed-loop run, position [m]", cl["max_position_difference_first_1s_m"], 1e-6)  # reached 4.5e-08
    figures(f"{label}, ball-joint gap [m]", fig["max_constraint_gap_m"], 5e-9)  # reached 7.4e-11


@pytest.mark.parametrize("general", [False, True], ids=["paper", "general"])
def test_trajectory_replay(general, figures):
    """MuJoCo driven open loop for 1 s by our inverse dynamics of the demo's move, against the
    move: the paper's model (MuJoCo's legs on random axes, without axial inertia) and the
    general model, each by its kernel. Bounds 1e-8 m and rad (measured ~3e-10 m, ~5e-11 rad);
    the ball joints stay closed within 1e-7 m (measured ~7e-11 m)."""
    pytest.importorskip("mujoco")
    from benchmarks.peers import mujoco_model

    if general:
        params = _general_params()
        inverse = stewart.Platform(params).inverse_dynamics
    else:
        ours = stewart.PlatformParams.preset(PRESET)
        params, inverse = mujoco_model.on_random_axes(ours, seed=5), stewart.Platform(ours).inverse_dynamics
    fig = mujoco_model.trajectory_replay(params, inverse, duration=1.0)
    label = "general model" if general else "paper model"
    figures(f"MuJoCo export (tight) replaying our ID of the move, {label}, 1 s, position [m]", fig["position_m"], 1e-8)  # reached 2.6e-10
    figures(f"MuJoCo export (tight) replaying our ID of the move, {label}, 1 s, angle [rad]", fig["angle_rad"], 2e-9)  # reached 4.6e-11
    figures(f"MuJoCo export (tight) replaying our ID of the move, {label}, ball-joint gap [m]", fig["gap_m"], 5e-9)  # reached 7.4e-11
