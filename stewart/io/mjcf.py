"""The platform or a rotary rig as a standalone MuJoCo model (MJCF), with real joints.

:func:`to_mjcf` writes what a built machine has, body by body, from :class:`PlatformParams`:

- per leg a **cylinder** body at the base joint ``b_i`` on a universal joint made of two
  hinges: the first (``u{i}a``) about the joint's base-fixed axis ``a_i``
  (``universal_joint_axes``), the second (``u{i}b``) about the cross axis ``y_i``,
  perpendicular to ``a_i`` and to the leg. The cylinder's frame is the model's leg frame
  ``x = u_i``, ``y = a_i x u_i / |a_i x u_i|``, ``z = x x y`` at every pose (two hinges in
  one MuJoCo body compose as a universal joint: the second axis turns with the first),
  so the leg spins about its axis exactly as the joint makes it;
- a **piston** body on a slide joint (``slide{i}``) along the leg, driven by a motor
  (``force{i}``, gear 1, no limits): ``ctrl`` is the actuator force along the leg in N,
  positive extends it. The slide's position is the leg length ``|l_i|`` (its ``ref`` is
  the leg length of the assembly pose); a parameter set's ``leg_length_limits`` become its
  range;
- the **platform**, a free body, tied to each piston's tip (``P_i``) by an equality
  ``connect`` constraint: a ball joint;
- masses, centres of mass and inertias from the parameters: the cylinder's at
  ``cylinder_com_distance`` from ``B_i`` and the piston's at ``piston_com_distance`` back
  from ``P_i`` along the leg, principal moments ``(axial, I_yy, I_zz)`` in the leg frame
  (eqs. 44-48, 64-66; MuJoCo needs positive masses and moments: :data:`MOMENT_FLOOR`); the
  platform's at ``platform_com`` in {P} with the full tensor ``platform_inertia_tensor``
  (eqs. 10-13);
- gravity ``-g e_z`` of {B} (eq. 72), and sites and sensors: ``tip{i}`` on each piston and
  ``joint{i}`` on the platform (the two ends of each ball joint), the platform's position
  and orientation (``platform_position``, ``platform_orientation``) and the leg lengths
  (``leg_length{i}``);
- visual geometry only: capsules for the legs (of ``leg_diameter`` when given), discs for
  the base and the platform (its plate of ``plate_radius`` when given), none of them
  colliding and none carrying mass (the ``inertial`` elements do).

Parameters without ``universal_joint_axes`` (the paper's model, eq. 29, where the legs
never spin) get the realistic default of
:meth:`PlatformParams.with_universal_joints`: first axes horizontal and tangential to the
base circle. MuJoCo's legs then spin about their own axis as a real machine's do, and the
legs' axial inertia enters MuJoCo's dynamics where the paper's model ignores it: the two
agree exactly for axisymmetric legs with zero axial inertia, and otherwise differ by the
leg spin the general model (:mod:`stewart.oracles.reference`) includes.

The model is assembled at ``pose`` (default: home) and at rest; MuJoCo's ``qpos0`` is that
assembly, so the equality constraints hold exactly there. The hinges read zero at it.
Contacts, further sensors or a scene can be added in MuJoCo (an ``<include>`` of the
file, or ``mujoco.MjSpec.from_string``); the legs and the platform have no colliding
geometry of their own.

A **rotary rig** (6-RSS, :class:`~stewart.RotaryParams`; docs/rotary.md) is written with
the same conventions:

- per leg a **crank** body at the motor point ``b_i`` on a hinge (``motor{i}``) about the
  motor axis ``a_i``, its frame ``x = u_i`` (the crank's direction), ``y = a_i x u_i``,
  ``z = a_i``; the hinge reads the crank angle ``alpha_i`` (its ``ref`` is the angle of the
  assembly pose, from the generated inverse kinematics), ``crank_angle_limits`` its range;
  a motor (``torque{i}``, gear 1): ``ctrl`` is the motor torque at the crank about ``+a_i``
  in N m, clamped to ``motor_torque_limit`` (``ctrlrange`` and ``forcerange``) when set;
- the crank's mass at ``crank_com_distance`` along ``u_i``, and its whole ``crank_inertia``
  about the motor axis (rotor and gearbox included) as the body's: principal moments
  ``(0, J, J)`` about its centre of mass in the crank's frame, ``J = crank_inertia -
  crank_mass crank_com_distance^2`` (a thin lever; the moments about the other axes act
  on the fixed bearing only). The hinge's ``armature`` stays 0: a crank turning about a
  fixed axis has the same kinetic energy whether the reflected rotor is body inertia or
  armature, so moving a known rotor's ``J_r N^2`` there changes nothing;
- per leg a **rod** body on a ball joint (``ball{i}``) at the crank tip (site ``tip{i}``),
  its frame ``x`` along the rod, ``y`` the motor axis's part normal to it; its mass at
  ``rod_com_distance`` along it, principal moments ``(0, rod_inertia, rod_inertia)`` (the
  axial one raised to :data:`MOMENT_FLOOR`). A rod between two ball joints spins freely
  about its axis, a degree of freedom the package's rods do not have; nothing drives it:
  every force on the rod (the two joints' and its weight) acts through its axis, so its spin
  rate keeps the value it starts with, zero in the keyframe and in :func:`joint_velocities`,
  and its axial moment of ``MOMENT_FLOOR`` carries no energy. The platform's and the cranks'
  motion are those of non-spinning rods;
- the platform, a free body, its joint sites ``joint{i}`` tied to the rod ends
  (``rod_end{i}``) by equality ``connect`` constraints between the two sites;
- gravity, the platform's inertia, the visual geometry and the sensors as above, with
  ``crank_angle{i}`` and ``crank_rate{i}`` instead of the leg lengths; a keyframe ``home``
  at :attr:`~stewart.RotaryPlatform.home` at rest, whose ``ctrl`` holds the torques of the
  static equilibrium there (within the torque limits). The ball-joint cones, the crank pins'
  tilt and the motor speed limit have no MuJoCo counterpart here: MuJoCo bounds a ball joint's
  whole rotation from its reference, spin included, not a cone, and a motor's speed not at all.

:func:`joint_positions` and :func:`joint_velocities` give MuJoCo's ``qpos`` and ``qvel`` of
the rotary model at a platform state; :func:`pose_accelerations` reads ``xdd`` from its
``qacc``, as for the linear machines.

Solver settings (:data:`SOLVERS`): MuJoCo's equality constraints are soft. ``"default"``
keeps MuJoCo's defaults (2 ms Euler steps, ``solref 0.02 1``, ``solimp 0.9 0.95 0.001``):
a fast, visually faithful model. ``"tight"`` (0.1 ms RK4 steps and a stiff, nearly hard
constraint) is what the agreement with the kernel is measured at.
"""

