"""The model's public functions, `FUNCTIONS`: each a C function `stewart_<name>` that runs
kernels of the derivation (`kinematics`, `dynamics`, `derivatives`; the variant its
parameters select) and steps (the unrolled solves of `linsolve`, the helpers of
codegen/templates).  The table drives the generated C, its Cython declarations and the
tables of stewart/_generated.py.
"""

import math
from dataclasses import dataclass
from functools import partial

from . import linsolve
from .calibration import (LEG_PARTIALS, leg_residual_jacobians_kernel, leg_residuals_kernel, target_jacobian_kernel,
                          target_positions_kernel)
from .cueing import joint_cosines_kernel, rider_signals_kernel
from .derivatives import (inverse_dynamics_points_kernel, leg_derivatives_kernel, leg_points_kernel,
                          residual_derivatives_kernel, static_derivatives_kernel)
from .dynamics import (REGRESSOR_VARIANTS, RIGID_BODY, coriolis_product_kernel, gravity_kernel,
                       inverse_dynamics_kernel, joint_forces_kernel, joint_reactions_kernel, regressor_kernel,
                       static_forces_kernel, twist_mass_matrix_kernel)
from .kinematics import (MODELS, VARIANTS, euler_maps_kernel, euler_rate_partials_kernel, jacobian_kernel,
                         leg_accelerations_kernel, leg_lengths_kernel, leg_rates_kernel, leg_unit_vectors_kernel,
                         leg_vectors_kernel, modal_stiffness_kernel, rotation_kernel)
from .schema import FRICTION_PARAMETERS, RIGID_BODY_PARAMETERS


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
INVERSE_DYNAMICS_POINTS = _variants(inverse_dynamics_points_kernel)


