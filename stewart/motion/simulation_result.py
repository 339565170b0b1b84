"""The result of :func:`stewart.simulate`: :class:`SimulationResult`, its outcomes
(:data:`OUTCOMES`), summary and CSV and ``.npz`` files, and :class:`SimulationInterrupted`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..io import csvfile
from ..model.kinematics import POSE_AXES

__all__ = ["SimulationResult", "SimulationInterrupted", "OUTCOMES"]

#: Every outcome of a run and its exit code in ``stewart simulate`` (0 is success).
OUTCOMES = {
    "completed": 0,
    "failed": 4,  # stroke limit, singular or non-finite state, assembly mode left, step budget, steps < MIN_DT
    "inaccurate": 5,  # final tracking error above the tolerance
    "saturated": 6,  # commanded force above the actuator limit
    "interrupted": 130,
}


@dataclass
class SimulationResult:
    """Time series of one run, sampled every ``dt`` (legs are indexed 0-5 as in arrays).

    ``forces`` are the actuator forces after saturation (what an actuator must deliver);
    ``commanded_forces`` the controller's output before it; friction, when modelled, is
    subtracted from ``forces`` before they act on the legs.

    For a rotary rig (``metadata["kind"] == "rotary"``, issue 40) the joints are the cranks:
    ``lengths``, ``leg_velocities`` and ``forces`` hold the crank angles [rad], crank rates
    [rad/s] and motor torques [N m] (also :attr:`crank_angles`, :attr:`crank_rates` and
    :attr:`torques`), and the CSV names them ``alpha0..5``, ``alpha0_dot..`` and ``torque0..5``.

    ``outcome`` is ``"completed"`` for a successful run, else ``"failed"`` (the platform
    hit a stroke limit, left its assembly mode, passed a singularity, became non-finite or
    used up its step budget), ``"inaccurate"`` (final tracking error above the tolerance),
    ``"saturated"`` (commanded force above the actuator limit) or ``"interrupted"``; with
    several problems the most severe is kept (the order of :data:`OUTCOMES`) and
    ``problems`` lists a sentence for each. ``completed`` and ``reason`` say only whether
    the integration ran to the end.
    """

    t: np.ndarray
    x: np.ndarray
    xd: np.ndarray
    reference: np.ndarray
    reference_velocity: np.ndarray
    lengths: np.ndarray
    leg_velocities: np.ndarray
    forces: np.ndarray
    completed: bool
    reason: str
    wall_time: float
    method: str
    stopped_leg: int | None = None
    metadata: dict = field(default_factory=dict)
    commanded_forces: np.ndarray | None = None
    outcome: str = "completed"
    problems: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when the run completed with no problem."""
        return self.outcome == "completed"

    @property
    def exit_code(self) -> int:
        """The exit code of ``stewart simulate`` for this outcome (:data:`OUTCOMES`)."""
        return OUTCOMES[self.outcome]

    @property
    def rotary(self) -> bool:
        """True for a rotary rig's run (the joints are cranks)."""
        return self.metadata.get("kind") == "rotary"

    def _of_rotary(self, name: str, values: np.ndarray) -> np.ndarray:
        if not self.rotary:
            raise AttributeError(f"{name}: a linear platform's run has leg lengths, rates and forces")
        return values

    @property
    def crank_angles(self) -> np.ndarray:
        """A rotary rig's crank angles [rad] at every sample, ``(N, 6)`` (``lengths``)."""
        return self._of_rotary("crank_angles", self.lengths)

    @property
    def crank_rates(self) -> np.ndarray:
        """A rotary rig's crank rates [rad/s] at every sample (``leg_velocities``)."""
        return self._of_rotary("crank_rates", self.leg_velocities)

    @property
    def torques(self) -> np.ndarray:
        """A rotary rig's motor torques [N m] after saturation at every sample (``forces``)."""
        return self._of_rotary("torques", self.forces)

    @property
    def tracking_error(self) -> np.ndarray:
        """``reference - x`` at every sample, ``(N, 6)``."""
        return self.reference - self.x

    def summary(self) -> dict:
        """Peak force per leg, final pose error, RMS tracking error (position and angle)
        and wall time against simulated time."""
        err = self.tracking_error
        return {
            "peak_force": np.max(np.abs(self.forces), axis=0),
            "final_position_error": float(np.linalg.norm(err[-1, :3])),
            "final_angle_error": float(np.linalg.norm(err[-1, 3:])),
            "rms_position_error": float(np.sqrt(np.mean(np.sum(err[:, :3] ** 2, axis=1)))),
            "rms_angle_error": float(np.sqrt(np.mean(np.sum(err[:, 3:] ** 2, axis=1)))),
            "simulated_time": float(self.t[-1] - self.t[0]),
            "wall_time": self.wall_time,
        }

    def _columns(self):
        pose = list(POSE_AXES)
        joint, effort = ("alpha", "torque") if self.rotary else ("L", "force")
        cols = [("t", self.t[:, None])]
        cols += [
            (pose, self.x),
            ([f"{p}_dot" for p in pose], self.xd),
            ([f"{p}_ref" for p in pose], self.reference),
            ([f"{p}_dot_ref" for p in pose], self.reference_velocity),
            ([f"{joint}{i}" for i in range(6)], self.lengths),
            ([f"{joint}{i}_dot" for i in range(6)], self.leg_velocities),
            ([f"{effort}{i}" for i in range(6)], self.forces),
        ]
        names = []
        for name, _ in cols:
            names += [name] if isinstance(name, str) else name
        return names, np.hstack([arr for _, arr in cols])

    def describe(self) -> str:
        """One line naming the platform, controller, method and outcome (a CSV comment)."""
        meta = self.metadata
        return (f"platform {meta.get('platform', 'unnamed')}, controller {meta.get('controller', '?')}, "
                f"method {self.method}, dt {meta.get('dt', float('nan')):g} s, outcome {self.outcome}")

    def to_csv(self, path) -> None:
        """Write every series as columns of a CSV file (SI units): a header line, then a
        ``#`` comment naming the platform, controller and outcome, then the rows."""
        names, data = self._columns()
        csvfile.write(path, names, data, self.describe(), fmt="%.10g")

    def to_npz(self, path) -> None:
        """Write every series and the run's outcome to a compressed ``.npz`` file (``kind``: a
        rotary rig's run, whose ``lengths``, ``leg_velocities`` and ``forces`` are its crank angles,
        crank rates and motor torques, also written as ``crank_angles``, ``crank_rates`` and
        ``torques``)."""
        commanded = {} if self.commanded_forces is None else {"commanded_forces": self.commanded_forces}
        if self.rotary:
            commanded.update(crank_angles=self.lengths, crank_rates=self.leg_velocities, torques=self.forces)
        np.savez_compressed(
            path, t=self.t, x=self.x, xd=self.xd, reference=self.reference,
            reference_velocity=self.reference_velocity, lengths=self.lengths,
            leg_velocities=self.leg_velocities, forces=self.forces, completed=self.completed, reason=self.reason,
            method=self.method, outcome=self.outcome, problems=np.array(self.problems, dtype=str),
            platform=self.metadata.get("platform", "unnamed"), controller=self.metadata.get("controller", ""),
            kind=self.metadata.get("kind", "linear"),
            **commanded,
        )


class SimulationInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`simulate`; ``result`` holds the run up to that point."""

    def __init__(self, result: SimulationResult):
        super().__init__("simulation interrupted")
        self.result = result
