"""The dynamics' kernels (Lopes & Pires 2011; see `kinematics`): the twist-space mass matrix M_t
(eqs. 19, 39, 51, 61, 69), the Coriolis product V vel, gravity G (eqs. 72-76) and the static
forces, the inverse dynamics' W = M xdd + V xd + G, the joint reactions, and the regressor,
W written linear in the inertial parameters.
"""

import sympy as sp

from .bodies import (gravity_forces, generalized_force, leg_angular_momentum, leg_force, leg_momenta, momenta,
                     momentum_rate_force, point_force)
from .graph import Graph, KernelSpec, cross, dot, skew, symbols
from .kinematics import (NUM_LEGS, PARAMS, TAU, X, XD, XDD, accelerated_graph, jacobian_rows,
                         kernel_name, kinematics, kinematics_of, leg_checks, twist, variant_spec)
from .schema import RIGID_BODY_PARAMETERS


def twist_mass_matrix(g, P, kin, variant):
    """Twist-space mass matrix M_t = sum_b J_b^T I_b J_b (symmetric).

    Platform block: blockdiag(m_P E, R diag(I_P) R^T) (eq. 13); for the general model,
    with rho = R c, [[m_P E, -m_P [rho]x], [m_P [rho]x, R I_P R^T - m_P [rho]x^2]].  Every leg
    Jacobian factors through the velocity of P_i, w_i = J_P t with
    J_P = [E, -[r_i]x] (eqs. 31, 35, 57), so leg i adds J_P^T K_i J_P with the
    symmetric 3x3 K_i whose column j is the force at P_i (`leg_force`) of the
    leg momenta for w = e_j.  Only upper triangles are derived.
    """
    if kin.rho is None:
        Mt = sp.diag(P.m_P * sp.eye(3), kin.R * sp.diag(*P.I_P) * kin.R.T)
    else:
        S = skew(kin.rho)
        Mt = sp.Matrix.vstack(sp.Matrix.hstack(P.m_P * sp.eye(3), -P.m_P * S),
                              sp.Matrix.hstack(P.m_P * S, kin.R * kin.I_P * kin.R.T - P.m_P * S * S))
    for i, leg in enumerate(kin.legs):
        K = sp.zeros(3, 3)
        for j in range(3):
            e = sp.Matrix([1 if k == j else 0 for k in range(3)])
            v_C, v_S, h_L = leg_momenta(g, P, leg, e, variant, f'k{i}{j}')
            f = leg_force(g, P, leg, P.m_C * v_C, P.m_S * v_S, h_L, f'k{i}{j}')
            for k in range(j + 1):
                K[k, j] = K[j, k] = g.define(f'K{i}_{k}{j}', f[k])
        B = -K * skew(leg.r)
        B = sp.Matrix(3, 3, [g.define(f'B{i}_{j}{k}', B[j, k]) for j in range(3) for k in range(3)])
        D = skew(leg.r) * B
        D = sp.Matrix(3, 3, lambda j, k: g.define(f'D{i}_{min(j, k)}{max(j, k)}', D[min(j, k), max(j, k)]))
        Mt += sp.Matrix.vstack(sp.Matrix.hstack(K, B), sp.Matrix.hstack(B.T, D))
    return sp.Matrix(6, 6, lambda j, k: g.define(f'Mt_{min(j, k)}{max(j, k)}', Mt[min(j, k), max(j, k)]))


def twist_mass_matrix_kernel(variant):
    g = Graph({})
    kin = kinematics_of(g, variant)
    Mt = twist_mass_matrix(g, PARAMS, kin, variant)
    return variant_spec(variant, 'twist_mass_matrix',
                      'M_t = sum_b J_b^T I_b J_b (eqs. 19, 39, 51, 61, 69), symmetric, row-major.', g,
                      [('x', X)], [('Mt', list(Mt))] + leg_checks(kin))


#: The velocity that `coriolis_product_kernel` applies V(x, xd) to.
VEL = symbols('vel', 6)


