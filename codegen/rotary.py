"""The rotary family: 6-RSS rigs (issue 40), a motor on the base turning a crank that pushes
the platform through a rod with ball joints at both ends, derived by the generalized-momentum
method of the linear model (Lopes & Pires 2011; see `kinematics`) and sharing its platform:
the pose's kinematics (R, J_A of eq. 8, P_i = p + R p_i: `kinematics.kinematics`), the
platform's momenta and generalized force (`bodies.platform_velocity`,
`bodies.platform_angular_momentum`, `bodies.platform_force`), and the platform's block of the
mass matrix (`dynamics.twist_mass_matrix`, with no leg of its own).

Leg i (parameters `ROTARY_FIELDS`): the crank turns about the unit axis a_i through b_i; its
tip is c_i = b_i + r u_i, u_i = cos(alpha_i) h_i + sin(alpha_i) k_i, k_i = a_i x h_i; the rod
joins c_i to P_i, n_i = P_i - c_i, |n_i| = d.

Inverse kinematics, closed form (`crank_geometry`): with e = P_i - b_i, |e - r u|^2 = d^2 is
A cos(alpha) + B sin(alpha) = C, A = 2 r e.h, B = 2 r e.k, C = e.e + r^2 - d^2, so
alpha = phi - beta delta with phi = atan2(B, A), delta = acos(C / rho), rho^2 = A^2 + B^2,
beta = crank_branch[i]: then (P_i - c_i) . (a_i x (c_i - b_i)) = (B cos(alpha) - A sin(alpha)) / 2
= beta rho sin(delta) / 2 has the sign beta.  Without the angle itself:
cos(alpha) = (A C + beta B S) / rho^2, sin(alpha) = (B C - beta A S) / rho^2,
S = sqrt(rho^2 - C^2) = rho sin(delta): a pose is within crank i's reach iff S^2 > 0.

Rates: |n|^2 = d^2 gives n . (w - alpha' t) = 0 with w = v + omega x R p_i the velocity of
P_i and t = r a x u the tip's velocity per unit crank rate, so alpha' = j . w with
j = n / (n . t) and n . t = beta rho S / 2 (zero at the edge of the reach): J_alpha, in the
twist [v; omega] as the linear model's J_C, has row i = [j_i^T, (R p_i x j_i)^T]; in the pose
rates J_alpha T (eq. 18).

Bodies of a leg and their velocities, each linear in w (the generalized forces they give are
a force f_i at P_i, contributing [f_i; r_i x f_i], as the linear legs: `leg_force`):
- the crank turns about its fixed axis: alpha'; its momentum about the axis I_K alpha'
  (crank_inertia, about the motor axis, rotor included), its weight m_K g e_z at
  b_i + b_K u_i, of generalized force m_K g b_K (a x u)_z per unit rate;
- the rod's centre of mass c + s n / d moves with (1 - s/d) alpha' t + (s/d) w;
- the rod, axisymmetric, does not spin about its axis: omega_R = n x (w - alpha' t) / d^2,
  its angular momentum I_R omega_R (rod_inertia, transverse, about its centre of mass).
"""

import sympy as sp

from .bodies import platform_angular_momentum, platform_force, platform_velocity
from .dynamics import twist_mass_matrix
from .graph import Graph, KernelSpec, cross, dot, skew
from .kinematics import NUM_LEGS, TAU, X, XD, XDD, Params, accelerated_graph, kinematics, platform_inertia_tensor, twist
from .schema import ParamField

