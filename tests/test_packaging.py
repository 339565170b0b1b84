"""The sdist and the wheel install, and work, outside the checkout, on each supported Python.

From a copy of the source files — a git checkout's tracked files, or an unpacked sdist's
own file list — and nothing else (no ``.venv``, build products or outputs), setuptools'
build backend builds the sdist once, in this environment; the copy also holds the
checkout's Cython output (``stewart/_*.c``, when the build wrote it and it is newer than
its ``.pyx``), so that setup.py's ``cythonize`` finds it up to date instead of translating
the ``.pyx`` again, and the sdist must still leave it out. ``make test`` checks that
sdist's contents: the complete source and nothing else (so ``make test`` also runs from
it).

The wheel tests (marked ``packaging``: ``make test-wheels``, which CI runs through ``make
test-ports``) then build a wheel from that sdist for each Python under test, with build
isolation: so the sdist is proven to build on its own, and the source is compiled once per
Python. The isolated build environments and the fresh environments are set up by uv (the
dev extra's ``build[uv]``), which installs the same wheels as pip in a fraction of the
time. Each wheel goes into a fresh virtual environment of its Python, where
``installed_smoke.py`` runs from a directory outside the checkout.

The Pythons under test (``STEWART_WHEEL_PYTHONS``): unset, the running one; ``all`` (``make
test-wheels``), every supported version and the running one; ``others``, each supported
version but the running one; or versions such as ``3.12 3.13``. A version is found as ``python3.X`` on the PATH or
among pyenv's versions; one not found is skipped (``python3.X not found``). The wheel of a
Python other than the running one is built by ``python -m build`` of that Python, from a
fresh environment with the same ``build[uv]``.
"""
import json
import os
import platform
import re
import shutil
import sys
import sysconfig
import tarfile
import zipfile
from importlib.metadata import version as installed_version
from pathlib import Path

import pytest
from c_example import run_command
from uv import find_uv_bin

ROOT = Path(__file__).resolve().parent.parent
UV = find_uv_bin()
#: The Python versions the package supports (pyproject.toml's requires-python and the wheels tested).
SUPPORTED = ("3.11", "3.12", "3.13")
RUNNING = "%d.%d" % sys.version_info[:2]
#: What a build needs, as paths inside the sdist (after its ``stewart-<version>/`` prefix).
SDIST_NEEDS = {"setup.py", "pyproject.toml", "MANIFEST.in", "README.md", "LICENSE", "mkdocs.yml", "docs/index.md",
               "docs/api.md",
               "stewart/_kernel.pyx", "stewart/_kernel.pxd", "stewart/_simulate.pxi", "stewart/_envelope.pxi",
               "generated/stewart_model.h", "generated/stewart_model.c", "generated/stewart_model.pxd",
               "generated/stewart_dispatch.h", "generated/stewart_target.c"}
#: Cython's C translation of the .pyx: written at build time, shipped in neither.
CYTHON_OUTPUT = {"stewart/_kernel.c"}


#: Files setuptools adds to an sdist: its metadata.
SDIST_METADATA = {"PKG-INFO", "setup.cfg"}


def source_files() -> list[str]:
    """The source files: a git checkout's tracked files, or the list an unpacked sdist carries
    in ``stewart.egg-info/SOURCES.txt`` (less its metadata)."""
    try:
        listed = [name for name in run_command(["git", "ls-files", "-z"], cwd=ROOT).split("\0") if name]
    except (OSError, AssertionError):
        listed = []
    if listed:
        return [name for name in listed if (ROOT / name).is_file()]  # not a tracked file deleted here
    sources = ROOT / "stewart.egg-info" / "SOURCES.txt"
    if (ROOT / "PKG-INFO").is_file() and sources.is_file():
        return [name for name in sources.read_text().splitlines()
                if name and name not in SDIST_METADATA and not name.startswith("stewart.egg-info/")]
    pytest.fail(f"{ROOT} is neither a git checkout nor an unpacked sdist: no list of its source files")


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    """A copy of the source files, as a fresh clone or a fresh unpacked sdist has them, and
    the checkout's Cython output where it is up to date (:data:`CYTHON_OUTPUT`: setup.py's
    ``cythonize`` then leaves it alone, as it does in the checkout)."""
    copy = tmp_path_factory.mktemp("tree")
    for name in source_files():
        (copy / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, copy / name)
    for name in CYTHON_OUTPUT:
        output, source = ROOT / name, ROOT / name.replace(".c", ".pyx")
        if output.is_file() and output.stat().st_mtime >= source.stat().st_mtime:
            shutil.copy2(output, copy / name)  # with its time, so still newer than its sources
    return copy


def wheel_pythons() -> list[str]:
    """The Python versions under test (STEWART_WHEEL_PYTHONS: unset, the running one; ``all``,
    every supported version and the running one; ``others``, the supported versions but the
    running one; or a list of versions)."""
    chosen = os.environ.get("STEWART_WHEEL_PYTHONS", "").split()
    if not chosen:
        return [RUNNING]
    if chosen == ["all"]:
        return sorted({*SUPPORTED, RUNNING}, key=lambda v: tuple(map(int, v.split("."))))
    if chosen == ["others"]:
        return [v for v in SUPPORTED if v != RUNNING]
    return chosen


