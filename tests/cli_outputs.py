"""The numbers the ``stewart`` commands print and write, read back and compared with what the
Python API returns for the same inputs: one checker per output, shared by each command's own
tests and by tests/test_readme.py, which runs the commands of the README and of the docs.

A number printed with a format is compared within that format's rounding, half a unit in its
last digit (:func:`printed_tolerance`). A number written to JSON, or by the ``csv`` module, is
the shortest repr of the double, which reads back to the same double: those are compared
with ``==``."""

from __future__ import annotations

import json
import re

import numpy as np

#: A decimal number as the commands print them (``-0.5``, ``2.5e+07``, ``+0.46759``, ``17``).
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
POSE = ["x", "y", "z", "psi", "theta", "phi"]


def printed_tolerance(fmt: str) -> dict:
    """The ``rtol`` and ``atol`` (of ``numpy.testing.assert_allclose``, against the exact value)
    of a number printed with the format ``fmt`` (``".4g"``, ``".3e"``, ``".4f"``; ``"g"`` is
    ``".6g"``): half a unit in the last digit shown (relative for ``g`` and ``e``, absolute
    for ``f``), plus one rounding of reading the decimal back (machine epsilon, relative)."""
    match = re.fullmatch(r"(?:\.(\d+))?([efg])", fmt)
    assert match, fmt
    digits, kind = 6 if match[1] is None else int(match[1]), match[2]
    half = 0.5 * 10.0 ** -digits
    eps = float(np.finfo(float).eps)
    if kind == "f":
        return {"rtol": eps, "atol": half}
    # "g" shows `digits` significant digits, "e" one more (one before the point, `digits` after).
    return {"rtol": (10.0 * half if kind == "g" else half) + eps, "atol": 0.0}


def assert_printed(printed, exact, fmt: str, what: str = "") -> None:
    """``printed`` (the numbers or strings read from a command's output) are ``exact`` printed
    with the format ``fmt`` (:func:`printed_tolerance`)."""
    got = np.asarray(printed, dtype=float)
    want = np.asarray(exact, dtype=float)
    assert got.shape == want.shape, (what, got.shape, want.shape)
    np.testing.assert_allclose(got, want, err_msg=what, **printed_tolerance(fmt))


def numbers(text: str) -> list[float]:
    """The numbers of a line, in order."""
    return [float(v) for v in NUMBER.findall(text)]


def assert_json_equal(written: dict, value: dict) -> None:
    """Every entry of ``value`` (plain Python: lists, dicts, floats; no NaN) is in ``written``
    (read from a JSON file or line) to the last bit."""
    expected = json.loads(json.dumps(value))
    assert {key: written[key] for key in expected} == expected


def line_after(out: str, start: str) -> str:
    """The first printed line that starts with ``start``."""
    found = [line for line in out.splitlines() if line.startswith(start)]
    assert found, f"no line starts with {start!r} in:\n{out}"
    return found[0]


def read_csv(path) -> dict:
    """A CSV file the commands write (a header line, a ``#`` comment, the rows): its columns
    by name, in order."""
    with open(path, encoding="utf-8") as handle:
        names = handle.readline().strip().split(",")
    return dict(zip(names, np.loadtxt(path, delimiter=",", comments="#", skiprows=1, ndmin=2).T, strict=True))


def check_csv_columns(path, columns: dict, fmt: str, atol: dict | None = None) -> None:
    """The CSV file ``path`` has exactly the ``columns`` (name: values), in order, written
    with the format ``fmt``; ``atol`` (name: value) widens the named columns' tolerance by an
    absolute amount (the caller says why)."""
    table = read_csv(path)
    assert list(table) == list(columns), path
    for name, want in columns.items():
        tolerance = printed_tolerance(fmt)
        tolerance["atol"] += (atol or {}).get(name, 0.0)
        np.testing.assert_allclose(table[name], want, err_msg=f"{path}: {name}", **tolerance)


# ---------------------------------------------------------------------------- modes


