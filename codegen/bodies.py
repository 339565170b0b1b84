"""The bodies' momenta and the generalized forces they give (Lopes & Pires 2011; see
`kinematics`): the velocities and angular momenta of the platform and of each leg for a twist
(eqs. 10, 13-15, 27-29, 43-48, 55-57, 65), and sum_b J_b^T y_b for per-body vectors y_b.  The
transposed partial-velocity Jacobians of the paper (eqs. 31, 35, 57) are applied as cross
products (`generalized_force`), never formed as matrices: each leg reduces to one force f_i
at P_i, contributing [f_i; r_i x f_i].
"""

from dataclasses import dataclass

import sympy as sp

from .graph import cross, dot


@dataclass
class Momenta:
    """Momenta of all bodies for one twist [v; omega]."""
    v: sp.Matrix       # platform velocity (platform linear momentum / m_P)
    h_P: sp.Matrix     # platform angular momentum (eqs. 13-15)
    legs: list         # per leg (v_C, v_S, h_L)


def leg_momenta(g, P, leg, w, variant, tag):
    """Velocities and angular momentum of leg `tag` for the velocity w of P_i.

    omega_l = lbar x w (eq. 29, shared by cylinder and piston); cylinder COM
    velocity omega_l x (b_C u) (eq. 27); piston COM velocity w + b_S u x
    omega_l (eqs. 55-57).  Leg angular momentum h_L = (I_C + I_S) omega_l with
    the inertias in {B} of eqs. 43-48 and 65: as omega_l is normal to u = x_C,
    the axial inertia drops out, leaving I_t omega_l for axisymmetric legs
    (I_t (E - u u^T) + I_a u u^T applied to omega_l) and
    (I_yy y_C y_C^T + I_zz z_C z_C^T) omega_l in the paper's frames.

    The general model's leg turns with its universal joint: its frame is x = u,
    y = n / |n|, z = x x y with n = a_i x l, and its angular velocity
    omega = vee(Rdot R^T) = alpha' a_i + beta' y (the joint's two rates) works out to
    omega_l + q lbar with the spin q = (a_i . l)(n . w) / (n . n), so (u . omega) u = q lbar
    and h_L = I_zz omega + (I_ax - I_zz) q lbar + (I_yy - I_zz) (n . omega_l) n / (n . n)
    = I_zz omega_l + I_ax q lbar + (I_yy - I_zz) (n . omega_l) n / (n . n): no square root.  The spin does not move the centres of mass (lbar x u = 0).
    Returns (v_C, v_S, h_L).
    """
    wl = g.vector(f'{tag}wl', cross(leg.lbar, w))
    v_C = g.vector(f'{tag}vC', P.b_C * cross(wl, leg.u))
    v_S = g.vector(f'{tag}vS', w + P.b_S * cross(leg.u, wl))
    h_L = leg_angular_momentum(g, leg, w, wl, [P.I_C[k] + P.I_S[k] for k in range(3)], variant, tag)
    return v_C, v_S, h_L


def leg_angular_momentum(g, leg, w, wl, I_L, variant, tag):
    """The angular momentum h_L of leg `tag` with inertia I_L = (axial, I_yy, I_zz) in its frame
    about the leg's centres of mass (`leg_momenta`), or about its joints in the parallel-axis
    form (`regressor_kernel`), for the velocity w of P_i and omega_l = wl (see `leg_momenta`)."""
    if variant == 'axisym':
        return g.vector(f'{tag}hL', I_L[1] * wl)
    if variant == 'general':
        q = g.define(f'{tag}q', leg.al * dot(leg.n, w) * leg.in2)
        ny = g.define(f'{tag}ny', dot(leg.n, wl) * leg.in2)
        return g.vector(f'{tag}hL', I_L[2] * wl + I_L[0] * q * leg.lbar + (I_L[1] - I_L[2]) * ny * leg.n)
    a_y = g.define(f'{tag}ay', dot(leg.y_C, wl))
    a_z = g.define(f'{tag}az', dot(leg.z_C, wl))
    return g.vector(f'{tag}hL', I_L[1] * a_y * leg.y_C + I_L[2] * a_z * leg.z_C)


