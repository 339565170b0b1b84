"""The rotary family's C, Cython declarations and Python tables (issue 40), beside the linear
model's and compiled in units of its own: the header stewart_rotary.h (the struct
`stewart_rotary_params` of `rotary.ROTARY_FIELDS`, the status codes of the cranks, the public
functions `stewart_rotary_<name>` of `FUNCTIONS` and their batch functions
`stewart_rotary_batch_<name>`), stewart_rotary_internal.h, the public functions' unit
stewart_rotary.c and a unit per kernel, stewart_rotary_<kernel>.c (the build compiles them
with the model's units, once per instruction set; the C API the package installs for C
programs, stewart_model*.c, is the linear model's alone so far), the table of one
compiled copy and the list of the copies (stewart_rotary_dispatch.h), the Cython
declarations (stewart_rotary.pxd) and stewart/_generated_rotary.py.

Least new machinery: the functions are `model.Function`s whose steps are the linear model's
helpers (the unrolled solves of `linsolve`, codegen/templates/vector.c and the Euler maps'
kernel), evaluated over blocks of states by the linear model's `batch_rows`, so a state gives
the same bits alone and in any row of any batch on every instruction set.  `batch_rows`, the
block functions and the dispatch table's `stewart_call` carry the parameters as an opaque
`const stewart_params *`; the rotary functions convert it back to the
`stewart_rotary_params` it points to (`rotary_params_of`).
"""

import math
from functools import partial

from . import linsolve, rotary, rotary_joints
from .csource import kernel_runs, params_finite
from .kinematics import euler_maps_kernel
from .model import Function, Kernels
from .pymodule import results
from .signatures import aligned

_BAREISS = ('FJ', linsolve.BAREISS.size)
_LDL = ('FM', linsolve.LDL_SIZE)
_MT = Kernels((rotary.rotary_twist_mass_matrix_kernel,), ('x',))
_EULER = Kernels((euler_maps_kernel,), ('x',))
_ID = (rotary.rotary_inverse_dynamics_kernel,)
#: The torques' partials by each input: (first column, kernel builder) of its kernels.
_DERIVATIVES = {name: tuple((first, partial(rotary.rotary_inverse_dynamics_derivatives_kernel, name, first))
                            for first in range(0, 6, rotary.DERIVATIVE_COLUMNS))
                for name in rotary.DERIVATIVE_INPUTS}

#: xdd from M_t y = J_alpha^T torque - W(x, xd, 0), xdd = [y_v; J_A^-1 y_w] (M_t factored in FM).
_FORWARD_STEPS = (_MT, _EULER, ('check_euler', ('ctheta',)), ('ldl_factor', ('Mt', 'FM')), ('zero', ('xdd0', '6')),
                  Kernels(_ID, ('x', 'xd', 'xdd0')), ('forward_rhs', ('JR', 'torque', 'W', 'rhs')),
                  ('ldl_solve', ('FM', '1', '1', 'rhs', 'y')), ('pose_accelerations', ('JAinv', '1', 'y', 'xdd')))
_FORWARD_SCRATCH = (_LDL, ('xdd0', 6), ('rhs', 6), ('y', 6))

