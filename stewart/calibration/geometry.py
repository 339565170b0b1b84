"""The 42 geometric parameters of kinematic calibration and the inverse-kinematics residuals
with their exact Jacobians.

The error model is that of Masory, Wang & Zhuang (1993): the six base joint centres
``b_i`` in {B}, the six platform joint centres ``p_i`` in {P} and the six leg length offsets
``delta_i``, with the true leg length the encoder reading ``e_i`` plus ``delta_i``. At a pose
``x = (t, R)`` (eq. 26 of Lopes & Pires 2011) the residual of leg ``i`` is

    r_i = e_i + delta_i - |l_i|,    l_i = t + R p_i - b_i,

the measured minus the modelled leg length (Zhuang & Roth 1993). With ``u_i = l_i / |l_i|``
its exact partial derivatives are

    dr_i/db_i = u_i,    dr_i/dp_i = -R^T u_i,    dr_i/ddelta_i = 1,

and with respect to the pose ``-[u_i, (R p_i) x u_i] T`` (``J_C`` of eq. 5 times ``T`` of
eq. 18). A tracked target at ``c`` in {P} is at ``t + R c``; its residual ``q - (t + R c)``
has the pose derivative ``-[I, -[R c]x J_A]``. Every function here is written with analytic
operations only, so it takes complex parameters for complex-step checks.
"""

from __future__ import annotations

import numpy as np

from ..model.kinematics import POSE_AXES, euler_rate_jacobian, rotation
from ..model.params import PlatformParams

__all__ = ["PARAMETER_NAMES", "NUM_PARAMETERS", "parameter_vector", "with_parameters", "leg_residuals",
           "leg_jacobian", "leg_pose_jacobian", "target_positions", "target_pose_jacobian"]

_AXES = "xyz"
#: The names of the 42 parameters in their order: ``base_points[i].x`` ... (18),
#: ``platform_points[i].x`` ... (18), ``leg_length_offsets[i]`` (6), all in metres.
PARAMETER_NAMES: tuple[str, ...] = (
    tuple(f"base_points[{i}].{a}" for i in range(6) for a in _AXES)
    + tuple(f"platform_points[{i}].{a}" for i in range(6) for a in _AXES)
    + tuple(f"leg_length_offsets[{i}]" for i in range(6))
)
NUM_PARAMETERS = len(PARAMETER_NAMES)


def parameter_vector(params: PlatformParams) -> np.ndarray:
    """The 42 geometric parameters of ``params`` in the order of :data:`PARAMETER_NAMES`."""
    return np.concatenate([params.base_points.ravel(), params.platform_points.ravel(), params.leg_length_offsets])


def with_parameters(params: PlatformParams, theta: np.ndarray) -> PlatformParams:
    """A copy of ``params`` whose geometry is ``theta`` (the inverse of :func:`parameter_vector`)."""
    base, platform, offsets = _split(np.asarray(theta, dtype=float))
    return params.replace(base_points=base, platform_points=platform, leg_length_offsets=offsets)


def _split(theta):
    return theta[:18].reshape(6, 3), theta[18:36].reshape(6, 3), theta[36:42]


def _legs(theta, poses):
    """``R`` (K, 3, 3), ``R p_i`` (K, 6, 3) and ``l_i`` (K, 6, 3) at the poses (K, 6)."""
    base, platform, _ = _split(theta)
    rot = rotation(poses)
    arms = np.einsum("kab,ib->kia", rot, platform)
    return rot, arms, poses[:, None, :3] + arms - base


def leg_residuals(theta, poses, readings) -> np.ndarray:
    """``r = e + delta - |l|`` (K, 6) at the poses (K, 6) with the encoder readings (K, 6)."""
    _, _, legs = _legs(theta, poses)
    return readings + _split(theta)[2] - np.sqrt(np.sum(legs * legs, axis=-1))


def leg_jacobian(theta, poses) -> np.ndarray:
    """The exact Jacobian ``dr/dtheta`` (K, 6, 42) of :func:`leg_residuals`."""
    rot, _, legs = _legs(theta, poses)
    units = legs / np.sqrt(np.sum(legs * legs, axis=-1))[..., None]
    k = len(poses)
    jac = np.zeros((k, 6, NUM_PARAMETERS), dtype=units.dtype)
    legs_index = np.arange(6)
    for a in range(3):
        jac[:, legs_index, 3 * legs_index + a] = units[..., a]
    jac[:, legs_index[:, None], 18 + 3 * legs_index[:, None] + np.arange(3)] = -np.einsum("kba,kib->kia", rot, units)
    jac[:, legs_index, 36 + legs_index] = 1.0
    return jac


def leg_pose_jacobian(theta, poses) -> np.ndarray:
    """``dr/dx`` (K, 6, 6) of :func:`leg_residuals` with respect to the poses' coordinates."""
    _, arms, legs = _legs(theta, poses)
    units = legs / np.sqrt(np.sum(legs * legs, axis=-1))[..., None]
    angular = np.einsum("kia,kab->kib", np.cross(arms, units), euler_rate_jacobian(poses))
    return -np.concatenate([units, angular], axis=-1)


def target_positions(poses, offsets) -> np.ndarray:
    """``t + R c`` (K, 3) of the targets at ``offsets`` (K, 3) in {P} at the poses (K, 6)."""
    return poses[:, :3] + np.einsum("kab,kb->ka", rotation(poses), offsets)


def target_pose_jacobian(poses, offsets) -> np.ndarray:
    """``d(q - t - R c)/dx`` (K, 3, 6): ``-[I, -[R c]x J_A]``."""
    arm = np.einsum("kab,kb->ka", rotation(poses), offsets)
    jac_a = euler_rate_jacobian(poses)
    # -[R c]x J_A w: the velocity omega x (R c) of the target for angle rates w (omega = J_A w).
    cross = np.stack([np.cross(jac_a[:, :, j], arm) for j in range(3)], axis=-1)
    out = np.zeros((len(poses), 3, 6), dtype=cross.dtype)
    out[:, :, :3] = -np.eye(3)
    out[:, :, 3:] = -cross
    return out


