"""acados NMPC's RTI step on the exported model against the CasADi route, side by side.

The same tracking OCP (:func:`stewart.acados.tracking_ocp`: narayan2017, a 20-step horizon of
20 ms, force bounds, the legs' stroke as ``con_h``, SQP-RTI, Gauss-Newton, HPIPM) with two
dynamics: ours, the exported ``rk4_step`` with its Jacobians as acados's generic discrete
dynamics; and the CasADi route a CasADi user of acados takes, the benchmarks' CasADi peer model
(:mod:`benchmarks.peers.casadi_model`: SX expressions, the parameters baked in) as the explicit
ODE under acados's own RK4 (ERK, 4 stages, 1 step a shooting interval, the same map as ours),
whose sensitivities acados generates with CasADi. The explicit ODE needs ``M(x)^-1``: as one
SX expression the symbolic 6x6 solve is expanded over ``M(x)``'s entries and the forward
sensitivities are 15.4 MB of C that gcc -O2 had not compiled after 30 min, so the route keeps
the solve a call, as a CasADi user would (:func:`_casadi_ocp`): the SX expressions as three SX
functions (``M(x)``, the right-hand side, a 6x6 ``solve``) in an MX model. Both routes compile
with the same flags (the export's, ``-O2`` and the model's rounding flags); a compile past
:data:`COMPILE_CAP_S` is reported as capped and ours then timed alone.

Each side tracks the seed paper's 5 s move in closed loop on the package's RK4 step (the
plant); an RTI step is preparation plus feedback, warm-started from the last iterate, timed
by the wall clock around the two calls. Rounds alternate the sides, a block of steps each;
the figures are the median over rounds of each round's median step, and the speed-up the
median of the rounds' ratios, with their 90 % intervals. Also reported: the largest
difference of the two sides' forces over the run (the same solution), and the CasADi route's
code generation and compile time against ours.

acados runs in its own environment (``make acados-env``): ``make bench`` (in ``.venv``) runs
:func:`measure` there in a subprocess that prints JSON (``python -m benchmarks.acados_nmpc``).
"""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
ACADOS_PYTHON = ROOT / ".venv-acados" / "bin" / "python"
PRESET = "narayan2017"
HORIZON = 20
DT = 0.02
FORCE_LIMIT = 60.0
#: The seed paper's move (the README's stewart simulate --target), 5 s, and the run's length.
SEED_TARGET = (0.04565, -0.0102, 0.192, -0.0863, 0.1046, 0.0960)
DURATION = 5.5
#: RTI steps of one side in a round, and the rounds (the closed loop restarts when it ends).
BLOCK = 25
ROUNDS = int(__import__("os").environ.get("STEWART_ACADOS_ROUNDS", "40"))  # fewer for a short run
#: The longest a route's compile may take [s] before it is reported as not finished (capped in
#: the row; the CasADi route with the solve kept a call compiles in well under it).
COMPILE_CAP_S = 600.0
#: The targets: a median RTI step of at most 1 ms, and at least 3x faster than the CasADi route.
STEP_MS = 1.0
SPEEDUP = 3.0


def _casadi_ocp(export, name: str):
    """The tracking OCP with the CasADi peer model's dynamics under acados's own RK4.

    The peer model's SX expressions (the parameters baked in) become three SX functions: the
    mass matrix ``M(x)``, the right-hand side ``J_C^T tau - (V xd + G)`` and a 6x6 solve
    ``solve(M, b)`` of a symbolic ``M`` (CasADi's QR in the graph, some 600 operations); the
    explicit ODE ``xdd = solve(M(x), rhs(x, xd, tau))`` calls them in an MX model. As one SX
    expression (the peer model's ``xdd_fd``) the solve is expanded over ``M(x)``'s entries and
    acados's forward sensitivities of it are 15 MB of C that gcc -O2 had not compiled after
    30 min; a CasADi user keeps the solve a node of its own, which CasADi differentiates as a
    call (``casadi.solve`` of an MX matrix would need a linear-solver plugin, which the
    acados wheel's casadi lacks)."""
    import casadi

    import stewart.acados as nmpc
    from stewart.model import kinematics

    from .peers.casadi_model import symbolic_model
    from .peers.common import param_vector

    ocp = nmpc.tracking_ocp(export, HORIZON, force_limit=FORCE_LIMIT, name=name)
    s = symbolic_model()
    p = casadi.DM(param_vector(export.params))
    mass = casadi.Function(f"{name}_mass", [s["x"]], [casadi.substitute(s["M"], s["p"], p)])
    rest = casadi.substitute(s["W"], s["xdd"], casadi.SX.zeros(6))
    rhs = casadi.Function(f"{name}_rhs", [s["x"], s["xd"], s["tau"]],
                          [casadi.substitute(s["JC"].T @ s["tau"] - rest, s["p"], p)])
    m_sym, b_sym = casadi.SX.sym("M", 6, 6), casadi.SX.sym("b", 6)
    solve = casadi.Function(f"{name}_solve", [m_sym, b_sym], [casadi.solve(m_sym, b_sym)])
    x, u = casadi.MX.sym("x", 12), casadi.MX.sym("u", 6)
    pose, rate = x[:6], x[6:]
    model = nmpc.template().AcadosModel()
    model.name = name
    model.x, model.u = x, u
    model.f_expl_expr = casadi.vertcat(rate, solve(mass(pose), rhs(pose, rate, u)))
    model.con_h_expr = casadi.vertcat(*kinematics.leg_length_expressions(export.params, [x[k] for k in range(6)],
                                                                          casadi))
    ocp.model = model
    ocp.solver_options.integrator_type = "ERK"
    ocp.solver_options.sim_method_num_stages = 4
    ocp.solver_options.sim_method_num_steps = 1
    return ocp


