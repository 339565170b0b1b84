"""The bench tables: each target met, missed or unsettled by the 90 % interval of its median
(given figures: nothing here times anything; the measuring engine is tested in
tests/test_interleaved.py), the peers' chart drawing a bar for every figure, and the
documentation's blocks rewritten from the commands."""

import json
import math

import numpy as np
import pytest

from stewart.cli import bench
from stewart.cli.interleaved import REFERENCE, Measurement

pytest.importorskip("benchmarks", reason="needs the checkout (benchmarks/)")
from benchmarks import docs, report  # noqa: E402


def interval(target, position: str, spread: float = 0.02) -> Measurement:
    """A figure whose 90 % interval lies inside the target's bound, outside it, or across it,
    by ``spread`` of the bound (nine rounds)."""
    bound, inside = target.bound, -1 if target.at_most else 1
    centre = {"inside": bound * (1 + inside * 2 * spread), "outside": bound * (1 - inside * 2 * spread),
              "across": bound}[position]
    return Measurement(centre, centre - spread * bound, centre + spread * bound, 9)


@pytest.mark.parametrize("key", sorted(bench.TARGETS))
def test_each_target_is_met_missed_or_unsettled_by_its_interval(key):
    target = bench.TARGETS[key]
    assert bench.measure_row("m", key, interval(target, "inside"), 1.0, "us", ".3f")[4] == "met"
    assert bench.measure_row("m", key, interval(target, "outside"), 1.0, "us", ".3f")[4] == "MISSED"
    assert bench.measure_row("m", key, interval(target, "across"), 1.0, "us", ".3f")[4] == "unsettled"
    bound = Measurement(target.bound, target.bound, target.bound, 9)
    assert bench.measure_row("m", key, bound, 1.0, "us", ".3f")[4] == "met"  # the bound itself is met


def test_rows_show_the_target_and_the_spread_in_the_displayed_unit():
    figure = Measurement(3.97e6, 3.90e6, 4.02e6, 31)
    row = bench.measure_row("throughput", "threads2_inverse_dynamics_states_per_s", figure, 1e-6, "M states/s", ".2f")
    assert row == ("throughput", "3.97 M states/s", "3.90-4.02 (31)", ">= 4 M states/s", "unsettled")
    two_cores = figure._replace(high=3.95e6, gauge=0.84)
    row = bench.measure_row("throughput", "threads2_inverse_dynamics_states_per_s", two_cores, 1e-6, "M states/s",
                            ".2f")
    assert row[2:] == ("3.90-3.95 (31, gauge 0.84)", ">= 4 M states/s", "unsettled")
    assert bench.measure_row("throughput", "threads2_inverse_dynamics_states_per_s", two_cores._replace(gauge=1.9),
                             1e-6, "M states/s", ".2f")[4] == "MISSED"
    assert bench.measure_row("mass matrix", "no target", 0.3, 1.0, "us", ".1f") == ("mass matrix", "0.3 us", "", "", "")


def test_the_table_counts_the_targets_met_missed_and_unsettled():
    fig = {key: Measurement(1.0, 0.99, 1.01, 9) for _, key, *_ in bench.KERNEL_MEASURES}
    fig["batch_inverse_dynamics_us"] = interval(bench.TARGETS["batch_inverse_dynamics_us"], "outside")
    fig["batch_forward_dynamics_us"] = interval(bench.TARGETS["batch_forward_dynamics_us"], "inside")
    fig["single_modes_us"] = interval(bench.TARGETS["single_modes_us"], "across")
    rows = bench.kernel_rows("p", fig)
    verdicts = {r[0]: r[4] for r in rows}
    assert verdicts["[p] inverse dynamics, C batch loop"] == "MISSED"
    assert verdicts["[p] forward dynamics, C batch loop"] == "met"
    assert verdicts["[p] modes (frequencies and shapes), one call from Python"] == "unsettled"
    last = bench.format_table(rows).splitlines()[-1]
    counts = {word: sum(v == spelling for v in verdicts.values()) for word, spelling in bench.VERDICTS.items()}
    assert sum(counts.values()) == len([k for _, k, *_ in bench.KERNEL_MEASURES if k in bench.TARGETS])
    assert last.startswith(f"targets: {counts['met']} met, {counts['missed']} missed, {counts['unsettled']} "
                           "unsettled (missed: ")
    assert "missed: [p] inverse dynamics, C batch loop" in last
    assert last.endswith("| unsettled: [p] modes (frequencies and shapes), one call from Python)")
    # The JSON's figures (a median by key, the interval under "spread") give the same rows.
    assert bench.kernel_rows("p", bench.figures_of(fig)) == rows


