"""Numeric reference of the generalized-momentum model (Lopes & Pires 2011), in numpy.

This module evaluates the paper's equations as written, body by body, with no symbolic
algebra at run time. It is slow and plain on purpose: it is the oracle the compiled
kernel is checked against.

For every body b (the platform, and per leg the cylinder and the piston, each with a
translational and a rotational part) it builds the partial-velocity Jacobian ``J_b``
(twist -> body velocity: eqs. 31, 35, 57) and the body's "inertia times T" matrix
``A_b = I_b J_b T`` whose product with ``xdot`` is the body's momentum (eqs. 17, 37, 49,
59, 67). Then, as in eqs. 19-23, 39-41, 51-53, 61-63 and 69-71,

    M = sum_b J_b^T A_b              (inertia matrix, multiplies the Euler accelerations)
    V = sum_b J_b^T d/dt(A_b)        (Coriolis and centripetal matrix)
    G = sum_b m_b g J_b^T e_z        (gravity: the gradient of eq. 72's potential)

with ``J^T`` of the platform translation and rotation being the identity blocks. The
time derivative ``d/dt A_b = sum_k dA_b/dx_k xdot_k`` is taken by complex step along
``x + i h xdot``, which is exact to round-off (no subtractive cancellation). The
equation of motion is ``M xddot + V xdot + G = J_C^T tau`` (eqs. 1-2).

Complex inputs: :func:`inverse_dynamics`, :func:`forward_dynamics` and :func:`body_terms`
accept complex ``x``, ``xdot``, ``xddot`` and ``tau``, so that they can themselves be
differentiated by complex step (the derivative oracle of the compiled kernel's
Jacobians, :func:`stewart.oracles.physics.complex_step_jacobians`). A complex step cannot nest on
the inner one, so for complex ``x`` or ``xdot`` the time derivative of ``A_b`` is taken
instead by the sixth-order central difference along the real time ``s``

    d/dt A_b = sum_k w_k A_b(x + k s xdot) / s,   k = +-1, +-2, +-3,
    w_{+-1} = +-3/4,  w_{+-2} = -+3/20,  w_{+-3} = +-1/60,

with ``s`` chosen so that one step moves a leg by 2e-3 of the shortest leg's length or
turns an angle by 2e-3 rad. The truncation error, ``O(s^6)``, and the round-off,
``O(eps / s)``, are then balanced: ``V xdot`` comes out within 1e-11 of the complex-step
value (relative; tests/test_derivatives.py measures it). Every function is holomorphic in its
inputs, so the imaginary parts carry the exact directional derivatives. Real inputs keep
the complex-step inner derivative, so their results do not change.

Gravity is written as ``J_b^T m_b g e_z`` rather than eq. 76's ``blockdiag(I, J_A^-T)
dP/dx``: the two are equal wherever ``J_A`` is invertible, and this form needs no
``cos(theta) != 0``.

Each public function refuses the states the compiled kernel's function of the same name
refuses, with the same :class:`~stewart.SingularityError` condition, by the same tests and
tolerances in the same order (:mod:`stewart.model.conditions`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..model import arguments, conditions
from .frames import jacobian, leg_lengths, leg_vectors, platform_points_in_base, rotation, twist_transform
from ..model.params import platform_params
from ..model.params import PlatformParams

__all__ = [
    "BODIES",
    "BodyTerms",
    "partial_velocity_jacobians",
    "rotational_inertias",
    "momenta",
    "body_terms",
    "twist_mass_matrix",
    "mass_matrix",
    "coriolis_matrix",
    "coriolis_vector",
    "gravity_vector",
    "inverse_dynamics",
    "forward_dynamics",
]

#: The bodies' parts, in the paper's order. Leg parts carry a leg axis of length 6.
BODIES = (
    "platform_translation",
    "platform_rotation",
    "cylinder_translation",
    "cylinder_rotation",
    "piston_translation",
    "piston_rotation",
)

#: Complex-step size for ``|xdot| <= 1`` (scaled down for larger rates, so that the step
#: ``h xdot`` stays tiny); the error of the derivative is O(h^2), far below round-off.
_STEP = 1e-30
#: The complex-input inner derivative: one step moves a leg by this fraction of the
#: shortest leg's length or turns an angle by this many radians.
_DIFFERENCE_STEP = 2e-3
#: Sixth-order central difference ``f'(0) ~ sum_k w_k f(k s) / s``.
_DIFFERENCE_WEIGHTS = ((-3, -1 / 60), (-2, 3 / 20), (-1, -3 / 4), (1, 3 / 4), (2, -3 / 20), (3, 1 / 60))


class BodyTerms(NamedTuple):
    """One body part's contribution to ``M``, ``V xdot``... For leg parts the arrays carry
    a leg axis before the matrix axes: ``mass_matrix`` is ``(..., 6, 6, 6)``."""

    mass_matrix: np.ndarray
    coriolis_matrix: np.ndarray
    gravity_vector: np.ndarray


def _skew(a: np.ndarray) -> np.ndarray:
    """``a~`` of eq. 33: ``skew(a) @ b == a x b``."""
    zero = np.zeros_like(a[..., 0])
    rows = [
        [zero, -a[..., 2], a[..., 1]],
        [a[..., 2], zero, -a[..., 0]],
        [-a[..., 1], a[..., 0], zero],
    ]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def partial_velocity_jacobians(params: PlatformParams, x) -> dict[str, np.ndarray]:
    """``J_b``: twist ``[v; omega]`` -> velocity of each body part, ``(..., [6,] 3, 6)``.

    Platform parts: ``[E (R c)~^T]`` (the centre of mass ``c`` in {P}; ``[E 0]`` at the
    origin, eq. 10) and ``[0 E]``. Leg angular velocity (both leg parts): the paper's
    ``J_D = [lbar~, lbar~ r~^T]`` (eq. 31, no spin), or with ``universal_joint_axes`` the
    rate of the leg frame ``vee(Rdot R^T)``, ``J_W = (E + (a.u) / |a x u|^2 u a^T) J_D``: the
    spin about ``u`` that keeps ``omega`` in the span of ``a`` and ``y = a x u / |a x u|``.
    Cylinder centre of mass: ``J_B = b_C u~^T J_D`` (eq. 35). Piston centre of mass:
    ``J_G = (E - b_S u~^T lbar~) [E, r~^T]`` (eq. 57).
    """
    return _partial_velocity_jacobians(platform_params(params), x)


def _partial_velocity_jacobians(params: PlatformParams, x) -> dict[str, np.ndarray]:
    x = arguments.states("x", x, allow_complex=True)
    units = jacobian(params, x)[..., :3]
    legs = leg_vectors(params, x)
    lbar_x = _skew(units / np.sqrt(np.sum(legs * legs, axis=-1))[..., None])
    u_x = _skew(units)
    arm_xT = -_skew(platform_points_in_base(params, x))  # r~^T
    eye = np.broadcast_to(np.eye(3, dtype=x.dtype), arm_xT.shape)
    point = np.concatenate([eye, arm_xT], axis=-1)  # velocity of P_i: [E, r~^T]
    j_d = lbar_x @ point
    zeros = np.zeros(x.shape[:-1] + (3, 3), dtype=x.dtype)
    eye_p = np.broadcast_to(np.eye(3, dtype=x.dtype), zeros.shape)
    com_xT = zeros if params.platform_com is None else -_skew(rotation(x) @ params.platform_com)
    with np.errstate(over="ignore", invalid="ignore"):
        j_w = j_d if params.universal_joint_axes is None else _spin(params.universal_joint_axes, units, j_d)
        jacs = {
            "platform_translation": np.concatenate([eye_p, com_xT], axis=-1),
            "platform_rotation": np.concatenate([zeros, eye_p], axis=-1),
            "cylinder_translation": -params.cylinder_com_distance * u_x @ j_d,
            "cylinder_rotation": j_w,
            "piston_translation": point + params.piston_com_distance * u_x @ j_d,
            "piston_rotation": j_w,
        }
    return arguments.finite_result("partial_velocity_jacobians", jacs, x)


def _spin(axes: np.ndarray, units: np.ndarray, j_d: np.ndarray) -> np.ndarray:
    """``J_W = (E + (a.u) / |a x u|^2 u a^T) J_D``: the leg's angular velocity with the spin
    its universal joint imposes. ``J_D`` gives ``u x udot``, the part across the leg; the
    axial part ``s u`` makes ``omega`` orthogonal to ``n = a x y``, and since
    ``u . n = -|a x u|`` and ``(u x udot) . n = (a.u) a.(u x udot) / |a x u|`` (the ``u``
    part of ``n`` is orthogonal to ``u x udot``), ``s = (a.u) a.(u x udot) / |a x u|^2``."""
    across = np.cross(axes, units)
    gain = np.sum(axes * units, axis=-1) / np.sum(across * across, axis=-1)
    return j_d + (gain[..., None] * units)[..., :, None] * np.einsum("ik,...ikj->...ij", axes, j_d)[..., None, :]


def _check_legs(function: str, params: PlatformParams, x: np.ndarray, general: bool, *steps) -> None:
    """Raise :class:`~stewart.SingularityError` where the generated C's ``function`` would at
    ``x``: the legs' tests (the vertical-leg test only with ``general``, the paper's
    cylinder frames; the gimbal-lock test with ``universal_joint_axes``), then ``steps``
    (see :func:`stewart.model.conditions.check`)."""
    legs = leg_vectors(params, np.real(x))
    axes = params.universal_joint_axes
    with np.errstate(over="ignore", invalid="ignore"):
        length_sq = np.sum(legs * legs, axis=-1)
        horizontal_sq = legs[..., 0] * legs[..., 0] + legs[..., 1] * legs[..., 1]
        locked = None if axes is None else np.cross(axes, legs)
        locked_sq = None if axes is None else np.sum(locked * locked, axis=-1)
    vertical = horizontal_sq if general and axes is None else None
    conditions.check(function, x, conditions.leg_codes(length_sq, vertical, locked_sq), *steps)


def _leg_inertia(units: np.ndarray, inertia: np.ndarray, axes: np.ndarray | None) -> np.ndarray:
    """Rotational inertia of a leg part in {B} (eqs. 43-48 and 65-66).

    With ``axes`` (the universal joints' first axes ``a_i``; ``e_z`` for the paper's
    cylinder frame {C_i} of eqs. 44-47) the leg frame x = u, y = a x u / |a x u|, z = x x y
    is built and the principal moments (axial, I_yy, I_zz) placed in it; without, the
    axisymmetric form ``I_t (E - u u^T) + I_a u u^T``, equal when ``I_yy == I_zz`` and
    defined for every leg direction.
    """
    uu = units[..., :, None] * units[..., None, :]
    if axes is None:
        return inertia[1] * (np.eye(3) - uu) + inertia[0] * uu
    across = np.cross(axes, units)
    y_c = across / np.sqrt(np.sum(across * across, axis=-1))[..., None]
    z_c = np.cross(units, y_c)
    frame = np.stack([units, y_c, z_c], axis=-1)  # columns x, y, z (eq. 44 for a = e_z)
    return (frame * inertia) @ np.swapaxes(frame, -1, -2)


def _leg_axes(params: PlatformParams, general: bool) -> np.ndarray | None:
    """The axes the leg frames are built on: the universal joints' first axes when given,
    else ``e_z`` (the paper's cylinder frame) with ``general``, else none (axisymmetric form)."""
    if params.universal_joint_axes is not None:
        return params.universal_joint_axes
    return np.array([0.0, 0.0, 1.0]) if general else None


def rotational_inertias(params: PlatformParams, x, general: bool | None = None) -> dict[str, np.ndarray]:
    """Rotational inertias in {B}: platform ``R I_P R^T`` (eq. 13, ``I_P`` the full tensor),
    ``(..., 3, 3)``; cylinders (eq. 43) and pistons (eq. 65), ``(..., 6, 3, 3)``.

    ``general`` picks the paper's leg inertia form (default: the frame form only when the
    legs are not axisymmetric); with ``universal_joint_axes`` the legs' frames are always
    built on those axes. Raises :class:`SingularityError` for a vertical leg in the paper's
    frame form, where {C_i} is undefined, and for a leg along its joint's first axis
    (:mod:`stewart.model.conditions`).
    """
    return _rotational_inertias(platform_params(params), x, general)


def _rotational_inertias(params: PlatformParams, x, general: bool | None) -> dict[str, np.ndarray]:
    x = arguments.states("x", x, allow_complex=True)
    if general is None:
        general = not params.is_axisymmetric
    _check_legs("rotational_inertias", params, x, general)
    rot = rotation(x)
    units = jacobian(params, x)[..., :3]
    axes = _leg_axes(params, general)
    with np.errstate(over="ignore", invalid="ignore"):
        inertias = {
            "platform_rotation": rot @ params.platform_inertia_tensor @ np.swapaxes(rot, -1, -2),
            "cylinder_rotation": _leg_inertia(units, params.cylinder_inertia, axes),
            "piston_rotation": _leg_inertia(units, params.piston_inertia, axes),
        }
    return arguments.finite_result("rotational_inertias", inertias, x)


def _masses(params: PlatformParams) -> dict[str, float]:
    """The mass of each translational body part."""
    return {
        "platform_translation": params.platform_mass,
        "cylinder_translation": params.cylinder_mass,
        "piston_translation": params.piston_mass,
    }


def _inertia_times_t(params: PlatformParams, x, general: bool | None) -> tuple[dict, dict]:
    """``J_b`` and ``A_b = I_b J_b T`` for every body part (the momentum is ``A_b xdot``)."""
    jacs = _partial_velocity_jacobians(params, x)
    inertias = _rotational_inertias(params, x, general)
    t_mat = twist_transform(x)
    masses = _masses(params)
    out = {}
    with np.errstate(over="ignore", invalid="ignore"):
        for body in BODIES:
            jt = jacs[body] @ (t_mat if body.startswith("platform") else t_mat[..., None, :, :])
            out[body] = masses[body] * jt if body in masses else inertias[body] @ jt
    return jacs, out


def momenta(params: PlatformParams, x, xd, general: bool | None = None) -> dict[str, np.ndarray]:
    """Momentum of every body part in {B}: linear momentum of the platform (eq. 9),
    cylinders (eq. 37) and pistons (eq. 59); angular momentum of the platform (eq. 15),
    cylinders (eq. 49) and pistons (eq. 67). Shapes ``(..., [6,] 3)``."""
    x = arguments.states("x", x)
    xd = arguments.states("xd", xd)
    arguments.same_batch(x=x, xd=xd)
    _, amat = _inertia_times_t(platform_params(params), x, general)
    with np.errstate(over="ignore", invalid="ignore"):
        out = {
            body: np.einsum("...ij,...j->...i", a, xd if body.startswith("platform") else xd[..., None, :])
            for body, a in amat.items()
        }
    return arguments.finite_result("momenta", out, x)


def _inertia_rates(params: PlatformParams, x: np.ndarray, xd: np.ndarray, general: bool | None) -> dict:
    """``d/dt A_b = sum_k dA_b/dx_k xdot_k`` for every body part: by complex step along
    ``x + i h xdot`` for real inputs, by the sixth-order central difference of the module
    docstring along ``x + s xdot`` when ``x`` or ``xdot`` is complex."""
    if not (np.iscomplexobj(x) or np.iscomplexobj(xd)):
        step = _STEP / np.maximum(1.0, np.max(np.abs(xd), axis=-1))
        _, shifted = _inertia_times_t(params, x + 1j * step[..., None] * xd, general)
        total = {body: a.imag for body, a in shifted.items()}
    else:
        rates = np.abs(np.real(xd))
        shortest = np.min(leg_lengths(params, np.real(x)), axis=-1)
        speed = np.maximum(np.max(rates[..., :3], axis=-1) / shortest, np.max(rates[..., 3:], axis=-1))
        step = _DIFFERENCE_STEP / np.where(speed > 0.0, speed, 1.0)
        total = {}
        for offset, weight in _DIFFERENCE_WEIGHTS:
            _, shifted = _inertia_times_t(params, x + offset * step[..., None] * xd, general)
            for body, a in shifted.items():
                total[body] = total.get(body, 0.0) + weight * a
    return {body: a / step.reshape(step.shape + (1,) * (a.ndim - step.ndim)) for body, a in total.items()}


def body_terms(params: PlatformParams, x, xd=None, general: bool | None = None) -> dict[str, BodyTerms]:
    """Each body part's inertia matrix ``J^T A`` (eqs. 22, 40, 52, 62, 70), Coriolis and
    centripetal matrix ``J^T dA/dt`` (eqs. 23, 41, 53, 63, 71; zero when ``xd`` is None)
    and gravity vector ``m g J^T e_z`` (eqs. 72-75). ``x`` and ``xd`` may be complex (the
    module docstring says how ``dA/dt`` is then taken)."""
    x, xd = _states_and_rates(x, xd)
    return _body_terms(platform_params(params), x, xd, general)


def _states_and_rates(x, xd) -> tuple[np.ndarray, np.ndarray]:
    """The checked ``x`` and ``xd`` of :func:`body_terms` (zero rates for ``None``)."""
    x = arguments.states("x", x, allow_complex=True)
    if xd is None:
        xd = np.zeros_like(x)
    xd = arguments.states("xd", xd, allow_complex=True)
    arguments.same_batch(x=x, xd=xd)
    return x, xd


def _body_terms(params: PlatformParams, x: np.ndarray, xd: np.ndarray, general: bool | None) -> dict[str, BodyTerms]:
    a_dot = _inertia_rates(params, x, xd, general)
    jacs, amat = _inertia_times_t(params, x, general)
    weights = {
        "platform_translation": params.platform_mass,
        "cylinder_translation": params.cylinder_mass,
        "piston_translation": params.piston_mass,
    }
    out = {}
    with np.errstate(over="ignore", invalid="ignore"):
        for body in BODIES:
            jac_t = np.swapaxes(jacs[body], -1, -2)
            mass = jac_t @ amat[body]
            coriolis = jac_t @ a_dot[body]
            weight = weights.get(body, 0.0) * params.gravity
            out[body] = BodyTerms(mass, coriolis, weight * jacs[body][..., 2, :])
    return arguments.finite_result("body_terms", out, x)


def _totals(params, x, xd, function: str, general: bool | None = None) -> BodyTerms:
    """``M``, ``V`` and ``G`` of the whole platform: the body terms summed over bodies and legs."""
    totals = [0.0, 0.0, 0.0]
    with np.errstate(over="ignore", invalid="ignore"):
        for body, term in _body_terms(params, *_states_and_rates(x, xd), general).items():
            for k, value in enumerate(term):
                leg_axis = -2 if k == 2 else -3  # the gravity vector has one axis less
                totals[k] = totals[k] + (value if body.startswith("platform") else value.sum(axis=leg_axis))
    return arguments.finite_result(function, BodyTerms(*totals), x)


def _general(params: PlatformParams) -> bool:
    """Whether the legs need the paper's cylinder frames (non-axisymmetric leg inertia)."""
    return not params.is_axisymmetric


def twist_mass_matrix(params: PlatformParams, x) -> np.ndarray:
    """The twist-space mass matrix ``M_t = sum_b J_b^T I_b J_b`` (eqs. 19, 39, 51, 61, 69
    without the factor ``T``), symmetric, ``(..., 6, 6)``: ``M = M_t T``."""
    return _twist_mass_matrix(platform_params(params), x)


def _twist_mass_matrix(params: PlatformParams, x) -> np.ndarray:
    x = arguments.states("x", x)
    general = _general(params)
    _check_legs("twist_mass_matrix", params, x, general)
    jacs = _partial_velocity_jacobians(params, x)
    inertias = _rotational_inertias(params, x, general)
    masses = _masses(params)
    total = 0.0
    with np.errstate(over="ignore", invalid="ignore"):
        for body in BODIES:
            jac = jacs[body]
            moved = masses[body] * jac if body in masses else inertias[body] @ jac
            term = np.swapaxes(jac, -1, -2) @ moved
            total = total + (term if body.startswith("platform") else term.sum(axis=-3))
    return arguments.finite_result("twist_mass_matrix", total, x)


def mass_matrix(params: PlatformParams, x) -> np.ndarray:
    """``M = sum_b J_b^T I_b J_b T`` (6x6, not symmetric: it multiplies ``xddot``)."""
    x = arguments.states("x", x)
    params = platform_params(params)
    _check_legs("mass_matrix", params, x, _general(params))
    return _totals(params, x, None, "mass_matrix").mass_matrix


def coriolis_matrix(params: PlatformParams, x, xd) -> np.ndarray:
    """``V = sum_b J_b^T d/dt(I_b J_b T)`` (6x6)."""
    x = arguments.states("x", x)
    params = platform_params(params)
    _check_legs("coriolis_matrix", params, x, _general(params))
    return _totals(params, x, xd, "coriolis_matrix").coriolis_matrix


def coriolis_vector(params: PlatformParams, x, xd) -> np.ndarray:
    """``V xdot``."""
    x = arguments.states("x", x)
    xd = arguments.states("xd", xd)
    params = platform_params(params)
    _check_legs("coriolis_vector", params, x, _general(params))
    matrix = _totals(params, x, xd, "coriolis_matrix").coriolis_matrix
    with np.errstate(over="ignore", invalid="ignore"):
        vxd = np.einsum("...ij,...j->...i", matrix, xd)
    return arguments.finite_result("coriolis_vector", vxd, x)


def gravity_vector(params: PlatformParams, x) -> np.ndarray:
    """``G = sum_b m_b g J_b^T e_z`` (eqs. 72-76); it does not depend on the rotational
    inertias, so the legs' axisymmetric form serves every platform (no vertical-leg test)."""
    x = arguments.states("x", x)
    params = platform_params(params)
    _check_legs("gravity_vector", params, x, False)
    return _totals(params, x, None, "gravity_vector", general=False).gravity_vector


def inverse_dynamics(params: PlatformParams, x, xd, xdd) -> np.ndarray:
    """Actuator forces ``tau = J_C^-T (M xddot + V xdot + G)`` (eqs. 1-2, 20); the legs are
    checked, then ``J_C`` (its Hadamard ratio).

    The inputs may be complex, for complex-step derivatives: ``dA/dt`` is then a
    sixth-order central difference (module docstring)."""
    x = arguments.states("x", x, allow_complex=True)
    xd = arguments.states("xd", xd, allow_complex=True)
    xdd = arguments.states("xdd", xdd, allow_complex=True)
    arguments.same_batch(x=x, xd=xd, xdd=xdd)
    rows = np.real(x).reshape(-1, 6)  # definedness is a property of the real point
    params = platform_params(params)
    _check_legs("inverse_dynamics", params, x, _general(params),
                lambda todo: conditions.jacobian_codes(jacobian(params, rows[todo])))
    jac = jacobian(params, x)
    total = _totals(params, x, xd, "inverse_dynamics")
    with np.errstate(over="ignore", invalid="ignore"):
        wrench = (
            np.einsum("...ij,...j->...i", total.mass_matrix, xdd)
            + np.einsum("...ij,...j->...i", total.coriolis_matrix, xd)
            + total.gravity_vector
        )
        tau = np.linalg.solve(np.swapaxes(jac, -1, -2), wrench[..., None])[..., 0]
    return arguments.finite_result("inverse_dynamics", tau, x)


def forward_dynamics(params: PlatformParams, x, xd, tau) -> np.ndarray:
    """Euler accelerations ``xddot = M^-1 (J_C^T tau - V xdot - G)``; the legs are checked,
    then ``cos theta`` (``J_A``), then the ``LDL^T`` pivots of :func:`twist_mass_matrix`.

    The inputs may be complex, for complex-step derivatives: ``dA/dt`` is then a
    sixth-order central difference (module docstring)."""
    x = arguments.states("x", x, allow_complex=True)
    xd = arguments.states("xd", xd, allow_complex=True)
    tau = arguments.states("tau", tau, allow_complex=True)
    arguments.same_batch(x=x, xd=xd, tau=tau)
    rows = np.real(x).reshape(-1, 6)  # definedness is a property of the real point
    params = platform_params(params)
    _check_legs("forward_dynamics", params, x, _general(params), conditions.euler_codes(rows),
                lambda todo: conditions.mass_codes(_twist_mass_matrix(params, rows[todo])))
    total = _totals(params, x, xd, "forward_dynamics")
    with np.errstate(over="ignore", invalid="ignore"):
        rhs = (
            np.einsum("...ji,...j->...i", jacobian(params, x), tau)
            - np.einsum("...ij,...j->...i", total.coriolis_matrix, xd)
            - total.gravity_vector
        )
        xdd = np.linalg.solve(total.mass_matrix, rhs[..., None])[..., 0]
    return arguments.finite_result("forward_dynamics", xdd, x)
