"""Motor sizing of a rotary rig (issue 40, "What a rig builder gets"): the motor torques, crank
speeds and crank angles along a motion reference, by the generated batch kernels of
:class:`~stewart.RotaryPlatform` (``inverse_dynamics``: ``J_alpha^T tau = M_t T xdd + V xd +
G``; ``crank_rates``: ``alpha' = J_alpha T xd``; ``crank_angles``), and per motor the peak and
RMS torque, the peak speed and power, the crank angles' range, where each peak occurs, and the
headroom against the rig's limits; with a gear ratio ``N`` also the torque ``tau / N`` and speed
``N alpha'`` at the motor.

The limits of :class:`~stewart.RotaryParams` are at the crank (``motor_torque_limit`` [N m],
``motor_speed_limit`` [rad/s], ``crank_angle_limits`` [rad]). A motor is held to the box
``|tau| <= motor_torque_limit``, ``|alpha'| <= motor_speed_limit`` of the torque-speed plane;
the headroom is ``1 - peak / limit`` (the fraction of the limit left, negative where the peak
passes it; the same at the motor as at the crank, whatever the gear ratio). The gear ratio
converts the figures only: ``crank_inertia`` already holds the rotor reflected through the
gearbox.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ..io import csvfile
from ..model import arguments
from ..model.kinematics import POSE_ACCELERATIONS, POSE_AXES, POSE_RATES
from ..model.rotary import RotaryPlatform
from ..model.rotary_params import RotaryParams, rotary_params

__all__ = ["Reference", "read_reference", "motor_sizing", "MotorSizing", "UNITS", "LAYOUTS"]

#: The layouts of a motion reference file, by their columns: a cueing reference (``stewart
#: cueing --output``: time, pose, rates, accelerations), a trajectory with rates (the Hermite
#: spline's acceleration), a trajectory of poses (the clamped cubic spline's rates and
#: accelerations, :class:`~stewart.motion.trajectory.SampledTrajectory`), and the states of
#: ``stewart id --input`` (pose, rates, accelerations, no time).
LAYOUTS = {
    "reference": ("t", *POSE_AXES, *POSE_RATES, *POSE_ACCELERATIONS),
    "poses and rates": ("t", *POSE_AXES, *POSE_RATES),
    "poses": ("t", *POSE_AXES),
    "states": (*POSE_AXES, *POSE_RATES, *POSE_ACCELERATIONS),
}

#: The unit of each per-motor figure of :meth:`MotorSizing.to_dict` (at the crank; ``at_motor``
#: holds the torque and speed at the motor, in the same units).
UNITS = {
    "peak_torque": "N m", "rms_torque": "N m", "peak_speed": "rad/s", "peak_power": "W",
    "angle_min": "rad", "angle_max": "rad", "torque_headroom": "fraction of motor_torque_limit",
    "speed_headroom": "fraction of motor_speed_limit", "angle_headroom": "rad", "time": "s",
}


class Reference(NamedTuple):
    """A motion reference: poses ``x``, rates ``xd`` and accelerations ``xdd`` (N, 6) at the
    times ``t`` (N,) (None for states without time), and the file's ``layout`` (:data:`LAYOUTS`)."""

    t: np.ndarray | None
    x: np.ndarray
    xd: np.ndarray
    xdd: np.ndarray
    layout: str


def _first_row(path: str) -> list[str] | None:
    """The fields of the first line that is not blank or a comment (a header or a row)."""
    try:
        with open(path, encoding="utf-8") as fh:
            for line in fh:
                line = line.strip()
                if line and not line.startswith("#"):
                    return [f.strip().lower() for f in line.split(",")]
    except (OSError, UnicodeDecodeError):
        return None
    return None


def _layout(path: str) -> str:
    names = csvfile.header(path)
    if names is not None:
        for layout, columns in LAYOUTS.items():
            if all(c in names for c in columns):
                return layout
        return "poses"  # csvfile.read names the missing columns
    fields = _first_row(path) or []
    return next((layout for layout, columns in LAYOUTS.items() if len(columns) == len(fields)), "poses")


