"""Identification from a long log, end to end: forward kinematics, filtering, the stacked
base regressor and the weighted least squares of :func:`stewart.identification.identify.identify`, on a
simulated 1 kHz log of the seed paper's platform following a designed excitation."""

from __future__ import annotations

import time

import numpy as np

import stewart
from stewart.identification.base_parameters import base_parameters
from stewart.identification.excitation import design_excitation
from stewart.identification.identify import identify, synthetic_measurements

from .report import target_table

#: Samples of the log, and the most seconds their identification may take.
SAMPLES = 100_000
SECONDS = 3.0
RATE = 1000.0


def figures(preset: str = "narayan2017", samples: int = SAMPLES, repeats: int = 3) -> dict:
    plat = stewart.Platform.preset(preset)
    design = design_excitation(plat, period=5.0, harmonics=4, starts=1, max_iterations=20,
                               periods=int(np.ceil(samples / RATE / 5.0)))
    log = synthetic_measurements(plat, design.trajectory, rate=RATE, noise_length=1e-6, noise_force=0.2)
    log = type(log)(log.t[:samples], log.lengths[:samples], log.forces[:samples])
    base = base_parameters(plat)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        identify(plat, log, base=base)
        times.append(time.perf_counter() - start)
    start = time.perf_counter()
    base_parameters(plat)
    return {"preset": preset, "samples": len(log.t), "identify_s": float(np.median(times)),
            "base_parameters_s": time.perf_counter() - start}


def rows(fig: dict) -> list[tuple[str, str, str, str]]:
    """(measure, figure, target, met) rows."""
    ok = fig["identify_s"] <= SECONDS
    return [(f"identification from {fig['samples']:,} samples (forward kinematics, filter, regressor, least squares)",
             f"{fig['identify_s']:.2f} s", f"<= {SECONDS:g} s", "met" if ok else "MISSED"),
            ("base parameters (QR of 200 random states' regressors)", f"{fig['base_parameters_s'] * 1e3:.0f} ms", "", "")]


def format_rows(fig: dict) -> str:
    return target_table(rows(fig))


if __name__ == "__main__":
    print(format_rows(figures()))
