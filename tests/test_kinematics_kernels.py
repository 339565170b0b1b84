"""The model's kinematics come from the derivation in codegen/: the generated rotation and its
partials, J_A and J_A^-1, the leg vectors, unit vectors and their pose gradients and the modal
stiffness, against the oracles' own numpy kinematics (stewart.oracles.frames), complex-step
derivatives of them and the formulas the package used before (kept here as oracles); and the
public functions of stewart.model.kinematics, now on the kernels, against the same oracles."""

import numpy as np
import pytest

import codegen.model
import stewart
from stewart import _generated
from stewart.model import kinematics
from stewart.oracles import frames
from stewart.oracles.physics import COMPLEX_STEP, relative_error
from conftest import random_params, random_states
from simd_paths import calls

#: Each quantity of the kinematics the table must hold: {function: its outputs' (name, row shape)}.
KINEMATICS = {
    "rotation": (("R", (3, 3)),),
    "rotation_partials": (("R", (3, 3)), ("dR_dpsi", (3, 3)), ("dR_dtheta", (3, 3)), ("dR_dphi", (3, 3))),
    "euler_rate_jacobian": (("JA", (3, 3)),),
    "euler_rate_jacobian_partials": (("JA", (3, 3)), ("dJA_dpsi", (3, 3)), ("dJA_dtheta", (3, 3)), ("dJA_dphi", (3, 3))),
    "inverse_euler_rate_jacobian": (("JAinv", (3, 3)),),
    "leg_vectors": (("l", (6, 3)),),
    "leg_unit_vectors": (("u", (6, 3)),),
    "leg_unit_vector_gradients": (("u", (6, 3)), ("du_dx", (6, 3, 6))),
    "modal_stiffness": (("Kt", (6, 6)), ("JC", (6, 6)), ("Mt", (6, 6))),
}


def test_the_table_holds_each_quantity_of_the_kinematics():
    """Each is a FUNCTIONS entry with a kernel of the derivation (no template), a batch
    function in the compiled table, and a Platform method."""
    table = {f.name: f for f in codegen.model.FUNCTIONS}
    for name, outputs in KINEMATICS.items():
        assert table[name].outputs == outputs, name
        assert not table[name].template and (table[name].kernels or table[name].steps), name
        assert hasattr(stewart.Platform, _generated.FUNCTIONS[name].method), name
    assert table["modal_stiffness"].inputs == ("x", "k")


def test_the_bit_for_bit_checks_cover_them():
    """tests/simd_paths.py's calls (test_bitwise, test_build: every path, alone and in batches, on
    threads) include each function of the kinematics."""
    assert set(KINEMATICS) <= set(calls(None, None, None, None, None))


@pytest.fixture(scope="module")
def states():
    params = random_params(np.random.default_rng(41), axisymmetric=False)
    x = random_states(params, 200, np.random.default_rng(42))[0]
    return stewart.Platform(params), x


def _complex_step(f, x, j):
    """d f / d x_j by complex step."""
    moved = x.astype(complex)
    moved[..., j] += 1j * COMPLEX_STEP
    return f(moved).imag / COMPLEX_STEP


def test_rotation_and_its_partials(states, figures):
    plat, x = states
    rot, *partials = plat.rotation(x, partials=True)
    np.testing.assert_array_equal(rot, plat.rotation(x))
    figures("rotation against the oracle's", np.max(np.abs(rot - frames.rotation(x))), 1e-14)  # reached 1.1e-16
    worst = max(np.max(np.abs(d - _complex_step(frames.rotation, x, 3 + k))) for k, d in enumerate(partials))
    figures("rotation partials against complex step", worst, 1e-14)  # reached 3.3e-16
    np.testing.assert_allclose(rot @ np.swapaxes(rot, -1, -2), np.broadcast_to(np.eye(3), rot.shape), atol=1e-15)


