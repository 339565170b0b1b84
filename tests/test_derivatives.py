"""Derivatives of the dynamics.

The oracle is complex-step differentiation of the numeric reference
(:func:`stewart.oracles.physics.reference_inverse_dynamics_jacobians` and its kin), never of the
kernel. It is checked first against what it must equal exactly: its own complex-input
path, the identities ``dtau/dxddot = J_C^-T M`` and ``dxddot/dtau = M^-1 J_C^T`` built
from the reference's ``M`` and ``J_C``, the implicit-function relation between its
inverse and forward Jacobians, and central differences of the real reference.

Then the compiled kernel's derivatives (``Platform.inverse_dynamics_derivatives``,
``forward_dynamics_derivatives``, ``rk4_step``) against the oracle on every preset's
random states and on random platforms (general leg inertia included), the same
identities with the kernel's own ``M`` and ``J_C``, the RK4 step against ``simulate``,
batches against single calls, singular rows and argument errors.
"""

from __future__ import annotations

import functools
import warnings
from typing import NamedTuple

import numpy as np
import pytest

import stewart
from stewart.oracles import reference as ref
from stewart.oracles.physics import (
    complex_step_jacobians,
    random_states,
    reference_forward_dynamics_jacobians,
    reference_inverse_dynamics_jacobians,
    reference_rk4_jacobians,
    reference_rk4_step,
    relative_error,
)
from conftest import random_params

#: States per case (a preset or a random platform), chosen from a pool this many times larger
#: (:func:`chosen_states`).
STATES = 200
POOL = 25
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


