"""The vestibular model: what a person senses of a motion, per axis of the head frame.

Semicircular canals (angular velocity ``w`` [rad/s] to perceived angular velocity), the
torsion-pendulum model with adaptation in the form of Telban & Cardullo (2005, NASA
CR-2005-213747, sec. 2.2)::

    w_hat / w = tau_a tau_L s^2 / ((tau_a s + 1) (tau_L s + 1) (tau_S s + 1))

with the long time constant ``tau_L = 5.73 s``, the short one ``tau_S = 0.005 s`` and the
adaptation ``tau_a = 80 s`` (Telban & Cardullo 2005, after Fernandez & Goldberg 1971).

Otoliths (specific force ``f`` [m/s^2] to perceived specific force), Young & Meiry (1968,
"A revised dynamic otolith model", Aerospace Medicine 39)::

    f_hat / f = K (tau_a s + 1) / ((tau_L s + 1) (tau_S s + 1))

with ``K = 0.4``, ``tau_a = 13.2 s``, ``tau_L = 5.33 s``, ``tau_S = 0.66 s`` (the constants
Reid & Nahon 1985 use in their washout study).

Perception thresholds, used by :mod:`stewart.cueing.metrics` for false cues: 3.0, 3.6 and
2.6 deg/s in roll, pitch and yaw (Telban & Cardullo 2005, table 2); 0.17, 0.17 and 0.28
m/s^2 for the specific force along x, y, z (Reid & Nahon 1985, after Meiry 1965).

Each channel is simulated with :func:`scipy.signal.lsim` from the steady state of its
first sample, so a log that starts at rest (``f = [0, 0, 9.81]``) has no start transient.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy import signal

from ..model import kinematics

__all__ = ["CANAL", "OTOLITH", "THRESHOLDS", "TILT_RATE_LIMIT", "CHANNELS", "Perceived", "canal", "otolith", "perceive",
           "vehicle", "platform_motion", "platform_signals"]

#: Semicircular canal time constants [s] (Telban & Cardullo 2005).
CANAL = {"tau_L": 5.73, "tau_S": 0.005, "tau_a": 80.0}
#: Otolith gain and time constants [s] (Young & Meiry 1968).
OTOLITH = {"K": 0.4, "tau_a": 13.2, "tau_L": 5.33, "tau_S": 0.66}
#: The six perceived channels, in the order of :attr:`Perceived.channels`.
CHANNELS = ("fx", "fy", "fz", "wx", "wy", "wz")
#: Perception thresholds per channel: m/s^2 for fx, fy, fz (Reid & Nahon 1985), rad/s for
#: wx, wy, wz (3.0, 3.6, 2.6 deg/s, Telban & Cardullo 2005).
THRESHOLDS = dict(zip(CHANNELS, (0.17, 0.17, 0.28, *np.radians([3.0, 3.6, 2.6]))))
#: The tilt rate [rad/s] below which a rider feels a tilt's force but not its rotation, 3 deg/s
#: (the roll threshold above; Reid & Nahon 1985 limit tilt coordination to it).
TILT_RATE_LIMIT = float(np.radians(3.0))


def canal() -> signal.TransferFunction:
    """The semicircular canals' transfer function (module docstring)."""
    c = CANAL
    den = np.polymul(np.polymul([c["tau_a"], 1.0], [c["tau_L"], 1.0]), [c["tau_S"], 1.0])
    return signal.TransferFunction([c["tau_a"] * c["tau_L"], 0.0, 0.0], den)


def otolith() -> signal.TransferFunction:
    """The otoliths' transfer function (module docstring)."""
    o = OTOLITH
    return signal.TransferFunction(np.multiply(o["K"], [o["tau_a"], 1.0]),
                                   np.polymul([o["tau_L"], 1.0], [o["tau_S"], 1.0]))


class Perceived(NamedTuple):
    """Perceived (or, from :func:`platform_signals`, actual) specific force ``f`` ``(N, 3)``
    [m/s^2] and angular velocity ``w`` ``(N, 3)`` [rad/s] in the head frame at times ``t``."""

    t: np.ndarray
    f: np.ndarray
    w: np.ndarray

    @property
    def channels(self) -> np.ndarray:
        """``(N, 6)``: fx, fy, fz, wx, wy, wz."""
        return np.column_stack([self.f, self.w])


def _filter(system: signal.TransferFunction, t: np.ndarray, u: np.ndarray, before=None) -> np.ndarray:
    """Each column of ``u`` through ``system``, starting from the steady state of ``before``
    (one value per column; default: the first row)."""
    ss = system.to_ss()
    out = np.empty_like(u)
    before = u[0] if before is None else np.asarray(before, dtype=float)
    for j in range(u.shape[1]):
        x0 = -np.linalg.solve(ss.A, ss.B[:, 0] * before[j])
        _, y, _ = signal.lsim(ss, u[:, j], t - t[0], X0=x0)
        out[:, j] = y
    return out


def perceive(t, f, w, before=None) -> Perceived:
    """The perceived specific force and angular velocity of ``f`` and ``w`` sampled at ``t``,
    after the signals ``before = (f0, w0)`` held long (default: the first samples)."""
    t = np.asarray(t, dtype=float)
    f0, w0 = (None, None) if before is None else before
    return Perceived(t, _filter(otolith(), t, np.asarray(f, dtype=float), f0),
                     _filter(canal(), t, np.asarray(w, dtype=float), w0))


def vehicle(log) -> Perceived:
    """What the driver of :class:`~stewart.cueing.log.VehicleLog` ``log`` perceives."""
    return perceive(log.t, log.f, log.w)


def platform_signals(poses, velocities, accelerations, gravity: float = 9.81) -> tuple[np.ndarray, np.ndarray]:
    """Specific force and angular velocity at {P}'s origin in the platform frame {P} for
    poses, pose rates and pose accelerations ``(N, 6)``: ``f = R^T (a + [0, 0, g])`` (gravity
    along -z of {B}, seen from the tilted platform) and ``w = R^T J_A [psi', theta', phi']``
    (eq. 8). At rest, level, ``f = [0, 0, g]``."""
    x = np.atleast_2d(np.asarray(poses, dtype=float))
    xd = np.atleast_2d(np.asarray(velocities, dtype=float))
    xdd = np.atleast_2d(np.asarray(accelerations, dtype=float))
    rot = kinematics.rotation(x)
    lin = xdd[:, :3] + np.array([0.0, 0.0, gravity])
    f = np.einsum("nji,nj->ni", rot, lin)
    omega = np.einsum("nij,nj->ni", kinematics.euler_rate_jacobian(x), xd[:, 3:])
    w = np.einsum("nji,nj->ni", rot, omega)
    return f, w


def platform_motion(t, poses, velocities, accelerations, gravity: float = 9.81) -> Perceived:
    """What a rider at {P}'s origin perceives of a platform motion (:func:`platform_signals`
    through the vestibular model) that starts from rest at its first pose."""
    f, w = platform_signals(poses, velocities, accelerations, gravity)
    rest = platform_signals(np.asarray(poses, dtype=float)[:1], np.zeros((1, 6)), np.zeros((1, 6)), gravity)
    return perceive(t, f, w, (rest[0][0], rest[1][0]))
