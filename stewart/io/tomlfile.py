"""Settings files in TOML: the sections and keys a reader knows, checked as they are read
(the cueing settings of :mod:`stewart.cueing`; the platform's parameter files are
:mod:`stewart.model.paramfile`)."""

from __future__ import annotations

import os
import tomllib

__all__ = ["read_sections"]


def read_sections(path, sections: dict[str, tuple]) -> dict[tuple[str, str], object]:
    """The settings of the TOML file ``path`` by ``(section, key)``, each section and key one
    of ``sections``; a missing, unreadable or unknown one is a ``ValueError`` naming the file."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ValueError(f"{path}: no such file")
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: not a valid TOML file ({exc})") from None
    out = {}
    for section, table in data.items():
        if section not in sections or not isinstance(table, dict):
            raise ValueError(f"{path}: unknown section [{section}]; expected {', '.join(sections)}")
        for key, value in table.items():
            if key not in sections[section]:
                raise ValueError(f"{path}: [{section}] {key}: unknown setting; expected {', '.join(sections[section])}")
            out[section, key] = value
    return out
