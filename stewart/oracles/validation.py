"""``stewart validate``: the model's self-check for one parameter set, as a report.

:func:`run` evaluates, over random states scattered around the home pose, the worst
disagreement of the compiled kernel (:class:`stewart.Platform`) with

* the numeric reference model (:mod:`stewart.oracles.reference`): inverse and forward dynamics,
  ``M``, ``V xdot``, ``G`` and the regressor (``Y pi``, the inverse dynamics plus friction);
* the independent Newton-Euler formulation (:mod:`stewart.oracles.newton_euler`): the actuator
  forces and the joint forces of :meth:`Platform.joint_reactions`;
* the derivative oracle (:func:`stewart.oracles.physics.complex_step_jacobians` of the reference):
  the exact Jacobians of inverse dynamics, forward dynamics and the RK4 step;
* itself: forward dynamics of the inverse dynamics gives back ``xddot``;
* physics (:mod:`stewart.oracles.physics`, shared with the test suite): the power balance
  ``dE/dt = tau . Ldot`` with the mechanical energy :func:`energy` written out from the
  bodies, conservation of energy over 1 s of motion with ``tau = 0``, a positive-definite
  twist-space mass matrix ``M_t`` with ``M = M_t T``, and the static balance of the
  Newton-Euler joint forces.

The physics checks and the Newton-Euler comparison need a conservative model: legs that
turn with their universal joints (``universal_joint_axes``) or axisymmetric legs
(I_yy == I_zz); for the paper's non-spinning legs with other inertias they are replaced by
one failing check that says so.
:func:`format_report` renders the checks as a table.

Each bound is a few tens of times the worst figure its check reaches on the presets and on
the test suite's random platforms (tests/), on the baseline, AVX2 and AVX-512 paths (the
figure beside each): loose enough for another parameter set's round-off, tight enough that
a wrong term, which moves the figures by many orders, fails.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..model import arguments
from . import newton_euler, reference
from .physics import energy, energy_drift, power_balance, random_states, relative_error, statics_residuals
from .physics import (
    reference_forward_dynamics_jacobians,
    reference_inverse_dynamics_jacobians,
    reference_rk4_jacobians,
)
from .physics import twist_mass_matrix_figures
from ..model.params import PlatformParams
from ..model.platform import Platform

__all__ = ["Check", "run", "format_report", "energy", "energy_drift", "statics_residuals", "random_states"]


class Check(NamedTuple):
    """One check: its worst figure over the states tried, the bound, and ``worst <= bound``."""

    name: str
    worst: float
    bound: float
    passed: bool


def _check(name: str, worst: float, bound: float) -> Check:
    worst = float(worst)
    return Check(name, worst, float(bound), bool(worst <= bound))


def _kernel_vs_reference(params, plat, x, xd, xdd) -> list[Check]:
    tau = reference.inverse_dynamics(params, x, xd, xdd)
    bound = 1e-12  # reached 5.5e-15 on the presets, 1.1e-14 (forward dynamics) on the random platforms
    return [
        _check("kernel vs reference: inverse dynamics", relative_error(plat.inverse_dynamics(x, xd, xdd), tau), bound),
        _check(
            "kernel vs reference: forward dynamics",
            relative_error(plat.forward_dynamics(x, xd, tau), reference.forward_dynamics(params, x, xd, tau)),
            bound,
        ),
        _check("kernel vs reference: mass matrix M", relative_error(plat.mass_matrix(x), reference.mass_matrix(params, x)), bound),
        _check(
            "kernel vs reference: V xdot",
            relative_error(plat.coriolis_vector(x, xd), reference.coriolis_vector(params, x, xd)),
            bound,
        ),
        _check("kernel vs reference: gravity G", relative_error(plat.gravity_vector(x), reference.gravity_vector(params, x)), bound),
        _check("kernel vs reference: regressor Y pi (with friction)",
               relative_error(plat.regressor(x, xd, xdd) @ params.inertial_vector(), tau + plat.friction_forces(x, xd)),
               bound),
    ]


#: States of the derivative checks (the oracle differentiates the slow reference), and
#: the RK4 step they use (an MPC-like 10 ms).
DERIVATIVE_STATES = 20
DERIVATIVE_DT = 0.01


def _derivatives_vs_oracle(params, plat, x, xd, xdd) -> list[Check]:
    """The kernel's exact Jacobians against complex step of the reference (``A - I``
    compared, so that the identity does not hide the dynamics)."""
    x, xd, xdd = x[:DERIVATIVE_STATES], xd[:DERIVATIVE_STATES], xdd[:DERIVATIVE_STATES]
    inverse = plat.inverse_dynamics_derivatives(x, xd, xdd)
    forward = plat.forward_dynamics_derivatives(x, xd, inverse.tau)
    _, _, a_mat, b_mat = plat.rk4_step(x, xd, inverse.tau, DERIVATIVE_DT, jacobians=True)
    want_a, want_b = reference_rk4_jacobians(params, x, xd, inverse.tau, DERIVATIVE_DT)
    eye = np.eye(12)
    pairs = {
        "inverse dynamics dtau/d(x, xd, xdd)": (
            inverse[1:], reference_inverse_dynamics_jacobians(params, x, xd, xdd)),
        "forward dynamics dxdd/d(x, xd, tau)": (
            forward[1:], reference_forward_dynamics_jacobians(params, x, xd, inverse.tau)),
        f"RK4 step A - I and B (dt {DERIVATIVE_DT:g} s)": ((a_mat - eye, b_mat), (want_a - eye, want_b)),
    }
    # reached 2.7e-13 on the presets, 1.5e-11 (inverse dynamics) on the random platforms
    return [
        _check(f"kernel vs oracle: {label}", np.max([relative_error(g, w) for g, w in zip(got, want)]), 5e-10)
        for label, (got, want) in pairs.items()
    ]


def run(params: PlatformParams, n_states: int = 200, seed: int = 0) -> list[Check]:
    """All checks for ``params`` over ``n_states`` random states around home (seeded)."""
    if not isinstance(params, PlatformParams):
        raise ValueError(f"params: expected a stewart.PlatformParams, got {type(params).__name__}")
    rng = np.random.default_rng(arguments.seed(seed))
    plat = Platform(params)
    x, xd, xdd = random_states(params, n_states, rng)
    checks = _kernel_vs_reference(params, plat, x, xd, xdd)
    checks += _derivatives_vs_oracle(params, plat, x, xd, xdd)
    tau = plat.inverse_dynamics(x, xd, xdd)
    checks.append(_check("kernel: forward(inverse(xddot)) round trip", relative_error(plat.forward_dynamics(x, xd, tau), xdd),
                         1e-12))  # reached 2.9e-14 on the presets, 1.5e-14 on the random platforms

    mismatch, cond = twist_mass_matrix_figures(plat, x)
    checks.append(_check("twist mass matrix M_t: M_t T vs M", mismatch, 5e-15))  # reached 1.1e-16
    # not an error but a verdict: finite and under 1e12, M_t is positive definite (reached 73)
    checks.append(_check("twist mass matrix M_t: positive definite (condition)", cond, 1e12))

    if params.universal_joint_axes is None and not params.is_axisymmetric:
        spread = np.concatenate([params.cylinder_inertia[1:], params.piston_inertia[1:]])
        mismatch = max(
            abs(params.cylinder_inertia[1] - params.cylinder_inertia[2]),
            abs(params.piston_inertia[1] - params.piston_inertia[2]),
        ) / np.max(spread)
        checks.append(
            Check("legs axisymmetric (I_yy == I_zz); physics checks skipped", float(mismatch), 0.0, False)
        )
        return checks

    joints, exact = plat.joint_reactions(x, xd, xdd), newton_euler.joint_reactions(params, x, xd, xdd)
    # reached 2.2e-15, 2.9e-15 and 1.3e-15 on the presets, 1.8e-15, 2.4e-15 and 1.2e-15 on the random platforms
    checks.append(_check("kernel vs Newton-Euler: inverse dynamics", relative_error(tau, exact.tau), 1e-13))
    checks.append(_check("kernel vs Newton-Euler: universal- and spherical-joint forces",
                         np.max([relative_error(joints.base, exact.base), relative_error(joints.platform, exact.platform)]),
                         1e-13))
    checks.append(_check("power balance |dE/dt - tau.Ldot| / sum|tau_i Ldot_i|", power_balance(params, x, xd, xdd, tau),
                         1e-13))
    try:
        drift = energy_drift(params, 1.0, seed)
        label = "energy drift over 1 s, tau = 0, zero gravity (DOP853)"
    except ImportError:
        drift, label = float("nan"), "energy drift over 1 s: not run, needs scipy"
    # DOP853 at rtol 1e-12, whose steps set the drift: reached 5.1e-14 on the presets, 8.9e-13 on
    # the random platforms
    checks.append(_check(label, drift, 5e-11))
    for label, value in statics_residuals(params, x).items():
        checks.append(_check(f"statics: {label} balance (Newton-Euler)", value, 1e-14))  # reached 3.2e-16
    return checks


def format_report(params: PlatformParams, checks: list[Check]) -> str:
    """The checks as a text table, with a header naming the parameter set and a verdict."""
    label = params.name or "unnamed parameter set"
    width = max([len(c.name) for c in checks] + [5])
    lines = [
        f"stewart validate: {label}",
        f"{'check':<{width}}  {'worst':>10}  {'bound':>8}  result",
        f"{'-' * width}  {'-' * 10}  {'-' * 8}  ------",
    ]
    for c in checks:
        lines.append(f"{c.name:<{width}}  {c.worst:10.3e}  {c.bound:8.0e}  {'ok' if c.passed else 'FAIL'}")
    failed = sum(not c.passed for c in checks)
    lines.append("")
    lines.append(
        f"all {len(checks)} checks passed" if not failed else f"{failed} of {len(checks)} checks FAILED"
    )
    return "\n".join(lines)
