"""``stewart simulate`` (a move or trajectory under PID or computed-torque control) and
``stewart optimize`` (the least-effort move to a target, with CasADi and IPOPT)."""

from __future__ import annotations

import json
import math
import sys

import numpy as np

from ..model.kinematics import POSE_AXES
from ..model.platform import Platform
from ..model.reachability import WorkspaceError
from ..motion.control import PID, Actuators, ComputedTorque
from ..motion.mechanism import mechanism
from ..motion.simulation import (
    DEFAULT_TOLERANCE,
    MAX_ADAPTIVE_STEPS,
    MAX_STEPS,
    OUTCOMES,
    SimulationInterrupted,
    simulate,
)
from ..motion.trajectory import PointToPoint
from ..motion.trajectory import load as load_trajectory
from .common import (
    EXIT_INTERRUPTED,
    EXIT_WORKSPACE,
    UserError,
    check_output,
    check_outputs,
    check_plotting,
    flag_names,
    platform_params,
    print_written,
    progress,
    rig_params,
)
from .options import (
    AXES,
    UNITS,
    add_file,
    add_force_limit,
    add_json,
    add_max_iterations,
    add_move_time,
    add_params,
    add_profile,
    add_progress,
    add_six,
    count,
    limit,
    non_negative,
    positive,
    subcommand,
)

# ---------------------------------------------------------------------------- simulate

#: The names simulate() gives its arguments, and the flags a user types for them.
_SIMULATE_FLAGS = {"dt": "--dt", "duration": "--duration", "max_steps": "--max-steps", "tolerance": "--tolerance"}


def _trajectory(args, rig):
    if args.trajectory:
        try:
            return load_trajectory(args.trajectory), f"--trajectory {args.trajectory}"
        except ValueError as exc:
            message = str(exc)
            prefix = "" if message.startswith(args.trajectory) else f"{args.trajectory}: "
            raise UserError(f"--trajectory {prefix}{message}") from None
    target, source = args.target, "--target"
    if not target and rig.default_target is not None:  # a rotary preset's default move
        target, source = rig.default_target, f"the default move of {rig.params.name}"
    if target is not None:
        try:
            return PointToPoint(rig.home, target, args.move_time, args.profile), source
        except ValueError as exc:
            raise UserError(f"--target, --move-time: {exc}") from None
    raise UserError("give --target (a pose to move to) or --trajectory (a CSV file)")


def _actuators(args, rig) -> Actuators:
    """The actuators of ``--force-limit`` (legs) or ``--torque-limit`` (a rotary rig's motors),
    with ``--viscous`` and ``--coulomb``; the flag of the other family refused."""
    if rig.kind == "rotary" and args.force_limit is not None:
        raise UserError("--force-limit: limits a linear platform's leg forces; a rotary rig takes --torque-limit")
    if rig.kind != "rotary" and args.torque_limit is not None:
        raise UserError("--torque-limit: limits a rotary rig's motor torques; a linear platform takes --force-limit")
    given = args.torque_limit if rig.kind == "rotary" else args.force_limit
    bound = rig.default_actuators().force_limit if given is None else given
    return Actuators(force_limit=bound, viscous=args.viscous, coulomb=args.coulomb)


def cmd_simulate(args) -> int:
    check_outputs(args, "--csv", "--npz")
    check_output("--plot", args.plot, directory=True)
    if args.plot:
        check_plotting("--plot")
    params, label = rig_params(args)
    rig = mechanism(params)
    plat = rig.platform
    trajectory, source = _trajectory(args, rig)
    controller = PID.tuned(plat, args.bandwidth) if args.controller == "pid" else \
        ComputedTorque.tuned(args.bandwidth or 5.0)
    actuators = _actuators(args, rig)
    try:
        result = simulate(plat, trajectory, controller, duration=args.duration, dt=args.dt, method=args.method,
                          actuators=actuators, progress=progress(args), tolerance=tuple(args.tolerance),
                          max_steps=args.max_steps)
    except WorkspaceError as exc:
        message = str(exc).partition(": ")[2] if str(exc).startswith(("trajectory: ", "x0: ")) else str(exc)
        if args.json:
            print(json.dumps({"command": "simulate", "platform": params.name or "unnamed", "platform_source": label,
                              "outcome": "outside_workspace", "ok": False, "exit_code": EXIT_WORKSPACE,
                              "problems": [f"{source}: {message}"], "times": exc.times}))
        raise UserError(f"{source}: {message}", EXIT_WORKSPACE) from None
    except SimulationInterrupted as exc:
        files = _save(args, exc.result, quiet=True)
        if args.json:
            print(json.dumps(_summary(exc.result, label, files)))
        print(f"stewart simulate: interrupted at t = {exc.result.t[-1]:.4f} s"
              + (f"; saved {', '.join(files)}" if files else ""), file=sys.stderr)
        return EXIT_INTERRUPTED
    except ValueError as exc:
        raise UserError(flag_names(str(exc), {**_SIMULATE_FLAGS, "trajectory": source})) from None
    if not args.json:
        _report(result, label, args)
    files = _save(args, result)
    if args.json:
        print(json.dumps(_summary(result, label, files)))
    return result.exit_code


