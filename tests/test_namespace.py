"""The package's namespace (the rule of stewart's docstring): the top level holds the public
functions, classes and errors and the sub-packages; each sub-package gives its modules on
first use; the module paths of 0.1.0 that 0.2.0 moved (stewart.MOVED) still import, as the
moved module, with a DeprecationWarning naming the new path."""

import importlib
import pkgutil
import subprocess
import sys
import types

import pytest

import stewart

SUBPACKAGES = ("model", "motion", "identification", "calibration", "cueing", "studies", "io", "oracles")


def _forget(name: str) -> None:
    """Undo an earlier use of ``stewart.<name>`` in this process, so that the next one warns."""
    sys.modules.pop(f"stewart.{name}", None)
    stewart.__dict__.pop(name, None)


@pytest.mark.parametrize("old", sorted(stewart.MOVED))
def test_a_moved_module_imports_with_a_warning_naming_its_new_path(old):
    new = stewart.MOVED[old]
    module = importlib.import_module(new)
    _forget(old)
    with pytest.warns(DeprecationWarning, match=f"^stewart.{old} is deprecated: it moved to {new} in 0.2.0"):
        assert importlib.import_module(f"stewart.{old}") is module
    assert module.__spec__.name == new and module.__spec__.origin.endswith(".py")  # the module keeps its own
    _forget(old)
    with pytest.warns(DeprecationWarning, match=f"moved to {new} "):
        assert getattr(stewart, old) is module
    _forget(old)


#: Public names that moved to another module after 0.2.0: (old module, name, new module).
MOVED_NAMES = [("stewart.cueing.washout", "axis_excursions", "stewart.model.reachability"),
               ("stewart.cueing.settings", "read_sections", "stewart.io.tomlfile"),
               ("stewart.model.arguments", "platform_params", "stewart.model.params")]


@pytest.mark.parametrize("old, name, new", MOVED_NAMES)
def test_a_moved_name_works_from_its_old_module_with_a_warning(old, name, new):
    importlib.import_module(old)
    module = sys.modules[old]
    assert name not in vars(module)  # reached through the module's __getattr__, which warns
    with pytest.warns(DeprecationWarning, match=f"^{old}.{name} is deprecated: it moved to {new}.{name} "):
        assert getattr(module, name) is getattr(importlib.import_module(new), name)
    with pytest.raises(AttributeError, match="has no attribute 'nonexistent'"):
        module.nonexistent


def test_the_moved_paths_include_those_the_docs_of_0_1_0_showed():
    assert {"envelope", "identify", "sweep", "paramfile", "trajectory", "base_parameters", "excitation", "workspace",
            "reference", "exactness", "kinematics"} <= set(stewart.MOVED)
    for new in stewart.MOVED.values():
        assert isinstance(importlib.import_module(new), types.ModuleType)


def test_the_top_level_holds_no_module_but_the_subpackages():
    modules = [name for name in stewart.__all__ if isinstance(getattr(stewart, name), types.ModuleType)]
    assert sorted(modules) == sorted(SUBPACKAGES)
    assert not set(stewart.MOVED) & set(stewart.__all__)


def test_each_subpackage_gives_its_modules_on_first_use():
    """In a new interpreter, after only `import stewart`, every public module of every
    sub-package is an attribute path, and a name that is none is an AttributeError."""
    names = [f"{package}.{info.name}" for package in SUBPACKAGES
             for info in pkgutil.iter_modules(importlib.import_module(f"stewart.{package}").__path__)
             if not info.name.startswith("_")]
    assert "studies.envelope" in names and "oracles.reference" in names
    script = ("import stewart, types\n"
              f"for name in {names!r}:\n"
              "    package, module = name.split('.')\n"
              "    value = getattr(getattr(stewart, package), module)\n"
              "    assert isinstance(value, types.ModuleType) or callable(value), name\n"
              "try:\n    stewart.studies.no_such_module\nexcept AttributeError as e:\n    print(e)\n")
    done = subprocess.run([sys.executable, "-W", "error::DeprecationWarning", "-c", script], capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "module 'stewart.studies' has no attribute 'no_such_module'"
