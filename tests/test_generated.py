"""generated/ is exactly what the generator writes now (same files, same bytes).

The generator runs once, into a temporary directory; the committed files came from an
earlier run, so a match also shows that the output does not depend on the run.
"""

import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def output(tmp_path_factory):
    """The directory the generator has just written."""
    out = tmp_path_factory.mktemp("generated")
    subprocess.run([sys.executable, "-m", "codegen", "--out", str(out)],
                   cwd=ROOT, check=True, capture_output=True, text=True)
    return out


def test_generator_writes_the_committed_files(output):
    assert sorted(p.name for p in output.iterdir()) == sorted(p.name for p in (ROOT / "generated").iterdir())


@pytest.mark.parametrize("name", sorted(p.name for p in (ROOT / "generated").iterdir()))
def test_generated_file_is_fresh(output, name):
    assert (output / name).read_bytes() == (ROOT / "generated" / name).read_bytes(), (
        f"generated/{name} is stale: run `make generate` and commit the result"
    )