def test_each_figure_is_its_rounds_ratio_to_its_anchor():
    """The value a round gives, from the times of its sides, by hand: an absolute figure is its
    ratio to the yardstick times the yardstick's reference cost (a batch of 1024 states in
    0.4 ms while the yardstick takes its reference time: 400 us / 1024 = 0.390625 us a
    state); a two-core rate against the one-thread yardstick, with its gauge; a speed-up."""
    rounds = bench.Rounds()
    ref = REFERENCE.seconds
    rounds.absolute("batch_inverse_dynamics_us", None, 1024)
    rounds.absolute("generation_s", None, unit=1.0, both_cores=True)
    rounds.rate("threads2_inverse_dynamics_states_per_s", None, 200_000)
    rounds.speedup("threads2_speedup_inverse_dynamics", None, None)
    rounds.ratio("speedup_batch_vs_reference", None, None, 200, 1024)
    fig = rounds.pending
    assert fig["batch_inverse_dynamics_us"].value(4e-4, ref) == pytest.approx(0.390625, rel=1e-15)
    assert fig["batch_inverse_dynamics_us"].value(8e-4, 2 * ref) == pytest.approx(0.390625, rel=1e-15)
    assert fig["batch_inverse_dynamics_us"].target == bench.TARGETS["batch_inverse_dynamics_us"]
    assert fig["generation_s"].value(10.0, ref / 2, ref) == pytest.approx(20.0, rel=1e-15)
    # The yardstick on two threads runs 4 calls on each: in the time of 4 calls, both cores were free.
    assert fig["generation_s"].gauge(10.0, ref, 4 * ref) == 2.0 and fig["generation_s"].gauge(10.0, ref, 8 * ref) == 1.0
    # 200 000 states in 25 ms at the reference speed: 8 M states a second.
    assert fig["threads2_inverse_dynamics_states_per_s"].value(0.025, ref, 4 * ref) == pytest.approx(8e6, rel=1e-15)
    assert fig["threads2_speedup_inverse_dynamics"].value(2e-3, 1.1e-3, ref, 5 * ref) == pytest.approx(2 / 1.1)
    assert fig["threads2_speedup_inverse_dynamics"].gauge(2e-3, 1.1e-3, ref, 5 * ref) == pytest.approx(1.6)
    assert fig["speedup_batch_vs_reference"].value(8e-3, 1e-4) == pytest.approx((8e-3 / 200) / (1e-4 / 1024))
    # A figure without a target gets a third of the budget.
    assert fig["speedup_batch_vs_reference"].budget == rounds.budget / 3 == bench.BUDGET / 3


#: Figures of the shape ``python -m benchmarks`` records for each peer.
PEERS = {
    "casadi": {"ours_single_id_us": 0.80, "ours_single_fd_us": 1.16, "python_single_id_us": 120.0,
               "python_single_fd_us": 140.0, "ours_batch_id_us": 0.50, "ours_batch_fd_us": 0.70,
               "python_map_id_us": 71.0, "python_map_fd_us": 90.0, "ours_c_loop_id_us": 0.51,
               "ours_c_loop_fd_us": 0.83, "c_loop_id_us": 1.73, "c_loop_fd_us": 2.87},
    "sympy": {"ours_single_id_us": 0.98, "ours_single_fd_us": 1.17, "autowrap": {"single_id_us": 15.8,
              "single_fd_us": 21.7}, "pydy": {"single_id_us": 5.8, "single_fd_us": 15.7}},
    "mujoco": {"ours_rk4_ct_wall_ms": 23.5,
               "default": {"integrator": "Euler", "timestep_s": 0.002, "wall_per_simulated_s_ms": 5.1},
               "tight": {"integrator": "RK4", "timestep_s": 0.0001, "wall_per_simulated_s_ms": 404.0}},
}


