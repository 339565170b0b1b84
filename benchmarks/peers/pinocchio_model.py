"""The platform as a Pinocchio closed-loop model: constraint dynamics and its derivatives
(``computeConstraintDynamicsDerivatives``) against our exact derivatives
(``python -m benchmarks``, package ``pin``).

The model: the platform on a free-flyer joint (its mass and principal inertia at its
centre); per leg, a universal joint at ``B_i`` (a revolute joint about the base x-axis,
then one about the rotated y-axis), whose body is the cylinder (its centre of mass at
``b_C`` along the leg), then a prismatic joint along the leg whose configuration is the
leg length, whose body is the piston (centre of mass at ``b_S`` back from ``P_i``). Each
piston's end is tied to the platform point ``P_i`` by a 3-D point constraint
(``RigidConstraintModel`` ``CONTACT_3D``): 24 degrees of freedom and 18 constraints. The
legs' actuator forces act on the prismatic joints.

A universal joint turns its leg about the leg's axis as it swings, which the paper's leg
does not; the agreement check therefore uses legs without axial inertia, where that spin
carries no energy and the mechanics are the same. It compares the platform's
accelerations at rest (where the Euler-angle and free-flyer accelerations map by the
rotation alone) with our forward dynamics, and Pinocchio's ``d ddq / d tau`` with our
``dxddot/dtau`` there.
"""

from __future__ import annotations

import numpy as np

import stewart
from stewart.cli import bench
from stewart.oracles.physics import relative_error
from stewart.model.kinematics import euler_rate_jacobian, rotation


def build(params):
    """``(model, constraint_models, prismatic velocity indices)`` of ``params``."""
    import pinocchio as pin

    model = pin.Model()
    platform = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "platform")
    model.appendBodyToJoint(platform, pin.Inertia(params.platform_mass, np.zeros(3),
                                                  np.diag(params.platform_inertia)), pin.SE3.Identity())
    model.gravity = pin.Motion(np.array([0.0, 0.0, -params.gravity, 0.0, 0.0, 0.0]))
    sliders = []
    for i in range(6):
        swing = model.addJoint(0, pin.JointModelRX(), pin.SE3(np.eye(3), params.base_points[i]), f"leg{i}_x")
        tilt = model.addJoint(swing, pin.JointModelRY(), pin.SE3.Identity(), f"leg{i}_y")
        axial, iyy, izz = params.cylinder_inertia
        model.appendBodyToJoint(tilt, pin.Inertia(params.cylinder_mass, np.array([0, 0, params.cylinder_com_distance]),
                                                  np.diag([iyy, izz, axial])), pin.SE3.Identity())
        slide = model.addJoint(tilt, pin.JointModelPZ(), pin.SE3.Identity(), f"leg{i}_slide")
        axial, iyy, izz = params.piston_inertia
        model.appendBodyToJoint(slide, pin.Inertia(params.piston_mass, np.array([0, 0, -params.piston_com_distance]),
                                                   np.diag([iyy, izz, axial])), pin.SE3.Identity())
        sliders.append(slide)
    # A constraint takes its sizes from the model as it is: made once every joint is in.
    constraints = pin.StdVec_RigidConstraintModel()
    for i, slide in enumerate(sliders):
        constraints.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, slide, pin.SE3.Identity(),
                                                    platform, pin.SE3(np.eye(3), params.platform_points[i]),
                                                    pin.ReferenceFrame.LOCAL))
    return model, constraints, np.array([model.joints[slide].idx_v for slide in sliders])


def configuration(params, x) -> np.ndarray:
    """Pinocchio's ``q`` of the pose ``x``: platform position and quaternion, then per leg
    the two universal-joint angles and the leg length."""
    import pinocchio as pin

    rot = rotation(x)
    quat = pin.Quaternion(rot).coeffs()  # x, y, z, w
    legs = stewart.leg_vectors(params, x)
    lengths = np.linalg.norm(legs, axis=-1)
    units = legs / lengths[:, None]
    # R_x(a) R_y(b) e_z = (sin b, -sin a cos b, cos a cos b)
    tilt = np.arcsin(units[:, 0])
    swing = np.arctan2(-units[:, 1], units[:, 2])
    return np.concatenate([x[:3], quat, np.column_stack([swing, tilt, lengths]).ravel()])


