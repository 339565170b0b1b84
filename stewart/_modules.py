"""The modules of a sub-package imported on first use, so that ``import stewart`` is enough
for ``stewart.studies.envelope`` (the rule of :mod:`stewart`'s namespace)."""

from __future__ import annotations

import importlib
import pkgutil


def on_first_use(package: str, path) -> callable:
    """The module ``__getattr__`` of ``package`` (its ``__name__`` and ``__path__``) that
    imports its public modules (those not starting with ``_``) when first named."""
    modules = {info.name for info in pkgutil.iter_modules(path) if not info.name.startswith("_")}

    def __getattr__(name: str):
        if name in modules:
            return importlib.import_module(f"{package}.{name}")
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
