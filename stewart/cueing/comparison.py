"""Washout against MPC cueing on the same logs and platform (:func:`compare`): per maneuver,
the perceived-error RMS of the main channel and of all channels together, the correlation
and the false cues, and the closed loop's outcome and peaks against the limits; with a
figure of one maneuver (:func:`plot`)."""

from __future__ import annotations

import os

import numpy as np

from ..model.platform import as_platform
from . import log as log_module
from .result import CueingResult
from .runners import mpc, washout
from .vestibular import CHANNELS, THRESHOLDS

__all__ = ["compare", "format_table", "plot", "main_channel"]


def main_channel(result: CueingResult) -> str:
    """The channel the vehicle's perceived motion varies most in, in perception thresholds."""
    v = result.vehicle.channels
    spread = [np.std(v[:, j]) / THRESHOLDS[c] for j, c in enumerate(CHANNELS)]
    return CHANNELS[int(np.argmax(spread))]


def _summary(result: CueingResult, channel: str) -> dict:
    m = result.achieved_metrics if result.achieved_metrics is not None else result.metrics
    thresholds = np.array([THRESHOLDS[c] for c in CHANNELS])
    errors = np.array([m["perceived_error_rms"][c] for c in CHANNELS])
    peaks = result.simulation_peaks or result.peaks
    return {"error": m["perceived_error_rms"][channel], "correlation": m["correlation"][channel],
            "false_cue_s": m["false_cue_s"][channel], "error_thresholds": float(np.sqrt(np.mean((errors / thresholds) ** 2))),
            "exit_code": result.exit_code, "peak_force": peaks["force"], "peak_leg_velocity": peaks["leg_velocity"]}


def compare(platform, logs, *, simulate: bool = True, progress: bool = False) -> list[dict]:
    """Washout (:func:`stewart.cueing.washout`, default settings) and MPC
    (:func:`stewart.cueing.mpc`, default settings) on each of ``logs`` (paths or
    :class:`~stewart.cueing.log.VehicleLog`) for ``platform``; with ``simulate`` each
    reference runs through the closed loop and the figures are those of the motion
    achieved. One row per log: ``name``, ``channel`` (:func:`main_channel`), ``washout`` and
    ``mpc`` (the error of that channel, its correlation and false cues, the RMS of all
    channels' errors in perception thresholds, the exit code and the peak force and leg
    speed), the ``limits`` MPC held and the two :class:`CueingResult`."""
    plat = as_platform(platform)
    rows = []
    for item in logs:
        log = item if isinstance(item, log_module.VehicleLog) else log_module.read(item)
        if not isinstance(item, log_module.VehicleLog):
            log = log_module.VehicleLog(log.t, log.f, log.w, os.path.splitext(os.path.basename(os.fspath(item)))[0])
        w = washout(log, plat, simulate=simulate)
        m = mpc(log, plat, simulate=simulate, progress=progress)
        channel = main_channel(w)
        rows.append({"name": log.name, "channel": channel, "washout": _summary(w, channel),
                     "mpc": _summary(m, channel), "limits": m.limits,
                     "solve_time_ms": 1e3 * m.solver["solve_time_s"]["median"], "results": (w, m)})
    return rows


def format_table(rows: list[dict]) -> str:
    """The rows of :func:`compare` as a text table."""
    head = (f"  {'maneuver':<22}{'channel':>8}{'error W':>10}{'error MPC':>11}{'corr W':>8}{'corr MPC':>9}"
            f"{'false W':>9}{'false MPC':>10}{'all W':>8}{'all MPC':>9}{'F/limit':>9}{'exit W/M':>10}")
    lines = [head]
    for r in rows:
        w, m = r["washout"], r["mpc"]
        corr = lambda v: f"{v:>8.3f}" if v is not None else f"{'-':>8}"  # noqa: E731
        lines.append(f"  {r['name']:<22}{r['channel']:>8}{w['error']:>10.3f}{m['error']:>11.3f}{corr(w['correlation'])}"
                     f"{corr(m['correlation']):>9}{w['false_cue_s']:>8.2f}s{m['false_cue_s']:>9.2f}s"
                     f"{w['error_thresholds']:>8.2f}{m['error_thresholds']:>9.2f}"
                     f"{m['peak_force'] / r['limits']['force']:>9.2f}{w['exit_code']:>6}/{m['exit_code']}")
    return "\n".join(lines)


def plot(row: dict, platform_name: str, path: str) -> str:
    """A figure of one row of :func:`compare`: the perceived signals of vehicle, washout and
    MPC per channel, and MPC's leg forces against the force limit. Needs matplotlib."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    w, m = row["results"]
    seen = lambda r: r.achieved if r.achieved is not None else r.platform  # noqa: E731
    fig, axes = plt.subplots(4, 2, figsize=(11, 10), sharex=True)
    units = ["m/s²"] * 3 + ["rad/s"] * 3
    t = w.t
    for j, name in enumerate(CHANNELS):
        ax = axes[j % 3, j // 3]
        ax.plot(t, w.vehicle.channels[:, j], "k", lw=1.2, label="vehicle")
        ax.plot(t, seen(w).channels[:, j], label="washout")
        ax.plot(t, seen(m).channels[:, j], label="MPC")
        ax.set_ylabel(f"perceived {name} [{units[j]}]")
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    limit = row["limits"]["force"]
    for k, (r, label) in enumerate(((w, "washout"), (m, "MPC"))):
        ax = axes[3, k]
        forces = r.simulation.forces if r.simulation is not None else None
        times = r.simulation.t if r.simulation is not None else None
        if forces is not None:
            ax.plot(times, forces, lw=0.8)
        ax.axhline(limit, color="r", ls="--", lw=1)
        ax.axhline(-limit, color="r", ls="--", lw=1)
        ax.set_ylabel(f"{label}: leg forces [N]")
        ax.set_xlabel("t [s]")
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{row['name']} on {platform_name}: perceived motion and leg forces (closed loop; dashed: the "
                 "force limit MPC holds)", fontsize=10)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