#: The rotary family's public functions, `stewart_rotary_<name>`.
FUNCTIONS = (
    Function('crank_angles', 'The crank angles alpha_i in their branches (crank_branch), in (-pi, pi].',
             ('x',), (('alpha', (6,)),), (rotary.rotary_crank_angles_kernel,), steps=(('crank_angles', ('cs', 'alpha')),)),
    Function('jacobian', 'J_alpha in the twist: alpha_dot = J_alpha [v; omega] (J_alpha T in the pose rates).',
             ('x',), (('JR', (6, 6)),), (rotary.rotary_jacobian_kernel,)),
    Function('pose_jacobian', 'J_alpha T in the pose rates: alpha_dot = J_alpha T xd (T = blockdiag(E, J_A)).',
             ('x',), (('JP', (6, 6)),), (rotary.rotary_jacobian_kernel,),
             steps=(_EULER, ('mass_matrix', ('JR', 'JA', 'JP')))),
    Function('crank_rates', 'The crank rates alpha_dot = J_alpha T xd.', ('x', 'xd'), (('ad', (6,)),),
             (rotary.rotary_crank_rates_kernel,)),
    Function('twist_mass_matrix', 'M_t, the symmetric positive definite twist-space mass matrix: M = M_t T.',
             ('x',), (('Mt', (6, 6)),), (rotary.rotary_twist_mass_matrix_kernel,)),
    Function('mass_matrix', 'M = M_t T, in the pose coordinates.', ('x',), (('M', (6, 6)),), (),
             steps=(_MT, _EULER, ('mass_matrix', ('Mt', 'JA', 'M')))),
    Function('gravity_vector', 'G(x).', ('x',), (('G', (6,)),), (rotary.rotary_gravity_kernel,)),
    Function('inverse_dynamics', 'The motor torques tau = J_alpha^-T (M xdd + V xd + G), N m about +a_i.',
             ('x', 'xd', 'xdd'), (('tau', (6,)),), _ID,
             steps=(('bareiss_factor', ('JR', 'FJ')), ('bareiss_solve', ('FJ', '1', '1', 'W', 'tau'))),
             scratch=(_BAREISS,)),
    Function('forward_dynamics', 'xdd = M^-1 (J_alpha^T torque - V xd - G); needs cos(theta) != 0.',
             ('x', 'xd', 'torque'), (('xdd', (6,)),), (), steps=_FORWARD_STEPS, scratch=_FORWARD_SCRATCH),
    Function('inverse_dynamics_derivatives',
             'tau and its Jacobians (row = output, column = input): dtau/dq = J_alpha^-T dR/dq for q = x, xd,'
             ' xdd, R = M_t T xdd + V xd + G - J_alpha^T tau at fixed tau.',
             ('x', 'xd', 'xdd'), (('tau', (6,)), ('dtau_dx', (6, 6)), ('dtau_dxd', (6, 6)), ('dtau_dxdd', (6, 6))), _ID,
             steps=(('bareiss_factor', ('JR', 'FJ')), ('bareiss_solve', ('FJ', '1', '1', 'W', 'tau')),
                    *(step for name in rotary.DERIVATIVE_INPUTS
                      for step in (*(Kernels((build,), ('x', 'xd', 'xdd', 'tau'), (('ZT', f'Z{name}T + {6 * first}'),))
                                     for first, build in _DERIVATIVES[name]),
                                   ('transpose', (f'Z{name}T', f'Z{name}')),
                                   ('bareiss_solve', ('FJ', '6', '6', f'Z{name}', f'dtau_d{name}'))))),
             scratch=(_BAREISS, *((f'Z{name}{t}', 36) for name in rotary.DERIVATIVE_INPUTS for t in ('T', ''))),
             result_type='InverseDynamicsDerivatives'),
    # ---- the workspace's joints (codegen/rotary_joints.py) ----
    Function('joint_cosines',
             'The crank angles alpha (6), the cosines c (18) of the rod-crank angles (-u_i . n_i / d: 1 where the rod'
             ' folds over its crank), of the crank joints\' and of the platform joints\' angles from their neutral'
             ' axes (the rod at the reference pose x0, fixed in the crank and in {P}), the platform joints\''
             ' heights z (6) in {B} and the sines s (6) of the rods\' tilts out of the cranks\' planes (n_i . a_i / d).',
             ('x', 'x0'), (('alpha', (6,)), ('c', (18,)), ('z', (6,)), ('s', (6,))), (),
             steps=(Kernels((rotary_joints.rotary_neutral_axes_kernel,), ('x0',)),
                    Kernels((rotary_joints.rotary_joint_cosines_kernel,), ('x', 'qc', 'qp')),
                    ('crank_angles', ('cs', 'alpha'))),
             results=('crank_angles', ('rod_crank', (6,)), ('crank_joint', (6,)), ('platform_joint', (6,)),
                      'platform_heights', 'pin_tilt_sines'),
             result_type='RotaryJointCosines'),
    Function('cueing_rows',
             'What MPC cueing holds: the crank angles alpha, the crank rates alpha_dot, the reach s_i ='
             ' sin^2(delta_i) (0 at the edge of crank i\'s reach), their gradients grads = [J_alpha T'
             ' (= d alpha/dx = d alpha_dot/dxd), d alpha_dot/dx, ds/dx], the joints (30: the values of joint_cosines'
             ' c, z and s, the ball joints centred at the reference pose x0) and their gradient djoints_dx.',
             ('x', 'xd', 'x0'),
             (('alpha', (6,)), ('ad', (6,)), ('reach', (6,)), ('grads', (3, 6, 6)), ('joints', (30,)),
              ('djoints_dx', (30, 6))), (),
             steps=(Kernels((rotary_joints.rotary_neutral_axes_kernel,), ('x0',)),
                    Kernels((rotary_joints.rotary_cueing_rows_kernel,), ('x', 'xd', 'qc', 'qp')),
                    ('crank_angles', ('cs', 'alpha')))),
    # The forward dynamics' derivatives and the RK4 step with its Jacobians (issue 40), as the
    # linear model's (codegen/model.py): keep these entries together, at the end of the table.
    Function('forward_dynamics_derivatives',
             'xdd and its Jacobians (row = output, column = input): dxdd/dq = -T^-1 M_t^-1 dR/dq for q = x, xd,'
             ' dxdd/dtau = T^-1 M_t^-1 J_alpha^T (tau: the torque), R = M_t T xdd + V xd + G - J_alpha^T torque at fixed torque'
             ' (the partials of inverse_dynamics_derivatives at the forward dynamics\' xdd); needs cos(theta) != 0.',
             ('x', 'xd', 'torque'),
             (('xdd', (6,)), ('dxdd_dx', (6, 6)), ('dxdd_dxd', (6, 6)), ('dxdd_dtau', (6, 6))), (),
             steps=(*_FORWARD_STEPS,
                    *(step for name in ('x', 'xd')
                      for step in (*(Kernels((build,), ('x', 'xd', 'xdd', 'torque'), (('ZT', f'Z{name}T + {6 * first}'),))
                                     for first, build in _DERIVATIVES[name]),
                                   ('negated_transpose', (f'Z{name}T', 'Z')),
                                   ('ldl_solve', ('FM', '6', '6', 'Z', 'Y')),
                                   ('pose_accelerations', ('JAinv', '6', 'Y', f'dxdd_d{name}')))),
                    ('transpose', ('JR', 'Z')), ('ldl_solve', ('FM', '6', '6', 'Z', 'Y')),
                    ('pose_accelerations', ('JAinv', '6', 'Y', 'dxdd_dtau'))),
             scratch=(*_FORWARD_SCRATCH, ('ZxT', 36), ('ZxdT', 36), ('Z', 36), ('Y', 36)),
             result_type='ForwardDynamicsDerivatives'),
    Function('rk4_step', 'One classic RK4 step of s = [x; xd], ds/dt = [xd; xdd(x, xd, torque)], torque constant'
             ' (zero-order hold): [xn; xdn] after dt.', ('x', 'xd', 'torque'), (('xn', (6,)), ('xdn', (6,))), (),
             scalars=('dt',), template='vector.c', results=('x', 'xd'), result_type='Step'),
    Function('rk4_step_derivatives', 'The RK4 step and its Jacobians A = d[xn; xdn]/d[x; xd] (12 x 12) and'
             ' B = d[xn; xdn]/dtorque (12 x 6), row-major, by the chain rule through the stages.',
             ('x', 'xd', 'torque'), (('xn', (6,)), ('xdn', (6,)), ('A', (12, 12)), ('B', (12, 6))), (),
             scalars=('dt',), template='vector.c', results=('x', 'xd', 'A', 'B'), result_type='StepDerivatives',
             option=('rk4_step', 'jacobians')),
)