from __future__ import annotations

import os
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

from ..model import arguments
from ..model.errors import SingularityError
from ..model.kinematics import euler_rate_jacobian, home_pose, leg_vectors, platform_points_in_base, rotation
from ..model.params import platform_params
from ..model.params import PlatformParams
from ..model.rotary import RotaryPlatform
from ..model.rotary_params import RotaryParams, rotary_params

__all__ = ["SOLVERS", "MOMENT_FLOOR", "to_mjcf", "joint_positions", "joint_velocities", "pose_accelerations"]

#: MuJoCo solver settings by name: the step, the integrator, and the equality constraints'
#: ``solref`` (time constant, damping ratio) and ``solimp`` (impedance); ``None`` keeps
#: MuJoCo's default.
SOLVERS: dict[str, dict[str, Any]] = {
    "default": {"timestep": 2e-3, "integrator": "Euler", "solref": None, "solimp": None},
    "tight": {"timestep": 1e-4, "integrator": "RK4", "solref": (2e-4, 1.0),
              "solimp": (0.9999, 0.9999, 1e-4, 0.5, 2.0)},
}

#: MuJoCo refuses a moving body with a mass below 1e-15 kg or a principal moment below
#: 1e-15 kg m^2; a smaller one (a leg's zero axial inertia, a massless leg) is written as
#: this one, in kg or kg m^2.
MOMENT_FLOOR = 1e-14

