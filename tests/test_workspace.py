"""The workspace: membership against the kinematics, joint limits and leg clearance against
hand-worked poses, volume convergence, symmetry, slices and the ``stewart workspace`` command."""

import json

import numpy as np
import pytest

import stewart
from stewart.studies import execution, workspace
from stewart.cli import main
from stewart.model.presets import hexapod_points


def _vertical_legs(**bounds):
    """Base and platform joints on one 0.5 m circle in pairs 20 deg apart, stroke 0.8-1.2 m:
    every leg is vertical and 1 m long at home."""
    points = hexapod_points(0.5, (0.0, 120.0, 240.0), 10.0)
    fields = stewart.PlatformParams.preset("motion_simulator").to_dict()
    fields.update(base_points=points, platform_points=points, leg_length_limits=(0.8, 1.2), name="vertical", **bounds)
    return stewart.PlatformParams(**fields)


def _uniform(rng, box, n):
    return box[:, 0] + (box[:, 1] - box[:, 0]) * rng.random((n, 3))


# ---------------------------------------------------------------- membership


def test_membership_agrees_with_inverse_kinematics():
    """Random positions and orientations: the stroke bits are set exactly where the numpy
    leg lengths leave the limits, and the margin is the inverse of numpy's condition number."""
    params = stewart.PlatformParams.preset("narayan2017").replace(universal_joint_max_angle=None,
                                                                  spherical_joint_max_angle=None)
    rng = np.random.default_rng(7)
    poses = np.hstack([_uniform(rng, workspace.position_bounds(params), 3000), rng.uniform(-0.4, 0.4, (3000, 3))])
    check = stewart.reachability(params, poses)
    lengths = stewart.leg_lengths(params, poses)
    low, high = params.leg_length_limits
    np.testing.assert_array_equal((check.flags & workspace.LEG_TOO_SHORT) != 0, np.any(lengths < low, axis=1))
    np.testing.assert_array_equal((check.flags & workspace.LEG_TOO_LONG) != 0, np.any(lengths > high, axis=1))
    assert 0.05 < check.ok.mean() < 0.95
    radius = np.max(np.linalg.norm(params.platform_points - params.platform_points.mean(axis=0), axis=1))
    unit_free = stewart.jacobian(params, poses) / np.r_[np.ones(3), np.full(3, radius)]
    np.testing.assert_allclose(check.margin, 1.0 / np.linalg.cond(unit_free), rtol=2e-11)  # reached 4.4e-13


def test_membership_agrees_with_forward_kinematics():
    """Leg lengths drawn within the stroke: the poses forward kinematics finds from home
    have those lengths and no stroke bit; and every reachable sampled pose is the pose
    forward kinematics returns for its own leg lengths."""
    params = stewart.PlatformParams.preset("motion_simulator")
    rng = np.random.default_rng(3)
    low, high = params.leg_length_limits
    lengths = rng.uniform(low + 0.1, high - 0.1, (200, 6))
    poses = stewart.forward_kinematics(params, lengths)
    check = stewart.reachability(params, poses)
    np.testing.assert_allclose(check.lengths, lengths, rtol=5e-11)  # reached 7.4e-13
    stroke = workspace.LEG_TOO_SHORT | workspace.LEG_TOO_LONG
    assert not np.any(check.flags & stroke) and check.ok.mean() > 0.9

    result = workspace.translational_workspace(params, samples=4000, seed=5, chunk_size=1000)
    job = workspace.WorkspaceJob(params, "translational", np.zeros(3), workspace.position_bounds(params), 0)
    sampled = np.vstack([job.poses(chunk) for chunk in execution.chunks(4000, 1000, seed=5)])
    reachable = sampled[stewart.reachability(params, sampled).ok]
    assert len(reachable) == result.reachable > 50
    found = stewart.forward_kinematics(params, stewart.leg_lengths(params, reachable))
    np.testing.assert_allclose(found, reachable, atol=5e-11, rtol=5e-9)  # reached 1/65 of it


# ---------------------------------------------------------------- joint limits and clearance


