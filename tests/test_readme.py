"""The commands and examples of the README and of the documentation's pages run as written.

The pages are those of ``mkdocs.yml``'s ``nav``, read in its order after the README, as one
session:

* Every ``stewart ...`` line of their ``sh`` blocks runs through :func:`stewart.cli.main`, in
  order, in one temporary directory holding a copy of ``examples/`` (so a command may read
  what an earlier one wrote, as in a shell session), and exits with 0, or with the
  code its comment names ("exit code 3"). ``stewart bench`` runs with ``--batch 2000
  --preset narayan2017 --budget 0`` added (the full run takes minutes; every preset runs the
  same code, and each figure its least number of rounds); its JSON and its table are checked
  here, the one run of the command in the suite.
  The numbers every other command prints or writes are compared with the Python API run on
  the same inputs, within the precision they are printed with (:data:`OUTPUT_CHECKS`).
* Their ``python`` blocks run in order in one namespace (a page's examples continue the
  README's tour). A statement followed by a comment ``# SomeError: message`` must raise that
  error with that message (``...`` matches anything).
* The generated sample of ``stewart validate`` lists the checks that command runs today.
"""

from __future__ import annotations

import ast
import csv
import functools
import json
import math
import pathlib
import re
import shlex
import shutil

import numpy as np
import pytest
from cli_outputs import (
    POSE,
    assert_json_equal,
    assert_printed,
    check_calibration,
    check_calibration_poses,
    check_csv_columns,
    check_envelope_table,
    check_excitation_csv,
    check_modes_table,
    check_optimize_csv,
    check_sweep_table,
    check_workspace_json,
    line_after,
    numbers,
)

import stewart
from stewart import cli
from stewart.model.stiffness import MOTION_AXES

ROOT = pathlib.Path(__file__).resolve().parent.parent
if not (ROOT / "examples").is_dir() or not (ROOT / "mkdocs.yml").is_file():
    pytest.skip("needs the checkout (README.md, mkdocs.yml, docs/ and examples/)", allow_module_level=True)


def nav_pages() -> list[str]:
    """The pages of ``mkdocs.yml``'s ``nav`` (``- Title: page.md``), in its order, as paths."""
    nav = (ROOT / "mkdocs.yml").read_text().split("\nnav:", 1)[1]
    return [f"docs/{name}" for name in re.findall(r"^\s*- [^\n]*?:\s*(\S+\.md)\s*$", nav, re.M)]


#: The files whose commands and examples run, in order: the README, then the site's pages.
PAGES = ["README.md", *nav_pages()]
TEXTS = {name: (ROOT / name).read_text() for name in PAGES}


def blocks(language: str, pages=PAGES) -> list[tuple[str, str]]:
    """(page, block) of every ``language`` block of ``pages``, in order."""
    return [(page, block) for page in pages
            for block in re.findall(rf"^```{language}\n(.*?)^```", TEXTS[page], re.S | re.M)]


def commands() -> list[tuple[str, list[str], int]]:
    """(line, argv after ``stewart``, expected exit code) of every command of the pages."""
    out = []
    for _, block in blocks("sh"):
        for line in block.splitlines():
            words = shlex.split(line, comments=True)
            if words[:1] == ["stewart"]:
                argv = words[1:]
            elif words[:3] == ["python", "-m", "stewart"]:
                argv = words[3:]
            else:
                continue
            code = re.search(r"#.*\bexit (?:code|status) (\d+)", line)
            out.append((line.strip(), argv, int(code.group(1)) if code else 0))
    return out


COMMANDS = commands()


@pytest.fixture(scope="module")
def session_dir(tmp_path_factory):
    directory = tmp_path_factory.mktemp("readme-session")
    shutil.copytree(ROOT / "examples", directory / "examples")
    return directory


@pytest.fixture
def in_examples_dir(session_dir, monkeypatch):
    monkeypatch.chdir(session_dir)
    return session_dir


def run_cli(argv) -> int:
    try:
        code = cli.main(list(argv))
    except SystemExit as stop:
        code = stop.code
    return 0 if code is None else code if isinstance(code, int) else 1


def option(argv, flag, n=1):
    """The value(s) given to ``flag``, or None."""
    if flag not in argv:
        return None
    k = argv.index(flag)
    return argv[k + 1] if n == 1 else [float(v) for v in argv[k + 1:k + 1 + n]]


def numeric_rows(text: str) -> np.ndarray:
    """The printed lines made of numbers only, as rows."""
    rows = []
    for line in text.splitlines():
        try:
            rows.append([float(v) for v in line.split()])
        except ValueError:
            continue
    return np.array([r for r in rows if r])


