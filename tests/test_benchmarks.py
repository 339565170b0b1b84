"""The bench tables: each target marked met or missed from the measured median, the peers'
chart drawing a bar for every figure, and the README blocks rewritten from the commands."""

import json
import math

import pytest

from stewart import bench

pytest.importorskip("benchmarks", reason="needs the checkout (benchmarks/)")
from benchmarks import readme, report  # noqa: E402


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
    assert readme.summary_table(PYTEST_OUTPUT) == rows
    # With nothing skipped, pytest -q ends with its count right after the table.
    no_skips = PYTEST_OUTPUT.split("=========================== short")[0] + "764 passed, 6 deselected in 100.40s\n"
    assert readme.summary_table(no_skips) == rows


def test_a_readme_block_is_replaced_between_its_markers():
    text = "intro\n<!-- BEGIN checks: generated -->\nold\nlines\n<!-- END checks -->\nafter\n"
    out = readme.replace_block(text, "checks", "new")
    assert out == "intro\n<!-- BEGIN checks: generated -->\nnew\n<!-- END checks -->\nafter\n"
    assert readme.replace_block(out, "checks", "new") == out  # deterministic
    with pytest.raises(SystemExit, match="no <!-- BEGIN validate"):
        readme.replace_block(text, "validate", "x")


def test_performance_block_marks_targets_from_the_bench_figures(tmp_path):
    fig = {key: bench.TARGETS[key].bound if key in bench.TARGETS else 1.0 for _, key, *_ in bench.KERNEL_MEASURES}
    fig["batch_inverse_dynamics_us"] = 0.45
    results = {"date": "2026-11-23 15:00 UTC", "kernel": {"narayan2017": fig, "motion_simulator": fig},
               "machine": {"platform": "Linux-6.1-x86_64-with-glibc2.36", "processor": "AMD EPYC", "cpus": 2,
                           "python": "3.11.7", "numpy": "2.4", "compiler": "cc 12.2.0", "march": "native",
                           "load_average": 1.27},
               "generation": {"generation_s": 10.65, "clean_build_s": 17.0},
               "code": {"generated_c_bytes": 580_000, "generated_c_lines": 11289,
                        "operation_counts": {"inverse_dynamics_axisym": 1781, "mass_matrix_general": 2045}}}
    (tmp_path / "b.json").write_text(json.dumps(results))
    block = readme.performance_block(tmp_path / "b.json")
    assert "2026-11-23 15:00 UTC, 2-core AMD EPYC, Linux x86_64" in block
    assert "-march=native, load average 1.3 at the start" in block
    assert "| inverse dynamics, C batch loop | 0.450 us/state | <= 0.4 us/state | MISSED |" in block
    assert "| forward dynamics, C batch loop | 0.700 us/state | <= 0.7 us/state | met |" in block
    assert "| generation (python -m codegen) | 10.65 s | <= 10 s | MISSED |" in block
    assert "| operations: inverse_dynamics_axisym | 1781 |  |  |" in block
    assert "mass_matrix_general" not in block and "[motion_simulator]" not in block.split("Targets")[0]
    assert block.count("MISSED") == 2
    assert block.splitlines()[-1] == (
        "Targets over every preset in that run: 15 met, 3 missed ([narayan2017] inverse dynamics, C batch "
        "loop; [motion_simulator] inverse dynamics, C batch loop; generation (python -m codegen)).")
