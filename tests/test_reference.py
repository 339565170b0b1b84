"""The numeric reference against physics: power balance, energy conservation, eq. 76's
gravity, and its own forward/inverse round trip."""

import warnings

import numpy as np
import pytest

import stewart
from stewart.oracles import reference as ref
from stewart.oracles.physics import COMPLEX_STEP as H
from stewart.oracles.physics import energy, power_balance, relative_error
from stewart.model.kinematics import euler_rate_jacobian
from conftest import random_params, random_states


def potential_energy(params, x):
    """The energy of pose ``x`` at rest."""
    return energy(params, x, np.zeros_like(x))


def _all_params(rng, n_random=4):
    return [stewart.PlatformParams.preset(n) for n in sorted(stewart.presets())] + [
        random_params(rng) for _ in range(n_random)
    ]


def test_forward_inverse_round_trip(figures):
    rng = np.random.default_rng(10)
    worst = 0.0
    for params in _all_params(rng):
        x, xd, xdd = random_states(params, 200, rng)
        tau = ref.inverse_dynamics(params, x, xd, xdd)
        back = ref.forward_dynamics(params, x, xd, tau)
        worst = np.maximum(worst, relative_error(back, xdd))
    figures("reference: FD(ID(xdd)) vs xdd (relative)", worst, 5e-13)  # reached 1.3e-14


def test_power_balance(figures):
    """dE/dt = tau . Ldot along any motion, E written out from the bodies (stewart.oracles.physics)."""
    rng = np.random.default_rng(11)
    worst = 0.0
    for params in _all_params(rng):
        x, xd, xdd = random_states(params, 40, rng)
        tau = ref.inverse_dynamics(params, x, xd, xdd)
        worst = np.maximum(worst, power_balance(params, x, xd, xdd, tau))
    figures("reference: power balance |dE/dt - tau.Ldot| (relative)", worst, 5e-14)  # reached 1.3e-15


def _rk4(params, x, xd, dt, steps):
    def f(state):
        pos, vel = state[:6], state[6:]
        return np.concatenate([vel, ref.forward_dynamics(params, pos, vel, np.zeros(6))])

    state = np.concatenate([x, xd])
    out = [state]
    for _ in range(steps):
        k1 = f(state)
        k2 = f(state + 0.5 * dt * k1)
        k3 = f(state + 0.5 * dt * k2)
        k4 = f(state + dt * k3)
        state = state + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append(state)
    return np.array(out)


def test_energy_conserved_with_zero_force(preset_params, figures):
    """With tau = 0 only gravity works: E stays constant over 0.1 s of RK4 (dt = 1 ms).

    The step sets only RK4's own drift, which falls as dt^4: 4e-12 at most here (2e-13 at
    0.5 ms), far below the bound. A wrong model drifts in proportion to its error and the
    horizon, whatever the step: accelerations off by 1e-7 (relative) drift 7e-8 to 1e-7
    over these 0.1 s, at 1 ms as at 0.5 ms."""
    rng = np.random.default_rng(12)
    home = stewart.home_pose(preset_params)
    xd = rng.normal(size=6) * np.array([0.1 * home[2]] * 3 + [0.3] * 3)
    path = _rk4(preset_params, home, xd, 1e-3, 100)
    energies = energy(preset_params, path[:, :6], path[:, 6:])
    kinetic = energies - potential_energy(preset_params, path[:, :6])
    drift = np.max(np.abs(energies - energies[0])) / np.max(kinetic)
    figures(f"reference: energy drift, RK4 0.1 s ({preset_params.name})", drift, 2e-10)  # reached 3.6e-12


def test_gravity_matches_eq76(preset_params, figures):
    """G = blockdiag(E, J_A^-T) dP/dx, with P from eq. 72 and dP/dx by complex step."""
    rng = np.random.default_rng(13)
    x, _, _ = random_states(preset_params, 30, rng)
    worst = 0.0
    for pose in x:
        grad = np.array([potential_energy(preset_params, pose + 1j * H * np.eye(6)[k]).imag / H for k in range(6)])
        g76 = np.concatenate([grad[:3], np.linalg.solve(euler_rate_jacobian(pose).T, grad[3:])])
        worst = np.maximum(worst, np.max(np.abs(ref.gravity_vector(preset_params, pose) - g76)) / np.max(np.abs(g76)))
    figures(f"reference: gravity vs eq. 76 ({preset_params.name})", worst, 1e-14)  # reached 2.4e-16


