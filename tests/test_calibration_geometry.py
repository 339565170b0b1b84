"""The calibration's generated functions (Platform.leg_residuals, leg_residual_jacobians,
target_positions, target_jacobian, and stewart.calibration.geometry through them) against the
numpy formulas the calibration computed them with before they were generated, kept here as
the oracle: their values, and the Jacobians against complex-step derivatives of the oracle's
residuals (exact to rounding) and central differences of the generated residuals."""

import numpy as np
import pytest

import stewart
from stewart.calibration import geometry, perturbed_geometry

NOMINAL = stewart.PlatformParams.preset("narayan2017")


# ---- the oracle: the numpy calibration geometry of 0.2 (analytic operations only, so complex-step
# derivatives go through it) -------------------------------------------------------------------


def _rotation(poses):
    """``R = Rz(psi) Ry(theta) Rx(phi)`` (K, 3, 3), written out element by element."""
    cz, sz = np.cos(poses[:, 3]), np.sin(poses[:, 3])
    cy, sy = np.cos(poses[:, 4]), np.sin(poses[:, 4])
    cx, sx = np.cos(poses[:, 5]), np.sin(poses[:, 5])
    return np.stack([np.stack([cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx], -1),
                     np.stack([sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx], -1),
                     np.stack([-sy, cy * sx, cy * cx], -1)], -2)


def _euler_rates(poses):
    """``J_A`` (K, 3, 3): omega = J_A (psi', theta', phi') (eq. 8)."""
    cz, sz, cy, sy = np.cos(poses[:, 3]), np.sin(poses[:, 3]), np.cos(poses[:, 4]), np.sin(poses[:, 4])
    zero, one = np.zeros_like(cz), np.ones_like(cz)
    return np.stack([np.stack([zero, -sz, cz * cy], -1), np.stack([zero, cz, sz * cy], -1),
                     np.stack([one, zero, -sy], -1)], -2)


def _oracle_legs(theta, poses):
    base, platform = theta[:18].reshape(6, 3), theta[18:36].reshape(6, 3)
    rot = _rotation(poses)
    arms = np.einsum("kab,ib->kia", rot, platform)
    return rot, arms, poses[:, None, :3] + arms - base


def _oracle_residuals(theta, poses, readings):
    _, _, legs = _oracle_legs(theta, poses)
    return readings + theta[36:42] - np.sqrt(np.sum(legs * legs, axis=-1))


def _oracle_pose_jacobian(theta, poses):
    _, arms, legs = _oracle_legs(theta, poses)
    units = legs / np.sqrt(np.sum(legs * legs, axis=-1))[..., None]
    return -np.concatenate([units, np.einsum("kia,kab->kib", np.cross(arms, units), _euler_rates(poses))], axis=-1)


def _oracle_targets(poses, offsets):
    return poses[:, :3] + np.einsum("kab,kb->ka", _rotation(poses), offsets)


def _complex_step(function, point, h=1e-30):
    """The columns d function / d point_k, exact to rounding."""
    columns = []
    for k in range(point.size):
        z = point.astype(complex)
        z.flat[k] += 1j * h
        columns.append(np.imag(function(z)) / h)
    return np.stack(columns, axis=-1)


@pytest.fixture(scope="module")
def case():
    """A built machine's geometry (offsets of millimetres), random poses about home and readings
    off the machine's by micrometres."""
    built = perturbed_geometry(NOMINAL, seed=4)
    rng = np.random.default_rng(3)
    poses = stewart.home_pose(NOMINAL) + rng.uniform(-1, 1, (40, 6)) * np.array([0.02] * 3 + [0.2] * 3)
    readings = stewart.encoder_readings(built, poses) + rng.normal(0.0, 1e-6, (40, 6))
    return built, poses, readings


def test_the_residuals_and_targets_are_the_oracles(case, figures):
    built, poses, readings = case
    theta = geometry.parameter_vector(built)
    plat = stewart.Platform(built)
    residuals = plat.leg_residuals(poses, readings)
    # differences of 0.3 m lengths: a few roundings of them (reached 1.1e-16 m)
    figures("calibration residuals against the numpy oracle [m]",
            np.max(np.abs(residuals - _oracle_residuals(theta, poses, readings))), 1e-14)
    np.testing.assert_array_equal(geometry.leg_residuals(theta, poses, readings), residuals)
    offsets = np.random.default_rng(5).uniform(-0.05, 0.05, (len(poses), 3))
    targets = plat.target_positions(poses, offsets)
    figures("calibration target positions against the numpy oracle [m]",
            np.max(np.abs(targets - _oracle_targets(poses, offsets))), 2e-15)  # reached 5.6e-17 m
    np.testing.assert_array_equal(geometry.target_positions(poses, offsets), targets)
    # one state is the batch's row, and a target's offset (3,) broadcasts against the poses
    np.testing.assert_array_equal(plat.target_positions(poses[7], offsets[7]), targets[7])
    np.testing.assert_array_equal(plat.target_positions(poses[:3], offsets[0]),
                                  plat.target_positions(poses[:3], np.tile(offsets[0], (3, 1))))


