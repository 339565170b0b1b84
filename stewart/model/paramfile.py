"""Parameter files: TOML (read with the standard library's ``tomllib``) and JSON.

Both formats hold one flat table whose keys are the fields of
:class:`stewart.PlatformParams` (see the README for the layout)::

    name = "narayan2017"
    gravity = 9.81
    base_points = [[0.0962, 0.0336, 0.0], ...]   # six [x, y, z] rows, metres, in {B}
    platform_points = [[0.0607, -0.0203, 0.0], ...]
    platform_mass = 6.77406
    platform_inertia = [0.1524, 0.1524, 0.3048]  # kg m^2, in {P}
    ...

This module reads and writes such tables as plain dictionaries (the layout of
:meth:`PlatformParams.to_dict`); :meth:`PlatformParams.load` and
:meth:`PlatformParams.save` build and check the parameters.
"""

from __future__ import annotations

import json
import math
import os
import tomllib
from typing import Any

__all__ = ["read", "write", "dumps_toml"]


def _format(format: str | None, path: str) -> str:
    fmt = format or os.path.splitext(path)[1].lstrip(".").lower()
    if fmt not in ("toml", "json"):
        raise ValueError(f"path: cannot tell the format of {path!r}; use a .toml or .json file")
    return fmt


def _path(path: str | os.PathLike[str]) -> str:
    try:
        return os.fsdecode(path)
    except TypeError:
        raise TypeError(f"path: expected a file name, got {type(path).__name__}") from None


def read(path: str | os.PathLike[str], format: str | None = None) -> dict[str, Any]:
    """The table of parameter fields in a ``.toml`` or ``.json`` file.

    A file that cannot be parsed or holds no table raises ``ValueError`` naming the file;
    a missing or unreadable file raises the usual ``OSError``.
    """
    path = _path(path)
    fmt = _format(format, path)
    try:
        if fmt == "toml":
            with open(path, "rb") as fh:
                data = tomllib.load(fh)
        else:
            with open(path, encoding="utf-8") as fh:
                data = json.load(fh)
    except ValueError as exc:  # a decode error, invalid UTF-8, an integer with too many digits
        raise ValueError(f"{path}: not a valid {fmt.upper()} file: {exc}") from None
    except RecursionError:
        raise ValueError(f"{path}: not a valid {fmt.upper()} file: nested too deeply") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path}: expected a table of parameter fields at the top level")
    return data


def _toml_value(value: Any) -> str:
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"cannot write non-finite value {value} to TOML")
    return repr(value)


def dumps_toml(fields: dict[str, Any]) -> str:
    """The TOML text of a table of parameter fields (values round-trip exactly)."""
    return "".join(f"{key} = {_toml_value(val)}\n" for key, val in fields.items())


def write(fields: dict[str, Any], path: str | os.PathLike[str], format: str | None = None) -> None:
    """Write a table of parameter fields to a ``.toml`` or ``.json`` file."""
    path = _path(path)
    if _format(format, path) == "toml":
        text = dumps_toml(fields)
    else:
        text = json.dumps(fields, indent=2) + "\n"
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
