"""Derivatives of the dynamics.

The oracle is complex-step differentiation of the numeric reference
(:func:`stewart.checks.reference_inverse_dynamics_jacobians` and its kin), never of the
kernel. It is checked first against what it must equal exactly: its own complex-input
path, the identities ``dtau/dxddot = J_C^-T M`` and ``dxddot/dtau = M^-1 J_C^T`` built
from the reference's ``M`` and ``J_C``, the implicit-function relation between its
inverse and forward Jacobians, and central differences of the real reference.
"""

from __future__ import annotations

import functools
import warnings
from typing import NamedTuple

import numpy as np
import pytest

import stewart
from stewart import reference as ref
from stewart.checks import (
    random_states,
    reference_forward_dynamics_jacobians,
    reference_inverse_dynamics_jacobians,
    relative_error,
)
from conftest import random_params

#: States per preset, and per random platform.
PRESET_STATES = 1000
RANDOM_STATES = 200
#: Random platforms: axisymmetric legs, and legs with I_yy != I_zz (the frame form).
RANDOM_PLATFORMS = ("random-axisymmetric", "random-general")
CASES = sorted(stewart.presets()) + list(RANDOM_PLATFORMS)


class Case(NamedTuple):
    """One parameter set, its random states and the oracle's Jacobians there."""

    params: stewart.PlatformParams
    x: np.ndarray
    xd: np.ndarray
    xdd: np.ndarray
    tau: np.ndarray
    inverse: tuple  # (dtau/dx, dtau/dxd, dtau/dxdd)
    forward: tuple  # (dxdd/dx, dxdd/dxd, dxdd/dtau)


@functools.cache
def case(name: str) -> Case:
    """The states and oracle Jacobians of ``name`` (a preset or a random platform), computed once."""
    rng = np.random.default_rng(sum(map(ord, name)))
    if name in RANDOM_PLATFORMS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
            params = random_params(rng, axisymmetric=name == "random-axisymmetric").replace(name=name)
        n = RANDOM_STATES
    else:
        params = stewart.PlatformParams.preset(name)
        n = PRESET_STATES
    x, xd, xdd = random_states(params, n, rng)
    tau = ref.inverse_dynamics(params, x, xd, xdd)
    return Case(
        params, x, xd, xdd, tau,
        reference_inverse_dynamics_jacobians(params, x, xd, xdd),
        reference_forward_dynamics_jacobians(params, x, xd, tau),
    )


def _solve_t(a, b):
    """``a^-T b`` for stacks of matrices."""
    return np.linalg.solve(np.swapaxes(a, -1, -2), b)


# --- the oracle ------------------------------------------------------------------------


@pytest.mark.parametrize("name", CASES)
def test_complex_input_path_matches_the_real_one(name, figures):
    """With complex inputs the reference takes dA/dt by a sixth-order central difference
    instead of a complex step: at zero imaginary part it must give the real results."""
    c = case(name)
    rows = slice(0, 200)
    x, xd, xdd, tau = c.x[rows], c.xd[rows], c.xdd[rows], c.tau[rows]
    worst = max(
        relative_error(ref.inverse_dynamics(c.params, x + 0j, xd + 0j, xdd), tau),
        relative_error(ref.forward_dynamics(c.params, x + 0j, xd + 0j, tau), xdd),
    )
    figures(f"oracle: complex-input reference vs real ({name})", worst, 1e-12)
    figures(
        f"oracle: complex-input V xdot vs real ({name})",
        relative_error(_coriolis_vector(c.params, x + 0j, xd), ref.coriolis_vector(c.params, x, xd)),
        5e-11,
    )


def _coriolis_vector(params, x, xd):
    """``V xdot`` summed from the reference's body terms (which take complex inputs)."""
    parts = [
        term.coriolis_matrix if body.startswith("platform") else term.coriolis_matrix.sum(axis=-3)
        for body, term in ref.body_terms(params, x, xd).items()
    ]
    return np.einsum("...ij,...j->...i", sum(parts), xd)