def test_the_jacobians_are_complex_step_derivatives_of_the_oracle(case, figures):
    built, poses, readings = case
    theta = geometry.parameter_vector(built)
    exact = geometry.leg_jacobian(theta, poses)
    numeric = _complex_step(lambda z: _oracle_residuals(z, poses, readings), theta)
    # complex step is exact to rounding (h = 1e-30): entries of unit size (reached 4.4e-16)
    figures("calibration dr/dtheta against complex step of the oracle", np.max(np.abs(exact - numeric)), 2e-14)
    assert np.count_nonzero(exact[0]) == 42  # 7 a leg: the scatter puts each where it belongs
    by_pose = np.stack([_complex_step(lambda z: _oracle_residuals(theta, z[None], readings[k:k + 1])[0], poses[k])
                        for k in range(len(poses))])
    pose_jacobian = geometry.leg_pose_jacobian(theta, poses)
    # reached 3.3e-16 (entries up to 0.2 m per rad)
    figures("calibration dr/dx against complex step of the oracle", np.max(np.abs(pose_jacobian - by_pose)), 1e-14)
    np.testing.assert_allclose(pose_jacobian, _oracle_pose_jacobian(theta, poses), rtol=0, atol=1e-14)
    offsets = np.array([0.01, -0.02, 0.03])
    target = np.stack([_complex_step(lambda z: -_oracle_targets(z[None], offsets[None])[0], pose) for pose in poses])
    # the target's columns are its offsets', centimetres (reached 1.4e-17)
    figures("calibration target d(q - t - R c)/dx against complex step of the oracle",
            np.max(np.abs(geometry.target_pose_jacobian(poses, np.tile(offsets, (len(poses), 1))) - target)), 4e-16)


def test_the_jacobians_are_central_differences_of_the_generated_residuals(case, figures):
    """Independent of the oracle: the generated residuals' central differences (step 1e-6 m or
    rad: truncation h^2 |r'''| / 6 ~ 1e-13 and rounding 1e-16 / h ~ 1e-10 of the unit entries;
    reached 4.0e-11, 5.5e-11 and 2.7e-11)."""
    built, poses, readings = case
    theta, h = geometry.parameter_vector(built), 1e-6
    plat = stewart.Platform(built)
    jac = plat.leg_residual_jacobians(poses[:5])
    dense = geometry.leg_jacobian(theta, poses[:5])
    steps = np.eye(42) * h
    numeric = np.stack([geometry.leg_residuals(theta + s, poses[:5], readings[:5])
                        - geometry.leg_residuals(theta - s, poses[:5], readings[:5]) for s in steps], -1) / (2 * h)
    figures("calibration dr/dtheta against central differences", np.max(np.abs(dense - numeric)), 2e-9)
    steps = np.eye(6) * h
    numeric = np.stack([plat.leg_residuals(poses[:5] + s, readings[:5])
                        - plat.leg_residuals(poses[:5] - s, readings[:5]) for s in steps], -1) / (2 * h)
    figures("calibration dr/dx against central differences", np.max(np.abs(jac.dr_dx - numeric)), 2e-9)
    offsets = np.array([0.01, -0.02, 0.03])
    numeric = np.stack([plat.target_positions(poses[:5] + s, offsets) - plat.target_positions(poses[:5] - s, offsets)
                        for s in steps], -1) / (2 * h)
    figures("calibration target dq/dx against central differences",
            np.max(np.abs(plat.target_jacobian(poses[:5], offsets) - numeric)), 1e-9)


def test_the_compact_block_is_the_legs_own_partials(case):
    """The 7 partials of each leg by hand from its unit vector: u_i, -R^T u_i, 1."""
    built, poses, _ = case
    plat = stewart.Platform(built)
    block = plat.leg_residual_jacobians(poses[0]).dr_dtheta
    legs = stewart.leg_vectors(built, poses[0])
    units = legs / np.linalg.norm(legs, axis=1)[:, None]
    want = np.column_stack([units, -units @ _rotation(poses[:1])[0], np.ones(6)])
    np.testing.assert_allclose(block, want, rtol=0, atol=1e-15)  # reached 1.1e-16


def test_bad_inputs_are_named_and_a_zero_leg_is_a_singularity():
    plat = stewart.Platform(NOMINAL)
    home = plat.home_pose
    with pytest.raises(ValueError, match=r"^offsets: expected shape \(3,\) or \(N, 3\), got \(6,\)$"):
        plat.target_positions(home, np.zeros(6))
    with pytest.raises(ValueError, match="readings"):
        plat.leg_residuals(home, [np.nan] * 6)
    with pytest.raises(ValueError, match="offsets"):
        plat.target_jacobian(home, [0.0, np.inf, 0.0])
    with pytest.raises(ValueError, match=r"^theta: expected the 42 geometric parameters, got shape \(41,\)$"):
        geometry.leg_residuals(np.zeros(41), home[None], np.zeros((1, 6)))
    with pytest.raises(ValueError, match="^theta: expected real numbers, got complex numbers$"):
        geometry.leg_jacobian(geometry.parameter_vector(NOMINAL) + 0j, home[None])
    # platform point 0 on base point 0: leg 0 has zero length, its unit vector none
    degenerate = np.r_[NOMINAL.base_points[0] - NOMINAL.platform_points[0], 0.0, 0.0, 0.0]
    np.testing.assert_array_equal(plat.leg_residuals(degenerate, np.zeros(6))[0], 0.0)
    with pytest.raises(stewart.SingularityError):
        plat.leg_residual_jacobians(degenerate)
    (block, pose), ok = plat.leg_residual_jacobians(np.stack([home, degenerate]), return_mask=True)
    assert ok.tolist() == [True, False] and np.isnan(block[1]).all() and np.isfinite(pose[0]).all()
