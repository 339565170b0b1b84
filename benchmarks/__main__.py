"""``make bench``: speed of the compiled kernel, and of the same model written with its
peers (CasADi, sympy's autowrap and PyDy, MuJoCo), measured side by side in one run.

Prints the tables, writes the figures as JSON (``--json``, default
``out/benchmarks.json``) and a bar chart of ours against the peers
(``out/benchmarks_peers.png``). Every figure with a target is measured in interleaved
rounds against an anchor in this process (:mod:`stewart.cli.interleaved`): the code it is
compared with, or the yardstick for an absolute figure; it is the median of its rounds, with
the 90 % interval of that median, and its target is met, missed, or unsettled when the
interval straddles the bound. The last line counts the three over every table; with
``--strict`` the exit status is 1 unless every target is met. The peers' figures (no
targets) are medians of repeats, on the same states. Peers that are not installed
(``pip install .[peers]``) are skipped and named.
"""

from __future__ import annotations

import argparse
import datetime
import json
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

import stewart
from stewart.cli import bench
from stewart.cli.options import non_negative

from . import acados_nmpc, batch_loop, calibration, cueing, identification, motor_sizing, report, rotary_kernel, studies
from .peers.common import peer_available

ROOT = pathlib.Path(__file__).resolve().parent.parent


def _generate(tmp: pathlib.Path) -> None:
    subprocess.run([sys.executable, "-m", "codegen", "--out", str(tmp)], cwd=ROOT, check=True, capture_output=True)


def _build(tmp: pathlib.Path) -> None:
    build = tmp / "build"
    subprocess.run([sys.executable, "setup.py", "-q", "build_ext", "--force", "--build-lib", str(build / "lib"),
                    "--build-temp", str(build / "temp")], cwd=ROOT, check=True, capture_output=True)
    shutil.rmtree(build)


#: Rounds of the generation (about 10 s each) and of the clean build (about 45 s, so one:
#: its interval is that round's value).
GENERATION_ROUNDS = 2
BUILD_ROUNDS = 1


def generation_figures(rounds: bench.Rounds) -> dict:
    """Generation time (``python -m codegen``) and a clean build of the extension, each
    against the yardstick with the gauge (both use both cores)."""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        rounds.job("generation_s", lambda: _generate(tmp), GENERATION_ROUNDS)
        rounds.job("clean_build_s", lambda: _build(tmp), BUILD_ROUNDS)
        out = bench.figures_of(rounds.measure())
    # Cython writes stewart/_kernel.c next to the .pyx; nothing else of the build is kept.
    return out


def code_figures() -> dict:
    """Size of the generated C (the model's units and the header they share) and the operation
    counts the generator records in the header."""
    generated = ROOT / "generated"
    source = b"".join(path.read_bytes() for path in sorted(generated.glob("stewart_model*.c"))
                      + [generated / "stewart_internal.h"])
    header = (ROOT / "generated" / "stewart_model.h").read_text()
    ops = {name: int(count) for name, count in re.findall(r"^\s*\*\s+(\w+)\s+(\d+)\s*$", header, re.M)}
    return {"generated_c_bytes": len(source), "generated_c_lines": source.count(b"\n"), "operation_counts": ops}


PEERS = ("casadi", "casadi_derivatives", "pinocchio", "optimization", "sympy", "mujoco")
#: Importable module each peer needs.
_NEEDS = {"casadi": ("casadi",), "casadi_derivatives": ("casadi",), "pinocchio": ("pinocchio",),
          "optimization": ("casadi",),
          "sympy": ("sympy", "Cython"), "mujoco": ("mujoco",)}
#: Default cap on compiling CasADi's Jacobian C (s): its inverse-dynamics Jacobian takes
#: about 10 minutes of gcc on this machine.
JACOBIAN_COMPILE_CAP_S = 600.0