# ------------------------------------------------------------------ the numbers of the commands
#
# Each command of the pages that prints or writes numbers has them compared with the Python API
# run here on the same inputs (the same seed, the defaults of the command's flags written out),
# by the checkers of tests/cli_outputs.py, within the precision they are printed with. A result
# two pages' commands share is computed once (functools.cache): the arguments are hashable
# (a parameter source, tuples of numbers).


def values(argv, flag) -> list[float] | None:
    """The numbers given to ``flag`` (one or more, up to the next flag), or None."""
    if flag not in argv:
        return None
    out = []
    for word in argv[argv.index(flag) + 1:]:
        if word.startswith("--"):
            break
        out.append(float(word))
    return out


def source(argv) -> tuple[str, str]:
    """The parameters a command names: ``("--params", FILE)`` or ``("--preset", NAME)``."""
    return ("--params", option(argv, "--params")) if option(argv, "--params") else \
        ("--preset", option(argv, "--preset") or "narayan2017")


def params_of(where: tuple[str, str]) -> stewart.PlatformParams:
    flag, name = where
    return stewart.PlatformParams.load(name) if flag == "--params" else stewart.PlatformParams.preset(name)


def check_kinematics(argv, out: str) -> None:
    """``ik``, ``id``, ``fd``: the printed (``%.10g``) or written (``--csv``, ``%.12g``) rows."""
    command = argv[0]
    flag, name = source(argv)
    rotary = name in stewart.model.rotary_presets.presets() if flag == "--preset" else \
        stewart.model.paramfile.read(name).get("kind") == "rotary"
    if rotary:  # a rotary rig: crank angles, motor torques, accelerations under them
        rig = stewart.RotaryPlatform(stewart.RotaryParams.preset(name) if flag == "--preset" else
                                     stewart.RotaryParams.load(name))
    else:
        plat = stewart.Platform(params_of((flag, name)))
    if option(argv, "--input"):
        data = np.loadtxt(option(argv, "--input"), delimiter=",", comments="#", ndmin=2)
    else:
        extra = {"ik": [], "id": ["--vel", "--acc"], "fd": ["--vel", "--force"]}[command]
        data = np.atleast_2d(np.concatenate([option(argv, f, 6) for f in ["--pose", *extra]]))
    if rotary:
        method = {"ik": rig.crank_angles, "id": rig.inverse_dynamics, "fd": rig.forward_dynamics}[command]
        expected = method(data[:, :6]) if command == "ik" else method(data[:, :6], data[:, 6:12], data[:, 12:])
    elif command == "ik":  # the encoder readings: leg lengths less the offsets
        expected = plat.leg_lengths(data) - plat.params.leg_length_offsets
    elif command == "id":
        expected = plat.inverse_dynamics(data[:, :6], data[:, 6:12], data[:, 12:])
    else:
        expected = plat.forward_dynamics(data[:, :6], data[:, 6:12], data[:, 12:])
    if option(argv, "--csv"):
        assert_printed(np.loadtxt(option(argv, "--csv"), delimiter=",", skiprows=1, ndmin=2), expected, ".12g")
    else:
        assert_printed(numeric_rows(out), expected, ".10g")


def check_exactness(argv, out: str) -> None:
    """``exactness``: the median and largest relative changes (``%.1e``) of
    :func:`stewart.oracles.exactness.leg_spin_effect` over the command's 200 states, seed 0."""
    from stewart.oracles import exactness

    states, seed = int(option(argv, "--states") or 200), int(option(argv, "--seed") or 0)
    effect = exactness.leg_spin_effect(params_of(source(argv)), states, seed)
    assert f"; {states} random states, seed {seed}" in out.splitlines()[0]
    for label, change in (("dynamic forces", effect.dynamic), ("velocity-dependent forces", effect.velocity)):
        assert_printed(line_after(out, label).split()[-2:], [change.median, change.max], ".1e", label)