#: Bars drawn when only these peers were measured: one call from Python (ours and each
#: peer, inverse and forward dynamics), batches (ours and CasADi, four measures) and the
#: simulation (ours and MuJoCo at two settings).
BARS = {("casadi", "sympy", "mujoco"): 4 * 2 + 2 * 4 + 3, ("sympy",): 3 * 2, ("casadi",): 2 * 2 + 2 * 4,
        ("mujoco",): 3}


@pytest.mark.parametrize("measured", sorted(BARS))
def test_every_bar_of_the_peers_chart_has_a_value(measured):
    peers = {name: PEERS[name] if name in measured else {"error": "not installed"} for name in PEERS}
    panels = report.chart_panels(peers)
    for _title, ylabel, groups, series in panels:
        assert "[µs]" in ylabel or "[ms]" in ylabel
        assert any(name.startswith("ours") for name in series)
        assert len(series) >= 2
        for values in series.values():
            assert len(values) == len(groups)
            assert all(math.isfinite(v) and v > 0 for v in values)
    drawn = sorted(v for _, _, _, series in panels for values in series.values() for v in values)
    assert len(drawn) == BARS[measured]
    if "casadi" in measured:
        assert drawn[0] == 0.5  # ours, inverse dynamics per state in a batch
    if "mujoco" in measured:
        assert drawn[-1] == 404.0  # MuJoCo at tight settings, ms per simulated second


def test_no_chart_without_a_peer():
    assert report.chart_panels({name: {"error": "not installed"} for name in PEERS}) == []


def test_peers_chart_is_written(tmp_path):
    pytest.importorskip("matplotlib")
    path = report.chart(PEERS, str(tmp_path / "peers.png"))
    assert path and (tmp_path / "peers.png").stat().st_size > 20_000


PYTEST_OUTPUT = """\
........                                                                 [100%]
=============================== warnings summary ===============================
============================ figures reached (worst case per check) ============================
FK(IK(x)) - x [m, rad]                    1.5e-12  (bound 1e-10)
J_C vs complex step of L (narayan2017)    4.0e-16  (bound 1e-13)
=========================== short test summary info ============================
SKIPPED [1] tests/test_peers.py:41: could not import 'casadi'
"""


def test_the_figures_table_is_taken_from_the_pytest_output():
    rows = [
        "FK(IK(x)) - x [m, rad]                    1.5e-12  (bound 1e-10)",
        "J_C vs complex step of L (narayan2017)    4.0e-16  (bound 1e-13)",
    ]
    assert docs.summary_table(PYTEST_OUTPUT) == rows
    # With nothing skipped, pytest -q ends with its count right after the table.
    no_skips = PYTEST_OUTPUT.split("=========================== short")[0] + "764 passed, 6 deselected in 100.40s\n"
    assert docs.summary_table(no_skips) == rows


def test_a_docs_block_is_replaced_between_its_markers():
    text = "intro\n<!-- BEGIN checks: generated -->\nold\nlines\n<!-- END checks -->\nafter\n"
    out = docs.replace_block(text, "checks", "new")
    assert out == "intro\n<!-- BEGIN checks: generated -->\nnew\n<!-- END checks -->\nafter\n"
    assert docs.replace_block(out, "checks", "new") == out  # deterministic
    with pytest.raises(SystemExit, match="no <!-- BEGIN validate"):
        docs.replace_block(text, "validate", "x")


