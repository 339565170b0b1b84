"""The same platform in MuJoCo (the package's MJCF export, :func:`stewart.to_mjcf`),
replaying our forces, and MuJoCo's accelerations at single states.

The model (see :mod:`stewart.io.mjcf`): per leg a cylinder on a universal joint (two hinges)
and a piston on a slide joint driven by a motor; the piston tips are tied to the free
platform by equality ``connect`` constraints. Contacts play no part (no colliding geoms).

Comparability with the paper's model: its legs never spin (eq. 29), so their axial
inertia has no effect; a MuJoCo leg on a universal joint does spin about its axis as it
swings, and its axial inertia then carries energy. :func:`comparable` therefore sets the
legs' axial moments to zero (the export raises them to ``stewart.io.mjcf.MOMENT_FLOOR`` of
the transverse ones, as MuJoCo needs positive moments); with it both describe the same
mechanics, whatever the joints' axes. Parameters of the general model (exact legs,
payload) are exported as they are.

The replay: our simulation of the demo's move (narayan2017, home to
``narayan2017_target_pose()`` in 5 s, sinusoidal profile) under computed torque, so the
forces are the exact inverse dynamics of our model along the simulated motion; those
forces, sampled at 1 kHz and interpolated linearly to the middle of each MuJoCo step, drive
MuJoCo open loop from the same initial state.

The accelerations (:func:`accelerations`): MuJoCo's own ``qacc`` under its soft
constraints, and the rigid-body accelerations of MuJoCo's model with the ``connect``
constraints held exactly, solved from MuJoCo's mass matrix, bias forces, constraint
Jacobian and the constraints' velocity-product acceleration.
"""

from __future__ import annotations

import time

import numpy as np

import stewart
from stewart.model.kinematics import rotation
from stewart.io.mjcf import SOLVERS, joint_velocities, pose_accelerations


def without_axial_inertia(params: stewart.PlatformParams) -> stewart.PlatformParams:
    """``params`` with the legs' axial moments set to zero: with axisymmetric legs, the
    mechanics of the paper's non-spinning legs (eq. 29) on universal joints of any axes."""
    return params.replace(cylinder_inertia=(0.0, *params.cylinder_inertia[1:]),
                          piston_inertia=(0.0, *params.piston_inertia[1:]))


def comparable(params: stewart.PlatformParams) -> stewart.PlatformParams:
    """The parameters MuJoCo's model is given to match ours: for the paper's model
    :func:`without_axial_inertia`, for the general model ``params`` themselves."""
    return without_axial_inertia(params) if params.is_paper_model else params


def random_axes(params: stewart.PlatformParams, seed: int = 3) -> np.ndarray:
    """First joint axes drawn around the tangential default of
    :meth:`~stewart.PlatformParams.with_universal_joints` (unit vectors, ``(6, 3)``)."""
    axes = params.with_universal_joints().universal_joint_axes
    axes = axes + 0.3 * np.random.default_rng(seed).standard_normal((6, 3))
    return axes / np.linalg.norm(axes, axis=1, keepdims=True)


def on_random_axes(params: stewart.PlatformParams, seed: int = 3) -> stewart.PlatformParams:
    """The paper's model of ``params`` on universal joints of :func:`random_axes`:
    :func:`without_axial_inertia`, which the general model then reproduces."""
    return without_axial_inertia(params).replace(universal_joint_axes=random_axes(params, seed))


def general_variant(params: stewart.PlatformParams, seed: int = 3) -> stewart.PlatformParams:
    """A general-model variant of ``params``: exact legs on :func:`random_axes`,
    non-axisymmetric leg inertias with axial moments, and an off-centre payload of a fifth
    of the platform's mass with a full tensor (parallel-axis theorem)."""
    legs = {f"{part}_inertia": getattr(params, f"{part}_inertia")[1] * np.array([0.5, 0.8, 1.2])
            for part in ("cylinder", "piston")}
    tensor = np.array([[0.4, 0.06, -0.04], [0.06, 0.3, 0.02], [-0.04, 0.02, 0.5]]) * float(np.max(params.platform_inertia))
    radius = float(np.max(np.linalg.norm(params.platform_points, axis=1)))
    exact = params.replace(universal_joint_axes=random_axes(params, seed), **legs)
    return exact.with_payload(0.2 * params.platform_mass, np.array([0.1, -0.08, 0.15]) * radius, tensor)


