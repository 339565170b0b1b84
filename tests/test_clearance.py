"""The platform's clearance of the base and of the legs (``plate_radius``, ``base_clearance``):
the gap against hand-worked tilts and a densely sampled rim, the legs' crossings of the plate
against line-plane intersections computed in {B}, the flags at hand-worked thresholds, the
parameters' checks and the ``stewart workspace`` flags."""

import json

import numpy as np
import pytest

import stewart
from stewart.cli import main
from stewart.model import reachability
from stewart.model.presets import hexapod_points


def _vertical_legs(**fields):
    """Base and platform joints on one 0.5 m circle in pairs 20 deg apart (legs 0 and 1 at -10
    and +10 deg), no stroke limits: every leg is vertical and 1 m long at ``z = 1``."""
    points = hexapod_points(0.5, (0.0, 120.0, 240.0), 10.0)
    base = stewart.PlatformParams.preset("motion_simulator").to_dict()
    base.update(base_points=points, platform_points=points, leg_length_limits=None, universal_joint_max_angle=None,
                spherical_joint_max_angle=None, leg_diameter=None, plate_radius=None, name="vertical")
    base.update(fields)
    return stewart.PlatformParams(**base)


def _pitched(theta):
    return np.array([0.0, 0.0, 1.0, 0.0, theta, 0.0])


def test_base_gap_of_a_hand_worked_tilt():
    """A plate of radius r at height 1 pitched by theta: its rim's lowest point is at
    1 - r sin theta; with a clearance c the platform is refused from sin theta = (1 - c) / r."""
    r, c = 0.8, 0.5
    params = _vertical_legs(plate_radius=r, base_clearance=c)
    threshold = np.arcsin((1.0 - c) / r)
    thetas = np.array([0.3, threshold * (1 - 1e-9), threshold * (1 + 1e-9), -threshold * (1 + 1e-9), 1e-7])
    check = stewart.reachability(params, np.array([_pitched(t) for t in thetas]))
    # (at 1e-7 rad, a sine from sqrt(1 - cos^2) would be 4e-4 off, the gap 3e-11 m)
    np.testing.assert_allclose(check.base_gap, 1.0 - r * np.abs(np.sin(thetas)), rtol=1e-14, atol=1e-15)
    assert [bool(f & reachability.BELOW_BASE) for f in check.flags] == [False, False, True, True, False]
    one = reachability.base_gaps(params, _pitched(0.3))
    assert one.shape == () and one == pytest.approx(1.0 - r * np.sin(0.3), rel=1e-15)
    assert ("its plate is at a height of 0.5 m over the base plane, less than the base clearance 0.5 m"
            in check.reasons(2)[0])
    # Without the plate, the lowest spherical joint: 1 - 0.5 sin theta for the joints on the x axis's side.
    poses = np.array([_pitched(t) for t in thetas])
    joints = stewart.reachability(_vertical_legs(), poses)
    heights = 1.0 + (stewart.rotation(poses) @ _vertical_legs().platform_points.T)[:, 2]
    np.testing.assert_allclose(joints.base_gap, heights.min(axis=1), rtol=1e-15)  # reached 0: a few ulp


def test_base_gap_against_a_densely_sampled_rim():
    """Random orientations and heights of a plate lying on joints below {P}'s origin: the gap is
    the lowest of the joints and of 20000 points of the rim, to the sampling's resolution."""
    points = hexapod_points(0.5, (0.0, 120.0, 240.0), 10.0)
    under = points - [0.0, 0.0, 0.05]  # the plate's plane is 5 cm under {P}'s origin
    params = _vertical_legs(platform_points=under, plate_radius=0.7, base_points=points + [0.0, 0.0, 0.02])
    rng = np.random.default_rng(5)
    poses = np.column_stack([rng.uniform(-0.2, 0.2, (50, 2)), rng.uniform(0.5, 1.5, 50), rng.uniform(-1, 1, (50, 3))])
    rot = stewart.rotation(poses)
    angle = np.linspace(0.0, 2 * np.pi, 20000, endpoint=False)
    rim = np.column_stack([0.7 * np.cos(angle), 0.7 * np.sin(angle), np.full(angle.size, -0.05)])
    lowest = np.minimum((poses[:, 2:3] + (rot @ rim.T)[:, 2]).min(axis=1),
                        (poses[:, 2:3] + (rot @ under.T)[:, 2]).min(axis=1))
    gap = reachability.base_gaps(params, poses)
    np.testing.assert_allclose(gap, lowest - 0.02, rtol=0, atol=0.7 * (np.pi / 20000) ** 2)  # reached 0.46 of it
    assert np.all(gap <= lowest - 0.02 + 1e-15)  # the sampled rim never dips below the exact one


