"""Argument checks shared by the public functions: shapes, dtypes and finiteness."""

from __future__ import annotations

from typing import Any

import numpy as np

from .errors import SingularityError

#: J_C is treated as singular when its condition number exceeds this.
JACOBIAN_COND_LIMIT = 1e12


def states(name: str, value: Any, width: int = 6) -> np.ndarray:
    """``value`` as a float (or complex) array of shape ``(width,)`` or ``(N, width)``.

    Raises ``ValueError`` naming ``name`` for a wrong shape, a non-numeric dtype or a
    non-finite entry (reporting the first offending row of a batch).
    """
    try:
        arr = np.asarray(value)
    except Exception as exc:  # ragged sequences and the like
        raise ValueError(f"{name}: cannot be read as an array ({exc})") from None
    if arr.dtype == object or not (
        np.issubdtype(arr.dtype, np.number) or arr.dtype == np.bool_
    ):
        raise ValueError(f"{name}: expected numbers, got dtype {arr.dtype}")
    if not np.iscomplexobj(arr):
        arr = arr.astype(float, copy=False)
    if arr.ndim not in (1, 2) or arr.shape[-1] != width:
        raise ValueError(f"{name}: expected shape ({width},) or (N, {width}), got {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        if arr.ndim == 1:
            raise ValueError(f"{name}: contains NaN or inf: {arr.tolist()}")
        row = int(np.argwhere(bad.any(axis=-1))[0, 0])
        raise ValueError(f"{name}: row {row} contains NaN or inf: {arr[row].tolist()}")
    return arr


def same_batch(**arrays: np.ndarray) -> None:
    """Raise ``ValueError`` unless the arrays share one leading shape."""
    shapes = {name: arr.shape[:-1] for name, arr in arrays.items()}
    if len(set(shapes.values())) > 1:
        desc = ", ".join(f"{name} {arr.shape}" for name, arr in arrays.items())
        raise ValueError(f"arguments must have matching batch shapes: {desc}")


def regular_jacobian(jac: np.ndarray) -> None:
    """Raise :class:`SingularityError` (naming the rows) where ``J_C`` is singular."""
    cond = np.linalg.cond(np.real(jac).reshape(-1, 6, 6))
    bad = ~(cond < JACOBIAN_COND_LIMIT)
    if bad.any():
        rows = np.flatnonzero(bad)
        raise SingularityError(
            f"x: J_C is singular (condition number {cond[rows[0]]:.3g}) at row(s) {rows[:10].tolist()}",
            rows=rows,
        )