#: Visual capsule radius of the legs, as a fraction of the base radius, without a ``leg_diameter``.
_LEG_RADIUS = 0.02


def _fmt(values) -> str:
    """Numbers as MJCF text, to the last bit."""
    return " ".join(f"{float(v):.17g}" for v in np.ravel(values))


def _jointed(platform_or_params) -> PlatformParams:
    """The parameters, with the default universal joints when they have none."""
    params = platform_params(platform_or_params, "platform_or_params")
    return params.with_universal_joints() if params.universal_joint_axes is None else params


def _pose(name: str, value) -> np.ndarray:
    pose = arguments.state_array(name, value)
    if pose.shape != (6,) or not np.all(np.isfinite(pose)):
        raise ValueError(f"{name}: expected 6 finite numbers [x, y, z, psi, theta, phi], got {value!r}")
    return pose


def _legs(params: PlatformParams, x: np.ndarray, name: str = "x"):
    """Arms ``R p_i``, leg frames (columns ``x = u_i``, ``y = a_i x u_i / |a_i x u_i|``,
    ``z = x x y``), lengths and ``|a_i x u_i|`` at the pose ``x``; a leg of zero length or
    parallel to its axis (the joint's gimbal lock) is a ``ValueError`` naming ``name``."""
    overflow = f"{name}: out of numeric range (its leg lengths overflow double precision)"
    try:
        arms, legs = platform_points_in_base(params, x), leg_vectors(params, x)
    except SingularityError:  # leg vectors out of double precision
        raise ValueError(overflow) from None
    with np.errstate(over="ignore", invalid="ignore"):
        lengths = np.linalg.norm(legs, axis=1)
    if not np.all(np.isfinite(lengths)):
        raise ValueError(overflow)
    with np.errstate(invalid="ignore", divide="ignore"):
        units = legs / lengths[:, None]
        axes = params.universal_joint_axes
        cross = np.cross(axes / np.linalg.norm(axes, axis=1, keepdims=True), units)
        sines = np.linalg.norm(cross, axis=1)
    bad = np.flatnonzero(~(sines >= 1e-9))
    if bad.size:
        raise ValueError(f"{name}: leg(s) {bad.tolist()} of zero length or parallel to their universal joint's "
                         "first axis (the joint's gimbal lock)")
    y = cross / sines[:, None]
    return arms, np.stack([units, y, np.cross(units, y)], axis=-1), lengths, sines


def joint_velocities(platform_or_params, x, xd) -> np.ndarray:
    """MuJoCo's ``qvel`` of the model :func:`to_mjcf` writes, at the platform state ``(x, xd)``.

    Per leg ``i`` the two hinge rates and the slide rate: with the tip velocity
    ``v_i = p' + omega x R p_i`` and the leg frame ``(u_i, y_i, z_i)``, the leg turns at
    ``omega_i = q_a a_i + q_b y_i``, so ``v_i = L_i (q_a |a_i x u_i| y_i - q_b z_i) + L' u_i``;
    then the platform's free joint: the velocity of the origin of {P} in {B} and the angular
    velocity ``J_A(x) [psi', theta', phi']`` (eq. 8) in {P}. Shape ``(24,)``.

    Of a rotary rig (:class:`~stewart.RotaryPlatform` or :class:`~stewart.RotaryParams`), per
    leg the crank rate ``alpha_i'`` (the generated ``crank_rates``) and the rod's angular
    velocity relative to its crank, ``n_i x n_i' / d^2 - alpha_i' a_i`` with ``n_i = P_i - c_i``
    (the rod does not spin about its axis), in the rod's frame (:func:`joint_positions`); then
    the platform's free joint as above. Shape ``(30,)``.
    """
    if _is_rotary(platform_or_params):
        return _rotary_velocities(_rotary_rig(platform_or_params, "platform_or_params"),
                                  _pose("x", x), _pose("xd", xd))
    params = _jointed(platform_or_params)
    x, xd = _pose("x", x), _pose("xd", xd)
    rot = rotation(x)
    omega = euler_rate_jacobian(x) @ xd[3:]
    arms, frames, lengths, sines = _legs(params, x)
    tips = xd[:3] + np.cross(omega, arms)
    rates = np.einsum("ij,ijk->ik", tips, frames)  # components along u_i, y_i, z_i
    legs = np.stack([rates[:, 1] / (lengths * sines), -rates[:, 2] / lengths, rates[:, 0]], axis=1)
    return np.concatenate([legs.ravel(), xd[:3], rot.T @ omega])


