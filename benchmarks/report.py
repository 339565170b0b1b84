"""The tables of a bench run (ours with each target met, missed or unsettled, and the peer
comparison) and the peers' bar chart (``python -m benchmarks``)."""

from __future__ import annotations

import math
import os
import platform as host
import subprocess
import sys

import numpy as np

import stewart
from stewart.cli import bench


def _march() -> str:
    """The -march of the path the kernel runs (stewart.build_info()), and whether the import
    chose it among the portable build's paths."""
    info = stewart.build_info()
    flags = info["flags"][info["simd"]].split()
    march = next((f.split("=", 1)[1] for f in flags if f.startswith("-march=")), "the compiler's default")
    return march if len(info["compiled"]) == 1 else f"{march} (dispatched)"


def machine() -> dict:
    """What the figures were measured on, and the machine's load (1-minute average of
    runnable processes) as the run starts."""
    cpu = host.processor()
    try:  # the CPU's model name, where Linux tells it
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    compiler = subprocess.run([os.environ.get("CC", "cc"), "--version"], capture_output=True, text=True)
    return {"platform": host.platform(), "processor": cpu, "cpus": os.cpu_count(), "python": sys.version.split()[0],
            "numpy": np.__version__, "compiler": compiler.stdout.splitlines()[0] if compiler.returncode == 0 else "?",
            "march": _march(),
            "load_average": os.getloadavg()[0] if hasattr(os, "getloadavg") else None}


