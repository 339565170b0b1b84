"""The workspace: membership against the kinematics, joint limits and leg clearance against
hand-worked poses, volume convergence, symmetry, slices and the ``stewart workspace`` command."""

import json

import numpy as np
import pytest
from cli_outputs import check_workspace_json

import stewart
from stewart.studies import execution, workspace
from stewart.cli import main
from stewart.model import reachability
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


def test_margin_and_flags_across_a_singularity_against_numpy(monkeypatch):
    """The motion simulator yawed through its singularity near 1.575 rad: the margin (of
    reachability and of margins) is numpy's inverse condition number, from the Gram matrix above
    1e-2 and from an SVD of exactly the rows below it; the singular bit is set where numpy's
    condition number passes 1000 and the assembly-mode bit where numpy's det J_C changes sign,
    each named in the row's reasons."""
    params = stewart.PlatformParams.preset("motion_simulator")
    poses = stewart.home_pose(params) + np.outer(np.r_[0.0, np.linspace(1.50, 1.66, 17)], [0, 0, 0, 1, 0, 0])
    radius = np.max(np.linalg.norm(params.platform_points - params.platform_points.mean(axis=0), axis=1))
    unit_free = stewart.jacobian(params, poses) / np.r_[np.ones(3), np.full(3, radius)]
    expected, det = 1.0 / np.linalg.cond(unit_free), np.linalg.det(unit_free)
    assert np.sum(expected < 1e-2) == 5 and np.sum(expected < 1e-3) == 1 and np.sum(det < 0) == 9
    decomposed = []
    svd = np.linalg.svd
    monkeypatch.setattr(np.linalg, "svd", lambda a, *args, **kw: (decomposed.append(len(a)), svd(a, *args, **kw))[1])
    check = stewart.reachability(params, poses)
    assert decomposed == [5]
    np.testing.assert_allclose(check.margin, expected, rtol=2e-11)  # reached 4.5e-13 (eps / margin^2)
    np.testing.assert_array_equal(reachability.margins(params, poses), check.margin)
    np.testing.assert_array_equal(check.flags & workspace.SINGULAR != 0, expected < 1e-3)
    np.testing.assert_array_equal(check.flags & workspace.OTHER_ASSEMBLY_MODE != 0, det < 0)
    singular, other = np.flatnonzero(expected < 1e-3)[0], np.flatnonzero(det < 0)[0]
    assert (f"J_C is singular or nearly so (condition number {1.0 / expected[singular]:.3g} > 1000)"
            in check.reasons(singular))
    assert ("det J_C has the other sign: the pose is in another assembly mode, beyond a singularity"
            in check.reasons(other))


def test_reasons_name_the_legs_and_the_message_the_first_row():
    """Vertical legs (1 m at z = 1, stroke 0.8-1.2 m) rolled by phi: leg i is sqrt((y_i (cos phi
    - 1))^2 + (1 + y_i sin phi)^2) long, leg 5 too short and leg 2 too long at phi = 0.5; at
    z = 1.3 all six are 1.3 m. The message reports the first row of each problem and how many
    more share it; these legs are parallel at home, a singular pose."""
    params = _vertical_legs().replace(universal_joint_max_angle=None, spherical_joint_max_angle=None,
                                      leg_diameter=None, plate_radius=None)
    phi = 0.5
    y = params.platform_points[:, 1]
    rolled = np.sqrt((y * (np.cos(phi) - 1)) ** 2 + (1 + y * np.sin(phi)) ** 2)
    assert np.flatnonzero(rolled < 0.8).tolist() == [5] and np.flatnonzero(rolled > 1.2).tolist() == [2]
    check = stewart.reachability(params, [[0, 0, 1.0, 0, 0, phi], [0, 0, 1.0, 0, 0, 0], [0, 0, 1.3, 0, 0, 0]])
    short = f"leg(s) [5] shorter than the minimum length 0.8 m ({rolled[5]:.6g} m)"
    long = f"leg(s) [2] longer than the maximum length 1.2 m ({rolled[2]:.6g} m)"
    assert check.reasons(0)[:2] == [short, long]
    assert check.reasons(2)[0] == "leg(s) [0, 1, 2, 3, 4, 5] longer than the maximum length 1.2 m " \
                                  "(1.3, 1.3, 1.3, 1.3, 1.3, 1.3 m)"
    parts = check.message(times=[0.0, 0.5, 1.0]).split("; ")
    assert parts[0] == f"3 of 3 pose(s) outside the workspace: {short} at t = 0 s"
    assert parts[1] == f"{long} at t = 0 s and 1 more"
    assert parts[2].startswith("J_C is singular") and parts[2].endswith("at t = 0 s and 2 more") and len(parts) == 3
    assert check.message("sample").split("; ")[1] == f"{long} at row 0 and 1 more"


