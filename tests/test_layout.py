"""The package's structure: the data model works without the compiled extension, and every
hand-written module stays small enough to read (the import contract between the
sub-packages is checked by `lint-imports`, configured in pyproject.toml, in `make test`)."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

import stewart

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "stewart"
CODEGEN = ROOT / "codegen"
#: The most lines a hand-written module of the package or of the generator may have.
MAX_LINES = 600
#: The modules the generator writes (stewart/_generated.py) are not hand-written.
GENERATED = {PACKAGE / "_generated.py"}

BUILDLESS = """
import json, sys
sys.modules["stewart._kernel"] = None   # any import of the compiled extension fails
import numpy as np
from stewart.model import conditions, kinematics, paramfile
from stewart.model.params import PlatformParams
from stewart.model.presets import presets
params = PlatformParams.preset("narayan2017")
params.save(sys.argv[1])
again = PlatformParams.load(sys.argv[1])
home = kinematics.home_pose(again)
print(json.dumps({"presets": presets(), "same": again == params, "home": home.tolist(),
                  "lengths": kinematics.leg_lengths(again, home).tolist(),
                  "conditions": sorted(conditions.CONDITIONS)}))
"""


def test_the_data_model_works_without_the_compiled_extension(tmp_path):
    """Parameters, presets, parameter files and kinematics import and run in a process where
    the compiled extension cannot be imported; the leg lengths agree with the compiled
    model's."""
    proc = subprocess.run([sys.executable, "-c", BUILDLESS, str(tmp_path / "p.toml")], capture_output=True,
                          text=True, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["presets"] == stewart.presets() and out["same"]
    assert out["conditions"] == sorted(stewart.model.conditions.CONDITIONS)
    params = stewart.PlatformParams.preset("narayan2017")
    home = stewart.Platform(params).home_pose
    np.testing.assert_allclose(out["home"], home, rtol=0, atol=1e-15)
    np.testing.assert_allclose(out["lengths"], stewart.Platform(params).leg_lengths(home), rtol=1e-15, atol=0)


def test_no_hand_written_module_is_over_the_limit():
    """Every hand-written module of the package (.py, .pyx, .pxi) and of the generator
    (codegen/*.py) has at most MAX_LINES lines."""
    modules = [path for pattern in ("*.py", "*.pyx", "*.pxi") for path in PACKAGE.rglob(pattern)
               if path not in GENERATED] + list(CODEGEN.glob("*.py"))
    sizes = {str(path.relative_to(ROOT)): len(path.read_text(encoding="utf-8").splitlines()) for path in modules}
    assert len(sizes) > 40 and sum(name.startswith("codegen/") for name in sizes) > 10
    assert {name: n for name, n in sizes.items() if n > MAX_LINES} == {}


def test_every_public_name_resolves():
    """Each name of ``stewart.__all__`` (imported on first use) is an object of the package,
    in a fresh process, and ``dir(stewart)`` lists them all."""
    code = ("import stewart, json; print(json.dumps({n: getattr(getattr(stewart, n), '__module__', None) "
            "or getattr(stewart, n).__name__ for n in stewart.__all__} | {'@dir': sorted(dir(stewart))}))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    names = out.pop("@dir")
    assert set(stewart.__all__) <= set(names) and len(out) == len(stewart.__all__) >= 50
    assert all(module.startswith("stewart") for module in out.values()), out
