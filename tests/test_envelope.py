"""Force and joint-load envelopes (stewart.studies.envelope): the peaks against brute-force dense
evaluation of the Newton-Euler solution, the stroke count, and one-line errors for bad
specifications."""

from __future__ import annotations

import itertools
import re

import numpy as np
import pytest
from cli_outputs import check_envelope_table

import stewart
from stewart.studies import envelope as env
from stewart.studies import execution
from stewart.oracles import newton_euler
from stewart.model.presets import narayan2017_target_pose

from conftest import make_general

PARAMS = stewart.PlatformParams.preset("narayan2017")


def _brute_force(params, x, xd, xdd):
    """The 30 per-leg magnitudes of each state from the Newton-Euler solution (an independent route)."""
    joints = newton_euler.joint_reactions(params, x, xd, xdd)
    rate = stewart.Platform(params).leg_rates(x, xd)[1]
    return np.hstack([np.abs(joints.tau), np.abs(rate), np.abs(joints.tau * rate),
                      np.linalg.norm(joints.base, axis=-1), np.linalg.norm(joints.platform, axis=-1)])


def _vertices(bounds):
    """Every vertex of the box |v_k| <= bounds_k (a zero bound gives one value)."""
    axes = [(-b, b) if b > 0 else (0.0,) for b in bounds]
    return np.array(list(itertools.product(*axes)))


#: The seed paper's platform, and the same with universal joints, legs with I_yy != I_zz and
#: an off-centre payload (the general model).
PLATFORMS = {"paper": PARAMS, "general": make_general(PARAMS, np.random.default_rng(12))}


@pytest.mark.parametrize("model", sorted(PLATFORMS))
def test_fixed_pose_peaks_equal_the_vertex_enumeration_and_bound_the_interior(model):
    params = PLATFORMS[model]
    pose = stewart.home_pose(params) + np.array([0.01, -0.005, 0.02, 0.05, -0.04, 0.03])
    velocity = np.array([0.2, 0.0, 0.1, 0.0, 0.5, 0.0])
    acceleration = np.array([2.0, 0.0, 3.0, 1.0, 0.0, 4.0])
    box = env.Box(pose, pose, velocity, acceleration)
    result = env.envelope(params, box, samples=20_000, chunk_size=3000, progress=False)
    vel, acc = _vertices(velocity), _vertices(acceleration)
    xd = np.repeat(vel, len(acc), axis=0)
    xdd = np.tile(acc, (len(vel), 1))
    values = _brute_force(params, np.tile(pose, (len(xd), 1)), xd, xdd)
    np.testing.assert_allclose(result.peak.value, values.max(axis=0), rtol=5e-14)  # reached 1.2e-15
    # Forces are affine in the acceleration: no point inside the acceleration box exceeds its vertices.
    inner = np.random.default_rng(3).uniform(-1, 1, (len(xd), 6)) * acceleration
    assert np.all(_brute_force(params, np.tile(pose, (len(xd), 1)), xd, inner) <= result.peak.value * (1 + 1e-12))
    # The state reported with each peak gives that peak.
    state = result.peak.state
    np.testing.assert_allclose(np.diag(_brute_force(params, state[:, :6], state[:, 6:12], state[:, 12:])),
                               result.peak.value, rtol=5e-14)  # reached 1.2e-15


def test_box_peaks_approach_a_dense_grid():
    home = stewart.home_pose(PARAMS)
    lower, upper = home + np.array([0, 0, -0.01, 0, -0.05, 0]), home + np.array([0, 0, 0.01, 0, 0.05, 0])
    velocity, acceleration = np.array([0.1, 0, 0, 0, 0.2, 0]), np.array([0, 0, 2.0, 0, 3.0, 0])
    result = env.envelope(PARAMS, env.Box(lower, upper, velocity, acceleration), samples=40_000, progress=False)
    grid = np.array([home + np.array([0, 0, dz, 0, dth, 0])
                     for dz in np.linspace(-0.01, 0.01, 21) for dth in np.linspace(-0.05, 0.05, 21)])
    rates = np.array([np.concatenate([v, a]) for v in _vertices(velocity) for a in _vertices(acceleration)])
    x = np.repeat(grid, len(rates), axis=0)
    rr = np.tile(rates, (len(grid), 1))
    dense = _brute_force(PARAMS, x, rr[:, :6], rr[:, 6:]).max(axis=0)
    # random samples against a 21 x 21 grid, the peaks between them: reached 6.0e-4
    np.testing.assert_allclose(result.peak.value, dense, rtol=2e-3)


