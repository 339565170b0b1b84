"""``make demo``: the default platform at home, and its dynamics at a moving state."""

from __future__ import annotations

import argparse

import numpy as np

import stewart
from stewart import reference


def _row(label: str, values) -> str:
    return f"  {label:<28}" + "".join(f"{v:>11.5f}" for v in values)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m stewart.demo", description=__doc__)
    parser.add_argument("--preset", default="narayan2017", choices=sorted(stewart.presets()))
    args = parser.parse_args(argv)

    params = stewart.PlatformParams.preset(args.preset)
    home = stewart.home_pose(params)
    print(f"Platform {params.name!r}: {stewart.presets()[params.name]}")
    print(f"  masses: platform {params.platform_mass:.4f} kg, cylinder {params.cylinder_mass:.4f} kg, "
          f"piston {params.piston_mass:.4f} kg")
    print(_row("home pose [m, rad]", home))
    print(_row("leg lengths at home [m]", stewart.leg_lengths(params, home)))

    zero = np.zeros(6)
    print(_row("static forces at home [N]", reference.inverse_dynamics(params, home, zero, zero)))
    scale = home[2]
    xd = np.array([0.1, -0.05, 0.2, 0.3, -0.2, 0.1]) * np.array([scale] * 3 + [1] * 3)
    xdd = np.array([1.0, 0.5, -2.0, 2.0, 1.0, -1.5]) * np.array([scale] * 3 + [1] * 3)
    tau = reference.inverse_dynamics(params, home, xd, xdd)
    print("Inverse dynamics at home (numeric reference, Lopes & Pires 2011):")
    print(_row("xdot [m/s, rad/s]", xd))
    print(_row("xddot [m/s^2, rad/s^2]", xdd))
    print(_row("actuator forces tau [N]", tau))
    print(_row("leg velocities [m/s]", stewart.leg_velocities(params, home, xd)))
    back = reference.forward_dynamics(params, home, xd, tau)
    print(f"  forward dynamics recovers xddot to {np.max(np.abs(back - xdd)):.1e}")


if __name__ == "__main__":
    main()
