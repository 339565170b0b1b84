"""The portable build: the copies of the model compiled for each instruction set, the choice
between them at import (``STEWART_SIMD``), ``stewart.build_info()``, and (``ports``: make
test-ports, as it compiles the package again) a build with the baseline flags only and without
OpenMP (its batches on plain threads)."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from c_example import CFLAGS, run_command

import stewart
from stewart._kernel import SIMD_VARIABLE

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "tests" / "simd_paths.py"
INFO = stewart.build_info()
#: The model's rounding flags (STEWART_ROUNDING_FLAGS of the generated header), in every path's flags.
ROUNDING = " ".join(stewart.io.capi.c_flags())


def run_python(args, env, cwd=None) -> str:
    """Run this Python with ``args`` in the environment ``env``; its output (a non-zero exit
    fails with all it printed)."""
    done = subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, env=env, cwd=cwd)
    assert done.returncode == 0, f"{args}: exit {done.returncode}\n{done.stdout}{done.stderr}"
    return done.stdout


def run_paths(out, path=None, threads=1, cwd=None, env=None):
    """simd_paths.py's arrays, run in a subprocess (with STEWART_SIMD=path)."""
    env = dict(os.environ if env is None else env)
    env.pop(SIMD_VARIABLE, None)
    if path is not None:
        env[SIMD_VARIABLE] = path
    run_python([SCRIPT, out, threads], env, cwd)
    with np.load(out) as data:
        return {name: data[name] for name in data.files}


def assert_same_results(result, expected):
    """Same masks, same errors, the same outputs bit for bit (NaN rows included)."""
    assert result.keys() == expected.keys()
    for name in expected:
        if name == "build_info":
            continue
        got, want = result[name], expected[name]
        assert got.shape == want.shape and got.tobytes() == want.tobytes(), name


@pytest.fixture(scope="module")
def baseline(tmp_path_factory):
    return run_paths(tmp_path_factory.mktemp("paths") / "baseline.npz", INFO["compiled"][0])


def test_build_info_describes_the_compiled_paths():
    assert INFO["compiled"] and INFO["supported"]
    assert set(INFO["supported"]) <= set(INFO["compiled"])
    # The copy that runs everywhere is compiled in and runs here; without STEWART_SIMD the
    # kernel runs the most capable path this CPU supports.
    assert INFO["compiled"][0] in INFO["supported"]
    if SIMD_VARIABLE not in os.environ:
        assert INFO["simd"] == INFO["supported"][-1]
    assert INFO["flags"].keys() == set(INFO["compiled"])
    assert isinstance(INFO["openmp"], bool) and INFO["compiler"]


def test_the_singular_rows_fail_as_expected(baseline):
    """The comparison below covers failing rows: they are there."""
    assert not baseline["inverse_dynamics.mask"][17] and baseline["inverse_dynamics.mask"][5]
    assert not baseline["forward_dynamics.mask"][5]
    assert baseline["forward_dynamics.mask"].sum() == len(baseline["forward_dynamics.mask"]) - 2
    assert "row(s) [5, 17]" in str(baseline["forward_dynamics.error"])


@pytest.mark.slow
@pytest.mark.parametrize("path", INFO["supported"][1:])
def test_each_path_agrees_with_the_baseline(path, baseline, tmp_path):
    result = run_paths(tmp_path / f"{path}.npz", path)
    assert json.loads(str(result["build_info"]))["simd"] == path
    assert_same_results(result, baseline)


@pytest.mark.parametrize("command", [["-c", "from stewart import Platform"], ["-m", "stewart", "info"]], ids=["import", "cli"])
@pytest.mark.parametrize("value", ["sse1", "AVX2", " "])
def test_an_unknown_path_is_a_one_line_error_naming_the_valid_ones(command, value):
    """At the compiled model's import and from the command: stderr is one line naming STEWART_SIMD and every path
    this CPU runs, exit code 2, no traceback."""
    env = dict(os.environ, **{SIMD_VARIABLE: value})
    proc = subprocess.run([sys.executable, *command], env=env, capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stdout == "" and "Traceback" not in proc.stderr
    line, = proc.stderr.splitlines()
    assert line.startswith(f"stewart: error: {SIMD_VARIABLE}={value!r} names no path of this build;")
    assert line.endswith("valid values: " + ", ".join(INFO["supported"]) + " (or unset: the best this CPU runs)")


def test_the_dispatch_header_compiles_on_its_own(tmp_path):
    """stewart_dispatch.h, with and without the list of copies, under the strictest flags."""
    source = tmp_path / "use.c"
    source.write_text('#include "stewart_dispatch.h"\n'
                      'int main(void) { return stewart_tables[0] == NULL || !stewart_cpu_supports(""); }\n')
    run_command([os.environ.get("CC", "cc"), *CFLAGS, "-fsyntax-only", "-DSTEWART_TABLES=X(baseline)",
                 f"-I{ROOT / 'generated'}", source])
    source.write_text('#include "stewart_dispatch.h"\nint main(void) { return STEWART_OPENMP; }\n')
    run_command([os.environ.get("CC", "cc"), *CFLAGS, "-fsyntax-only", f"-I{ROOT / 'generated'}", source])


def test_the_dispatch_header_carries_its_template():
    template = (ROOT / "codegen" / "templates" / "dispatch" / "dispatch.h").read_text()
    assert template in (ROOT / "generated" / "stewart_dispatch.h").read_text()


#: The part of the suite run against the baseline build without OpenMP.
SUBSET = ["tests/test_kernel.py", "tests/test_robustness.py", "tests/test_simulation.py"]


@pytest.fixture(scope="module")
def baseline_tree(tmp_path_factory):
    """A copy of the source files built with the baseline flags only (STEWART_MARCH=x86-64,
    one copy of the model) and without OpenMP (STEWART_OPENMP=0)."""
    from test_packaging import source_files

    tree = tmp_path_factory.mktemp("baseline-build")
    for name in source_files():
        (tree / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, tree / name)
    env = dict(os.environ, STEWART_MARCH="x86-64", STEWART_OPENMP="0")
    run_python(["setup.py", "-q", "build_ext", "-b", "."], env, tree)
    return tree


def _tree_env(tree):
    """The environment that imports stewart from ``tree`` (ahead of the checkout's)."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    env.pop(SIMD_VARIABLE, None)
    return env


@pytest.mark.ports
def test_baseline_build_without_openmp(baseline_tree):
    info = json.loads(run_python(["-c", "import json, stewart; print(json.dumps(stewart.build_info()))"],
                                 _tree_env(baseline_tree), baseline_tree))
    assert info["compiled"] == ["x86_64"] and info["simd"] == "x86_64"
    assert info["flags"] == {"x86_64": f"-O3 -g0 {ROUNDING} -march=x86-64"}
    assert info["openmp"] is False


@pytest.mark.ports
def test_baseline_build_plain_threads_agree_with_the_portable_build(baseline_tree, baseline, tmp_path):
    """Batches split over two plain threads give the portable baseline's results."""
    result = run_paths(tmp_path / "threads.npz", threads=2, cwd=baseline_tree, env=_tree_env(baseline_tree))
    assert json.loads(str(result["build_info"]))["simd"] == "x86_64"
    assert_same_results(result, baseline)


@pytest.mark.ports
def test_baseline_build_runs_the_suite_subset(baseline_tree):
    out = run_python(["-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider", "-m", "not slow", *SUBSET],
                     _tree_env(baseline_tree), baseline_tree)
    assert " passed" in out and " failed" not in out