def figures(preset: str, n_states: int = 200, repeats: int = 5) -> dict:
    """Time per state of ``constraintDynamics`` and of it with
    ``computeConstraintDynamicsDerivatives`` (from Python), at rest poses, with our
    forward dynamics with its Jacobians beside them; and the agreement of the platform's
    accelerations with ours on the same platform with legs of no axial inertia."""
    import pinocchio as pin

    params = stewart.PlatformParams.preset(preset)
    out = {"pinocchio_version": pin.__version__, "states": n_states}
    x, _, _ = bench.states(params, n_states, seed=2)
    zero = np.zeros(6)
    settings = pin.ProximalSettings(1e-12, 1e-12, 0.0, 1)

    def setup(p):
        model, constraints, sliders = build(p)
        data = model.createData()
        datas = pin.StdVec_RigidConstraintData()
        for c in constraints:
            datas.append(c.createData())
        pin.initConstraintDynamics(model, data, constraints, datas)
        return model, data, constraints, datas, sliders

    def accelerations(setup_, p, pose, tau):
        model, data, constraints, datas, sliders = setup_
        torque = np.zeros(model.nv)
        torque[sliders] = tau
        return pin.constraintDynamics(model, data, configuration(p, pose), np.zeros(model.nv), torque, constraints,
                                      datas, settings)

    # Agreement, on legs without axial inertia.
    free_spin = params.replace(cylinder_inertia=(0.0, *params.cylinder_inertia[1:]),
                               piston_inertia=(0.0, *params.piston_inertia[1:]))
    plat = stewart.Platform(free_spin)
    s = setup(free_spin)
    worst = worst_jacobian = 0.0
    taus = plat.inverse_dynamics(x, np.zeros_like(x), np.zeros_like(x)) * (1.0 + 0.2 * np.sin(np.arange(6)))
    for pose, tau in zip(x[:20], taus[:20]):
        ddq = accelerations(s, free_spin, pose, tau)
        d_tau = pin.computeConstraintDynamicsDerivatives(s[0], s[1], s[2], s[3], settings)[2][:6, s[4]]
        rot = np.kron(np.eye(2), rotation(pose))  # free-flyer (local) to {B}, at rest
        euler = np.kron(np.diag([1.0, 0.0]), np.eye(3)) + np.kron(np.diag([0.0, 1.0]), euler_rate_jacobian(pose))
        ours = plat.forward_dynamics_derivatives(pose, zero, tau)
        worst = max(worst, relative_error((rot @ ddq[:6])[None], (euler @ ours.xdd)[None]))
        worst_jacobian = max(worst_jacobian, relative_error((rot @ d_tau)[None], (euler @ ours.dxdd_dtau)[None]))
    out["platform_acceleration_rel_error"] = worst
    out["dxdd_dtau_rel_error"] = worst_jacobian

    # Timing, on the preset itself.
    model, data, constraints, datas, sliders = s = setup(params)
    ours = stewart.Platform(params)
    tau = ours.inverse_dynamics(x, np.zeros_like(x), np.zeros_like(x))
    qs = [configuration(params, pose) for pose in x]
    torques = np.zeros((n_states, model.nv))
    torques[:, sliders] = tau
    v = np.zeros(model.nv)

    def dynamics():
        for q, t in zip(qs, torques):
            pin.constraintDynamics(model, data, q, v, t, constraints, datas, settings)

    def with_derivatives():
        for q, t in zip(qs, torques):
            pin.constraintDynamics(model, data, q, v, t, constraints, datas, settings)
            pin.computeConstraintDynamicsDerivatives(model, data, constraints, datas, settings)

    out["constraint_dynamics_us"] = bench.median_time(dynamics, 1, repeats) / n_states * 1e6
    out["constraint_dynamics_derivatives_us"] = bench.median_time(with_derivatives, 1, repeats) / n_states * 1e6
    zeros = np.zeros_like(x)
    out["ours_single_forward_dynamics_us"] = bench.median_time(lambda: ours.forward_dynamics(x[0], zero, tau[0]),
                                                               2000) * 1e6
    out["ours_single_forward_dynamics_derivatives_us"] = bench.median_time(
        lambda: ours.forward_dynamics_derivatives(x[0], zero, tau[0]), 2000) * 1e6
    out["ours_batch_forward_dynamics_derivatives_us"] = bench.median_time(
        lambda: ours.forward_dynamics_derivatives(x, zeros, tau), 1, repeats) / n_states * 1e6
    return out