def coriolis_product_kernel(variant):
    """V(x, xd) vel = sum_b J_b^T d/dt(I_b J_b T) vel with vel held constant: V xd for
    vel = xd, column j of V for vel = e_j."""
    g = Graph({x: xd for x, xd in zip(X, XD)})
    kin = kinematics_of(g, variant)
    v, omega = twist(g, kin, VEL, 'q')
    m = momenta(g, PARAMS, kin, v, omega, variant, 'q')
    W = momentum_rate_force(g, PARAMS, kin, m, False, 'q')
    return variant_spec(variant, 'coriolis_product', coriolis_product_kernel.__doc__, g,
                         [('x', X), ('xd', XD), ('vel', VEL)], [('Vv', list(W))] + leg_checks(kin))


def gravity_force(g, P, kin):
    """G = sum_b J_b^T m_b g e_z (eqs. 72-76)."""
    w_P, w_C, w_S = gravity_forces(P, True)
    return generalized_force(P, kin, sp.Matrix.vstack(w_P, sp.zeros(3, 1)),
                             [(w_C, w_S, sp.zeros(3, 1))] * NUM_LEGS, g, 'g')


def gravity_kernel(variant):
    g = Graph({})
    kin = kinematics_of(g, variant)
    G = gravity_force(g, PARAMS, kin)
    return variant_spec(variant, 'gravity_vector', 'G = sum_b J_b^T m_b g e_z (eqs. 72-76).', g,
                      [('x', X)], [('G', list(G))] + leg_checks(kin))


def static_forces_kernel(variant):
    g = Graph({})
    kin = kinematics_of(g, variant)
    return variant_spec(variant, 'static_forces', 'W = G (eqs. 72-76) and J_C (eq. 5), to solve J_C^T tau_s = G.',
                         g, [('x', X)],
                         [('W', list(gravity_force(g, PARAMS, kin))), ('JC', list(jacobian_rows(kin)))] + leg_checks(kin))


def inverse_dynamics(g, variant):
    """W = M xdd + V xd + G (eqs. 19, 39, 51, 61, 69, 72-76) of a kernel `variant` on the graph
    `g` of `accelerated_graph`: (the kinematics, the twist [v; omega], W)."""
    kin = kinematics_of(g, variant)
    v, omega = twist(g, kin, XD, 'q')
    m = momenta(g, PARAMS, kin, v, omega, variant, 'q')
    return kin, v, omega, momentum_rate_force(g, PARAMS, kin, m, True, 'q')


def inverse_dynamics_kernel(variant):
    g = accelerated_graph()
    kin, _, _, W = inverse_dynamics(g, variant)
    return variant_spec(variant, 'inverse_dynamics',
                      'W = M xdd + V xd + G and J_C (to solve J_C^T tau = W).', g,
                      [('x', X), ('xd', XD), ('xdd', XDD)],
                      [('W', list(W)), ('JC', list(jacobian_rows(kin)))]
                      + leg_checks(kin))


#: Per leg, the inputs of `joint_forces_kernel` that do not depend on tau: the force f at P_i
#: equivalent to the leg's motion and weight (`leg_force`), and y = y_C + y_S, the rates of the
#: linear momenta of cylinder and piston plus their weights.
JOINT_LEG = symbols('jl', 6 * NUM_LEGS)