def our_rows(results: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, median, spread, target, verdict) rows of our own figures."""
    out = []
    for preset, fig in results["kernel"].items():
        out += bench.kernel_rows(preset, fig)
    gen = results.get("generation")
    if gen:
        out += [
            bench.measure_row("generation (python -m codegen)", "generation_s",
                              bench.as_measurement(gen, "generation_s"), 1.0, "s", ".2f"),
            bench.measure_row("clean build of the extension", "clean_build_s",
                              bench.as_measurement(gen, "clean_build_s"), 1.0, "s", ".1f"),
        ]
    code = results["code"]
    out.append(("generated C", f"{code['generated_c_bytes'] / 1024:.0f} KiB, {code['generated_c_lines']} lines", "",
                "", ""))
    for name, count in code["operation_counts"].items():
        out.append((f"operations: {name}", str(count), "", "", ""))
    return out


def targets(table_rows) -> list[dict]:
    """Every row with a target, for the JSON figures: its measure, figure, spread, target and
    verdict (met, missed or unsettled); a row's first entry is its measure and its last four
    its figure, spread, target and verdict."""
    words = {spelling: word for word, spelling in bench.VERDICTS.items()}
    return [{"measure": r[0], "figure": r[-4], "spread": r[-3], "target": r[-2], "verdict": words[r[-1]]}
            for r in table_rows if r[-2]]


#: (section, key in figures, what, key of ours, key of the peer, unit)
_PAIRS = {
    "casadi": [
        ("inverse dynamics, one call from Python", "ours_single_id_us", "python_single_id_us", "us"),
        ("forward dynamics, one call from Python", "ours_single_fd_us", "python_single_fd_us", "us"),
        ("inverse dynamics, batch from Python (ours: Platform batch; CasADi: .map(N))", "ours_batch_id_us",
         "python_map_id_us", "us/state"),
        ("forward dynamics, batch from Python (ours: Platform batch; CasADi: .map(N))", "ours_batch_fd_us",
         "python_map_fd_us", "us/state"),
        ("inverse dynamics, generated C in the same C loop", "ours_c_loop_id_us", "c_loop_id_us", "us/state"),
        ("forward dynamics, generated C in the same C loop", "ours_c_loop_fd_us", "c_loop_fd_us", "us/state"),
    ],
    "sympy": [
        ("inverse dynamics, one call from Python", "ours_single_id_us", "single_id_us", "us"),
        ("forward dynamics, one call from Python", "ours_single_fd_us", "single_fd_us", "us"),
    ],
}


def _num(v: float, unit: str = "") -> str:
    if v is None:
        return "-"
    if v == 0:
        return f"0 {unit}".strip()
    digits = max(0, 2 - int(math.floor(math.log10(abs(v)))))
    return f"{v:.{min(digits, 3)}f} {unit}".strip() if abs(v) >= 1e-3 else f"{v:.2e} {unit}".strip()


def rows(peers: dict, ours: dict) -> list[tuple[str, str, str, str]]:
    """(measure, ours, peer, peer/ours) rows for every peer measured."""
    out = []
    cas = peers.get("casadi")
    if cas and "error" not in cas:
        for what, k_ours, k_peer, unit in _PAIRS["casadi"]:
            out.append((f"CasADi: {what}", _num(cas[k_ours], unit), _num(cas[k_peer], unit),
                        f"{cas[k_peer] / cas[k_ours]:.1f}x"))
        ops = cas["operations"]
        out.append(("CasADi: size, inverse / forward dynamics (ours: operations of the C after cse)",
                    f"{ours['ops'].get('inverse_dynamics', '?')} / {ours['ops'].get('forward_dynamics', '?')} ops",
                    f"{ops['inverse_dynamics']['n_instructions']} / {ops['forward_dynamics']['n_instructions']} instr.",
                    ""))
        if ours.get("generation_s") is not None:
            ours_gen = f"{ours['generation_s']:.1f} s + {ours['clean_build_s']:.1f} s"
            ratio = f"{(cas['build_s'] + cas['generate_s'] + cas['compile_s']) / (ours['generation_s'] + ours['clean_build_s']):.2f}x"
        else:
            ours_gen, ratio = "(skipped)", ""
        out.append(("CasADi: generation + compile (ours: codegen + clean build of the extension)", ours_gen,
                    f"{cas['build_s'] + cas['generate_s']:.2f} s + {cas['compile_s']:.1f} s", ratio))
        out.append(("CasADi: agreement, max relative error of tau / xdd", "", f"{cas['tau_rel_error']:.1e} / "
                    f"{cas['xdd_rel_error']:.1e}", ""))
    out += _casadi_derivative_rows(peers.get("casadi_derivatives"))
    out += _pinocchio_rows(peers.get("pinocchio"))
    out += _optimization_rows(peers.get("optimization"))
    sym = peers.get("sympy")
    if sym and "error" not in sym:
        for route, label in (("autowrap", "sympy autowrap (Cython)"), ("pydy", "PyDy CythonMatrixGenerator")):
            fig = sym.get(route)
            if not fig:
                continue
            for what, k_ours, k_peer, unit in _PAIRS["sympy"]:
                out.append((f"{label}: {what} (+ numpy solve)", _num(sym[k_ours], unit), _num(fig[k_peer], unit),
                            f"{fig[k_peer] / sym[k_ours]:.1f}x"))
            gen = ours.get("generation_s")
            out.append((f"{label}: generation + compile", f"{gen:.1f} s" if gen is not None else "(skipped)",
                        f"{sym['expressions_s'] + fig['generate_and_compile_s']:.1f} s", ""))
            out.append((f"{label}: agreement, max relative error of tau / xdd", "",
                        f"{fig['tau_rel_error']:.1e} / {fig['xdd_rel_error']:.1e}", ""))
    mj = peers.get("mujoco")
    if mj and "error" not in mj:
        w = mj["window_s"]
        for setting in ("default", "tight"):
            fig = mj[setting]
            label = f"MuJoCo {setting} (dt {fig['timestep_s']:g} s, {fig['integrator']})"
            out.append((f"{label}: wall time per simulated second", f"{mj['ours_rk4_ct_wall_ms'] / 5:.1f} ms",
                        f"{fig['wall_per_simulated_s_ms']:.1f} ms",
                        f"{fig['wall_per_simulated_s_ms'] / (mj['ours_rk4_ct_wall_ms'] / 5):.1f}x"))
            out.append((f"{label}: time per step (ours: RK4 step with controller)", _num(mj["ours_step_us"], "us"),
                        _num(fig["step_us"], "us"), ""))
            out.append((f"{label}: max connect-anchor gap", "", f"{fig['max_constraint_gap_m']:.1e} m", ""))
            ol = fig.get("vs_our_open_loop_replay")
            if ol:
                out.append((f"{label}: platform difference from our open-loop replay, first {w:g} s", "",
                            f"{ol[f'max_position_difference_first_{w:g}s_m']:.1e} m, "
                            f"{ol[f'max_angle_difference_first_{w:g}s_rad']:.1e} rad", ""))
                out.append((f"{label}: same, up to {ol['compared_until_s']:.2f} s", "",
                            f"{ol['max_position_difference_m']:.1e} m, {ol['max_angle_difference_rad']:.1e} rad", ""))
            cl = fig["vs_our_closed_loop_run"]
            t1 = cl["time_to_1mm_difference_s"]
            out.append((f"{label}: difference from our closed-loop run, first {w:g} s; time to 1 mm", "",
                        f"{cl[f'max_position_difference_first_{w:g}s_m']:.1e} m; "
                        + ("never" if t1 is None else f"{t1:.2f} s"), ""))
        ol = mj["our_open_loop_replay"]["vs_our_closed_loop_run"]
        t1 = ol["time_to_1mm_difference_s"]
        out.append(("our own open-loop replay (RK4, 0.1 ms) vs our closed-loop run, first "
                    f"{w:g} s; time to 1 mm", f"{ol[f'max_position_difference_first_{w:g}s_m']:.1e} m; "
                    + ("never" if t1 is None else f"{t1:.2f} s"), "", ""))
    for name, info in peers.items():
        if "error" in info:
            out.append((f"{name}: skipped", "", info["error"], ""))
        for what in info.get("skipped", []):
            out.append((f"{name}: skipped", "", f"{what}; pip install '.[peers]'", ""))
    return out


def _casadi_derivative_rows(cas: dict | None) -> list[tuple[str, str, str, str]]:
    """Rows of CasADi's ca.jacobian code against our exact derivatives."""
    if not cas or "error" in cas:
        return []
    out = []
    for name, what in (("inverse_dynamics_derivatives", "tau + dtau/d(x, xd, xdd)"),
                       ("forward_dynamics_derivatives", "xdd + dxdd/d(x, xd, tau)")):
        fig = cas[name]
        label = f"CasADi ca.jacobian: {what}"
        out.append((f"{label}, one call from Python", _num(fig["ours_single_us"], "us"),
                    _num(fig["python_single_us"], "us"), f"{fig['python_single_us'] / fig['ours_single_us']:.0f}x"))
        out.append((f"{label}, batch from Python (ours: Platform batch; CasADi: .map(N))",
                    _num(fig["ours_batch_us"], "us/state"), _num(fig["python_map_us"], "us/state"),
                    f"{fig['python_map_us'] / fig['ours_batch_us']:.0f}x"))
        compiled = f"{fig['generated_c_bytes'] / 2**20:.1f} MiB of C"
        if fig.get("c_loop_us") is not None:
            peer, ratio = _num(fig["c_loop_us"], "us/state"), f"{fig['c_loop_us'] / fig['ours_batch_us']:.0f}x"
            compiled += f", {fig['compile_s']:.0f} s to compile"
        else:
            peer, ratio = fig["did_not_finish"], ""
        out.append((f"{label}, generated C in a C loop (ours: Platform batch)", _num(fig["ours_batch_us"], "us/state"),
                    peer, ratio))
        out.append((f"{label}, generated C", "", compiled, ""))
        out.append((f"{label}, agreement with ours, max relative error of the Jacobian", "",
                    f"{fig['jacobian_rel_error']:.1e}", ""))
    return out