class CompileCap(Exception):
    """A route's compile ran past :data:`COMPILE_CAP_S`."""


def _built(ocp, export, cap_s: float = COMPILE_CAP_S):
    """(solver, code generation [s], compile [s]) of ``ocp``: acados's build (its Makefile's
    ``ocp_shared_lib``), stopped with :class:`CompileCap` past ``cap_s``."""
    import contextlib
    import os

    import stewart.acados as nmpc

    interface = nmpc.template()
    json_file = os.path.join(ocp.code_export_directory, f"{ocp.model.name}_ocp.json")
    os.makedirs(ocp.code_export_directory, exist_ok=True)
    with contextlib.chdir(export.directory):
        started = time.perf_counter()
        interface.AcadosOcpSolver.generate(ocp, json_file=json_file)
        generated = time.perf_counter()
        for target in ("clean_ocp_shared_lib", "ocp_shared_lib"):
            try:
                subprocess.run(["make", target], cwd=ocp.code_export_directory, check=True, capture_output=True,
                               timeout=cap_s)
            except subprocess.TimeoutExpired:
                raise CompileCap(f"{ocp.model.name}: not compiled within {cap_s:g} s (capped)") from None
        built = time.perf_counter()
        solver = interface.AcadosOcpSolver(ocp, json_file=json_file, build=False, generate=False, verbose=False)
    return solver, generated - started, built - generated


class _Loop:
    """One side's closed loop, stepped a block at a time, restarted at the move's end."""

    def __init__(self, solver, export, move, platform):
        import stewart.acados as nmpc

        self.tracker = nmpc.Tracker(solver, export, move, HORIZON)
        self.move, self.platform, self.dt = move, platform, export.dt
        self.steps = int(round(DURATION / self.dt))
        self.forces: list[np.ndarray] = []
        self.restart()

    def restart(self):
        pose, rate, _ = self.move.sample(0.0)
        self.state, self.k = np.concatenate([pose, rate]), 0
        self.tracker.warm_start(self.state, 0.0)

    def block(self, count: int, record: bool) -> list[float]:
        times = []
        for _ in range(count):
            if self.k == self.steps:
                self.restart()
            before = len(self.tracker.step_times)
            u = self.tracker(self.state, self.k * self.dt)
            times.append(self.tracker.step_times[before])
            if record:
                self.forces.append(u)
            x, xd = self.state[:6], self.state[6:]
            for _ in range(20):
                x, xd = self.platform.rk4_step(x, xd, u, self.dt / 20)
            self.state, self.k = np.concatenate([x, xd]), self.k + 1
        return times


