"""Calibration measurements: poses or tracked points measured in the base frame {B} with the
encoder readings at each, their CSV files, and simulated campaigns.

Two layouts (:mod:`stewart.io.csvfile`; the header names the columns):

* **poses** ``x, y, z, psi, theta, phi, L0..L5``: the pose of {P} in {B} measured by a
  tracker with a 6-DOF probe, a CMM or a camera [m, rad], and the six encoder readings [m];
* **points** ``px, py, pz, L0..L5`` (and optionally ``target``): the position in {B} of a
  target fixed to the platform at a known offset in {P} [m], and the encoder readings. With
  several targets, ``target`` is the index (0, 1, ...) of its offset among those given;
  rows with identical encoder readings are one pose of the platform (the machine holds
  still while the tracker visits its targets).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..io import csvfile
from ..model import arguments
from ..model.kinematics import POSE_AXES, encoder_readings
from ..model.params import PlatformParams
from .geometry import target_positions

__all__ = ["CalibrationData", "POSE_COLUMNS", "POINT_COLUMNS", "simulate_measurements", "perturbed_geometry"]

READINGS = [f"L{i}" for i in range(6)]
#: The columns of pose measurements and of point measurements.
POSE_COLUMNS = list(POSE_AXES) + READINGS
POINT_COLUMNS = ["px", "py", "pz"] + READINGS


@dataclass(frozen=True)
class CalibrationData:
    """Measurements for calibration: encoder ``readings`` (n, 6) [m] with either the measured
    ``poses`` (n, 6) of {P} in {B} [m, rad] or the measured ``points`` (n, 3) in {B} [m] of
    the targets ``targets`` (n,) (indices into ``target_offsets`` (m, 3), the targets'
    positions in {P})."""

    readings: np.ndarray
    poses: np.ndarray | None = None
    points: np.ndarray | None = None
    targets: np.ndarray | None = None
    target_offsets: np.ndarray | None = None
    source: str = "measurements"

    def __post_init__(self) -> None:
        name = self.source
        readings = _finite(name, "readings", self.readings, 6)
        n = len(readings)
        if (self.poses is None) == (self.points is None):
            raise ValueError(f"{name}: give either poses or points")
        if self.poses is not None:
            poses = _finite(name, "poses", self.poses, 6)
            _same_rows(name, "poses", poses, n)
            object.__setattr__(self, "poses", poses)
        else:
            points = _finite(name, "points", self.points, 3)
            _same_rows(name, "points", points, n)
            if self.target_offsets is None:
                raise ValueError(f"{name}: point measurements need their targets' offsets in {{P}} "
                                 "(target_offsets, --target-offset X Y Z)")
            offsets = _finite(name, "target_offsets", self.target_offsets, 3)
            targets = np.zeros(n, dtype=int) if self.targets is None else arguments.reals("targets", self.targets)
            if targets.shape != (n,) or np.any(targets != np.round(targets)) or np.any(targets < 0) \
                    or np.any(targets >= len(offsets)):
                raise ValueError(f"{name}: target: expected indices 0..{len(offsets) - 1} of the "
                                 f"{len(offsets)} target offset(s) given, one per row")
            object.__setattr__(self, "points", points)
            object.__setattr__(self, "targets", targets.astype(int))
            object.__setattr__(self, "target_offsets", offsets)
        object.__setattr__(self, "readings", readings)

    @property
    def kind(self) -> str:
        """``"poses"`` or ``"points"``."""
        return "poses" if self.poses is not None else "points"

    def pose_index(self) -> tuple[np.ndarray, np.ndarray]:
        """The distinct poses: their encoder readings (K, 6), in the order they first appear,
        and for each row the index of its pose (n,)."""
        if self.poses is not None:
            return self.readings, np.arange(len(self.readings))
        _, first, inverse = np.unique(self.readings, axis=0, return_index=True, return_inverse=True)
        order = np.argsort(first)
        rank = np.empty_like(order)
        rank[order] = np.arange(len(order))
        return self.readings[first[order]], rank[inverse.ravel()]

    @classmethod
    def from_csv(cls, path, target_offsets=None) -> "CalibrationData":
        """Read a file of either layout (the header's ``px`` column tells points from poses)."""
        path = os.fspath(path)
        header = _header(path)
        if "px" in header:
            columns = POINT_COLUMNS + (["target"] if "target" in header else [])
            table = csvfile.read(path, columns)
            targets = table[:, 9] if "target" in header else None
            return cls(table[:, 3:9], points=table[:, :3], targets=targets,
                       target_offsets=target_offsets, source=path)
        table = csvfile.read(path, POSE_COLUMNS)
        return cls(table[:, 6:], poses=table[:, :6], source=path)

    def to_csv(self, path, comment: str = "calibration measurements") -> None:
        """Write the file :meth:`from_csv` reads."""
        if self.poses is not None:
            csvfile.write(path, POSE_COLUMNS, np.column_stack([self.poses, self.readings]), comment, fmt="%.17g")
        else:
            csvfile.write(path, POINT_COLUMNS + ["target"],
                          np.column_stack([self.points, self.readings, self.targets]), comment, fmt="%.17g")


def _header(path: str) -> list[str]:
    """The lower-cased names of the file's header (empty without one; a missing or unreadable
    file is reported by :func:`stewart.io.csvfile.read`)."""
    try:
        with open(path, encoding="utf-8") as handle:
            for line in handle:
                line = line.strip()
                if line and not line.startswith("#"):
                    return [name.strip().lower() for name in line.split(",")]
    except (OSError, UnicodeDecodeError):
        pass
    return []


def _finite(source, name, value, width) -> np.ndarray:
    arr = arguments.reals(name, value)
    if arr.shape == (width,) and name == "target_offsets":  # one target's offset
        arr = arr[None]
    if arr.ndim != 2 or arr.shape[1] != width:
        raise ValueError(f"{source}: {name}: expected {width} columns, got shape {arr.shape}")
    bad = np.flatnonzero(~np.all(np.isfinite(arr), axis=1))
    if bad.size:
        raise ValueError(f"{source}: {name}: NaN or inf in row(s) {bad[:10].tolist()}")
    return arr


def _same_rows(source, name, arr, n) -> None:
    if len(arr) != n:
        raise ValueError(f"{source}: {name} has {len(arr)} rows and readings {n}")


def perturbed_geometry(params: PlatformParams, *, joint_error: float = 1e-3, offset_error: float = 2e-3,
                       seed: int = 0) -> PlatformParams:
    """A built machine's geometry: every joint coordinate of ``params`` moved by a uniform
    random amount within ``+-joint_error`` [m], and leg length offsets uniform within
    ``+-offset_error`` [m] (seeded)."""
    rng = np.random.default_rng(arguments.seed(seed))
    return params.replace(
        base_points=params.base_points + rng.uniform(-joint_error, joint_error, (6, 3)),
        platform_points=params.platform_points + rng.uniform(-joint_error, joint_error, (6, 3)),
        leg_length_offsets=params.leg_length_offsets + rng.uniform(-offset_error, offset_error, 6),
        name=f"{params.name or 'platform'} (built)")


def simulate_measurements(true_params: PlatformParams, poses, *, position_std: float = 1e-5,
                          angle_std: float = 1e-4, length_std: float = 1e-6, target_offsets=None,
                          seed: int = 0) -> CalibrationData:
    """A measurement campaign on the machine ``true_params`` at ``poses`` (K, 6): its encoder
    readings (true lengths less the offsets) with Gaussian noise ``length_std`` [m], and the
    poses with noise ``position_std`` [m] and ``angle_std`` [rad] per coordinate, or with
    ``target_offsets`` (m, 3) the positions of every target at every pose with noise
    ``position_std`` per coordinate (seeded)."""
    rng = np.random.default_rng(arguments.seed(seed))
    poses = np.atleast_2d(arguments.states("poses", poses))
    readings = encoder_readings(true_params, poses)
    readings = readings + rng.normal(0.0, length_std, readings.shape)
    if target_offsets is None:
        noise = rng.normal(size=poses.shape) * np.array([position_std] * 3 + [angle_std] * 3)
        return CalibrationData(readings, poses=poses + noise, source="simulated measurements")
    offsets = np.atleast_2d(np.asarray(target_offsets, dtype=float))
    rows = np.repeat(np.arange(len(poses)), len(offsets))
    targets = np.tile(np.arange(len(offsets)), len(poses))
    points = target_positions(poses[rows], offsets[targets]) + rng.normal(0.0, position_std, (len(rows), 3))
    return CalibrationData(readings[rows], points=points, targets=targets, target_offsets=offsets,
                           source="simulated measurements")