def test_performance_block_marks_targets_from_the_bench_figures(tmp_path):
    measured = {key: interval(bench.TARGETS[key], "inside") if key in bench.TARGETS else Measurement(1.0, 0.9, 1.1, 9)
                for _, key, *_ in bench.KERNEL_MEASURES}
    measured["batch_inverse_dynamics_us"] = Measurement(0.45, 0.44, 0.47, 41)
    measured["batch_forward_dynamics_us"] = Measurement(0.7, 0.68, 0.7, 9)
    measured["single_modes_us"] = Measurement(19.0, 18.0, 21.0, 133)
    fig = bench.figures_of(measured)
    gen_bound = bench.TARGETS["generation_s"].bound
    results = {"date": "2026-11-23 15:00 UTC", "kernel": {"narayan2017": fig, "motion_simulator": fig},
               "machine": {"platform": "Linux-6.1-x86_64-with-glibc2.36", "processor": "AMD EPYC", "cpus": 2,
                           "python": "3.11.7", "numpy": "2.4", "compiler": "cc 12.2.0", "march": "native",
                           "load_average": 1.27},
               "generation": bench.figures_of({
                   "generation_s": Measurement(gen_bound + 0.65, gen_bound + 0.6, gen_bound + 0.7, 2, (), 1.8),
                   "clean_build_s": Measurement(17.0, 17.0, 17.0, 1, (), 1.8)}),
               "code": {"generated_c_bytes": 580_000, "generated_c_lines": 11289,
                        "operation_counts": {"inverse_dynamics_axisym": 1781, "mass_matrix_general": 2045}}}
    (tmp_path / "b.json").write_text(json.dumps(results))
    block = docs.performance_block(tmp_path / "b.json")
    assert "2026-11-23 15:00 UTC, 2-core AMD EPYC, Linux x86_64" in block
    assert "-march=native, load average 1.3 at the start" in block
    assert "| inverse dynamics, C batch loop | 0.450 us/state | 0.440-0.470 (41) | <= 0.4 us/state | MISSED |" in block
    assert "| forward dynamics, C batch loop | 0.700 us/state | 0.680-0.700 (9) | <= 0.7 us/state | met |" in block
    assert ("| modes (frequencies and shapes), one call from Python | 19.00 us | 18.00-21.00 (133) | <= 20 us "
            "| unsettled |") in block
    assert (f"| generation (python -m codegen) | {gen_bound + 0.65:.2f} s | {gen_bound + 0.6:.2f}-{gen_bound + 0.7:.2f}"
            f" (2, gauge 1.80) | <= {gen_bound:g} s | MISSED |") in block
    assert "| operations: inverse_dynamics_axisym | 1781 |  |  |  |" in block
    assert "mass_matrix_general" not in block and "[motion_simulator]" not in block.split("Over every table")[0]
    assert block.count("| MISSED |") == 2 and block.count("| unsettled |") == 1
    per_preset = len([key for _, key, *_ in bench.KERNEL_MEASURES if key in bench.TARGETS])
    met = 2 * per_preset + 2 - 3 - 2  # every target of both presets and the build, but 3 missed and 2 unsettled
    assert block.splitlines()[-1] == (
        f"Over every table of that run (every preset, the batch loop): targets: {met} met, 3 missed, 2 unsettled "
        "(missed: [narayan2017] inverse dynamics, C batch loop; [motion_simulator] inverse dynamics, C batch loop; "
        "generation (python -m codegen) | unsettled: [narayan2017] modes (frequencies and shapes), one call from "
        "Python; [motion_simulator] modes (frequencies and shapes), one call from Python).")


def test_forward_differences_of_a_known_function():
    """The benchmark's forward differences: rows are outputs, columns the inputs of every
    argument in order, each shifted by 1e-7 max(1, |input|)."""
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(3, 6)) * 10, rng.normal(size=(3, 6))
    jac = bench.forward_differences(lambda u, v: np.concatenate([u * u, u * v], axis=-1), a, b)
    want = np.zeros((3, 12, 12))
    for n in range(3):
        want[n, :6, :6] = np.diag(2 * a[n])
        want[n, 6:, :6] = np.diag(b[n])
        want[n, 6:, 6:] = np.diag(a[n])
    # u^2 has second derivative 2: the forward difference is off by the shift, 1e-7 max(1, |u|)
    # (reached 0.41 of the bound).
    np.testing.assert_allclose(jac, want, rtol=0, atol=2e-7 * max(1.0, np.abs(a).max()) + 1e-6)