def test_trajectory_peaks_equal_brute_force_over_the_samples():
    home = stewart.home_pose(PARAMS)
    move = stewart.PointToPoint(home, narayan2017_target_pose(), 1.0)
    result = env.envelope(PARAMS, env.Trajectories([move, stewart.PointToPoint(home, home + 0.01, 0.5)], dt=0.002),
                          chunk_size=300, progress=False)
    t1, t2 = np.arange(501) * 0.002, np.arange(251) * 0.002
    states = [np.concatenate(parts) for parts in zip(move.sample(t1), stewart.PointToPoint(home, home + 0.01, 0.5)
                                                     .sample(t2))]
    values = _brute_force(PARAMS, *states)
    assert result.states == 752 and result.outside_stroke == 0 and result.singular == 0
    np.testing.assert_allclose(result.peak.value, values.max(axis=0), rtol=5e-14)  # reached 1.4e-15
    assert np.array_equal(result.peak.index, np.argmax(values, axis=0))


def test_states_outside_the_stroke_are_counted_and_left_out():
    home = stewart.home_pose(PARAMS)
    box = env.Box(home - [0, 0, 0.15, 0, 0, 0], home + [0, 0, 0.15, 0, 0, 0], np.zeros(6), np.zeros(6))
    result = env.envelope(PARAMS, box, samples=5000, chunk_size=1000, progress=False)
    x = np.concatenate([box.states(c)[0] for c in execution.chunks(5000, 1000, 0)])
    lengths = stewart.Platform(PARAMS).leg_lengths(x)
    lo, hi = PARAMS.leg_length_limits
    outside = np.any((lengths < lo) | (lengths > hi), axis=1)
    assert 0 < result.outside_stroke == np.count_nonzero(outside) < 5000
    assert np.all(np.isin(result.peak.index, np.flatnonzero(~outside)))


def test_margin_box_holds_the_move():
    home = stewart.home_pose(PARAMS)
    move = stewart.PointToPoint(home, narayan2017_target_pose(), 2.0)
    box = env.Box.around(move, 0.2)
    x, xd, xdd = move.sample(np.linspace(0, 2, 201))
    assert np.all((x >= box.lower) & (x <= box.upper))
    assert np.all(np.abs(xd) <= box.velocity / 1.2 * (1 + 1e-12)) and np.all(np.abs(xdd) <= box.acceleration)
    # the margin by hand: each pose range widened by 0.2 of its width on either side, the peak
    # rates times 1.2 (the box samples every 0.01 s, as linspace does here: reached 0)
    low, high = x.min(axis=0), x.max(axis=0)
    np.testing.assert_allclose(box.lower, low - 0.2 * (high - low), rtol=1e-15, atol=0)
    np.testing.assert_allclose(box.upper, high + 0.2 * (high - low), rtol=1e-15, atol=0)
    np.testing.assert_allclose(box.velocity, 1.2 * np.abs(xd).max(axis=0), rtol=1e-15, atol=0)
    np.testing.assert_allclose(box.acceleration, 1.2 * np.abs(xdd).max(axis=0), rtol=1e-15, atol=0)


@pytest.mark.parametrize("fields, name", [
    ({"upper": np.zeros(6) - 1}, "upper"),
    ({"velocity": [-1, 0, 0, 0, 0, 0]}, "velocity"),
    ({"acceleration": [1, 2, 3]}, "acceleration"),
    ({"lower": [0, 0, np.nan, 0, 0, 0]}, "lower"),
])
def test_bad_boxes_name_the_field(fields, name):
    spec = {"lower": np.zeros(6), "upper": np.ones(6), "velocity": np.ones(6), "acceleration": np.ones(6), **fields}
    with pytest.raises(ValueError, match=f"^{name}: [^\n]*$"):
        env.Box(**spec)


