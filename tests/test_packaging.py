"""The sdist and the wheel install, and work, outside the checkout.

From a copy of the source files — a git checkout's tracked files, or an unpacked sdist's
own file list — and nothing else (no ``.venv``, build products or outputs), ``python -m
build`` builds the sdist and then the wheel from that sdist, with build isolation, as
``pip install stewart-*.tar.gz`` does: so the sdist is proven to build on its own, and the
source is compiled once. The isolated build environments and the fresh environment are
set up by uv (the dev extra's ``build[uv]``), which installs the same wheels as pip in a
fraction of the time. The sdist is the complete source, so ``make test`` also runs from
it. The wheel goes into a fresh virtual environment, where ``installed_smoke.py`` runs from
a directory outside the checkout. Marked ``packaging``: ``pytest -m "not packaging"``
leaves it out.
"""

import json
import shutil
import sys
import sysconfig
import tarfile
import zipfile
from pathlib import Path

import pytest
from c_example import run_command
from uv import find_uv_bin

pytestmark = pytest.mark.packaging

ROOT = Path(__file__).resolve().parent.parent
UV = find_uv_bin()
#: What a build needs, as paths inside the sdist (after its ``stewart-<version>/`` prefix).
SDIST_NEEDS = {"setup.py", "pyproject.toml", "MANIFEST.in", "README.md", "LICENSE",
               "stewart/_kernel.pyx", "stewart/_kernel.pxd", "stewart/_simulate.pyx", "stewart/_envelope.pyx",
               "generated/stewart_model.h", "generated/stewart_model.c", "generated/stewart_model.pxd",
               "generated/stewart_dispatch.h", "generated/stewart_target.c"}
#: Cython's C translation of the .pyx: written at build time, shipped in neither.
CYTHON_OUTPUT = {"stewart/_kernel.c", "stewart/_simulate.c", "stewart/_envelope.c"}


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


@pytest.fixture(scope="module")
def dists(tree, tmp_path_factory):
    """``(sdist, wheel, python)``: the distributions, the wheel built from the sdist, and the
    Python of a fresh virtual environment holding the wheel."""
    out, env = tmp_path_factory.mktemp("dist"), tmp_path_factory.mktemp("env")
    run_command([sys.executable, "-m", "build", "--installer=uv", "--outdir", out, tree])
    (sdist,), (wheel,) = out.glob("*.tar.gz"), out.glob("*.whl")
    run_command([UV, "venv", "-q", "--python", sys.executable, env])
    python = env / "bin" / "python"
    run_command([UV, "pip", "install", "-q", "--python", python, wheel])
    return sdist, wheel, python


def test_sdist_is_the_complete_source_and_nothing_else(dists):
    with tarfile.open(dists[0]) as sdist:
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
    # Tagged for the plain platform it was built on (not manylinux: not audited for it).
    assert dists[1].name.endswith(f"-{sysconfig.get_platform().replace('-', '_').replace('.', '_')}.whl")
    with zipfile.ZipFile(dists[1]) as wheel:
        names = set(wheel.namelist())
    assert {"stewart/generated/stewart_model.h", "stewart/generated/stewart_model.c"} <= names
    assert not names & CYTHON_OUTPUT
    assert not [n for n in names if n.endswith((".pyx", ".pxd", ".html"))]
    for module in ("_kernel", "_simulate", "_envelope"):
        assert [n for n in names if n.startswith(f"stewart/{module}.") and n.endswith(".so")], module
    assert [n for n in names if n.endswith(".dist-info/licenses/LICENSE")]


def test_installs_and_runs_outside_the_checkout(dists, tree, tmp_path):
    python = dists[2]
    assert "smoke test passed" in run_command([python, tree / "tests" / "installed_smoke.py"], cwd=tmp_path)


def test_wheel_is_portable(dists, tmp_path):
    """The wheel carries the portable build's copies of the model, as the checkout's build
    does (STEWART_MARCH unset), and runs the best one this CPU supports."""
    import stewart

    info = json.loads(run_command([dists[2], "-c", "import json, stewart; print(json.dumps(stewart.build_info()))"],
                                  cwd=tmp_path))
    assert info["compiled"] == stewart.build_info()["compiled"]
    assert info["simd"] == info["supported"][-1]
