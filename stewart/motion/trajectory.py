"""Reference trajectories in pose space: smooth point-to-point moves, sampled paths and
periodic Fourier series (the excitation trajectories of :mod:`stewart.identification.excitation`).

Every trajectory answers ``sample(t) -> (x, xdot, xddot)`` for a scalar time or an array
of times (shapes ``(6,)`` or ``(N, 6)``), and holds its end pose at rest after ``duration``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..model.kinematics import POSE_AXES, POSE_RATES
from ..model import arguments

__all__ = ["PointToPoint", "SampledTrajectory", "FourierTrajectory", "PROFILES", "load"]


def _sinusoidal(s):
    """Cycloidal profile: the velocity rises as ``sin^2(pi s)`` from zero to its maximum at
    mid-move and falls back (Narayan Rao et al. 2017, fig. 15); returns position, rate and
    second rate of the fraction of the move done at normalised time ``s``."""
    two_pi = 2.0 * np.pi
    return (
        s - np.sin(two_pi * s) / two_pi,
        1.0 - np.cos(two_pi * s),
        two_pi * np.sin(two_pi * s),
    )


def _quintic(s):
    """Minimum-jerk quintic ``10 s^3 - 15 s^4 + 6 s^5``: zero velocity and acceleration at both ends."""
    return (
        s**3 * (10.0 - 15.0 * s + 6.0 * s**2),
        30.0 * s**2 * (1.0 - s) ** 2,
        60.0 * s * (1.0 - s) * (1.0 - 2.0 * s),
    )


PROFILES = {"sinusoidal": _sinusoidal, "quintic": _quintic}


#: Bound on the profiles' normalised rate and second rate over a move (2 pi for both).
_PROFILE_BOUND = 2.0 * np.pi


def _times(t, name: str = "t") -> np.ndarray:
    arr = arguments.reals(name, t)
    if arr.ndim > 1 or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected a finite time or a 1-D array of finite times")
    return arr


@dataclass(frozen=True)
class PointToPoint:
    """A straight move in pose space from ``start`` to ``goal`` over ``duration`` seconds,
    timed by ``profile`` ("sinusoidal", the seed paper's profile, or "quintic")."""

    start: np.ndarray
    goal: np.ndarray
    duration: float
    profile: str = "sinusoidal"

    def __post_init__(self):
        start = arguments.states("start", self.start)
        goal = arguments.states("goal", self.goal)
        if start.ndim != 1 or goal.ndim != 1:
            raise ValueError("start, goal: expected one pose each, shape (6,)")
        duration = arguments.real("duration", self.duration)
        if not duration > 0:
            raise ValueError(f"duration: must be a positive number of seconds, got {duration}")
        if not isinstance(self.profile, str) or self.profile not in PROFILES:
            raise ValueError(f"profile: expected one of {sorted(PROFILES)}, got {self.profile!r}")
        with np.errstate(over="ignore", invalid="ignore"):
            delta = goal - start
            peak = _PROFILE_BOUND * np.max(np.abs(delta)) / duration / duration
        if not np.all(np.isfinite(delta)):
            raise ValueError("start, goal: too far apart for double precision")
        if not (np.isfinite(peak) and np.isfinite(_PROFILE_BOUND / duration / duration)):
            raise ValueError(f"duration: {duration} s is too short: the move's velocity or acceleration overflows")
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "goal", goal)
        object.__setattr__(self, "duration", duration)

    def sample(self, t):
        """Pose, velocity and acceleration at time(s) ``t`` (held at the goal after the move)."""
        t = _times(t)
        with np.errstate(over="ignore"):
            s = np.clip(t / self.duration, 0.0, 1.0)
        pos, rate, rate2 = PROFILES[self.profile](s)
        moving = (t >= 0.0) & (t <= self.duration)
        rate = np.where(moving, rate, 0.0) / self.duration
        rate2 = np.where(moving, rate2, 0.0) / self.duration / self.duration
        delta = self.goal - self.start
        return (
            self.start + pos[..., None] * delta,
            rate[..., None] * delta,
            rate2[..., None] * delta,
        )


