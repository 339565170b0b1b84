"""The ``stewart`` command, with assertions on the numbers it prints and writes."""

import json
import pathlib
import sys

import numpy as np
import pytest
from cli_run import run as _run
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from interrupt import press_ctrl_c_after

import stewart
from stewart.cli import main
from stewart.model.presets import narayan2017_target_pose
from stewart.oracles import exactness


def _numbers(text):
    """The rows of a printed table: a '# platform' line, a header line, then numbers."""
    lines = text.strip().splitlines()
    assert lines[0].startswith("# platform ")
    return np.array([[float(v) for v in line.split()] for line in lines[2:]])


def test_ik_prints_leg_lengths(capsys):
    main(["ik", "--pose", "0.01", "0", "0.25", "0", "0.05", "0"])
    printed = _numbers(capsys.readouterr().out)
    expected = stewart.Platform.preset("narayan2017").leg_lengths([0.01, 0, 0.25, 0, 0.05, 0])
    np.testing.assert_allclose(printed[0], expected, rtol=1e-9)


def test_id_and_fd_round_trip_through_csv_files(tmp_path, capsys):
    plat = stewart.Platform.preset("motion_simulator")
    x = plat.home_pose + [0.1, 0, 0, 0, 0.05, 0]
    rows = np.array([np.concatenate([x, [0, 0, 0.2, 0, 0, 0.1], [1, 0, -1, 0, 0.5, 0]])])
    np.savetxt(tmp_path / "in.csv", rows, delimiter=",")
    main(["id", "--preset", "motion_simulator", "--input", str(tmp_path / "in.csv"), "--csv", str(tmp_path / "tau.csv")])
    tau = np.loadtxt(tmp_path / "tau.csv", delimiter=",", skiprows=1)
    assert "(platform motion_simulator (preset))" in capsys.readouterr().out
    np.testing.assert_allclose(tau, plat.inverse_dynamics(rows[0, :6], rows[0, 6:12], rows[0, 12:]), rtol=1e-10)
    main(["fd", "--preset", "motion_simulator", "--pose", *map(str, x), "--vel", "0", "0", "0.2", "0", "0", "0.1",
          "--force", *map(str, tau)])
    np.testing.assert_allclose(_numbers(capsys.readouterr().out)[0], rows[0, 12:], atol=1e-10, rtol=1e-12)  # reached 1/33 of it


def test_params_file_is_used(tmp_path, capsys):
    params = stewart.PlatformParams.preset("narayan2017").replace(name="file")
    params.save(tmp_path / "p.toml")
    main(["ik", "--params", str(tmp_path / "p.toml"), "--pose", "0", "0", "0.3", "0", "0", "0"])
    np.testing.assert_allclose(_numbers(capsys.readouterr().out)[0], stewart.leg_lengths(params, [0, 0, 0.3, 0, 0, 0]),
                               rtol=1e-9)


@pytest.mark.slow
def test_simulate_writes_series(tmp_path, capsys):
    """The series; the plots of --plot are checked by tests/test_readme.py, whose command
    of docs/cli.md runs the same simulation with --plot."""
    target = ["0.04565", "-0.0102", "0.192", "-0.086", "0.105", "0.096"]
    main(["simulate", "--target", *target, "--csv", str(tmp_path / "run.csv"), "--no-progress"])
    out = capsys.readouterr().out
    assert "outcome: completed" in out
    table = np.genfromtxt(tmp_path / "run.csv", delimiter=",", names=True)
    assert table["t"][-1] == pytest.approx(5.0, rel=1e-10, abs=0)  # reached 0: the file's 10 digits
    # the PID's settling after the 5 s move (reached 1.0e-5)
    np.testing.assert_allclose([table[k][-1] for k in ("x", "y", "z", "psi", "theta", "phi")],
                               np.array(target, dtype=float), rtol=0, atol=1e-4)
    peak = [float(v) for v in out.split("peak force per leg [N]: ")[1].split("\n")[0].split()]
    np.testing.assert_allclose(peak, [np.max(np.abs(table[f"force{i}"])) for i in range(6)], rtol=1e-3)


