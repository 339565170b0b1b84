"""The parameter schema: which fields of a `stewart.PlatformParams` reach the C model.

One entry per member of the C struct `stewart_params`, in struct order.  The generator
derives everything that depends on the layout from this table: the struct in
`stewart_model.h`, its finiteness check, the Cython declaration and the copy from a
`PlatformParams` in `stewart_model.pxd`, and the parameter symbols of the derivation
(`kinematics.PARAMS`).  Adding a parameter means adding a row here (and its use in
`model`), nothing else.
"""

from dataclasses import dataclass
from itertools import product


@dataclass(frozen=True)
class ParamField:
    """One `stewart_params` member: a double, or an array of doubles."""
    name: str        # the `PlatformParams` field and the struct member
    attr: str        # its attribute of `kinematics.Params` (the symbols of the derivation)
    shape: tuple     # () for a scalar, (n,) or (n, m) for an array
    doc: str = ''    # its C comment
    symbol: str = None   # prefix of its symbol names in the C (default: `attr`)
    source: str = None   # the `PlatformParams` attribute (field or property) it is copied from
    field: str = None    # the `PlatformParams` field it stands for (default: `name`)

    @property
    def size(self):
        """Number of doubles."""
        n = 1
        for d in self.shape:
            n *= d
        return n

    def indices(self):
        """Index tuples of the entries, row-major."""
        return list(product(*map(range, self.shape)))

    def member(self, index=()):
        """The C member, or one entry of it (`base_points[1][2]`)."""
        return self.name + ''.join(f'[{i}]' for i in index)

    def declaration(self):
        """The C declaration of the member (`double base_points[6][3];`)."""
        return f'double {self.name}{"".join(f"[{d}]" for d in self.shape)};'


PARAM_FIELDS = (
    ParamField('base_points', 'base', (6, 3), 'b_i in {B}', symbol='b'),
    ParamField('platform_points', 'plat', (6, 3), 'p_i in {P}', symbol='pp'),
    ParamField('platform_mass', 'm_P', ()),
    ParamField('platform_inertia', 'I_P', (3,), 'Ixx, Iyy, Izz in {P} about the centre of mass',
               source='platform_inertia_diagonal'),
    ParamField('platform_inertia_products', 'I_Pp', (3,), 'Ixy, Ixz, Iyz (tensor entries) in {P}',
               source='platform_inertia_products', field='platform_inertia'),
    ParamField('platform_com', 'c_P', (3,), 'the centre of mass in {P}', symbol='cP',
               source='platform_com_in_model'),
    ParamField('cylinder_mass', 'm_C', ()),
    ParamField('cylinder_inertia', 'I_C', (3,), 'axial, Iyy, Izz in {C_i}', source='cylinder_inertia_in_model'),
    ParamField('cylinder_com_distance', 'b_C', (), 'b_C from B_i along the leg'),
    ParamField('piston_mass', 'm_S', ()),
    ParamField('piston_inertia', 'I_S', (3,), 'axial, Iyy, Izz in {S_i}', source='piston_inertia_in_model'),
    ParamField('piston_com_distance', 'b_S', (), 'b_S from P_i back along the leg'),
    ParamField('gravity', 'g', (), 'm/s^2 along -z'),
    ParamField('universal_joint_axes', 'axes', (6, 3),
               'a_i in {B}, the first axis of each universal joint; all zero (and platform_com zero, '
               'the products zero): the paper\'s model, whose legs do not spin (eq. 29)',
               symbol='a', source='universal_joint_axes_in_model'),
    ParamField('spinless_legs', 'spinless', (),
               'nonzero: the legs do not spin with their joints (eq. 29) whatever universal_joint_axes hold '
               '(a_i = z standing for the leg frames of eqs. 44-47 in a model with the platform\'s centre of mass '
               'or products of inertia given), so the regressor\'s columns of their axial moments are zero; '
               '0: they spin about the a_i given',
               source='spinless_legs_in_model', field='universal_joint_axes'),
    ParamField('coulomb_velocity', 'v_c', (), 'v_c > 0, m/s: the smooth sign tanh(Ld / v_c) of the Coulomb '
               'friction of a leg moving at Ld (the regressor)'),
    ParamField('leg_length_offsets', 'delta', (6,), 'delta_i, m: encoder zero offsets, the true leg length '
               'the encoder reading plus delta_i (the calibration residuals, stewart_leg_residuals)', symbol='dlt'),
)

