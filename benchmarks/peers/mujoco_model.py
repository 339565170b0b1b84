"""The same platform in MuJoCo (MJCF generated from PlatformParams), replaying our forces.

The model: per leg a cylinder body at the base joint ``b_i`` with a universal joint (two
hinges, both normal to the leg at home) and a piston body on a slide joint along the leg;
the piston tip (``P_i`` at home) is tied to the platform, a free body, by an equality
``connect`` constraint (a ball joint). A motor with gear 1 and no limits drives each slide
joint, so ``ctrl`` is the actuator force along the leg (positive extends it). Contacts
are off (there are no geoms), joints have no damping, armature or friction.

Comparability: our model (Lopes & Pires, eq. 29) lets no leg spin about its own axis,
and its axial leg inertia has no effect. A MuJoCo leg on a universal joint does spin a
little about its axis as it swings (the first hinge's axis is fixed in the base, so the
leg's angular velocity has a component ``q1' a1 . u`` along the leg). The spin is a
consequence of the hinge angles, not a degree of freedom, and its only dynamic effect is
the axial inertia's kinetic energy ``I_a (omega . u)^2 / 2``. The MJCF therefore gives
the cylinder and the piston a near-zero axial inertia (``AXIAL_FRACTION`` of their
transverse inertia); with it the spin carries no energy and the two models describe the
same mechanics: the transverse leg inertia sees the same angular velocity component
normal to the leg (``u x u'``) in both.

The replay: our simulation of the demo's move (narayan2017, home to
``narayan2017_target_pose()`` in 5 s, sinusoidal profile) under computed torque, so the
forces are the exact inverse dynamics of our model along the simulated motion; those
forces, sampled at 1 kHz and interpolated linearly to the middle of each MuJoCo step, drive
MuJoCo open loop from the same initial state.
"""

from __future__ import annotations

import time

import numpy as np

import stewart
from stewart.kinematics import rotation

#: The MJCF legs' axial inertia as a fraction of their transverse inertia (see above).
AXIAL_FRACTION = 1e-6

#: MuJoCo settings compared: its defaults, and a stiff constraint with a small step.
SETTINGS = {
    "default": {"timestep": 2e-3, "integrator": "Euler", "solref": None, "solimp": None},
    "tight": {"timestep": 1e-4, "integrator": "RK4", "solref": "0.0002 1", "solimp": "0.9999 0.9999 0.0001 0.5 2"},
}


def _fmt(values) -> str:
    return " ".join(f"{float(v):.17g}" for v in np.ravel(values))


def _quat_z_to(direction) -> np.ndarray:
    """Unit quaternion (w, x, y, z) rotating the z axis onto ``direction``."""
    z = np.array([0.0, 0.0, 1.0])
    d = direction / np.linalg.norm(direction)
    c = float(z @ d)
    if c < -1 + 1e-12:
        return np.array([0.0, 1.0, 0.0, 0.0])
    axis = np.cross(z, d)
    q = np.concatenate([[1.0 + c], axis])
    return q / np.linalg.norm(q)


def _quat_from_matrix(r) -> np.ndarray:
    import mujoco

    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(r).ravel())
    return q