def pose_accelerations(x, xd, qacc) -> np.ndarray:
    """``xdd`` of the platform from MuJoCo's ``qacc`` of its free joint (the last six: the
    acceleration of the origin of {P} in {B}, and ``omega'`` in {P}) at the state ``(x, xd)``:
    ``[psi'', theta'', phi''] = J_A^-1 (R omega'_P - J_A' [psi', theta', phi'])`` (eq. 8)."""
    x, xd = _pose("x", x), _pose("xd", xd)
    qacc = np.asarray(qacc, dtype=float)[-6:]
    # J_A' e': J_A's columns are e_z, Rz(psi) e_y (turning about e_z at psi') and R e_x (turning
    # at omega = J_A e'), so J_A' e' = theta' psi' (e_z x J_A e_y) + phi' (omega x R e_x).
    j_a = euler_rate_jacobian(x)
    omega = j_a @ xd[3:]
    j_a_rate = xd[4] * xd[3] * np.cross(j_a[:, 0], j_a[:, 1]) + xd[5] * np.cross(omega, j_a[:, 2])
    angular = rotation(x) @ qacc[3:] - j_a_rate
    return np.concatenate([qacc[:3], np.linalg.solve(j_a, angular)])


def _moments(inertia) -> str:
    """Masses or principal moments as MJCF text, raised to :data:`MOMENT_FLOOR`."""
    return _fmt(np.maximum(inertia, MOMENT_FLOOR))


def _xyaxes(frame: np.ndarray) -> str:
    return _fmt(np.concatenate([frame[:, 0], frame[:, 1]]))


def _solver(solver) -> dict[str, Any]:
    if isinstance(solver, str):
        if solver not in SOLVERS:
            raise ValueError(f"solver: expected one of {', '.join(SOLVERS)}, got {solver!r}")
        return SOLVERS[solver]
    return {**SOLVERS["default"], **dict(solver)}


