"""The vector batch path against the scalar one (``python -m benchmarks.batch_loop``, and in
``make bench``): per-state time on one core of each batched function in the same C loop
(``batch_loop.c``: the scalar function row by row, then the batch function, one run), the
batch call from Python on one and two threads, and the targets of the batch path marked
met or missed."""

from __future__ import annotations

import argparse
import pathlib
import subprocess
import tempfile

import numpy as np

import stewart
from stewart import bench

from .peers.common import compile_c, param_vector

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent

#: Functions timed, in batch_loop.c's order.
FUNCTIONS = ("inverse_dynamics", "forward_dynamics", "mass_matrix", "coriolis_vector", "gravity_vector")
#: Most microseconds per state (one core) of each batch function.
US_PER_STATE = {"inverse_dynamics": 0.10, "forward_dynamics": 0.15, "mass_matrix": 0.08, "coriolis_vector": 0.08,
                "gravity_vector": 0.08}
#: Least speed-up of the batch function over the scalar loop.
SPEEDUP = {"inverse_dynamics": 3.5}
#: Least inverse-dynamics states per second from Python on both cores, and the least speed-up
#: of two threads over one, for a batch of at least 10^4 states.
BOTH_CORES_STATES_PER_S = 18e6
THREAD_SPEEDUP = 1.8
#: Most a batch call from Python may take over the C loop's batch function.
PYTHON_OVERHEAD = 1.10


def c_loop(params, n: int, repeats: int = 7) -> dict:
    """{function: (scalar s/state, batch s/state, worst relative difference, failures)} of
    the C loop on n states, and the lanes."""
    x, xd, xdd = bench.states(params, n)
    with tempfile.TemporaryDirectory() as tmp:
        exe, data = pathlib.Path(tmp) / "batch_loop", pathlib.Path(tmp) / "in.bin"
        compile_c([HERE / "batch_loop.c", ROOT / "generated" / "stewart_model.c"], exe,
                  include=[ROOT / "generated"])
        pvec = param_vector(params)
        data.write_bytes(np.int64(n).tobytes() + np.int64(len(pvec)).tobytes() + pvec.tobytes()
                         + np.ascontiguousarray(np.hstack([x, xd, xdd]), dtype=np.float64).tobytes())
        lines = subprocess.run([str(exe), str(data), str(repeats)], capture_output=True, text=True,
                               check=True).stdout.split("\n")
    out = {"lanes": int(lines[0].split()[1])}
    for line in lines[1:]:
        if line:
            name, scalar, batch, worst, fails_scalar, fails_batch = line.split()
            out[name] = (float(scalar), float(batch), float(worst), int(fails_scalar) + int(fails_batch))
    return out


def figures(preset: str = "narayan2017", n: int = 100_000) -> dict:
    """The C loop's figures, the Python batch call of inverse dynamics on one and two threads."""
    plat = stewart.Platform.preset(preset)
    both = stewart.Platform.preset(preset, threads=2)
    fig = {"c_loop": c_loop(plat.params, n), "states": n}
    x, xd, xdd = bench.states(plat.params, n)
    fig["python_inverse_dynamics_us"] = bench.median_time(lambda: plat.inverse_dynamics(x, xd, xdd), 3) / n * 1e6
    fig["python_threads2_inverse_dynamics_us"] = (
        bench.median_time(lambda: both.inverse_dynamics(x, xd, xdd), 3) / n * 1e6)
    return fig


def _mark(ok: bool) -> str:
    return "met" if ok else "MISSED"


def rows(fig: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, scalar, vector, target, met) rows of the figures."""
    loop, out = fig["c_loop"], []
    for name in FUNCTIONS:
        scalar, batch, worst, failures = loop[name]
        speedup = scalar / batch
        ok = batch * 1e6 <= US_PER_STATE[name] and speedup >= SPEEDUP.get(name, 0.0)
        target = f"<= {US_PER_STATE[name]:.2f} us" + (f", >= {SPEEDUP[name]}x" if name in SPEEDUP else "")
        out.append((f"{name}, C loop, 1 core (max diff {worst:.0e}, {failures} failed rows)",
                    f"{scalar * 1e6:.3f} us", f"{batch * 1e6:.3f} us ({speedup:.1f}x)", target, _mark(ok)))
    one, two = fig["python_inverse_dynamics_us"], fig["python_threads2_inverse_dynamics_us"]
    c_batch = loop["inverse_dynamics"][1] * 1e6
    out.append(("inverse_dynamics, batch from Python, 1 thread", "", f"{one:.3f} us ({one / c_batch:.2f}x C loop)",
                f"<= {PYTHON_OVERHEAD:.2f}x C loop", _mark(one <= PYTHON_OVERHEAD * c_batch)))
    out.append(("inverse_dynamics, batch from Python, 2 threads", "",
                f"{1 / two:.1f} M states/s ({one / two:.2f}x 1 thread)",
                f">= {BOTH_CORES_STATES_PER_S / 1e6:.0f} M/s, >= {THREAD_SPEEDUP}x",
                _mark(1e6 / two >= BOTH_CORES_STATES_PER_S and one / two >= THREAD_SPEEDUP)))
    return out


def format_rows(fig: dict) -> str:
    header = ("measure", "scalar", f"vector ({fig['c_loop']['lanes']} lanes)", "target", "")
    table = [header] + rows(fig)
    widths = [max(len(r[k]) for r in table) for k in range(len(header))]
    return "\n".join("| " + " | ".join(c.ljust(w) for c, w in zip(r, widths)) + " |" for r in table)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.batch_loop", description=__doc__)
    parser.add_argument("--preset", default="narayan2017")
    parser.add_argument("--states", type=int, default=100_000)
    args = parser.parse_args(argv)
    print(format_rows(figures(args.preset, args.states)))


if __name__ == "__main__":
    main()