def test_statics_with_massless_legs_carry_the_platform_weight():
    """Hand calculation: with massless legs, J_C^T tau is the platform's weight [0,0,m g,0,0,0]."""
    params = stewart.PlatformParams.preset("narayan2017").replace(
        cylinder_mass=0.0, piston_mass=0.0, cylinder_inertia=(0, 0, 0), piston_inertia=(0, 0, 0)
    )
    x = stewart.home_pose(params)
    tau = ref.inverse_dynamics(params, x, np.zeros(6), np.zeros(6))
    wrench = stewart.jacobian(params, x).T @ tau
    np.testing.assert_allclose(wrench, [0, 0, params.platform_mass * 9.81, 0, 0, 0], atol=1e-13, rtol=1e-8)  # reached 1/56 of it


def test_paper_frame_form_equals_axisymmetric_form(preset_params):
    rng = np.random.default_rng(14)
    x, xd, _ = random_states(preset_params, 20, rng)
    frame = ref.body_terms(preset_params, x, xd, general=True)
    axi = ref.body_terms(preset_params, x, xd, general=False)
    for body in ref.BODIES:
        for a, b in zip(frame[body], axi[body]):
            np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-13 * np.max(np.abs(b)))  # reached 1/45 of it


def test_twist_mass_matrix_is_symmetric_positive_definite(preset_params):
    rng = np.random.default_rng(15)
    x, _, _ = random_states(preset_params, 50, rng)
    m_twist = ref.mass_matrix(preset_params, x) @ np.linalg.inv(stewart.twist_transform(x))
    np.testing.assert_allclose(m_twist, np.swapaxes(m_twist, -1, -2), rtol=0, atol=2e-15 * np.max(np.abs(m_twist)))  # reached 5.1e-17
    assert np.all(np.linalg.eigvalsh(m_twist) > 0)


def test_body_terms_sum_to_the_model(preset_params):
    rng = np.random.default_rng(16)
    x, xd, _ = random_states(preset_params, 5, rng)
    terms = ref.body_terms(preset_params, x, xd)
    assert terms["cylinder_rotation"].mass_matrix.shape == (5, 6, 6, 6)  # a leg axis
    total = sum(t.mass_matrix if b.startswith("platform") else t.mass_matrix.sum(axis=-3) for b, t in terms.items())
    np.testing.assert_allclose(total, ref.mass_matrix(preset_params, x), rtol=2e-15)  # reached 0: a few ulp
    momenta = ref.momenta(preset_params, x, xd)
    np.testing.assert_allclose(momenta["platform_translation"], preset_params.platform_mass * xd[:, :3],
                               rtol=1e-15)  # reached 0


def test_singular_states_raise():
    params = stewart.PlatformParams.preset("narayan2017")
    zero = np.zeros(6)
    with pytest.raises(stewart.SingularityError, match="J_C is singular"):
        ref.inverse_dynamics(params, np.zeros(6), zero, zero)  # platform in the base plane
    tilted = stewart.home_pose(params) + [0, 0, 0, 0, np.pi / 2, 0]
    with pytest.raises(stewart.SingularityError, match="theta = \\+-90 deg") as info:
        ref.forward_dynamics(params, np.stack([stewart.home_pose(params), tilted]), np.zeros((2, 6)), np.zeros((2, 6)))
    assert info.value.rows == [1]


def test_vertical_leg_needs_axisymmetric_inertia():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        params = stewart.PlatformParams.preset("narayan2017").replace(cylinder_inertia=(1e-4, 6e-4, 5e-4))
    x = np.zeros(6)
    x[:3] = params.base_points[0] - params.platform_points[0] + [0, 0, 0.25]  # leg 0 vertical
    with pytest.raises(stewart.SingularityError, match="vertical leg"):
        ref.mass_matrix(params, x)
    axisymmetric = params.replace(cylinder_inertia=(1e-4, 6e-4, 6e-4))
    assert np.all(np.isfinite(ref.mass_matrix(axisymmetric, x)))


def test_bad_dynamics_inputs_are_named():
    params = stewart.PlatformParams.preset("narayan2017")
    x = stewart.home_pose(params)
    with pytest.raises(ValueError, match="xdd: contains NaN"):
        ref.inverse_dynamics(params, x, np.zeros(6), [np.nan] * 6)
    with pytest.raises(ValueError, match="tau: expected shape"):
        ref.forward_dynamics(params, x, np.zeros(6), np.zeros(7))