@pytest.mark.parametrize("name", CASES)
def test_oracle_identities(name, figures):
    """``dtau/dxddot = J_C^-T M`` and ``dxddot/dtau = M^-1 J_C^T`` from the reference's own
    ``M`` and ``J_C`` (exact: tau is linear in xddot)."""
    c = case(name)
    mass = ref.mass_matrix(c.params, c.x)
    jac = stewart.jacobian(c.params, c.x)
    worst = max(
        relative_error(c.inverse[2], _solve_t(jac, mass)),
        relative_error(c.forward[2], np.linalg.solve(mass, np.swapaxes(jac, -1, -2))),
    )
    figures(f"oracle: dtau/dxdd = J_C^-T M, dxdd/dtau = M^-1 J_C^T ({name})", worst, 1e-12)


@pytest.mark.parametrize("name", CASES)
def test_oracle_implicit_function_relation(name, figures):
    """The forward Jacobians from the inverse ones: ``dxddot/d(x, xdot) = -(dtau/dxddot)^-1
    dtau/d(x, xdot)`` (the implicit-function theorem on ``tau(x, xdot, xddot)``)."""
    c = case(name)
    worst = max(relative_error(c.forward[k], -np.linalg.solve(c.inverse[2], c.inverse[k])) for k in (0, 1))
    figures(f"oracle: forward vs implicit function of inverse ({name})", worst, 1e-10)


def _central_difference(function, point, step):
    """Columns ``(f(p + s e_j) - f(p - s e_j)) / 2s`` for a batch of points, per-state steps ``(N, n)``."""
    columns = []
    for j in range(point.shape[-1]):
        shift = np.zeros_like(point)
        shift[:, j] = step[:, j]
        columns.append((function(point + shift) - function(point - shift)) / (2 * step[:, j : j + 1]))
    return np.stack(columns, axis=-1)


@pytest.mark.parametrize("name", CASES)
def test_oracle_rate_jacobian_against_central_differences(name, figures):
    """``tau`` is quadratic in ``xdot`` (``V xdot`` is), so a central difference in
    ``xdot`` is exact up to round-off whatever its step: the real reference's own
    differences, with a step of each rate's spread over the states, bound the oracle tightly."""
    c = case(name)
    rows = slice(0, 200)
    x, xd, xdd = c.x[rows], c.xd[rows], c.xdd[rows]
    step = np.broadcast_to(np.std(c.xd, axis=0), xd.shape)
    numeric = _central_difference(lambda v: ref.inverse_dynamics(c.params, x, v, xdd), xd, step)
    figures(f"oracle: dtau/dxd vs exact central difference ({name})", relative_error(c.inverse[1][rows], numeric), 5e-11)


@pytest.mark.parametrize("name", CASES)
def test_oracle_pose_jacobians_against_central_differences(name, figures):
    """``dtau/dx`` and ``dxddot/dx`` against central differences of the real reference:
    a step of 1e-5 of the home height and 1e-5 rad leaves truncation and round-off near
    1e-9, so this checks the oracle to that level."""
    c = case(name)
    rows = slice(0, 200)
    x, xd, xdd, tau = c.x[rows], c.xd[rows], c.xdd[rows], c.tau[rows]
    scale = stewart.home_pose(c.params)[2]
    step = np.broadcast_to(np.array([1e-5 * scale] * 3 + [1e-5] * 3), x.shape)
    inverse = _central_difference(lambda p: ref.inverse_dynamics(c.params, p, xd, xdd), x, step)
    forward = _central_difference(lambda p: ref.forward_dynamics(c.params, p, xd, tau), x, step)
    worst = max(relative_error(c.inverse[0][rows], inverse), relative_error(c.forward[0][rows], forward))
    figures(f"oracle: d/dx vs central difference ({name})", worst, 1e-8)
