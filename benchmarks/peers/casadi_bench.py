"""CasADi against our kernel on identical states, in one run (``python -m benchmarks``)."""

from __future__ import annotations

import pathlib
import tempfile
import time

import numpy as np

import stewart
from stewart.cli import bench

from . import casadi_model, cdriver
from .common import PARAM_COUNT, param_vector, relative_error


def figures(preset: str, n_batch: int = 20_000, n_map: int = 2_000, repeats: int = 7) -> dict:
    import casadi as ca

    plat = stewart.Platform.preset(preset)
    pvec = param_vector(plat.params)
    x, xd, xdd = bench.states(plat.params, n_batch, seed=1)
    tau = plat.inverse_dynamics(x, xd, xdd)
    out: dict = {"casadi_version": ca.__version__, "parameters": f"runtime function input p ({PARAM_COUNT} doubles)"}

    start = time.perf_counter()
    funcs = casadi_model.build(general=not plat.params.is_axisymmetric)
    out["build_s"] = time.perf_counter() - start
    out["operations"] = casadi_model.operation_counts(funcs)
    f_id, f_fd = funcs["inverse_dynamics"], funcs["forward_dynamics"]
    baked = casadi_model.build(general=not plat.params.is_axisymmetric, baked=plat.params)
    out["operations_baked_parameters"] = casadi_model.operation_counts(baked)

    # (a) Python calls, single state, and .map(N) over a batch (serial), next to ours.
    one = (x[0], xd[0], xdd[0])
    out["python_single_id_us"] = bench.median_time(lambda: f_id(*one, pvec), 2000) * 1e6
    out["python_single_fd_us"] = bench.median_time(lambda: f_fd(x[0], xd[0], tau[0], pvec), 2000) * 1e6
    out["ours_single_id_us"] = bench.median_time(lambda: plat.inverse_dynamics(*one), 20000) * 1e6
    out["ours_single_fd_us"] = bench.median_time(lambda: plat.forward_dynamics(x[0], xd[0], tau[0]), 20000) * 1e6
    m_id, m_fd = f_id.map(n_map, "serial"), f_fd.map(n_map, "serial")
    sl = slice(0, n_map)
    xT, xdT, xddT, tauT = (np.ascontiguousarray(a[sl].T) for a in (x, xd, xdd, tau))
    out["python_map_id_us"] = bench.median_time(lambda: m_id(xT, xdT, xddT, pvec), 1, 5) / n_map * 1e6
    out["python_map_fd_us"] = bench.median_time(lambda: m_fd(xT, xdT, tauT, pvec), 1, 5) / n_map * 1e6
    tau_map = np.asarray(m_id(xT, xdT, xddT, pvec)).T
    xdd_map = np.asarray(m_fd(xT, xdT, tauT, pvec)).T

    # (b) CasADi's generated C and (c) ours, each called from the same C loop.
    with tempfile.TemporaryDirectory(prefix="stewart-casadi-") as tmp:
        start = time.perf_counter()
        gen = ca.CodeGenerator("casadi_stewart.c", {"with_header": True})
        gen.add(f_id)
        gen.add(f_fd)
        gen.generate(tmp + "/")
        out["generate_s"] = time.perf_counter() - start
        source = pathlib.Path(tmp) / "casadi_stewart.c"
        out["generated_c_bytes"] = source.stat().st_size
        exe, out["compile_s"] = cdriver.build_casadi(tmp, source)
        ours = cdriver.build_ours(tmp)
        out["c_loop_id_us"], tau_c = (v for v in cdriver.run(exe, "id", pvec, x, xd, xdd, repeats))
        out["c_loop_fd_us"], xdd_c = cdriver.run(exe, "fd", pvec, x, xd, tau, repeats)
        out["ours_c_loop_id_us"], tau_ours_c = cdriver.run(ours, "id", pvec, x, xd, xdd, repeats)
        out["ours_c_loop_fd_us"], _ = cdriver.run(ours, "fd", pvec, x, xd, tau, repeats)
    for key in ("c_loop_id_us", "c_loop_fd_us", "ours_c_loop_id_us", "ours_c_loop_fd_us"):
        out[key] *= 1e6
    # Our Platform batch (C loop behind the Python API) on the same states.
    out["ours_batch_id_us"] = bench.median_time(lambda: plat.inverse_dynamics(x, xd, xdd), 3) / n_batch * 1e6
    out["ours_batch_fd_us"] = bench.median_time(lambda: plat.forward_dynamics(x, xd, tau), 3) / n_batch * 1e6

    out["tau_rel_error"] = max(relative_error(tau_c, tau), relative_error(tau_map, tau[sl]))
    out["xdd_rel_error"] = max(relative_error(xdd_c, xdd), relative_error(xdd_map, xdd[sl]))
    out["ours_driver_tau_rel_error"] = relative_error(tau_ours_c, tau)
    out["states"] = n_batch
    return out
