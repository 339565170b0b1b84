"""Where the model is undefined: the generated C's conditions, with its tolerances and its
tests, for the numpy modules (:mod:`stewart.oracles.reference`, :mod:`stewart.oracles.newton_euler`,
:mod:`stewart.model.kinematics`, :mod:`stewart.motion.control`).

The conditions and their tolerances are the generated C's (``codegen/conditions.py``),
read from the generator's table (:mod:`stewart._generated`), never retyped. Each test below is the C's test
written in numpy, so that the kernel and the numpy modules agree on whether a state is
defined and raise the same :class:`~stewart.SingularityError` condition:

* ``leg_degenerate``: a leg with ``L_i^2 < DEGENERATE_TOL`` (``DBL_MIN``);
* ``nonfinite``: a leg length that overflows (and, in :mod:`stewart.model.arguments`, a result);
* ``leg_vertical``: ``l_x^2 + l_y^2 < VERTICAL_TOL L_i^2`` with non-axisymmetric leg
  inertia, where the cylinder frame of eqs. 44-47 is undefined;
* ``gimbal_lock``: ``|a_i x l_i|^2 < GIMBAL_TOL L_i^2`` for the general model's universal-joint
  axes ``a_i``, where the leg frame ``y = a_i x u_i / |a_i x u_i|`` is undefined;
* ``jacobian_singular``: the Hadamard ratio ``|det J_C| / prod_i |row_i(J_C)|`` of eq. 5's
  ``J_C`` below ``JACOBIAN_TOL``;
* ``euler_singular``: ``|cos theta| < EULER_TOL``, where the Euler-rate map ``J_A`` of
  eq. 8 is singular;
* ``mass_singular``: an ``LDL^T`` pivot ``d_k`` of the twist-space mass matrix ``M_t``
  (eqs. 19-23) with ``d_k <= MASS_TOL M_t[k, k]`` or ``M_t[k, k] <= 0``.

Each function checks in the C's order (:func:`check`): the legs (zero length, overflow,
vertical, gimbal lock), then its own steps; a batch fails with the condition of its first bad row.
"""

from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

import numpy as np

from .._generated import CONDITIONS as _GENERATED
from .errors import SingularityError

__all__ = [
    "Condition",
    "CONDITIONS",
    "Status",
    "hadamard_ratio",
    "ldl_pivots",
    "leg_codes",
    "jacobian_codes",
    "euler_codes",
    "mass_codes",
    "check",
]


class Condition(NamedTuple):
    """A status code of the generated C: its number, name, message and tolerance."""

    code: int
    name: str
    message: str
    tolerance: float | None


#: Every condition by name, in the order of the C status codes.
CONDITIONS = {name: Condition(code, name, message, tol) for code, (name, message, tol) in sorted(_GENERATED.items())}
_BY_CODE = {c.code: c for c in CONDITIONS.values()}

#: The status codes by name (``Status.JACOBIAN_SINGULAR``), from the table.
Status = IntEnum("Status", {c.name.upper(): c.code for c in CONDITIONS.values()})

#: Smallest squared leg length ``L_i^2`` (m^2) of a leg that is not degenerate.
DEGENERATE_TOL = CONDITIONS["leg_degenerate"].tolerance
#: A leg is vertical when ``l_x^2 + l_y^2 < VERTICAL_TOL L_i^2``.
VERTICAL_TOL = CONDITIONS["leg_vertical"].tolerance
#: A leg is in its universal joint's gimbal lock when ``|a_i x l_i|^2 < GIMBAL_TOL L_i^2``.
GIMBAL_TOL = CONDITIONS["gimbal_lock"].tolerance
#: ``J_C`` is singular when its Hadamard ratio is below this.
JACOBIAN_TOL = CONDITIONS["jacobian_singular"].tolerance
#: ``J_A`` is singular when ``|cos theta|`` is below this.
EULER_TOL = CONDITIONS["euler_singular"].tolerance
#: ``M_t`` is singular when an ``LDL^T`` pivot is at most this times its diagonal entry.
MASS_TOL = CONDITIONS["mass_singular"].tolerance


def hadamard_ratio(jac) -> np.ndarray:
    """``|det J| / prod_i |row_i(J)|`` of 6x6 matrices ``(..., 6, 6)``: 1 for orthogonal rows,
    0 for a singular matrix, unchanged by scaling a row (NaN for a non-finite matrix)."""
    jac = np.real(jac)
    with np.errstate(all="ignore"):
        return np.abs(np.linalg.det(jac)) / np.prod(np.sqrt(np.sum(jac * jac, axis=-1)), axis=-1)


