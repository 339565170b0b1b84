"""Kinematics against the seed paper's worked example, complex-step derivatives (of the
oracles' own numpy kinematics, stewart.oracles.frames: the compiled model takes real states)
and forward/inverse round trips."""

import numpy as np
import pytest

import stewart
from conftest import random_params, random_states
from stewart.oracles import frames
from stewart.model.presets import narayan2017_target_pose

# Narayan Rao et al. (2017), section IX, in the paper's y-up frame.
PAPER_ROTATION = np.array([[0.9908, 0.0953, -0.09575], [-0.1044, 0.99, -0.09531], [0.0857, 0.1044, 0.9908]])
PAPER_LEG_VECTORS = np.array(
    [
        [0.007647, -0.01286, 0.1119, 0.07525, 0.01001, 0.07248],
        [0.1838, 0.1967, 0.1999, 0.1969, 0.193, 0.1824],
        [0.06912, 0.01557, 0.002573, 0.05882, -0.04866, -0.03997],
    ]
).T
PAPER_EXTENSIONS = np.array([0.006484, 0.007723, 0.03912, 0.02881, 0.009245, 0.01027])
Y_UP_TO_Z_UP = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])  # (X, Y, Z) = (x, -z, y)


def test_rotation_is_zyx_euler_and_inverts():
    x = np.array([0, 0, 0, 0.3, -0.2, 0.1])
    c, s = np.cos, np.sin
    rz = np.array([[c(0.3), -s(0.3), 0], [s(0.3), c(0.3), 0], [0, 0, 1]])
    ry = np.array([[c(-0.2), 0, s(-0.2)], [0, 1, 0], [-s(-0.2), 0, c(-0.2)]])
    rx = np.array([[1, 0, 0], [0, c(0.1), -s(0.1)], [0, s(0.1), c(0.1)]])
    np.testing.assert_allclose(stewart.rotation(x), rz @ ry @ rx, atol=1e-15, rtol=1e-14)  # reached 1/93 of it


def test_paper_worked_example(figures):
    params = stewart.PlatformParams.preset("narayan2017")
    x = narayan2017_target_pose()
    # the paper prints its rotation to 4 decimals: reached 4.2e-5
    np.testing.assert_allclose(stewart.rotation(x), Y_UP_TO_Z_UP @ PAPER_ROTATION @ Y_UP_TO_Z_UP.T, rtol=0, atol=6e-4)
    legs = stewart.leg_vectors(params, x)
    expected = PAPER_LEG_VECTORS @ Y_UP_TO_Z_UP.T
    figures("paper example: leg vectors [m]", np.max(np.abs(legs - expected)), 2e-4)  # reached 9.0e-05
    extensions = stewart.leg_lengths(params, x) - 0.19
    figures("paper example: extensions [m]", np.max(np.abs(extensions - PAPER_EXTENSIONS)), 2e-4)  # reached 4.1e-05


def _complex_step_columns(fn, x, h=1e-30):
    return np.stack([fn(x + 1j * h * np.eye(6)[k]).imag / h for k in range(6)], axis=-1)


def test_jacobian_matches_complex_step_of_leg_lengths(preset_params, figures):
    rng = np.random.default_rng(1)
    x, _, _ = random_states(preset_params, 50, rng)
    worst = 0.0
    for pose in x:
        numeric = _complex_step_columns(lambda z: frames.leg_lengths(preset_params, z), pose)
        analytic = stewart.jacobian(preset_params, pose) @ stewart.twist_transform(pose)
        np.testing.assert_allclose(stewart.euler_jacobian(preset_params, pose), analytic, rtol=0, atol=0)
        worst = np.maximum(worst, np.max(np.abs(numeric - analytic)) / np.max(np.abs(numeric)))
    figures(f"J_C vs complex step of L ({preset_params.name})", worst, 2e-14)  # reached 4.0e-16


def test_euler_rate_jacobian_gives_angular_velocity_of_rotation():
    """skew(omega) = Rdot R^T with omega = J_A [psi', theta', phi'] (eq. 8)."""
    rng = np.random.default_rng(2)
    for _ in range(20):
        x = rng.uniform(-1, 1, 6)
        xd = rng.normal(size=6)
        h = 1e-30
        rdot = frames.rotation(x + 1j * h * xd).imag / h
        omega_x = rdot @ stewart.rotation(x).T
        omega = stewart.euler_rate_jacobian(x) @ xd[3:]
        np.testing.assert_allclose([omega_x[2, 1], omega_x[0, 2], omega_x[1, 0]], omega, rtol=0, atol=2e-14)  # reached 4.4e-16