#: The rotary rig's parameters, the members of `stewart_rotary_params` in struct order (the
#: platform's under the linear schema's names and symbols, which the shared kinematics reads).
ROTARY_FIELDS = (
    ParamField('base_points', 'base', (6, 3), 'b_i in {B}, on the motor axis', symbol='b'),
    ParamField('platform_points', 'plat', (6, 3), 'p_i in {P}', symbol='pp'),
    ParamField('motor_axes', 'axes', (6, 3), 'a_i in {B}, unit', symbol='a'),
    ParamField('crank_zero', 'zero', (6, 3), 'h_i in {B}, unit, normal to a_i: the crank at alpha_i = 0',
               symbol='h'),
    ParamField('crank_branch', 'branch', (6,), '+1 or -1: the sign of (P_i - c_i) . (a_i x (c_i - b_i))',
               symbol='beta'),
    ParamField('crank_length', 'r', (), 'r, m', symbol='r_K'),
    ParamField('rod_length', 'd', (), 'd, m', symbol='d_R'),
    ParamField('platform_mass', 'm_P', ()),
    ParamField('platform_inertia', 'I_P', (3,), 'Ixx, Iyy, Izz in {P} about the centre of mass',
               source='platform_inertia_diagonal'),
    ParamField('platform_inertia_products', 'I_Pp', (3,), 'Ixy, Ixz, Iyz (tensor entries) in {P}',
               source='platform_inertia_products', field='platform_inertia'),
    ParamField('platform_com', 'c_P', (3,), 'the centre of mass in {P}', symbol='cP', source='platform_com_in_model'),
    ParamField('crank_mass', 'm_K', ()),
    ParamField('crank_com_distance', 'b_K', (), 'from the motor axis along the crank'),
    ParamField('crank_inertia', 'I_K', (), 'about the motor axis, the rotor and gearbox reflected included'),
    ParamField('rod_mass', 'm_R', ()),
    ParamField('rod_com_distance', 'b_R', (), 'from the crank end along the rod'),
    ParamField('rod_inertia', 'I_R', (), 'transverse, about the centre of mass'),
    ParamField('gravity', 'g', (), 'm/s^2 along -z'),
)

#: `RotaryParams` fields with no member in `stewart_rotary_params`, and why.
ROTARY_LEFT_OUT = {
    'crank_angle_limits': 'a workspace bound, checked in Python',
    'motor_torque_limit': 'a sizing bound, checked in Python',
    'motor_speed_limit': 'a sizing bound, checked in Python',
    'crank_joint_max_angle': 'a workspace bound, checked in Python',
    'platform_joint_max_angle': 'a workspace bound, checked in Python',
    'rod_crank_angle_limits': 'a workspace bound, checked in Python',
    'base_clearance': 'a workspace bound, checked in Python',
    'crank_pin_max_tilt': 'a workspace bound, checked in Python',
    'name': 'a label, not a model input',
}

RPARAMS = Params(ROTARY_FIELDS)


class Crank:
    """One leg's crank and rod at a pose (`crank_geometry`), all entries defined symbols."""

    def __init__(self, **entries):
        self.__dict__.update(entries)


def crank_geometry(g, P, kin, i):
    """Leg i at the pose of `kin`: the closed-form inverse kinematics (module docstring),
    u = cos(alpha) h + sin(alpha) k, the rod n = P_i - c_i, t = r a x u, and
    j = n / (n . t), alpha' = j . w."""
    leg = kin.legs[i]
    e, h, a = leg.l, P.zero[i], P.axes[i]
    k = cross(a, h)
    A = g.define(f'A_{i}', 2 * P.r * dot(e, h))
    B = g.define(f'B_{i}', 2 * P.r * dot(e, k))
    C = g.define(f'C_{i}', leg.L2 + P.r ** 2 - P.d ** 2)
    rho2 = g.define(f'rho2_{i}', A ** 2 + B ** 2)
    S2 = g.define(f'S2_{i}', rho2 - C ** 2)
    S = g.define(f'S_{i}', sp.sqrt(S2))
    irho2 = g.define(f'irho2_{i}', 1 / rho2)
    beta = P.branch[i]
    cos_a = g.define(f'ca_{i}', (A * C + beta * B * S) * irho2)
    sin_a = g.define(f'sa_{i}', (B * C - beta * A * S) * irho2)
    u = g.vector(f'uK{i}', cos_a * h + sin_a * k)
    n = g.vector(f'nR{i}', e - P.r * u)
    t = g.vector(f'tK{i}', P.r * (cos_a * k - sin_a * h))
    iD = g.define(f'iD_{i}', 1 / dot(n, t))
    j = g.vector(f'j{i}', n * iD)
    return Crank(cos=cos_a, sin=sin_a, u=u, n=n, t=t, j=j, S2=S2, rho2=rho2, r=leg.r)


