"""The workspace, the arms study and the envelope of rotary rigs (issue 40): the generated joint
quantities and every limit against numpy geometry written here on the crank angles of
tests/rotary_oracle.py (which imports nothing from stewart.model or the kernels), boundary
points that make a limit active, the envelope's peaks against brute force over the oracle's
torques, Dask against local, and the command line's one-line errors."""

import json

import numpy as np
import pytest

import stewart
import rotary_oracle as oracle
from stewart.model import rotary_reachability as rr
from stewart.studies import envelope as env
from stewart.studies import execution, rotary_arms, workspace

from test_rotary import RIGS, random_states
from cli_run import call

SIMRIG = stewart.RotaryParams.preset("simrig100")


def _geometry(rig, x, reference):
    """Per leg, by numpy on the oracle's crank angles: alpha, the cosine of the rod-crank angle,
    of the crank joint's and the platform joint's angles from the rod at ``reference`` (fixed in
    the crank and in {P}), the platform joint's height and the sine of the rod's tilt out of the
    crank's plane (its component along the motor axis)."""
    def legs(pose):
        alpha = oracle.crank_angles(rig, pose)
        R = oracle.rotation(pose[3:])
        out = []
        for i in range(6):
            a, h = rig.motor_axes[i], rig.crank_zero[i]
            u = np.cos(alpha[i]) * h + np.sin(alpha[i]) * np.cross(a, h)
            P = pose[:3] + R @ rig.platform_points[i]
            n = (P - rig.base_points[i] - rig.crank_length * u) / rig.rod_length
            out.append((alpha[i], u, n, R, P, a))
        return out

    rows = []
    for (alpha, u, n, R, P, a), (_, u0, n0, R0, _, _) in zip(legs(x), legs(reference)):
        frame0, frame = np.array([u0, np.cross(a, u0), a]), np.array([u, np.cross(a, u), a])
        crank_axis = frame.T @ (frame0 @ n0)
        rows.append((alpha, -u @ n, n @ crank_axis, n @ (R @ (R0.T @ n0)), P[2], n @ a))
    return [np.array(column) for column in zip(*rows)]


@pytest.mark.parametrize("k", range(len(RIGS)))
def test_joint_cosines_against_numpy_geometry(k, figures):
    rig = RIGS[k]
    model = stewart.RotaryPlatform(rig)
    x, _, _ = random_states(rig, 31 + k)
    reference = x[0] if k == 0 else model.home  # any reference pose, the home by default
    result = model.joint_cosines(x, reference if k == 0 else None)
    worst = 0.0
    for row, pose in enumerate(x):
        expected = _geometry(rig, pose, reference)
        for got, want in zip(result, expected):
            worst = max(worst, float(np.max(np.abs(got[row] - want))))
    figures("rotary: joint cosines, crank angles and joint heights against numpy geometry (abs)", worst, 2e-14)
    # the rods at the reference pose are on their neutral axes
    at_reference = model.joint_cosines(reference, reference)
    assert np.max(np.abs(at_reference.crank_joint - 1.0)) <= 1e-15 and np.max(np.abs(at_reference.platform_joint - 1.0)) <= 1e-15


def _limited(rig):
    """The rig with every limit set, tight enough that each excludes some poses near home."""
    return rig.replace(crank_angle_limits=(-0.5, 0.6), rod_crank_angle_limits=(np.radians(60.0), np.radians(150.0)),
                       crank_joint_max_angle=np.radians(12.0), platform_joint_max_angle=np.radians(11.0),
                       base_clearance=0.41, crank_pin_max_tilt=np.radians(22.0))


def _slacks(rig, pose, home):
    """Per limit, how far inside it (> 0) the pose lies, by numpy on the oracle; None out of reach."""
    if oracle.crank_angles(rig, pose) is None:
        return None
    alpha, fold, crank, platform, heights, tilt = _geometry(rig, pose, home)
    fold, crank, platform = (np.arccos(np.clip(c, -1, 1)) for c in (fold, crank, platform))
    lo, hi = rig.crank_angle_limits
    flo, fhi = rig.rod_crank_angle_limits or (-np.inf, np.inf)
    return {rr.CRANK_ANGLE_LIMIT: np.min(np.minimum(alpha - lo, hi - alpha)),
            rr.ROD_CRANK_ANGLE_LIMIT: np.min(np.minimum(fold - flo, fhi - fold)),
            rr.CRANK_JOINT_LIMIT: np.min(rig.crank_joint_max_angle - crank),
            rr.PLATFORM_JOINT_LIMIT: np.min(rig.platform_joint_max_angle - platform),
            rr.CRANK_PIN_LIMIT: np.min((rig.crank_pin_max_tilt or np.inf) - np.abs(np.arcsin(tilt))),
            stewart.model.reachability.BELOW_BASE: np.min(heights) - np.max(rig.base_points[:, 2])
            - (rig.base_clearance or 0.0)}


