"""Smoke test of an installed stewart, outside the source tree.

The packaging check (``test_packaging.py``) runs it with the Python of a fresh virtual
environment holding the wheel built from the sdist (one for each Python under test), from
a directory outside the checkout::

    python tests/installed_smoke.py

It checks that the package imported is the installed one, its dynamics against the
numeric reference, the C files it carries (the C example compiled against them) and the
``stewart`` command.
"""

import re
import sys
import tempfile
from pathlib import Path

import numpy as np

import stewart
from c_example import check_example, run_command
from stewart.io import capi
from stewart.oracles import validation

PRESET = "narayan2017"


def _command(*args: str) -> str:
    return run_command([Path(sys.executable).parent / "stewart", *args])


def main() -> None:
    installed = Path(stewart.__file__).resolve()
    assert installed.is_relative_to(Path(sys.prefix).resolve()), f"imported {installed}, not from {sys.prefix}"

    params = stewart.PlatformParams.preset(PRESET)
    checks = validation.run(params, n_states=50)
    names = {check.name for check in checks}
    assert {"kernel vs reference: inverse dynamics", "kernel vs reference: forward dynamics"} <= names
    failed = [check for check in checks if not check.passed]
    assert not failed, f"checks failed: {failed}"

    include = Path(stewart.c_include_dir()).resolve()
    assert include.is_relative_to(Path(sys.prefix).resolve()), f"C files in {include}, not in {sys.prefix}"
    with tempfile.TemporaryDirectory() as tmp:
        Path(tmp, capi.PARAMS_HEADER).write_text(capi.params_header(params), encoding="ascii")
        check_example(params, [include, tmp], stewart.c_sources(), tmp)

    assert "usage" in _command("--help")
    pose = [0.0, 0.0, 0.3, 0.0, 0.0, 0.0]
    printed = [float(v) for v in re.findall(r"[-+]?\d+\.\d+(?:[eE][-+]?\d+)?", _command(
        "ik", "--preset", PRESET, "--pose", *map(str, pose)))]
    lengths = stewart.leg_lengths(params, np.array(pose))
    assert all(np.isclose(printed, length, rtol=1e-6, atol=0).any() for length in lengths), (printed, lengths)
    print(f"stewart {stewart.__version__} on Python {sys.version.split()[0]} from {installed.parent}: smoke test passed")


if __name__ == "__main__":
    main()
