"""The bench tables: each target marked met or missed from the measured median, the peers'
chart drawing a bar for every figure, and the documentation's blocks rewritten from the commands."""

import json
import math

import numpy as np
import pytest

from stewart.cli import bench

pytest.importorskip("benchmarks", reason="needs the checkout (benchmarks/)")
from benchmarks import docs, report  # noqa: E402


@pytest.mark.parametrize("key", sorted(bench.TARGETS))
def test_each_target_is_met_or_missed_by_the_median(key):
    target = bench.TARGETS[key]
    inside = target.bound * (0.99 if target.at_most else 1.01)
    outside = target.bound * (1.01 if target.at_most else 0.99)
    assert bench.measure_row("m", key, inside, 1.0, "us", ".3f")[3] == "met"
    assert bench.measure_row("m", key, outside, 1.0, "us", ".3f")[3] == "MISSED"
    assert bench.measure_row("m", key, target.bound, 1.0, "us", ".3f")[3] == "met"  # the bound itself is met


def test_rows_show_the_target_in_the_displayed_unit():
    row = bench.measure_row("throughput", "threads2_inverse_dynamics_states_per_s", 3.97e6, 1e-6, "M states/s", ".2f")
    assert row == ("throughput", "3.97 M states/s", ">= 4 M states/s", "MISSED")
    assert bench.measure_row("mass matrix", "no target", 0.3, 1.0, "us", ".1f") == ("mass matrix", "0.3 us", "", "")


def test_the_table_counts_the_targets_met_and_missed():
    fig = {key: 1.0 for _, key, *_ in bench.KERNEL_MEASURES}
    fig["batch_inverse_dynamics_us"] = 0.45  # target <= 0.4: missed
    fig["batch_forward_dynamics_us"] = 0.6  # target <= 0.7: met
    rows = bench.kernel_rows("p", fig)
    verdicts = {r[0]: r[3] for r in rows}
    assert verdicts["[p] inverse dynamics, C batch loop"] == "MISSED"
    assert verdicts["[p] forward dynamics, C batch loop"] == "met"
    last = bench.format_table(rows).splitlines()[-1]
    n_met = sum(v == "met" for v in verdicts.values())
    n_missed = sum(v == "MISSED" for v in verdicts.values())
    assert n_met + n_missed == len([k for _, k, *_ in bench.KERNEL_MEASURES if k in bench.TARGETS])
    assert last.startswith(f"targets: {n_met} met, {n_missed} missed: ")
    assert "[p] inverse dynamics, C batch loop" in last


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
    fig = {key: bench.TARGETS[key].bound if key in bench.TARGETS else 1.0 for _, key, *_ in bench.KERNEL_MEASURES}
    fig["batch_inverse_dynamics_us"] = 0.45
    results = {"date": "2026-11-23 15:00 UTC", "kernel": {"narayan2017": fig, "motion_simulator": fig},
               "machine": {"platform": "Linux-6.1-x86_64-with-glibc2.36", "processor": "AMD EPYC", "cpus": 2,
                           "python": "3.11.7", "numpy": "2.4", "compiler": "cc 12.2.0", "march": "native",
                           "load_average": 1.27},
               "generation": {"generation_s": bench.TARGETS["generation_s"].bound + 0.65, "clean_build_s": 17.0},
               "code": {"generated_c_bytes": 580_000, "generated_c_lines": 11289,
                        "operation_counts": {"inverse_dynamics_axisym": 1781, "mass_matrix_general": 2045}}}
    (tmp_path / "b.json").write_text(json.dumps(results))
    block = docs.performance_block(tmp_path / "b.json")
    assert "2026-11-23 15:00 UTC, 2-core AMD EPYC, Linux x86_64" in block
    assert "-march=native, load average 1.3 at the start" in block
    assert "| inverse dynamics, C batch loop | 0.450 us/state | <= 0.4 us/state | MISSED |" in block
    assert "| forward dynamics, C batch loop | 0.700 us/state | <= 0.7 us/state | met |" in block
    bound = bench.TARGETS["generation_s"].bound
    assert f"| generation (python -m codegen) | {bound + 0.65:.2f} s | <= {bound:g} s | MISSED |" in block
    assert "| operations: inverse_dynamics_axisym | 1781 |  |  |" in block
    assert "mass_matrix_general" not in block and "[motion_simulator]" not in block.split("Targets")[0]
    assert block.count("MISSED") == 2
    assert block.splitlines()[-1] == (
        "Targets over every preset in that run: 23 met, 3 missed ([narayan2017] inverse dynamics, C batch "
        "loop; [motion_simulator] inverse dynamics, C batch loop; generation (python -m codegen)).")


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


