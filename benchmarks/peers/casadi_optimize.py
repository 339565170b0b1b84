"""The minimum-effort move of :mod:`stewart.motion.optimize`, solved over CasADi's own model.

The RK4 step and the leg lengths are CasADi SX expressions built from the model of
:mod:`benchmarks.peers.casadi_model` (the parameters baked in as constants), so CasADi
differentiates them by its own algorithmic differentiation. The NLP, its initial guess and
IPOPT's options are exactly those of :func:`stewart.motion.optimize.minimum_effort_move`
(:func:`stewart.motion.optimize.solve_move`), so the two optima must agree.
"""

from __future__ import annotations

import numpy as np

from . import casadi_model

__all__ = ["casadi_functions", "compact_step", "jit_figures", "minimum_effort_move", "figures"]

#: The JIT anchor's compile flags and its cap [s] (the JIT runs in a subprocess, stopped past it).
JIT_FLAGS = ["-O1"]
JIT_CAP_S = 600.0


def casadi_functions(params, dt: float):
    """``(step(s, tau) -> s_next, lengths(x) -> L)`` as CasADi SX functions."""
    import casadi as ca

    forward = casadi_model.build(baked=params)["forward_dynamics"]
    s, tau, x = ca.SX.sym("s", 12), ca.SX.sym("tau", 6), ca.SX.sym("x", 6)

    def rate(state):
        return ca.vertcat(state[6:], forward(state[:6], state[6:], tau))

    k1 = rate(s)
    k2 = rate(s + dt / 2 * k1)
    k3 = rate(s + dt / 2 * k2)
    k4 = rate(s + dt * k3)
    step = ca.Function("casadi_rk4_step", [s, tau], [s + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)])
    psi, theta, phi = x[3], x[4], x[5]
    rz = ca.vertcat(ca.horzcat(ca.cos(psi), -ca.sin(psi), 0), ca.horzcat(ca.sin(psi), ca.cos(psi), 0),
                    ca.horzcat(0, 0, 1))
    ry = ca.vertcat(ca.horzcat(ca.cos(theta), 0, ca.sin(theta)), ca.horzcat(0, 1, 0),
                    ca.horzcat(-ca.sin(theta), 0, ca.cos(theta)))
    rx = ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, ca.cos(phi), -ca.sin(phi)),
                    ca.horzcat(0, ca.sin(phi), ca.cos(phi)))
    rot = rz @ ry @ rx
    legs = [x[:3] + rot @ ca.DM(np.asarray(params.platform_points[i])) - ca.DM(np.asarray(params.base_points[i]))
            for i in range(6)]
    lengths = ca.Function("casadi_leg_lengths", [x], [ca.vertcat(*[ca.norm_2(leg) for leg in legs])])
    return step, lengths


def compact_step(params, dt: float):
    """The RK4 step of CasADi's model with its 6x6 solve kept a call: SX functions of the mass
    matrix ``M(x)``, the right-hand side ``J_C^T tau - (V xd + G)`` and ``solve(M, b)`` of a
    symbolic ``M``, called from an MX step. As one SX expression (:func:`casadi_functions`)
    the step's Jacobian is some 2 million SX instructions, C that no JIT compiles in minutes;
    a CasADi user who JIT-compiles keeps the solve a node of its own."""
    import casadi as ca

    from .common import param_vector

    sym = casadi_model.symbolic_model()
    p = ca.DM(param_vector(params))
    mass = ca.Function("peer_mass", [sym["x"]], [ca.substitute(sym["M"], sym["p"], p)])
    rest = ca.substitute(sym["W"], sym["xdd"], ca.SX.zeros(6))
    rhs = ca.Function("peer_rhs", [sym["x"], sym["xd"], sym["tau"]],
                      [ca.substitute(sym["JC"].T @ sym["tau"] - rest, sym["p"], p)])
    m, b = ca.SX.sym("M", 6, 6), ca.SX.sym("b", 6)
    solve = ca.Function("peer_solve", [m, b], [ca.solve(m, b)])
    s, tau = ca.MX.sym("s", 12), ca.MX.sym("tau", 6)

    def rate(state):
        return ca.vertcat(state[6:], solve(mass(state[:6]), rhs(state[:6], state[6:], tau)))

    k1 = rate(s)
    k2 = rate(s + dt / 2 * k1)
    k3 = rate(s + dt / 2 * k2)
    k4 = rate(s + dt * k3)
    return ca.Function("casadi_rk4_step_compact", [s, tau], [s + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)])