def model(params: stewart.PlatformParams, pose=None, setting: str = "tight"):
    """The compiled MJCF of ``params`` assembled at ``pose`` with the ``setting`` of
    :data:`stewart.io.mjcf.SOLVERS`, and sensors of both ends of each ball joint appended
    (``tip{i}`` then ``joint{i}``, after the export's own sensors)."""
    import mujoco

    spec = mujoco.MjSpec.from_string(stewart.to_mjcf(params, pose=pose, solver=setting))
    for i in range(6):
        for site in (f"tip{i}", f"joint{i}"):
            spec.add_sensor(name=f"{site}_position", type=mujoco.mjtSensor.mjSENS_FRAMEPOS,
                            objtype=mujoco.mjtObj.mjOBJ_SITE, objname=site)
    return spec.compile()


def accelerations(params: stewart.PlatformParams, x, xd, tau, setting: str = "tight") -> dict:
    """The platform's ``xdd`` in MuJoCo (the model of :func:`comparable`) at the state
    ``(x, xd)`` under the actuator forces ``tau``: ``"soft"``, MuJoCo's forward dynamics with its soft constraints at ``setting``;
    ``"rigid"``, MuJoCo's model with the six ball joints held exactly,
    ``[M J^T; J 0] [qacc; f] = [tau - bias; -J' qvel]``, where ``J' qvel`` is the two ends'
    relative acceleration at ``qacc = 0`` (``mj_objectAcceleration`` after
    ``mj_rnePostConstraint``)."""
    import mujoco

    m = model(comparable(params), x, setting)
    d = mujoco.MjData(m)
    d.qvel[:] = joint_velocities(params, x, xd)
    d.ctrl[:] = tau
    mujoco.mj_forward(m, d)
    soft = pose_accelerations(x, xd, d.qacc)
    mass = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, mass)
    forces = d.qfrc_actuator + d.qfrc_passive - d.qfrc_bias
    d.qacc[:] = 0.0
    mujoco.mj_rnePostConstraint(m, d)
    jac, bias = np.zeros((18, m.nv)), np.zeros(18)
    for i in range(6):
        for site, sign in ((f"tip{i}", 1.0), (f"joint{i}", -1.0)):
            sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, site)
            jacp, acc = np.zeros((3, m.nv)), np.zeros(6)
            mujoco.mj_jacSite(m, d, jacp, None, sid)
            mujoco.mj_objectAcceleration(m, d, mujoco.mjtObj.mjOBJ_SITE, sid, acc, 0)
            jac[3 * i:3 * i + 3] += sign * jacp
            bias[3 * i:3 * i + 3] += sign * acc[3:]
    kkt = np.block([[mass, jac.T], [jac, np.zeros((18, 18))]])
    rigid = np.linalg.solve(kkt, np.concatenate([forces, -bias]))[:m.nv]
    return {"soft": soft, "rigid": pose_accelerations(x, xd, rigid)}


def our_run(dt: float = 1e-3, params: stewart.PlatformParams | None = None):
    """Our simulation of the demo's move under computed torque (RK4 at ``dt``), for the
    narayan2017 preset or ``params`` (a variant of it)."""
    from stewart.cli.demo import MOVE_DURATION
    from stewart.model.presets import narayan2017_target_pose

    plat = stewart.Platform(params or stewart.PlatformParams.preset("narayan2017"))
    move = stewart.PointToPoint(plat.home_pose, narayan2017_target_pose(), MOVE_DURATION, "sinusoidal")
    return plat, stewart.simulate(plat, move, stewart.ComputedTorque.tuned(), dt=dt)


def _rotations_from_quats(quats) -> np.ndarray:
    w, x, y, z = quats.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def _differences(times, pos, rots, ref_t, ref_x, window: float) -> dict:
    """Platform position and orientation differences from ``ref_x`` on the common time grid."""
    step = ref_t[1] - ref_t[0]
    idx = np.rint(times / step).astype(int)
    common = (idx < len(ref_t)) & (np.abs(ref_t[np.minimum(idx, len(ref_t) - 1)] - times) < 1e-9)
    t, ref = times[common], ref_x[idx[common]]
    dpos = np.linalg.norm(pos[common] - ref[:, :3], axis=1)
    rel = np.swapaxes(rotation(ref), -1, -2) @ rots[common]
    skew = rel - np.swapaxes(rel, -1, -2)
    dang = np.arcsin(np.clip(0.5 * np.linalg.norm(skew, axis=(-1, -2)) / np.sqrt(2), 0, 1))
    early = t <= window + 1e-12
    over = np.flatnonzero(dpos > 1e-3)
    return {
        f"max_position_difference_first_{window:g}s_m": float(dpos[early].max()),
        f"max_angle_difference_first_{window:g}s_rad": float(dang[early].max()),
        "time_to_1mm_difference_s": float(t[over[0]]) if over.size else None,
        "max_position_difference_m": float(dpos.max()),
        "max_angle_difference_rad": float(dang.max()),
        "compared_until_s": float(t[-1]),
    }