def _summary(result, label: str, files: list[str]) -> dict:
    """The JSON summary of a run (a rotary rig's peaks named ``peak_torque``, in N m)."""
    s = result.summary()
    effort = "torque" if result.rotary else "force"
    return {
        "command": "simulate", "platform": result.metadata["platform"], "platform_source": label,
        "controller": result.metadata["controller"], "method": result.method, "dt": result.metadata["dt"],
        "outcome": result.outcome, "ok": result.ok, "exit_code": result.exit_code, "problems": result.problems,
        "completed": result.completed, "reason": result.reason,
        f"peak_{effort}": s["peak_force"].tolist(),
        f"peak_commanded_{effort}": float(np.max(np.abs(result.commanded_forces))),
        "final_position_error": s["final_position_error"], "final_angle_error": s["final_angle_error"],
        "rms_position_error": s["rms_position_error"], "rms_angle_error": s["rms_angle_error"],
        "simulated_time": s["simulated_time"], "wall_time": s["wall_time"], "files": files,
    }


def _report(result, label: str, args) -> None:
    s = result.summary()
    print(f"platform {label}, controller {result.metadata['controller']}, {args.method}, dt = {args.dt:g} s")
    print(f"outcome: {result.outcome}" + ("" if result.ok else f" (exit code {result.exit_code})"))
    for problem in result.problems:
        print(f"  problem: {problem}")
    what = "torque per motor [N m]" if result.rotary else "force per leg [N]"
    print(f"peak {what}: " + "  ".join(f"{v:.4g}" for v in s["peak_force"]))
    print(f"final error: position {s['final_position_error']:.3e} m, angle {s['final_angle_error']:.3e} rad")
    print(f"RMS error:   position {s['rms_position_error']:.3e} m, angle {s['rms_angle_error']:.3e} rad")
    print(f"wall time {1e3 * s['wall_time']:.1f} ms for {s['simulated_time']:g} s simulated")


def _save(args, result, quiet: bool = False) -> list[str]:
    """Write the requested files; returns their paths (a message for each unless quiet or --json)."""
    files = []
    say = (lambda text: None) if args.json or quiet else print
    if args.csv:
        result.to_csv(args.csv)
        files.append(args.csv)
        say(f"time series written to {args.csv}")
    if args.npz:
        result.to_npz(args.npz)
        files.append(args.npz)
        say(f"time series written to {args.npz}")
    if args.plot and len(result.t) > 1:
        from ..io.plots import plot_run

        for path in plot_run(result, args.plot, prefix="simulation"):
            files.append(str(path))
            say(f"figure written to {path}")
    return files


def add_simulate(sub) -> None:
    p = subcommand(sub, "simulate", "simulate a move under PID or computed-torque control (a rotary rig: PID on "
                   "the crank angles, motor torques out)", cmd_simulate)
    add_params(p, rotary=True)
    goal = p.add_mutually_exclusive_group()
    add_six(goal, "--target", f"pose to move to from home: {AXES} [{UNITS}] (a rotary preset has a default move "
            "within its reach)")
    goal.add_argument("--trajectory", metavar="FILE", help=f"follow t,{','.join(POSE_AXES)} rows of a CSV file "
                      "instead (a header naming these columns picks them from a wider file, e.g. a simulation's "
                      "--csv), or the Fourier series of a .toml/.json file written by stewart excitation --output")
    add_move_time(p)
    add_profile(p)
    p.add_argument("--duration", type=positive, help="simulated time [s] (default: the move's)")
    p.add_argument("--controller", choices=["pid", "ct"], default="pid", help="joint PID or computed torque")
    p.add_argument("--bandwidth", type=positive, help="controller bandwidth [Hz] (default: tuned per preset)")
    p.add_argument("--dt", type=positive, default=1e-3, help="step / output interval [s]")
    p.add_argument("--method", choices=["rk4", "adaptive"], default="rk4", help="fixed-step RK4 or adaptive DOP853")
    p.add_argument("--max-steps", type=count, help=f"step budget of the run (default: {MAX_STEPS} for rk4, "
                   f"{MAX_ADAPTIVE_STEPS} or four per --dt, whichever is more, for the adaptive solver)")
    p.add_argument("--tolerance", nargs=2, type=positive, metavar=("METRES", "RADIANS"),
                   default=list(DEFAULT_TOLERANCE),
                   help="largest final tracking error accepted: position and Euler-angle norms")
    p.add_argument("--force-limit", type=limit, help="actuator force saturation [N] of a linear platform's "
                   "legs (default: none)")
    p.add_argument("--torque-limit", type=limit, help="motor torque saturation [N m at the crank] of a rotary "
                   "rig (default: its motor_torque_limit)")
    p.add_argument("--viscous", type=non_negative, help="viscous friction of every leg [N s/m] or motor "
                   "[N m s/rad] (default: the platform's viscous_friction; a rotary rig's none)")
    p.add_argument("--coulomb", type=non_negative, help="Coulomb friction of every leg [N] or motor [N m] "
                   "(default: the platform's coulomb_friction; a rotary rig's none)")
    add_progress(p)
    add_file(p, "--csv", "write the time series as CSV")
    add_file(p, "--npz", "write the time series as NPZ")
    add_file(p, "--plot", "write PNG figures into DIR (needs matplotlib)", metavar="DIR")
    add_json(p)


