"""Kinematic calibration from 200 measured poses, end to end (:func:`stewart.calibration.calibrate`:
the workspace check, the identifiability SVD, the least squares with the exact Jacobian,
the standard errors), on simulated measurements of the seed paper's platform with a
hidden geometry error."""

from __future__ import annotations

import time

import numpy as np

import stewart
from stewart.calibration import calibrate, perturbed_geometry, simulate_measurements
from stewart.calibration.design import design_poses

from .report import target_table

#: Poses measured, and the most seconds their calibration may take.
POSES = 200
SECONDS = 1.0


def figures(preset: str = "narayan2017", poses: int = POSES, repeats: int = 3) -> dict:
    nominal = stewart.PlatformParams.preset(preset)
    data = simulate_measurements(perturbed_geometry(nominal), design_poses(nominal, poses).poses)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        calibrate(nominal, data)
        times.append(time.perf_counter() - start)
    return {"preset": preset, "poses": poses, "calibrate_s": float(np.median(times))}


def rows(fig: dict) -> list[tuple[str, str, str, str]]:
    """(measure, figure, target, met) rows."""
    ok = fig["calibrate_s"] <= SECONDS
    return [(f"kinematic calibration from {fig['poses']} measured poses (42 parameters, exact Jacobian)",
             f"{fig['calibrate_s'] * 1e3:.0f} ms", f"<= {SECONDS:g} s", "met" if ok else "MISSED")]


def format_rows(fig: dict) -> str:
    return target_table(rows(fig))


if __name__ == "__main__":
    print(format_rows(figures()))
