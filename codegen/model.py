"""Symbolic derivation of the Stewart platform dynamics.

Generalized-momentum model of Lopes & Pires (2011), "Complete Dynamic Modeling
of a Stewart Platform Using the Generalized Momentum Approach" (equation
numbers below refer to that paper).  Every geometry
and inertia parameter is a symbol, so one set of kernels serves every platform.

The same derivation gives two kernel families (`VARIANTS`, `MODELS`): the paper's model
(legs that do not spin, eq. 29; the centre of mass at {P}'s origin, a diagonal tensor), and
the general model of a built machine, whose legs turn with their universal joints (leg
frame x = u_i, y = a_i x u_i / |a_i x u_i|, z = x x y, angular velocity vee(Rdot R^T),
`leg_momenta`) and whose platform has its centre of mass at c in {P} and a full tensor.

Performance rests on three rules:

* every intermediate quantity (rotation matrix entries, leg vectors, unit
  vectors, velocities, momenta, ...) gets its own symbol through `Graph.define`,
  so no expression is ever expanded;
* time derivatives, and the partials of the derivative functions, are taken by
  the chain rule on those definitions (`Tangent`, symbolic forward mode along a
  seed: `Graph.rate` along time, `Graph.partials` along inputs), never on
  expanded expressions and never by finite differences;
* the transposed partial-velocity Jacobians of the paper (eqs. 31, 35, 57) are
  applied as cross products (`generalized_force`), never formed as matrices;
* the partials of the dynamics go through each leg's local Jacobian: a leg
  depends on the platform only through its leg vector and the velocity and
  acceleration of P_i (`leg_derivatives_kernel`, `residual_derivatives_kernel`).
"""

import math
from dataclasses import dataclass
from functools import partial, reduce

import sympy as sp

from . import linsolve
from .schema import FRICTION_PARAMETERS, PARAM_FIELDS, RIGID_BODY_PARAMETERS

NUM_LEGS = 6
AXES = 'xyz'


def _symbols(prefix, n):
    return [sp.Symbol(f'{prefix}_{k}', real=True) for k in range(n)]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _skew(a):
    """[a]x: _skew(a) * b == a x b."""
    return sp.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def _cross(a, b):
    return sp.Matrix([a[1] * b[2] - a[2] * b[1],
                      a[2] * b[0] - a[0] * b[2],
                      a[0] * b[1] - a[1] * b[0]])


X = _symbols('x', 6)      # pose [px, py, pz, psi, theta, phi]
XD = _symbols('xd', 6)    # pose rates
XDD = _symbols('xdd', 6)  # pose accelerations
TAU = _symbols('tau', 6)  # actuator forces


def _column(prefix, n):
    """n symbols as a column, suffixed _x, _y, _z (n = 3) or _0, _1, ..."""
    return sp.Matrix([sp.Symbol(f'{prefix}_{c}', real=True) for c in (AXES if n == 3 else range(n))])


def _field_symbols(field):
    """The symbols of a `schema.ParamField`: a symbol, a column, or a tuple of row columns."""
    prefix = field.symbol or field.attr
    if not field.shape:
        return sp.Symbol(prefix, real=True)
    if len(field.shape) == 1:
        return _column(prefix, field.shape[0])
    return tuple(_column(f'{prefix}{i}', field.shape[1]) for i in range(field.shape[0]))


class Params:
    """Runtime parameter symbols, one attribute per field of the parameter schema
    (`schema.ParamField.attr`): `base` and `plat` (b_i in {B}, p_i in {P}, tuples of
    3x1 matrices), masses `m_P`, `m_C`, `m_S`, principal inertias `I_P` (in {P}),
    `I_C`, `I_S` (axial, Iyy, Izz in {C_i} = {S_i}), distances `b_C`, `b_S`, gravity `g`.
    """

    def __init__(self, fields=PARAM_FIELDS):
        self.fields = tuple(fields)
        for field in self.fields:
            setattr(self, field.attr, _field_symbols(field))

    def members(self):
        """(symbol, `stewart_params` member entry) pairs, in struct order."""
        return [(reduce(lambda value, i: value[i], index, getattr(self, field.attr)), field.member(index))
                for field in self.fields for index in field.indices()]


PARAMS = Params()


class Tangent:
    """Symbolic forward-mode derivative of a graph's expressions along one direction.

    `seed` maps independent inputs to their derivatives along the direction (x -> xd for
    the time derivative, x_k -> 1 for the partial along x_k); every other symbol the
    graph does not define is constant.  The derivative of each defined symbol is taken by
    the chain rule on its definition, defined in the graph as `<symbol>_<tag>` (zeros
    are not defined), and cached, so no expression is ever expanded.
    """

    def __init__(self, graph, seed, tag):
        self.graph = graph
        self.seed = dict(seed)
        self.tag = tag
        self._cache = {}

    def __call__(self, expr):
        """Derivative of `expr` along the direction."""
        expr = sp.sympify(expr)
        if expr.is_Symbol:
            return self._symbol(expr)
        if expr.is_Number:
            return sp.S.Zero
        if expr.is_Add:
            return sp.Add(*[d for d in map(self, expr.args) if d is not sp.S.Zero])
        if expr.is_Mul:
            args = expr.args
            terms = [(k, self(a)) for k, a in enumerate(args)]
            return sp.Add(*[sp.Mul(*args[:k], d, *args[k + 1:]) for k, d in terms if d is not sp.S.Zero])
        if expr.is_Pow and expr.exp.is_Number:
            d = self(expr.base)
            return sp.S.Zero if d is sp.S.Zero else expr.exp * expr.base ** (expr.exp - 1) * d
        known = self.graph.known
        if isinstance(expr, (sp.sin, sp.cos)):
            d = self(expr.args[0])
            if d is sp.S.Zero:
                return d
            if isinstance(expr, sp.sin):
                return known(sp.cos(expr.args[0])) * d
            return -known(sp.sin(expr.args[0])) * d
        raise TypeError(f'no derivative rule for {expr.func}')

    def _symbol(self, s):
        if s in self.seed:
            return self.seed[s]
        definition = self.graph.definition(s)
        if definition is None:
            return sp.S.Zero
        if s not in self._cache:
            if definition.is_Pow and definition.exp.is_Number:
                # d(b^k) = k b^k b^-1 db reuses s = b^k (no second root)
                d = self(definition.base)
                d = d if d is sp.S.Zero else definition.exp * s / definition.base * d
            else:
                d = self(definition)
            self._cache[s] = self.graph.define(f'{s.name}_{self.tag}', d)
        return self._cache[s]