def chosen_states(params, n, rng):
    """``n`` states of :func:`random_states`: from a pool of ``POOL * n``, the ``n // 2`` where
    the model is worst conditioned (``cond(J_C) cond(M)``, by the kernel: where round-off and
    a wrong term are amplified most), and ``n - n // 2`` of the others at random, shuffled
    together so that every leading slice holds both kinds.

    The oracle costs milliseconds a state, so the checks take a few hundred states instead of
    a thousand random ones: the kernel's figures sit two orders of magnitude or more inside their
    bounds on every state, so a wrong term, which shows on a set of states of non-zero
    measure, fails them; its worst figures are where the conditioning is worst, which the
    pool's tail samples densely, and a fault confined to a fraction ``p`` of the states of
    :func:`random_states` escapes the ``n - n // 2`` random ones with probability
    ``(1 - p) ** (n - n // 2)`` (below 1 % for ``p`` = 5 % and 100 states)."""
    x, xd, xdd = random_states(params, POOL * n, rng)
    plat = stewart.Platform(params)
    conditioning = np.linalg.cond(plat.jacobian(x)) * np.linalg.cond(plat.mass_matrix(x))
    order = np.argsort(conditioning)
    worst, others = order[len(order) - n // 2:], order[:len(order) - n // 2]
    rows = rng.permutation(np.concatenate([worst, rng.choice(others, n - n // 2, replace=False)]))
    return x[rows], xd[rows], xdd[rows]


@functools.cache
def case(name: str) -> Case:
    """The states and oracle Jacobians of ``name`` (a preset or a random platform), computed once."""
    rng = np.random.default_rng(sum(map(ord, name)))
    if name in RANDOM_PLATFORMS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
            params = random_params(rng, axisymmetric=name == "random-axisymmetric").replace(name=name)
    else:
        params = stewart.PlatformParams.preset(name)
    x, xd, xdd = chosen_states(params, STATES, rng)
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
    rows = slice(0, STATES)
    x, xd, xdd, tau = c.x[rows], c.xd[rows], c.xdd[rows], c.tau[rows]
    worst = np.max([
        relative_error(ref.inverse_dynamics(c.params, x + 0j, xd + 0j, xdd), tau),
        relative_error(ref.forward_dynamics(c.params, x + 0j, xd + 0j, tau), xdd),
    ])
    figures(f"oracle: complex-input reference vs real ({name})", worst, 1e-12)  # reached 1.2e-13
    figures(
        f"oracle: complex-input V xdot vs real ({name})",
        relative_error(_coriolis_vector(c.params, x + 0j, xd), ref.coriolis_vector(c.params, x, xd)),
        5e-11,  # reached 2.5e-12
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
    worst = np.max([
        relative_error(c.inverse[2], _solve_t(jac, mass)),
        relative_error(c.forward[2], np.linalg.solve(mass, np.swapaxes(jac, -1, -2))),
    ])
    figures(f"oracle: dtau/dxdd = J_C^-T M, dxdd/dtau = M^-1 J_C^T ({name})", worst, 1e-13)  # reached 1.7e-15


@pytest.mark.parametrize("name", CASES)
def test_oracle_implicit_function_relation(name, figures):
    """The forward Jacobians from the inverse ones: ``dxddot/d(x, xdot) = -(dtau/dxddot)^-1
    dtau/d(x, xdot)`` (the implicit-function theorem on ``tau(x, xdot, xddot)``)."""
    c = case(name)
    worst = np.max([relative_error(c.forward[k], -np.linalg.solve(c.inverse[2], c.inverse[k])) for k in (0, 1)])
    figures(f"oracle: forward vs implicit function of inverse ({name})", worst, 1e-12)  # reached 2.8e-14


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
    rows = slice(0, STATES)
    x, xd, xdd = c.x[rows], c.xd[rows], c.xdd[rows]
    step = np.broadcast_to(np.std(c.xd, axis=0), xd.shape)
    numeric = _central_difference(lambda v: ref.inverse_dynamics(c.params, x, v, xdd), xd, step)
    figures(f"oracle: dtau/dxd vs exact central difference ({name})", relative_error(c.inverse[1][rows], numeric), 5e-11)  # reached 1.0e-11


@pytest.mark.parametrize("name", CASES)
def test_oracle_pose_jacobians_against_central_differences(name, figures):
    """``dtau/dx`` and ``dxddot/dx`` against central differences of the real reference:
    a step of 1e-5 of the home height and 1e-5 rad leaves truncation and round-off near
    1e-9, so this checks the oracle to that level."""
    c = case(name)
    rows = slice(0, STATES)
    x, xd, xdd, tau = c.x[rows], c.xd[rows], c.xdd[rows], c.tau[rows]
    scale = stewart.home_pose(c.params)[2]
    step = np.broadcast_to(np.array([1e-5 * scale] * 3 + [1e-5] * 3), x.shape)
    inverse = _central_difference(lambda p: ref.inverse_dynamics(c.params, p, xd, xdd), x, step)
    forward = _central_difference(lambda p: ref.forward_dynamics(c.params, p, xd, tau), x, step)
    worst = np.max([relative_error(c.inverse[0][rows], inverse), relative_error(c.forward[0][rows], forward)])
    figures(f"oracle: d/dx vs central difference ({name})", worst, 1e-8)  # reached 4.0e-10


# --- the compiled kernel against the oracle --------------------------------------------

#: The RK4 step of the discrete-time checks (an MPC-like 10 ms) and its states per case.
DT = 0.01
RK4_STATES = 50


@functools.cache
def platform(name: str) -> stewart.Platform:
    return stewart.Platform(case(name).params)


@pytest.mark.parametrize("name", CASES)
@pytest.mark.parametrize("method", ["inverse_dynamics_derivatives", "forward_dynamics_derivatives"])
def test_dynamics_derivatives_match_the_oracle(method, name, figures):
    c = case(name)
    if method == "inverse_dynamics_derivatives":
        fields, args, value, oracle = ("tau", "dtau_dx", "dtau_dxd", "dtau_dxdd"), (c.x, c.xd, c.xdd), c.tau, c.inverse
    else:
        fields, args, value, oracle = ("xdd", "dxdd_dx", "dxdd_dxd", "dxdd_dtau"), (c.x, c.xd, c.tau), c.xdd, c.forward
    out = getattr(platform(name), method)(*args)
    assert out._fields == fields
    figures(f"kernel {fields[0]} (with derivatives) vs reference ({name})", relative_error(out[0], value), 5e-13)  # reached 1.3e-14
    for label, got, want in zip(fields[1:], out[1:], oracle):
        assert got.shape == (len(c.x), 6, 6)
        figures(f"kernel {label} vs oracle ({name})", relative_error(got, want), 1e-9)  # reached 1.0e-11


@pytest.mark.parametrize("name", CASES)
def test_kernel_identities(name, figures):
    """``dtau/dxddot = J_C^-T M`` and ``dxddot/dtau = M^-1 J_C^T`` with the kernel's own
    ``M`` and ``J_C``, and the implicit-function round trip
    ``dxddot/dx = -(dtau/dxddot)^-1 dtau/dx`` (likewise for ``xdot``)."""
    c = case(name)
    plat = platform(name)
    inverse = plat.inverse_dynamics_derivatives(c.x, c.xd, c.xdd)
    forward = plat.forward_dynamics_derivatives(c.x, c.xd, inverse.tau)
    mass, jac = plat.mass_matrix(c.x), plat.jacobian(c.x)
    figures(
        f"kernel: dtau/dxdd = J_C^-T M, dxdd/dtau = M^-1 J_C^T ({name})",
        np.max([
            relative_error(inverse.dtau_dxdd, _solve_t(jac, mass)),
            relative_error(forward.dxdd_dtau, np.linalg.solve(mass, np.swapaxes(jac, -1, -2))),
        ]),
        1e-13,  # reached 1.9e-15
    )
    figures(
        f"kernel: dxdd/d(x, xd) = -(dtau/dxdd)^-1 dtau/d(x, xd) ({name})",
        np.max([
            relative_error(forward.dxdd_dx, -np.linalg.solve(inverse.dtau_dxdd, inverse.dtau_dx)),
            relative_error(forward.dxdd_dxd, -np.linalg.solve(inverse.dtau_dxdd, inverse.dtau_dxd)),
        ]),
        1e-12,  # reached 2.0e-14
    )


#: States per case of the static forces' checks (the oracle at rest costs as much as elsewhere).
STATIC_STATES = 50


@pytest.mark.parametrize("name", CASES)
def test_static_force_derivatives_match_the_oracle(name, figures):
    """``static_force_derivatives`` against the reference's inverse dynamics at ``xdot = xddot =
    0`` and its complex-step ``dtau/dx`` there."""
    c = case(name)
    x = c.x[:STATIC_STATES]
    rest = np.zeros_like(x)
    out = platform(name).static_force_derivatives(x)
    assert out._fields == ("tau", "dtau_dx") and out.dtau_dx.shape == (len(x), 6, 6)
    figures(f"kernel static forces vs reference ({name})",
            relative_error(out.tau, ref.inverse_dynamics(c.params, x, rest, rest)), 1e-13)  # reached 2.0e-15
    figures(f"kernel static dtau/dx vs oracle ({name})",
            relative_error(out.dtau_dx, reference_inverse_dynamics_jacobians(c.params, x, rest, rest)[0]), 1e-13)  # reached 1.7e-15


@pytest.mark.parametrize("name", CASES)
def test_static_force_derivatives_are_the_inverse_dynamics_at_rest(name, figures):
    """The same numbers as ``inverse_dynamics_derivatives`` at ``xdot = xddot = 0`` to round-off,
    not bit for bit: G comes from its own kernel rather than the inverse dynamics' ``W`` at rest,
    and ``R_x`` by forward mode through the whole static derivation rather than the per-leg
    chain rule with the velocity terms, so the same sums are taken in other orders."""
    c = case(name)
    rest = np.zeros_like(c.x)
    static = platform(name).static_force_derivatives(c.x)
    dynamic = platform(name).inverse_dynamics_derivatives(c.x, rest, rest)
    figures(f"kernel static forces vs inverse dynamics at rest ({name})",
            np.max([relative_error(static.tau, dynamic.tau), relative_error(static.dtau_dx, dynamic.dtau_dx)]), 1e-13)  # reached 2.7e-15


@pytest.mark.parametrize("name", CASES)
def test_rk4_step_and_jacobians_match_the_oracle(name, figures):
    """The compiled step and its ``A``, ``B`` against the same RK4 step written with the
    reference's forward dynamics, complex-stepped (the compiled step takes real inputs
    only). ``A - I`` is compared, so the identity does not hide the dynamics."""
    c = case(name)
    rows = slice(0, RK4_STATES)
    x, xd, tau = c.x[rows], c.xd[rows], c.tau[rows]
    x_next, xd_next, a_mat, b_mat = platform(name).rk4_step(x, xd, tau, DT, jacobians=True)
    assert a_mat.shape == (RK4_STATES, 12, 12) and b_mat.shape == (RK4_STATES, 12, 6)
    want = reference_rk4_step(c.params, x, xd, tau, DT)
    want_a, want_b = reference_rk4_jacobians(c.params, x, xd, tau, DT)
    eye = np.eye(12)
    figures(f"kernel RK4 step vs reference ({name})", relative_error(np.concatenate([x_next, xd_next], -1), want), 1e-14)  # reached 2.5e-16
    figures(f"kernel RK4 A - I vs oracle ({name})", relative_error(a_mat - eye, want_a - eye), 1e-12)  # reached 2.1e-14
    figures(f"kernel RK4 B vs oracle ({name})", relative_error(b_mat, want_b), 5e-14)  # reached 8.8e-16


def test_rk4_step_is_what_simulate_integrates(figures):
    """The compiled step equals :func:`stewart.simulate`'s RK4 with an open loop and a
    constant feed-forward force, step after step."""
    c = case("narayan2017")
    plat = platform("narayan2017")
    x, xd, tau = c.x[0], 0.1 * c.xd[0], ref.inverse_dynamics(c.params, c.x[0], np.zeros(6), np.zeros(6))
    steps, dt = 20, 1e-3
    run = stewart.simulate(
        plat, stewart.PointToPoint(x, x, steps * dt), stewart.OpenLoop(), dt=dt, x0=x, xd0=xd,
        feedforward=lambda t: np.tile(tau, (len(t), 1)), check_workspace=False,
    )
    assert run.completed and len(run.t) == steps + 1
    stepped = [np.concatenate([x, xd])]
    for _ in range(steps):
        x, xd = plat.rk4_step(x, xd, tau, dt)
        stepped.append(np.concatenate([x, xd]))
    figures("kernel RK4 step vs simulate (open loop)", relative_error(np.array(stepped), np.hstack([run.x, run.xd])), 1e-14)  # reached 0


def test_batch_matches_single_calls(simd_path):
    c = case("motion_simulator")
    plat = platform("motion_simulator")
    rows = range(5)
    batch = (
        plat.inverse_dynamics_derivatives(c.x[:5], c.xd[:5], c.xdd[:5]),
        plat.forward_dynamics_derivatives(c.x[:5], c.xd[:5], c.tau[:5]),
        plat.rk4_step(c.x[:5], c.xd[:5], c.tau[:5], DT, jacobians=True),
    )
    for k in rows:
        single = (
            plat.inverse_dynamics_derivatives(c.x[k], c.xd[k], c.xdd[k]),
            plat.forward_dynamics_derivatives(c.x[k], c.xd[k], c.tau[k]),
            plat.rk4_step(c.x[k], c.xd[k], c.tau[k], DT, jacobians=True),
        )
        for many, one in zip(batch, single):
            for got, want in zip(many, one):
                assert got[k].shape == want.shape
                np.testing.assert_array_equal(got[k], want)


def _singular_batch(plat, method):
    """Three states, the middle one singular: for inverse dynamics the platform in the base
    plane (J_C singular), else theta = 90 deg (the Euler-rate map singular)."""
    home = plat.home_pose
    bad = np.zeros(6) if method == "inverse_dynamics_derivatives" else home + [0, 0, 0, 0, np.pi / 2, 0]
    x = np.stack([home, bad, home])
    return x, np.zeros((3, 6)), np.zeros((3, 6))


@pytest.mark.parametrize("method", ["inverse_dynamics_derivatives", "forward_dynamics_derivatives", "rk4_step"])
def test_singular_rows_raise_or_come_back_masked(method):
    plat = platform("narayan2017")
    x, xd, third = _singular_batch(plat, method)
    extra = (DT,) if method == "rk4_step" else ()
    options = {"jacobians": True} if method == "rk4_step" else {}
    call = getattr(plat, method)
    with pytest.raises(stewart.SingularityError, match=r"row\(s\) \[1\]") as info:
        call(x, xd, third, *extra, **options)
    assert info.value.rows == [1]
    result, ok = call(x, xd, third, *extra, return_mask=True, **options)
    assert ok.tolist() == [True, False, True]
    for part in result:
        assert np.all(np.isnan(part[1])) and np.all(np.isfinite(part[[0, 2]]))
    one, ok_one = call(x[1], xd[1], third[1], *extra, return_mask=True, **options)
    assert ok_one is False and all(np.all(np.isnan(part)) for part in one)


def test_static_force_derivatives_singular_rows_raise_or_come_back_masked():
    """The platform in the base plane (J_C singular) in the middle of three poses."""
    plat = platform("narayan2017")
    x = np.stack([plat.home_pose, np.zeros(6), plat.home_pose])
    with pytest.raises(stewart.SingularityError, match=r"static_force_derivatives.*row\(s\) \[1\]") as info:
        plat.static_force_derivatives(x)
    assert info.value.rows == [1]
    result, ok = plat.static_force_derivatives(x, return_mask=True)
    assert ok.tolist() == [True, False, True]
    for part in result:
        assert np.all(np.isnan(part[1])) and np.all(np.isfinite(part[[0, 2]]))


@pytest.mark.parametrize("method", ["inverse_dynamics_derivatives", "forward_dynamics_derivatives", "rk4_step"])
@pytest.mark.parametrize("position", [0, 1, 2])
def test_bad_arguments_are_named(method, position):
    plat = platform("narayan2017")
    names = {
        "inverse_dynamics_derivatives": ("x", "xd", "xdd"),
        "forward_dynamics_derivatives": ("x", "xd", "tau"),
        "rk4_step": ("x", "xd", "tau"),
    }[method]
    extra = (DT,) if method == "rk4_step" else ()
    good = [plat.home_pose, np.zeros(6), np.zeros(6)]
    for bad in (np.zeros(5), np.full(6, np.nan), np.zeros(6) + 1e-30j):
        args = list(good)
        args[position] = bad
        with pytest.raises(ValueError, match=f"^{names[position]}: "):
            getattr(plat, method)(*args, *extra)


@pytest.mark.parametrize("dt", [0.0, -1e-3, np.nan, np.inf, "0.01", np.ones(2)])
def test_rk4_step_refuses_a_bad_time_step(dt):
    plat = platform("narayan2017")
    with pytest.raises(ValueError, match="^dt: "):
        plat.rk4_step(plat.home_pose, np.zeros(6), np.zeros(6), dt)


@pytest.mark.parametrize("name", ["narayan2017", "random-general"])
def test_casadi_jacobians_match_the_oracle(name, figures):
    """An independent derivative of an independent model: CasADi's ``ca.jacobian`` of its
    SX model (benchmarks/peers; the cylinder-frame leg inertia for general legs) against
    the oracle."""
    pytest.importorskip("casadi")
    pytest.importorskip("benchmarks", reason="needs the checkout (benchmarks/)")
    from benchmarks.peers import casadi_derivatives
    from benchmarks.peers.common import param_vector

    c = case(name)
    n = 40
    functions = casadi_derivatives.build(general=not c.params.is_axisymmetric)
    columns = {"xdd": c.xdd, "tau": c.tau}
    worst = 0.0
    for (method, _, third), oracle in zip(casadi_derivatives.FUNCTIONS, (c.inverse, c.forward)):
        mapped = functions[method].map(n, "serial")
        rows = mapped(c.x[:n].T, c.xd[:n].T, columns[third][:n].T, param_vector(c.params))
        _, jac = casadi_derivatives.unpack(np.asarray(rows).T)
        worst = np.maximum(worst, relative_error(jac, np.concatenate([o[:n] for o in oracle], axis=-1)))
    figures(f"oracle vs CasADi ca.jacobian of its own model ({name})", worst, 1e-11)  # reached 1.4e-13


def test_complex_step_jacobians_of_one_point_and_of_a_batch():
    """The oracle's helper: one point gives ``(m, n)`` per argument, a batch ``(N, m, n)``,
    equal row for row; on ``f(u, v) = [u0 v1, sin(u2)]`` the exact partials."""

    def function(u, v):
        return np.stack([u[:, 0] * v[:, 1], np.sin(u[:, 2])], axis=-1)

    u, v = np.array([[0.3, 0.0, 1.1], [2.0, 1.0, -0.4]]), np.array([[1.5, -2.0], [0.5, 3.0]])
    d_u, d_v = complex_step_jacobians(function, u, v)
    assert d_u.shape == (2, 2, 3) and d_v.shape == (2, 2, 2)
    for k in range(2):
        one_u, one_v = complex_step_jacobians(function, u[k], v[k])
        np.testing.assert_array_equal(one_u, d_u[k])
        np.testing.assert_array_equal(one_v, d_v[k])
        np.testing.assert_allclose(one_u, [[v[k, 1], 0, 0], [0, 0, np.cos(u[k, 2])]], rtol=1e-15, atol=0)
        np.testing.assert_allclose(one_v, [[0, u[k, 0]], [0, 0]], rtol=1e-15, atol=0)


@pytest.mark.peers
def test_pinocchio_closed_loop_matches_the_kernel(figures):
    """Pinocchio's constraint dynamics of the platform as a closed loop (benchmarks/peers),
    with legs of no axial inertia, against our forward dynamics and ``dxddot/dtau`` at rest."""
    pytest.importorskip("pinocchio")
    pytest.importorskip("benchmarks", reason="needs the checkout (benchmarks/)")
    from benchmarks.peers import pinocchio_model

    out = pinocchio_model.figures("narayan2017", n_states=20, repeats=1)
    figures("Pinocchio closed loop vs kernel: xdd at rest (narayan2017)", out["platform_acceleration_rel_error"], 1e-12)
    figures("Pinocchio closed loop vs kernel: dxdd/dtau at rest (narayan2017)", out["dxdd_dtau_rel_error"], 1e-12)