def test_simulate_takes_the_friction_of_the_parameter_file(tmp_path, capsys):
    """The actuators lose the file's per-leg friction unless --viscous/--coulomb replace it:
    the run's forces are those of stewart.simulate with the same actuators."""
    params = stewart.PlatformParams.preset("narayan2017").replace(
        viscous_friction=[20.0, 30.0, 40.0, 50.0, 60.0, 70.0], coulomb_friction=[0.5, 1.0, 1.5, 2.0, 2.5, 3.0])
    params.save(tmp_path / "machine.toml")
    goal = narayan2017_target_pose()
    runs = {}
    for name, flags in (("own", []), ("none", ["--viscous", "0", "--coulomb", "0"])):
        main(["simulate", "--params", str(tmp_path / "machine.toml"), "--target", *(repr(float(v)) for v in goal),
              "--duration", "1", "--no-progress", "--csv", str(tmp_path / f"{name}.csv")] + flags)
        assert "outcome: completed" in capsys.readouterr().out
        table = np.genfromtxt(tmp_path / f"{name}.csv", delimiter=",", names=True)
        runs[name] = np.column_stack([table[f"force{i}"] for i in range(6)])
    plat = stewart.Platform(params)
    move = stewart.PointToPoint(plat.home_pose, goal, 5.0)
    for name, actuators in (("own", None), ("none", stewart.Actuators(viscous=0.0, coulomb=0.0))):
        want = stewart.simulate(plat, move, duration=1.0, actuators=actuators).forces
        np.testing.assert_allclose(runs[name], want, rtol=1e-9, atol=1e-9 * np.max(np.abs(want)))
    assert np.max(np.abs(runs["own"] - runs["none"])) > 1.0


def test_simulate_refuses_a_target_below_the_stroke(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["simulate", "--target", "0", "0", "0.1", "0", "0", "0", "--no-progress"])
    assert exit_info.value.code == 3
    err = capsys.readouterr().err
    assert err.startswith("stewart simulate: error: --target: ") and "shorter than the minimum length 0.19 m" in err


def test_validate_passes_for_presets(capsys):
    main(["validate", "--preset", "motion_simulator", "--states", "50"])
    assert "all 20 checks passed" in capsys.readouterr().out


def test_bad_input_is_an_error_naming_the_argument(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["ik", "--pose", "0", "0", "nan", "0", "0", "0"])
    assert exit_info.value.code == 2
    assert "argument --pose: not a finite number: 'nan'" in capsys.readouterr().err


# `stewart bench --json` (its JSON on stdout, the same figures in its table on stderr) is
# tested by tests/test_readme.py, which runs the bench command of docs/cli.md: the one run of it.


def _one_error_line(err, command, start):
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"stewart {command}: error: {start}"), lines[0]
    return lines[0]


ISSUE_TARGET = ["0", "0", "0.278", "0", "1.5707963", "0"]


def spherical_cone_crossing(params, target, duration=5.0):
    """The time [s] at which a spherical joint first leaves its cone (``spherical_joint_max_angle``)
    on the default move (the seed paper's sinusoidal profile ``s - sin(2 pi s) / (2 pi)``) from
    home to ``target``, a pure pitch ``theta`` with the other angles zero, in closed form: the
    leg ``p + R_y(theta) p_i - b_i`` against its neutral axis, the home leg direction turned
    with the platform by ``R_y(theta)``; root-found between the 1 ms samples."""
    from scipy.optimize import brentq

    home, target = stewart.home_pose(params), np.asarray(target)
    assert not np.any(home[3:]) and not np.any(target[[3, 5]])

    def largest_angle(t):
        s = t / duration - np.sin(2 * np.pi * t / duration) / (2 * np.pi)
        x = home + s * (target - home)
        c, n = np.cos(x[4]), np.sin(x[4])
        turn = np.array([[c, 0.0, n], [0.0, 1.0, 0.0], [-n, 0.0, c]])
        legs = x[:3] + params.platform_points @ turn.T - params.base_points
        neutral = (home[:3] + params.platform_points - params.base_points) @ turn.T
        cosine = np.sum(legs * neutral, axis=1) / np.linalg.norm(legs, axis=1) / np.linalg.norm(neutral, axis=1)
        return np.max(np.arccos(np.clip(cosine, -1.0, 1.0))) - params.spherical_joint_max_angle

    t = np.arange(0.0, duration, 1e-3)
    after = np.argmax([largest_angle(v) > 0 for v in t])
    return brentq(largest_angle, t[after - 1], t[after], xtol=1e-12)