def check_excitation(argv, out: str) -> None:
    """``excitation --output S --csv C``: the series of S, read back, gives the CSV's rows
    (:func:`cli_outputs.check_excitation_csv`) and the printed report: its condition number
    (the column-normalized stacked base regressor over the design samples, by numpy), its
    peaks on the check grid (the compiled model's leg lengths, rates, accelerations, inverse
    dynamics and margins) and the default limits, 4 significant digits. (Its random start's
    condition number, the amplitudes' scale and the iterations come from the optimizer: to
    compare them would be to run it again, half a minute.)"""
    from stewart.identification import excitation
    from stewart.identification.base_parameters import base_parameters
    from stewart.motion.trajectory import load

    plat = stewart.Platform(params_of(source(argv)))
    series = load(option(argv, "--output"))
    harmonics = int(option(argv, "--harmonics") or excitation.DEFAULT_HARMONICS)
    assert (series.period, series.harmonics, series.periods) == (float(option(argv, "--period")), harmonics, 1)
    assert np.array_equal(series.centre, plat.home_pose) and series.starts_at_rest  # at rest at home, the default
    check_excitation_csv(option(argv, "--csv"), series, plat, excitation.DEFAULT_RATE)
    base = base_parameters(plat, friction=True)
    assert f", {len(base.names)} base parameters" in out.splitlines()[0]
    samples = excitation.SAMPLES_PER_HARMONIC * harmonics
    stacked = base.reduce(plat.regressor(*series.series(np.arange(samples) * series.period / samples)))
    stacked = stacked.reshape(-1, stacked.shape[-1])
    assert_printed(numbers(line_after(out, "condition number"))[0],
                   np.linalg.cond(stacked / np.linalg.norm(stacked, axis=0)), ".4g", "condition number")
    grid = excitation.CHECK_DENSITY * harmonics
    x, xd, xdd = series.series(np.arange(grid) * series.period / grid)
    lengths = plat.leg_lengths(x)
    low, high = plat.params.leg_length_limits
    stroke, home_margin = high - low, stewart.reachability(plat, plat.home_pose).margin[0]
    rows = {"leg length min [m]": (lengths.min(), low + excitation.STROKE_MARGIN * stroke),
            "leg length max [m]": (lengths.max(), high - excitation.STROKE_MARGIN * stroke),
            "leg velocity [m/s]": (np.abs(plat.leg_rates(x, xd)[1]).max(), excitation.VELOCITY_PER_STROKE * stroke),
            "leg acceleration [m/s^2]": (np.abs(plat.leg_accelerations(x, xd, xdd)).max(),
                                         excitation.ACCELERATION_PER_STROKE * stroke),
            "actuator force [N]": (np.abs(plat.inverse_dynamics(x, xd, xdd)).max(), None),
            "singularity margin (min)": (stewart.reachability(plat, x).margin.min(),
                                         excitation.MARGIN_FRACTION * home_margin)}
    for label, (reached, limit) in rows.items():
        printed = line_after(out, label)[len(label):].split()
        assert_printed(printed[0], reached, ".4g", label)
        if limit is None:
            assert printed[1] == "none"  # no --force-limit
        else:
            assert_printed(printed[1], limit, ".4g", f"{label}: limit")


def check_calibration_poses_command(argv, out: str) -> None:
    """``calibration-poses``: :func:`stewart.calibration.design.design_poses` with the
    command's arguments (seed 0 and the function's box by default)."""
    from stewart.calibration.design import design_poses

    count = int(option(argv, "--count"))
    want = design_poses(params_of(source(argv)), count, seed=int(option(argv, "--seed") or 0))
    check_calibration_poses(out, want, count, option(argv, "--csv"))


@functools.cache
def calibration(where: tuple[str, str], measurements: str, offsets: tuple | None, held: str | None):
    """:func:`stewart.calibration.fit.calibrate` of the measurements (the command's default
    standard deviations are the function's), and the held-out errors of the nominal and the
    calibrated geometry (:func:`stewart.calibration.validation.pose_errors`)."""
    from stewart.calibration import fit, validation
    from stewart.calibration.measurements import CalibrationData

    nominal = params_of(where)
    offsets = None if offsets is None else np.array(offsets)
    result = fit.calibrate(nominal, CalibrationData.from_csv(measurements, offsets))
    if held is None:
        return result, None
    data = CalibrationData.from_csv(held, offsets)
    return result, {"nominal": validation.pose_errors(nominal, data),
                    "calibrated": validation.pose_errors(result.params, data)}


def check_calibrate(argv, out: str) -> None:
    """``calibrate``: the printed report (:func:`cli_outputs.check_calibration`); the
    parameter file of ``--output`` and the JSON of ``--report`` to the last bit."""
    offsets = tuple(tuple(float(v) for v in argv[j + 1:j + 4]) for j, word in enumerate(argv)
                    if word == "--target-offset") or None
    result, held_out = calibration(source(argv), argv[1], offsets, option(argv, "--validate"))
    check_calibration(out, result, held_out)
    if option(argv, "--output"):
        assert stewart.PlatformParams.load(option(argv, "--output")) == result.params
    if option(argv, "--report"):
        report = json.loads(pathlib.Path(option(argv, "--report")).read_text())
        assert_json_equal(report, result.summary())
        if held_out is not None:
            assert report["validation"] == {"file": option(argv, "--validate"), **{
                f"{geometry}_rms_{kind}": float(np.sqrt(np.mean(errors[kind] ** 2)))
                for geometry, errors in held_out.items() for kind in errors}}


