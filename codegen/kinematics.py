"""The derivation's symbols and the platform's kinematics.

The model is the generalized-momentum model of Lopes & Pires (2011), "Complete Dynamic
Modeling of a Stewart Platform Using the Generalized Momentum Approach" (equation numbers in
codegen/ refer to that paper).  Every geometry and inertia parameter is a symbol (`PARAMS`),
so one set of kernels serves every platform.

The same derivation gives two kernel families (`VARIANTS`, `MODELS`): the paper's model
(legs that do not spin, eq. 29; the centre of mass at {P}'s origin, a diagonal tensor), and
the general model of a built machine, whose legs turn with their universal joints (leg
frame x = u_i, y = a_i x u_i / |a_i x u_i|, z = x x y, angular velocity vee(Rdot R^T),
`bodies.leg_momenta`) and whose platform has its centre of mass at c in {P} and a full tensor.

Here: the pose-dependent geometry (R, J_A of eq. 8 and its inverse, the legs of eqs. 26, 32,
43-48, J_C of eq. 5) and the kinematic kernels (leg lengths, J_C, leg rates and
accelerations, the Euler maps).
"""

from dataclasses import dataclass
from functools import reduce

import sympy as sp

from .graph import AXES, Graph, KernelSpec, cross, dot, symbols
from .schema import PARAM_FIELDS


NUM_LEGS = 6
X = symbols('x', 6)      # pose [px, py, pz, psi, theta, phi]
XD = symbols('xd', 6)    # pose rates
XDD = symbols('xdd', 6)  # pose accelerations
TAU = symbols('tau', 6)  # actuator forces


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
    trig: tuple = ()        # cos psi, sin psi, cos theta, sin theta, cos phi, sin phi


def leg_geometry(g, l, r, tag, leg_frames, lengths=None, axis=None):
    """The geometry of a leg from its leg vector l (eq. 26): length, unit vector, l / (l . l)
    (eq. 32) and, with `leg_frames`, the {C_i} axes (eqs. 43-48); `r` = R p_i.  `lengths`,
    when given, are symbols for |l| and sqrt(l_x^2 + l_y^2) (no square root here).  With the
    first axis a_i of its universal joint (`axis`, general model): n = a_i x l, n . n and
    a_i . l, from which the leg frame x = u, y = n / |n|, z = x x y follows (`leg_momenta`)."""
    L2 = g.define(f'L2_{tag}', dot(l, l))
    iL2 = g.define(f'iL2_{tag}', 1 / L2)
    L = lengths[0] if lengths else g.define(f'L_{tag}', sp.sqrt(L2))
    iL = g.define(f'iL_{tag}', L * iL2)
    leg = Leg(r=r, l=l, L2=L2, L=L, u=g.vector(f'u{tag}', l * iL), lbar=g.vector(f'lb{tag}', l * iL2))
    if leg_frames:
        leg.h2 = g.define(f'h2_{tag}', l[0] ** 2 + l[1] ** 2)
        ih = g.define(f'ih_{tag}', 1 / (lengths[1] if lengths else g.define(f'h_{tag}', sp.sqrt(leg.h2))))
        leg.y_C = g.vector(f'yC{tag}', [-l[1] * ih, l[0] * ih, 0])
        leg.z_C = g.vector(f'zC{tag}', cross(leg.u, leg.y_C))
    if axis is not None:
        leg.n = g.vector(f'n{tag}', cross(axis, l))
        leg.n2 = g.define(f'n2_{tag}', dot(leg.n, leg.n))
        leg.in2 = g.define(f'in2_{tag}', 1 / leg.n2)
        leg.al = g.define(f'al_{tag}', dot(axis, l))
    return leg


def trig_seeds(trig, d):
    """Forward-mode seeds of the Euler angles' cosines and sines `trig` (`Kinematics.trig`
    order) along the change d = (d psi, d theta, d phi) of the angles: d cos = -sin d,
    d sin = cos d."""
    return {k: v for (c, s), dk in zip(zip(trig[::2], trig[1::2]), d) for k, v in ((c, -s * dk), (s, c * dk))}


def kinematics(g, P, leg_frames=False, general=False, axes=None, trig=None):
    """Pose-dependent geometry: R, J_A (eq. 8), legs (eqs. 26, 32, 43-48); for the `general`
    model also the joints' axes (`leg_geometry`: the parameters' a_i, or `axes`), the
    platform's centre of mass R c and its full inertia tensor.  With `trig`, symbols for the
    Euler angles' cosines and sines (`Kinematics.trig` order, a kernel's inputs from one that
    computed them), those instead of cos and sin of x, their rates those of the angles
    (`trig_seeds`)."""
    psi, theta, phi = X[3:]
    if trig is None:
        trig = (g.define('c_psi', sp.cos(psi)), g.define('s_psi', sp.sin(psi)),
                g.define('c_theta', sp.cos(theta)), g.define('s_theta', sp.sin(theta)),
                g.define('c_phi', sp.cos(phi)), g.define('s_phi', sp.sin(phi)))
    else:
        g.rate.seed.update(trig_seeds(trig, [g.rates.get(angle, sp.S.Zero) for angle in X[3:]]))
    cps, sps, cth, sth, cph, sph = trig
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
    kin = Kinematics(R=R, J_A=J_A, c_theta=cth, legs=legs, trig=tuple(trig))
    if general:
        kin.rho = g.vector('rho', R * P.c_P)
        kin.I_P = platform_inertia_tensor(P)
    return kin


