"""PNG figures of a calibration: the residuals of each leg before and after, the estimates
against the nominal with their standard errors, and the held-out pose errors of forward
kinematics with the nominal and the calibrated geometry. Needs matplotlib
(``pip install stewart[plot]``)."""

from __future__ import annotations

import os

import numpy as np

from ..io.plots import plot_bars, pyplot
from .fit import Calibration

__all__ = ["plot_calibration"]


def plot_calibration(result: Calibration, directory, held_out: dict | None = None) -> list[str]:
    """Write ``calibration_residuals.png``, ``calibration_estimates.png`` and, given
    ``held_out`` (``{"nominal": errors, "calibrated": errors}`` of
    :func:`stewart.calibration.validation.pose_errors`), ``calibration_held_out.png`` into
    ``directory``; returns their paths."""
    os.makedirs(directory, exist_ok=True)
    paths = [plot_bars(list(result.residual_names),
                       {"nominal geometry": 1e6 * result.rms_before, "calibrated": 1e6 * result.rms_after},
                       "RMS residual [um]", "inverse-kinematics residuals per leg, before and after calibration",
                       os.path.join(directory, "calibration_residuals.png"),
                       caption=f"{len(result.poses)} measurements ({result.kind}); condition number "
                               f"{result.identifiability.condition:.4g}", value_format="{:.3g}")]
    plt = pyplot()
    change = 1e3 * (result.estimates - result.nominal_values)
    error = 1e3 * result.standard_errors
    fig, axes = plt.subplots(3, 1, figsize=(12, 8), constrained_layout=True)
    fig.suptitle("calibrated geometry: change from the nominal with 2 standard errors")
    for ax, (title, part) in zip(axes, (("base_points", slice(0, 18)), ("platform_points", slice(18, 36)),
                                        ("leg_length_offsets", slice(36, 42)))):
        names = [name.split("]")[0].split("[")[1] + (name.split("]")[1] or "") for name in result.names[part]]
        ax.errorbar(np.arange(len(names)), change[part], yerr=2 * error[part], fmt="o", ms=4, capsize=3)
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_xticks(np.arange(len(names)), names, fontsize=7)
        ax.set_ylabel(f"{title} [mm]")
        ax.grid(True, alpha=0.3)
    paths.append(os.path.join(directory, "calibration_estimates.png"))
    fig.savefig(paths[-1], dpi=90)
    plt.close(fig)
    if held_out is not None:
        paths.append(_plot_held_out(plt, held_out, os.path.join(directory, "calibration_held_out.png")))
    return paths


def _plot_held_out(plt, held_out: dict, path: str) -> str:
    kinds = [k for k in ("position", "orientation") if k in held_out["nominal"]]
    fig, axes = plt.subplots(1, len(kinds), figsize=(6 * len(kinds), 4.5), constrained_layout=True, squeeze=False)
    fig.suptitle("held-out poses: forward kinematics from the encoder readings against the measurement")
    for ax, kind in zip(axes[0], kinds):
        unit, factor = ("um", 1e6) if kind == "position" else ("urad", 1e6)
        for label, errors in held_out.items():
            values = factor * errors[kind]
            ax.plot(np.arange(len(values)), values, "o", ms=4,
                    label=f"{label} geometry (RMS {np.sqrt(np.mean(values**2)):.3g} {unit})")
        ax.set_yscale("log")
        ax.set_xlabel("held-out measurement")
        ax.set_ylabel(f"{kind} error [{unit}]")
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
