"""The general model: legs that turn with their universal joints, an off-centre
payload with a full inertia tensor.

The kernel is checked against Lagrange's equations of the energy written out from the
bodies (:func:`stewart.oracles.physics.energy`, differentiated by complex step and polarization, not
by the derivation), against the paper's kernel where the two models coincide, and by the
energy it conserves and the power it balances.
"""

from __future__ import annotations

import numpy as np
import pytest

import stewart
from stewart.oracles import physics
from stewart.model import conditions, kinematics
from stewart.oracles import reference as ref
from stewart.oracles.physics import COMPLEX_STEP, random_states, relative_error

from conftest import random_params


def random_axes(rng):
    """Six random unit vectors, away from the legs (mostly horizontal, as built)."""
    axes = rng.normal(size=(6, 3)) * np.array([1.0, 1.0, 0.3])
    return axes / np.linalg.norm(axes, axis=1, keepdims=True)


def random_tensor(rng, scale):
    """A symmetric positive-definite tensor whose moments satisfy the triangle inequality."""
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    moments = scale * rng.uniform(0.6, 1.0, size=3)
    return q @ np.diag(moments) @ q.T


def random_general(seed):
    """A random platform with random joint axes, non-axisymmetric legs and an off-centre
    payload with a full tensor."""
    rng = np.random.default_rng(seed)
    params = random_params(rng, axisymmetric=False)
    size = np.max(np.abs(params.platform_points))
    return params.replace(universal_joint_axes=random_axes(rng),
                          platform_com=rng.normal(scale=0.2 * size, size=3),
                          platform_inertia=random_tensor(rng, np.max(params.platform_inertia)))


def _kinetic(params, x, xd):
    return physics.energy(params, x, xd) - physics.energy(params, x, np.zeros_like(xd))


def lagrange_mass_matrix(params, x):
    """M_L(x), the Hessian of the kinetic energy in xd, by polarization (exact for a
    quadratic form; complex x carried through), ``(N, 6, 6)``."""
    eye = np.eye(6)
    diag = np.stack([_kinetic(params, x, np.broadcast_to(eye[k], x.shape)) for k in range(6)], axis=-1)
    out = np.empty(x.shape[:-1] + (6, 6), dtype=np.result_type(x, float))
    for i in range(6):
        for j in range(6):
            pair = _kinetic(params, x, np.broadcast_to(eye[i] + eye[j], x.shape))
            out[..., i, j] = 2.0 * diag[..., i] if i == j else pair - diag[..., i] - diag[..., j]
    return out


def lagrange_forces(params, x, xd, xdd):
    """Q = d/dt dT/dxd - dT/dx + dV/dx, the generalized forces on the pose coordinates
    (Lagrange), with every x-derivative by complex step, ``(N, 6)``."""
    h = COMPLEX_STEP
    mass = lagrange_mass_matrix(params, x)
    dmass = [lagrange_mass_matrix(params, x + 1j * h * np.eye(6)[k]).imag / h for k in range(6)]
    mdot = sum(dmass[k] * xd[:, k, None, None] for k in range(6))
    quadratic = np.stack([np.einsum("ni,nij,nj->n", xd, dmass[k], xd) for k in range(6)], axis=-1)
    potential = np.stack([physics.energy(params, x + 1j * h * np.eye(6)[k], np.zeros_like(xd)).imag / h
                          for k in range(6)], axis=-1)
    return (np.einsum("nij,nj->ni", mass, xdd) + np.einsum("nij,nj->ni", mdot, xd)
            - 0.5 * quadratic + potential)


def kernel_forces(plat, x, xd, xdd):
    """T^T J_C^T tau of the kernel's inverse dynamics: its generalized forces on x."""
    tau = plat.inverse_dynamics(x, xd, xdd)
    wrench = np.einsum("nji,nj->ni", plat.jacobian(x), tau)
    return np.einsum("nji,nj->ni", kinematics.twist_transform(x), wrench)