@pytest.mark.parametrize("controller", ["pid", "ct"])
def test_the_issue_target_is_outside_the_workspace(capsys, controller):
    code, out, err = _run(["simulate", "--target", *ISSUE_TARGET, "--controller", controller, "--no-progress"], capsys)
    assert code == 3 and "completed" not in out
    line = _one_error_line(err, "simulate", "--target: ")
    assert "another assembly mode" in line and "theta = +-90 deg" in line


def test_each_failed_run_has_its_exit_code(capsys):
    target = ["0.04565", "-0.0102", "0.192", "-0.086", "0.105", "0.096"]
    code, out, _ = _run(["simulate", "--target", *target, "--tolerance", "1e-9", "1e-9"], capsys)
    assert code == 5 and "outcome: inaccurate (exit code 5)" in out and "above the tolerance 1e-09 m" in out
    code, out, _ = _run(["simulate", "--target", *target, "--controller", "ct", "--force-limit", "21",
                         "--duration", "1"], capsys)
    assert code == 6 and "outcome: saturated (exit code 6)" in out and "exceeded the actuator limit 21 N" in out
    code, out, _ = _run(["simulate", "--target", *target, "--method", "adaptive", "--max-steps", "5"], capsys)
    assert code == 4 and "outcome: failed (exit code 4)" in out and "budget of 5 steps" in out
    code, out, _ = _run(["simulate", "--target", *target, "--duration", "0.2"], capsys)
    assert code == 0 and "outcome: completed" in out and "platform narayan2017 (preset), controller PID" in out


def test_ik_id_fd_check_reachability(tmp_path, capsys):
    low = ["0", "0", "0.1", "0", "0", "0"]
    code, out, err = _run(["ik", "--pose", *low], capsys)
    assert code == 3 and out == ""
    assert "shorter than the minimum length 0.19 m" in _one_error_line(err, "ik", "--pose: 1 of 1 pose(s) outside")
    code, _, err = _run(["ik", "--pose", "0", "0", "1e308", "0", "0", "0"], capsys)
    assert code == 3 and "out of numeric range" in _one_error_line(err, "ik", "--pose: ")
    below = ["0.0015", "-0.0005", "-0.278", "0", "0", "0"]
    code, _, err = _run(["id", "--pose", *below, "--vel", *"000000", "--acc", *"000000"], capsys)
    assert code == 3 and "the platform is not above the base" in err
    plat = stewart.Platform.preset("narayan2017")
    poses = np.array([plat.home_pose, [0, 0, 0.1, 0, 0, 0], plat.home_pose + [0, 0, 0, 0, np.pi / 2, 0]])
    np.savetxt(tmp_path / "poses.csv", poses, delimiter=",", header=",".join(POSE_NAMES), comments="")
    code, _, err = _run(["ik", "--input", str(tmp_path / "poses.csv"), "--on-unreachable", "warn",
                         "--csv", str(tmp_path / "L.csv")], capsys)
    assert code == 0 and err.startswith("stewart ik: warning: --input ") and "2 of 3 pose(s)" in err
    table = np.genfromtxt(tmp_path / "L.csv", delimiter=",", names=True)
    np.testing.assert_array_equal(table["reachable"], [1, 0, 0])
    np.testing.assert_allclose(table["L0"], stewart.leg_lengths(plat.params, poses)[:, 0], rtol=1e-11)
    assert (tmp_path / "L.csv").read_text().splitlines()[1] == "# platform narayan2017 (preset)"


