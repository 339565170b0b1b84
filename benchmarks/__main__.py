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

import numpy as np

import stewart
from stewart import bench

ROOT = pathlib.Path(__file__).resolve().parent.parent


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
        rows += bench.kernel_rows(preset, fig)
    gen = results.get("generation")
    if gen:
        rows += [
            ("generation (python -m codegen)", f"{gen['generation_s']:.2f} s", "<= 10 s"),
            ("clean build of the extensions", f"{gen['clean_build_s']:.1f} s", "<= 30 s"),
        ]
    code = results["code"]
    rows.append(("generated C", f"{code['generated_c_bytes'] / 1024:.0f} KiB, {code['generated_c_lines']} lines", ""))
    for name, count in code["operation_counts"].items():
        rows.append((f"operations: {name}", str(count), ""))
    return bench.format_table(rows)


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
        print(f"[bench] kernel, reference and simulation loop, {preset} ...", flush=True)
        results["kernel"][preset] = bench.kernel_figures(preset, args.batch)
        results["kernel"][preset].update(bench.simulation_figures(preset))
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