@functools.cache
def modes(where: tuple[str, str], pose: tuple | None, stiffness: tuple, damping: tuple | None):
    """The pose (home by default) and :meth:`stewart.Platform.modes` there."""
    plat = stewart.Platform(params_of(where))
    pose = plat.home_pose if pose is None else np.array(pose)
    return pose, plat.modes(pose, np.array(stiffness), None if damping is None else np.array(damping))


def check_modes(argv, out: str) -> None:
    """``modes``: the table (:func:`cli_outputs.check_modes_table`), or with ``--json`` every
    number to the last bit."""
    def given(flag):
        return None if values(argv, flag) is None else tuple(values(argv, flag))

    pose, result = modes(source(argv), given("--pose"), given("--stiffness"), given("--damping"))
    if "--json" not in argv:
        check_modes_table(out, result, pose)
        return
    summary = json.loads(out)
    every_leg = {"stiffness": given("--stiffness"), "damping": given("--damping")}
    share = result.participation()
    assert_json_equal(summary, {
        "pose": pose.tolist(), "frequencies": result.frequencies.tolist(), "motions": result.motions(),
        "participation": {axis: share[i].tolist() for i, axis in enumerate(MOTION_AXES)},
        "damping_ratios": None if result.damping_ratios is None else result.damping_ratios.tolist(),
        **{key: None if v is None else np.broadcast_to(v, 6).tolist() for key, v in every_leg.items()}})


def check_workspace(argv, out: str) -> None:
    """``workspace``: with ``--json`` its summary to the last bit
    (:func:`cli_outputs.check_workspace_json`), else the printed report: the study's fixed
    pose, limits, counts, volume with its error, bounding box, margins and, with
    ``--stiffness``, its lowest frequency and largest compliance, each in its format."""
    from stewart.studies import workspace

    overrides = {"--universal-max-angle": ("universal_joint_max_angle", math.radians),
                 "--spherical-max-angle": ("spherical_joint_max_angle", math.radians),
                 "--leg-diameter": ("leg_diameter", float), "--plate-radius": ("plate_radius", float),
                 "--base-clearance": ("base_clearance", float)}
    params = params_of(source(argv)).replace(**{name: unit(float(option(argv, flag)))
                                                for flag, (name, unit) in overrides.items() if flag in argv})
    study = workspace.orientation_workspace if option(argv, "--kind") == "orientation" else \
        workspace.translational_workspace
    result = study(params, samples=int(option(argv, "--samples") or 100_000), seed=int(option(argv, "--seed") or 0),
                   stiffness=values(argv, "--stiffness"), progress=False)
    if "--json" in argv:
        check_workspace_json(json.loads(out), result)
        return
    assert_printed(line_after(out, "platform ").split(" at ")[-1].split()[-3:], result.fixed, "g", "fixed")
    limits = re.fullmatch(r"limits: stroke (\S+)-(\S+) m; joint cones universal (\S+) deg, spherical (\S+) deg; "
                          r"legs (\S+) m thick; plate of radius (\S+) m; base clearance none",
                          line_after(out, "limits: "))
    assert limits and params.base_clearance is None
    assert_printed(limits.groups()[:2], params.leg_length_limits, "g", "stroke")
    assert_printed(limits.groups()[2:4], np.degrees([params.universal_joint_max_angle,
                                                     params.spherical_joint_max_angle]), ".0f", "joint cones")
    assert_printed(limits.groups()[4:], [params.leg_diameter, params.plate_radius], "g", "leg diameter, plate radius")
    assert f"{result.method}: {result.reachable} of {result.samples} poses reachable (seed {result.seed})" in out
    volume = line_after(out, "volume ").split()
    assert_printed(volume[1], result.volume, ".6g", "volume")
    assert_printed(volume[3], result.volume_error, ".2g", "volume error")
    box = [line.split() for line in out.splitlines() if line.startswith("  ")]
    assert [row[0] for row in box] == list(result.axes)
    assert_printed([[row[1], row[3]] for row in box], result.bounding_box, ".5g", "bounding box")
    assert_printed(numbers(line_after(out, "singularity margin").split(": ")[1]),
                   [result.margin_min, result.margin_mean, result.margin_max], ".3g", "margin")
    if result.stiffness is not None:
        frequency, compliance = numbers(line_after(out, "on legs of ").split(": ")[1])
        assert_printed(frequency, result.frequency_min, ".4g", "lowest frequency")
        assert_printed(compliance, result.compliance_max, ".3g", "largest compliance")
    assert line_after(out, "excluded: ") == "excluded: " + ", ".join(f"{name} {n}" for name, n in
                                                                      result.excluded.items())


