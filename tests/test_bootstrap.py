"""The bootstrap of a fresh checkout: ``make`` builds the package without build isolation, so
uv installs none of its build requirements, and the Makefile installs them first from
pyproject.toml's ``[build-system] requires``. A package that the extension's sources cimport
but that list leaves out builds only where a warm cache happens to have it."""

import re
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
REQUIRES = tomllib.loads((ROOT / "pyproject.toml").read_text())["build-system"]["requires"]
#: What Cython itself provides to a cimport.
CYTHON_OWN = {"cython", "cpython", "libc", "libcpp", "posix"}


def _name(requirement: str) -> str:
    return re.match(r"[A-Za-z0-9_.-]+", requirement).group(0).lower()


def _make(tmp_path, *args) -> str:
    venv = tmp_path / "venv"
    done = subprocess.run(["make", "--no-print-directory", "-C", str(ROOT), f"VENV={venv}", f"PY={sys.executable}",
                           *[a.replace("VENV", str(venv)) for a in args]], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def test_the_bootstrap_installs_the_build_requirements_of_pyproject(tmp_path):
    (tmp_path / "venv").mkdir()
    _make(tmp_path, "VENV/build-requires.txt")
    assert (tmp_path / "venv" / "build-requires.txt").read_text().split("\n")[:-1] == REQUIRES


def test_the_build_requirements_are_installed_before_the_editable_build(tmp_path):
    commands = _make(tmp_path, "-n", "VENV/.installed").splitlines()
    installs = [i for i, line in enumerate(commands) if " pip install " in line]
    requirements = [i for i in installs if f"-r {tmp_path / 'venv' / 'build-requires.txt'}" in commands[i]]
    editable = [i for i in installs if "--no-build-isolation -e" in commands[i]]
    assert len(requirements) == 1 and len(editable) == 1 and requirements[0] < editable[0], commands


def test_every_cimported_package_is_a_build_requirement():
    sources = [*ROOT.glob("stewart/*.pyx"), *ROOT.glob("stewart/*.pxi"), *ROOT.glob("stewart/*.pxd")]
    cimported = set()
    for source in sources:
        for line in source.read_text().splitlines():
            match = re.match(r"\s*(?:from\s+([\w.]+)\s+cimport|cimport\s+([\w.]+))", line)
            if match:
                cimported.add((match.group(1) or match.group(2)).split(".")[0].lower())
    assert "scipy" in cimported and "numpy" in cimported  # the test reads the sources it guards
    own = {pxd.stem for pxd in [*ROOT.glob("stewart/*.pxd"), *ROOT.glob("generated/*.pxd")]}
    assert cimported - CYTHON_OWN - own <= {_name(r) for r in REQUIRES}
