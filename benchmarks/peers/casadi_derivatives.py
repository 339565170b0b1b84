"""CasADi's derivatives of its own model against our exact derivatives, on identical
states, in one run (``python -m benchmarks``).

What a CasADi user writes: ``ca.jacobian`` of the SX model of :mod:`.casadi_model`, for
``tau`` with ``dtau/d(x, xdot, xddot)`` and for ``xddot`` with
``dxddot/d(x, xdot, tau)`` (each a 6 x 18 Jacobian, as ours returns them). Each is one
``casadi.Function`` whose output is the value followed by the Jacobian, column-major. It
is timed

* from Python: one call (CasADi's SX virtual machine) and ``.map(N)`` per state;
* as generated C compiled with our flags (-O3 -march=native) into the C driver loop
  (``driver.c``), under a compile-time cap: a compilation still running at the cap is
  stopped and reported as "did not finish".

Ours: ``Platform.inverse_dynamics_derivatives`` and ``forward_dynamics_derivatives``, one
call and a batch (the C loop behind the Python API).
"""

from __future__ import annotations

import pathlib
import subprocess
import tempfile
import time

import numpy as np

import stewart
from stewart.cli import bench
from stewart.oracles.physics import relative_error

from . import casadi_model, cdriver
from .common import param_vector

#: (our method, CasADi function name, the third input: differentiated with x and xdot)
FUNCTIONS = (
    ("inverse_dynamics_derivatives", "stewart_casadi_id_jac", "xdd"),
    ("forward_dynamics_derivatives", "stewart_casadi_fd_jac", "tau"),
)
#: A value (6) and its 6 x 18 Jacobian a state.
WIDTH = 6 + 6 * 18


def build(general: bool = False) -> dict:
    """``{name: casadi.Function}``: ``(x, xd, xdd or tau, p) -> [value; vec(J)]``, ``J`` the
    6 x 18 Jacobian by ``ca.jacobian`` (``vec`` stacks its columns)."""
    import casadi as ca

    s = casadi_model.symbolic_model(general)
    out = {}
    for name, c_name, third in FUNCTIONS:
        value = s["tau_id"] if third == "xdd" else s["xdd_fd"]
        jac = ca.jacobian(value, ca.vertcat(s["x"], s["xd"], s[third]))
        out[name] = ca.Function(c_name, [s["x"], s["xd"], s[third], s["p"]], [ca.vertcat(value, ca.vec(jac))])
    return out


def unpack(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(values (N, 6), Jacobians (N, 6, 18))`` from outputs ``(N, WIDTH)``."""
    rows = np.asarray(rows).reshape(-1, WIDTH)
    return rows[:, :6], np.swapaxes(rows[:, 6:].reshape(-1, 18, 6), -1, -2)


def figures(preset: str, n_batch: int = 2_000, n_map: int = 200, compile_cap_s: float = 600.0,
            repeats: int = 5) -> dict:
    """Our figures and CasADi's, per function, with their agreement (relative error of
    CasADi's Jacobians against ours) and the compile time or "did not finish"."""
    import casadi as ca

    plat = stewart.Platform.preset(preset)
    pvec = param_vector(plat.params)
    x, xd, xdd = bench.states(plat.params, n_batch, seed=1)
    tau = plat.inverse_dynamics(x, xd, xdd)
    start = time.perf_counter()
    funcs = build(general=not plat.params.is_axisymmetric)
    out: dict = {"casadi_version": ca.__version__, "build_s": time.perf_counter() - start, "states": n_batch,
                 "compile_cap_s": compile_cap_s}
    for name, c_name, third in FUNCTIONS:
        fn = funcs[name]
        ours = getattr(plat, name)
        args = (x, xd, xdd if third == "xdd" else tau)
        one = tuple(a[0] for a in args)
        fig = {"n_instructions": int(fn.n_instructions())}
        fig["ours_single_us"] = bench.median_time(lambda: ours(*one), 2000) * 1e6
        fig["ours_batch_us"] = bench.median_time(lambda: ours(*args), 1, repeats) / n_batch * 1e6
        fig["python_single_us"] = bench.median_time(lambda: fn(*one, pvec), 20, repeats) * 1e6
        mapped = fn.map(n_map, "serial")
        columns = [np.ascontiguousarray(a[:n_map].T) for a in args]
        fig["python_map_us"] = bench.median_time(lambda: mapped(*columns, pvec), 1, repeats) / n_map * 1e6
        exact = ours(*args)
        want = np.concatenate(exact[1:], axis=-1)
        value, jac = unpack(np.asarray(mapped(*columns, pvec)).T)
        fig["value_rel_error"] = relative_error(value, exact[0][:n_map])
        fig["jacobian_rel_error"] = relative_error(jac, want[:n_map])
        fig.update(_compiled(fn, c_name, pvec, args, want, compile_cap_s, repeats))
        out[name] = fig
    return out


def _compiled(fn, c_name: str, pvec, args, want, cap: float, repeats: int) -> dict:
    """CasADi's generated C of ``fn`` in the C driver loop, or why not."""
    import casadi as ca

    with tempfile.TemporaryDirectory(prefix="stewart-casadi-jac-") as tmp:
        gen = ca.CodeGenerator("casadi_stewart.c", {"with_header": True})
        gen.add(fn)
        start = time.perf_counter()
        gen.generate(tmp + "/")
        fig = {"generate_s": time.perf_counter() - start}
        source = pathlib.Path(tmp) / "casadi_stewart.c"
        fig["generated_c_bytes"] = source.stat().st_size
        print(f"[bench] compiling CasADi's {c_name} ({fig['generated_c_bytes'] / 2**20:.1f} MiB of C, "
              f"cap {cap:g} s) ...", flush=True)
        try:
            exe, fig["compile_s"] = cdriver.build_casadi(tmp, source, function=c_name, width=WIDTH, timeout=cap)
        except subprocess.TimeoutExpired:
            fig["compile_s"] = None
            fig["did_not_finish"] = f"did not finish compiling in {cap:g} s"
            return fig
        seconds, rows = cdriver.run(exe, "id", pvec, *args, repeats=repeats, width=WIDTH)
    fig["c_loop_us"] = seconds * 1e6
    fig["c_loop_jacobian_rel_error"] = relative_error(unpack(rows)[1], want)
    return fig
