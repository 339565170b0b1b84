"""The package's structure: the data model works without the compiled extension, every
hand-written module stays small enough to read, one module imports the compiled extension,
no module reaches into another's private names, no imports go in circles, and the
calibration builds no rotation or leg itself (the import contract between the sub-packages
is checked by `lint-imports`, configured in pyproject.toml, in `make test`)."""

import ast
import re
import json
import re
import subprocess
import sys
from pathlib import Path

import grimp
import numpy as np
import pytest

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
try:
    kinematics.leg_lengths(again, home)
    compiled = "ran"
except ImportError:
    compiled = "needs the extension"
print(json.dumps({"presets": presets(), "same": again == params, "home": home.tolist(), "compiled": compiled,
                  "conditions": sorted(conditions.CONDITIONS)}))
"""


def test_the_data_model_works_without_the_compiled_extension(tmp_path):
    """Parameters, presets, parameter files and kinematics import, and all but the kinematics
    per state (the compiled model's) run, in a process where the compiled extension cannot be
    imported; the home pose agrees with the compiled model's."""
    proc = subprocess.run([sys.executable, "-c", BUILDLESS, str(tmp_path / "p.toml")], capture_output=True,
                          text=True, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["presets"] == stewart.presets() and out["same"]
    assert out["conditions"] == sorted(stewart.model.conditions.CONDITIONS)
    params = stewart.PlatformParams.preset("narayan2017")
    home = stewart.Platform(params).home_pose
    np.testing.assert_allclose(out["home"], home, rtol=0, atol=1e-15)
    assert out["compiled"] == "needs the extension"


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


#: The one module that imports the compiled extension, re-exporting what the others use.
KERNEL_DOOR = "stewart.model.compiled"
#: The package's private modules others may import, and why.
SHARED_PRIVATE_MODULES = {
    "stewart._generated": "the generator's table of the compiled model (written by codegen/, read where it is used)",
    "stewart._modules": "the namespace rule's helper, the module __getattr__ of each sub-package",
}


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def is_module(name: str) -> bool:
    path = ROOT.joinpath(*name.split("."))
    return path.with_suffix(".py").is_file() or (path / "__init__.py").is_file() or any(
        path.parent.glob(f"{path.name}.*.so")) or path.with_suffix(".pyx").is_file()


def imports(path: Path) -> list[tuple[int, str, str | None]]:
    """(line, module, name) of each import of a module, relative imports resolved: ``name`` the
    imported name of a ``from`` import of a non-module, else None (the module itself)."""
    here = module_name(path)
    package = here if path.name == "__init__.py" else here.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out += [(node.lineno, alias.name, None) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([node.module] if node.module else []))
            for alias in node.names:
                if is_module(f"{base}.{alias.name}"):
                    out.append((node.lineno, f"{base}.{alias.name}", None))
                else:
                    out.append((node.lineno, base, alias.name))
    return out


def hand_written(package: str = "stewart") -> list[Path]:
    return [path for path in sorted((ROOT / package).rglob("*.py")) if path not in GENERATED]


def test_only_the_door_imports_the_compiled_extension():
    """``stewart._kernel`` is imported by :data:`KERNEL_DOOR` alone (import-linter cannot see an
    extension module, so this test holds the rule)."""
    importers = {module_name(path) for path in hand_written()
                 for _, module, _ in imports(path) if module == "stewart._kernel"}
    assert importers == {KERNEL_DOOR}


def test_no_private_name_crosses_a_module():
    """No module imports another's underscore name, reads one as ``module._name``, or imports a
    private module of the package other than the compiled extension (through its door) and
    :data:`SHARED_PRIVATE_MODULES`: each seam between modules is public and documented."""
    crossings = []
    for path in hand_written():
        here = module_name(path)
        found = imports(path)
        aliases = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                aliases |= {(alias.asname or alias.name).split(".")[0] for alias in node.names}
        for line, module, name in found:
            private = [part for part in module.split(".") if part.startswith("_") and not part.startswith("__")]
            if name is not None and name.startswith("_") and not name.startswith("__") and module != "__future__":
                crossings.append(f"{here}:{line} imports {module}.{name}")
            elif private and module.startswith("stewart.") and module not in SHARED_PRIVATE_MODULES and not (
                    module == "stewart._kernel" and here == KERNEL_DOOR):
                crossings.append(f"{here}:{line} imports the private module {module}")
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in aliases
                    and node.attr.startswith("_") and not node.attr.startswith("__")):
                crossings.append(f"{here}:{node.lineno} reads {node.value.id}.{node.attr}")
    assert crossings == []


@pytest.mark.parametrize("package", ["stewart", "codegen"])
def test_no_import_cycles(package, monkeypatch):
    """No module of ``package`` imports, through any chain, a module that imports it (grimp,
    which import-linter builds on; imports under ``TYPE_CHECKING`` left out)."""
    monkeypatch.syspath_prepend(str(ROOT))  # codegen/ is not installed
    graph = grimp.build_graph(package, include_external_packages=False, exclude_type_checking_imports=True)
    cycles = sorted({" -> ".join(graph.find_shortest_chain(importer=other, imported=module))
                     for module in graph.modules for other in graph.find_modules_directly_imported_by(module)
                     if graph.chain_exists(importer=other, imported=module)})
    assert cycles == []


#: The model's numpy kinematics of a rotation, its rates and the legs (stewart.model.kinematics).
KINEMATICS = {"rotation", "euler_rate_jacobian", "twist_transform", "platform_points_in_base", "leg_vectors",
              "leg_unit_vectors", "leg_lengths", "jacobian", "euler_jacobian"}


def test_calibration_builds_no_rotation_or_leg_itself():
    """The calibration's residuals and Jacobians are the generated model's (codegen/calibration.py,
    through stewart.Platform): no module of stewart/calibration calls a trigonometric function
    (a rotation matrix is built from the Euler angles' cosines and sines) or imports the model's
    numpy rotation, Euler-rate map or legs (:data:`KINEMATICS`)."""
    found = []
    for path in sorted((PACKAGE / "calibration").glob("*.py")):
        here = module_name(path)
        found += [f"{here}:{line} imports {name}" for line, module, name in imports(path)
                  if module == "stewart.model.kinematics" and name in KINEMATICS]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call):
                called = getattr(node.func, "attr", getattr(node.func, "id", ""))
                if called in {"cos", "sin", "tan"}:
                    found.append(f"{here}:{node.lineno} calls {called}")
    assert found == []