def _casadi_derivatives(compiled: bool) -> dict:
    fig = {"ours_single_us": 5.0, "ours_batch_us": 3.5, "python_single_us": 1150.0, "python_map_us": 1050.0,
           "generated_c_bytes": 4.3 * 2**20, "jacobian_rel_error": 1.4e-13}
    fig.update({"c_loop_us": 105.0, "compile_s": 580.0} if compiled else
               {"compile_s": None, "did_not_finish": "did not finish compiling in 600 s"})
    return {"inverse_dynamics_derivatives": fig, "forward_dynamics_derivatives": fig}


@pytest.mark.parametrize("compiled", [True, False])
def test_casadi_derivative_rows_say_when_the_compilation_did_not_finish(compiled):
    rows = {r[0]: r[1:] for r in report.rows({"casadi_derivatives": _casadi_derivatives(compiled)}, {})}
    c_row = rows["CasADi ca.jacobian: tau + dtau/d(x, xd, xdd), generated C in a C loop (ours: Platform batch)"]
    if compiled:
        assert c_row == ("3.50 us/state", "105 us/state", "30x")
    else:
        assert c_row == ("3.50 us/state", "did not finish compiling in 600 s", "")
    assert rows["CasADi ca.jacobian: xdd + dxdd/d(x, xd, tau), one call from Python"] == ("5.00 us", "1150 us", "230x")


def test_pinocchio_rows_compare_one_call_and_batches():
    fig = {"pinocchio_version": "4.1.0", "constraint_dynamics_us": 13.0, "constraint_dynamics_derivatives_us": 77.0,
           "ours_single_forward_dynamics_us": 1.3, "ours_single_forward_dynamics_derivatives_us": 5.5,
           "ours_batch_forward_dynamics_derivatives_us": 2.2, "platform_acceleration_rel_error": 1.8e-15,
           "dxdd_dtau_rel_error": 1.3e-15}
    rows = [r for r in report.rows({"pinocchio": fig}, {}) if r[0].startswith("Pinocchio")]
    assert [r[1:] for r in rows] == [("1.30 us", "13.0 us", "10.0x"), ("5.50 us", "77.0 us", "14.0x"),
                                     ("2.20 us/state", "77.0 us", "35.0x"), ("", "1.8e-15 / 1.3e-15", "")]


def figure(median: float, low: float | None = None, high: float | None = None, rounds: int = 9,
           gauge: float | None = None) -> dict:
    """A figure as the JSON records it (a narrow interval about the median by default)."""
    return {"median": median, "low": median * 0.99 if low is None else low,
            "high": median * 1.01 if high is None else high, "rounds": rounds, "gauge": gauge}


