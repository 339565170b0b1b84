"""The compiled kernel against physics: energy conservation in free motion, the power
balance, a symmetric positive-definite twist-space mass matrix; a check that these
tests catch the paper's eq. 60 typo; and stewart.validation on every preset."""

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import stewart
from stewart import newton_euler as ne
from stewart import reference as ref
from stewart import validation
from conftest import PRESETS, random_params, random_states
from energy import energy, leg_rates, potential_energy

H = 1e-30



def _power_balance(params, x, xd, xdd, tau):
    """Worst |dE/dt - tau . Ldot| / sum |tau_i Ldot_i|, dE/dt by complex step of tests/energy.py."""
    worst = 0.0
    for k in range(len(x)):
        de_dt = energy(params, x[k] + 1j * H * xd[k], xd[k] + 1j * H * xdd[k]).imag / H
        power = tau[k] * leg_rates(params, x[k], xd[k])[2]
        worst = max(worst, abs(de_dt - power.sum()) / np.sum(np.abs(power)))
    return worst


def test_energy_conserved_in_free_motion(any_params, figures):
    """With tau = 0 the kernel's motion conserves E (tests/energy.py) over 1 s.

    Initial condition: a zero-gravity copy of the parameters (with gravity and no actuator
    force the platform would fall through the base within the second), the home pose and
    a twist of 0.15 x home height per second and 0.4 rad/s in a random direction: over the
    second the free platform coasts about 15% of its height and turns 0.4 rad while the
    legs' inertia bends its path. The test asserts that J_C stays well conditioned
    (cond < 1e3) on the whole path, so no leg nears a singular configuration.
    Integrated with the compiled forward dynamics and DOP853 (rtol 1e-12, atol 1e-15 of
    the state's scale); drift relative to the largest kinetic energy.
    """
    free = any_params.replace(gravity=0.0)
    plat = stewart.Platform(free)
    rng = np.random.default_rng(40)
    home = stewart.home_pose(free)
    direction = rng.normal(size=6)
    xd0 = np.concatenate(
        [
            direction[:3] / np.linalg.norm(direction[:3]) * 0.15 * home[2],
            direction[3:] / np.linalg.norm(direction[3:]) * 0.4,
        ]
    )
    zero = np.zeros(6)

    def rhs(_t, state):
        return np.concatenate([state[6:], plat.forward_dynamics(state[:6], state[6:], zero)])

    scale = np.concatenate([np.full(6, max(home[2], 1.0)), np.full(6, np.max(np.abs(xd0)))])
    sol = solve_ivp(
        rhs, (0.0, 1.0), np.concatenate([home, xd0]), method="DOP853", rtol=1e-12, atol=1e-15 * scale,
        t_eval=np.linspace(0.0, 1.0, 201),
    )
    assert sol.success, sol.message
    poses, rates = sol.y[:6].T, sol.y[6:].T
    assert np.max(np.linalg.cond(stewart.jacobian(free, poses))) < 1e3
    energies = np.array([energy(free, q, qd) for q, qd in zip(poses, rates)])
    kinetic = energies - np.array([potential_energy(free, q) for q in poses])
    drift = np.max(np.abs(energies - energies[0])) / np.max(kinetic)
    figures(f"kernel: energy drift, DOP853 1 s, tau = 0 ({any_params.name})", drift, 1e-8)


def test_power_balance(any_params, figures):
    """dE/dt = tau . Ldot at random states, tau from the compiled kernel."""
    rng = np.random.default_rng(41)
    x, xd, xdd = random_states(any_params, 60, rng)
    tau = stewart.Platform(any_params).inverse_dynamics(x, xd, xdd)
    figures(f"kernel: power balance (relative) ({any_params.name})", _power_balance(any_params, x, xd, xdd, tau), 1e-10)


def test_twist_mass_matrix_is_symmetric_positive_definite(any_params, figures):
    """M T^-1 = sum_b J_b^T I_b J_b is the kinetic energy's Hessian in twist space."""
    rng = np.random.default_rng(42)
    x, _, _ = random_states(any_params, 200, rng)
    m_twist = stewart.Platform(any_params).mass_matrix(x) @ np.linalg.inv(stewart.twist_transform(x))
    size = np.max(np.abs(m_twist), axis=(1, 2))
    asym = np.max(np.abs(m_twist - np.swapaxes(m_twist, 1, 2)), axis=(1, 2)) / size
    figures(f"kernel: twist mass matrix asymmetry ({any_params.name})", np.max(asym), 1e-13)
    eig = np.linalg.eigvalsh(0.5 * (m_twist + np.swapaxes(m_twist, 1, 2)))
    assert np.all(eig[:, 0] > 0.0)
    figures(f"kernel: twist mass matrix condition ({any_params.name})", np.max(eig[:, -1] / eig[:, 0]), 1e8)


# --- The paper's eq. 60 typo ------------------------------------------------------------


