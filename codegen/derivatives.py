"""The partials of the dynamics (Lopes & Pires 2011; see `kinematics`), through each leg's
local Jacobian: a leg depends on the platform only through its leg vector and the velocity
and acceleration of P_i, so its force at P_i is differentiated in those few variables
(`leg_derivatives_kernel`, the six legs at once), chained to the pose and its rates
(`leg_chain_kernel`) and summed with the platform's own terms (`residual_derivatives_kernel`);
the statics' likewise through the leg vector alone (`static_derivatives_kernel`).
"""

import sympy as sp

from .bodies import (gravity_forces, leg_force, leg_momenta, platform_angular_momentum, platform_force,
                     platform_velocity)
from .graph import Graph, KernelSpec, Tangent, cross, dot, symbols
from .kinematics import (NUM_LEGS, PARAMS, TAU, X, XD, XDD, accelerated_graph, kinematics, kinematics_of,
                         leg_geometry, twist, variant_spec)


def static_derivatives_kernel(variant):
    """Z = R_x = d(G - J_C^T tau)/dx at fixed tau (6 x 6, row-major), the partials of the
    residual of the equation of motion at rest (xd = xdd = 0; eqs. 5, 72-76), with no velocity
    or acceleration in the derivation.  The residual is the platform's weight (`platform_force`)
    plus per leg [f_i; r_i x f_i] with f_i the force at P_i equivalent to the leg's weights
    (`leg_force`) less tau_i u_i.  f_i depends on x only through the leg vector l_i, so its
    3 x 3 Jacobian F_i = df_i/dl_i (forward mode along each component of l_i) is chained to x:
    dl_i/dp_k = e_k, and along theta_k dr_i = dl_i = (J_A e_k) x r_i (likewise for R c)."""
    P = PARAMS
    g = Graph({})
    kin = kinematics_of(g, variant)
    w_P, w_C, w_S = gravity_forces(P, True)
    legs = []
    for i, leg in enumerate(kin.legs):
        f = g.vector(f'st{i}', leg_force(g, P, leg, w_C, w_S, sp.zeros(3, 1), f's{i}') - TAU[i] * leg.u)
        F = [Tangent(g, {leg.l[c]: sp.S.One}, f'Dl{i}{c}')(f[a]) for a in range(3) for c in range(3)]
        legs.append((leg, f, sp.Matrix(3, 3, [g.define(f'F{i}_{k}', e) for k, e in enumerate(F)])))
    columns = []
    for j in range(6):
        turn = kin.J_A[:, j - 3] if j >= 3 else None  # the angular velocity of a unit rate of theta_{j-3}
        column = sp.zeros(6, 1)
        if turn is not None and kin.rho is not None:
            column[3:, 0] = cross(g.vector(f'sdrho{j}', cross(turn, kin.rho)), w_P)
        for i, (leg, f, F) in enumerate(legs):
            dr = g.vector(f'sdr{i}_{j}', cross(turn, leg.r)) if turn is not None else sp.zeros(3, 1)
            df = g.vector(f'sdf{i}_{j}', F[:, j] if turn is None else F * dr)
            column += sp.Matrix.vstack(df, cross(leg.r, df) + cross(dr, f))
        columns.append(column)
    return variant_spec(variant, 'static_derivatives', static_derivatives_kernel.__doc__, g,
                         [('x', X), ('tau', TAU)], [('Z', [columns[j][i] for i in range(6) for j in range(6)])])


#: Inputs of the per-leg kernel: the leg vector l, the velocity w and the acceleration a of
#: P_i (l' = w, w' = a, as b_i is fixed), |l| and sqrt(l_x^2 + l_y^2), and the actuator force.
LEG_POINT = symbols('P', 11)
LEG_TAU = symbols('tau_leg', 1)

#: Size of the per-leg outputs of `leg_derivatives_kernel`: f (3), df/d[l; w; a] (27), u (3).
LEG_OUT = 33

#: Size of the per-leg outputs of `leg_points_kernel`: the inputs of the leg kernel, then r_i
#: (and, for the general model, the joint's first axis a_i after them).
POINT_OUT = len(LEG_POINT) + 3

#: The joint's first axis a_i, the general model's further input of the per-leg kernel.
LEG_AXIS = symbols('A', 3)


def _point_motion(g, kin, v, omega):
    """Per leg (l, w, a): the leg vector, the velocity w = v + omega x r and the acceleration
    a = dw/dt of P_i (eqs. 26, 27)."""
    out = []
    for i, leg in enumerate(kin.legs):
        w = g.vector(f'qvP{i}', v + cross(omega, leg.r))
        out.append((leg.l, w, w.applyfunc(g.rate)))
    return out


