"""Built-in parameter sets.

``narayan2017``
    The small platform of Narayan Rao, Ashok & Tammana (2017), section VIII: its base and
    top-plate coordinates converted from the paper's y-up frame to our z-up {B} by
    ``(X, Y, Z) = (x, -z, y)``, its 6.77406 kg top plate and its legs of section V (outer
    cylinder 100 mm long, 50 mm OD, 40 mm ID; solid piston rod 90 mm long, 40 mm diameter).
    The paper states no material: the legs are taken as steel (7850 kg/m^3), each part a
    uniform tube with its centre of mass at mid-length, so b_C = 50 mm from B_i and
    b_S = 45 mm from P_i. The top plate is taken as a uniform steel disc of the paper's
    600 mm diameter and the paper's mass (hence 3.05 mm thick). Leg lengths run from the
    0.19 m nominal length to that plus the paper's 190 mm expansion. The paper names no
    joints: the joint cones are those of :data:`UNIVERSAL_JOINT_MAX_ANGLE` and
    :data:`SPHERICAL_JOINT_MAX_ANGLE`. It sets no leg diameter: its neighbouring base joints
    are 38 mm apart, closer than its 50 mm cylinders, so its legs must narrow at the joints
    and the leg-leg check of a 50 mm leg would refuse even the home pose. Its plate, 300 mm
    in radius and three times wider than the joints' circle, is checked against the base
    and the legs (``plate_radius``): tilted by 38 degrees at home height, its rim meets the
    base.

``motion_simulator``
    A full-size motion base of the proportions common in driving and flight simulators
    (a design example, not a product's data sheet): a semi-regular 6-6 hexapod with base
    joints on a 1.6 m radius and platform joints on a 1.1 m radius, paired 20 degrees
    apart and rotated 60 degrees from each other; a 1500 kg payload (cockpit, frame and
    occupant) modelled as a uniform 2.6 m x 2.6 m x 0.8 m box centred on {P}; steel
    electric actuators whose body is a 1.0 m tube of 160/140 mm OD/ID and whose rod is a
    1.0 m tube of 80/60 mm OD/ID, each with its centre of mass at mid-length; 0.7 m of
    stroke between 1.15 m and 1.85 m; the joint cones of :data:`UNIVERSAL_JOINT_MAX_ANGLE`
    and :data:`SPHERICAL_JOINT_MAX_ANGLE`; legs of the cylinders' 160 mm diameter for
    the leg-leg clearance; a platform frame reaching 0.1 m beyond its joints, a plate of 1.2 m
    radius for the plate's clearance of the base and the legs (``plate_radius``).

The joint cones (:class:`stewart.PlatformParams` ``universal_joint_max_angle``,
``spherical_joint_max_angle``, the angle between a leg and its direction at home) bound the
workspace of both presets (:mod:`stewart.model.reachability`), so that their maps do not reach
poses where the legs lie nearly flat.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

__all__ = ["presets", "fields", "narayan2017_target_pose"]

STEEL_DENSITY = 7850.0  # kg/m^3
#: The universal joints' cone half-angle [rad]: 45 degrees, the largest working angle of a
#: single cardan joint (DIN 808).
UNIVERSAL_JOINT_MAX_ANGLE = math.radians(45.0)
#: The spherical joints' cone half-angle [rad]: 30 degrees, that of a wide-angle ball joint made
#: for parallel mechanisms (plain rod ends tilt only 6-15 degrees).
SPHERICAL_JOINT_MAX_ANGLE = math.radians(30.0)


def tube(outer_diameter: float, inner_diameter: float, length: float, density: float = STEEL_DENSITY):
    """Mass and principal inertia (axial, transverse, transverse) of a uniform tube about its centre."""
    ro, ri = outer_diameter / 2.0, inner_diameter / 2.0
    mass = density * math.pi * (ro**2 - ri**2) * length
    axial = 0.5 * mass * (ro**2 + ri**2)
    transverse = mass * (3.0 * (ro**2 + ri**2) + length**2) / 12.0
    return mass, (axial, transverse, transverse)


def _narayan2017() -> dict[str, Any]:
    # Section VIII of the paper, y-up: rows are x and z of points 1..6 (y = 0 for all).
    base_x = [0.0962, 0.0772, -0.0742, -0.0962, -0.019, 0.019]
    base_z = [-0.0336, -0.0665, -0.0599, -0.0336, 0.1001, 0.1001]
    top_x = [0.0607, 0.0128, -0.0145, -0.0652, -0.0507, 0.0507]
    top_z = [0.0203, -0.0628, -0.0669, 0.0208, 0.046, 0.046]
    base = np.column_stack([base_x, -np.array(base_z), np.zeros(6)])
    top = np.column_stack([top_x, -np.array(top_z), np.zeros(6)])

    plate_mass, plate_radius = 6.77406, 0.3
    thickness = plate_mass / (STEEL_DENSITY * math.pi * plate_radius**2)
    i_diam = plate_mass * (3.0 * plate_radius**2 + thickness**2) / 12.0
    i_axis = 0.5 * plate_mass * plate_radius**2

    cyl_mass, cyl_inertia = tube(0.050, 0.040, 0.100)
    pis_mass, pis_inertia = tube(0.040, 0.0, 0.090)
    return dict(
        base_points=base,
        platform_points=top,
        platform_mass=plate_mass,
        platform_inertia=(i_diam, i_diam, i_axis),
        cylinder_mass=cyl_mass,
        cylinder_inertia=cyl_inertia,
        cylinder_com_distance=0.050,
        piston_mass=pis_mass,
        piston_inertia=pis_inertia,
        piston_com_distance=0.045,
        gravity=9.81,
        leg_length_limits=(0.19, 0.38),
        universal_joint_max_angle=UNIVERSAL_JOINT_MAX_ANGLE,
        spherical_joint_max_angle=SPHERICAL_JOINT_MAX_ANGLE,
        plate_radius=plate_radius,
        name="narayan2017",
    )


def narayan2017_target_pose() -> np.ndarray:
    """The target pose of Narayan Rao et al. (2017), section IX, in our z-up frame.

    The paper gives the position (0.04565, 0.192, 0.0102) m and a rotation matrix rounded
    to four digits, both in its y-up frame. The position maps by ``(x, -z, y)``; the
    rotation is conjugated into the z-up frame, replaced by the nearest proper rotation
    (polar decomposition) and read as ZYX Euler angles.
    """
    y_up_to_z_up = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    position = y_up_to_z_up @ np.array([0.04565, 0.192, 0.0102])
    rounded = np.array([[0.9908, 0.0953, -0.09575], [-0.1044, 0.99, -0.09531], [0.0857, 0.1044, 0.9908]])
    u, _, vt = np.linalg.svd(y_up_to_z_up @ rounded @ y_up_to_z_up.T)
    rot = u @ vt
    angles = [np.arctan2(rot[1, 0], rot[0, 0]), -np.arcsin(rot[2, 0]), np.arctan2(rot[2, 1], rot[2, 2])]
    return np.concatenate([position, angles])


def hexapod_points(radius: float, pair_centres_deg, half_separation_deg: float) -> np.ndarray:
    """Six joint centres in the z = 0 plane, in pairs around the given centre angles."""
    angles = []
    for centre in pair_centres_deg:
        angles += [centre - half_separation_deg, centre + half_separation_deg]
    rad = np.radians(angles)
    return np.column_stack([radius * np.cos(rad), radius * np.sin(rad), np.zeros(6)])


def _motion_simulator() -> dict[str, Any]:
    # Base pairs centred at 0, 120, 240 deg; platform pairs at 60, 180, 300 deg. Leg i joins
    # base point i to platform point i after rolling the base list by one, so that each
    # platform pair is reached from two different base pairs (the usual crossing layout).
    base = np.roll(hexapod_points(1.6, (0.0, 120.0, 240.0), 10.0), -1, axis=0)
    top = hexapod_points(1.1, (60.0, 180.0, 300.0), 10.0)
    mass, width, height = 1500.0, 2.6, 0.8
    i_xy = mass * (width**2 + height**2) / 12.0
    i_z = mass * (2.0 * width**2) / 12.0
    cyl_mass, cyl_inertia = tube(0.160, 0.140, 1.0)
    rod_mass, rod_inertia = tube(0.080, 0.060, 1.0)
    return dict(
        base_points=base,
        platform_points=top,
        platform_mass=mass,
        platform_inertia=(i_xy, i_xy, i_z),
        cylinder_mass=cyl_mass,
        cylinder_inertia=cyl_inertia,
        cylinder_com_distance=0.5,
        piston_mass=rod_mass,
        piston_inertia=rod_inertia,
        piston_com_distance=0.5,
        gravity=9.81,
        leg_length_limits=(1.15, 1.85),
        universal_joint_max_angle=UNIVERSAL_JOINT_MAX_ANGLE,
        spherical_joint_max_angle=SPHERICAL_JOINT_MAX_ANGLE,
        leg_diameter=0.160,
        plate_radius=1.2,
        name="motion_simulator",
    )


_PRESETS: dict[str, tuple[Callable[[], dict[str, Any]], str]] = {
    "narayan2017": (_narayan2017, "small 6.8 kg platform of Narayan Rao et al. (2017), steel legs"),
    "motion_simulator": (_motion_simulator, "1500 kg motion-simulator base, 3.2 m base, 0.7 m stroke"),
}


def presets() -> dict[str, str]:
    """Names of the built-in parameter sets, each with a one-line description."""
    return {name: desc for name, (_, desc) in _PRESETS.items()}


def fields(name: str) -> dict[str, Any]:
    """The fields of the built-in parameter set ``name`` (see :func:`presets`), as the
    keyword arguments of :class:`stewart.PlatformParams` (which
    :meth:`PlatformParams.preset` builds from them)."""
    try:
        build, _ = _PRESETS[name]
    except KeyError:
        raise ValueError(f"name: unknown preset {name!r}; available: {', '.join(_PRESETS)}") from None
    return build()


#: A realistic axial stiffness of each preset's legs [N/m] (actuator, screw and leg in series),
#: for modal studies, the demo and the benchmarks; the parameter sets themselves carry none.
#: ``narayan2017``: a small ball-screw actuator, 1 N/um (catalogue values of 0.5-5 N/um);
#: ``motion_simulator``: an electromechanical simulator actuator of its size, 20 N/um (the
#: 10-100 N/um of 0.1-0.3 m screws and 1.5 m legs, and of hydraulic legs' oil columns).
LEG_STIFFNESS = {"narayan2017": 1e6, "motion_simulator": 2e7}
