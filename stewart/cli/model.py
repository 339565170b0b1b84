"""``stewart info`` and ``presets`` (the compiled model and the built-in parameter sets), and
``ik``, ``id`` and ``fd``: the model at states given on the command line or in a CSV file."""

from __future__ import annotations

import sys

import numpy as np

from .. import __version__, build_info
from ..model.kinematics import POSE_AXES
from ..model.platform import Platform
from ..model.presets import presets as list_presets
from ..model.rotary_presets import presets as list_rotary_presets
from ..model.reachability import reachability
from ..model.rotary_params import RotaryParams
from .common import EXIT_WORKSPACE, UserError, check_output, print_table, read_csv, rig_params
from .options import ACCELERATION_UNITS, AXES, RATE_UNITS, UNITS, add_file, add_params, add_six, subcommand

POSE = list(POSE_AXES)


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
    for name, desc in list_rotary_presets().items():
        print(f"{name:<18} rotary rig: {desc}")
    return 0


def add_info(sub) -> None:
    subcommand(sub, "info", "how the compiled model was built and which instruction-set path runs", cmd_info)
    subcommand(sub, "presets", "list the built-in parameter sets", cmd_presets)


STATE_COMMANDS = {
    # command: (second and third CLI vectors, their CSV column names, output header)
    "ik": ([], [], [f"L{i}" for i in range(6)]),
    "id": (["vel", "acc"], [f"{p}_dot" for p in POSE] + [f"{p}_ddot" for p in POSE], [f"tau{i}" for i in range(6)]),
    "fd": (["vel", "force"], [f"{p}_dot" for p in POSE] + [f"tau{i}" for i in range(6)],
           [f"{p}_ddot" for p in POSE]),
}


#: What ``ik``, ``id`` and ``fd`` compute for a rotary rig: the crank angles [rad], the motor
#: torques [N m] and the accelerations under motor torques.
ROTARY_HEADERS = {"ik": [f"alpha_{i}" for i in range(6)], "id": [f"tau{i}" for i in range(6)], "fd": [f"{p}_ddot" for p in POSE]}


def cmd_state(args) -> int:
    """``ik``, ``id`` and ``fd``: states from the command line or a CSV file."""
    vectors, more_columns, header = STATE_COMMANDS[args.command]
    check_output("--csv", args.csv)
    params, label = rig_params(args)
    if args.input:
        data = read_csv("--input", args.input, POSE + more_columns)
        source = f"--input {args.input}"
    else:
        data = np.atleast_2d(np.concatenate([args.pose] + [getattr(args, v) for v in vectors]))
        source = "--pose"
    if isinstance(params, RotaryParams):
        return _rotary_state(args, params, label, data, source)
    plat = Platform(params)
    poses = data[:, :6]
    check = reachability(plat, poses, name=source)
    if args.command == "ik":
        values, computed = plat.leg_lengths(poses, return_mask=True)
        values = values - params.leg_length_offsets  # the machine's encoder readings
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
    print_table(label, header, values, args.csv)
    return 0


def _rotary_state(args, params, label, data, source) -> int:
    """``ik``, ``id`` and ``fd`` of a rotary rig (:class:`stewart.RotaryPlatform`): the crank
    angles, the motor torques, the accelerations under motor torques; a pose out of a crank's
    reach is an error (exit 3), or with ``--on-unreachable warn`` a NaN row and a ``reachable``
    column."""
    from ..model.rotary import RotaryPlatform

    rig = RotaryPlatform(params)
    poses, header = data[:, :6], list(ROTARY_HEADERS[args.command])
    if args.command == "ik":
        values, computed = rig.crank_angles(poses, return_mask=True)
    elif args.command == "id":
        values, computed = rig.inverse_dynamics(poses, data[:, 6:12], data[:, 12:], return_mask=True)
    else:
        values, computed = rig.forward_dynamics(poses, data[:, 6:12], data[:, 12:], return_mask=True)
    computed = np.atleast_1d(computed)
    if not computed.all():
        failed = np.flatnonzero(~computed)
        text = (f"{source}: the model is undefined at row(s) {failed[:10].tolist()} (a pose out of a crank's reach, "
                "or a singular state)")
        if args.on_unreachable == "error":
            raise UserError(text + " (use --on-unreachable warn to compute anyway)", EXIT_WORKSPACE)
        print(f"stewart {args.command}: warning: {text}", file=sys.stderr)
    values = np.atleast_2d(values)
    if args.on_unreachable == "warn":
        values, header = np.column_stack([values, computed.astype(float)]), header + ["reachable"]
    print_table(label, header, values, args.csv)
    return 0


def state_usage_error(args) -> str | None:
    """What is wrong with the vectors of an ``ik``, ``id`` or ``fd`` command line, if anything."""
    vectors = ["pose"] + STATE_COMMANDS[args.command][0]
    given = [f"--{v}" for v in vectors if getattr(args, v) is not None]
    if args.input and given:
        return f"{args.command}: --input cannot be combined with {' '.join(given)}"
    missing = [f"--{v}" for v in vectors if getattr(args, v) is None]
    if not args.input and missing:
        return f"{args.command}: give {' '.join(missing)} or --input CSV"
    return None


def add_state_commands(sub) -> None:
    """``ik``, ``id`` and ``fd``."""
    first, last = POSE[0], POSE[-1]
    rates = ("--vel", f"pose rates [{RATE_UNITS}]")
    state_commands = [
        ("ik", "encoder readings of poses: the leg lengths (inverse kinematics) less the parameters' "
         "leg_length_offsets; for a rotary rig the crank angles [rad]", [], f"poses, one per row: {','.join(POSE)}"),
        ("id", "actuator forces for a motion (inverse dynamics); for a rotary rig the motor torques [N m]",
         [rates, ("--acc", f"pose accelerations [{ACCELERATION_UNITS}]")],
         f"rows of pose, velocity, acceleration (18 columns; a header {first},...,{last},{first}_dot,...,{last}_dot,"
         f"{first}_ddot,...,{last}_ddot picks them by name)"),
        ("fd", "accelerations under actuator forces (forward dynamics); for a rotary rig under motor torques",
         [rates, ("--force", "actuator forces [N]; for a rotary rig motor torques [N m]")],
         f"rows of pose, velocity, forces (18 columns; a header {first},...,{last},{first}_dot,...,{last}_dot,"
         "tau0,...,tau5 picks them by name)"),
    ]
    for name, help_text, extra, input_help in state_commands:
        p = subcommand(sub, name, help_text, cmd_state)
        p.set_defaults(usage_error=state_usage_error)
        add_params(p, rotary=True)
        add_six(p, "--pose", f"{AXES} [{UNITS}]")
        for flag, flag_help in extra:
            add_six(p, flag, flag_help)
        p.add_argument("--input", metavar="CSV", help=f"{input_help}; a header line is allowed "
                       "(instead of the vectors above)")
        add_file(p, "--csv", "write the results to a CSV file")
        p.add_argument("--on-unreachable", choices=["error", "warn"], default="error",
                       help="a pose outside the workspace (stroke limits, below the base, singular) is an error "
                            "(exit 3), or a warning and a 'reachable' column (1 or 0) in the output")
