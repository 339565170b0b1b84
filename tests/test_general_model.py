"""The general model (legs that turn with their universal joints, an off-centre payload with
a full inertia tensor) in the numeric reference and the Newton-Euler check: against the
energy written out from the bodies (stewart.oracles.physics.energy), against each other, against
the paper's model where the two must coincide, and at the joints' gimbal lock."""

import numpy as np
import pytest

import stewart
from stewart.model import kinematics
from stewart.oracles import frames
from stewart.oracles import newton_euler as ne
from stewart.oracles import reference as ref
from stewart.oracles.physics import COMPLEX_STEP as H
from stewart.oracles.physics import energy, power_balance, relative_error
from conftest import random_states


def _time_derivative(function, x, xd, xdd):
    """d/dt of ``function(x, xd)`` along the motion, by complex step."""
    return function(x + 1j * H * xd, xd + 1j * H * xdd).imag / H


def test_power_balance_of_the_general_reference(general_params, figures):
    """dE/dt = tau . Ldot with tau from the reference, E written out from the bodies with the
    leg frames' rate (e_k x edot_k)/2 (an independent formula for the legs' spin)."""
    x, xd, xdd = random_states(general_params, 30, np.random.default_rng(60))
    tau = ref.inverse_dynamics(general_params, x, xd, xdd)
    figures(f"general reference: power balance ({general_params.name})",
            power_balance(general_params, x, xd, xdd, tau), 5e-14)  # reached 1.1e-15


def test_energy_conserved_by_the_general_reference(general_params, figures):
    """With tau = 0 the reference's accelerations keep E constant: dE/dt = 0 relative to the
    rates of its kinetic and potential parts, which exchange energy under gravity."""
    x, xd, _ = random_states(general_params, 30, np.random.default_rng(61))
    xdd = ref.forward_dynamics(general_params, x, xd, np.zeros_like(x))
    total = _time_derivative(lambda a, b: energy(general_params, a, b), x, xd, xdd)
    potential = _time_derivative(lambda a, b: energy(general_params, a, 0.0 * b), x, xd, xdd)
    scale = np.abs(total - potential) + np.abs(potential)
    figures(f"general reference: dE/dt with tau = 0 ({general_params.name})", float(np.max(np.abs(total) / scale)),
            1e-13)  # reached 2.5e-15


def test_twist_mass_matrix_is_the_kinetic_energy(general_params, figures):
    """E - E(at rest) = t . M_t t / 2 with the twist t = T xdot, and M_t is symmetric."""
    x, xd, _ = random_states(general_params, 20, np.random.default_rng(62))
    kinetic = energy(general_params, x, xd) - energy(general_params, x, np.zeros_like(xd))
    twist = np.einsum("nij,nj->ni", kinematics.twist_transform(x), xd)
    m_t = ref.twist_mass_matrix(general_params, x)
    quadratic = 0.5 * np.einsum("ni,nij,nj->n", twist, m_t, twist)
    figures(f"general reference: kinetic energy vs t.M_t t/2 ({general_params.name})",
            relative_error(kinetic[:, None], quadratic[:, None]), 1e-12)  # reached 5.5e-14
    assert relative_error(m_t, np.swapaxes(m_t, -1, -2)) < 1e-15  # reached 2.6e-17


def test_newton_euler_agrees_with_the_general_reference(general_params, figures):
    x, xd, xdd = random_states(general_params, 50, np.random.default_rng(63))
    worst = relative_error(ne.inverse_dynamics(general_params, x, xd, xdd),
                           ref.inverse_dynamics(general_params, x, xd, xdd))
    figures(f"general model: newton-euler vs reference, tau ({general_params.name})", worst, 5e-14)  # reached 7.2e-16


def test_leg_angular_velocity_is_the_frame_rate_in_the_joint_plane(general_params, figures):
    """The reference's leg angular velocity is vee(Rdot R^T) of the leg frame
    R = (u, y, z), y = a x u / |a x u|, with Rdot by complex step of R along the motion,
    and it lies in the span of a and y (orthogonal to a x y)."""
    x, xd, _ = random_states(general_params, 20, np.random.default_rng(64))
    axes = general_params.universal_joint_axes

    def frame(pose):
        u = frames.jacobian(general_params, pose)[..., :3]
        across = np.cross(axes, u)
        y = across / np.sqrt(np.sum(across * across, axis=-1))[..., None]
        return np.stack([u, y, np.cross(u, y)], axis=-1)

    rot = frame(x)
    spin = frame(x + 1j * H * xd).imag / H @ np.swapaxes(rot, -1, -2)
    vee = np.stack([spin[..., 2, 1], spin[..., 0, 2], spin[..., 1, 0]], axis=-1)
    twist = np.einsum("nij,nj->ni", kinematics.twist_transform(x), xd)
    jacs = ref.partial_velocity_jacobians(general_params, x)
    for part in ("cylinder_rotation", "piston_rotation"):
        omega = np.einsum("nlij,nj->nli", jacs[part], twist)
        figures(f"general reference: {part} omega vs vee(Rdot R^T) ({general_params.name})",
                relative_error(omega, vee), 2e-14)  # reached 6.0e-16
        normal = np.cross(axes, rot[..., 1])
        off_plane = np.abs(np.sum(omega * normal, axis=-1)) / np.linalg.norm(omega, axis=-1)
        assert np.max(off_plane) < 1e-14  # reached 5.3e-16