class SampledTrajectory:
    """A trajectory through poses given at increasing times: a cubic spline with zero
    velocity at both ends (a C2 path, so the reference acceleration exists), or, with the
    pose rates ``velocities`` at those times too, the cubic Hermite spline through poses and
    rates (C1; a motion of constant acceleration between samples, such as
    :func:`stewart.cueing.mpc`'s, exactly)."""

    def __init__(self, times, poses, velocities=None):
        from scipy.interpolate import CubicHermiteSpline, CubicSpline

        times = _times(times, "times")
        poses = arguments.states("poses", poses)
        if times.ndim != 1 or poses.ndim != 2 or len(times) != len(poses):
            raise ValueError(f"times, poses: need N times and (N, 6) poses, got {times.shape} and {poses.shape}")
        if velocities is not None:
            velocities = arguments.states("velocities", velocities)
            if velocities.shape != poses.shape:
                raise ValueError(f"velocities: need {poses.shape} like poses, got {velocities.shape}")
        with np.errstate(over="ignore"):
            steps = np.diff(times)
        if len(times) < 2 or np.any(steps <= 0):
            raise ValueError("times: need at least two strictly increasing times")
        self.times = times
        self.poses = poses
        self.duration = float(times[-1])
        try:
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                spline = (CubicSpline(times, poses, axis=0, bc_type="clamped") if velocities is None
                          else CubicHermiteSpline(times, poses, velocities, axis=0))
        except ValueError:  # scipy's own check of the slopes: they overflowed
            spline = None
        if spline is None or not np.all(np.isfinite(spline.c)):
            raise ValueError("times, poses: the spline through these samples overflows (times too close "
                             "or values too large for double precision)")
        self._spline = spline

    @classmethod
    def from_csv(cls, path) -> "SampledTrajectory":
        """Read ``t, x, y, z, psi, theta, phi`` rows from a CSV file (:mod:`stewart.io.csvfile`:
        a header line and ``#`` comments are allowed; a header naming these columns picks
        them from a wider file, such as a simulation's output). A header that also names the
        rates ``x_dot, ..., phi_dot`` (a cueing reference) gives the Hermite spline through
        poses and rates."""
        from ..io import csvfile

        names = csvfile.header(path) or []
        rates = all(name in names for name in POSE_RATES)
        data = csvfile.read(path, ["t", *POSE_AXES, *(POSE_RATES if rates else ())])
        try:
            return cls(data[:, 0], data[:, 1:7], data[:, 7:13] if rates else None)
        except ValueError as exc:
            raise ValueError(f"{os.fspath(path)}: {exc}") from None

    def sample(self, t):
        """Pose, velocity and acceleration at time(s) ``t`` (held at the ends outside the samples)."""
        t = _times(t)
        inside = (t >= self.times[0]) & (t <= self.times[-1])
        tc = np.clip(t, self.times[0], self.times[-1])
        with np.errstate(over="ignore", invalid="ignore"):
            pos = self._spline(tc)
            vel = np.where(inside[..., None], self._spline(tc, 1), 0.0)
            acc = np.where(inside[..., None], self._spline(tc, 2), 0.0)
        if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(vel)) and np.all(np.isfinite(acc))):
            raise ValueError("t: the spline overflows at these times (values too large for double precision)")
        return pos, vel, acc


