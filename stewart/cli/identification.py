"""``stewart excitation`` (a trajectory designed for identification) and ``stewart identify``
(a built platform's inertial and friction parameters from a log)."""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings

import numpy as np

from ..identification import excitation
from ..model.params import NonAxisymmetricLegWarning
from ..model.platform import Platform
from ..model.reachability import WorkspaceError
from ..motion.simulation import OUTCOMES
from .common import (
    EXIT_CHECK_FAILED,
    EXIT_WORKSPACE,
    UserError,
    check_outputs,
    check_parameter_file_name,
    check_plotting,
    flag_names,
    platform_params,
    print_written,
    progress,
)
from .options import (
    UNITS,
    add_file,
    add_force_limit,
    add_json,
    add_max_iterations,
    add_params,
    add_progress,
    add_seed,
    add_six,
    count,
    non_negative,
    positive,
    subcommand,
)

# ---------------------------------------------------------------------------- excitation

#: The user's flags for the arguments of :func:`stewart.identification.excitation.design_excitation`.
_EXCITATION_FLAGS = {"period": "--period", "harmonics": "--harmonics", "centre": "--centre", "periods": "--periods",
                     "samples": "--samples", "starts": "--starts", "seed": "--seed", "rate": "--rate",
                     "max_leg_velocity": "--max-leg-velocity", "max_leg_acceleration": "--max-leg-acceleration",
                     "force_limit": "--force-limit", "min_margin": "--min-margin", "stroke_margin": "--stroke-margin",
                     "max_iterations": "--max-iterations"}


def cmd_excitation(args) -> int:
    check_outputs(args, "--csv", "--output", "--plot")
    check_parameter_file_name("--output", args.output)
    if args.plot:
        check_plotting("--plot")
    params, label = platform_params(args)
    plat = Platform(params)
    try:
        design = excitation.design_excitation(
            plat, period=args.period, harmonics=args.harmonics, centre=args.centre, periods=args.periods,
            samples=args.samples, starts=args.starts, seed=args.seed, max_leg_velocity=args.max_leg_velocity,
            max_leg_acceleration=args.max_leg_acceleration,
            force_limit=None if math.isinf(args.force_limit) else args.force_limit, min_margin=args.min_margin,
            stroke_margin=args.stroke_margin, friction=args.friction, max_iterations=args.max_iterations,
            progress=progress(args))
        if args.csv:
            design.to_csv(args.csv, plat, args.rate)
    except WorkspaceError as exc:
        raise UserError(flag_names(str(exc), _EXCITATION_FLAGS), EXIT_WORKSPACE) from None
    except ValueError as exc:
        raise UserError(flag_names(str(exc), _EXCITATION_FLAGS)) from None
    files = [args.csv] if args.csv else []
    if args.output:
        design.save(args.output)
        files.append(args.output)
    if args.plot:
        from ..io.plots import plot_excitation

        files.append(plot_excitation(design, plat, args.plot))
    code = 0 if design.feasible else OUTCOMES["failed"]
    if args.json:
        print(json.dumps({"command": "excitation", "platform_source": label, **design.summary(), "files": files,
                          "exit_code": code}))
    else:
        _excitation_report(design, label, files)
    for problem in design.problems:
        print(f"stewart excitation: error: {problem}", file=sys.stderr)
    return code


