"""The partials of the dynamics (Lopes & Pires 2011; see `kinematics`), through each leg's
local Jacobian: a leg depends on the platform only through its leg vector and the velocity
and acceleration of P_i, so its force at P_i is differentiated in those few variables and
chained, in the same loop over the six legs, to the platform's twist-level coordinates
(`leg_derivatives_kernel`); the platform's own terms are differentiated in those coordinates
and the sum taken to the pose and its rates (`residual_derivatives_kernel`), the legs' points
coming from `leg_points_kernel` (or, for the inverse dynamics, from its own kernel,
`inverse_dynamics_points_kernel`); the statics' likewise through the leg vector alone
(`static_derivatives_kernel`).
"""

import sympy as sp

from .bodies import (axisymmetric_leg_force, gravity_forces, leg_force, leg_momenta, platform_angular_momentum, platform_force,
                     platform_velocity)
from .dynamics import inverse_dynamics
from .graph import Graph, Tangent, cross, dot, skew, symbols
from .kinematics import (NUM_LEGS, PARAMS, TAU, X, XD, XDD, accelerated_graph, jacobian_rows, kinematics,
                         kinematics_of, leg_checks, leg_geometry, trig_seeds, twist, variant_spec)


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
#: P_i (l' = w, w' = a, as b_i is fixed), |l| and sqrt(l_x^2 + l_y^2), then r_i = R p_i.
LEG_POINT = symbols('P', 11)
LEG_R = symbols('Pr', 3)
LEG_TAU = symbols('tau_leg', 1)

#: The joint's first axis a_i, the general model's further input of the per-leg kernel.
LEG_AXIS = symbols('A', 3)

#: What the legs' chains share (`leg_points_kernel`): the platform's angular velocity omega
#: and A = [omega']x + [omega]x^2 (row-major), the acceleration of a point r fixed in the
#: platform being v' + A r; then the Euler angles' cosines and sines (`Kinematics.trig`),
#: which `residual_derivatives_kernel` takes.
SPIN = symbols('S', 18)

#: The twist-level coordinates of the residual's partials (3 each, in this order): the
#: platform's position p, a small rotation delta of it (R -> (E + [delta]x) R), its twist
#: [v; omega] and the twist's rate [v'; omega'].
TWIST = ('p', 'delta', 'v', 'omega', 'vd', 'omegad')


def _point_motion(g, kin, v, omega):
    """Per leg (l, w, a): the leg vector, the velocity w = v + omega x r and the acceleration
    a = dw/dt of P_i (eqs. 26, 27)."""
    out = []
    for i, leg in enumerate(kin.legs):
        w = g.vector(f'qvP{i}', v + cross(omega, leg.r))
        out.append((leg.l, w, w.applyfunc(g.rate)))
    return out


def _points(g, kin, v, omega, variant):
    """The outputs lwa and spin of `leg_points_kernel` for the legs of `kin` and the twist
    [v; omega], for the leg kernel `variant` (of `VARIANTS` or `MODELS`): sqrt(l_x^2 + l_y^2)
    where it uses the frames of eqs. 43-48, else 0, and the joint's axis for the general model."""
    heights = variant in ('paper', 'frames')
    points = [list(l) + list(w) + list(a) + [leg.L, sp.sqrt(l[0] ** 2 + l[1] ** 2) if heights else 0] + list(leg.r)
              + (list(PARAMS.axes[i]) if variant == 'general' else [])
              for i, (leg, (l, w, a)) in enumerate(zip(kin.legs, _point_motion(g, kin, v, omega)))]
    spin = list(omega) + list(skew(omega.applyfunc(g.rate)) + skew(omega) * skew(omega)) + list(kin.trig)
    return [('lwa', [points[i][k] for k in range(len(points[0])) for i in range(NUM_LEGS)]), ('spin', spin)]