def platform_inertia_tensor(P):
    """The platform's inertia tensor in {P} about its centre of mass, from its diagonal I_P and
    its products I_Pp = (I_xy, I_xz, I_yz)."""
    (xx, yy, zz), (xy, xz, yz) = P.I_P, P.I_Pp
    return sp.Matrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


#: The kernel variants, in the order a public function tries them, with the C test under
#: which each runs (the last runs otherwise): the paper's model with axisymmetric legs, the
#: paper's model with legs in the frames of eqs. 43-48 (I_yy != I_zz), the general model.
VARIANTS = {'axisym': 'stewart_is_paper_model(p) && stewart_is_axisymmetric(p)',
            'frames': 'stewart_is_paper_model(p)', 'general': None}

#: The variants of kernels that do not involve the legs' inertia.
MODELS = {'paper': 'stewart_is_paper_model(p)', 'general': None}


def kernel_name(name, variant):
    """A kernel's C name: the paper model's keeps the name of a kernel with no variants."""
    return name if variant == 'paper' else f'{name}_{variant}'


def variant_spec(variant, name, *args, **kwargs):
    """The `KernelSpec` of a kernel `variant` (of `VARIANTS` or `MODELS`), named by `kernel_name`."""
    return KernelSpec(kernel_name(name, variant), *args, when={**VARIANTS, **MODELS}[variant], **kwargs)


def kinematics_of(g, variant, trig=None):
    """`kinematics` for a kernel `variant`: 'axisym' (the paper's model, axisymmetric legs),
    'frames' (the paper's model, legs with I_yy != I_zz in the frames of eqs. 43-48) or
    'general' (legs that turn with their universal joints, payload off-centre)."""
    return kinematics(g, PARAMS, leg_frames=variant == 'frames', general=variant == 'general', trig=trig)


def twist(g, kin, qd, tag):
    """Twist t = T qd = [v; J_A * euler rates] (eq. 18)."""
    v = sp.Matrix(qd[:3])
    omega = g.vector(f'{tag}w', kin.J_A * sp.Matrix(qd[3:]))
    return v, omega


def jacobian_rows(kin):
    """J_C (eq. 5): row i = [u_i^T, (r_i x u_i)^T]."""
    return sp.Matrix([list(leg.u) + list(cross(leg.r, leg.u)) for leg in kin.legs])


def euler_rates_inverse(kin):
    """J_A^-1 (inverse of eq. 8) in closed form; divides by cos(theta)."""
    cps, sps = kin.J_A[1, 1], -kin.J_A[0, 1]
    sth, cth = -kin.R[2, 0], kin.c_theta
    return sp.Matrix([[sth * cps / cth, sth * sps / cth, 1],
                      [-sps, cps, 0],
                      [cps / cth, sps / cth, 0]])


def accelerated_graph():
    """A graph whose rates are x' = xd and xd' = xdd (accelerations, and rates of rates)."""
    return Graph({**{x: xd for x, xd in zip(X, XD)}, **{xd: xdd for xd, xdd in zip(XD, XDD)}})


def leg_checks(kin):
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
                      [('JC', list(jacobian_rows(kin)))] + leg_checks(kin))


def leg_rates_kernel():
    """L_i = |l_i| (eq. 26) and Ldot = J_C T xd (eqs. 5, 8, 18): row i of J_C applied to
    the twist, u_i . v + (r_i x u_i) . omega."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    v, omega = twist(g, kin, XD, 'q')
    Ld = jacobian_rows(kin) * sp.Matrix.vstack(v, omega)
    return KernelSpec('leg_rates', leg_rates_kernel.__doc__, g, [('x', X), ('xd', XD)],
                      [('LLd', [leg.L for leg in kin.legs] + list(Ld))] + leg_checks(kin))


def leg_accelerations_kernel():
    """Lddot_i, the time derivative of Ldot_i = u_i . w_i (eqs. 4, 26) with w_i = v + omega x
    r_i the velocity of P_i (eq. 27), by forward mode along x' = xd, xd' = xdd."""
    g = accelerated_graph()
    kin = kinematics(g, PARAMS)
    v, omega = twist(g, kin, XD, 'q')
    rates = [g.define(f'Ld{i}', dot(leg.u, v + cross(omega, leg.r))) for i, leg in enumerate(kin.legs)]
    return KernelSpec('leg_accelerations', leg_accelerations_kernel.__doc__, g, [('x', X), ('xd', XD), ('xdd', XDD)],
                      [('Ldd', [g.rate(Ld) for Ld in rates])] + leg_checks(kin))


def euler_maps_kernel():
    """J_A (eq. 8), J_A^-1 and cos(theta), by which J_A^-1 divides: T = blockdiag(E, J_A)
    (eq. 18) maps the pose rates to the twist."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    return KernelSpec('euler_maps', euler_maps_kernel.__doc__ + ' Row-major.', g, [('x', X)],
                      [('JA', list(kin.J_A)), ('JAinv', list(euler_rates_inverse(kin))), ('ctheta', [kin.c_theta])])