POSE_NAMES = ["x", "y", "z", "psi", "theta", "phi"]


@pytest.mark.parametrize("text, where", [
    ("", "no data rows"),
    ("# only a comment\n", "no data rows"),
    ("x,y,z,psi,theta,phi\n", "no data rows"),
    ("0,0,0.28,0,0,0\n0,0,0.28,0\n", "line 2: 4 column(s) where earlier lines have 6"),
    ("0;0;0.28;0;0;0\n", "line 1: values separated by semicolons; expected commas"),
    ("0\t0\t0.28\t0\t0\t0\n", "line 1: values separated by tabs"),
    ("0,0,0.28,0,0,0\n0,0,abc,0,0,0\n", "line 2, column 3: 'abc' is not a number"),
    ("0,0,0.28,0,0,nan\n", "line 1, column 6: 'nan' is not a finite number"),
    ("0,0," + "9" * 200_000 + ",0,0,0\n", "line 1, column 3: '999"),
    ("0,0,\"" + "1" * 200_000 + "\",0,0,0\n", "line 1, column 3: '\"111"),
    ("0,0,0.28,0,0\n", "line 1: 5 column(s); expected 6"),
    ("a,b\n0,1\n", "line 1: the header has 2 column(s) and lacks"),
])
def test_bad_csv_files_give_one_line_naming_file_line_and_column(tmp_path, capsys, text, where):
    path = tmp_path / "in.csv"
    path.write_text(text)
    code, _, err = _run(["ik", "--input", str(path)], capsys)
    assert code == 2
    assert where in _one_error_line(err, "ik", f"--input {path}: ")
    traj = tmp_path / "traj.csv"
    traj.write_text(text.replace("0,0,0.28", "0,0,0,0.28"))
    code, _, err = _run(["simulate", "--trajectory", str(traj)], capsys)
    assert code == 2 and _one_error_line(err, "simulate", f"--trajectory {traj}: ")


def test_a_simulation_csv_reads_back_as_a_trajectory(tmp_path, capsys):
    target = ["0.01", "0", "0.27", "0", "0.05", "0"]
    code, _, _ = _run(["simulate", "--target", *target, "--move-time", "1", "--csv", str(tmp_path / "run.csv")], capsys)
    assert code == 0
    code, out, _ = _run(["simulate", "--trajectory", str(tmp_path / "run.csv"), "--controller", "ct",
                         "--csv", str(tmp_path / "again.csv")], capsys)
    assert code == 0 and "outcome: completed" in out
    first = np.genfromtxt(tmp_path / "run.csv", delimiter=",", names=True)
    again = np.genfromtxt(tmp_path / "again.csv", delimiter=",", names=True)
    # reached 0: the reference's knots are the first file's samples, printed again to its 10 digits
    np.testing.assert_allclose(again["z_ref"], first["z"], rtol=0, atol=1e-12)


@pytest.mark.parametrize("argv, flag", [
    (["ik", "--input", "x.csv", "--pose", *"000000"], "--input cannot be combined with --pose"),
    (["id", "--input", "x.csv", "--acc", *"000000"], "--input cannot be combined with --acc"),
    (["simulate", "--target", *"000000", "--trajectory", "t.csv"], "argument --trajectory: not allowed with"),
    (["ik", "--pose", "0", "0", "0.25"], "argument --pose: expected 6 arguments"),
    (["bench", "--batch", "0"], "argument --batch: must be at least 1, got 0"),
    (["validate", "--states", "0"], "argument --states: must be at least 1, got 0"),
    (["validate", "--states", "-5"], "argument --states: must be at least 1, got -5"),
    (["simulate", "--target", *ISSUE_TARGET, "--dt", "0"], "argument --dt: must be > 0"),
    (["simulate", "--target", *ISSUE_TARGET, "--force-limit", "nan"], "argument --force-limit: must be > 0"),
    (["simulate", "--target", *ISSUE_TARGET, "--acc", "1"], "unrecognized arguments: --acc"),
])
def test_usage_errors_exit_2_naming_the_flag(capsys, argv, flag):
    code, out, err = _run(argv, capsys)
    assert code == 2 and out == ""
    assert err.startswith("usage: ") and flag in err.strip().splitlines()[-1]