def test_euler_rate_jacobian_and_its_inverse(states, figures):
    plat, x = states
    j_a = plat.euler_rate_jacobian(x)
    figures("J_A against the oracle's", np.max(np.abs(j_a - frames.euler_rate_jacobian(x))), 1e-14)  # reached 1.1e-16
    same, *partials = plat.euler_rate_jacobian(x, partials=True)
    np.testing.assert_array_equal(same, j_a)
    worst = max(np.max(np.abs(d - _complex_step(frames.euler_rate_jacobian, x, 3 + k))) for k, d in enumerate(partials))
    figures("J_A partials against complex step", worst, 1e-14)  # reached 1.1e-16
    inverse = plat.inverse_euler_rate_jacobian(x)
    figures("J_A^-1 J_A - I", np.max(np.abs(inverse @ j_a - np.eye(3))), 2e-14)  # reached 2.2e-16
    # J_A itself is defined at theta = 90 deg; its inverse is not.
    upright = np.array([0.0, 0.0, 1.0, 0.3, np.pi / 2, 0.1])
    assert np.isfinite(plat.euler_rate_jacobian(upright)).all()
    with pytest.raises(stewart.SingularityError, match="Euler-rate map"):
        plat.inverse_euler_rate_jacobian(upright)
    assert plat.inverse_euler_rate_jacobian(upright, return_mask=True)[1] is False


def test_leg_vectors_unit_vectors_and_their_gradients(states, figures):
    plat, x = states
    legs = plat.leg_vectors(x)
    figures("leg vectors against the oracle's", relative_error(legs, frames.leg_vectors(plat.params, x)), 1e-14)  # reached 2.7e-16
    units, gradients = plat.leg_unit_vectors(x, gradients=True)
    np.testing.assert_array_equal(units, plat.leg_unit_vectors(x))
    figures("unit vectors against the oracle's J_C", np.max(np.abs(units - frames.jacobian(plat.params, x)[..., :3])),
            1e-14)  # reached 3.3e-16

    def oracle_units(poses):
        legs = frames.leg_vectors(plat.params, poses)
        return legs / np.sqrt(np.sum(legs * legs, axis=-1))[..., None]

    expected = np.stack([_complex_step(oracle_units, x, j) for j in range(6)], axis=-1)
    figures("unit vectors' gradients against complex step", relative_error(gradients, expected), 1e-13)  # reached 9.6e-16
    # A zero-length leg: its vector is zero, its unit vector undefined.
    collapsed = np.r_[plat.params.base_points[0] - plat.params.platform_points[0], 0.0, 0.0, 0.0]
    assert np.all(plat.leg_vectors(collapsed)[0] == 0.0)
    with pytest.raises(stewart.SingularityError):
        plat.leg_unit_vectors(collapsed)


def _stiffness_oracle(jac, dtau_dx, j_a, k):
    """``K_t = J_C^T (diag(k) J_C + dtau_s/dx T^-1)`` in numpy, as stewart/_modes.pxi formed it."""
    t_inv = np.zeros(jac.shape)
    t_inv[..., :3, :3] = np.eye(3)
    t_inv[..., 3:, 3:] = np.linalg.inv(j_a)
    return np.swapaxes(jac, -1, -2) @ (k[:, None] * jac + dtau_dx @ t_inv)


def test_modal_stiffness_against_its_formula(states, figures):
    plat, x = states
    k = np.linspace(1e6, 3e6, 6)
    stiffness, jac, mass = plat.modal_stiffness(x, k)
    np.testing.assert_array_equal(jac, plat.jacobian(x))
    np.testing.assert_array_equal(mass, plat.twist_mass_matrix(x))
    expected = _stiffness_oracle(jac, plat.static_force_derivatives(x).dtau_dx, frames.euler_rate_jacobian(x), k)
    figures("modal stiffness against its formula", relative_error(stiffness, expected), 3e-14)  # reached 3.5e-16
    # One set of stiffnesses per state gives each state's own.
    per_state = np.tile(k, (len(x), 1)) * np.linspace(1, 2, len(x))[:, None]
    each = plat.modal_stiffness(x, per_state).Kt
    np.testing.assert_array_equal(each[3], plat.modal_stiffness(x[3], per_state[3]).Kt)
    with pytest.raises(stewart.SingularityError, match="Euler-rate map"):
        plat.modal_stiffness(np.r_[x[0, :4], np.pi / 2, x[0, 5]], k)


