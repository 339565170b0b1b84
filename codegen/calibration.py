"""Kinematic calibration: the inverse-kinematics residuals of a built machine and their exact
Jacobians in its geometry and its pose.

The error model is that of Masory, Wang & Zhuang (1993): the base joint centres b_i, the
platform joint centres p_i in {P} and the leg length offsets delta_i (the parameters of the
kernels, `PARAMS.base`, `PARAMS.plat`, `PARAMS.delta`), the true leg length the encoder
reading e_i plus delta_i.  With the legs of `kinematics.kinematics` (l_i = t + R p_i - b_i,
eq. 26; u_i = l_i / |l_i|) the residual of leg i is the measured less the modelled length
(Zhuang & Roth 1993)

    r_i = e_i + delta_i - |l_i|,

whose partials are dr_i/db_i = u_i, dr_i/dp_i = -R^T u_i, dr_i/ddelta_i = 1 (its other 35
parameters' are zero) and, along the pose, dr/dx = -J_C T (J_C of eq. 5, T of eq. 18).
A target at c in {P} is at q = t + R c, with dq/dx = [E, -[R c]x J_A] (J_A of eq. 8: the
velocity omega x R c for angle rates w, omega = J_A w).
"""

import sympy as sp

from .graph import Graph, KernelSpec, cross, symbols
from .kinematics import PARAMS, X, jacobian_rows, kinematics, leg_checks

READINGS = symbols('e', 6)   # the legs' encoder readings e_i
TARGET = symbols('tc', 6)    # a target's position c in {P}: its first three entries (the rest unread)

#: The nonzero partials of a leg's residual in the 42 geometric parameters, in the order of
#: the compact block `leg_residual_jacobians_kernel` writes per leg.
LEG_PARTIALS = 'd/db_i (x, y, z), d/dp_i (x, y, z), d/ddelta_i'


def leg_residuals_kernel():
    """The residuals r_i = e_i + delta_i - |l_i| (eq. 26) of the encoder readings e."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    residuals = [e + delta - leg.L for e, delta, leg in zip(READINGS, PARAMS.delta, kin.legs)]
    return KernelSpec('leg_residuals', leg_residuals_kernel.__doc__, g, [('x', X), ('readings', READINGS)],
                      [('r', residuals)])


def leg_residual_jacobians_kernel():
    """The residuals' partials: per leg i (row-major, 7 a leg) those in its own parameters,
    [u_i, -R^T u_i, 1] (`LEG_PARTIALS`), and dr/dx = -J_C T (eqs. 5, 8, 18), row-major."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    own = []
    for leg in kin.legs:
        own += list(leg.u) + list(-(kin.R.T * leg.u)) + [sp.S.One]
    T = sp.diag(sp.eye(3), kin.J_A)
    return KernelSpec('leg_residual_jacobians', leg_residual_jacobians_kernel.__doc__, g, [('x', X)],
                      [('dr_dtheta', own), ('dr_dx', list(-jacobian_rows(kin) * T))] + leg_checks(kin))


def _target(g):
    """The rotation's kinematics and R c of the target c."""
    kin = kinematics(g, PARAMS)
    return kin, g.vector('rc', kin.R * sp.Matrix(TARGET[:3]))


def target_positions_kernel():
    """The position q = t + R c in {B} of a target at c in {P}."""
    g = Graph({})
    _, rc = _target(g)
    return KernelSpec('target_positions', target_positions_kernel.__doc__, g, [('x', X), ('offsets', TARGET)],
                      [('q', list(sp.Matrix(X[:3]) + rc))])


def target_jacobian_kernel():
    """dq/dx = [E, -[R c]x J_A] (3 x 6, row-major) of q = t + R c: column 3 + j is the
    velocity (J_A e_j) x R c of the target (eq. 8)."""
    g = Graph({})
    kin, rc = _target(g)
    turn = sp.Matrix.hstack(*(cross(kin.J_A[:, j], rc) for j in range(3)))
    return KernelSpec('target_jacobian', target_jacobian_kernel.__doc__, g, [('x', X), ('offsets', TARGET)],
                      [('dq_dx', list(sp.Matrix.hstack(sp.eye(3), turn)))])
