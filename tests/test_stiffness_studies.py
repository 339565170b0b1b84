"""The modal metrics of the studies: the lowest frequency and largest compliance over a
workspace, on a slice and per design of a sweep, locally and on a Dask LocalCluster. The
studies' figures are checked against a direct eigen-solve of the platform's stiffness and
mass matrices (:func:`direct_modal_metrics`), not the metric functions the studies call."""

import json

import numpy as np
import pytest
import scipy.linalg

import stewart
from stewart.model.presets import LEG_STIFFNESS
from stewart.studies import sweep, workspace
from test_sweep import SMALL

K = LEG_STIFFNESS["motion_simulator"]
#: The studies' metrics against the direct eigen-solve, relative (reached 8.9e-16).
AGREEMENT = 5e-14


def direct_modal_metrics(plat, poses, stiffness):
    """``(lowest frequency [Hz], largest translational compliance [m/N])`` at each pose, from the
    Platform API's matrices in pose coordinates: the stiffness ``K_x`` (the Hessian of the
    potential, :meth:`~stewart.Platform.stiffness_matrix`) and the symmetric mass matrix
    ``T^T M`` (the kinetic energy's, ``M`` of :meth:`~stewart.Platform.mass_matrix` and ``T``
    of :func:`stewart.twist_transform`): the frequencies from the generalized eigenproblem
    ``K_x v = omega^2 T^T M v`` (scipy.linalg.eigh), the compliance the largest eigenvalue of
    the position block of ``K_x^-1`` (a force at {P}'s origin moves it by the position block,
    which ``T`` leaves alone)."""
    frequency, compliance = [], []
    for x in poses:
        stiff, mass = plat.stiffness_matrix(x, stiffness), stewart.twist_transform(x).T @ plat.mass_matrix(x)
        squares = scipy.linalg.eigh(0.5 * (stiff + stiff.T), 0.5 * (mass + mass.T), eigvals_only=True)
        frequency.append(np.sqrt(squares[0]) / (2.0 * np.pi))
        block = np.linalg.inv(stiff)[:3, :3]
        compliance.append(np.linalg.eigvalsh(0.5 * (block + block.T))[-1])
    return np.array(frequency), np.array(compliance)