LAYOUT = ROOT / "docs" / "layout.md"
#: The files of a module: Python, and the compiled wrapper's Cython sources.
MODULE_PATTERNS = ("*.py", "*.pyx", "*.pxi", "*.pxd")


def layout_names(text: str) -> set[str]:
    """The modules of ``stewart/`` and ``codegen/`` that docs/layout.md names, as paths from
    the checkout: each name in backticks (``options.py``, ``model/compiled.py``) is read from
    the folder of the bullet it stands in (``- `stewart/` ``, ``    - `cli/` ``; a sub-bullet
    that names a file keeps its parent's folder), a path from the checkout as it is."""
    names, folders = set(), {}
    folder = ""
    for line in text.splitlines():
        bullet = re.match(r"^( *)- `([^`]+)`", line)
        if bullet:
            depth, first = len(bullet.group(1)), bullet.group(2)
            parent = next((folders[d] for d in sorted(folders, reverse=True) if d < depth), "")
            folder = parent + first if first.endswith("/") else parent
            folders = {d: f for d, f in folders.items() if d < depth} | {depth: folder}
        for name in re.findall(r"`([\w./-]+\.(?:py|pyx|pxi|pxd))`", line):
            top = name.split("/")[0]
            path = name if "/" in name and (ROOT / top).is_dir() and top != name else folder + name
            if path.startswith(("stewart/", "codegen/")):
                names.add(path)
    return names


def test_the_layout_names_every_module_and_no_other():
    """docs/layout.md names every module of ``stewart/`` and ``codegen/`` (a package's
    ``__init__.py`` is named by its folder's bullet), and every module it names exists."""
    tree = {path.relative_to(ROOT).as_posix() for base in (PACKAGE, CODEGEN) for pattern in MODULE_PATTERNS
            for path in base.rglob(pattern) if "__pycache__" not in path.parts}
    named = layout_names(LAYOUT.read_text(encoding="utf-8"))
    assert {"stewart/cli/interleaved.py", "stewart/model/compiled.py", "codegen/graph.py"} <= named
    missing = sorted(path for path in tree - named if not path.endswith("/__init__.py"))
    assert not missing, ("docs/layout.md does not name these modules: " + ", ".join(missing) + ". Add each, "
                         "with its one job, to the bullet of its package, in backticks as a path from the "
                         "package's folder (`cueing.py` in the bullet of `cli/`, `calibration.py` in that of "
                         "`codegen/`).")
    stale = sorted(named - tree)
    assert not stale, ("docs/layout.md names modules that are not in the tree: " + ", ".join(stale) + ". Update "
                       "or drop their lines (moved or removed?).")