def test_batch_loop_rows_mark_the_batch_targets():
    """The vector batch table: per-state times in us on each path, the speed-up over the row-by-row
    loop, and each target met, missed or unsettled by the dispatched path's figures (a row of
    two targets missed if either is, met if both are)."""
    from benchmarks import batch_loop

    def loop(scale):
        out = {"inverse_dynamics": figure(0.09 * scale), "forward_dynamics": figure(0.16 * scale),
               "mass_matrix": figure(0.08, 0.079, 0.0815), "coriolis_vector": figure(0.05), "gravity_vector":
               figure(0.09)}
        out.update({name: figure(1.0) for name in batch_loop.FUNCTIONS[5:]})
        out["regressor"] = figure(0.38 * scale)
        return out

    paths = {"avx2": loop(2.0), "avx512": loop(1.0), "native": loop(0.9)}
    scalar = {name: figure(value) for name, value in zip(batch_loop.FUNCTIONS, [0.4, 0.6, 0.26, 0.27, 0.1, 4, 4, 4,
                                                                                 1.6])}
    check = {name: {"worst": 2e-15, "failures": 3 if name == "forward_dynamics" else 0}
             for name in batch_loop.FUNCTIONS}
    fig = {"paths": list(paths), "dispatched": "avx512", "lanes": {"avx2": 4, "avx512": 8, "native": 8},
           "batch": paths, "scalar": scalar, "check": check,
           "targets": {"inverse_dynamics_speedup": figure(4.0), "regressor_ratio": figure(3.8),
                       "native_ratio": figure(1.11), "python_overhead": figure(1.05),
                       "python_threads2_states_per_s": figure(20e6, gauge=1.9),
                       "python_threads2_speedup": figure(2.1, gauge=1.9)},
           "casadi": {"casadi_version": "3.8.2", "c_loop_us": {"avx2": figure(2.5), "avx512": figure(0.5),
                                                               "native": figure(0.45)},
                      "ratio": {"avx2": figure(0.08), "avx512": figure(0.2), "native": figure(0.2)}}}
    table = batch_loop.rows(fig)
    (inverse, forward, mass, _, gravity, derivatives, _, _, _, regressor, native, python, threads, casadi_c,
     casadi_avx2) = table
    assert inverse[1:5] == ("0.400 us", "0.180 us (2.2x)", "0.090 us (4.4x)", "0.081 us (4.9x)")
    assert inverse[-3:] == ("batch 0.0891-0.0909 (9); speed-up 3.96-4.04 (9)", "<= 0.10 us, >= 3.5x", "met")
    assert forward[-1] == "MISSED" and "3 failed rows" in forward[0]
    assert mass[-3:] == ("batch 0.079-0.0815 (9)", "<= 0.08 us", "unsettled")
    assert gravity[-2:] == ("<= 0.08 us", "MISSED")
    assert derivatives[1:] == ("4.000 us", "1.000 us (4.0x)", "1.000 us (4.0x)", "1.000 us (4.0x)", "", "", "")
    assert regressor[-4:] == ("3.80x", "3.76-3.84 (9)", "<= 4x", "met")
    assert native[-4:] == ("1.11x", "1.1-1.12 (9)", "<= 1.05x", "MISSED")
    assert python[-4:] == ("1.05x C loop", "1.04-1.06 (9)", "<= 1.10x C loop", "met")
    assert threads[-4:] == ("20.0 M states/s (2.10x 1 thread)", "19.8-20.2 (9, gauge 1.90) M/s; 2.08-2.12 (9, gauge "
                            "1.90)", ">= 18 M/s, >= 1.8x", "met")
    # CasADi's C compiled for each path: ours over it on that path.
    assert casadi_c[2:5] == ("2.500 us (ours 0.080x)", "0.500 us (ours 0.200x)", "0.450 us (ours 0.200x)")
    assert casadi_avx2[-4:] == ("0.080x", "0.0792-0.0808 (9)", "<= 0.10x", "met")
    assert "| avx512 (8 lanes) |" in batch_loop.format_rows(fig).replace("  ", "")
    # Two threads below the target while the second core was busy (the gauge under the floor): unsettled.
    fig["targets"]["python_threads2_speedup"] = figure(0.2, gauge=0.9)
    fig["targets"]["python_threads2_states_per_s"] = figure(2e6, gauge=0.9)
    assert batch_loop.rows(fig)[12][-1] == "unsettled"
    fig["casadi"] = {"skipped": "casadi is not installed"}
    assert batch_loop.rows(fig)[-1][0] == "inverse_dynamics, CasADi: skipped (casadi is not installed)"