def test_kernel_matches_the_reference(general_params, figures):
    """Every term of the general kernel against the numeric reference's general model."""
    plat = stewart.Platform(general_params)
    x, xd, xdd = random_states(general_params, 10, np.random.default_rng(12))
    tau = plat.inverse_dynamics(x, xd, xdd)
    worst = np.max([
        relative_error(tau, ref.inverse_dynamics(general_params, x, xd, xdd)),
        relative_error(plat.forward_dynamics(x, xd, tau), ref.forward_dynamics(general_params, x, xd, tau)),
        relative_error(plat.mass_matrix(x), ref.mass_matrix(general_params, x)),
        relative_error(plat.twist_mass_matrix(x), ref.twist_mass_matrix(general_params, x)),
        relative_error(plat.coriolis_vector(x, xd), ref.coriolis_vector(general_params, x, xd)),
        relative_error(plat.gravity_vector(x), ref.gravity_vector(general_params, x)),
    ])
    figures(f"general kernel vs reference ({general_params.name})", worst, 1e-13)  # reached 2.7e-15


def test_derivative_kernels_match_complex_step_of_the_reference(figures):
    params = random_general(3)
    plat = stewart.Platform(params)
    x, xd, xdd = random_states(params, 3, np.random.default_rng(3))
    tau = plat.inverse_dynamics(x, xd, xdd)
    inv = plat.inverse_dynamics_derivatives(x, xd, xdd)
    fwd = plat.forward_dynamics_derivatives(x, xd, tau)
    worst = np.max([relative_error(got, want) for out, oracle in (
        (inv, physics.reference_inverse_dynamics_jacobians(params, x, xd, xdd)),
        (fwd, physics.reference_forward_dynamics_jacobians(params, x, xd, tau))) for got, want in zip(out[1:], oracle)])
    figures("general kernel derivatives vs complex step of the reference", worst, 1e-11)  # reached 2.3e-13


def test_static_force_derivatives_match_complex_step_of_the_reference(figures):
    """The static forces of the general model and their ``dtau/dx``: the reference's inverse
    dynamics at ``xdot = xddot = 0`` complex-stepped, and the kernel's inverse dynamics derivatives
    there (the same to round-off: other orders of the same sums)."""
    params = random_general(4)
    plat = stewart.Platform(params)
    x = random_states(params, 20, np.random.default_rng(4))[0]
    rest = np.zeros_like(x)
    static = plat.static_force_derivatives(x)
    dynamic = plat.inverse_dynamics_derivatives(x, rest, rest)
    oracle = np.max([relative_error(static.tau, ref.inverse_dynamics(params, x, rest, rest)),
                     relative_error(static.dtau_dx, physics.reference_inverse_dynamics_jacobians(params, x, rest, rest)[0])])
    figures("general kernel static force derivatives vs complex step of the reference", oracle, 5e-14)  # reached 1.5e-15
    kernel = np.max([relative_error(static.tau, dynamic.tau), relative_error(static.dtau_dx, dynamic.dtau_dx)])
    figures("general kernel static force derivatives vs inverse dynamics at rest", kernel, 1e-13)  # reached 1.4e-15


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_inverse_dynamics_obeys_lagrange(seed, figures):
    params = random_general(seed)
    plat = stewart.Platform(params)
    x, xd, xdd = random_states(params, 4, np.random.default_rng(seed))
    err = relative_error(kernel_forces(plat, x, xd, xdd), lagrange_forces(params, x, xd, xdd))
    figures("general model: inverse dynamics vs Lagrange", err, 1e-13)  # reached 2.0e-15


def test_paper_model_obeys_lagrange_through_the_same_oracle(figures):
    """The oracle itself on the paper's model, which the paper's kernel is known to satisfy."""
    params = random_params(np.random.default_rng(5))
    plat = stewart.Platform(params)
    x, xd, xdd = random_states(params, 3, np.random.default_rng(5))
    figures("paper model: inverse dynamics vs Lagrange",
            relative_error(kernel_forces(plat, x, xd, xdd), lagrange_forces(params, x, xd, xdd)), 2e-13)  # reached 4.0e-15


