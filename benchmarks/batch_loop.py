"""The batch functions against the single-state ones (``python -m benchmarks.batch_loop``, and in
``make bench``): per-state time on one core of each batched function in the same C loop
(``batch_loop.c``: the single-state function row by row, or the batch function), compiled
with one copy of the model into a shared library per instruction-set path of the portable
build this CPU runs (with that path's flags) and one with ``-march=native``; every copy is
loaded into this process (ctypes) and timed in interleaved rounds (:mod:`stewart.cli.interleaved`).
Beside them: the batch call from Python on one and two threads, and CasADi's generated C for
inverse dynamics in the same kind of loop (``casadi_loop.c``, compiled per path; skipped
without casadi). Each target is met, missed or unsettled by the dispatched path's figures."""

from __future__ import annotations

import argparse
import ctypes
import pathlib
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import stewart
from stewart.cli import bench
from stewart.cli.interleaved import REFERENCE, Measurement, Target

from .peers.common import compile_c, param_vector

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent

#: Functions timed, in batch_loop.c's order.
FUNCTIONS = ("inverse_dynamics", "forward_dynamics", "mass_matrix", "coriolis_vector", "gravity_vector",
             "inverse_dynamics_derivatives", "forward_dynamics_derivatives", "rk4_step_derivatives", "regressor")
#: States a round times of each function, as the batch function and row by row: a call of
#: about 0.1-0.5 ms on one core (a longer one is interrupted by the machine's other jobs
#: more often).
ROUND_STATES = {name: 64 if name == "rk4_step_derivatives" else 256 if "derivatives" in name else 1024
                for name in FUNCTIONS}
SCALAR_STATES = {name: 16 if name == "rk4_step_derivatives" else 64 if "derivatives" in name else 256
                 for name in FUNCTIONS}
#: States of the correctness check of the batch functions against the row-by-row loop (the
#: derivative functions: the first 10^4 of them).
DERIVATIVE_CHECK = 10_000
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
#: The -march=native build's column.
NATIVE = "native"
#: Most the batch inverse dynamics may take over CasADi's generated C compiled for the same
#: path (same flags, same kind of loop), per path.
CASADI_RATIO = {"avx2": 0.10}
#: States of CasADi's loop in a round (about 5 us a state).
CASADI_STATES = 256


def paths() -> dict:
    """{path: compiler flags} of every path of the portable build this CPU runs (its flags in
    ``stewart.build_info()``), and of a ``-march=native`` build."""
    info = stewart.build_info()
    out = {name: info["flags"][name].split() for name in info["supported"]}
    out.setdefault(NATIVE, ["-O3", *stewart.io.capi.c_flags(), "-march=native"])
    return out


def _pointer(a: np.ndarray):
    return a.ctypes.data_as(ctypes.c_void_p)