def rotary_kinematics(g, P=RPARAMS):
    """The pose's kinematics (`kinematics.kinematics`, legs l_i = P_i - b_i) with the
    platform's centre of mass R c and its full tensor, and each leg's `crank_geometry`."""
    kin = kinematics(g, P)
    kin.rho = g.vector('rho', kin.R * P.c_P)
    kin.I_P = platform_inertia_tensor(P)
    return kin, [crank_geometry(g, P, kin, i) for i in range(NUM_LEGS)]


def jacobian_rows(cranks):
    """J_alpha in the twist: row i = [j_i^T, (R p_i x j_i)^T] (alpha' = J_alpha [v; omega])."""
    return sp.Matrix([list(c.j) + list(cross(c.r, c.j)) for c in cranks])


def crank_checks(cranks):
    """Outputs the C checks (`vcheck_cranks`): S_i^2 and rho_i^2 (within reach iff
    S^2 > STEWART_ROTARY_REACH_TOL rho^2)."""
    return [('S2', [c.S2 for c in cranks]), ('rho2', [c.rho2 for c in cranks])]


def leg_velocities(g, P, c, w, tag):
    """(alpha', the rod's centre-of-mass velocity, omega_R) for the velocity w of P_i."""
    ad = g.define(f'{tag}ad', dot(c.j, w))
    sigma = P.b_R / P.d
    v_R = g.vector(f'{tag}vR', (1 - sigma) * ad * c.t + sigma * w)
    w_R = g.vector(f'{tag}wR', cross(c.n, w - ad * c.t) / P.d ** 2)
    return ad, v_R, w_R


def leg_force(g, P, c, y_K, y_R, y_L, tag):
    """The force f at P_i whose power on w equals that of y_K on alpha', y_R on the rod's
    centre-of-mass velocity and y_L on omega_R (`leg_velocities`):
    f = sigma y_R + (y_L x n) / d^2 + (y_K + (1 - sigma) y_R . t - (y_L . (n x t)) / d^2) j."""
    sigma = P.b_R / P.d
    along = g.define(f'{tag}fj', y_K + (1 - sigma) * dot(y_R, c.t) - dot(y_L, cross(c.n, c.t)) / P.d ** 2)
    return g.vector(f'{tag}f', sigma * y_R + cross(y_L, c.n) / P.d ** 2 + along * c.j)


def crank_weight(P, c):
    """The crank's weight per unit crank rate: m_K g b_K (a x u)_z, (a x u) = t / r."""
    return P.m_K * P.g * P.b_K * c.t[2] / P.r


def legs_force(g, P, kin, cranks, legs):
    """sum_b J_b^T y_b of the platform's pair `legs[0]` ([y_v; y_omega]) and the legs'
    (y_K, y_R, y_L) (`leg_force`)."""
    platform, forces = legs
    W = platform_force(kin, platform)
    for i, (c, (y_K, y_R, y_L)) in enumerate(zip(cranks, forces)):
        f = leg_force(g, P, c, y_K, y_R, y_L, f'F{i}')
        W += sp.Matrix.vstack(f, cross(c.r, f))
    return W


def seed_crank_rates(g, cranks, v, omega):
    """Seed the time derivative of cos(alpha_i), sin(alpha_i) with alpha_i' = j_i . w_i
    (-sin alpha', cos alpha'), so the rates never differentiate the square root."""
    for i, c in enumerate(cranks):
        ad = g.define(f'ad_{i}', dot(c.j, v + cross(omega, c.r)))
        g.rate.seed.update({c.cos: -c.sin * ad, c.sin: c.cos * ad})