def forces_at(run, times) -> np.ndarray:
    """``run.forces`` (sampled every ``dt``) interpolated linearly to ``times``."""
    return np.stack([np.interp(times, run.t, run.forces[:, k]) for k in range(6)], axis=1)


def our_open_loop(plat, run, dt: float = 1e-4):
    """Our model driven open loop by the same interpolated forces (the replay's input),
    RK4 at ``dt``: how sensitive the open-loop plant is, with no model difference at all."""
    move = stewart.PointToPoint(run.x[0], run.reference[-1], run.t[-1], "sinusoidal")
    return stewart.simulate(plat, move, stewart.OpenLoop(), feedforward=lambda t: forces_at(run, t), dt=dt,
                            x0=run.x[0], xd0=run.xd[0])


def replay(params, run, setting: str = "default", *, duration: float | None = None, window: float = 1.0,
           repeats: int = 3, open_loop=None) -> dict:
    """Drive MuJoCo open loop with ``run.forces`` for ``duration`` (default: the whole run)
    and compare its platform pose with ``run.x`` (and with ``open_loop``, our own open-loop
    replay of the same forces, if given).

    Returns the median wall time per step (``mujoco.rollout``, a C loop), the largest gap
    between the connect anchors, and the platform position and orientation differences:
    the largest over the first ``window`` seconds, the time they first exceed 1 mm, and the
    largest over the run."""
    import mujoco
    from mujoco import rollout

    opts = SOLVERS[setting]
    m = model(comparable(params), run.x[0], setting)
    data = mujoco.MjData(m)
    dt = m.opt.timestep
    steps = int(round((run.t[-1] - run.t[0] if duration is None else duration) / dt))
    ctrl = forces_at(run, (np.arange(steps) + 0.5) * dt)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.zeros(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, data, state0, spec)
    walls, sensordata = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        _, sensordata = rollout.rollout(m, data, state0[None], ctrl[None])
        walls.append(time.perf_counter() - start)
    sens = sensordata[0]  # row k: sensors computed at the start of step k, t = k dt
    times = np.arange(steps) * dt
    pos, rots = sens[:, 0:3], _rotations_from_quats(sens[:, 3:7])
    anchors = sens[:, -36:].reshape(steps, 6, 2, 3)
    gap = np.linalg.norm(anchors[:, :, 0] - anchors[:, :, 1], axis=-1)
    out = {
        "timestep_s": dt, "integrator": opts["integrator"],
        "solref": " ".join(f"{v:g}" for v in opts["solref"]) if opts["solref"] else "default (0.02 1)",
        "solimp": " ".join(f"{v:g}" for v in opts["solimp"]) if opts["solimp"] else "default (0.9 0.95 0.001 0.5 2)",
        "steps": steps,
        "step_us": float(np.median(walls)) / steps * 1e6,
        "wall_per_simulated_s_ms": float(np.median(walls)) / (steps * dt) * 1e3,
        "max_constraint_gap_m": float(gap.max()),
        "vs_our_closed_loop_run": _differences(times, pos, rots, run.t, run.x, window),
    }
    if open_loop is not None:
        out["vs_our_open_loop_replay"] = _differences(times, pos, rots, open_loop.t, open_loop.x, window)
    return out


def figures(window: float = 1.0) -> dict:
    """Both settings, with our run's wall time for the same move and our own open-loop
    replay of the forces (the plant's sensitivity) alongside."""
    import mujoco

    plat, run = our_run()
    ours_ol = our_open_loop(plat, run)
    ol_self = _differences(ours_ol.t, ours_ol.x[:, :3], rotation(ours_ol.x), run.t, run.x, window)
    out = {"mujoco_version": mujoco.__version__, "axial_fraction": stewart.io.mjcf.MOMENT_FLOOR, "window_s": window,
           "ours_rk4_ct_wall_ms": run.wall_time * 1e3, "ours_steps": len(run.t) - 1,
           "ours_step_us": run.wall_time / (len(run.t) - 1) * 1e6,
           "our_open_loop_replay": {"timestep_s": 1e-4, "completed": ours_ol.completed, "reason": ours_ol.reason,
                                    "vs_our_closed_loop_run": ol_self}}
    for setting in SOLVERS:
        out[setting] = replay(plat.params, run, setting, window=window, open_loop=ours_ol)
    return out