def _eq60_variant(params, x, xd, xdd):
    """Inverse dynamics with eq. 60 as printed: the piston's translational momentum built
    with J_B (the cylinder's centre-of-mass Jacobian) instead of J_G, i.e. the piston term
    J_G^T m_S J_B T xddot + J_G^T m_S d/dt(J_B T) xdot in place of the J_G^T m_S J_G T
    one; returns (correct tau from the same body terms, variant tau)."""
    terms = ref.body_terms(params, x, xd)
    total_m = sum(t.mass_matrix if b.startswith("platform") else t.mass_matrix.sum(axis=-3) for b, t in terms.items())
    total_v = sum(
        t.coriolis_matrix if b.startswith("platform") else t.coriolis_matrix.sum(axis=-3) for b, t in terms.items()
    )
    total_g = sum(
        t.gravity_vector if b.startswith("platform") else t.gravity_vector.sum(axis=-2) for b, t in terms.items()
    )

    def jb_t(pose):
        jacs = ref.partial_velocity_jacobians(params, pose)
        return jacs["cylinder_translation"] @ stewart.twist_transform(pose)[..., None, :, :]

    j_g_t = np.swapaxes(ref.partial_velocity_jacobians(params, x)["piston_translation"], -1, -2)
    wrong_m = params.piston_mass * (j_g_t @ jb_t(x)).sum(axis=-3)
    wrong_v = params.piston_mass * (j_g_t @ (jb_t(x + 1j * H * xd).imag / H)).sum(axis=-3)
    piston = terms["piston_translation"]
    variant_m = total_m - piston.mass_matrix.sum(axis=-3) + wrong_m
    variant_v = total_v - piston.coriolis_matrix.sum(axis=-3) + wrong_v

    jac_t = np.swapaxes(stewart.jacobian(params, x), -1, -2)

    def solve(m, v):
        wrench = np.einsum("...ij,...j->...i", m, xdd) + np.einsum("...ij,...j->...i", v, xd) + total_g
        return np.linalg.solve(jac_t, wrench[..., None])[..., 0]

    return solve(total_m, total_v), solve(variant_m, variant_v)


def _relative(got, want):
    return np.max(np.abs(got - want) / np.max(np.abs(want), axis=1, keepdims=True))


def test_eq60_typo_is_caught(any_params, figures):
    """Eq. 60 prints J_Bi where the piston's translation needs J_Gi. The model assembled
    with that typo must FAIL both the Newton-Euler comparison and the power balance, by
    orders of magnitude more than their tolerances, while the same assembly with J_G
    passes them."""
    rng = np.random.default_rng(43)
    x, xd, xdd = random_states(any_params, 40, rng)
    correct, variant = _eq60_variant(any_params, x, xd, xdd)
    newton = ne.inverse_dynamics(any_params, x, xd, xdd)

    figures(f"eq. 60 as fixed: vs newton-euler ({any_params.name})", _relative(correct, newton), 1e-9)
    figures(f"eq. 60 as fixed: power balance ({any_params.name})", _power_balance(any_params, x, xd, xdd, correct), 1e-10)
    np.testing.assert_allclose(correct, stewart.Platform(any_params).inverse_dynamics(x, xd, xdd), rtol=1e-9, atol=1e-9 * np.max(np.abs(correct)))

    typo_ne = _relative(variant, newton)
    typo_power = _power_balance(any_params, x, xd, xdd, variant)
    assert typo_ne > 1e4 * 1e-9, f"the eq. 60 typo went unnoticed by Newton-Euler: {typo_ne:.3e}"
    assert typo_power > 1e4 * 1e-10, f"the eq. 60 typo kept the power balance: {typo_power:.3e}"
    # Recorded as the margin: tolerance / typo's error (small means the typo is far out).
    figures(f"eq. 60 typo detected: NE tolerance / typo error ({any_params.name})", 1e-9 / typo_ne, 1e-4)
    figures(f"eq. 60 typo detected: power tolerance / typo error ({any_params.name})", 1e-10 / typo_power, 1e-4)


# --- stewart.validation ------------------------------------------------------------------


@pytest.mark.parametrize("name", PRESETS)
def test_validation_passes_on_presets(name, figures):
    params = stewart.PlatformParams.preset(name)
    checks = validation.run(params)
    assert len(checks) >= 10
    failed = [c for c in checks if not c.passed]
    assert not failed, validation.format_report(params, checks)
    for check in checks:
        if "condition" not in check.name:
            figures(f"validate {name}: {check.name}", check.worst, check.bound)
    report = validation.format_report(params, checks)
    assert name in report and f"all {len(checks)} checks passed" in report
    for check in checks:
        assert check.name in report


def test_validation_flags_non_axisymmetric_legs():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        params = random_params(np.random.default_rng(44), axisymmetric=False)
    checks = validation.run(params, n_states=50)
    failed = [c for c in checks if not c.passed]
    assert [c.name for c in failed] == ["legs axisymmetric (I_yy == I_zz); physics checks skipped"]
    assert all(c.passed for c in checks if c.name.startswith("kernel vs reference"))
    assert "1 of" in validation.format_report(params, checks) and "FAIL" in validation.format_report(params, checks)


def test_validation_energy_matches_the_test_oracle(any_params):
    rng = np.random.default_rng(45)
    x, xd, _ = random_states(any_params, 20, rng)
    batch = validation.energy(any_params, x, xd)
    oracle = np.array([energy(any_params, q, qd) for q, qd in zip(x, xd)])
    np.testing.assert_allclose(batch, oracle, rtol=1e-13)
    assert validation.energy(any_params, x[0], xd[0]).shape == ()


def test_validation_rejects_non_params():
    with pytest.raises(ValueError, match="^params: "):
        validation.run("narayan2017")
