"""The vehicle log that motion cueing reads: CSV columns ``t, fx, fy, fz, wx, wy, wz``.

Frames and signs (ISO 8855 vehicle axes): x forward, y to the driver's left, z up; the
specific force ``f = a - g`` at the driver's head [m/s^2] in the vehicle frame, so a
vehicle at rest reads ``[0, 0, 9.81]`` and braking reads ``fx < 0``; the angular
velocity ``w`` [rad/s] in the same frame (``wz > 0`` turning left). Samples come at a
constant rate. Every problem is one ``ValueError`` naming the file, column and row.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..io import csvfile
from ..model import arguments
from ..model.errors import WrongTypeError

__all__ = ["COLUMNS", "VehicleLog", "read"]

#: The columns of a vehicle log, in order.
COLUMNS = ("t", "fx", "fy", "fz", "wx", "wy", "wz")
#: Largest relative deviation of a sample interval from the first one.
RATE_TOLERANCE = 1e-6


@dataclass(frozen=True)
class VehicleLog:
    """A vehicle's motion: times ``t`` ``(N,)`` [s], specific force ``f`` ``(N, 3)`` [m/s^2]
    and angular velocity ``w`` ``(N, 3)`` [rad/s] in the vehicle frame; ``name`` for reports."""

    t: np.ndarray
    f: np.ndarray
    w: np.ndarray
    name: str = "log"

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise WrongTypeError(f"name: expected a string, got {type(self.name).__name__}")
        where = self.name
        t, f, w = (arguments.reals(f"{where}: {name}", getattr(self, name)) for name in ("t", "f", "w"))
        if t.ndim != 1 or f.shape != (len(t), 3) or w.shape != (len(t), 3):
            raise ValueError(f"{where}: need t (N,), f (N, 3) and w (N, 3), got {t.shape}, {f.shape}, {w.shape}")
        if len(t) < 3:
            raise ValueError(f"{where}: need at least 3 samples, got {len(t)}")
        for k, name in enumerate(COLUMNS):
            column = t if k == 0 else (f[:, k - 1] if k <= 3 else w[:, k - 4])
            bad = np.flatnonzero(~np.isfinite(column))
            if bad.size:
                raise ValueError(f"{where}: column {name}, row {bad[0] + 1}: not a finite number")
        steps = np.diff(t)
        back = np.flatnonzero(steps <= 0)
        if back.size:
            r = back[0] + 1
            raise ValueError(f"{where}: column t, row {r + 1}: time goes backwards or repeats "
                             f"({t[r]:.9g} s after {t[r - 1]:.9g} s)")
        dt = steps[0]
        uneven = np.flatnonzero(np.abs(steps - dt) > RATE_TOLERANCE * dt)
        if uneven.size:
            r = uneven[0] + 1
            raise ValueError(f"{where}: column t, row {r + 1}: uneven sample rate (step {steps[r - 1]:.9g} s, "
                             f"first step {dt:.9g} s); resample the log to a constant rate")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "f", f)
        object.__setattr__(self, "w", w)

    @property
    def dt(self) -> float:
        """The sample interval [s]."""
        return float((self.t[-1] - self.t[0]) / (len(self.t) - 1))

    def to_csv(self, path, comment: str = "vehicle log") -> None:
        """Write the log in the layout :func:`read` reads."""
        csvfile.write(path, list(COLUMNS), np.column_stack([self.t, self.f, self.w]), comment, fmt="%.10g")


def read(path) -> VehicleLog:
    """The vehicle log in the CSV file ``path`` (a header naming the columns picks them
    from a wider file; without a header the file has exactly the seven columns)."""
    if not isinstance(path, (str, os.PathLike)):
        raise WrongTypeError(f"path: expected the path of a CSV log, got {type(path).__name__}")
    path = os.fspath(path)
    data = csvfile.read(path, list(COLUMNS))
    return VehicleLog(data[:, 0], data[:, 1:4], data[:, 4:7], name=path)
