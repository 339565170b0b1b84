"""``make bench``: speed of the compiled kernel, measured side by side in one run.

Prints one table and writes the figures as JSON (``--json``, default
``out/benchmarks.json``). Every timing is the median of several repeats; ratios are
taken between figures measured in this same run.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import platform as host
import re
import subprocess
import sys
import tempfile
import time
import timeit

import numpy as np

import stewart
from stewart import reference

ROOT = pathlib.Path(__file__).resolve().parent.parent


def median_time(fn, number: int, repeat: int = 7) -> float:
    """Median over ``repeat`` runs of the time per call of ``fn`` (``number`` calls a run)."""
    return float(np.median(timeit.repeat(fn, number=number, repeat=repeat)) / number)


def states(params, n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    home = stewart.home_pose(params)
    scale = np.array([0.04 * home[2]] * 3 + [0.1] * 3)
    x = home + rng.uniform(-1, 1, (n, 6)) * scale
    xd = rng.normal(size=(n, 6)) * scale * 5
    xdd = rng.normal(size=(n, 6)) * scale * 50
    return x, xd, xdd


def kernel_figures(preset: str, batch: int) -> dict:
    plat = stewart.Platform.preset(preset)
    both = stewart.Platform.preset(preset, threads=2)
    x, xd, xdd = states(plat.params, batch)
    tau = plat.inverse_dynamics(x, xd, xdd)
    one = (x[0], xd[0], xdd[0])
    out = {
        "single_inverse_dynamics_us": median_time(lambda: plat.inverse_dynamics(*one), 20000) * 1e6,
        "single_forward_dynamics_us": median_time(lambda: plat.forward_dynamics(x[0], xd[0], tau[0]), 20000) * 1e6,
        "batch_inverse_dynamics_us": median_time(lambda: plat.inverse_dynamics(x, xd, xdd), 3) / batch * 1e6,
        "batch_forward_dynamics_us": median_time(lambda: plat.forward_dynamics(x, xd, tau), 3) / batch * 1e6,
        "batch_mass_matrix_us": median_time(lambda: plat.mass_matrix(x), 3) / batch * 1e6,
        "batch_coriolis_vector_us": median_time(lambda: plat.coriolis_vector(x, xd), 3) / batch * 1e6,
        "threads2_inverse_dynamics_states_per_s": batch / median_time(lambda: both.inverse_dynamics(x, xd, xdd), 3),
        "threads2_forward_dynamics_states_per_s": batch / median_time(lambda: both.forward_dynamics(x, xd, tau), 3),
    }
    n_ref = 200
    ref_id = median_time(lambda: reference.inverse_dynamics(plat.params, x[:n_ref], xd[:n_ref], xdd[:n_ref]), 1, 5)
    ref_single = median_time(lambda: reference.inverse_dynamics(plat.params, *one), 20, 5)
    out["reference_batch_inverse_dynamics_us"] = ref_id / n_ref * 1e6
    out["reference_single_inverse_dynamics_us"] = ref_single * 1e6
    out["speedup_batch_vs_reference"] = out["reference_batch_inverse_dynamics_us"] / out["batch_inverse_dynamics_us"]
    out["speedup_single_vs_reference"] = out["reference_single_inverse_dynamics_us"] / out["single_inverse_dynamics_us"]
    return out


def generation_figures() -> dict:
    """Generation time (``python -m codegen``) and a clean build of the extension."""
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "codegen", "--out", tmp], cwd=ROOT, check=True, capture_output=True)
        out["generation_s"] = time.perf_counter() - start
        build = pathlib.Path(tmp) / "build"
        start = time.perf_counter()
        subprocess.run(
            [sys.executable, "setup.py", "-q", "build_ext", "--force", "--build-lib", str(build / "lib"),
             "--build-temp", str(build / "temp")],
            cwd=ROOT, check=True, capture_output=True,
        )
        out["clean_build_s"] = time.perf_counter() - start
    # Cython writes stewart/_kernel.c next to the .pyx; nothing else of the build is kept.
    return out


def code_figures() -> dict:
    """Size of the generated C and the operation counts the generator records in the header."""
    source = (ROOT / "generated" / "stewart_model.c").read_bytes()
    header = (ROOT / "generated" / "stewart_model.h").read_text()
    ops = {name: int(count) for name, count in re.findall(r"^\s*\*\s+(\w+)\s+(\d+)\s*$", header, re.M)}
    return {"generated_c_bytes": len(source), "generated_c_lines": source.count(b"\n"), "operation_counts": ops}


def table(results: dict) -> str:
    rows = []
    for preset, fig in results["kernel"].items():
        rows += [
            (f"[{preset}] inverse dynamics, one call from Python", f"{fig['single_inverse_dynamics_us']:.3f} us", "<= 1.5 us"),
            (f"[{preset}] forward dynamics, one call from Python", f"{fig['single_forward_dynamics_us']:.3f} us", ""),
            (f"[{preset}] inverse dynamics, C batch loop", f"{fig['batch_inverse_dynamics_us']:.3f} us/state", "<= 0.4 us"),
            (f"[{preset}] forward dynamics, C batch loop", f"{fig['batch_forward_dynamics_us']:.3f} us/state", "<= 0.7 us"),
            (f"[{preset}] mass matrix, C batch loop", f"{fig['batch_mass_matrix_us']:.3f} us/state", ""),
            (f"[{preset}] V xdot, C batch loop", f"{fig['batch_coriolis_vector_us']:.3f} us/state", ""),
            (f"[{preset}] inverse dynamics, 2 threads", f"{fig['threads2_inverse_dynamics_states_per_s'] / 1e6:.2f} M states/s", ">= 4 M/s"),
            (f"[{preset}] forward dynamics, 2 threads", f"{fig['threads2_forward_dynamics_states_per_s'] / 1e6:.2f} M states/s", ""),
            (f"[{preset}] numeric reference, inverse dynamics batch", f"{fig['reference_batch_inverse_dynamics_us']:.1f} us/state", ""),
            (f"[{preset}] kernel / reference speed-up, batch", f"{fig['speedup_batch_vs_reference']:.0f}x", ">= 1000x"),
            (f"[{preset}] kernel / reference speed-up, one call", f"{fig['speedup_single_vs_reference']:.0f}x", ""),
        ]
    gen = results.get("generation")
    if gen:
        rows += [
            ("generation (python -m codegen)", f"{gen['generation_s']:.2f} s", "<= 10 s"),
            ("clean build of the extension", f"{gen['clean_build_s']:.1f} s", "<= 30 s"),
        ]
    code = results["code"]
    rows.append(("generated C", f"{code['generated_c_bytes'] / 1024:.0f} KiB, {code['generated_c_lines']} lines", ""))
    for name, count in code["operation_counts"].items():
        rows.append((f"operations: {name}", str(count), ""))
    width = max(len(r[0]) for r in rows)
    vwidth = max(len(r[1]) for r in rows)
    lines = [f"{'measure':<{width}}  {'median':>{vwidth}}  target", "-" * (width + vwidth + 12)]
    lines += [f"{a:<{width}}  {b:>{vwidth}}  {c}" for a, b, c in rows]
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__)
    parser.add_argument("--json", default=str(ROOT / "out" / "benchmarks.json"), help="where to write the figures")
    parser.add_argument("--batch", type=int, default=200_000, help="states per batch (default 200000)")
    parser.add_argument("--skip-build", action="store_true", help="skip the generation and clean-build timings")
    args = parser.parse_args(argv)

    results = {
        "machine": {"platform": host.platform(), "processor": host.processor(), "cpus": os.cpu_count(),
                    "python": sys.version.split()[0], "numpy": np.__version__},
        "kernel": {},
    }
    for preset in sorted(stewart.presets()):
        print(f"[bench] kernel and reference, {preset} ...", flush=True)
        results["kernel"][preset] = kernel_figures(preset, args.batch)
    if not args.skip_build:
        print("[bench] generation and clean build ...", flush=True)
        results["generation"] = generation_figures()
    results["code"] = code_figures()
    print()
    print(table(results))
    path = pathlib.Path(args.json)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(results, indent=2) + "\n")
    print(f"\nfigures written to {path}")


if __name__ == "__main__":
    main()
