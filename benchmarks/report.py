"""The peer comparison as table rows and a bar chart (``python -m benchmarks``)."""

from __future__ import annotations

import math

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
        out.append(("CasADi: size, inverse / forward dynamics (ours: sympy count_ops after cse)",
                    f"{ours['ops'].get('inverse_dynamics', '?')} / {ours['ops'].get('forward_dynamics', '?')} ops",
                    f"{ops['inverse_dynamics']['n_instructions']} / {ops['forward_dynamics']['n_instructions']} instr.",
                    ""))
        if ours.get("generation_s") is not None:
            ours_gen = f"{ours['generation_s']:.1f} s + {ours['clean_build_s']:.1f} s"
            ratio = f"{(cas['build_s'] + cas['generate_s'] + cas['compile_s']) / (ours['generation_s'] + ours['clean_build_s']):.2f}x"
        else:
            ours_gen, ratio = "(skipped)", ""
        out.append(("CasADi: generation + compile (ours: codegen + clean build of both extensions)", ours_gen,
                    f"{cas['build_s'] + cas['generate_s']:.2f} s + {cas['compile_s']:.1f} s", ratio))
        out.append(("CasADi: agreement, max relative error of tau / xdd", "", f"{cas['tau_rel_error']:.1e} / "
                    f"{cas['xdd_rel_error']:.1e}", ""))
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


def format_rows(table_rows) -> str:
    widths = [max(len(r[k]) for r in table_rows) for k in range(4)]
    head = ("peer comparison (same run, same states)", "ours", "peer", "peer/ours")
    widths = [max(w, len(h)) for w, h in zip(widths, head)]
    fmt = lambda r: f"{r[0]:<{widths[0]}}  {r[1]:>{widths[1]}}  {r[2]:>{widths[2]}}  {r[3]:>{widths[3]}}"
    return "\n".join([fmt(head), "-" * (sum(widths) + 6)] + [fmt(r) for r in table_rows])


def chart(peers: dict, path: str) -> str | None:
    """Bar chart of the timings (log scale), ours next to every peer; None without matplotlib."""
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    groups = ["ID, one call\nfrom Python", "FD, one call\nfrom Python", "ID, C loop\n(per state)",
              "FD, C loop\n(per state)"]
    series: dict[str, list] = {}
    cas, sym = peers.get("casadi", {}), peers.get("sympy", {})
    if cas and "error" not in cas:
        series["ours"] = [cas["ours_single_id_us"], cas["ours_single_fd_us"], cas["ours_c_loop_id_us"],
                          cas["ours_c_loop_fd_us"]]
        series["CasADi"] = [cas["python_single_id_us"], cas["python_single_fd_us"], cas["c_loop_id_us"],
                            cas["c_loop_fd_us"]]
    elif sym and "error" not in sym:
        series["ours"] = [sym["ours_single_id_us"], sym["ours_single_fd_us"], np.nan, np.nan]
    if sym and "error" not in sym:
        for route, label in (("autowrap", "sympy autowrap"), ("pydy", "PyDy")):
            if route in sym:
                series[label] = [sym[route]["single_id_us"], sym[route]["single_fd_us"], np.nan, np.nan]
    if len(series) < 2:
        return None
    fig, ax = plt.subplots(figsize=(9, 4.8), constrained_layout=True)
    width = 0.8 / len(series)
    pos = np.arange(len(groups))
    for k, (name, values) in enumerate(series.items()):
        bars = ax.bar(pos + (k - (len(series) - 1) / 2) * width, values, width, label=name)
        for bar, v in zip(bars, values):
            if np.isfinite(v):
                ax.annotate(f"{v:.3g}", (bar.get_x() + bar.get_width() / 2, v), ha="center", va="bottom",
                            fontsize=7)
    ax.set_yscale("log")
    ax.set_xticks(pos, groups)
    ax.set_ylabel("time [us] (log scale)")
    ax.set_title("Stewart platform dynamics: ours vs peers, one run, identical states")
    ax.legend()
    ax.grid(True, axis="y", which="both", alpha=0.3)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