def measure(preset: str = PRESET, compile_cap_s: float = COMPILE_CAP_S) -> dict:
    """The figures, measured here (in ``.venv-acados``); the CasADi route reported as not
    compiled past ``compile_cap_s`` (ours then timed alone)."""
    import stewart
    import stewart.acados as nmpc
    from stewart.io import acados_export
    from stewart.motion.trajectory import PointToPoint

    with tempfile.TemporaryDirectory() as tmp:
        acados_export.export(tmp, stewart.PlatformParams.preset(preset), DT)
        export = nmpc.load(tmp)
        ours, ours_gen, ours_build = _built(nmpc.tracking_ocp(export, HORIZON, force_limit=FORCE_LIMIT,
                                                              name="stewart_ours"), export)
        platform = stewart.Platform(export.params)
        move = PointToPoint(platform.home_pose, np.array(SEED_TARGET), 5.0)
        out = {"preset": preset, "horizon": HORIZON, "dt": DT, "block": BLOCK, "force_limit": FORCE_LIMIT,
               "ours_codegen_s": ours_gen, "ours_compile_s": ours_build}
        try:
            theirs, casadi_gen, casadi_build = _built(_casadi_ocp(export, "stewart_casadi"), export, compile_cap_s)
        except CompileCap as exc:
            # Ours alone, so that its step is still measured.
            side = _Loop(ours, export, move, platform)
            out["rounds"] = {"ours_ms": [float(np.median(side.block(BLOCK, record=False))) * 1e3
                                         for _ in range(ROUNDS)]}
            return out | {"error": str(exc)}
        sides = [_Loop(ours, export, move, platform), _Loop(theirs, export, move, platform)]
        # The same solution: both sides' whole closed loop from the same start (recorded, untimed).
        for side in sides:
            side.block(side.steps, record=True)
            side.restart()
        forces = [np.array(side.forces) for side in sides]
        difference = float(np.max(np.abs(forces[0] - forces[1])) / np.max(np.abs(forces[1])))
        rounds = {"ours_ms": [], "casadi_ms": [], "speedup": []}
        for r in range(ROUNDS):
            order = sides if r % 2 == 0 else sides[::-1]
            medians = {id(side): float(np.median(side.block(BLOCK, record=False))) for side in order}
            a, b = medians[id(sides[0])], medians[id(sides[1])]
            rounds["ours_ms"].append(a * 1e3)
            rounds["casadi_ms"].append(b * 1e3)
            rounds["speedup"].append(b / a)
        return out | {"rounds": rounds, "solution_difference": difference,
                      "forces_max": float(np.max(np.abs(forces[0]))),
                      "casadi_codegen_s": casadi_gen, "casadi_compile_s": casadi_build}


def figures(preset: str = PRESET) -> dict:
    """:func:`measure` run in ``.venv-acados``, or {"error": why not}."""
    if not ACADOS_PYTHON.is_file():
        return {"error": "no .venv-acados: run make acados-env"}
    done = subprocess.run([str(ACADOS_PYTHON), "-m", "benchmarks.acados_nmpc", preset], cwd=ROOT,
                          capture_output=True, text=True)
    if done.returncode != 0:
        return {"error": f"failed: {done.stderr.strip().splitlines()[-1] if done.stderr.strip() else done.returncode}"}
    return json.loads(done.stdout.strip().splitlines()[-1])


def _measurement(values):
    from stewart.cli.bench import Measurement
    from stewart.cli.interleaved import median_interval

    low, high = median_interval(values)
    return Measurement(float(np.median(values)), low, high, len(values), (), None)


def rows(fig: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, figure, spread, target, verdict) rows."""
    from stewart.cli import bench
    from stewart.cli.interleaved import Target

    if "rounds" not in fig:
        return [("acados NMPC RTI step", fig.get("error", "not measured"), "", "", "")]
    what = f"acados NMPC RTI step ({fig['preset']}, {fig['horizon']} steps of {fig['dt'] * 1e3:g} ms, warm-started)"
    r = fig["rounds"]
    out = [bench.measure_row(what + ", ours (exported rk4_step), median", "acados_rti_ms", _measurement(r["ours_ms"]),
                             1.0, "ms", ".3f", Target(STEP_MS, True, "the wall clock")),
           ("acados NMPC, code generation + compile: ours (as measured)",
            f"{fig['ours_codegen_s']:.1f} s + {fig['ours_compile_s']:.1f} s", "", "", "")]
    if "error" in fig:
        return out + [("acados NMPC, the CasADi route (SX functions, the solve a call, MX model, acados's RK4)", fig["error"], "", "", "")]
    return out + [
        bench.measure_row("acados NMPC RTI step, the CasADi route (SX functions, the solve a call, MX model, acados's RK4), median",
                          "acados_casadi_rti_ms", _measurement(r["casadi_ms"]), 1.0, "ms", ".3f"),
        bench.measure_row("acados NMPC RTI step, speed-up over the CasADi route", "acados_rti_speedup",
                          _measurement(r["speedup"]), 1.0, "x", ".2f", Target(SPEEDUP, False, "the CasADi route")),
        bench.measure_row("acados NMPC, the two routes' forces over the closed loop, largest difference / largest "
                          "force", "acados_solution_difference", fig["solution_difference"], 1.0, "", ".1e",
                          Target(1e-8, True)),
        ("acados NMPC, code generation + compile: the CasADi route (as measured)",
         f"{fig['casadi_codegen_s']:.1f} s + {fig['casadi_compile_s']:.1f} s", "", "", ""),
    ]


def format_rows(fig: dict) -> str:
    from .report import target_table

    return target_table(rows(fig))


if __name__ == "__main__":  # python -m benchmarks.acados_nmpc [PRESET [COMPILE_CAP_S]], in .venv-acados
    print(json.dumps(measure(sys.argv[1] if len(sys.argv) > 1 else PRESET,
                             float(sys.argv[2]) if len(sys.argv) > 2 else COMPILE_CAP_S)))
