"""The ``stewart`` command: kinematics, dynamics, simulation, validation and benchmarks
from the shell. Parameters come from ``--preset NAME`` or ``--params FILE`` (TOML/JSON)."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from .presets import presets as list_presets
from .control import PID, Actuators, ComputedTorque
from .params import PlatformParams
from .platform import Platform
from .simulation import simulate
from .trajectory import PROFILES, PointToPoint, SampledTrajectory

POSE = ["x", "y", "z", "psi", "theta", "phi"]


def _params(args) -> PlatformParams:
    if args.params:
        return PlatformParams.load(args.params)
    return PlatformParams.preset(args.preset)


def _rows(args, width: int, what: str) -> np.ndarray:
    """The input states: one from the command line, or rows of a CSV file."""
    if args.input:
        data = np.atleast_2d(np.loadtxt(args.input, delimiter=",", comments="#", ndmin=2))
        if data.shape[1] != width:
            raise ValueError(f"--input: expected {width} columns ({what}), got {data.shape[1]}")
        return data
    return None


def _print_table(header: list[str], rows: np.ndarray, csv_path: str | None) -> None:
    if csv_path:
        np.savetxt(csv_path, rows, delimiter=",", header=",".join(header), comments="", fmt="%.12g")
        print(f"wrote {len(rows)} row(s) to {csv_path}")
        return
    print("".join(f"{h:>18}" for h in header))
    for row in rows:
        print("".join(f"{v:>18.10g}" for v in row))


def cmd_presets(args) -> None:
    for name, desc in list_presets().items():
        print(f"{name:<18} {desc}")


def cmd_ik(args) -> None:
    plat = Platform(_params(args))
    poses = _rows(args, 6, "x y z psi theta phi")
    poses = np.atleast_2d(args.pose if poses is None else poses)
    _print_table([f"L{i}" for i in range(6)], plat.leg_lengths(poses), args.csv)


def cmd_id(args) -> None:
    plat = Platform(_params(args))
    data = _rows(args, 18, "pose, velocity, acceleration")
    if data is None:
        data = np.atleast_2d(np.concatenate([args.pose, args.vel, args.acc]))
    _print_table([f"tau{i}" for i in range(6)], plat.inverse_dynamics(data[:, :6], data[:, 6:12], data[:, 12:]), args.csv)


def cmd_fd(args) -> None:
    plat = Platform(_params(args))
    data = _rows(args, 18, "pose, velocity, forces")
    if data is None:
        data = np.atleast_2d(np.concatenate([args.pose, args.vel, args.force]))
    header = [f"{p}_ddot" for p in POSE]
    _print_table(header, plat.forward_dynamics(data[:, :6], data[:, 6:12], data[:, 12:]), args.csv)


def cmd_simulate(args) -> None:
    plat = Platform(_params(args))
    if args.trajectory:
        trajectory = SampledTrajectory.from_csv(args.trajectory)
    elif args.target:
        trajectory = PointToPoint(plat.home_pose, args.target, args.move_time, args.profile)
    else:
        raise ValueError("--target or --trajectory: give the pose to move to, or a trajectory file")
    controller = PID.tuned(plat, args.bandwidth) if args.controller == "pid" else \
        ComputedTorque.tuned(args.bandwidth or 5.0)
    actuators = Actuators(force_limit=args.force_limit, viscous=args.viscous, coulomb=args.coulomb)
    progress = sys.stderr.isatty() if args.progress is None else args.progress
    result = simulate(plat, trajectory, controller, duration=args.duration, dt=args.dt, method=args.method,
                      actuators=actuators, progress=progress)
    s = result.summary()
    print(f"platform {plat.params.name or args.params!r}, {type(controller).__name__}, {args.method}, dt = {args.dt:g} s")
    print(f"outcome: {result.reason}")
    print("peak force per leg [N]: " + "  ".join(f"{v:.4g}" for v in s["peak_force"]))
    print(f"final error: position {s['final_position_error']:.3e} m, angle {s['final_angle_error']:.3e} rad")
    print(f"RMS error:   position {s['rms_position_error']:.3e} m, angle {s['rms_angle_error']:.3e} rad")
    print(f"wall time {1e3 * s['wall_time']:.1f} ms for {s['simulated_time']:g} s simulated")
    if args.csv:
        result.to_csv(args.csv)
        print(f"time series written to {args.csv}")
    if args.npz:
        result.to_npz(args.npz)
        print(f"time series written to {args.npz}")
    if args.plot:
        from .plots import plot_run

        for path in plot_run(result, args.plot, prefix="simulation", title=plat.params.name or ""):
            print(f"figure written to {path}")
    if not result.completed:
        sys.exit(3)


def cmd_validate(args) -> None:
    from . import validation

    params = _params(args)
    checks = validation.run(params, n_states=args.states, seed=args.seed)
    print(validation.format_report(params, checks))
    if not all(c.passed for c in checks):
        sys.exit(1)


def cmd_bench(args) -> None:
    from . import bench

    bench.main([args.preset] if args.preset else None, batch=args.batch)


def _add_params(parser) -> None:
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--preset", default="narayan2017", choices=sorted(list_presets()),
                       help="built-in parameter set (default narayan2017)")
    group.add_argument("--params", metavar="FILE", help="parameter file, .toml or .json")


_METAVARS = {
    "--pose": tuple(POSE), "--target": tuple(POSE),
    "--vel": tuple(f"{p}'" for p in POSE), "--acc": tuple(f"{p}''" for p in POSE),
    "--force": tuple(f"tau{i}" for i in range(6)),
}


def _six(parser, flag: str, help_text: str) -> None:
    parser.add_argument(flag, nargs=6, type=float, metavar=_METAVARS[flag], help=help_text)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="stewart", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("presets", help="list the built-in parameter sets")
    p.set_defaults(func=cmd_presets)

    # ik, id and fd: states from the command line or a CSV file, results printed or written.
    state_commands = [
        ("ik", "leg lengths of poses (inverse kinematics)", cmd_ik, [], "poses, one per row (6 columns)"),
        ("id", "actuator forces for a motion (inverse dynamics)", cmd_id,
         [("--vel", "pose rates [m/s, rad/s]"), ("--acc", "pose accelerations [m/s^2, rad/s^2]")],
         "rows of pose, velocity, acceleration (18 columns)"),
        ("fd", "accelerations under actuator forces (forward dynamics)", cmd_fd,
         [("--vel", "pose rates [m/s, rad/s]"), ("--force", "actuator forces [N]")],
         "rows of pose, velocity, forces (18 columns)"),
    ]
    for name, help_text, func, extra, input_help in state_commands:
        p = sub.add_parser(name, help=help_text)
        _add_params(p)
        _six(p, "--pose", "x y z psi theta phi [m, rad]")
        for flag, flag_help in extra:
            _six(p, flag, flag_help)
        p.add_argument("--input", metavar="CSV", help=input_help)
        p.add_argument("--csv", metavar="FILE", help="write the results to a CSV file")
        p.set_defaults(func=func)

    p = sub.add_parser("simulate", help="simulate a move under PID or computed-torque control")
    _add_params(p)
    _six(p, "--target", "pose to move to from home: x y z psi theta phi [m, rad]")
    p.add_argument("--trajectory", metavar="CSV", help="follow t,x,y,z,psi,theta,phi rows instead")
    p.add_argument("--move-time", type=float, default=5.0, help="duration of the move to --target [s] (5)")
    p.add_argument("--profile", choices=sorted(PROFILES), default="sinusoidal", help="velocity profile")
    p.add_argument("--duration", type=float, help="simulated time [s] (default: the move's)")
    p.add_argument("--controller", choices=["pid", "ct"], default="pid", help="joint PID or computed torque")
    p.add_argument("--bandwidth", type=float, help="controller bandwidth [Hz] (default: tuned per preset)")
    p.add_argument("--dt", type=float, default=1e-3, help="step / output interval [s] (0.001)")
    p.add_argument("--method", choices=["rk4", "adaptive"], default="rk4")
    p.add_argument("--force-limit", type=float, default=np.inf, help="actuator force saturation [N]")
    p.add_argument("--viscous", type=float, default=0.0, help="viscous friction per leg [N s/m]")
    p.add_argument("--coulomb", type=float, default=0.0, help="Coulomb friction per leg [N]")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar (default: when stderr is a terminal)")
    p.add_argument("--csv", metavar="FILE", help="write the time series as CSV")
    p.add_argument("--npz", metavar="FILE", help="write the time series as NPZ")
    p.add_argument("--plot", metavar="DIR", help="write PNG figures into DIR")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("validate", help="check the model against independent physics for a platform")
    _add_params(p)
    p.add_argument("--states", type=int, default=200, help="random states per check (200)")
    p.add_argument("--seed", type=int, default=0)
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("bench", help="time the compiled kernel and the simulation loop")
    p.add_argument("--preset", choices=sorted(list_presets()), help="one preset (default: all)")
    p.add_argument("--batch", type=int, default=200_000, help="states per batch (200000)")
    p.set_defaults(func=cmd_bench)
    return parser


def main(argv=None) -> None:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command in ("ik", "id", "fd") and getattr(args, "input", None) is None:
        needed = {"ik": ["pose"], "id": ["pose", "vel", "acc"], "fd": ["pose", "vel", "force"]}[args.command]
        missing = [f"--{n}" for n in needed if getattr(args, n) is None]
        if missing:
            parser.error(f"{args.command}: give {' '.join(missing)} or --input CSV")
    try:
        args.func(args)
    except (ValueError, OSError) as exc:
        print(f"stewart {args.command}: error: {exc}", file=sys.stderr)
        sys.exit(2)


if __name__ == "__main__":
    main()