def test_joint_angles_of_hand_worked_poses():
    """Vertical legs of 1 m at home: a sideways shift d tilts every leg by atan(d / 1 m),
    and a yaw psi moves each platform joint by 2 r sin(psi / 2) sideways, for both joints."""
    shift, yaw = 0.1, 0.3
    tilt_shift = np.arctan(shift / 1.0)
    tilt_yaw = np.arctan(2 * 0.5 * np.sin(yaw / 2) / 1.0)
    params = _vertical_legs()
    home = stewart.home_pose(params)
    np.testing.assert_allclose(home, [0, 0, 1.0, 0, 0, 0], rtol=0, atol=1e-15)  # reached 0
    poses = [home, home + [shift, 0, 0, 0, 0, 0], home + [0, 0, 0, yaw, 0, 0]]
    universal, spherical = workspace.joint_angles(params, poses)
    expected = np.repeat([0.0, tilt_shift, tilt_yaw], 6).reshape(3, 6)
    np.testing.assert_allclose(universal, expected, atol=1e-15, rtol=1e-14)  # reached 1/89 of it
    np.testing.assert_allclose(spherical, expected, atol=1e-15, rtol=1e-14)  # reached 1/89 of it
    for limit, flagged in ((tilt_shift * (1 + 1e-9), False), (tilt_shift * (1 - 1e-9), True)):
        check = stewart.reachability(_vertical_legs(universal_joint_max_angle=limit), poses[1])
        assert bool(check.flags[0] & workspace.UNIVERSAL_JOINT_LIMIT) == flagged
        check = stewart.reachability(_vertical_legs(spherical_joint_max_angle=limit), poses[1])
        assert bool(check.flags[0] & workspace.SPHERICAL_JOINT_LIMIT) == flagged
    assert "universal joint(s) [0, 1, 2, 3, 4, 5] beyond their cone half-angle" in stewart.reachability(
        _vertical_legs(universal_joint_max_angle=0.05), poses[1]).message()


def test_spherical_joint_angle_follows_the_platform_frame():
    """A pitch theta of the vertical-legs platform: the universal-joint angle is the leg's
    angle from z of {B}, the spherical-joint angle its angle from z of {P}, which is
    (sin theta, 0, cos theta) in {B}."""
    params = _vertical_legs()
    theta = 0.2
    pose = np.array([0, 0, 1.0, 0, theta, 0])
    universal, spherical = workspace.joint_angles(params, pose)
    legs = stewart.leg_vectors(params, pose)
    units = legs / np.linalg.norm(legs, axis=1)[:, None]
    np.testing.assert_allclose(universal, np.arccos(units[:, 2]), atol=1e-15, rtol=1e-10)  # reached 1/35 of it
    axis = np.array([np.sin(theta), 0.0, np.cos(theta)])
    np.testing.assert_allclose(spherical, np.arccos(np.clip(units @ axis, -1, 1)), atol=1e-14, rtol=1e-14)  # reached 1/34 of it


def test_leg_clearance_of_hand_worked_poses():
    """Vertical legs at home are parallel segments: the closest two are a pair of joints
    20 deg apart on the 0.5 m circle, 2 (0.5 m) sin 10 deg apart."""
    gap = 2 * 0.5 * np.sin(np.radians(10.0))
    home = np.array([0, 0, 1.0, 0, 0, 0])
    for diameter, flagged in ((gap * (1 - 1e-9), False), (gap * (1 + 1e-9), True)):
        check = stewart.reachability(_vertical_legs(leg_diameter=diameter), home)
        np.testing.assert_allclose(check.clearance, [gap], rtol=1e-14)  # reached 0
        assert bool(check.flags[0] & workspace.LEG_COLLISION) == flagged
    assert "legs 0 and 1 collide: their axes are 0.1736 m apart" in stewart.reachability(
        _vertical_legs(leg_diameter=0.2), home).message()


