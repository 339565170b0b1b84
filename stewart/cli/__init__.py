"""The ``stewart`` command: kinematics, dynamics, simulation, validation and benchmarks
from the shell. Parameters come from ``--preset NAME`` or ``--params FILE`` (TOML/JSON).
CSV files are comma-separated with an optional header line; lines starting with ``#``
are comments (outputs name the platform in one)."""

from __future__ import annotations

import argparse
import sys

from .. import __version__, build_info
from . import calibration, checks, cueing, export, identification, model, modes, motion, rotary, sizing, workspace
from .common import EXIT_CHECK_FAILED, EXIT_CODES, EXIT_INTERRUPTED, EXIT_USAGE, EXIT_WORKSPACE, UserError, refuse_rotary
from .options import Formatter

__all__ = ["main", "build_parser", "UserError", "EXIT_CHECK_FAILED", "EXIT_USAGE", "EXIT_WORKSPACE",
           "EXIT_INTERRUPTED", "EXIT_CODES"]

#: The commands in the order ``stewart --help`` lists them: each adds its parsers to the subparsers.
COMMANDS = (
    model.add_info,  # info, presets
    model.add_state_commands,  # ik, id, fd
    rotary.add_fk,
    motion.add_simulate,
    motion.add_optimize,
    cueing.add_cueing,
    identification.add_excitation,
    sizing.add_envelope,
    rotary.add_motor_sizing,
    rotary.add_servo_angles,
    workspace.add_workspace,
    modes.add_modes,
    sizing.add_sweep,
    identification.add_identify,
    calibration.add_calibrate,
    calibration.add_calibration_poses,
    checks.add_validate,
    checks.add_exactness,
    export.add_c_export,
    export.add_export_acados,
    export.add_export_mjcf,
    checks.add_bench,
)


def build_parser() -> argparse.ArgumentParser:
    """The parser of the ``stewart`` command and its subcommands."""
    parser = argparse.ArgumentParser(prog="stewart", description=__doc__.replace("``", ""),
                                     formatter_class=Formatter, epilog=EXIT_CODES)
    info = build_info()
    parser.add_argument("--version", action="version",
                        version=f"%(prog)s {__version__} ({info['simd']} path, {info['compiler']})")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in COMMANDS:
        add(sub)
    return parser


def main(argv=None) -> None:
    """Run the ``stewart`` command line ``argv`` (default: ``sys.argv[1:]``); exits with its code
    unless that is 0."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        refuse_rotary(args)
    except UserError as exc:
        print(f"stewart {args.command}: error: {exc}", file=sys.stderr)
        sys.exit(exc.code)
    usage_error = getattr(args, "usage_error", None)
    message = usage_error(args) if usage_error else None
    if message:
        parser.error(message)
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
