"""``stewart envelope`` (the peak forces and joint loads per leg over a box of states, a move
or trajectories) and ``stewart sweep`` (a family of designs sized from a TOML file)."""

from __future__ import annotations

import os
import sys

from ..model import kinematics
from ..model.kinematics import POSE_AXES
from ..motion.trajectory import PointToPoint
from ..motion.trajectory import load as load_trajectory
from .common import (
    EXIT_WORKSPACE,
    UserError,
    check_outputs,
    check_plotting,
    chunking,
    flag_names,
    progress,
    rig_params,
    scheduler,
)
from .options import (
    ACCELERATION_UNITS,
    AXES,
    RATE_UNITS,
    UNITS,
    add_chunk_size,
    add_file,
    add_move_time,
    add_params,
    add_profile,
    add_progress,
    add_scheduler,
    add_seed,
    add_six,
    count,
    non_negative,
    positive,
    subcommand,
)

# ---------------------------------------------------------------------------- envelope

#: The user's flags for the arguments of the envelope's specification.
_ENVELOPE_FLAGS = {"dt": "--dt", "margin": "--margin", "motion": "--target", "motions": "--trajectory"}


def _envelope_spec(args, params):
    """The specification of ``stewart envelope``, a description of it and the flags that set it."""
    try:
        return _envelope_arguments(args, params)
    except ValueError as exc:
        raise UserError(flag_names(str(exc), _ENVELOPE_FLAGS)) from None


def _home(params):
    """The home pose of ``params``: a linear platform's, or a rotary rig's (RotaryPlatform.home)."""
    from ..model.rotary_params import RotaryParams

    if isinstance(params, RotaryParams):
        from ..model.rotary import RotaryPlatform

        return RotaryPlatform(params).home
    return kinematics.home_pose(params)


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
            move = PointToPoint(_home(params), args.target, args.move_time, args.profile)
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


def _write(args, result) -> None:
    """The files of ``--csv``, ``--json`` and ``--plot`` of an envelope or a sweep."""
    for flag, write in (("csv", result.to_csv), ("json", result.to_json), ("plot", result.plot)):
        if getattr(args, flag):
            write(getattr(args, flag))
            print(f"wrote {getattr(args, flag)}")


def cmd_envelope(args) -> int:
    from ..studies.envelope import envelope

    check_outputs(args, "--csv", "--json", "--plot")
    if args.plot:
        check_plotting("--plot")
    params, label = rig_params(args)
    spec, what, flags = _envelope_spec(args, params)
    if args.trajectory or (args.target is not None and args.margin is None):
        if args.samples is not None:
            raise UserError("--samples: trajectories are sampled every --dt seconds")
    try:
        with scheduler(args.scheduler) as client:
            result = envelope(params, spec, samples=args.samples, seed=args.seed, client=client,
                              progress=progress(args), **chunking(args))
    except ValueError as exc:
        raise UserError(flag_names(str(exc), {"spec": flags, "samples": "--samples", "seed": "--seed",
                                              "chunk_size": "--chunk-size"})) from None
    print(f"# platform {label}: envelope over {what}, {result.states:,} states "
          f"({result.outside_stroke:,} {result.outside_words}, {result.singular:,} singular, left out)")
    print(f"{result.member:>4}" + "".join(f"{f'{q} [{u}]':>22}" for q, u in result.quantities))
    for leg in range(6):
        print(f"{leg:>4}" + "".join(f"{result.value(q)[leg]:>22.6g}" for q, _ in result.quantities))
    _write(args, result)
    if result.outside_stroke + result.singular == result.states:
        print("stewart envelope: error: no state of the specification is reachable", file=sys.stderr)
        return EXIT_WORKSPACE
    return 0


def add_envelope(sub) -> None:
    p = subcommand(sub, "envelope", "peak actuator force, velocity and power and joint forces per leg (a rotary "
                   "rig's: motor torque, crank speed and mechanical power per motor) over a box of poses with "
                   "velocity and acceleration bounds, a move or trajectory files", cmd_envelope)
    add_params(p, rotary=True)
    add_six(p, "--lower", f"lowest pose of the box: {AXES} [{UNITS}]")
    add_six(p, "--upper", f"highest pose of the box [{UNITS}]")
    add_six(p, "--velocity", f"largest |rate| per axis [{RATE_UNITS}]")
    add_six(p, "--acceleration", f"largest |acceleration| per axis [{ACCELERATION_UNITS}]")
    add_six(p, "--target", f"instead of a box: the move from home to this pose [{UNITS}]")
    add_move_time(p)
    add_profile(p)
    p.add_argument("--margin", type=non_negative, help="with --target: the box around the move, each pose range "
                   "widened by this fraction on either side and the rate bounds by 1 + this fraction")
    p.add_argument("--trajectory", action="append", metavar="FILE", help=f"instead of a box: t,{','.join(POSE_AXES)} "
                   "rows of a trajectory, or a .toml/.json Fourier series of stewart excitation (repeatable)")
    p.add_argument("--dt", type=positive, default=1e-3, help="sampling interval of moves and trajectories [s]")
    p.add_argument("--samples", type=count, help="states drawn from the box (default 1000000)")
    add_seed(p, "samples")
    add_chunk_size(p)
    add_scheduler(p)
    add_progress(p)
    add_file(p, "--csv", "write the sizing table (peaks with their states) as CSV")
    add_file(p, "--json", "write the sizing table as JSON")
    add_file(p, "--plot", "write a PNG figure of the peaks per leg")


# ---------------------------------------------------------------------------- sweep

def cmd_sweep(args) -> int:
    from ..studies import sweep

    check_outputs(args, "--csv", "--json", "--plot")
    if args.plot:
        check_plotting("--plot")
    if not args.design:
        raise UserError("DESIGN.toml: the file name is empty; give the sweep file")
    if not os.path.isfile(args.design):
        raise UserError(f"{args.design}: no such file")
    try:
        spec = sweep.load(args.design)
    except ValueError as exc:
        raise UserError(f"{args.design}: {exc}") from None
    with scheduler(args.scheduler) as client:
        result = sweep.sweep(spec, client=client, progress=progress(args))
    front = result.front()
    names = list(spec.designs[0])
    shown = names + ["workspace_volume", "margin_mean", "peak_force", "peak_universal_joint", "peak_spherical_joint"]
    print(f"# design sweep of {result.platform}: {len(spec.designs)} designs; * on the Pareto front of "
          f"{spec.pareto[0]} and {spec.pareto[1]}")
    print(f"{'design':>7} " + "".join(f"{name:>22}" for name in shown))
    for k, design in enumerate(spec.designs):
        values = [design[n] for n in names] + [result.metrics[m][k] for m in shown[len(names):]]
        print(f"{k:>6}{'*' if front[k] else ' '} " + "".join(f"{v:>22.6g}" for v in values))
    _write(args, result)
    return 0


def add_sweep(sub) -> None:
    p = subcommand(sub, "sweep", "size a family of designs (geometry and mass parameters on a grid or at random, "
                   "from a TOML file): workspace volume, force and joint-load peaks, singularity margin, and the "
                   "Pareto front of two of them", cmd_sweep)
    p.add_argument("design", metavar="DESIGN.toml", help="the sweep file (see examples/sweep.toml)")
    add_scheduler(p)
    add_progress(p)
    add_file(p, "--csv", "write every design's parameters and metrics as CSV")
    add_file(p, "--json", "write them as JSON")
    add_file(p, "--plot", "write the Pareto-front figure (PNG)")