def test_segment_distances_against_brute_force():
    """Random segments, and parallel, collinear and crossing ones: the distance is the
    minimum over a dense grid of points on both segments, to the grid's resolution."""
    rng = np.random.default_rng(11)
    p0, p1, q0, q1 = (rng.normal(size=(60, 3)) for _ in range(4))
    across = np.cross(p1 - p0, [0.0, 0.0, 1.0])
    across = 0.3 * across / np.linalg.norm(across, axis=1)[:, None]
    q0[:20], q1[:20] = p0[:20] + across[:20], p1[:20] + across[:20]  # parallel, 0.3 apart
    ahead = p1[20:30] - p0[20:30]
    q0[20:30], q1[20:30] = p1[20:30] + 0.5 * ahead, p1[20:30] + 2 * ahead  # collinear, half a length apart
    q0[30:40], q1[30:40] = 0.5 * (p0[30:40] + p1[30:40]) - [0, 1, 0], 0.5 * (p0[30:40] + p1[30:40]) + [0, 1, 0]
    exact = workspace.segment_distances(p0, p1, q0, q1)
    s = np.linspace(0, 1, 401)[:, None]
    for k in range(len(exact)):
        a, b = p0[k] + s * (p1[k] - p0[k]), q0[k] + s * (q1[k] - q0[k])
        brute = np.min(np.linalg.norm(a[:, None] - b[None], axis=-1))
        step = (np.linalg.norm(p1[k] - p0[k]) + np.linalg.norm(q1[k] - q0[k])) / 400
        assert exact[k] <= brute + 1e-12 and brute - exact[k] <= step, k
    np.testing.assert_allclose(exact[:20], 0.3, rtol=5e-14)  # reached 1.1e-15
    np.testing.assert_allclose(exact[20:30], 0.5 * np.linalg.norm(ahead, axis=1), rtol=1e-14)  # reached 1.8e-16
    np.testing.assert_allclose(exact[30:40], 0.0, atol=2e-14)  # reached 1/36 of it


# ---------------------------------------------------------------- volumes


def test_volume_converges_as_the_samples_grow(figures):
    """The standard error shrinks like 1 / sqrt(N) and the estimates agree within their
    errors, with each other and with a grid's."""
    params = stewart.PlatformParams.preset("narayan2017")
    runs = [workspace.translational_workspace(params, samples=n, seed=n) for n in (4000, 16000, 64000)]
    for small, large in zip(runs, runs[1:]):
        # statistical: each standard error is itself an estimate (reached 9.6e-3)
        assert large.volume_error / small.volume_error == pytest.approx(0.5, rel=0.1)
        assert abs(large.volume - small.volume) <= 3 * np.hypot(large.volume_error, small.volume_error)
    grid = workspace.translational_workspace(params, grid=40)
    assert grid.samples == 40**3 and grid.seed is None and grid.volume_error > 0
    gap = abs(grid.volume - runs[-1].volume)
    figures("workspace: grid vs Monte-Carlo volume, in their combined errors", gap / (grid.volume_error + 3 *
            runs[-1].volume_error), 1.0)  # reached 1.3e-02
    for result in runs + [grid]:
        box = result.bounding_box
        assert np.all(result.region[:, 0] <= box[:, 0]) and np.all(box[:, 1] <= result.region[:, 1])
        assert 0 < result.margin_min <= result.margin_mean <= result.margin_max <= 1 and result.clipped == ()
        worst = stewart.reachability(params, result.margin_min_pose)
        assert worst.ok[0] and worst.margin[0] == result.margin_min


def test_chunks_and_seeds_give_reproducible_results(simd_path):
    # Without the preset's joint cones, inside which few orientations are reachable.
    params = stewart.PlatformParams.preset("narayan2017").replace(universal_joint_max_angle=None,
                                                                  spherical_joint_max_angle=None)
    one = workspace.orientation_workspace(params, samples=3000, seed=4, chunk_size=1000)
    again = workspace.orientation_workspace(params, samples=3000, seed=4, chunk_size=1000)
    other = workspace.orientation_workspace(params, samples=3000, seed=5, chunk_size=1000)
    assert one.summary() == again.summary() and one.volume != other.volume
    # Chunks of other sizes: the same counts and extremes; the margin's mean up to rounding.
    grids = [workspace.translational_workspace(params, grid=12, chunk_size=c).summary() for c in (100, 1728)]
    assert grids[0].pop("margin_mean") == pytest.approx(grids[1].pop("margin_mean"), rel=1e-14)
    assert grids[0] == grids[1]


