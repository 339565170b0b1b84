"""``stewart validate`` (the model against independent physics), ``stewart exactness`` (what
the legs' spin changes) and ``stewart bench`` (the speed of the compiled kernel)."""

from __future__ import annotations

import contextlib
import json
import sys

from ..model.presets import presets as list_presets
from .common import EXIT_CHECK_FAILED, UserError, flag_names, platform_params
from .interleaved import BUDGET
from .options import add_json, add_params, add_seed, count, non_negative, subcommand


def cmd_validate(args) -> int:
    from ..oracles import validation

    params, label = platform_params(args)
    with contextlib.redirect_stdout(sys.stderr) if args.json else contextlib.nullcontext():
        checks = validation.run(params, n_states=args.states, seed=args.seed)
    code = 0 if all(c.passed for c in checks) else EXIT_CHECK_FAILED
    if args.json:
        print(json.dumps({
            "command": "validate", "platform": params.name or "unnamed", "platform_source": label,
            "states": args.states, "seed": args.seed, "passed": code == 0, "exit_code": code,
            "checks": [{"name": c.name, "worst": float(c.worst), "bound": float(c.bound), "passed": bool(c.passed)}
                       for c in checks],
        }))
    else:
        print(validation.format_report(params, checks))
    return code


def cmd_exactness(args) -> int:
    from ..oracles import exactness

    params, label = platform_params(args)
    try:
        effect = exactness.leg_spin_effect(params, n_states=args.states, seed=args.seed)
    except ValueError as exc:
        source = f"--params {args.params}" if args.params else f"--preset {args.preset}"
        raise UserError(flag_names(str(exc), {"params": source, "seed": "--seed", "n_states": "--states"})) from None
    if args.json:
        print(json.dumps({"command": "exactness", "platform": params.name or "unnamed", "platform_source": label,
                          "states": args.states, "seed": args.seed, "assumed_axes": effect.assumed_axes,
                          "dynamic": effect.dynamic._asdict(), "velocity": effect.velocity._asdict(),
                          "exit_code": 0}))
        return 0
    axes = ("first axes horizontal and tangential to the base circle (assumed)" if effect.assumed_axes
            else "the parameters' universal_joint_axes")
    print(f"platform {label}: the paper's legs (no spin, eq. 29) against legs that turn with their universal "
          f"joints, {axes}; {args.states} random states, seed {args.seed}")
    print(f"{'relative change of the actuator forces':<44} {'median':>9} {'max':>9}")
    for name, change in (("dynamic forces (all but gravity)", effect.dynamic),
                         ("velocity-dependent forces", effect.velocity)):
        print(f"{name:<44} {change.median:>9.1e} {change.max:>9.1e}")
    return 0


def _add_states(parser, help_text: str) -> None:
    """``--states``: how many random states a check draws."""
    parser.add_argument("--states", type=count, default=200, help=help_text)


def add_validate(sub) -> None:
    p = subcommand(sub, "validate", "check the model against independent physics for a platform", cmd_validate)
    add_params(p)
    _add_states(p, "random states per check")
    add_seed(p, "states")
    add_json(p)


def add_exactness(sub) -> None:
    p = subcommand(sub, "exactness", "how much the legs' spin with their universal joints changes the actuator "
                   "forces: the paper's model against the exact-leg model", cmd_exactness)
    add_params(p)
    _add_states(p, "random states around home")
    add_seed(p, "states")
    add_json(p)


def cmd_bench(args) -> int:
    from . import bench

    with contextlib.redirect_stdout(sys.stderr) if args.json else contextlib.nullcontext():
        figures = bench.main([args.preset] if args.preset else None, batch=args.batch, budget=args.budget,
                             ratios_only=args.ratios_only)
    if args.json:
        print(json.dumps({"command": "bench", "batch": args.batch, "exit_code": 0, "figures": figures}))
    return 0


def add_bench(sub) -> None:
    p = subcommand(sub, "bench", "time the compiled kernel and the simulation loop", cmd_bench)
    p.add_argument("--preset", choices=sorted(list_presets()), help="one preset (default: all)")
    p.add_argument("--batch", type=count, default=200_000, help="states of the large batch the two-thread figures run")
    p.add_argument("--budget", type=non_negative, default=BUDGET, metavar="S",
                   help="seconds of rounds a figure with a target may take before it is judged as it stands "
                        "(default %(default)g; a figure without one gets a third)")
    p.add_argument("--ratios-only", action="store_true",
                   help="only the exact derivatives' cost over the values', a state each, on the avx2 and avx512 "
                        "paths the CPU runs, with their targets (a few seconds)")
    add_json(p, "print only a JSON summary of the figures on stdout")
