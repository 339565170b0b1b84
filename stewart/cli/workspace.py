"""``stewart workspace``: the reachable workspace's volume, bounding box and singularity
margin, and its slices through home as heat maps, of a linear platform or a rotary rig; and
for a rotary rig the arms study (``--arms``: the roll and pitch it reaches with its arms
outwards and inwards)."""

from __future__ import annotations

import itertools
import json
import os

import numpy as np

from ..io import csvfile
from ..model.kinematics import POSE_AXES, POSE_UNITS
from ..model.rotary_params import RotaryParams
from .common import (
    EXIT_WORKSPACE,
    UserError,
    check_output,
    check_plotting,
    chunking,
    flag_names,
    print_written,
    progress,
    rig_params,
    scheduler,
)
from .options import add_chunk_size, add_file, add_json, add_params, add_progress, add_scheduler, add_seed, count, \
    number, positive, subcommand

#: The user's flags for the arguments of the workspace functions and the parameters they override.
_WORKSPACE_FLAGS = {"region": "--region", "orientation": "--orientation", "position": "--position",
                    "samples": "--samples", "grid": "--grid", "seed": "--seed", "chunk_size": "--chunk-size",
                    "resolution": "--resolution", "universal_joint_max_angle": "--universal-max-angle",
                    "spherical_joint_max_angle": "--spherical-max-angle", "leg_diameter": "--leg-diameter",
                    "plate_radius": "--plate-radius", "base_clearance": "--base-clearance", "stiffness": "--stiffness",
                    "crank_joint_max_angle": "--crank-joint-max-angle",
                    "platform_joint_max_angle": "--platform-joint-max-angle", "crank_angle_limits": "--crank-limits",
                    "rod_crank_angle_limits": "--rod-crank-limits", "crank_pin_max_tilt": "--crank-pin-max-tilt"}

#: The parameters the bound flags give in degrees, stored in radians.
_ANGLES = ("universal_joint_max_angle", "spherical_joint_max_angle", "crank_joint_max_angle", "platform_joint_max_angle",
           "crank_angle_limits", "rod_crank_angle_limits", "crank_pin_max_tilt")

#: The flags of one family's bounds: a linear platform's, a rotary rig's.
_LINEAR_FLAGS = ("--universal-max-angle", "--spherical-max-angle", "--leg-diameter", "--plate-radius", "--stiffness")
_ROTARY_FLAGS = ("--crank-joint-max-angle", "--platform-joint-max-angle", "--crank-limits", "--rod-crank-limits",
                 "--crank-pin-max-tilt", "--arms", "--arms-height")


def _bounds(args, rotary: bool) -> dict:
    """The parameters the bound flags override (radians from degrees), after refusing in one line
    a flag of the other family."""
    given = lambda flag: getattr(args, flag[2:].replace("-", "_")) not in (None, False)  # noqa: E731
    for flag in _ROTARY_FLAGS if not rotary else _LINEAR_FLAGS:
        if given(flag):
            raise UserError(f"{flag}: bounds a {'linear platform' if rotary else 'rotary rig'}; the parameters are "
                            f"a {'rotary rig' if rotary else 'linear platform'}'s (its bounds: "
                            f"{', '.join(_ROTARY_FLAGS[:4] if rotary else _LINEAR_FLAGS[:4])}, --base-clearance)")
    cones = ("--crank-joint-max-angle", "--platform-joint-max-angle", "--crank-pin-max-tilt") if rotary else \
        ("--universal-max-angle", "--spherical-max-angle")
    for flag in cones:
        value = getattr(args, flag[2:].replace("-", "_"))
        if value is not None and value > 90.0:
            raise UserError(f"{flag}: {'a tilt' if flag == '--crank-pin-max-tilt' else 'a cone half-angle'} needs "
                            f"0 < DEG <= 90, got {value:g}")
    if rotary:
        bounds = {"crank_joint_max_angle": args.crank_joint_max_angle,
                  "platform_joint_max_angle": args.platform_joint_max_angle,
                  "crank_angle_limits": args.crank_limits, "rod_crank_angle_limits": args.rod_crank_limits,
                  "crank_pin_max_tilt": args.crank_pin_max_tilt}
    else:
        bounds = {"universal_joint_max_angle": args.universal_max_angle,
                  "spherical_joint_max_angle": args.spherical_max_angle, "leg_diameter": args.leg_diameter,
                  "plate_radius": args.plate_radius}
    bounds["base_clearance"] = args.base_clearance
    return {key: (np.radians(v).tolist() if key in _ANGLES else v)
            for key, v in bounds.items() if v is not None}