def test_payload_without_joint_axes_keeps_the_paper_legs(figures):
    """An off-centre payload alone takes the general kernel with legs that do not spin."""
    rng = np.random.default_rng(7)
    with pytest.warns(stewart.NonAxisymmetricLegWarning):
        params = random_params(rng, axisymmetric=False).replace(platform_com=(0.01, -0.02, 0.03))
    assert not params.is_paper_model
    x, xd, xdd = random_states(params, 3, rng)
    plat = stewart.Platform(params)
    figures("payload without joint axes: inverse dynamics vs Lagrange",
            relative_error(kernel_forces(plat, x, xd, xdd), lagrange_forces(params, x, xd, xdd)), 1e-13)  # reached 3.0e-15


def test_any_joint_axes_reproduce_the_paper_model(figures):
    """With zero axial inertia and axisymmetric legs the spin carries no energy."""
    rng = np.random.default_rng(11)
    params = random_params(rng)
    params = params.replace(cylinder_inertia=(0.0, *params.cylinder_inertia[1:]),
                            piston_inertia=(0.0, *params.piston_inertia[1:]))
    paper, general = stewart.Platform(params), stewart.Platform(params.replace(universal_joint_axes=random_axes(rng)))
    x, xd, xdd = random_states(params, 5, rng)
    tau = paper.inverse_dynamics(x, xd, xdd)
    figures("general kernel, any axes, no axial inertia vs paper kernel", np.max([
        relative_error(general.inverse_dynamics(x, xd, xdd), tau),
        relative_error(general.forward_dynamics(x, xd, tau), paper.forward_dynamics(x, xd, tau)),
        relative_error(general.all_terms(x, xd)[0], paper.all_terms(x, xd)[0])]), 1e-13)  # reached 1.7e-15


@pytest.mark.parametrize("seed", [0, 3])
def test_power_balance(seed, figures):
    params = random_general(seed)
    plat = stewart.Platform(params)
    x, xd, xdd = random_states(params, 5, np.random.default_rng(seed))
    figures("general kernel: power balance", physics.power_balance(params, x, xd, xdd, plat.inverse_dynamics(x, xd, xdd)),
            2e-14)  # reached 6.0e-16


def test_forward_dynamics_inverts_inverse_dynamics(figures):
    params = random_general(4)
    plat = stewart.Platform(params)
    x, xd, xdd = random_states(params, 5, np.random.default_rng(4))
    figures("general kernel FD(ID(xdd)) vs xdd",
            relative_error(plat.forward_dynamics(x, xd, plat.inverse_dynamics(x, xd, xdd)), xdd), 1e-13)  # reached 1.9e-15


def test_batch_matches_single_states(simd_path):
    params = random_general(6)
    plat = stewart.Platform(params)
    x, xd, xdd = random_states(params, 24, np.random.default_rng(6))
    batch = plat.inverse_dynamics(x, xd, xdd)
    single = np.stack([plat.inverse_dynamics(*row) for row in zip(x, xd, xdd)])
    np.testing.assert_array_equal(batch, single)
    terms = plat.forward_dynamics(x, xd, batch)
    np.testing.assert_array_equal(terms, np.stack([plat.forward_dynamics(*row) for row in zip(x, xd, batch)]))


def test_gimbal_lock_is_flagged_per_state():
    params = random_general(8)
    plat = stewart.Platform(params)
    x, xd, xdd = random_states(params, 3, np.random.default_rng(8))
    legs = kinematics.leg_vectors(params, x[1])
    axes = np.array(params.universal_joint_axes)
    axes[2] = legs[2] / np.linalg.norm(legs[2])
    locked = stewart.Platform(params.replace(universal_joint_axes=axes))
    with pytest.raises(stewart.SingularityError) as err:
        locked.inverse_dynamics(x[1], xd[1], xdd[1])
    assert err.value.condition == "gimbal_lock"
    tau, ok = locked.inverse_dynamics(x, xd, xdd, return_mask=True)
    assert ok.tolist() == [True, False, True] and np.isnan(tau[1]).all() and np.isfinite(tau[[0, 2]]).all()
    # The numpy test of stewart.model.conditions agrees, row by row.
    legs = kinematics.leg_vectors(params, x)
    codes = conditions.leg_codes(np.sum(legs * legs, axis=-1), None,
                                 np.sum(np.cross(axes, legs) ** 2, axis=-1))
    assert codes.tolist() == [conditions.Status.OK, conditions.Status.GIMBAL_LOCK, conditions.Status.OK]