def test_bad_requests_name_the_argument():
    box = env.Box(np.zeros(6), np.ones(6), np.ones(6), np.ones(6))
    with pytest.raises(ValueError, match="^samples: "):
        env.envelope(PARAMS, box, samples=0, progress=False)
    with pytest.raises(TypeError, match="positional argument"):  # the options are keyword-only
        env.envelope(PARAMS, box, 2000)
    for samples in (1.5, True, np.int64(0)):
        with pytest.raises(ValueError, match=f"^{re.escape(f'samples: expected a whole number >= 1, got {samples!r}')}$"):
            env.envelope(PARAMS, box, samples=samples, progress=False)
    assert box.count(10**12) == 10**12 and box.count(np.int64(7)) == 7  # the most a study may draw
    with pytest.raises(ValueError, match=r"^samples: at most 1e\+12 states, got 1000000000001$"):
        box.count(10**12 + 1)
    with pytest.raises(ValueError, match="^motions: "):
        env.Trajectories([])
    with pytest.raises(ValueError, match="^dt: "):
        env.Trajectories([stewart.PointToPoint(np.zeros(6), np.ones(6), 1.0)], dt=0)


def test_outputs_hold_the_sizing_table(tmp_path):
    pytest.importorskip("matplotlib")
    home = stewart.home_pose(PARAMS)
    result = env.envelope(PARAMS, env.Box(home, home, np.full(6, 0.1), np.full(6, 1.0)), samples=2000,
                          progress=False)
    result.to_csv(tmp_path / "e.csv")
    result.to_json(tmp_path / "e.json")
    result.plot(tmp_path / "e.png")
    import json

    rows = json.loads((tmp_path / "e.json").read_text())["peaks"]
    assert len(rows) == 30 and rows[0]["quantity"] == "force" and rows[0]["peak"] == result.peak.value[0]
    assert (tmp_path / "e.png").stat().st_size > 10_000
    assert (tmp_path / "e.csv").read_text().count("\n") == 32


def test_cli_prints_the_table_and_writes_the_files(tmp_path, capsys):
    from stewart.cli import main

    target = narayan2017_target_pose().tolist()
    main(["envelope", "--target", *map(str, target), "--move-time", "1", "--dt", "0.01",
          "--json", str(tmp_path / "e.json"), "--no-progress"])
    out = capsys.readouterr().out
    home = stewart.home_pose(PARAMS)
    expected = env.envelope(PARAMS, env.Trajectories([stewart.PointToPoint(home, target, 1.0)], 0.01), progress=False)
    check_envelope_table(out, expected)
    import json

    assert json.loads((tmp_path / "e.json").read_text())["states"] == 101


@pytest.mark.parametrize("argv, message", [
    (["--lower", "0", "0", "0", "0", "0", "0", "--upper", "0", "0", "-1", "0", "0", "0", "--velocity", *"000000",
      "--acceleration", *"000000"], "--upper: below lower on axis z"),
    (["--lower", *"000000"], "--upper --velocity --acceleration missing"),
    (["--trajectory", "missing.csv"], "--trajectory missing.csv"),
])
def test_cli_bad_specifications_give_one_line(argv, message, capsys):
    from stewart.cli import main

    with pytest.raises(SystemExit) as exit_info:
        main(["envelope", *argv, "--no-progress"])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2 and message in err and err.count("\n") == 1


def test_chunks_beyond_the_threads_buffer_draw_the_same_states(monkeypatch, simd_path):
    """A chunk larger than the per-thread buffer of uniform numbers draws into its own array:
    the same states, the same peaks."""
    home = stewart.home_pose(PARAMS)
    box = env.Box(home - 0.01, home + 0.01, np.full(6, 0.1), np.full(6, 1.0))
    buffered = env.envelope(PARAMS, box, samples=3000, chunk_size=1500, progress=False)
    monkeypatch.setattr(env, "_UNIFORMS_ROWS", 1000)
    own = env.envelope(PARAMS, box, samples=3000, chunk_size=1500, progress=False)
    assert np.array_equal(buffered.peak.value, own.peak.value) and np.array_equal(buffered.peak.index, own.peak.index)
    assert np.array_equal(buffered.peak.state, own.peak.state)
