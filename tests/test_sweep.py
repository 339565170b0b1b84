"""Design sweeps (stewart.studies.sweep): the design parameters against hand-built layouts, the Pareto
front against its definition, each design's metrics against separate envelope and workspace
runs, the same result on a 2-worker Dask cluster, and one-line errors naming the field."""

from __future__ import annotations

import json

import numpy as np
import pytest
from cli_outputs import check_sweep_table

import stewart
from stewart.studies import envelope, sweep, workspace
from stewart.model.presets import hexapod_points

SIM = stewart.PlatformParams.preset("motion_simulator")

SMALL = {
    "preset": "narayan2017",
    "parameters": {"base_radius": [0.09, 0.11], "payload_mass": 2.0},
    "envelope": {"lower": [-0.005] * 3 + [-0.02] * 3, "upper": [0.005] * 3 + [0.02] * 3,
                 "velocity": [0.05] * 3 + [0.2] * 3, "acceleration": [0.5] * 3 + [2.0] * 3, "samples": 3000},
    "workspace": {"samples": 2000},
}


def test_spacing_and_radius_rebuild_the_symmetric_layout():
    # motion_simulator: base pairs 20 deg apart around 0, 120, 240 deg on a 1.6 m circle (rolled by one).
    params = sweep.design_params(SIM, {"base_spacing": 30.0, "base_radius": 2.0, "platform_spacing": 40.0})
    expected = np.roll(hexapod_points(2.0, (0.0, 120.0, 240.0), 15.0), -1, axis=0)
    np.testing.assert_allclose(params.base_points, expected, rtol=0, atol=5e-14)  # reached 8.9e-16
    np.testing.assert_allclose(params.platform_points, hexapod_points(1.1, (60.0, 180.0, 300.0), 20.0), atol=1e-15, rtol=1e-13)  # reached 1/56 of it


def test_radius_keeps_the_angles_and_payload_scales_the_inertia():
    base = stewart.PlatformParams.preset("narayan2017")
    params = sweep.design_params(base, {"platform_radius": 0.1, "payload_mass": 3.0, "stroke": 0.25})
    rel = params.platform_points[:, :2] - base.platform_points[:, :2].mean(axis=0)
    old = base.platform_points[:, :2] - base.platform_points[:, :2].mean(axis=0)
    assert np.isclose(np.hypot(*rel.T).mean(), 0.1, rtol=1e-14, atol=0)  # reached 1.4e-16
    # reached 0: a few ulp of pi
    np.testing.assert_allclose(np.arctan2(rel[:, 1], rel[:, 0]), np.arctan2(old[:, 1], old[:, 0]), rtol=0, atol=2e-15)
    assert params.platform_mass == base.platform_mass + 3.0
    np.testing.assert_allclose(params.platform_inertia, base.platform_inertia * params.platform_mass / base.platform_mass,
                               rtol=1e-15)  # reached 0
    assert params.leg_length_limits == (base.leg_length_limits[0], base.leg_length_limits[0] + 0.25)


def test_pareto_front_against_its_definition():
    rng = np.random.default_rng(4)
    x, y = rng.normal(size=60), rng.normal(size=60)
    front = sweep.pareto_front(x, y)
    for k in range(60):
        dominated = any(x[j] >= x[k] and y[j] >= y[k] and (x[j] > x[k] or y[j] > y[k]) for j in range(60))
        assert front[k] == (not dominated)
    assert sweep.pareto_front([1.0, 2.0, 2.0], [3.0, 1.0, 1.0]).tolist() == [True, True, True]
    # a design with a NaN metric is never on the front (and never dominates): (3, NaN) and (NaN, 10)
    # would be, one better in x and one in y; (1, 3), (2, 2), (0.5, 4) are, (0.4, 2.5) is not
    front = sweep.pareto_front([1.0, 2.0, np.nan, 3.0, 0.5, 0.4], [3.0, 2.0, 10.0, np.nan, 4.0, 2.5])
    assert front.tolist() == [True, True, False, False, True, False]


def test_grid_and_random_designs():
    grid = sweep.parse({**SMALL, "parameters": {"base_radius": {"low": 0.08, "high": 0.12, "count": 3},
                                                "stroke": [0.15, 0.2]}})
    assert [d["base_radius"] for d in grid.designs] == [0.08, 0.08, 0.1, 0.1, 0.12, 0.12]
    assert [d["stroke"] for d in grid.designs] == [0.15, 0.2] * 3
    rand = sweep.parse({**SMALL, "method": "random", "designs": 7, "seed": 3,
                        "parameters": {"base_radius": {"low": 0.08, "high": 0.12}}})
    values = [d["base_radius"] for d in rand.designs]
    assert len(values) == 7 and all(0.08 <= v <= 0.12 for v in values) and len(set(values)) == 7
    again = sweep.parse({**SMALL, "method": "random", "designs": 7, "seed": 3,
                         "parameters": {"base_radius": {"low": 0.08, "high": 0.12}}})
    assert again.designs == rand.designs