def check_simulate(argv, out: str) -> None:
    """``simulate``: :func:`stewart.simulate` of the same move (the command's defaults: a 5 s
    sinusoidal move to ``--target`` or the ``--trajectory`` file; PID tuned for the
    platform, or computed torque at 5 Hz; RK4 at 1 ms): the printed report (peak forces
    ``%.4g``, final and RMS errors ``%.3e``), the ``--csv`` series (``%.10g``) and the
    ``--json`` summary to the last bit. (The wall time is a measurement.) A rotary rig (its
    preset, or a file of ``kind = "rotary"``): the motor torques, crank angles and rates, the
    preset's default move without ``--target``."""
    from stewart.model import paramfile
    from stewart.model.rotary_presets import presets as rotary_presets
    from stewart.motion.mechanism import mechanism
    from stewart.motion.trajectory import load

    flag, name = source(argv)
    rotary = name in rotary_presets() if flag == "--preset" else \
        paramfile.read(name).get("kind") == "rotary"
    rig = mechanism((stewart.RotaryParams.load(name) if flag == "--params" else stewart.RotaryParams.preset(name))
                    if rotary else params_of((flag, name)))
    plat = rig.platform
    target = option(argv, "--target", 6)
    move = load(option(argv, "--trajectory")) if option(argv, "--trajectory") else \
        stewart.PointToPoint(rig.home, rig.default_target if target is None else target, 5.0)
    controller = stewart.ComputedTorque.tuned(5.0) if option(argv, "--controller") == "ct" else None
    tolerance = {"tolerance": tuple(values(argv, "--tolerance"))} if "--tolerance" in argv else {}
    run = stewart.simulate(plat, move, controller, **tolerance)
    summary = run.summary()
    effort = "torque" if rotary else "force"
    if "--json" in argv:
        assert_json_equal(json.loads(out), {
            "controller": run.metadata["controller"], "method": run.method, "dt": run.metadata["dt"],
            "outcome": run.outcome, "ok": run.ok, "exit_code": run.exit_code, "problems": run.problems,
            "completed": run.completed, "reason": run.reason, f"peak_{effort}": summary["peak_force"].tolist(),
            f"peak_commanded_{effort}": float(np.max(np.abs(run.commanded_forces))),
            **{key: summary[key] for key in ("final_position_error", "final_angle_error", "rms_position_error",
                                             "rms_angle_error", "simulated_time")}})
        return
    assert f", controller {run.metadata['controller']}, {run.method}, dt = {run.metadata['dt']:g} s\n" in out
    assert f"outcome: {run.outcome}\n" in out
    peak = "peak torque per motor [N m]: " if rotary else "peak force per leg [N]: "
    assert_printed(line_after(out, peak).split(": ")[1].split(), summary["peak_force"], ".4g", "peak force")
    for label, what in (("final error:", "final"), ("RMS error:", "rms")):
        assert_printed(numbers(line_after(out, label)),
                       [summary[f"{what}_position_error"], summary[f"{what}_angle_error"]], ".3e", label)
    assert line_after(out, "wall time ").endswith(f" ms for {summary['simulated_time']:g} s simulated")
    if option(argv, "--csv"):
        columns = {"t": run.t}
        for name, series in (("", run.x), ("_dot", run.xd), ("_ref", run.reference),
                             ("_dot_ref", run.reference_velocity)):
            columns.update({f"{p}{name}": series[:, k] for k, p in enumerate(POSE)})
        joint = "alpha" if rotary else "L"
        for name, series in ((joint + "{}", run.lengths), (joint + "{}_dot", run.leg_velocities),
                             (effort + "{}", run.forces)):
            columns.update({name.format(i): series[:, i] for i in range(6)})
        check_csv_columns(option(argv, "--csv"), columns, ".10g")