def to_mjcf(platform_or_params, path=None, *, pose=None, solver="default") -> str:
    """The MJCF text of a platform (a :class:`~stewart.Platform` or :class:`PlatformParams`),
    written to ``path`` too when given; see the module's documentation for what it holds.

    ``pose``: the assembly pose ``[x, y, z, psi, theta, phi]`` (default: home).
    ``solver``: a name in :data:`SOLVERS` or a mapping of its keys (missing ones from
    ``"default"``).

    A rotary rig (:class:`~stewart.RotaryPlatform` or :class:`~stewart.RotaryParams`) is
    written with motor hinges, rods on ball joints and the loops closed at the platform (see
    the module's documentation); its default pose is :attr:`~stewart.RotaryPlatform.home`.
    """
    if _is_rotary(platform_or_params):
        settings = _solver(solver)
        return _written(path, _rotary_mjcf(_rotary_rig(platform_or_params, "platform_or_params"), pose, settings))
    params = _jointed(platform_or_params)
    pose = home_pose(params) if pose is None else _pose("pose", pose)
    settings = _solver(solver)
    _, frames, lengths, _ = _legs(params, pose, "pose")
    rot = rotation(pose)
    radius = (_LEG_RADIUS * float(np.max(np.linalg.norm(params.base_points[:, :2], axis=1)))
              if params.leg_diameter is None else 0.5 * params.leg_diameter)
    eq_opts = "".join(f' {key}="{_fmt(settings[key])}"' for key in ("solref", "solimp") if settings[key] is not None)
    limits = "" if params.leg_length_limits is None else f' range="{_fmt(params.leg_length_limits)}"'
    legs = []
    for i in range(6):
        length, b_c, b_s = lengths[i], params.cylinder_com_distance, params.piston_com_distance
        first_axis = frames[i].T @ params.universal_joint_axes[i]
        legs.append(f"""
    <body name="cylinder{i}" pos="{_fmt(params.base_points[i])}" xyaxes="{_xyaxes(frames[i])}">
      <joint name="u{i}a" type="hinge" axis="{_fmt(first_axis)}"/>
      <joint name="u{i}b" type="hinge" axis="0 1 0"/>
      <inertial pos="{_fmt([b_c, 0, 0])}" mass="{_moments(params.cylinder_mass)}" diaginertia="{_moments(params.cylinder_inertia)}"/>
      <geom type="capsule" fromto="0 0 0 {_fmt(length / 2)} 0 0" size="{_fmt(radius)}" rgba="0.3 0.3 0.35 1"/>
      <body name="piston{i}">
        <joint name="slide{i}" type="slide" axis="1 0 0" ref="{_fmt(length)}"{limits}/>
        <inertial pos="{_fmt([length - b_s, 0, 0])}" mass="{_moments(params.piston_mass)}" diaginertia="{_moments(params.piston_inertia)}"/>
        <geom type="capsule" fromto="{_fmt(length / 2)} 0 0 {_fmt(length)} 0 0" size="{_fmt(radius / 2)}" rgba="0.75 0.75 0.8 1"/>
        <site name="tip{i}" pos="{_fmt([length, 0, 0])}"/>
      </body>
    </body>""")
    sites = "".join(f'\n      <site name="joint{i}" pos="{_fmt(params.platform_points[i])}"/>' for i in range(6))
    com = np.zeros(3) if params.platform_com is None else params.platform_com
    tensor = params.platform_inertia_tensor
    full = [tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]]
    # The plate as the workspace checks it (stewart.model.reachability), else a disc through the joints.
    top = (float(np.max(np.linalg.norm(params.platform_points[:, :2], axis=1))) if params.plate_radius is None
           else params.plate_radius)
    plate = np.max(params.platform_points[:, 2]) if params.plate_radius is not None else np.mean(params.platform_points[:, 2])
    bottom = float(np.max(np.linalg.norm(params.base_points[:, :2], axis=1)))
    eqs = "".join(f'\n    <connect name="ball{i}" body1="piston{i}" body2="platform" anchor="{_fmt([lengths[i], 0, 0])}"'
                  f'{eq_opts}/>' for i in range(6))
    motors = "".join(f'\n    <motor name="force{i}" joint="slide{i}" gear="1"/>' for i in range(6))
    sensors = "".join(f'\n    <jointpos name="leg_length{i}" joint="slide{i}"/>' for i in range(6))
    label = "stewart platform" + ("" if params.name is None else " " + params.name)
    return _written(path, _document(
        label, f"the platform assembled at the pose {_fmt(pose)}", "ctrl = actuator forces [N]", settings, params,
        bottom, radius, "".join(legs), pose, rot, com, full, plate, top, sites, eqs, motors, sensors))