def test_the_kinematics_functions_keep_their_results(states, figures):
    """stewart.model.kinematics, now on the kernels, against the oracles' numpy (the formulas
    of the functions before), one state and a batch."""
    plat, x = states
    params = plat.params
    xd, xdd = random_states(params, len(x), np.random.default_rng(43))[1:]
    pairs = {
        "rotation": (kinematics.rotation(x), frames.rotation(x)),
        "euler_rate_jacobian": (kinematics.euler_rate_jacobian(x), frames.euler_rate_jacobian(x)),
        "twist_transform": (kinematics.twist_transform(x), frames.twist_transform(x)),
        "leg_vectors": (kinematics.leg_vectors(params, x), frames.leg_vectors(params, x)),
        "leg_lengths": (kinematics.leg_lengths(params, x), frames.leg_lengths(params, x)),
        "leg_unit_vectors": (kinematics.leg_unit_vectors(params, x), frames.jacobian(params, x)[..., :3]),
        "jacobian": (kinematics.jacobian(params, x), frames.jacobian(params, x)),
        "euler_jacobian": (kinematics.euler_jacobian(params, x), frames.jacobian(params, x) @ frames.twist_transform(x)),
        "leg_velocities": (kinematics.leg_velocities(params, x, xd), frames.leg_velocities(params, x, xd)),
        "leg_accelerations": (kinematics.leg_accelerations(params, x, xd, xdd),
                              frames.leg_accelerations(params, x, xd, xdd)),
    }
    worst = 0.0
    for name, (got, want) in pairs.items():
        assert got.shape == want.shape, name
        worst = np.maximum(worst, relative_error(got, want))
    figures("kinematics functions against the oracles' numpy", worst, 5e-14)  # reached 7.5e-16
    assert kinematics.jacobian(params, x[0]).shape == (6, 6) and kinematics.rotation(x[0]).shape == (3, 3)
    np.testing.assert_array_equal(kinematics.jacobian(plat, x), plat.jacobian(x))
    lengths = plat.leg_lengths(x[:20])
    poses = kinematics.forward_kinematics(params, lengths, x[:20] + 1e-3)
    figures("forward kinematics round trip", np.max(np.abs(poses - x[:20])), 1e-10)  # reached 1.6e-12 (tol 1e-12 of the lengths)
    with pytest.raises(ValueError, match="^x: "):
        kinematics.rotation(np.full(5, 0.1))


def test_the_orientation_takes_a_complex_step(states, figures):
    """rotation, euler_rate_jacobian and twist_transform of x + i h d: the complex step of the
    oracles' numpy (f(x) + i h df/dx d to round-off); an imaginary part beyond a step is refused."""
    x = states[1][:50]
    d = np.random.default_rng(44).normal(size=x.shape)
    moved = x + 1j * COMPLEX_STEP * d
    worst = 0.0
    for name in ("rotation", "euler_rate_jacobian", "twist_transform"):
        got, want = getattr(kinematics, name)(moved), getattr(frames, name)(moved)
        np.testing.assert_array_equal(got.real, getattr(kinematics, name)(x))
        worst = np.maximum(worst, relative_error(got.imag / COMPLEX_STEP, want.imag / COMPLEX_STEP))
    figures("orientation's complex step against the oracles'", worst, 1e-14)  # reached 4.0e-16
    with pytest.raises(ValueError, match="^x: a complex pose is taken as a complex step"):
        kinematics.rotation(x[0] + 1e-3j)


def test_a_kernel_is_built_once_for_the_same_parameters():
    params = stewart.PlatformParams.preset("narayan2017")
    other = stewart.PlatformParams.preset("motion_simulator")
    x = stewart.home_pose(params)
    first = kinematics.leg_lengths(params, x)
    np.testing.assert_array_equal(kinematics.leg_lengths(other, stewart.home_pose(other)),
                                  stewart.Platform(other).leg_lengths(stewart.home_pose(other)))
    np.testing.assert_array_equal(kinematics.leg_lengths(params, x), first)
