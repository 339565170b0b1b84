"""The platform model written with CasADi SX, the way a CasADi user would write it.

Per body part b (platform translation and rotation; per leg, cylinder and piston
translation and rotation) the partial-velocity Jacobian ``J_b`` (twist -> body velocity,
eqs. 31, 35, 57) is an explicit SX matrix and the momentum is
``h_b(x, xd) = I_b J_b T xd`` (eqs. 9, 15, 37, 49, 59, 67). CasADi's forward-mode
automatic differentiation gives its time derivative

    d/dt h_b = jtimes(h_b, x, xd) + jtimes(h_b, xd, xdd),

and the generalized force is ``W = sum_b J_b^T (d/dt h_b + m_b g e_z)``
(``= M xdd + V xd + G``). Inverse dynamics solves ``J_C^T tau = W`` and forward dynamics
``M xdd = J_C^T tau - W|_{xdd=0}`` with ``M = dW/dxdd``, both with CasADi's symbolic
linear solve (``casadi.solve``, a QR factorization in the expression graph).

The 51 parameters are a function input ``p`` (runtime parameters, as in our kernel; see
:func:`benchmarks.peers.common.param_vector`). :func:`build` can also bake one parameter
set in as constants (``baked=params``), which lets CasADi fold them.

Leg inertias: the axisymmetric form ``I_t (E - u u^T) + I_a u u^T`` (the presets' legs
are axisymmetric), or with ``general=True`` the paper's cylinder frame {C_i}.
"""

from __future__ import annotations

import numpy as np

from .common import PARAM_COUNT, unpack

__all__ = ["build", "operation_counts"]


def _skew(ca, a):
    return ca.vertcat(ca.horzcat(0, -a[2], a[1]), ca.horzcat(a[2], 0, -a[0]), ca.horzcat(-a[1], a[0], 0))


def _leg_inertia(ca, u, inertia, general):
    axial, iyy, izz = inertia[0], inertia[1], inertia[2]
    uu = u @ u.T
    if not general:
        return iyy * (ca.SX.eye(3) - uu) + axial * uu
    h = ca.sqrt(u[0] ** 2 + u[1] ** 2)
    y_c = ca.vertcat(-u[1] / h, u[0] / h, 0)
    z_c = ca.cross(u, y_c)
    return axial * uu + iyy * (y_c @ y_c.T) + izz * (z_c @ z_c.T)


