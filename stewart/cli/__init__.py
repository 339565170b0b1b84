"""The ``stewart`` command: kinematics, dynamics, simulation, validation and benchmarks
from the shell. Parameters come from ``--preset NAME`` or ``--params FILE`` (TOML/JSON).
CSV files are comma-separated with an optional header line; lines starting with ``#``
are comments (outputs name the platform in one)."""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import sys
import warnings

import numpy as np

from .. import __version__, build_info
from ..io import csvfile
from ..model.kinematics import POSE_AXES
from ..model import kinematics
from ..identification import excitation
from ..motion.control import PID, Actuators, ComputedTorque
from ..io.mjcf import SOLVERS, to_mjcf
from ..model.params import NonAxisymmetricLegWarning, PlatformParams
from ..model.platform import Platform
from ..model.presets import presets as list_presets
from ..motion.simulation import (
    DEFAULT_TOLERANCE,
    MAX_ADAPTIVE_STEPS,
    MAX_STEPS,
    OUTCOMES,
    SimulationInterrupted,
    simulate,
)
from ..motion.trajectory import PROFILES, PointToPoint
from ..motion.trajectory import load as load_trajectory
from ..model.reachability import WorkspaceError, reachability

POSE = list(POSE_AXES)

EXIT_CHECK_FAILED = 1
EXIT_USAGE = 2
EXIT_WORKSPACE = 3
EXIT_INTERRUPTED = OUTCOMES["interrupted"]

EXIT_CODES = """\
exit codes:
  0    success
  1    a check failed (stewart validate)
  2    usage or input error: bad flag, conflicting flags, bad or missing file, bad value
  3    the target, trajectory or pose is outside the workspace (stroke limits, singular
       or unreachable poses), found before any run
  4    the run failed: the platform left its assembly mode or passed a singularity, hit a
       stroke limit, the state became non-finite or the solver used its step budget
  5    the run finished but the final tracking error is above --tolerance
  6    the commanded actuator force exceeded --force-limit (the actuators saturated)
  130  interrupted (Ctrl-C); what was computed is saved
With several problems the lowest code >= 3 is returned; every problem is printed."""


class UserError(Exception):
    """A mistake in the command line or its files: one line on stderr and ``code``."""

    def __init__(self, message: str, code: int = EXIT_USAGE):
        super().__init__(message)
        self.code = code


# ---------------------------------------------------------------------------- arguments

def _parsed(text: str, kind=float):
    try:
        return kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not {'a whole' if kind is int else 'a'} number: {text!r}") from None


