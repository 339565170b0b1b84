"""Built-in rotary rigs (:class:`stewart.RotaryParams`), design examples of the two common
sizes, not a product's data sheet.  Both use the usual 6-6 layout: motors in three pairs
around the base (pairs centred at 0, 120 and 240 degrees, the list rolled by one so that
each platform pair is reached from two base pairs), platform joints in three pairs centred
at 60, 180 and 300 degrees; each motor axis horizontal, each crank at alpha = 0 horizontal
and tangent to the motors' circle, pointing towards its platform joint, so that
a_i = h_i x z and a positive angle lifts the crank tip; the rods lean inwards from the
crank tips to the platform joints, leaving the tip along its motion (``crank_branch`` +1).

``simrig100``
    A sim-racing rig of the size DIY and commercial 6-DOF seat movers have (XSimulator
    builds, 0.1 m cranks): motors on a 0.45 m radius in pairs 30 degrees apart, platform
    joints on a 0.35 m radius in pairs 30 degrees apart; 0.1 m cranks and 0.48 m rods
    (the rods' length when the platform stands 0.45 m above the motor axes with the cranks
    horizontal).  The platform carries 100 kg: a 75 kg driver and a 25 kg seat with its
    frame, taken as a uniform 0.6 m x 0.6 m x 1.0 m (x, y, z) box whose centre of mass is
    0.3 m above {P}.  Motors: 750 W AC servos (rated 2.39 N m, 3000 rpm, rotor 1.2e-4 kg m^2,
    the common 80 mm frame size) through 50:1 gearboxes at 90 % efficiency: 107 N m and
    6.28 rad/s at the crank; the reflected rotor, 1.2e-4 * 50^2 = 0.30 kg m^2, plus the
    crank, a 1.0 kg steel lever with its centre of mass at 0.05 m (m r^2 / 3 = 3.3e-3 kg m^2
    about the axis).  Rods: 0.8 kg each (a 25/21 mm steel tube of 0.48 m, 0.55 kg, and two
    rod ends of 0.125 kg), centre of mass at mid-length, transverse m d^2 / 12.  Crank angles
    within +-60 degrees (the bound of stewart-core's workspace search), ball-joint cones of
    30 degrees (wide-angle rod ends).

``desktop_servo``
    A small desktop servo hexapod of the hobby kind: MG996R-class servos (stall torque
    11 kg cm = 1.08 N m at 6 V, 0.17 s / 60 degrees = 6.16 rad/s) on a 75 mm radius in
    pairs 30 degrees apart, platform joints on a 55 mm radius in pairs 20 degrees apart,
    25 mm horns and 115 mm rods with M3 ball ends (the rods' length for an 0.11 m home
    height).  Platform: a 3 mm acrylic disc of 120 mm diameter (1190 kg/m^3: 0.040 kg)
    carrying 0.1 kg, taken as a 0.14 kg uniform disc.  Horn: 5 g with its centre of mass at
    12.5 mm; the reflected rotor, an estimate: a 130-size motor's rotor (about 5e-8 kg m^2)
    through the servo's gear train of about 250:1, 3.1e-3 kg m^2.  Rods: 4 g, centre of
    mass at mid-length, transverse m d^2 / 12.  Servo angles within +-90 degrees; ball-ends'
    cones of 25 degrees.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from .presets import hexapod_points

__all__ = ["presets", "fields", "crank_layout"]


def crank_layout(base: np.ndarray, top: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(motor_axes, crank_zero) of the presets' layout: each crank at alpha = 0 horizontal and
    tangent to the circle of the motors, pointing towards its platform joint p_i (h_i), its
    axis a_i = h_i x z (a positive angle lifts the tip)."""
    tangent = np.column_stack([-base[:, 1], base[:, 0], np.zeros(6)])
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    zero = tangent * np.sign(np.sum(tangent * (top - base), axis=1))[:, None]
    return np.cross(zero, [0.0, 0.0, 1.0]), zero


