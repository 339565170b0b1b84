"""The Newton-Euler formulation (stewart.oracles.newton_euler) against the compiled kernel and the
numeric reference, and its joint forces against statics and against the bodies' motion
differentiated numerically, independently of the module."""

import warnings

import numpy as np
import pytest

import stewart
from stewart.oracles import frames
from stewart.oracles import newton_euler as ne
from stewart.oracles import reference as ref
from stewart.oracles.physics import COMPLEX_STEP as H
from stewart.oracles.physics import relative_error, statics_residuals
from conftest import PRESETS, random_params, random_states

E_Z = np.array([0.0, 0.0, 1.0])



def test_kernel_reference_and_newton_euler_agree(any_params, figures):
    rng = np.random.default_rng(30)
    x, xd, xdd = random_states(any_params, 300, rng)
    kernel = stewart.Platform(any_params).inverse_dynamics(x, xd, xdd)
    numeric = ref.inverse_dynamics(any_params, x, xd, xdd)
    newton = ne.inverse_dynamics(any_params, x, xd, xdd)
    worst = np.max([relative_error(kernel, numeric), relative_error(newton, numeric), relative_error(newton, kernel)])
    figures(f"newton-euler vs kernel vs reference, tau ({any_params.name})", worst, 1e-13)  # reached 2.2e-15


def test_agreement_at_rest_and_in_pure_rotation(any_params, figures):
    """Special motions where few terms are active: statics, pure spin, pure translation."""
    rng = np.random.default_rng(31)
    x, xd, xdd = random_states(any_params, 50, rng)
    zero = np.zeros_like(x)
    spin = xd * np.array([0, 0, 0, 1, 1, 1])
    slide = xdd * np.array([1, 1, 1, 0, 0, 0])
    worst = 0.0
    for args in [(x, zero, zero), (x, spin, zero), (x, zero, slide), (x, spin, xdd)]:
        worst = np.maximum(worst, relative_error(ne.inverse_dynamics(any_params, *args), ref.inverse_dynamics(any_params, *args)))
    figures(f"newton-euler vs reference, special motions ({any_params.name})", worst, 5e-14)  # reached 1.4e-15


def test_shapes_and_single_state():
    params = stewart.PlatformParams.preset("narayan2017")
    x, xd, xdd = random_states(params, 4, np.random.default_rng(32))
    batch = ne.joint_reactions(params, x, xd, xdd)
    assert isinstance(batch, ne.JointReactions)
    assert batch.tau.shape == (4, 6) and batch.base.shape == (4, 6, 3) and batch.platform.shape == (4, 6, 3)
    one = ne.joint_reactions(params, x[2], xd[2], xdd[2])
    assert one.tau.shape == (6,) and one.base.shape == (6, 3) and one.platform.shape == (6, 3)
    for a, b in zip(one, batch):
        np.testing.assert_allclose(a, b[2], rtol=0, atol=2e-15 * np.max(np.abs(b)))  # reached 0: a few ulp
    np.testing.assert_array_equal(ne.inverse_dynamics(params, x, xd, xdd), batch.tau)
    assert ne.inverse_dynamics(params, list(x[0]), list(xd[0]), list(xdd[0])).shape == (6,)


def test_non_axisymmetric_legs_are_rejected():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        params = stewart.PlatformParams.preset("narayan2017").replace(cylinder_inertia=(1e-4, 6e-4, 5e-4))
    x = stewart.home_pose(params)
    with pytest.raises(ValueError, match="^params: .*axisymmetric"):
        ne.inverse_dynamics(params, x, np.zeros(6), np.zeros(6))
    with pytest.raises(ValueError, match="^params: "):
        ne.joint_reactions("narayan2017", x, np.zeros(6), np.zeros(6))