def read_reference(path) -> Reference:
    """The motion reference in the CSV file ``path`` (:data:`LAYOUTS`, picked by a header's
    names, or without a header by the number of columns: 19, 13, 7 or 18); where the file gives
    no rates or accelerations they are the spline's through its samples
    (:class:`~stewart.motion.trajectory.SampledTrajectory`). ``ValueError`` naming the file."""
    from ..motion.trajectory import SampledTrajectory

    path = os.fspath(path)
    layout = _layout(path)
    columns = LAYOUTS[layout]
    data = csvfile.read(path, list(columns))
    if layout == "states":
        return Reference(None, data[:, :6], data[:, 6:12], data[:, 12:18], layout)
    t, x = data[:, 0], data[:, 1:7]
    if len(t) > 1 and not np.all(np.diff(t) > 0):
        row = int(np.flatnonzero(~(np.diff(t) > 0))[0]) + 1
        raise ValueError(f"{path}: t: the times must increase strictly (data row {row + 1}: {t[row]:.9g} s after "
                         f"{t[row - 1]:.9g} s)")
    if layout == "reference":
        return Reference(t, x, data[:, 7:13], data[:, 13:19], layout)
    try:
        spline = SampledTrajectory(t, x, data[:, 7:13] if layout == "poses and rates" else None)
        _, xd, xdd = spline.sample(t)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
    return Reference(t, x, data[:, 7:13] if layout == "poses and rates" else xd, xdd, layout)