def test_symmetric_platform_gives_a_symmetric_workspace():
    """The motion simulator's joints repeat every 120 deg and mirror in the x-z plane: so
    do its reachable positions and their margins, at zero orientation."""
    params = stewart.PlatformParams.preset("motion_simulator")
    rng = np.random.default_rng(2)
    poses = np.zeros((4000, 6))
    poses[:, :3] = _uniform(rng, workspace.position_bounds(params), 4000)
    turn = np.radians(120.0)
    rotated, mirrored = poses.copy(), poses.copy()
    rotated[:, :2] = poses[:, :2] @ np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    mirrored[:, 1] *= -1
    check = stewart.reachability(params, poses)
    assert 0.01 < check.ok.mean() < 0.99
    for image in (rotated, mirrored):
        other = stewart.reachability(params, image)
        np.testing.assert_array_equal(other.flags, check.flags)
        np.testing.assert_allclose(other.margin, check.margin, rtol=2e-11, atol=2e-14)  # reached 1/52 of it
    result = workspace.translational_workspace(params, grid=30)
    y_lo, y_hi = result.bounding_box[1]
    assert y_lo == pytest.approx(-y_hi, abs=2e-14)  # reached 3.9e-16


def test_slices_hold_the_margin_where_reachable():
    params = stewart.PlatformParams.preset("narayan2017")
    cut = workspace.workspace_slice(params, "xz", at=0.01, resolution=15)
    assert cut.axes == ("x", "z") and cut.at == ("y", 0.01) and cut.margin.shape == (15, 15)
    pose = np.array([cut.u[4], 0.01, cut.v[9], 0, 0, 0])
    check = stewart.reachability(params, pose)
    assert cut.flags[9, 4] == check.flags[0]
    assert cut.margin[9, 4] == pytest.approx(check.margin[0], rel=1e-14) if check.ok[0] else np.isnan(cut.margin[9, 4])
    np.testing.assert_array_equal(np.isnan(cut.margin), cut.flags != 0)
    assert 0 < np.isnan(cut.margin).sum() < cut.margin.size
    angles = workspace.workspace_slice(params, ("psi", "phi"), resolution=9)
    assert angles.unit == "rad" and angles.at == ("theta", 0.0)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda p: workspace.translational_workspace(p, samples=10, region=[[0, 1], [0, 1], [1, 0]]),
         "region: empty or inverted bounds on axis 2"),
        (lambda p: workspace.translational_workspace(p, samples=10, region=[[0, 1], [0, 1]]),
         "region: expected 3 finite (low, high) pairs"),
        (lambda p: workspace.translational_workspace(p), "samples, grid: give exactly one"),
        (lambda p: workspace.translational_workspace(p, samples=10, grid=3), "samples, grid: give exactly one"),
        (lambda p: workspace.translational_workspace(p, samples=0), "samples: must be from 1"),
        (lambda p: workspace.translational_workspace(p, samples=10, seed=-2), "seed: expected a whole number >= 0"),
        (lambda p: workspace.translational_workspace(p, [0, np.nan, 0], samples=10), "orientation: expected 3 finite"),
        (lambda p: workspace.orientation_workspace(p, [0, 0], samples=10), "position: expected 3 finite"),
        (lambda p: workspace.translational_workspace(p.replace(leg_length_limits=None), samples=10),
         "region: the parameters have no leg_length_limits"),
        (lambda p: workspace.workspace_slice(p, "xpsi"), "axes: expected two of x, y, z or two of psi, theta, phi"),
        (lambda p: workspace.workspace_slice(p, "xx"), "axes: expected two of"),
    ],
)
def test_bad_specifications_name_the_argument(call, message):
    with pytest.raises(ValueError) as info:
        call(stewart.PlatformParams.preset("narayan2017"))
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


# ---------------------------------------------------------------- the command