class FourierTrajectory:
    """A periodic trajectory in the six pose coordinates, a finite Fourier series about
    ``centre`` (Swevers et al. 1997, eq. 5, written for the pose instead of its rate)::

        x_j(t) = centre_j + sum_{l=1..n} ( sine[j, l-1] sin(l w t) + cosine[j, l-1] cos(l w t) )

    with ``w = 2 pi / period`` [rad/s]; ``sine`` and ``cosine`` are ``(6, n)`` amplitudes
    [m for x, y, z; rad for psi, theta, phi]. The velocity has zero mean and the pose,
    velocity and acceleration repeat every ``period``, so the motion can run ``periods``
    times in a row (``duration = periods * period``). After ``duration`` (and before 0) it
    holds the pose at 0 at rest: a trajectory that starts at rest (:attr:`starts_at_rest`)
    joins that hold smoothly.
    """

    #: The ``kind`` its files carry.
    KIND = "fourier"

    def __init__(self, centre, period, sine, cosine, periods: int = 1):
        centre = arguments.states("centre", centre)
        if centre.ndim != 1:
            raise ValueError(f"centre: expected one pose, shape (6,), got {centre.shape}")
        period = arguments.real("period", period)
        if not period > 0:
            raise ValueError(f"period: must be a positive number of seconds, got {period}")
        sine = arguments.reals("sine", sine)
        cosine = arguments.reals("cosine", cosine)
        for name, arr in (("sine", sine), ("cosine", cosine)):
            if arr.ndim != 2 or arr.shape[0] != 6 or arr.shape[1] < 1:
                raise ValueError(f"{name}: expected amplitudes of shape (6, harmonics), got {arr.shape}")
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"{name}: contains NaN or inf")
        if sine.shape != cosine.shape:
            raise ValueError(f"sine, cosine: need the same shape, got {sine.shape} and {cosine.shape}")
        self.periods = arguments.count("periods", periods, 1_000_000)
        self.centre, self.period, self.sine, self.cosine = centre, period, sine, cosine
        self.duration = self.periods * period
        orders = np.arange(1, sine.shape[1] + 1)
        with np.errstate(over="ignore", invalid="ignore"):
            peak = np.sum((np.abs(sine) + np.abs(cosine)) * (2.0 * np.pi * orders / period) ** 2)
        if not np.isfinite(peak):
            raise ValueError(f"period: {period} s is too short: the acceleration overflows")

    @property
    def harmonics(self) -> int:
        return self.sine.shape[1]

    @property
    def frequency(self) -> float:
        """The fundamental angular frequency ``w = 2 pi / period`` [rad/s]."""
        return 2.0 * np.pi / self.period

    @property
    def starts_at_rest(self) -> bool:
        """Whether the pose at 0 is ``centre`` with zero velocity and acceleration (to
        round-off), so that the run starts and ends at rest at the centre."""
        x, xd, xdd = self.series(0.0)
        scale = np.max(np.abs(self.sine) + np.abs(self.cosine)) + np.finfo(float).tiny
        tol = 1e-12 * scale
        w = self.frequency * self.harmonics
        return bool(np.all(np.abs(x - self.centre) <= tol) and np.all(np.abs(xd) <= tol * w)
                    and np.all(np.abs(xdd) <= tol * w * w))

    def series(self, t):
        """Pose, velocity and acceleration of the series itself at time(s) ``t`` (not held
        outside ``[0, duration]``)."""
        t = _times(t)
        orders = np.arange(1, self.harmonics + 1)
        rates = self.frequency * orders  # (n,)
        phase = t[..., None] * rates
        sin, cos = np.sin(phase), np.cos(phase)
        x = self.centre + sin @ self.sine.T + cos @ self.cosine.T
        xd = (cos * rates) @ self.sine.T - (sin * rates) @ self.cosine.T
        xdd = -(sin * rates**2) @ self.sine.T - (cos * rates**2) @ self.cosine.T
        return x, xd, xdd

    def sample(self, t):
        """Pose, velocity and acceleration at time(s) ``t`` (the pose at 0, at rest, outside
        ``[0, duration]``)."""
        t = _times(t)
        inside = (t >= 0.0) & (t <= self.duration)
        x, xd, xdd = self.series(np.where(inside, t, 0.0))
        return x, np.where(inside[..., None], xd, 0.0), np.where(inside[..., None], xdd, 0.0)

    def to_dict(self) -> dict:
        """The trajectory as a table (``kind``, ``period``, ``periods``, ``centre``,
        ``sine``, ``cosine``) that :meth:`from_dict` reads back exactly."""
        return {"kind": self.KIND, "period": self.period, "periods": self.periods, "centre": self.centre.tolist(),
                "sine": self.sine.tolist(), "cosine": self.cosine.tolist()}

    @classmethod
    def from_dict(cls, data) -> "FourierTrajectory":
        if not isinstance(data, dict):
            raise ValueError(f"expected a table, got {type(data).__name__}")
        if data.get("kind") != cls.KIND:
            raise ValueError(f"kind: expected {cls.KIND!r}, got {data.get('kind')!r}")
        missing = [key for key in ("period", "centre", "sine", "cosine") if key not in data]
        if missing:
            raise ValueError(f"missing {', '.join(missing)}")
        unknown = sorted(set(data) - {"kind", "period", "periods", "centre", "sine", "cosine"})
        if unknown:
            raise ValueError(f"unknown key(s) {', '.join(unknown)}")
        periods = data.get("periods", 1)
        if isinstance(periods, float) and periods.is_integer():  # a file format may write numbers as floats
            periods = int(periods)
        return cls(data["centre"], data["period"], data["sine"], data["cosine"], periods)

    def save(self, path) -> None:
        """Write the trajectory to a ``.toml`` or ``.json`` file (values round-trip exactly)."""
        from ..model import paramfile

        paramfile.write(self.to_dict(), path)

    @classmethod
    def load(cls, path) -> "FourierTrajectory":
        """Read a trajectory written by :meth:`save`; ``ValueError`` naming the file."""
        from ..model import paramfile

        path = os.fspath(path)
        if not os.path.isfile(path):
            raise ValueError(f"{path}: no such file")
        data = paramfile.read(path)
        try:
            return cls.from_dict(data)
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None


def load(path):
    """The trajectory in the file ``path``: a :class:`FourierTrajectory` from ``.toml`` or
    ``.json``, otherwise a :class:`SampledTrajectory` from CSV rows."""
    if os.fspath(path).lower().endswith((".toml", ".json")):
        return FourierTrajectory.load(path)
    return SampledTrajectory.from_csv(path)