def joint_reactions_kernel(variant):
    """The inverse dynamics' W and J_C (`inverse_dynamics_kernel`), and per leg the terms of its
    joint reactions that do not depend on tau: `JOINT_LEG` [f_i (3) for the six legs, then y_i
    (3) for the six], and the moment n_B (3 per leg) its universal joint exerts on it.

    The leg's moment balance about the fixed B_i, n_B = y_L + b_C u x y_C + (L - b_S) u x y_S
    + l x f_P with f_P = tau u - f (`joint_forces_kernel`) and f from `point_force`, reduces to
    n_B = (u . y_L) u - s l x n, s the spin's term of `point_force`: for the general model's
    legs, with n . n = L^2 - (a_i . l)^2, n_B = (u . y_L) L (l - (a_i . l) a_i) / (n . n), along
    a_i x y, the direction neither joint axis turns about; for the paper's legs (eq. 29: no
    spin) n_B = (u . y_L) u, the axial moment that keeps the leg from spinning, zero for
    axisymmetric legs (their y_L = I_t d/dt omega_l is normal to u)."""
    P = PARAMS
    g = accelerated_graph()
    kin = kinematics_of(g, variant)
    v, omega = twist(g, kin, XD, 'q')
    m = momenta(g, P, kin, v, omega, variant, 'q')
    W = momentum_rate_force(g, P, kin, m, True, 'q')
    rate = lambda vec: vec.applyfunc(g.rate)
    _, w_C, w_S = gravity_forces(P, True)
    forces, momenta_rates, moments = [], [], []
    for i, (leg, (v_C, v_S, h_L)) in enumerate(zip(kin.legs, m.legs)):
        y_C, y_S, y_L = P.m_C * rate(v_C) + w_C, P.m_S * rate(v_S) + w_S, rate(h_L)
        forces += list(leg_force(g, P, leg, y_C, y_S, y_L, f'q{i}'))  # the terms of W, defined once
        momenta_rates += list(y_C + y_S)
        axial = g.define(f'q{i}uyL', dot(leg.u, y_L))
        if variant == 'axisym':
            moments += [0, 0, 0]
        elif variant == 'frames':
            moments += list(axial * leg.u)
        else:
            a = P.axes[i]
            moments += list(axial * leg.L * leg.in2 * (leg.l - leg.al * a))
    return variant_spec(variant, 'joint_reactions', joint_reactions_kernel.__doc__, g,
                         [('x', X), ('xd', XD), ('xdd', XDD)],
                         [('W', list(W)), ('JC', list(jacobian_rows(kin))), ('legf', forces + momenta_rates),
                          ('n_base', moments)] + leg_checks(kin))


def joint_forces_kernel():
    """The forces at the joints of each leg from its actuator force tau_i: on the platform at
    P_i, f_P = tau_i u_i - f_i (the leg's virtual work: f_i . dw = (tau_i u_i - f_P) . dw for
    every motion dw of P_i, as the joints at B_i do no work and the actuator does tau_i dL =
    tau_i u_i . dw), and on the leg at B_i, from the leg's Newton equation, f_B = f_P + y_i
    (`JOINT_LEG`); u_i is row i of J_C (eq. 5)."""
    JC = symbols('JC', 36)
    f_P, f_B = [], []
    for i in range(NUM_LEGS):
        for k in range(3):
            f = TAU[i] * JC[6 * i + k] - JOINT_LEG[3 * i + k]
            f_P.append(f)
            f_B.append(f + JOINT_LEG[3 * NUM_LEGS + 3 * i + k])
    return KernelSpec('joint_forces', joint_forces_kernel.__doc__, Graph({}),
                      [('tau', TAU), ('JC', JC), ('legf', JOINT_LEG)], [('f_base', f_B), ('f_platform', f_P)])


#: The rigid-body inertial parameters of the regressor (`schema.RIGID_BODY_PARAMETERS`).
RIGID_BODY = symbols('pi', len(RIGID_BODY_PARAMETERS))


