"""Controllers and actuator models for :func:`stewart.simulate`.

The control laws themselves run in the generated C model's closed loop (``stewart_loop_derivative``
of the C API, through ``stewart.model.compiled.ClosedLoop``); these classes hold and document their gains, and each tells the loop which law it is
(:meth:`Controller.loop_settings`) and where its integral starts.

* :class:`PID` — joint-space PID on the leg lengths with actuator forces as output, as in
  Narayan Rao et al. (2017), section VII: ``tau = Kp e + Ki int(e) + Kd edot`` with
  ``e = L_ref - L``.
* :class:`ComputedTorque` — task-space computed torque with the compiled inverse
  dynamics: ``tau = ID(x, xdot, xddot_ref + Kd (xdot_ref - xdot) + Kp (x_ref - x)) + f(Ldot)``,
  where ``f`` is the platform's own leg friction (:meth:`stewart.Platform.friction_forces`)
  at the measured leg rates, as :meth:`stewart.Platform.actuator_forces` adds it.
* :class:`OpenLoop` — no feedback: the forces come from the feed-forward schedule only.
* :class:`Actuators` — force saturation and viscous and Coulomb friction in each leg.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..model import arguments, conditions
from ..model.compiled import Mode
from ..model.params import PlatformParams
from ..model.platform import Platform, as_platform, friction_law
from ..model.rotary import RotaryPlatform
from ..model.rotary_params import RotaryParams

__all__ = ["Controller", "PID", "ComputedTorque", "OpenLoop", "Actuators", "PID_BANDWIDTH_HZ", "leg_masses"]

#: Closed-loop bandwidth of the tuned leg PID for each preset, in Hz. The small
#: ``narayan2017`` platform is stiff and light; the 1500 kg ``motion_simulator`` is tuned
#: well below its hydraulic/electric actuators' typical 10-20 Hz bandwidth.
PID_BANDWIDTH_HZ = {"narayan2017": 2.5, "motion_simulator": 3.0}
DEFAULT_BANDWIDTH_HZ = 5.0


def _per_leg(name: str, value) -> np.ndarray:
    """``value`` (one number, or one per leg) as six floats; ``ValueError`` naming ``name``."""
    arr = arguments.reals(name, value)
    if arr.shape not in ((), (1,), (6,)):
        raise ValueError(f"{name}: expected one value or one per leg (6), got shape {arr.shape}")
    return np.broadcast_to(arr, (6,)).copy()


def _six(name: str, value) -> np.ndarray:
    arr = _per_leg(name, value)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise ValueError(f"{name}: must be finite and >= 0, got {arr.tolist()}")
    return arr


def _bandwidth(value) -> float:
    bandwidth = arguments.real("bandwidth_hz", value)
    if not bandwidth > 0:
        raise ValueError(f"bandwidth_hz: must be positive, got {bandwidth}")
    return bandwidth


def _tuned_gains(bandwidth_hz: float, **gains: np.ndarray) -> dict[str, np.ndarray]:
    """``gains`` unless one overflows (``ValueError`` naming ``bandwidth_hz``)."""
    for values in gains.values():
        if not np.all(np.isfinite(values)):
            raise ValueError(f"bandwidth_hz: {bandwidth_hz} Hz is too high: the gains overflow")
    return gains


def _rig(value):
    """A rotary rig's :class:`~stewart.RotaryPlatform` (of itself or its params), else
    :func:`~stewart.model.platform.as_platform` of ``value``."""
    if isinstance(value, RotaryParams):
        return RotaryPlatform(value)
    return value if isinstance(value, RotaryPlatform) else as_platform(value)


def _home(platform) -> np.ndarray:
    return platform.home if isinstance(platform, RotaryPlatform) else platform.home_pose


def leg_masses(platform, x=None) -> np.ndarray:
    """Effective mass each actuator moves at pose ``x`` (default home): the diagonal of the
    leg-space mass matrix ``J_C^-T M_t J_C^-1``, with ``M_t`` the twist-space mass matrix; of
    a rotary rig (:class:`~stewart.RotaryPlatform`), the effective inertia [kg m^2] each motor
    turns, the diagonal of ``J_alpha^-T M_t J_alpha^-1``."""
    platform = _rig(platform)
    x = _home(platform) if x is None else arguments.states("x", x)
    if x.shape != (6,):
        raise ValueError(f"x: expected one pose, shape (6,), got {x.shape}")
    return _leg_masses(platform, x)


def _leg_masses(platform: Platform, x: np.ndarray) -> np.ndarray:
    """:func:`leg_masses` of the compiled ``platform`` at the checked pose ``x``."""
    jac = platform.jacobian(x)
    conditions.check("leg_masses", x, conditions.jacobian_codes(jac))
    with np.errstate(over="ignore", invalid="ignore"):
        jac_inv = np.linalg.inv(jac)
        masses = np.diag(jac_inv.T @ platform.twist_mass_matrix(x) @ jac_inv).copy()
    return arguments.finite_result("leg_masses", masses, x)


class Controller:
    """A control law of the compiled loop: :class:`PID`, :class:`ComputedTorque` or
    :class:`OpenLoop`."""

    #: The controller's name in a run's metadata.
    label: ClassVar[str]

    def loop_settings(self) -> tuple[Mode, np.ndarray, np.ndarray, np.ndarray]:
        """The compiled loop's control law and its per-leg gains ``(mode, kp, ki, kd)``
        (unused gains are zero)."""
        raise NotImplementedError

    def initial_integral(self, platform: Platform, x0: np.ndarray, feedforward0: np.ndarray) -> np.ndarray:
        """The integral of the leg-length error at the start of a run (zero)."""
        return np.zeros(6)


@dataclass(frozen=True)
class PID(Controller):
    """Joint-space PID gains per leg (N/m, N/(m s), N s/m); scalars apply to every leg. On a
    rotary rig (:class:`~stewart.RotaryPlatform`) the joints are the cranks and the gains act on
    the crank angles with motor torques as output: N m/rad, N m/(rad s), N m s/rad."""

    label: ClassVar[str] = "PID"
    kp: np.ndarray
    ki: np.ndarray
    kd: np.ndarray

    def __post_init__(self):
        for name in ("kp", "ki", "kd"):
            object.__setattr__(self, name, _six(name, getattr(self, name)))

    def loop_settings(self) -> tuple[Mode, np.ndarray, np.ndarray, np.ndarray]:
        return Mode.PID, self.kp, self.ki, self.kd

    def initial_integral(self, platform: Platform, x0: np.ndarray, feedforward0: np.ndarray) -> np.ndarray:
        """The bumpless start: ``Ki * I = tau_static(x0) - feedforward(0)`` on every leg with
        ``Ki > 0``, so the first commanded forces hold the start pose at rest (a leg whose
        ``Ki`` is too small to represent ``I`` starts from 0)."""
        static = platform.inverse_dynamics(x0, np.zeros(6), np.zeros(6)) - feedforward0
        with np.errstate(over="ignore"):
            integral = np.divide(static, self.ki, out=np.zeros(6), where=self.ki > 0)
        return np.where(np.isfinite(integral), integral, 0.0)

    @classmethod
    def tuned(cls, platform, bandwidth_hz: float | None = None) -> "PID":
        """Gains that put each leg's three closed-loop poles at ``-2 pi f`` (critically
        damped) for the leg's effective mass ``m`` (:func:`leg_masses`):
        ``Kp = 3 m w^2``, ``Ki = m w^3``, ``Kd = 3 m w``.

        ``f`` defaults to :data:`PID_BANDWIDTH_HZ` for a preset, else 5 Hz. For a rotary rig
        ``m`` is each crank's effective inertia (:func:`leg_masses`), the gains in N m/rad.
        """
        platform = _rig(platform)
        if bandwidth_hz is None:
            bandwidth_hz = PID_BANDWIDTH_HZ.get(platform.params.name, DEFAULT_BANDWIDTH_HZ)
        bandwidth_hz = _bandwidth(bandwidth_hz)
        w = np.float64(2.0 * np.pi * bandwidth_hz)
        m = _leg_masses(platform, _home(platform))
        with np.errstate(over="ignore"):
            return cls(**_tuned_gains(bandwidth_hz, kp=3.0 * m * w**2, ki=m * w**3, kd=3.0 * m * w))


@dataclass(frozen=True)
class ComputedTorque(Controller):
    """Task-space gains (1/s^2 and 1/s) on ``[x, y, z, psi, theta, phi]``.

    The law adds back the friction of the platform's parameters at the measured leg rates;
    legs that lose more or less (:class:`Actuators` values other than the platform's) leave
    the difference to the feedback."""

    label: ClassVar[str] = "computed torque"
    kp: np.ndarray
    kd: np.ndarray

    def __post_init__(self):
        for name in ("kp", "kd"):
            object.__setattr__(self, name, _six(name, getattr(self, name)))

    def loop_settings(self) -> tuple[Mode, np.ndarray, np.ndarray, np.ndarray]:
        return Mode.COMPUTED_TORQUE, self.kp, np.zeros(6), self.kd

    @classmethod
    def tuned(cls, bandwidth_hz: float = 5.0) -> "ComputedTorque":
        """Critically damped error dynamics at ``bandwidth_hz`` (default 5 Hz): ``Kp = w^2``, ``Kd = 2 w``."""
        bandwidth_hz = _bandwidth(bandwidth_hz)
        w = np.float64(2.0 * np.pi * bandwidth_hz)
        with np.errstate(over="ignore"):
            return cls(**_tuned_gains(bandwidth_hz, kp=w**2, kd=2.0 * w))


@dataclass(frozen=True)
class OpenLoop(Controller):
    """No feedback: the actuator forces are the feed-forward forces given to the run."""

    label: ClassVar[str] = "open loop"

    def loop_settings(self) -> tuple[Mode, np.ndarray, np.ndarray, np.ndarray]:
        return Mode.OPEN_LOOP, np.zeros(6), np.zeros(6), np.zeros(6)


@dataclass(frozen=True)
class Actuators:
    """Actuator limits and losses per leg.

    ``force_limit`` (N; a rotary rig's motor torque limit in N m, by default in
    :func:`stewart.simulate` the rig's ``motor_torque_limit``) saturates the commanded force;
    the leg then receives
    ``tau - F_v Ldot - F_c tanh(Ldot / v_c)``: the friction law of
    :meth:`stewart.Platform.friction_forces` (a smooth Coulomb law, so the closed loop
    stays a smooth ODE).

    ``viscous`` (``F_v`` in N s/m), ``coulomb`` (``F_c`` in N; one value, or one per leg)
    and ``coulomb_velocity`` (``v_c`` in m/s) default to the platform's own parameters
    (:class:`~stewart.PlatformParams` ``viscous_friction``, ``coulomb_friction`` and
    ``coulomb_velocity``; no friction when it has none), so that a simulation of an
    identified machine loses what its legs lose. A value given replaces the platform's.
    """

    force_limit: float | np.ndarray = np.inf
    viscous: float | np.ndarray | None = None
    coulomb: float | np.ndarray | None = None
    coulomb_velocity: float | None = None

    def __post_init__(self):
        limit = _per_leg("force_limit", self.force_limit)
        if not np.all(limit > 0):
            raise ValueError(f"force_limit: must be > 0, got {limit.tolist()}")
        object.__setattr__(self, "force_limit", limit)
        for name in ("viscous", "coulomb"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, _six(name, getattr(self, name)))
        if self.coulomb_velocity is not None:
            velocity = arguments.real("coulomb_velocity", self.coulomb_velocity)
            if not velocity > 0:
                raise ValueError(f"coulomb_velocity: must be > 0, got {velocity}")
            object.__setattr__(self, "coulomb_velocity", velocity)

    def friction(self, params: PlatformParams | RotaryParams) -> tuple[np.ndarray, np.ndarray, float]:
        """``(F_v (6,), F_c (6,), v_c)`` on a platform with parameters ``params``: the values
        given here, else the platform's (zeros where it has none). A rotary rig's
        (:class:`~stewart.RotaryParams`) parameters hold no friction: its motors lose what is
        given here, at the crank rates (``F_v`` in N m s/rad, ``F_c`` in N m, ``v_c`` in rad/s,
        by default that of :class:`~stewart.PlatformParams`), else nothing."""
        if isinstance(params, RotaryParams):
            default = PlatformParams.__dataclass_fields__["coulomb_velocity"].default
            return (np.zeros(6) if self.viscous is None else self.viscous,
                    np.zeros(6) if self.coulomb is None else self.coulomb,
                    default if self.coulomb_velocity is None else self.coulomb_velocity)
        return friction_law(params, self.viscous, self.coulomb, self.coulomb_velocity)
