"""``stewart c-export`` (the generated C with a platform's parameter header, for C programs),
``stewart export-acados`` (the one-step map as acados's generic discrete dynamics) and
``stewart export-mjcf`` (the platform as a MuJoCo model)."""

from __future__ import annotations

import os
import sys

from ..io.mjcf import SOLVERS, to_mjcf
from ..model.rotary_params import RotaryParams
from .common import UserError, check_output, platform_params, rig_params
from .options import AXES, UNITS, add_file, add_params, add_six, positive, subcommand


def cmd_c_export(args) -> int:
    from ..io import capi

    params, label = platform_params(args)
    if os.path.exists(args.directory) and not os.path.isdir(args.directory):
        raise UserError(f"DIR {args.directory}: exists and is not a directory")
    try:
        written = capi.export(args.directory, params)
    except OSError as exc:
        raise UserError(f"DIR {args.directory}: {exc.strerror or exc}") from None
    for path in written:
        print(f"wrote {path}")
    print(f"platform {label}: stewart_platform_params in {capi.PARAMS_HEADER}")
    print(f"C/C++ library: cmake -S {args.directory} -B BUILD && cmake --build BUILD && cmake --install BUILD "
          "--prefix PREFIX; then find_package(stewart CONFIG) gives stewart::stewart, or pkg-config stewart")
    return 0


def add_c_export(sub) -> None:
    p = subcommand(sub, "c-export", "write the generated C model, a platform's parameter header and a CMake "
                   "and pkg-config package of it into a directory, for C and C++ programs", cmd_c_export)
    add_params(p)
    p.add_argument("directory", metavar="DIR", help="directory to write into (created if missing)")


def cmd_export_acados(args) -> int:
    from ..io import acados_export

    params, label = platform_params(args)
    if os.path.exists(args.directory) and not os.path.isdir(args.directory):
        raise UserError(f"DIR {args.directory}: exists and is not a directory")
    try:
        acados_export.compile_flags(args.directory)
    except ValueError as exc:
        raise UserError(f"DIR {args.directory}: {str(exc).partition(': ')[2]}") from None
    try:
        written = acados_export.export(args.directory, params, args.dt, args.integrator)
    except OSError as exc:
        raise UserError(f"DIR {args.directory}: {exc.strerror or exc}") from None
    for path in written:
        print(f"wrote {path}")
    print(f"platform {label}: {args.integrator} step of {args.dt:g} s as acados's generic discrete dynamics in "
          f"{acados_export.SOURCE} (stewart.acados builds the model and a tracking OCP from {args.directory})")
    return 0


def add_export_acados(sub) -> None:
    p = subcommand(sub, "export-acados", "write the platform's one-step map with its Jacobians as acados's generic "
                   "discrete dynamics (state [x, xd], input the six actuator forces), for nonlinear MPC",
                   cmd_export_acados)
    add_params(p)
    p.add_argument("directory", metavar="DIR", help="directory to write into (created if missing)")
    p.add_argument("--dt", type=positive, required=True, help="the step of the discrete dynamics [s]")
    p.add_argument("--integrator", choices=["rk4"], default="rk4", help="the one-step map: classic RK4 "
                   "(Platform.rk4_step)")


def cmd_export_mjcf(args) -> int:
    check_output("--output", args.output)
    params, label = rig_params(args)
    try:
        text = to_mjcf(params, pose=args.pose, solver=args.solver)
    except ValueError as exc:
        message = str(exc)
        raise UserError(f"--{message}" if message.startswith("pose:") else message) from None
    if not args.output:
        sys.stdout.write(text)
        return 0
    try:
        with open(args.output, "w", encoding="utf-8") as handle:
            handle.write(text)
    except OSError as exc:
        raise UserError(f"--output {args.output}: {exc.strerror or exc}") from None
    kind = "rotary rig" if isinstance(params, RotaryParams) else "platform"
    print(f"wrote {args.output}: MuJoCo model of {kind} {label}, solver settings '{args.solver}'")
    return 0


def add_export_mjcf(sub) -> None:
    p = subcommand(sub, "export-mjcf", "write the platform as a standalone MuJoCo model (MJCF): universal "
                   "joints, actuated slides, ball joints as equality constraints; ctrl = actuator forces [N]. "
                   "A rotary rig: motor hinges (reading the crank angles), rods on ball joints, the loops "
                   "closed at the platform by equality constraints; ctrl = motor torques [N m]",
                   cmd_export_mjcf)
    add_params(p, rotary=True)
    add_file(p, "--output", "write the model to FILE (default: standard output)")
    add_six(p, "--pose", f"assembly pose: {AXES} [{UNITS}] (default: home)")
    p.add_argument("--solver", choices=list(SOLVERS), default="default",
                   help="MuJoCo's defaults (2 ms Euler step, soft constraints), or the 0.1 ms RK4 step and stiff "
                        "constraints the agreement with this model is measured at")