def _pinocchio_rows(pin: dict | None) -> list[tuple[str, str, str, str]]:
    """Rows of Pinocchio's closed-loop constraint dynamics and derivatives against ours."""
    if not pin or "error" in pin:
        return []
    label = f"Pinocchio {pin['pinocchio_version']} closed loop, from Python"
    pairs = [
        ("forward dynamics, one call (constraintDynamics)", "ours_single_forward_dynamics_us",
         "constraint_dynamics_us", "us"),
        ("forward dynamics with its Jacobians, one call (+ computeConstraintDynamicsDerivatives)",
         "ours_single_forward_dynamics_derivatives_us", "constraint_dynamics_derivatives_us", "us"),
        ("same, ours in a batch", "ours_batch_forward_dynamics_derivatives_us", "constraint_dynamics_derivatives_us",
         "us/state"),
    ]
    out = [(f"{label}: {what}", _num(pin[k_ours], unit), _num(pin[k_peer], "us"), f"{pin[k_peer] / pin[k_ours]:.1f}x")
           for what, k_ours, k_peer, unit in pairs]
    out.append((f"{label}: agreement at rest, legs without axial inertia: xdd / dxdd/dtau", "",
                f"{pin['platform_acceleration_rel_error']:.1e} / {pin['dxdd_dtau_rel_error']:.1e}", ""))
    return out