def check_optimize(argv, out: str) -> None:
    """``optimize``: :func:`stewart.motion.optimize.minimum_effort_move` with the command's
    arguments (5 s, 50 intervals by default): the printed intervals, step, status and
    iterations, effort (``%.6g``), peak forces and leg length range (``%.4g``), and the
    ``--csv`` nodes (:func:`cli_outputs.check_optimize_csv`). (The solve time is a
    measurement.)"""
    from stewart.motion import optimize

    plat = stewart.Platform(params_of(source(argv)))
    move = optimize.minimum_effort_move(plat, np.array(option(argv, "--target", 6)), 5.0, 50,
                                        force_limit=float(option(argv, "--force-limit")))
    assert f": {len(move.tau)} intervals of {move.dt:g} s, {move.status} after {move.iterations} IPOPT " in out
    assert_printed(line_after(out, "effort ").split(" = ")[1].split()[0], move.effort, ".6g", "effort")
    assert_printed(line_after(out, "peak force per leg [N]: ").split(": ")[1].split(),
                   np.max(np.abs(move.tau), axis=0), ".4g", "peak force")
    assert_printed(line_after(out, "leg length range [m]: ").split(": ")[1].split(" .. "),
                   [move.lengths.min(), move.lengths.max()], ".4g", "leg length range")
    check_optimize_csv(option(argv, "--csv"), move)


def check_envelope(argv, out: str) -> None:
    """``envelope``: :func:`stewart.studies.envelope.envelope` of the same specification (the
    command's ``--dt`` 1 ms, seed 0): the printed table (:func:`cli_outputs.check_envelope_table`)
    and the rows of ``--csv`` and ``--json`` to the last bit."""
    from stewart.motion.trajectory import load
    from stewart.studies import envelope

    params = params_of(source(argv))
    if option(argv, "--trajectory"):
        spec = envelope.Trajectories([load(option(argv, "--trajectory"))], 1e-3)
    else:
        move = stewart.PointToPoint(stewart.home_pose(params), option(argv, "--target", 6), 5.0)
        spec = envelope.Box.around(move, float(option(argv, "--margin")), 1e-3)
    samples = option(argv, "--samples")
    result = envelope.envelope(params, spec, samples=None if samples is None else int(samples), progress=False)
    check_envelope_table(out, result)
    rows = json.loads(json.dumps(result.rows()))
    if option(argv, "--json"):
        written = json.loads(pathlib.Path(option(argv, "--json")).read_text())
        assert written == {**result.summary(), "peaks": rows}
    if option(argv, "--csv"):
        with open(option(argv, "--csv"), newline="") as handle:
            assert handle.readline() == "# " + ", ".join(f"{k} = {v}" for k, v in result.summary().items()) + "\n"
            reader = csv.DictReader(handle)
            assert reader.fieldnames == list(rows[0])
            written = [{key: v if isinstance(want[key], str) else float(v) for key, v in row.items()}
                       for row, want in zip(reader, rows, strict=True)]
        assert written == rows


#: The designs of ``stewart sweep`` computed again here, each by its own envelope and workspace
#: (the corners of examples/sweep.toml's grid; all nine would take as long as the command).
SWEEP_DESIGNS = (0, 8)


def check_sweep(argv, out: str) -> None:
    """``sweep FILE --csv C``: the printed table is C's rows (:func:`cli_outputs.check_sweep_table`);
    C's designs are those of the file, its Pareto marks those of its two metrics, and the
    metrics of :data:`SWEEP_DESIGNS` those of their own envelope and workspace runs (the
    file's samples and seed) to the last bit."""
    from stewart.studies import envelope, sweep, workspace

    spec = sweep.load(argv[1])
    with open(option(argv, "--csv"), newline="") as handle:
        handle.readline()  # the units
        rows = [{key: (v == "True" if key == "pareto" else int(v) if key == "design" else float(v))
                 for key, v in row.items()} for row in csv.DictReader(handle)]
    check_sweep_table(out, rows)
    assert [{name: row[name] for name in design} for row, design in zip(rows, spec.designs)] == list(spec.designs)
    (x, x_sense), (y, y_sense) = ((name, sweep.METRICS[name][1]) for name in spec.pareto)
    front = sweep.pareto_front([x_sense * row[x] for row in rows], [y_sense * row[y] for row in rows])
    assert [row["pareto"] for row in rows] == front.tolist()
    for k in SWEEP_DESIGNS:
        params = sweep.design_params(spec.base, spec.designs[k])
        home = stewart.home_pose(params)
        box = envelope.Box(home + spec.offsets.lower, home + spec.offsets.upper, spec.offsets.velocity,
                           spec.offsets.acceleration)
        env = envelope.envelope(params, box, samples=spec.envelope_samples, seed=spec.seed, progress=False)
        work = workspace.translational_workspace(params, samples=spec.workspace_samples, seed=spec.seed,
                                                 progress=False)
        assert {name: rows[k][name] for name in sweep.METRICS if name in rows[k]} == {
            "workspace_volume": work.volume, "workspace_volume_error": work.volume_error,
            "margin_mean": work.margin_mean, "home_margin": float(stewart.reachability(params, home).margin[0]),
            **{f"peak_{q}": float(np.max(env.value(q))) for q, _ in envelope.QUANTITIES},
            "outside_stroke": env.outside_stroke / env.states}


