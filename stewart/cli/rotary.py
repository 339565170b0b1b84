"""The commands of rotary rigs only (issue 40, "What a rig builder gets"): ``motor-sizing`` (the
motors' torques and speeds along a motion reference against their limits), ``servo-angles``
(the crank angles in degrees for a servo controller) and ``fk`` (the pose from the encoders'
crank angles)."""

from __future__ import annotations

import sys

import numpy as np

from ..io import csvfile
from ..model.errors import ConvergenceError
from ..model.kinematics import POSE_AXES
from .common import (
    EXIT_WORKSPACE,
    UserError,
    check_output,
    check_plotting,
    print_table,
    print_written,
    read_csv,
    rotary_rig_params,
)
from .options import AXES, UNITS, add_file, add_params, number, positive, subcommand

#: The columns of a servo controller's file: time and the six crank angles [deg].
ANGLE_COLUMNS = [f"alpha_{i}" for i in range(6)]
SERVO_COLUMNS = ["t", *ANGLE_COLUMNS]

#: How each layout of a reference file (:data:`stewart.studies.motor_sizing.LAYOUTS`) gives the states.
LAYOUT_WORDS = {"reference": "poses, rates and accelerations given",
                "poses and rates": "poses and rates given, accelerations of their spline",
                "poses": "poses given, rates and accelerations of their spline, at rest at both ends",
                "states": "states without times"}

_REFERENCE_HELP = ("a motion reference CSV: a cueing reference (stewart cueing --output: t, pose, rates, "
                   "accelerations), t, pose and rates, t and pose (the spline through the poses gives rates and "
                   "accelerations, at rest at both ends, as stewart simulate plays it), or the 18 columns of "
                   "stewart id --input; picked by a header's names, or without a header by the number of columns "
                   "(19, 13, 7, 18)")


def _reference(path: str):
    from ..studies.motor_sizing import read_reference

    try:
        return read_reference(path)
    except ValueError as exc:
        message = str(exc)
        raise UserError(message if message.startswith(path) else f"{path}: {message}") from None


# ---------------------------------------------------------------------------- motor-sizing

def cmd_motor_sizing(args) -> int:
    from ..model.rotary import RotaryPlatform
    from ..studies.motor_sizing import motor_sizing

    params, label = rotary_rig_params(args)
    check_output("--report", args.report)
    check_output("--plot", args.plot, directory=True)
    if args.plot:
        check_plotting("--plot")
    ref = _reference(args.reference)
    try:
        result = motor_sizing(RotaryPlatform(params), ref.x, ref.xd, ref.xdd, t=ref.t, gear_ratio=args.gear_ratio)
    except ValueError as exc:  # no pose in reach
        raise UserError(f"{args.reference}: {str(exc).removeprefix('x: ')}", EXIT_WORKSPACE) from None
    m, n = result.motors, result.gear_ratio
    span = "" if ref.t is None else f" over {ref.t[-1] - ref.t[0]:.6g} s"
    print(f"# rig {label}: {result.samples:,} samples{span} ({LAYOUT_WORDS[ref.layout]}), figures at the crank")
    print(f"{'motor':>5}{'peak torque [N m]':>19}{'sample':>9}{'RMS torque [N m]':>18}{'peak speed [rad/s]':>20}"
          f"{'sample':>9}{'peak power [W]':>16}{'crank angles [deg]':>22}")
    for k in range(6):
        angles = f"{np.degrees(m['angle_min'][k]):.4g} to {np.degrees(m['angle_max'][k]):.4g}"
        print(f"{k:>5}{m['peak_torque'][k]:>19.6g}{m['peak_torque_sample'][k]:>9}{m['rms_torque'][k]:>18.6g}"
              f"{m['peak_speed'][k]:>20.6g}{m['peak_speed_sample'][k]:>9}{m['peak_power'][k]:>16.6g}{angles:>22}")
    if n != 1.0:
        print(f"# at the motor, gear ratio {n:g} (torque / {n:g}, speed x {n:g})")
        print(f"{'motor':>5}{'peak torque [N m]':>19}{'RMS torque [N m]':>18}{'peak speed [rad/s]':>20}"
              f"{'peak speed [rpm]':>18}")
        for k in range(6):
            print(f"{k:>5}{m['peak_torque'][k] / n:>19.6g}{m['rms_torque'][k] / n:>18.6g}"
                  f"{m['peak_speed'][k] * n:>20.6g}{m['peak_speed'][k] * n * 30 / np.pi:>18.6g}")
    _print_headroom(params, m)
    if args.report:
        result.to_json(args.report)
        print_written([args.report])
    if args.plot:
        print_written(result.plot(args.plot))
    for problem in result.problems:
        print(f"stewart motor-sizing: {problem}", file=sys.stderr)
    return EXIT_WORKSPACE if result.problems else 0