def test_batch_loop_rows_mark_the_batch_targets():
    """The vector batch table: per-state times in us on each path, the speed-up over the row-by-row
    loop, and each target met or missed by the dispatched path's figures."""
    from benchmarks import batch_loop

    def loop(lanes, scale):
        out = {"lanes": lanes, "inverse_dynamics": (0.40e-6, 0.10e-6 * scale, 2e-15, 0),
               "forward_dynamics": (0.6e-6, 0.16e-6 * scale, 1e-15, 3), "mass_matrix": (0.26e-6, 0.08e-6, 0.0, 0),
               "coriolis_vector": (0.27e-6, 0.05e-6, 0.0, 0), "gravity_vector": (0.1e-6, 0.09e-6, 0.0, 0)}
        out.update({name: (4e-6, 1e-6, 3e-15, 0) for name in batch_loop.FUNCTIONS[5:]})
        out["regressor"] = (1.6e-6, 0.38e-6 * scale, 1e-15, 0)
        return out

    paths = {"avx2": loop(4, 2.0), "avx512": loop(8, 1.0), "native": loop(8, 0.9)}
    fig = {"paths": paths, "dispatched": "avx512", "c_loop": paths["avx512"], "python_inverse_dynamics_us": 0.105,
           "python_threads2_inverse_dynamics_us": 0.05,
           "casadi": {"casadi_version": "3.8.2", "c_loop_s": {"avx2": 2.5e-6, "avx512": 0.5e-6, "native": 0.45e-6},
                      "map_thread2_s": 0.4e-6}}
    table = batch_loop.rows(fig)
    (inverse, forward, _, _, gravity, derivatives, _, _, _, regressor, native, python, threads, casadi_c, casadi_avx2,
     casadi_map) = table
    assert inverse[1:] == ("0.400 us", "0.200 us (2.0x)", "0.100 us (4.0x)", "0.090 us (4.4x)",
                           "<= 0.10 us, >= 3.5x", "met")
    assert forward[-1] == "MISSED" and "3 failed rows" in forward[0]
    assert gravity[-3:] == ("0.090 us (1.1x)", "<= 0.08 us", "MISSED")
    assert derivatives[1:] == ("4.000 us", "1.000 us (4.0x)", "1.000 us (4.0x)", "1.000 us (4.0x)", "", "")
    assert regressor[-3:] == ("3.80x", "<= 4x", "met")  # 0.38 us over 0.10 us on the dispatched path
    assert native[-3:] == ("1.11x", "<= 1.05x", "MISSED")
    assert python[-3:] == ("0.105 us (1.05x C loop)", "<= 1.10x C loop", "met")
    assert threads[-3:] == ("0.050 us, 20.0 M states/s (2.10x 1 thread)", ">= 18 M/s, >= 1.8x", "met")
    # CasADi's C compiled for each path: ours over it on that path (0.2 / 2.5, 0.1 / 0.5, 0.09 / 0.45).
    assert casadi_c[2:5] == ("2.500 us (ours 0.080x)", "0.500 us (ours 0.200x)", "0.450 us (ours 0.200x)")
    assert casadi_avx2[-3:] == ("0.080x", "<= 0.10x", "met")
    assert casadi_map[-3] == "0.400 us (ours: 0.050 us, 8.0x)"
    assert "| avx512 (8 lanes) |" in batch_loop.format_rows(fig).replace("  ", "")
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

    fig = {"local_states_per_s": 7.0e6, "cluster_states_per_s": 6.0e6, "ratio": 6.0 / 7.0, "large_states": 10**7,
           "large_s": 1.5, "chunk_size": 100_000, "chunk_s": 0.028, "task_overhead_s": 0.0018}
    rows = {row[0]: row[1:] for row in studies.rows(fig)}
    assert rows["envelope, 2-worker LocalCluster (Dask's defaults)"] == ("6.000 M states/s (86% of in process)",
                                                                         ">= 85%", "met")
    assert rows["envelope of 1e+07 states, in process"] == ("1.5 s", "<= 5 s", "met")
    slow = {row[0]: row[-1] for row in studies.rows({**fig, "ratio": 0.8, "large_s": 5.5})}
    assert slow["envelope, 2-worker LocalCluster (Dask's defaults)"] == slow["envelope of 1e+07 states, in process"] \
        == "MISSED"


def test_identification_rows_mark_the_target():
    from benchmarks import identification

    fast = identification.rows({"samples": 100_000, "identify_s": 2.5, "base_parameters_s": 0.16})
    slow = identification.rows({"samples": 100_000, "identify_s": 3.5, "base_parameters_s": 0.16})
    assert fast[0][1:] == ("2.50 s", "<= 3 s", "met") and slow[0][-1] == "MISSED"
    assert "100,000 samples" in fast[0][0] and fast[1][1] == "160 ms"


def test_calibration_rows_mark_the_target():
    from benchmarks import calibration

    fast = calibration.rows({"poses": 200, "calibrate_s": 0.12})
    slow = calibration.rows({"poses": 200, "calibrate_s": 1.5})
    assert fast[0][1:] == ("120 ms", "<= 1 s", "met") and slow[0][-1] == "MISSED"
    assert "200 measured poses" in fast[0][0]


def test_cueing_rows_mark_the_target():
    from benchmarks import cueing

    fig = {"preset": "motion_simulator", "horizon_s": 1.0, "steps": 10, "step_max_ms": 9.0, "qp_median_ms": 1.0}
    assert cueing.rows({**fig, "step_median_ms": 1.9})[0][3] == "met"
    assert cueing.rows({**fig, "step_median_ms": 2.1})[0][3] == "MISSED"