def check_validate(argv, out: str) -> None:
    """``validate``: the checks of :func:`stewart.oracles.validation.run` (the command's 200
    states, seed 0): each one's name, worst figure (``%.3e``), bound (``%.0e``) and verdict."""
    from stewart.oracles import validation

    checks = validation.run(params_of(source(argv)), n_states=int(option(argv, "--states") or 200),
                            seed=int(option(argv, "--seed") or 0))
    lines = out.splitlines()
    rows = [line.rsplit(None, 3) for line in lines[3:3 + len(checks)]]
    assert [row[0] for row in rows] == [c.name for c in checks]
    assert_printed([row[1] for row in rows], [c.worst for c in checks], ".3e", "worst")
    assert_printed([row[2] for row in rows], [c.bound for c in checks], ".0e", "bound")
    assert [row[3] for row in rows] == ["ok" if c.passed else "FAIL" for c in checks]
    assert lines[-1] == f"all {len(checks)} checks passed"


#: The check of the numbers each command prints and writes (``bench``'s are measurements:
#: :func:`check_bench`; the other commands print none, or names and paths).
def check_motor_sizing(argv, out: str) -> None:
    """``motor-sizing``: the printed table at the crank (``%.6g``) and the ``--report`` against
    :func:`stewart.studies.motor_sizing.motor_sizing` on the same file."""
    from stewart.studies.motor_sizing import motor_sizing, read_reference

    where = source(argv)
    params = stewart.RotaryParams.load(where[1]) if where[0] == "--params" else stewart.RotaryParams.preset(where[1])
    ref = read_reference(argv[1])
    m = motor_sizing(params, ref.x, ref.xd, ref.xdd, t=ref.t, gear_ratio=float(option(argv, "--gear-ratio") or 1)).motors
    lines = out.splitlines()
    rows = np.array([line.split()[:7] for line in lines[2:8]], dtype=float)
    assert_printed(rows[:, 0], np.arange(6), ".0f")
    for column, key in ((1, "peak_torque"), (3, "rms_torque"), (4, "peak_speed"), (6, "peak_power")):
        assert_printed(rows[:, column], m[key], ".6g", key)
    assert rows[:, 2].tolist() == m["peak_torque_sample"].tolist() and rows[:, 5].tolist() == m["peak_speed_sample"].tolist()
    if option(argv, "--report"):
        report = json.loads(pathlib.Path(option(argv, "--report")).read_text())
        for key in ("peak_torque", "rms_torque", "peak_speed", "torque_headroom"):
            np.testing.assert_allclose([motor[key] for motor in report["motors"]], m[key], rtol=1e-15, err_msg=key)


OUTPUT_CHECKS = {"motor-sizing": check_motor_sizing, "ik": check_kinematics, "id": check_kinematics, "fd": check_kinematics,
                 "exactness": check_exactness, "excitation": check_excitation,
                 "calibration-poses": check_calibration_poses_command, "calibrate": check_calibrate,
                 "modes": check_modes, "workspace": check_workspace, "simulate": check_simulate,
                 "optimize": check_optimize, "envelope": check_envelope, "sweep": check_sweep,
                 "validate": check_validate}


def test_every_page_of_the_docs_is_in_the_nav():
    pages = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").rglob("*.md"))
    assert pages == sorted(PAGES[1:]), "a page missing from mkdocs.yml's nav would escape these tests"


def test_the_readme_shows_commands_on_the_shipped_examples():
    used = " ".join(line for line, _, _ in COMMANDS)
    for name in ("examples/platform.toml", "examples/states.csv", "examples/trajectory.csv"):
        assert name in used
        assert (ROOT / name).is_file()
    for command in ("ik", "id", "fd", "simulate", "validate"):
        assert any(argv[:1] == [command] for _, argv, _ in COMMANDS)