#: The slices drawn by ``stewart workspace --slices``: the three coordinate planes through home.
_SLICES = {"translational": tuple("".join(pair) for pair in itertools.combinations(POSE_AXES[:3], 2)),
           "orientation": tuple(",".join(pair) for pair in itertools.combinations(POSE_AXES[3:], 2))}


def cmd_workspace(args) -> int:
    from ..studies import workspace

    check_output("--csv", args.csv)
    check_output("--slices", args.slices, directory=True)
    if args.slices:
        check_plotting("--slices")
    if args.kind == "orientation" and args.orientation is not None:
        raise UserError("--orientation: holds the orientation of a translational workspace; "
                        "with --kind orientation give --position")
    if args.kind == "translational" and args.position is not None:
        raise UserError("--position: holds the position of an orientation workspace; "
                        "with --kind translational give --orientation")
    params, label = rig_params(args)
    rotary = isinstance(params, RotaryParams)
    bounds = _bounds(args, rotary)
    if args.arms:
        return _arms(args, params.replace(**bounds) if bounds else params, label)
    if args.arms_height is not None:
        raise UserError("--arms-height: holds the platform of the arms study; give it with --arms")
    region = None if args.region is None else np.reshape(args.region, (3, 2))
    fixed = ({"orientation": args.orientation or (0.0, 0.0, 0.0)} if args.kind == "translational"
             else {"position": args.position})
    try:
        params = params.replace(**bounds)
        study = workspace.translational_workspace if args.kind == "translational" else workspace.orientation_workspace
        with scheduler(args.scheduler) as client:
            result = study(params, **fixed, region=region, samples=None if args.grid else args.samples,
                           grid=args.grid, seed=args.seed, client=client, progress=progress(args),
                           stiffness=args.stiffness, **chunking(args))
        slices = [workspace.workspace_slice(params, axes, **fixed, region=_zoom(result, axes),
                                            resolution=args.resolution, stiffness=args.stiffness)
                  for axes in _SLICES[args.kind]] if args.slices else []
    except ValueError as exc:
        raise UserError(flag_names(str(exc), _WORKSPACE_FLAGS)) from None
    files = []
    if slices:
        from ..io.plots import plot_workspace_slices

        os.makedirs(args.slices, exist_ok=True)
        title = f"{params.name or 'unnamed'}: {args.kind} workspace slices through home"
        files.append(plot_workspace_slices(slices, os.path.join(args.slices, f"workspace_{args.kind}.png"), title))
        if args.stiffness is not None:
            files.append(plot_workspace_slices(slices, os.path.join(args.slices, f"frequency_{args.kind}.png"),
                                               title, quantity="frequency"))
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
        _workspace_report(result, label, files, _limits(params), "J_alpha" if rotary else "J_C")
    if not result.reachable:
        excluded = ", ".join(f"{name} {n}" for name, n in result.excluded.items())
        raise UserError(f"no sampled pose is reachable ({result.samples} samples; excluded: {excluded})",
                        EXIT_WORKSPACE)
    return code


def _limits(params) -> str:
    """The limits in force of ``params``, in words (its family's ``limits_in_force``)."""
    from ..model import reachability, rotary_reachability

    family = rotary_reachability if isinstance(params, RotaryParams) else reachability
    return family.limits_in_force(params)