def _optimization_rows(opt: dict | None) -> list[tuple[str, str, str, str]]:
    """Rows of the minimum-effort move solved over our CasADi functions and over CasADi's own
    model (:mod:`benchmarks.peers.casadi_optimize`)."""
    if not opt or "error" in opt:
        return []
    ours, cas = opt["ours"], opt["casadi"]
    label = f"IPOPT, minimum-effort move ({opt['intervals']} RK4 intervals; CasADi: its own SX model)"
    return [
        (f"{label}: optimum sum |tau|^2 dt [N^2 s]", f"{ours['effort']:.10g}", f"{cas['effort']:.10g}",
         f"{opt['effort_relative_difference']:.1e} apart"),
        (f"{label}: iterations", str(ours["iterations"]), str(cas["iterations"]), ""),
        (f"{label}: wall time per solve", f"{ours['solve_s']:.3g} s", f"{cas['solve_s']:.3g} s",
         f"{cas['solve_s'] / ours['solve_s']:.0f}x"),
        (f"{label}: wall time per iteration", f"{ours['per_iteration_ms']:.3g} ms", f"{cas['per_iteration_ms']:.3g} ms",
         f"{cas['per_iteration_ms'] / ours['per_iteration_ms']:.0f}x"),
    ] + _jit_rows(opt)


def _jit_rows(opt: dict) -> list[tuple[str, str, str, str]]:
    """Rows of the same NLP with CasADi's ``jit=True`` (:func:`benchmarks.peers.casadi_optimize.jit_figures`)."""
    jit, ours = opt.get("casadi_jit"), opt["ours"]
    if not jit:
        return []
    label = (f"IPOPT, minimum-effort move ({opt['intervals']} RK4 intervals; CasADi jit=True {jit.get('flags', '')}, "
             "its model with the solve a call)")
    if "error" in jit:
        return [(f"{label}", "", jit["error"], "")]
    return [
        (f"{label}: optimum sum |tau|^2 dt [N^2 s]", f"{ours['effort']:.10g}", f"{jit['effort']:.10g}",
         f"{opt['jit_effort_relative_difference']:.1e} apart"),
        (f"{label}: iterations", str(ours["iterations"]), str(jit["iterations"]), ""),
        (f"{label}: JIT compile (ours: compiled at make build)", "-", f"{jit['compile_s']:.3g} s", ""),
        (f"{label}: wall time per solve", f"{ours['solve_s']:.3g} s", f"{jit['solve_s']:.3g} s",
         f"{jit['solve_s'] / ours['solve_s']:.1f}x"),
        (f"{label}: wall time per iteration", f"{ours['per_iteration_ms']:.3g} ms",
         f"{jit['per_iteration_ms']:.3g} ms", f"{jit['per_iteration_ms'] / ours['per_iteration_ms']:.1f}x"),
    ]


def target_table(rows) -> str:
    """``(measure, figure, spread, target, verdict)`` rows as a Markdown table under a header."""
    table = [("measure", "figure", "90% interval (rounds)", "target", "verdict")] + list(rows)
    widths = [max(len(r[k]) for r in table) for k in range(5)]
    return "\n".join("| " + " | ".join(c.ljust(w) for c, w in zip(r, widths)) + " |" for r in table)


def format_rows(table_rows) -> str:
    widths = [max(len(r[k]) for r in table_rows) for k in range(4)]
    head = ("peer comparison (same run, same states)", "ours", "peer", "peer/ours")
    widths = [max(w, len(h)) for w, h in zip(widths, head)]
    fmt = lambda r: f"{r[0]:<{widths[0]}}  {r[1]:>{widths[1]}}  {r[2]:>{widths[2]}}  {r[3]:>{widths[3]}}"
    return "\n".join([fmt(head), "-" * (sum(widths) + 6)] + [fmt(r) for r in table_rows])


