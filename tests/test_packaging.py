"""The sdist and the wheel install, and work, outside the checkout.

From a copy of the source files — a git checkout's tracked files, or an unpacked sdist's
own file list — and nothing else (no ``.venv``, build products or outputs), ``python -m
build`` builds the sdist and the wheel. The sdist is the complete source, so ``make test``
also runs from it. The wheel goes
into a fresh virtual environment; the sdist into another through
``pip install stewart-*.tar.gz``, which builds it with build isolation, as a user's pip does,
so the sdist is proven to build on its own. The two compilations run side by side.
``installed_smoke.py`` then runs in each environment, from a directory outside the checkout.
Marked ``packaging``: ``pytest -m "not packaging"`` leaves it out.
"""

import shutil
import sys
import tarfile
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from c_example import run_command

pytestmark = pytest.mark.packaging

ROOT = Path(__file__).resolve().parent.parent
#: What a build needs, as paths inside the sdist (after its ``stewart-<version>/`` prefix).
SDIST_NEEDS = {"setup.py", "pyproject.toml", "MANIFEST.in", "README.md", "LICENSE",
               "stewart/_kernel.pyx", "stewart/_kernel.pxd", "stewart/_simulate.pyx",
               "generated/stewart_model.h", "generated/stewart_model.c", "generated/stewart_model.pxd"}
#: Cython's C translation of the .pyx: written at build time, shipped in neither.
CYTHON_OUTPUT = {"stewart/_kernel.c", "stewart/_simulate.c"}


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
    """A copy of the source files, as a fresh clone or a fresh unpacked sdist has them."""
    copy = tmp_path_factory.mktemp("tree")
    for name in source_files():
        (copy / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, copy / name)
    return copy


def _environment(directory: Path, dist: Path) -> Path:
    """A fresh virtual environment with ``dist`` installed; its Python."""
    run_command([sys.executable, "-m", "venv", directory])
    python = directory / "bin" / "python"
    run_command([python, "-m", "pip", "install", "-q", dist])
    return python


@pytest.fixture(scope="module")
def dists(tree, tmp_path_factory):
    """``{"sdist": (file, python), "wheel": (file, python)}``: each distribution and the
    Python of a fresh environment holding it."""
    out, envs = tmp_path_factory.mktemp("dist"), tmp_path_factory.mktemp("envs")
    run_command([sys.executable, "-m", "build", "--sdist", "--outdir", out, tree])
    (sdist,) = out.glob("*.tar.gz")
    with ThreadPoolExecutor() as pool:
        from_sdist = pool.submit(_environment, envs / "sdist", sdist)
        run_command([sys.executable, "-m", "build", "--wheel", "--outdir", out, tree])
        (wheel,) = out.glob("*.whl")
        return {"wheel": (wheel, _environment(envs / "wheel", wheel)), "sdist": (sdist, from_sdist.result())}


def test_sdist_is_the_complete_source_and_nothing_else(dists):
    with tarfile.open(dists["sdist"][0]) as sdist:
        names = {member.name.split("/", 1)[1] for member in sdist.getmembers()
                 if "/" in member.name and not member.isdir()}
    assert SDIST_NEEDS <= names, sorted(SDIST_NEEDS - names)
    assert not names & CYTHON_OUTPUT
    # Every source file (so make test and make demo run from the unpacked sdist), and
    # nothing else but setuptools' metadata: no outputs, environments or build products.
    sources = set(source_files())
    metadata = {n for n in names if n in SDIST_METADATA or n.startswith("stewart.egg-info/")}
    assert names - metadata == sources, (sorted(names - metadata - sources), sorted(sources - names))


def test_wheel_holds_the_c_model_and_no_cython_output(dists):
    with zipfile.ZipFile(dists["wheel"][0]) as wheel:
        names = set(wheel.namelist())
    assert {"stewart/generated/stewart_model.h", "stewart/generated/stewart_model.c"} <= names
    assert not names & CYTHON_OUTPUT
    assert not [n for n in names if n.endswith((".pyx", ".pxd", ".html"))]
    for module in ("_kernel", "_simulate"):
        assert [n for n in names if n.startswith(f"stewart/{module}.") and n.endswith(".so")], module
    assert [n for n in names if n.endswith(".dist-info/licenses/LICENSE")]


@pytest.mark.parametrize("kind", ["wheel", "sdist"])
def test_installs_and_runs_outside_the_checkout(dists, tree, kind, tmp_path):
    _, python = dists[kind]
    assert "smoke test passed" in run_command([python, tree / "tests" / "installed_smoke.py"], cwd=tmp_path)