def test_cluster_estimate_by_hand():
    from benchmarks import studies

    fig = {"chunk_s": 0.1, "chunk_size": 50_000, "task_overhead_s": 0.004}

    def near(a, b):  # the hand products to a few ulp (reached 0)
        return np.isclose(a, b, rtol=1e-15, atol=0)

    # 1e10 states at 2 us each over 200 cores: 100 s of work; 2e5 tasks at 4 ms: 800 s on the scheduler.
    est = studies.estimate(fig, designs=1e4, states=1e6, nodes=100, cores=2)
    assert est["tasks"] == 2e5 and near(est["compute_s"], 100.0) and near(est["scheduler_s"], 800.0)
    assert est["total_s"] == est["scheduler_s"] and near(est["efficiency"], 0.125)
    whole = studies.estimate(fig, chunk_size=1e6)
    assert whole["tasks"] == 1e4 and near(whole["scheduler_s"], 40.0) and whole["efficiency"] == 1.0


def test_studies_rows_mark_the_targets():
    from benchmarks import studies

    fig = {"local_states_per_s": 7.0e6, "cluster_states_per_s": 6.0e6, "large_states": 10**7, "chunk_size": 100_000,
           "task_overhead_s": 0.0018, **bench.figures_of({
               "ratio": Measurement(6.0 / 7.0, 0.84, 0.87, 5, (), 1.9),
               "large_s": Measurement(1.5, 1.4, 1.6, 2, (), 1.9),
               "chunk_s": Measurement(0.028, 0.027, 0.029, 9)})}
    rows = {row[0]: row[1:] for row in studies.rows(fig)}
    ratio = "envelope, 2-worker LocalCluster (Dask's defaults) over in process (2 threads)"
    assert rows[ratio] == ("86%", "84-87 (5, gauge 1.90)", ">= 85%", "unsettled")
    assert rows["envelope of 1e+07 states, in process"] == ("1.5 s", "1.4-1.6 (2, gauge 1.90)", "<= 5 s", "met")
    assert rows["envelope, in process (2 threads), as measured"][0] == "7.000 M states/s"
    fig = {**fig, **bench.figures_of({"ratio": Measurement(0.8, 0.78, 0.82, 5, (), 1.9),
                                      "large_s": Measurement(5.5, 5.4, 5.6, 2, (), 1.9)})}
    slow = {row[0]: row[-1] for row in studies.rows(fig)}
    assert slow[ratio] == slow["envelope of 1e+07 states, in process"] == "MISSED"


def test_identification_rows_mark_the_target():
    from benchmarks import identification

    base = Measurement(0.16, 0.15, 0.17, 9)
    fast = identification.rows({"samples": 100_000, **bench.figures_of(
        {"identify_s": Measurement(2.5, 2.4, 2.6, 3, (), 1.8), "base_parameters_s": base})})
    slow = identification.rows({"samples": 100_000, **bench.figures_of(
        {"identify_s": Measurement(3.5, 3.4, 3.6, 3, (), 1.8), "base_parameters_s": base})})
    busy = identification.rows({"samples": 100_000, **bench.figures_of(
        {"identify_s": Measurement(3.5, 3.4, 3.6, 3, (), 0.7), "base_parameters_s": base})})
    assert fast[0][1:] == ("2.50 s", "2.40-2.60 (3, gauge 1.80)", "<= 3 s", "met")
    assert slow[0][-1] == "MISSED" and busy[0][-1] == "unsettled"
    assert "100,000 samples" in fast[0][0] and fast[1][1:3] == ("160 ms", "150-170 (9)")


def test_calibration_rows_mark_the_target():
    from benchmarks import calibration

    fast = calibration.rows({"poses": 200, **bench.figures_of({"calibrate_s": Measurement(0.12, 0.11, 0.13, 40)})})
    slow = calibration.rows({"poses": 200, **bench.figures_of({"calibrate_s": Measurement(1.5, 1.4, 1.6, 40)})})
    assert fast[0][1:] == ("120 ms", "110-130 (40)", "<= 1000 ms", "met") and slow[0][-1] == "MISSED"
    assert "200 measured poses" in fast[0][0]