def peer_figures(names, batch: int, jacobian_compile_cap_s: float = JACOBIAN_COMPILE_CAP_S) -> dict:
    """Each peer's figures, or {"error": why it was skipped}."""
    out = {}
    for name in names:
        missing = [m for m in _NEEDS[name] if not peer_available(m)]
        if missing:
            out[name] = {"error": f"not installed ({', '.join(missing)}); pip install '.[peers]'"}
            print(f"[bench] peer {name}: skipped, {out[name]['error']}", flush=True)
            continue
        print(f"[bench] peer {name} ...", flush=True)
        try:
            if name == "casadi":
                from .peers import casadi_bench

                out[name] = casadi_bench.figures("narayan2017", n_batch=min(batch, 20_000))
            elif name == "casadi_derivatives":
                from .peers import casadi_derivatives

                out[name] = casadi_derivatives.figures("narayan2017", n_batch=min(batch, 2_000),
                                                       compile_cap_s=jacobian_compile_cap_s)
            elif name == "pinocchio":
                from .peers import pinocchio_model

                out[name] = pinocchio_model.figures("narayan2017")
            elif name == "optimization":
                from .peers import casadi_optimize

                out[name] = casadi_optimize.figures("narayan2017")
            elif name == "sympy":
                from .peers import sympy_route

                out[name] = sympy_route.figures("narayan2017")
            else:
                from .peers import mujoco_model

                out[name] = mujoco_model.figures()
        except Exception as exc:  # a peer's failure must not lose our own figures
            out[name] = {"error": f"failed: {type(exc).__name__}: {exc}"[:300]}
            print(f"[bench] peer {name}: {out[name]['error']}", flush=True)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", default=str(ROOT / "out" / "benchmarks.json"), help="where to write the figures")
    parser.add_argument("--batch", type=int, default=200_000,
                        help="states of the large batch the two-thread figures run (default 200000)")
    parser.add_argument("--presets", type=lambda v: [p.strip() for p in v.split(",") if p.strip()], default=None,
                        help="comma-separated presets to time (default: all)")
    parser.add_argument("--budget", type=non_negative, default=bench.BUDGET, metavar="S",
                        help="seconds of rounds a figure with a target may take before it is judged as it stands "
                             f"(default {bench.BUDGET:g}; a figure without one gets a third)")
    parser.add_argument("--strict", action="store_true",
                        help="exit with status 1 unless every target is met (a missed or unsettled one fails)")
    parser.add_argument("--skip-build", action="store_true", help="skip the generation and clean-build timings")
    parser.add_argument("--peers", default=",".join(PEERS),
                        help=f"comma-separated peers to compare ({','.join(PEERS)}; 'none' for none)")
    parser.add_argument("--jacobian-compile-cap", type=float, default=JACOBIAN_COMPILE_CAP_S, metavar="S",
                        help="seconds CasADi's Jacobian C may take to compile before it is reported as not "
                             f"finished (default {JACOBIAN_COMPILE_CAP_S:g})")
    parser.add_argument("--chart", default=str(ROOT / "out" / "benchmarks_peers.png"), help="bar chart path")
    args = parser.parse_args(argv)
    peers = [] if args.peers.strip().lower() == "none" else [p.strip() for p in args.peers.split(",") if p.strip()]
    unknown = sorted(set(peers) - set(PEERS))
    if unknown:
        parser.error(f"--peers: unknown peer(s) {unknown}; choose from {list(PEERS)}")

    started = time.perf_counter()
    rounds = bench.Rounds(args.budget)
    results = {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": report.machine(),
        "budget_s": args.budget,
        "kernel": {},
    }
    for preset in args.presets or sorted(stewart.presets()):
        print(f"[bench] kernel, reference, simulation loop, general model, derivatives, modes: {preset} ...",
              flush=True)
        results["kernel"][preset] = bench.figures_of(bench.preset_figures(preset, args.batch, rounds))
    print(f"[bench] rotary rig {rotary_kernel.ROTARY} against linear {rotary_kernel.LINEAR}, a state each ...",
          flush=True)
    results["rotary_kernel"] = rotary_kernel.figures(rounds)
    print("[bench] batch functions against the single-state ones, C loop ...", flush=True)
    results["batch_loop"] = batch_loop.figures("narayan2017", min(args.batch, 100_000), rounds)
    if peer_available("distributed"):
        print("[bench] envelopes in process and on a 2-worker Dask LocalCluster ...", flush=True)
        results["studies"] = studies.figures("narayan2017", rounds=rounds)
    else:
        print("[bench] studies: skipped, dask.distributed not installed (pip install '.[cluster]')", flush=True)
    print("[bench] identification from a long log ...", flush=True)
    results["identification"] = identification.figures("narayan2017", rounds=rounds)
    print("[bench] kinematic calibration from 200 poses ...", flush=True)
    results["calibration"] = calibration.figures("narayan2017", rounds=rounds)
    print("[bench] MPC cueing, time per step ...", flush=True)
    results["cueing"] = cueing.figures("motion_simulator", rounds=rounds)
    results["cueing_rotary"] = cueing.figures("simrig100", rounds=rounds)
    print("[bench] motor sizing of a rotary rig from an hour of 60 Hz telemetry ...", flush=True)
    results["motor_sizing"] = motor_sizing.figures("simrig100", rounds=rounds)
    print("[bench] acados NMPC's RTI step against the CasADi route (in .venv-acados) ...", flush=True)
    results["acados"] = acados_nmpc.figures()
    if not args.skip_build:
        print("[bench] generation and clean build ...", flush=True)
        results["generation"] = generation_figures(rounds)
    results["code"] = code_figures()
    results["ours_s"] = time.perf_counter() - started
    results["peers"] = peer_figures(peers, args.batch, args.jacobian_compile_cap)
    table_rows = report.our_rows(results)
    tables = [table_rows, batch_loop.rows(results["batch_loop"])] + [
        module.rows(results[name]) for name, module in (("rotary_kernel", rotary_kernel), ("studies", studies),
                                                        ("identification", identification),
                                                        ("calibration", calibration), ("cueing", cueing),
                                                        ("cueing_rotary", cueing),
                                                        ("motor_sizing", motor_sizing), ("acados", acados_nmpc))
        if name in results]
    every = [row for table in tables for row in table]
    results["targets"] = report.targets(every)
    print()
    print(bench.yardstick_line(rounds))
    print()
    print(bench.format_table(table_rows))
    print()
    print(batch_loop.format_rows(results["batch_loop"]))
    print()
    print(rotary_kernel.format_rows(results["rotary_kernel"]))
    if "studies" in results:
        print()
        print(studies.format_rows(results["studies"]))
    print()
    print(identification.format_rows(results["identification"]))
    print()
    print(calibration.format_rows(results["calibration"]))
    print()
    print(cueing.format_rows(results["cueing"]))
    print(cueing.format_rows(results["cueing_rotary"]))
    print()
    print(motor_sizing.format_rows(results["motor_sizing"]))
    print(acados_nmpc.format_rows(results["acados"]))
    if results["peers"]:
        ops = results["code"]["operation_counts"]
        ours = {"ops": {"inverse_dynamics": ops.get("inverse_dynamics_axisym"),
                        "forward_dynamics": ops.get("forward_dynamics_axisym")}}
        gen = results.get("generation") or {}
        ours["generation_s"], ours["clean_build_s"] = gen.get("generation_s"), gen.get("clean_build_s")
        print()
        print(report.format_rows(report.rows(results["peers"], ours)))
        print(PEER_NOTES)
    path = pathlib.Path(args.json)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(results, indent=2) + "\n")
    print(f"\nfigures written to {path}")
    if results["peers"]:
        chart = report.chart(results["peers"], args.chart)
        print(f"chart written to {chart}" if chart else "no chart (needs matplotlib and at least one peer)")
    print(f"\nour figures took {results['ours_s'] / 60:.1f} min; every table's {bench.count_verdicts(every)}")
    return 1 if args.strict and any(t["verdict"] != "met" for t in results["targets"]) else 0