def inverse_dynamics(g, P=RPARAMS):
    """W = M xdd + V xd + G in the twist (the rates of the bodies' momenta plus their weights,
    through their transposed Jacobians), on the graph of `accelerated_graph`: (the kinematics,
    the cranks, W)."""
    kin, cranks = rotary_kinematics(g, P)
    v, omega = twist(g, kin, XD, 'q')
    seed_crank_rates(g, cranks, v, omega)
    rate = lambda vec: vec.applyfunc(g.rate)
    ez = sp.Matrix([0, 0, P.g])
    v_G = platform_velocity(g, kin, v, omega, 'q')
    h_P = platform_angular_momentum(g, P, kin, omega, 'q')
    platform = sp.Matrix.vstack(P.m_P * rate(v_G) + P.m_P * ez, rate(h_P))
    forces = []
    for i, c in enumerate(cranks):
        ad, v_R, w_R = leg_velocities(g, P, c, v + cross(omega, c.r), f'q{i}')
        forces.append((P.I_K * g.rate(ad) + crank_weight(P, c), P.m_R * rate(v_R) + P.m_R * ez, P.I_R * rate(w_R)))
    return kin, cranks, legs_force(g, P, kin, cranks, (platform, forces))


def twist_mass_matrix_of(g, P=RPARAMS):
    """M_t = sum_b J_b^T I_b J_b in the twist (symmetric): the platform's block
    (`dynamics.twist_mass_matrix` with no legs), and per leg J_P^T K_i J_P with J_P = [E, -[r_i]x]
    and K_i's column j the force at P_i of the leg's momenta for w = e_j."""
    kin, cranks = rotary_kinematics(g, P)
    platform_only = type(kin)(R=kin.R, J_A=kin.J_A, c_theta=kin.c_theta, legs=[], rho=kin.rho, I_P=kin.I_P)
    Mt = twist_mass_matrix(g, P, platform_only, None)
    for i, c in enumerate(cranks):
        K = sp.zeros(3, 3)
        for j in range(3):
            e = sp.Matrix([1 if k == j else 0 for k in range(3)])
            ad, v_R, w_R = leg_velocities(g, P, c, e, f'k{i}{j}')
            f = leg_force(g, P, c, P.I_K * ad, P.m_R * v_R, P.I_R * w_R, f'k{i}{j}')
            for k in range(j + 1):
                K[k, j] = K[j, k] = g.define(f'K{i}_{k}{j}', f[k])
        Bm = -K * skew(c.r)
        Bm = sp.Matrix(3, 3, [g.define(f'B{i}_{j}{k}', Bm[j, k]) for j in range(3) for k in range(3)])
        D = skew(c.r) * Bm
        D = sp.Matrix(3, 3, lambda j, k: g.define(f'D{i}_{min(j, k)}{max(j, k)}', D[min(j, k), max(j, k)]))
        Mt += sp.Matrix.vstack(sp.Matrix.hstack(K, Bm), sp.Matrix.hstack(Bm.T, D))
    return cranks, sp.Matrix(6, 6, lambda j, k: g.define(f'Mtr_{min(j, k)}{max(j, k)}', Mt[min(j, k), max(j, k)]))


def gravity_force(g, P=RPARAMS):
    """G = sum_b J_b^T m_b g e_z."""
    kin, cranks = rotary_kinematics(g, P)
    ez = sp.Matrix([0, 0, P.g])
    platform = sp.Matrix.vstack(P.m_P * ez, sp.zeros(3, 1))
    forces = [(crank_weight(P, c), P.m_R * ez, sp.zeros(3, 1)) for c in cranks]
    return cranks, legs_force(g, P, kin, cranks, (platform, forces))


# ---- the kernels ----

def rotary_crank_angles_kernel():
    """cos(alpha_i) then sin(alpha_i) of the six cranks, in their branches (module docstring)."""
    g = Graph({})
    _, cranks = rotary_kinematics(g)
    return KernelSpec('rotary_crank_angles', rotary_crank_angles_kernel.__doc__, g, [('x', X)],
                      [('cs', [c.cos for c in cranks] + [c.sin for c in cranks])] + crank_checks(cranks))


