"""The C declarations of the public functions: the prototypes of the model's functions and of
their batch functions (from `model.Function`s), the types, constants and functions of the
actuators and the closed loop (codegen/templates/control.c), and the entries of the table of
the public functions (stewart_dispatch.h).  `csource` writes them into the header and the
dispatch, `pxd` into the Cython declarations.
"""

import textwrap


#: The types of the actuators and the closed loop (codegen/templates/control.c): (name, doc,
#: members), each member (C type, name, array length or 0 for a scalar, doc).
LOOP_TYPES = (
    ('stewart_friction', 'The friction law of the legs: leg i loses F_v,i Ld_i + F_c,i tanh(Ld_i / v_c) at the'
     ' leg rate Ld_i (a smooth Coulomb law).',
     (('double', 'viscous', 6, 'F_v of each leg, N s/m'), ('double', 'coulomb', 6, 'F_c of each leg, N'),
      ('double', 'velocity', 0, 'v_c > 0, m/s'))),
    ('stewart_loop', 'A controller and its actuators (stewart_loop_derivative): the commanded forces, each'
     ' saturated at +-force_limit, act on the legs less the legs\' friction.',
     (('int', 'mode', 0, 'STEWART_OPEN_LOOP, STEWART_PID or STEWART_COMPUTED_TORQUE'),
      ('double', 'kp', 6, 'PID: N/m per leg; computed torque: 1/s^2 per pose coordinate'),
      ('double', 'ki', 6, 'PID: N/(m s) per leg'),
      ('double', 'kd', 6, 'PID: N s/m per leg; computed torque: 1/s per pose coordinate'),
      ('double', 'force_limit', 6, 'N, > 0 (may be infinite)'),
      ('stewart_friction', 'friction', 0, 'what the legs lose'),
      ('stewart_friction', 'model_friction', 0, 'what computed torque adds back at the measured leg rates'))),
)


#: The constants of the closed loop: (name, value, doc).
LOOP_CONSTANTS = (
    ('STEWART_OPEN_LOOP', 0, 'the commanded forces are the feed-forward'),
    ('STEWART_PID', 1, 'joint-space PID on the leg lengths, plus the feed-forward'),
    ('STEWART_COMPUTED_TORQUE', 2, 'task-space computed torque with the model\'s friction, plus the feed-forward'),
    ('STEWART_STOP_LEG_SHORT', -1, 'stewart_loop_rk4: a leg shorter than min_length'),
    ('STEWART_STOP_LEG_LONG', -2, 'stewart_loop_rk4: a leg longer than max_length'),
    ('STEWART_STOP_NONFINITE', -3, 'stewart_loop_rk4: a state that is not finite'),
)


#: The public functions of the actuators and the closed loop (codegen/templates/control.c):
#: (name, parameter list, doc).
LOOP_FUNCTIONS = (
    ('friction_forces', 'const stewart_friction *f, const double *Ld, double *friction',
     'The force each leg loses to friction at the leg rates Ld (6 doubles): friction_i = F_v,i Ld_i'
     ' + F_c,i tanh(Ld_i / v_c), summed from +0, the Coulomb term only where F_c,i != 0.'
     '  STEWART_ERR_NONFINITE if f or a force is not finite.'),
    ('batch_friction_forces', 'const stewart_friction *f, size_t n, const double *Ld, double *friction, int *status',
     'stewart_friction_forces on n rows (as the batch functions below).'),
    ('loop_derivative', 'const stewart_params *p, const stewart_loop *loop, const double *y, const double *ref,'
     ' const double *feedforward, double *ydot, double *force, double *L, double *Ld',
     'The closed loop as one ODE: ydot (18) at the state y = [x; xd; e] (18; e the integral of the leg-length'
     ' error L_r - L of the PID) for the reference ref = [x_r; xd_r; xdd_r] (18) and the feed-forward forces (6),'
     ' with the commanded forces (before saturation and friction), the leg lengths L and rates Ld at y.'
     '  PID: force = kp (L_r - L) + ki e + kd (Ld_r - Ld) + feedforward, de/dt = L_r - L; computed torque:'
     ' force = stewart_inverse_dynamics(x, xd, xdd_r + kd (xd_r - xd) + kp (x_r - x)) + model friction at Ld'
     ' + feedforward; open loop: force = feedforward.  The legs receive the force saturated at +-force_limit'
     ' less their friction (stewart_friction_forces); xdd = stewart_forward_dynamics of it.  Returns the status'
     ' of the first model function that fails (the outputs are then not all set).'),
    ('loop_rk4', 'const stewart_params *p, const stewart_loop *loop, double *y, const double *refs,'
     ' const double *feedforward, double dt, size_t start, size_t stop, double min_length, double max_length,'
     ' double *states, double *forces, double *lengths, double *rates, size_t *step, int *leg',
     'Classic fixed-step RK4 of stewart_loop_derivative (the stages of stewart_rk4_step), y (18) advanced'
     ' in place from step start to stop: refs (rows of 18) and feedforward (rows of 6) on the half-step grid'
     ' (row 2k at t_k, 2k + 1 at t_k + dt/2); row k of states (18), forces, lengths and rates (6) receives'
     ' y, the commanded forces, L and Ld at t_k.  Stops after a step whose state is not finite'
     ' (STEWART_STOP_NONFINITE) or has a leg outside [min_length, max_length] (STEWART_STOP_LEG_SHORT,'
     ' STEWART_STOP_LEG_LONG, *leg that leg, else -1), or at a step whose derivative fails (its status);'
     ' *step is the step it stopped at (stop when it ran through).  Returns STEWART_OK or the reason.'),
)


