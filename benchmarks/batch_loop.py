"""The batch functions against the single-state ones (``python -m benchmarks.batch_loop``, and in
``make bench``): per-state time on one core of each batched function in the same C loop
(``batch_loop.c``: the single-state function row by row, then the batch function, one run), built
once per instruction-set path of the portable build this CPU runs (with that path's flags)
and once with ``-march=native``, side by side; the batch call from Python on one and two
threads; CasADi's generated C and ``casadi.Function.map(N, "thread", 2)`` for inverse dynamics
on the same states (skipped without casadi); and the targets of the batch path marked met or
missed.  The derivative functions against the functions they differentiate are timed in
alternation in the thread's CPU time, which the machine's other work does not lengthen, and
quoted as the median ratio with its quartiles: met, missed, or unsettled when the quartiles
straddle the target."""

from __future__ import annotations

import argparse
import pathlib
import subprocess
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import stewart
from stewart.cli import bench

from .peers.common import compile_c, param_vector

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent

#: Functions timed, in batch_loop.c's order (the derivative functions on its first ND states).
FUNCTIONS = ("inverse_dynamics", "forward_dynamics", "mass_matrix", "coriolis_vector", "gravity_vector",
             "inverse_dynamics_derivatives", "forward_dynamics_derivatives", "rk4_step_derivatives", "regressor")
#: Most microseconds per state (one core) of each batch function.
US_PER_STATE = {"inverse_dynamics": 0.10, "forward_dynamics": 0.15, "mass_matrix": 0.08, "coriolis_vector": 0.08,
                "gravity_vector": 0.08}
#: Least speed-up of the batch function over the row-by-row loop.
SPEEDUP = {"inverse_dynamics": 3.5}
#: Least inverse-dynamics states per second from Python on both cores, and the least speed-up
#: of two threads over one, for a batch of at least 10^4 states.
BOTH_CORES_STATES_PER_S = 18e6
THREAD_SPEEDUP = 1.8
#: Most a batch call from Python may take over the C loop's batch function.
PYTHON_OVERHEAD = 1.10
#: Most the portable build's dispatched path may take over a -march=native build.
NATIVE_RATIO = 1.05
#: Most the regressor (6 x 32) may take over inverse dynamics, a state each, batch functions.
REGRESSOR_RATIO = 4.0
#: Most each derivative function may take over the function it differentiates, a state each,
#: batch functions (issue 39), on each of the paths named.
DERIVATIVE_RATIO = 5.0
DERIVATIVE_PATHS = ("avx2", "avx512")
#: The -march=native build's column.
NATIVE = "native"
#: Most the batch inverse dynamics may take over CasADi's generated C compiled for the same
#: path (same flags, same C loop), per path.
CASADI_RATIO = {"avx2": 0.10}


def paths() -> dict:
    """{path: compiler flags} of every path of the portable build this CPU runs (its flags in
    ``stewart.build_info()``), and of a ``-march=native`` build."""
    info = stewart.build_info()
    out = {name: info["flags"][name].split() for name in info["supported"]}
    out.setdefault(NATIVE, ["-O3", *stewart.io.capi.c_flags(), "-march=native"])
    return out


def c_loop(exe, data, repeats: int) -> dict:
    """{function: (scalar s/state, batch s/state, worst relative difference, failures)} of the
    C loop ``exe`` on the states of ``data``, the lanes, and "ratios": {derivative function:
    (the function it differentiates, median, lower and upper quartile of the ratio of their
    batch times)}."""
    lines = subprocess.run([str(exe), str(data), str(repeats)], capture_output=True, text=True,
                           check=True).stdout.split("\n")
    out = {"lanes": int(lines[0].split()[1]), "ratios": {}}
    for line in lines[1:]:
        if line.startswith("ratio "):
            _, name, of, median, low, high = line.split()
            out["ratios"][name] = (of, float(median), float(low), float(high))
        elif line:
            name, scalar, batch, worst, fails_scalar, fails_batch = line.split()
            out[name] = (float(scalar), float(batch), float(worst), int(fails_scalar) + int(fails_batch))
    return out


def c_loops(params, n: int, flags: dict, repeats: int = 7) -> dict:
    """{path: `c_loop` figures} of the C loop on n states, built with each path's ``flags``
    (side by side), run one after the other."""
    x, xd, xdd = bench.states(params, n)
    with tempfile.TemporaryDirectory() as tmp:
        data = pathlib.Path(tmp) / "in.bin"
        pvec = param_vector(params)
        data.write_bytes(np.int64(n).tobytes() + np.int64(len(pvec)).tobytes() + pvec.tobytes()
                         + np.ascontiguousarray(np.hstack([x, xd, xdd]), dtype=np.float64).tobytes())
        exes = {name: pathlib.Path(tmp) / f"batch_loop_{name}" for name in flags}
        with ThreadPoolExecutor(2) as pool:
            list(pool.map(lambda name: compile_c([HERE / "batch_loop.c", *stewart.c_sources()],
                                                 exes[name], include=[ROOT / "generated"], extra=flags[name]),
                          flags))
        return {name: c_loop(exe, data, repeats) for name, exe in exes.items()}