def _document(label: str, assembled: str, notes: str, settings: dict[str, Any], params, base_radius: float,
              radius: float, legs: str, pose, rot, com, full, plate: float, top: float, sites: str, eqs: str,
              motors: str, sensors: str, tail: str = "") -> str:
    """The MJCF document of either family: the header comment (``assembled``, ``notes``), the
    solver's options, the base (a disc of ``base_radius``), the ``legs``' bodies, the platform
    (freejoint, inertia ``com``, ``full``, a disc of radius ``top`` at height ``plate``,
    ``sites``), the loops' ``eqs``, the ``motors``, the ``sensors`` and a ``tail`` (a keyframe)."""
    return f"""<mujoco model={quoteattr(label)}>
  <!-- Generated by stewart.to_mjcf: {assembled}
       (x, y, z [m], ZYX Euler angles psi, theta, phi [rad]); {notes}. -->
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{_fmt(settings['timestep'])}" integrator="{settings['integrator']}" gravity="0 0 {_fmt(-params.gravity)}"/>
  <default>
    <geom contype="0" conaffinity="0"/>
  </default>
  <worldbody>
    <geom name="base" type="cylinder" pos="0 0 {_fmt(np.mean(params.base_points[:, 2]))}" size="{_fmt([base_radius, radius / 2])}" rgba="0.5 0.5 0.5 1"/>{legs}
    <body name="platform" pos="{_fmt(pose[:3])}" xyaxes="{_xyaxes(rot)}">
      <freejoint name="platform"/>
      <inertial pos="{_fmt(com)}" mass="{_moments(params.platform_mass)}" fullinertia="{_fmt(full)}"/>
      <geom type="cylinder" pos="0 0 {_fmt(plate)}" size="{_fmt([top, radius / 2])}" rgba="0.8 0.5 0.2 1"/>{sites}
    </body>
  </worldbody>
  <equality>{eqs}
  </equality>
  <actuator>{motors}
  </actuator>
  <sensor>
    <framepos name="platform_position" objtype="xbody" objname="platform"/>
    <framequat name="platform_orientation" objtype="xbody" objname="platform"/>{sensors}
  </sensor>
{tail}</mujoco>
"""


def _written(path, text: str) -> str:
    if path is not None:
        with open(os.fspath(path), "w", encoding="utf-8") as handle:
            handle.write(text)
    return text


# ------------------------------------------------------------------ rotary rigs (6-RSS)

def _is_rotary(value) -> bool:
    return isinstance(value, RotaryParams) or isinstance(getattr(value, "params", None), RotaryParams)


def _rotary_legs(rig: RotaryPlatform, x: np.ndarray, name: str = "x"):
    """At the pose ``x``, from the generated model: the crank angles (in each leg's branch),
    the crank frames (columns ``u_i``, ``a_i x u_i``, ``a_i``), the rods' vectors
    ``n_i = P_i - c_i`` (``J_alpha``'s row is ``[j_i, R p_i x j_i]`` with
    ``j_i = n_i / (n_i . t_i)`` and ``sign(n_i . t_i)`` the leg's branch, so
    ``n_i = branch_i d j_i / |j_i|``) and their frames (columns ``n_i / d``, the motor axis's
    part normal to the rod, their cross product). A pose out of a crank's reach or on its edge
    (``J_alpha`` singular) is a ``ValueError`` naming ``name``."""
    params = rig.params
    try:
        alpha = rig.crank_angles(x)
        along = rig.jacobian(x)[:, :3]
    except SingularityError as exc:
        raise ValueError(f"{name}: {exc}") from None
    along = params.crank_branch[:, None] * along / np.linalg.norm(along, axis=1, keepdims=True)
    a = params.motor_axes
    u = np.cos(alpha)[:, None] * params.crank_zero + np.sin(alpha)[:, None] * params.crank_tip_directions
    cranks = np.stack([u, np.cross(a, u), a], axis=-1)
    # The motor axis is never along a rod off the edge of the crank's reach (n_i . t_i != 0, t_i normal to a_i).
    normal = a - np.sum(a * along, axis=1, keepdims=True) * along
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    return alpha, cranks, params.rod_length * along, np.stack([along, normal, np.cross(along, normal)], axis=-1)