#: Where a rotation matrix or a leg vector may be built: the derivation, the model (which calls
#: its kernels) and the oracles (deliberately independent of both).
KINEMATICS_OWNERS = ("codegen/", "stewart/model/", "stewart/oracles/")
#: What building a rotation or a leg vector looks like: the cosine and sine of a pose angle (x[..., k],
#: k = 3, 4, 5: R's entries, eq. 3); the platform's joints rotated, R p_i (an einsum of a rotation and
#: the platform's points, or the points times a rotation); a leg vector p + R p_i - b_i (a sum less the
#: base's points).
HAND_KINEMATICS = {
    "cosine and sine of a pose angle": re.compile(r"\b(?:cos|sin)\(\s*[\w.]+\[[^\]]*\b([345])\]\s*\)"),
    "rotated platform points": re.compile(r"einsum\(.*\b(?:rot\w*|rotation|r)\b.*\bplatform(?:_points)?\b"
                                          r"|\bplatform(?:_points)?\s*@\s*(?:rot\w*|rotation\()"),
    "leg vector": re.compile(r"\+\s*[\w.]+(?:\[[^\]]*\])?\s*-\s*(?:[\w]+\.)*base(?:_points)?\b"),
}


def hand_kinematics(text: str) -> list[str]:
    """The kinds of :data:`HAND_KINEMATICS` the source ``text`` holds: cosines and sines only when
    both of one angle appear (one cosine alone is a test, e.g. of cos(theta))."""
    found = []
    cosines = {m.group(1) for line in text.splitlines() for m in HAND_KINEMATICS["cosine and sine of a pose angle"].finditer(line)
               if m.group(0).startswith("cos")}
    sines = {m.group(1) for line in text.splitlines() for m in HAND_KINEMATICS["cosine and sine of a pose angle"].finditer(line)
             if m.group(0).startswith("sin")}
    if cosines & sines:
        found.append("cosine and sine of a pose angle")
    found += [kind for kind in ("rotated platform points", "leg vector") if HAND_KINEMATICS[kind].search(text)]
    return found


def test_no_module_builds_a_rotation_or_a_leg_vector_by_hand():
    """Outside the derivation, the model and the oracles, every module takes the rotation and the
    leg vectors from their one owner (the generated kernels, through :class:`stewart.Platform` or
    :mod:`stewart.model.kinematics`)."""
    modules = [path for pattern in ("*.py", "*.pyx", "*.pxi") for path in PACKAGE.rglob(pattern) if path not in GENERATED]
    found = {}
    for path in modules:
        name = str(path.relative_to(ROOT))
        if name.startswith(KINEMATICS_OWNERS):
            continue
        kinds = hand_kinematics(path.read_text(encoding="utf-8"))
        if kinds:
            found[name] = kinds
    assert found == {}
    assert len(modules) > 60


@pytest.mark.parametrize("copy, kind", [
    ("cps, sps = np.cos(x[..., 3]), np.sin(x[..., 3])", "cosine and sine of a pose angle"),
    ("cth = np.cos(poses[:, 4])\nsth = np.sin(poses[:, 4])", "cosine and sine of a pose angle"),
    ('arms = np.einsum("...jk,ik->...ij", rotation(x), params.platform_points)', "rotated platform points"),
    ('arms = np.einsum("kab,ib->kia", rot, platform)', "rotated platform points"),
    ("arms = params.platform_points @ rotation(x).T", "rotated platform points"),
    ("legs = x[..., None, :3] + arms - params.base_points", "leg vector"),
    ("return rot, arms, poses[:, None, :3] + arms - base", "leg vector"),
    ("legs = x[:, None, :3] + rp[0] - base_points", "leg vector"),
])
def test_the_search_catches_a_planted_copy(copy, kind):
    """The copies the package held (the numpy kinematics, the calibration's and the cueing's) are
    found; what is not one is not (cos(theta) alone, the centres of the stroke balls)."""
    assert kind in hand_kinematics(f"import numpy as np\n\n\ndef f(x, params):\n    {copy}\n")
    for innocent in ("cos_theta = np.cos(result.x[:, 4])", "centres = params.base_points - arms",
                     "sin, cos = np.sin(phase), np.cos(phase)", "w = np.einsum('nji,nj->ni', rot, omega)"):
        assert hand_kinematics(innocent) == []


#: What building a rotation or a leg vector takes: the Euler angles' sines and cosines, the
#: joints' points.
KINEMATICS_BY_HAND = ({"sin", "cos", "tan"}, {"base_points", "platform_points"})


def test_cueing_builds_no_rotation_or_leg_vector_of_its_own():
    """stewart/cueing takes the platform's rotation, legs and their derivatives from the model
    (the generated functions, or stewart.model's kinematics), never by hand: none of its modules
    takes a sine or cosine of an array's entries (a pose's angles) or reads the joints' points."""
    trig, points = KINEMATICS_BY_HAND
    found = []
    for path in sorted((PACKAGE / "cueing").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in trig
                    and any(isinstance(arg, ast.Subscript) for arg in ast.walk(node))):
                found.append(f"{path.name}:{node.lineno}: {ast.unparse(node)}")
            if isinstance(node, (ast.Attribute, ast.Name)) and getattr(node, "attr", getattr(node, "id", "")) in points:
                found.append(f"{path.name}:{node.lineno}: {ast.unparse(node)}")
    assert not found, "stewart/cueing builds kinematics by hand:\n" + "\n".join(found)