class Graph:
    """Ordered symbol definitions with symbolic forward-mode derivatives (`Tangent`).

    `rates` maps the independent inputs to their time derivatives (x -> xd,
    optionally xd -> xdd); every other free symbol is a constant parameter.
    Identical expressions are defined once.
    """

    def __init__(self, rates):
        self.rates = dict(rates)
        self.defs = []
        self._expr = {}
        self._by_expr = {}
        self.rate = Tangent(self, self.rates, 'd')
        """Total time derivative of an expression (forward mode along the rates)."""

    def define(self, name, expr):
        """Name `expr` (returned as is when it is already a number or symbol)."""
        expr = sp.sympify(expr)
        if expr.is_Atom:
            return expr
        if expr in self._by_expr:
            return self._by_expr[expr]
        sym = sp.Symbol(name, real=True)
        if sym in self._expr:
            raise ValueError(f'symbol {name} defined twice')
        self._expr[sym] = expr
        self._by_expr[expr] = sym
        self.defs.append((sym, expr))
        return sym

    def definition(self, sym):
        """The expression `sym` was defined as, or None for an input or parameter."""
        return self._expr.get(sym)

    def known(self, expr):
        """The symbol defined as `expr`, or `expr` itself."""
        return self._by_expr.get(expr, expr)

    def vector(self, name, exprs):
        return sp.Matrix([self.define(f'{name}_{c}', e) for c, e in zip(AXES, exprs)])

    def partials(self, exprs, inputs, tag):
        """Rows d exprs_i / d inputs_j (lists), one `Tangent` per input."""
        columns = [[Tangent(self, {s: sp.S.One}, f'{tag}{j}')(e) for e in exprs]
                   for j, s in enumerate(inputs)]
        return [list(row) for row in zip(*columns)]


@dataclass
class Leg:
    """Per-leg kinematics (eqs. 26, 32), all entries defined symbols."""
    r: sp.Matrix       # R p_i
    l: sp.Matrix       # leg vector (eq. 26)
    L2: sp.Symbol      # l . l
    L: sp.Symbol
    u: sp.Matrix       # unit vector l / L
    lbar: sp.Matrix    # l / (l . l) (eq. 32)
    h2: sp.Symbol = None   # l_x^2 + l_y^2 (frame {C_i} exists iff > 0)
    y_C: sp.Matrix = None  # {C_i} axes (eqs. 43-48); x_C = u
    z_C: sp.Matrix = None
    n: sp.Matrix = None    # exact legs: a_i x l, along the joint's second axis y = n / |n|
    n2: sp.Symbol = None   # n . n (the joint is out of gimbal lock iff > 0)
    in2: sp.Symbol = None  # 1 / (n . n)
    al: sp.Symbol = None   # a_i . l


@dataclass
class Kinematics:
    R: sp.Matrix       # ZYX Euler rotation {P} -> {B}
    J_A: sp.Matrix     # Euler rates -> angular velocity (eq. 8)
    c_theta: sp.Symbol
    legs: list
    rho: sp.Matrix = None   # general model: R c, the platform's centre of mass from its origin
    I_P: sp.Matrix = None   # general model: the platform's inertia tensor in {P} about its centre of mass


def leg_geometry(g, l, r, tag, leg_frames, lengths=None, axis=None):
    """The geometry of a leg from its leg vector l (eq. 26): length, unit vector, l / (l . l)
    (eq. 32) and, with `leg_frames`, the {C_i} axes (eqs. 43-48); `r` = R p_i.  `lengths`,
    when given, are symbols for |l| and sqrt(l_x^2 + l_y^2) (no square root here).  With the
    first axis a_i of its universal joint (`axis`, general model): n = a_i x l, n . n and
    a_i . l, from which the leg frame x = u, y = n / |n|, z = x x y follows (`leg_momenta`)."""
    L2 = g.define(f'L2_{tag}', _dot(l, l))
    iL2 = g.define(f'iL2_{tag}', 1 / L2)
    L = lengths[0] if lengths else g.define(f'L_{tag}', sp.sqrt(L2))
    iL = g.define(f'iL_{tag}', L * iL2)
    leg = Leg(r=r, l=l, L2=L2, L=L, u=g.vector(f'u{tag}', l * iL), lbar=g.vector(f'lb{tag}', l * iL2))
    if leg_frames:
        leg.h2 = g.define(f'h2_{tag}', l[0] ** 2 + l[1] ** 2)
        ih = g.define(f'ih_{tag}', 1 / (lengths[1] if lengths else g.define(f'h_{tag}', sp.sqrt(leg.h2))))
        leg.y_C = g.vector(f'yC{tag}', [-l[1] * ih, l[0] * ih, 0])
        leg.z_C = g.vector(f'zC{tag}', _cross(leg.u, leg.y_C))
    if axis is not None:
        leg.n = g.vector(f'n{tag}', _cross(axis, l))
        leg.n2 = g.define(f'n2_{tag}', _dot(leg.n, leg.n))
        leg.in2 = g.define(f'in2_{tag}', 1 / leg.n2)
        leg.al = g.define(f'al_{tag}', _dot(axis, l))
    return leg


def kinematics(g, P, leg_frames=False, general=False, axes=None):
    """Pose-dependent geometry: R, J_A (eq. 8), legs (eqs. 26, 32, 43-48); for the `general`
    model also the joints' axes (`leg_geometry`: the parameters' a_i, or `axes`), the
    platform's centre of mass R c and its full inertia tensor."""
    psi, theta, phi = X[3:]
    cps, sps = g.define('c_psi', sp.cos(psi)), g.define('s_psi', sp.sin(psi))
    cth, sth = g.define('c_theta', sp.cos(theta)), g.define('s_theta', sp.sin(theta))
    cph, sph = g.define('c_phi', sp.cos(phi)), g.define('s_phi', sp.sin(phi))
    Rz = sp.Matrix([[cps, -sps, 0], [sps, cps, 0], [0, 0, 1]])
    Ry = sp.Matrix([[cth, 0, sth], [0, 1, 0], [-sth, 0, cth]])
    Rx = sp.Matrix([[1, 0, 0], [0, cph, -sph], [0, sph, cph]])
    R = Rz * Ry * Rx
    R = sp.Matrix(3, 3, [g.define(f'R_{j}{k}', R[j, k]) for j in range(3) for k in range(3)])
    J_A = sp.Matrix([[0, -sps, R[0, 0]], [0, cps, R[1, 0]], [1, 0, R[2, 0]]])
    p = sp.Matrix(X[:3])
    legs = []
    for i in range(NUM_LEGS):
        r = g.vector(f'r{i}', R * P.plat[i])
        legs.append(leg_geometry(g, g.vector(f'l{i}', p + r - P.base[i]), r, i, leg_frames,
                                 axis=(axes or P.axes)[i] if general else None))
    kin = Kinematics(R=R, J_A=J_A, c_theta=cth, legs=legs)
    if general:
        kin.rho = g.vector('rho', R * P.c_P)
        kin.I_P = platform_inertia_tensor(P)
    return kin


def platform_inertia_tensor(P):
    """The platform's inertia tensor in {P} about its centre of mass, from its diagonal I_P and
    its products I_Pp = (I_xy, I_xz, I_yz)."""
    (xx, yy, zz), (xy, xz, yz) = P.I_P, P.I_Pp
    return sp.Matrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def kinematics_of(g, variant):
    """`kinematics` for a kernel `variant`: 'axisym' (the paper's model, axisymmetric legs),
    'frames' (the paper's model, legs with I_yy != I_zz in the frames of eqs. 43-48) or
    'general' (legs that turn with their universal joints, payload off-centre)."""
    return kinematics(g, PARAMS, leg_frames=variant == 'frames', general=variant == 'general')


