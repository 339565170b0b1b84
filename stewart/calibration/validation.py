"""Held-out checks of a calibration: how far forward kinematics from the encoder readings
lands from the measured poses (or targets), with one geometry and another."""

from __future__ import annotations

import numpy as np

from ..model.params import platform_params
from ..model.errors import ConvergenceError
from ..model.kinematics import forward_kinematics
from .geometry import target_positions
from .measurements import CalibrationData

__all__ = ["pose_errors"]


def pose_errors(platform, data: CalibrationData) -> dict:
    """The errors of forward kinematics of ``platform``'s geometry from the encoder readings of
    ``data`` (offsets applied): for pose data ``{"position": (n,) [m], "orientation": (n,)
    [rad]}``, the distance between the computed and measured origins of {P} and the angle of
    the rotation between the computed and measured orientations; for point data
    ``{"position": (n,) [m]}``, the distance of each computed target from the measured one."""
    params = platform_params(platform, "platform")
    if not isinstance(data, CalibrationData):
        raise ValueError(f"data: expected a stewart.calibration.CalibrationData, got {type(data).__name__}")
    guess = data.poses if data.poses is not None else None
    try:
        poses = forward_kinematics(params, data.readings, guess, encoder=True)
    except ConvergenceError as exc:
        raise ValueError(f"{data.source}: forward kinematics finds no pose for the readings of row(s) "
                         f"{exc.rows[:10]}") from None
    if data.poses is None:
        computed = target_positions(poses, data.target_offsets[data.targets])
        return {"position": np.sqrt(np.sum((computed - data.points) ** 2, axis=1))}
    position = np.sqrt(np.sum((poses[:, :3] - data.poses[:, :3]) ** 2, axis=1))
    relative = np.einsum("kba,kbc->kac", _axes(poses), _axes(data.poses))
    # The angle of a rotation from its skew part (accurate for small angles, unlike the trace).
    skew = np.stack([relative[:, 2, 1] - relative[:, 1, 2], relative[:, 0, 2] - relative[:, 2, 0],
                     relative[:, 1, 0] - relative[:, 0, 1]], axis=1)
    cosine = (np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0
    return {"position": position, "orientation": np.arctan2(np.sqrt(np.sum(skew**2, axis=1)) / 2.0, cosine)}


def _axes(poses) -> np.ndarray:
    """The rotation of {P} at the poses (K, 3, 3): its column k the axis k of {P} in {B}, the
    position of a target at the unit offset e_k less {P}'s origin, ``(t + R e_k) - t``."""
    return np.stack([target_positions(poses, axis) - poses[:, :3] for axis in np.eye(3)], axis=-1)