def test_params_file_errors(tmp_path, capsys):
    pose = ["--pose", "0", "0", "0.28", "0", "0", "0"]
    code, _, err = _run(["ik", "--params", str(tmp_path / "missing.toml"), *pose], capsys)
    assert code == 2 and "no such file" in _one_error_line(err, "ik", f"--params {tmp_path / 'missing.toml'}: ")
    code, _, err = _run(["ik", "--params", str(tmp_path), *pose], capsys)
    assert code == 2 and "is a directory" in _one_error_line(err, "ik", f"--params {tmp_path}: ")
    (tmp_path / "bad.toml").write_text("platform_mass = [\n")
    code, _, err = _run(["ik", "--params", str(tmp_path / "bad.toml"), *pose], capsys)
    assert code == 2 and _one_error_line(err, "ik", f"--params {tmp_path / 'bad.toml'}: ")


def test_output_paths_and_matplotlib_are_checked_before_the_run(tmp_path, capsys, monkeypatch):
    def no_run(*args, **kwargs):
        raise AssertionError("the run started")

    monkeypatch.setattr("stewart.cli.motion.simulate", no_run)
    target = ["--target", "0.01", "0", "0.27", "0", "0", "0"]
    code, _, err = _run(["simulate", *target, "--csv", str(tmp_path / "nowhere" / "run.csv")], capsys)
    assert code == 2 and "does not exist" in _one_error_line(err, "simulate", "--csv ")
    code, _, err = _run(["simulate", *target, "--npz", str(tmp_path)], capsys)
    assert code == 2 and "is a directory" in _one_error_line(err, "simulate", "--npz ")
    (tmp_path / "file").write_text("")
    code, _, err = _run(["simulate", *target, "--plot", str(tmp_path / "file")], capsys)
    assert code == 2 and "is not a directory" in _one_error_line(err, "simulate", "--plot ")
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    code, _, err = _run(["simulate", *target, "--plot", str(tmp_path / "figs")], capsys)
    assert code == 2 and "needs matplotlib" in _one_error_line(err, "simulate", "--plot: ")


def test_ctrl_c_saves_what_was_computed_and_exits_130(tmp_path, capsys, monkeypatch):
    press_ctrl_c_after(monkeypatch, 0.0)
    code, out, err = _run(["simulate", "--target", "0.01", "0", "0.27", "0", "0", "0", "--move-time", "10",
                           "--csv", str(tmp_path / "run.csv")], capsys)
    assert code == 130 and out == ""
    assert err.strip() == f"stewart simulate: interrupted at t = 2.0000 s; saved {tmp_path / 'run.csv'}"
    table = np.genfromtxt(tmp_path / "run.csv", delimiter=",", names=True)
    assert table["t"][-1] == pytest.approx(2.0, rel=1e-10, abs=0) and "outcome interrupted" in (tmp_path / "run.csv").read_text()


def test_version_help_and_exit_codes(capsys):
    code, out, _ = _run(["--version"], capsys)
    info = stewart.build_info()
    assert code == 0 and out.strip() == f"stewart {stewart.__version__} ({info['simd']} path, {info['compiler']})"
    code, out, _ = _run(["--help"], capsys)
    assert code == 0 and "exit codes:" in out and "130  interrupted" in out
    code, out, _ = _run(["simulate", "--help"], capsys)
    assert "(default: 0.001)" in out and "(default: 5.0)" in out and "(default: narayan2017)" in out
    assert "6    the commanded actuator force exceeded --force-limit" in out