def test_euler_singular_poses_from_the_hand_worked_threshold():
    """theta is refused where |cos theta| < 1e-3: from acos(1e-3) on either side of zero."""
    params = _vertical_legs().replace(leg_length_limits=None, universal_joint_max_angle=None,
                                      spherical_joint_max_angle=None, leg_diameter=None, plate_radius=None)
    edge = np.arccos(1e-3)
    poses = [[0, 0, 1.0, 0, theta, 0] for theta in (edge * (1 - 1e-9), edge * (1 + 1e-9), -edge * (1 + 1e-9),
                                                     np.pi / 2, -edge * (1 - 1e-9))]
    check = stewart.reachability(params, poses)
    assert [bool(f & workspace.EULER_SINGULAR) for f in check.flags] == [False, True, True, True, False]
    for row in (1, 2, 3):  # J_C is singular there too
        first, then = check.reasons(row)
        assert first.startswith("J_C is singular") and then == "theta = +-90 deg, where the Euler angles are singular"


def test_long_trajectories_are_checked_in_blocks(monkeypatch):
    """Blocks of two poses: every row is still checked, against its hand-worked leg lengths
    (vertical legs of length z)."""
    monkeypatch.setattr(reachability, "_BLOCK", 2)
    z = np.array([0.7, 0.9, 1.0, 1.25, 1.1])
    check = stewart.reachability(_vertical_legs(), np.column_stack([np.zeros((5, 2)), z, np.zeros((5, 3))]))
    np.testing.assert_allclose(check.lengths, np.repeat(z[:, None], 6, axis=1), rtol=1e-15)
    np.testing.assert_array_equal(check.flags & workspace.LEG_TOO_SHORT != 0, z < 0.8)
    np.testing.assert_array_equal(check.flags & workspace.LEG_TOO_LONG != 0, z > 1.2)


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
    check_workspace_json(summary, direct)
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


def test_axis_excursions_in_heave_against_the_stroke_by_hand():
    """Along z alone, with the stroke the only limit, the excursion is where the first leg
    reaches an end of its stroke: l_i(dz) = sqrt(d_i^2 + (h_i + dz)^2) with d_i its horizontal
    span and h_i its height at home, so up to min_i sqrt(L_max^2 - d_i^2) - h_i and down to
    min_i h_i - sqrt(L_min^2 - d_i^2); the grid of 2000 steps gives the last step inside."""
    params = stewart.PlatformParams.preset("narayan2017").replace(
        universal_joint_max_angle=None, spherical_joint_max_angle=None)
    home = stewart.home_pose(params)
    legs = home[:3] + params.platform_points - params.base_points
    span_sq, height = np.sum(legs[:, :2] ** 2, axis=1), legs[:, 2]
    low, high = params.leg_length_limits
    up = np.min(np.sqrt(high ** 2 - span_sq) - height)
    down = np.min(height - np.sqrt(low ** 2 - span_sq))
    limit = 0.2
    step = limit / 2000
    got = reachability.axis_excursions(params, limit)[2]
    assert min(up, down) - step < got <= min(up, down)
    assert got == pytest.approx(np.floor(min(up, down) / step) * step, rel=0, abs=1e-15)
    # nothing stops a yaw of 0.002 rad: the excursion is the limit itself
    assert reachability.axis_excursions(params, 0.002)[5] == 0.002


def test_a_region_cut_through_home_is_clipped_on_that_axis_only():
    """position_bounds holds the motion simulator's whole workspace: given as the region, no axis
    is clipped; with one face moved to the home pose's coordinate (through the workspace), the
    reachable cells reach that face, and only that axis is clipped."""
    params = stewart.PlatformParams.preset("motion_simulator")
    home, full = stewart.home_pose(params)[:3], workspace.position_bounds(params)
    assert workspace.translational_workspace(params, region=full, grid=12, progress=False).clipped == ()
    for axis, name in enumerate("xyz"):
        for side in (0, 1):
            region = full.copy()
            region[axis, side] = home[axis]
            assert workspace.translational_workspace(params, region=region, grid=12, progress=False).clipped == (name,)
