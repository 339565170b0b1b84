"""Rotary-actuator platform parameters (6-RSS rigs, issue 40): the geometry, masses and
inertias of a rig whose six motors on the base turn cranks that push the platform through
rods with ball joints at both ends, and its limits.

Leg i: a motor at b_i (in {B}) turns a crank of length r about the unit axis a_i; at crank
angle alpha_i the crank tip is c_i = b_i + r (cos(alpha_i) h_i + sin(alpha_i) (a_i x h_i)),
h_i the crank's unit direction at alpha_i = 0, normal to a_i; a rod of length d joins c_i to
the platform joint P_i = p + R p_i (p_i in {P}).  ``crank_branch[i]`` is the sign of
(P_i - c_i) . (a_i x (c_i - b_i)), the assembly mode the inverse kinematics keeps.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from . import arguments, fields, paramfile
from .errors import WrongTypeError
from .fields import TOLERANCE
from .rotary_presets import fields as _preset_fields

__all__ = ["RotaryParams", "KIND", "rotary_params"]

#: The ``kind`` of a rotary rig's parameter file (a linear platform's file has none).
KIND = "rotary"


def _unit_rows(name: str, value: Any) -> np.ndarray:
    """Six unit vectors (6, 3) in {B}, each within :data:`TOLERANCE` of length 1."""
    arr = fields.joint_axes(name, value)
    if arr is None:
        raise ValueError(f"{name}: expected six unit vectors, got None")
    return arr


def _per_motor(name: str, value: Any) -> np.ndarray | None:
    """One positive finite value or one per motor, as six floats; ``None`` for none."""
    if value is None:
        return None
    return fields.leg_coefficients(name, value, positive=True)


def _branches(value: Any) -> np.ndarray:
    arr = arguments.reals("crank_branch", value)
    if arr.shape != (6,):
        raise ValueError(f"crank_branch: expected 6 values (one per leg), got shape {arr.shape}")
    if not np.all((arr == 1.0) | (arr == -1.0)):
        raise ValueError(f"crank_branch: each value must be +1 or -1, got {arr.tolist()}")
    return arr.astype(float, copy=True)


def _angle_limits(value: Any, name: str = "crank_angle_limits", low: float = -np.pi) -> tuple[float, float] | None:
    """``(min, max)`` radians with ``low <= min < max <= pi``, or ``None``."""
    if value is None:
        return None
    arr = arguments.reals(name, value)
    if arr.shape != (2,):
        raise ValueError(f"{name}: expected (min, max), got {value!r}")
    lo, hi = arr.tolist()
    if not low <= lo < hi <= np.pi:
        raise ValueError(f"{name}: need {'-pi' if low else '0'} <= min < max <= pi (radians), got ({lo}, {hi})")
    return (lo, hi)


@dataclasses.dataclass(frozen=True, eq=False)
class RotaryParams:
    """Immutable parameter set of a 6-RSS rotary-actuator platform (SI units: m, kg, rad,
    N m at the crank; {B} z up, gravity along -z).

    Attributes
    ----------
    base_points : (6, 3) motor points b_i in {B}, on the motor axes (the crank's pivot).
    platform_points : (6, 3) platform ball-joint centres p_i in {P}.
    motor_axes : (6, 3) unit axes a_i in {B}; the crank angle is positive by the right-hand
        rule about a_i, and the motor torque acts on the crank about +a_i.
    crank_zero : (6, 3) unit directions h_i in {B} of each crank at alpha_i = 0, normal to a_i.
    crank_branch : six +1 or -1: the sign of (P_i - c_i) . (a_i x (c_i - b_i)), whether the
        rod leaves the crank tip along (+1) or against (-1) the tip's direction of motion.
    crank_length : r > 0, from the motor axis to the crank's ball joint.
    rod_length : d > 0, between the rod's two ball-joint centres.
    platform_mass, platform_inertia, platform_com : the platform with its payload, as for
        :class:`stewart.PlatformParams`: the mass, the principal moments (3,) or a (3, 3)
        tensor in {P} about the centre of mass, the centre of mass in {P} (default origin).
    crank_mass : each crank's mass (its weight acts at its centre of mass).
    crank_com_distance : the crank's centre of mass along h at alpha = 0, from the motor axis
        (negative for a counterweighted crank).
    crank_inertia : the crank's moment of inertia about the motor axis, including the motor's
        rotor and gearbox reflected to the crank (J_rotor times the gear ratio squared), which
        often dominates; at least crank_mass * crank_com_distance^2.
    rod_mass : each rod's mass.
    rod_com_distance : the rod's centre of mass from its crank end, along the rod (0..d).
    rod_inertia : the rod's transverse moment of inertia about its centre of mass. A rod is
        axisymmetric and does not spin about its own axis (as the legs of the paper's model).
    gravity : g in m/s^2 along -z of {B}.
    crank_angle_limits : optional (min, max) crank angle in radians, -pi <= min < max <= pi.
    motor_torque_limit, motor_speed_limit : optional limits at the crank, N m and rad/s, one
        value or one per motor.
    crank_joint_max_angle, platform_joint_max_angle : optional cone half-angles in radians
        (0 < angle <= pi/2) of the ball joints at the crank tips and on the platform, about
        their neutral axes (the rod's direction at the home pose, fixed in the crank and in {P}).
    rod_crank_angle_limits : optional (min, max) in radians, 0 <= min < max <= pi, of the
        rod-crank angle at the crank tip, between the crank (from the tip back to the motor
        axis) and the rod: 0 where the rod folds back over its crank, pi where it stretches
        straight out of it; both are singular (the rod normal to the tip's motion), so a rig is
        kept away from them.
    base_clearance : optional smallest height [m] of the platform's joints above the base
        plane, the horizontal plane through the highest motor point b_i (default: above it).
    crank_pin_max_tilt : optional largest tilt in radians (0 < tilt <= pi/2) of each rod out of
        its crank's plane of motion (the plane normal to the motor axis): the misalignment of a
        rod end on a pin parallel to the motor axis, the usual mount on a crank or servo horn,
        which turns freely about its pin (a cone about the rod's home direction,
        ``crank_joint_max_angle``, models a ball joint instead).
    name : optional label.

    Arrays are stored read-only; construction checks every field and raises ``ValueError``
    naming it.
    """

    base_points: np.ndarray
    platform_points: np.ndarray
    motor_axes: np.ndarray
    crank_zero: np.ndarray
    crank_branch: np.ndarray
    crank_length: float
    rod_length: float
    platform_mass: float
    platform_inertia: np.ndarray
    crank_mass: float
    crank_com_distance: float
    crank_inertia: float
    rod_mass: float
    rod_com_distance: float
    rod_inertia: float
    platform_com: np.ndarray | None = None
    gravity: float = 9.81
    crank_angle_limits: tuple[float, float] | None = None
    motor_torque_limit: np.ndarray | None = None
    motor_speed_limit: np.ndarray | None = None
    crank_joint_max_angle: float | None = None
    platform_joint_max_angle: float | None = None
    rod_crank_angle_limits: tuple[float, float] | None = None
    base_clearance: float | None = None
    crank_pin_max_tilt: float | None = None
    name: str | None = None

    def __post_init__(self) -> None:
        cone = fields.BOUNDS["spherical_joint_max_angle"]
        checked = {
            "base_points": fields.points("base_points", self.base_points),
            "platform_points": fields.points("platform_points", self.platform_points),
            "motor_axes": _unit_rows("motor_axes", self.motor_axes),
            "crank_zero": _unit_rows("crank_zero", self.crank_zero),
            "crank_branch": _branches(self.crank_branch),
            "crank_length": fields.positive("crank_length", self.crank_length),
            "rod_length": fields.positive("rod_length", self.rod_length),
            "platform_mass": fields.scalar("platform_mass", self.platform_mass),
            "platform_inertia": fields.inertia_tensor("platform_inertia", self.platform_inertia),
            "crank_mass": fields.scalar("crank_mass", self.crank_mass),
            "crank_com_distance": fields.scalar("crank_com_distance", self.crank_com_distance, minimum=None),
            "crank_inertia": fields.scalar("crank_inertia", self.crank_inertia),
            "rod_mass": fields.scalar("rod_mass", self.rod_mass),
            "rod_com_distance": fields.scalar("rod_com_distance", self.rod_com_distance),
            "rod_inertia": fields.scalar("rod_inertia", self.rod_inertia),
            "platform_com": None if self.platform_com is None else fields.vector3("platform_com", self.platform_com),
            "gravity": fields.scalar("gravity", self.gravity),
            "crank_angle_limits": _angle_limits(self.crank_angle_limits),
            "motor_torque_limit": _per_motor("motor_torque_limit", self.motor_torque_limit),
            "motor_speed_limit": _per_motor("motor_speed_limit", self.motor_speed_limit),
            "crank_joint_max_angle": fields.optional_bound("crank_joint_max_angle", self.crank_joint_max_angle, cone),
            "platform_joint_max_angle": fields.optional_bound("platform_joint_max_angle",
                                                              self.platform_joint_max_angle, cone),
            "rod_crank_angle_limits": _angle_limits(self.rod_crank_angle_limits, "rod_crank_angle_limits", 0.0),
            "base_clearance": fields.optional_bound("base_clearance", self.base_clearance,
                                                    fields.BOUNDS["base_clearance"]),
            "crank_pin_max_tilt": fields.optional_bound("crank_pin_max_tilt", self.crank_pin_max_tilt, cone),
            "name": self._checked_name(self.name),
        }
        for key, val in checked.items():
            if isinstance(val, np.ndarray):
                val = fields.readonly(val)
            object.__setattr__(self, key, val)
        normal = np.abs(np.sum(self.motor_axes * self.crank_zero, axis=1))
        if np.any(normal > TOLERANCE):
            i = int(np.argmax(normal > TOLERANCE))
            raise ValueError(f"crank_zero: direction {i} is not normal to motor axis {i} "
                             f"(cosine {normal[i]:.3g}); the crank turns in the plane normal to its axis")
        if self.crank_inertia < self.crank_mass * self.crank_com_distance ** 2 * (1.0 - 1e-12):
            raise ValueError(f"crank_inertia: {self.crank_inertia:g} kg m^2 about the motor axis is less than "
                             f"crank_mass * crank_com_distance^2 = {self.crank_mass * self.crank_com_distance ** 2:g}"
                             " (the parallel-axis part alone); no physical crank")
        if self.rod_com_distance > self.rod_length:
            raise ValueError(f"rod_com_distance: {self.rod_com_distance:g} m lies beyond the rod's "
                             f"rod_length {self.rod_length:g} m")

    @staticmethod
    def _checked_name(name: Any) -> str | None:
        if name is not None and not isinstance(name, str):
            raise ValueError(f"name: expected a string, got {name!r}")
        return name

    @property
    def platform_inertia_tensor(self) -> np.ndarray:
        """The platform's (3, 3) inertia tensor in {P} about its centre of mass (read-only)."""
        inertia = self.platform_inertia
        return fields.readonly(np.diag(inertia) if inertia.shape == (3,) else inertia.copy())

    @property
    def platform_inertia_diagonal(self) -> np.ndarray:
        """(I_xx, I_yy, I_zz) of :attr:`platform_inertia_tensor` (the C model's ``platform_inertia``)."""
        return fields.readonly(np.diag(self.platform_inertia_tensor).copy())

    @property
    def platform_inertia_products(self) -> np.ndarray:
        """(I_xy, I_xz, I_yz) of :attr:`platform_inertia_tensor` (the C model's ``platform_inertia_products``)."""
        return fields.readonly(self.platform_inertia_tensor[[0, 0, 1], [1, 2, 2]].copy())

    @property
    def platform_com_in_model(self) -> np.ndarray:
        """The centre of mass in {P} as the C model takes it: the origin for ``None``."""
        return fields.readonly(np.zeros(3) if self.platform_com is None else self.platform_com.copy())

    @property
    def crank_tip_directions(self) -> np.ndarray:
        """(6, 3) unit vectors a_i x h_i: the crank's direction at alpha_i = pi / 2 (read-only)."""
        return fields.readonly(np.cross(self.motor_axes, self.crank_zero))

    def replace(self, **changes: Any) -> "RotaryParams":
        """A copy with some fields changed (checked again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python form (lists and floats), the layout of the parameter files without
        their ``kind``; the fields that are ``None`` are left out."""
        out: dict[str, Any] = {}
        for field in dataclasses.fields(self):
            val = getattr(self, field.name)
            if isinstance(val, np.ndarray):
                val = val.tolist()
            elif isinstance(val, tuple):
                val = list(val)
            if val is not None:
                out[field.name] = val
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> "RotaryParams":
        """Build from the layout of :meth:`to_dict` (a ``kind`` key, if any, must be
        ``"rotary"``); unknown keys are an error."""
        if not isinstance(data, Mapping):
            raise ValueError(f"data: expected a mapping of parameter fields, got {type(data).__name__}")
        data = dict(data)
        kind = data.pop("kind", KIND)
        if kind != KIND:
            raise ValueError(f"kind: {kind!r} is not a rotary rig's (kind = {KIND!r})")
        return fields.dataclass_from(cls, data)

    @classmethod
    def preset(cls, name: str) -> "RotaryParams":
        """A built-in rotary rig by name (:func:`stewart.model.rotary_presets.presets`)."""
        if not isinstance(name, str):
            raise ValueError(f"name: expected a preset name, got {type(name).__name__} {name!r}")
        return cls(**_preset_fields(name))

    @classmethod
    def load(cls, path: Any) -> "RotaryParams":
        """Read a TOML or JSON parameter file holding ``kind = "rotary"``
        (:mod:`stewart.model.paramfile`); ``ValueError`` naming the file otherwise."""
        data = paramfile.read(path)
        if data.get("kind") != KIND:
            raise ValueError(f"{os.fsdecode(path)}: not a rotary rig's parameter file (it has no "
                             f'kind = "{KIND}"); a linear platform\'s loads with stewart.PlatformParams.load')
        try:
            return cls.from_dict(data)
        except ValueError as exc:
            raise ValueError(f"{os.fsdecode(path)}: {exc}") from None

    def save(self, path: Any) -> None:
        """Write a TOML or JSON parameter file, ``kind = "rotary"`` first."""
        paramfile.write({"kind": KIND, **self.to_dict()}, path)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, RotaryParams):
            return NotImplemented
        return self.to_dict() == other.to_dict()

    def __hash__(self) -> int:
        return hash(json.dumps(self.to_dict(), sort_keys=True))

    def __repr__(self) -> str:
        return (f"RotaryParams({self.name or 'unnamed'!r}, crank_length={self.crank_length:g}, "
                f"rod_length={self.rod_length:g}, platform_mass={self.platform_mass:g})")


def rotary_params(value: Any, name: str = "params") -> RotaryParams:
    """The parameters of ``value``, a :class:`RotaryParams` or an object whose ``params`` is
    one; :class:`~stewart.WrongTypeError` naming ``name`` otherwise."""
    if isinstance(value, RotaryParams):
        return value
    params = getattr(value, "params", None)
    if isinstance(params, RotaryParams):
        return params
    raise WrongTypeError(f"{name}: expected a stewart.RotaryParams, got {type(value).__name__}")