@dataclass
class Momenta:
    """Momenta of all bodies for one twist [v; omega]."""
    v: sp.Matrix       # platform velocity (platform linear momentum / m_P)
    h_P: sp.Matrix     # platform angular momentum (eqs. 13-15)
    legs: list         # per leg (v_C, v_S, h_L)


def twist(g, kin, qd, tag):
    """Twist t = T qd = [v; J_A * euler rates] (eq. 18)."""
    v = sp.Matrix(qd[:3])
    omega = g.vector(f'{tag}w', kin.J_A * sp.Matrix(qd[3:]))
    return v, omega


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
    wl = g.vector(f'{tag}wl', _cross(leg.lbar, w))
    v_C = g.vector(f'{tag}vC', P.b_C * _cross(wl, leg.u))
    v_S = g.vector(f'{tag}vS', w + P.b_S * _cross(leg.u, wl))
    h_L = leg_angular_momentum(g, leg, w, wl, [P.I_C[k] + P.I_S[k] for k in range(3)], variant, tag)
    return v_C, v_S, h_L


def leg_angular_momentum(g, leg, w, wl, I_L, variant, tag):
    """The angular momentum h_L of leg `tag` with inertia I_L = (axial, I_yy, I_zz) in its frame
    about the leg's centres of mass (`leg_momenta`), or about its joints in the parallel-axis
    form (`regressor_kernel`), for the velocity w of P_i and omega_l = wl (see `leg_momenta`)."""
    if variant == 'axisym':
        return g.vector(f'{tag}hL', I_L[1] * wl)
    if variant == 'general':
        q = g.define(f'{tag}q', leg.al * _dot(leg.n, w) * leg.in2)
        ny = g.define(f'{tag}ny', _dot(leg.n, wl) * leg.in2)
        return g.vector(f'{tag}hL', I_L[2] * wl + I_L[0] * q * leg.lbar + (I_L[1] - I_L[2]) * ny * leg.n)
    a_y = g.define(f'{tag}ay', _dot(leg.y_C, wl))
    a_z = g.define(f'{tag}az', _dot(leg.z_C, wl))
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
    return v if kin.rho is None else g.vector(f'{tag}vG', v + _cross(omega, kin.rho))


