"""sympy's own route to compiled code, on our generator's expressions.

``codegen/`` derives the model as a graph of named intermediate symbols. Here
the inverse-dynamics outputs (``W = M xdd + V xd + G`` and ``J_C``) and the
forward-dynamics outputs (upper triangle of ``M_t``, ``rhs = J_C^T tau - V xd - G``,
``J_A^-1``) are substituted back into whole sympy expressions (a shared DAG, nothing is
expanded) and handed to

* ``sympy.utilities.autowrap.autowrap`` with the Cython backend and sympy's C99 code
  printer with common-subexpression elimination (``C99CodeGen(cse=True)``), and
* PyDy's ``CythonMatrixGenerator`` (``pydy.codegen.cython_code``; it runs sympy's cse),

both compiled with our flags (``-O3 -march=native``). The small linear solves
(``J_C^T tau = W``; ``M_t y = rhs``, ``xdd = [y_v; J_A^-1 y_w]``) are done by numpy, as a
user of these tools would. Parameters are runtime inputs (the 51-vector ``p``).
"""

from __future__ import annotations

import os
import pathlib
import sys
import tempfile
import time

import numpy as np

from .common import CFLAGS, PARAM_COUNT

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent


def _derivation():
    """codegen's kinematics (the symbols, the Euler maps' kernel) and dynamics (the kernels)."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from codegen import dynamics, kinematics

    return kinematics, dynamics


def _param_symbols(kinematics):
    """The parameter symbols in ``stewart_params`` order (the flat vector of ``param_vector``)."""
    syms = [symbol for symbol, _ in kinematics.PARAMS.members()]
    assert len(syms) == PARAM_COUNT
    return syms


def _expand_outputs(kernel) -> dict:
    """The kernel's outputs as whole expressions of the inputs (definitions substituted)."""
    import sympy as sp

    full = {}
    for sym, expr in kernel.graph.defs:
        full[sym] = sp.sympify(expr).xreplace(full)
    return {name: [sp.sympify(e).xreplace(full) for e in exprs] for name, exprs in kernel.outputs}


def expressions() -> dict:
    """``{'id': (inputs, [W (6), JC (36)]), 'fd': (inputs, [Mt upper (21), rhs (6), JAinv (9)])}``,
    inputs being four lists of symbols (x, xd, xdd or tau, p). Axisymmetric legs."""
    kinematics, dynamics = _derivation()
    p = _param_symbols(kinematics)
    kid = _expand_outputs(dynamics.inverse_dynamics_kernel("axisym"))
    mt = _expand_outputs(dynamics.twist_mass_matrix_kernel("axisym"))["Mt"]
    at_rest = {s: 0 for s in kinematics.XDD}  # W at xdd = 0 is V xd + G
    w0 = [e.xreplace(at_rest) for e in kid["W"]]
    rhs = [sum(kid["JC"][6 * k + i] * kinematics.TAU[k] for k in range(6)) - w0[i] for i in range(6)]
    return {
        "id": ([list(kinematics.X), list(kinematics.XD), list(kinematics.XDD), p], [kid["W"], kid["JC"]]),
        "fd": ([list(kinematics.X), list(kinematics.XD), list(kinematics.TAU), p],
               [[mt[6 * i + j] for i in range(6) for j in range(i, 6)], rhs,
                _expand_outputs(kinematics.euler_maps_kernel())["JAinv"]]),
    }


def _solve_id(w, jc):
    return np.linalg.solve(jc.reshape(6, 6).T, w.ravel())


_UPPER = np.triu_indices(6)


def _solve_fd(mt_upper, rhs, ja_inv):
    mt = np.zeros((6, 6))
    mt[_UPPER] = mt_upper.ravel()
    mt = mt + np.triu(mt, 1).T
    y = np.linalg.solve(mt, rhs.ravel())
    return np.concatenate([y[:3], ja_inv.reshape(3, 3) @ y[3:]])