#: The block functions of the rotary functions written in C (codegen/templates/vector.c's RK4
#: step over the rotary forward dynamics), by name.
VECTOR_TEMPLATES = {'rk4_step': 'vrk4(opaque, vblock_rotary_forward_dynamics, 0, scalar, in, out)',
                    'rk4_step_derivatives': 'vrk4(opaque, vblock_rotary_forward_dynamics_derivatives, 1, scalar, in, out)'}

#: The first status code of the cranks: STEWART_ERR_CRANK_REACH + i, crank i cannot reach the pose.
CRANK_REACH = 16
#: Its tolerance: a pose is within crank i's reach iff S_i^2 > STEWART_ROTARY_REACH_TOL rho_i^2
#: (`rotary.crank_geometry`: S / rho = sin(delta), zero where the rod is normal to the tip's
#: motion, the edge of the reach, where J_alpha is singular).
REACH_TOL = '1e-12'

#: {status code: (name, message, tolerance)} of the codes the rotary functions add.
CRANK_CONDITIONS = {CRANK_REACH + i: ('crank_reach', f'crank {i} cannot reach the pose', float(REACH_TOL))
                    for i in range(6)}


def _fields_struct():
    return aligned([(f.declaration(), f.doc) for f in rotary.ROTARY_FIELDS])


