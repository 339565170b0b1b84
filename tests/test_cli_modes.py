"""``stewart modes``: the table and JSON of the modes, and its errors with their exit codes."""

import json

import numpy as np
import pytest
from cli_run import run as _run

import stewart


def test_modes_prints_the_frequencies_and_dominant_motions(capsys):
    plat = stewart.Platform.preset("motion_simulator")
    modes = plat.modes(plat.home_pose, 2e7, 4e4)
    code, out, _ = _run(["modes", "--preset", "motion_simulator", "--stiffness", "2e7", "--damping", "4e4"], capsys)
    assert code == 0
    rows = [line.split() for line in out.splitlines()[2:]]
    # printed with 4 decimals: reached 1.5e-6 (frequencies) and 1.7e-4 (damping ratios), relative
    np.testing.assert_allclose([float(r[1]) for r in rows], modes.frequencies, rtol=1e-5)
    np.testing.assert_allclose([float(r[2]) for r in rows], modes.damping_ratios, rtol=1e-3)
    assert [" ".join(r[3:6]) for r in rows] == modes.motions()


def test_modes_json_at_a_pose(capsys):
    pose = [0.05, 0.0, 1.2, 0.0, 0.0, 0.1]
    code, out, _ = _run(["modes", "--preset", "motion_simulator", "--stiffness", *["2e7"] * 6, "--pose",
                         *map(str, pose), "--json"], capsys)
    assert code == 0
    data = json.loads(out)
    np.testing.assert_array_equal(data["frequencies"],
                                  stewart.Platform.preset("motion_simulator").modes(pose, 2e7).frequencies)
    assert data["damping_ratios"] is None and len(data["motions"]) == 6


@pytest.mark.parametrize("argv, code, start", [
    (["--stiffness", "2e7", "1e7"], 2, "--stiffness: give one value or six"),
    (["--stiffness", "5e3"], 3, "--pose: the preloaded legs cannot hold the pose"),
    (["--stiffness", "2e7", "--pose", "0", "0", "0", "0", "0", "0"], 3, "--pose: 1 of 1 pose(s) outside the workspace"),
])
def test_modes_errors_are_one_line_with_their_exit_code(capsys, argv, code, start):
    got, _, err = _run(["modes", "--preset", "motion_simulator", *argv], capsys)
    assert got == code
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"stewart modes: error: {start}"), err


def test_modes_takes_the_stiffness_of_the_parameter_file(tmp_path, capsys):
    params = stewart.PlatformParams.preset("motion_simulator")
    params.replace(leg_stiffness=2e7).save(tmp_path / "p.toml")
    code, out, _ = _run(["modes", "--params", str(tmp_path / "p.toml"), "--json"], capsys)
    assert code == 0
    np.testing.assert_array_equal(json.loads(out)["frequencies"], stewart.Platform(params).modes(
        stewart.Platform(params).home_pose, 2e7).frequencies)
    code, _, err = _run(["modes", "--preset", "motion_simulator"], capsys)
    assert code == 2 and err.strip() == ("stewart modes: error: --stiffness: none given, and the parameters have "
                                         "no leg_stiffness (N/m)")
