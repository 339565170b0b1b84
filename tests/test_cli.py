"""The ``stewart`` command, with assertions on the numbers it prints and writes."""

import numpy as np
import pytest

import stewart
from stewart.cli import main


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
    np.testing.assert_allclose(_numbers(capsys.readouterr().out)[0], rows[0, 12:], atol=1e-5)


def test_params_file_is_used(tmp_path, capsys):
    params = stewart.PlatformParams.preset("narayan2017").replace(name="file")
    params.save(tmp_path / "p.toml")
    main(["ik", "--params", str(tmp_path / "p.toml"), "--pose", "0", "0", "0.3", "0", "0", "0"])
    np.testing.assert_allclose(_numbers(capsys.readouterr().out)[0], stewart.leg_lengths(params, [0, 0, 0.3, 0, 0, 0]),
                               rtol=1e-9)


def test_simulate_writes_series_and_plots(tmp_path, capsys):
    target = ["0.04565", "-0.0102", "0.192", "-0.086", "0.105", "0.096"]
    main(["simulate", "--target", *target, "--csv", str(tmp_path / "run.csv"), "--plot", str(tmp_path / "figs"),
          "--no-progress"])
    out = capsys.readouterr().out
    assert "outcome: completed" in out
    table = np.genfromtxt(tmp_path / "run.csv", delimiter=",", names=True)
    assert table["t"][-1] == pytest.approx(5.0)
    np.testing.assert_allclose([table[k][-1] for k in ("x", "y", "z", "psi", "theta", "phi")],
                               np.array(target, dtype=float), atol=1e-4)
    peak = [float(v) for v in out.split("peak force per leg [N]: ")[1].split("\n")[0].split()]
    np.testing.assert_allclose(peak, [np.max(np.abs(table[f"force{i}"])) for i in range(6)], rtol=1e-3)
    for name in ("pose", "error", "forces", "leg_velocities"):
        assert (tmp_path / "figs" / f"simulation_{name}.png").stat().st_size > 10_000


def test_simulate_refuses_a_target_below_the_stroke(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["simulate", "--target", "0", "0", "0.1", "0", "0", "0", "--no-progress"])
    assert exit_info.value.code == 3
    err = capsys.readouterr().err
    assert err.startswith("stewart simulate: error: --target: ") and "shorter than the minimum length 0.19 m" in err


def test_validate_passes_for_presets(capsys):
    main(["validate", "--preset", "motion_simulator", "--states", "50"])
    assert "all 15 checks passed" in capsys.readouterr().out


def test_bad_input_is_an_error_naming_the_argument(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["ik", "--pose", "0", "0", "nan", "0", "0", "0"])
    assert exit_info.value.code == 2
    assert "argument --pose: not a finite number: 'nan'" in capsys.readouterr().err


def test_bench_prints_the_kernel_table(capsys):
    main(["bench", "--preset", "narayan2017", "--batch", "2000"])
    out = capsys.readouterr().out
    line = next(l for l in out.splitlines() if "inverse dynamics, C batch loop" in l)
    per_state = float(line.split("us/state")[0].split()[-1])
    assert 0 < per_state < 100  # microseconds per state, a real measurement
    assert "5 s move, RK4 at 1 kHz with PID" in out