def leg_points_kernel(variant):
    """[l; w; a; |l|; sqrt(l_x^2 + l_y^2); r] of every leg's P_i (`_point_motion`), 14 per
    leg, interleaved (entry k of leg i at k * 6 + i): the inputs of the per-leg kernels; for
    the general model, then the joint's first axis a_i (17 per leg); and what the legs'
    chains share, spin = [omega; [omega']x + [omega]x^2; the angles' cosines and sines] (`SPIN`)."""
    g = accelerated_graph()
    kin = kinematics(g, PARAMS)
    v, omega = twist(g, kin, XD, 'q')
    return variant_spec(variant, 'leg_points', leg_points_kernel.__doc__, g,
                        [('x', X), ('xd', XD), ('xdd', XDD)], _points(g, kin, v, omega, variant))


def inverse_dynamics_points_kernel(variant):
    """W = M xdd + V xd + G and J_C (to solve J_C^T tau = W), with the legs' points and what
    their chains share (`leg_points_kernel`): the first kernel of the inverse dynamics'
    derivatives."""
    g = accelerated_graph()
    kin, v, omega, W = inverse_dynamics(g, variant)
    return variant_spec(variant, 'inverse_dynamics_points', inverse_dynamics_points_kernel.__doc__, g,
                        [('x', X), ('xd', XD), ('xdd', XDD)],
                        [('W', list(W)), ('JC', list(jacobian_rows(kin)))] + leg_checks(kin)
                        + _points(g, kin, v, omega, variant))


def _block(g, name, matrix):
    """The 3 x 3 `matrix` with each entry a defined symbol."""
    return sp.Matrix(3, 3, lambda j, k: g.define(f'{name}_{j}{k}', matrix[j, k]))


def _upper(n):
    """(j, k) of the upper triangle of an n x n matrix, row by row."""
    return [(j, k) for j in range(n) for k in range(j, n)]


def _rotation_jacobian(g, leg, f, l, w, a, F_w, F_a):
    """F_l = df/dl of an axisymmetric leg from F_w and F_a: the leg and the gravity turned as
    a whole by a rotation Q turn its force, f(Q l, Q w, Q a; Q gamma) = Q f, so
    F_l [l]x = K = [f]x - F_w [w]x - F_a [a]x - G [gamma]x, with gamma = g e_z and
    G = df/dgamma (its columns the leg's force under a unit gravity along x and along y,
    `leg_force`); which gives F_l on the plane normal to u: F_l x = (F_l u)(u . x) - K [u]x x
    / L.  F_l u comes by forward mode along l' = u, seeded with what does not change (u) or
    changes by a power of L (L' = 1, (l . l)' = 2 L, (1 / L)' = -1 / L^2,
    (1 / L^2)' = -2 / L^3, lbar' = -lbar / L)."""
    P = PARAMS
    iL2 = g.known(1 / leg.L2)
    iL = g.known(leg.L * iL2)
    seed = {**dict(zip(l, leg.u)), leg.L: sp.S.One, leg.L2: 2 * leg.L, iL: -iL2, iL2: -2 * iL2 * iL,
            **{c: sp.S.Zero for c in leg.u}, **{c: -c * iL for c in leg.lbar}}
    along_u = Tangent(g, seed, 'Du')
    radial = g.vector('iDu', [along_u(c) for c in f])
    G_x, G_y = (leg_force(g, P, leg, P.m_C * e, P.m_S * e, sp.zeros(3, 1), f'iG{axis}')
                for axis, e in (('x', sp.Matrix([1, 0, 0])), ('y', sp.Matrix([0, 1, 0]))))
    turned_gravity = P.g * sp.Matrix.hstack(G_y, -G_x, sp.zeros(3, 1))  # G [g e_z]x
    K = _block(g, 'iK', skew(f) - F_w * skew(w) - F_a * skew(a) - turned_gravity)
    return radial * leg.u.T - K * skew(leg.u) * iL