def platform_angular_momentum(g, P, kin, omega, tag):
    """h_P = I_P omega with I_P = R diag(I_P) R^T (eqs. 13-15), R I_P R^T with the full
    tensor I_P in {P} for the general model."""
    wb = g.vector(f'{tag}wP', kin.R.T * omega)
    if kin.I_P is not None:
        return g.vector(f'{tag}hP', kin.R * (kin.I_P * wb))
    return g.vector(f'{tag}hP', kin.R * sp.Matrix([P.I_P[k] * wb[k] for k in range(3)]))


def platform_velocity(g, kin, v, omega, tag):
    """The velocity of the platform's centre of mass: v (eq. 10), v + omega x R c for the
    general model."""
    return v if kin.rho is None else g.vector(f'{tag}vG', v + cross(omega, kin.rho))


def momenta(g, P, kin, v, omega, variant, tag):
    """Body velocities and angular momenta for the twist [v; omega].

    Platform: the velocity of its centre of mass (`platform_velocity`), I_P = R diag(I_P) R^T
    (eq. 13), h_P = I_P omega.  Leg i: see `leg_momenta` with w_i = v + omega x r_i, the
    velocity of P_i.
    """
    h_P = platform_angular_momentum(g, P, kin, omega, tag)
    legs = [leg_momenta(g, P, leg, g.vector(f'{tag}vP{i}', v + cross(omega, leg.r)),
                        variant, f'{tag}{i}')
            for i, leg in enumerate(kin.legs)]
    return Momenta(v=platform_velocity(g, kin, v, omega, tag), h_P=h_P, legs=legs)


def generalized_force(P, kin, platform, leg_forces, g, tag):
    """sum_b J_b^T y_b for per-body vectors y_b (eqs. 19, 39, 51, 61, 69).

    `platform` is the 6-vector [y_v; y_omega] of the platform, y_v paired with the velocity
    of its centre of mass (J = identity in twist coordinates, [E, -[R c]x] for the general
    model: `platform_force`); `leg_forces` holds per leg (y_C, y_S, y_L): the vectors
    paired with the cylinder COM velocity, the piston COM velocity and the leg
    angular velocity.  The transposed Jacobians of eqs. 31, 35 and 57 (with
    J_G in place of the misprinted J_B of eq. 60) act as cross products:
    J_D^T y = [z; r x z] with z = y x lbar, J_B^T y = J_D^T (b_C u x y),
    J_G^T y = [y; r x y] + J_D^T (b_S y x u).  Each leg thus reduces to one
    force f_i at P_i contributing [f_i; r_i x f_i].
    """
    W = platform_force(kin, platform)
    for i, (leg, (y_C, y_S, y_L)) in enumerate(zip(kin.legs, leg_forces)):
        f = leg_force(g, P, leg, y_C, y_S, y_L, f'{tag}{i}')
        W += sp.Matrix.vstack(f, cross(leg.r, f))
    return W


def platform_force(kin, platform):
    """J^T [y_v; y_omega] = [y_v; y_omega + R c x y_v] for the platform, whose centre of mass
    moves with v + omega x R c (the general model; J = identity for the paper's)."""
    W = sp.Matrix(platform)
    if kin.rho is not None:
        W[3:, 0] = W[3:, 0] + cross(kin.rho, W[:3, 0])
    return W


def leg_force(g, P, leg, y_C, y_S, y_L, tag):
    """Force f at P_i equivalent to (y_C, y_S, y_L): f = y_S + z with
    z = (y_L + b_C u x y_C + b_S y_S x u) x lbar (see `generalized_force`); for a leg that
    spins with its joint (`leg_momenta`), the spin's partial velocity q = (a_i . l) n^T w / (n . n)
    along lbar adds (a_i . l)(lbar . y_L) / (n . n) n."""
    return point_force(g, leg, y_S, y_L + P.b_C * cross(leg.u, y_C) + P.b_S * cross(y_S, leg.u), y_L, tag)


