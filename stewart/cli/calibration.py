"""``stewart calibrate`` (a built machine's joint centres and leg length offsets from measured
poses or points) and ``stewart calibration-poses`` (the poses to measure)."""

from __future__ import annotations

import json
import sys

import numpy as np

from ..calibration import design, fit, validation
from ..calibration.identifiability import UnidentifiableError
from ..calibration.measurements import POSE_COLUMNS, CalibrationData
from ..model.errors import ConvergenceError
from ..model.reachability import WorkspaceError
from ..motion.simulation import OUTCOMES
from .common import (
    EXIT_WORKSPACE,
    UserError,
    check_output,
    check_outputs,
    check_parameter_file_name,
    check_plotting,
    flag_names,
    platform_params,
    print_written,
    progress,
)
from .options import UNITS, add_file, add_params, add_progress, add_seed, add_six, count, number, positive, subcommand

#: The user's flags for the arguments of :func:`stewart.calibration.calibrate` and of the design.
_FLAGS = {"position_std": "--pose-std", "angle_std": "--pose-std", "length_std": "--length-std",
          "target_offsets": "--target-offset", "count": "--count", "centre": "--centre",
          "translation": "--translation", "rotation": "--rotation", "seed": "--seed"}


def _data(flag: str, path: str, offsets) -> CalibrationData:
    if not path:
        raise UserError(f"{flag or 'MEAS.csv'}: the file name is empty; give the measurements")
    try:
        return CalibrationData.from_csv(path, offsets)
    except ValueError as exc:
        text = str(exc).replace("(target_offsets, --target-offset X Y Z)", "(--target-offset X Y Z)")
        raise UserError(f"{flag}{text}") from None


def cmd_calibrate(args) -> int:
    check_outputs(args, "--output", "--report")
    check_output("--plot", args.plot, directory=True)
    check_parameter_file_name("--output", args.output)
    if args.plot:
        check_plotting("--plot")
    nominal, label = platform_params(args)
    offsets = np.array(args.target_offset) if args.target_offset else None
    data = _data("", args.measurements, offsets)
    if offsets is not None and data.kind == "poses":
        raise UserError(f"--target-offset: {args.measurements} holds poses, not tracked points (px, py, pz); "
                        "leave --target-offset out")
    held = _data("--validate ", args.validate, offsets) if args.validate else None
    try:
        result = fit.calibrate(nominal, data, position_std=args.pose_std[0], angle_std=args.pose_std[1],
                               length_std=args.length_std)
    except WorkspaceError as exc:
        raise UserError(str(exc), EXIT_WORKSPACE) from None
    except UnidentifiableError as exc:
        raise UserError(str(exc)) from None
    except ConvergenceError as exc:
        raise UserError(str(exc), OUTCOMES["failed"]) from None
    except ValueError as exc:
        raise UserError(flag_names(str(exc), _FLAGS)) from None
    warning = result.stroke_warning()
    if warning:
        print(f"stewart calibrate: warning: {args.measurements}: {warning}", file=sys.stderr)
    print(f"# platform {label}: calibrated from {args.measurements} ({len(data.readings)} {data.kind} "
          f"measurement(s), {len(data.pose_index()[0])} pose(s))")
    print(result.table())
    print(f"condition number {result.identifiability.condition:.4g}; residual scale s = {result.sigma:.3g} "
          f"(1 when --pose-std and --length-std are right) on {result.dof} degrees of freedom")
    print(f"RMS residual [um] {'':<8}" + "".join(f"{name:>9}" for name in result.residual_names))
    for what, rms in (("nominal", result.rms_before), ("calibrated", result.rms_after)):
        print(f"{what:<25}" + "".join(f"{1e6 * v:>9.3g}" for v in rms))
    summary = {"command": "calibrate", "platform_source": label, "measurements": args.measurements,
               **result.summary()}
    held_out = None
    if held is not None:
        try:
            held_out = {"nominal": validation.pose_errors(nominal, held),
                        "calibrated": validation.pose_errors(result.params, held)}
        except ValueError as exc:
            raise UserError(f"--validate {exc}") from None
        summary["validation"] = {"file": args.validate, **{
            f"{geometry}_rms_{kind}": float(np.sqrt(np.mean(errors[kind] ** 2)))
            for geometry, errors in held_out.items() for kind in errors}}
        for kind in held_out["nominal"]:
            unit = "um" if kind == "position" else "urad"
            rms = [1e6 * np.sqrt(np.mean(held_out[g][kind] ** 2)) for g in ("nominal", "calibrated")]
            print(f"held-out {args.validate}: RMS {kind} error of forward kinematics {rms[0]:.4g} {unit} with the "
                  f"nominal geometry, {rms[1]:.4g} {unit} calibrated")
    files = []
    if args.output:
        result.params.save(args.output)
        files.append(args.output)
    if args.report:
        with open(args.report, "w", encoding="utf-8") as handle:
            json.dump(summary, handle, indent=2)
        files.append(args.report)
    if args.plot:
        from ..calibration.figures import plot_calibration

        files += plot_calibration(result, args.plot, held_out)
    print_written(files)
    return 0