def test_every_limit_against_numpy_geometry():
    """On 600 poses about home, each limit's flag is set exactly where the independent geometry
    says the pose breaks it (poses within 1e-9 of a limit aside), and every limit excludes some."""
    rig = _limited(SIMRIG)
    model = stewart.RotaryPlatform(rig)
    rng = np.random.default_rng(5)
    size = rng.uniform(0.05, 1.0, (600, 1))  # from close to home to far out
    x = model.home + size * np.concatenate([rng.uniform(-0.08, 0.08, (600, 3)), rng.uniform(-0.25, 0.25, (600, 3))], 1)
    check = rr.reachability(model, x)
    seen = {bit: 0 for bit in (*_slacks(rig, model.home, model.home), rr.OUT_OF_REACH)}
    for row, pose in enumerate(x):
        slack = _slacks(rig, pose, model.home)
        if slack is None:
            assert check.flags[row] == rr.OUT_OF_REACH, row
            seen[rr.OUT_OF_REACH] += 1
            continue
        for bit, value in slack.items():
            if abs(value) > 1e-9:
                assert bool(check.flags[row] & bit) == (value < 0), (row, bit, value)
                seen[bit] += value < 0
    assert all(count > 0 for count in seen.values()), seen
    assert check.ok.sum() > 0 and "outside the workspace" in check.message()


@pytest.mark.parametrize("axis", [4, 5])
def test_axis_range_ends_on_an_active_limit(axis):
    """The ends of the roll and pitch ranges found by bisection: reachable, a point 1e-9 rad
    beyond not, and there one limit of the independent geometry is active (slack <= 1e-8) or the
    rig's conditioning ends the range (SINGULAR beyond)."""
    rig = _limited(SIMRIG)
    model = stewart.RotaryPlatform(rig)
    low, high = rr.axis_range(model, axis, limit=0.6)
    assert low < 0 < high
    for end, sign in ((low, -1.0), (high, 1.0)):
        pose, beyond = model.home.copy(), model.home.copy()
        pose[axis] += end
        beyond[axis] += end + sign * 1e-9
        assert rr.reachability(model, pose).ok[0] and not rr.reachability(model, beyond).ok[0]
        slack = _slacks(rig, pose, model.home)
        assert slack is not None and min(slack.values()) >= -1e-12
        flags = rr.reachability(model, beyond).flags[0]
        assert min(slack.values()) <= 1e-8 or flags & (stewart.model.reachability.SINGULAR |
                                                       stewart.model.reachability.OTHER_ASSEMBLY_MODE), (end, slack)


def test_arms_study_turns_the_cranks_and_finds_boundaries(tmp_path):
    assert rotary_arms.arm_directions(SIMRIG).tolist() == [1.0] * 6  # the presets' arms point outwards
    inwards = rotary_arms.with_arms(SIMRIG, "inwards")
    assert rotary_arms.arm_directions(inwards).tolist() == [-1.0] * 6
    np.testing.assert_array_equal(inwards.crank_zero, -SIMRIG.crank_zero)
    np.testing.assert_array_equal(np.cross(inwards.motor_axes, inwards.crank_zero),
                                  np.cross(SIMRIG.motor_axes, SIMRIG.crank_zero))  # the tips still rise
    assert rotary_arms.with_arms(SIMRIG, "outwards") == SIMRIG.replace(name="simrig100, arms outwards")
    for height in (None, 0.48):
        study = rotary_arms.arms_study(SIMRIG, resolution=21, height=height)
        for way in rotary_arms.ARMS:
            rig = rotary_arms.with_arms(SIMRIG, way)
            start = study.start[way]
            assert start[2] == (stewart.RotaryPlatform(rig).home[2] if height is None else height)
            for axis, (low, high) in ((5, study.roll[way]), (4, study.pitch[way])):
                for end in (low, high):
                    pose = start.copy()
                    pose[axis] += end
                    slack = _slacks(rig, pose, start)  # the joints centred at the start pose
                    assert -1e-12 <= min(slack.values()) <= 1e-8, (way, axis, end, slack)
        assert study.roll["outwards"] != study.roll["inwards"]
    # held at 0.48 m, arms inwards stand 57.5 deg up their +-60 deg travel: less than a degree of roll is left
    assert study.roll["inwards"][1] < np.radians(1.0) < np.radians(5.0) < study.roll["outwards"][1]
    assert study.plot(str(tmp_path / "arms.png")) and (tmp_path / "arms.png").stat().st_size > 0
    with pytest.raises(ValueError, match="way"):
        rotary_arms.with_arms(SIMRIG, "sideways")
    with pytest.raises(ValueError, match="limit"):
        rotary_arms.arms_study(SIMRIG, limit=2.0)


