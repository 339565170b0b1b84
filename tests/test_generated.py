"""generated/ and stewart/_generated.py are exactly what the generator writes now (same files,
same bytes).

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
    subprocess.run([sys.executable, "-m", "codegen", "--out", str(out / "generated"),
                    "--python", str(out / "_generated.py")],
                   cwd=ROOT, check=True, capture_output=True, text=True)
    return out / "generated"


def test_generator_writes_the_committed_files(output):
    assert sorted(p.name for p in output.iterdir()) == sorted(p.name for p in (ROOT / "generated").iterdir())


def test_the_python_tables_are_fresh(output):
    assert (output.parent / "_generated.py").read_bytes() == (ROOT / "stewart" / "_generated.py").read_bytes(), (
        "stewart/_generated.py is stale: run `make generate` and commit the result"
    )


@pytest.mark.parametrize("name", sorted(p.name for p in (ROOT / "generated").iterdir()))
def test_generated_file_is_fresh(output, name):
    assert (output / name).read_bytes() == (ROOT / "generated" / name).read_bytes(), (
        f"generated/{name} is stale: run `make generate` and commit the result"
    )


#: Imports stewart._generated, stewart.model.params and stewart.model.conditions with the compiled extension
#: made unimportable and the package's __init__ (which imports it) skipped.
WITHOUT_EXTENSION = """
import importlib.abc, sys, types
class Refuse(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name == "stewart._kernel":
            raise ImportError("the compiled extension is not to be imported")
sys.meta_path.insert(0, Refuse())
package = types.ModuleType("stewart")
package.__path__ = [sys.argv[1]]
sys.modules["stewart"] = package
import stewart._generated, stewart.model.params, stewart.model.conditions
assert "stewart._kernel" not in sys.modules
print(len(stewart._generated.FUNCTIONS), stewart.model.conditions.JACOBIAN_TOL, len(stewart.model.params.PlatformParams.inertial_names()))
"""


def test_the_python_tables_import_without_the_extension():
    """stewart._generated is plain Python, and the modules that read it (stewart.model.params,
    stewart.model.conditions) need no compiled code."""
    run = subprocess.run([sys.executable, "-c", WITHOUT_EXTENSION, str(ROOT / "stewart")],
                         check=True, capture_output=True, text=True)
    from stewart import _generated

    assert run.stdout.split() == [str(len(_generated.FUNCTIONS)), "1e-12", str(len(_generated.INERTIAL_NAMES))]


def test_the_python_tables_are_the_compiled_models():
    """The status messages of the table are the compiled C's, its tolerances the header's
    macros, and each function's results have the shapes of its table entry, one state and a batch."""
    import re

    import numpy as np

    import stewart
    from stewart import _generated, _kernel

    header = (ROOT / "generated" / "stewart_model.h").read_text()
    macros = dict(re.findall(r"#define (STEWART_\w+_TOL) (\S+)", header))
    values = {"DBL_MIN": sys.float_info.min}
    tolerances = sorted(tol for _, _, tol in _generated.CONDITIONS.values() if tol is not None)
    assert tolerances == sorted(values.get(v, None) or float(v) for v in macros.values())
    for code, (_, message, _) in _generated.CONDITIONS.items():
        assert message == _kernel.status_message(code)
    params = stewart.PlatformParams.preset("narayan2017")
    kernel = _kernel.Kernel(params)
    x = stewart.home_pose(params)
    for name, spec in _generated.FUNCTIONS.items():
        for rows in ((), (3,)):
            arrays = [np.broadcast_to(x, rows + (6,))] + [np.full(rows + (6,), 0.1)] * (len(spec.inputs) - 1)
            result = kernel.call(name, tuple(arrays), False, 1e-3)
            parts = (result,) if len(spec.results) == 1 else result
            assert [p.shape for p in parts] == [rows + shape for _, _, _, shape in spec.results]
            assert all(np.isfinite(p).all() for p in parts)