PEER_NOTES = """
Notes: every peer runs the narayan2017 preset with runtime parameters (a 51-double input
p, as our kernel's stewart_params). CasADi: SX model, momenta differentiated by jtimes,
symbolic linear solves; its C and ours are compiled with the same flags (-O3
-march=native) into the same C driver loop. sympy routes: our generator's expressions,
whole, through autowrap / PyDy (their own cse), numpy solves the 6x6 systems. MuJoCo:
MJCF legs on universal joints (two hinges) + slide, tied to the free platform by connect
equalities, legs with near-zero axial inertia (a U-joint leg spins a little about its
axis, the paper's leg does not; without axial inertia the spin carries no energy, so the
mechanics are the same). It replays, open loop, the forces of our computed-torque run of
the demo's move. The open-loop platform is unstable (constant leg forces push it like an
inverted pendulum): our own open-loop replay of the same forces drifts from our
closed-loop run just as MuJoCo does, so MuJoCo is compared with that replay, on the same
input. CasADi derivatives: ca.jacobian of the same SX model, value and 6 x 18 Jacobian in
one Function; its C is compiled under a time cap (--jacobian-compile-cap) and reported as
not finished past it. Pinocchio: the platform on a free-flyer joint, each leg a universal
joint and a slider, tied to the platform by 3-D point constraints (24 DOF, 18
constraints); constraintDynamics and computeConstraintDynamicsDerivatives called from
Python per state, at rest poses."""


if __name__ == "__main__":
    sys.exit(main())
