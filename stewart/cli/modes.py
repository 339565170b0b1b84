"""``stewart modes``: the natural frequencies, dominant motions and damping ratios of the
platform on preloaded leg springs at one pose (:meth:`stewart.Platform.modes`)."""

from __future__ import annotations

import json

import numpy as np

from ..model.errors import SingularityError, UnstableError
from ..model.platform import Platform
from ..model.reachability import reachability
from ..model.stiffness import MOTION_AXES
from .common import EXIT_WORKSPACE, UserError, flag_names, platform_params
from .options import AXES, UNITS, add_json, add_params, add_six, non_negative, positive, subcommand

#: The flags of the arguments of :meth:`stewart.Platform.modes`, for its messages.
FLAGS = {"x": "--pose", "stiffness": "--stiffness", "damping": "--damping"}


def _per_leg(flag: str, values):
    """One value or six from the command line; a usage error otherwise."""
    if values is None or len(values) in (1, 6):
        return values
    raise UserError(f"{flag}: give one value or six (one per leg), got {len(values)}")


def _legs(values: list) -> str:
    """Six per-leg values for the table's header: one number when they are all equal."""
    return f"{values[0]:g}" if len(set(values)) == 1 else " ".join(f"{v:g}" for v in values)


def cmd_modes(args) -> int:
    params, label = platform_params(args)
    plat = Platform(params)
    stiffness = _per_leg("--stiffness", args.stiffness)
    damping = _per_leg("--damping", args.damping)
    pose = plat.home_pose if args.pose is None else np.array(args.pose)
    check = reachability(plat, pose, name="--pose")
    if not np.all(check.ok):
        raise UserError(f"--pose: {check.message('pose')}", EXIT_WORKSPACE)
    try:
        modes = plat.modes(pose, stiffness, damping)
    except (SingularityError, UnstableError) as exc:
        raise UserError(f"--pose: {str(exc).removeprefix('modes: ')}", EXIT_WORKSPACE) from None
    except ValueError as exc:
        raise UserError(flag_names(str(exc), FLAGS)) from None
    motions, share = modes.motions(), modes.participation()
    stiffness = (plat.params.leg_stiffness if stiffness is None else np.broadcast_to(stiffness, (6,))).tolist()
    damping = None if modes.damping_ratios is None else (
        plat.params.leg_damping if damping is None else np.broadcast_to(damping, (6,))).tolist()
    if args.json:
        print(json.dumps({
            "platform": label, "pose": pose.tolist(), "stiffness": stiffness, "damping": damping,
            "frequencies": modes.frequencies.tolist(), "motions": motions,
            "participation": {axis: share[i].tolist() for i, axis in enumerate(MOTION_AXES)},
            "damping_ratios": None if modes.damping_ratios is None else modes.damping_ratios.tolist(),
        }))
        return 0
    print(f"# {label}; pose {' '.join(f'{v:g}' for v in pose)}; leg stiffness {_legs(stiffness)} N/m"
          + ("" if damping is None else f"; leg damping {_legs(damping)} N s/m"))
    print(f"{'mode':>4}  {'frequency [Hz]':>14}  {'damping ratio':>13}  dominant motion")
    for j in range(6):
        ratio = "-" if modes.damping_ratios is None else f"{modes.damping_ratios[j]:.4f}"
        print(f"{j + 1:>4}  {modes.frequencies[j]:>14.4f}  {ratio:>13}  {motions[j]} "
              f"({100 * share[MOTION_AXES.index(motions[j]), j]:.0f} %)")
    return 0


def add_modes(sub) -> None:
    p = subcommand(sub, "modes", "natural frequencies and mode shapes on preloaded leg springs", cmd_modes)
    add_params(p)
    add_six(p, "--pose", f"{AXES} [{UNITS}] (default: home)")
    p.add_argument("--stiffness", nargs="+", type=positive, metavar="K",
                   help="leg stiffness [N/m]: one value, or six (one per leg) (default: the parameters' "
                        "leg_stiffness)")
    p.add_argument("--damping", nargs="+", type=non_negative, metavar="C",
                   help="leg damping [N s/m]: one value, or six; adds the damping ratios (default: the "
                        "parameters' leg_damping, if any)")
    add_json(p)
