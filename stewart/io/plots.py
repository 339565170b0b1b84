"""PNG figures of a simulation run, after Narayan Rao et al. (2017), figs. 15-18:
reference and actual pose, tracking error, leg (input) forces and leg velocities; and of
an optimized move: forces and leg strokes against their limits; and of an excitation
trajectory against its limits. Needs matplotlib (``pip install stewart[plot]``)."""

from __future__ import annotations

import os

import numpy as np

from ..model.kinematics import POSE_AXES, POSE_UNITS

__all__ = ["pyplot", "plot_run", "plot_move", "plot_excitation", "plot_bars", "run_title", "plot_workspace_slices",
           "plot_force_prediction"]

_POSE = list(zip(POSE_AXES, POSE_UNITS, strict=True))


def pyplot():
    """matplotlib's ``pyplot`` on the file-writing Agg backend; ``ImportError`` saying how to
    install it when matplotlib is absent (the ``plot`` extra). Every figure of the package
    is drawn through it."""
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


def run_title(result) -> str:
    """The platform and the controller of a run, from its metadata (``"narayan2017, PID"``)."""
    return ", ".join(str(result.metadata[key]) for key in ("platform", "controller") if result.metadata.get(key))


def plot_run(result, directory, prefix: str = "run", title: str | None = None) -> list[str]:
    """Write ``{prefix}_pose.png``, ``_error.png``, ``_forces.png`` and
    ``_leg_velocities.png`` into ``directory``; returns their paths.

    Each figure's title names the platform and the controller (:func:`run_title`) unless
    ``title`` is given."""
    plt = pyplot()
    os.makedirs(directory, exist_ok=True)
    title = run_title(result) if title is None else title
    label = f"{title}: " if title else ""
    t = result.t
    paths = []

    fig, axes = _figure(plt, f"{label}pose, reference (wide grey) and actual")
    for k, ax in enumerate(axes):
        # The reference is drawn first, wide and light, so that the actual pose on top
        # leaves it visible wherever the two agree.
        ax.plot(t, result.reference[:, k], color="0.75", lw=5, solid_capstyle="butt", label="reference")
        ax.plot(t, result.x[:, k], color="C0", lw=1.2, label="actual")
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


def plot_move(move, directory, limits=None, prefix: str = "optimize") -> list[str]:
    """Write ``{prefix}_forces.png`` (the actuator forces, held over each interval, with the
    force limit dashed) and ``{prefix}_legs.png`` (the leg lengths at the nodes, with the
    stroke limits dashed) of a :class:`stewart.motion.optimize.MinimumEffortMove` into
    ``directory``; ``limits`` is ``(force_limit, stroke)``, either may be None. Returns the
    paths."""
    plt = pyplot()
    os.makedirs(directory, exist_ok=True)
    force_limit, stroke = (None, None) if limits is None else limits
    title = f"{move.platform}: minimum-effort move"
    paths = []
    fig, axes = _figure(plt, f"{title}, actuator forces (limit dashed)")
    for k, ax in enumerate(axes):
        ax.step(move.t, np.append(move.tau[:, k], move.tau[-1, k]), where="post")
        if force_limit is not None and np.isfinite(np.ravel(force_limit)[0]):
            bound = np.broadcast_to(force_limit, (6,))[k]
            for value in (-bound, bound):
                ax.axhline(value, color="0.4", ls="--", lw=1)
        ax.set_ylabel(f"leg {k} force [N]")
    paths.append(_save(plt, fig, directory, prefix, "forces", axes[3:]))
    fig, axes = _figure(plt, f"{title}, leg lengths (stroke limits dashed)")
    for k, ax in enumerate(axes):
        ax.plot(move.t, move.lengths[:, k], marker=".", ms=3)
        for value in stroke or ():
            ax.axhline(value, color="0.4", ls="--", lw=1)
        ax.set_ylabel(f"leg {k} length [m]")
    paths.append(_save(plt, fig, directory, prefix, "legs", axes[3:]))
    return paths


def plot_excitation(design, platform, path: str, samples: int = 2000) -> str:
    """One figure of a :class:`stewart.identification.excitation.Excitation` over one period: the
    translations and rotations, and per leg the length, velocity, acceleration and actuator
    force with their limits dashed. Returns ``path``."""
    from ..model.kinematics import leg_accelerations, leg_velocities

    plt = pyplot()
    traj, lim = design.trajectory, design.limits
    t = np.linspace(0.0, traj.period, samples)
    x, xd, xdd = traj.series(t)
    params = platform.params
    legs = [
        ("leg length [m]", platform.leg_lengths(x), lim.lengths),
        ("leg velocity [m/s]", leg_velocities(params, x, xd), (-lim.leg_velocity, lim.leg_velocity)),
        ("leg acceleration [m/s^2]", leg_accelerations(params, x, xd, xdd),
         (-lim.leg_acceleration, lim.leg_acceleration)),
        ("actuator force [N]", platform.actuator_forces(x, xd, xdd),
         (-lim.force, lim.force) if np.isfinite(lim.force) else ()),
    ]
    fig, axes = plt.subplots(2, 3, figsize=(14, 7), sharex=True, constrained_layout=True)
    fig.suptitle(f"{design.platform}: excitation, {traj.harmonics} harmonics, condition number "
                 f"{design.condition:.3g} (limits dashed)")
    names = [name for name, _ in _POSE]
    panels = [("translation [mm]", 1e3 * (x[:, :3] - traj.centre[:3]), names[:3], ()),
              ("rotation [deg]", np.degrees(x[:, 3:] - traj.centre[3:]), names[3:], ())]
    panels += [(label, values, [f"leg {k}" for k in range(6)], bounds) for label, values, bounds in legs]
    for ax, (label, values, names, bounds) in zip(axes.ravel(), panels):
        for k, name in enumerate(names):
            ax.plot(t, values[:, k], lw=1.1, label=name)
        for value in bounds:
            ax.axhline(value, color="0.4", ls="--", lw=1)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0, 0].set_title("offset from the centre pose", fontsize=9)
    axes[0, 1].set_title("offset from the centre pose", fontsize=9)
    for ax in axes[0, :2]:
        ax.legend(fontsize=8, ncols=3)
    axes[0, 2].legend(fontsize=7, ncols=3)
    for ax in axes[1]:
        ax.set_xlabel("time [s]")
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


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