def test_plate_crossings_against_line_plane_intersections():
    """Random poses: a leg's crossing is NaN exactly where its base joint lies below the plate's
    plane, else the distance from the plate's centre of the intersection of the line B_i P_i
    with that plane, both computed in {B} (plane normal R e_z through c = p + R (0, 0, h))."""
    points = hexapod_points(0.5, (0.0, 120.0, 240.0), 10.0)
    under = points - [[0.0, 0.0, 0.03 + 0.02 * i] for i in range(6)]  # 0 to 10 cm under the plate, 3 cm under {P}
    params = _vertical_legs(platform_points=under, plate_radius=0.6)
    rng = np.random.default_rng(9)
    poses = np.column_stack([rng.uniform(-0.3, 0.3, (400, 2)), rng.uniform(0.3, 1.2, 400),
                             rng.uniform(-1.5, 1.5, (400, 3))])
    rot = stewart.rotation(poses)
    normal = rot[:, :, 2]
    centre = poses[:, :3] - 0.03 * normal  # the plate's centre: p + R (0, 0, h), h = -0.03 m
    joints = poses[:, None, :3] + np.einsum("nij,kj->nki", rot, under)
    bases = np.broadcast_to(points, joints.shape)
    side = np.einsum("ni,nki->nk", normal, bases - centre[:, None, :])
    along = np.einsum("ni,nki->nk", normal, centre[:, None, :] - bases) / np.einsum("ni,nki->nk", normal,
                                                                                     joints - bases)
    crossing = bases + along[..., None] * (joints - bases)
    distance = np.linalg.norm(crossing - centre[:, None, :], axis=2)
    crossings = reachability.plate_crossings(params, poses)
    above = side >= 0
    assert 0.1 < above.mean() < 0.9
    np.testing.assert_array_equal(np.isnan(crossings), ~above)
    np.testing.assert_allclose(crossings[above], distance[above], rtol=5e-13, atol=5e-16)  # reached 1/68 of it
    flagged = stewart.reachability(params, poses).flags & reachability.LEG_THROUGH_PLATE
    np.testing.assert_array_equal(flagged != 0, np.any(above & (distance < 0.6), axis=1))


def test_a_leg_rising_above_the_plate_is_flagged_at_its_hand_worked_tilt():
    """Pitched by theta at z = 1, leg i's base joint, at angle a_i on the 0.5 m circle, lies above
    the plate's plane (normal (sin theta, 0, cos theta)) from tan theta = 2 / cos a_i: legs 0 and 1
    (a = -+10 deg) first. Their joints lie in the plane, within the plate: they pass through it,
    and with legs 0.1 m thick the plate must end 0.05 m before their joints to clear them."""
    threshold = np.arctan(2.0 / np.cos(np.radians(10.0)))
    params = _vertical_legs(plate_radius=0.6)
    check = stewart.reachability(params, np.array([_pitched(threshold * (1 - 1e-9)), _pitched(threshold * (1 + 1e-9))]))
    assert not check.flags[0] & reachability.LEG_THROUGH_PLATE and check.flags[1] & reachability.LEG_THROUGH_PLATE
    # the crossing is the platform joint itself (s = 0), 0.5 m out: reached 0, a bound of a few ulp
    np.testing.assert_allclose(check.plate_crossings[1, :2], [0.5, 0.5], rtol=1e-15)
    assert np.all(np.isnan(check.plate_crossings[:, 2:])) and np.all(np.isnan(check.plate_crossings[0]))
    assert check.reasons(1)[-1] == ("leg(s) [0, 1] pass through the platform's plate: they cross its plane 0.5, 0.5 m "
                                    "from its centre, within its radius 0.6 m")
    beyond = _pitched(threshold * (1 + 1e-9))
    for radius, flagged in ((0.45 - 1e-6, False), (0.45 + 1e-6, True)):
        thick = stewart.reachability(_vertical_legs(plate_radius=radius, leg_diameter=0.1), beyond)
        assert bool(thick.flags[0] & reachability.LEG_THROUGH_PLATE) == flagged


def test_legs_lying_in_the_plate_plane_cross_it_at_their_joints():
    """Platform joints on a 0.3 m circle, base joints on a 0.5 m one, the plate lowered into the
    base plane (z = 0, yawed or not): every leg lies in the plate's plane, where it meets it at
    its own joint, 0.3 m from the centre, inside a 0.4 m plate (legs 0.1 m thick: they clear a
    0.2 m plate by 0.05 m)."""
    params = _vertical_legs(platform_points=hexapod_points(0.3, (0.0, 120.0, 240.0), 10.0), plate_radius=0.4)
    poses = np.array([[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.4, 0.0, 0.0]])
    np.testing.assert_allclose(reachability.plate_crossings(params, poses), np.full((2, 6), 0.3), rtol=1e-15)
    assert np.all(stewart.reachability(params, poses).flags & reachability.LEG_THROUGH_PLATE)
    thick = params.replace(plate_radius=0.2, leg_diameter=0.1)
    assert not np.any(stewart.reachability(thick, poses).flags & reachability.LEG_THROUGH_PLATE)