def _central_difference(function, point, step):
    """Columns ``(f(p + s e_j) - f(p - s e_j)) / 2s``, ``(N, m, n)``."""
    columns = []
    for j in range(point.shape[-1]):
        shift = np.zeros_like(point)
        shift[:, j] = step[j]
        columns.append((function(point + shift) - function(point - shift)) / (2 * step[j]))
    return np.stack(columns, axis=-1)


@pytest.mark.parametrize("seed", [0, 9])
def test_derivative_kernels_match_differences_of_the_values(seed, figures):
    """The general family's derivative kernels against central differences of its inverse
    and forward dynamics (which Lagrange's equations check above): exact up to round-off in
    xd, xdd and tau (tau is quadratic in xd, linear in xdd; xdd linear in tau), about 1e-9
    in x with steps of 1e-5."""
    params = random_general(seed)
    plat = stewart.Platform(params)
    x, xd, xdd = random_states(params, 4, np.random.default_rng(seed))
    tau = plat.inverse_dynamics(x, xd, xdd)
    pose = np.array([1e-5 * stewart.home_pose(params)[2]] * 3 + [1e-5] * 3)
    rate, acc, force = (np.std(a, axis=0) for a in (xd, xdd, tau))
    inv = plat.inverse_dynamics_derivatives(x, xd, xdd)
    fwd = plat.forward_dynamics_derivatives(x, xd, tau)
    exact = np.max([
        relative_error(inv.dtau_dxd, _central_difference(lambda v: plat.inverse_dynamics(x, v, xdd), xd, rate)),
        relative_error(inv.dtau_dxdd, _central_difference(lambda a: plat.inverse_dynamics(x, xd, a), xdd, acc)),
        relative_error(fwd.dxdd_dtau, _central_difference(lambda t: plat.forward_dynamics(x, xd, t), tau, force)),
    ])
    in_pose = np.max([
        relative_error(inv.dtau_dx, _central_difference(lambda p: plat.inverse_dynamics(p, xd, xdd), x, pose)),
        relative_error(fwd.dxdd_dx, _central_difference(lambda p: plat.forward_dynamics(p, xd, tau), x, pose)),
        relative_error(fwd.dxdd_dxd, _central_difference(lambda v: plat.forward_dynamics(x, v, tau), xd, pose)),
    ])
    figures("general model: derivative kernels vs exact differences", exact, 5e-12)  # reached 1.4e-13
    figures("general model: derivative kernels vs differences in x", in_pose, 2e-8)  # reached 5.7e-10
    # reached 0 and 3.2e-15
    assert relative_error(inv.tau, tau) <= 1e-14 and relative_error(fwd.xdd, xdd) <= 2e-13


def test_energy_is_conserved_with_no_forces(figures):
    """tau = 0 in zero gravity (physics.energy_drift, DOP853 on the kernel's forward
    dynamics), with spinning non-axisymmetric legs and an off-centre payload."""
    pytest.importorskip("scipy")
    figures("general kernel: energy drift, DOP853 1 s, tau = 0", physics.energy_drift(random_general(1), 1.0, seed=1), 5e-12)  # reached 1.1e-13


def test_energy_is_conserved_under_gravity_by_the_rk4_step(figures):
    """The package's RK4 step at 1e-4 s over 0.05 s with tau = 0 and gravity: the energy
    (potential included) is kept to the step's truncation error. The energies of the 500
    states are evaluated in one batch."""
    params = random_general(2)
    plat = stewart.Platform(params)
    x, xd = plat.home_pose, np.zeros(6)
    start = physics.energy(params, x, xd)
    path = []
    for _ in range(500):
        x, xd = plat.rk4_step(x, xd, np.zeros(6), 1e-4)[:2]
        path.append(np.concatenate([x, xd]))
    path = np.array(path)
    kinetic = float(np.max(_kinetic(params, path[:, :6], path[:, 6:])))
    worst = float(np.max(np.abs(physics.energy(params, path[:, :6], path[:, 6:]) - start)))
    assert kinetic > 0.0
    figures("general kernel: energy change over RK4 steps, relative to the kinetic energy", worst / kinetic, 2e-12)  # reached 5.5e-14
