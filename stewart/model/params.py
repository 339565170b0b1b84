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

from .._generated import INERTIAL_NAMES as _inertial_names_of_the_model
from . import arguments, fields, paramfile  # fields: the checks of each field
from .errors import WrongTypeError
from .fields import TOLERANCE
from .presets import fields as _preset_fields

__all__ = ["PlatformParams", "NonAxisymmetricLegWarning", "TOLERANCE", "platform_params"]


class NonAxisymmetricLegWarning(UserWarning):
    """Leg inertia with I_yy != I_zz: the paper's no-spin leg model is not energy-consistent.

    The leg angular velocity of eq. 29 has no component along the leg axis, while the
    cylinder frame {C_i} of eqs. 44-47 turns about that axis as the leg swings. With
    I_yy == I_zz the rotational inertia does not depend on that frame and the model is a
    conservative mechanical system; otherwise energy is not conserved with zero actuator
    force, and the cylinder frame is undefined for a vertical leg.
    """


@dataclasses.dataclass(frozen=True, eq=False)
class PlatformParams:
    """Immutable parameter set of a 6-UPS Stewart platform (SI units, {B} z up).

    Attributes
    ----------
    base_points : (6, 3) universal-joint centres b_i in the base frame {B}.
    platform_points : (6, 3) spherical-joint centres p_i in the platform frame {P}.
    platform_mass : m_P (eq. 10).
    platform_inertia : (I_Pxx, I_Pyy, I_Pzz) principal moments in {P} (eq. 12), or a symmetric
        (3, 3) tensor in {P}; about the centre of mass in both cases.
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
        home pose (:func:`stewart.model.kinematics.home_pose`), fixed in {B} for the universal
        joints and in {P} for the spherical joints (:mod:`stewart.studies.workspace`).
    leg_diameter : optional outer diameter of the legs in metres; two legs (segments B_i P_i)
        closer than it collide (:mod:`stewart.studies.workspace`).
    plate_radius : optional radius in metres of the platform's plate, a disc centred on the
        z axis of {P} lying on the spherical joints (in the plane of {P} through the highest of
        them); given, the plate must stay above the base and no leg may pass through it
        (:mod:`stewart.model.reachability`).
    base_clearance : optional smallest gap in metres between the platform (its spherical
        joints, and its plate when ``plate_radius`` is given) and the base, the plane of the
        highest universal joint; ``None``: the platform need only be above that plane.
    name : optional label.
    universal_joint_axes : optional (6, 3) first (base-fixed) axis a_i of each universal joint
        in {B}, unit vectors (within :data:`TOLERANCE`). Given, the legs turn with their
        joints: leg frame x = u_i, y = a_i x u_i / |a_i x u_i|, z = x x y (a_i = z gives the
        frame of eqs. 44-47). ``None``: the paper's legs that do not spin (eq. 29).
    platform_com : optional centre of mass in {P}; ``None`` is the origin of {P} (eq. 10).
    viscous_friction, coulomb_friction : optional (6,) actuator friction of each leg,
        ``F_v,i`` >= 0 in N s/m and ``F_c,i`` >= 0 in N; ``None`` is none. A leg moving at
        ``Ldot_i`` loses ``F_v,i Ldot_i + F_c,i tanh(Ldot_i / coulomb_velocity)`` of its actuator
        force (:meth:`stewart.Platform.friction_forces`). The rigid-body model (inverse and
        forward dynamics) does not include it; the regressor, the actuator forces
        (:meth:`stewart.Platform.regressor`, :meth:`stewart.Platform.actuator_forces`) and
        :func:`stewart.simulate` (whose :class:`stewart.motion.control.Actuators` default to them) do.
    coulomb_velocity : v_c > 0 in m/s, the speed scale of the smooth sign of the Coulomb
        friction.
    leg_stiffness : optional axial stiffness ``k_i`` > 0 of each leg in N/m (actuator, screw and
        leg in series; one value or six), the default of the stiffness and modes
        (:meth:`stewart.Platform.modes`); ``None`` is none: those then need it given.
    leg_damping : optional axial damping ``c_i`` >= 0 of each leg in N s/m (one value or six),
        the default damping of :meth:`stewart.Platform.modes`; ``None`` is none.
    leg_length_offsets : (6,) each leg's encoder zero offset in metres: the true leg length
        ``|l_i|`` is the encoder reading plus the offset (default zeros, left out of
        :meth:`to_dict` and the parameter files when all zero). The model takes true lengths;
        the functions that take a machine's readings apply them
        (:meth:`stewart.Platform.encoder_readings`, :func:`stewart.forward_kinematics` with
        ``encoder=True``, :mod:`stewart.identification.identify`'s logs, :mod:`stewart.calibration`).

    Arrays are stored read-only. Construction validates every field and raises
    ``ValueError`` naming the field; without ``universal_joint_axes``, leg inertias with
    I_yy != I_zz give a :class:`NonAxisymmetricLegWarning`. An axis parallel to its leg at
    the home pose is rejected when a :class:`stewart.Platform` is built
    (:func:`stewart.model.kinematics.check_universal_joint_axes`).
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
    plate_radius: float | None = None
    base_clearance: float | None = None
    name: str | None = None
    universal_joint_axes: np.ndarray | None = None
    platform_com: np.ndarray | None = None
    viscous_friction: np.ndarray | None = None
    coulomb_friction: np.ndarray | None = None
    coulomb_velocity: float = 1e-3
    leg_stiffness: np.ndarray | None = None
    leg_damping: np.ndarray | None = None
    leg_length_offsets: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(6))

    def __post_init__(self) -> None:
        checked = {
            "base_points": fields.points("base_points", self.base_points),
            "platform_points": fields.points("platform_points", self.platform_points),
            "platform_mass": fields.scalar("platform_mass", self.platform_mass),
            "platform_inertia": fields.inertia_tensor("platform_inertia", self.platform_inertia),
            "cylinder_mass": fields.scalar("cylinder_mass", self.cylinder_mass),
            "cylinder_inertia": fields.inertia("cylinder_inertia", self.cylinder_inertia),
            "cylinder_com_distance": fields.scalar("cylinder_com_distance", self.cylinder_com_distance),
            "piston_mass": fields.scalar("piston_mass", self.piston_mass),
            "piston_inertia": fields.inertia("piston_inertia", self.piston_inertia),
            "piston_com_distance": fields.scalar("piston_com_distance", self.piston_com_distance),
            "gravity": fields.scalar("gravity", self.gravity),
            "leg_length_limits": self._checked_limits(self.leg_length_limits),
            **{key: fields.optional_bound(key, getattr(self, key), top) for key, top in fields.BOUNDS.items()},
            "name": self._checked_name(self.name),
            "universal_joint_axes": fields.joint_axes("universal_joint_axes", self.universal_joint_axes),
            "platform_com": None if self.platform_com is None else fields.vector3("platform_com", self.platform_com),
            "viscous_friction": fields.friction("viscous_friction", self.viscous_friction),
            "coulomb_friction": fields.friction("coulomb_friction", self.coulomb_friction),
            "coulomb_velocity": fields.positive("coulomb_velocity", self.coulomb_velocity),
            "leg_stiffness": None if self.leg_stiffness is None else fields.leg_coefficients(
                "leg_stiffness", self.leg_stiffness, positive=True),
            "leg_damping": None if self.leg_damping is None else fields.leg_coefficients(
                "leg_damping", self.leg_damping, positive=False),
            "leg_length_offsets": fields.offsets("leg_length_offsets", self.leg_length_offsets),
        }
        for key, val in checked.items():
            if isinstance(val, np.ndarray):
                val = fields.readonly(val)
            object.__setattr__(self, key, val)
        self._check_inertial_vector()
        if not self.is_axisymmetric and self.universal_joint_axes is None:
            warnings.warn(
                f"PlatformParams{'' if self.name is None else ' ' + repr(self.name)}: "
                "cylinder_inertia or piston_inertia has I_yy != I_zz; the model's legs do not "
                "spin about their axis (eq. 29), so with non-axisymmetric legs energy is not "
                "conserved and vertical legs are singular. Use I_yy == I_zz for physical results.",
                NonAxisymmetricLegWarning,
                stacklevel=3,
            )

    def _check_inertial_vector(self) -> None:
        """``ValueError`` naming a body's fields when its inertial parameters (:meth:`inertial_vector`:
        mass times centre of mass, moments about the joint) overflow double precision."""
        with np.errstate(over="ignore", invalid="ignore"):
            pi = self.inertial_vector()
        bad = np.flatnonzero(~np.isfinite(pi))
        if bad.size:
            name = INERTIAL_NAMES[bad[0]]
            body = name.split(".")[0]
            named = {"platform": "platform_mass, platform_inertia, platform_com"}.get(
                body, f"{body}_mass, {body}_inertia, {body}_com_distance")
            raise ValueError(f"{named}: too large for double precision: the inertial parameter {name} "
                             "(inertial_vector) overflows")

    @staticmethod
    def _checked_limits(limits: Any) -> tuple[float, float] | None:
        if limits is None:
            return None
        arr = arguments.reals("leg_length_limits", limits)
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

    @property
    def platform_inertia_tensor(self) -> np.ndarray:
        """The platform's (3, 3) inertia tensor in {P} about its centre of mass (read-only)."""
        inertia = self.platform_inertia
        return fields.readonly(np.diag(inertia) if inertia.shape == (3,) else inertia.copy())

    @property
    def is_paper_model(self) -> bool:
        """True for the paper's model: legs that do not spin (no ``universal_joint_axes``),
        the centre of mass at the origin of {P} and a diagonal inertia tensor in {P}."""
        tensor = self.platform_inertia_tensor
        return bool(
            self.universal_joint_axes is None
            and (self.platform_com is None or not np.any(self.platform_com))
            and not np.any(tensor - np.diag(np.diag(tensor)))
        )

    def with_payload(self, mass: Any, com: Any, inertia: Any) -> "PlatformParams":
        """The platform carrying a rigid payload: ``mass`` in kg, centre of mass ``com`` in
        {P}, ``inertia`` (3 principal moments in {P} or a (3, 3) tensor in {P}) about the
        payload's own centre of mass. Masses add, the centre of mass is their mean, and
        each body's tensor moves to the common centre of mass by the parallel-axis
        theorem, I + m (|d|^2 E - d d^T)."""
        mass = fields.scalar("mass", mass)
        com = fields.vector3("com", com)
        tensor = fields.inertia_tensor("inertia", inertia)
        tensor = np.diag(tensor) if tensor.shape == (3,) else tensor
        bodies = [(self.platform_mass, self._com(), self.platform_inertia_tensor), (mass, com, tensor)]
        total = self.platform_mass + mass
        if total == 0.0:
            raise ValueError("mass: the platform and the payload have no mass together")
        centre = sum(m * c for m, c, _ in bodies) / total
        combined = sum(i + m * (np.dot(c - centre, c - centre) * np.eye(3) - np.outer(c - centre, c - centre))
                       for m, c, i in bodies)
        diagonal = not np.any(combined - np.diag(np.diag(combined)))
        return self.replace(
            platform_mass=total,
            platform_com=centre if np.any(centre) or self.platform_com is not None else None,
            platform_inertia=np.diag(combined) if diagonal else 0.5 * (combined + combined.T),
        )

    def with_universal_joints(self, axes: Any = None) -> "PlatformParams":
        """A copy with universal joints whose first axes are ``axes`` (6, 3) in {B}.

        By default each first axis is horizontal and tangential to the base circle: the
        unit vector z x r_i / |z x r_i| with r_i the horizontal offset of b_i from the base
        joints' centroid. That is an assumption about the machine (a common way to mount
        the joints), not part of the paper's parameters."""
        if axes is None:
            radial = self.base_points - self.base_points.mean(axis=0)
            tangent = np.stack([-radial[:, 1], radial[:, 0], np.zeros(6)], axis=1)
            norms = np.sqrt(np.sum(tangent * tangent, axis=1))
            if np.any(norms == 0.0):
                raise ValueError("axes: a base joint lies above the base centroid; "
                                 "its tangential axis is undefined, give the axes explicitly")
            axes = tangent / norms[:, None]
        return self.replace(universal_joint_axes=axes)

    def _com(self) -> np.ndarray:
        return np.zeros(3) if self.platform_com is None else self.platform_com

    @property
    def platform_inertia_diagonal(self) -> np.ndarray:
        """(I_xx, I_yy, I_zz), the diagonal of :attr:`platform_inertia_tensor` (the C model's
        ``platform_inertia``)."""
        return fields.readonly(np.diag(self.platform_inertia_tensor).copy())

    @property
    def platform_inertia_products(self) -> np.ndarray:
        """(I_xy, I_xz, I_yz), the entries of :attr:`platform_inertia_tensor` off its diagonal
        (the C model's ``platform_inertia_products``)."""
        return fields.readonly(self.platform_inertia_tensor[[0, 0, 1], [1, 2, 2]].copy())

    @property
    def platform_com_in_model(self) -> np.ndarray:
        """The centre of mass in {P} as the C model takes it: the origin for ``None``."""
        return fields.readonly(np.zeros(3) if self.platform_com is None else self.platform_com.copy())

    @property
    def universal_joint_axes_in_model(self) -> np.ndarray:
        """The joints' first axes as the C model takes them: zeros for the paper's model;
        without ``universal_joint_axes`` in a general model (off-centre or full-tensor
        payload), the z axis of {B}, whose frames are those of eqs. 44-47, with the legs'
        axial inertia left out (:attr:`cylinder_inertia_in_model`) so that they do not spin."""
        if self.universal_joint_axes is not None:
            return self.universal_joint_axes
        return fields.readonly(np.zeros((6, 3)) if self.is_paper_model else np.tile([0.0, 0.0, 1.0], (6, 1)))

    @property
    def spinless_legs_in_model(self) -> float:
        """1.0 where the legs do not spin with their joints (no ``universal_joint_axes``, eq. 29),
        else 0.0: the C model's flag (``stewart_params.spinless_legs``) that leaves the axial
        moments out of the regressor where its joint axes stand for the frames of eqs. 44-47
        (:attr:`universal_joint_axes_in_model`)."""
        return 1.0 if self.universal_joint_axes is None else 0.0

    @property
    def cylinder_inertia_in_model(self) -> np.ndarray:
        """cylinder_inertia as the C model takes it: without ``universal_joint_axes`` the legs
        do not spin (eq. 29), so the axial moment is left out (it has no effect there)."""
        return self._leg_inertia_in_model(self.cylinder_inertia)

    @property
    def piston_inertia_in_model(self) -> np.ndarray:
        """piston_inertia as the C model takes it (see :attr:`cylinder_inertia_in_model`)."""
        return self._leg_inertia_in_model(self.piston_inertia)

    def _leg_inertia_in_model(self, inertia: np.ndarray) -> np.ndarray:
        if self.universal_joint_axes is not None:
            return inertia
        return fields.readonly(np.array([0.0, inertia[1], inertia[2]]))

    @classmethod
    def inertial_names(cls) -> tuple[str, ...]:
        """The names of the inertial parameters pi of :meth:`inertial_vector`, in the order of
        the columns of :meth:`stewart.Platform.regressor`."""
        return INERTIAL_NAMES

    def inertial_vector(self) -> np.ndarray:
        """The inertial parameters pi, with ``Platform.regressor(x, xd, xdd) @ pi`` the actuator
        forces (:meth:`stewart.Platform.actuator_forces`). Per body the mass, the first moments
        (mass times the centre of mass) and the second moments about a point fixed in the body
        (the parallel-axis form): the platform's about the origin of {P}, in {P}; a cylinder's
        about its universal joint B_i and a piston's about its spherical joint P_i, in the leg
        frame (axial, I_yy, I_zz); then the legs' viscous and Coulomb friction
        (:meth:`inertial_names`)."""
        com = self._com()
        m = self.platform_mass
        tensor = self.platform_inertia_tensor + m * (np.dot(com, com) * np.eye(3) - np.outer(com, com))
        values = {"platform.m": m, **dict(zip(("platform.mx", "platform.my", "platform.mz"), m * com)),
                  **{f"platform.I{a}{b}": tensor[i, j] for (a, i), (b, j) in _TENSOR_ENTRIES}}
        for body, mass, distance, inertia in self._legs():
            moment = mass * np.square(distance)  # a double: inf (refused by the constructor), not an OverflowError
            values.update({f"{body}.m": mass, f"{body}.mb": mass * distance, f"{body}.Ixx": inertia[0],
                           f"{body}.Iyy": inertia[1] + moment, f"{body}.Izz": inertia[2] + moment})
        for kind in ("viscous", "coulomb"):
            coefficients = getattr(self, f"{kind}_friction")
            values.update({f"friction.{kind}_{i}": 0.0 if coefficients is None else coefficients[i]
                           for i in range(6)})
        return np.array([values[name] for name in INERTIAL_NAMES], dtype=float)

    def with_inertial_vector(self, pi: Any) -> "PlatformParams":
        """A copy whose masses, centres of mass, inertias and friction are those of the inertial
        parameters ``pi`` (the inverse of :meth:`inertial_vector`); the geometry, gravity and
        the other fields stay. ``ValueError`` naming the entry when ``pi`` describes no
        physical body: a negative mass, a first moment without mass, an inertia that is not
        positive semidefinite about the centre of mass or breaks the triangle inequality, or
        negative friction."""
        arr = arguments.reals("pi", pi)
        if arr.shape != (len(INERTIAL_NAMES),):
            raise ValueError(f"pi: expected {len(INERTIAL_NAMES)} inertial parameters, got shape {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError("pi: values must be finite")
        value = dict(zip(INERTIAL_NAMES, arr.tolist()))

        def mass_and_offset(body, first):
            mass = value[f"{body}.m"]
            if mass < 0.0:
                raise ValueError(f"pi: {body}.m is negative ({mass:g})")
            if mass == 0.0:
                if np.any(first):
                    raise ValueError(f"pi: {body} has a first moment but no mass")
                return mass, np.zeros_like(first)
            return mass, first / mass

        # Values that overflow (a first moment over a tiny mass ...) are refused by the
        # constructor, naming the field.
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            m, com = mass_and_offset("platform", np.array([value[f"platform.m{a}"] for a in "xyz"]))
            tensor = np.array([[value[f"platform.I{min(a, b)}{max(a, b)}"] for b in "xyz"] for a in "xyz"])
            tensor = tensor - m * (np.dot(com, com) * np.eye(3) - np.outer(com, com))
            changes = {"platform_mass": m,
                       "platform_com": com if np.any(com) or self.platform_com is not None else None,
                       "platform_inertia": _inertia_of(tensor)}
            for body in ("cylinder", "piston"):
                mass, distance = mass_and_offset(body, np.array([value[f"{body}.mb"]]))
                if distance[0] < 0.0:
                    raise ValueError(f"pi: {body}.mb is negative ({value[f'{body}.mb']:g}); the centre of mass "
                                     "lies on the leg between its joints")
                moments = np.array([value[f"{body}.Ixx"], value[f"{body}.Iyy"] - mass * distance[0] ** 2,
                                    value[f"{body}.Izz"] - mass * distance[0] ** 2])
                changes.update({f"{body}_mass": mass, f"{body}_com_distance": float(distance[0]),
                                f"{body}_inertia": _inertia_of(moments)})
            for kind in ("viscous", "coulomb"):
                coefficients = np.array([value[f"friction.{kind}_{i}"] for i in range(6)])
                if np.any(coefficients < 0.0):
                    raise ValueError(f"pi: friction.{kind}_{int(np.argmax(coefficients < 0.0))} is negative")
                changes[f"{kind}_friction"] = (coefficients if np.any(coefficients)
                                               or getattr(self, f"{kind}_friction") is not None else None)
        try:
            return self.replace(**changes)
        except ValueError as exc:
            raise ValueError(f"pi: no physical body: {exc}") from None

    def _legs(self):
        """(body, mass, centre-of-mass distance from its joint, inertia) of the leg bodies."""
        return (("cylinder", self.cylinder_mass, self.cylinder_com_distance, self.cylinder_inertia),
                ("piston", self.piston_mass, self.piston_com_distance, self.piston_inertia))

    def replace(self, **changes: Any) -> "PlatformParams":
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python form (lists and floats), the layout of the TOML and JSON files; the
        fields that are ``None``, and ``leg_length_offsets`` when all zero, are left out."""
        out: dict[str, Any] = {}
        for field in dataclasses.fields(self):
            val = getattr(self, field.name)
            if field.name == "leg_length_offsets" and not np.any(val):
                continue
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
        return fields.dataclass_from(cls, data)

    @classmethod
    def preset(cls, name: str) -> "PlatformParams":
        """A built-in parameter set by name; :func:`stewart.presets` lists them."""
        if not isinstance(name, str):
            raise ValueError(f"name: expected a preset name, got {type(name).__name__} {name!r}")
        return cls(**_preset_fields(name))

    @classmethod
    def load(cls, path: Any) -> "PlatformParams":
        """Read a TOML (``.toml``) or JSON (``.json``) parameter file (:mod:`stewart.model.paramfile`).

        A file that cannot be parsed or holds invalid parameters raises ``ValueError``
        naming the file; a missing or unreadable file raises the usual ``OSError``.
        """
        data = paramfile.read(path)
        if "kind" in data:
            raise ValueError(f"{os.fsdecode(path)}: holds kind = {data['kind']!r}, not a linear platform; "
                             "a rotary rig's file loads with stewart.RotaryParams.load")
        try:
            return cls.from_dict(data)
        except ValueError as exc:
            raise ValueError(f"{os.fsdecode(path)}: {exc}") from None

    def save(self, path: Any) -> None:
        """Write a TOML (``.toml``) or JSON (``.json``) parameter file (:mod:`stewart.model.paramfile`)."""
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


#: The inertial parameters pi of the regressor, in its column order (codegen/schema.py).
INERTIAL_NAMES: tuple[str, ...] = tuple(_inertial_names_of_the_model)
#: The number of inertial parameters, and of those of the rigid bodies (the friction follows).
NUM_INERTIAL = len(INERTIAL_NAMES)
NUM_RIGID_BODY = sum(not name.startswith("friction.") for name in INERTIAL_NAMES)
_TENSOR_ENTRIES = [((a, i), (b, j)) for i, a in enumerate("xyz") for j, b in enumerate("xyz") if j >= i]


def platform_params(value: Any, name: str = "params") -> PlatformParams:
    """The parameters of ``value``, a :class:`~stewart.PlatformParams` or a
    :class:`~stewart.Platform` (its :attr:`~stewart.Platform.params`, or any object whose
    ``params`` is a :class:`~stewart.PlatformParams`): how a function that works on the
    parameters takes its platform argument (see :mod:`stewart.model`).
    :class:`~stewart.WrongTypeError` (a ``TypeError`` and a ``ValueError``) naming ``name``
    for anything else."""
    if isinstance(value, PlatformParams):
        return value
    params = getattr(value, "params", None)
    if isinstance(params, PlatformParams):
        return params
    raise WrongTypeError(f"{name}: expected a stewart.PlatformParams, got {type(value).__name__}")


def _inertia_of(moments: np.ndarray) -> np.ndarray:
    """Moments (3,) or a tensor (3, 3) computed from pi, with entries within round-off of
    zero (1e-14 of the largest) set to zero, so that a diagonal tensor stays diagonal (3
    moments); the constructor checks them."""
    scale = np.max(np.abs(moments))
    if scale > 0.0:
        moments = np.where(np.abs(moments) <= 1e-14 * scale, 0.0, moments)
    if moments.shape == (3, 3) and not np.any(moments - np.diag(np.diag(moments))):
        return np.diag(moments).copy()
    return moments
