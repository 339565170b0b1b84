"""The package's structure: the data model works without the compiled extension, every
hand-written module stays small enough to read, one module imports the compiled extension,
no module reaches into another's private names, and no imports go in circles (the import
contract between the sub-packages is checked by `lint-imports`, configured in pyproject.toml,
in `make test`)."""

import ast
import json
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