def _arguments(function, batch):
    args = ['const stewart_rotary_params *p'] + (['size_t n'] if batch else [])
    args += [f'const double *{name}' if batch else f'const double {name}[6]' for name in function.inputs]
    args += [f'double {name}' for name in function.scalars]
    args += [f'double *{name}' if batch else f'double {name}[{size}]' for name, size in function.sizes]
    return ', '.join(args + (['int *status'] if batch else []))


def prototype(function, batch=False):
    """`int stewart_rotary_[batch_]<name>(const stewart_rotary_params *p, ...)`."""
    return f'int stewart_rotary_{"batch_" if batch else ""}{function.name}({_arguments(function, batch)})'


HEADER = r'''/* stewart_rotary.h -- the dynamic model of a 6-RSS rotary-actuator platform (issue 40).
 *
 * GENERATED by `python -m codegen` from codegen/ (rotary.py, rotary_source.py); do not edit.
 *
 * Plain C99 beside stewart_model.h, whose conventions it keeps (pose x, twist, T, J_A, batches,
 * rounding: compile with STEWART_ROUNDING_FLAGS).  Leg i: a motor at b_i turns a crank of
 * length r about the unit axis a_i; its tip is c_i = b_i + r (cos(alpha_i) h_i +
 * sin(alpha_i) a_i x h_i); a rod of length d joins c_i to P_i = p + R p_i.  tau_i [N m] acts
 * on the crank about +a_i.  Equation of motion (twist space):
 *     M_t(x) T xdd + V(x, xd) xd + G(x) = J_alpha(x)^T tau,   alpha_dot = J_alpha T xd.
 * The rods are axisymmetric and do not spin about their axes.
 */
#ifndef STEWART_ROTARY_H
#define STEWART_ROTARY_H

#include "stewart_model.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
@STRUCT@} stewart_rotary_params;

/* Beyond the codes of stewart_model.h: crank i cannot reach the pose (no root of its loop, or the
 * rod tangent to the crank tip's circle, where J_alpha is singular): S_i^2 <= STEWART_ROTARY_REACH_TOL rho_i^2. */
enum {
@STATUS@};
#define STEWART_ROTARY_REACH_TOL @TOL@

/* Message for a status code (a static string, never NULL). */
const char *stewart_rotary_status_message(int status);

@FUNCTIONS@
@BATCH@
#ifdef __cplusplus
}
#endif

#endif /* STEWART_ROTARY_H */
'''


def header(ops):
    """stewart_rotary.h; `ops`, (kernel name, operation count) pairs, in a comment."""
    table = ''.join(f' *   {name:<32}  {n:6d}\n' for name, n in ops)
    return (HEADER.replace('@STRUCT@', _fields_struct())
            .replace('@STATUS@', ''.join(f'    STEWART_ERR_CRANK_REACH_{i} = {CRANK_REACH + i},\n' for i in range(6)))
            .replace('@TOL@', REACH_TOL)
            .replace('@FUNCTIONS@', ''.join(f'/* {f.doc} */\n{prototype(f)};\n' for f in FUNCTIONS))
            .replace('@BATCH@', ''.join(f'{prototype(f, True)};\n' for f in FUNCTIONS)
                     + f'\n/* Operation counts of the rotary kernels:\n{table} */\n'))