def leg_derivatives_kernel(variant):
    """One leg's share of the partials of the residual r = M xdd + V xd + G - J_C^T tau in the
    twist-level coordinates (`TWIST`).  The leg acts on the platform as the force f at P_i
    (r gets [f; r_i x f], see `generalized_force`): the leg momenta (eqs. 27-29, 55-57, 65)
    and their rates by forward mode along l' = w, w' = a, gravity (eqs. 72-76) and the
    actuator force, f = f_legs - tau_i u_i (for axisymmetric legs f_legs in closed form,
    `bodies.axisymmetric_leg_force`: half the operations of the leg's chain); and its Jacobians F_w, F_a (symmetric, the leg's
    mass at P_i: its upper triangle) and F_l = df/d(w, a, l) by forward mode along each of
    the leg's variables (for axisymmetric legs F_l from the others, `_rotation_jacobian`).
    They are chained to the platform's motion through l = p + r - b, w = v + omega x r,
    a = v' + A r (`SPIN`), r the platform's point P_i: along p, df = F_l; along delta
    (dr = delta x r = -[r]x delta), df = -(F_l + F_w [omega]x + F_a A) [r]x, and
    [0; dr x f] = [0; (r f^T - (r . f) E) delta] more; along v, F_w; along omega,
    -(F_w [r]x + F_a ([omega]x [r]x + [omega x r]x)); each df enters as [df; r x df].  Along
    the twist's rate the share is the leg's part of M_t, [[F_a, -F_a [r]x], [[r]x F_a,
    -[r]x F_a [r]x]] (`dynamics.twist_mass_matrix`), symmetric.  The leg depends on the
    platform only through (l, w, a) and r, so one kernel serves the six legs at once
    (`KernelSpec.lanes`), their shares summed: Zt (6 x 12, row-major, the columns of p, delta,
    v, omega) and Mlegs (the upper triangle of M_t's part, row by row); and per leg, its row of
    J_C, [u; r x u] (eq. 5), interleaved.  |l| and sqrt(l_x^2 + l_y^2) come in with their
    derivatives as seeds, so the six legs run with no square root, which would keep the
    compiler from vectorizing them."""
    P = PARAMS
    l, w, a = (sp.Matrix(LEG_POINT[3 * k:3 * k + 3]) for k in range(3))
    L, h = LEG_POINT[9:]
    # dL = u . dl, dh = (l_x dl_x + l_y dl_y) / h
    along = lambda d: {L: dot(l, d) / L, h: (l[0] * d[0] + l[1] * d[1]) / h}
    g = Graph({**dict(zip(l, w)), **dict(zip(w, a)), **along(w)})
    general = variant == 'general'
    leg = leg_geometry(g, l, None, 'i', variant == 'frames', (L, h), axis=sp.Matrix(LEG_AXIS) if general else None)
    if variant == 'axisym':
        f = g.vector('ires', axisymmetric_leg_force(g, P, leg, w, a, 'i') - LEG_TAU[0] * leg.u)
    else:
        v_C, v_S, h_L = leg_momenta(g, P, leg, w, variant, 'i')
        _, w_C, w_S = gravity_forces(P, True)
        rate = lambda vec: vec.applyfunc(g.rate)
        f = g.vector('ires', leg_force(g, P, leg, P.m_C * rate(v_C) + w_C, P.m_S * rate(v_S) + w_S, rate(h_L), 'i')
                     - LEG_TAU[0] * leg.u)

    def jacobian(point, entries, tag):
        """df/d(point) (3 x 3), the given (row, column) entries by forward mode along each column."""
        J = sp.zeros(3, 3)
        for k in sorted({k for _, k in entries}):
            e = [1 if j == k else 0 for j in range(3)]
            tangent = Tangent(g, {point[k]: sp.S.One, **(along(e) if point is l else {})}, f'{tag}{k}')
            for c in sorted(c for c, col in entries if col == k):
                J[c, k] = tangent(f[c])
        return J

    full = [(c, k) for c in range(3) for k in range(3)]
    F_w = jacobian(w, full, 'Dw')
    F_a = jacobian(a, _upper(3), 'Da')
    F_a = sp.Matrix(3, 3, lambda c, k: F_a[min(c, k), max(c, k)])
    F_l = _rotation_jacobian(g, leg, f, l, w, a, F_w, F_a) if variant == 'axisym' else jacobian(l, full, 'Dl')
    r, omega, A = sp.Matrix(LEG_R), sp.Matrix(SPIN[:3]), sp.Matrix(3, 3, SPIN[3:12])
    Rx, Om = skew(r), skew(omega)
    G = _block(g, 'iG', F_l + F_w * Om + F_a * A)
    Dw = _block(g, 'iDw', Om * Rx + skew(g.vector('ic', cross(omega, r))))
    turn = _block(g, 'iT', r * f.T - g.define('irf', dot(r, f)) * sp.eye(3))  # [0; dr x f] per unit delta
    blocks = (F_l, -G * Rx, F_w, -(F_w * Rx + F_a * Dw))
    shares = []
    for b, (name, block) in enumerate(zip(TWIST, blocks)):
        for k in range(3):
            df = g.vector(f'id{name}{k}', block[:, k])
            moment = cross(r, df) + (turn[:, k] if name == 'delta' else sp.zeros(3, 1))
            shares.append(list(df) + list(moment))
    coupling = _block(g, 'iMB', -F_a * Rx)  # the mass's force along omega'; its transpose the moment along v'
    mass = sp.Matrix(sp.BlockMatrix([[F_a, coupling], [coupling.T, Rx * coupling]]))
    return variant_spec(variant, 'leg_derivatives', leg_derivatives_kernel.__doc__, g,
                        [('lwa', LEG_POINT + LEG_R + (LEG_AXIS if general else [])), ('tau', LEG_TAU), ('spin', SPIN)],
                        [('Zt', [shares[j][i] for i in range(6) for j in range(len(shares))]),
                         ('Mlegs', [mass[j, k] for j, k in _upper(6)]),
                         ('JCt', list(leg.u) + list(cross(r, leg.u)))],
                        lanes=NUM_LEGS, shared=('spin',), sums=('Zt', 'Mlegs'))