def test_cli_reports_the_volume_and_writes_slices(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    main(["workspace", "--samples", "5000", "--seed", "3", "--json", "--slices", str(tmp_path / "s"),
          "--resolution", "20", "--csv", str(tmp_path / "w.csv")])
    summary = json.loads(capsys.readouterr().out)
    direct = workspace.translational_workspace(stewart.PlatformParams.preset("narayan2017"), samples=5000, seed=3)
    assert summary["volume"] == direct.volume and summary["volume_error"] == direct.volume_error
    assert summary["exit_code"] == 0 and (tmp_path / "s" / "workspace_translational.png").stat().st_size > 10_000
    header, row = (tmp_path / "w.csv").read_text().splitlines()[::2]
    # the file's 12 digits (reached 1.9e-16 on this value)
    assert float(row.split(",")[header.split(",").index("volume")]) == pytest.approx(direct.volume, rel=1e-11)


def test_cli_joint_limits_shrink_the_workspace(capsys):
    main(["workspace", "--kind", "orientation", "--grid", "12", "--json", "--spherical-max-angle", "90",
          "--universal-max-angle", "90"])
    free = json.loads(capsys.readouterr().out)
    main(["workspace", "--kind", "orientation", "--grid", "12", "--json", "--spherical-max-angle", "30",
          "--universal-max-angle", "90"])
    limited = json.loads(capsys.readouterr().out)
    assert 0 < limited["reachable"] < free["reachable"] and limited["excluded"]["spherical_joint_limit"] > 0


@pytest.mark.parametrize(
    "argv, code, message",
    [
        (["--region", "0", "1", "0", "1", "1", "0"], 2, "--region: empty or inverted bounds on axis 2"),
        (["--region", "1", "2", "1", "2", "1", "2"], 3, "no sampled pose is reachable"),
        (["--leg-diameter", "0.5", "--samples", "500"], 3, "leg_collision 500"),
        (["--universal-max-angle", "120"], 2, "--universal-max-angle: a cone half-angle needs 0 < DEG <= 90"),
        (["--kind", "orientation", "--orientation", "0", "0", "0"], 2, "--orientation: holds the orientation"),
        (["--seed", "-1"], 2, "--seed: expected a whole number >= 0"),
        (["--params", "/no/such/file.toml"], 2, "--params /no/such/file.toml: no such file"),
    ],
)
def test_cli_bad_specifications_exit_with_one_line(argv, code, message, capsys):
    with pytest.raises(SystemExit) as info:
        main(["workspace", "--samples", "500", *argv] if "--samples" not in argv else ["workspace", *argv])
    err = capsys.readouterr().err.strip()
    assert info.value.code == code and message in err and len(err.splitlines()) == 1


def test_dask_cluster_gives_the_local_result(capsys):
    """Two worker processes of a LocalCluster: the job travels to them by pickle and the
    result equals the local run's, for random samples and for a grid, from Python and from
    ``stewart workspace --scheduler``."""
    distributed = pytest.importorskip("distributed")
    params = stewart.PlatformParams.preset("narayan2017").replace(spherical_joint_max_angle=0.6, leg_diameter=0.01)
    studies = [dict(samples=6000, seed=9, chunk_size=1500), dict(grid=14, chunk_size=700)]
    local = [workspace.translational_workspace(params, **kw).summary() for kw in studies]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        remote = [workspace.translational_workspace(params, **kw, client=client).summary() for kw in studies]
        capsys.readouterr()
        main(["workspace", "--samples", "6000", "--seed", "9", "--chunk-size", "1500", "--spherical-max-angle",
              str(np.degrees(0.6)), "--leg-diameter", "0.01", "--scheduler", cluster.scheduler_address, "--json"])
    assert remote == local and all(r["reachable"] > 0 for r in remote)
    printed = json.loads(capsys.readouterr().out)
    assert printed["volume"] == local[0]["volume"] and printed["margin_mean"] == local[0]["margin_mean"]


def test_a_region_inside_the_workspace_is_all_reachable_and_clipped():
    """A 10 cm box around home lies inside the motion simulator's workspace: the volume is
    the box's, exactly, with no sampling error, and every axis is reported clipped."""
    params = stewart.PlatformParams.preset("motion_simulator")
    home = stewart.home_pose(params)[:3]
    box = np.column_stack([home - 0.05, home + 0.05])
    for kw in (dict(samples=2000), dict(grid=8)):
        result = workspace.translational_workspace(params, region=box, **kw)
        assert result.reachable == result.samples and result.volume == pytest.approx(1e-3, rel=5e-14)  # reached 1.1e-15
        assert result.clipped == ("x", "y", "z") and result.excluded == {}
    assert result.volume_error == 0.0
