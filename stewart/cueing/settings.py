"""The settings of MPC cueing (:class:`MPCParams`): horizon, weights and limits, from a TOML
file or scaled to a platform (:meth:`MPCParams.for_platform`).

A TOML file has three sections, each key optional::

    [horizon]
    duration = 1.0        # s, the prediction horizon
    steps = 10            # equal prediction intervals (each at least one log sample long)
    preview = false       # true: predict with the log's future (a recorded run); false: hold
                          # the vehicle's present signals over the horizon (a live simulator)

    [weights]             # relative weights of the squared, scaled errors
    specific_force = [1.0, 1.0, 1.0]      # perceived fx, fy, fz error / perception threshold
    angular_velocity = [1.0, 1.0, 1.0]    # perceived wx, wy, wz error / perception threshold
    position = 0.05       # pose from home / the pose box, per axis or one value
    velocity = 0.01       # pose rate / (pose box per second)
    acceleration = 0.001  # pose acceleration / (pose box per second^2)

    [limits]
    force = 8000.0        # N, |actuator force| (default: twice the largest static leg force at home)
    margin = 0.1          # share of the force and leg-speed limits the plan keeps for the
                          # controller where it can (the limits themselves always hold)
    leg_velocity = 0.7    # m/s, |leg extension rate| (default: one stroke per second)
    stroke_margin = 0.01  # m, kept from each end of the stroke
    tilt_rate = 3.0       # deg/s, roll and pitch rates beyond the vehicle's or against them
                          # (the rotation a rider would feel that the vehicle does not have)
    box = [0.3, 0.3, 0.3, 0.3, 0.3, 0.3]   # m, m, m, rad, rad, rad from home (default: 90 % of
                                           # the platform's free excursion along each axis)
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace

import numpy as np

from .._modules import moved_names
from ..io import tomlfile
from ..model import reachability
from ..model.platform import as_platform
from . import rotary, vestibular

__all__ = ["MPCParams", "FORCE_LIMIT_PER_STATIC", "LEG_VELOCITY_PER_STROKE", "BOX_SHARE"]

#: Default force limit: this many times the largest static leg force at home.
FORCE_LIMIT_PER_STATIC = 2.0
#: Default leg speed limit: strokes per second.
LEG_VELOCITY_PER_STROKE = 1.0
#: Default pose box: this share of the free excursion along each axis (the legs' clearance,
#: the base and the plate, which the QP does not constrain, bind first on combined motions).
BOX_SHARE = 0.9

_SECTIONS = {
    "horizon": ("duration", "steps", "preview"),
    "weights": ("specific_force", "angular_velocity", "position", "velocity", "acceleration"),
    "limits": ("force", "margin", "leg_velocity", "stroke_margin", "tilt_rate", "box"),
}
_PER_AXIS = {"specific_force": 3, "angular_velocity": 3, "position": 6, "velocity": 6, "acceleration": 6, "box": 6}


@dataclass(frozen=True)
class MPCParams:
    """MPC cueing settings (the module docstring gives the TOML layout). ``tilt_rate`` in
    rad/s here (degrees per second in the file); ``force``, ``leg_velocity`` and ``box``
    None until :meth:`for_platform` fills them."""

    duration: float = 1.0
    steps: int = 10
    preview: bool = False
    specific_force: tuple = (1.0, 1.0, 1.0)
    angular_velocity: tuple = (1.0, 1.0, 1.0)
    position: tuple = (0.05,) * 6
    velocity: tuple = (0.01,) * 6
    acceleration: tuple = (0.001,) * 6
    force: float | None = None
    margin: float = 0.1
    leg_velocity: float | None = None
    stroke_margin: float = 0.01
    tilt_rate: float = vestibular.TILT_RATE_LIMIT
    box: tuple | None = None
    gravity: float = 9.81
    source: str = field(default="defaults", compare=False)

    def __post_init__(self):
        where = self.source
        for name, size in _PER_AXIS.items():
            value = getattr(self, name)
            if value is None and name == "box":  # filled by for_platform
                continue
            try:
                arr = np.broadcast_to(np.asarray(value, dtype=float), (size,))
            except (TypeError, ValueError):
                raise ValueError(f"{where}: {self._key(name)}: need one number or {size}, got {value!r}") from None
            strict = name == "box"
            if not np.all(np.isfinite(arr)) or np.any(arr <= 0 if strict else arr < 0):
                raise ValueError(f"{where}: {self._key(name)}: must be {'> 0' if strict else '>= 0'}, got {arr.tolist()}")
            object.__setattr__(self, name, tuple(float(v) for v in arr))
        for name, low, high in (("duration", 0.0, math.inf), ("force", 0.0, math.inf),
                                ("leg_velocity", 0.0, math.inf), ("tilt_rate", 0.0, math.inf),
                                ("gravity", 0.0, math.inf)):
            value = getattr(self, name)
            if value is None:
                continue
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and low < value < high):
                raise ValueError(f"{where}: {self._key(name)}: must be a number > 0, got {value!r}")
        for name in ("margin", "stroke_margin"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and 0 <= value < math.inf):
                raise ValueError(f"{where}: {self._key(name)}: must be a number >= 0, got {value!r}")
        if self.margin >= 1:
            raise ValueError(f"{where}: limits.margin: must be below 1, got {self.margin!r}")
        if not (isinstance(self.steps, int) and not isinstance(self.steps, bool) and self.steps >= 2):
            raise ValueError(f"{where}: horizon.steps: must be an integer >= 2, got {self.steps!r}")
        if not isinstance(self.preview, bool):
            raise ValueError(f"{where}: horizon.preview: must be true or false, got {self.preview!r}")

    @staticmethod
    def _key(name: str) -> str:
        for section, keys in _SECTIONS.items():
            if name in keys:
                return f"{section}.{name}"
        return name

    def intervals(self, dt: float) -> np.ndarray:
        """The prediction intervals [s] for log samples ``dt`` apart: ``steps`` equal ones
        spanning ``duration`` (the first input is applied for one sample, then the plan is
        made again); intervals shorter than a sample are a ``ValueError``."""
        h = self.duration / self.steps
        if h < dt * (1 - 1e-9):
            raise ValueError(f"{self.source}: horizon.duration: {self.duration:g} s with {self.steps} steps gives "
                             f"intervals shorter than the log's sample interval {dt:g} s; need duration >= "
                             f"{self.steps * dt:g} s or fewer steps")
        return np.full(self.steps, h)

    @classmethod
    def for_platform(cls, platform, **overrides) -> "MPCParams":
        """The settings with the limits left open filled from ``platform``: ``force`` at
        :data:`FORCE_LIMIT_PER_STATIC` times its largest static leg force at home,
        ``leg_velocity`` at :data:`LEG_VELOCITY_PER_STROKE` strokes per second (the stroke of
        ``leg_length_limits``), ``box`` :data:`BOX_SHARE` of the free excursion along each
        pose axis (:func:`stewart.model.reachability.axis_excursions`).

        On a rotary rig (:class:`~stewart.RotaryPlatform` or :class:`~stewart.RotaryParams`),
        ``force`` is the motors' torque [N m] and ``leg_velocity`` their speed [rad/s] at the crank:
        by default the least of ``motor_torque_limit`` and ``motor_speed_limit``
        (:func:`stewart.cueing.rotary.motor_limits`), ``box`` :data:`BOX_SHARE` of the free
        excursion within every limit of the rotary workspace and the cranks' reach
        (:func:`stewart.cueing.rotary.axis_excursions`); ``stroke_margin`` is unused."""
        plat = rotary.rotary_rig(platform)
        plat = as_platform(platform) if plat is None else plat
        base = cls(**overrides)
        changes = {}
        if rotary.is_rotary(plat):
            torque, speed = rotary.motor_limits(plat)
            if base.force is None:
                changes["force"] = float(np.min(torque))
            if base.leg_velocity is None:
                changes["leg_velocity"] = float(np.min(speed))
            if base.box is None:
                changes["box"] = tuple(BOX_SHARE * rotary.axis_excursions(plat))
            return replace(base, **changes)
        if base.force is None:
            home = plat.home_pose
            static = plat.inverse_dynamics(home, np.zeros(6), np.zeros(6))
            changes["force"] = FORCE_LIMIT_PER_STATIC * float(np.max(np.abs(static)))
        limits = plat.params.leg_length_limits
        if limits is None:
            raise ValueError(f"{plat.params.name or 'platform'}: MPC cueing needs leg_length_limits")
        if base.leg_velocity is None:
            changes["leg_velocity"] = LEG_VELOCITY_PER_STROKE * (limits[1] - limits[0])
        if base.box is None:
            changes["box"] = tuple(BOX_SHARE * reachability.axis_excursions(plat))
        if 2 * base.stroke_margin >= limits[1] - limits[0]:
            raise ValueError(f"{base.source}: limits.stroke_margin: {base.stroke_margin:g} m leaves no stroke "
                             f"of {limits[1] - limits[0]:g} m")
        return replace(base, **changes)

    def for_platform_of(self, platform) -> "MPCParams":
        """These settings with the limits they leave open filled from ``platform``
        (:meth:`for_platform`); themselves when none is open."""
        if self.force is not None and self.leg_velocity is not None and self.box is not None:
            return self
        return MPCParams.for_platform(platform, **{k: getattr(self, k) for k in self.__dataclass_fields__
                                                   if getattr(self, k) is not None})

    @classmethod
    def load(cls, path, platform=None) -> "MPCParams":
        """Settings from a TOML file (module docstring); what it leaves out comes from
        :meth:`for_platform` (or the plain defaults without ``platform``)."""
        path = os.fspath(path)
        overrides = {}
        for (_, key), value in tomlfile.read_sections(path, _SECTIONS).items():
            if key == "tilt_rate":
                if not isinstance(value, (int, float)) or isinstance(value, bool) or value <= 0:
                    raise ValueError(f"{path}: [limits] tilt_rate: must be a number > 0 (deg/s), got {value!r}")
                value = math.radians(value)
            overrides[key] = value
        overrides["source"] = path
        if platform is not None:
            return cls.for_platform(platform, **overrides)
        return cls(**overrides)

    def to_dict(self) -> dict:
        """The settings under the TOML file's section and key names (deg/s for the tilt rate)."""
        out = {}
        for section, keys in _SECTIONS.items():
            out[section] = {}
            for key in keys:
                value = getattr(self, key)
                if key == "tilt_rate":
                    value = math.degrees(value)
                out[section][key] = list(value) if isinstance(value, tuple) else value
        return out


#: Moved in 0.2.1, deprecated aliases until 0.3.0.
__getattr__ = moved_names(__name__, {"read_sections": "stewart.io.tomlfile"})