INTERNAL = r'''/* stewart_rotary_internal.h -- GENERATED by `python -m codegen` from codegen/; do not edit.
 * What the rotary units share: the linear model's (stewart_internal.h: the lane-wise arithmetic,
 * the solvers, batch_rows), the names of a copy for one instruction set, the rotary checks and
 * the kernels' prototypes. */
#ifndef STEWART_ROTARY_INTERNAL_H
#define STEWART_ROTARY_INTERNAL_H

#include "stewart_internal.h"

#ifdef STEWART_PREFIX
@RENAME@
#endif

#include "stewart_rotary.h"

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
/* The rotary parameters batch_rows and the block functions carry as an opaque pointer. */
static const stewart_rotary_params *rotary_params_of(const stewart_params *opaque)
{
    return (const stewart_rotary_params *)(const void *)opaque;
}

@FINITE@
/* STEWART_OK unless a crank cannot reach the pose, lane by lane: the first such crank i gives
 * STEWART_ERR_CRANK_REACH_0 + i. */
static stewart_vl vcheck_cranks(const stewart_vd S2[6], const stewart_vd rho2[6])
{
    stewart_vl status = vnone();
    int i;
    for (i = 0; i < 6; ++i) {
        status = vmerge(status, ~(S2[i] > STEWART_ROTARY_REACH_TOL * rho2[i]) & (STEWART_ERR_CRANK_REACH_0 + i));
    }
    return status;
}

/* alpha_i = atan2(sin, cos) from cs = [cos(alpha); sin(alpha)], in (-pi, pi], lane by lane. */
static stewart_vl vcrank_angles(const stewart_vd cs[12], stewart_vd alpha[6])
{
    int i, lane;
    for (i = 0; i < 6; ++i) {
        for (lane = 0; lane < STEWART_LANES; ++lane) {
            const double a = atan2(cs[6 + i][lane], cs[i][lane]);
            alpha[i][lane] = a == -atan2(0.0, -1.0) ? -a : a;
        }
    }
    return vnone();
}

/* Z = -ZT^T of a 6 x 6 matrix (row-major), over a block: the residual's partials, written by
 * columns (ZT), as the right-hand sides of M_t T dxdd/dq = -dR/dq. */
static stewart_vl vnegated_transpose(const stewart_vd ZT[36], stewart_vd Z[36])
{
    int i, j;
    for (i = 0; i < 6; ++i)
        for (j = 0; j < 6; ++j)
            Z[6 * j + i] = -ZT[6 * i + j];
    return vnone();
}
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

/* ---- the rotary kernels (stewart_rotary_<kernel>.c) ---- */
@KERNELS@
#endif /* STEWART_ROTARY_INTERNAL_H */
'''


def _public_names():
    return ([f'rotary_{f.name}' for f in FUNCTIONS] + [f'rotary_batch_{f.name}' for f in FUNCTIONS]
            + ['rotary_status_message'])


def internal_header(emitted):
    """stewart_rotary_internal.h for the rotary kernels `emitted` (`emit.EmittedKernel`s)."""
    rename = '\n'.join([f'#define stewart_{name} STEWART_LOCAL({name})' for name in _public_names()]
                       + [f'#define vkernel_{k.name} STEWART_LOCAL(vkernel_{k.name})' for k in emitted])
    finite = params_finite(rotary.ROTARY_FIELDS).replace(
        'static int params_finite(const stewart_params *p)',
        'static int rotary_params_finite(const stewart_rotary_params *p)')
    return (INTERNAL.replace('@RENAME@', rename).replace('@FINITE@', finite)
            .replace('@KERNELS@', ''.join(f'STEWART_HIDDEN {k.declaration};\n' for k in emitted)))