def inertial_force(g, kin, v, omega, pi, spin=True):
    """W = M xdd + V xd + G (eqs. 19, 39, 51, 61, 69, 72-76) written linear in the inertial
    parameters `pi` (`schema.RIGID_BODY_PARAMETERS`), for the general model's legs (`kin` with
    joint axes): each body's Newton-Euler equations about
    a point fixed in it, with its first moments and its second moments about that point.

    Platform, about the origin of {P} (first moment h = R (m c), tensor I_O in {P}):
    F = m (a + g e_z) + d/dt(omega x h), N = d/dt(R I_O R^T omega) + h x (a + g e_z).
    Leg i, with w and a_P the velocity and acceleration of P_i and u' = omega_l x u: the
    piston's force y_S = m_S (a_P + g e_z) - (m_S b_S) u''; the moment about the joints
    M = d/dt h_L + (m_C b_C) u x g e_z + (m_S b_S)(a_P + g e_z) x u, h_L (`leg_angular_momentum`)
    with the cylinder's moments about B_i and the piston's about P_i: the parallel-axis terms
    m b^2 u x u'' = m b^2 d/dt omega_l of `leg_force` move into them.  The leg acts on the
    platform through `point_force` (with the spin's term unless `spin` is False)."""
    P = PARAMS
    rate = lambda vec: vec.applyfunc(g.rate)
    ez = sp.Matrix([0, 0, P.g])
    m, first, (xx, xy, xz, yy, yz, zz) = pi[0], sp.Matrix(pi[1:4]), pi[4:10]
    h = g.vector('yh', kin.R * first)
    wb = g.vector('ywP', kin.R.T * omega)
    h_P = g.vector('yhP', kin.R * (sp.Matrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]) * wb))
    a = rate(v) + ez
    W = sp.Matrix.vstack(m * a + rate(cross(omega, h)), rate(h_P) + cross(h, a))
    cylinder, piston = pi[10:15], pi[15:20]
    I_L = [cylinder[k] + piston[k] for k in range(2, 5)]
    for i, leg in enumerate(kin.legs):
        tag = f'y{i}'
        w = g.vector(f'{tag}vP', v + cross(omega, leg.r))
        wl = g.vector(f'{tag}wl', cross(leg.lbar, w))
        ud = g.vector(f'{tag}ud', cross(wl, leg.u))
        y_L = rate(leg_angular_momentum(g, leg, w, wl, I_L, 'general', tag))
        a_P = rate(w) + ez
        force = piston[0] * a_P - piston[1] * rate(ud)
        moment = y_L + cylinder[1] * cross(leg.u, ez) + piston[1] * cross(a_P, leg.u)
        f = point_force(g, leg, force, moment, y_L, tag, spin)
        W += sp.Matrix.vstack(f, cross(leg.r, f))
    return W


#: The regressor's kernel variants: the paper's legs that do not spin (eq. 29), or legs that
#: turn with their joints (`leg_momenta`).
REGRESSOR_VARIANTS = {'paper': '!legs_spin(p)', 'general': None}


def regressor_kernel(variant):
    """The regressor before its solve: Y (6 x 32, row-major) holds in its first 20 columns
    dW/dpi of `inertial_force`, which is linear in pi, by forward mode along each parameter
    (J_C^T times the regressor's columns: solved in place with J_C, eq. 5), then per leg i the
    friction columns, the rate Ld_i = u_i . w_i at 20 + i and its smooth sign tanh(Ld_i / v_c)
    at 26 + i (the friction law of codegen/templates/vector.c).
    The paper's legs, which do not spin, are the general model's with a_i = z, no axial
    moment and no spin: the leg frame y = z x l / |z x l| is that of eqs. 44-47, and
    |z x l|^2 = l_x^2 + l_y^2 is checked as the frame's h2."""
    paper = variant == 'paper'
    g = accelerated_graph()
    kin = kinematics(g, PARAMS, general=True, axes=[sp.Matrix([0, 0, 1])] * NUM_LEGS if paper else None)
    v, omega = twist(g, kin, XD, 'q')
    pi = [sp.S.Zero if paper and name in ('cylinder.Ixx', 'piston.Ixx') else symbol  # they never act
          for symbol, (name, _) in zip(RIGID_BODY, RIGID_BODY_PARAMETERS)]
    WY = g.partials(list(inertial_force(g, kin, v, omega, pi, spin=not paper)), RIGID_BODY, 'Y')
    rates = [g.define(f'Ld_{i}', dot(leg.u, g.vector(f'y{i}vP', v + cross(omega, leg.r))))
             for i, leg in enumerate(kin.legs)]
    signs = [sp.tanh(rate / PARAMS.v_c) for rate in rates]  # vector.c's vcoulomb_sign: vtanh(Ld_i (1 / v_c))
    Y = [row + [rates[i] if j == i else 0 for j in range(NUM_LEGS)] + [signs[i] if j == i else 0 for j in range(NUM_LEGS)]
         for i, row in enumerate(WY)]
    checks = [('L2', [leg.L2 for leg in kin.legs]), ('h2' if paper else 'n2', [leg.n2 for leg in kin.legs])]
    return KernelSpec(kernel_name('regressor', variant), regressor_kernel.__doc__, g, [('x', X), ('xd', XD), ('xdd', XDD)],
                      [('Y', [e for row in Y for e in row]), ('JC', list(jacobian_rows(kin)))] + checks,
                      when=REGRESSOR_VARIANTS[variant])