def test_cueing_rows_mark_the_target():
    from benchmarks import cueing

    fig = {"preset": "motion_simulator", "horizon_s": 1.0, "steps": 10, "step_max_ms": 9.0, "qp_median_ms": 1.0}
    for median, low, high, verdict in ((0.9, 0.8, 0.95, "met"), (1.1, 1.05, 1.2, "MISSED"),
                                       (1.0, 0.9, 1.1, "unsettled")):
        speedup = Measurement(3.0 - median, 3.0 - high, 3.0 - low, 2)  # 2.1 met, 1.9 missed, 2.0 unsettled
        measured = bench.figures_of({"step_median_ms": Measurement(median, low, high, 2), "step_speedup": speedup})
        step, faster = cueing.rows({**fig, **measured})[:2]
        assert step[2:] == (f"{low:.2f}-{high:.2f} (2)", "<= 1 ms", verdict)
        assert faster[2:] == (f"{3.0 - high:.2f}-{3.0 - low:.2f} (2)", ">= 2x", verdict)
    # a rotary rig's step has no anchor: its rows are the median's with its target and the two as measured
    rotary = cueing.rows({**fig, "preset": "simrig100", **bench.figures_of({"step_median_ms": Measurement(0.7, 0.6,
                                                                                                          0.8, 2)})})
    assert len(rotary) == 3 and "simrig100" in rotary[0][0] and rotary[0][3:] == ("<= 1 ms", "met")


def test_rotary_kernel_rows_mark_the_targets():
    """The rotary torques and forward dynamics over the linear model's carry the 1.5x target
    (met, MISSED, unsettled by the interval); the derivatives' rows carry none."""
    from benchmarks import rotary_kernel

    names = list(rotary_kernel.FUNCTIONS)
    for median, low, high, verdict in ((1.2, 1.1, 1.3, "met"), (1.7, 1.6, 1.8, "MISSED"),
                                       (1.5, 1.4, 1.6, "unsettled")):
        measured = {**{f"rotary_over_linear_{n}": Measurement(median, low, high, 5) for n in names},
                    **{f"rotary_batch_{n}_us": Measurement(0.2, 0.19, 0.21, 5) for n in names}}
        out = rotary_kernel.rows({"rotary": "simrig100", "linear": "motion_simulator", "path": "avx2",
                                  **bench.figures_of(measured)})
        assert len(out) == 2 * len(names)
        by_name = dict(zip((f"{kind}_{n}" for n in names for kind in ("batch", "ratio")), out))
        for n in ("inverse_dynamics", "forward_dynamics"):
            assert by_name[f"ratio_{n}"][1:] == (f"{median:.2f}x", f"{low:.2f}-{high:.2f} (5)", "<= 1.5x", verdict)
        for n in names[2:]:
            assert by_name[f"ratio_{n}"][3:] == ("", "") and by_name[f"batch_{n}"][1] == "0.200 us/state"
        assert "avx2" in by_name["ratio_forward_dynamics"][0] and "simrig100" in by_name["batch_inverse_dynamics"][0]


def test_motor_sizing_rows_mark_the_target():
    from benchmarks import motor_sizing

    fig = {"preset": "simrig100", "samples": 216_000, "megabytes": 65.0}
    for median, low, high, verdict in ((0.9, 0.8, 0.95, "met"), (1.1, 1.05, 1.2, "MISSED"),
                                       (1.0, 0.9, 1.1, "unsettled")):
        measured = bench.figures_of({"motor_sizing_s": Measurement(median / 4, low / 4, high / 4, 3),
                                     "motor_sizing_read_s": Measurement(median, low, high, 3),
                                     "motor_sizing_read_and_size_s": Measurement(median, low, high, 3)})
        size, read, both = motor_sizing.rows({**fig, **measured})
        assert size[3:] == ("<= 1 s", "met") and read[3:] == ("", "")
        assert both[1:] == (f"{median:.2f} s", f"{low:.2f}-{high:.2f} (3)", "<= 1 s", verdict)
        assert "216,000 samples" in both[0] and "reading and sizing" in both[0]