#: `PlatformParams` fields with no member in `stewart_params`, and why.
LEFT_OUT = {
    'leg_length_limits': 'the C model has no stroke limits (compare stewart_leg_lengths() with them)',
    'universal_joint_max_angle': 'a workspace bound, checked in Python (stewart.model.reachability)',
    'spherical_joint_max_angle': 'a workspace bound, checked in Python (stewart.model.reachability)',
    'leg_diameter': 'a workspace bound, checked in Python (stewart.model.reachability)',
    'plate_radius': 'a workspace bound, checked in Python (stewart.model.reachability)',
    'base_clearance': 'a workspace bound, checked in Python (stewart.model.reachability)',
    'name': 'a label, not a model input',
    'viscous_friction': 'actuator friction: a column of the regressor (stewart_regressor), not in the rigid-body model',
    'coulomb_friction': 'actuator friction: a column of the regressor (stewart_regressor), not in the rigid-body model',
    'leg_stiffness': 'the legs as springs: the stiffness and modes (stewart.model.stiffness), not in the rigid-body model',
    'leg_damping': 'the legs as dampers: the damping ratios (stewart.model.stiffness), not in the rigid-body model',
}

#: The inertial parameters pi of the regressor (tau = Y pi, `dynamics.regressor_kernel`), in its
#: column order: per body the mass, the first moments and the second moments about a
#: point of the body fixed in it (parallel-axis form), then the legs' actuator friction.
#: (name, meaning).
RIGID_BODY_PARAMETERS = (
    ('platform.m', 'm_P'),
    ('platform.mx', 'm_P c_x, c the centre of mass in {P}'),
    ('platform.my', 'm_P c_y'),
    ('platform.mz', 'm_P c_z'),
    ('platform.Ixx', 'the inertia tensor in {P} about the origin of {P}, I_G + m_P (|c|^2 E - c c^T): xx'),
    ('platform.Ixy', 'its xy entry'),
    ('platform.Ixz', 'its xz entry'),
    ('platform.Iyy', 'its yy entry'),
    ('platform.Iyz', 'its yz entry'),
    ('platform.Izz', 'its zz entry'),
    ('cylinder.m', 'm_C (never acts: the cylinder turns about the fixed B_i)'),
    ('cylinder.mb', 'm_C b_C'),
    ('cylinder.Ixx', 'the axial moment (acts only when the legs spin with their joints)'),
    ('cylinder.Iyy', 'I_yy + m_C b_C^2, about B_i'),
    ('cylinder.Izz', 'I_zz + m_C b_C^2, about B_i'),
    ('piston.m', 'm_S'),
    ('piston.mb', 'm_S b_S'),
    ('piston.Ixx', 'the axial moment (acts only when the legs spin with their joints)'),
    ('piston.Iyy', 'I_yy + m_S b_S^2, about P_i'),
    ('piston.Izz', 'I_zz + m_S b_S^2, about P_i'),
)
FRICTION_PARAMETERS = (tuple((f'friction.viscous_{i}', f'F_v of leg {i}: F_v Ld_i, N s/m') for i in range(6))
                       + tuple((f'friction.coulomb_{i}', f'F_c of leg {i}: F_c tanh(Ld_i / v_c), N')
                               for i in range(6)))
INERTIAL_PARAMETERS = RIGID_BODY_PARAMETERS + FRICTION_PARAMETERS