def check_modes_table(out: str, modes, pose) -> None:
    """``stewart modes``: the pose of the header (``%g``), then per mode its frequency and
    damping ratio (4 decimals; ``-`` without dampers), its dominant motion and that axis's
    share of the mode (a whole percentage): those of ``modes`` (:meth:`stewart.Platform.modes`
    at ``pose``)."""
    lines = out.splitlines()
    assert_printed(re.search(r"; pose ([^;]*);", lines[0])[1].split(), pose, "g", "pose")
    rows = [line.split() for line in lines[2:]]
    assert [row[0] for row in rows] == [str(k) for k in range(1, 7)]
    assert_printed([row[1] for row in rows], modes.frequencies, ".4f", "frequencies")
    if modes.damping_ratios is None:
        assert all(row[2] == "-" for row in rows)
    else:
        assert_printed([row[2] for row in rows], modes.damping_ratios, ".4f", "damping ratios")
    assert [" ".join(row[3:6]) for row in rows] == modes.motions()
    assert [row[7] for row in rows] == ["%)"] * 6
    assert_printed([row[6].lstrip("(") for row in rows], 100 * np.max(modes.participation(), axis=0), ".0f",
                   "share of the dominant motion [%]")


# ---------------------------------------------------------------------------- calibration


def check_calibration_poses(out: str, want, count: int, csv=None) -> None:
    """``stewart calibration-poses``: the observability indexes O1, condition and O4 of the
    designed poses and of ``count`` random ones (4 significant digits), and the poses with
    their nominal encoder readings, in the ``--csv`` file or listed (12 significant digits):
    those of ``want`` (:func:`stewart.calibration.design.design_poses` with the same arguments)."""
    for label, index in (("designed", want.designed), (f"{count} random poses", want.random)):
        assert_printed(line_after(out, label).split()[-3:], [index["O1"], index["condition"], index["O4"]], ".4g",
                       label)
    columns = POSE + [f"L{i}" for i in range(6)]
    if csv is None:
        lines = out.splitlines()
        start = lines.index(",".join(columns)) + 1
        listed = np.array([[float(v) for v in line.split(",")] for line in lines[start:] if "," in line])
    else:
        table = read_csv(csv)
        assert list(table) == columns
        listed = np.column_stack([table[name] for name in columns])
    assert_printed(listed, np.column_stack([want.poses, want.readings]), ".12g", "poses and readings")


def check_calibration(out: str, result, held_out: dict | None = None) -> None:
    """``stewart calibrate``'s report: every parameter's nominal value, estimate, change and
    standard error [mm, 4 decimals], the condition number (4 significant digits), the
    residual scale (3) and the degrees of freedom, the RMS residuals [um, 3 significant
    digits] with the nominal and the calibrated geometry, and with ``held_out``
    (``{"nominal": errors, "calibrated": errors}`` of
    :func:`stewart.calibration.validation.pose_errors`) the held-out RMS errors [um, urad, 4
    significant digits]: those of ``result`` (:func:`stewart.calibration.fit.calibrate`)."""
    lines = out.splitlines()
    assert f"({len(result.poses)} {result.kind} measurement(s)," in lines[0]
    table = [line.split() for line in lines[2:2 + len(result.names)]]
    assert [row[0] for row in table] == list(result.names)
    nominal, estimates = 1e3 * result.nominal_values, 1e3 * result.estimates
    for k, (what, values) in enumerate((("nominal", nominal), ("estimate", estimates),
                                        ("change", estimates - nominal),
                                        ("standard error", 1e3 * result.standard_errors))):
        assert_printed([row[1 + k] for row in table], values, ".4f", f"{what} [mm]")
    condition, scale, _, dof = numbers(line_after(out, "condition number"))
    assert_printed(condition, result.identifiability.condition, ".4g", "condition number")
    assert_printed(scale, result.sigma, ".3g", "residual scale")
    assert dof == result.dof
    assert line_after(out, "RMS residual [um]").split()[3:] == list(result.residual_names)
    for what, rms in (("nominal", result.rms_before), ("calibrated", result.rms_after)):
        assert_printed(line_after(out, what + " ").split()[1:], 1e6 * rms, ".3g", f"RMS residual, {what}")
    held = [line for line in lines if line.startswith("held-out ")]
    assert len(held) == (0 if held_out is None else len(held_out["nominal"]))
    for line, kind in zip(held, [] if held_out is None else held_out["nominal"]):
        assert f": RMS {kind} error of forward kinematics " in line
        rms = [1e6 * np.sqrt(np.mean(held_out[geometry][kind] ** 2)) for geometry in ("nominal", "calibrated")]
        assert_printed(numbers(line.split(": RMS ")[1]), rms, ".4g", f"held-out {kind}")


# ---------------------------------------------------------------------------- studies