def _print_headroom(params, m) -> None:
    """The headroom table: the fraction of each limit left (negative: passed), and the crank
    angles' distance to the nearer limit."""
    columns = []
    if params.motor_torque_limit is not None:
        columns.append(("torque", "torque_headroom", "%"))
    if params.motor_speed_limit is not None:
        columns.append(("speed", "speed_headroom", "%"))
    if params.crank_angle_limits is not None:
        columns.append(("crank angle", "angle_headroom", "deg"))
    if not columns:
        print("# headroom: the rig's parameters set no motor or crank limits")
        return
    print("# headroom: the part of each limit left (negative: passed), the crank angles' distance to the nearer "
          "limit")
    print(f"{'motor':>5}" + "".join(f"{f'{name} [{unit}]':>20}" for name, _, unit in columns))
    for k in range(6):
        cells = []
        for _, key, unit in columns:
            value = m[key][k] * 100.0 if unit == "%" else np.degrees(m[key][k])
            cells.append(f"{value:>20.4g}")
        print(f"{k:>5}" + "".join(cells))


def add_motor_sizing(sub) -> None:
    p = subcommand(sub, "motor-sizing", "size a rotary rig's motors on a motion reference: per motor the peak "
                   "and RMS torque, the peak speed and power, the crank angles' range, the sample of each peak and "
                   "the headroom against motor_torque_limit, motor_speed_limit and crank_angle_limits (at the "
                   "crank; --gear-ratio adds torque and speed at the motor); exit 3 when a motor passes a limit, a "
                   "crank its angle limits or a pose is out of the cranks' reach (each named on stderr, after the "
                   "tables, the report and the plot are written). Rotary rigs only", cmd_motor_sizing)
    p.add_argument("reference", metavar="TRAJ.csv", help=_REFERENCE_HELP)
    add_params(p, rotary=True, default="simrig100")
    p.add_argument("--gear-ratio", type=positive, default=1.0, metavar="N",
                   help="gearbox ratio from motor to crank: the report adds torque / N and speed x N at the motor "
                        "(the limits and crank_inertia stay the crank's)")
    add_file(p, "--report", "write the per-motor figures, their units, samples and headroom as JSON",
             metavar="REPORT.json")
    add_file(p, "--plot", "write motor_sizing_torque_speed.png into this directory: the torque-speed points of "
             "each motor against its limits", metavar="DIR")


# ---------------------------------------------------------------------------- servo-angles

def cmd_servo_angles(args) -> int:
    from ..model.rotary import RotaryPlatform
    from ..motion.trajectory import SampledTrajectory

    params, label = rotary_rig_params(args)
    check_output("--output", args.output)
    ref = _reference(args.reference)
    if ref.t is None:
        raise UserError(f"{args.reference}: has no times (a t column); a servo controller's file needs them")
    t, x = ref.t, ref.x
    if args.rate is not None:
        if len(t) < 2:
            raise UserError(f"--rate {args.rate:g}: {args.reference} has one sample; nothing to resample")
        count = int(np.floor((t[-1] - t[0]) * args.rate * (1 + 1e-12))) + 1
        if count > 100_000_000:
            raise UserError(f"--rate {args.rate:g}: {count:,} samples; give a lower rate")
        spline = SampledTrajectory(ref.t, ref.x, None if ref.layout == "poses" else ref.xd)
        t = t[0] + np.arange(count) / args.rate
        x = spline.sample(t)[0]
    rig = RotaryPlatform(params)
    angles, ok = rig.crank_angles(x, return_mask=True)
    angles = np.atleast_2d(angles)
    bad = np.flatnonzero(~np.atleast_1d(ok))
    if bad.size:
        raise UserError(f"{args.reference}: {bad.size} pose(s) out of the cranks' reach at t = "
                        f"{', '.join(f'{v:.6g}' for v in t[bad[:5]])} s{' ...' if bad.size > 5 else ''}; "
                        "nothing written", EXIT_WORKSPACE)
    if params.crank_angle_limits is not None:
        lo, hi = params.crank_angle_limits
        outside = (angles < lo) | (angles > hi)
        if outside.any():
            row, crank = np.argwhere(outside)[0]
            raise UserError(f"{args.reference}: crank {crank} at {np.degrees(angles[row, crank]):.4g} deg (t = "
                            f"{t[row]:.6g} s) passes crank_angle_limits ({np.degrees(lo):.4g}, {np.degrees(hi):.4g}) "
                            f"deg at {np.count_nonzero(outside.any(axis=1))} sample(s); nothing written",
                            EXIT_WORKSPACE)
    rate = f"{args.rate:g} Hz" if args.rate is not None else "the reference's samples"
    csvfile.write(args.output, SERVO_COLUMNS, np.column_stack([t, np.degrees(angles)]),
                  f"rig {label}: crank angles [deg] at {rate}, from {args.reference}")
    print(f"wrote {len(t)} row(s) of t [s], {', '.join(ANGLE_COLUMNS)} [deg] to {args.output} (rig {label})")
    return 0


