"""What a motion-cueing controller predicts of the platform (Lopes & Pires 2011; see
`kinematics`): the joints' angles against their cones and the signals a rider at {P}'s
origin senses, each with its exact partials (forward mode on the definitions, `Graph.partials`).

* The cosines of the universal- and spherical-joint angles: leg i's unit vector u_i (eq. 26)
  against its neutral axis a_i, fixed in {B} for the universal joint (u_i . a_i) and in {P}
  for the spherical joint (u_i . R a_i).  The axes are inputs, three rows (their x, y and z
  components, one column per leg), so that any neutral axes serve.
* The rider's specific force f = R^T (a + g e_z), with a the acceleration of {P}'s origin
  (the pose accelerations' first three), and angular velocity w = R^T J_A [psi', theta',
  phi'] (eq. 8), both in {P}.
"""

import sympy as sp

from .graph import Graph, KernelSpec, dot, symbols
from .kinematics import PARAMS, X, XD, XDD, kinematics, leg_checks

#: The neutral axes' components: AXES_IN[c][i] is component c of leg i's axis a_i.
AXES_IN = tuple(symbols(f'a{c}', 6) for c in 'xyz')


def joint_cosines_kernel():
    """c = [u_i . a_i; u_i . R a_i] (12) of the universal and spherical joints and dc/dx
    (12 x 6, row-major), u_i = l_i / |l_i| (eq. 26)."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    axes = [sp.Matrix([AXES_IN[c][i] for c in range(3)]) for i in range(6)]
    spherical = [g.vector(f'Ra{i}', kin.R * a) for i, a in enumerate(axes)]
    cosines = ([g.define(f'cu{i}', dot(leg.u, a)) for i, (leg, a) in enumerate(zip(kin.legs, axes))]
               + [g.define(f'cs{i}', dot(leg.u, ra)) for i, (leg, ra) in enumerate(zip(kin.legs, spherical))])
    gradient = g.partials(cosines, X, 'x')
    return KernelSpec('joint_cosines', joint_cosines_kernel.__doc__, g,
                      [('x', X)] + [(f'a{c}', AXES_IN[k]) for k, c in enumerate('xyz')],
                      [('c', cosines), ('dc_dx', [d for row in gradient for d in row])] + leg_checks(kin))


def rider_signals_kernel():
    """y = [f; w] (6): the specific force f = R^T (a + g e_z) and the angular velocity w =
    R^T J_A [psi', theta', phi'] (eq. 8) in {P}, and their Jacobians (6 x 6 each, row-major)
    in the pose x, its rates xd and its accelerations xdd."""
    g = Graph({})
    kin = kinematics(g, PARAMS)
    force = kin.R.T * sp.Matrix([XDD[0], XDD[1], XDD[2] + PARAMS.g])
    omega = kin.R.T * (kin.J_A * sp.Matrix(XD[3:]))
    y = [g.define(f'y{k}', e) for k, e in enumerate(list(force) + list(omega))]
    flat = lambda rows: [d for row in rows for d in row]  # noqa: E731
    return KernelSpec('rider_signals', rider_signals_kernel.__doc__, g, [('x', X), ('xd', XD), ('xdd', XDD)],
                      [('y', y), ('dy_dx', flat(g.partials(y, X, 'x'))), ('dy_dxd', flat(g.partials(y, XD, 'v'))),
                       ('dy_dxdd', flat(g.partials(y, XDD, 'u')))])
