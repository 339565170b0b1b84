"""Identification from a long log, end to end: forward kinematics, filtering, the stacked
base regressor and the weighted least squares of :func:`stewart.identification.identify.identify`, on a
simulated 1 kHz log of the seed paper's platform following a designed excitation; timed in
rounds against the yardstick, with the gauge (its least squares may run on both cores)."""

from __future__ import annotations

import numpy as np

import stewart
from stewart.cli import bench
from stewart.cli.interleaved import Target
from stewart.identification.base_parameters import base_parameters
from stewart.identification.excitation import design_excitation
from stewart.identification.identify import identify, synthetic_measurements

from .report import target_table

#: Samples of the log, and the most seconds their identification may take.
SAMPLES = 100_000
SECONDS = 3.0
TARGET = Target(SECONDS, True)
RATE = 1000.0
#: Rounds of the identification (a few seconds each).
ROUNDS = 3


def figures(preset: str = "narayan2017", samples: int = SAMPLES, rounds: bench.Rounds | None = None) -> dict:
    rounds = rounds or bench.Rounds()
    plat = stewart.Platform.preset(preset)
    design = design_excitation(plat, period=5.0, harmonics=4, starts=1, max_iterations=20,
                               periods=int(np.ceil(samples / RATE / 5.0)))
    log = synthetic_measurements(plat, design.trajectory, rate=RATE, noise_length=1e-6, noise_force=0.2)
    log = type(log)(log.t[:samples], log.lengths[:samples], log.forces[:samples])
    base = base_parameters(plat)
    rounds.job("identify_s", lambda: identify(plat, log, base=base), ROUNDS, target=TARGET)
    rounds.absolute("base_parameters_s", lambda: base_parameters(plat), unit=1.0)
    return {"preset": preset, "samples": len(log.t), **bench.figures_of(rounds.measure())}


def rows(fig: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, figure, spread, target, verdict) rows."""
    return [bench.measure_row(f"identification from {fig['samples']:,} samples (forward kinematics, filter, "
                              "regressor, least squares)", "identify_s", bench.as_measurement(fig, "identify_s"),
                              1.0, "s", ".2f", TARGET),
            bench.measure_row("base parameters (QR of 200 random states' regressors)", "base_parameters_s",
                              bench.as_measurement(fig, "base_parameters_s"), 1e3, "ms", ".0f")]


def format_rows(fig: dict) -> str:
    return target_table(rows(fig))


if __name__ == "__main__":
    print(format_rows(figures()))
