"""The documentation site (``mkdocs.yml``, ``docs/``): it builds with ``mkdocs build --strict``
(no broken link, anchor or reference; the API reference's objects all found), and its API
reference covers every public name of the ``stewart`` namespace."""

from __future__ import annotations

import importlib
import pathlib
import re
import subprocess
import sys
import types

import pytest

import stewart

ROOT = pathlib.Path(__file__).resolve().parent.parent
API = ROOT / "docs" / "api.md"
if not (ROOT / "mkdocs.yml").is_file():
    pytest.skip("needs the checkout (mkdocs.yml and docs/)", allow_module_level=True)


def documented() -> list[str]:
    """The objects the API reference renders (``::: stewart.NAME`` lines), in order."""
    return re.findall(r"^::: (\S+)\s*$", API.read_text(), re.M)


def test_the_api_reference_covers_every_public_name():
    names = documented()
    missing = [name for name in stewart.__all__ if f"stewart.{name}" not in names]
    assert not missing, f"docs/api.md has no '::: stewart.NAME' for {missing}"
    assert len(names) == len(set(names)), "an object rendered twice"


def test_the_api_reference_names_objects_by_their_public_path():
    """``stewart.NAME`` for a name of ``stewart.__all__``, which stays put when modules move, or
    ``stewart.PACKAGE.MODULE`` for a public module of a sub-package (its one path)."""
    for name in documented():
        parts = name.split(".")
        assert parts[0] == "stewart" and parts[1] in stewart.__all__, name
        if len(parts) == 3:
            package = getattr(stewart, parts[1])
            assert isinstance(package, types.ModuleType) and not parts[2].startswith("_"), name
            assert isinstance(importlib.import_module(name), types.ModuleType), name
        else:
            assert len(parts) == 2, name


@pytest.mark.slow
def test_the_site_builds_strictly(tmp_path):
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "--site-dir",
                          str(tmp_path / "site")], cwd=ROOT, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    assert (tmp_path / "site" / "api" / "index.html").is_file()
    page = (tmp_path / "site" / "api" / "index.html").read_text()
    for name in stewart.__all__:  # each object rendered under its public path
        assert f'id="stewart.{name}"' in page, name
