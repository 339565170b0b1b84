"""Every Python example of ``examples/`` runs: each as its own process, from the repository
root as its docstring says, with the arguments of :data:`RUNS`. (The example's data files are
read by the documentation's commands, ``tests/test_readme.py``; the C example is built and run
by ``tests/test_capi.py``.)"""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
if not EXAMPLES.is_dir():
    pytest.skip("needs the checkout (examples/)", allow_module_level=True)

#: Each example's arguments (``{out}``: a fresh directory) and what its output must show.
RUNS = {
    "identification.py": (["--short", "--out", "{out}"], ["estimates within 2 standard errors of the truth",
                                                          "held-out RMS error, identified [N]", "wrote "]),
}


def test_every_example_has_a_run():
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(RUNS)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(RUNS))
def test_example_runs(name, tmp_path):
    pytest.importorskip("matplotlib")
    arguments, expected = RUNS[name]
    argv = [a.format(out=tmp_path / "out") for a in arguments]
    run = subprocess.run([sys.executable, str(EXAMPLES / name), *argv], cwd=ROOT, capture_output=True, text=True,
                         env={**os.environ, "MPLBACKEND": "Agg"}, timeout=600)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    for text in expected:
        assert text in run.stdout, text
    assert any((tmp_path / "out").glob("*.png"))