def leg_points_kernel(variant):
    """[l; w; a; |l|; sqrt(l_x^2 + l_y^2); r] of every leg's P_i (`_point_motion`), 14 per
    leg, interleaved (entry k of leg i at k * 6 + i): the inputs of the per-leg kernels; for
    the general model, then the joint's first axis a_i (17 per leg)."""
    g = accelerated_graph()
    kin = kinematics(g, PARAMS)
    v, omega = twist(g, kin, XD, 'q')
    points = [list(l) + list(w) + list(a) + [leg.L, sp.sqrt(l[0] ** 2 + l[1] ** 2)] + list(leg.r)
              + (list(PARAMS.axes[i]) if variant == 'general' else [])
              for i, (leg, (l, w, a)) in enumerate(zip(kin.legs, _point_motion(g, kin, v, omega)))]
    return variant_spec(variant, 'leg_points', leg_points_kernel.__doc__, g,
                      [('x', X), ('xd', XD), ('xdd', XDD)],
                      [('lwa', [points[i][k] for k in range(len(points[0])) for i in range(NUM_LEGS)])])


def leg_derivatives_kernel(variant):
    """One leg's share of the residual r = M xdd + V xd + G - J_C^T tau, as the force f at
    P_i (r gets [f; r_i x f], see `generalized_force`): the leg momenta (eqs. 27-29, 55-57,
    65) and their rates by forward mode along l' = w, w' = a, gravity (eqs. 72-76) and the
    actuator force, f = f_legs - tau_i u_i; then df/d[l; w; a] (3 x 9, row-major) by forward
    mode along each of them, and u = -df/dtau_i.  The leg depends on the platform only
    through (l, w, a), so one kernel serves the six legs at once (`KernelSpec.lanes`):
    legs = [f (3); df/d[l; w; a] (27); u (3)] per leg, interleaved.  |l| and
    sqrt(l_x^2 + l_y^2) come in with their derivatives as seeds, so the six legs run with no
    square root, which would keep the compiler from vectorizing them."""
    P = PARAMS
    l, w, a = (sp.Matrix(LEG_POINT[3 * k:3 * k + 3]) for k in range(3))
    L, h = LEG_POINT[9:]
    # dL = u . dl, dh = (l_x dl_x + l_y dl_y) / h
    along = lambda d: {L: dot(l, d) / L, h: (l[0] * d[0] + l[1] * d[1]) / h}
    g = Graph({**dict(zip(l, w)), **dict(zip(w, a)), **along(w)})
    general = variant == 'general'
    leg = leg_geometry(g, l, None, 'i', variant == 'frames', (L, h), axis=sp.Matrix(LEG_AXIS) if general else None)
    v_C, v_S, h_L = leg_momenta(g, P, leg, w, variant, 'i')
    _, w_C, w_S = gravity_forces(P, True)
    rate = lambda vec: vec.applyfunc(g.rate)
    f = leg_force(g, P, leg, P.m_C * rate(v_C) + w_C, P.m_S * rate(v_S) + w_S, rate(h_L), 'i') - LEG_TAU[0] * leg.u
    columns = []
    for k, s in enumerate(LEG_POINT[:9]):
        e = [1 if j == k else 0 for j in range(3)]
        tangent = Tangent(g, {s: sp.S.One, **(along(e) if k < 3 else {})}, f'D{k}')
        columns.append([tangent(c) for c in f])
    out = list(f) + [columns[k][c] for c in range(3) for k in range(9)] + list(leg.u)
    return variant_spec(variant, 'leg_derivatives', leg_derivatives_kernel.__doc__, g,
                      [('lwa', LEG_POINT + (symbols('Pr', 3) + LEG_AXIS if general else [])), ('tau', LEG_TAU)],
                      [('legs', out)], lanes=NUM_LEGS)


def _directions(forward):
    """(tag, inputs) of the partials: dr/dxdd (inverse dynamics only), dr/dx, dr/dxd."""
    return (('Dx', X), ('Dxd', XD)) if forward else (('Dxdd', XDD), ('Dx', X), ('Dxd', XD))


