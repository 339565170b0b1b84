"""The checks of the fields of :class:`~stewart.PlatformParams`: each takes the field's name
and value and returns the value as stored (a float or a float array), or raises
``ValueError`` naming the field; also the checks of :meth:`~stewart.PlatformParams.with_payload`'s
arguments."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from . import arguments

__all__ = ["dataclass_from", "TOLERANCE", "BOUNDS", "vector3", "scalar", "points", "inertia", "inertia_tensor", "optional_bound",
           "joint_axes", "friction", "leg_coefficients", "offsets", "positive", "readonly"]


def dataclass_from(cls, data) -> Any:
    """The parameter dataclass ``cls`` from a mapping of its fields (the layout of its
    ``to_dict``): a name it does not have, or one of its required fields left out, is a
    ``ValueError`` naming them; each field's own check is the constructor's."""
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(str(key) for key in set(data) - names)
    if unknown:
        raise ValueError(f"unknown parameter field(s): {', '.join(unknown)}")
    missing = sorted(f.name for f in dataclasses.fields(cls)
                     if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
                     and f.name not in data)
    if missing:
        raise ValueError(f"missing parameter field(s): {', '.join(missing)}")
    return cls(**data)


def vector3(name: str, value: Any) -> np.ndarray:
    arr = arguments.reals(name, value)
    if arr.shape != (3,):
        raise ValueError(f"{name}: expected 3 values, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: values must be finite, got {arr.tolist()}")
    return arr


def scalar(name: str, value: Any, minimum: float | None = 0.0) -> float:
    val = arguments.real(name, value)
    if minimum is not None and val < minimum:
        raise ValueError(f"{name}: must be >= {minimum}, got {val}")
    return val


def points(name: str, value: Any) -> np.ndarray:
    arr = arguments.reals(name, value)
    if arr.shape != (6, 3):
        raise ValueError(f"{name}: expected shape (6, 3), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: coordinates must be finite")
    with np.errstate(over="ignore", invalid="ignore"):
        centred = arr - arr.mean(axis=0)
        scale = np.max(np.linalg.norm(centred, axis=1))
    if not np.isfinite(scale):
        raise ValueError(f"{name}: coordinates too large for double precision")
    if scale == 0.0:
        raise ValueError(f"{name}: all six points coincide")
    for i in range(6):
        for j in range(i + 1, 6):
            if np.linalg.norm(arr[i] - arr[j]) <= 1e-9 * scale:
                raise ValueError(f"{name}: points {i} and {j} coincide")
    sv = np.linalg.svd(centred, compute_uv=False)
    if sv[1] <= 1e-9 * sv[0]:
        raise ValueError(f"{name}: the six points are collinear (degenerate platform)")
    return arr


def inertia(name: str, value: Any) -> np.ndarray:
    arr = vector3(name, value)
    return _moments(name, arr)


def _moments(name: str, arr: np.ndarray) -> np.ndarray:
    if np.any(arr < 0.0):
        raise ValueError(f"{name}: principal moments must be >= 0, got {arr.tolist()}")
    with np.errstate(over="ignore"):  # moments near the largest double: their sum is inf, the test holds
        total = arr.sum()
        holds = [arr[k] <= total - arr[k] + 1e-12 * total for k in range(3)]
    for k in range(3):
        if not holds[k]:
            raise ValueError(
                f"{name}: principal moments {arr.tolist()} violate the triangle inequality "
                f"(moment {k} exceeds the sum of the other two)"
            )
    return arr


#: Optional workspace bounds and their largest values (the smallest is always > 0).
BOUNDS = {"universal_joint_max_angle": np.pi / 2, "spherical_joint_max_angle": np.pi / 2, "leg_diameter": np.inf,
           "plate_radius": np.inf, "base_clearance": np.inf}


def optional_bound(name: str, value: Any, maximum: float) -> float | None:
    if value is None:
        return None
    val = arguments.real(name, value)
    if not 0.0 < val <= maximum:
        need = "> 0 (metres)" if maximum == np.inf else f"0 < angle <= {maximum:.6g} (a cone half-angle in radians)"
        raise ValueError(f"{name}: need {need}, got {val}")
    return val


#: Tolerance of the parameter checks on unit vectors and on the symmetry of a tensor
#: (relative), and on the angle in radians between a joint axis and its leg at home.
TOLERANCE = 1e-6


def inertia_tensor(name: str, value: Any) -> np.ndarray:
    """Principal moments (3,) as given, or a symmetric positive-semidefinite (3, 3) tensor
    whose eigenvalues (the principal moments) satisfy the triangle inequality."""
    arr = arguments.reals(name, value)
    if arr.shape == (3,):
        return inertia(name, arr)
    if arr.shape != (3, 3):
        raise ValueError(f"{name}: expected 3 principal moments or a (3, 3) tensor, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: values must be finite, got {arr.tolist()}")
    if np.max(np.abs(arr - arr.T)) > TOLERANCE * np.max(np.abs(arr)):
        raise ValueError(f"{name}: the inertia tensor must be symmetric, got {arr.tolist()}")
    with np.errstate(over="ignore"):  # entries near the largest double
        moments = np.linalg.eigvalsh(0.5 * arr + 0.5 * arr.T)
        slack = 1e-12 * max(float(np.sum(np.abs(moments))), np.finfo(float).tiny)
    if not np.all(np.isfinite(moments)):
        raise ValueError(f"{name}: too large for double precision, got {arr.tolist()}")
    if np.any(moments < -slack):
        raise ValueError(f"{name}: the inertia tensor must be positive-semidefinite, "
                         f"got eigenvalues {moments.tolist()}")
    _moments(name, np.maximum(moments, 0.0))
    return arr


def joint_axes(name: str, value: Any) -> np.ndarray | None:
    """Six unit vectors (6, 3), each within :data:`TOLERANCE` of length 1."""
    if value is None:
        return None
    arr = arguments.reals(name, value)
    if arr.shape != (6, 3):
        raise ValueError(f"{name}: expected shape (6, 3), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: values must be finite, got {arr.tolist()}")
    norms = np.sqrt(np.sum(arr * arr, axis=1))
    bad = np.flatnonzero(np.abs(norms - 1.0) > TOLERANCE)
    if bad.size:
        i = int(bad[0])
        what = "is zero" if norms[i] == 0.0 else f"has length {norms[i]:.12g}"
        raise ValueError(f"{name}: axis {i} {what}; each axis must be a unit vector")
    return arr


def friction(name: str, value: Any) -> np.ndarray | None:
    """Six coefficients >= 0, one per leg, or None."""
    if value is None:
        return None
    arr = arguments.reals(name, value)
    if arr.shape != (6,):
        raise ValueError(f"{name}: expected 6 values (one per leg), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)) or np.any(arr < 0.0):
        raise ValueError(f"{name}: values must be finite and >= 0, got {arr.tolist()}")
    return arr


def leg_coefficients(name: str, value: Any, *, positive: bool) -> np.ndarray:
    """``value`` (one number, or one per leg) as six finite floats, each > 0 (``positive``) or
    >= 0; ``ValueError`` naming ``name`` otherwise: the legs' stiffness and damping."""
    arr = arguments.reals(name, value)
    if arr.shape not in ((), (1,), (6,)):
        raise ValueError(f"{name}: expected one value or one per leg (6), got shape {arr.shape}")
    arr = np.broadcast_to(arr, (6,)).astype(float)
    bad = ~np.isfinite(arr) | ((arr <= 0.0) if positive else (arr < 0.0))
    if bad.any():
        raise ValueError(f"{name}: must be finite and {'> 0' if positive else '>= 0'} on every leg, "
                         f"got {arr.tolist()}")
    return arr


def offsets(name: str, value: Any) -> np.ndarray:
    """Six finite lengths in metres, one per leg (any sign)."""
    arr = arguments.reals(name, value)
    if arr.shape != (6,):
        raise ValueError(f"{name}: expected 6 values (one per leg), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: values must be finite, got {arr.tolist()}")
    return arr.astype(float, copy=True)


def positive(name: str, value: Any) -> float:
    val = arguments.real(name, value)
    if not 0.0 < val < np.inf:
        raise ValueError(f"{name}: must be a positive finite number, got {val}")
    return val


def readonly(arr: np.ndarray) -> np.ndarray:
    arr.flags.writeable = False
    return arr