def test_bad_inputs_are_named():
    params = stewart.PlatformParams.preset("narayan2017")
    x = stewart.home_pose(params)
    zero = np.zeros(6)
    with pytest.raises(ValueError, match="xdd: contains NaN"):
        ne.inverse_dynamics(params, x, zero, [np.nan] * 6)
    with pytest.raises(ValueError, match="xd: expected shape"):
        ne.inverse_dynamics(params, x, np.zeros(5), zero)
    with pytest.raises(ValueError, match="matching batch shapes"):
        ne.inverse_dynamics(params, np.stack([x, x]), np.zeros((3, 6)), np.zeros((2, 6)))
    with pytest.raises(stewart.SingularityError, match="J_C is singular") as info:
        ne.inverse_dynamics(params, np.stack([x, np.zeros(6)]), np.zeros((2, 6)), np.zeros((2, 6)))
    assert info.value.rows == [1]


def test_massless_legs_hand_calculation():
    """Massless legs are two-force members: each joint force is along its leg and equals
    tau u, and the six carry the platform's weight."""
    params = stewart.PlatformParams.preset("motion_simulator").replace(
        cylinder_mass=0.0, piston_mass=0.0, cylinder_inertia=(0, 0, 0), piston_inertia=(0, 0, 0)
    )
    x = stewart.home_pose(params)
    forces = ne.joint_reactions(params, x, np.zeros(6), np.zeros(6))
    units = stewart.leg_unit_vectors(params, x)
    scale = np.max(np.abs(forces.platform))  # reached 0 in both: a bound of a few ulp
    np.testing.assert_allclose(forces.platform, forces.tau[:, None] * units, rtol=0, atol=2e-15 * scale)
    np.testing.assert_allclose(forces.base, forces.platform, rtol=0, atol=2e-15 * scale)
    np.testing.assert_allclose(forces.platform.sum(axis=0), [0, 0, params.platform_mass * 9.81], rtol=2e-15, atol=2e-11)  # reached 1/44 of it


def _weights_scale(params):
    return params.gravity * (params.platform_mass + 6 * (params.cylinder_mass + params.piston_mass))


def test_statics_balance(any_params, figures):
    """At rest the joint forces balance the weights (:func:`stewart.oracles.physics.statics_residuals`):
    the platform's legs carry m_P g with no moment about its centre of mass; each leg's
    base force, the platform's push (-platform force) and its weight sum to zero, and so do
    their moments about B_i. The piston's axial balance gives tau; tau equals the compiled
    kernel's."""
    p = any_params
    rng = np.random.default_rng(33)
    x, _, _ = random_states(p, 100, rng)
    residuals = statics_residuals(p, x)
    assert sorted(residuals) == ["leg force", "leg moment about B_i", "platform force", "platform moment"]
    rest = np.zeros_like(x)
    forces = ne.joint_reactions(p, x, rest, rest)
    units = stewart.leg_unit_vectors(p, x)
    axial = np.sum(units * -forces.platform, axis=-1) + forces.tau - p.piston_mass * p.gravity * units[..., 2]
    worst = np.max([*residuals.values(), np.max(np.abs(axial)) / _weights_scale(p)])
    figures(f"newton-euler statics balance ({p.name})", worst, 1e-14)  # reached 2.6e-16
    kernel = stewart.Platform(p).inverse_dynamics(x, rest, rest)
    figures(f"newton-euler vs kernel, tau at rest ({p.name})", relative_error(forces.tau, kernel), 1e-13)  # reached 2.3e-15


# --- Dynamics of the reactions, against numerically differentiated body motions ---------

DT = 1e-4  # step of the time-derivative stencil (s); motions have time scales >~ 0.1 s


def _path(x, xd, xdd, t):
    """Poses along ``x + xd t + xdd t^2 / 2`` (``t`` may be complex)."""
    return x + xd * t + 0.5 * xdd * t * t


def _bodies(params, pose):
    """Positions of the cylinder and piston centres of mass, leg units and R, at poses."""
    legs = frames.leg_vectors(params, pose)
    units = legs / np.sqrt(np.sum(legs * legs, axis=-1))[..., None]
    cyl = params.base_points + params.cylinder_com_distance * units
    pis = params.base_points + legs - params.piston_com_distance * units
    return {"cyl": cyl, "pis": pis, "u": units, "rot": frames.rotation(pose)}