def symbolic_model(general: bool = False):
    """SX symbols and expressions: dict with x, xd, xdd, tau, p, W (= M xdd + V xd + G),
    JC, M, tau_id (inverse dynamics) and xdd_fd (forward dynamics)."""
    import casadi as ca

    x, xd, xdd = ca.SX.sym("x", 6), ca.SX.sym("xd", 6), ca.SX.sym("xdd", 6)
    tau, p = ca.SX.sym("tau", 6), ca.SX.sym("p", PARAM_COUNT)
    P = unpack(p)
    psi, theta, phi = x[3], x[4], x[5]
    cps, sps, cth, sth, cph, sph = ca.cos(psi), ca.sin(psi), ca.cos(theta), ca.sin(theta), ca.cos(phi), ca.sin(phi)
    rz = ca.vertcat(ca.horzcat(cps, -sps, 0), ca.horzcat(sps, cps, 0), ca.horzcat(0, 0, 1))
    ry = ca.vertcat(ca.horzcat(cth, 0, sth), ca.horzcat(0, 1, 0), ca.horzcat(-sth, 0, cth))
    rx = ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, cph, -sph), ca.horzcat(0, sph, cph))
    rot = rz @ ry @ rx
    j_a = ca.vertcat(ca.horzcat(0, -sps, cps * cth), ca.horzcat(0, cps, sps * cth), ca.horzcat(1, 0, -sth))
    t_mat = ca.diagcat(ca.SX.eye(3), j_a)
    e3, z3 = ca.SX.eye(3), ca.SX.zeros(3, 3)
    ez = ca.vertcat(0, 0, 1)

    # (J_b, A_b = I_b J_b, mass for gravity) of every body part; J_b: twist -> velocity.
    bodies = [
        (ca.horzcat(e3, z3), P["platform_mass"] * ca.horzcat(e3, z3), P["platform_mass"]),
        (ca.horzcat(z3, e3), rot @ ca.diag(P["platform_inertia"]) @ rot.T @ ca.horzcat(z3, e3), 0),
    ]
    jc_rows = []
    for i in range(6):
        r = rot @ P["platform_points"][i]
        leg = x[:3] + r - P["base_points"][i]
        length_sq = ca.dot(leg, leg)
        u = leg / ca.sqrt(length_sq)
        point = ca.horzcat(e3, -_skew(ca, r))          # velocity of P_i: [E, r~^T]
        j_d = _skew(ca, leg / length_sq) @ point        # leg angular velocity (eq. 31)
        j_cyl = -P["cylinder_com_distance"] * _skew(ca, u) @ j_d        # eq. 35
        j_pis = point + P["piston_com_distance"] * _skew(ca, u) @ j_d  # eq. 57
        bodies += [
            (j_cyl, P["cylinder_mass"] * j_cyl, P["cylinder_mass"]),
            (j_d, _leg_inertia(ca, u, P["cylinder_inertia"], general) @ j_d, 0),
            (j_pis, P["piston_mass"] * j_pis, P["piston_mass"]),
            (j_d, _leg_inertia(ca, u, P["piston_inertia"], general) @ j_d, 0),
        ]
        jc_rows.append(ca.horzcat(u.T, ca.cross(r, u).T))
    jc = ca.vertcat(*jc_rows)

    wrench = ca.SX.zeros(6)
    for jac, amat, mass in bodies:
        h = amat @ (t_mat @ xd)                                   # momentum h_b(x, xd)
        h_dot = ca.jtimes(h, x, xd) + ca.jtimes(h, xd, xdd)       # d/dt h_b by forward AD
        wrench += jac.T @ h_dot
        if not (isinstance(mass, int) and mass == 0):
            wrench += jac.T @ (mass * P["gravity"] * ez)
    mass_matrix = ca.jacobian(wrench, xdd)
    rest = ca.substitute(wrench, xdd, ca.SX.zeros(6))             # V xd + G
    return {
        "x": x, "xd": xd, "xdd": xdd, "tau": tau, "p": p, "W": wrench, "JC": jc, "M": mass_matrix,
        "tau_id": ca.solve(jc.T, wrench),
        "xdd_fd": ca.solve(mass_matrix, jc.T @ tau - rest),
    }


def build(general: bool = False, baked=None) -> dict:
    """CasADi Functions ``inverse_dynamics(x, xd, xdd, p) -> tau`` and
    ``forward_dynamics(x, xd, tau, p) -> xdd`` (``p`` from ``param_vector``).

    With ``baked`` (a PlatformParams) the functions take no ``p``: the parameters are
    constants in the expression graph."""
    import casadi as ca

    s = symbolic_model(general)
    f_id = ca.Function("stewart_casadi_id", [s["x"], s["xd"], s["xdd"], s["p"]], [s["tau_id"]],
                       ["x", "xd", "xdd", "p"], ["tau"])
    f_fd = ca.Function("stewart_casadi_fd", [s["x"], s["xd"], s["tau"], s["p"]], [s["xdd_fd"]],
                       ["x", "xd", "tau", "p"], ["xdd"])
    if baked is not None:
        from .common import param_vector

        pv = ca.DM(param_vector(baked))
        a, b, c = ca.SX.sym("x", 6), ca.SX.sym("xd", 6), ca.SX.sym("u", 6)
        f_id = ca.Function("stewart_casadi_id", [a, b, c], [f_id(a, b, c, pv)], ["x", "xd", "xdd"], ["tau"])
        f_fd = ca.Function("stewart_casadi_fd", [a, b, c], [f_fd(a, b, c, pv)], ["x", "xd", "tau"], ["xdd"])
    return {"inverse_dynamics": f_id, "forward_dynamics": f_fd}


def operation_counts(functions: dict) -> dict:
    """CasADi's own size measures: instructions of the SX algorithm and expression nodes."""
    return {name: {"n_instructions": int(f.n_instructions()), "n_nodes": int(f.n_nodes())}
            for name, f in functions.items()}


def evaluate(function, a, b, c, p=None) -> np.ndarray:
    """One call of a CasADi Function on numpy inputs; returns a (6,) array."""
    args = (a, b, c) if p is None else (a, b, c, p)
    return np.asarray(function(*args)).ravel()
