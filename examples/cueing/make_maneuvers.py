"""Write the example vehicle logs of examples/cueing/ (CSV t, fx, fy, fz, wx, wy, wz at 100 Hz;
vehicle frame x forward, y left, z up; specific force at the driver's head, [0, 0, 9.81] at
rest) from simple kinematic vehicle models:

* double_lane_change.csv: 80 km/h, a 3.5 m shift left and back (two smooth lane changes);
* hard_braking.csv: 100 km/h to rest at 9 m/s^2, with 0.25 s jerk ramps;
* constant_radius_turn.csv: 15 m/s on a 50 m radius (4.5 m/s^2, 0.3 rad/s), ramped in and out;
* slalom.csv: 15 m/s through cones 18 m apart, lateral amplitude 0.6 m;
* takeoff_roll.csv: an aircraft accelerating at 3 m/s^2 to 60 m/s, then rotating at 3 deg/s
  to 10 deg nose up;
* racing_lap.csv: a GT car on a 2.2 km circuit of straights, a hairpin, a chicane and fast
  sweepers, at the limit of 14 m/s^2 of cornering, 6 m/s^2 of traction and 12 m/s^2 of braking,
  with kerb strikes in the chicane (vertical specific force bursts).

The cars follow their path with the heading of its tangent (no side slip): lateral specific
force ``fy = ydd`` and yaw rate ``wz = ydd / v`` for small heading angles. Run
``python examples/cueing/make_maneuvers.py [DIR]``; the files are reproduced bit for bit.
"""

import os
import sys

import numpy as np

G = 9.81
RATE = 100.0