def _arms(args, params, label) -> int:
    """``--arms``: the roll and pitch ranges of the rig with its arms outwards and inwards, the
    figure of their pitch-roll slices into ``--slices DIR``."""
    from ..studies.rotary_arms import arms_study

    if args.kind != "translational" or args.orientation or args.position or args.region or args.grid \
            or args.csv:
        raise UserError("--arms: studies roll and pitch about home on its own; leave out --kind, --orientation, "
                        "--position, --region, --grid and --csv")
    from ..model.rotary import RotaryPlatform

    height = float(RotaryPlatform(params).home[2]) if args.arms_height is None else args.arms_height
    try:
        studies = {"same_height": arms_study(params, height=height, resolution=args.resolution),
                   "own_home": arms_study(params, resolution=args.resolution)}
    except ValueError as exc:
        raise UserError(flag_names(str(exc), {"height": "--arms-height", "limit": "--arms",
                                              "resolution": "--resolution"})) from None
    files = []
    if args.slices:
        os.makedirs(args.slices, exist_ok=True)
        files += [study.plot(os.path.join(args.slices, f"arms_{case}.png")) for case, study in studies.items()]
    if args.json:
        print(json.dumps({"command": "workspace", "platform_source": label,
                          **{case: study.summary() for case, study in studies.items()}, "files": files}))
        return 0
    print(f"platform {label}: roll and pitch reachable, each alone, arms outwards and inwards")
    print(f"limits: {studies['own_home'].limits}")
    for case, study in studies.items():
        held = f"both at z = {height:.4g} m" + (" (the rig's home)" if args.arms_height is None else "")
        print(f"{held if case == 'same_height' else 'each at its own home, cranks at zero'}:")
        print(f"  {'arms':<10}{'z [m]':>8}{'roll [deg]':>22}{'pitch [deg]':>22}")
        for way in study.ways:
            if study.roll[way] is None:
                print(f"  {way:<10}{study.start[way][2]:>8.4f}  cannot stand there: {'; '.join(study.reasons[way])}")
                continue
            roll, pitch = (np.degrees(getattr(study, axis)[way]) for axis in ("roll", "pitch"))
            print(f"  {way:<10}{study.start[way][2]:>8.4f}{f'{roll[0]:+.3f} .. {roll[1]:+.3f}':>22}"
                  f"{f'{pitch[0]:+.3f} .. {pitch[1]:+.3f}':>22}")
    print_written(files)
    return 0


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


def _workspace_report(result, label: str, files: list[str], limits: str, jacobian: str) -> None:
    unit = result.unit
    axes = ", ".join(result.axes)
    held = "orientation" if result.kind == "translational" else "position"
    print(f"platform {label}: {result.kind} workspace ({axes}) at {held} "
          f"{' '.join(f'{v:.6g}' for v in result.fixed)}")
    print(f"limits: {limits}")
    print(f"{result.method}: {result.reachable} of {result.samples} poses reachable"
          + (f" (seed {result.seed})" if result.seed is not None else ""))
    print(f"volume {result.volume:.6g} +- {result.volume_error:.2g} {unit}^3")
    if result.bounding_box is not None:
        for name, (lo, hi) in zip(result.axes, result.bounding_box):
            print(f"  {name:<6} {lo:+.5g} .. {hi:+.5g} {unit}")
        print(f"singularity margin (1/cond {jacobian}): min {result.margin_min:.3g}, mean {result.margin_mean:.3g}, "
              f"max {result.margin_max:.3g}")
    if result.stiffness is not None:
        print(f"on legs of {' '.join(f'{k:g}' for k in np.unique(result.stiffness))} N/m: lowest natural frequency "
              f"{result.frequency_min:.4g} Hz, largest compliance {result.compliance_max:.3g} m/N"
              + (f"; {result.unheld} reachable poses the legs cannot hold" if result.unheld else ""))
    if result.clipped:
        print(f"warning: the workspace reaches the --region faces on {', '.join(result.clipped)}; widen --region")
    if result.excluded:
        print("excluded: " + ", ".join(f"{name} {n}" for name, n in result.excluded.items()))
    print_written(files)