#: The Euler angles, the last three coordinates of the pose, in the order of x.
EULER_ANGLES = ('psi', 'theta', 'phi')


def rotation_kernel(partials):
    """R = Rz(psi) Ry(theta) Rx(phi), {P} in {B} (eq. 3), with `partials` also its partials
    along psi, theta and phi (forward mode on R's definition), each row-major."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    out = [('R', list(kin.R))]
    if partials:
        columns = g.partials(list(kin.R), X[3:], 'dR')  # row: entry of R; column: angle
        out += [(f'dR_d{angle}', [row[k] for row in columns]) for k, angle in enumerate(EULER_ANGLES)]
    return KernelSpec('rotation_partials' if partials else 'rotation', rotation_kernel.__doc__, g, [('x', X)], out)


def euler_rate_partials_kernel():
    """J_A (eq. 8) and its partials along psi, theta and phi (forward mode on its definition),
    each row-major."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    partials = g.partials(list(kin.J_A), X[3:], 'dJA')  # row: entry of J_A; column: angle
    return KernelSpec('euler_rate_partials', euler_rate_partials_kernel.__doc__, g, [('x', X)],
                      [('JA', list(kin.J_A))] + [(f'dJA_d{angle}', [row[k] for row in partials])
                                                 for k, angle in enumerate(EULER_ANGLES)])


def leg_vectors_kernel():
    """The leg vectors l_i = p + R p_i - b_i (eq. 26), leg-major, row i = l_i; no test of
    their lengths."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    return KernelSpec('leg_vectors', leg_vectors_kernel.__doc__, g, [('x', X)],
                      [('l', [c for leg in kin.legs for c in leg.l])])


def leg_unit_vectors_kernel(gradients):
    """The unit vectors u_i = l_i / |l_i| (eqs. 25, 26), leg-major, with `gradients` also their
    pose gradients du_dx[i, a, j] = d u_i,a / d x_j (forward mode on u_i's definition along each
    x_j: dl_i/dp = I, dl_i/d angle = dR/d angle p_i)."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    units = [c for leg in kin.legs for c in leg.u]
    out = [('u', units)]
    if gradients:
        out.append(('du_dx', [d for row in g.partials(units, X, 'du') for d in row]))
    return KernelSpec('leg_unit_vector_gradients' if gradients else 'leg_unit_vectors',
                      leg_unit_vectors_kernel.__doc__, g, [('x', X)], out + leg_checks(kin))


#: The inputs of `modal_stiffness_kernel`: J_C (eq. 5), the legs' stiffnesses k, the static
#: forces' Jacobian dtau_s/dx and J_A^-1 (eq. 8), each row-major.
MODAL_JC = symbols('mJC', 36)
MODAL_K = symbols('mk', 6)
MODAL_DTAU = symbols('mD', 36)
MODAL_JAINV = symbols('mJi', 9)


def modal_stiffness_kernel():
    """K_t = J_C^T (diag(k) J_C + dtau_s/dx T^-1), T^-1 = blockdiag(I, J_A^-1) (eqs. 5, 8, 18):
    the twist-space stiffness of the platform on leg springs k preloaded by the static forces
    tau_s, row-major and not symmetrized (stewart.model.stiffness)."""
    g = Graph({})
    jac, dtau, inv = (sp.Matrix(6, 6, MODAL_JC), sp.Matrix(6, 6, MODAL_DTAU), sp.Matrix(3, 3, MODAL_JAINV))
    t_inv = sp.diag(sp.eye(3), inv)
    inner = sp.Matrix(6, 6, [g.define(f'Kin_{i}{j}', MODAL_K[i] * jac[i, j] + (dtau[i, :] * t_inv[:, j])[0])
                             for i in range(6) for j in range(6)])
    return KernelSpec('modal_stiffness', modal_stiffness_kernel.__doc__, g,
                      [('JC', MODAL_JC), ('k', MODAL_K), ('dtau_dx', MODAL_DTAU), ('JAinv', MODAL_JAINV)],
                      [('Kt', list(jac.T * inner))])
