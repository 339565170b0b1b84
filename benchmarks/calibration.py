"""Kinematic calibration from 200 measured poses, end to end (:func:`stewart.calibration.calibrate`:
the workspace check, the identifiability SVD, the least squares with the exact Jacobian,
the standard errors), on simulated measurements of the seed paper's platform with a
hidden geometry error; timed in rounds against the yardstick (:mod:`stewart.cli.interleaved`)."""

from __future__ import annotations

import stewart
from stewart.calibration import calibrate, perturbed_geometry, simulate_measurements
from stewart.calibration.design import design_poses
from stewart.cli import bench
from stewart.cli.interleaved import Target

from .report import target_table

#: Poses measured, and the most seconds their calibration may take.
POSES = 200
SECONDS = 1.0
TARGET = Target(SECONDS, True)


def figures(preset: str = "narayan2017", poses: int = POSES, rounds: bench.Rounds | None = None) -> dict:
    rounds = rounds or bench.Rounds()
    nominal = stewart.PlatformParams.preset(preset)
    data = simulate_measurements(perturbed_geometry(nominal), design_poses(nominal, poses).poses)
    rounds.absolute("calibrate_s", lambda: calibrate(nominal, data), unit=1.0, target=TARGET)
    return {"preset": preset, "poses": poses, **bench.figures_of(rounds.measure())}


def rows(fig: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, figure, spread, target, verdict) rows."""
    return [bench.measure_row(f"kinematic calibration from {fig['poses']} measured poses (42 parameters, exact "
                              "Jacobian)", "calibrate_s", bench.as_measurement(fig, "calibrate_s"), 1e3, "ms", ".0f",
                              TARGET)]


def format_rows(fig: dict) -> str:
    return target_table(rows(fig))


if __name__ == "__main__":
    print(format_rows(figures()))