def check_envelope_table(out: str, result) -> None:
    """``stewart envelope``'s table: the states drawn, outside the stroke and singular, then
    per leg the peak of each quantity (6 significant digits): those of ``result``
    (:func:`stewart.studies.envelope.envelope`)."""
    from stewart.studies.envelope import QUANTITIES

    lines = out.splitlines()
    counts = re.search(r"([\d,]+) states \(([\d,]+) outside the stroke, ([\d,]+) singular", lines[0])
    assert [int(v.replace(",", "")) for v in counts.groups()] == [result.states, result.outside_stroke,
                                                                   result.singular]
    assert [name for name in lines[1].split() if not name.startswith("[")] == ["leg"] + [q for q, _ in QUANTITIES]
    rows = [line.split() for line in lines[2:8]]
    assert [row[0] for row in rows] == [str(leg) for leg in range(6)]
    assert_printed([row[1:] for row in rows], np.column_stack([result.value(q) for q, _ in QUANTITIES]), ".6g",
                   "peaks per leg")


def check_sweep_table(out: str, rows: list[dict]) -> None:
    """``stewart sweep``'s table: per design its number, a ``*`` on the Pareto front, and the
    values of the columns its header names (6 significant digits): those of ``rows``
    (:meth:`stewart.studies.sweep.Sweep.rows`, or the rows of its CSV file)."""
    lines = out.splitlines()
    names = lines[1].split()[1:]
    printed = [line.split() for line in lines[2:] if re.match(r"\s*\d+\*? ", line)]
    assert len(printed) == len(rows)
    for row, line in zip(rows, printed):
        assert line[0] == f"{row['design']}{'*' if row['pareto'] else ''}"
        assert_printed(line[1:], [row[name] for name in names], ".6g", f"design {row['design']}")


def check_workspace_json(summary: dict, result) -> None:
    """``stewart workspace --json``: the study's summary, every number to the last bit."""
    assert_json_equal(summary, result.summary())


# ---------------------------------------------------------------------------- motion


def check_optimize_csv(path, move) -> None:
    """``stewart optimize --csv``: the node times, poses, pose rates and leg lengths, and the
    forces held from each node to the next (the last row repeats the last interval's), 12
    significant digits: those of ``move`` (:func:`stewart.motion.optimize.minimum_effort_move`)."""
    held = np.vstack([move.tau, move.tau[-1:]])
    check_csv_columns(path, {"t": move.t, **{p: move.x[:, k] for k, p in enumerate(POSE)},
                             **{f"{p}_dot": move.xd[:, k] for k, p in enumerate(POSE)},
                             **{f"L{i}": move.lengths[:, i] for i in range(6)},
                             **{f"force{i}": held[:, i] for i in range(6)}}, ".12g")


#: The largest difference [m/s] between the compiled model's leg velocities and numpy's
#: (:func:`stewart.model.kinematics.leg_velocities`) on an excitation: reached 8.3e-17 m/s on
#: every SIMD path, on the series of the docs and of tests/test_excitation.py (peaks of 0.19 m/s);
#: the bound is 12 times that.
LEG_VELOCITY_ROUNDING = 1e-15


def check_excitation_csv(path, trajectory, plat, rate: float) -> None:
    """``stewart excitation --csv``: the trajectory sampled every ``1 / rate`` seconds over its
    duration, with its poses, leg lengths and leg velocities (12 significant digits): those
    of ``trajectory`` (the series of ``--output``, :meth:`FourierTrajectory.sample`) through
    :meth:`stewart.Platform.leg_rates` (the lengths and their rates).

    The velocities are the compiled model's, the command's numpy's
    (:func:`stewart.model.kinematics.leg_velocities`): they differ by rounding, which is
    absolute, large against a velocity near zero; :data:`LEG_VELOCITY_ROUNDING` bounds it."""
    t = np.minimum(np.arange(int(round(trajectory.duration * rate)) + 1) / rate, trajectory.duration)
    x, xd, _ = trajectory.sample(t)
    lengths, rates = plat.leg_rates(x, xd)
    check_csv_columns(path, {"t": t, **{p: x[:, k] for k, p in enumerate(POSE)},
                             **{f"L{i}": lengths[:, i] for i in range(6)},
                             **{f"L{i}_dot": rates[:, i] for i in range(6)}}, ".12g",
                      atol={f"L{i}_dot": LEG_VELOCITY_ROUNDING for i in range(6)})