def add_servo_angles(sub) -> None:
    p = subcommand(sub, "servo-angles", "crank angles in degrees for a servo controller: a CSV of "
                   f"{','.join(SERVO_COLUMNS)} (t [s], angles [deg] about each motor axis from crank_zero) along a "
                   "motion reference, at its samples or resampled at --rate; a pose out of reach or an angle past "
                   "crank_angle_limits exits 3 and writes nothing. Rotary rigs only", cmd_servo_angles)
    p.add_argument("reference", metavar="TRAJ.csv", help=_REFERENCE_HELP.replace(", or the 18 columns of stewart id "
                                                                                 "--input", "").replace(", 18)", ")"))
    add_params(p, rotary=True, default="simrig100")
    p.add_argument("--rate", type=positive, metavar="HZ", help="resample the reference at this rate, from its first "
                   "time, through its spline (default: the reference's own samples)")
    p.add_argument("--output", required=True, metavar="FILE", help="the CSV file to write")


# ---------------------------------------------------------------------------- fk

def cmd_fk(args) -> int:
    from ..model.rotary import RotaryPlatform

    params, label = rotary_rig_params(args)
    if args.input and args.angles is not None:
        raise UserError("--input cannot be combined with --angles")
    if not args.input and args.angles is None:
        raise UserError("give --angles or --input CSV")
    check_output("--csv", args.csv)
    times = None
    if args.input:
        names = csvfile.header(args.input) or []
        timed = "t" in names
        data = read_csv("--input", args.input, (["t"] if timed else []) + ANGLE_COLUMNS)
        times, angles = (data[:, 0], data[:, 1:]) if timed else (None, data)
        source = f"--input {args.input}"
    else:
        angles, source = np.atleast_2d(np.array(args.angles)), "--angles"
    if args.degrees:
        angles = np.radians(angles)
    try:
        poses = np.atleast_2d(RotaryPlatform(params).forward_kinematics(angles))
    except ConvergenceError as exc:
        raise UserError(f"{source}: {str(exc).removeprefix('forward_kinematics: ')} (out of the rig's reach?)",
                        EXIT_WORKSPACE) from None
    header = list(POSE_AXES)
    if times is not None:
        poses, header = np.column_stack([times, poses]), ["t"] + header
    print_table(label, header, poses, args.csv)
    return 0


def add_fk(sub) -> None:
    p = subcommand(sub, "fk", "the pose from a rotary rig's crank angles, e.g. its encoders' (forward kinematics: "
                   f"Newton from the rig's home); prints {AXES} [{UNITS}]. Rotary rigs only", cmd_fk)
    add_params(p, rotary=True, default="simrig100")
    p.add_argument("--angles", nargs=6, type=number, metavar=tuple(ANGLE_COLUMNS),
                   help="the six crank angles [rad, or deg with --degrees]")
    p.add_argument("--input", metavar="CSV", help=f"rows of {','.join(ANGLE_COLUMNS)}, or with a header naming t "
                   "too (stewart servo-angles --output) the times, carried to the output")
    p.add_argument("--degrees", action="store_true", help="the angles are in degrees (as stewart servo-angles writes)")
    add_file(p, "--csv", "write the poses to a CSV file")
