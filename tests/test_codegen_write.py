"""The generator leaves an output file that would not change alone, modification time
included, so that the build does not recompile after ``make generate``."""

import os
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from codegen.__main__ import _write_if_changed  # noqa: E402


def test_unchanged_output_is_left_alone(tmp_path):
    path = tmp_path / "stewart_model.h"
    assert _write_if_changed(path, "int a;\n")
    os.utime(path, ns=(10**9, 10**9))
    assert not _write_if_changed(path, "int a;\n")
    assert path.stat().st_mtime_ns == 10**9 and path.read_bytes() == b"int a;\n"
    assert _write_if_changed(path, "int b;\n")
    assert path.read_bytes() == b"int b;\n" and path.stat().st_mtime_ns != 10**9