def _number(text: str) -> float:
    value = _parsed(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def _positive(text: str) -> float:
    value = _number(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def _non_negative(text: str) -> float:
    value = _number(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text}")
    return value


def _limit(text: str) -> float:
    """A force limit: > 0, and ``inf`` allowed (no limit)."""
    value = _parsed(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0 (or inf for no limit), got {text}")
    return value


def _count(text: str) -> int:
    value = _parsed(text, int)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text}")
    return value


class _Formatter(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Shows every option's default (unless it has none) and keeps the epilog's layout."""

    def _get_help_string(self, action):
        if action.default is None or action.default is False or "%(default)" in (action.help or ""):
            return action.help
        return super()._get_help_string(action)


_METAVARS = {
    "--pose": tuple(POSE), "--target": tuple(POSE), "--centre": tuple(POSE),
    "--vel": tuple(f"{p}'" for p in POSE), "--acc": tuple(f"{p}''" for p in POSE),
    "--force": tuple(f"tau{i}" for i in range(6)),
    "--lower": tuple(POSE), "--upper": tuple(POSE),
    "--velocity": tuple(f"{p}'" for p in POSE), "--acceleration": tuple(f"{p}''" for p in POSE),
}


def _six(parser, flag: str, help_text: str) -> None:
    parser.add_argument(flag, nargs=6, type=_number, metavar=_METAVARS[flag], help=help_text)


def _add_params(parser) -> None:
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--preset", default="narayan2017", choices=sorted(list_presets()),
                       help="built-in parameter set")
    group.add_argument("--params", metavar="FILE", help="parameter file, .toml or .json (instead of --preset)")


def _subcommand(sub, name: str, help_text: str, func):
    p = sub.add_parser(name, help=help_text, description=help_text, formatter_class=_Formatter,
                       epilog=EXIT_CODES)
    p.set_defaults(func=func)
    return p


# ---------------------------------------------------------------------------- helpers

def _params(args) -> tuple[PlatformParams, str]:
    """The parameter set and a label naming it."""
    if not args.params:
        return PlatformParams.preset(args.preset), f"{args.preset} (preset)"
    path = args.params
    if not os.path.exists(path):
        raise UserError(f"--params {path}: no such file")
    if os.path.isdir(path):
        raise UserError(f"--params {path}: is a directory, not a parameter file")
    try:
        params = PlatformParams.load(path)
    except (ValueError, OSError, TypeError, RecursionError) as exc:
        message = str(exc)
        message = message[len("path: "):] if message.startswith("path: ") else message
        raise UserError(f"--params {path}: {message}") from None
    return params, f"{params.name or 'unnamed'} (from {path})"


def _check_output(flag: str, path: str | None, directory: bool = False) -> None:
    """Fail now, not after a long run, when ``path`` cannot be written."""
    if not path:
        return
    if directory:
        if os.path.exists(path) and not os.path.isdir(path):
            raise UserError(f"{flag} {path}: exists and is not a directory")
        parent = path if os.path.isdir(path) else os.path.dirname(os.path.abspath(path))
    else:
        if os.path.isdir(path):
            raise UserError(f"{flag} {path}: is a directory; give a file name")
        parent = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(parent):
        raise UserError(f"{flag} {path}: the directory {parent} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise UserError(f"{flag} {path}: the directory {parent} is not writable")


def _check_parameter_file_name(flag: str, path: str | None) -> None:
    """A file to write parameters or a series to: its format is in its name (.toml or .json)."""
    if path and not path.lower().endswith((".toml", ".json")):
        raise UserError(f"{flag} {path}: give a .toml or .json file name")


def _check_plotting(flag: str) -> None:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UserError(f"{flag}: plotting needs matplotlib; install it with pip install 'stewart[plot]'") from None


@contextlib.contextmanager
def _scheduler(address: str | None):
    """A ``dask.distributed.Client`` of the cluster at ``address`` (``--scheduler``), or None."""
    if address is None:
        yield None
        return
    try:
        from distributed import Client
    except ImportError:
        raise UserError("--scheduler: needs dask.distributed; install it with pip install 'stewart[cluster]'") from None
    try:
        client = Client(address, timeout=10)
    except (OSError, ValueError, TypeError) as exc:
        raise UserError(f"--scheduler {address}: cannot connect ({exc})") from None
    with client:
        yield client


def _read_csv(flag: str, path: str, columns: list[str]) -> np.ndarray:
    try:
        return csvfile.read(path, columns)
    except ValueError as exc:
        raise UserError(f"{flag} {exc}") from None


def _print_table(label: str, header: list[str], rows: np.ndarray, csv_path: str | None) -> None:
    if csv_path:
        csvfile.write(csv_path, header, rows, f"platform {label}")
        print(f"wrote {len(rows)} row(s) to {csv_path} (platform {label})")
        return
    print(f"# platform {label}")
    print("".join(f"{h:>18}" for h in header))
    for row in rows:
        print("".join(f"{v:>18.10g}" for v in row))


# ---------------------------------------------------------------------------- commands

def cmd_info(args) -> int:
    """How the compiled model was built and which path runs (stewart.build_info())."""
    info = build_info()
    print(f"stewart {__version__}")
    print(f"simd path     {info['simd']} (compiled: {', '.join(info['compiled'])};"
          f" this CPU: {', '.join(info['supported'])}; force one with STEWART_SIMD)")
    print(f"compiler      {info['compiler']}")
    for name, flags in info["flags"].items():
        print(f"flags         {name}: {flags}")
    print(f"threads       {info['threads']}")
    return 0


def cmd_presets(args) -> int:
    for name, desc in list_presets().items():
        print(f"{name:<18} {desc}")
    return 0


_STATE_COMMANDS = {
    # command: (second and third CLI vectors, their CSV column names, output header)
    "ik": ([], [], [f"L{i}" for i in range(6)]),
    "id": (["vel", "acc"], [f"{p}_dot" for p in POSE] + [f"{p}_ddot" for p in POSE], [f"tau{i}" for i in range(6)]),
    "fd": (["vel", "force"], [f"{p}_dot" for p in POSE] + [f"tau{i}" for i in range(6)],
           [f"{p}_ddot" for p in POSE]),
}


def cmd_state(args) -> int:
    """``ik``, ``id`` and ``fd``: states from the command line or a CSV file."""
    vectors, more_columns, header = _STATE_COMMANDS[args.command]
    _check_output("--csv", args.csv)
    params, label = _params(args)
    plat = Platform(params)
    if args.input:
        data = _read_csv("--input", args.input, POSE + more_columns)
        source = f"--input {args.input}"
    else:
        data = np.atleast_2d(np.concatenate([args.pose] + [getattr(args, v) for v in vectors]))
        source = "--pose"
    poses = data[:, :6]
    check = reachability(plat, poses, name=source)
    if args.command == "ik":
        values, computed = plat.leg_lengths(poses, return_mask=True)
    elif args.command == "id":
        values, computed = plat.inverse_dynamics(poses, data[:, 6:12], data[:, 12:], return_mask=True)
    else:
        values, computed = plat.forward_dynamics(poses, data[:, 6:12], data[:, 12:], return_mask=True)
    reachable = check.ok & np.atleast_1d(computed)
    if not reachable.all():
        lines = [check.message("pose")] if not check.ok.all() else []
        failed = np.flatnonzero(~np.atleast_1d(computed))
        if failed.size:
            lines.append(f"the model is undefined at row(s) {failed[:10].tolist()} (singular state)")
        text = f"{source}: " + "; ".join(lines)
        if args.on_unreachable == "error":
            raise UserError(text + " (use --on-unreachable warn to compute anyway)", EXIT_WORKSPACE)
        print(f"stewart {args.command}: warning: {text}", file=sys.stderr)
    values = np.atleast_2d(values)
    if args.on_unreachable == "warn":
        values, header = np.column_stack([values, reachable.astype(float)]), header + ["reachable"]
    _print_table(label, header, values, args.csv)
    return 0


def _trajectory(args, plat):
    if args.trajectory:
        try:
            return load_trajectory(args.trajectory), f"--trajectory {args.trajectory}"
        except ValueError as exc:
            message = str(exc)
            prefix = "" if message.startswith(args.trajectory) else f"{args.trajectory}: "
            raise UserError(f"--trajectory {prefix}{message}") from None
    if args.target:
        try:
            return PointToPoint(plat.home_pose, args.target, args.move_time, args.profile), "--target"
        except ValueError as exc:
            raise UserError(f"--target, --move-time: {exc}") from None
    raise UserError("give --target (a pose to move to) or --trajectory (a CSV file)")


# The names simulate() gives its arguments, and the flags a user types for them.
_SIMULATE_FLAGS = {"dt": "--dt", "duration": "--duration", "max_steps": "--max-steps", "tolerance": "--tolerance"}


def _flags(message: str, names: dict[str, str]) -> str:
    """Rename the argument names leading ``message`` (``"dt, duration: ..."``) as flags."""
    head, sep, tail = message.partition(": ")
    parts = [p.strip() for p in head.split(",")]
    if sep and all(p in names for p in parts):
        message = ", ".join(names[p] for p in parts) + sep + tail
    return message.replace("max_steps=", names.get("max_steps", "max_steps") + " ")


def cmd_simulate(args) -> int:
    for flag in ("--csv", "--npz"):
        _check_output(flag, getattr(args, flag[2:]))
    _check_output("--plot", args.plot, directory=True)
    if args.plot:
        _check_plotting("--plot")
    params, label = _params(args)
    plat = Platform(params)
    trajectory, source = _trajectory(args, plat)
    controller = PID.tuned(plat, args.bandwidth) if args.controller == "pid" else \
        ComputedTorque.tuned(args.bandwidth or 5.0)
    actuators = Actuators(force_limit=args.force_limit, viscous=args.viscous, coulomb=args.coulomb)
    progress = sys.stderr.isatty() if args.progress is None else args.progress
    try:
        result = simulate(plat, trajectory, controller, duration=args.duration, dt=args.dt, method=args.method,
                          actuators=actuators, progress=progress, tolerance=tuple(args.tolerance),
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
        raise UserError(_flags(str(exc), {**_SIMULATE_FLAGS, "trajectory": source})) from None
    if not args.json:
        _report(result, label, args)
    files = _save(args, result)
    if args.json:
        print(json.dumps(_summary(result, label, files)))
    return result.exit_code


def _summary(result, label: str, files: list[str]) -> dict:
    """The JSON summary of a run."""
    s = result.summary()
    return {
        "command": "simulate", "platform": result.metadata["platform"], "platform_source": label,
        "controller": result.metadata["controller"], "method": result.method, "dt": result.metadata["dt"],
        "outcome": result.outcome, "ok": result.ok, "exit_code": result.exit_code, "problems": result.problems,
        "completed": result.completed, "reason": result.reason,
        "peak_force": s["peak_force"].tolist(), "peak_commanded_force": float(np.max(np.abs(result.commanded_forces))),
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
    print("peak force per leg [N]: " + "  ".join(f"{v:.4g}" for v in s["peak_force"]))
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


def cmd_optimize(args) -> int:
    if args.target is None:
        raise UserError("give --target x y z psi theta phi")
    _check_output("--csv", args.csv)
    _check_output("--plot", args.plot, directory=True)
    if args.plot:
        _check_plotting("--plot")
    try:
        from ..motion import optimize
    except ImportError:  # pragma: no cover - depends on the environment
        raise UserError("needs CasADi (with IPOPT): pip install 'stewart[opt]'") from None
    params, label = _params(args)
    plat = Platform(params)
    force_limit = None if math.isinf(args.force_limit) else args.force_limit
    try:
        move = optimize.minimum_effort_move(plat, np.array(args.target), args.move_time, args.intervals,
                                            force_limit=force_limit, max_iterations=args.max_iterations)
    except WorkspaceError as exc:
        raise UserError(f"--target: {str(exc).partition(': ')[2]}", EXIT_WORKSPACE) from None
    except ValueError as exc:
        raise UserError(_flags(str(exc), _OPTIMIZE_FLAGS)) from None
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
    for path in files:
        print(f"written: {path}")
    return code


#: The user's flags for the arguments of :func:`stewart.motion.optimize.minimum_effort_move`.
_OPTIMIZE_FLAGS = {"target": "--target", "duration": "--move-time", "intervals": "--intervals",
                   "force_limit": "--force-limit", "max_iterations": "--max-iterations"}


#: The user's flags for the arguments of the workspace functions and the parameters they override.
_WORKSPACE_FLAGS = {"region": "--region", "orientation": "--orientation", "position": "--position",
                    "samples": "--samples", "grid": "--grid", "seed": "--seed", "chunk_size": "--chunk-size",
                    "resolution": "--resolution", "universal_joint_max_angle": "--universal-max-angle",
                    "spherical_joint_max_angle": "--spherical-max-angle", "leg_diameter": "--leg-diameter"}

#: The slices drawn by ``stewart workspace --slices``: the three coordinate planes through home.
_SLICES = {"translational": ("xy", "xz", "yz"), "orientation": ("psi,theta", "psi,phi", "theta,phi")}


def cmd_workspace(args) -> int:
    from ..studies import workspace

    _check_output("--csv", args.csv)
    _check_output("--slices", args.slices, directory=True)
    if args.slices:
        _check_plotting("--slices")
    if args.kind == "orientation" and args.orientation is not None:
        raise UserError("--orientation: holds the orientation of a translational workspace; "
                        "with --kind orientation give --position")
    if args.kind == "translational" and args.position is not None:
        raise UserError("--position: holds the position of an orientation workspace; "
                        "with --kind translational give --orientation")
    for flag, value in (("--universal-max-angle", args.universal_max_angle),
                        ("--spherical-max-angle", args.spherical_max_angle)):
        if value is not None and value > 90.0:
            raise UserError(f"{flag}: a cone half-angle needs 0 < DEG <= 90, got {value:g}")
    params, label = _params(args)
    bounds = {"universal_joint_max_angle": args.universal_max_angle, "spherical_joint_max_angle":
              args.spherical_max_angle, "leg_diameter": args.leg_diameter}
    region = None if args.region is None else np.reshape(args.region, (3, 2))
    fixed = ({"orientation": args.orientation or (0.0, 0.0, 0.0)} if args.kind == "translational"
             else {"position": args.position})
    progress = sys.stderr.isatty() if args.progress is None else args.progress
    try:
        params = params.replace(**{key: math.radians(v) if "angle" in key else v
                                   for key, v in bounds.items() if v is not None})
        study = workspace.translational_workspace if args.kind == "translational" else workspace.orientation_workspace
        with _scheduler(args.scheduler) as client:
            result = study(params, **fixed, region=region, samples=None if args.grid else args.samples,
                           grid=args.grid, seed=args.seed, client=client, progress=progress,
                           **_chunking(args))
        slices = [workspace.workspace_slice(params, axes, **fixed, region=_zoom(result, axes),
                                            resolution=args.resolution)
                  for axes in _SLICES[args.kind]] if args.slices else []
    except ValueError as exc:
        raise UserError(_flags(str(exc), _WORKSPACE_FLAGS)) from None
    files = []
    if slices:
        from ..io.plots import plot_workspace_slices

        os.makedirs(args.slices, exist_ok=True)
        files.append(plot_workspace_slices(slices, os.path.join(args.slices, f"workspace_{args.kind}.png"),
                                           f"{params.name or 'unnamed'}: {args.kind} workspace slices through home"))
    summary = {"command": "workspace", "platform_source": label, **result.summary()}
    code = 0 if result.reachable else EXIT_WORKSPACE
    if args.csv:
        flat = {key: json.dumps(val) if isinstance(val, (list, dict)) else val for key, val in summary.items()}
        numeric = {key: val for key, val in flat.items() if isinstance(val, (int, float)) and val is not None}
        csvfile.write(args.csv, list(numeric), np.array([list(numeric.values())], dtype=float), f"platform {label}")
        files.append(args.csv)
    summary.update(exit_code=code, files=files)
    if args.json:
        print(json.dumps(summary))
    else:
        _workspace_report(result, label, files)
    if not result.reachable:
        excluded = ", ".join(f"{name} {n}" for name, n in result.excluded.items())
        raise UserError(f"no sampled pose is reachable ({result.samples} samples; excluded: {excluded})",
                        EXIT_WORKSPACE)
    return code


def _zoom(result, axes: str):
    """The two rows of the sampled region for a slice's ``axes``, narrowed to the reachable
    samples' bounding box widened by a fifth of its size (the whole region if none is reachable)."""
    names = axes.split(",") if "," in axes else list(axes)
    rows = [result.axes.index(name) for name in names]
    region = result.region[rows]
    if result.bounding_box is None:
        return region
    box = result.bounding_box[rows]
    pad = 0.2 * (box[:, 1] - box[:, 0]) + 1e-9 * (region[:, 1] - region[:, 0])
    return np.column_stack([np.maximum(box[:, 0] - pad, region[:, 0]), np.minimum(box[:, 1] + pad, region[:, 1])])


def _workspace_report(result, label: str, files: list[str]) -> None:
    unit = result.unit
    axes = ", ".join(result.axes)
    held = "orientation" if result.kind == "translational" else "position"
    print(f"platform {label}: {result.kind} workspace ({axes}) at {held} "
          f"{' '.join(f'{v:.6g}' for v in result.fixed)}")
    print(f"{result.method}: {result.reachable} of {result.samples} poses reachable"
          + (f" (seed {result.seed})" if result.seed is not None else ""))
    print(f"volume {result.volume:.6g} +- {result.volume_error:.2g} {unit}^3")
    if result.bounding_box is not None:
        for name, (lo, hi) in zip(result.axes, result.bounding_box):
            print(f"  {name:<6} {lo:+.5g} .. {hi:+.5g} {unit}")
        print(f"singularity margin (1/cond J_C): min {result.margin_min:.3g}, mean {result.margin_mean:.3g}, "
              f"max {result.margin_max:.3g}")
    if result.clipped:
        print(f"warning: the workspace reaches the --region faces on {', '.join(result.clipped)}; widen --region")
    if result.excluded:
        print("excluded: " + ", ".join(f"{name} {n}" for name, n in result.excluded.items()))
    for path in files:
        print(f"written: {path}")


def cmd_validate(args) -> int:
    from ..oracles import validation

    params, label = _params(args)
    with contextlib.redirect_stdout(sys.stderr) if args.json else contextlib.nullcontext():
        checks = validation.run(params, n_states=args.states, seed=args.seed)
    code = 0 if all(c.passed for c in checks) else EXIT_CHECK_FAILED
    if args.json:
        print(json.dumps({
            "command": "validate", "platform": params.name or "unnamed", "platform_source": label,
            "states": args.states, "seed": args.seed, "passed": code == 0, "exit_code": code,
            "checks": [{"name": c.name, "worst": float(c.worst), "bound": float(c.bound), "passed": bool(c.passed)}
                       for c in checks],
        }))
    else:
        print(validation.format_report(params, checks))
    return code


def cmd_exactness(args) -> int:
    from ..oracles import exactness

    params, label = _params(args)
    try:
        effect = exactness.leg_spin_effect(params, n_states=args.states, seed=args.seed)
    except ValueError as exc:
        source = f"--params {args.params}" if args.params else f"--preset {args.preset}"
        raise UserError(_flags(str(exc), {"params": source, "seed": "--seed", "n_states": "--states"})) from None
    if args.json:
        print(json.dumps({"command": "exactness", "platform": params.name or "unnamed", "platform_source": label,
                          "states": args.states, "seed": args.seed, "assumed_axes": effect.assumed_axes,
                          "dynamic": effect.dynamic._asdict(), "velocity": effect.velocity._asdict(),
                          "exit_code": 0}))
        return 0
    axes = ("first axes horizontal and tangential to the base circle (assumed)" if effect.assumed_axes
            else "the parameters' universal_joint_axes")
    print(f"platform {label}: the paper's legs (no spin, eq. 29) against legs that turn with their universal "
          f"joints, {axes}; {args.states} random states, seed {args.seed}")
    print(f"{'relative change of the actuator forces':<44} {'median':>9} {'max':>9}")
    for name, change in (("dynamic forces (all but gravity)", effect.dynamic),
                         ("velocity-dependent forces", effect.velocity)):
        print(f"{name:<44} {change.median:>9.1e} {change.max:>9.1e}")
    return 0


def cmd_bench(args) -> int:
    from . import bench

    with contextlib.redirect_stdout(sys.stderr) if args.json else contextlib.nullcontext():
        figures = bench.main([args.preset] if args.preset else None, batch=args.batch)
    if args.json:
        print(json.dumps({"command": "bench", "batch": args.batch, "exit_code": 0, "figures": figures}))
    return 0


def cmd_c_export(args) -> int:
    from ..io import capi

    params, label = _params(args)
    if os.path.exists(args.directory) and not os.path.isdir(args.directory):
        raise UserError(f"DIR {args.directory}: exists and is not a directory")
    try:
        written = capi.export(args.directory, params)
    except OSError as exc:
        raise UserError(f"DIR {args.directory}: {exc.strerror or exc}") from None
    for path in written:
        print(f"wrote {path}")
    print(f"platform {label}: stewart_platform_params in {capi.PARAMS_HEADER}")
    return 0


def cmd_export_mjcf(args) -> int:
    _check_output("--output", args.output)
    params, label = _params(args)
    try:
        text = to_mjcf(params, pose=args.pose, solver=args.solver)
    except ValueError as exc:
        message = str(exc)
        raise UserError(f"--{message}" if message.startswith("pose:") else message) from None
    if not args.output:
        sys.stdout.write(text)
        return 0
    try:
        with open(args.output, "w", encoding="utf-8") as handle:
            handle.write(text)
    except OSError as exc:
        raise UserError(f"--output {args.output}: {exc.strerror or exc}") from None
    print(f"wrote {args.output}: MuJoCo model of platform {label}, solver settings '{args.solver}'")
    return 0


def cmd_identify(args) -> int:
    from ..identification import identify

    for flag in ("--output", "--report", "--plot"):
        _check_output(flag, getattr(args, flag[2:]))
    _check_parameter_file_name("--output", args.output)
    if args.plot:
        _check_plotting("--plot")
        if not args.validate:
            raise UserError("--plot: draws the prediction of a held-out run; give --validate FILE too")
    prior, label = _params(args)
    plat = Platform(prior)

    def measurements(flag, path):
        try:
            return identify.Measurements.from_csv(path)
        except ValueError as exc:
            raise UserError(f"{flag}{exc}") from None

    if not args.data:
        raise UserError("DATA.csv: the file name is empty; give the log to identify from")
    data = measurements("", args.data)
    try:
        result = identify.identify(plat, data, filter=args.filter, cutoff=args.cutoff, friction=args.friction)
    except ValueError as exc:
        raise UserError(_flags(str(exc), {"cutoff": "--cutoff", "measurements": args.data, "forces": args.data})) \
            from None
    print(f"# platform {label}: identified from {args.data} ({len(data.t)} samples at {data.rate:.6g} Hz, "
          f"{args.filter} filter, cut-off {args.cutoff:g} Hz)")
    print(result.table())
    summary = result.summary()
    if args.validate:
        held = measurements("--validate ", args.validate)
        try:
            t, predicted, measured, rms = identify.validation(result, plat, held, filter=args.filter,
                                                              cutoff=args.cutoff)
        except ValueError as exc:
            raise UserError(_flags(str(exc), {"cutoff": "--cutoff", "measurements": f"--validate {args.validate}",
                                              "forces": f"--validate {args.validate}"})) from None
        spread = np.sqrt(np.mean((measured - measured.mean(axis=0)) ** 2, axis=0))
        print(f"held-out run {args.validate}: RMS error per leg [N] {', '.join(f'{v:.3g}' for v in rms)} "
              f"(force spread {', '.join(f'{v:.3g}' for v in spread)})")
        summary["validation"] = {"file": args.validate, "rms": rms.tolist(), "spread": spread.tolist()}
        if args.plot:
            from ..io.plots import plot_force_prediction

            print(f"wrote {plot_force_prediction(t, predicted, measured, args.plot)}")
    if args.report:
        with open(args.report, "w", encoding="utf-8") as handle:
            json.dump(summary, handle, indent=2)
        print(f"wrote {args.report}")
    if args.output:
        try:
            params = result.params()
        except ValueError as exc:
            print(f"stewart identify: error: --output {args.output}: not written: {exc}", file=sys.stderr)
            return EXIT_CHECK_FAILED
        with warnings.catch_warnings():  # the legs' I_yy and I_zz are identified apart (Identification.params)
            warnings.simplefilter("ignore", NonAxisymmetricLegWarning)
            params.replace(name=f"{prior.name or 'platform'} (identified)").save(args.output)
        print(f"wrote {args.output}: the prior's parameters with the identified inertial and friction values")
    return 0


def cmd_excitation(args) -> int:
    for flag in ("--csv", "--output", "--plot"):
        _check_output(flag, getattr(args, flag[2:]))
    _check_parameter_file_name("--output", args.output)
    if args.plot:
        _check_plotting("--plot")
    params, label = _params(args)
    plat = Platform(params)
    try:
        design = excitation.design_excitation(
            plat, period=args.period, harmonics=args.harmonics, centre=args.centre, periods=args.periods,
            samples=args.samples, starts=args.starts, seed=args.seed, max_leg_velocity=args.max_leg_velocity,
            max_leg_acceleration=args.max_leg_acceleration,
            force_limit=None if math.isinf(args.force_limit) else args.force_limit, min_margin=args.min_margin,
            stroke_margin=args.stroke_margin, friction=args.friction, max_iterations=args.max_iterations,
            progress=_progress(args))
        if args.csv:
            design.to_csv(args.csv, plat, args.rate)
    except WorkspaceError as exc:
        raise UserError(_flags(str(exc), _EXCITATION_FLAGS), EXIT_WORKSPACE) from None
    except ValueError as exc:
        raise UserError(_flags(str(exc), _EXCITATION_FLAGS)) from None
    files = [args.csv] if args.csv else []
    if args.output:
        design.save(args.output)
        files.append(args.output)
    if args.plot:
        from ..io.plots import plot_excitation

        files.append(plot_excitation(design, plat, args.plot))
    code = 0 if design.feasible else OUTCOMES["failed"]
    if args.json:
        print(json.dumps({"command": "excitation", "platform_source": label, **design.summary(), "files": files,
                          "exit_code": code}))
    else:
        _excitation_report(design, label, files)
    for problem in design.problems:
        print(f"stewart excitation: error: {problem}", file=sys.stderr)
    return code


#: The user's flags for the arguments of :func:`stewart.identification.excitation.design_excitation`.
_EXCITATION_FLAGS = {"period": "--period", "harmonics": "--harmonics", "centre": "--centre", "periods": "--periods",
                     "samples": "--samples", "starts": "--starts", "seed": "--seed", "rate": "--rate",
                     "max_leg_velocity": "--max-leg-velocity", "max_leg_acceleration": "--max-leg-acceleration",
                     "force_limit": "--force-limit", "min_margin": "--min-margin", "stroke_margin": "--stroke-margin",
                     "max_iterations": "--max-iterations", "centre": "--centre"}


def _excitation_report(design, label: str, files: list[str]) -> None:
    traj, peaks, lim = design.trajectory, design.peaks, design.limits
    print(f"platform {label}: Fourier excitation, {traj.harmonics} harmonics, period {traj.period:g} s, "
          f"{traj.periods} period(s), {len(design.base_names)} base parameters")
    print(f"condition number {design.condition:.4g} (random start {design.initial_condition:.4g}; best of "
          f"{design.starts} start(s), {design.iterations} SLSQP iterations"
          + (f"; amplitudes scaled by {design.scaled:.4g} to hold on the check grid)" if design.scaled < 1 else ")"))
    force = "none" if math.isinf(lim.force) else f"{lim.force:.4g}"
    print(f"{'':<26}{'reached':>12}{'limit':>12}")
    for name, reached, limit in (("leg length min [m]", peaks["leg_length_min"], f"{lim.lengths[0]:.4g}"),
                                 ("leg length max [m]", peaks["leg_length_max"], f"{lim.lengths[1]:.4g}"),
                                 ("leg velocity [m/s]", peaks["leg_velocity"], f"{lim.leg_velocity:.4g}"),
                                 ("leg acceleration [m/s^2]", peaks["leg_acceleration"], f"{lim.leg_acceleration:.4g}"),
                                 ("actuator force [N]", peaks["force"], force),
                                 ("singularity margin (min)", peaks["margin_min"], f"{lim.margin:.4g}")):
        print(f"{name:<26}{reached:>12.4g}{limit:>12}")
    for path in files:
        print(f"written: {path}")


# ---------------------------------------------------------------------------- parser

def _add_execution(parser) -> None:
    """The flags of a chunked study (:mod:`stewart.studies.execution`)."""
    parser.add_argument("--seed", type=int, default=0, help="seed of the random samples")
    from ..studies import execution, workspace

    parser.add_argument("--chunk-size", type=_count, help="states per chunk (per task on a cluster; default: "
                        f"{workspace.CHUNK_SIZE} poses for a workspace, {execution.DEFAULT_CHUNK_SIZE} states "
                        "for an envelope)")
    _add_cluster(parser)


def _chunking(args) -> dict:
    """``chunk_size`` for a study if ``--chunk-size`` was given (else the study's default)."""
    return {} if args.chunk_size is None else {"chunk_size": args.chunk_size}


def _add_cluster(parser) -> None:
    """Where a study runs: ``--scheduler`` of a Dask cluster, and its progress bar."""
    parser.add_argument("--scheduler", metavar="ADDRESS", help="run the chunks on the Dask cluster of this "
                        "scheduler (e.g. tcp://10.0.0.5:8786; needs pip install 'stewart[cluster]')")
    parser.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                        help="progress bar on stderr (default: when stderr is a terminal)")


def _progress(args) -> bool:
    return sys.stderr.isatty() if args.progress is None else args.progress


def _envelope_spec(args, params):
    """The specification of ``stewart envelope``, a description of it and the flags that set it."""
    try:
        return _envelope_arguments(args, params)
    except ValueError as exc:
        raise UserError(_flags(str(exc), _ENVELOPE_FLAGS)) from None


#: The user's flags for the arguments of the envelope's specification.
_ENVELOPE_FLAGS = {"dt": "--dt", "margin": "--margin", "motion": "--target", "motions": "--trajectory"}


def _envelope_arguments(args, params):
    from ..studies import envelope

    box = [args.lower, args.upper, args.velocity, args.acceleration]
    if args.trajectory:
        if any(v is not None for v in box) or args.target is not None:
            raise UserError("--trajectory cannot be combined with --target or the box flags")
        motions = []
        for path in args.trajectory:
            try:
                motions.append(load_trajectory(path))
            except ValueError as exc:
                message = str(exc)
                raise UserError(f"--trajectory {message if message.startswith(path) else path + ': ' + message}") \
                    from None
        return envelope.Trajectories(motions, args.dt), f"{len(motions)} trajectory file(s)", "--trajectory, --dt"
    if args.target is not None:
        if any(v is not None for v in box):
            raise UserError("--target cannot be combined with the box flags (--lower, --upper, ...)")
        try:
            move = PointToPoint(kinematics.home_pose(params), args.target, args.move_time, args.profile)
        except ValueError as exc:
            raise UserError(f"--target, --move-time: {exc}") from None
        if args.margin is None:
            return envelope.Trajectories([move], args.dt), "the move to --target", "--target, --move-time"
        return (envelope.Box.around(move, args.margin, args.dt), f"the box around the move, margin {args.margin:g}",
                "--target, --move-time, --margin")
    missing = [f for f, v in zip(("--lower", "--upper", "--velocity", "--acceleration"), box) if v is None]
    if missing:
        raise UserError(f"give the box ({' '.join(missing)} missing), --target or --trajectory")
    try:
        return envelope.Box(*box), "the box", "--velocity, --acceleration"
    except ValueError as exc:
        raise UserError("--" + str(exc)) from None


def cmd_envelope(args) -> int:
    from ..studies.envelope import QUANTITIES, envelope

    for flag in ("--csv", "--json", "--plot"):
        _check_output(flag, getattr(args, flag[2:]))
    if args.plot:
        _check_plotting("--plot")
    params, label = _params(args)
    spec, what, flags = _envelope_spec(args, params)
    if args.trajectory or (args.target is not None and args.margin is None):
        if args.samples is not None:
            raise UserError("--samples: trajectories are sampled every --dt seconds")
    try:
        with _scheduler(args.scheduler) as client:
            result = envelope(params, spec, samples=args.samples, seed=args.seed, client=client,
                              progress=_progress(args), **_chunking(args))
    except ValueError as exc:
        raise UserError(_flags(str(exc), {"spec": flags, "samples": "--samples", "seed": "--seed",
                                          "chunk_size": "--chunk-size"})) from None
    print(f"# platform {label}: envelope over {what}, {result.states:,} states "
          f"({result.outside_stroke:,} outside the stroke, {result.singular:,} singular, left out)")
    print(f"{'leg':>4}" + "".join(f"{f'{q} [{u}]':>22}" for q, u in QUANTITIES))
    for leg in range(6):
        print(f"{leg:>4}" + "".join(f"{result.value(q)[leg]:>22.6g}" for q, _ in QUANTITIES))
    for flag, write in (("csv", result.to_csv), ("json", result.to_json), ("plot", result.plot)):
        if getattr(args, flag):
            write(getattr(args, flag))
            print(f"wrote {getattr(args, flag)}")
    if result.outside_stroke + result.singular == result.states:
        print("stewart envelope: error: no state of the specification is reachable", file=sys.stderr)
        return EXIT_WORKSPACE
    return 0


def cmd_sweep(args) -> int:
    from ..studies import sweep

    for flag in ("--csv", "--json", "--plot"):
        _check_output(flag, getattr(args, flag[2:]))
    if args.plot:
        _check_plotting("--plot")
    if not args.design:
        raise UserError("DESIGN.toml: the file name is empty; give the sweep file")
    if not os.path.isfile(args.design):
        raise UserError(f"{args.design}: no such file")
    try:
        spec = sweep.load(args.design)
    except ValueError as exc:
        raise UserError(f"{args.design}: {exc}") from None
    with _scheduler(args.scheduler) as client:
        result = sweep.sweep(spec, client=client, progress=_progress(args))
    front = result.front()
    names = list(spec.designs[0])
    shown = names + ["workspace_volume", "margin_mean", "peak_force", "peak_universal_joint", "peak_spherical_joint"]
    print(f"# design sweep of {result.platform}: {len(spec.designs)} designs; * on the Pareto front of "
          f"{spec.pareto[0]} and {spec.pareto[1]}")
    print(f"{'design':>7} " + "".join(f"{name:>22}" for name in shown))
    for k, design in enumerate(spec.designs):
        values = [design[n] for n in names] + [result.metrics[m][k] for m in shown[len(names):]]
        print(f"{k:>6}{'*' if front[k] else ' '} " + "".join(f"{v:>22.6g}" for v in values))
    for flag, write in (("csv", result.to_csv), ("json", result.to_json), ("plot", result.plot)):
        if getattr(args, flag):
            write(getattr(args, flag))
            print(f"wrote {getattr(args, flag)}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="stewart", description=__doc__.replace("``", ""),
                                     formatter_class=_Formatter, epilog=EXIT_CODES)
    info = build_info()
    parser.add_argument("--version", action="version",
                        version=f"%(prog)s {__version__} ({info['simd']} path, {info['compiler']})")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    _subcommand(sub, "info", "how the compiled model was built and which instruction-set path runs", cmd_info)
    _subcommand(sub, "presets", "list the built-in parameter sets", cmd_presets)

    state_commands = [
        ("ik", "leg lengths of poses (inverse kinematics)", [], "poses, one per row: x,y,z,psi,theta,phi"),
        ("id", "actuator forces for a motion (inverse dynamics)",
         [("--vel", "pose rates [m/s, rad/s]"), ("--acc", "pose accelerations [m/s^2, rad/s^2]")],
         "rows of pose, velocity, acceleration (18 columns; a header x,...,phi,x_dot,...,phi_dot,x_ddot,...,"
         "phi_ddot picks them by name)"),
        ("fd", "accelerations under actuator forces (forward dynamics)",
         [("--vel", "pose rates [m/s, rad/s]"), ("--force", "actuator forces [N]")],
         "rows of pose, velocity, forces (18 columns; a header x,...,phi,x_dot,...,phi_dot,tau0,...,tau5 "
         "picks them by name)"),
    ]
    for name, help_text, extra, input_help in state_commands:
        p = _subcommand(sub, name, help_text, cmd_state)
        _add_params(p)
        _six(p, "--pose", "x y z psi theta phi [m, rad]")
        for flag, flag_help in extra:
            _six(p, flag, flag_help)
        p.add_argument("--input", metavar="CSV", help=f"{input_help}; a header line is allowed "
                       "(instead of the vectors above)")
        p.add_argument("--csv", metavar="FILE", help="write the results to a CSV file")
        p.add_argument("--on-unreachable", choices=["error", "warn"], default="error",
                       help="a pose outside the workspace (stroke limits, below the base, singular) is an error "
                            "(exit 3), or a warning and a 'reachable' column (1 or 0) in the output")

    p = _subcommand(sub, "simulate", "simulate a move under PID or computed-torque control", cmd_simulate)
    _add_params(p)
    goal = p.add_mutually_exclusive_group()
    _six(goal, "--target", "pose to move to from home: x y z psi theta phi [m, rad]")
    goal.add_argument("--trajectory", metavar="FILE", help="follow t,x,y,z,psi,theta,phi rows of a CSV file instead "
                      "(a header naming these columns picks them from a wider file, e.g. a simulation's --csv), or "
                      "the Fourier series of a .toml/.json file written by stewart excitation --output")
    p.add_argument("--move-time", type=_positive, default=5.0, help="duration of the move to --target [s]")
    p.add_argument("--profile", choices=sorted(PROFILES), default="sinusoidal", help="velocity profile of the move")
    p.add_argument("--duration", type=_positive, help="simulated time [s] (default: the move's)")
    p.add_argument("--controller", choices=["pid", "ct"], default="pid", help="joint PID or computed torque")
    p.add_argument("--bandwidth", type=_positive, help="controller bandwidth [Hz] (default: tuned per preset)")
    p.add_argument("--dt", type=_positive, default=1e-3, help="step / output interval [s]")
    p.add_argument("--method", choices=["rk4", "adaptive"], default="rk4", help="fixed-step RK4 or adaptive DOP853")
    p.add_argument("--max-steps", type=_count, help=f"step budget of the run (default: {MAX_STEPS} for rk4, "
                   f"{MAX_ADAPTIVE_STEPS} or four per --dt, whichever is more, for the adaptive solver)")
    p.add_argument("--tolerance", nargs=2, type=_positive, metavar=("METRES", "RADIANS"),
                   default=list(DEFAULT_TOLERANCE),
                   help="largest final tracking error accepted: position and Euler-angle norms")
    p.add_argument("--force-limit", type=_limit, default=math.inf, help="actuator force saturation [N]")
    p.add_argument("--viscous", type=_non_negative, help="viscous friction of every leg [N s/m] (default: the "
                   "platform's viscous_friction, none without it)")
    p.add_argument("--coulomb", type=_non_negative, help="Coulomb friction of every leg [N] (default: the "
                   "platform's coulomb_friction, none without it)")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar on stderr (default: when stderr is a terminal)")
    p.add_argument("--csv", metavar="FILE", help="write the time series as CSV")
    p.add_argument("--npz", metavar="FILE", help="write the time series as NPZ")
    p.add_argument("--plot", metavar="DIR", help="write PNG figures into DIR (needs matplotlib)")
    p.add_argument("--json", action="store_true", help="print only a JSON summary on stdout")

    p = _subcommand(sub, "optimize", "the least-effort move from home to a target pose within the stroke and "
                    "force limits (trajectory optimization with IPOPT; needs CasADi)", cmd_optimize)
    _add_params(p)
    _six(p, "--target", "pose to move to from home, at rest at both ends: x y z psi theta phi [m, rad]")
    p.add_argument("--move-time", type=_positive, default=5.0, help="duration of the move [s]")
    p.add_argument("--intervals", type=_count, default=50, help="RK4 intervals (multiple-shooting nodes - 1)")
    p.add_argument("--force-limit", type=_limit, default=math.inf, help="largest actuator force per leg [N]")
    p.add_argument("--max-iterations", type=_count, default=1000, help="IPOPT's iteration budget")
    p.add_argument("--csv", metavar="FILE", help="write the nodes (t, pose, rates, leg lengths, forces) as CSV")
    p.add_argument("--plot", metavar="DIR", help="write PNG figures of forces and leg strokes into DIR")
    p.add_argument("--json", action="store_true", help="print only a JSON summary on stdout")

    p = _subcommand(sub, "excitation", "design a periodic Fourier-series trajectory for identification that "
                    "minimizes the condition number of the base regressor within the stroke, leg velocity, "
                    "acceleration and force limits, away from singularities", cmd_excitation)
    _add_params(p)
    p.add_argument("--period", type=_positive, default=excitation.DEFAULT_PERIOD, help="period of the series [s]")
    p.add_argument("--harmonics", type=_count, default=excitation.DEFAULT_HARMONICS, help="harmonics of the series (at least 2)")
    p.add_argument("--periods", type=_count, default=1, help="periods the exported trajectory repeats")
    _six(p, "--centre", "pose the series moves about, at rest at its start and end (default: home) [m, rad]")
    p.add_argument("--samples", type=_count, help=f"design samples per period (default: {excitation.SAMPLES_PER_HARMONIC} per harmonic)")
    p.add_argument("--starts", type=_count, default=excitation.DEFAULT_STARTS, help="random starts of the optimizer")
    p.add_argument("--seed", type=int, default=0, help="seed of the random starts")
    p.add_argument("--max-iterations", type=_count, default=excitation.DEFAULT_ITERATIONS,
                   help="SLSQP iterations per start")
    p.add_argument("--max-leg-velocity", type=_positive, metavar="M/S", help="largest |leg velocity| "
                   f"(default: {excitation.VELOCITY_PER_STROKE:g} stroke(s) per second)")
    p.add_argument("--max-leg-acceleration", type=_positive, metavar="M/S2", help="largest |leg acceleration| "
                   f"(default: {excitation.ACCELERATION_PER_STROKE:g} strokes per second squared)")
    p.add_argument("--force-limit", type=_limit, default=math.inf, help="largest |actuator force| [N]")
    p.add_argument("--min-margin", type=_positive, help="smallest singularity margin 1/cond(J_C) "
                   f"(default: {excitation.MARGIN_FRACTION:g} times the centre pose's)")
    p.add_argument("--stroke-margin", type=_non_negative, default=excitation.STROKE_MARGIN, help="fraction of the stroke kept free "
                   "at either end")
    p.add_argument("--friction", action=argparse.BooleanOptionalAction, default=True,
                   help="excite the per-leg viscous and Coulomb friction parameters too")
    p.add_argument("--rate", type=_positive, default=excitation.DEFAULT_RATE, help="sample rate of the --csv rows [Hz]")
    p.add_argument("--csv", metavar="FILE", help="write t, pose, leg lengths and leg velocities for a machine "
                   "controller (stewart simulate --trajectory reads it)")
    p.add_argument("--output", metavar="FILE", help="write the series (.toml or .json; stewart simulate "
                   "--trajectory reads it)")
    p.add_argument("--plot", metavar="FILE", help="write a PNG figure of the poses and leg strokes")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar on stderr (default: when stderr is a terminal)")
    p.add_argument("--json", action="store_true", help="print only a JSON summary on stdout")

    p = _subcommand(sub, "envelope", "peak actuator force, velocity and power and joint forces per leg over a "
                    "box of poses with velocity and acceleration bounds, a move or trajectory files", cmd_envelope)
    _add_params(p)
    _six(p, "--lower", "lowest pose of the box: x y z psi theta phi [m, rad]")
    _six(p, "--upper", "highest pose of the box [m, rad]")
    _six(p, "--velocity", "largest |rate| per axis [m/s, rad/s]")
    _six(p, "--acceleration", "largest |acceleration| per axis [m/s^2, rad/s^2]")
    _six(p, "--target", "instead of a box: the move from home to this pose [m, rad]")
    p.add_argument("--move-time", type=_positive, default=5.0, help="duration of the move to --target [s]")
    p.add_argument("--profile", choices=sorted(PROFILES), default="sinusoidal", help="velocity profile of the move")
    p.add_argument("--margin", type=_non_negative, help="with --target: the box around the move, each pose range "
                   "widened by this fraction on either side and the rate bounds by 1 + this fraction")
    p.add_argument("--trajectory", action="append", metavar="FILE", help="instead of a box: t,x,y,z,psi,theta,phi "
                   "rows of a trajectory, or a .toml/.json Fourier series of stewart excitation (repeatable)")
    p.add_argument("--dt", type=_positive, default=1e-3, help="sampling interval of moves and trajectories [s]")
    p.add_argument("--samples", type=_count, help="states drawn from the box (default 1000000)")
    _add_execution(p)
    p.add_argument("--csv", metavar="FILE", help="write the sizing table (peaks with their states) as CSV")
    p.add_argument("--json", metavar="FILE", help="write the sizing table as JSON")
    p.add_argument("--plot", metavar="FILE", help="write a PNG figure of the peaks per leg")

    p = _subcommand(sub, "workspace", "the reachable workspace: volume with its error, bounding box, singularity "
                    "margin, and slices as heat maps", cmd_workspace)
    _add_params(p)
    p.add_argument("--kind", choices=["translational", "orientation"], default="translational",
                   help="positions at a constant orientation, or orientations at a position")
    p.add_argument("--orientation", nargs=3, type=_number, metavar=("PSI", "THETA", "PHI"),
                   help="orientation held by a translational workspace [rad] (default 0 0 0)")
    p.add_argument("--position", nargs=3, type=_number, metavar=("X", "Y", "Z"),
                   help="position held by an orientation workspace [m] (default: home)")
    count = p.add_mutually_exclusive_group()
    count.add_argument("--samples", type=_count, default=100_000, help="uniform random poses (Monte Carlo)")
    count.add_argument("--grid", type=_count, help="grid points per axis instead of random samples")
    p.add_argument("--seed", type=int, default=0, help="seed of the random poses")
    p.add_argument("--region", nargs=6, type=_number, metavar=("LO1", "HI1", "LO2", "HI2", "LO3", "HI3"),
                   help="box to sample [m or rad] (default: one that holds the whole workspace)")
    p.add_argument("--universal-max-angle", type=_positive, metavar="DEG",
                   help="universal-joint cone half-angle [deg] (overrides the parameters')")
    p.add_argument("--spherical-max-angle", type=_positive, metavar="DEG",
                   help="spherical-joint cone half-angle [deg] (overrides the parameters')")
    p.add_argument("--leg-diameter", type=_positive, metavar="M", help="leg diameter for the leg-leg clearance [m] "
                   "(overrides the parameters')")
    p.add_argument("--chunk-size", type=_count, default=20_000, help="poses per chunk (one task)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run the chunks on the Dask cluster at ADDRESS "
                   "(e.g. tcp://host:8786; needs stewart[cluster]) instead of the local cores")
    p.add_argument("--slices", metavar="DIR", help="write PNG heat maps of the margin on the three coordinate "
                   "planes through home, around the reachable samples, into DIR (needs matplotlib)")
    p.add_argument("--resolution", type=_count, default=121, help="cells per axis of each slice")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar on stderr (default: when stderr is a terminal)")
    p.add_argument("--csv", metavar="FILE", help="write the summary's numbers as a one-row CSV file")
    p.add_argument("--json", action="store_true", help="print only a JSON summary on stdout")

    p = _subcommand(sub, "sweep", "size a family of designs (geometry and mass parameters on a grid or at random, "
                    "from a TOML file): workspace volume, force and joint-load peaks, singularity margin, and the "
                    "Pareto front of two of them", cmd_sweep)
    p.add_argument("design", metavar="DESIGN.toml", help="the sweep file (see examples/sweep.toml)")
    _add_cluster(p)
    p.add_argument("--csv", metavar="FILE", help="write every design's parameters and metrics as CSV")
    p.add_argument("--json", metavar="FILE", help="write them as JSON")
    p.add_argument("--plot", metavar="FILE", help="write the Pareto-front figure (PNG)")

    p = _subcommand(sub, "identify", "estimate a built platform's base inertial and friction parameters from a "
                    "log of leg lengths and actuator forces (CSV: t, L0..L5 [m], F0..F5 [N]); the parameters given "
                    "are the prior (geometry, and the values the log cannot determine)", cmd_identify)
    p.add_argument("data", metavar="DATA.csv", help="the log to identify from")
    _add_params(p)
    p.add_argument("--filter", choices=["savgol", "butterworth"], default="savgol",
                   help="zero-phase differentiation of the poses")
    p.add_argument("--cutoff", type=_positive, default=10.0, help="the filter's cut-off [Hz]")
    p.add_argument("--friction", action=argparse.BooleanOptionalAction, default=True,
                   help="identify each leg's viscous and Coulomb friction too")
    p.add_argument("--validate", metavar="FILE", help="a held-out log: print the prediction's RMS error per leg")
    p.add_argument("--output", metavar="FILE", help="write the identified parameters (.toml or .json), loadable "
                   "with --params and Platform.from_file")
    p.add_argument("--report", metavar="FILE", help="write the base parameters with their standard errors (JSON)")
    p.add_argument("--plot", metavar="FILE", help="write predicted against measured forces of --validate (PNG)")

    p = _subcommand(sub, "validate", "check the model against independent physics for a platform", cmd_validate)
    _add_params(p)
    p.add_argument("--states", type=_count, default=200, help="random states per check")
    p.add_argument("--seed", type=int, default=0, help="seed of the random states")
    p.add_argument("--json", action="store_true", help="print only a JSON summary on stdout")

    p = _subcommand(sub, "exactness", "how much the legs' spin with their universal joints changes the actuator "
                    "forces: the paper's model against the exact-leg model", cmd_exactness)
    _add_params(p)
    p.add_argument("--states", type=_count, default=200, help="random states around home")
    p.add_argument("--seed", type=int, default=0, help="seed of the random states")
    p.add_argument("--json", action="store_true", help="print only a JSON summary on stdout")

    p = _subcommand(sub, "c-export", "write the generated C model and a platform's parameter header into a "
                    "directory, for C programs", cmd_c_export)
    _add_params(p)
    p.add_argument("directory", metavar="DIR", help="directory to write into (created if missing)")

    p = _subcommand(sub, "export-mjcf", "write the platform as a standalone MuJoCo model (MJCF): universal "
                    "joints, actuated slides, ball joints as equality constraints; ctrl = actuator forces [N]",
                    cmd_export_mjcf)
    _add_params(p)
    p.add_argument("--output", metavar="FILE", help="write the model to FILE (default: standard output)")
    _six(p, "--pose", "assembly pose: x y z psi theta phi [m, rad] (default: home)")
    p.add_argument("--solver", choices=list(SOLVERS), default="default",
                   help="MuJoCo's defaults (2 ms Euler step, soft constraints), or the 0.1 ms RK4 step and stiff "
                        "constraints the agreement with this model is measured at")

    p = _subcommand(sub, "bench", "time the compiled kernel and the simulation loop", cmd_bench)
    p.add_argument("--preset", choices=sorted(list_presets()), help="one preset (default: all)")
    p.add_argument("--batch", type=_count, default=200_000, help="states per batch")
    p.add_argument("--json", action="store_true", help="print only a JSON summary of the figures on stdout")
    return parser


def main(argv=None) -> None:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command in _STATE_COMMANDS:
        vectors = ["pose"] + _STATE_COMMANDS[args.command][0]
        given = [f"--{v}" for v in vectors if getattr(args, v) is not None]
        if args.input and given:
            parser.error(f"{args.command}: --input cannot be combined with {' '.join(given)}")
        missing = [f"--{v}" for v in vectors if getattr(args, v) is None]
        if not args.input and missing:
            parser.error(f"{args.command}: give {' '.join(missing)} or --input CSV")
    try:
        code = args.func(args)
    except UserError as exc:
        print(f"stewart {args.command}: error: {exc}", file=sys.stderr)
        code = exc.code
    except (ValueError, OSError) as exc:
        print(f"stewart {args.command}: error: {exc}", file=sys.stderr)
        code = EXIT_USAGE
    except KeyboardInterrupt:
        print(f"stewart {args.command}: interrupted", file=sys.stderr)
        code = EXIT_INTERRUPTED
    if code:
        sys.exit(code)


if __name__ == "__main__":
    main()
