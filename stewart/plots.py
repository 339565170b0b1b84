"""PNG figures of a simulation run, after Narayan Rao et al. (2017), figs. 15-18:
reference and actual pose, tracking error, leg (input) forces and leg velocities.
Needs matplotlib (``pip install stewart[plot]``)."""

from __future__ import annotations

import os

import numpy as np

__all__ = ["plot_run"]

_POSE = [("x", "m"), ("y", "m"), ("z", "m"), ("psi", "rad"), ("theta", "rad"), ("phi", "rad")]


def _pyplot():
    try:
        import matplotlib
    except ImportError:
        raise ImportError("plots need matplotlib: pip install 'stewart[plot]'") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _figure(plt, title):
    fig, axes = plt.subplots(2, 3, figsize=(12, 6), sharex=True, constrained_layout=True)
    fig.suptitle(title)
    return fig, axes.ravel()


def plot_run(result, directory, prefix: str = "run", title: str = "") -> list[str]:
    """Write ``{prefix}_pose.png``, ``_error.png``, ``_forces.png`` and
    ``_leg_velocities.png`` into ``directory``; returns their paths."""
    plt = _pyplot()
    os.makedirs(directory, exist_ok=True)
    label = f"{title}: " if title else ""
    t = result.t
    paths = []

    fig, axes = _figure(plt, f"{label}pose, reference (dashed) and actual")
    for k, ax in enumerate(axes):
        ax.plot(t, result.reference[:, k], "k--", lw=1, label="reference")
        ax.plot(t, result.x[:, k], lw=1.5, label="actual")
        ax.set_ylabel(f"{_POSE[k][0]} [{_POSE[k][1]}]")
    axes[0].legend()
    paths.append(_save(plt, fig, directory, prefix, "pose", axes[3:]))

    fig, axes = _figure(plt, f"{label}tracking error (reference - actual)")
    for k, ax in enumerate(axes):
        scale, unit = (1e3, "mm") if k < 3 else (1e3, "mrad")
        ax.plot(t, scale * result.tracking_error[:, k])
        ax.set_ylabel(f"{_POSE[k][0]} error [{unit}]")
    paths.append(_save(plt, fig, directory, prefix, "error", axes[3:]))

    fig, axes = _figure(plt, f"{label}actuator forces")
    for k, ax in enumerate(axes):
        ax.plot(t, result.forces[:, k])
        ax.set_ylabel(f"leg {k} force [N]")
    paths.append(_save(plt, fig, directory, prefix, "forces", axes[3:]))

    fig, axes = _figure(plt, f"{label}leg velocities")
    for k, ax in enumerate(axes):
        ax.plot(t, 1e3 * result.leg_velocities[:, k])
        ax.set_ylabel(f"leg {k} velocity [mm/s]")
    paths.append(_save(plt, fig, directory, prefix, "leg_velocities", axes[3:]))
    return paths


def _save(plt, fig, directory, prefix, name, bottom_axes) -> str:
    for ax in bottom_axes:
        ax.set_xlabel("time [s]")
    for ax in fig.axes:
        ax.grid(True, alpha=0.3)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))
    path = os.path.join(directory, f"{prefix}_{name}.png")
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def plot_bars(labels, series: dict[str, np.ndarray], ylabel: str, title: str, path: str) -> str:
    """A grouped bar chart: one group per label, one bar per series."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(9, 4.5), constrained_layout=True)
    width = 0.8 / len(series)
    pos = np.arange(len(labels))
    for k, (name, values) in enumerate(series.items()):
        ax.bar(pos + (k - (len(series) - 1) / 2) * width, values, width, label=name)
    ax.set_xticks(pos, labels)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend()
    ax.grid(True, axis="y", alpha=0.3)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