def test_info_shows_the_build(capsys):
    code, out, _ = _run(["info"], capsys)
    info = stewart.build_info()
    assert code == 0 and f"simd path     {info['simd']} (compiled: {', '.join(info['compiled'])};" in out
    assert all(f"flags         {name}: {flags}" in out for name, flags in info["flags"].items())
    assert f"threads       {info['threads']}" in out


def test_json_summaries(capsys):
    code, out, err = _run(["simulate", "--target", *ISSUE_TARGET[:2], "0.27", "0", "0", "0", "--json",
                           "--tolerance", "1e-12", "1e-12"], capsys)
    summary = json.loads(out)
    assert code == 5 and summary["exit_code"] == 5 and summary["outcome"] == "inaccurate" and not summary["ok"]
    assert summary["platform"] == "narayan2017" and summary["controller"] == "PID" and summary["problems"]
    code, out, err = _run(["simulate", "--target", *ISSUE_TARGET, "--json"], capsys)
    summary = json.loads(out)
    assert code == 3 and summary["exit_code"] == 3 and summary["outcome"] == "outside_workspace"
    # The spherical joints leave their 30 deg cone (the preset's) at 2.016 s, before the singularity
    # at 3.9 s: the first reference sample (every --dt, 1 ms) past the crossing is named.
    crossing = spherical_cone_crossing(stewart.PlatformParams.preset("narayan2017"), [float(v) for v in ISSUE_TARGET])
    assert summary["problems"][0] in err and crossing < summary["times"][0] <= crossing + 1e-3
    code, out, _ = _run(["validate", "--preset", "motion_simulator", "--states", "20", "--json"], capsys)
    summary = json.loads(out)
    assert code == 0 and summary["passed"] and len(summary["checks"]) == 20
    assert all(c["worst"] <= c["bound"] for c in summary["checks"])
    code, out, _ = _run(["exactness", "--preset", "motion_simulator", "--states", "20", "--seed", "2", "--json"], capsys)
    summary = json.loads(out)
    effect = exactness.leg_spin_effect(stewart.PlatformParams.preset("motion_simulator"), 20, 2)
    assert code == 0 and summary["assumed_axes"] and summary["states"] == 20
    assert summary["dynamic"] == effect.dynamic._asdict() and summary["velocity"] == effect.velocity._asdict()


# ---------------------------------------------------------------- fuzzing the command line


_VALUES = st.sampled_from(["0", "-1", "nan", "inf", "-inf", "1e308", "5e-324", "abc", "", "0.001", "0.02", "0.27",
                           "1", "2", "--", "-", "1e400", "0x10", "pid", "ct", "rk4", "adaptive", "quintic"])
_FLAGS = st.sampled_from(["--pose", "--vel", "--acc", "--force", "--target", "--dt", "--duration", "--move-time",
                          "--controller", "--method", "--bandwidth", "--tolerance", "--force-limit", "--viscous",
                          "--coulomb", "--profile", "--preset", "--params", "--input", "--trajectory",
                          "--on-unreachable", "--max-steps", "--json", "--states", "--batch", "--seed", "--bogus"])
_FRAGMENTS = st.lists(st.one_of(_FLAGS, _VALUES), max_size=14)
EXIT_CODES = {0, 1, 2, 3, 4, 5, 6, 130}


def _exit_code(argv, capsys):
    code, out, err = _run(argv, capsys)
    assert code in EXIT_CODES, (argv, code, err)
    if code:
        last = err.strip().splitlines()[-1] if err.strip() else ""
        assert last.startswith(("stewart", "usage")) or code in (4, 5, 6), (argv, err)
    return code, out, err


_GOOD = {
    # command: flags with values that work (the fuzz test corrupts some of them)
    "ik": {"--pose": ["0.01", "0", "0.27", "0", "0.05", "0"], "--on-unreachable": ["warn"]},
    "id": {"--pose": ["0", "0", "0.27", "0", "0", "0"], "--vel": ["0"] * 6, "--acc": ["0", "0", "1", "0", "0", "0"]},
    "fd": {"--pose": ["0", "0", "0.27", "0", "0", "0"], "--vel": ["0"] * 6, "--force": ["20"] * 6},
    "simulate": {"--target": ["0.01", "0", "0.27", "0", "0.05", "0"], "--duration": ["0.05"], "--dt": ["0.002"],
                 "--controller": ["ct"], "--method": ["adaptive"], "--tolerance": ["0.001", "0.01"],
                 "--force-limit": ["30"], "--move-time": ["1"], "--max-steps": ["300"], "--json": []},
}