def momenta(g, P, kin, v, omega, variant, tag):
    """Body velocities and angular momenta for the twist [v; omega].

    Platform: the velocity of its centre of mass (`platform_velocity`), I_P = R diag(I_P) R^T
    (eq. 13), h_P = I_P omega.  Leg i: see `leg_momenta` with w_i = v + omega x r_i, the
    velocity of P_i.
    """
    h_P = platform_angular_momentum(g, P, kin, omega, tag)
    legs = [leg_momenta(g, P, leg, g.vector(f'{tag}vP{i}', v + _cross(omega, leg.r)),
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
        W += sp.Matrix.vstack(f, _cross(leg.r, f))
    return W


def platform_force(kin, platform):
    """J^T [y_v; y_omega] = [y_v; y_omega + R c x y_v] for the platform, whose centre of mass
    moves with v + omega x R c (the general model; J = identity for the paper's)."""
    W = sp.Matrix(platform)
    if kin.rho is not None:
        W[3:, 0] = W[3:, 0] + _cross(kin.rho, W[:3, 0])
    return W


def leg_force(g, P, leg, y_C, y_S, y_L, tag):
    """Force f at P_i equivalent to (y_C, y_S, y_L): f = y_S + z with
    z = (y_L + b_C u x y_C + b_S y_S x u) x lbar (see `generalized_force`); for a leg that
    spins with its joint (`leg_momenta`), the spin's partial velocity q = (a_i . l) n^T w / (n . n)
    along lbar adds (a_i . l)(lbar . y_L) / (n . n) n."""
    return point_force(g, leg, y_S, y_L + P.b_C * _cross(leg.u, y_C) + P.b_S * _cross(y_S, leg.u), y_L, tag)


def point_force(g, leg, force, moment, y_L, tag, spin=True):
    """Force f at P_i equivalent to a force on the leg at P_i and a moment about its joints
    (see `leg_force`): f = force + moment x lbar, plus (a_i . l)(lbar . y_L) / (n . n) n for a
    leg that spins with its joint (y_L the rate of its angular momentum, `leg_momenta`; not
    with `spin` False)."""
    z = g.vector(f'{tag}z', _cross(moment, leg.lbar))
    if leg.n is not None and spin:
        s = g.define(f'{tag}sL', leg.al * _dot(leg.lbar, y_L) * leg.in2)
        return g.vector(f'{tag}f', force + z + s * leg.n)
    return g.vector(f'{tag}f', force + z)


def _gravity_forces(P, gravity):
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
    w_P, w_C, w_S = _gravity_forces(P, gravity)
    platform = sp.Matrix.vstack(P.m_P * rate(m.v) + w_P, rate(m.h_P))
    legs = [(P.m_C * rate(v_C) + w_C, P.m_S * rate(v_S) + w_S, rate(h_L))
            for v_C, v_S, h_L in m.legs]
    return generalized_force(P, kin, platform, legs, g, tag)


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
        S = _skew(kin.rho)
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
        B = -K * _skew(leg.r)
        B = sp.Matrix(3, 3, [g.define(f'B{i}_{j}{k}', B[j, k]) for j in range(3) for k in range(3)])
        D = _skew(leg.r) * B
        D = sp.Matrix(3, 3, lambda j, k: g.define(f'D{i}_{min(j, k)}{max(j, k)}', D[min(j, k), max(j, k)]))
        Mt += sp.Matrix.vstack(sp.Matrix.hstack(K, B), sp.Matrix.hstack(B.T, D))
    return sp.Matrix(6, 6, lambda j, k: g.define(f'Mt_{min(j, k)}{max(j, k)}', Mt[min(j, k), max(j, k)]))


def euler_map(kin):
    """T = blockdiag(E, J_A) (eq. 18): twist = T xd."""
    return sp.diag(sp.eye(3), kin.J_A)


def jacobian_rows(kin):
    """J_C (eq. 5): row i = [u_i^T, (r_i x u_i)^T]."""
    return sp.Matrix([list(leg.u) + list(_cross(leg.r, leg.u)) for leg in kin.legs])


@dataclass
class KernelSpec:
    """One straight-line C function: named input arrays -> named output arrays.  With
    `lanes` > 1 it runs on that many independent sets of inputs at once (a loop the
    compiler vectorizes), entry k of set i at index k * lanes + i of every array."""
    name: str
    doc: str
    graph: Graph
    inputs: list     # [(C array name, [symbols])]
    outputs: list    # [(C array name, [expressions])]
    lanes: int = 1
    shared: tuple = ()  # with lanes > 1: the inputs every lane reads whole
    when: str = None    # of a kernel with variants: the C test under which it runs (None: otherwise)


def _leg_checks(kin):
    """Outputs the C code checks: L_i^2, for the {C_i} frame l_x^2 + l_y^2, for the general
    model's joints |a_i x l_i|^2."""
    out = [('L2', [leg.L2 for leg in kin.legs])]
    if kin.legs[0].h2 is not None:
        out.append(('h2', [leg.h2 for leg in kin.legs]))
    if kin.legs[0].n2 is not None:
        out.append(('n2', [leg.n2 for leg in kin.legs]))
    return out


def leg_lengths_kernel():
    g = Graph({})
    kin = kinematics(g, PARAMS)
    return KernelSpec('leg_lengths', 'Leg lengths L_i = |l_i| (eq. 26).', g,
                      [('x', X)], [('L', [leg.L for leg in kin.legs])])


def jacobian_kernel():
    g = Graph({})
    kin = kinematics(g, PARAMS)
    return KernelSpec('jacobian', 'J_C (eq. 5), row-major.', g, [('x', X)],
                      [('JC', list(jacobian_rows(kin)))] + _leg_checks(kin))


def leg_rates_kernel():
    """L_i = |l_i| (eq. 26) and Ldot = J_C T xd (eqs. 5, 8, 18): row i of J_C applied to
    the twist, u_i . v + (r_i x u_i) . omega."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    v, omega = twist(g, kin, XD, 'q')
    Ld = jacobian_rows(kin) * sp.Matrix.vstack(v, omega)
    return KernelSpec('leg_rates', leg_rates_kernel.__doc__, g, [('x', X), ('xd', XD)],
                      [('LLd', [leg.L for leg in kin.legs] + list(Ld))] + _leg_checks(kin))


def leg_accelerations_kernel():
    """Lddot_i, the time derivative of Ldot_i = u_i . w_i (eqs. 4, 26) with w_i = v + omega x
    r_i the velocity of P_i (eq. 27), by forward mode along x' = xd, xd' = xdd."""
    g = _accelerated_graph()
    kin = kinematics(g, PARAMS)
    v, omega = twist(g, kin, XD, 'q')
    rates = [g.define(f'Ld{i}', _dot(leg.u, v + _cross(omega, leg.r))) for i, leg in enumerate(kin.legs)]
    return KernelSpec('leg_accelerations', leg_accelerations_kernel.__doc__, g, [('x', X), ('xd', XD), ('xdd', XDD)],
                      [('Ldd', [g.rate(Ld) for Ld in rates])] + _leg_checks(kin))


def gravity_force(g, P, kin):
    """G = sum_b J_b^T m_b g e_z (eqs. 72-76)."""
    w_P, w_C, w_S = _gravity_forces(P, True)
    return generalized_force(P, kin, sp.Matrix.vstack(w_P, sp.zeros(3, 1)),
                             [(w_C, w_S, sp.zeros(3, 1))] * NUM_LEGS, g, 'g')


def gravity_kernel(variant):
    g = Graph({})
    kin = kinematics_of(g, variant)
    G = gravity_force(g, PARAMS, kin)
    return _variant_spec(variant, 'gravity_vector', 'G = sum_b J_b^T m_b g e_z (eqs. 72-76).', g,
                      [('x', X)], [('G', list(G))] + _leg_checks(kin))


def static_forces_kernel(variant):
    g = Graph({})
    kin = kinematics_of(g, variant)
    return _variant_spec(variant, 'static_forces', 'W = G (eqs. 72-76) and J_C (eq. 5), to solve J_C^T tau_s = G.',
                         g, [('x', X)],
                         [('W', list(gravity_force(g, PARAMS, kin))), ('JC', list(jacobian_rows(kin)))] + _leg_checks(kin))


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
    w_P, w_C, w_S = _gravity_forces(P, True)
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
            column[3:, 0] = _cross(g.vector(f'sdrho{j}', _cross(turn, kin.rho)), w_P)
        for i, (leg, f, F) in enumerate(legs):
            dr = g.vector(f'sdr{i}_{j}', _cross(turn, leg.r)) if turn is not None else sp.zeros(3, 1)
            df = g.vector(f'sdf{i}_{j}', F[:, j] if turn is None else F * dr)
            column += sp.Matrix.vstack(df, _cross(leg.r, df) + _cross(dr, f))
        columns.append(column)
    return _variant_spec(variant, 'static_derivatives', static_derivatives_kernel.__doc__, g,
                         [('x', X), ('tau', TAU)], [('Z', [columns[j][i] for i in range(6) for j in range(6)])])


def euler_maps_kernel():
    """J_A (eq. 8), J_A^-1 and cos(theta), by which J_A^-1 divides: T = blockdiag(E, J_A)
    (eq. 18) maps the pose rates to the twist."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    return KernelSpec('euler_maps', euler_maps_kernel.__doc__ + ' Row-major.', g, [('x', X)],
                      [('JA', list(kin.J_A)), ('JAinv', list(euler_rates_inverse(kin))), ('ctheta', [kin.c_theta])])


def twist_mass_matrix_kernel(variant):
    g = Graph({})
    kin = kinematics_of(g, variant)
    Mt = twist_mass_matrix(g, PARAMS, kin, variant)
    return _variant_spec(variant, 'twist_mass_matrix',
                      'M_t = sum_b J_b^T I_b J_b (eqs. 19, 39, 51, 61, 69), symmetric, row-major.', g,
                      [('x', X)], [('Mt', list(Mt))] + _leg_checks(kin))


#: The velocity that `coriolis_product_kernel` applies V(x, xd) to.
VEL = _symbols('vel', 6)


def coriolis_product_kernel(variant):
    """V(x, xd) vel = sum_b J_b^T d/dt(I_b J_b T) vel with vel held constant: V xd for
    vel = xd, column j of V for vel = e_j."""
    g = Graph({x: xd for x, xd in zip(X, XD)})
    kin = kinematics_of(g, variant)
    v, omega = twist(g, kin, VEL, 'q')
    m = momenta(g, PARAMS, kin, v, omega, variant, 'q')
    W = momentum_rate_force(g, PARAMS, kin, m, False, 'q')
    return _variant_spec(variant, 'coriolis_product', coriolis_product_kernel.__doc__, g,
                         [('x', X), ('xd', XD), ('vel', VEL)], [('Vv', list(W))] + _leg_checks(kin))


def inverse_dynamics_kernel(variant):
    g = Graph({**{x: xd for x, xd in zip(X, XD)}, **{xd: xdd for xd, xdd in zip(XD, XDD)}})
    kin = kinematics_of(g, variant)
    v, omega = twist(g, kin, XD, 'q')
    m = momenta(g, PARAMS, kin, v, omega, variant, 'q')
    W = momentum_rate_force(g, PARAMS, kin, m, True, 'q')
    return _variant_spec(variant, 'inverse_dynamics',
                      'W = M xdd + V xd + G and J_C (to solve J_C^T tau = W).', g,
                      [('x', X), ('xd', XD), ('xdd', XDD)],
                      [('W', list(W)), ('JC', list(jacobian_rows(kin)))]
                      + _leg_checks(kin))


#: Per leg, the inputs of `joint_forces_kernel` that do not depend on tau: the force f at P_i
#: equivalent to the leg's motion and weight (`leg_force`), and y = y_C + y_S, the rates of the
#: linear momenta of cylinder and piston plus their weights.
JOINT_LEG = _symbols('jl', 6 * NUM_LEGS)


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
    g = _accelerated_graph()
    kin = kinematics_of(g, variant)
    v, omega = twist(g, kin, XD, 'q')
    m = momenta(g, P, kin, v, omega, variant, 'q')
    W = momentum_rate_force(g, P, kin, m, True, 'q')
    rate = lambda vec: vec.applyfunc(g.rate)
    _, w_C, w_S = _gravity_forces(P, True)
    forces, momenta_rates, moments = [], [], []
    for i, (leg, (v_C, v_S, h_L)) in enumerate(zip(kin.legs, m.legs)):
        y_C, y_S, y_L = P.m_C * rate(v_C) + w_C, P.m_S * rate(v_S) + w_S, rate(h_L)
        forces += list(leg_force(g, P, leg, y_C, y_S, y_L, f'q{i}'))  # the terms of W, defined once
        momenta_rates += list(y_C + y_S)
        axial = g.define(f'q{i}uyL', _dot(leg.u, y_L))
        if variant == 'axisym':
            moments += [0, 0, 0]
        elif variant == 'frames':
            moments += list(axial * leg.u)
        else:
            a = P.axes[i]
            moments += list(axial * leg.L * leg.in2 * (leg.l - leg.al * a))
    return _variant_spec(variant, 'joint_reactions', joint_reactions_kernel.__doc__, g,
                         [('x', X), ('xd', XD), ('xdd', XDD)],
                         [('W', list(W)), ('JC', list(jacobian_rows(kin))), ('legf', forces + momenta_rates),
                          ('n_base', moments)] + _leg_checks(kin))


def joint_forces_kernel():
    """The forces at the joints of each leg from its actuator force tau_i: on the platform at
    P_i, f_P = tau_i u_i - f_i (the leg's virtual work: f_i . dw = (tau_i u_i - f_P) . dw for
    every motion dw of P_i, as the joints at B_i do no work and the actuator does tau_i dL =
    tau_i u_i . dw), and on the leg at B_i, from the leg's Newton equation, f_B = f_P + y_i
    (`JOINT_LEG`); u_i is row i of J_C (eq. 5)."""
    JC = _symbols('JC', 36)
    f_P, f_B = [], []
    for i in range(NUM_LEGS):
        for k in range(3):
            f = TAU[i] * JC[6 * i + k] - JOINT_LEG[3 * i + k]
            f_P.append(f)
            f_B.append(f + JOINT_LEG[3 * NUM_LEGS + 3 * i + k])
    return KernelSpec('joint_forces', joint_forces_kernel.__doc__, Graph({}),
                      [('tau', TAU), ('JC', JC), ('legf', JOINT_LEG)], [('f_base', f_B), ('f_platform', f_P)])


#: Inputs of the per-leg kernel: the leg vector l, the velocity w and the acceleration a of
#: P_i (l' = w, w' = a, as b_i is fixed), |l| and sqrt(l_x^2 + l_y^2), and the actuator force.
LEG_POINT = _symbols('P', 11)
LEG_TAU = _symbols('tau_leg', 1)
#: Size of the per-leg outputs of `leg_derivatives_kernel`: f (3), df/d[l; w; a] (27), u (3).
LEG_OUT = 33
#: Size of the per-leg outputs of `leg_points_kernel`: the inputs of the leg kernel, then r_i
#: (and, for the general model, the joint's first axis a_i after them).
POINT_OUT = len(LEG_POINT) + 3
#: The joint's first axis a_i, the general model's further input of the per-leg kernel.
LEG_AXIS = _symbols('A', 3)


def _point_motion(g, kin, v, omega):
    """Per leg (l, w, a): the leg vector, the velocity w = v + omega x r and the acceleration
    a = dw/dt of P_i (eqs. 26, 27)."""
    out = []
    for i, leg in enumerate(kin.legs):
        w = g.vector(f'qvP{i}', v + _cross(omega, leg.r))
        out.append((leg.l, w, w.applyfunc(g.rate)))
    return out


def _accelerated_graph():
    return Graph({**{x: xd for x, xd in zip(X, XD)}, **{xd: xdd for xd, xdd in zip(XD, XDD)}})


def leg_points_kernel(variant):
    """[l; w; a; |l|; sqrt(l_x^2 + l_y^2); r] of every leg's P_i (`_point_motion`), 14 per
    leg, interleaved (entry k of leg i at k * 6 + i): the inputs of the per-leg kernels; for
    the general model, then the joint's first axis a_i (17 per leg)."""
    g = _accelerated_graph()
    kin = kinematics(g, PARAMS)
    v, omega = twist(g, kin, XD, 'q')
    points = [list(l) + list(w) + list(a) + [leg.L, sp.sqrt(l[0] ** 2 + l[1] ** 2)] + list(leg.r)
              + (list(PARAMS.axes[i]) if variant == 'general' else [])
              for i, (leg, (l, w, a)) in enumerate(zip(kin.legs, _point_motion(g, kin, v, omega)))]
    return _variant_spec(variant, 'leg_points', leg_points_kernel.__doc__, g,
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
    along = lambda d: {L: _dot(l, d) / L, h: (l[0] * d[0] + l[1] * d[1]) / h}
    g = Graph({**dict(zip(l, w)), **dict(zip(w, a)), **along(w)})
    general = variant == 'general'
    leg = leg_geometry(g, l, None, 'i', variant == 'frames', (L, h), axis=sp.Matrix(LEG_AXIS) if general else None)
    v_C, v_S, h_L = leg_momenta(g, P, leg, w, variant, 'i')
    _, w_C, w_S = _gravity_forces(P, True)
    rate = lambda vec: vec.applyfunc(g.rate)
    f = leg_force(g, P, leg, P.m_C * rate(v_C) + w_C, P.m_S * rate(v_S) + w_S, rate(h_L), 'i') - LEG_TAU[0] * leg.u
    columns = []
    for k, s in enumerate(LEG_POINT[:9]):
        e = [1 if j == k else 0 for j in range(3)]
        tangent = Tangent(g, {s: sp.S.One, **(along(e) if k < 3 else {})}, f'D{k}')
        columns.append([tangent(c) for c in f])
    out = list(f) + [columns[k][c] for c in range(3) for k in range(9)] + list(leg.u)
    return _variant_spec(variant, 'leg_derivatives', leg_derivatives_kernel.__doc__, g,
                      [('lwa', LEG_POINT + (_symbols('Pr', 3) + LEG_AXIS if general else [])), ('tau', LEG_TAU)],
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
    g = _accelerated_graph()
    kin = kinematics(g, PARAMS)
    v, omega = twist(g, kin, XD, 'q')
    point = _symbols('Q', POINT_OUT)
    rv = sp.Matrix(point[-3:])
    g.rate.seed.update(zip(rv, _cross(omega, rv)))
    w = g.vector('qvP', v + _cross(omega, rv))
    motion = (sp.Matrix(X[:3]) + rv, w, w.applyfunc(g.rate))  # l up to the constant b_i
    leg = _symbols('Lg', LEG_OUT)
    f, F = sp.Matrix(leg[:3]), sp.Matrix(3, 9, leg[3:30])
    share = list(f) + list(_cross(rv, f))
    columns = []
    for tag, inputs in _directions(forward):
        for j, s in enumerate(inputs):
            seed = {s: sp.S.One}
            if s in X[3:]:
                seed.update(zip(rv, _cross(kin.J_A[:, X.index(s) - 3], rv)))
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
    g = _accelerated_graph()
    kin = kinematics_of(g, variant)
    v, omega = twist(g, kin, XD, 'q')
    w_P, _, _ = _gravity_forces(P, True)
    rate = lambda vec: vec.applyfunc(g.rate)
    platform = platform_force(kin, sp.Matrix.vstack(P.m_P * rate(platform_velocity(g, kin, v, omega, 'q')) + w_P,
                                                    rate(platform_angular_momentum(g, P, kin, omega, 'q'))))
    columns = [[(-1 if forward else 1) * Tangent(g, {s: sp.S.One}, f'{tag}{j}')(e) for e in platform]
               for tag, inputs in _directions(forward) for j, s in enumerate(inputs)]
    ncol = len(columns)
    chain = _symbols('chain', NUM_LEGS * 6 * ncol)
    lwa = _symbols('lwa', NUM_LEGS * POINT_OUT)
    legs = _symbols('legs', NUM_LEGS * LEG_OUT)
    Z = [[columns[j][i] + sp.Add(*[chain[(i * ncol + j) * NUM_LEGS + leg] for leg in range(NUM_LEGS)])
          for j in range(ncol)] for i in range(6)]
    if forward:
        for leg in range(NUM_LEGS):
            u = sp.Matrix([legs[k * NUM_LEGS + leg] for k in range(30, 33)])
            rv = sp.Matrix([lwa[k * NUM_LEGS + leg] for k in range(POINT_OUT - 3, POINT_OUT)])
            for i, e in enumerate(list(u) + list(_cross(rv, u))):
                Z[i].append(e)
    return _variant_spec(variant, f'residual_derivatives_{"forward" if forward else "inverse"}',
                      residual_derivatives_kernel.__doc__, g,
                      [('x', X), ('xd', XD), ('xdd', XDD), ('chain', chain)]
                      + ([('lwa', lwa), ('legs', legs)] if forward else []),
                      [('Z', [e for row in Z for e in row])])


def euler_rates_inverse(kin):
    """J_A^-1 (inverse of eq. 8) in closed form; divides by cos(theta)."""
    cps, sps = kin.J_A[1, 1], -kin.J_A[0, 1]
    sth, cth = -kin.R[2, 0], kin.c_theta
    return sp.Matrix([[sth * cps / cth, sth * sps / cth, 1],
                      [-sps, cps, 0],
                      [cps / cth, sps / cth, 0]])


#: The rigid-body inertial parameters of the regressor (`schema.RIGID_BODY_PARAMETERS`).
RIGID_BODY = _symbols('pi', len(RIGID_BODY_PARAMETERS))


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
    W = sp.Matrix.vstack(m * a + rate(_cross(omega, h)), rate(h_P) + _cross(h, a))
    cylinder, piston = pi[10:15], pi[15:20]
    I_L = [cylinder[k] + piston[k] for k in range(2, 5)]
    for i, leg in enumerate(kin.legs):
        tag = f'y{i}'
        w = g.vector(f'{tag}vP', v + _cross(omega, leg.r))
        wl = g.vector(f'{tag}wl', _cross(leg.lbar, w))
        ud = g.vector(f'{tag}ud', _cross(wl, leg.u))
        y_L = rate(leg_angular_momentum(g, leg, w, wl, I_L, 'general', tag))
        a_P = rate(w) + ez
        force = piston[0] * a_P - piston[1] * rate(ud)
        moment = y_L + cylinder[1] * _cross(leg.u, ez) + piston[1] * _cross(a_P, leg.u)
        f = point_force(g, leg, force, moment, y_L, tag, spin)
        W += sp.Matrix.vstack(f, _cross(leg.r, f))
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
    g = _accelerated_graph()
    kin = kinematics(g, PARAMS, general=True, axes=[sp.Matrix([0, 0, 1])] * NUM_LEGS if paper else None)
    v, omega = twist(g, kin, XD, 'q')
    pi = [sp.S.Zero if paper and name in ('cylinder.Ixx', 'piston.Ixx') else symbol  # they never act
          for symbol, (name, _) in zip(RIGID_BODY, RIGID_BODY_PARAMETERS)]
    WY = g.partials(list(inertial_force(g, kin, v, omega, pi, spin=not paper)), RIGID_BODY, 'Y')
    rates = [g.define(f'Ld_{i}', _dot(leg.u, g.vector(f'y{i}vP', v + _cross(omega, leg.r))))
             for i, leg in enumerate(kin.legs)]
    signs = [sp.tanh(rate / PARAMS.v_c) for rate in rates]  # vector.c's vcoulomb_sign: vtanh(Ld_i (1 / v_c))
    Y = [row + [rates[i] if j == i else 0 for j in range(NUM_LEGS)] + [signs[i] if j == i else 0 for j in range(NUM_LEGS)]
         for i, row in enumerate(WY)]
    checks = [('L2', [leg.L2 for leg in kin.legs]), ('h2' if paper else 'n2', [leg.n2 for leg in kin.legs])]
    return KernelSpec(_named('regressor', variant), regressor_kernel.__doc__, g, [('x', X), ('xd', XD), ('xdd', XDD)],
                      [('Y', [e for row in Y for e in row]), ('JC', list(jacobian_rows(kin)))] + checks,
                      when=REGRESSOR_VARIANTS[variant])


@dataclass(frozen=True)
class Kernels:
    """A step running a kernel (one of its variants, by the parameters: `VARIANTS`, `MODELS`)
    on the given arrays: the function's inputs or arrays computed by earlier steps.  Its
    outputs go to the arrays of their names, or to those `outputs` names."""
    builders: tuple    # builders of the kernel: one, or one per variant
    inputs: tuple      # the C arrays passed as its inputs
    outputs: tuple = ()  # (kernel output, C array) pairs: where an output goes instead


@dataclass(frozen=True)
class Function:
    """A public C function `stewart_<name>(p, <inputs>, <scalars>, <outputs>)`.

    It checks that the parameters and inputs are finite, runs its kernel on its inputs (the
    first variant whose test holds: `VARIANTS`, `MODELS`), if it has one, then its `steps`,
    checking the legs each kernel reports (`L2`, `h2`, `n2`), and returns the status with
    every output NaN unless it is STEWART_OK and all outputs are finite.  A step is a C
    function returning a status (the solvers of `linsolve`, or codegen/templates/vector.c),
    called with kernel outputs, `scratch` arrays, outputs or constants, or a further kernel
    (`Kernels`).  A function with neither kernels nor steps is written in C in `template`
    (codegen/templates), from the functions before it.
    """
    name: str
    doc: str
    inputs: tuple     # its input arrays, 6 doubles each
    outputs: tuple    # (array, row shape) of its outputs: (6,), (6, 6), ...; its size the shape's product
    kernels: tuple    # builders of its kernel: one, or one per variant; or none (steps only)
    steps: tuple = ()    # (C function, argument arrays) or `Kernels`
    scratch: tuple = ()  # (array, size) of the steps' intermediate arrays
    scalars: tuple = ()  # its scalar (double) inputs
    template: str = ''   # the template file of a function written in C
    # In Python (stewart/_generated.py): its results, filling its outputs in turn, each the name
    # of a whole output or (name, row shape) of the next part of one (default: one per output,
    # named as it is); the named tuple they form ('': the one array, or a plain tuple); and
    # (method, keyword) if it is that method's result with that keyword true (default: the
    # method of its own name).
    results: tuple = ()
    result_type: str = ''
    option: tuple = ()

    @property
    def sizes(self):
        """(array, number of doubles) of its outputs."""
        return tuple((name, math.prod(shape)) for name, shape in self.outputs)


#: The kernel variants, in the order a public function tries them, with the C test under
#: which each runs (the last runs otherwise): the paper's model with axisymmetric legs, the
#: paper's model with legs in the frames of eqs. 43-48 (I_yy != I_zz), the general model.
VARIANTS = {'axisym': 'stewart_is_paper_model(p) && stewart_is_axisymmetric(p)',
            'frames': 'stewart_is_paper_model(p)', 'general': None}
#: The variants of kernels that do not involve the legs' inertia.
MODELS = {'paper': 'stewart_is_paper_model(p)', 'general': None}


def _named(name, variant):
    """A kernel's C name: the paper model's keeps the name of a kernel with no variants."""
    return name if variant == 'paper' else f'{name}_{variant}'


def _variant_spec(variant, name, *args, **kwargs):
    """The `KernelSpec` of a kernel `variant` (of `VARIANTS` or `MODELS`), named by `_named`."""
    return KernelSpec(_named(name, variant), *args, when={**VARIANTS, **MODELS}[variant], **kwargs)


def _variants(build, *args, variants=VARIANTS):
    return tuple(partial(build, *args, variant) for variant in variants)


INVERSE_DYNAMICS = _variants(inverse_dynamics_kernel)
TWIST_MASS_MATRIX = _variants(twist_mass_matrix_kernel)
CORIOLIS_PRODUCT = _variants(coriolis_product_kernel)
GRAVITY = _variants(gravity_kernel, variants=MODELS)
LEG_DERIVATIVES = _variants(leg_derivatives_kernel)
LEG_POINTS = _variants(leg_points_kernel, variants=MODELS)
REGRESSOR = _variants(regressor_kernel, variants=REGRESSOR_VARIANTS)
JOINT_REACTIONS = _variants(joint_reactions_kernel)
STATIC_FORCES = _variants(static_forces_kernel, variants=MODELS)
STATIC_DERIVATIVES = _variants(static_derivatives_kernel, variants=MODELS)



def _residual_steps(forward):
    """The residual's partials Z at (x, xd, xdd, tau): P_i's motion, the legs, the chain rule
    per leg, the sum with the platform's terms."""
    return (Kernels(LEG_POINTS, ('x', 'xd', 'xdd')),
            Kernels(LEG_DERIVATIVES, ('lwa', 'tau')),
            Kernels((partial(leg_chain_kernel, forward),), ('x', 'xd', 'xdd', 'lwa', 'legs')),
            Kernels(_variants(residual_derivatives_kernel, forward, variants=MODELS),
                    ('x', 'xd', 'xdd', 'chain') + (('lwa', 'legs') if forward else ())))

#: Scratch arrays of the solves: the factors of J_C^T and of M_t (`linsolve`).
_BAREISS_FACTORS = ('FJ', linsolve.BAREISS.size)
_LDL_FACTORS = ('FM', linsolve.LDL_SIZE)

#: M = M_t T from M_t and J_A (T = blockdiag(E, J_A), eq. 18).
_MASS_STEPS = (Kernels(TWIST_MASS_MATRIX, ('x',)), Kernels((euler_maps_kernel,), ('x',)),
               ('mass_matrix', ('Mt', 'JA', 'M')))

#: xdd from M_t y = rhs = J_C^T tau - V xd - G (y = T xdd; V xd + G is the inverse dynamics'
#: W at xdd = 0), xdd = [y_v; J_A^-1 y_w].
_FORWARD_STEPS = (Kernels(TWIST_MASS_MATRIX, ('x',)), Kernels((euler_maps_kernel,), ('x',)),
                  ('check_euler', ('ctheta',)), ('ldl_factor', ('Mt', 'FM')),
                  ('zero', ('xdd0', '6')), Kernels(INVERSE_DYNAMICS, ('x', 'xd', 'xdd0')),
                  ('forward_rhs', ('JC', 'tau', 'W', 'rhs')),
                  ('ldl_solve', ('FM', '1', '1', 'rhs', 'y')), ('pose_accelerations', ('JAinv', '1', 'y', 'xdd')))
_FORWARD_SCRATCH = (_LDL_FACTORS, ('xdd0', 6), ('rhs', 6), ('y', 6))

#: The number of columns of the regressor: the rigid-body parameters, then the friction's.
_REGRESSOR_COLUMNS = str(len(RIGID_BODY) + len(FRICTION_PARAMETERS))
#: The regressor's columns of the legs' axial moments.
_AXIAL_COLUMNS = tuple(str([name for name, _ in RIGID_BODY_PARAMETERS].index(f'{body}.Ixx'))
                       for body in ('cylinder', 'piston'))

FUNCTIONS = (
    Function('leg_lengths', 'Leg lengths L_i (a zero length is not an error here).', ('x',), (('L', (6,)),),
             (leg_lengths_kernel,)),
    Function('jacobian', 'J_C (eq. 5): Ldot = J_C t.', ('x',), (('JC', (6, 6)),), (jacobian_kernel,)),
    Function('leg_rates', 'Leg lengths L and rates Ldot = J_C T xd in one pass: LLd = [L; Ldot].',
             ('x', 'xd'), (('LLd', (12,)),), (leg_rates_kernel,),
             results=(('L', (6,)), ('Ldot', (6,)))),
    Function('leg_accelerations', 'Leg accelerations Lddot, the time derivative of Ldot = J_C T xd at xdd.',
             ('x', 'xd', 'xdd'), (('Ldd', (6,)),), (leg_accelerations_kernel,)),
    Function('mass_matrix', 'M = M_t T.', ('x',), (('M', (6, 6)),), (), steps=_MASS_STEPS),
    Function('twist_mass_matrix', 'M_t, the symmetric positive definite twist-space mass matrix: M = M_t T.',
             ('x',), (('Mt', (6, 6)),), TWIST_MASS_MATRIX),
    Function('coriolis_matrix', 'V(x, xd), column by column: column j is V e_j.', ('x', 'xd'), (('V', (6, 6)),), (),
             steps=(('identity', ('E',)),
                    *(Kernels(CORIOLIS_PRODUCT, ('x', 'xd', f'E + {6 * j}'), (('Vv', f'VT + {6 * j}'),))
                      for j in range(6)),
                    ('transpose', ('VT', 'V'))),
             scratch=(('E', 36), ('VT', 36))),
    Function('coriolis_vector', 'V xd without forming V.', ('x', 'xd'), (('Vxd', (6,)),), (),
             steps=(Kernels(CORIOLIS_PRODUCT, ('x', 'xd', 'xd'), (('Vv', 'Vxd'),)),)),
    Function('gravity_vector', 'G(x).', ('x',), (('G', (6,)),), GRAVITY),
    Function('all_terms', 'M, V xd, G and J_C of one state, the terms of M xdd + V xd + G = J_C^T tau.',
             ('x', 'xd'), (('M', (6, 6)), ('Vxd', (6,)), ('G', (6,)), ('JC', (6, 6))), (),
             results=('mass_matrix', 'coriolis_vector', 'gravity_vector', 'jacobian'), result_type='AllTerms',
             steps=(*_MASS_STEPS, Kernels(CORIOLIS_PRODUCT, ('x', 'xd', 'xd'), (('Vv', 'Vxd'),)), Kernels(GRAVITY, ('x',)),
                    Kernels((jacobian_kernel,), ('x',)))),
    Function('inverse_dynamics', 'tau = J_C^-T (M xdd + V xd + G).', ('x', 'xd', 'xdd'), (('tau', (6,)),),
             INVERSE_DYNAMICS, steps=(('bareiss_factor', ('JC', 'FJ')), ('bareiss_solve', ('FJ', '1', '1', 'W', 'tau'))),
             scratch=(_BAREISS_FACTORS,)),
    Function('forward_dynamics', 'xdd = M^-1 (J_C^T tau - V xd - G); needs cos(theta) != 0.',
             ('x', 'xd', 'tau'), (('xdd', (6,)),), (), steps=_FORWARD_STEPS, scratch=_FORWARD_SCRATCH),
    Function('inverse_dynamics_derivatives',
             'tau and its Jacobians (row = output, column = input): dtau/dx = J_C^-T R_x,'
             ' dtau/dxd = J_C^-T R_xd, dtau/dxdd = J_C^-T M, R = partials of M xdd + V xd + G - J_C^T tau.',
             ('x', 'xd', 'xdd'), (('tau', (6,)), ('dtau_dx', (6, 6)), ('dtau_dxd', (6, 6)), ('dtau_dxdd', (6, 6))),
             INVERSE_DYNAMICS,
             steps=(('bareiss_factor', ('JC', 'FJ')), ('bareiss_solve', ('FJ', '1', '1', 'W', 'tau')),
                    *_residual_steps(False),
                    ('bareiss_solve', ('FJ', '18', '18', 'Z', 'Y')),
                    ('split_jacobians', ('Y', 'dtau_dxdd', 'dtau_dx', 'dtau_dxd'))),
             scratch=(_BAREISS_FACTORS, ('Y', 108)),
             result_type='InverseDynamicsDerivatives'),
    Function('static_force_derivatives',
             'The static forces tau_s = J_C^-T G, which hold the platform at rest at x, and their Jacobian'
             ' dtau_s/dx = J_C^-T R_x, R_x = d(G - J_C^T tau)/dx at fixed tau: inverse_dynamics_derivatives at'
             ' xd = xdd = 0 (its tau and dtau_dx), derived without the velocity and acceleration terms.',
             ('x',), (('tau', (6,)), ('dtau_dx', (6, 6))), STATIC_FORCES,
             steps=(('bareiss_factor', ('JC', 'FJ')), ('bareiss_solve', ('FJ', '1', '1', 'W', 'tau')),
                    Kernels(STATIC_DERIVATIVES, ('x', 'tau')),
                    ('bareiss_solve', ('FJ', '6', '6', 'Z', 'dtau_dx'))),
             scratch=(_BAREISS_FACTORS,),
             result_type='StaticForceDerivatives'),
    Function('forward_dynamics_derivatives',
             'xdd and its Jacobians (row = output, column = input): dxdd/dx = -M^-1 R_x,'
             ' dxdd/dxd = -M^-1 R_xd, dxdd/dtau = M^-1 J_C^T, R = partials of M xdd + V xd + G - J_C^T tau;'
             ' needs cos(theta) != 0.',
             ('x', 'xd', 'tau'), (('xdd', (6,)), ('dxdd_dx', (6, 6)), ('dxdd_dxd', (6, 6)), ('dxdd_dtau', (6, 6))),
             (),
             steps=_FORWARD_STEPS + _residual_steps(True) + (
                                     ('ldl_solve', ('FM', '18', '18', 'Z', 'Y')),
                                     ('pose_accelerations', ('JAinv', '18', 'Y', 'D')),
                                     ('split_jacobians', ('D', 'dxdd_dx', 'dxdd_dxd', 'dxdd_dtau'))),
             scratch=_FORWARD_SCRATCH + (('Y', 108), ('D', 108)),
             result_type='ForwardDynamicsDerivatives'),
    Function('joint_reactions',
             'tau and the joint reactions of each leg i (3 doubles per leg, leg-major, in {B}): f_base, the'
             ' force the base exerts on the leg at its universal joint B_i; f_platform, the force the leg'
             ' exerts on the platform at its spherical joint P_i; n_base, the moment the base exerts on'
             ' the leg through its universal joint.',
             ('x', 'xd', 'xdd'), (('tau', (6,)), ('f_base', (6, 3)), ('f_platform', (6, 3)), ('n_base', (6, 3))),
             JOINT_REACTIONS,
             steps=(('bareiss_factor', ('JC', 'FJ')), ('bareiss_solve', ('FJ', '1', '1', 'W', 'tau')),
                    Kernels((joint_forces_kernel,), ('tau', 'JC', 'legf'))),
             scratch=(_BAREISS_FACTORS,),
             results=('tau', 'base', 'platform', 'base_moment'), result_type='JointReactions'),
    Function('regressor',
             'The regressor Y (6 x 32, row-major) of the actuator forces, tau + friction = Y pi, with pi the'
             ' inertial parameters (the columns listed below): J_C^T Y = dW/dpi for the 20 rigid-body'
             ' parameters (W = M xdd + V xd + G), then per leg i Ld_i (column 20 + i) and'
             ' tanh(Ld_i / coulomb_velocity) (column 26 + i), Ld = J_C T xd: the friction law of'
             ' stewart_friction_forces.  The columns of the legs\' axial moments are zero where the legs do'
             ' not spin (spinless_legs != 0, or no universal_joint_axes).',
             ('x', 'xd', 'xdd'), (('Y', (6, len(RIGID_BODY) + len(FRICTION_PARAMETERS))),), REGRESSOR,
             steps=(('bareiss_factor', ('JC', 'FJ')),
                    ('bareiss_solve', ('FJ', str(len(RIGID_BODY)), _REGRESSOR_COLUMNS, 'Y', 'Y')),
                    ('spinless_columns', ('p', _REGRESSOR_COLUMNS, *_AXIAL_COLUMNS, 'Y'))),
             scratch=(_BAREISS_FACTORS,)),
    Function('rk4_step', 'One classic RK4 step of s = [x; xd], ds/dt = [xd; xdd(x, xd, tau)], tau constant:'
             ' [xn; xdn] after dt.', ('x', 'xd', 'tau'), (('xn', (6,)), ('xdn', (6,))), (), scalars=('dt',),
             template='vector.c', results=('x', 'xd'), result_type='Step'),
    Function('rk4_step_derivatives', 'The RK4 step and its Jacobians A = d[xn; xdn]/d[x; xd] (12 x 12) and'
             ' B = d[xn; xdn]/dtau (12 x 6), row-major, by the chain rule through the stages.',
             ('x', 'xd', 'tau'), (('xn', (6,)), ('xdn', (6,)), ('A', (12, 12)), ('B', (12, 6))), (), scalars=('dt',),
             template='vector.c', results=('x', 'xd', 'A', 'B'), result_type='StepDerivatives',
             option=('rk4_step', 'jacobians')),
)