def find_python(version: str) -> str | None:
    """The interpreter (its ``sys.executable``) of Python ``version``: ``python<version>`` on the
    PATH if it runs (a pyenv shim of a version not selected does not), else pyenv's newest
    ``<version>.*``; None if neither is here."""
    pyenv = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv")) / "versions"
    found = sorted(pyenv.glob(f"{version}.*/bin/python{version}"),
                   key=lambda p: [int(n) for n in re.findall(r"\d+", p.parent.parent.name)], reverse=True)
    for candidate in [shutil.which(f"python{version}"), *found]:
        if not candidate:
            continue
        try:
            executable, got = run_command(
                [candidate, "-c", "import sys; print(sys.executable); print('%d.%d' % sys.version_info[:2])"]).split()
        except (OSError, AssertionError, ValueError):
            continue
        if got == version:
            return executable
    return None


@pytest.fixture(scope="module")
def sdist(tree, tmp_path_factory):
    """The sdist, built from the copy of the source files by setuptools' build backend in this
    environment (which has the build requirements: the Makefile installs them), as ``python
    -m build --sdist --no-isolation`` does but running setup.py once, not twice."""
    out = tmp_path_factory.mktemp("sdist")
    run_command([sys.executable, "-c", "import sys; from setuptools import build_meta; build_meta.build_sdist(sys.argv[1])",
                 out], cwd=tree)
    (built,) = out.glob("*.tar.gz")
    return built


def build_frontend(python: str, where: Path) -> str:
    """The Python that runs ``python -m build`` for ``python``: this one, or a fresh environment
    of ``python`` with the same build[uv] as this one's."""
    if python == sys.executable:
        return python
    run_command([UV, "venv", "-q", "--python", python, where])
    frontend = where / "bin" / "python"
    run_command([UV, "pip", "install", "-q", "--python", frontend, f"build[uv]=={installed_version('build')}"])
    return str(frontend)


@pytest.fixture(scope="module", params=wheel_pythons(), ids=lambda version: f"python{version}")
def dists(request, sdist, tmp_path_factory):
    """``(wheel, python, version)`` for one Python version: the wheel built from the sdist by that
    Python, and the Python of a fresh virtual environment holding the wheel."""
    version = request.param
    interpreter = sys.executable if version == RUNNING else find_python(version)
    if interpreter is None:
        pytest.skip(f"python{version} not found")
    out, env = tmp_path_factory.mktemp("wheel"), tmp_path_factory.mktemp("env")
    frontend = build_frontend(interpreter, tmp_path_factory.mktemp("frontend"))
    run_command([frontend, "-m", "build", "--wheel", "--installer=uv", "--outdir", out, sdist])
    (wheel,) = out.glob("*.whl")
    run_command([UV, "venv", "-q", "--python", interpreter, env])
    python = env / "bin" / "python"
    run_command([UV, "pip", "install", "-q", "--python", python, wheel])
    return wheel, python, version


@pytest.mark.slow
def test_sdist_is_the_complete_source_and_nothing_else(sdist):
    with tarfile.open(sdist) as archive:
        names = {member.name.split("/", 1)[1] for member in archive.getmembers()
                 if "/" in member.name and not member.isdir()}
    assert SDIST_NEEDS <= names, sorted(SDIST_NEEDS - names)
    assert not names & CYTHON_OUTPUT
    # Every source file (so make test and make demo run from the unpacked sdist), and
    # nothing else but setuptools' metadata: no outputs, environments or build products.
    sources = set(source_files())
    metadata = {n for n in names if n in SDIST_METADATA or n.startswith("stewart.egg-info/")}
    assert names - metadata == sources, (sorted(names - metadata - sources), sorted(sources - names))


@pytest.mark.packaging
def test_wheel_holds_the_c_model_and_no_cython_output(dists):
    # For its Python, tagged for the plain platform it was built on (not manylinux: not audited for it).
    tag = "cp" + dists[2].replace(".", "")
    assert dists[0].name.endswith(f"-{tag}-{tag}-{sysconfig.get_platform().replace('-', '_').replace('.', '_')}.whl")
    with zipfile.ZipFile(dists[0]) as wheel:
        names = set(wheel.namelist())
    assert {"stewart/generated/stewart_model.h", "stewart/generated/stewart_model.c"} <= names
    assert not names & CYTHON_OUTPUT
    assert not [n for n in names if n.endswith((".pyx", ".pxi", ".pxd", ".html"))]
    assert [n for n in names if n.startswith("stewart/_kernel.") and n.endswith(".so")]
    assert [n for n in names if n.endswith(".dist-info/licenses/LICENSE")]


@pytest.mark.packaging
def test_installs_and_runs_outside_the_checkout(dists, tree, tmp_path):
    python, version = dists[1:]
    printed = run_command([python, tree / "tests" / "installed_smoke.py"], cwd=tmp_path)
    assert "smoke test passed" in printed and f" on Python {version}." in printed, printed


@pytest.mark.packaging
def test_wheel_is_portable(dists, tmp_path):
    """The wheel carries the portable build's copies of the model -- every x86-64 copy with
    STEWART_TARGETS=all (make test-wheels), else those this CPU runs, as the checkout's build
    (STEWART_MARCH unset) -- and runs the best one this CPU supports."""
    import stewart

    info = json.loads(run_command([dists[1], "-c", "import json, stewart; print(json.dumps(stewart.build_info()))"],
                                  cwd=tmp_path))
    every = os.environ.get("STEWART_TARGETS") == "all" and platform.machine() in ("x86_64", "AMD64")
    assert info["compiled"] == (["baseline", "avx2", "avx512"] if every else stewart.build_info()["compiled"])
    assert info["supported"] == stewart.build_info()["supported"]
    assert info["simd"] == info["supported"][-1]
