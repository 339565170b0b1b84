"""The generated C model for use from C: where its files are, and a copy with a platform's parameters.

The package carries ``stewart_model.h`` and the model's source files (dependency-free C99,
libm only; written by the sympy generator in ``codegen/``): ``stewart_model.c``, the public
functions, the ``stewart_model_<family>.c`` of the kernels they run, and the header they
share, ``stewart_internal.h``. So a C program can use the model without the source repository,
in the manner of ``numpy.get_include()``::

    cc -std=c99 -O2 $(python -c 'import stewart; print(*stewart.io.capi.c_flags())') \\
        -I"$(python -c 'import stewart; print(stewart.c_include_dir())')" \\
        my_program.c $(python -c 'import stewart; print(*stewart.c_sources())') -lm

:func:`export` copies them into a directory together with a header holding the
``stewart_params`` of a :class:`~stewart.PlatformParams`.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from .._generated import PARAM_FIELDS, PARAM_INPUTS, PARAM_SOURCES, PARAMS_LEFT_OUT
from ..model.params import PlatformParams
from . import cmake

__all__ = ["c_include_dir", "c_flags", "c_sources", "export", "params_header", "params_initializer", "HEADER",
           "INTERNAL_HEADER", "SOURCE", "SOURCES", "PARAMS_HEADER"]

#: The model's header, the header its source files share, and its source files: the public
#: functions (SOURCE) and the kernels of each family (stewart_model_<family>.c).
HEADER = "stewart_model.h"
INTERNAL_HEADER = "stewart_internal.h"
SOURCE = "stewart_model.c"
SOURCES = "stewart_model*.c"
#: The header :func:`export` writes for a parameter set; it defines ``stewart_platform_params``.
PARAMS_HEADER = "stewart_platform_params.h"

_PACKAGE = Path(__file__).resolve().parent.parent
#: Where the C files are: an installed package carries them as package data in
#: ``stewart/generated/`` (pyproject.toml maps the repository's ``generated/`` there); an
#: editable install runs from the source tree, whose ``generated/`` is the generator's output.
_LOCATIONS = (_PACKAGE / "generated", _PACKAGE.parent / "generated")

def c_include_dir() -> str:
    """The directory holding ``stewart_model.h`` and the model's source files (pass it to ``-I``)."""
    for directory in _LOCATIONS:
        if (directory / HEADER).is_file() and (directory / SOURCE).is_file():
            return str(directory)
    raise FileNotFoundError(
        f"{HEADER} and {SOURCE} are not in this installation of stewart "
        f"(looked in {', '.join(map(str, _LOCATIONS))}); reinstall the package"
    )


def c_flags() -> list[str]:
    """The compiler flags of the model's rounding (``STEWART_ROUNDING_FLAGS`` of the header):
    compiled with them, a state's results are the same bit for bit from the one-state and the
    batch functions, on every instruction set."""
    header = (Path(c_include_dir()) / HEADER).read_text(encoding="ascii")
    return re.search(r'#define STEWART_ROUNDING_FLAGS "(.*)"', header).group(1).split()


def c_sources() -> list[str]:
    """The C source files to compile with a program that uses ``stewart_model.h`` (each on its
    own, side by side if you like): ``stewart_model.c`` first, then the kernels' files."""
    directory = Path(c_include_dir())
    return [str(path) for path in sorted(directory.glob(SOURCES), key=lambda path: (path.name != SOURCE, path.name))]


def export(directory: Any, params: PlatformParams | None = None) -> list[str]:
    """Copy ``stewart_model.h``, ``stewart_internal.h`` and the model's source files
    (:func:`c_sources`) into ``directory`` (created if needed).

    With ``params``, also write ``stewart_platform_params.h``, which defines
    ``static const stewart_params stewart_platform_params`` with those parameters. Then the
    package files of :mod:`stewart.io.cmake`: a CMake project and package (``find_package(stewart
    CONFIG)``: ``stewart::stewart``) and a pkg-config file, for C and C++ programs that link the
    model as a library. Returns the paths written.
    """
    if params is not None and not isinstance(params, PlatformParams):
        raise TypeError(f"params: expected a stewart.PlatformParams or None, got {type(params).__name__}")
    target = Path(directory)
    target.mkdir(parents=True, exist_ok=True)
    source = Path(c_include_dir())
    written = []
    for name in [HEADER, INTERNAL_HEADER] + [Path(path).name for path in c_sources()]:
        (target / name).write_bytes((source / name).read_bytes())
        written.append(str(target / name))
    if params is not None:
        with open(target / PARAMS_HEADER, "w", encoding="ascii", newline="\n") as f:
            f.write(params_header(params))
        written.append(str(target / PARAMS_HEADER))
    header = (source / HEADER).read_text(encoding="ascii")
    for name, text in cmake.package_files(__version__, header).items():
        with open(target / name, "w", encoding="ascii", newline="\n") as f:
            f.write(text)
        written.append(str(target / name))
    return written


def _c_initializer(value: Any) -> str:
    """A float or an array as a C initializer (a matrix one row a line), every number
    printed to round-trip exactly."""
    if isinstance(value, np.ndarray) and value.ndim == 2:
        return "{\n" + "".join(f"        {_c_initializer(row)},\n" for row in value) + "    }"
    if isinstance(value, np.ndarray):
        return "{" + ", ".join(repr(float(v)) for v in value) + "}"
    return repr(float(value))


def _comment(value: Any) -> str:
    """``value``'s Python form made safe inside a C block comment (ASCII, no comment end)."""
    return ascii(value).replace("*/", "* /")


def params_initializer(params: PlatformParams) -> str:
    """The C initializer of a ``stewart_params`` holding ``params``.

    Each struct member is set by name (C99 designated initializers), so it stays right
    whatever the order of the members. The members are the generator's parameter schema
    (``PARAM_FIELDS`` of the generated ``stewart._generated``); every other field of ``params`` must be one the
    schema leaves out (``TypeError`` otherwise).
    """
    for field in dataclasses.fields(params):
        if field.name not in PARAMS_LEFT_OUT and field.name not in PARAM_INPUTS:
            raise TypeError(f"params: field {field.name!r} is neither a member of stewart_params "
                            "nor left out of it")
    members = [f"    .{name} = {_c_initializer(getattr(params, PARAM_SOURCES[name]))},\n" for name, _ in PARAM_FIELDS]
    return "{\n" + "".join(members) + "}"


def params_header(params: PlatformParams) -> str:
    """The text of ``stewart_platform_params.h`` for ``params`` (see :func:`params_initializer`)."""
    label = "unnamed" if params.name is None else params.name
    left_out = [f" *   {name} = {_comment(getattr(params, name))}: {why}."
                for name, why in PARAMS_LEFT_OUT.items()]
    return "\n".join([
        f"/* {PARAMS_HEADER} -- the parameters of the platform {_comment(label)} for {HEADER}.",
        " *",
        " * Written by stewart.io.capi.export() from its PlatformParams;",
        " * every number is the exact float64 (shortest round-trip form).",
        " * Left out, having no member in stewart_params:",
        *left_out,
        " */",
        "#ifndef STEWART_PLATFORM_PARAMS_H",
        "#define STEWART_PLATFORM_PARAMS_H",
        "",
        f'#include "{HEADER}"',
        "",
        f"static const stewart_params stewart_platform_params = {params_initializer(params)};",
        "",
        "#endif /* STEWART_PLATFORM_PARAMS_H */",
        "",
    ])