def _rig(base, top, **values) -> dict[str, Any]:
    axes, zero = crank_layout(base, top)
    return dict(base_points=base, platform_points=top, motor_axes=axes, crank_zero=zero,
                crank_branch=np.ones(6), **values)


def _box(mass: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    return (mass * (y * y + z * z) / 12.0, mass * (x * x + z * z) / 12.0, mass * (x * x + y * y) / 12.0)


def _simrig100() -> dict[str, Any]:
    base = np.roll(hexapod_points(0.45, (0.0, 120.0, 240.0), 15.0), -1, axis=0)
    top = hexapod_points(0.35, (60.0, 180.0, 300.0), 15.0)
    crank_mass, crank_com, rod_mass, rod_length = 1.0, 0.05, 0.8, 0.48
    return _rig(base, top, crank_length=0.1, rod_length=rod_length,
                platform_mass=100.0, platform_inertia=_box(100.0, 0.6, 0.6, 1.0), platform_com=(0.0, 0.0, 0.3),
                crank_mass=crank_mass, crank_com_distance=crank_com,
                crank_inertia=1.2e-4 * 50.0**2 + crank_mass * 0.1**2 / 3.0,
                rod_mass=rod_mass, rod_com_distance=rod_length / 2.0, rod_inertia=rod_mass * rod_length**2 / 12.0,
                gravity=9.81, crank_angle_limits=(-math.radians(60.0), math.radians(60.0)),
                motor_torque_limit=2.39 * 50.0 * 0.9, motor_speed_limit=3000.0 * 2.0 * math.pi / 60.0 / 50.0,
                crank_joint_max_angle=math.radians(30.0), platform_joint_max_angle=math.radians(30.0),
                name="simrig100")


def _desktop_servo() -> dict[str, Any]:
    base = np.roll(hexapod_points(0.075, (0.0, 120.0, 240.0), 15.0), -1, axis=0)
    top = hexapod_points(0.055, (60.0, 180.0, 300.0), 10.0)
    mass, radius, horn, rod_mass, rod_length = 0.14, 0.06, 0.005, 0.004, 0.115
    disc = mass * radius**2 / 4.0
    return _rig(base, top, crank_length=0.025, rod_length=rod_length,
                platform_mass=mass, platform_inertia=(disc, disc, 2.0 * disc),
                crank_mass=horn, crank_com_distance=0.0125, crank_inertia=5e-8 * 250.0**2 + horn * 0.025**2 / 3.0,
                rod_mass=rod_mass, rod_com_distance=rod_length / 2.0, rod_inertia=rod_mass * rod_length**2 / 12.0,
                gravity=9.81, crank_angle_limits=(-math.pi / 2.0, math.pi / 2.0),
                motor_torque_limit=1.08, motor_speed_limit=math.radians(60.0) / 0.17,
                crank_joint_max_angle=math.radians(25.0), platform_joint_max_angle=math.radians(25.0),
                name="desktop_servo")


_PRESETS: dict[str, tuple[Callable[[], dict[str, Any]], str]] = {
    "simrig100": (_simrig100, "sim-racing rig, 100 kg of driver and seat, 0.1 m cranks, 750 W servos at 50:1"),
    "desktop_servo": (_desktop_servo, "desktop hobby-servo hexapod, 25 mm horns, 0.14 kg platform"),
}


def presets() -> dict[str, str]:
    """Names of the built-in rotary rigs, each with a one-line description."""
    return {name: desc for name, (_, desc) in _PRESETS.items()}


def fields(name: str) -> dict[str, Any]:
    """The fields of the built-in rotary rig ``name`` (:func:`presets`), as keyword arguments
    of :class:`stewart.RotaryParams`."""
    try:
        build, _ = _PRESETS[name]
    except KeyError:
        raise ValueError(f"name: unknown rotary preset {name!r}; available: {', '.join(_PRESETS)}") from None
    return build()