def _directions(forward):
    """(tag, inputs) of the partials: dr/dxdd (inverse dynamics only), dr/dx, dr/dxd."""
    return (('Dx', X), ('Dxd', XD)) if forward else (('Dxdd', XDD), ('Dx', X), ('Dxd', XD))


def residual_derivatives_kernel(forward, variant):
    """The partials of the residual r(x, xd, xdd, tau) = M xdd + V xd + G - J_C^T tau of the
    equation of motion (eqs. 5, 19, 39, 51, 61, 69, 72-76) at any (xdd, tau).  In the
    twist-level coordinates (`TWIST`): the legs' shares Zt and Mlegs (`leg_derivatives_kernel`) plus
    the platform's own terms [m_P (v_G' + g e_z); d/dt(I_P omega)] (`platform_force`), their
    rates taken with R' = [omega]x R, and their partials by forward mode along each twist-level
    coordinate, the others held (along delta, dR = [delta]x R).  Then to x, xd, xdd by the
    chain rule: a pose rate theta_k' turns the platform by delta = J_A e_k (eq. 8), and
    omega = J_A theta', omega' = d/dt(J_A theta') change with x, xd, xdd (forward mode on
    those few entries).  The 6 x 6 blocks (row-major) M = dr/dxdd, R_x = dr/dx, R_xd = dr/dxd
    and J_C^T = -dr/dtau (row i = [u_i; r_i x u_i]): inverse dynamics solves
    J_C^T dtau/dxdd = Zxdd = M, J_C^T dtau/dx = Zx = R_x, J_C^T dtau/dxd = Zxd = R_xd; forward
    dynamics (`forward`) M dxdd/dx = Zx = -R_x, M dxdd/dxd = Zxd = -R_xd (and
    M dxdd/dtau = J_C^T, `leg_derivatives_kernel`'s JCt)."""
    P = PARAMS
    g = accelerated_graph()
    trig = SPIN[12:]  # the points kernel's cosines and sines of the angles
    kin = kinematics_of(g, variant, trig=trig)
    R = kin.R
    v, omega = twist(g, kin, XD, 'q')
    vd, omegad = sp.Matrix(XDD[:3]), omega.applyfunc(g.rate)
    turn = skew(omega) * R
    spin = Tangent(g, {**dict(zip(v, vd)), **dict(zip(omega, omegad)),
                       **{R[j, k]: turn[j, k] for j in range(3) for k in range(3)}}, 't')
    rate = lambda vec: vec.applyfunc(spin)
    w_P, _, _ = gravity_forces(P, True)
    platform = platform_force(kin, sp.Matrix.vstack(P.m_P * rate(platform_velocity(g, kin, v, omega, 'q')) + w_P,
                                                    rate(platform_angular_momentum(g, P, kin, omega, 'q'))))
    held = {s: sp.S.Zero for s in [*v, *omega, *vd, *omegad, *R]}
    seeds = {'p': lambda k: None,
             'delta': lambda k: {R[j, m]: cross(sp.eye(3)[:, k], R[:, m])[j] for j in range(3) for m in range(3)},
             'v': lambda k: {v[k]: sp.S.One}, 'omega': lambda k: {omega[k]: sp.S.One},
             'vd': lambda k: {vd[k]: sp.S.One}, 'omegad': lambda k: {omegad[k]: sp.S.One}}
    Zt, Mlegs = symbols('Zt', 6 * 12), symbols('Mlegs', 21)
    upper = {jk: Mlegs[n] for n, jk in enumerate(_upper(6))}
    legs = [[Zt[12 * i + column] for i in range(6)] for column in range(12)]  # the legs' shares, by column
    legs += [[upper[min(i, column), max(i, column)] for i in range(6)] for column in range(6)]
    total = []  # the twist-level partials, column by column: the legs' and the platform's
    for b, name in enumerate(TWIST):
        for k in range(3):
            seed = seeds[name](k)
            own = [Tangent(g, {**held, **seed}, f'T{name}{k}')(e) for e in platform] if seed else [0] * 6
            total.append([g.define(f'Zt{name}{k}_{i}', legs[3 * b + k][i] + own[i]) for i in range(6)])
    columns = []
    for tag, inputs in _directions(forward):
        for s in inputs:
            dangles = [1 if s == angle else 0 for angle in X[3:]]
            tangent = Tangent(g, {s: sp.S.One, **trig_seeds(trig, dangles)}, f'{tag}{inputs.index(s)}')
            motion = ([1 if s == x else 0 for x in X[:3]],
                      list(kin.J_A[:, X.index(s) - 3]) if s in X[3:] else [0] * 3,
                      [1 if s == x else 0 for x in XD[:3]], [tangent(e) for e in omega],
                      [1 if s == x else 0 for x in XDD[:3]], [tangent(e) for e in omegad])
            d = [e for part in motion for e in part]
            columns.append([(-1 if forward else 1) * sp.Add(*[total[j][i] * d[j] for j in range(len(d)) if d[j] != 0])
                            for i in range(6)])
    blocks = [('Z' + tag[1:], [columns[6 * b + j][i] for i in range(6) for j in range(6)])
              for b, (tag, _) in enumerate(_directions(forward))]
    return variant_spec(variant, f'residual_derivatives_{"forward" if forward else "inverse"}',
                        residual_derivatives_kernel.__doc__, g,
                        [('x', X), ('xd', XD), ('xdd', XDD), ('spin', SPIN), ('Zt', Zt), ('Mlegs', Mlegs)], blocks)