def test_any_axes_reproduce_the_paper_model_without_axial_inertia(preset_params, figures):
    """With zero axial inertia and axisymmetric legs the legs' spin carries no energy, so any
    joint axes give the paper's M, V, G and tau, in the reference and in Newton-Euler."""
    rng = np.random.default_rng(65)
    paper = preset_params.replace(cylinder_inertia=(0.0, *preset_params.cylinder_inertia[1:]),
                                  piston_inertia=(0.0, *preset_params.piston_inertia[1:]))
    axes = rng.normal(size=(6, 3))
    general = paper.with_universal_joints(axes / np.linalg.norm(axes, axis=1, keepdims=True))
    x, xd, xdd = random_states(paper, 30, rng)
    worst = np.max([
        relative_error(ref.mass_matrix(general, x), ref.mass_matrix(paper, x)),
        relative_error(ref.coriolis_vector(general, x, xd), ref.coriolis_vector(paper, x, xd)),
        relative_error(ref.gravity_vector(general, x), ref.gravity_vector(paper, x)),
        relative_error(ref.inverse_dynamics(general, x, xd, xdd), ref.inverse_dynamics(paper, x, xd, xdd)),
        relative_error(ne.inverse_dynamics(general, x, xd, xdd), ne.inverse_dynamics(paper, x, xd, xdd)),
    ])
    figures(f"general model: any axes, no axial inertia vs paper ({preset_params.name})", worst, 1e-13)  # reached 1.1e-15


def test_the_exact_legs_change_the_dynamics(preset_params):
    """With axial inertia the joints' axes matter: the legs' spin changes V xdot."""
    x, xd, _ = random_states(preset_params, 10, np.random.default_rng(66))
    general = preset_params.with_universal_joints()
    change = relative_error(ref.coriolis_vector(general, x, xd), ref.coriolis_vector(preset_params, x, xd))
    assert 1e-8 < change < 1.0


def test_universal_joint_moment_is_across_both_joint_axes(general_params, figures):
    """The base's moment on a leg (Newton-Euler) is along a x y: a universal joint transmits
    no moment about either of its axes. It is not zero: the legs' spin needs it."""
    x, xd, xdd = random_states(general_params, 10, np.random.default_rng(67))
    forces = ne.joint_reactions(general_params, x, xd, xdd)
    axes = general_params.universal_joint_axes
    u = kinematics.leg_unit_vectors(general_params, x)
    y = np.cross(axes, u)
    along = np.abs(np.sum(forces.base_moment * axes, axis=-1)) + np.abs(np.sum(forces.base_moment * y, axis=-1))
    assert np.max(along) < 5e-15 * np.max(np.linalg.norm(forces.base_moment, axis=-1))  # reached 1.1e-16
    assert np.max(np.linalg.norm(forces.base_moment, axis=-1)) > 0.0


def test_gimbal_lock_is_a_singularity():
    """A leg along its joint's first axis: the reference and Newton-Euler raise the
    gimbal_lock condition naming the row; the paper's model is defined there."""
    params = stewart.PlatformParams.preset("narayan2017")
    x = kinematics.home_pose(params) + np.array([0.01, -0.02, 0.0, 0.05, 0.0, 0.0])
    axes = np.array(params.with_universal_joints().universal_joint_axes)
    axes[3] = kinematics.leg_unit_vectors(params, x)[3]
    locked = params.with_universal_joints(axes)
    states = np.stack([kinematics.home_pose(params), x])
    zero = np.zeros_like(states)
    for function in (lambda: ref.inverse_dynamics(locked, states, zero, zero),
                     lambda: ref.mass_matrix(locked, states),
                     lambda: ref.forward_dynamics(locked, states, zero, zero),
                     lambda: ne.joint_reactions(locked, states, zero, zero)):
        with pytest.raises(stewart.SingularityError) as info:
            function()
        assert info.value.condition == "gimbal_lock" and info.value.rows == [1]
    assert np.all(np.isfinite(ref.inverse_dynamics(params, states, zero, zero)))


def test_leg_spin_effect_against_newton_euler(figures):
    """stewart.oracles.exactness measures with the reference; Newton-Euler, an independent
    formulation, gives the same changes of the actuator forces."""
    from stewart.oracles import exactness
    from stewart.oracles.physics import random_states as states

    params = stewart.PlatformParams.preset("narayan2017")
    effect = exactness.leg_spin_effect(params, n_states=40, seed=3)
    exact = params.with_universal_joints()
    x, xd, xdd = states(params, 40, np.random.default_rng(3))
    zero = np.zeros_like(x)

    def changes(xd_, xdd_):
        parts = [ne.inverse_dynamics(p, x, xd_, xdd_) - ne.inverse_dynamics(p, x, zero, zero) for p in (exact, params)]
        ratio = np.linalg.norm(parts[0] - parts[1], axis=-1) / np.linalg.norm(parts[1], axis=-1)
        return np.median(ratio), np.max(ratio)

    got, want = np.array([*effect.dynamic, *effect.velocity]), np.array([*changes(xd, xdd), *changes(xd, zero)])
    # reached 1.0e-9: each a difference of forces (the spin's share), which cancels their leading digits
    figures("leg spin effect (median, max) vs Newton-Euler, relative", np.max(np.abs(got / want - 1)), 5e-8)
    assert effect.assumed_axes and effect.states == 40 and 0.0 < effect.dynamic.max < effect.velocity.max
    no_axial = params.replace(cylinder_inertia=(0.0, *params.cylinder_inertia[1:]),
                              piston_inertia=(0.0, *params.piston_inertia[1:]))
    # reached 0; the same forces compared on other states reach 1.1e-15 (any axes, no axial inertia)
    figures("leg spin effect without axial inertia (max, relative)",
            exactness.leg_spin_effect(no_axial, n_states=10).velocity.max, 5e-14)
    with pytest.raises(ValueError, match="^n_states: must be from 1"):
        exactness.leg_spin_effect(params, n_states=0)
