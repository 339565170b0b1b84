"""The singularity policy: every condition under which the model is undefined, in one table.

One row per C status code, in order from 0: its name, the enum's comment, the message of
`stewart_status_message`, its tolerance (a `#define STEWART_<...>_TOL`, where it has one)
and the exact test it stands for.  The generator emits from this table the header's enum,
the tolerance macros and their documentation, `stewart_status_message`, the Cython
declarations, and the Python table `CONDITIONS` of stewart/_generated.py (`pymodule`), from
which `stewart.model.conditions` reads the tolerances.  The tests themselves are written once in C
(codegen/templates/runtime.c: check_legs, check_euler; `linsolve`: the two solvers) and once
in numpy (`stewart.model.conditions`), each after the `test` given here.

Precedence, the same in C and Python: non-finite inputs; then the legs (a zero-length leg,
then an overflowing one, then a vertical one, then one in gimbal lock); then each function's steps in order
(inverse dynamics: J_C; forward dynamics: the Euler-rate map, then M_t); last a non-finite
result.
"""

import textwrap
from dataclasses import dataclass


@dataclass(frozen=True)
class Condition:
    """One status code of the C model."""
    name: str             # its name in Python (`SingularityError.condition`)
    doc: str              # the comment of its enum constant
    message: str          # what `stewart_status_message` returns for it
    test: str = ''        # the exact test, with its tolerance macro
    tolerance: str = ''   # the value of its tolerance macro (a C expression), if any
    macro: str = ''       # the name of its tolerance macro, if any

    @property
    def enum(self):
        """The C enum constant: STEWART_OK, STEWART_ERR_<NAME>."""
        return 'STEWART_OK' if self.name == 'ok' else f'STEWART_ERR_{self.name.upper()}'


CONDITIONS = (
    Condition('ok', '', 'ok'),
    Condition('nonfinite', 'non-finite input (or output)', 'non-finite input or output',
              'an input, a leg length L_i^2 or an output is NaN or inf'),
    Condition('leg_degenerate', 'a leg of zero length', 'a leg has zero length',
              'L_i^2 < STEWART_DEGENERATE_TOL (m^2)', 'DBL_MIN', 'STEWART_DEGENERATE_TOL'),
    Condition('jacobian_singular', 'J_C singular (kinematic singularity)',
              'leg Jacobian J_C is singular (kinematic singularity)',
              '|det J_C| / prod_i |row_i(J_C)| < STEWART_JACOBIAN_TOL (Hadamard ratio, invariant to '
              'scaling the leg rows)', '1e-12', 'STEWART_JACOBIAN_TOL'),
    Condition('euler_singular', 'theta = +-90 deg: Euler-rate map J_A singular (forward dynamics)',
              'theta = +-90 deg: the Euler-rate map J_A is singular',
              '|cos(theta)| < STEWART_EULER_TOL', '1e-12', 'STEWART_EULER_TOL'),
    Condition('leg_vertical', 'vertical leg with non-axisymmetric leg inertia: cylinder frame undefined',
              'vertical leg with non-axisymmetric leg inertia: cylinder frame undefined',
              'l_x^2 + l_y^2 < STEWART_VERTICAL_TOL * L_i^2 for a leg vector l_i (general kernels only)',
              '1e-16', 'STEWART_VERTICAL_TOL'),
    Condition('mass_singular', 'twist-space mass matrix not positive definite (e.g. massless platform)',
              'twist-space mass matrix is not positive definite',
              'an LDL^T pivot d_k of M_t <= STEWART_MASS_TOL * M_t[k][k], or M_t[k][k] <= 0 '
              '(invariant to unit changes)', '1e-12', 'STEWART_MASS_TOL'),
    Condition('gimbal_lock', "a leg along its universal joint's first axis (general model)",
              "a leg is along its universal joint's first axis (gimbal lock)",
              '|a_i x l_i|^2 < STEWART_GIMBAL_TOL * L_i^2 for a joint axis a_i and leg vector l_i '
              '(general model only)', '1e-16', 'STEWART_GIMBAL_TOL'),
)


def tolerances():
    """The header's documentation of every test and its `#define STEWART_*_TOL`s."""
    width = max(len(c.enum) for c in CONDITIONS) - len('STEWART_ERR_') + 2
    docs = ''.join(f' *  {c.enum[len("STEWART_ERR_"):]:<{width}}'
                   + f'\n *  {"":<{width}}'.join(textwrap.wrap(c.test + '.', 80)) + '\n'
                   for c in CONDITIONS if c.test)
    defines = ''.join(f'#define {c.macro} {c.tolerance}\n' for c in CONDITIONS if c.macro)
    order = (' * In order: the inputs, then the legs (zero length, overflow, vertical, gimbal lock), then each\n'
             " * function's steps (J_C; or cos(theta), then M_t), last the output.\n")
    return f'/* The tests behind the status codes:\n{docs}{order} */\n{defines}'


def status_message():
    """C text of `stewart_status_message`."""
    cases = ''.join(f'    case {c.enum}: return "{c.message}";\n' for c in CONDITIONS)
    return ('const char *stewart_status_message(int status)\n{\n    switch (status) {\n' + cases
            + '    default: return "unknown status";\n    }\n}\n')


def pxd_declarations():
    """Cython lines (inside `cdef extern from "stewart_model.h"`) of the enum and the macros."""
    return ['    enum:'] + [f'        {c.enum}' for c in CONDITIONS] + [
        f'    const double {c.macro}' for c in CONDITIONS if c.macro]