def casadi_figures(params, n: int, flags: dict, repeats: int = 7) -> dict:
    """CasADi's inverse dynamics on the same n states: its generated C in the C loop of the
    peers (``peers/driver.c``) compiled with each path's ``flags`` (``c_loop_s``: {path: s}),
    and ``Function.map(n, "thread", 2)`` from Python, s a state; ``{"skipped": why}``
    without casadi."""
    try:
        import casadi as ca
    except ImportError:
        return {"skipped": "casadi is not installed"}
    from .peers import casadi_model, cdriver

    x, xd, xdd = bench.states(params, n)
    pvec = param_vector(params)
    funcs = casadi_model.build(general=not params.is_axisymmetric)
    f_id = funcs["inverse_dynamics"]
    mapped = f_id.map(n, "thread", 2)
    xT, xdT, xddT = (np.ascontiguousarray(a.T) for a in (x, xd, xdd))
    out = {"casadi_version": ca.__version__,
           "map_thread2_s": bench.median_time(lambda: mapped(xT, xdT, xddT, pvec), 1, 3) / n}
    with tempfile.TemporaryDirectory(prefix="stewart-casadi-") as tmp:
        gen = ca.CodeGenerator("casadi_stewart.c", {"with_header": True})
        gen.add(f_id)
        gen.add(funcs["forward_dynamics"])  # the driver links both
        gen.generate(tmp + "/")
        out["c_loop_s"] = {}
        for path, path_flags in flags.items():
            work = pathlib.Path(tmp) / path
            work.mkdir()
            exe, _ = cdriver.build_casadi(work, pathlib.Path(tmp) / "casadi_stewart.c", extra=path_flags)
            out["c_loop_s"][path], _ = cdriver.run(exe, "id", pvec, x, xd, xdd, repeats)
    return out


def figures(preset: str = "narayan2017", n: int = 100_000) -> dict:
    """The C loop's figures per path, the Python batch call of inverse dynamics on one and two
    threads, CasADi's on the same states."""
    plat = stewart.Platform.preset(preset)
    both = stewart.Platform.preset(preset, threads=2)
    flags = paths()
    fig = {"paths": c_loops(plat.params, n, flags), "dispatched": stewart.build_info()["simd"], "states": n}
    fig["c_loop"] = fig["paths"][fig["dispatched"]]
    x, xd, xdd = bench.states(plat.params, n)
    fig["python_inverse_dynamics_us"] = bench.median_time(lambda: plat.inverse_dynamics(x, xd, xdd), 3) / n * 1e6
    fig["python_threads2_inverse_dynamics_us"] = (
        bench.median_time(lambda: both.inverse_dynamics(x, xd, xdd), 3) / n * 1e6)
    fig["casadi"] = casadi_figures(plat.params, n, flags)
    return fig


def _mark(ok: bool) -> str:
    return "met" if ok else "MISSED"


