"""Speed of the compiled kernel and the simulation loop, measured side by side in one run
(``stewart bench``). Timings are medians of repeats; ratios are taken within the run."""

from __future__ import annotations

import timeit

import numpy as np

import stewart
from stewart import reference

__all__ = ["median_time", "states", "kernel_figures", "simulation_figures", "kernel_rows", "format_table"]


def median_time(fn, number: int, repeat: int = 7) -> float:
    """Median over ``repeat`` runs of the time per call of ``fn`` (``number`` calls a run)."""
    return float(np.median(timeit.repeat(fn, number=number, repeat=repeat)) / number)


def states(params, n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    home = stewart.home_pose(params)
    scale = np.array([0.04 * home[2]] * 3 + [0.1] * 3)
    x = home + rng.uniform(-1, 1, (n, 6)) * scale
    xd = rng.normal(size=(n, 6)) * scale * 5
    xdd = rng.normal(size=(n, 6)) * scale * 50
    return x, xd, xdd


def kernel_figures(preset: str, batch: int) -> dict:
    plat = stewart.Platform.preset(preset)
    both = stewart.Platform.preset(preset, threads=2)
    x, xd, xdd = states(plat.params, batch)
    tau = plat.inverse_dynamics(x, xd, xdd)
    one = (x[0], xd[0], xdd[0])
    out = {
        "single_inverse_dynamics_us": median_time(lambda: plat.inverse_dynamics(*one), 20000) * 1e6,
        "single_forward_dynamics_us": median_time(lambda: plat.forward_dynamics(x[0], xd[0], tau[0]), 20000) * 1e6,
        "batch_inverse_dynamics_us": median_time(lambda: plat.inverse_dynamics(x, xd, xdd), 3) / batch * 1e6,
        "batch_forward_dynamics_us": median_time(lambda: plat.forward_dynamics(x, xd, tau), 3) / batch * 1e6,
        "batch_mass_matrix_us": median_time(lambda: plat.mass_matrix(x), 3) / batch * 1e6,
        "batch_coriolis_vector_us": median_time(lambda: plat.coriolis_vector(x, xd), 3) / batch * 1e6,
        "threads2_inverse_dynamics_states_per_s": batch / median_time(lambda: both.inverse_dynamics(x, xd, xdd), 3),
        "threads2_forward_dynamics_states_per_s": batch / median_time(lambda: both.forward_dynamics(x, xd, tau), 3),
    }
    n_ref = 200
    ref_id = median_time(lambda: reference.inverse_dynamics(plat.params, x[:n_ref], xd[:n_ref], xdd[:n_ref]), 1, 5)
    ref_single = median_time(lambda: reference.inverse_dynamics(plat.params, *one), 20, 5)
    out["reference_batch_inverse_dynamics_us"] = ref_id / n_ref * 1e6
    out["reference_single_inverse_dynamics_us"] = ref_single * 1e6
    out["speedup_batch_vs_reference"] = out["reference_batch_inverse_dynamics_us"] / out["batch_inverse_dynamics_us"]
    out["speedup_single_vs_reference"] = out["reference_single_inverse_dynamics_us"] / out["single_inverse_dynamics_us"]
    return out


def simulation_figures(preset: str) -> dict:
    """Wall time of the paper's 5 s move at 1 kHz with RK4 and PID, in the compiled loop."""
    plat = stewart.Platform.preset(preset)
    goal = plat.home_pose + np.array([0.02, -0.01, -0.05, 0.05, 0.03, -0.04]) * np.array([plat.home_pose[2]] * 3 + [1] * 3)
    move = stewart.PointToPoint(plat.home_pose, goal, 5.0)
    pid = stewart.PID.tuned(plat)
    wall = median_time(lambda: stewart.simulate(plat, move, pid, dt=1e-3), 1, 7)
    return {"rk4_pid_5s_at_1kHz_ms": wall * 1e3}


def kernel_rows(preset: str, fig: dict) -> list[tuple[str, str, str]]:
    """Table rows (measure, median, target) for one preset's figures."""
    rows = [
        (f"[{preset}] inverse dynamics, one call from Python", f"{fig['single_inverse_dynamics_us']:.3f} us", "<= 1.5 us"),
        (f"[{preset}] forward dynamics, one call from Python", f"{fig['single_forward_dynamics_us']:.3f} us", ""),
        (f"[{preset}] inverse dynamics, C batch loop", f"{fig['batch_inverse_dynamics_us']:.3f} us/state", "<= 0.4 us"),
        (f"[{preset}] forward dynamics, C batch loop", f"{fig['batch_forward_dynamics_us']:.3f} us/state", "<= 0.7 us"),
        (f"[{preset}] mass matrix, C batch loop", f"{fig['batch_mass_matrix_us']:.3f} us/state", ""),
        (f"[{preset}] V xdot, C batch loop", f"{fig['batch_coriolis_vector_us']:.3f} us/state", ""),
        (f"[{preset}] inverse dynamics, 2 threads", f"{fig['threads2_inverse_dynamics_states_per_s'] / 1e6:.2f} M states/s", ">= 4 M/s"),
        (f"[{preset}] forward dynamics, 2 threads", f"{fig['threads2_forward_dynamics_states_per_s'] / 1e6:.2f} M states/s", ""),
        (f"[{preset}] numeric reference, inverse dynamics, batch of 200", f"{fig['reference_batch_inverse_dynamics_us']:.1f} us/state", ""),
        (f"[{preset}] numeric reference, inverse dynamics, one call", f"{fig['reference_single_inverse_dynamics_us']:.0f} us", ""),
        (f"[{preset}] kernel speed-up over reference, one state", f"{fig['speedup_single_vs_reference']:.0f}x", ">= 1000x"),
        (f"[{preset}] kernel speed-up over reference, batches", f"{fig['speedup_batch_vs_reference']:.0f}x", ""),
    ]
    if "rk4_pid_5s_at_1kHz_ms" in fig:
        rows.append((f"[{preset}] 5 s move, RK4 at 1 kHz with PID", f"{fig['rk4_pid_5s_at_1kHz_ms']:.1f} ms wall", "<= 50 ms"))
    return rows


def format_table(rows: list[tuple[str, str, str]]) -> str:
    width = max(len(r[0]) for r in rows)
    vwidth = max(len(r[1]) for r in rows)
    lines = [f"{'measure':<{width}}  {'median':>{vwidth}}  target", "-" * (width + vwidth + 12)]
    lines += [f"{a:<{width}}  {b:>{vwidth}}  {c}" for a, b, c in rows]
    return "\n".join(lines)


def main(presets=None, batch: int = 200_000) -> dict:
    """Measure every preset (or the given ones), print the table and return the figures."""
    results = {}
    rows = []
    for preset in presets or sorted(stewart.presets()):
        print(f"[bench] {preset} ...", flush=True)
        fig = kernel_figures(preset, batch)
        fig.update(simulation_figures(preset))
        results[preset] = fig
        rows += kernel_rows(preset, fig)
    print(format_table(rows))
    return results