def kernel_unit(kernel):
    """stewart_rotary_<kernel>.c: one rotary kernel (`emit.EmittedKernel`)."""
    return (f'/* stewart_{kernel.name}.c -- GENERATED by `python -m codegen` from codegen/; do not edit.\n'
            ' * A kernel of the rotary family (stewart_rotary_internal.h declares it). */\n'
            '#include "stewart_rotary_internal.h"\n\n' + kernel.source)


def _block(function, kernels):
    """C lines of `vblock_rotary_<name>`: its kernels and steps on a block of states, each
    rotary kernel followed by the cranks' check, the statuses merged (for a function written
    in C, its block function in `VECTOR_TEMPLATES`)."""
    if function.template:
        return [f'static stewart_vl vblock_rotary_{function.name}(const stewart_params *opaque, double scalar,'
                ' const stewart_vd *const in[], stewart_vd *const out[])', '{',
                f'    return {VECTOR_TEMPLATES[function.name]};', '}', '']
    listed = kernel_runs(function, kernels)
    runs = iter(listed)
    outputs = dict(function.sizes)
    arrays = {}
    for specs, _, renames in listed:
        for name, exprs in specs[0].outputs:
            name = renames.get(name, name)
            if name not in outputs and name.isidentifier():  # not a place in another array
                arrays[name] = specs[0].size(name, exprs)
    arrays.update(dict(function.scratch))
    lines = [f'static stewart_vl vblock_rotary_{function.name}(const stewart_params *opaque, double scalar,'
             ' const stewart_vd *const in[], stewart_vd *const out[])', '{',
             '    const stewart_rotary_params *p = rotary_params_of(opaque);']
    lines += [f'    const stewart_vd *{name} = in[{k}];' for k, name in enumerate(function.inputs)]
    lines += [f'    stewart_vd *{name} = out[{k}];' for k, (name, _) in enumerate(function.sizes)]
    lines += ['    stewart_vd ' + ', '.join(f'{name}[{n}]' for name, n in arrays.items()) + ';',
              '    stewart_vl status = vnone();', '    (void)scalar;', '    (void)p;']

    def run():
        (kernel,), inputs, renames = next(runs)
        names = [name for name, _ in kernel.outputs]
        own = kernel.name.startswith('rotary_')
        out = [f'    vkernel_{kernel.name}({", ".join(["p" if own else "opaque", *inputs, *(renames.get(n, n) for n in names)])});']
        if 'S2' in names:
            out.append('    status = vmerge(status, vcheck_cranks(S2, rho2));')
        return out

    if function.kernels:
        lines += run()
    for step in function.steps:
        if isinstance(step, Kernels):
            lines += run()
        else:
            lines.append(f'    status = vmerge(status, v{step[0]}({", ".join(step[1])}));')
    return lines + ['    return status;', '}', '']


def _batch(function):
    nin, nout = len(function.inputs), len(function.outputs)
    arrays = lambda kind, names: '(' + kind + '[]){' + ', '.join(names) + '}'
    call = ', '.join(['rotary_params_finite(p)', '(const stewart_params *)(const void *)p',
                      f'vblock_rotary_{function.name}', function.scalars[0] if function.scalars else '0.0', 'n', str(nin),
                      arrays('const double *const ', function.inputs),
                      arrays('stewart_vd *const ', [f'in{k}' for k in range(nin)]), str(nout),
                      arrays('double *const ', [name for name, _ in function.sizes]),
                      arrays('stewart_vd *const ', [f'out{k}' for k in range(nout)]),
                      arrays('const int ', [str(size) for _, size in function.sizes]), 'status'])
    single = ', '.join(['p', '1', *function.inputs, *function.scalars, *(name for name, _ in function.sizes), 'NULL'])
    adapter = ', '.join(['rotary_params_of(p)', 'n', *(f'in[{k}]' for k in range(nin)),
                         *(['scalar'] if function.scalars else []), *(f'out[{k}]' for k in range(nout)), 'status'])
    return [prototype(function, True), '{',
            '    stewart_vd ' + ', '.join([f'in{k}[6]' for k in range(nin)]
                                          + [f'out{k}[{size}]' for k, (_, size) in enumerate(function.sizes)]) + ';',
            f'    return batch_rows({call});', '}', '',
            prototype(function), '{', f'    return stewart_rotary_batch_{function.name}({single});', '}', '',
            '#ifdef STEWART_TARGET  /* the call of this copy\'s table, below */',
            f'static int call_rotary_{function.name}(const stewart_params *p, size_t n, const double *const in[],'
            ' double scalar, double *const out[], int *status)', '{', *([] if function.scalars else ['    (void)scalar;']),
            f'    return stewart_rotary_batch_{function.name}({adapter});', '}', '#endif', '']


