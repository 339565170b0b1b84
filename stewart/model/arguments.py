"""Argument checks shared by the public functions: numbers, shapes, finiteness and thread
counts, and the finiteness of results (the other conditions under which the model is
undefined are :mod:`stewart.model.conditions`).

What counts as a number: real values of an integer or floating dtype (and, where a
function says so, complex ones for complex-step derivatives), or Python numbers. Booleans,
``timedelta64``/``datetime64``, strings, ``None``, dicts and other objects are refused
with a ``ValueError`` naming the argument: a mask or a time stamp passed where a state
belongs is a mistake, not a number.
"""

from __future__ import annotations

import numbers
import operator
from typing import Any

import numpy as np

from .._modules import moved_names
from .errors import SingularityError, WrongTypeError, row_list

#: Most threads a :class:`stewart.Platform` may use.
MAX_THREADS = 256

_NOT_NUMBERS = (bool, np.bool_, np.timedelta64, np.datetime64)


def _describe(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _real_scalar(name: str, value: Any) -> float:
    if not isinstance(value, numbers.Real) or isinstance(value, _NOT_NUMBERS):
        raise ValueError(f"{name}: expected a number, got {type(value).__name__} {_describe(value)}")
    try:
        return float(value)
    except OverflowError:
        raise ValueError(f"{name}: {_describe(value)} is too large for a float") from None


def reals(name: str, value: Any, *, allow_complex: bool = False) -> np.ndarray:
    """``value`` as a float64 array (complex128 if complex and ``allow_complex``).

    Raises ``ValueError`` naming ``name`` for anything that is not an array of real
    numbers (see the module docstring); finiteness and shape are not checked here.
    """
    try:
        arr = np.asarray(value)
    except Exception as exc:  # ragged or too deeply nested sequences, failing __array__ ...
        raise ValueError(f"{name}: cannot be read as an array ({type(exc).__name__}: {exc})") from None
    kind = arr.dtype.kind
    if kind in "iuf":
        return arr.astype(float, copy=False)
    if kind == "c" and allow_complex:
        return arr.astype(complex, copy=False)
    if kind == "O" and arr.size <= 10_000:  # Python numbers beyond int64, Fractions ...
        flat = [_real_scalar(name, v) for v in arr.flat]
        return np.array(flat, dtype=float).reshape(arr.shape)
    if arr.ndim == 0:
        raise ValueError(f"{name}: expected a number, got {type(value).__name__} {_describe(value)}")
    what = "complex numbers" if kind == "c" else f"dtype {arr.dtype}"
    raise ValueError(f"{name}: expected real numbers, got {what}")


def real(name: str, value: Any) -> float:
    """``value`` as one finite real number; ``ValueError`` naming ``name`` otherwise."""
    arr = reals(name, value)
    if arr.ndim != 0:
        raise ValueError(f"{name}: expected one number, got shape {arr.shape}")
    val = float(arr)
    if not np.isfinite(val):
        raise ValueError(f"{name}: must be finite, got {val}")
    return val


def time_step(name: str, value: Any) -> float:
    """``value`` as a positive finite number of seconds (a step of the RK4 integrators);
    ``ValueError`` naming ``name`` otherwise."""
    if type(value) is float and 0.0 < value < np.inf:  # a positive finite float passes as it is
        return value
    value = real(name, value)
    if not value > 0:
        raise ValueError(f"{name}: must be a positive number of seconds, got {value}")
    return value


def state_array(name: str, value: Any, width: int = 6, *, allow_complex: bool = False) -> np.ndarray:
    """``value`` as a float (or complex) array of shape ``(width,)`` or ``(N, width)``,
    finiteness not checked: the compiled kernel checks it row by row itself."""
    arr = reals(name, value, allow_complex=allow_complex)
    if arr.ndim not in (1, 2) or arr.shape[-1] != width:
        raise ValueError(f"{name}: expected shape ({width},) or (N, {width}), got {arr.shape}")
    return arr


def finite_states(name: str, arr: np.ndarray) -> np.ndarray:
    """``arr`` unless it holds NaN or inf: then ``ValueError`` naming ``name`` and the first bad row."""
    bad = ~np.isfinite(arr)
    if bad.any():
        if arr.ndim == 1:
            raise ValueError(f"{name}: contains NaN or inf: {arr.tolist()}")
        row = int(np.argwhere(bad.any(axis=-1))[0, 0])
        raise ValueError(f"{name}: row {row} contains NaN or inf: {arr[row].tolist()}")
    return arr


def states(name: str, value: Any, width: int = 6, *, allow_complex: bool = False) -> np.ndarray:
    """``value`` as a finite float (or complex) array of shape ``(width,)`` or ``(N, width)``.

    Raises ``ValueError`` naming ``name`` for a wrong shape, a value that is not a real
    number (complex only with ``allow_complex``) or a non-finite entry (reporting the
    first offending row of a batch).
    """
    return finite_states(name, state_array(name, value, width, allow_complex=allow_complex))


def trajectory(name: str, value: Any) -> Any:
    """``value`` if it is a trajectory, with ``sample(t)`` and ``duration``
    (:mod:`stewart.motion.trajectory`); :class:`~stewart.WrongTypeError` naming ``name`` otherwise."""
    if not (callable(getattr(value, "sample", None)) and hasattr(value, "duration")):
        raise WrongTypeError(f"{name}: expected an object with sample(t) and duration (stewart.PointToPoint, "
                             f"SampledTrajectory ...), got {type(value).__name__}")
    return value


def sampled(name: str, trajectory: Any, times: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``trajectory.sample(times)`` of the trajectory named ``name``, checked at the boundary:
    three finite float arrays of shape ``(len(times), 6)`` (or ``(6,)`` for a scalar time);
    ``ValueError`` naming ``name`` otherwise."""
    shape = (6,) if np.ndim(times) == 0 else (len(times), 6)
    out = trajectory.sample(times)
    if not isinstance(out, tuple) or len(out) != 3:
        raise ValueError(f"{name}: sample(t) must return (x, xdot, xddot), got {type(out).__name__}")
    checked = []
    for part, arr in zip(("x", "xdot", "xddot"), out):
        arr = states(f"{name}: sample(t)'s {part}", arr)
        if np.iscomplexobj(arr) or arr.shape != shape:
            raise ValueError(f"{name}: sample(t)'s {part} must be real with shape {shape} for "
                             f"{shape[0] if len(shape) == 2 else 'one'} time(s), got {arr.dtype} {arr.shape}")
        checked.append(np.ascontiguousarray(arr, dtype=float))
    return tuple(checked)


def same_batch(**arrays: np.ndarray) -> None:
    """Raise ``ValueError`` unless the arrays share one leading shape."""
    shapes = {name: arr.shape[:-1] for name, arr in arrays.items()}
    if len(set(shapes.values())) > 1:
        desc = ", ".join(f"{name} {arr.shape}" for name, arr in arrays.items())
        raise ValueError(f"arguments must have matching batch shapes: {desc}")


def count(name: str, value: Any, maximum: int) -> int:
    """``value`` as an int (not a bool) from 1 to ``maximum``; ``ValueError`` naming ``name`` otherwise."""
    if isinstance(value, _NOT_NUMBERS):
        raise ValueError(f"{name}: expected an integer, got {_describe(value)}")
    try:
        number = operator.index(value)
    except TypeError:
        raise ValueError(f"{name}: expected an integer, got {type(value).__name__} {_describe(value)}") from None
    if not 1 <= number <= maximum:
        raise ValueError(f"{name}: must be from 1 to {maximum}, got {number}")
    return number


def seed(value: Any, name: str = "seed") -> int:
    """A seed of random numbers: an int (not a bool) >= 0; ``ValueError`` naming ``name`` otherwise."""
    if isinstance(value, _NOT_NUMBERS) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ValueError(f"{name}: expected a whole number >= 0, got {_describe(value)}")
    return int(value)


def thread_count(value: Any) -> int:
    """A thread count: an int (not a bool) from 1 to :data:`MAX_THREADS`."""
    return count("threads", value, MAX_THREADS)


def _rows(bad: np.ndarray) -> tuple[list[int], str]:
    rows = np.flatnonzero(bad).tolist()
    return rows, row_list(rows)


def _arrays(result: Any):
    if isinstance(result, dict):
        result = tuple(result.values())
    if isinstance(result, tuple):
        for item in result:
            yield from _arrays(item)
    else:
        yield np.asarray(result)


def _nonfinite_rows(result: Any, n: int) -> np.ndarray:
    """Which of the ``n`` rows of ``result`` (an array, or a tuple or dict of them) hold NaN or inf."""
    bad = np.zeros(n, dtype=bool)
    for arr in _arrays(result):
        bad |= ~np.isfinite(arr.reshape(n, -1)).all(axis=1)
    return bad


def finite_result(function: str, result: Any, x: np.ndarray) -> Any:
    """``result`` (an array, or a tuple or dict of them) of ``function`` at the state(s)
    ``x``, unless it holds NaN or inf: then :class:`SingularityError` naming the rows, with
    the condition ``"nonfinite"``."""
    n = x.shape[0] if x.ndim == 2 else 1
    if n == 0:
        return result
    bad = _nonfinite_rows(result, n)
    if bad.any():
        rows, text = _rows(bad)
        raise SingularityError(
            f"{function}: non-finite result at row(s) {text} (an input too large for double precision)",
            rows=rows,
            condition="nonfinite",
        )
    return result


def finite_rows(function: str, values: np.ndarray, ok: Any, return_mask: bool) -> Any:
    """The result of a method with ``return_mask`` (as the compiled kernel's methods give it)
    computed from the kernel's ``values`` ``(..., 6)`` and mask ``ok``, where a row of
    ``values`` may overflow: with ``return_mask``, ``(values, ok)`` with the non-finite rows
    set to NaN and marked failed in ``ok``; without, ``values`` unless a row is not finite
    (:func:`finite_result`)."""
    if not return_mask:
        return finite_result(function, values, values)
    bad = _nonfinite_rows(values, values.shape[0] if values.ndim == 2 else 1)
    if not bad.any():
        return values, ok
    values[bad.reshape(values.shape[:-1])] = np.nan
    return values, (ok & ~bad) if values.ndim == 2 else bool(ok and not bad[0])


#: Moved in 0.2.1, deprecated aliases until 0.3.0.
__getattr__ = moved_names(__name__, {"platform_params": "stewart.model.params"})