# ---------------------------------------------------------------------------- optimize

#: The user's flags for the arguments of :func:`stewart.motion.optimize.minimum_effort_move`.
_OPTIMIZE_FLAGS = {"target": "--target", "duration": "--move-time", "intervals": "--intervals",
                   "force_limit": "--force-limit", "max_iterations": "--max-iterations"}


def cmd_optimize(args) -> int:
    if args.target is None:
        raise UserError(f"give --target {AXES}")
    check_output("--csv", args.csv)
    check_output("--plot", args.plot, directory=True)
    if args.plot:
        check_plotting("--plot")
    try:
        from ..motion import optimize
    except ImportError:  # pragma: no cover - depends on the environment
        raise UserError("needs CasADi (with IPOPT): pip install 'stewart[opt]'") from None
    params, label = platform_params(args)
    plat = Platform(params)
    force_limit = None if math.isinf(args.force_limit) else args.force_limit
    try:
        move = optimize.minimum_effort_move(plat, np.array(args.target), args.move_time, args.intervals,
                                            force_limit=force_limit, max_iterations=args.max_iterations)
    except WorkspaceError as exc:
        raise UserError(f"--target: {str(exc).partition(': ')[2]}", EXIT_WORKSPACE) from None
    except ValueError as exc:
        raise UserError(flag_names(str(exc), _OPTIMIZE_FLAGS)) from None
    files = []
    if args.csv:
        move.to_csv(args.csv)
        files.append(args.csv)
    if args.plot:
        from ..io.plots import plot_move

        files += plot_move(move, args.plot, (force_limit, params.leg_length_limits))
    code = 0 if move.ok else OUTCOMES["failed"]
    if not move.ok:  # on stderr, with --json too: stdout holds only the summary
        print(f"stewart optimize: error: IPOPT did not solve the problem ({move.status})", file=sys.stderr)
    if args.json:
        print(json.dumps({"command": "optimize", "platform": params.name or "unnamed", "platform_source": label,
                          "ok": move.ok, "status": move.status, "exit_code": code, "effort": move.effort,
                          "iterations": move.iterations, "solve_seconds": move.solve_seconds,
                          "peak_force": np.max(np.abs(move.tau), axis=0).tolist(), "files": files}))
        return code
    print(f"platform {label}: {len(move.tau)} intervals "
          f"of {move.dt:g} s, {move.status} after {move.iterations} IPOPT iterations ({move.solve_seconds:.3g} s)")
    print(f"effort sum |tau|^2 dt = {move.effort:.6g} N^2 s")
    print("peak force per leg [N]: " + "  ".join(f"{v:.4g}" for v in np.max(np.abs(move.tau), axis=0)))
    print("leg length range [m]: " + f"{np.min(move.lengths):.4g} .. {np.max(move.lengths):.4g}")
    print_written(files)
    return code


def add_optimize(sub) -> None:
    p = subcommand(sub, "optimize", "the least-effort move from home to a target pose within the stroke and "
                   "force limits (trajectory optimization with IPOPT; needs CasADi)", cmd_optimize)
    add_params(p)
    add_six(p, "--target", f"pose to move to from home, at rest at both ends: {AXES} [{UNITS}]")
    add_move_time(p)
    p.add_argument("--intervals", type=count, default=50, help="RK4 intervals (multiple-shooting nodes - 1)")
    add_force_limit(p)
    add_max_iterations(p, 1000, "IPOPT's iteration budget")
    add_file(p, "--csv", "write the nodes (t, pose, rates, leg lengths, forces) as CSV")
    add_file(p, "--plot", "write PNG figures of forces and leg strokes into DIR", metavar="DIR")
    add_json(p)