def _residual_steps(forward):
    """The residual's partials Z at (x, xd, xdd, tau): P_i's motion (for the inverse dynamics,
    its kernel's), the legs' shares, the sum with the platform's terms."""
    return ((Kernels(LEG_POINTS, ('x', 'xd', 'xdd')),) if forward else ()) + (
            Kernels(LEG_DERIVATIVES, ('lwa', 'tau', 'spin')),
            Kernels(_variants(residual_derivatives_kernel, forward, variants=MODELS),
                    ('x', 'xd', 'xdd', 'spin', 'Zt', 'Mlegs')))


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
             INVERSE_DYNAMICS_POINTS,
             steps=(('bareiss_factor', ('JC', 'FJ')), ('bareiss_solve', ('FJ', '1', '1', 'W', 'tau')),
                    *_residual_steps(False),
                    *(('bareiss_solve', ('FJ', '6', '6', f'Z{name}', f'dtau_d{name}')) for name in ('xdd', 'x', 'xd'))),
             scratch=(_BAREISS_FACTORS,),
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
             steps=_FORWARD_STEPS + _residual_steps(True) + tuple(
                 step for name, Z in (('x', 'Zx'), ('xd', 'Zxd'), ('tau', 'JCt'))
                 for step in (('ldl_solve', ('FM', '6', '6', Z, 'Y')),
                              ('pose_accelerations', ('JAinv', '6', 'Y', f'dxdd_d{name}')))),
             scratch=_FORWARD_SCRATCH + (('Y', 36),),
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
    # Kinematic calibration (`calibration`).
    Function('leg_residuals', 'The calibration residuals r_i = e_i + delta_i - |l_i| (eq. 26) of the encoder'
             ' readings e: the measured less the modelled leg lengths, delta the leg_length_offsets (a zero'
             ' length is not an error here).', ('x', 'readings'), (('r', (6,)),), (leg_residuals_kernel,)),
    Function('leg_residual_jacobians', 'The exact partials of stewart_leg_residuals: dr_dtheta, per leg i (7 a'
             f' leg, row-major) those in its own parameters, {LEG_PARTIALS}: [u_i, -R^T u_i, 1] (u_i = l_i /'
             ' |l_i|; the other 35 of the 42 parameters b, p, delta are zero), and dr_dx = -J_C T (eqs. 5, 8,'
             ' 18).', ('x',), (('dr_dtheta', (6, 7)), ('dr_dx', (6, 6))), (leg_residual_jacobians_kernel,),
             result_type='LegResidualJacobians'),
    Function('target_positions', 'The position q = t + R c in {B} of a target at c in {P} (c: the first three'
             ' doubles of offsets; the other three are not read, but must be finite).', ('x', 'offsets'),
             (('q', (3,)),), (target_positions_kernel,)),
    Function('target_jacobian', 'dq/dx = [E, -[R c]x J_A] (3 x 6, row-major) of the target position q = t +'
             ' R c of stewart_target_positions (eq. 8).', ('x', 'offsets'), (('dq_dx', (3, 6)),),
             (target_jacobian_kernel,)),
    Function('rotation', 'R = Rz(psi) Ry(theta) Rx(phi), {P} in {B} (eq. 3), 3 x 3 row-major.', ('x',),
             (('R', (3, 3)),), (partial(rotation_kernel, False),)),
    Function('rotation_partials', 'R = Rz(psi) Ry(theta) Rx(phi), {P} in {B} (eq. 3), and its partials along psi,'
             ' theta and phi, each 3 x 3 row-major.', ('x',),
             (('R', (3, 3)), ('dR_dpsi', (3, 3)), ('dR_dtheta', (3, 3)), ('dR_dphi', (3, 3))),
             (partial(rotation_kernel, True),),
             result_type='RotationPartials', option=('rotation', 'partials')),
    Function('euler_rate_jacobian', 'J_A (eq. 8): omega = J_A [psi\', theta\', phi\'], 3 x 3 row-major.', ('x',),
             (('JA', (3, 3)),), (euler_maps_kernel,)),
    Function('euler_rate_jacobian_partials', 'J_A (eq. 8) and its partials along psi, theta and phi, each 3 x 3'
             ' row-major.', ('x',), (('JA', (3, 3)), ('dJA_dpsi', (3, 3)), ('dJA_dtheta', (3, 3)), ('dJA_dphi', (3, 3))),
             (euler_rate_partials_kernel,), result_type='EulerRateJacobianPartials',
             option=('euler_rate_jacobian', 'partials')),
    Function('inverse_euler_rate_jacobian', 'J_A^-1 (eq. 8 inverted): the Euler rates of an angular velocity in {B},'
             ' 3 x 3 row-major; needs cos(theta) != 0.', ('x',), (('JAinv', (3, 3)),), (euler_maps_kernel,),
             steps=(('check_euler', ('ctheta',)),)),
    Function('leg_vectors', 'The leg vectors l_i = p + R p_i - b_i (eq. 26), row i = l_i (a zero length is not an'
             ' error here).', ('x',), (('l', (6, 3)),), (leg_vectors_kernel,)),
    Function('leg_unit_vectors', 'The unit leg vectors u_i = l_i / |l_i| (eqs. 25, 26), row i = u_i.', ('x',),
             (('u', (6, 3)),), (partial(leg_unit_vectors_kernel, False),)),
    Function('leg_unit_vector_gradients', 'The unit leg vectors u_i = l_i / |l_i| (eqs. 25, 26), row i = u_i, and'
             ' their pose gradients du_dx[i][a][j] = d u_i,a / d x_j.', ('x',), (('u', (6, 3)), ('du_dx', (6, 3, 6))),
             (partial(leg_unit_vectors_kernel, True),), result_type='LegUnitVectors',
             option=('leg_unit_vectors', 'gradients')),
    Function('modal_stiffness', 'The twist-space stiffness K_t = J_C^T (diag(k) J_C + dtau_s/dx T^-1), T^-1 ='
             ' blockdiag(I, J_A^-1) (eqs. 5, 8, 18), of the platform on leg springs of stiffness k (one per leg)'
             ' preloaded by the static forces tau_s, not symmetrized, with J_C and the twist-space mass matrix M_t:'
             ' K_t phi = w^2 M_t phi gives its modes; needs cos(theta) != 0.', ('x', 'k'),
             (('Kt', (6, 6)), ('JC', (6, 6)), ('Mt', (6, 6))), (),
             steps=(Kernels(TWIST_MASS_MATRIX, ('x',)), Kernels(STATIC_FORCES, ('x',)),
                    ('bareiss_factor', ('JC', 'FJ')), ('bareiss_solve', ('FJ', '1', '1', 'W', 'tau')),
                    Kernels(STATIC_DERIVATIVES, ('x', 'tau')), ('bareiss_solve', ('FJ', '6', '6', 'Z', 'dtau_dx')),
                    Kernels((euler_maps_kernel,), ('x',)), ('check_euler', ('ctheta',)),
                    Kernels((modal_stiffness_kernel,), ('JC', 'k', 'dtau_dx', 'JAinv'))),
             scratch=(_BAREISS_FACTORS, ('tau', 6), ('dtau_dx', 36)), result_type='ModalStiffness'),
    Function('joint_cosines',
             'The cosines of the universal- and spherical-joint angles, c = [u_i . a_i; u_i . R a_i] (12) with'
             ' u_i = l_i / |l_i| (eq. 26) and a_i the joints\' neutral axes (ax, ay, az: their x, y and z'
             ' components, one per leg), the universal joint\'s fixed in {B}, the spherical joint\'s in {P};'
             ' and their gradient in the pose dc/dx (12 x 6).',
             ('x', 'ax', 'ay', 'az'), (('c', (12,)), ('dc_dx', (12, 6))), (joint_cosines_kernel,),
             results=('cosines', 'dcosines_dx'), result_type='JointCosines'),
    Function('rider_signals',
             'What a rider at the origin of {P} senses: y = [f; w], the specific force f = R^T (a + g e_z) and'
             ' the angular velocity w = R^T J_A [psi\', theta\', phi\'] (eq. 8), in {P}; and their Jacobians'
             ' in the pose, its rates and its accelerations (row = output, column = input).',
             ('x', 'xd', 'xdd'), (('y', (6,)), ('dy_dx', (6, 6)), ('dy_dxd', (6, 6)), ('dy_dxdd', (6, 6))),
             (rider_signals_kernel,), result_type='RiderSignals'),
)