@st.composite
def _argv(draw):
    command = draw(st.sampled_from(sorted(_GOOD) + ["presets", "validate", "bench", "nonsense"]))
    argv = [command]
    for flag, values in _GOOD.get(command, {}).items():
        if draw(st.integers(0, 3)) == 0:
            continue  # leave the flag out
        argv.append(flag)
        argv += [draw(_VALUES) if draw(st.integers(0, 9)) == 0 else v for v in values]
    return argv + draw(st.lists(st.one_of(_FLAGS, _VALUES), max_size=draw(st.sampled_from([0, 0, 3, 8]))))


@settings(max_examples=80, deadline=20_000, suppress_health_check=[HealthCheck.too_slow,
                                                                    HealthCheck.function_scoped_fixture])
@given(argv=_argv())
def test_fuzz_argv(capsys, argv):
    """Random flags and values: an exit code from the documented set, no traceback, and
    for a value error a message naming a flag."""
    if argv[0] in ("validate", "bench"):
        argv += ["--states" if argv[0] == "validate" else "--batch", "0"]  # only their argument checks: fast
    if argv[0] == "simulate":
        argv += ["--no-progress"] + (["--max-steps", "300"] if "adaptive" in argv else [])
    code, out, err = _exit_code(argv, capsys)
    event(f"exit {code}")
    if code == 2 and not err.startswith("usage"):
        message = err.strip().splitlines()[-1].split("error: ", 1)[1]
        assert message.startswith("--") or message.startswith("give --"), message


@settings(max_examples=40, deadline=10_000, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=st.one_of(
    st.text(alphabet=st.sampled_from("0123456789.,;-e\t #\nabxyz\"'"), max_size=300),
    st.lists(st.lists(st.sampled_from(["0", "0.28", "1e-3", "nan", "x", "", "1e999", "-0.5"]), min_size=1,
                      max_size=8), max_size=6).map(lambda rows: "\n".join(",".join(r) for r in rows)),
))
def test_fuzz_csv_files(tmp_path_factory, capsys, text):
    path = tmp_path_factory.mktemp("csv") / "in.csv"
    path.write_text(text)
    code, _, err = _exit_code(["ik", "--input", str(path), "--on-unreachable", "warn"], capsys)
    assert code in (0, 2)
    if code:
        assert _one_error_line(err, "ik", f"--input {path}: ")
    code, _, err = _exit_code(["simulate", "--trajectory", str(path), "--duration", "0.01", "--no-progress"], capsys)
    if code == 2:
        assert _one_error_line(err, "simulate", f"--trajectory {path}: ")


@settings(max_examples=40, deadline=10_000, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=st.one_of(
    st.text(max_size=200),
    st.sampled_from(["[" * 5000, "a = " + "[" * 3000 + "]" * 3000, "{" * 3000, '{"platform_mass": 1e999}',
                     "platform_mass = 1e999", "name = 5", "base_points = [[0, 0, 0]]", "platform_mass = -1"]),
), suffix=st.sampled_from([".toml", ".json", ".txt", ""]))
def test_fuzz_parameter_files(tmp_path_factory, capsys, text, suffix):
    path = tmp_path_factory.mktemp("params") / f"p{suffix}"
    path.write_text(text)
    code, _, err = _exit_code(["ik", "--params", str(path), "--pose", "0", "0", "0.28", "0", "0", "0"], capsys)
    assert code == 2
    assert _one_error_line(err, "ik", f"--params {path}: ")


