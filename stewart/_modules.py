"""The modules of a sub-package imported on first use, so that ``import stewart`` is enough
for ``stewart.studies.envelope`` (the rule of :mod:`stewart`'s namespace), and the deprecated
aliases of public names and module paths that moved.

A moved module path (:data:`MOVED_MODULES`, filled by each package with
:func:`moved_modules`) is an alias of its new module: ``import <old path>``, ``from <old
path> import name`` and the old path as an attribute of its package give the new module, with
a ``DeprecationWarning`` naming the new path. Where the package binds the old name to
something else (``stewart.cueing.washout`` is the function, its module
``stewart.cueing.classical``), the attribute stays what the package binds and the import
statements still give the moved module."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import pkgutil
import sys
import types
import warnings

#: Every deprecated module path of the package: {old path: (new path, the version that moved
#: it or None for the next one)}.
MOVED_MODULES: dict[str, tuple[str, str | None]] = {}


def on_first_use(package: str, path) -> callable:
    """The module ``__getattr__`` of ``package`` (its ``__name__`` and ``__path__``) that
    imports its public modules (those not starting with ``_``) when first named, and gives
    its moved module paths (:func:`moved_modules`) with their warning."""
    modules = {info.name for info in pkgutil.iter_modules(path) if not info.name.startswith("_")}

    def __getattr__(name: str):
        if name in modules:
            return importlib.import_module(f"{package}.{name}")
        if f"{package}.{name}" in MOVED_MODULES:
            return moved_module(f"{package}.{name}", 2)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__


def moved_modules(package: str, moved: dict[str, str], since: str | None = None) -> None:
    """Record the module paths ``<package>.<name>`` of ``moved`` (name: the module it moved to,
    in version ``since``, or in the next one) as deprecated aliases of their new modules, and
    keep the names ``package`` binds itself from being replaced by those modules on import."""
    MOVED_MODULES.update({f"{package}.{name}": (new, since) for name, new in moved.items()})
    sys.modules[package].__class__ = Package


def moved_module(old: str, stacklevel: int) -> types.ModuleType:
    """The module that the path ``old`` moved to, with the warning that says where."""
    new, since = MOVED_MODULES[old]
    parent, _, name = new.rpartition(".")
    warnings.warn(f"{old} is deprecated: it moved to {new}{f' in {since}' if since else ''} (use `from {parent} "
                  f"import {name}`); the old path goes in 0.3.0", DeprecationWarning, stacklevel=stacklevel + 1)
    return importlib.import_module(new)


class Package(types.ModuleType):
    """A package with moved module paths: the import system binds each module it imports as
    an attribute of its package, and for a moved path whose name the package binds to
    something else (a function) that binding is what stays."""

    def __setattr__(self, name: str, value) -> None:
        if (f"{self.__name__}.{name}" in MOVED_MODULES and isinstance(value, types.ModuleType)
                and name in vars(self) and not isinstance(vars(self)[name], types.ModuleType)):
            return
        super().__setattr__(name, value)


class MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """``import <old path>``: the moved module itself, with the deprecation warning."""

    def find_spec(self, fullname, path=None, target=None):
        return importlib.util.spec_from_loader(fullname, self) if fullname in MOVED_MODULES else None

    def create_module(self, spec):
        module = moved_module(spec.name, 2)
        self.specs[spec.name] = module.__spec__  # the import system puts the alias's spec on it
        return module

    def exec_module(self, module):
        module.__spec__ = self.specs.pop(module.__spec__.name)

    specs: dict = {}


sys.meta_path.append(MovedModules())


def moved_names(module: str, moved: dict[str, str]) -> callable:
    """The module ``__getattr__`` of ``module`` that gives each name of ``moved`` (name: the
    module it moved to) from its new module, with a ``DeprecationWarning`` naming the new path."""

    def __getattr__(name: str):
        if name not in moved:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        warnings.warn(f"{module}.{name} is deprecated: it moved to {moved[name]}.{name} (use `from {moved[name]} "
                      f"import {name}`); the old path goes in 0.3.0", DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(moved[name]), name)

    return __getattr__