def leg_chain_kernel(forward):
    """One leg's share [f; r x f] of the residual's partials (see `residual_derivatives_kernel`):
    its f and df/d[l; w; a] from `leg_derivatives_kernel` chained to x, xd (and xdd) by
    forward mode through l = p + r - b, w = v + omega x r and a = dw/dt, with r = R p_i given
    (r' = omega x r, dr/dtheta_k = (J_A e_k) x r).  The six legs at once (`KernelSpec.lanes`):
    chain = 6 x (12 or 18) per leg, row-major, interleaved, negated for forward dynamics."""
    g = accelerated_graph()
    kin = kinematics(g, PARAMS)
    v, omega = twist(g, kin, XD, 'q')
    point = symbols('Q', POINT_OUT)
    rv = sp.Matrix(point[-3:])
    g.rate.seed.update(zip(rv, cross(omega, rv)))
    w = g.vector('qvP', v + cross(omega, rv))
    motion = (sp.Matrix(X[:3]) + rv, w, w.applyfunc(g.rate))  # l up to the constant b_i
    leg = symbols('Lg', LEG_OUT)
    f, F = sp.Matrix(leg[:3]), sp.Matrix(3, 9, leg[3:30])
    share = list(f) + list(cross(rv, f))
    columns = []
    for tag, inputs in _directions(forward):
        for j, s in enumerate(inputs):
            seed = {s: sp.S.One}
            if s in X[3:]:
                seed.update(zip(rv, cross(kin.J_A[:, X.index(s) - 3], rv)))
            tangent = Tangent(g, seed, f'{tag}{j}')
            dpoint = [tangent(e) for vec in motion for e in vec]
            tangent.seed.update({f[c]: sp.Add(*[F[c, k] * d for k, d in enumerate(dpoint)]) for c in range(3)})
            columns.append([(-1 if forward else 1) * tangent(e) for e in share])
    chain = [columns[j][i] for i in range(6) for j in range(len(columns))]
    return KernelSpec(f'leg_chain_{"forward" if forward else "inverse"}', leg_chain_kernel.__doc__, g,
                      [('x', X), ('xd', XD), ('xdd', XDD), ('lwa', point), ('legs', leg)], [('chain', chain)],
                      lanes=NUM_LEGS, shared=('x', 'xd', 'xdd'))


def residual_derivatives_kernel(forward, variant):
    """The partials of the residual r(x, xd, xdd, tau) = M xdd + V xd + G - J_C^T tau of the
    equation of motion (eqs. 5, 19, 39, 51, 61, 69, 72-76) at any (xdd, tau): the platform's
    own terms [m_P (v' + g e_z); d/dt(I_P omega)] by forward mode along each input, plus the
    legs' shares [f_i; r_i x f_i] from `leg_chain_kernel`.  Z is 6 x 18, row-major, with
    M = dr/dxdd, R_x = dr/dx, R_xd = dr/dxd and J_C^T = -dr/dtau (row i = [u_i; r_i x u_i]):
    inverse dynamics solves J_C^T [dtau/dxdd, dtau/dx, dtau/dxd] = Z = [M, R_x, R_xd];
    forward dynamics (`forward`) M [dxdd/dx, dxdd/dxd, dxdd/dtau] = Z = [-R_x, -R_xd, J_C^T]."""
    P = PARAMS
    g = accelerated_graph()
    kin = kinematics_of(g, variant)
    v, omega = twist(g, kin, XD, 'q')
    w_P, _, _ = gravity_forces(P, True)
    rate = lambda vec: vec.applyfunc(g.rate)
    platform = platform_force(kin, sp.Matrix.vstack(P.m_P * rate(platform_velocity(g, kin, v, omega, 'q')) + w_P,
                                                    rate(platform_angular_momentum(g, P, kin, omega, 'q'))))
    columns = [[(-1 if forward else 1) * Tangent(g, {s: sp.S.One}, f'{tag}{j}')(e) for e in platform]
               for tag, inputs in _directions(forward) for j, s in enumerate(inputs)]
    ncol = len(columns)
    chain = symbols('chain', NUM_LEGS * 6 * ncol)
    lwa = symbols('lwa', NUM_LEGS * POINT_OUT)
    legs = symbols('legs', NUM_LEGS * LEG_OUT)
    Z = [[columns[j][i] + sp.Add(*[chain[(i * ncol + j) * NUM_LEGS + leg] for leg in range(NUM_LEGS)])
          for j in range(ncol)] for i in range(6)]
    if forward:
        for leg in range(NUM_LEGS):
            u = sp.Matrix([legs[k * NUM_LEGS + leg] for k in range(30, 33)])
            rv = sp.Matrix([lwa[k * NUM_LEGS + leg] for k in range(POINT_OUT - 3, POINT_OUT)])
            for i, e in enumerate(list(u) + list(cross(rv, u))):
                Z[i].append(e)
    return variant_spec(variant, f'residual_derivatives_{"forward" if forward else "inverse"}',
                      residual_derivatives_kernel.__doc__, g,
                      [('x', X), ('xd', XD), ('xdd', XDD), ('chain', chain)]
                      + ([('lwa', lwa), ('legs', legs)] if forward else []),
                      [('Z', [e for row in Z for e in row])])
