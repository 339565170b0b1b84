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
has the pose derivative ``-[I, -[R c]x J_A]``.

The mathematics is generated: every residual and Jacobian here is the compiled model's
(:meth:`stewart.Platform.leg_residuals`, :meth:`~stewart.Platform.leg_residual_jacobians`,
:meth:`~stewart.Platform.target_positions`, :meth:`~stewart.Platform.target_jacobian`, derived in
``codegen/calibration.py``) for the geometry ``theta``; this module keeps the parameters'
bookkeeping and scatters each leg's 7 nonzero partials into the 42 columns.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..model import arguments
from ..model.compiled import Kernel
from ..model.params import PlatformParams
from ..model.platform import Platform

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


_LEGS = np.arange(6)
#: The columns among the 42 of each leg's 7 nonzero partials (``dr_dtheta`` of
#: :meth:`stewart.Platform.leg_residual_jacobians`): ``b_i``, ``p_i``, ``delta_i``, (6, 7).
_LEG_COLUMNS = np.column_stack([3 * _LEGS[:, None] + np.arange(3), 18 + 3 * _LEGS[:, None] + np.arange(3),
                                36 + _LEGS])


@lru_cache(maxsize=8)
def _compiled(theta: bytes) -> Kernel:
    """The compiled model of the geometry ``theta`` (42 float64 bytes), the kernel of
    :class:`stewart.Platform` without its home pose: its functions here read the geometry only,
    so the masses and inertias are placeholders of one unit."""
    base, platform, offsets = _split(np.frombuffer(theta))
    return Kernel(PlatformParams(
        base_points=base, platform_points=platform, leg_length_offsets=offsets, platform_mass=1.0,
        platform_inertia=np.ones(3), cylinder_mass=1.0, cylinder_inertia=np.ones(3), cylinder_com_distance=0.0,
        piston_mass=1.0, piston_inertia=np.ones(3), piston_com_distance=0.0, name="calibration geometry"))


def _kernel(theta) -> Kernel:
    """:func:`_compiled` for the 42 parameters ``theta`` (``ValueError`` naming ``theta``
    unless they are 42 real numbers)."""
    theta = arguments.reals("theta", theta)
    if theta.shape != (NUM_PARAMETERS,):
        raise ValueError(f"theta: expected the {NUM_PARAMETERS} geometric parameters, got shape {theta.shape}")
    return _compiled(np.ascontiguousarray(theta).tobytes())


@lru_cache(maxsize=1)
def _targets() -> Platform:
    """A compiled model for the targets' functions, which read no parameter (the seed paper's)."""
    return Platform(PlatformParams.preset("narayan2017"))


def leg_residuals(theta, poses, readings) -> np.ndarray:
    """``r = e + delta - |l|`` (K, 6) at the poses (K, 6) with the encoder readings (K, 6)."""
    return _kernel(theta).leg_residuals(poses, readings)


def leg_jacobian(theta, poses) -> np.ndarray:
    """The exact Jacobian ``dr/dtheta`` (K, 6, 42) of :func:`leg_residuals`."""
    block = _kernel(theta).leg_residual_jacobians(poses)[0]
    jac = np.zeros(block.shape[:-1] + (NUM_PARAMETERS,))
    jac[..., _LEGS[:, None], _LEG_COLUMNS] = block
    return jac


def leg_pose_jacobian(theta, poses) -> np.ndarray:
    """``dr/dx`` (K, 6, 6) of :func:`leg_residuals` with respect to the poses' coordinates."""
    return _kernel(theta).leg_residual_jacobians(poses)[1]


def target_positions(poses, offsets) -> np.ndarray:
    """``t + R c`` (K, 3) of the targets at ``offsets`` (K, 3) in {P} at the poses (K, 6)."""
    return _targets().target_positions(poses, offsets)


def target_pose_jacobian(poses, offsets) -> np.ndarray:
    """``d(q - t - R c)/dx`` (K, 3, 6): ``-[I, -[R c]x J_A]``, less the target's (the measured
    ``q`` does not move with the pose)."""
    return -_targets().target_jacobian(poses, offsets)