def test_presets_name_their_plate_in_the_limits_in_force():
    for name, radius in (("narayan2017", 0.3), ("motion_simulator", 1.2)):
        params = stewart.PlatformParams.preset(name)
        assert params.plate_radius == radius and params.base_clearance is None
        assert f"plate of radius {radius:g} m; base clearance none" in reachability.limits_in_force(params)
        assert stewart.reachability(params, stewart.home_pose(params)).ok[0]
    # The seed paper's 300 mm plate meets the base when tilted by asin(h / r) at home height h.
    params = stewart.PlatformParams.preset("narayan2017").replace(universal_joint_max_angle=None,
                                                                  spherical_joint_max_angle=None)
    home = stewart.home_pose(params)
    tilt = np.arcsin(home[2] / 0.3)
    check = stewart.reachability(params, [home + [0, 0, 0, 0, tilt * (1 - 1e-6), 0],
                                          home + [0, 0, 0, 0, tilt * (1 + 1e-6), 0]])
    assert [bool(f & reachability.BELOW_BASE) for f in check.flags] == [False, True]


@pytest.mark.parametrize("field, value, message", [
    ("plate_radius", 0.0, "plate_radius: need > 0 (metres), got 0.0"),
    ("plate_radius", -0.3, "plate_radius: need > 0 (metres), got -0.3"),
    ("base_clearance", -0.01, "base_clearance: need > 0 (metres), got -0.01"),
    ("base_clearance", float("nan"), "base_clearance: "),
])
def test_bad_clearances_are_errors_naming_the_field(field, value, message):
    with pytest.raises(ValueError, match="^" + message.replace("(", r"\(").replace(")", r"\)")):
        stewart.PlatformParams.preset("narayan2017").replace(**{field: value})


def test_parameter_files_keep_the_clearances(tmp_path):
    params = stewart.PlatformParams.preset("motion_simulator").replace(base_clearance=0.05)
    path = tmp_path / "p.toml"
    params.save(path)
    loaded = stewart.PlatformParams.load(path)
    assert loaded.plate_radius == 1.2 and loaded.base_clearance == 0.05


def test_cli_clearance_flags(capsys):
    """A base clearance excludes the poses whose platform comes closer to the base (none at the
    preset's stroke without one), and the report names the limits in force."""
    argv = ["workspace", "--preset", "narayan2017", "--samples", "3000", "--seed", "2", "--json"]
    main(argv)
    free = json.loads(capsys.readouterr().out)
    main([*argv, "--base-clearance", "0.2", "--plate-radius", "0.35"])
    kept = json.loads(capsys.readouterr().out)
    assert "below_base" not in free["excluded"] and kept["excluded"]["below_base"] > 0
    assert 0 < kept["reachable"] < free["reachable"]
    for flag in ("--plate-radius", "--base-clearance"):
        with pytest.raises(SystemExit) as info:
            main([*argv, flag, "-1"])
        err = capsys.readouterr().err.strip()
        assert info.value.code == 2 and err.splitlines()[-1].endswith(f"argument {flag}: must be > 0, got -1")
    main(["workspace", "--preset", "narayan2017", "--samples", "500", "--seed", "2", "--base-clearance", "0.05"])
    out = capsys.readouterr().out
    assert "limits: stroke 0.19-0.38 m; joint cones universal 45 deg, spherical 30 deg; legs of no thickness; " \
           "plate of radius 0.3 m; base clearance 0.05 m" in out


def test_slices_and_their_figures_name_the_limits_in_force(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    import matplotlib.figure

    from stewart.io.plots import plot_workspace_slices
    from stewart.studies import workspace

    params = stewart.PlatformParams.preset("narayan2017").replace(base_clearance=0.01)
    cut = workspace.workspace_slice(params, "xz", resolution=11)
    assert cut.limits == reachability.limits_in_force(params) and "base clearance 0.01 m" in cut.limits
    titles = []
    save = matplotlib.figure.Figure.savefig
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig",
                        lambda fig, *a, **k: (titles.append(fig._suptitle.get_text()), save(fig, *a, **k))[1])
    plot_workspace_slices([cut], str(tmp_path / "slice.png"), "a study")
    assert titles == [f"a study\nlimits: {cut.limits}"]