def build_autowrap(exprs: dict, tmp: str) -> dict:
    """Compile both kernels with autowrap (Cython backend); returns callables
    ``f(x, xd, u, p) -> (6,)`` and the generation + compile time."""
    import sympy as sp
    from sympy.utilities.autowrap import autowrap
    from sympy.utilities.codegen import C99CodeGen

    out = {}
    for kind, (inputs, outputs) in exprs.items():
        mats = [sp.MatrixSymbol(n, len(v), 1) for n, v in zip(("a", "b", "c", "p"), inputs)]
        subs = {s: m[k, 0] for m, v in zip(mats, inputs) for k, s in enumerate(v)}
        flat = sp.Matrix([e.xreplace(subs) for group in outputs for e in group])
        start = time.perf_counter()
        fn = autowrap(flat, backend="cython", args=mats, tempdir=os.path.join(tmp, f"autowrap_{kind}"),
                      code_gen=C99CodeGen(project="stewart", cse=True), extra_compile_args=list(CFLAGS))
        seconds = time.perf_counter() - start
        sizes = np.cumsum([len(g) for g in outputs])[:-1]
        if kind == "id":
            def call(a, b, c, p, fn=fn, sizes=sizes):
                r = fn(a.reshape(6, 1), b.reshape(6, 1), c.reshape(6, 1), p.reshape(-1, 1)).ravel()
                return _solve_id(*np.split(r, sizes))
        else:
            def call(a, b, c, p, fn=fn, sizes=sizes):
                r = fn(a.reshape(6, 1), b.reshape(6, 1), c.reshape(6, 1), p.reshape(-1, 1)).ravel()
                return _solve_fd(*np.split(r, sizes))
        out[kind] = (call, fn, seconds)
    return out


def build_pydy(exprs: dict, tmp: str) -> dict:
    """Compile both kernels with PyDy's CythonMatrixGenerator; callables as above."""
    import sympy as sp
    from pydy.codegen.cython_code import CythonMatrixGenerator

    out = {}
    old = os.environ.get("CFLAGS")
    os.environ["CFLAGS"] = " ".join(CFLAGS)
    try:
        for kind, (inputs, outputs) in exprs.items():
            start = time.perf_counter()
            gen = CythonMatrixGenerator(inputs, [sp.Matrix(g) for g in outputs], prefix=f"stewart_pydy_{kind}")
            fn = gen.compile(tmp_dir=os.path.join(tmp, f"pydy_{kind}"))
            seconds = time.perf_counter() - start
            bufs = [np.empty(len(g)) for g in outputs]
            if kind == "id":
                def call(a, b, c, p, fn=fn, bufs=bufs):
                    return _solve_id(*fn(a, b, c, p, *bufs))
            else:
                def call(a, b, c, p, fn=fn, bufs=bufs):
                    return _solve_fd(*fn(a, b, c, p, *bufs))
            out[kind] = (call, fn, seconds)
    finally:
        if old is None:
            os.environ.pop("CFLAGS", None)
        else:
            os.environ["CFLAGS"] = old
    return out


def figures(preset: str = "narayan2017", n_check: int = 200) -> dict:
    """Generation + compile time, single-call speed (with and without numpy's solve) and
    agreement of each available sympy route, next to our single call on the same state."""
    import stewart
    from stewart.cli import bench

    from .common import param_vector, peer_available, relative_error

    plat = stewart.Platform.preset(preset)
    if not plat.params.is_axisymmetric:
        raise ValueError("the sympy routes use the axisymmetric-leg expressions")
    pvec = param_vector(plat.params)
    x, xd, xdd = bench.states(plat.params, n_check, seed=2)
    tau = plat.inverse_dynamics(x, xd, xdd)
    start = time.perf_counter()
    exprs = expressions()
    out = {"expressions_s": time.perf_counter() - start,
           "ours_single_id_us": bench.median_time(lambda: plat.inverse_dynamics(x[0], xd[0], xdd[0]), 20000) * 1e6,
           "ours_single_fd_us": bench.median_time(lambda: plat.forward_dynamics(x[0], xd[0], tau[0]), 20000) * 1e6}
    routes = {"autowrap": build_autowrap}
    if peer_available("pydy"):
        routes["pydy"] = build_pydy
    else:
        out["skipped"] = ["pydy (not installed)"]
    with tempfile.TemporaryDirectory(prefix="stewart-sympy-") as tmp:
        for name, builder in routes.items():
            built = builder(exprs, tmp)
            fig = {"generate_and_compile_s": sum(v[2] for v in built.values())}
            (id_call, id_raw, _), (fd_call, fd_raw, _) = built["id"], built["fd"]
            fig["single_id_us"] = bench.median_time(lambda: id_call(x[0], xd[0], xdd[0], pvec), 2000) * 1e6
            fig["single_fd_us"] = bench.median_time(lambda: fd_call(x[0], xd[0], tau[0], pvec), 2000) * 1e6
            tau_s = np.array([id_call(x[i], xd[i], xdd[i], pvec) for i in range(n_check)])
            xdd_s = np.array([fd_call(x[i], xd[i], tau[i], pvec) for i in range(n_check)])
            fig["tau_rel_error"] = relative_error(tau_s, tau)
            fig["xdd_rel_error"] = relative_error(xdd_s, xdd)
            out[name] = fig
    return out