def smoothstep(s):
    """0 -> 1 with zero slope and curvature at both ends (quintic)."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10.0 - 15.0 * s + 6.0 * s**2)


def times(duration):
    return np.arange(int(round(duration * RATE)) + 1) / RATE


def car(t, ay, ax=None, v=None):
    """A level car: specific force (ax, ay, g), yaw rate ay / v."""
    ax = np.zeros_like(t) if ax is None else ax
    wz = np.zeros_like(t) if v is None else ay / v
    zero = np.zeros_like(t)
    return np.column_stack([t, ax, ay, np.full_like(t, G), zero, zero, wz])


def lateral_from_offset(t, offset):
    """The lateral acceleration of a path offset sampled at t (second derivative, analytic grid)."""
    return np.gradient(np.gradient(offset, t), t)


def double_lane_change():
    t = times(10.0)
    v = 80 / 3.6
    y = 3.5 * (smoothstep((t - 1.0) / 2.5) - smoothstep((t - 5.0) / 2.5))
    return car(t, lateral_from_offset(t, y), v=v)


def hard_braking():
    t = times(6.0)
    v0, decel, ramp = 100 / 3.6, 9.0, 0.25
    stop = 0.5 + ramp + v0 / decel  # the speed lost during both ramps evens out
    ax = -decel * (smoothstep((t - 0.5) / ramp) - smoothstep((t - stop) / ramp))
    return car(t, np.zeros_like(t), ax=ax)


def constant_radius_turn():
    t = times(12.0)
    v, radius = 15.0, 50.0
    ay = v * v / radius * (smoothstep((t - 1.0) / 2.0) - smoothstep((t - 9.0) / 2.0))
    return car(t, ay, v=v)


def slalom():
    t = times(12.0)
    v, gap, amplitude = 15.0, 18.0, 0.6
    w = np.pi * v / gap
    envelope = smoothstep((t - 1.0) / 2.0) - smoothstep((t - 9.0) / 2.0)
    y = amplitude * envelope * np.sin(w * (t - 1.0))
    return car(t, lateral_from_offset(t, y), v=v)


def takeoff_roll():
    t = times(28.0)
    accel, v_rotate, rate, pitch_max = 3.0, 60.0, np.radians(3.0), np.radians(10.0)
    t_rotate = 1.0 + v_rotate / accel
    ax = accel * smoothstep((t - 1.0) / 0.5)
    pitch = np.clip(rate * (t - t_rotate), 0.0, pitch_max)  # nose up
    q = np.gradient(pitch, t)
    climb = 0.5 * G * smoothstep((t - t_rotate - 1.0) / 2.0)  # lift above weight after rotation
    # specific force in the body frame: the world's (ax, 0, g + climb) seen from a nose-up pitch
    fx = ax * np.cos(pitch) + (G + climb) * np.sin(pitch)
    fz = -ax * np.sin(pitch) + (G + climb) * np.cos(pitch)
    zero = np.zeros_like(t)
    return np.column_stack([t, fx, zero, fz, zero, -q, zero])  # nose up is a negative pitch rate (y left)


#: The circuit of racing_lap: (length [m], turn angle [deg], positive left) a segment; a
#: straight has no angle.
CIRCUIT = (
    (350.0, 0.0), (60.0, -90.0), (180.0, 0.0), (50.0, 180.0), (260.0, 0.0),
    (35.0, 45.0), (35.0, -45.0), (240.0, 0.0), (220.0, -110.0), (160.0, 0.0),
    (120.0, 75.0), (250.0, 0.0), (90.0, -100.0), (200.0, 0.0),
)


def racing_lap():
    ds = 0.5  # path step [m]
    curvature = np.concatenate([np.full(int(round(length / ds)), np.radians(angle) / length)
                                for length, angle in CIRCUIT])
    window = np.hanning(int(round(30.0 / ds)))  # turn-in over ~30 m, as a clothoid entry
    curvature = np.convolve(curvature, window / window.sum(), mode="same")
    cornering, traction, braking, top = 14.0, 6.0, 12.0, 70.0
    v2 = np.minimum(top**2, cornering / np.maximum(np.abs(curvature), 1e-9))
    v2[0] = 40.0**2  # a flying lap
    for k in range(1, v2.size):  # traction-limited acceleration
        v2[k] = min(v2[k], v2[k - 1] + 2 * traction * ds)
    for k in range(v2.size - 2, -1, -1):  # braking-limited deceleration
        v2[k] = min(v2[k], v2[k + 1] + 2 * braking * ds)
    v = np.sqrt(v2)
    s_path = np.arange(v.size) * ds
    elapsed = np.concatenate([[0.0], np.cumsum(2 * ds / (v[1:] + v[:-1]))])
    t = times(np.floor(elapsed[-1] * RATE) / RATE)
    speed = np.interp(t, elapsed, v)
    kappa = np.interp(t, elapsed, curvature)
    ax = np.gradient(speed, t)
    ay = speed**2 * kappa
    wz = speed * kappa
    chicane = sum(length for length, _ in CIRCUIT[:5]), sum(length for length, _ in CIRCUIT[:7])
    on_kerb = (np.interp(t, elapsed, s_path) > chicane[0]) & (np.interp(t, elapsed, s_path) < chicane[1])
    kerb = 2.5 * np.sin(2 * np.pi * 12.0 * t) * on_kerb  # 12 Hz kerb rumble
    zero = np.zeros_like(t)
    return np.column_stack([t, ax, ay, G + kerb, zero, zero, wz])


MANEUVERS = {
    "double_lane_change": double_lane_change,
    "hard_braking": hard_braking,
    "constant_radius_turn": constant_radius_turn,
    "slalom": slalom,
    "takeoff_roll": takeoff_roll,
    "racing_lap": racing_lap,
}


def main(directory):
    for name, make in MANEUVERS.items():
        path = os.path.join(directory, f"{name}.csv")
        np.savetxt(path, make(), delimiter=",", fmt="%.10g", comments="",
                   header=f"t,fx,fy,fz,wx,wy,wz\n# {name}: examples/cueing/make_maneuvers.py")
        print(path)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__)))
