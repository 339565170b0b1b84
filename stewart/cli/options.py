"""The flags the commands share, each declared once here, the types that check the values
given on the command line, and the help layout of every command."""

from __future__ import annotations

import argparse
import math

from ..model.kinematics import POSE_AXES, POSE_UNITS
from ..model.presets import presets as list_presets
from ..model.rotary_presets import presets as list_rotary_presets
from ..motion.trajectory import PROFILES
from .common import EXIT_CODES

#: The pose's axes as the help spells them, and their units (``m, rad``).
AXES = " ".join(POSE_AXES)
UNITS = ", ".join(dict.fromkeys(POSE_UNITS))
RATE_UNITS = ", ".join(f"{unit}/s" for unit in dict.fromkeys(POSE_UNITS))
ACCELERATION_UNITS = ", ".join(f"{unit}/s^2" for unit in dict.fromkeys(POSE_UNITS))


# ---------------------------------------------------------------------------- value types

def _parsed(text: str, kind=float):
    try:
        return kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not {'a whole' if kind is int else 'a'} number: {text!r}") from None


def number(text: str) -> float:
    """A finite number."""
    value = _parsed(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def positive(text: str) -> float:
    """A finite number > 0."""
    value = number(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def non_negative(text: str) -> float:
    """A finite number >= 0."""
    value = number(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text}")
    return value


def limit(text: str) -> float:
    """A force limit: > 0, and ``inf`` allowed (no limit)."""
    value = _parsed(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0 (or inf for no limit), got {text}")
    return value


def count(text: str) -> int:
    """A whole number >= 1."""
    value = _parsed(text, int)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text}")
    return value


# ---------------------------------------------------------------------------- commands

class Formatter(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Shows every option's default (unless it has none) and keeps the epilog's layout."""

    def _get_help_string(self, action):
        if action.default is None or action.default is False or "%(default)" in (action.help or ""):
            return action.help
        return super()._get_help_string(action)


def subcommand(sub, name: str, help_text: str, func):
    """The parser of the command ``name``, which ``func(args)`` runs (returning the exit code)."""
    p = sub.add_parser(name, help=help_text, description=help_text, formatter_class=Formatter,
                       epilog=EXIT_CODES)
    p.set_defaults(func=func)
    return p


# ---------------------------------------------------------------------------- shared flags

def add_params(parser, rotary: bool = False, default: str = "narayan2017") -> None:
    """``--preset NAME`` or ``--params FILE``: the platform's parameters; with ``rotary`` the
    command serves rotary rigs too (their presets and ``kind = "rotary"`` files,
    :func:`stewart.cli.common.rig_params`)."""
    parser.set_defaults(serves_rotary=rotary)
    group = parser.add_mutually_exclusive_group()
    names = sorted(list_presets()) + (sorted(list_rotary_presets()) if rotary else [])
    group.add_argument("--preset", default=default, choices=names,
                       help="built-in parameter set" + (" (linear platforms, then rotary rigs)" if rotary else ""))
    group.add_argument("--params", metavar="FILE", help="parameter file, .toml or .json (instead of --preset)"
                       + ('; a rotary rig\'s holds kind = "rotary"' if rotary else ""))


_METAVARS = {
    "--pose": POSE_AXES, "--target": POSE_AXES, "--centre": POSE_AXES,
    "--lower": POSE_AXES, "--upper": POSE_AXES,
    "--vel": tuple(f"{p}'" for p in POSE_AXES), "--acc": tuple(f"{p}''" for p in POSE_AXES),
    "--velocity": tuple(f"{p}'" for p in POSE_AXES), "--acceleration": tuple(f"{p}''" for p in POSE_AXES),
    "--force": tuple(f"tau{i}" for i in range(6)),
}


def add_six(parser, flag: str, help_text: str) -> None:
    """A flag of six numbers: a pose, its rates or accelerations, or the six actuator forces."""
    parser.add_argument(flag, nargs=6, type=number, metavar=_METAVARS[flag], help=help_text)


def add_file(parser, flag: str, help_text: str, metavar: str = "FILE") -> None:
    """A file (or with ``metavar="DIR"`` a directory) to write."""
    parser.add_argument(flag, metavar=metavar, help=help_text)


def add_json(parser, help_text: str = "print only a JSON summary on stdout") -> None:
    """``--json``: the command's summary as JSON, alone on stdout."""
    parser.add_argument("--json", action="store_true", help=help_text)


def add_seed(parser, drawn: str) -> None:
    """``--seed`` of the random ``drawn`` (``"states"``, ``"poses"``, ...)."""
    parser.add_argument("--seed", type=int, default=0, help=f"seed of the random {drawn}")


def add_move_time(parser) -> None:
    """``--move-time``: the duration of the move to ``--target``."""
    parser.add_argument("--move-time", type=positive, default=5.0, help="duration of the move to --target [s]")


def add_profile(parser) -> None:
    """``--profile``: the velocity profile of the move to ``--target``."""
    parser.add_argument("--profile", choices=sorted(PROFILES), default="sinusoidal", help="velocity profile of the move")


def add_force_limit(parser, help_text: str = "largest actuator force per leg [N]") -> None:
    """``--force-limit``: a force bound on every leg [N], by default none (``inf``)."""
    parser.add_argument("--force-limit", type=limit, default=math.inf, help=help_text)


def add_max_iterations(parser, default: int, help_text: str) -> None:
    """``--max-iterations``: an optimizer's iteration budget."""
    parser.add_argument("--max-iterations", type=count, default=default, help=help_text)


def add_chunk_size(parser) -> None:
    """``--chunk-size`` of a chunked study (:mod:`stewart.studies.execution`)."""
    from ..studies import execution, workspace

    parser.add_argument("--chunk-size", type=count, help="states per chunk (per task on a cluster; default: "
                        f"{workspace.CHUNK_SIZE} poses for a workspace, {execution.DEFAULT_CHUNK_SIZE} states "
                        "for an envelope)")


def add_scheduler(parser) -> None:
    """``--scheduler``: run a study's chunks on a Dask cluster."""
    parser.add_argument("--scheduler", metavar="ADDRESS", help="run the chunks on the Dask cluster of this "
                        "scheduler (e.g. tcp://10.0.0.5:8786; needs pip install 'stewart[cluster]')")


def add_progress(parser) -> None:
    """``--progress``/``--no-progress``: the progress bar on stderr."""
    parser.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                        help="progress bar on stderr (default: when stderr is a terminal)")
