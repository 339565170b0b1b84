"""What the commands share beyond their flags: the exit codes, :class:`UserError` (a mistake
in the command line or its files), the parameter set of ``--preset``/``--params``, the checks
of output paths made before a run, and the table, progress and cluster helpers."""

from __future__ import annotations

import contextlib
import os
import sys

import numpy as np

from ..io import csvfile
from ..model import paramfile
from ..model.params import PlatformParams
from ..model.rotary_params import KIND as ROTARY, RotaryParams
from ..model.rotary_presets import presets as rotary_presets
from ..motion.simulation import OUTCOMES

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
       or unreachable poses), or a cueing reference passes the leg-speed or force limits,
       found before any run
  4    the run failed: the platform left its assembly mode or passed a singularity, hit a
       stroke limit, the state became non-finite or the solver used its step budget
  5    the run finished but the final tracking error is above --tolerance
  6    the commanded actuator force exceeded --force-limit, or a motor torque --torque-limit (saturated)
  130  interrupted (Ctrl-C); what was computed is saved
With several problems the lowest code >= 3 is returned; every problem is printed."""


class UserError(Exception):
    """A mistake in the command line or its files: one line on stderr and ``code``."""

    def __init__(self, message: str, code: int = EXIT_USAGE):
        super().__init__(message)
        self.code = code


def platform_params(args) -> tuple[PlatformParams, str]:
    """The linear platform's parameter set of ``--preset`` or ``--params`` and a label naming it;
    a rotary rig's file is refused (:func:`refuse_rotary`)."""
    refuse_rotary(args)
    return rig_params(args)


def refuse_rotary(args) -> None:
    """One line naming the command when ``--params`` holds a rotary rig (``kind = "rotary"``) and
    the command serves linear platforms only (its ``--params`` added without ``rotary``)."""
    path = getattr(args, "params", None)
    if path and os.path.isfile(path) and not getattr(args, "serves_rotary", False):
        try:
            rotary = paramfile.read(path).get("kind") == ROTARY
        except (ValueError, OSError, TypeError, RecursionError):
            return  # rig_params names what is wrong with the file
        if rotary:
            raise UserError(f"--params {path}: a rotary rig's parameter file (kind = \"{ROTARY}\"); "
                            f"stewart {args.command} serves linear platforms only")


def rotary_rig_params(args) -> tuple[RotaryParams, str]:
    """The rotary rig of ``--preset`` or ``--params`` (:func:`rig_params`) and its label; a
    linear platform's preset or file is refused in one line naming the command."""
    params, label = rig_params(args)
    if not isinstance(params, RotaryParams):
        given = f"--params {args.params}: a linear platform's parameter file" if args.params else \
            f"--preset {args.preset}: a linear platform"
        raise UserError(f"{given}; stewart {args.command} serves rotary rigs only")
    return params, label


def rig_params(args) -> tuple[PlatformParams | RotaryParams, str]:
    """The parameter set of ``--preset`` or ``--params`` and a label naming it: a
    :class:`RotaryParams` for a rotary preset or a file holding ``kind = "rotary"``, a
    :class:`PlatformParams` otherwise."""
    if not args.params:
        kind = RotaryParams if args.preset in rotary_presets() else PlatformParams
        return kind.preset(args.preset), f"{args.preset} (preset)"
    path = args.params
    if not os.path.exists(path):
        raise UserError(f"--params {path}: no such file")
    if os.path.isdir(path):
        raise UserError(f"--params {path}: is a directory, not a parameter file")
    try:
        kind = RotaryParams if paramfile.read(path).get("kind") == ROTARY else PlatformParams
        params = kind.load(path)
    except (ValueError, OSError, TypeError, RecursionError) as exc:
        message = str(exc)
        message = message[len("path: "):] if message.startswith("path: ") else message
        message = message[len(path) + 2:] if message.startswith(path + ": ") else message
        raise UserError(f"--params {path}: {message}") from None
    return params, f"{params.name or 'unnamed'} (from {path})"


def flag_names(message: str, names: dict[str, str]) -> str:
    """Rename the argument names leading ``message`` (``"dt, duration: ..."``) as flags."""
    head, sep, tail = message.partition(": ")
    parts = [p.strip() for p in head.split(",")]
    if sep and all(p in names for p in parts):
        message = ", ".join(names[p] for p in parts) + sep + tail
    return message.replace("max_steps=", names.get("max_steps", "max_steps") + " ")


# ---------------------------------------------------------------------------- checks before a run

def check_output(flag: str, path: str | None, directory: bool = False) -> None:
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


def check_outputs(args, *flags: str) -> None:
    """:func:`check_output` for each file flag of ``flags`` (``"--csv"``, ...)."""
    for flag in flags:
        check_output(flag, getattr(args, flag[2:]))


def check_parameter_file_name(flag: str, path: str | None) -> None:
    """A file to write parameters or a series to: its format is in its name (.toml or .json)."""
    if path and not path.lower().endswith((".toml", ".json")):
        raise UserError(f"{flag} {path}: give a .toml or .json file name")


def check_plotting(flag: str) -> None:
    """Fail unless matplotlib, which the figures of ``flag`` need, is installed."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UserError(f"{flag}: plotting needs matplotlib; install it with pip install 'stewart[plot]'") from None


# ---------------------------------------------------------------------------- runs and their output

def progress(args) -> bool:
    """``--progress``/``--no-progress``, or whether stderr is a terminal if neither was given."""
    return sys.stderr.isatty() if args.progress is None else args.progress


def chunking(args) -> dict:
    """``chunk_size`` for a study if ``--chunk-size`` was given (else the study's default)."""
    return {} if args.chunk_size is None else {"chunk_size": args.chunk_size}


@contextlib.contextmanager
def scheduler(address: str | None):
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


def read_csv(flag: str, path: str, columns: list[str]) -> np.ndarray:
    """The ``columns`` of the CSV file ``path`` given with ``flag``."""
    try:
        return csvfile.read(path, columns)
    except ValueError as exc:
        raise UserError(f"{flag} {exc}") from None


def print_table(label: str, header: list[str], rows: np.ndarray, csv_path: str | None) -> None:
    """``rows`` under ``header`` on stdout, or into the CSV file ``csv_path``."""
    if csv_path:
        csvfile.write(csv_path, header, rows, f"platform {label}")
        print(f"wrote {len(rows)} row(s) to {csv_path} (platform {label})")
        return
    print(f"# platform {label}")
    print("".join(f"{h:>18}" for h in header))
    for row in rows:
        print("".join(f"{v:>18.10g}" for v in row))


def print_written(files: list[str]) -> None:
    """One ``written:`` line per file."""
    for path in files:
        print(f"written: {path}")
