"""Base parameters: the combinations of the inertial parameters the actuator forces determine.

The forces are linear in the inertial parameters, ``tau = Y pi`` (:meth:`stewart.Platform.regressor`),
but not every column of ``Y`` is independent: some parameters never act (the cylinders'
mass, the legs' axial moments when they do not spin) and some act only in fixed combinations
(the cylinders' and pistons' transverse moments always together). Measured forces can only
ever determine the base parameters ``beta = K pi``, with ``Y pi == Y[..., indices] @ beta`` for
every state.

:func:`base_parameters` finds them numerically, as in the identification of serial robots
(Gautier, "Numerical calculation of the base inertial parameters of robots", 1991): the
regressors of random states are stacked, their columns scaled to unit norm, and a QR
factorization with column pivoting picks a set of independent columns (``|R_kk|`` above
:data:`RANK_TOLERANCE`; ``|R_00|``, the norm of the first pivot, is 1); every other column is a
combination of those, found by least squares on the stack, and adds its parameter to theirs
with that coefficient.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.linalg

from ..model import arguments
from ..model.sampling import random_states
from ..model.params import INERTIAL_NAMES, NUM_RIGID_BODY
from ..model.platform import as_platform

__all__ = ["BaseParameters", "base_parameters", "RANK_TOLERANCE"]

#: Size of ``|R_kk|`` (columns scaled to unit norm, so that ``|R_00| = 1``) below which a column
#: counts as a combination of the columns before it.
RANK_TOLERANCE = 1e-9
#: Coefficients within this of an integer are that integer; smaller ones are zero.
ROUNDING = 1e-9


@dataclasses.dataclass(frozen=True)
class BaseParameters:
    """The base parameters ``beta = K pi`` of a platform's regressor.

    Attributes
    ----------
    names : one readable combination per base parameter, e.g. ``"cylinder.Iyy + piston.Iyy"``.
    indices : ``(r,)`` the independent columns of ``Y``, in the order of ``columns``.
    matrix : ``(r, p)`` ``K``, with ``Y pi == Y[..., indices] @ (K pi)`` for every state.
    columns : the ``p`` names of ``pi`` it was computed over (:meth:`PlatformParams.inertial_names`,
        without the friction for ``friction=False``).
    scale : ``(r,)`` the RMS of each independent column over the random states: a column's size
        when every coordinate moves, against which a trajectory's excitation is measured.
    """

    names: tuple[str, ...]
    indices: np.ndarray
    matrix: np.ndarray
    columns: tuple[str, ...]
    scale: np.ndarray

    @property
    def rank(self) -> int:
        return len(self.indices)

    def values(self, pi) -> np.ndarray:
        """``beta = K pi`` for the inertial parameters ``pi`` (all of them, or the ``columns``)."""
        pi = arguments.reals("pi", pi)
        if pi.shape == (len(INERTIAL_NAMES),):
            pi = pi[: len(self.columns)]
        if pi.shape != (len(self.columns),):
            raise ValueError(f"pi: expected {len(self.columns)} inertial parameters, got shape {pi.shape}")
        return self.matrix @ pi

    def reduce(self, regressor) -> np.ndarray:
        """The base regressor ``Y[..., indices]`` of a regressor ``(..., 6, 32)`` (or its ``columns``)."""
        return np.asarray(regressor)[..., self.indices]

    def describe(self) -> str:
        """How ``pi`` maps to ``beta``: one line per base parameter, and the parameters that never act."""
        acting = np.any(self.matrix != 0.0, axis=0)
        lines = [f"beta_{k} = {name}" for k, name in enumerate(self.names)]
        idle = [name for name, used in zip(self.columns, acting) if not used]
        if idle:
            lines.append("never act: " + ", ".join(idle))
        return "\n".join(lines)


def _combination(names, coefficients) -> str:
    terms = []
    for name, c in zip(names, coefficients):
        if c == 0.0:
            continue
        sign = "-" if c < 0 else "+"
        size = abs(c)
        text = name if size == 1.0 else f"{size:.6g} {name}"
        terms.append((sign, text))
    first_sign, first = terms[0]
    return (("-" if first_sign == "-" else "") + first
            + "".join(f" {sign} {text}" for sign, text in terms[1:]))


def _rounded(values: np.ndarray, scale: float) -> np.ndarray:
    out = np.where(np.abs(values) <= ROUNDING * scale, 0.0, values)
    nearest = np.round(out)
    return np.where(np.abs(out - nearest) <= ROUNDING * np.maximum(1.0, np.abs(nearest)), nearest, out)


def base_parameters(platform, *, samples: int = 200, seed: int = 0, friction: bool = True) -> BaseParameters:
    """The base parameters of ``platform`` (a :class:`stewart.Platform` or :class:`stewart.PlatformParams`) from its regressor at
    ``samples`` random states around home (:func:`stewart.oracles.physics.random_states`, seeded);
    ``friction=False`` leaves the friction columns out."""
    platform = as_platform(platform)
    samples = arguments.count("samples", samples, 10**6)
    if samples < 10:
        raise ValueError(f"samples: need at least 10 states, got {samples}")
    rng = np.random.default_rng(arguments.seed(seed))
    x, xd, xdd = random_states(platform.params, samples, rng)
    Y, ok = platform.regressor(x, xd, xdd, return_mask=True)
    if ok.sum() < 10:
        raise ValueError("samples: fewer than 10 of the random states are inside the model's domain")
    p = len(INERTIAL_NAMES) if friction else NUM_RIGID_BODY
    stack = Y[ok][..., :p].reshape(-1, p)
    norms = np.linalg.norm(stack, axis=0)
    acting = np.flatnonzero(norms > 0.0)
    _, r, pivots = scipy.linalg.qr(stack[:, acting] / norms[acting], mode="economic", pivoting=True)
    diagonal = np.abs(np.diag(r))
    rank = int(np.sum(diagonal > RANK_TOLERANCE))  # |R_00| = 1: the pivots are unit columns
    independent = np.sort(acting[pivots[:rank]])
    dependent = np.setdiff1d(acting, independent)
    matrix = np.zeros((rank, p))
    matrix[np.arange(rank), independent] = 1.0
    if dependent.size:
        coefficients, *_ = np.linalg.lstsq(stack[:, independent], stack[:, dependent], rcond=None)
        # in the units of each pair: beta_j gains c pi_d, c in units of column d over column j
        matrix[:, dependent] = _rounded(coefficients, 1.0)
    columns = INERTIAL_NAMES[:p]
    names = tuple(_combination(columns, row) for row in matrix)
    scale = np.sqrt(np.mean(stack[:, independent] ** 2, axis=0))
    return BaseParameters(names=names, indices=independent, matrix=matrix, columns=columns, scale=scale)
