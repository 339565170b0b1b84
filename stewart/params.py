"""Platform parameters: geometry, masses and inertias of the 13 bodies of the model.

The fields follow section 3 of Lopes & Pires (2011): the moving platform (eqs. 9-13),
six identical cylinders hanging from the base by universal joints (eqs. 24, 43-48) and
six identical pistons joined to the platform by spherical joints (eqs. 54, 65-66).
"""

from __future__ import annotations

import dataclasses
import json
import os
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np

from . import _checks, paramfile
from .presets import fields as _preset_fields

__all__ = ["PlatformParams", "NonAxisymmetricLegWarning", "checked_params"]


class NonAxisymmetricLegWarning(UserWarning):
    """Leg inertia with I_yy != I_zz: the paper's no-spin leg model is not energy-consistent.

    The leg angular velocity of eq. 29 has no component along the leg axis, while the
    cylinder frame {C_i} of eqs. 44-47 turns about that axis as the leg swings. With
    I_yy == I_zz the rotational inertia does not depend on that frame and the model is a
    conservative mechanical system; otherwise energy is not conserved with zero actuator
    force, and the cylinder frame is undefined for a vertical leg.
    """


def _vector3(name: str, value: Any) -> np.ndarray:
    arr = _checks.reals(name, value)
    if arr.shape != (3,):
        raise ValueError(f"{name}: expected 3 values, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: values must be finite, got {arr.tolist()}")
    return arr


def _scalar(name: str, value: Any, minimum: float | None = 0.0) -> float:
    val = _checks.real(name, value)
    if minimum is not None and val < minimum:
        raise ValueError(f"{name}: must be >= {minimum}, got {val}")
    return val


def _points(name: str, value: Any) -> np.ndarray:
    arr = _checks.reals(name, value)
    if arr.shape != (6, 3):
        raise ValueError(f"{name}: expected shape (6, 3), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: coordinates must be finite")
    with np.errstate(over="ignore", invalid="ignore"):
        centred = arr - arr.mean(axis=0)
        scale = np.max(np.linalg.norm(centred, axis=1))
    if not np.isfinite(scale):
        raise ValueError(f"{name}: coordinates too large for double precision")
    if scale == 0.0:
        raise ValueError(f"{name}: all six points coincide")
    for i in range(6):
        for j in range(i + 1, 6):
            if np.linalg.norm(arr[i] - arr[j]) <= 1e-9 * scale:
                raise ValueError(f"{name}: points {i} and {j} coincide")
    sv = np.linalg.svd(centred, compute_uv=False)
    if sv[1] <= 1e-9 * sv[0]:
        raise ValueError(f"{name}: the six points are collinear (degenerate platform)")
    return arr


def _inertia(name: str, value: Any) -> np.ndarray:
    arr = _vector3(name, value)
    if np.any(arr < 0.0):
        raise ValueError(f"{name}: principal moments must be >= 0, got {arr.tolist()}")
    total = arr.sum()
    for k in range(3):
        if arr[k] > total - arr[k] + 1e-12 * total:
            raise ValueError(
                f"{name}: principal moments {arr.tolist()} violate the triangle inequality "
                f"(moment {k} exceeds the sum of the other two)"
            )
    return arr


#: Optional workspace bounds and their largest values (the smallest is always > 0).
_BOUNDS = {"universal_joint_max_angle": np.pi / 2, "spherical_joint_max_angle": np.pi / 2, "leg_diameter": np.inf}


def _optional_bound(name: str, value: Any, maximum: float) -> float | None:
    if value is None:
        return None
    val = _checks.real(name, value)
    if not 0.0 < val <= maximum:
        need = "> 0 (metres)" if maximum == np.inf else f"0 < angle <= {maximum:.6g} (a cone half-angle in radians)"
        raise ValueError(f"{name}: need {need}, got {val}")
    return val


def _readonly(arr: np.ndarray) -> np.ndarray:
    arr.flags.writeable = False
    return arr