class Copy:
    """One copy of the model with the C loop, loaded from its shared library: each function
    row by row or as the batch function on the given states."""

    def __init__(self, library: pathlib.Path, params: np.ndarray, x, xd, xdd, tau):
        self.lib = ctypes.CDLL(str(library))
        self.lib.batch_loop_run.restype = ctypes.c_int
        self.lib.batch_loop_run.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_void_p, ctypes.c_size_t] + [
            ctypes.c_void_p] * 5
        self.lib.batch_loop_worst.restype = ctypes.c_double
        self.lib.batch_loop_worst.argtypes = [ctypes.c_int, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
        self.lanes = self.lib.batch_loop_lanes()
        self.params, self.x, self.xd, self.xdd, self.tau = params, x, xd, xdd, tau
        width = max(self.lib.batch_loop_width(f) for f in range(len(FUNCTIONS)))
        self.out = np.empty(width * len(x))
        self.status = np.empty(len(x), dtype=np.intc)

    def third(self, name: str) -> np.ndarray:
        """The third input of ``name``: the forces for forward dynamics and the RK4 step."""
        return self.tau if name in ("forward_dynamics", "forward_dynamics_derivatives",
                                    "rk4_step_derivatives") else self.xdd

    def run(self, name: str, batch: bool, n: int, out: np.ndarray | None = None) -> int:
        """``name`` on the first ``n`` states, the rows that failed."""
        return self.lib.batch_loop_run(FUNCTIONS.index(name), int(batch), _pointer(self.params), n, _pointer(self.x),
                                       _pointer(self.xd), _pointer(self.third(name)),
                                       _pointer(self.out if out is None else out), _pointer(self.status))

    def timed(self, name: str, batch: bool):
        """A callable running ``name`` on its :data:`ROUND_STATES` states (row by row: its
        :data:`SCALAR_STATES`), its arguments converted once."""
        n = (ROUND_STATES if batch else SCALAR_STATES)[name]
        args = (FUNCTIONS.index(name), int(batch), _pointer(self.params), n, _pointer(self.x),
                _pointer(self.xd), _pointer(self.third(name)), _pointer(self.out), _pointer(self.status))
        run = self.lib.batch_loop_run
        return lambda: run(*args)

    def check(self, name: str, n: int) -> tuple[float, int]:
        """The worst difference of the batch function's outputs from the row-by-row loop's on
        the first ``n`` states (relative to each row's largest output), and the rows either
        reported failed."""
        a, b = np.empty_like(self.out), np.empty_like(self.out)
        failures = self.run(name, False, n, a) + self.run(name, True, n, b)
        return float(self.lib.batch_loop_worst(FUNCTIONS.index(name), n, _pointer(a), _pointer(b))), failures


def build(flags: dict, tmp: pathlib.Path) -> dict:
    """{path: shared library of the C loop with the model compiled with its flags}, compiled
    side by side."""
    libraries = {name: tmp / f"batch_loop_{name}.so" for name in flags}
    with ThreadPoolExecutor(2) as pool:
        list(pool.map(lambda name: compile_c([HERE / "batch_loop.c", *stewart.c_sources()], libraries[name],
                                             shared=True, include=[ROOT / "generated"],
                                             extra=[*flags[name], "-Wl,-Bsymbolic"]), flags))
    return libraries


def casadi_library(params, flags: dict, tmp: pathlib.Path) -> dict:
    """{path: CasADi's inverse dynamics in its C loop, compiled with the path's flags, a
    callable on :data:`CASADI_STATES` rows}, and its version; ``{"skipped": why}`` without
    casadi."""
    try:
        import casadi as ca
    except ImportError:
        return {"skipped": "casadi is not installed"}
    from .peers import casadi_model

    funcs = casadi_model.build(general=not params.is_axisymmetric)
    gen = ca.CodeGenerator("casadi_stewart.c", {"with_header": True})
    gen.add(funcs["inverse_dynamics"])
    gen.generate(str(tmp) + "/")
    libraries = {name: tmp / f"casadi_loop_{name}.so" for name in flags}
    with ThreadPoolExecutor(2) as pool:
        list(pool.map(lambda name: compile_c([HERE / "casadi_loop.c", tmp / "casadi_stewart.c"], libraries[name],
                                             shared=True, include=[tmp], extra=[*flags[name], "-Wl,-Bsymbolic"]),
                      flags))
    return {"casadi_version": ca.__version__, "libraries": libraries}


def as_dict(m: Measurement) -> dict:
    """A measurement as the JSON records it."""
    return {"median": m.median, "low": m.low, "high": m.high, "rounds": m.rounds, "gauge": m.gauge}


def of_dict(d: dict) -> Measurement:
    return Measurement(d["median"], d["low"], d["high"], d["rounds"], (), d.get("gauge"))


def figures(preset: str = "narayan2017", n: int = 100_000, rounds: bench.Rounds | None = None) -> dict:
    """The C loop's figures per path, the Python batch call of inverse dynamics on one and two
    threads, CasADi's C on the same states; every figure a :class:`Measurement` (as a dict),
    all measured together."""
    rounds = rounds or bench.Rounds()
    plat = stewart.Platform.preset(preset)
    both = stewart.Platform.preset(preset, threads=2)
    x, xd, xdd = bench.states(plat.params, n)
    tau = plat.inverse_dynamics(x, xd, xdd)
    pvec = np.ascontiguousarray(param_vector(plat.params))
    flags = paths()
    dispatched = stewart.build_info()["simd"]
    fig: dict = {"dispatched": dispatched, "states": n, "paths": list(flags)}
    us = REFERENCE.seconds * 1e6
    with tempfile.TemporaryDirectory(prefix="stewart-batch-loop-") as tmp:
        tmp = pathlib.Path(tmp)
        copies = {name: Copy(lib, pvec, x, xd, xdd, tau) for name, lib in build(flags, tmp).items()}
        peer = casadi_library(plat.params, flags, tmp)
        fig["lanes"] = {name: copy.lanes for name, copy in copies.items()}
        here = copies[dispatched]
        fig["check"] = {name: dict(zip(("worst", "failures"), here.check(
            name, min(n, DERIVATIVE_CHECK) if "derivatives" in name else n))) for name in FUNCTIONS}
        for name in FUNCTIONS:
            m = ROUND_STATES[name]
            rounds.absolute(f"scalar {name}", here.timed(name, False), SCALAR_STATES[name])
            for path, copy in copies.items():
                target = Target(US_PER_STATE[name], True) if path == dispatched and name in US_PER_STATE else None
                rounds.add(f"batch {path} {name}", [copy.timed(name, True), rounds.one],
                           lambda t, y, m=m: t / m / y * us, target=target)
        for name, bound in SPEEDUP.items():
            rounds.ratio(f"{name}_speedup", here.timed(name, False), here.timed(name, True), SCALAR_STATES[name],
                         ROUND_STATES[name], target=Target(bound, False, "row by row"))
        rounds.ratio("regressor_ratio", here.timed("regressor", True), here.timed("inverse_dynamics", True),
                     target=Target(REGRESSOR_RATIO, True, "inverse dynamics"))
        if NATIVE in copies and dispatched != NATIVE:
            rounds.ratio("native_ratio", here.timed("inverse_dynamics", True),
                         copies[NATIVE].timed("inverse_dynamics", True),
                         target=Target(NATIVE_RATIO, True, "the -march=native copy"))
        m = ROUND_STATES["inverse_dynamics"]
        xs, xds, xdds = x[:m], xd[:m], xdd[:m]
        rounds.ratio("python_overhead", lambda: plat.inverse_dynamics(xs, xds, xdds),
                     here.timed("inverse_dynamics", True),
                     target=Target(PYTHON_OVERHEAD, True, "the C loop's batch function"))
        one, two = (lambda: plat.inverse_dynamics(x, xd, xdd)), (lambda: both.inverse_dynamics(x, xd, xdd))
        rounds.rate("python_threads2_states_per_s", two, n,
                    target=Target(BOTH_CORES_STATES_PER_S, False, "the yardstick"))
        rounds.speedup("python_threads2_speedup", one, two, target=Target(THREAD_SPEEDUP, False, "one thread"))
        if "skipped" not in peer:
            rows = np.ascontiguousarray(np.hstack([x, xd, xdd])[:CASADI_STATES])
            out = np.empty((CASADI_STATES, 6))
            for path, library in peer["libraries"].items():
                lib = ctypes.CDLL(str(library))
                lib.casadi_loop.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
                args = (_pointer(pvec), CASADI_STATES, _pointer(rows), _pointer(out))
                loop = (lambda lib=lib, args=args: lib.casadi_loop(*args))
                rounds.add(f"casadi {path}", [loop, rounds.one], lambda c, y: c / CASADI_STATES / y * us)
                rounds.ratio(f"casadi ratio {path}", copies[path].timed("inverse_dynamics", True), loop, m,
                             CASADI_STATES, target=Target(CASADI_RATIO[path], True, "CasADi's C")
                             if path in CASADI_RATIO else None)
        measured = {key: as_dict(value) for key, value in rounds.measure().items()}
    fig["scalar"] = {name: measured[f"scalar {name}"] for name in FUNCTIONS}
    fig["batch"] = {path: {name: measured[f"batch {path} {name}"] for name in FUNCTIONS} for path in flags}
    fig["targets"] = {key: measured[key] for key in (*(f"{name}_speedup" for name in SPEEDUP), "regressor_ratio",
                                                     "native_ratio", "python_overhead", "python_threads2_states_per_s",
                                                     "python_threads2_speedup") if key in measured}
    if "skipped" in peer:
        fig["casadi"] = {"skipped": peer["skipped"]}
    else:
        fig["casadi"] = {"casadi_version": peer["casadi_version"],
                         "c_loop_us": {path: measured[f"casadi {path}"] for path in flags},
                         "ratio": {path: measured[f"casadi ratio {path}"] for path in flags}}
    return fig


def _cell(d: dict, fmt: str = ".3f") -> str:
    return f"{d['median']:{fmt}}"


def _spread(d: dict, fmt: str = ".3g") -> str:
    return bench.spread_cell(of_dict(d), 1.0, fmt)


def _verdict(*judged: str) -> str:
    """One row's verdict from its targets': missed if any is, met if all are, else unsettled."""
    word = "missed" if "missed" in judged else "met" if all(v == "met" for v in judged) else "unsettled"
    return bench.VERDICTS[word]


def rows(fig: dict) -> list[tuple[str, ...]]:
    """(measure, row by row, the batch function on each path, spread, target, verdict) rows of
    the figures: the targets are those of the dispatched path."""
    names, here, t = fig["paths"], fig["dispatched"], fig["targets"]
    blank = [""] * len(names)
    out = []
    for name in FUNCTIONS:
        scalar = fig["scalar"][name]["median"]
        check = fig["check"][name]
        cells = [f"{fig['batch'][path][name]['median']:.3f} us ({scalar / fig['batch'][path][name]['median']:.1f}x)"
                 for path in names]
        spread = target = mark = ""
        if name in US_PER_STATE:
            batch = fig["batch"][here][name]
            judged = [of_dict(batch).verdict(Target(US_PER_STATE[name], True))]
            spread = f"batch {_spread(batch)}"
            target = f"<= {US_PER_STATE[name]:.2f} us"
            if name in SPEEDUP:
                speedup = t[f"{name}_speedup"]
                judged.append(of_dict(speedup).verdict(Target(SPEEDUP[name], False)))
                spread += f"; speed-up {_spread(speedup)}"
                target += f", >= {SPEEDUP[name]}x"
            mark = _verdict(*judged)
        out.append((f"{name}, C loop, 1 core (max diff {check['worst']:.0e}, {check['failures']} failed rows)",
                    f"{scalar:.3f} us", *cells, spread, target, mark))
    ratio = t["regressor_ratio"]
    out.append(("regressor over inverse_dynamics, batch, 1 core", "", *blank[:-1], f"{ratio['median']:.2f}x",
                _spread(ratio), f"<= {REGRESSOR_RATIO:.0f}x",
                _verdict(of_dict(ratio).verdict(Target(REGRESSOR_RATIO, True)))))
    if "native_ratio" in t:
        ratio = t["native_ratio"]
        out.append((f"inverse_dynamics, {here} (dispatched) over -march=native", "", *blank[:-1],
                    f"{ratio['median']:.2f}x", _spread(ratio), f"<= {NATIVE_RATIO:.2f}x",
                    _verdict(of_dict(ratio).verdict(Target(NATIVE_RATIO, True)))))
    over = t["python_overhead"]
    out.append(("inverse_dynamics, batch from Python, 1 thread", "", *blank[:-1], f"{over['median']:.2f}x C loop",
                _spread(over), f"<= {PYTHON_OVERHEAD:.2f}x C loop",
                _verdict(of_dict(over).verdict(Target(PYTHON_OVERHEAD, True)))))
    rate, speedup = t["python_threads2_states_per_s"], t["python_threads2_speedup"]
    out.append(("inverse_dynamics, batch from Python, 2 threads", "", *blank[:-1],
                f"{rate['median'] / 1e6:.1f} M states/s ({speedup['median']:.2f}x 1 thread)",
                f"{_spread({**rate, 'low': rate['low'] / 1e6, 'high': rate['high'] / 1e6})} M/s; "
                f"{_spread(speedup)}", f">= {BOTH_CORES_STATES_PER_S / 1e6:.0f} M/s, >= {THREAD_SPEEDUP}x",
                _verdict(of_dict(rate).verdict(Target(BOTH_CORES_STATES_PER_S, False)),
                         of_dict(speedup).verdict(Target(THREAD_SPEEDUP, False)))))
    peer = fig.get("casadi", {})
    if "skipped" in peer:
        out.append((f"inverse_dynamics, CasADi: skipped ({peer['skipped']})", "", *blank, "", "", ""))
    elif peer:
        cells = [f"{peer['c_loop_us'][path]['median']:.3f} us (ours {peer['ratio'][path]['median']:.3f}x)"
                 for path in names]
        out.append((f"inverse_dynamics, CasADi {peer['casadi_version']} generated C, same flags, C loop, 1 core", "",
                    *cells, "", "", ""))
        for path, bound in CASADI_RATIO.items():
            if path in names:
                ratio = peer["ratio"][path]
                out.append((f"inverse_dynamics, {path}: ours over CasADi's C for {path}", "", *blank[:-1],
                            f"{ratio['median']:.3f}x", _spread(ratio), f"<= {bound:.2f}x",
                            _verdict(of_dict(ratio).verdict(Target(bound, True)))))
    return out


def format_rows(fig: dict) -> str:
    header = ("measure", "row by row", *(f"{path} ({fig['lanes'][path]} lanes)" for path in fig["paths"]),
              "90% interval (rounds)", "target", "verdict")
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