def rotary_jacobian_kernel():
    g = Graph({})
    _, cranks = rotary_kinematics(g)
    return KernelSpec('rotary_jacobian', 'J_alpha in the twist: alpha_dot = J_alpha [v; omega], row-major.', g,
                      [('x', X)], [('JR', list(jacobian_rows(cranks)))] + crank_checks(cranks))


def rotary_crank_rates_kernel():
    """alpha_dot = J_alpha T xd: crank i's rate j_i . (v + omega x R p_i)."""
    g = Graph({})
    kin, cranks = rotary_kinematics(g)
    v, omega = twist(g, kin, XD, 'q')
    rates = [dot(c.j, v + cross(omega, c.r)) for c in cranks]
    return KernelSpec('rotary_crank_rates', rotary_crank_rates_kernel.__doc__, g, [('x', X), ('xd', XD)],
                      [('ad', rates)] + crank_checks(cranks))


def rotary_inverse_dynamics_kernel():
    g = accelerated_graph()
    _, cranks, W = inverse_dynamics(g)
    return KernelSpec('rotary_inverse_dynamics', 'W = M xdd + V xd + G and J_alpha (to solve J_alpha^T tau = W).',
                      g, [('x', X), ('xd', XD), ('xdd', XDD)],
                      [('W', list(W)), ('JR', list(jacobian_rows(cranks)))] + crank_checks(cranks))


def rotary_twist_mass_matrix_kernel():
    g = Graph({})
    cranks, Mt = twist_mass_matrix_of(g)
    return KernelSpec('rotary_twist_mass_matrix', 'M_t = sum_b J_b^T I_b J_b, symmetric, row-major.', g,
                      [('x', X)], [('Mt', list(Mt))] + crank_checks(cranks))


def rotary_gravity_kernel():
    g = Graph({})
    cranks, G = gravity_force(g)
    return KernelSpec('rotary_gravity_vector', 'G = sum_b J_b^T m_b g e_z.', g, [('x', X)],
                      [('G', list(G))] + crank_checks(cranks))


#: The motor torques, an input of `rotary_inverse_dynamics_derivatives_kernel`.
TAU_IN = TAU


#: The inputs by which `rotary_inverse_dynamics_derivatives_kernel` differentiates.
DERIVATIVE_INPUTS = {'x': X, 'xd': XD, 'xdd': XDD}
#: The columns each of its kernels gives: three, so that each unit compiles quickly (a unit's
#: compile time grows faster than its size: one kernel of the 18 columns, 31 700 operations,
#: takes 25 s at -O3).
DERIVATIVE_COLUMNS = 3


def rotary_inverse_dynamics_derivatives_kernel(name, first):
    """Columns first .. first + 2 of the partials of the residual R = W(x, xd, xdd) - J_alpha(x)^T tau
    at fixed tau by the input `name` (x, xd or xdd; forward mode on the definitions,
    `Graph.partials`), column by column (ZT: column-major): dtau/dq = J_alpha^-T dR/dq
    (dR/dxdd = M_t T)."""
    g = accelerated_graph()
    _, cranks, W = inverse_dynamics(g)
    residual = list(W - jacobian_rows(cranks).T * sp.Matrix(TAU_IN))
    inputs = DERIVATIVE_INPUTS[name][first:first + DERIVATIVE_COLUMNS]
    rows = g.partials(residual, inputs, f'p{name}{first}')
    return KernelSpec(f'rotary_inverse_dynamics_derivatives_{name}{first}',
                      rotary_inverse_dynamics_derivatives_kernel.__doc__, g,
                      [('x', X), ('xd', XD), ('xdd', XDD), ('tau', TAU_IN)],
                      [('ZT', [row[j] for j in range(len(inputs)) for row in rows])] + crank_checks(cranks))
