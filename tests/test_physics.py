"""The compiled kernel against physics: energy conservation in free motion, the power
balance, a symmetric positive-definite twist-space mass matrix; a check that these
tests catch the paper's eq. 60 typo; and stewart.oracles.validation on every preset."""

import warnings

import numpy as np
import pytest

import stewart
from stewart.oracles import frames
from stewart.oracles import newton_euler as ne
from stewart.oracles import reference as ref
from stewart.oracles import validation
from stewart.oracles.physics import COMPLEX_STEP as H
from stewart.oracles.physics import energy, energy_drift, power_balance, relative_error, twist_mass_matrix_figures
from conftest import PRESETS, random_params, random_states


def test_energy_conserved_in_free_motion(any_params, figures):
    """With tau = 0 the kernel's motion conserves E (:func:`stewart.oracles.physics.energy`) over 1 s
    (:func:`stewart.oracles.physics.energy_drift`: zero gravity, a modest twist from home, DOP853
    at rtol 1e-12; ``inf`` if the path nears a singular pose); drift relative to the
    largest kinetic energy."""
    drift = energy_drift(any_params, seconds=1.0, seed=40)
    figures(f"kernel: energy drift, DOP853 1 s, tau = 0 ({any_params.name})", drift, 5e-11)  # reached 1.2e-12


def test_power_balance(any_params, figures):
    """dE/dt = tau . Ldot at random states, tau from the compiled kernel."""
    rng = np.random.default_rng(41)
    x, xd, xdd = random_states(any_params, 60, rng)
    tau = stewart.Platform(any_params).inverse_dynamics(x, xd, xdd)
    figures(f"kernel: power balance (relative) ({any_params.name})", power_balance(any_params, x, xd, xdd, tau), 5e-14)  # reached 1.1e-15


def test_twist_mass_matrix_is_symmetric_positive_definite(any_params, figures):
    """M_t = sum_b J_b^T I_b J_b is the kinetic energy's Hessian in twist space, and M = M_t T."""
    rng = np.random.default_rng(42)
    x, _, _ = random_states(any_params, 200, rng)
    mismatch, cond = twist_mass_matrix_figures(stewart.Platform(any_params), x)
    figures(f"kernel: twist mass matrix M_t T vs M ({any_params.name})", mismatch, 2e-15)  # reached 6.5e-17
    assert np.isfinite(cond), "M_t is not positive definite"
    # not an error but a verdict: finite and under 1e8, M_t is well inside positive definite (reached 73)
    figures(f"kernel: twist mass matrix condition ({any_params.name})", cond, 1e8)


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
        return jacs["cylinder_translation"] @ frames.twist_transform(pose)[..., None, :, :]

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


def test_eq60_typo_is_caught(any_params, figures):
    """Eq. 60 prints J_Bi where the piston's translation needs J_Gi. The model assembled
    with that typo must FAIL both the Newton-Euler comparison and the power balance, by
    orders of magnitude more than their tolerances, while the same assembly with J_G
    passes them."""
    rng = np.random.default_rng(43)
    x, xd, xdd = random_states(any_params, 40, rng)
    correct, variant = _eq60_variant(any_params, x, xd, xdd)
    newton = ne.inverse_dynamics(any_params, x, xd, xdd)
    ne_tolerance, power_tolerance = 5e-14, 2e-14  # reached 1.1e-15 and 6.5e-16

    figures(f"eq. 60 as fixed: vs newton-euler ({any_params.name})", relative_error(correct, newton), ne_tolerance)
    figures(f"eq. 60 as fixed: power balance ({any_params.name})", power_balance(any_params, x, xd, xdd, correct),
            power_tolerance)
    figures(f"eq. 60 as fixed: vs the kernel ({any_params.name})",
            relative_error(correct, stewart.Platform(any_params).inverse_dynamics(x, xd, xdd)), 5e-14)  # reached 1.1e-15

    # Recorded as the margin: tolerance / typo's error (small means the typo is far out): the
    # typo misses both checks by more than 10^10 times their tolerance (reached 1.0e-12).
    typo_ne = relative_error(variant, newton)
    typo_power = power_balance(any_params, x, xd, xdd, variant)
    figures(f"eq. 60 typo detected: NE tolerance / typo error ({any_params.name})", ne_tolerance / typo_ne, 1e-10)
    figures(f"eq. 60 typo detected: power tolerance / typo error ({any_params.name})", power_tolerance / typo_power,
            1e-10)


# --- stewart.oracles.validation ------------------------------------------------------------------


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


def test_validation_runs_every_check_on_the_general_model(general_params):
    """Legs that turn with their joints, non-axisymmetric legs and an off-centre payload with a
    full tensor: the physics checks run (the statics take moments about the payload's centre of
    mass) and all pass."""
    checks = validation.run(general_params, n_states=40)
    assert any(c.name.startswith("statics: platform moment") for c in checks)
    assert any(c.name.startswith("power balance") for c in checks)
    failed = [c for c in checks if not c.passed]
    assert not failed, validation.format_report(general_params, checks)


def test_validation_flags_non_axisymmetric_legs():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        params = random_params(np.random.default_rng(44), axisymmetric=False)
    checks = validation.run(params, n_states=50)
    failed = [c for c in checks if not c.passed]
    assert [c.name for c in failed] == ["legs axisymmetric (I_yy == I_zz); physics checks skipped"]
    assert all(c.passed for c in checks if c.name.startswith("kernel vs reference"))
    assert "1 of" in validation.format_report(params, checks) and "FAIL" in validation.format_report(params, checks)


def test_kinetic_energy_is_the_twist_mass_matrix_quadratic_form(any_params, figures):
    """The energy written out from the bodies less its potential part (the same pose at
    rest) is ``t . M_t t / 2`` with the twist ``t = T xdot`` and the kernel's twist-space
    mass matrix ``M_t = M T^-1``, so ``t . M_t t = (T xdot) . (M xdot)``; batches and
    single states agree."""
    rng = np.random.default_rng(45)
    x, xd, _ = random_states(any_params, 20, rng)
    kinetic = energy(any_params, x, xd) - energy(any_params, x, np.zeros_like(xd))
    twist = np.einsum("nij,nj->ni", stewart.twist_transform(x), xd)
    wrench = np.einsum("nij,nj->ni", stewart.Platform(any_params).mass_matrix(x), xd)
    quadratic = 0.5 * np.einsum("ni,ni->n", twist, wrench)
    worst = relative_error(kinetic[:, None], quadratic[:, None])
    figures(f"energy: kinetic part vs (T xdot).(M xdot)/2 ({any_params.name})", worst, 1e-12)  # reached 3.9e-14
    assert energy(any_params, x[0], xd[0]).shape == ()
    assert energy(any_params, x[0], xd[0]) == pytest.approx(energy(any_params, x, xd)[0], rel=1e-14)


def test_validation_rejects_non_params():
    with pytest.raises(ValueError, match="^params: "):
        validation.run("narayan2017")