def source(kernels):
    """stewart_rotary.c: the rotary public functions, their batch functions, their calls in
    the convention of stewart_call and the table of this compiled copy (stewart_rotary_dispatch.h)."""
    lines = ['/* stewart_rotary.c -- GENERATED by `python -m codegen` from codegen/; do not edit.',
             ' * The rotary family\'s public functions (stewart_rotary.h) and the table of this compiled copy. */',
             '#include "stewart_rotary_internal.h"', '#include "stewart_rotary_dispatch.h"', '',
             'const char *stewart_rotary_status_message(int status)', '{',
             f'    static const char *const reach[6] = {{{", ".join(chr(34) + m + chr(34) for _, m, _ in CRANK_CONDITIONS.values())}}};',
             f'    if (status >= {CRANK_REACH} && status < {CRANK_REACH + 6}) {{',
             f'        return reach[status - {CRANK_REACH}];', '    }',
             '    return stewart_status_message(status);', '}', '']
    for function in FUNCTIONS:
        lines += _block(function, kernels) + _batch(function)
    lines += ['#define STEWART_ROTARY_STRING_(a) #a', '#define STEWART_ROTARY_STRING(a) STEWART_ROTARY_STRING_(a)',
              '#ifdef STEWART_TARGET',
              'const stewart_rotary_table STEWART_JOIN(stewart_rotary_table, STEWART_TARGET) = {',
              '    STEWART_ROTARY_STRING(STEWART_TARGET),',
              '    {' + ', '.join(f'call_rotary_{f.name}' for f in FUNCTIONS) + '},', '};', '#endif', '']
    return '\n'.join(lines)


DISPATCH = r'''/* stewart_rotary_dispatch.h -- GENERATED by `python -m codegen` from codegen/; do not edit.
 *
 * The table of the rotary functions of one compiled copy of the model (stewart_rotary.c,
 * compiled once per target as the model's units are), in the convention of stewart_call (the
 * parameters a const stewart_rotary_params * passed as const stewart_params *), and, where
 * STEWART_TABLES lists the copies, the list of their tables. */
#ifndef STEWART_ROTARY_DISPATCH_H
#define STEWART_ROTARY_DISPATCH_H

#include "stewart_dispatch.h"
#include "stewart_rotary.h"

/* The rotary functions of the table's `call`, in this order (their index):
@INDEX@ */
#define STEWART_ROTARY_FUNCTIONS @COUNT@

typedef struct {
    const char *name;  /* the target, as the linear table's */
    stewart_call call[STEWART_ROTARY_FUNCTIONS];
} stewart_rotary_table;

#ifdef STEWART_TABLES
#define X(name) extern const stewart_rotary_table stewart_rotary_table_##name;
STEWART_TABLES
#undef X
#define X(name) &stewart_rotary_table_##name,
static const stewart_rotary_table *const stewart_rotary_tables[] = {STEWART_TABLES NULL};
#undef X
#endif

#endif /* STEWART_ROTARY_DISPATCH_H */
'''


def dispatch_header():
    return (DISPATCH.replace('@INDEX@', ''.join(f' *   {k:2d}  {f.name}\n' for k, f in enumerate(FUNCTIONS)))
            .replace('@COUNT@', str(len(FUNCTIONS))))