def rows(fig: dict) -> list[tuple[str, ...]]:
    """(measure, row by row, the batch function on each path, target, met) rows of the figures:
    the targets are those of the dispatched path."""
    loop, names = fig["c_loop"], list(fig["paths"])
    out = []
    for name in FUNCTIONS:
        scalar, batch, worst, failures = loop[name]
        speedup = scalar / batch
        cells = [f"{fig['paths'][path][name][1] * 1e6:.3f} us ({scalar / fig['paths'][path][name][1]:.1f}x)"
                 for path in names]
        if name in US_PER_STATE:
            ok = batch * 1e6 <= US_PER_STATE[name] and speedup >= SPEEDUP.get(name, 0.0)
            target = f"<= {US_PER_STATE[name]:.2f} us" + (f", >= {SPEEDUP[name]}x" if name in SPEEDUP else "")
            mark = _mark(ok)
        else:
            target = mark = ""
        out.append((f"{name}, C loop, 1 core (max diff {worst:.0e}, {failures} failed rows)",
                    f"{scalar * 1e6:.3f} us", *cells, target, mark))
    blank = [""] * len(names)
    ratio = loop["regressor"][1] / loop["inverse_dynamics"][1]
    out.append(("regressor over inverse_dynamics, batch, 1 core", "", *blank[:-1], f"{ratio:.2f}x",
                f"<= {REGRESSOR_RATIO:.0f}x", _mark(ratio <= REGRESSOR_RATIO)))
    out += derivative_rows(fig)
    if NATIVE in fig["paths"] and fig["dispatched"] != NATIVE:
        native = fig["paths"][NATIVE]["inverse_dynamics"][1]
        ratio = loop["inverse_dynamics"][1] / native
        out.append((f"inverse_dynamics, {fig['dispatched']} (dispatched) over -march=native", "",
                    *blank[:-1], f"{ratio:.2f}x", f"<= {NATIVE_RATIO:.2f}x", _mark(ratio <= NATIVE_RATIO)))
    one, two = fig["python_inverse_dynamics_us"], fig["python_threads2_inverse_dynamics_us"]
    c_batch = loop["inverse_dynamics"][1] * 1e6
    out.append(("inverse_dynamics, batch from Python, 1 thread", "", *blank[:-1],
                f"{one:.3f} us ({one / c_batch:.2f}x C loop)",
                f"<= {PYTHON_OVERHEAD:.2f}x C loop", _mark(one <= PYTHON_OVERHEAD * c_batch)))
    out.append(("inverse_dynamics, batch from Python, 2 threads", "", *blank[:-1],
                f"{two:.3f} us, {1 / two:.1f} M states/s ({one / two:.2f}x 1 thread)",
                f">= {BOTH_CORES_STATES_PER_S / 1e6:.0f} M/s, >= {THREAD_SPEEDUP}x",
                _mark(1e6 / two >= BOTH_CORES_STATES_PER_S and one / two >= THREAD_SPEEDUP)))
    peer = fig.get("casadi", {})
    if "skipped" in peer:
        out.append((f"inverse_dynamics, CasADi: skipped ({peer['skipped']})", "", *blank, "", ""))
    elif peer:
        cells = [f"{peer['c_loop_s'][path] * 1e6:.3f} us (ours {fig['paths'][path]['inverse_dynamics'][1] / peer['c_loop_s'][path]:.3f}x)"
                 for path in names]
        out.append((f"inverse_dynamics, CasADi {peer['casadi_version']} generated C, same flags, C loop, 1 core", "",
                    *cells, "", ""))
        for path, bound in CASADI_RATIO.items():
            if path in names:
                ratio = fig["paths"][path]["inverse_dynamics"][1] / peer["c_loop_s"][path]
                out.append((f"inverse_dynamics, {path}: ours over CasADi's C for {path}", "", *blank[:-1],
                            f"{ratio:.3f}x", f"<= {bound:.2f}x", _mark(ratio <= bound)))
        us = peer["map_thread2_s"] * 1e6
        out.append((f"inverse_dynamics, CasADi {peer['casadi_version']} Function.map(N, \"thread\", 2)", "",
                    *blank[:-1], f"{us:.3f} us (ours: {two:.3f} us, {us / two:.1f}x)", "", ""))
    return out


def derivative_verdict(low: float, high: float, bound: float = DERIVATIVE_RATIO) -> str:
    """"met" when the quartiles of a ratio lie at or below `bound`, "MISSED" when above it,
    "unsettled" when they straddle it."""
    return "met" if high <= bound else "MISSED" if low > bound else "unsettled"


def derivative_rows(fig: dict) -> list[tuple[str, ...]]:
    """A row per derivative function: the median ratio of its batch time per state over that of
    the function it differentiates on each path, with their quartiles, timed in alternation in
    one run (the C loop's "ratios"); the target on DERIVATIVE_PATHS, the worst verdict of those
    paths (`derivative_verdict`)."""
    out = []
    for name, (of, _, _, _) in fig["c_loop"]["ratios"].items():
        figures = {path: fig["paths"][path]["ratios"][name][1:] for path in fig["paths"]}
        cells = [f"{m:.2f}x ({lo:.2f}-{hi:.2f})" for m, lo, hi in figures.values()]
        verdicts = [derivative_verdict(lo, hi) for path, (_, lo, hi) in figures.items() if path in DERIVATIVE_PATHS]
        mark = next((v for v in ("MISSED", "unsettled") if v in verdicts), "met") if verdicts else ""
        out.append((f"{name} over {of}, batch, per state (quartiles; CPU time, in alternation)", "", *cells,
                    f"<= {DERIVATIVE_RATIO:.0f}x on {', '.join(DERIVATIVE_PATHS)}", mark))
    return out


def format_rows(fig: dict) -> str:
    header = ("measure", "row by row", *(f"{path} ({fig['paths'][path]['lanes']} lanes)" for path in fig["paths"]),
              "target", "")
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
