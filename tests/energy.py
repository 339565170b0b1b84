"""The platform's mechanical energy, written out from the model's bodies and kinematics
(model section 3; leg angular velocity u x udot, eq. 29) independently of the dynamics
code, as an oracle for power balance and energy conservation. Axisymmetric legs only.
Analytic operations only, so complex-step differentiation applies."""

import numpy as np

import stewart


def euler_rate_jacobian(x):
    psi, theta = x[3], x[4]
    return np.array(
        [
            [0.0, -np.sin(psi), np.cos(psi) * np.cos(theta)],
            [0.0, np.cos(psi), np.sin(psi) * np.cos(theta)],
            [1.0, 0.0, -np.sin(theta)],
        ]
    )


def leg_rates(params, x, xd):
    """Unit vectors u, their rates udot and the leg length rates Ldot for one state."""
    rot = stewart.rotation(x)
    omega = euler_rate_jacobian(x) @ xd[3:]
    arms = params.platform_points @ rot.T
    legs = x[:3] + arms - params.base_points
    lengths = np.sqrt(np.sum(legs * legs, axis=1))
    units = legs / lengths[:, None]
    leg_dot = xd[:3] + np.cross(omega, arms)
    length_dot = np.sum(units * leg_dot, axis=1)
    unit_dot = (leg_dot - units * length_dot[:, None]) / lengths[:, None]
    return units, unit_dot, length_dot, leg_dot, omega, rot, arms


def energy(params, x, xd):
    """Kinetic plus potential energy (J) of platform, cylinders and pistons."""
    assert params.is_axisymmetric
    units, unit_dot, _, leg_dot, omega, rot, arms = leg_rates(params, x, xd)
    v = xd[:3]
    kinetic = 0.5 * params.platform_mass * v @ v
    kinetic += 0.5 * omega @ (rot @ np.diag(params.platform_inertia) @ rot.T) @ omega
    cyl_vel = params.cylinder_com_distance * unit_dot
    pis_vel = leg_dot - params.piston_com_distance * unit_dot
    kinetic += 0.5 * params.cylinder_mass * np.sum(cyl_vel * cyl_vel)
    kinetic += 0.5 * params.piston_mass * np.sum(pis_vel * pis_vel)
    leg_omega = np.cross(units, unit_dot)
    axial = params.cylinder_inertia[0] + params.piston_inertia[0]
    transverse = params.cylinder_inertia[1] + params.piston_inertia[1]
    along = np.sum(leg_omega * units, axis=1)
    kinetic += 0.5 * np.sum(transverse * (np.sum(leg_omega * leg_omega, axis=1) - along**2) + axial * along**2)
    heights = (
        params.platform_mass * x[2]
        + params.cylinder_mass * np.sum(params.base_points[:, 2] + params.cylinder_com_distance * units[:, 2])
        + params.piston_mass * np.sum(x[2] + arms[:, 2] - params.piston_com_distance * units[:, 2])
    )
    return kinetic + params.gravity * heights


def potential_energy(params, x):
    return energy(params, x, np.zeros(6, dtype=np.asarray(x).dtype))
