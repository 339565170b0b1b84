"""Every Python example of ``examples/`` runs: each as its own process, from the repository
root as its docstring says, with the arguments of :data:`RUNS`. (The example's data files are
read by the documentation's commands, ``tests/test_readme.py``; the C example is built and run
by ``tests/test_capi.py``.)"""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
if not EXAMPLES.is_dir():
    pytest.skip("needs the checkout (examples/)", allow_module_level=True)

#: Each example's arguments (``{out}``: a fresh directory), what its output must show and the
#: files it writes into ``{out}``.
RUNS = {
    "identification.py": (["--short", "--out", "{out}"], ["estimates within 2 standard errors of the truth",
                                                          "held-out RMS error, identified [N]", "wrote "], "*.png"),
    "calibration.py": (["--out", "{out}"], ["wrote "], "*.csv"),
}


def test_every_example_has_a_run():
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(RUNS)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(RUNS))
def test_example_runs(name, tmp_path):
    pytest.importorskip("matplotlib")
    arguments, expected, written = RUNS[name]
    argv = [a.format(out=tmp_path / "out") for a in arguments]
    run = subprocess.run([sys.executable, str(EXAMPLES / name), *argv], cwd=ROOT, capture_output=True, text=True,
                         env={**os.environ, "MPLBACKEND": "Agg"}, timeout=600)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    for text in expected:
        assert text in run.stdout, text
    assert any((tmp_path / "out").glob(written))
    # the measurement files shipped are the ones it writes, to the last digits (reached 0 here;
    # another machine's libm and BLAS may change the last of the 17)
    if name == "calibration.py":
        for path in sorted((EXAMPLES / "calibration").iterdir()):
            np.testing.assert_allclose(np.loadtxt(tmp_path / "out" / path.name, delimiter=",", skiprows=2),
                                       np.loadtxt(path, delimiter=",", skiprows=2), rtol=1e-12, atol=0)