def _excitation_report(design, label: str, files: list[str]) -> None:
    traj, peaks, lim = design.trajectory, design.peaks, design.limits
    print(f"platform {label}: Fourier excitation, {traj.harmonics} harmonics, period {traj.period:g} s, "
          f"{traj.periods} period(s), {len(design.base_names)} base parameters")
    print(f"condition number {design.condition:.4g} (random start {design.initial_condition:.4g}; best of "
          f"{design.starts} start(s), {design.iterations} SLSQP iterations"
          + (f"; amplitudes scaled by {design.scaled:.4g} to hold on the check grid)" if design.scaled < 1 else ")"))
    force = "none" if math.isinf(lim.force) else f"{lim.force:.4g}"
    print(f"{'':<26}{'reached':>12}{'limit':>12}")
    for name, reached, limit in (("leg length min [m]", peaks["leg_length_min"], f"{lim.lengths[0]:.4g}"),
                                 ("leg length max [m]", peaks["leg_length_max"], f"{lim.lengths[1]:.4g}"),
                                 ("leg velocity [m/s]", peaks["leg_velocity"], f"{lim.leg_velocity:.4g}"),
                                 ("leg acceleration [m/s^2]", peaks["leg_acceleration"], f"{lim.leg_acceleration:.4g}"),
                                 ("actuator force [N]", peaks["force"], force),
                                 ("singularity margin (min)", peaks["margin_min"], f"{lim.margin:.4g}")):
        print(f"{name:<26}{reached:>12.4g}{limit:>12}")
    print_written(files)


def add_excitation(sub) -> None:
    p = subcommand(sub, "excitation", "design a periodic Fourier-series trajectory for identification that "
                   "minimizes the condition number of the base regressor within the stroke, leg velocity, "
                   "acceleration and force limits, away from singularities", cmd_excitation)
    add_params(p)
    p.add_argument("--period", type=positive, default=excitation.DEFAULT_PERIOD, help="period of the series [s]")
    p.add_argument("--harmonics", type=count, default=excitation.DEFAULT_HARMONICS,
                   help="harmonics of the series (at least 2)")
    p.add_argument("--periods", type=count, default=1, help="periods the exported trajectory repeats")
    add_six(p, "--centre", f"pose the series moves about, at rest at its start and end (default: home) [{UNITS}]")
    p.add_argument("--samples", type=count, help="design samples per period "
                   f"(default: {excitation.SAMPLES_PER_HARMONIC} per harmonic)")
    p.add_argument("--starts", type=count, default=excitation.DEFAULT_STARTS, help="random starts of the optimizer")
    add_seed(p, "starts")
    add_max_iterations(p, excitation.DEFAULT_ITERATIONS, "SLSQP iterations per start")
    p.add_argument("--max-leg-velocity", type=positive, metavar="M/S", help="largest |leg velocity| "
                   f"(default: {excitation.VELOCITY_PER_STROKE:g} stroke(s) per second)")
    p.add_argument("--max-leg-acceleration", type=positive, metavar="M/S2", help="largest |leg acceleration| "
                   f"(default: {excitation.ACCELERATION_PER_STROKE:g} strokes per second squared)")
    add_force_limit(p)
    p.add_argument("--min-margin", type=positive, help="smallest singularity margin 1/cond(J_C) "
                   f"(default: {excitation.MARGIN_FRACTION:g} times the centre pose's)")
    p.add_argument("--stroke-margin", type=non_negative, default=excitation.STROKE_MARGIN,
                   help="fraction of the stroke kept free at either end")
    p.add_argument("--friction", action=argparse.BooleanOptionalAction, default=True,
                   help="excite the per-leg viscous and Coulomb friction parameters too")
    p.add_argument("--rate", type=positive, default=excitation.DEFAULT_RATE, help="sample rate of the --csv rows [Hz]")
    add_file(p, "--csv", "write t, pose, leg lengths and leg velocities for a machine controller (stewart "
             "simulate --trajectory reads it)")
    add_file(p, "--output", "write the series (.toml or .json; stewart simulate --trajectory reads it)")
    add_file(p, "--plot", "write a PNG figure of the poses and leg strokes")
    add_progress(p)
    add_json(p)


# ---------------------------------------------------------------------------- identify