def _quaternions(rot: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(w, x, y, z)`` of rotation matrices, ``w >= 0``."""
    from scipy.spatial.transform import Rotation

    quat = np.roll(Rotation.from_matrix(rot).as_quat(), 1, axis=-1)
    return quat * np.where(quat[..., :1] < 0.0, -1.0, 1.0)


def _rotary_positions(rig: RotaryPlatform, x: np.ndarray, assembly: np.ndarray, name: str = "x") -> np.ndarray:
    _, cranks0, _, rods0 = _rotary_legs(rig, assembly, "pose")
    alpha, cranks, _, rods = _rotary_legs(rig, x, name)
    # Each rod's frame in its crank's, against the one it is written with at the assembly pose.
    relative = np.einsum("ikj,ikl->ijl", cranks0, rods0)
    balls = np.einsum("ikj,ikl->ijl", relative, np.einsum("ikj,ikl->ijl", cranks, rods))
    legs = np.concatenate([alpha[:, None], _quaternions(balls)], axis=1)
    return np.concatenate([legs.ravel(), x[:3], _quaternions(rotation(x))])


def joint_positions(rig, x, *, pose=None) -> np.ndarray:
    """MuJoCo's ``qpos`` of a rotary rig's model (a :class:`~stewart.RotaryPlatform` or
    :class:`~stewart.RotaryParams`; :func:`to_mjcf` assembled at ``pose``, default home) at the
    platform pose ``x``: per leg the crank angle (the motor hinge reads the crank angle
    ``alpha_i`` of the generated inverse kinematics) and the rod's ball-joint quaternion (its
    frame: ``x`` along the rod, ``y`` the motor axis's part normal to it), then the platform's
    free joint (position of the origin of {P} in {B}, and orientation). Shape ``(37,)``.
    """
    rig = _rotary_rig(rig, "rig")
    assembly = rig.home if pose is None else _pose("pose", pose)
    return _rotary_positions(rig, _pose("x", x), assembly)


def _rotary_velocities(rig: RotaryPlatform, x: np.ndarray, xd: np.ndarray) -> np.ndarray:
    params = rig.params
    _, cranks, rods, frames = _rotary_legs(rig, x)
    rates = rig.crank_rates(x, xd)
    omega = euler_rate_jacobian(x) @ xd[3:]
    tips = params.base_points + params.crank_length * cranks[:, :, 0]
    arms = tips + rods - x[:3]  # R p_i = P_i - p
    tip_rates = rates[:, None] * params.crank_length * cranks[:, :, 1]  # alpha' a_i x (c_i - b_i)
    rod_rates = xd[:3] + np.cross(omega, arms) - tip_rates
    # The rod turns without spinning (omega_rod = n x n' / d^2), relative to its crank (alpha' a_i).
    spins = np.cross(rods, rod_rates) / np.sum(rods * rods, axis=1, keepdims=True) - rates[:, None] * params.motor_axes
    balls = np.einsum("ikj,ik->ij", frames, spins)
    legs = np.concatenate([rates[:, None], balls], axis=1)
    return np.concatenate([legs.ravel(), xd[:3], rotation(x).T @ omega])


def _rotary_rig(value, name: str) -> RotaryPlatform:
    return value if isinstance(value, RotaryPlatform) else RotaryPlatform(rotary_params(value, name))


_KEYFRAME = """  <keyframe>
    <key name="home" qpos="{qpos}" ctrl="{ctrl}"/>
  </keyframe>
"""


def _rotary_mjcf(rig: RotaryPlatform, pose, settings: dict[str, Any]) -> str:
    params = rig.params
    home = rig.home
    pose = home if pose is None else _pose("pose", pose)
    alpha, cranks, _, frames = _rotary_legs(rig, pose, "pose")
    try:
        keyframe = _rotary_positions(rig, home, pose, "home")
        holding = rig.inverse_dynamics(home, np.zeros(6), np.zeros(6))
    except ValueError as exc:  # an asymmetric rig's home out of a crank's reach, or singular
        keyframe, note = None, "no keyframe: " + str(exc).replace("--", "- -")  # no "--" in an XML comment
    else:
        if params.motor_torque_limit is not None:
            holding = np.clip(holding, -params.motor_torque_limit, params.motor_torque_limit)
        note = 'keyframe "home": the home pose at rest, ctrl the torques that hold it'
    base_radius = float(np.max(np.linalg.norm(params.base_points[:, :2], axis=1)))
    radius = _LEG_RADIUS * base_radius
    r, d = params.crank_length, params.rod_length
    eq_opts = "".join(f' {key}="{_fmt(settings[key])}"' for key in ("solref", "solimp") if settings[key] is not None)
    limits = "" if params.crank_angle_limits is None else f' range="{_fmt(params.crank_angle_limits)}"'
    crank_own = params.crank_inertia - params.crank_mass * params.crank_com_distance ** 2
    legs = []
    for i in range(6):
        relative = cranks[i].T @ frames[i]
        legs.append(f"""
    <body name="crank{i}" pos="{_fmt(params.base_points[i])}" xyaxes="{_xyaxes(cranks[i])}">
      <joint name="motor{i}" type="hinge" axis="0 0 1" ref="{_fmt(alpha[i])}"{limits}/>
      <inertial pos="{_fmt([params.crank_com_distance, 0, 0])}" mass="{_moments(params.crank_mass)}" diaginertia="{_moments([0.0, crank_own, crank_own])}"/>
      <geom type="capsule" fromto="0 0 0 {_fmt(r)} 0 0" size="{_fmt(radius)}" rgba="0.3 0.3 0.35 1"/>
      <site name="tip{i}" pos="{_fmt([r, 0, 0])}"/>
      <body name="rod{i}" pos="{_fmt([r, 0, 0])}" xyaxes="{_xyaxes(relative)}">
        <joint name="ball{i}" type="ball"/>
        <inertial pos="{_fmt([params.rod_com_distance, 0, 0])}" mass="{_moments(params.rod_mass)}" diaginertia="{_moments([0.0, params.rod_inertia, params.rod_inertia])}"/>
        <geom type="capsule" fromto="0 0 0 {_fmt(d)} 0 0" size="{_fmt(radius / 2)}" rgba="0.75 0.75 0.8 1"/>
        <site name="rod_end{i}" pos="{_fmt([d, 0, 0])}"/>
      </body>
    </body>""")
    sites = "".join(f'\n      <site name="joint{i}" pos="{_fmt(params.platform_points[i])}"/>' for i in range(6))
    tensor = params.platform_inertia_tensor
    full = [tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]]
    top = float(np.max(np.linalg.norm(params.platform_points[:, :2], axis=1)))
    eqs = "".join(f'\n    <connect name="ball_platform{i}" site1="rod_end{i}" site2="joint{i}"{eq_opts}/>' for i in range(6))
    torque = params.motor_torque_limit
    motors = "".join(f'\n    <motor name="torque{i}" joint="motor{i}" gear="1"'
                     + ("" if torque is None else f' ctrlrange="{_fmt([-torque[i], torque[i]])}" '
                                                  f'forcerange="{_fmt([-torque[i], torque[i]])}"')
                     + "/>" for i in range(6))
    sensors = "".join(f'\n    <jointpos name="crank_angle{i}" joint="motor{i}"/>' for i in range(6))
    sensors += "".join(f'\n    <jointvel name="crank_rate{i}" joint="motor{i}"/>' for i in range(6))
    label = "stewart rotary rig" + ("" if params.name is None else " " + params.name)
    return _document(label, f"the rotary rig assembled at the pose {_fmt(pose)}",
                     "the motor hinges read the crank\n       angles [rad]; ctrl = motor torques at the crank [N m]; "
                     + note, settings, params, base_radius, radius, "".join(legs), pose, rotation(pose),
                     params.platform_com_in_model, full, np.mean(params.platform_points[:, 2]), top, sites, eqs, motors,
                     sensors, "" if keyframe is None else _KEYFRAME.format(qpos=_fmt(keyframe), ctrl=_fmt(holding)))