def chart_panels(peers: dict) -> list[tuple[str, str, list[str], dict[str, list[float]]]]:
    """The chart's panels, one per unit: (title, y label, group labels, {series: values}),
    each holding only the series measured for it, so that every bar drawn has a value."""
    panels = []
    cas, sym, mj = (peers.get(k, {}) for k in ("casadi", "sympy", "mujoco"))
    cas = cas if "error" not in cas else {}
    sym = sym if "error" not in sym else {}
    mj = mj if "error" not in mj else {}
    single: dict[str, list[float]] = {}
    if cas or sym:
        ours = cas or sym
        single["ours"] = [ours["ours_single_id_us"], ours["ours_single_fd_us"]]
    if cas:
        single["CasADi Function"] = [cas["python_single_id_us"], cas["python_single_fd_us"]]
    for route, label in (("autowrap", "sympy autowrap"), ("pydy", "PyDy")):
        if route in sym:
            single[label] = [sym[route]["single_id_us"], sym[route]["single_fd_us"]]
    if len(single) > 1:
        panels.append(("one call from Python", "time per call [µs]", ["inverse dynamics", "forward dynamics"],
                       single))
    if cas:
        groups = ["ID, from Python", "FD, from Python", "ID, same C loop", "FD, same C loop"]
        panels.append(("batches (CasADi: .map(N); its C in our C loop)",
                       "time per state [µs]", groups,
                       {"ours": [cas["ours_batch_id_us"], cas["ours_batch_fd_us"], cas["ours_c_loop_id_us"],
                                 cas["ours_c_loop_fd_us"]],
                        "CasADi": [cas["python_map_id_us"], cas["python_map_fd_us"], cas["c_loop_id_us"],
                                   cas["c_loop_fd_us"]]}))
    if mj:
        series = {"ours (RK4, 1 ms)": [mj["ours_rk4_ct_wall_ms"] / 5]}
        for setting in ("default", "tight"):
            fig = mj[setting]
            series[f"MuJoCo {setting} ({fig['integrator']}, {1e3 * fig['timestep_s']:g} ms)"] = [
                fig["wall_per_simulated_s_ms"]]
        panels.append(("simulation, the demo's move", "wall time per simulated second [ms]",
                       ["ours; MuJoCo replays our forces"], series))
    return panels


def chart(peers: dict, path: str) -> str | None:
    """Bar chart of ours against every peer measured, one panel per kind of timing (log
    scale where the bars span more than a factor of 30), every bar labelled with its value;
    None without matplotlib or without a peer."""
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = chart_panels(peers)
    if not panels:
        return None
    widths = [len(groups) * (1 + len(series)) for _, _, groups, series in panels]
    fig, axes = plt.subplots(1, len(panels), figsize=(min(16, 4 + 0.5 * sum(widths)), 5.5), constrained_layout=True,
                             gridspec_kw={"width_ratios": widths}, squeeze=False)
    for ax, (title, ylabel, groups, series) in zip(axes[0], panels):
        values = np.array([v for vals in series.values() for v in vals], float)
        log = values.max() / values.min() > 30
        width = 0.8 / len(series)
        pos = np.arange(len(groups))
        for k, (name, vals) in enumerate(series.items()):
            bars = ax.bar(pos + (k - (len(series) - 1) / 2) * width, vals, width, label=name)
            ax.bar_label(bars, [f"{v:.3g}" for v in vals], fontsize=7, padding=1)
        if log:
            ax.set_yscale("log")
            ax.set_ylim(values.min() / 3, values.max() * 8)
            ylabel += " (log scale)"
        else:
            ax.set_ylim(0, values.max() * 1.3)
        ax.set_xticks(pos, groups, fontsize=8)
        ax.set_ylabel(ylabel)
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=7, loc="upper left")
        ax.grid(True, axis="y", which="both", alpha=0.3)
    fig.suptitle("Stewart platform dynamics (narayan2017): ours against its peers, one run, identical states")
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