def test_design_metrics_equal_separate_runs():
    spec = sweep.parse(SMALL)
    result = sweep.sweep(spec, progress=False)
    for k, design in enumerate(spec.designs):
        params = sweep.design_params(spec.base, design)
        home = stewart.home_pose(params)
        box = envelope.Box(home + spec.offsets.lower, home + spec.offsets.upper, spec.offsets.velocity,
                           spec.offsets.acceleration)
        env = envelope.envelope(params, box, samples=3000, seed=0, progress=False)
        work = workspace.translational_workspace(params, samples=2000, seed=0, progress=False)
        assert result.metrics["peak_force"][k] == env.value("force").max()
        assert result.metrics["peak_spherical_joint"][k] == env.value("spherical_joint").max()
        assert result.metrics["workspace_volume"][k] == work.volume
    assert result.metrics["peak_force"][0] != result.metrics["peak_force"][1]


def test_dask_cluster_matches_the_local_sweep():
    distributed = pytest.importorskip("distributed")
    spec = sweep.parse(SMALL)
    local = sweep.sweep(spec, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        remote = sweep.sweep(spec, client=client, progress=False)
    assert set(local.metrics) == set(remote.metrics)
    for name in local.metrics:
        assert np.array_equal(local.metrics[name], remote.metrics[name])


@pytest.mark.parametrize("change, field", [
    ({"shape": 1}, "shape"),
    ({"parameters": {"radius": 1.0}}, "parameters.radius"),
    ({"parameters": {}}, "parameters"),
    ({"parameters": {"base_radius": {"low": 0.2, "high": 0.1, "count": 2}}}, "parameters.base_radius.high"),
    ({"parameters": {"base_radius": {"low": 0.1, "high": 0.2}}}, "parameters.base_radius.count"),
    ({"parameters": {"base_radius": "big"}}, "parameters.base_radius"),
    ({"parameters": {"payload_mass": -50.0}}, "parameters"),
    ({"method": "exhaustive"}, "method"),
    ({"preset": "big"}, "preset"),
    ({"method": "random"}, "designs"),
    ({"envelope": {"lower": [0] * 6}}, "envelope.upper"),
    ({"envelope": {**SMALL["envelope"], "upper": [-1] * 6}}, "envelope.upper"),
    ({"envelope": {**SMALL["envelope"], "speed": 1}}, "envelope.speed"),
    ({"pareto": {"x": "volume"}}, "pareto.x"),
])
def test_bad_sweep_files_name_the_field(change, field):
    with pytest.raises(ValueError, match=f"^{field}[:.\\[ ][^\n]*$"):
        sweep.parse({**SMALL, **change})


def test_cli_sweep(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    from stewart.cli import main

    path = tmp_path / "design.toml"
    path.write_text('preset = "narayan2017"\n[parameters]\nbase_radius = [0.09, 0.11]\n[envelope]\n'
                    'lower = [0, 0, 0, 0, 0, 0]\nupper = [0, 0, 0, 0, 0, 0]\nvelocity = [0.1, 0, 0, 0, 0, 0]\n'
                    'acceleration = [1, 0, 0, 0, 0, 0]\nsamples = 200\n[workspace]\nsamples = 500\n')
    main(["sweep", str(path), "--no-progress", "--plot", str(tmp_path / "p.png"), "--json", str(tmp_path / "s.json")])
    out = capsys.readouterr().out
    assert out.count("\n") == 2 + 2 + 2 and (tmp_path / "p.png").stat().st_size > 10_000
    # the JSON and the printed table are the Python API's sweep of the same file
    result = sweep.sweep(sweep.load(path), progress=False)
    written = json.loads((tmp_path / "s.json").read_text())
    assert written["platform"] == result.platform and written["pareto"] == list(result.pareto_axes)
    np.testing.assert_equal(written["designs"], result.rows())
    check_sweep_table(out, result.rows())
    path.write_text('preset = "narayan2017"\n[parameters]\nradius = 1\n')
    with pytest.raises(SystemExit) as exit_info:
        main(["sweep", str(path)])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2 and "parameters.radius: unknown name" in err and err.count("\n") == 1