def _jit_run(preset, intervals, force_limit, queue):
    import time

    import stewart
    from stewart.motion import optimize

    plat = stewart.Platform.preset(preset)
    target = np.array([0.04565, -0.0102, 0.192, -0.0863, 0.1046, 0.0960])
    duration = 5.0
    step = compact_step(plat.params, duration / intervals)
    _, lengths = casadi_functions(plat.params, duration / intervals)
    guess = optimize.initial_guess(plat, plat.home_pose, target, duration, intervals)
    options = {"jit": True, "compiler": "shell", "jit_cleanup": True, "jit_options": {"flags": JIT_FLAGS}}
    started = time.perf_counter()
    _, _, effort, stats, seconds = optimize.solve_move(
        step.map(intervals), lengths.map(intervals + 1), plat.home_pose, target, duration, intervals,
        initial_guess=guess, force_limit=force_limit, stroke=plat.params.leg_length_limits, solver_options=options)
    total = time.perf_counter() - started
    queue.put({"effort": effort, "iterations": int(stats["iter_count"]), "status": str(stats["return_status"]),
               "solve_s": seconds, "compile_s": total - seconds,
               "per_iteration_ms": 1e3 * seconds / max(1, int(stats["iter_count"]))})


def jit_figures(preset: str = "narayan2017", intervals: int = 50, force_limit: float = 60.0,
                cap_s: float = JIT_CAP_S) -> dict:
    """The same NLP over :func:`compact_step` with ``nlpsol``'s ``jit=True`` (CasADi's shell
    compiler, :data:`JIT_FLAGS`): the JIT's compile time (the NLP's construction and compile,
    before the solve) and the solve's; in a subprocess stopped past ``cap_s``."""
    import multiprocessing

    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    process = context.Process(target=_jit_run, args=(preset, intervals, force_limit, queue))
    process.start()
    try:
        return queue.get(timeout=cap_s) | {"flags": " ".join(JIT_FLAGS)}
    except Exception:
        return {"error": f"not compiled and solved within {cap_s:g} s (capped)", "flags": " ".join(JIT_FLAGS)}
    finally:
        if process.is_alive():
            process.kill()
        process.join()


def minimum_effort_move(platform, target, duration: float, intervals: int, force_limit=None):
    """:func:`stewart.motion.optimize.solve_move` over CasADi's model: ``(states, forces, effort,
    stats, seconds)``, with the initial guess of :func:`stewart.motion.optimize.initial_guess`."""
    from stewart.motion import optimize

    step, lengths = casadi_functions(platform.params, duration / intervals)
    return optimize.solve_move(step.map(intervals), lengths.map(intervals + 1), platform.home_pose, np.asarray(target, dtype=float), duration,
                               intervals, initial_guess=optimize.initial_guess(platform, platform.home_pose, target,
                                                                               duration, intervals),
                               force_limit=force_limit, stroke=platform.params.leg_length_limits)


def figures(preset: str = "narayan2017", intervals: int = 50, force_limit: float = 60.0, repeats: int = 5) -> dict:
    """The seed paper's move (home to its target in 5 s) as a minimum-effort problem, solved
    over our CasADi functions and over CasADi's own model: each optimum, IPOPT's iterations,
    the median wall time per solve (of ``repeats`` solves over ours; one over CasADi's,
    which takes long enough to measure alone) and per iteration, and the relative
    difference of the optima. CasADi's model is built once, outside the timing; both NLPs
    are built before their solves' timing starts."""
    import time

    import stewart
    from stewart.motion import casadi_functions as ours
    from stewart.motion import optimize

    plat = stewart.Platform.preset(preset)
    target = np.array([0.04565, -0.0102, 0.192, -0.0863, 0.1046, 0.0960])
    duration = 5.0
    dt = duration / intervals
    guess = optimize.initial_guess(plat, plat.home_pose, target, duration, intervals)
    started = time.perf_counter()
    step, lengths = casadi_functions(plat.params, dt)
    casadi_build_s = time.perf_counter() - started
    routes = {
        "ours": (ours.rk4_step(plat, dt, intervals), ours.leg_lengths(plat, intervals + 1)),
        "casadi": (step.map(intervals), lengths.map(intervals + 1)),
    }
    out = {"intervals": intervals, "force_limit": force_limit, "casadi_build_s": casadi_build_s}
    for name, (dynamics, leg_lengths) in routes.items():
        runs = [optimize.solve_move(dynamics, leg_lengths, plat.home_pose, target, duration, intervals,
                                    initial_guess=guess, force_limit=force_limit,
                                    stroke=plat.params.leg_length_limits)
                for _ in range(repeats if name == "ours" else 1)]
        _, _, effort, stats, _ = runs[0]
        seconds = float(np.median([r[4] for r in runs]))
        out[name] = {"effort": effort, "iterations": int(stats["iter_count"]), "status": str(stats["return_status"]),
                     "solve_s": seconds, "per_iteration_ms": 1e3 * seconds / max(1, int(stats["iter_count"]))}
    out["effort_relative_difference"] = abs(out["ours"]["effort"] - out["casadi"]["effort"]) / out["casadi"]["effort"]
    out["casadi_jit"] = jit_figures(preset, intervals, force_limit)
    if "effort" in out["casadi_jit"]:
        out["jit_effort_relative_difference"] = (abs(out["ours"]["effort"] - out["casadi_jit"]["effort"])
                                                 / out["casadi_jit"]["effort"])
    return out