def _peak(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per motor (a row of ``rows``, (6, N), NaN where unreachable) the largest ``|value|`` and
    its first sample."""
    magnitude = np.abs(rows)
    if np.isnan(magnitude).any():
        magnitude[np.isnan(magnitude)] = -1.0
    samples = np.argmax(magnitude, axis=1)
    return np.abs(rows[np.arange(len(rows)), samples]), samples


def _rms(rows: np.ndarray, t: np.ndarray | None) -> np.ndarray:
    """Per motor (a row of ``rows``, (6, N)) ``sqrt(int tau^2 dt / T)`` by the trapezoidal rule
    over the times ``t``; the mean over the samples where there are no times or one sample."""
    squares = rows ** 2
    if t is None or len(t) < 2:
        return np.sqrt(np.mean(squares, axis=1))
    area = (squares[:, 1:] + squares[:, :-1]) @ np.diff(t) / 2.0  # the trapezoidal rule
    return np.sqrt(area / (t[-1] - t[0]))


@dataclass(frozen=True)
class MotorSizing:
    """The sizing of a rig's motors along a reference (:func:`motor_sizing`). Per sample:
    ``angles`` [rad], ``speeds`` (crank rates) [rad/s] and ``torques`` [N m], (N, 6) at the
    crank, and ``reachable`` (N,); per motor (6,): the figures of :data:`UNITS` (over the
    reachable samples), each peak's ``*_sample`` (row of the reference) and its time."""

    rig: str
    t: np.ndarray | None
    angles: np.ndarray
    speeds: np.ndarray
    torques: np.ndarray
    reachable: np.ndarray
    gear_ratio: float
    params: RotaryParams
    motors: dict = field(default_factory=dict)

    @property
    def samples(self) -> int:
        return len(self.reachable)

    @property
    def motor_torques(self) -> np.ndarray:
        """Torques at the motor, ``tau / gear_ratio`` [N m]."""
        return self.torques / self.gear_ratio

    @property
    def motor_speeds(self) -> np.ndarray:
        """Speeds at the motor, ``gear_ratio alpha'`` [rad/s]."""
        return self.speeds * self.gear_ratio

    def time_of(self, sample: int) -> float | None:
        return None if self.t is None else float(self.t[sample])

    def _where(self, sample: int) -> str:
        time = self.time_of(sample)
        return f"sample {sample}" + ("" if time is None else f" (t = {time:.6g} s)")

    @property
    def problems(self) -> list[str]:
        """What passes the rig's limits, in words (empty when every motor is within them)."""
        out = []
        bad = np.flatnonzero(~self.reachable)
        if bad.size:
            out.append(f"{bad.size} pose(s) out of the cranks' reach at sample(s) {bad[:10].tolist()}"
                       + (" ..." if bad.size > 10 else ""))
        m, p = self.motors, self.params
        for k in range(6):
            if p.motor_torque_limit is not None and m["torque_headroom"][k] < 0:
                out.append(f"motor {k}: peak torque {m['peak_torque'][k]:.6g} N m at "
                           f"{self._where(m['peak_torque_sample'][k])} passes motor_torque_limit "
                           f"{p.motor_torque_limit[k]:.6g} N m")
            if p.motor_speed_limit is not None and m["speed_headroom"][k] < 0:
                out.append(f"motor {k}: peak speed {m['peak_speed'][k]:.6g} rad/s at "
                           f"{self._where(m['peak_speed_sample'][k])} passes motor_speed_limit "
                           f"{p.motor_speed_limit[k]:.6g} rad/s")
            if p.crank_angle_limits is not None and m["angle_headroom"][k] < 0:
                lo, hi = np.degrees(p.crank_angle_limits)
                out.append(f"crank {k}: angles {np.degrees(m['angle_min'][k]):.4g} to "
                           f"{np.degrees(m['angle_max'][k]):.4g} deg pass crank_angle_limits ({lo:.4g}, {hi:.4g}) deg")
        return out

    @property
    def within_limits(self) -> bool:
        return not self.problems

    def to_dict(self) -> dict:
        """The report: the rig, the samples, the gear ratio, the limits, and per motor the
        figures of :data:`UNITS` with each peak's sample and time, and ``at_motor`` (the
        torques and speed through the gear ratio)."""
        p, m = self.params, self.motors

        def limit(values):
            return None if values is None else [float(v) for v in values]

        motors = []
        for k in range(6):
            entry = {"motor": k}
            for key in ("peak_torque", "rms_torque", "peak_speed", "peak_power", "angle_min", "angle_max"):
                entry[key] = float(m[key][k])
                if f"{key}_sample" in m:
                    sample = int(m[f"{key}_sample"][k])
                    entry[f"{key}_sample"], entry[f"{key}_time"] = sample, self.time_of(sample)
            for key in ("torque_headroom", "speed_headroom", "angle_headroom"):
                entry[key] = None if np.isnan(m[key][k]) else float(m[key][k])
            entry["at_motor"] = {"peak_torque": float(m["peak_torque"][k] / self.gear_ratio),
                                 "rms_torque": float(m["rms_torque"][k] / self.gear_ratio),
                                 "peak_speed": float(m["peak_speed"][k] * self.gear_ratio)}
            motors.append(entry)
        reachable = int(np.count_nonzero(self.reachable))
        return {
            "rig": self.rig, "samples": self.samples, "reachable_samples": reachable,
            "duration": None if self.t is None else float(self.t[-1] - self.t[0]),
            "gear_ratio": self.gear_ratio, "units": dict(UNITS),
            "limits": {"motor_torque_limit": limit(p.motor_torque_limit), "motor_speed_limit": limit(p.motor_speed_limit),
                       "crank_angle_limits": limit(p.crank_angle_limits)},
            "within_limits": self.within_limits, "problems": self.problems, "motors": motors,
        }

    def to_json(self, path) -> None:
        with open(path, "w", encoding="utf-8") as fh:
            json.dump(self.to_dict(), fh, indent=2)
            fh.write("\n")

    def plot(self, directory) -> list[str]:
        """``motor_sizing_torque_speed.png`` in ``directory``: per motor the torque-speed points
        (at the motor with a gear ratio) against the box of the limits, the peaks marked."""
        from ..io.plots import plot_torque_speed

        p, n = self.params, self.gear_ratio
        torque_limit = None if p.motor_torque_limit is None else p.motor_torque_limit / n
        speed_limit = None if p.motor_speed_limit is None else p.motor_speed_limit * n
        where = "at the motor, gear ratio " + f"{n:g}" if n != 1.0 else "at the crank"
        os.makedirs(directory, exist_ok=True)
        path = os.path.join(os.fspath(directory), "motor_sizing_torque_speed.png")
        return [plot_torque_speed(self.motor_speeds[self.reachable], self.motor_torques[self.reachable],
                                  torque_limit, speed_limit, path,
                                  title=f"{self.rig}: motor torque against speed {where}, {self.samples:,} samples")]


def motor_sizing(rig, x, xd, xdd, *, t=None, gear_ratio: float = 1.0) -> MotorSizing:
    """The sizing of the motors of ``rig`` (a :class:`~stewart.RotaryPlatform` or
    :class:`~stewart.RotaryParams`) along the states ``x, xd, xdd`` ((N, 6) or one (6,)) at the
    times ``t`` ((N,), increasing; None for states without time, whose RMS is the mean over
    the states): crank angles, crank rates and motor torques by the generated batch kernels,
    and per motor peak and RMS torque, peak speed and power, the angles' range, the peaks'
    samples and the headroom against the rig's limits (:class:`MotorSizing`). Poses out of a
    crank's reach are left out of the figures and named by :attr:`MotorSizing.problems`;
    ``ValueError`` when none is in reach."""
    if isinstance(rig, RotaryPlatform):
        model = rig
    else:
        model = RotaryPlatform(rotary_params(rig, "rig"))
    x = np.atleast_2d(arguments.states("x", x))
    xd = np.atleast_2d(arguments.states("xd", xd))
    xdd = np.atleast_2d(arguments.states("xdd", xdd))
    arguments.same_batch(x=x, xd=xd, xdd=xdd)
    gear_ratio = arguments.real("gear_ratio", gear_ratio)
    if not (np.isfinite(gear_ratio) and gear_ratio > 0):
        raise ValueError(f"gear_ratio: must be a positive finite number, got {gear_ratio}")
    if t is not None:
        t = arguments.reals("t", t)
        if t.shape != (len(x),):
            raise ValueError(f"t: expected {len(x)} times (one per state), got shape {t.shape}")
        if not np.all(np.isfinite(t)):
            raise ValueError("t: contains NaN or inf")
        if len(t) > 1 and not np.all(np.diff(t) > 0):
            raise ValueError("t: the times must increase strictly")
    angles, ok_angles = model.crank_angles(x, return_mask=True)
    torques, ok_torques = model.inverse_dynamics(x, xd, xdd, return_mask=True)
    reachable = np.atleast_1d(ok_angles & ok_torques)
    if not reachable.any():
        raise ValueError("x: no pose of the reference is in the cranks' reach")
    if reachable.all():
        speeds = np.atleast_2d(model.crank_rates(x, xd))
    else:
        speeds = np.full_like(np.atleast_2d(angles), np.nan)
        speeds[reachable] = model.crank_rates(x[reachable], xd[reachable])
    return _sized(model.params, t, np.atleast_2d(angles), speeds, np.atleast_2d(torques), reachable, gear_ratio)


def _sized(params: RotaryParams, t, angles, speeds, torques, reachable, gear_ratio) -> MotorSizing:
    """The per-motor figures of the per-sample ones (each motor's samples a contiguous row)."""
    tau, speed, alpha = (np.ascontiguousarray(a.T) for a in (torques, speeds, angles))
    m = {}
    m["peak_torque"], m["peak_torque_sample"] = _peak(tau)
    m["peak_speed"], m["peak_speed_sample"] = _peak(speed)
    m["peak_power"], m["peak_power_sample"] = _peak(tau * speed)
    everywhere = bool(reachable.all())
    m["rms_torque"] = _rms(tau if everywhere else tau[:, reachable], None if t is None else t[reachable])
    low, high = (alpha, alpha) if everywhere else (np.where(reachable, alpha, np.inf), np.where(reachable, alpha, -np.inf))
    m["angle_min_sample"], m["angle_max_sample"] = np.argmin(low, axis=1), np.argmax(high, axis=1)
    m["angle_min"], m["angle_max"] = alpha[np.arange(6), m["angle_min_sample"]], alpha[np.arange(6), m["angle_max_sample"]]
    nan = np.full(6, np.nan)
    m["torque_headroom"] = nan if params.motor_torque_limit is None else 1.0 - m["peak_torque"] / params.motor_torque_limit
    m["speed_headroom"] = nan if params.motor_speed_limit is None else 1.0 - m["peak_speed"] / params.motor_speed_limit
    if params.crank_angle_limits is None:
        m["angle_headroom"] = nan
    else:
        lo, hi = params.crank_angle_limits
        m["angle_headroom"] = np.minimum(m["angle_min"] - lo, hi - m["angle_max"])
    return MotorSizing(params.name or "unnamed", t, angles, speeds, torques, reachable, float(gear_ratio), params, m)