PXD = '''# stewart_rotary.pxd -- GENERATED by `python -m codegen` from codegen/; do not edit.
# The Cython declarations of stewart_rotary.h and stewart_rotary_dispatch.h, and the copy of a
# stewart.RotaryParams into the C struct stewart_rotary_params.
from stewart_model cimport stewart_call

cdef extern from "stewart_rotary_dispatch.h" nogil:
    ctypedef struct stewart_rotary_params:
@STRUCT@
    const char *stewart_rotary_status_message(int status)
    ctypedef struct stewart_rotary_table:
        const char *name
        stewart_call call[@COUNT@]
    const stewart_rotary_table **stewart_rotary_tables


cdef inline int stewart_rotary_params_fill(stewart_rotary_params *p, object params) except -1:
    """Copy params, a stewart.RotaryParams, into p member by member."""
    cdef Py_ssize_t i0, i1
@COPY@
    return 0
'''


def _copy(field):
    source = f'params.{field.source or field.name}'
    if not field.shape:
        return [f'    p.{field.name} = {source}']
    lines = [f'    value = {source}']
    loops = [f'i{k}' for k in range(len(field.shape))]
    for depth, (index, n) in enumerate(zip(loops, field.shape)):
        lines.append(f'    {"    " * depth}for {index} in range({n}):')
    lines.append(f'    {"    " * len(loops)}p.{field.name}{"".join(f"[{i}]" for i in loops)} = value[{", ".join(loops)}]')
    return lines


def pxd():
    """The text of generated/stewart_rotary.pxd."""
    return (PXD.replace('@STRUCT@', '\n'.join(f'        {f.declaration()[:-1]}' for f in rotary.ROTARY_FIELDS))
            .replace('@COUNT@', str(len(FUNCTIONS)))
            .replace('@COPY@', '\n'.join(line for f in rotary.ROTARY_FIELDS for line in _copy(f))))


MODULE = '''"""The rotary family's tables for the Python layer (stewart.model.rotary).

GENERATED by `python -m codegen` from codegen/ (rotary.py, rotary_source.py); do not edit.
"""

from ._generated import Function

#: (member, shape) of every member of the C struct stewart_rotary_params, in order.
PARAM_FIELDS = (
@FIELDS@
)

#: The fields of a RotaryParams with no member in stewart_rotary_params, and why.
PARAMS_LEFT_OUT = {
@LEFT_OUT@
}

#: {status code: (name, message, tolerance)} of the codes the rotary functions add to those of
#: stewart._generated.CONDITIONS: crank i cannot reach the pose.
CRANK_CONDITIONS = {
@CONDITIONS@
}

#: {name: Function} of every rotary function (stewart_rotary_<name>), in the order of the
#: rotary table's ``call``.
FUNCTIONS = {
@FUNCTIONS@
}
'''


def _function(index, function):
    fields = {'index': index, 'inputs': tuple(function.inputs), 'scalar': function.scalars[0] if function.scalars else '',
              'outputs': tuple((name, math.prod(shape)) for name, shape in function.outputs),
              'results': results(function), 'result_type': function.result_type,
              'method': (function.option or (function.name, ''))[0], 'option': (function.option or ('', ''))[1]}
    return f'    {function.name!r}: Function(\n' + ''.join(f'        {k}={v!r},\n' for k, v in fields.items()) + '    ),'


def module():
    """The text of stewart/_generated_rotary.py."""
    parts = {
        'FIELDS': [f'    ({f.name!r}, {f.shape!r}),' for f in rotary.ROTARY_FIELDS],
        'LEFT_OUT': [f'    {name!r}: {why!r},' for name, why in rotary.ROTARY_LEFT_OUT.items()],
        'CONDITIONS': [f'    {k}: {v!r},' for k, v in CRANK_CONDITIONS.items()],
        'FUNCTIONS': [_function(k, f) for k, f in enumerate(FUNCTIONS)],
    }
    text = MODULE
    for key, lines in parts.items():
        text = text.replace(f'@{key}@', '\n'.join(lines))
    return text


#: The rotary kernels' builders, in the order the functions first use them.
BUILDERS = tuple(dict.fromkeys(
    build for function in FUNCTIONS
    for build in list(function.kernels) + [b for step in function.steps if isinstance(step, Kernels) for b in step.builders]
    if build is not euler_maps_kernel))