def cmd_identify(args) -> int:
    from ..identification import identify

    check_outputs(args, "--output", "--report", "--plot")
    check_parameter_file_name("--output", args.output)
    if args.plot:
        check_plotting("--plot")
        if not args.validate:
            raise UserError("--plot: draws the prediction of a held-out run; give --validate FILE too")
    prior, label = platform_params(args)
    plat = Platform(prior)

    def measurements(flag, path):
        try:
            return identify.Measurements.from_csv(path)
        except ValueError as exc:
            raise UserError(f"{flag}{exc}") from None

    if not args.data:
        raise UserError("DATA.csv: the file name is empty; give the log to identify from")
    data = measurements("", args.data)
    try:
        result = identify.identify(plat, data, filter=args.filter, cutoff=args.cutoff, friction=args.friction)
    except ValueError as exc:
        raise UserError(flag_names(str(exc), {"cutoff": "--cutoff", "measurements": args.data,
                                              "forces": args.data})) from None
    print(f"# platform {label}: identified from {args.data} ({len(data.t)} samples at {data.rate:.6g} Hz, "
          f"{args.filter} filter, cut-off {args.cutoff:g} Hz)")
    print(result.table())
    summary = result.summary()
    if args.validate:
        held = measurements("--validate ", args.validate)
        try:
            t, predicted, measured, rms = identify.validation(result, plat, held, filter=args.filter,
                                                              cutoff=args.cutoff)
        except ValueError as exc:
            source = f"--validate {args.validate}"
            raise UserError(flag_names(str(exc), {"cutoff": "--cutoff", "measurements": source,
                                                  "forces": source})) from None
        spread = np.sqrt(np.mean((measured - measured.mean(axis=0)) ** 2, axis=0))
        print(f"held-out run {args.validate}: RMS error per leg [N] {', '.join(f'{v:.3g}' for v in rms)} "
              f"(force spread {', '.join(f'{v:.3g}' for v in spread)})")
        summary["validation"] = {"file": args.validate, "rms": rms.tolist(), "spread": spread.tolist()}
        if args.plot:
            from ..io.plots import plot_force_prediction

            print(f"wrote {plot_force_prediction(t, predicted, measured, args.plot)}")
    if args.report:
        with open(args.report, "w", encoding="utf-8") as handle:
            json.dump(summary, handle, indent=2)
        print(f"wrote {args.report}")
    if args.output:
        try:
            params = result.params()
        except ValueError as exc:
            print(f"stewart identify: error: --output {args.output}: not written: {exc}", file=sys.stderr)
            return EXIT_CHECK_FAILED
        with warnings.catch_warnings():  # the legs' I_yy and I_zz are identified apart (Identification.params)
            warnings.simplefilter("ignore", NonAxisymmetricLegWarning)
            params.replace(name=f"{prior.name or 'platform'} (identified)").save(args.output)
        print(f"wrote {args.output}: the prior's parameters with the identified inertial and friction values")
    return 0


def add_identify(sub) -> None:
    p = subcommand(sub, "identify", "estimate a built platform's base inertial and friction parameters from a "
                   "log of leg lengths and actuator forces (CSV: t, L0..L5 [m], F0..F5 [N]); the parameters given "
                   "are the prior (geometry, and the values the log cannot determine)", cmd_identify)
    p.add_argument("data", metavar="DATA.csv", help="the log to identify from")
    add_params(p)
    p.add_argument("--filter", choices=["savgol", "butterworth"], default="savgol",
                   help="zero-phase differentiation of the poses")
    p.add_argument("--cutoff", type=positive, default=10.0, help="the filter's cut-off [Hz]")
    p.add_argument("--friction", action=argparse.BooleanOptionalAction, default=True,
                   help="identify each leg's viscous and Coulomb friction too")
    p.add_argument("--validate", metavar="FILE", help="a held-out log: print the prediction's RMS error per leg")
    add_file(p, "--output", "write the identified parameters (.toml or .json), loadable with --params and "
             "Platform.from_file")
    add_file(p, "--report", "write the base parameters with their standard errors (JSON)")
    add_file(p, "--plot", "write predicted against measured forces of --validate (PNG)")