def ldl_pivots(mt) -> np.ndarray:
    """The pivots ``d_k`` of the ``LDL^T`` factorization (no pivoting, as in the C) of the
    symmetric matrices ``mt`` ``(..., 6, 6)``, shape ``(..., 6)``."""
    m = np.array(np.real(mt), dtype=float)
    pivots = np.empty(m.shape[:-1])
    with np.errstate(all="ignore"):
        for k in range(m.shape[-1]):
            pivots[..., k] = m[..., k, k]
            factors = m[..., k, k + 1:] / m[..., k, k, None]
            m[..., k + 1:, k + 1:] -= factors[..., :, None] * m[..., k, None, k + 1:]
    return pivots


def _first(tests: list[tuple[np.ndarray, int]], n: int) -> np.ndarray:
    """Per row, the code of the first test (``bad``, code) that fails; ``Status.OK`` if none."""
    codes = np.full(n, Status.OK)
    for bad, code in reversed(tests):
        codes[np.asarray(bad).reshape(n)] = code
    return codes


def leg_codes(length_sq, horizontal_sq=None, locked_sq=None) -> np.ndarray:
    """The C's leg tests per row, from ``L_i^2``, (for the paper's model with non-axisymmetric
    leg inertia) ``l_x^2 + l_y^2`` and (for the general model) ``|a_i x l_i|^2`` of the legs,
    shapes ``(..., 6)``: ``leg_degenerate`` if a leg has ``L_i^2 < DEGENERATE_TOL`` (or NaN),
    else ``nonfinite`` if a length overflows, else ``leg_vertical`` if a leg has
    ``l_x^2 + l_y^2 < VERTICAL_TOL L_i^2``, else ``gimbal_lock`` if a leg has
    ``|a_i x l_i|^2 < GIMBAL_TOL L_i^2``."""
    length_sq = np.real(length_sq).reshape(-1, 6)
    tests = [
        (~(length_sq >= DEGENERATE_TOL).all(axis=1), Status.LEG_DEGENERATE),
        (~(length_sq <= np.finfo(float).max).all(axis=1), Status.NONFINITE),
    ]
    if horizontal_sq is not None:
        horizontal_sq = np.real(horizontal_sq).reshape(-1, 6)
        tests.append((~(horizontal_sq >= VERTICAL_TOL * length_sq).all(axis=1), Status.LEG_VERTICAL))
    if locked_sq is not None:
        locked_sq = np.real(locked_sq).reshape(-1, 6)
        tests.append((~(locked_sq >= GIMBAL_TOL * length_sq).all(axis=1), Status.GIMBAL_LOCK))
    return _first(tests, len(length_sq))


def jacobian_codes(jac) -> np.ndarray:
    """``jacobian_singular`` where the Hadamard ratio of ``J_C`` ``(..., 6, 6)`` is below
    ``JACOBIAN_TOL`` (or NaN), per row."""
    ratio = hadamard_ratio(jac).reshape(-1)
    return _first([(~(ratio >= JACOBIAN_TOL), Status.JACOBIAN_SINGULAR)], ratio.size)


def euler_codes(x) -> np.ndarray:
    """``euler_singular`` where ``|cos theta| < EULER_TOL`` for the poses ``x`` ``(..., 6)``, per row."""
    cos_theta = np.abs(np.cos(np.real(x)[..., 4])).reshape(-1)
    return _first([(~(cos_theta >= EULER_TOL), Status.EULER_SINGULAR)], cos_theta.size)


def mass_codes(mt) -> np.ndarray:
    """``mass_singular`` where the twist-space mass matrix ``M_t`` ``(..., 6, 6)`` is not
    positive definite by the C's rule, per row: an ``LDL^T`` pivot ``d_k <= MASS_TOL M_t[k, k]``
    or ``M_t[k, k] <= 0``."""
    mt = np.real(mt).reshape(-1, 6, 6)
    diag = np.diagonal(mt, axis1=-2, axis2=-1)
    with np.errstate(invalid="ignore"):
        good = (diag > 0.0) & (ldl_pivots(mt) > MASS_TOL * diag)
    return _first([(~good.all(axis=1), Status.MASS_SINGULAR)], len(mt))


def check(function: str, x: np.ndarray, *tests) -> None:
    """Raise :class:`~stewart.SingularityError` as the generated C's ``function`` would at
    the state(s) ``x`` ``(6,)`` or ``(N, 6)``: ``tests`` are in the C's order of precedence,
    each an array of codes for every row or a function of the indices of the rows that
    passed so far returning their codes. The error names the condition of the first bad
    row and lists every bad row."""
    n = 1 if x.ndim == 1 else len(x)
    codes = np.full(n, Status.OK)
    for test in tests:
        todo = np.flatnonzero(codes == Status.OK)
        if todo.size == 0:
            break
        codes[todo] = test(todo) if callable(test) else np.asarray(test).reshape(n)[todo]
    rows = np.flatnonzero(codes != Status.OK)
    if rows.size:
        condition = _BY_CODE[int(codes[rows[0]])]
        raise SingularityError.at_rows(function, condition.name, condition.message, rows.tolist(), x.ndim == 2)
