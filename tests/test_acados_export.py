"""``stewart export-acados`` and :mod:`stewart.io.acados_export` in make test's environment (no
acados): the files, the settings, the leg-length expressions and the command's errors. The
export compiled and evaluated by acados is checked by make test-acados (tests/acados/)."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest

import stewart
from stewart.io import acados_export, capi
from stewart.model import kinematics
from stewart.oracles import frames


def _one_error_line(err, start):
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"stewart export-acados: error: {start}"), lines[0]
    return lines[0]


def test_export_writes_the_model_the_source_and_the_settings(tmp_path):
    params = stewart.PlatformParams.preset("motion_simulator")
    written = acados_export.export(tmp_path, params, 0.0125)
    names = {p.rsplit("/", 1)[-1] for p in written}
    assert {capi.HEADER, capi.PARAMS_HEADER, acados_export.SOURCE, acados_export.SETTINGS_FILE,
            acados_export.PARAMS_FILE} <= names
    settings = json.loads((tmp_path / acados_export.SETTINGS_FILE).read_text())
    assert settings["dt"] == 0.0125 and settings["integrator"] == "rk4"
    assert settings["functions"] == acados_export.FUNCTIONS
    assert settings["compile_flags"].split() == ["-O2", "-ffp-contract=off", "-fno-tree-slp-vectorize",
                                                 f"-I{tmp_path.resolve()}"]
    assert stewart.PlatformParams.load(tmp_path / acados_export.PARAMS_FILE) == params
    source = (tmp_path / acados_export.SOURCE).read_text()
    # The step is the exact float64, every model source is included, both functions defined.
    assert float(re.search(r"#define STEWART_ACADOS_DT (\S+)", source).group(1)) == 0.0125
    included = set(re.findall(r'#include "(stewart_model[^"]*\.c)"', source))
    assert included == {p.rsplit("/", 1)[-1] for p in capi.c_sources()}
    for function in acados_export.FUNCTIONS.values():
        assert re.search(rf"^int {function}\(void \*\*in, void \*\*out, void \*params\)$", source, re.M)
    assert "stewart_rk4_step_derivatives(&stewart_platform_params" in source


@pytest.mark.slow
def test_the_source_is_plain_c_against_acados_s_declarations(tmp_path):
    """The source compiles (-std=c99 -pedantic -Werror, the model's units included) against
    minimal declarations of the blasfeo and acados types it uses, as acados's build compiles it."""
    import shutil

    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        pytest.skip("no C compiler")
    acados_export.export(tmp_path / "x", stewart.PlatformParams.preset("narayan2017"), 0.01)
    stubs = tmp_path / "inc"
    (stubs / "blasfeo" / "include").mkdir(parents=True)
    (stubs / "acados" / "utils").mkdir(parents=True)
    (stubs / "blasfeo" / "include" / "blasfeo_common.h").write_text(
        "struct blasfeo_dvec { int m; double *pa; };\nstruct blasfeo_dmat { int m, n; double *pA; };\n")
    (stubs / "blasfeo" / "include" / "blasfeo_d_aux.h").write_text(
        "double blasfeo_dvecex1(struct blasfeo_dvec *sx, int xi);\n"
        "void blasfeo_dvecin1(double a, struct blasfeo_dvec *sx, int xi);\n"
        "void blasfeo_pack_dmat(int m, int n, double *A, int lda, struct blasfeo_dmat *sB, int bi, int bj);\n")
    (stubs / "acados" / "utils" / "external_function_generic.h").write_text(
        "struct blasfeo_dvec_args { struct blasfeo_dvec *x; int xi; };\n"
        "struct blasfeo_dmat_args { struct blasfeo_dmat *A; int ai; int aj; };\n")
    flags = acados_export.compile_flags(tmp_path / "x").split()
    done = subprocess.run([compiler, "-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror", "-fsyntax-only", *flags,
                           f"-I{stubs}", str(tmp_path / "x" / acados_export.SOURCE)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("preset", ["narayan2017", "motion_simulator"])
def test_leg_length_expressions_are_the_model_s_leg_lengths(preset):
    """numpy's arithmetic through the expressions against the compiled model and the oracles'
    own kinematics, at random poses."""
    platform = stewart.Platform.preset(preset)
    rng = np.random.default_rng(7)
    poses = platform.home_pose + rng.normal(scale=[0.02, 0.02, 0.02, 0.1, 0.1, 0.1], size=(20, 6))
    for x in poses:
        lengths = np.array(kinematics.leg_length_expressions(platform.params, list(x), np))
        np.testing.assert_allclose(lengths, platform.leg_lengths(x), rtol=1e-15, atol=0)
        np.testing.assert_allclose(lengths, frames.leg_lengths(platform.params, x), rtol=1e-15, atol=0)
    # In any arithmetic: math's scalars give the same numbers.
    x = poses[0]
    assert kinematics.leg_length_expressions(platform.params, list(x), math) == pytest.approx(
        platform.leg_lengths(x), rel=1e-15, abs=0)


def test_export_refuses_bad_arguments(tmp_path):
    params = stewart.PlatformParams.preset("narayan2017")
    for dt in (0.0, -1.0, math.inf, math.nan):
        with pytest.raises(ValueError, match="dt"):
            acados_export.export(tmp_path, params, dt)
    with pytest.raises(ValueError, match="dt"):
        acados_export.export(tmp_path, params, "x")
    with pytest.raises(ValueError, match="integrator"):
        acados_export.export(tmp_path, params, 0.01, "euler")
    with pytest.raises(TypeError, match="params"):
        acados_export.export(tmp_path, "narayan2017", 0.01)
    with pytest.raises(ValueError, match="directory"):
        acados_export.export(tmp_path / "a b", params, 0.01)
    assert not (tmp_path / "a b").exists() and not list(tmp_path.iterdir())


def _run(args):
    done = subprocess.run([sys.executable, "-m", "stewart", "export-acados", *args], capture_output=True, text=True)
    return done.returncode, done.stdout, done.stderr


def test_cli_writes_the_export(tmp_path):
    code, out, err = _run([str(tmp_path / "e"), "--preset", "motion_simulator", "--dt", "0.02"])
    assert code == 0, err
    assert f"wrote {tmp_path / 'e' / acados_export.SOURCE}" in out
    assert json.loads((tmp_path / "e" / acados_export.SETTINGS_FILE).read_text())["dt"] == 0.02
    assert stewart.PlatformParams.load(tmp_path / "e" / acados_export.PARAMS_FILE) == \
        stewart.PlatformParams.preset("motion_simulator")


def test_cli_user_mistakes_are_one_line_and_exit_2(tmp_path):
    (tmp_path / "file").write_text("")
    code, _, err = _run([str(tmp_path / "file"), "--dt", "0.01"])
    assert code == 2 and "not a directory" in _one_error_line(err, f"DIR {tmp_path / 'file'}: ")
    code, _, err = _run([str(tmp_path / "a b"), "--dt", "0.01"])
    assert code == 2 and "no spaces" in _one_error_line(err, f"DIR {tmp_path / 'a b'}: ")
    for bad in (["--dt", "0"], ["--dt", "nan"], ["--dt", "0.01", "--integrator", "euler"], []):
        code, _, err = _run([str(tmp_path / "d"), *bad])
        assert code == 2 and err.strip().splitlines()[-1].startswith("stewart export-acados: error: "), err
        assert ("--dt" in err) or ("--integrator" in err)
        assert "Traceback" not in err
    assert not (tmp_path / "d").exists() and not (tmp_path / "a b").exists()


def test_stewart_acados_imports_without_acados_and_says_where_it_is(tmp_path):
    """make test's environment has no acados: the module imports, reads an export and checks
    its arguments, and its first call into acados names the environment that has it."""
    import importlib.util

    import stewart.acados as nmpc

    if importlib.util.find_spec("acados") is None and importlib.util.find_spec("acados_template") is None:
        with pytest.raises(ImportError, match="make acados-env"):
            nmpc.template()
    params = stewart.PlatformParams.preset("narayan2017")
    acados_export.export(tmp_path, params, 0.02)
    export = nmpc.load(tmp_path)
    assert export.params == params and export.dt == 0.02 and export.functions == acados_export.FUNCTIONS
    assert export.compile_flags == acados_export.compile_flags(tmp_path)
    with pytest.raises(FileNotFoundError, match="export-acados"):
        nmpc.load(tmp_path / "missing")
    weights = nmpc.Weights(position=4.0, angle=3.0, rate=2.0, force=1.0, terminal=10.0)
    assert np.array_equal(np.diag(weights.stage()), [4.0] * 3 + [3.0] * 3 + [2.0] * 6 + [1.0] * 6)
    assert np.array_equal(np.diag(weights.final()), [40.0] * 3 + [30.0] * 3 + [20.0] * 6)
    for bad in ({"position": -1.0}, {"angle": math.inf}, {"rate": math.nan}, {"force": 0.0}, {"terminal": "x"}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            nmpc.Weights(**bad)