def plot_bars(labels, series: dict[str, np.ndarray], ylabel: str, title: str, path: str, *,
              xlabel: str = "", caption: str = "", value_format: str = "{:.3g}") -> str:
    """A grouped bar chart: one group per label, one bar per series, each bar labelled with
    its value; ``caption`` is printed under the title."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(10, 5), constrained_layout=True)
    width = 0.8 / len(series)
    pos = np.arange(len(labels))
    for k, (name, values) in enumerate(series.items()):
        bars = ax.bar(pos + (k - (len(series) - 1) / 2) * width, values, width, label=name)
        ax.bar_label(bars, [value_format.format(v) for v in values], fontsize=7, padding=1)
    ax.set_xticks(pos, labels)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    fig.suptitle(title)
    if caption:
        ax.set_title(caption, fontsize=9)
    ax.margins(y=0.25)  # room for the legend above the tallest bars
    ax.legend(loc="upper center", ncols=len(series))
    ax.grid(True, axis="y", alpha=0.3)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def plot_workspace_slices(slices, path: str, title: str = "", quantity: str = "margin", titles=None,
                          marks=None) -> str:
    """One heat map per :class:`stewart.studies.workspace.Slice` side by side with one colour
    scale: of the singularity margin (``quantity="margin"``) or of the lowest natural frequency
    on the preloaded leg springs (``"frequency"``, slices with a stiffness); unreachable cells (and
    for the frequency, cells the legs cannot hold) are grey. Angles are drawn in degrees. Under
    ``title`` the figure names the slices' limits in force (``Slice.limits``). ``titles`` (one per
    slice) replace the panels' titles; ``marks`` (one per slice, each ``(u, v)`` pairs in the
    slices' units, or None) are drawn on them as points (the ends of reachable ranges)."""
    plt = pyplot()
    from matplotlib.patches import Patch

    fig, axes = plt.subplots(1, len(slices), figsize=(5.2 * len(slices) + 1.2, 4.8), constrained_layout=True,
                             squeeze=False)
    cmap = plt.get_cmap("viridis").with_extremes(bad="0.85")
    maps = [getattr(s, quantity) for s in slices]
    finite = [m[np.isfinite(m)] for m in maps if np.isfinite(m).any()]
    low = 0.0 if quantity == "margin" or not finite else min(float(f.min()) for f in finite)
    top = max([float(f.max()) for f in finite] or [1.0])
    for k, (ax, s, values) in enumerate(zip(axes[0], slices, maps)):
        scale, unit = (180.0 / np.pi, "deg") if s.unit == "rad" else (1.0, s.unit)
        mesh = ax.pcolormesh(scale * s.u, scale * s.v, np.ma.masked_invalid(values), cmap=cmap, vmin=low,
                             vmax=top, shading="nearest")
        ax.set_xlabel(f"{s.axes[0]} [{unit}]")
        ax.set_ylabel(f"{s.axes[1]} [{unit}]")
        ax.set_title(titles[k] if titles else f"{s.at[0]} = {np.round(scale * s.at[1], 9):.4g} {unit}",
                     fontsize=10)  # 1e-16 shows as 0
        if marks and marks[k] is not None:
            points = scale * np.asarray(marks[k], dtype=float).reshape(-1, 2)
            ax.plot(points[:, 0], points[:, 1], "o", color="tab:red", markersize=4)
        ax.set_aspect("equal")
    if quantity == "margin":
        label, grey = f"singularity margin, 1 / cond({slices[0].jacobian}) (unit-free)", "unreachable"
    else:
        stiffness = slices[0].stiffness
        legs = f"{stiffness[0]:.3g} N/m" if np.all(stiffness == stiffness[0]) else "the legs' stiffness"
        label, grey = f"lowest natural frequency [Hz], legs of {legs}", "unreachable or not held"
    fig.colorbar(mesh, ax=axes[0].tolist(), label=label)
    axes[0][0].legend(handles=[Patch(color="0.85", label=grey)], loc="upper right", fontsize=8)
    limits = slices[0].limits
    fig.suptitle((title or f"{slices[0].platform}: workspace slices") + (f"\nlimits: {limits}" if limits else ""))
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def plot_force_prediction(t, predicted, measured, path: str, title: str = "") -> str:
    """Predicted against measured actuator forces of the six legs over time (an identified
    model on a held-out run, :func:`stewart.identification.identify.validation`), with the residual RMS per leg."""
    plt = pyplot()
    fig, axes = _figure(plt, title or "identified model: predicted and measured actuator forces")
    for leg, ax in enumerate(axes):
        rms = float(np.sqrt(np.mean((predicted[:, leg] - measured[:, leg]) ** 2)))
        ax.plot(t, measured[:, leg], color="0.6", lw=1.0, label="measured")
        ax.plot(t, predicted[:, leg], color="C0", lw=1.0, label="predicted")
        ax.set_title(f"leg {leg}: RMS error {rms:.3g} N")
        ax.set_ylabel("force [N]")
        ax.grid(True, alpha=0.3)
    for ax in axes[3:]:
        ax.set_xlabel("time [s]")
    axes[0].legend(loc="best")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
