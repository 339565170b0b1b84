"""The CSV layout read and written by the command line and :mod:`stewart.motion.simulation`.

A file holds comma-separated numbers, one row per line. The first line may be a header of
column names; lines starting with ``#`` are comments (the writers put one after the
header naming the platform). When the header names the columns a reader wants, they are
picked by name (so a simulation's output can be read back as a trajectory); otherwise
the file must have exactly those columns, in order.

Every problem is one ``ValueError`` naming the file, the line and the column.

A well-formed file is parsed by numpy's C reader (``np.loadtxt``): an hour of 60 Hz rows of
19 columns (216000 lines, 61 MB) in a seventh of the time of the line-by-line reader, which
reads any file the fast path does not take (a blank line of spaces, a ``#`` after a value,
a bad value) and names the problem.
"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["read", "write"]


def _number(path: str, lineno: int, col: int, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        shown = text if len(text) <= 40 else text[:37] + "..."
        raise ValueError(f"{path}: line {lineno}, column {col}: {shown!r} is not a number") from None
    if not np.isfinite(value):
        raise ValueError(f"{path}: line {lineno}, column {col}: {text[:40]!r} is not a finite number")
    return value


def read(path, columns: list[str]) -> np.ndarray:
    """The ``columns`` of the CSV file ``path`` as a float array ``(rows, len(columns))``
    (a header's names are matched regardless of case)."""
    path = os.fspath(path)
    if not os.path.exists(path):
        raise ValueError(f"{path}: no such file")
    if os.path.isdir(path):
        raise ValueError(f"{path}: is a directory, not a CSV file")
    fast = _read_fast(path, columns)
    if fast is not None:
        return fast
    try:
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file (it is not UTF-8)") from None
    width = len(columns)
    pick = None  # column indices chosen by the header
    rows: list[list[float]] = []
    expected = None
    for lineno, line in enumerate(text.splitlines(), start=1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        fields = [f.strip() for f in line.split(",")]
        if len(fields) == 1 and width > 1:
            for sep, name in ((";", "semicolons"), ("\t", "tabs"), (" ", "spaces")):
                if sep in line:
                    raise ValueError(f"{path}: line {lineno}: values separated by {name}; expected commas")
        if not rows and pick is None and expected is None and not _numeric(fields[0]):
            names = [f.lower() for f in fields]
            missing = [c for c in columns if c.lower() not in names]
            if missing and len(fields) != width:
                raise ValueError(f"{path}: line {lineno}: the header has {len(fields)} column(s) and lacks "
                                 f"{', '.join(missing)}; expected the columns {', '.join(columns)}")
            pick = list(range(width)) if missing else [names.index(c.lower()) for c in columns]
            expected = len(fields)
            continue
        if expected is None:
            expected = len(fields)
            if expected != width:
                raise ValueError(f"{path}: line {lineno}: {expected} column(s); expected {width} "
                                 f"({', '.join(columns)})")
        if len(fields) != expected:
            raise ValueError(f"{path}: line {lineno}: {len(fields)} column(s) where earlier lines have {expected}")
        values = [_number(path, lineno, col, f) for col, f in enumerate(fields, start=1)]
        rows.append(values if pick is None else [values[i] for i in pick])
    if not rows:
        raise ValueError(f"{path}: no data rows (expected {', '.join(columns)})")
    return np.array(rows, dtype=float)


def _read_fast(path: str, columns: list[str]) -> np.ndarray | None:
    """What :func:`read` returns, by ``np.loadtxt`` after the leading blank, comment and header
    lines; None for any file it does not read to the same numbers, which :func:`read` then
    reads line by line (and explains)."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
        lines, pos, names = 0, 0, None
        while True:  # the blank and comment lines and the header before the first row
            end = raw.find(b"\n", pos)
            line = raw[pos:len(raw) if end < 0 else end].strip()
            if line and not line.startswith(b"#"):
                fields = [f.strip().decode("utf-8").lower() for f in line.split(b",")]
                if names is not None or _numeric(fields[0]):
                    break
                names = fields
            if end < 0:
                return None
            lines, pos = lines + 1, end + 1
        hashes = raw.count(b"#", pos)
        if hashes and hashes != raw.count(b"\n#", max(pos - 1, 0)):  # a '#' that does not start a line
            return None
        data = np.loadtxt(path, delimiter=",", skiprows=lines, comments="#" if hashes else None, ndmin=2,
                          dtype=float, encoding="utf-8")
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    width = len(columns)
    if names is not None and len(names) == data.shape[1] and all(c.lower() in names for c in columns):
        pick = [names.index(c.lower()) for c in columns]
    elif data.shape[1] == width and (names is None or len(names) == width):
        pick = list(range(width))
    else:
        return None
    if not data.size or not np.all(np.isfinite(data)):
        return None
    return np.ascontiguousarray(data[:, pick])


def header(path) -> list[str] | None:
    """The lower-case column names of the CSV file ``path``'s header, or None without one
    (or for a file that cannot be read: :func:`read` says why)."""
    try:
        with open(os.fspath(path), encoding="utf-8") as fh:
            for line in fh:
                line = line.strip()
                if line and not line.startswith("#"):
                    fields = [f.strip().lower() for f in line.split(",")]
                    return None if _numeric(fields[0]) else fields
    except (OSError, UnicodeDecodeError):
        return None
    return None


def _numeric(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def write(path, columns: list[str], rows: np.ndarray, comment: str, fmt: str = "%.12g") -> None:
    """Write ``rows`` under a header of ``columns`` and a ``# comment`` line."""
    np.savetxt(path, np.atleast_2d(rows), delimiter=",", header=",".join(columns) + "\n# " + comment,
               comments="", fmt=fmt)