def _loop_types():
    """The C of `LOOP_CONSTANTS` and `LOOP_TYPES`."""
    width = max(len(name) for name, _, _ in LOOP_CONSTANTS) + 1
    text = ''.join(f'#define {name:<{width}}{f"({value})" if value < 0 else value:<5}/* {doc} */\n'
                   for name, value, doc in LOOP_CONSTANTS) + '\n'
    for name, doc, members in LOOP_TYPES:
        text += comment(doc) + 'typedef struct {\n' + aligned(
            [(f'{ctype} {member}{f"[{n}]" if n else ""};', mdoc) for ctype, member, n, mdoc in members])
        text += f'}} {name};\n\n'
    return text


def comment(doc):
    """`doc` as a C comment, wrapped at 100 columns."""
    return textwrap.fill(f'/* {doc} */', 100, subsequent_indent=' * ', break_on_hyphens=False) + '\n'


def loop_header():
    """The header's section of the actuators and the closed loop: types, constants, functions."""
    return ('/* ---- actuators and the closed loop (stewart.simulate) ---- */\n\n' + _loop_types()
            + ''.join(comment(doc) + f'int stewart_{name}({args});\n' for name, args, doc in LOOP_FUNCTIONS))


def loop_pxd():
    """The Cython declarations of `LOOP_CONSTANTS` and `LOOP_TYPES` (in a `cdef extern` block)."""
    lines = ['    enum:'] + [f'        {name}' for name, _, _ in LOOP_CONSTANTS]
    for name, _, members in LOOP_TYPES:
        lines.append(f'    ctypedef struct {name}:')
        lines += [f'        {ctype} {member}{f"[{n}]" if n else ""}' for ctype, member, n, _ in members]
    return '\n'.join(lines)


def aligned(lines):
    """C lines (code, comment) with the comments aligned."""
    width = max(len(code) for code, doc in lines if doc) + 2
    return ''.join(f'    {code:<{width}}/* {doc} */\n' if doc else f'    {code}\n' for code, doc in lines)


def arguments(function, sizes):
    """The parameter list of a `model.Function`: its arrays `x[6]`, or `*x` without `sizes`."""
    array = (lambda name, n: f'{name}[{n}]') if sizes else (lambda name, n: f'*{name}')
    args = ['const stewart_params *p'] + [f'const double {array(name, 6)}' for name in function.inputs]
    args += [f'double {name}' for name in function.scalars]
    args += [f'double {array(name, size)}' for name, size in function.sizes]
    return ', '.join(args)


def prototype(function, sizes=True):
    """`int stewart_<name>(const stewart_params *p, ...)` of a `model.Function`; its
    arrays `x[6]`, or `*x` without `sizes`."""
    return f'int stewart_{function.name}({arguments(function, sizes)})'


def batch_arguments(function):
    """The parameter list of a batch function: `p`, the row count `n`, the row-major arrays,
    the scalars and the per-row statuses."""
    args = (['const stewart_params *p', 'size_t n'] + [f'const double *{name}' for name in function.inputs]
            + [f'double {name}' for name in function.scalars]
            + [f'double *{name}' for name, _ in function.sizes] + ['int *status'])
    return ', '.join(args)


def batch_prototype(function):
    """`int stewart_batch_<name>(const stewart_params *p, size_t n, ..., int *status)`."""
    return f'int stewart_batch_{function.name}({batch_arguments(function)})'


#: The table's entries for the fixed public functions (codegen/templates/public.c,
#: `conditions`, `LOOP_FUNCTIONS`), before those of `model.FUNCTIONS`: (name, pointer declaration).
FIXED_ENTRIES = (('status_message', 'const char *(*status_message)(int status)'),
                 ('is_axisymmetric', 'int (*is_axisymmetric)(const stewart_params *p)'),
                 ('is_paper_model', 'int (*is_paper_model)(const stewart_params *p)'),
                 ('batch_lanes', 'int (*batch_lanes)(void)')) + tuple(
    (name, f'int (*{name})({args})') for name, args, _ in LOOP_FUNCTIONS)


def table_entries(functions):
    """(name, pointer declaration `int (*name)(...)`) of every public function: the fixed ones,
    then the `functions` (`model.Function`s), then their batch functions."""
    return (list(FIXED_ENTRIES) + [(f.name, f'int (*{f.name})({arguments(f, False)})') for f in functions]
            + [(f'batch_{f.name}', f'int (*batch_{f.name})({batch_arguments(f)})') for f in functions])