def mjcf(params: stewart.PlatformParams, pose=None, *, timestep=2e-3, integrator="Euler", solref=None,
         solimp=None, axial_fraction: float = AXIAL_FRACTION) -> str:
    """MJCF text of the platform assembled at ``pose`` (default: home), at rest."""
    pose = stewart.home_pose(params) if pose is None else np.asarray(pose, float)
    rot = rotation(pose)
    legs = pose[:3] + params.platform_points @ rot.T - params.base_points
    lengths = np.linalg.norm(legs, axis=1)
    eq_opts = (f' solref="{solref}"' if solref else "") + (f' solimp="{solimp}"' if solimp else "")

    def leg_inertia(inertia):
        transverse = float(inertia[1]), float(inertia[2])
        axial = axial_fraction * max(transverse) if max(transverse) > 0 else 0.0
        return _fmt([transverse[0], transverse[1], axial])  # local x, y normal to the leg, z along it

    body = []
    for i in range(6):
        q = _quat_z_to(legs[i])
        body.append(f"""
    <body name="cylinder{i}" pos="{_fmt(params.base_points[i])}" quat="{_fmt(q)}">
      <joint name="u{i}a" type="hinge" axis="1 0 0"/>
      <joint name="u{i}b" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 {_fmt(params.cylinder_com_distance)}" mass="{_fmt(params.cylinder_mass)}" diaginertia="{leg_inertia(params.cylinder_inertia)}"/>
      <body name="piston{i}">
        <joint name="slide{i}" type="slide" axis="0 0 1"/>
        <inertial pos="0 0 {_fmt(lengths[i] - params.piston_com_distance)}" mass="{_fmt(params.piston_mass)}" diaginertia="{leg_inertia(params.piston_inertia)}"/>
        <site name="tip{i}" pos="0 0 {_fmt(lengths[i])}"/>
      </body>
    </body>""")
    sites = "".join(f'\n      <site name="joint{i}" pos="{_fmt(params.platform_points[i])}"/>' for i in range(6))
    eqs = "".join(f'\n    <connect body1="piston{i}" body2="platform" anchor="0 0 {_fmt(lengths[i])}"{eq_opts}/>'
                  for i in range(6))
    motors = "".join(f'\n    <motor name="force{i}" joint="slide{i}" gear="1"/>' for i in range(6))
    sensors = '\n    <framepos objtype="body" objname="platform"/>\n    <framequat objtype="body" objname="platform"/>'
    sensors += "".join(f'\n    <framepos objtype="site" objname="tip{i}"/>\n    <framepos objtype="site" objname="joint{i}"/>'
                       for i in range(6))
    return f"""<mujoco model="stewart {params.name or ''}">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{_fmt(timestep)}" integrator="{integrator}" gravity="0 0 {_fmt(-params.gravity)}">
    <flag contact="disable"/>
  </option>
  <worldbody>{''.join(body)}
    <body name="platform" pos="{_fmt(pose[:3])}" quat="{_fmt(_quat_from_matrix(rot))}">
      <freejoint/>
      <inertial pos="0 0 0" mass="{_fmt(params.platform_mass)}" diaginertia="{_fmt(params.platform_inertia)}"/>{sites}
    </body>
  </worldbody>
  <equality>{eqs}
  </equality>
  <actuator>{motors}
  </actuator>
  <sensor>{sensors}
  </sensor>
</mujoco>
"""


def our_run(dt: float = 1e-3):
    """Our simulation of the demo's move under computed torque (RK4 at ``dt``)."""
    from stewart.demo import MOVE_DURATION
    from stewart.presets import narayan2017_target_pose

    plat = stewart.Platform.preset("narayan2017")
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

    opts = SETTINGS[setting]
    model = mujoco.MjModel.from_xml_string(mjcf(params, run.x[0], **opts))
    data = mujoco.MjData(model)
    dt = model.opt.timestep
    steps = int(round((run.t[-1] - run.t[0] if duration is None else duration) / dt))
    ctrl = forces_at(run, (np.arange(steps) + 0.5) * dt)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    walls, sensordata = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        _, sensordata = rollout.rollout(model, data, state0[None], ctrl[None])
        walls.append(time.perf_counter() - start)
    sens = sensordata[0]  # row k: sensors computed at the start of step k, t = k dt
    times = np.arange(steps) * dt
    pos, rots = sens[:, 0:3], _rotations_from_quats(sens[:, 3:7])
    anchors = sens[:, 7:].reshape(steps, 6, 2, 3)
    gap = np.linalg.norm(anchors[:, :, 0] - anchors[:, :, 1], axis=-1)
    out = {
        "timestep_s": dt, "integrator": opts["integrator"], "solref": opts["solref"] or "default (0.02 1)",
        "solimp": opts["solimp"] or "default (0.9 0.95 0.001 0.5 2)", "steps": steps,
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
    out = {"mujoco_version": mujoco.__version__, "axial_fraction": AXIAL_FRACTION, "window_s": window,
           "ours_rk4_ct_wall_ms": run.wall_time * 1e3, "ours_steps": len(run.t) - 1,
           "ours_step_us": run.wall_time / (len(run.t) - 1) * 1e6,
           "our_open_loop_replay": {"timestep_s": 1e-4, "completed": ours_ol.completed, "reason": ours_ol.reason,
                                    "vs_our_closed_loop_run": ol_self}}
    for setting in SETTINGS:
        out[setting] = replay(plat.params, run, setting, window=window, open_loop=ours_ol)
    return out
