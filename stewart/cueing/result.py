"""The result of a cueing run (:class:`CueingResult`): the platform reference, the
perceived signals of vehicle, reference and (after ``simulate=True``) the achieved
motion, the metrics, the workspace check and the files it writes."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field

import numpy as np

from ..io import csvfile
from ..model.kinematics import POSE_ACCELERATIONS, POSE_AXES, POSE_RATES
from .vestibular import CHANNELS, Perceived

__all__ = ["CueingResult", "REFERENCE_COLUMNS"]

#: The columns of :meth:`CueingResult.to_csv`: time, pose, pose rates and accelerations
#: (``stewart simulate --trajectory`` picks ``t``, the pose and its rates by name).
REFERENCE_COLUMNS = ("t", *POSE_AXES, *POSE_RATES, *POSE_ACCELERATIONS)


@dataclass
class CueingResult:
    """A cueing run. ``reference`` is a :class:`~stewart.motion.trajectory.SampledTrajectory`
    through ``poses`` at the log's times (what :func:`~stewart.motion.simulation.simulate`
    takes); ``velocities`` and ``accelerations`` are its rates at those times; ``vehicle``,
    ``platform`` and ``achieved`` are :class:`~stewart.cueing.vestibular.Perceived`;
    ``reachability`` checks every pose; ``peaks`` holds the reference's largest leg speed
    [m/s] and actuator force [N] (exact kinematics and inverse dynamics), ``limits`` the
    limits they were held to (MPC) and ``beyond_limits`` whether they passed them;
    ``solver`` the MPC's timing and QP statistics; ``limiting`` what the washout's limiter did
    (:class:`~stewart.cueing.limiter.Limiting`; None without it); ``problems`` says in words
    what is wrong."""

    method: str
    platform_name: str
    log: object
    params: object
    reference: object
    poses: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray
    vehicle: Perceived
    platform: Perceived
    metrics: dict
    reachability: object
    simulation: object = None
    achieved: Perceived | None = None
    achieved_metrics: dict | None = None
    problems: list = field(default_factory=list)
    peaks: dict = field(default_factory=dict)
    limits: dict | None = None
    beyond_limits: bool = False
    solver: dict | None = None
    simulation_peaks: dict | None = None
    simulation_beyond_limits: bool = False
    limiting: object = None

    @property
    def t(self) -> np.ndarray:
        return self.log.t

    @property
    def inside(self) -> bool:
        """Whether every pose of the reference lies inside the workspace."""
        return bool(np.all(self.reachability.ok))

    @property
    def exit_code(self) -> int:
        """0 on success; 3 (``EXIT_WORKSPACE``) for a reference outside the workspace or beyond
        the leg-speed or force limits; else the simulation's own code (4 a run that failed, 6
        forces above the limit, ...), or 4 for a closed loop whose legs pass the speed limit."""
        if not self.inside or self.beyond_limits:
            return 3
        if self.simulation is None:
            return 0
        code = int(self.simulation.exit_code)
        if code == 0 and self.simulation_beyond_limits:
            return 4
        return code

    @property
    def ok(self) -> bool:
        return self.exit_code == 0

    def to_csv(self, path) -> None:
        """Write ``t``, the pose, its rates and accelerations (SI units, rad)."""
        rows = np.column_stack([self.t, self.poses, self.velocities, self.accelerations])
        csvfile.write(path, list(REFERENCE_COLUMNS), rows,
                      f"cueing reference ({self.method}) of {self.log.name} for {self.platform_name}", fmt="%.17g")

    def report(self) -> dict:
        """The report: method, platform, inputs, outcome, problems, settings and metrics (and
        the washout limiter's ``limiter`` entry, :meth:`~stewart.cueing.limiter.Limiting.report`)."""
        out = {"method": self.method, "platform": self.platform_name, "log": self.log.name,
               "duration_s": float(self.t[-1] - self.t[0]), "dt_s": self.log.dt, "ok": self.ok,
               "exit_code": self.exit_code, "inside_workspace": self.inside, "problems": list(self.problems),
               "settings": self.params.to_dict(), **self.metrics,
               "peak_excursion": dict(zip(POSE_AXES, np.max(np.abs(self.poses - self.poses[0]), axis=0).tolist())),
               **{f"peak_{name}": value for name, value in self.peaks.items()}}
        if self.limits is not None:
            out["limits"] = dict(self.limits)
        if self.solver is not None:
            out.update(self.solver)
        if self.limiting is not None:
            out["limiter"] = self.limiting.report()
        if self.simulation is not None:
            sim = self.simulation
            out["simulation"] = {"outcome": sim.outcome, "ok": sim.ok, "exit_code": int(sim.exit_code),
                                 "problems": list(sim.problems),
                                 "peak_force": np.max(np.abs(sim.forces), axis=0).tolist()}
            if self.simulation_peaks is not None:
                speed = "crank_speed" if "crank_speed" in self.simulation_peaks else "leg_velocity"
                out["simulation"][f"peak_{speed}"] = self.simulation_peaks[speed]
            if self.achieved_metrics is not None:
                out["simulation"].update(self.achieved_metrics)
        return out

    def to_json(self, path) -> None:
        """Write :meth:`report` as JSON."""
        with open(path, "w", encoding="utf-8") as fh:
            json.dump(self.report(), fh, indent=2)
            fh.write("\n")

    def plot(self, directory) -> list[str]:
        """Write ``cueing_perceived.png`` (per channel: vehicle, reference and achieved
        perceived signals) and ``cueing_reference.png`` (the pose from home, the washout
        limiter's intervals shaded) into
        ``directory``; returns their paths. Needs matplotlib."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        os.makedirs(directory, exist_ok=True)
        t = self.t
        fig, axes = plt.subplots(3, 2, figsize=(10, 8), sharex=True)
        units = ["m/s²"] * 3 + ["rad/s"] * 3
        for j, name in enumerate(CHANNELS):
            ax = axes[j % 3, j // 3]
            ax.plot(t, self.vehicle.channels[:, j], label="vehicle")
            ax.plot(t, self.platform.channels[:, j], label="reference")
            if self.achieved is not None:
                ax.plot(t, self.achieved.channels[:, j], "--", label="achieved")
            ax.set_ylabel(f"perceived {name} [{units[j]}]")
            ax.grid(True, alpha=0.3)
        axes[0, 0].legend()
        for ax in axes[-1]:
            ax.set_xlabel("t [s]")
        fig.tight_layout()
        paths = [os.path.join(directory, "cueing_perceived.png")]
        fig.savefig(paths[0], dpi=90)
        plt.close(fig)
        fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
        d = self.poses - self.poses[0]
        for k, name in enumerate(POSE_AXES[:3]):
            axes[0].plot(t, d[:, k], label=name)
        for k, name in enumerate(POSE_AXES[3:], start=3):
            axes[1].plot(t, np.degrees(d[:, k]), label=name)
        axes[0].set_ylabel("position from home [m]")
        axes[1].set_ylabel("angle [deg]")
        axes[1].set_xlabel("t [s]")
        spans = self.limiting.intervals() if self.limiting is not None else []
        for ax in axes:
            for k, span in enumerate(spans):
                ax.axvspan(span["start_s"], span["end_s"], color="0.9", label=None if k else "limited")
            ax.legend()
            ax.grid(True, alpha=0.3)
        fig.tight_layout()
        paths.append(os.path.join(directory, "cueing_reference.png"))
        fig.savefig(paths[1], dpi=90)
        plt.close(fig)
        return paths