def test_input_columns_are_picked_by_header_name(tmp_path, capsys):
    plat = stewart.Platform.preset("narayan2017")
    x = plat.home_pose + [0.01, 0, 0, 0, 0.02, 0]
    xd, xdd = np.array([0, 0, 0.1, 0, 0, 0.2]), np.array([1, 0, 0, 0, -1, 0])
    names = POSE_NAMES + [f"{p}_dot" for p in POSE_NAMES] + [f"{p}_ddot" for p in POSE_NAMES]
    order = np.random.default_rng(1).permutation(18)
    row = np.concatenate([x, xd, xdd])
    (tmp_path / "in.csv").write_text("# shuffled columns\n" + ",".join(np.array(names + ["note"])[list(order) + [18]])
                                     + "\n" + ",".join(f"{v:.17g}" for v in row[order]) + ",7\n")
    code, out, _ = _run(["id", "--input", str(tmp_path / "in.csv")], capsys)
    assert code == 0
    np.testing.assert_allclose(_numbers(out)[0], stewart.oracles.reference.inverse_dynamics(plat.params, x, xd, xdd),
                               rtol=1e-9)


def test_a_binary_file_is_not_read_as_csv(tmp_path, capsys):
    path = tmp_path / "data.npz"
    np.savez(path, x=np.arange(10.0))
    code, _, err = _run(["ik", "--input", str(path)], capsys)
    assert code == 2 and "not a text file" in _one_error_line(err, "ik", f"--input {path}: ")


def test_c_export_writes_the_model_and_the_platform_header(tmp_path, capsys):
    params = stewart.PlatformParams.preset("motion_simulator").replace(name="exported")
    params.save(tmp_path / "p.toml")
    code, out, _ = _run(["c-export", str(tmp_path / "c"), "--params", str(tmp_path / "p.toml")], capsys)
    assert code == 0 and "exported" in out
    sources = [pathlib.Path(path) for path in stewart.c_sources()]
    for source in [pathlib.Path(stewart.c_include_dir()) / "stewart_model.h"] + sources:
        assert (tmp_path / "c" / source.name).read_bytes() == source.read_bytes()
    assert (tmp_path / "c" / "stewart_platform_params.h").read_text() == stewart.io.capi.params_header(params)
    (tmp_path / "file").write_text("")
    code, _, err = _run(["c-export", str(tmp_path / "file")], capsys)
    assert code == 2 and "not a directory" in _one_error_line(err, "c-export", f"DIR {tmp_path / 'file'}: ")
    code, _, err = _run(["c-export", str(tmp_path / "file" / "sub")], capsys)
    assert code == 2 and _one_error_line(err, "c-export", f"DIR {tmp_path / 'file' / 'sub'}: ")


def test_bench_ratios_only_times_the_derivatives_against_the_values(capsys):
    """``stewart bench --ratios-only``: only the exact derivatives' cost over the values', a
    state each, on each vector path this CPU runs, each row with its target and verdict. The
    derivative functions compute the values too, so each ratio's median is above 1 (a round
    the machine's other jobs interrupt may not be: the interval's ends are not checked)."""
    code, out, err = _run(["bench", "--ratios-only", "--preset", "narayan2017", "--budget", "0", "--json"], capsys)
    assert code == 0
    figures = json.loads(out)["figures"]["narayan2017"]
    paths = [path for path in ("avx2", "avx512") if path in stewart.build_info()["supported"]]
    keys = {f"derivative_ratio_{name}_{path}" for name in ("inverse_dynamics", "forward_dynamics") for path in paths}
    assert set(figures) == keys | {"spread"}
    for key in keys:
        spread = figures["spread"][key]
        assert spread["low"] <= figures[key] <= spread["high"] and 1 < figures[key] < 50
        name, path = key.removeprefix("derivative_ratio_").rsplit("_", 1)
        row = next(line for line in err.splitlines() if line.startswith("[narayan2017]") and f"over {name}" in line
                   and line.split(",")[-1].split()[0] == path)
        assert f"{figures[key]:.2f}x" in row and "<= 5x" in row and row.split()[-1] in ("met", "MISSED", "unsettled")
