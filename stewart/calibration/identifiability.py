"""Which parameter combinations the measurements determine: the singular value decomposition of
the column-scaled identification Jacobian (Hollerbach, Khalil & Gautier 2016, ch. 6), its
condition number and its named null space.

Each column of the weighted Jacobian is divided by its norm, so that the condition number
does not depend on the units or the scale of a parameter. A singular value below
:data:`RANK_TOLERANCE` times the largest leaves a direction of the parameters that changes
no residual, or so little that its standard error is more than ``1 / RANK_TOLERANCE`` times
that of the best-determined combination (measurement noise then decides it, as when nearly
level poses carry the noise of a tracker's angles): the data cannot determine it. The null space is written in a readable basis:
column-pivoted QR picks one parameter per direction, and each direction is the change of the
others that compensates a unit change of that one (a reduced row-echelon form of the basis).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

__all__ = ["Identifiability", "UnidentifiableError", "identifiability", "scaled_svd", "RANK_TOLERANCE"]

#: Singular values of the column-scaled Jacobian at most this fraction of the largest are zero:
#: a condition number above 1e5 (well-spread poses give a few thousand) is unidentifiable data.
RANK_TOLERANCE = 1e-5
#: Terms shown per combination, and the smallest coefficient shown (relative to the largest).
_TERMS, _SMALLEST = 6, 1e-3


class UnidentifiableError(ValueError):
    """The measurements leave parameter combinations undetermined; ``identifiability`` is the
    :class:`Identifiability` of the data."""

    def __init__(self, message: str, identifiability: "Identifiability"):
        super().__init__(message)
        self.identifiability = identifiability


@dataclass(frozen=True)
class Identifiability:
    """``singular_values`` of the column-scaled Jacobian (largest first), its ``condition``
    number (``inf`` when rank deficient) and the undetermined ``combinations``: one string
    per null-space direction, ``"a + 0.5 b - c"`` meaning that raising ``a`` by 1 while ``b``
    rises by 0.5 and ``c`` falls by 1 changes no residual."""

    singular_values: np.ndarray
    condition: float
    combinations: tuple[str, ...]
    directions: np.ndarray

    @property
    def identifiable(self) -> bool:
        return not self.combinations


def identifiability(jacobian: np.ndarray, names, free: np.ndarray | None = None) -> Identifiability:
    """The :class:`Identifiability` of the weighted Jacobian ``(rows, columns)`` whose columns
    are the parameters ``names``, in the parameter directions ``free`` (columns x k, an
    orthonormal basis; default all), those a gauge constraint leaves free."""
    if free is not None:
        report = identifiability(jacobian @ free, [f"direction {k}" for k in range(free.shape[1])])
        if report.identifiable:
            return report
        directions = free @ report.directions
        return _named(report.singular_values, report.condition, directions, names)
    norms = np.sqrt(np.sum(jacobian * jacobian, axis=0))
    scale = np.where(norms > 0.0, 1.0 / np.where(norms > 0.0, norms, 1.0), 0.0)
    sv, vt = scaled_svd(jacobian * scale)
    null = sv <= RANK_TOLERANCE * sv[0]
    condition = float(np.inf if null.any() else sv[0] / sv[-1])
    if not null.any():
        return Identifiability(sv, condition, (), np.zeros((jacobian.shape[1], 0)))
    basis = (vt[null].T * scale[:, None])  # the directions in the parameters' own units
    basis[norms == 0.0] = vt[null].T[norms == 0.0]  # a parameter nothing depends on
    return _named(sv, condition, basis, names)


def _named(sv, condition, basis: np.ndarray, names) -> Identifiability:
    """The :class:`Identifiability` whose null space is spanned by the columns of ``basis``,
    written in the readable basis of the module's docstring."""
    _, _, pivots = scipy.linalg.qr(basis.T, pivoting=True)
    lead = pivots[:basis.shape[1]]
    directions = basis @ np.linalg.inv(basis[lead])
    directions[np.abs(directions) < 1e-12 * np.max(np.abs(directions), axis=0)] = 0.0
    combos = tuple(_combination(directions[:, k], lead[k], names) for k in range(len(lead)))
    return Identifiability(sv, condition, combos, directions)


def scaled_svd(jacobian: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The singular values (largest first) and right singular vectors (rows) of ``jacobian``,
    from the eigenvalues of its normal matrix ``J^T J`` (columns x columns): a small
    symmetric eigenproblem instead of a factorization of the tall ``J``. Its singular values
    are exact to about ``1e-8`` of the largest, far below :data:`RANK_TOLERANCE`."""
    # einsum's own loop, not a threaded BLAS product: a few milliseconds on a busy machine too.
    eigenvalues, vectors = np.linalg.eigh(np.einsum("ri,rj->ij", jacobian, jacobian))
    return np.sqrt(np.maximum(eigenvalues[::-1], 0.0)), vectors[:, ::-1].T


def _combination(direction: np.ndarray, lead: int, names) -> str:
    others = [i for i in np.argsort(-np.abs(direction)) if i != lead and
              abs(direction[i]) > _SMALLEST * abs(direction[lead])]
    terms = [names[lead]] + [f"{'+' if direction[i] > 0 else '-'} {abs(direction[i]):.3g} {names[i]}"
                             for i in others[:_TERMS - 1]]
    more = len(others) - (_TERMS - 1)
    return " ".join(terms) + (f" (+{more} more)" if more > 0 else "")