def test_leg_velocities_are_time_derivative_of_lengths():
    params = stewart.PlatformParams.preset("motion_simulator")
    x, xd, _ = random_states(params, 10, np.random.default_rng(3))
    h = 1e-30
    numeric = frames.leg_lengths(params, x + 1j * h * xd).imag / h
    np.testing.assert_allclose(stewart.leg_velocities(params, x, xd), numeric, rtol=1e-13, atol=1e-15)  # reached 1/29 of it


def test_batch_shapes_follow_input():
    params = stewart.PlatformParams.preset("narayan2017")
    x = stewart.home_pose(params)
    assert stewart.leg_lengths(params, x).shape == (6,)
    assert stewart.leg_lengths(params, np.stack([x] * 4)).shape == (4, 6)
    assert stewart.jacobian(params, np.stack([x] * 4)).shape == (4, 6, 6)
    assert stewart.rotation(x).shape == (3, 3)


def test_home_pose_is_centred_at_mid_stroke(preset_params):
    home = stewart.home_pose(preset_params)
    lo, hi = preset_params.leg_length_limits
    # the bisection ends on adjacent floats: reached 2.0e-16
    assert np.mean(stewart.leg_lengths(preset_params, home)) == pytest.approx(0.5 * (lo + hi), rel=1e-14)
    assert np.all(home[3:] == 0.0)
    centroid = preset_params.base_points.mean(axis=0) - preset_params.platform_points.mean(axis=0)
    np.testing.assert_allclose(home[:2], centroid[:2], rtol=0, atol=1e-15)  # reached 0
    assert stewart.home_pose(preset_params, leg_length=lo + 0.01 * (hi - lo))[2] < home[2]


def test_forward_kinematics_round_trip(figures):
    rng = np.random.default_rng(4)
    worst = 0.0
    for params in [stewart.PlatformParams.preset(n) for n in stewart.presets()] + [random_params(rng) for _ in range(5)]:
        x, _, _ = random_states(params, 200, rng)
        found = stewart.forward_kinematics(params, stewart.leg_lengths(params, x))
        worst = np.maximum(worst, np.max(np.abs(found - x)))
        one = stewart.forward_kinematics(params, stewart.leg_lengths(params, x[0]), guess=x[0] + 0.01)
        np.testing.assert_allclose(one, x[0], atol=5e-15, rtol=5e-12)  # reached 1/38 of it
    figures("FK(IK(x)) - x [m, rad]", worst, 1e-10)  # reached 1.5e-12


def test_forward_kinematics_reports_unreachable_lengths():
    params = stewart.PlatformParams.preset("narayan2017")
    lengths = np.full((3, 6), 0.285)
    lengths[1] = [0.1, 0.5, 0.1, 0.5, 0.1, 0.5]  # no pose stretches legs like this
    with pytest.raises(stewart.ConvergenceError, match=r"row\(s\) \[1\]") as info:
        stewart.forward_kinematics(params, lengths)
    assert info.value.rows == [1]


@pytest.mark.parametrize(
    "value, message",
    [
        (np.zeros(5), r"x: expected shape \(6,\) or \(N, 6\), got \(5,\)"),
        (np.zeros((2, 3, 6)), r"x: expected shape"),
        ([0, 0, np.nan, 0, 0, 0], "x: contains NaN or inf"),
        (np.array([[0.0] * 6, [0, 0, 0, np.inf, 0, 0]]), "x: row 1 contains NaN or inf"),
        (["a"] * 6, "x: expected real numbers"),
    ],
)
def test_bad_pose_is_reported_by_name(value, message):
    params = stewart.PlatformParams.preset("narayan2017")
    with pytest.raises(ValueError, match=message):
        stewart.leg_lengths(params, value)


def test_bad_lengths_and_mismatched_batches():
    params = stewart.PlatformParams.preset("narayan2017")
    with pytest.raises(ValueError, match="lengths: leg lengths must be positive"):
        stewart.forward_kinematics(params, [-0.2] * 6)
    with pytest.raises(ValueError, match="matching batch shapes"):
        stewart.leg_velocities(params, np.zeros((3, 6)) + stewart.home_pose(params), np.zeros((2, 6)))