def trajectory_replay(params: stewart.PlatformParams, inverse_dynamics, duration: float = 1.0,
                      setting: str = "tight") -> dict:
    """MuJoCo driven open loop along the demo's move (home to ``narayan2017_target_pose()``
    in 5 s, sinusoidal) by our inverse dynamics of it, ``inverse_dynamics(x, xd, xdd)``
    (batched), evaluated in the middle of each MuJoCo step, for ``duration`` seconds; the
    largest platform position and orientation differences from the move itself (which
    those forces reproduce exactly in our model) and the largest ball-joint gap."""
    import mujoco
    from mujoco import rollout

    from stewart.cli.demo import MOVE_DURATION
    from stewart.model.presets import narayan2017_target_pose

    move = stewart.PointToPoint(stewart.home_pose(params), narayan2017_target_pose(), MOVE_DURATION, "sinusoidal")
    m = model(comparable(params), move.start, setting)
    data = mujoco.MjData(m)
    steps = int(round(duration / m.opt.timestep))
    ctrl = inverse_dynamics(*move.sample((np.arange(steps) + 0.5) * m.opt.timestep))
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.zeros(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, data, state0, spec)
    sens = rollout.rollout(m, data, state0[None], ctrl[None])[1][0]  # row k: at t = k dt
    x = move.sample(np.arange(steps) * m.opt.timestep)[0]
    rel = np.swapaxes(rotation(x), -1, -2) @ _rotations_from_quats(sens[:, 3:7])
    skew = rel - np.swapaxes(rel, -1, -2)
    anchors = sens[:, -36:].reshape(steps, 6, 2, 3)
    return {"position_m": float(np.max(np.linalg.norm(sens[:, :3] - x[:, :3], axis=1))),
            "angle_rad": float(np.max(np.arcsin(np.clip(np.linalg.norm(skew, axis=(-1, -2)) / np.sqrt(8), 0, 1)))),
            "gap_m": float(np.max(np.linalg.norm(anchors[:, :, 0] - anchors[:, :, 1], axis=-1))),
            "duration_s": duration}


def acceleration_differences(ours: stewart.PlatformParams, theirs: stewart.PlatformParams, inverse_dynamics,
                             states: int, seed: int = 0) -> dict:
    """The largest relative difference of MuJoCo's ``xdd`` (:func:`accelerations`, the
    model of ``theirs``) from ``xdd`` at random states of ``ours`` (:func:`stewart.cli.bench.states`)
    under the forces ``inverse_dynamics(x, xd, xdd)``: ``{"rigid": .., "soft": ..}``."""
    from stewart.cli import bench
    from stewart.oracles.physics import relative_error

    x, xd, xdd = bench.states(ours, states, seed=seed)
    worst = {"rigid": 0.0, "soft": 0.0}
    for k in range(states):
        acc = accelerations(theirs, x[k], xd[k], inverse_dynamics(x[k], xd[k], xdd[k]))
        for kind in worst:
            worst[kind] = max(worst[kind], relative_error(acc[kind], xdd[k]))
    return worst


def export_figures(states: int = 20, seed: int = 0, duration: float = 1.0) -> dict:
    """How closely the exported model reproduces ours, for the README, per model: the
    largest relative difference of MuJoCo's ``xdd`` (rigid-body and tight soft constraints)
    at ``states`` random states (:func:`acceleration_differences`) and the tight
    :func:`trajectory_replay` over ``duration`` seconds; for narayan2017 on random joint
    axes (the paper's model) and for its :func:`general_variant` (the general model), each
    by its kernel."""
    paper = stewart.PlatformParams.preset("narayan2017")
    general = general_variant(paper)
    cases = {  # our parameters, MuJoCo's, our inverse dynamics
        "paper model, random joint axes": (paper, on_random_axes(paper), stewart.Platform(paper).inverse_dynamics),
        "general model": (general, general, stewart.Platform(general).inverse_dynamics),
    }
    return {label: {**acceleration_differences(ours, theirs, inverse, states=states, seed=seed),
                    **trajectory_replay(theirs, inverse, duration)}
            for label, (ours, theirs, inverse) in cases.items()}
