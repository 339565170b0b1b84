"""Controllers and actuator models for :func:`stewart.simulate`.

The control laws themselves run in the compiled loop (``stewart._simulate``); these
classes hold and document their gains.

* :class:`PID` — joint-space PID on the leg lengths with actuator forces as output, as in
  Narayan Rao et al. (2017), section VII: ``tau = Kp e + Ki int(e) + Kd edot`` with
  ``e = L_ref - L``.
* :class:`ComputedTorque` — task-space computed torque with the compiled inverse
  dynamics: ``tau = ID(x, xdot, xddot_ref + Kd (xdot_ref - xdot) + Kp (x_ref - x))``.
* :class:`OpenLoop` — no feedback: the forces come from the feed-forward schedule only.
* :class:`Actuators` — force saturation and viscous and Coulomb friction in each leg.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _checks
from .params import PlatformParams
from .platform import Platform

__all__ = ["PID", "ComputedTorque", "OpenLoop", "Actuators", "PID_BANDWIDTH_HZ", "leg_masses"]

#: Closed-loop bandwidth of the tuned leg PID for each preset, in Hz. The small
#: ``narayan2017`` platform is stiff and light; the 1500 kg ``motion_simulator`` is tuned
#: well below its hydraulic/electric actuators' typical 10-20 Hz bandwidth.
PID_BANDWIDTH_HZ = {"narayan2017": 2.5, "motion_simulator": 3.0}
DEFAULT_BANDWIDTH_HZ = 5.0


def _per_leg(name: str, value) -> np.ndarray:
    """``value`` (one number, or one per leg) as six floats; ``ValueError`` naming ``name``."""
    arr = _checks.reals(name, value)
    if arr.shape not in ((), (1,), (6,)):
        raise ValueError(f"{name}: expected one value or one per leg (6), got shape {arr.shape}")
    return np.broadcast_to(arr, (6,)).copy()


def _six(name: str, value) -> np.ndarray:
    arr = _per_leg(name, value)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise ValueError(f"{name}: gains must be finite and >= 0, got {arr.tolist()}")
    return arr


def _platform(value) -> Platform:
    if not isinstance(value, Platform):
        hint = " (build one with stewart.Platform(params))" if isinstance(value, PlatformParams) else ""
        raise ValueError(f"platform: expected a stewart.Platform, got {type(value).__name__}{hint}")
    return value


def _bandwidth(value) -> float:
    bandwidth = _checks.real("bandwidth_hz", value)
    if not bandwidth > 0:
        raise ValueError(f"bandwidth_hz: must be positive, got {bandwidth}")
    return bandwidth


def _tuned_gains(bandwidth_hz: float, **gains: np.ndarray) -> dict[str, np.ndarray]:
    """``gains`` unless one overflows (``ValueError`` naming ``bandwidth_hz``)."""
    for values in gains.values():
        if not np.all(np.isfinite(values)):
            raise ValueError(f"bandwidth_hz: {bandwidth_hz} Hz is too high: the gains overflow")
    return gains


def leg_masses(platform, x=None) -> np.ndarray:
    """Effective mass each actuator moves at pose ``x`` (default home): the diagonal of the
    leg-space mass matrix ``J_C^-T M_t J_C^-1``, with ``M_t = M T^-1`` the twist-space
    mass matrix."""
    from .kinematics import twist_transform

    platform = _platform(platform)
    x = platform.home_pose if x is None else _checks.states("x", x)
    if x.shape != (6,):
        raise ValueError(f"x: expected one pose, shape (6,), got {x.shape}")
    jac = platform.jacobian(x)
    _checks.regular_jacobian(jac)
    _checks.regular_euler_rates(x)
    with np.errstate(over="ignore", invalid="ignore"):
        jac_inv = np.linalg.inv(jac)
        m_twist = platform.mass_matrix(x) @ np.linalg.inv(twist_transform(x))
        masses = np.diag(jac_inv.T @ m_twist @ jac_inv).copy()
    return _checks.finite_result("leg_masses", masses, x)


@dataclass(frozen=True)
class PID:
    """Joint-space PID gains per leg (N/m, N/(m s), N s/m); scalars apply to every leg."""

    kp: np.ndarray
    ki: np.ndarray
    kd: np.ndarray

    def __post_init__(self):
        for name in ("kp", "ki", "kd"):
            object.__setattr__(self, name, _six(name, getattr(self, name)))

    @classmethod
    def tuned(cls, platform, bandwidth_hz: float | None = None) -> "PID":
        """Gains that put each leg's three closed-loop poles at ``-2 pi f`` (critically
        damped) for the leg's effective mass ``m`` (:func:`leg_masses`):
        ``Kp = 3 m w^2``, ``Ki = m w^3``, ``Kd = 3 m w``.

        ``f`` defaults to :data:`PID_BANDWIDTH_HZ` for a preset, else 5 Hz.
        """
        platform = _platform(platform)
        if bandwidth_hz is None:
            bandwidth_hz = PID_BANDWIDTH_HZ.get(platform.params.name, DEFAULT_BANDWIDTH_HZ)
        bandwidth_hz = _bandwidth(bandwidth_hz)
        w = np.float64(2.0 * np.pi * bandwidth_hz)
        m = leg_masses(platform)
        with np.errstate(over="ignore"):
            return cls(**_tuned_gains(bandwidth_hz, kp=3.0 * m * w**2, ki=m * w**3, kd=3.0 * m * w))


@dataclass(frozen=True)
class ComputedTorque:
    """Task-space gains (1/s^2 and 1/s) on ``[x, y, z, psi, theta, phi]``."""

    kp: np.ndarray
    kd: np.ndarray

    def __post_init__(self):
        for name in ("kp", "kd"):
            object.__setattr__(self, name, _six(name, getattr(self, name)))

    @classmethod
    def tuned(cls, bandwidth_hz: float = 5.0) -> "ComputedTorque":
        """Critically damped error dynamics at ``bandwidth_hz``: ``Kp = w^2``, ``Kd = 2 w``."""
        bandwidth_hz = _bandwidth(bandwidth_hz)
        w = np.float64(2.0 * np.pi * bandwidth_hz)
        with np.errstate(over="ignore"):
            return cls(**_tuned_gains(bandwidth_hz, kp=w**2, kd=2.0 * w))


@dataclass(frozen=True)
class OpenLoop:
    """No feedback: the actuator forces are the feed-forward forces given to the run."""


@dataclass(frozen=True)
class Actuators:
    """Actuator limits and losses per leg.

    ``force_limit`` (N) saturates the commanded force; the leg then receives
    ``tau - viscous Ldot - coulomb tanh(Ldot / coulomb_velocity)`` (a smooth Coulomb law,
    so the closed loop stays a smooth ODE).
    """

    force_limit: float | np.ndarray = np.inf
    viscous: float = 0.0
    coulomb: float = 0.0
    coulomb_velocity: float = 1e-3

    def __post_init__(self):
        limit = _per_leg("force_limit", self.force_limit)
        if not np.all(limit > 0):
            raise ValueError(f"force_limit: must be > 0, got {limit.tolist()}")
        object.__setattr__(self, "force_limit", limit)
        for name in ("viscous", "coulomb"):
            value = _checks.real(name, getattr(self, name))
            if not value >= 0:
                raise ValueError(f"{name}: must be finite and >= 0, got {value}")
            object.__setattr__(self, name, value)
        velocity = _checks.real("coulomb_velocity", self.coulomb_velocity)
        if not velocity > 0:
            raise ValueError(f"coulomb_velocity: must be > 0, got {velocity}")
        object.__setattr__(self, "coulomb_velocity", velocity)
