"""Motor sizing of rotary rigs (stewart.studies.motor_sizing, ``stewart motor-sizing``), the servo
controller's angles (``stewart servo-angles``) and forward kinematics from crank angles
(``stewart fk``): the figures against the independent model of tests/rotary_oracle.py sample
by sample, RMS by its definition, the reference layouts against motions whose derivatives are
known exactly, and every flag's bad input."""

import json

import numpy as np
import pytest

import stewart
import rotary_oracle as oracle
from stewart.io import csvfile
from stewart.studies.motor_sizing import LAYOUTS, motor_sizing, read_reference
from test_rotary import random_rig

from cli_run import call

RATE = 60.0
POSE = ["x", "y", "z", "psi", "theta", "phi"]
REFERENCE = LAYOUTS["reference"]


def _motion(rig, n=240, seed=0):
    """(t, x, xd, xdd): sines about the rig's home at RATE Hz, each axis its own frequency and
    phase, exact derivatives."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / RATE
    w = rng.uniform(2.0, 9.0, 6)
    phase = rng.uniform(0, 2 * np.pi, 6)
    amp = np.array([0.012, 0.012, 0.012, 0.04, 0.04, 0.04])
    arg = w * t[:, None] + phase
    home = stewart.RotaryPlatform(rig).home
    return t, home + amp * np.sin(arg), amp * w * np.cos(arg), -amp * w ** 2 * np.sin(arg)


RIG = random_rig(7)
T, X, XD, XDD = _motion(RIG)
TAU = np.array([oracle.torques(RIG, *s) for s in zip(X, XD, XDD)])
SPEED = np.array([oracle.crank_rates(RIG, x, xd) for x, xd in zip(X, XD)])
ALPHA = np.array([oracle.crank_angles(RIG, x) for x in X])


def _close(a, b, rtol=1e-12):
    np.testing.assert_allclose(a, b, rtol=rtol, atol=rtol * np.max(np.abs(b)))


def test_peaks_rms_and_samples_against_the_oracle():
    result = motor_sizing(RIG, X, XD, XDD, t=T)
    m = result.motors
    _close(result.torques, TAU)
    _close(result.speeds, SPEED)
    _close(result.angles, ALPHA)
    np.testing.assert_array_equal(m["peak_torque_sample"], np.argmax(np.abs(TAU), axis=0))
    np.testing.assert_array_equal(m["peak_speed_sample"], np.argmax(np.abs(SPEED), axis=0))
    np.testing.assert_array_equal(m["peak_power_sample"], np.argmax(np.abs(TAU * SPEED), axis=0))
    _close(m["peak_torque"], np.max(np.abs(TAU), axis=0))
    _close(m["peak_speed"], np.max(np.abs(SPEED), axis=0))
    _close(m["peak_power"], np.max(np.abs(TAU * SPEED), axis=0))
    _close(m["angle_min"], ALPHA.min(axis=0))
    _close(m["angle_max"], ALPHA.max(axis=0))
    # RMS over time: sqrt of the time-average of tau^2, the average by the trapezoidal rule
    dt = np.diff(T)[:, None]
    mean_square = np.sum(dt * (TAU[1:] ** 2 + TAU[:-1] ** 2) / 2, axis=0) / (T[-1] - T[0])
    _close(m["rms_torque"], np.sqrt(mean_square))
    report = result.to_dict()
    for k, motor in enumerate(report["motors"]):
        sample = int(np.argmax(np.abs(TAU[:, k])))
        assert motor["peak_torque_sample"] == sample and motor["peak_torque_time"] == T[sample]


def test_states_without_times_take_the_mean_over_the_samples():
    result = motor_sizing(RIG, X, XD, XDD)
    _close(result.motors["rms_torque"], np.sqrt(np.mean(TAU ** 2, axis=0)))
    assert result.to_dict()["motors"][0]["peak_torque_time"] is None and result.to_dict()["duration"] is None


def test_headroom_signs_and_the_problems_named():
    peak_torque = np.max(np.abs(TAU), axis=0)
    peak_speed = np.max(np.abs(SPEED), axis=0)
    roomy = RIG.replace(motor_torque_limit=1.25 * peak_torque, motor_speed_limit=2.0 * peak_speed,
                        crank_angle_limits=(ALPHA.min() - 0.1, ALPHA.max() + 0.2))
    result = motor_sizing(roomy, X, XD, XDD, t=T)
    _close(result.motors["torque_headroom"], np.full(6, 0.2))
    _close(result.motors["speed_headroom"], np.full(6, 0.5))
    _close(result.motors["angle_headroom"], np.minimum(ALPHA.min(axis=0) - ALPHA.min() + 0.1,
                                                       ALPHA.max() + 0.2 - ALPHA.max(axis=0)))
    assert result.within_limits and result.problems == []
    limit = peak_torque.copy()
    limit[4] *= 0.9
    tight = roomy.replace(motor_torque_limit=limit, crank_angle_limits=(ALPHA.min() + 1e-3, np.pi))
    result = motor_sizing(tight, X, XD, XDD, t=T)
    assert result.motors["torque_headroom"][4] == pytest.approx(1 - 1 / 0.9, rel=1e-12)
    assert np.all(result.motors["torque_headroom"][[0, 1, 2, 3, 5]] >= 0)
    assert not result.within_limits
    problems = result.problems
    assert sum(p.startswith("motor 4: peak torque") for p in problems) == 1
    assert all(not p.startswith(f"motor {k}:") for k in (0, 1, 2, 3, 5) for p in problems)
    crank = int(np.argmin(ALPHA.min(axis=0)))
    assert any(p.startswith(f"crank {crank}: angles") for p in problems)
    sample = int(np.argmax(np.abs(TAU[:, 4])))
    assert f"sample {sample} (t = {T[sample]:.6g} s)" in problems[0]


def test_gear_ratio_scales_torque_and_speed_at_the_motor():
    base = motor_sizing(RIG, X, XD, XDD, t=T).to_dict()
    geared = motor_sizing(RIG, X, XD, XDD, t=T, gear_ratio=35.0).to_dict()
    for a, b in zip(base["motors"], geared["motors"]):
        assert b["at_motor"]["peak_torque"] == pytest.approx(a["peak_torque"] / 35.0, rel=1e-15)
        assert b["at_motor"]["rms_torque"] == pytest.approx(a["rms_torque"] / 35.0, rel=1e-15)
        assert b["at_motor"]["peak_speed"] == pytest.approx(a["peak_speed"] * 35.0, rel=1e-15)
        assert b["peak_torque"] == a["peak_torque"] and b["torque_headroom"] == a["torque_headroom"]
    assert geared["gear_ratio"] == 35.0


def test_unreachable_poses_are_left_out_and_named():
    x = X.copy()
    x[[3, 50], 2] += 1.0  # out of every crank's reach
    result = motor_sizing(RIG, x, XD, XDD, t=T)
    keep = np.ones(len(T), bool)
    keep[[3, 50]] = False
    assert result.reachable.tolist() == keep.tolist()
    _close(result.motors["peak_torque"], np.max(np.abs(TAU[keep]), axis=0))
    assert result.problems[0] == "2 pose(s) out of the cranks' reach at sample(s) [3, 50]"
    with pytest.raises(ValueError, match="no pose of the reference is in the cranks' reach"):
        motor_sizing(RIG, X + [0, 0, 1, 0, 0, 0], XD, XDD)


@pytest.mark.parametrize("kwargs, match", [
    ({"gear_ratio": 0.0}, "gear_ratio: must be a positive"),
    ({"gear_ratio": np.inf}, "gear_ratio: must be finite"),
    ({"gear_ratio": "x"}, "gear_ratio"),
    ({"t": np.arange(5.0)}, "t: expected 240 times"),
    ({"t": T[::-1]}, "t: the times must increase strictly"),
    ({"t": np.where(T == T[3], np.nan, T)}, "t: contains NaN"),
    ({"xd": XD[:10]}, "xd"),
    ({"x": np.where(X == X[2, 2], np.nan, X)}, "x: row 2 contains NaN"),
    ({"rig": stewart.PlatformParams.preset("narayan2017")}, "rig"),
])
def test_bad_arguments_are_named(kwargs, match):
    args = {"rig": RIG, "x": X, "xd": XD, "xdd": XDD, "t": T, **kwargs}
    with pytest.raises((ValueError, TypeError), match=match):
        motor_sizing(args.pop("rig"), args.pop("x"), args.pop("xd"), args.pop("xdd"), **args)


# ---------------------------------------------------------------------------- reference files

def _smoothstep(n=61):
    """A rest-to-rest move x(s) = x0 + d (3 s^2 - 2 s^3), s = t / 1 s: cubic, so that the
    clamped spline through its poses and the Hermite spline through poses and rates are the
    motion itself."""
    t = np.linspace(0.0, 1.0, n)
    d = np.array([0.01, -0.008, 0.012, 0.03, -0.02, 0.025])
    rig = stewart.RotaryPlatform.preset("simrig100")
    s = t[:, None]
    return t, rig.home + d * (3 * s ** 2 - 2 * s ** 3), d * (6 * s - 6 * s ** 2), d * (6 - 12 * s)


@pytest.mark.parametrize("layout", list(LAYOUTS))
@pytest.mark.parametrize("header", [True, False])
def test_every_layout_reads_the_motion(tmp_path, layout, header):
    t, x, xd, xdd = _smoothstep()
    columns = {"t": t[:, None], "pose": x, "rates": xd, "accelerations": xdd}
    parts = {"reference": ["t", "pose", "rates", "accelerations"], "poses and rates": ["t", "pose", "rates"],
             "poses": ["t", "pose"], "states": ["pose", "rates", "accelerations"]}[layout]
    rows = np.column_stack([columns[p] for p in parts])
    path = tmp_path / "ref.csv"
    if header:
        order = np.random.default_rng(2).permutation(len(LAYOUTS[layout]))  # columns picked by name
        csvfile.write(path, [LAYOUTS[layout][i] for i in order], rows[:, order], "test", fmt="%.17g")
    else:
        np.savetxt(path, rows, delimiter=",", fmt="%.17g")
    ref = read_reference(path)
    assert ref.layout == layout
    assert (ref.t is None) == (layout == "states")
    if ref.t is not None:
        np.testing.assert_array_equal(ref.t, t)
    np.testing.assert_array_equal(ref.x, x)
    np.testing.assert_allclose(ref.xd, xd, rtol=0, atol=1e-13)
    np.testing.assert_allclose(ref.xdd, xdd, rtol=0, atol=1e-11)


def test_times_that_do_not_increase_are_refused(tmp_path):
    t, x, _, _ = _smoothstep()
    t[10] = t[9]
    csvfile.write(tmp_path / "r.csv", ["t", *POSE], np.column_stack([t, x]), "test")
    with pytest.raises(ValueError, match=r"r\.csv: t: the times must increase strictly \(data row 11"):
        read_reference(tmp_path / "r.csv")


# ---------------------------------------------------------------------------- the command line

@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """The motion on RIG as a cueing reference, RIG's file, and a linear platform's file."""
    d = tmp_path_factory.mktemp("sizing")
    csvfile.write(d / "ref.csv", list(REFERENCE), np.column_stack([T, X, XD, XDD]), "test", fmt="%.17g")
    RIG.replace(name="random7").save(d / "rig.toml")
    stewart.PlatformParams.preset("narayan2017").save(d / "linear.toml")
    return d


def _one_line(result, command, start, code=2):
    assert result.returncode == code, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"stewart {command}: error: {start}"), lines[0]
    return lines[0]


def test_motor_sizing_command_report_and_plot(files, tmp_path):
    pytest.importorskip("matplotlib")
    result = call("motor-sizing", files / "ref.csv", "--params", files / "rig.toml", "--gear-ratio", "20",
                  "--report", tmp_path / "report.json", "--plot", tmp_path / "figs")
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["rig"] == "random7" and report["samples"] == len(T) and report["gear_ratio"] == 20.0
    assert report["within_limits"] is True and report["problems"] == []
    assert report["units"]["peak_torque"] == "N m" and report["units"]["peak_speed"] == "rad/s"
    for k, motor in enumerate(report["motors"]):
        assert {"peak_torque", "rms_torque", "peak_speed", "peak_torque_sample", "peak_torque_time",
                "peak_speed_sample", "peak_speed_time", "torque_headroom", "speed_headroom", "angle_headroom",
                "at_motor"} <= set(motor)
        assert motor["peak_torque"] == pytest.approx(np.max(np.abs(TAU[:, k])), rel=1e-12)
        assert motor["peak_speed"] == pytest.approx(np.max(np.abs(SPEED[:, k])), rel=1e-12)
        assert motor["at_motor"]["peak_torque"] == pytest.approx(motor["peak_torque"] / 20, rel=1e-15)
    png = tmp_path / "figs" / "motor_sizing_torque_speed.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    lines = result.stdout.splitlines()
    row = lines[2].split()  # motor 0 of the crank table
    assert float(row[1]) == pytest.approx(np.max(np.abs(TAU[:, 0])), rel=1e-5)
    assert int(row[2]) == int(np.argmax(np.abs(TAU[:, 0])))
    assert f"written: {tmp_path / 'report.json'}" in lines and f"written: {png}" in lines


def test_motor_sizing_past_a_limit_exits_3_naming_the_motor(files, tmp_path):
    limit = np.max(np.abs(TAU), axis=0) * [1.1, 1.1, 0.95, 1.1, 1.1, 1.1]
    RIG.replace(motor_torque_limit=limit).save(tmp_path / "tight.toml")
    result = call("motor-sizing", files / "ref.csv", "--params", tmp_path / "tight.toml", "--report",
                  tmp_path / "r.json")
    assert result.returncode == 3
    assert result.stderr.strip().splitlines() == [line for line in result.stderr.strip().splitlines()
                                                  if line.startswith("stewart motor-sizing: motor 2: peak torque")]
    assert json.loads((tmp_path / "r.json").read_text())["within_limits"] is False  # written all the same


def test_motor_sizing_of_a_preset_on_a_cueing_reference(tmp_path):
    t, x, xd, xdd = _smoothstep()
    csvfile.write(tmp_path / "ref.csv", list(REFERENCE), np.column_stack([t, x, xd, xdd]), "test", fmt="%.17g")
    result = call("motor-sizing", tmp_path / "ref.csv", "--preset", "simrig100", "--report", tmp_path / "r.json")
    assert result.returncode == 0, result.stderr
    expected = np.array([oracle.torques(stewart.RotaryParams.preset("simrig100"), *s) for s in zip(x, xd, xdd)])
    got = [m["peak_torque"] for m in json.loads((tmp_path / "r.json").read_text())["motors"]]
    np.testing.assert_allclose(got, np.max(np.abs(expected), axis=0), rtol=1e-12)


@pytest.mark.parametrize("command", ["motor-sizing", "servo-angles"])
def test_rotary_only_commands_refuse_linear_platforms(files, tmp_path, command):
    out = ["--output", tmp_path / "o.csv"] if command == "servo-angles" else []
    result = call(command, files / "ref.csv", "--params", files / "linear.toml", *out)
    _one_line(result, command, f"--params {files / 'linear.toml'}: a linear platform's parameter file; "
              f"stewart {command} serves rotary rigs only")
    result = call(command, files / "ref.csv", "--preset", "narayan2017", *out)
    _one_line(result, command, "--preset narayan2017: a linear platform; "
              f"stewart {command} serves rotary rigs only")
    assert result.stdout == ""


def test_motor_sizing_bad_input(files, tmp_path):
    ref, rig = files / "ref.csv", ["--params", files / "rig.toml"]
    for value in ("0", "-2", "abc", "nan"):
        result = call("motor-sizing", ref, *rig, "--gear-ratio", value)
        assert result.returncode == 2 and "argument --gear-ratio" in result.stderr and "Traceback" not in result.stderr
    _one_line(call("motor-sizing", tmp_path / "none.csv", *rig), "motor-sizing", f"{tmp_path / 'none.csv'}: no such file")
    (tmp_path / "bad.csv").write_text("t,x,y,z,psi,theta,phi\n0,0,0,0.4,0,0,abc\n")
    _one_line(call("motor-sizing", tmp_path / "bad.csv", *rig), "motor-sizing",
              f"{tmp_path / 'bad.csv'}: line 2, column 7: 'abc' is not a number")
    _one_line(call("motor-sizing", ref, *rig, "--report", tmp_path / "no" / "r.json"), "motor-sizing",
              f"--report {tmp_path / 'no' / 'r.json'}: the directory")
    (tmp_path / "file").write_text("")
    _one_line(call("motor-sizing", ref, *rig, "--plot", tmp_path / "file"), "motor-sizing",
              f"--plot {tmp_path / 'file'}: exists and is not a directory")
    _one_line(call("motor-sizing", ref, "--params", tmp_path / "none.toml"), "motor-sizing",
              f"--params {tmp_path / 'none.toml'}: no such file")
    t, x, xd, xdd = _smoothstep()
    csvfile.write(tmp_path / "far.csv", list(REFERENCE), np.column_stack([t, x + [0, 0, 2, 0, 0, 0], xd, xdd]), "t")
    _one_line(call("motor-sizing", tmp_path / "far.csv", "--preset", "simrig100"), "motor-sizing",
              f"{tmp_path / 'far.csv'}: no pose of the reference is in the cranks' reach", code=3)


# ---------------------------------------------------------------------------- servo-angles and fk

def test_servo_angles_round_trip_through_forward_kinematics(files, tmp_path):
    result = call("servo-angles", files / "ref.csv", "--params", files / "rig.toml", "--output", tmp_path / "s.csv")
    assert result.returncode == 0, result.stderr
    servo = csvfile.read(tmp_path / "s.csv", ["t", *(f"alpha_{i}" for i in range(6))])
    np.testing.assert_allclose(servo[:, 0], T, rtol=1e-11, atol=0)  # written with 12 digits
    np.testing.assert_allclose(servo[:, 1:], np.degrees(ALPHA), rtol=0, atol=1e-9)
    result = call("fk", "--params", files / "rig.toml", "--input", tmp_path / "s.csv", "--degrees",
                  "--csv", tmp_path / "poses.csv")
    assert result.returncode == 0, result.stderr
    back = csvfile.read(tmp_path / "poses.csv", ["t", *POSE])
    np.testing.assert_array_equal(back[:, 0], servo[:, 0])
    np.testing.assert_allclose(back[:, 1:], X, rtol=0, atol=1e-11)  # the file's 12 digits of degrees


def test_servo_angles_resampled_at_a_rate(tmp_path):
    t, x, xd, xdd = _smoothstep()
    csvfile.write(tmp_path / "ref.csv", list(REFERENCE), np.column_stack([t, x, xd, xdd]), "test", fmt="%.17g")
    result = call("servo-angles", tmp_path / "ref.csv", "--preset", "simrig100", "--rate", "250",
                  "--output", tmp_path / "s.csv")
    assert result.returncode == 0, result.stderr
    servo = csvfile.read(tmp_path / "s.csv", ["t", *(f"alpha_{i}" for i in range(6))])
    np.testing.assert_allclose(servo[:, 0], np.arange(251) / 250, rtol=0, atol=1e-15)
    s = servo[:, :1]  # the cubic move itself at the new times (the Hermite spline reproduces it)
    poses = x[0] + (x[-1] - x[0]) * (3 * s ** 2 - 2 * s ** 3)
    rig = stewart.RotaryParams.preset("simrig100")
    expected = np.degrees([oracle.crank_angles(rig, p) for p in poses])
    np.testing.assert_allclose(servo[:, 1:], expected, rtol=0, atol=1e-9)


def test_servo_angles_past_the_limits_write_nothing(files, tmp_path):
    RIG.replace(crank_angle_limits=(ALPHA.min() + 0.01, np.pi)).save(tmp_path / "tight.toml")
    result = call("servo-angles", files / "ref.csv", "--params", tmp_path / "tight.toml", "--output",
                  tmp_path / "s.csv")
    row = int(np.flatnonzero((ALPHA < ALPHA.min() + 0.01).any(axis=1))[0])
    crank = int(np.flatnonzero(ALPHA[row] < ALPHA.min() + 0.01)[0])
    line = _one_line(result, "servo-angles", f"{files / 'ref.csv'}: crank {crank} at "
                     f"{np.degrees(ALPHA[row, crank]):.4g} deg (t = {T[row]:.6g} s) passes crank_angle_limits", code=3)
    assert line.endswith("nothing written")
    assert not (tmp_path / "s.csv").exists()


def test_servo_angles_bad_input(files, tmp_path):
    rig = ["--params", files / "rig.toml"]
    for value in ("0", "-5", "x"):
        result = call("servo-angles", files / "ref.csv", *rig, "--rate", value, "--output", tmp_path / "s.csv")
        assert result.returncode == 2 and "argument --rate" in result.stderr
    result = call("servo-angles", files / "ref.csv", *rig)
    assert result.returncode == 2 and "--output" in result.stderr
    _one_line(call("servo-angles", files / "ref.csv", *rig, "--output", tmp_path), "servo-angles",
              f"--output {tmp_path}: is a directory")
    np.savetxt(tmp_path / "states.csv", np.column_stack([X, XD, XDD]), delimiter=",")
    _one_line(call("servo-angles", tmp_path / "states.csv", *rig, "--output", tmp_path / "s.csv"), "servo-angles",
              f"{tmp_path / 'states.csv'}: has no times")


def test_fk_from_angles_on_the_command_line(files):
    x = X[17]
    for angles, flag in ((ALPHA[17], []), (np.degrees(ALPHA[17]), ["--degrees"])):
        result = call("fk", "--params", files / "rig.toml", "--angles", *(f"{a:.17g}" for a in angles), *flag)
        assert result.returncode == 0, result.stderr
        lines = result.stdout.strip().splitlines()
        assert lines[0] == "# platform random7 (from %s)" % (files / "rig.toml") and lines[1].split() == POSE
        np.testing.assert_allclose([float(v) for v in lines[2].split()], x, rtol=0, atol=1e-9)  # 10 digits printed


def test_fk_bad_input(files, tmp_path):
    rig = ["--params", files / "rig.toml"]
    _one_line(call("fk", *rig), "fk", "give --angles or --input CSV")
    _one_line(call("fk", *rig, "--angles", *["0"] * 6, "--input", files / "ref.csv"), "fk",
              "--input cannot be combined with --angles")
    for bad in (["0"] * 5, ["0"] * 5 + ["nan"], ["0"] * 5 + ["x"]):
        result = call("fk", *rig, "--angles", *bad)
        assert result.returncode == 2 and "--angles" in result.stderr and "Traceback" not in result.stderr
    _one_line(call("fk", "--preset", "narayan2017", "--angles", *["0"] * 6), "fk",
              "--preset narayan2017: a linear platform; stewart fk serves rotary rigs only")
    _one_line(call("fk", *rig, "--angles", *["3"] * 6), "fk", "--angles: no pose with these crank angles", code=3)
    (tmp_path / "a.csv").write_text("alpha_0,alpha_1\n0,0\n")
    _one_line(call("fk", *rig, "--input", tmp_path / "a.csv"), "fk", f"--input {tmp_path / 'a.csv'}: line 1")
    _one_line(call("fk", *rig, "--angles", *["0"] * 6, "--csv", tmp_path / "no" / "p.csv"), "fk",
              f"--csv {tmp_path / 'no' / 'p.csv'}: the directory")


# ---------------------------------------------------------------------------- ik, id and fd

def test_ik_id_fd_serve_rotary_rigs(files, tmp_path):
    """Crank angles, motor torques and the accelerations under them, from a CSV, against the oracle."""
    rows = slice(0, 240, 37)
    names = POSE + [f"{p}_dot" for p in POSE] + [f"{p}_ddot" for p in POSE]
    csvfile.write(tmp_path / "s.csv", names, np.column_stack([X, XD, XDD])[rows], "test", fmt="%.17g")
    torque = np.column_stack([X, XD, TAU])[rows]
    csvfile.write(tmp_path / "f.csv", names[:12] + [f"tau{i}" for i in range(6)], torque, "test", fmt="%.17g")
    rig = ["--params", files / "rig.toml"]
    for command, path, columns, expected, tol in (
            ("ik", "s.csv", [f"alpha_{i}" for i in range(6)], ALPHA[rows], 1e-12),
            ("id", "s.csv", [f"tau{i}" for i in range(6)], TAU[rows], 1e-11 * np.max(np.abs(TAU))),
            ("fd", "f.csv", [f"{p}_ddot" for p in POSE], XDD[rows], 1e-10)):
        result = call(command, *rig, "--input", tmp_path / path, "--csv", tmp_path / f"{command}.csv")
        assert result.returncode == 0, result.stderr
        got = csvfile.read(tmp_path / f"{command}.csv", columns)
        np.testing.assert_allclose(got, expected, rtol=0, atol=tol, err_msg=command)
    far = ["--pose", "0", "0", "2", "0", "0", "0"]
    _one_line(call("ik", *rig, *far), "ik", "--pose: the model is undefined at row(s) [0]", code=3)
    result = call("ik", *rig, *far, "--on-unreachable", "warn")
    assert result.returncode == 0 and result.stdout.splitlines()[1].split()[-1] == "reachable"
    assert result.stdout.splitlines()[2].split()[-1] == "0"
