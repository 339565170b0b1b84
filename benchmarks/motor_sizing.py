"""Motor sizing of a rotary rig from an hour of 60 Hz telemetry (issue 40: "the sizing of an
hour of 60 Hz telemetry takes <= 1 s on one core once read; reading its CSV is part of the
user's wait"): ``simrig100`` along a one-hour cueing reference (216000 rows of t, pose, rates
and accelerations, 19 columns, written once into a temporary file), timed as
:func:`stewart.studies.motor_sizing.read_reference` (numpy's C reader through
:func:`stewart.io.csvfile.read`), :func:`~stewart.studies.motor_sizing.motor_sizing` once read
(the generated batch kernels: crank angles, crank rates, motor torques; one core), and both
together, what ``stewart motor-sizing`` waits for before it prints. Each figure is a call a
round against the yardstick, at the reference machine's speed (:mod:`stewart.cli.interleaved`)."""

from __future__ import annotations

import pathlib
import tempfile

import numpy as np

import stewart
from stewart.cli import bench
from stewart.cli.interleaved import ANCHOR_SECONDS, Target
from stewart.io import csvfile
from stewart.studies.motor_sizing import LAYOUTS, motor_sizing, read_reference

from .report import target_table

RATE = 60.0
SAMPLES = 216_000
SECONDS = 1.0
TARGET = Target(SECONDS, True)
#: Rounds of each figure (a second or two each).
ROUNDS = 3


def telemetry(path, rig: stewart.RotaryPlatform, samples: int = SAMPLES) -> None:
    """An hour of a sim-racing rig's motion at 60 Hz as a cueing reference: three sines per axis
    (0.05 to 2 Hz) about home, their exact rates and accelerations."""
    rng = np.random.default_rng(40)
    t = np.arange(samples) / RATE
    amp = np.array([0.008, 0.008, 0.008, 0.02, 0.02, 0.02])
    x, xd, xdd = np.tile(rig.home, (samples, 1)), np.zeros((samples, 6)), np.zeros((samples, 6))
    for _ in range(3):
        w, phase = 2 * np.pi * rng.uniform(0.05, 2.0, 6), rng.uniform(0, 2 * np.pi, 6)
        arg = w * t[:, None] + phase
        x += amp * np.sin(arg)
        xd += amp * w * np.cos(arg)
        xdd -= amp * w ** 2 * np.sin(arg)
    csvfile.write(path, list(LAYOUTS["reference"]), np.column_stack([t, x, xd, xdd]), "platform simrig100 (preset)")


def figures(preset: str = "simrig100", rounds: bench.Rounds | None = None, samples: int = SAMPLES) -> dict:
    rounds = rounds or bench.Rounds()
    rig = stewart.RotaryPlatform.preset(preset)
    with tempfile.TemporaryDirectory() as tmp:
        path = pathlib.Path(tmp) / "telemetry.csv"
        telemetry(path, rig, samples)
        ref = read_reference(path)

        def size():
            return motor_sizing(rig, ref.x, ref.xd, ref.xdd, t=ref.t)

        def both():
            r = read_reference(path)
            return motor_sizing(rig, r.x, r.xd, r.xdd, t=r.t)

        options = {"unit": 1.0, "numbers": [1, None], "seconds": ANCHOR_SECONDS, "min_rounds": ROUNDS}
        rounds.absolute("motor_sizing_s", size, target=TARGET, **options)
        rounds.absolute("motor_sizing_read_s", lambda: read_reference(path), **options)
        rounds.absolute("motor_sizing_read_and_size_s", both, target=TARGET, **options)
        out = {"preset": preset, "samples": samples, "megabytes": path.stat().st_size / 1e6,
               **bench.figures_of(rounds.measure())}
    return out


def rows(fig: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, figure, spread, target, verdict) rows."""
    what = f"motor sizing, {fig['preset']}, an hour at 60 Hz ({fig['samples']:,} samples, {fig['megabytes']:.0f} MB CSV)"
    return [bench.measure_row(f"{what}: sizing once read (one core)", "motor_sizing_s",
                              bench.as_measurement(fig, "motor_sizing_s"), 1.0, "s", ".2f", TARGET),
            bench.measure_row(f"{what}: reading the CSV", "motor_sizing_read_s",
                              bench.as_measurement(fig, "motor_sizing_read_s"), 1.0, "s", ".2f"),
            bench.measure_row(f"{what}: reading and sizing", "motor_sizing_read_and_size_s",
                              bench.as_measurement(fig, "motor_sizing_read_and_size_s"), 1.0, "s", ".2f", TARGET)]


def format_rows(fig: dict) -> str:
    return target_table(rows(fig))


if __name__ == "__main__":
    print(format_rows(figures()))