def test_workspace_frequency_and_compliance_are_the_extremes_over_the_reachable_grid():
    """On a grid the poses are known: the study's lowest frequency and largest compliance are
    the extremes of the direct eigen-solve over the reachable cells, and the poses it names
    have them (two cells, mirror images, tie)."""
    params = stewart.PlatformParams.preset("motion_simulator")
    plat = stewart.Platform(params)
    result = workspace.translational_workspace(params, grid=12, stiffness=K, progress=False)
    lo, hi = result.region[:, 0], result.region[:, 1]
    cells = np.stack(np.meshgrid(*[(np.arange(12) + 0.5) / 12] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    poses = np.hstack([lo + (hi - lo) * cells, np.zeros((len(cells), 3))])
    ok = workspace.reachability(plat, poses).ok
    frequency, compliance = direct_modal_metrics(plat, poses[ok], K)
    assert result.reachable == ok.sum() > 50 and result.unheld == 0 and np.all(frequency > 0)
    at_poses = direct_modal_metrics(plat, [result.frequency_min_pose, result.compliance_max_pose], K)
    np.testing.assert_allclose([result.frequency_min, at_poses[0][0]], frequency.min(), rtol=AGREEMENT)
    np.testing.assert_allclose([result.compliance_max, at_poses[1][1]], compliance.max(), rtol=AGREEMENT)
    plain = workspace.translational_workspace(params, grid=12, progress=False)
    assert np.isnan(plain.frequency_min) and plain.stiffness is None and plain.volume == result.volume


def test_the_slice_carries_the_lowest_frequency():
    plat = stewart.Platform.preset("motion_simulator")
    cut = workspace.workspace_slice(plat, "xy", resolution=21, stiffness=K)
    reachable = np.isfinite(cut.margin)
    assert np.array_equal(np.isfinite(cut.frequency), reachable) and reachable.sum() > 50
    row, col = np.argwhere(reachable)[0]
    pose = np.r_[cut.u[col], cut.v[row], cut.at[1], 0.0, 0.0, 0.0]
    assert cut.frequency[row, col] == pytest.approx(direct_modal_metrics(plat, [pose], K)[0][0], rel=AGREEMENT)
    assert workspace.workspace_slice(plat, "xy", resolution=5).frequency is None


def test_a_sweep_gives_each_designs_modal_metrics_and_needs_the_stiffness_to_rank_by_them():
    spec = sweep.parse({**SMALL, "modes": {"stiffness": 1e6}, "pareto": {"x": "workspace_volume",
                                                                          "y": "lowest_frequency"}})
    result = sweep.sweep(spec, progress=False)
    for k, design in enumerate(spec.designs):
        work = workspace.translational_workspace(sweep.design_params(spec.base, design), samples=2000,
                                                 seed=spec.seed, stiffness=1e6, progress=False)
        assert result.metrics["lowest_frequency"][k] == work.frequency_min
        assert result.metrics["largest_compliance"][k] == work.compliance_max
        assert result.metrics["unheld"][k] == work.unheld
    bare = sweep.sweep(sweep.parse(SMALL), progress=False)
    assert set(bare.metrics) == set(sweep.METRICS) - set(sweep.MODAL_METRICS)
    assert all(np.isfinite(values).all() for values in bare.metrics.values())
    assert all(np.isfinite(result.metrics[name]).all() for name in sweep.MODAL_METRICS)
    rows = bare.rows()
    assert not any(name in row for row in rows for name in sweep.MODAL_METRICS)
    with pytest.raises(ValueError, match=r"^pareto.y: lowest_frequency needs the legs' stiffness"):
        sweep.parse({**SMALL, "pareto": {"y": "lowest_frequency"}})
    with pytest.raises(ValueError, match=r"^modes.stiffness: must be finite and > 0"):
        sweep.parse({**SMALL, "modes": {"stiffness": 0}})


def test_dask_cluster_gives_the_local_frequency_map_and_sweep():
    distributed = pytest.importorskip("distributed")
    params = stewart.PlatformParams.preset("motion_simulator")
    study = dict(samples=4000, seed=3, chunk_size=1000, stiffness=K, progress=False)
    local = workspace.translational_workspace(params, **study).summary()
    spec = sweep.parse({**SMALL, "modes": {"stiffness": 1e6}})
    local_sweep = sweep.sweep(spec, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        remote = workspace.translational_workspace(params, **study, client=client).summary()
        remote_sweep = sweep.sweep(spec, client=client, progress=False)
    assert np.isfinite(local["frequency_min"])
    assert remote == local
    for name in sweep.MODAL_METRICS:
        assert np.array_equal(local_sweep.metrics[name], remote_sweep.metrics[name])


def test_workspace_command_reports_the_frequency_and_draws_its_map(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    from stewart.cli import main

    main(["workspace", "--preset", "motion_simulator", "--samples", "3000", "--stiffness", "2e7", "--slices",
          str(tmp_path), "--resolution", "15", "--json"])
    summary = json.loads(capsys.readouterr().out)
    params = stewart.PlatformParams.preset("motion_simulator")
    local = workspace.translational_workspace(params, samples=3000, stiffness=2e7, progress=False)
    assert summary["frequency_min"] == local.frequency_min and summary["compliance_max"] == local.compliance_max
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frequency_translational.png", "workspace_translational.png"]
    main(["workspace", "--preset", "motion_simulator", "--samples", "3000", "--stiffness", "2e7"])
    out = capsys.readouterr().out
    assert f"lowest natural frequency {local.frequency_min:.4g} Hz" in out
    assert "limits: stroke 1.15-1.85 m; joint cones universal 45 deg, spherical 30 deg; legs 0.16 m thick" in out