def _rates(params, x, xd, xdd, t):
    """Positions (real) and velocities (complex step in t) of the bodies at time t."""
    pos = _bodies(params, _path(x, xd, xdd, t))
    shifted = _bodies(params, _path(x, xd, xdd, t + 1j * H))
    return pos, {k: v.imag / H for k, v in shifted.items()}


def _stencil(fun):
    """d/dt at t = 0 of ``fun(t)`` by the fourth-order central difference."""
    return (fun(-2 * DT) - 8 * fun(-DT) + 8 * fun(DT) - fun(2 * DT)) / (12 * DT)


def _skew_vector(mat):
    return np.stack([mat[..., 2, 1], mat[..., 0, 2], mat[..., 1, 0]], axis=-1)


def test_reactions_follow_the_bodies_motion(any_params, figures):
    """Newton's and Euler's laws for each leg and for the platform, with the momenta
    computed from the bodies' positions along x + xd t + xdd t^2/2 (complex step for
    velocities, a fourth-order stencil for their time derivatives), not from
    stewart.oracles.newton_euler:

    * leg force: f_B - f_P - (m_C + m_S) g e_z = m_C a_C + m_S a_S;
    * leg moment about B_i: l x (-f_P) + (c - b) x m_C g_vec + (s - b) x m_S g_vec
      = d/dt [I_t u x udot + (c - b) x m_C cdot + (s - b) x m_S sdot];
    * platform: sum f_P - m_P g e_z = m_P a and sum r_i x f_P = d/dt (R I_P R^T omega),
      omega from Rdot R^T.
    """
    p = any_params
    rng = np.random.default_rng(34)
    x, xd, xdd = random_states(p, 60, rng)
    forces = ne.joint_reactions(p, x, xd, xdd)
    g_vec = -p.gravity * E_Z
    m_c, m_s = p.cylinder_mass, p.piston_mass
    transverse = p.cylinder_inertia[1] + p.piston_inertia[1]

    def momenta(t):
        pos, vel = _rates(p, x, xd, xdd, t)
        base = p.base_points
        leg_omega = np.cross(pos["u"], vel["u"])
        omega = _skew_vector(vel["rot"] @ np.swapaxes(pos["rot"], -1, -2))
        inertia = (pos["rot"] * p.platform_inertia) @ np.swapaxes(pos["rot"], -1, -2)
        return {
            "linear": m_c * vel["cyl"] + m_s * vel["pis"],
            "leg angular": transverse * leg_omega
            + np.cross(pos["cyl"] - base, m_c * vel["cyl"])
            + np.cross(pos["pis"] - base, m_s * vel["pis"]),
            "platform angular": np.einsum("...ij,...j->...i", inertia, omega),
        }

    samples = {t: momenta(t) for t in (-2 * DT, -DT, DT, 2 * DT)}
    rate = {k: _stencil(lambda t: samples[t][k]) for k in samples[DT]}

    pos = _bodies(p, x)
    legs = stewart.leg_vectors(p, x)
    arms = legs - x[:, None, :3] + p.base_points
    force_scale = np.max(np.abs(np.concatenate([forces.base, forces.platform], axis=1)), axis=(1, 2))[:, None, None]
    size = stewart.home_pose(p)[2]
    leg_force = forces.base - forces.platform + (m_c + m_s) * g_vec - rate["linear"]
    leg_moment = (
        np.cross(legs, -forces.platform)
        + np.cross(pos["cyl"] - p.base_points, m_c * g_vec)
        + np.cross(pos["pis"] - p.base_points, m_s * g_vec)
        - rate["leg angular"]
    )
    plat_force = forces.platform.sum(axis=1) + p.platform_mass * (g_vec - xdd[:, :3])
    plat_moment = np.cross(arms, forces.platform).sum(axis=1) - rate["platform angular"]
    worst = np.max([
        np.max(np.abs(leg_force) / force_scale),
        np.max(np.abs(leg_moment) / (size * force_scale)),
        np.max(np.abs(plat_force) / force_scale[:, 0]),
        np.max(np.abs(plat_moment) / (size * force_scale[:, 0])),
    ])
    figures(f"newton-euler reactions vs differentiated momenta ({p.name})", worst, 5e-11)  # reached 9.1e-13