def point_force(g, leg, force, moment, y_L, tag, spin=True):
    """Force f at P_i equivalent to a force on the leg at P_i and a moment about its joints
    (see `leg_force`): f = force + moment x lbar, plus (a_i . l)(lbar . y_L) / (n . n) n for a
    leg that spins with its joint (y_L the rate of its angular momentum, `leg_momenta`; not
    with `spin` False)."""
    z = g.vector(f'{tag}z', cross(moment, leg.lbar))
    if leg.n is not None and spin:
        s = g.define(f'{tag}sL', leg.al * dot(leg.lbar, y_L) * leg.in2)
        return g.vector(f'{tag}f', force + z + s * leg.n)
    return g.vector(f'{tag}f', force + z)


def gravity_forces(P, gravity):
    """Per-body weights m_b g e_z (the Kane form of eqs. 72-76)."""
    ez = sp.Matrix([0, 0, P.g if gravity else 0])
    return ez * P.m_P, ez * P.m_C, ez * P.m_S


def momentum_rate_force(g, P, kin, m, gravity, tag):
    """sum_b J_b^T (d/dt momentum_b + m_b g e_z) (eqs. 19, 39, 51, 61, 69, 72-76).

    The momentum derivatives are total time derivatives by the chain rule
    (`Graph.rate`), i.e. d/dt(I_b J_b T) xd + I_b J_b T xdd for the graph's
    rates.
    """
    rate = lambda vec: vec.applyfunc(g.rate)
    w_P, w_C, w_S = gravity_forces(P, gravity)
    platform = sp.Matrix.vstack(P.m_P * rate(m.v) + w_P, rate(m.h_P))
    legs = [(P.m_C * rate(v_C) + w_C, P.m_S * rate(v_S) + w_S, rate(h_L))
            for v_C, v_S, h_L in m.legs]
    return generalized_force(P, kin, platform, legs, g, tag)


def axisymmetric_leg_force(g, P, leg, w, a, tag):
    """The force f at P_i of an axisymmetric leg of the paper's model (`leg_force` with
    `leg_momenta`'s I_t omega_l), in closed form from the leg's Lagrangian in its leg vector
    l (P_i's velocity w = l', acceleration a = w'; the leg's configuration is l alone, as it
    does not spin, eq. 29).  With s = u . w and w_p = w - s u (|w_p| = L |omega_l|), the piston's
    centre of mass moving with s u + (L - b_S) omega_l x u (eqs. 55-57), the cylinder's with
    b_C omega_l x u (eq. 27), the kinetic energy is T = 1/2 w^T K w, K = k E + (m_S - k) u u^T
    with k = J / L^2, J = I_t + m_C b_C^2 + m_S (L - b_S)^2 (I_t = I_C,yy + I_S,yy, eq. 65),
    and the potential V = g (m_C b_C + m_S (L - b_S)) u_z (eqs. 72-76).  Lagrange's equations
    f = d/dt dT/dw - dT/dl + dV/dl give
    f = K a + k_L s w_p + ((m_S - k) / L - k_L / 2) |w_p|^2 u + g m_S e_z
        + g (m_C b_C - m_S b_S) (e_z - u_z u) / L,
    k_L = dk/dL = 2 (m_S (L - b_S) - k L) / L^2; K is the leg's part of M_t
    (`dynamics.twist_mass_matrix`).  No rates by forward mode, and F_a = K."""
    u, iL2 = leg.u, g.known(leg.L2 ** -1)
    iL = g.known(leg.L * iL2)
    s = g.define(f'{tag}s', dot(u, w))
    w_p = g.vector(f'{tag}wp', w - s * u)
    J = P.I_C[1] + P.I_S[1] + P.m_C * P.b_C ** 2 + P.m_S * (leg.L - P.b_S) ** 2
    k = g.define(f'{tag}k', J * iL2)
    k_L = g.define(f'{tag}kL', 2 * (P.m_S * (leg.L - P.b_S) - k * leg.L) * iL2)
    ez = sp.Matrix([0, 0, 1])
    lift = P.g * (P.m_C * P.b_C - P.m_S * P.b_S) * iL
    along_u = g.define(f'{tag}fu', (P.m_S - k) * dot(u, a) + ((P.m_S - k) * iL - k_L / 2) * dot(w_p, w_p)
                       - lift * u[2])
    return k * a + (k_L * s) * w_p + along_u * u + (P.g * P.m_S + lift) * ez
