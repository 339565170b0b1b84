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
#: (stewart.cueing.washout's axis_excursions: that module's path moved to stewart.cueing.classical.)
MOVED_NAMES = [("stewart.cueing.classical", "axis_excursions", "stewart.model.reachability"),
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


#: Module paths of a sub-package that moved after 0.2.0: old path -> new path.
MOVED_PATHS = {"stewart.cueing.washout": "stewart.cueing.classical",
               "stewart.cueing.prediction": "stewart.cueing.horizon",
               "stewart.cueing.predictive": "stewart.cueing.planner"}


def _forget_path(old: str) -> None:
    """Undo an earlier import of the moved path ``old`` in this process, so that the next one warns."""
    sys.modules.pop(old, None)
    package, _, name = old.rpartition(".")
    if isinstance(vars(sys.modules[package]).get(name), types.ModuleType):
        delattr(sys.modules[package], name)


@pytest.mark.parametrize("old", sorted(MOVED_PATHS))
def test_a_moved_path_of_a_subpackage_imports_as_its_new_module_with_a_warning(old):
    new = MOVED_PATHS[old]
    module = importlib.import_module(new)
    package, _, name = old.rpartition(".")
    _forget_path(old)
    warning = f"^{old} is deprecated: it moved to {new} \\(use `from {package} import {new.rpartition('.')[2]}`\\)"
    with pytest.warns(DeprecationWarning, match=warning):
        assert importlib.import_module(old) is module
    assert module.__spec__.name == new and module.__spec__.origin.endswith(f"{new.rpartition('.')[2]}.py")
    _forget_path(old)
    with pytest.warns(DeprecationWarning, match=warning):
        exec(f"from {old} import __doc__ as doc", {})
    _forget_path(old)
    if name != "washout":  # the attribute path too (stewart.cueing.washout is the function)
        with pytest.warns(DeprecationWarning, match=warning):
            assert getattr(sys.modules[package], name) is module
        _forget_path(old)


def test_the_washout_function_keeps_its_name_beside_the_old_module_path():
    """``stewart.cueing.washout`` is the runner before and after ``import stewart.cueing.washout``,
    which (like ``from stewart.cueing.washout import ...``) gives the filters' module."""
    from stewart import cueing
    from stewart.cueing import classical, runners

    _forget_path("stewart.cueing.washout")
    assert cueing.washout is runners.washout
    with pytest.warns(DeprecationWarning, match="^stewart.cueing.washout is deprecated: it moved to "
                                                "stewart.cueing.classical "):
        import stewart.cueing.washout  # noqa: F401
    assert sys.modules["stewart.cueing.washout"] is classical
    assert stewart.cueing.washout is runners.washout and cueing.washout is runners.washout
    from stewart.cueing.washout import WashoutParams, reference_poses
    assert (WashoutParams, reference_poses) == (classical.WashoutParams, classical.reference_poses)
    from stewart.cueing import washout
    assert washout is runners.washout
    _forget_path("stewart.cueing.washout")


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