@pytest.mark.slow
@pytest.mark.parametrize("line, argv, code", COMMANDS, ids=[line for line, _, _ in COMMANDS])
def test_readme_command_runs(line, argv, code, in_examples_dir, capsys):
    if argv[:1] == ["bench"]:
        argv = [*argv, "--batch", "2000", "--preset", "narayan2017", "--budget", "0"]
    assert run_cli(argv) == code, capsys.readouterr()
    out, err = capsys.readouterr()
    if argv[:1] == ["bench"]:
        check_bench(argv, out, err)
    if code == 0 and argv[0] in OUTPUT_CHECKS:
        OUTPUT_CHECKS[argv[0]](argv, out)
    if option(argv, "--plot"):
        assert len(list(pathlib.Path(option(argv, "--plot")).glob("*.png"))) >= 4
        if argv[0] == "simulate":  # its figures (tests/test_cli.py leaves --plot to this run)
            rotary = any(name in argv for name in ("simrig100", "desktop_servo"))
            for name in ("pose", "error", *(("torques", "crank_angles", "crank_rates") if rotary
                                            else ("forces", "leg_velocities"))):
                assert (pathlib.Path(option(argv, "--plot")) / f"simulation_{name}.png").stat().st_size > 10_000


def check_bench(argv, out: str, err: str) -> None:
    """``stewart bench --json``: stdout holds only the JSON, with the figures of every preset
    measured (or of ``--preset``'s), each with its interval and rounds, and the table on
    stderr shows the same measurements and counts the targets met, missed and unsettled."""
    from stewart.cli.bench import TARGETS

    assert "--json" in argv
    figures = json.loads(out)["figures"]
    assert sorted(figures) == ([option(argv, "--preset")] if option(argv, "--preset") else sorted(stewart.presets()))
    for preset, values in figures.items():
        line = next(row for row in err.splitlines() if f"[{preset}] inverse dynamics, C batch loop" in row)
        per_state = float(line.split("us/state")[0].split()[-1])
        assert 0 < per_state < 100  # microseconds per state, a real measurement
        assert per_state == pytest.approx(values["batch_inverse_dynamics_us"], rel=1e-3, abs=1e-3)
        spread = values["spread"]["batch_inverse_dynamics_us"]
        assert spread["low"] <= values["batch_inverse_dynamics_us"] <= spread["high"] and spread["rounds"] >= 9
        assert f"{spread['low']:.3f}-{spread['high']:.3f} ({spread['rounds']})" in line
        assert f"[{preset}] 5 s move, RK4 at 1 kHz with PID" in err
    counts = re.search(r"^targets: (\d+) met, (\d+) missed, (\d+) unsettled", err, re.M)
    judged = [key for key in TARGETS for preset in figures if key in figures[preset]]
    assert counts and sum(map(int, counts.groups())) == len(judged)


_RAISES = re.compile(r"#\s*((?:\w+\.)*\w+(?:Error|Exception)):\s*(.*?)\s*$")


def run_python(source: str, namespace: dict, page: str = "README.md") -> int:
    """Run ``source`` statement by statement; returns how many raised as their comment says."""
    lines = source.splitlines()
    raised = 0
    for node in ast.parse(source).body:
        code = compile(ast.Module([node], type_ignores=[]), page, "exec")
        following = lines[node.end_lineno].strip() if node.end_lineno < len(lines) else ""
        expected = _RAISES.match(following)
        if not expected:
            exec(code, namespace)
            continue
        with pytest.raises(Exception) as info:
            exec(code, namespace)
        name, message = expected.groups()
        assert type(info.value).__name__ == name.split(".")[-1], info.value
        pattern = ".*".join(re.escape(part) for part in message.split("..."))
        assert re.fullmatch(pattern, str(info.value)), f"{page} says {message!r}, got {str(info.value)!r}"
        raised += 1
    return raised


@pytest.mark.slow
def test_the_python_tour_runs(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    shutil.copytree(ROOT / "examples", tmp_path / "examples")   # the files the pages' examples read
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    raised = sum(run_python(block, namespace, page) for page, block in blocks("python"))
    assert raised >= 2  # the error messages the tour shows are the ones raised
    assert isinstance(namespace["run"], stewart.SimulationResult)
    assert (tmp_path / "run.csv").is_file() and any((tmp_path / "figures").glob("*.png"))


def test_the_validate_sample_lists_the_checks_stewart_validate_runs():
    from stewart.oracles import validation

    sample = re.search(r"<!-- BEGIN validate\b.*?-->\n(.*?)<!-- END validate -->", TEXTS["docs/checks.md"], re.S)
    assert sample, "docs/checks.md has the generated block of make validate"
    rows = [line.split(" | ")[0].lstrip("| ").replace("\\|", "|") for line in sample.group(1).splitlines()
            if line.startswith("| ") and not line.startswith("| check")]
    checks = validation.run(stewart.PlatformParams.preset("narayan2017"), n_states=5)
    assert rows == [c.name for c in checks]