def test_bad_arguments_name_themselves():
    model = stewart.RotaryPlatform(SIMRIG)
    for kwargs, name in ((dict(axis=6), "axis"), (dict(axis=1.5), "axis"), (dict(axis=0, step=-1.0), "step"),
                         (dict(axis=0, start=np.zeros(5)), "start")):
        with pytest.raises(ValueError, match=name):
            rr.axis_range(model, **kwargs)
    with pytest.raises(ValueError, match="poses"):
        rr.reachability(model, [0.0, 0.0, np.nan, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="platform"):
        rr.reachability(stewart.PlatformParams.preset("narayan2017"), np.zeros(6))
    with pytest.raises(ValueError, match="reference"):
        model.joint_cosines(model.home, np.zeros((2, 6)))
    with pytest.raises(ValueError, match="stiffness"):
        workspace.translational_workspace(SIMRIG, samples=10, stiffness=1e6)


@pytest.mark.parametrize("field, value", [("rod_crank_angle_limits", (0.5, 3.5)),
                                          ("rod_crank_angle_limits", (-0.1, 1.0)),
                                          ("rod_crank_angle_limits", (1.0, 0.5)),
                                          ("rod_crank_angle_limits", (1.0,)), ("base_clearance", -0.1),
                                          ("base_clearance", "x"), ("crank_pin_max_tilt", 1.7),
                                          ("crank_pin_max_tilt", np.nan)])
def test_new_limits_are_checked(field, value):
    with pytest.raises(ValueError, match=field):
        SIMRIG.replace(**{field: value})


def test_new_limits_round_trip(tmp_path):
    rig = _limited(SIMRIG)
    for ext in ("toml", "json"):
        rig.save(tmp_path / f"rig.{ext}")
        assert stewart.RotaryParams.load(tmp_path / f"rig.{ext}") == rig
    words = rr.limits_in_force(rig)
    assert "rod-crank angles 60 to 150 deg" in words and "base clearance 0.41 m" in words
    assert "crank pins' tilt 22 deg" in words


def test_workspace_study_counts_what_the_test_excludes():
    """A translational study's counts are those of the reachability test on its own poses, the
    slices name the rotary limits, and a grid's reachable cells are those the test passes."""
    rig = _limited(SIMRIG)
    home = stewart.RotaryPlatform(rig).home[:3]
    region = np.column_stack([home - 0.1, home + 0.1])
    result = workspace.translational_workspace(rig, region=region, samples=3000, chunk_size=1000, seed=4)
    job, total = workspace.study_job(rig, "translational", result.fixed, result.region, 3000, None)
    poses = np.concatenate([job.poses(c) for c in execution.chunks(total, 1000, 4)])
    check = rr.reachability(rig, poses)
    assert 0 < result.reachable == int(check.ok.sum()) < 3000
    assert result.excluded == {rr.FLAG_NAMES[b]: int(np.count_nonzero(check.flags & b)) for b in rr.FLAGS
                               if np.count_nonzero(check.flags & b)}
    ranges = workspace.orientation_workspace(rig, samples=2000, region=[[-0.5, 0.5]] * 3)
    assert 0 < ranges.reachable < 2000
    cut = workspace.workspace_slice(rig, ("phi", "theta"), resolution=15)
    assert "crank angles" in cut.limits and cut.jacobian == "J_alpha"
    assert np.array_equal(np.isnan(cut.margin), cut.flags != 0)


def test_dask_gives_the_local_workspace_and_envelope():
    distributed = pytest.importorskip("distributed")
    rig = _limited(SIMRIG)
    home = stewart.RotaryPlatform(rig).home
    box = env.Box(home - [0.03, 0.03, 0.03, 0.1, 0.1, 0.1], home + [0.03, 0.03, 0.03, 0.1, 0.1, 0.1],
                  np.full(6, 0.2), np.full(6, 2.0))
    region = np.column_stack([home[:3] - 0.1, home[:3] + 0.1])
    local = (workspace.translational_workspace(rig, region=region, samples=4000, chunk_size=1000).summary(),
             env.envelope(rig, box, samples=4000, chunk_size=1000, progress=False))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        remote = (workspace.translational_workspace(rig, region=region, samples=4000, chunk_size=1000,
                                                    client=client).summary(),
                  env.envelope(rig, box, samples=4000, chunk_size=1000, progress=False, client=client))
    assert remote[0] == local[0] and local[0]["reachable"] > 0
    assert np.array_equal(remote[1].peak.value, local[1].peak.value)
    assert np.array_equal(remote[1].peak.index, local[1].peak.index)
    assert (remote[1].outside_stroke, remote[1].singular) == (local[1].outside_stroke, local[1].singular)


def _brute(rig, x, xd, xdd):
    """Per state, |tau|, |alpha_dot| and |tau alpha_dot| of each motor from the oracle."""
    rows = []
    for state in zip(x, xd, xdd):
        tau, rate = oracle.torques(rig, *state), oracle.crank_rates(rig, *state[:2])
        rows.append(np.concatenate([np.abs(tau), np.abs(rate), np.abs(tau * rate)]))
    return np.array(rows)


def test_envelope_peaks_equal_brute_force_over_the_oracle(figures):
    rig = RIGS[1].replace(crank_angle_limits=(-0.35, 0.35))
    model = stewart.RotaryPlatform(rig)
    box = env.Box(model.home - [0.02, 0.02, 0.03, 0.05, 0.05, 0.05], model.home + [0.02, 0.02, 0.03, 0.05, 0.05, 0.05],
                  np.array([0.1, 0.1, 0.2, 0.3, 0.3, 0.3]), np.array([1.0, 1.0, 3.0, 2.0, 2.0, 2.0]))
    result = env.envelope(rig, box, samples=1500, chunk_size=400, progress=False)
    states = [np.concatenate(parts) for parts in zip(*(box.states(c) for c in execution.chunks(1500, 400, 0)))]
    alpha = model.crank_angles(states[0])
    inside = np.all((alpha >= -0.35) & (alpha <= 0.35), axis=1)
    assert 0 < result.outside_stroke == np.count_nonzero(~inside) and result.singular == 0
    values = _brute(rig, *(s[inside] for s in states))
    figures("rotary: envelope peaks against brute force over the oracle (relative)",
            np.max(np.abs(result.peak.value / values.max(axis=0) - 1.0)), 1e-12)
    assert np.array_equal(result.peak.index, np.flatnonzero(inside)[np.argmax(values, axis=0)])
    assert [row["motor"] for row in result.rows()[:6]] == list(range(6)) and result.summary()["outside_crank_limits"]


def test_envelope_on_every_simd_path_alike():
    model = stewart.RotaryPlatform(SIMRIG)
    box = env.Box(model.home - 0.02, model.home + 0.02, np.full(6, 0.2), np.full(6, 2.0))
    previous, first = stewart.set_simd(None), None
    try:
        for path in stewart.build_info()["supported"]:
            stewart.set_simd(path)
            peaks = env.envelope(SIMRIG, box, samples=700, chunk_size=300, progress=False).peak.value
            first = peaks if first is None else first
            assert np.array_equal(first, peaks), path
    finally:
        stewart.set_simd(previous)


def test_cli_workspace_arms_and_envelope(tmp_path):
    path = tmp_path / "rig.toml"
    _limited(SIMRIG).save(path)
    out = call("workspace", "--params", path, "--samples", "2000", "--slices", tmp_path / "maps", "--resolution", "15",
               "--region", -0.1, 0.1, -0.1, 0.1, 0.35, 0.55)
    assert out.returncode == 0, out.stderr
    assert "limits: crank angles" in out.stdout and "1/cond J_alpha" in out.stdout
    assert (tmp_path / "maps" / "workspace_translational.png").stat().st_size > 0
    out = call("workspace", "--preset", "simrig100", "--kind", "orientation", "--samples", "2000", "--json",
               "--region", *[-0.5, 0.5] * 3)
    assert out.returncode == 0 and json.loads(out.stdout)["reachable"] > 0
    out = call("workspace", "--preset", "simrig100", "--arms", "--json", "--resolution", "11", "--arms-height", "0.48")
    printed = json.loads(out.stdout)
    study = rotary_arms.arms_study(SIMRIG, resolution=11, height=0.48)
    assert printed["same_height"]["arms"]["inwards"]["roll"] == list(study.roll["inwards"])
    assert printed["same_height"]["arms"]["outwards"]["pitch"] == list(study.pitch["outwards"])
    assert printed["own_home"]["arms"]["inwards"]["roll"] == list(rotary_arms.arms_study(SIMRIG, resolution=11).roll["inwards"])
    out = call("workspace", "--preset", "simrig100", "--arms", "--resolution", "11", "--slices", tmp_path / "arms")
    assert out.returncode == 0 and "both at z = 0.4508 m (the rig's home)" in out.stdout
    assert (tmp_path / "arms" / "arms_same_height.png").stat().st_size > 0
    out = call("envelope", "--params", path, "--lower", 0, 0, 0.44, 0, 0, 0, "--upper", 0, 0, 0.46, 0, 0, 0, "--velocity", *[0.1] * 6, "--acceleration", *[1.0] * 6,
               "--samples", "500")
    assert out.returncode == 0, out.stderr
    assert "motor" in out.stdout.splitlines()[1] and "torque [N m]" in out.stdout


def test_cli_bound_flags_override_the_parameters():
    """--crank-pin-max-tilt in degrees becomes the rig's limit in radians: the command's counts
    are the reachability test's on the same poses with that limit."""
    region = ["-0.05", "0.05", "-0.05", "0.05", "0.42", "0.48"]
    out = call("workspace", "--preset", "simrig100", "--crank-pin-max-tilt", "20", "--samples", "400", "--region",
               *region)
    assert out.returncode == 0 and "crank pins' tilt 20 deg" in out.stdout, out.stderr
    rig = SIMRIG.replace(crank_pin_max_tilt=np.radians(20.0))
    result = workspace.translational_workspace(rig, region=np.array(region, float).reshape(3, 2), samples=400)
    assert f"crank_pin_limit {result.excluded['crank_pin_limit']}" in out.stdout


@pytest.mark.parametrize("argv, flag", [
    (["--preset", "simrig100", "--leg-diameter", "0.01"], "--leg-diameter"),
    (["--preset", "simrig100", "--stiffness", "1e6"], "--stiffness"),
    (["--preset", "narayan2017", "--crank-limits", "-30", "30"], "--crank-limits"),
    (["--preset", "narayan2017", "--arms"], "--arms"),
    (["--preset", "simrig100", "--rod-crank-limits", "10", "200"], "--rod-crank-limits"),
    (["--preset", "simrig100", "--crank-joint-max-angle", "95"], "--crank-joint-max-angle"),
    (["--preset", "simrig100", "--crank-pin-max-tilt", "95"], "--crank-pin-max-tilt"),
    (["--preset", "narayan2017", "--crank-pin-max-tilt", "20"], "--crank-pin-max-tilt"),
    (["--preset", "simrig100", "--arms", "--grid", "5"], "--arms"),
    (["--preset", "simrig100", "--arms-height", "0.4"], "--arms-height"),
])
def test_cli_bad_input_gives_one_line(argv, flag):
    out = call("workspace", *argv)
    lines = out.stderr.strip().splitlines()
    assert out.returncode == 2 and len(lines) == 1 and flag in lines[0] and "Traceback" not in out.stderr, out.stderr


def test_envelope_of_a_move_and_a_trajectory_file(tmp_path):
    """A move sampled every 10 ms: the peaks and their sample indices are brute force's over the
    oracle; the same move written as a trajectory file gives the same peaks from the command."""
    model = stewart.RotaryPlatform(SIMRIG)
    move = stewart.PointToPoint(model.home, model.home + [0.02, -0.01, 0.015, 0.03, 0.04, -0.05], 0.8)
    result = env.envelope(SIMRIG, env.Trajectories([move], dt=0.01), progress=False)
    states = move.sample(np.arange(81) * 0.01)
    values = _brute(SIMRIG, *states)
    assert result.states == 81 and result.outside_stroke == result.singular == 0
    np.testing.assert_allclose(result.peak.value, values.max(axis=0), rtol=1e-12)
    assert np.array_equal(result.peak.index, np.argmax(values, axis=0))
    path = tmp_path / "move.csv"
    np.savetxt(path, np.column_stack([np.arange(81) * 0.01, states[0]]), delimiter=",",
               header="t,x,y,z,psi,theta,phi", comments="")
    out = call("envelope", "--preset", "simrig100", "--trajectory", path, "--dt", "0.01", "--json", tmp_path / "e.json")
    assert out.returncode == 0, out.stderr
    written = json.loads((tmp_path / "e.json").read_text())
    assert written["states"] == 81 and [row["quantity"] for row in written["peaks"][::6]] == ["torque", "speed", "power"]