def add_workspace(sub) -> None:
    p = subcommand(sub, "workspace", "the reachable workspace: volume with its error, bounding box, singularity "
                   "margin, and slices as heat maps (linear platforms and rotary rigs)", cmd_workspace)
    add_params(p, rotary=True)
    p.add_argument("--kind", choices=["translational", "orientation"], default="translational",
                   help="positions at a constant orientation, or orientations at a position")
    position, orientation = POSE_AXES[:3], POSE_AXES[3:]
    p.add_argument("--orientation", nargs=3, type=number, metavar=tuple(a.upper() for a in orientation),
                   help=f"orientation held by a translational workspace [{POSE_UNITS[3]}] (default 0 0 0)")
    p.add_argument("--position", nargs=3, type=number, metavar=tuple(a.upper() for a in position),
                   help=f"position held by an orientation workspace [{POSE_UNITS[0]}] (default: home)")
    samples = p.add_mutually_exclusive_group()
    samples.add_argument("--samples", type=count, default=100_000, help="uniform random poses (Monte Carlo)")
    samples.add_argument("--grid", type=count, help="grid points per axis instead of random samples")
    add_seed(p, "poses")
    p.add_argument("--region", nargs=6, type=number, metavar=("LO1", "HI1", "LO2", "HI2", "LO3", "HI3"),
                   help=f"box to sample [{' or '.join(dict.fromkeys(POSE_UNITS))}] (default: one that holds the "
                        "whole workspace)")
    p.add_argument("--universal-max-angle", type=positive, metavar="DEG",
                   help="universal-joint cone half-angle [deg] (overrides the parameters')")
    p.add_argument("--spherical-max-angle", type=positive, metavar="DEG",
                   help="spherical-joint cone half-angle [deg] (overrides the parameters')")
    p.add_argument("--leg-diameter", type=positive, metavar="M", help="leg diameter for the leg-leg clearance [m] "
                   "(overrides the parameters')")
    p.add_argument("--plate-radius", type=positive, metavar="M", help="radius of the platform's plate, kept above "
                   "the base and clear of the legs [m] (overrides the parameters')")
    p.add_argument("--base-clearance", type=positive, metavar="M", help="smallest gap between the platform and the "
                   "base plane [m] (overrides the parameters')")
    p.add_argument("--crank-joint-max-angle", type=positive, metavar="DEG",
                   help="rotary rigs: cone half-angle of the ball joints at the crank tips [deg] (overrides the "
                        "parameters')")
    p.add_argument("--platform-joint-max-angle", type=positive, metavar="DEG",
                   help="rotary rigs: cone half-angle of the ball joints on the platform [deg] (overrides the "
                        "parameters')")
    p.add_argument("--crank-limits", nargs=2, type=number, metavar=("MIN", "MAX"),
                   help="rotary rigs: crank angle limits [deg] (overrides the parameters')")
    p.add_argument("--rod-crank-limits", nargs=2, type=number, metavar=("MIN", "MAX"),
                   help="rotary rigs: limits of the angle between rod and crank at the crank tip [deg], 0 folded "
                        "over the crank, 180 stretched straight out (overrides the parameters')")
    p.add_argument("--crank-pin-max-tilt", type=positive, metavar="DEG",
                   help="rotary rigs: largest tilt of a rod out of its crank's plane of motion, the misalignment of "
                        "a rod end on a pin parallel to the motor axis [deg] (overrides the parameters')")
    p.add_argument("--arms", action="store_true",
                   help="rotary rigs: instead of the workspace, the roll and pitch reachable with the arms outwards "
                        "and inwards, both at the platform height of the rig's home and each at its own home (with "
                        "--slices DIR, their figures arms_same_height.png and arms_own_home.png)")
    p.add_argument("--arms-height", type=number, metavar="M", help="with --arms: the platform height both ways are "
                   "held at [m] (default: the rig's home height)")
    add_chunk_size(p)
    add_scheduler(p)
    add_file(p, "--slices", "write PNG heat maps of the margin on the three coordinate planes through home, around "
             "the reachable samples, into DIR (needs matplotlib)", metavar="DIR")
    p.add_argument("--resolution", type=count, default=121, help="cells per axis of each slice")
    p.add_argument("--stiffness", nargs="+", type=positive, metavar="K",
                   help="leg stiffness [N/m], one value or six: adds the lowest natural frequency and the largest "
                        "compliance on the preloaded legs (and, with --slices, heat maps of the frequency)")
    add_progress(p)
    add_file(p, "--csv", "write the summary's numbers as a one-row CSV file")
    add_json(p)