@dataclasses.dataclass(frozen=True, eq=False)
class PlatformParams:
    """Immutable parameter set of a 6-UPS Stewart platform (SI units, {B} z up).

    Attributes
    ----------
    base_points : (6, 3) universal-joint centres b_i in the base frame {B}.
    platform_points : (6, 3) spherical-joint centres p_i in the platform frame {P}.
    platform_mass : m_P; the centre of mass is at the origin of {P} (eq. 10).
    platform_inertia : (I_Pxx, I_Pyy, I_Pzz) in {P} about the centre of mass (eq. 12).
    cylinder_mass : m_C (eq. 36).
    cylinder_inertia : (axial, I_yy, I_zz) in the cylinder frame {C_i} (eq. 48).
    cylinder_com_distance : b_C, from B_i along the leg to the cylinder's centre of mass (eq. 24).
    piston_mass : m_S (eq. 58).
    piston_inertia : (axial, I_yy, I_zz) in the piston frame {S_i} (eq. 66).
    piston_com_distance : b_S, from P_i back along the leg to the piston's centre of mass (eq. 54).
    gravity : g in m/s^2, acting along -z of {B} (eq. 72).
    leg_length_limits : optional (min, max) leg length |l_i| in metres.
    universal_joint_max_angle, spherical_joint_max_angle : optional cone half-angles in
        radians (0 < angle <= pi/2) of the joints' range, as joint catalogues state it:
        the angle between the leg and the joint's neutral axis, the leg direction at the
        home pose (:func:`stewart.kinematics.home_pose`), fixed in {B} for the universal
        joints and in {P} for the spherical joints (:mod:`stewart.workspace`).
    leg_diameter : optional outer diameter of the legs in metres; two legs (segments B_i P_i)
        closer than it collide (:mod:`stewart.workspace`).
    name : optional label.

    Arrays are stored read-only. Construction validates every field and raises
    ``ValueError`` naming the field; leg inertias with I_yy != I_zz give a
    :class:`NonAxisymmetricLegWarning`.
    """

    base_points: np.ndarray
    platform_points: np.ndarray
    platform_mass: float
    platform_inertia: np.ndarray
    cylinder_mass: float
    cylinder_inertia: np.ndarray
    cylinder_com_distance: float
    piston_mass: float
    piston_inertia: np.ndarray
    piston_com_distance: float
    gravity: float = 9.81
    leg_length_limits: tuple[float, float] | None = None
    universal_joint_max_angle: float | None = None
    spherical_joint_max_angle: float | None = None
    leg_diameter: float | None = None
    name: str | None = None

    def __post_init__(self) -> None:
        fields = {
            "base_points": _points("base_points", self.base_points),
            "platform_points": _points("platform_points", self.platform_points),
            "platform_mass": _scalar("platform_mass", self.platform_mass),
            "platform_inertia": _inertia("platform_inertia", self.platform_inertia),
            "cylinder_mass": _scalar("cylinder_mass", self.cylinder_mass),
            "cylinder_inertia": _inertia("cylinder_inertia", self.cylinder_inertia),
            "cylinder_com_distance": _scalar("cylinder_com_distance", self.cylinder_com_distance),
            "piston_mass": _scalar("piston_mass", self.piston_mass),
            "piston_inertia": _inertia("piston_inertia", self.piston_inertia),
            "piston_com_distance": _scalar("piston_com_distance", self.piston_com_distance),
            "gravity": _scalar("gravity", self.gravity),
            "leg_length_limits": self._checked_limits(self.leg_length_limits),
            **{key: _optional_bound(key, getattr(self, key), top) for key, top in _BOUNDS.items()},
            "name": self._checked_name(self.name),
        }
        for key, val in fields.items():
            if isinstance(val, np.ndarray):
                val = _readonly(val)
            object.__setattr__(self, key, val)
        if not self.is_axisymmetric:
            warnings.warn(
                f"PlatformParams{'' if self.name is None else ' ' + repr(self.name)}: "
                "cylinder_inertia or piston_inertia has I_yy != I_zz; the model's legs do not "
                "spin about their axis (eq. 29), so with non-axisymmetric legs energy is not "
                "conserved and vertical legs are singular. Use I_yy == I_zz for physical results.",
                NonAxisymmetricLegWarning,
                stacklevel=3,
            )

    @staticmethod
    def _checked_limits(limits: Any) -> tuple[float, float] | None:
        if limits is None:
            return None
        arr = _checks.reals("leg_length_limits", limits)
        if arr.shape != (2,):
            raise ValueError(f"leg_length_limits: expected (min, max), got {limits!r}")
        lo, hi = arr.tolist()
        if not (np.isfinite(lo) and np.isfinite(hi)) or not 0.0 < lo < hi:
            raise ValueError(f"leg_length_limits: need finite 0 < min < max, got ({lo}, {hi})")
        return (lo, hi)

    @staticmethod
    def _checked_name(name: Any) -> str | None:
        if name is not None and not isinstance(name, str):
            raise ValueError(f"name: expected a string, got {name!r}")
        return name

    @property
    def is_axisymmetric(self) -> bool:
        """True when both leg bodies have I_yy == I_zz (the energy-consistent case)."""
        return bool(
            self.cylinder_inertia[1] == self.cylinder_inertia[2]
            and self.piston_inertia[1] == self.piston_inertia[2]
        )

    def replace(self, **changes: Any) -> "PlatformParams":
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python form (lists and floats), the layout of the TOML and JSON files."""
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
    def from_dict(cls, data: dict[str, Any]) -> "PlatformParams":
        """Build from the layout of :meth:`to_dict`; unknown keys are an error."""
        if not isinstance(data, Mapping):
            raise ValueError(f"data: expected a mapping of parameter fields, got {type(data).__name__}")
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(str(key) for key in set(data) - names)
        if unknown:
            raise ValueError(f"unknown parameter field(s): {', '.join(unknown)}")
        missing = sorted(
            f.name
            for f in dataclasses.fields(cls)
            if f.default is dataclasses.MISSING and f.name not in data
        )
        if missing:
            raise ValueError(f"missing parameter field(s): {', '.join(missing)}")
        return cls(**data)

    @classmethod
    def preset(cls, name: str) -> "PlatformParams":
        """A built-in parameter set by name; :func:`stewart.presets` lists them."""
        if not isinstance(name, str):
            raise ValueError(f"name: expected a preset name, got {type(name).__name__} {name!r}")
        return cls(**_preset_fields(name))

    @classmethod
    def load(cls, path: Any) -> "PlatformParams":
        """Read a TOML (``.toml``) or JSON (``.json``) parameter file (:mod:`stewart.paramfile`).

        A file that cannot be parsed or holds invalid parameters raises ``ValueError``
        naming the file; a missing or unreadable file raises the usual ``OSError``.
        """
        data = paramfile.read(path)
        try:
            return cls.from_dict(data)
        except ValueError as exc:
            raise ValueError(f"{os.fsdecode(path)}: {exc}") from None

    def save(self, path: Any) -> None:
        """Write a TOML (``.toml``) or JSON (``.json``) parameter file (:mod:`stewart.paramfile`)."""
        paramfile.write(self.to_dict(), path)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, PlatformParams):
            return NotImplemented
        return self.to_dict() == other.to_dict()

    def __hash__(self) -> int:
        return hash(json.dumps(self.to_dict(), sort_keys=True))

    def __repr__(self) -> str:
        label = self.name or "unnamed"
        return (
            f"PlatformParams({label!r}, platform_mass={self.platform_mass:g}, "
            f"cylinder_mass={self.cylinder_mass:g}, piston_mass={self.piston_mass:g}, "
            f"gravity={self.gravity:g})"
        )


def checked_params(value: Any, name: str = "params") -> PlatformParams:
    """``value`` if it is a :class:`PlatformParams`; ``ValueError`` naming ``name`` otherwise."""
    if not isinstance(value, PlatformParams):
        hint = " (a Platform's parameters are platform.params)" if hasattr(value, "params") else ""
        raise ValueError(f"{name}: expected a stewart.PlatformParams, got {type(value).__name__}{hint}")
    return value
