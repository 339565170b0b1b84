"""``stewart cueing``: a platform reference from a vehicle log by classical washout or
model-predictive cueing, checked against the platform's limits and optionally run through
the closed loop (``--simulate``)."""

from __future__ import annotations

import json
import sys
from dataclasses import replace

from ..cueing import MPCParams, WashoutParams, mpc, read_log, washout
from ..model.platform import Platform
from ..model.rotary import RotaryPlatform
from ..model.rotary_params import RotaryParams
from .common import (
    EXIT_USAGE,
    UserError,
    check_output,
    check_outputs,
    check_plotting,
    rig_params,
    print_written,
    progress,
)
from .options import add_file, add_json, add_params, add_progress, subcommand


def _usage_error(args) -> str | None:
    if not args.output:
        return "give --output FILE for the reference"
    return None


def cmd_cueing(args) -> int:
    check_outputs(args, "--output", "--report")
    check_output("--plot", args.plot, directory=True)
    if args.plot:
        check_plotting("--plot")
    params, label = rig_params(args)
    rotary = isinstance(params, RotaryParams)
    plat = RotaryPlatform(params) if rotary else Platform(params)
    try:
        log = read_log(args.log)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    kind = MPCParams if args.method == "mpc" else WashoutParams
    if args.no_limiter and args.method != "washout":
        raise UserError("--no-limiter: the limiter is the washout's; give it with --method washout", EXIT_USAGE)
    try:
        settings = kind.load(args.cueing, plat) if args.cueing else kind.for_platform(plat)
        if args.method == "mpc":
            settings.intervals(log.dt)
    except ValueError as exc:
        raise UserError(f"--cueing {exc}", EXIT_USAGE) from None
    if args.no_limiter:
        settings = replace(settings, limiter_enabled=False)
    if args.method == "mpc":
        result = mpc(log, plat, settings, simulate=args.simulate, progress=progress(args))
    else:
        result = washout(log, plat, settings, simulate=args.simulate)
    files = []
    if result.inside and not result.beyond_limits:
        result.to_csv(args.output)
        files.append(args.output)
    if args.report:
        result.to_json(args.report)
        files.append(args.report)
    if args.plot:
        files += result.plot(args.plot)
    report = result.report()
    if args.json:
        print(json.dumps({"command": "cueing", "platform_source": label, **report, "files": files}))
    else:
        print(f"platform {label}, {args.method} of {log.name} ({len(log.t)} samples at {1 / log.dt:g} Hz)")
        if result.solver is not None:
            step = report["solve_time_s"]
            print(f"MPC: {settings.duration:g} s horizon in {settings.steps} steps, "
                  f"{'preview of the log' if settings.preview else 'no preview'}; time per step median "
                  f"{1e3 * step['median']:.2f} ms, max {1e3 * step['max']:.2f} ms")
            yielded = {level: count for level, count in report["qp_levels"].items() if level != "plan" and count}
            if yielded:
                print("MPC steps whose plan yielded (qp_levels): "
                      + ", ".join(f"{level} {count}" for level, count in yielded.items()))
        if result.limiting is not None:
            print(result.limiting.summary())
        print("perceived error RMS: " + "  ".join(f"{k} {v:.3g}" for k, v in report["perceived_error_rms"].items()))
        if result.simulation is not None:
            sim = report["simulation"]
            print(f"simulation (computed torque): {sim['outcome']}")
            if "perceived_error_rms" in sim:
                print("achieved perceived error RMS: "
                      + "  ".join(f"{k} {v:.3g}" for k, v in sim["perceived_error_rms"].items()))
        print_written(files)
    for problem in result.problems:
        print(f"stewart cueing: problem: {problem}", file=sys.stderr)
    if not result.inside or result.beyond_limits:
        print(f"stewart cueing: error: the reference leaves the platform's limits; {args.output} not written",
              file=sys.stderr)
    return result.exit_code


def add_cueing(sub) -> None:
    p = subcommand(sub, "cueing", "a platform reference from a vehicle log (t,fx,fy,fz,wx,wy,wz CSV) by "
                   "motion cueing, within the platform's limits", cmd_cueing)
    p.add_argument("log", metavar="LOG.csv", help="vehicle log: specific force [m/s^2] and angular velocity "
                   "[rad/s] in the vehicle frame (x forward, y left, z up), constant sample rate")
    p.add_argument("--method", choices=["washout", "mpc"], default="washout", help="cueing algorithm")
    add_params(p, rotary=True)
    p.set_defaults(preset="motion_simulator", usage_error=_usage_error)
    p.add_argument("--cueing", metavar="C.toml", help="washout or MPC settings (default: scaled to the platform; "
                   "see docs/cueing.md)")
    add_file(p, "--output", "write the reference t, pose, rates, accelerations as CSV (stewart simulate "
             "--trajectory reads it)")
    add_file(p, "--report", "write the metrics and outcome as JSON")
    add_file(p, "--plot", "write PNG figures into DIR (needs matplotlib)", metavar="DIR")
    p.add_argument("--no-limiter", action="store_true", help="washout: leave the reference unlimited (one that "
                   "leaves the workspace is refused, exit 3) instead of scaling it back smoothly (see docs/cueing.md)")
    p.add_argument("--simulate", action="store_true", help="run the reference through the closed loop "
                   "(computed torque) and report the achieved motion's perceived error and problems (on a "
                   "rotary rig: crank speeds, motor torques and the achieved poses' workspace)")
    add_json(p)
    add_progress(p)