def add_calibrate(sub) -> None:
    p = subcommand(sub, "calibrate", "calibrate a built platform's geometry (its base and platform joint centres "
                   "and leg length offsets, the 42 parameters) from poses (CSV: x,y,z,psi,theta,phi,L0..L5) or "
                   "tracked points (px,py,pz,L0..L5[,target]) measured in the base frame with the encoder "
                   "readings; the parameters given are the nominal", cmd_calibrate)
    p.add_argument("measurements", metavar="MEAS.csv", help="the measurements to calibrate from")
    add_params(p)
    p.add_argument("--pose-std", nargs=2, type=positive, metavar=("M", "RAD"),
                   default=[fit.DEFAULT_POSITION_STD, fit.DEFAULT_ANGLE_STD],
                   help="standard deviation of each measured position coordinate [m] and angle [rad]")
    p.add_argument("--length-std", type=positive, metavar="M", default=fit.DEFAULT_LENGTH_STD,
                   help="standard deviation of an encoder reading [m]")
    p.add_argument("--target-offset", nargs=3, type=number, action="append", metavar=("X", "Y", "Z"),
                   help="a tracked target's position in the platform frame [m] (point data; repeat it for "
                        "several targets, numbered 0, 1, ... in the target column)")
    p.add_argument("--validate", metavar="FILE", help="held-out measurements: print the pose error of forward "
                   "kinematics from their encoder readings with the nominal and the calibrated geometry")
    add_file(p, "--output", "write the calibrated parameters (.toml or .json), loadable with --params")
    add_file(p, "--report", "write every parameter's estimate and standard error, the residuals and the legs "
             "past the stroke with the calibrated geometry (JSON)")
    add_file(p, "--plot", "write PNG figures: residuals per leg, estimates with error bars, held-out errors",
             metavar="DIR")


def cmd_calibration_poses(args) -> int:
    check_outputs(args, "--csv")
    params, label = platform_params(args)
    try:
        result = design.design_poses(params, args.count, centre=args.centre, translation=args.translation,
                                     rotation=args.rotation, seed=args.seed, progress=progress(args))
        if args.csv:
            result.to_csv(args.csv, f"calibration poses for platform {label} (encoder readings of the nominal)")
    except ValueError as exc:
        raise UserError(flag_names(str(exc), _FLAGS)) from None
    print(f"platform {label}: {args.count} calibration poses chosen for D-optimality (O1) among random reachable "
          "candidates")
    print(f"{'':<22}{'O1':>12}{'condition':>12}{'O4':>12}")
    for what, index in (("designed", result.designed), (f"{args.count} random poses", result.random)):
        print(f"{what:<22}{index['O1']:>12.4g}{index['condition']:>12.4g}{index['O4']:>12.4g}")
    if not args.csv:
        print(",".join(POSE_COLUMNS))
        for pose, reading in zip(result.poses, result.readings):
            print(",".join(f"{v:.12g}" for v in np.concatenate([pose, reading])))
    print_written([args.csv] if args.csv else [])
    return 0


def add_calibration_poses(sub) -> None:
    p = subcommand(sub, "calibration-poses", "choose poses to measure for calibration: reachable poses that "
                   "maximize the observability index O1 (D-optimal) of the 42 geometric parameters",
                   cmd_calibration_poses)
    add_params(p)
    p.add_argument("--count", type=count, required=True, help="number of poses (at least 7)")
    add_six(p, "--centre", f"pose the candidates are drawn around (default: home) [{UNITS}]")
    p.add_argument("--translation", type=positive, metavar="M", help="half-width of the candidates' positions "
                   f"(default: {design.DEFAULT_TRANSLATION:g} of the home height) [m]")
    p.add_argument("--rotation", type=positive, metavar="RAD", default=design.DEFAULT_ROTATION,
                   help="half-width of the candidates' angles [rad]")
    add_seed(p, "candidates")
    add_file(p, "--csv", "write the poses with the nominal encoder readings (the layout stewart calibrate reads)")
    add_progress(p)
