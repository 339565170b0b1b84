"""The modules of a sub-package imported on first use, so that ``import stewart`` is enough
for ``stewart.studies.envelope`` (the rule of :mod:`stewart`'s namespace), and the deprecated
aliases of public names that moved to another module."""

from __future__ import annotations

import importlib
import pkgutil
import warnings


def on_first_use(package: str, path) -> callable:
    """The module ``__getattr__`` of ``package`` (its ``__name__`` and ``__path__``) that
    imports its public modules (those not starting with ``_``) when first named."""
    modules = {info.name for info in pkgutil.iter_modules(path) if not info.name.startswith("_")}

    def __getattr__(name: str):
        if name in modules:
            return importlib.import_module(f"{package}.{name}")
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__


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
