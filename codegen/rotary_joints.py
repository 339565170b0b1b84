"""The rotary rig's joints against their limits (issue 40: the workspace of a 6-RSS rig), on
the geometry of `rotary.crank_geometry` (leg i: the crank's direction u_i, the rod
n_i = P_i - c_i of length d, the crank tip's motion per unit rate t_i = r a_i x u_i).

* The rod-crank angle gamma_i, at the crank tip between the crank (from the tip back to the
  motor axis, -u_i) and the rod: cos(gamma_i) = -u_i . n_i / d; gamma = 0 where the rod folds
  back over its crank, pi where it stretches straight out from it (both singular: the rod is
  then normal to the tip's motion, n . t = 0).
* The ball joints' angles against their neutral axes: the rod's direction at a reference pose
  x0 (the rig as it is mounted, by default its home), fixed in the crank for the joint at the
  crank tip and in {P} for the joint on the platform.  In the crank's frame (u, a x u, a) the
  crank joint's axis has the components q_c = [n0 . u0, n0 . (a x u0), n0 . a] / d, at x the
  direction q_c0 u + q_c1 (a x u) + q_c2 a; the platform joint's axis is q_p = R0^T n0 / d in
  {P}, at x the direction R q_p.  The cosines are those directions dotted with n / d.
* The platform joints' heights (P_i)_z in {B}, for the platform's clearance above the base.
* The sine of the rod's tilt out of the crank's plane of motion, n_i . a_i / d: the
  misalignment of a rod end on a pin parallel to the motor axis (the usual mount on a crank or
  a servo horn), which turns freely about its pin.

And what MPC cueing holds of the rig (`rotary_cueing_rows_kernel`): the cranks' angles, rates
and reach, and these joints, each with its exact pose gradient.
"""

import sympy as sp

from .graph import Graph, KernelSpec, cross, dot, symbols
from .kinematics import NUM_LEGS, X, XD, twist
from .rotary import RPARAMS, crank_checks, rotary_kinematics

#: The neutral axes' components, leg by leg (three per leg): the crank joint's in the crank's
#: frame (u, a x u, a), the platform joint's in {P}.
QC_IN = symbols('qc', 3 * NUM_LEGS)
QP_IN = symbols('qp', 3 * NUM_LEGS)


def rotary_neutral_axes_kernel():
    """The joints' neutral axes of the rods at the reference pose x (module docstring): the
    crank joints' q_c (18, three per leg in the crank's frame (u, a x u, a)) and the platform
    joints' q_p = R^T n / d (18, three per leg in {P})."""
    g = Graph({})
    kin, cranks = rotary_kinematics(g)
    P = RPARAMS
    qc, qp = [], []
    for i, c in enumerate(cranks):
        w = c.t / P.r  # a x u
        qc += [g.define(f'qc{i}_{k}', dot(c.n, e) / P.d) for k, e in enumerate((c.u, w, P.axes[i]))]
        qp += [g.define(f'qp{i}_{k}', e) for k, e in enumerate(kin.R.T * c.n / P.d)]
    return KernelSpec('rotary_neutral_axes', rotary_neutral_axes_kernel.__doc__, g, [('x', X)],
                      [('qc', qc), ('qp', qp)] + crank_checks(cranks))


def _joints(g, kin, cranks):
    """The joints' values at the pose of `kin` for the neutral axes QC_IN, QP_IN (module
    docstring): the rod-crank cosines, the crank joints' and the platform joints' cosines, the
    platform joints' heights and the sines of the rods' tilts out of the cranks' planes, each (6)."""
    P = RPARAMS
    fold, crank_joint, platform_joint, heights, tilt = [], [], [], [], []
    for i, c in enumerate(cranks):
        qc = QC_IN[3 * i:3 * i + 3]
        qp = sp.Matrix(QP_IN[3 * i:3 * i + 3])
        axis = g.vector(f'Ac{i}', qc[0] * c.u + qc[1] * c.t / P.r + qc[2] * P.axes[i])
        fold.append(g.define(f'cg{i}', -dot(c.u, c.n) / P.d))
        crank_joint.append(g.define(f'cc{i}', dot(c.n, axis) / P.d))
        platform_joint.append(g.define(f'cp{i}', dot(c.n, kin.R * qp) / P.d))
        heights.append(g.define(f'zP{i}', kin.legs[i].l[2] + P.base[i][2]))
        tilt.append(g.define(f'st{i}', dot(c.n, P.axes[i]) / P.d))
    return fold, crank_joint, platform_joint, heights, tilt


def rotary_joint_cosines_kernel():
    """cos and sin of the crank angles (`rotary.rotary_crank_angles_kernel`), the cosines of
    the rod-crank angles, the crank joints' and the platform joints' angles (18), the platform
    joints' heights and the sines of the rods' tilts out of the cranks' planes (module
    docstring), at the pose x for the neutral axes qc, qp."""
    g = Graph({})
    kin, cranks = rotary_kinematics(g)
    fold, crank_joint, platform_joint, heights, tilt = _joints(g, kin, cranks)
    return KernelSpec('rotary_joint_cosines', rotary_joint_cosines_kernel.__doc__, g,
                      [('x', X), ('qc', QC_IN), ('qp', QP_IN)],
                      [('cs', [c.cos for c in cranks] + [c.sin for c in cranks]),
                       ('c', fold + crank_joint + platform_joint), ('z', heights), ('s', tilt)] + crank_checks(cranks))


def rotary_cueing_rows_kernel():
    """What MPC cueing holds of a rotary rig (stewart.cueing.planner), with the exact partials
    (forward mode on the definitions, `Graph.partials`, one tangent per pose coordinate shared by
    every row): cos(alpha_i) then sin(alpha_i); the crank rates alpha' = J_alpha T xd; the
    reach s_i = S_i^2 / rho_i^2 = sin^2(delta_i) (`rotary.crank_geometry`: 1 with the rod along
    the tip's motion, 0 at the edge of the reach, where J_alpha is singular); grads, three 6 x 6
    row-major: J_alpha T = d alpha' / d xd = d alpha / d x, d alpha' / d x and d s / d x; the 30
    joints of `rotary_joint_cosines_kernel` (the rod-crank, crank-joint and platform-joint
    cosines, the platform joints' heights, the sines of the rods' tilts out of the cranks'
    planes) for the neutral axes qc, qp, and their partials in x, 30 x 6 row-major."""
    g = Graph({})
    kin, cranks = rotary_kinematics(g)
    v, omega = twist(g, kin, XD, 'q')
    rates = [g.define(f'ad{i}', dot(c.j, v + cross(omega, c.r))) for i, c in enumerate(cranks)]
    reach = [g.define(f'sr{i}', c.S2 / c.rho2) for i, c in enumerate(cranks)]
    joints = [value for part in _joints(g, kin, cranks) for value in part]
    flat = lambda rows: [d for row in rows for d in row]  # noqa: E731
    by_pose = g.partials(rates + reach + joints, X, 'x')
    return KernelSpec('rotary_cueing_rows', rotary_cueing_rows_kernel.__doc__, g,
                      [('x', X), ('xd', XD), ('qc', QC_IN), ('qp', QP_IN)],
                      [('cs', [c.cos for c in cranks] + [c.sin for c in cranks]), ('ad', rates), ('reach', reach),
                       ('grads', flat(g.partials(rates, XD, 'v')) + flat(by_pose[:12])),
                       ('joints', joints), ('djoints_dx', flat(by_pose[12:]))] + crank_checks(cranks))
