"""Stiffness, modes and compliance of the spring-legged platform (stewart.model.stiffness),
against the potential's complex-step Hessian, free oscillations simulated by stewart.simulate,
hand formulas and the textbook J^T k J model."""

import warnings

import numpy as np
import pytest
from scipy.linalg import eigh
from scipy.optimize import least_squares

import stewart
from conftest import make_general, random_params
from stewart.model.kinematics import euler_jacobian, leg_lengths, twist_transform
from stewart.oracles import frames, reference

#: A realistic leg stiffness of the 1500 kg motion simulator [N/m] and a leg damper [N s/m].
K_LEG, C_LEG = 2e7, 4e4
#: An off-home pose of the motion simulator: every coordinate moved, so every term acts.
OFFSET = np.array([0.05, -0.03, 0.04, 0.05, -0.04, 0.03])


@pytest.fixture(scope="module", params=["paper", "general"])
def case(request):
    """A platform (the motion simulator, or its general model with an off-centre payload) and a
    pose away from home."""
    params = stewart.PlatformParams.preset("motion_simulator")
    if request.param == "general":
        params = make_general(params, np.random.default_rng(28))
    plat = stewart.Platform(params)
    return plat, plat.home_pose + OFFSET


def _massless_legs(params):
    return params.replace(cylinder_mass=0.0, piston_mass=0.0, cylinder_inertia=[0.0] * 3, piston_inertia=[0.0] * 3)


def _static_forces(params, q, x, tau, k):
    """The generalized force of the preloaded springs and gravity in pose coordinates,
    ``J_E^T (tau_spring - tau_s(q))`` (``J_E^T tau_s = T^T G``), complex-friendly."""
    spring = tau + k * (frames.leg_lengths(params, x) - frames.leg_lengths(params, q))
    euler = frames.jacobian(params, q) @ frames.twist_transform(q)
    return np.einsum("ji,j->i", euler, spring - reference.inverse_dynamics(params, q, 0 * q, 0 * q))


def test_stiffness_is_the_hessian_of_the_potential(case, figures):
    """K_q against the complex-step derivative of the static generalized forces of the numeric
    reference (an independent evaluation of gravity and the leg forces), and symmetric."""
    plat, x = case
    k = K_LEG * np.array([1.0, 0.8, 1.2, 0.9, 1.1, 1.3])
    tau = plat.inverse_dynamics(x, np.zeros(6), np.zeros(6))
    h = 1e-30
    hessian = np.stack([-_static_forces(plat.params, x + 1j * h * e, x, tau, k).imag / h for e in np.eye(6)], axis=1)
    stiffness = plat.stiffness_matrix(x, k)
    scale = np.abs(hessian).max()
    figures("stiffness vs complex-step Hessian of the potential (rel.)", np.abs(stiffness - hessian).max() / scale, 1e-14)  # reached 2.3e-16
    figures("stiffness asymmetry (rel.)", np.abs(stiffness - stiffness.T).max() / scale, 5e-15)  # reached 8.1e-17
    t_inv = np.linalg.inv(twist_transform(x))
    # The coordinates named by a string made at run time (read from a file, say), not a literal.
    for name, want in (("pose", hessian), ("twist", t_inv.T @ hessian @ t_inv)):
        got = plat.stiffness_matrix(x, k, coordinates="".join(list(name)))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-14 * np.abs(want).max())  # reached 2.3e-16


def _fit(t, signal, rate, omega):
    """``(sigma, omega)`` of ``exp(sigma t) (a cos(omega t) + b sin(omega t)) + c`` fitted to ``signal``."""
    a = np.abs(signal).max()

    def residual(v):
        return np.exp(v[3] * t) * (v[0] * np.cos(v[4] * t) + v[1] * np.sin(v[4] * t)) + v[2] - signal

    fit = least_squares(residual, [signal[0], 0.0, 0.0, rate, omega], x_scale=[a, a, a, omega, omega],
                        xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return fit.x[3], fit.x[4]


def _oscillate(plat, x, x0, xd0, k, c, duration=0.3):
    """A free oscillation about ``x`` from ``(x0, xd0)`` by stewart.simulate: each leg a spring
    ``k`` about its static force and a damper ``c``, the leg PID ``tau = k (L(x) - L) - c Ldot`` plus
    the static forces as feed-forward, no actuator friction. RK4 at 0.1 ms (its frequency
    error, (w dt)^4 / 120 ~ 1e-9, is far below the bound)."""
    tau = plat.inverse_dynamics(x, np.zeros(6), np.zeros(6))
    run = stewart.simulate(plat, stewart.PointToPoint(x, x, duration), stewart.PID(kp=k, ki=0.0, kd=c), dt=1e-4,
                           feedforward=lambda t: np.tile(tau, (len(t), 1)), x0=x0, xd0=xd0,
                           actuators=stewart.Actuators(viscous=0.0, coulomb=0.0))
    assert run.outcome == "completed", run.problems
    return run.t, (run.x - x) @ twist_transform(x).T  # small twists [dp; dtheta]


def test_frequencies_match_a_simulated_free_oscillation(case, figures):
    """Started on each mode shape 1 um from the pose, the simulated platform oscillates at the
    mode's frequency (fitted on its modal coordinate), to 1e-6."""
    plat, x = case
    modes = plat.modes(x, K_LEG)
    t_inv, mass = np.linalg.inv(twist_transform(x)), plat.twist_mass_matrix(x)
    worst = 0.0
    for j in range(6):
        shape = modes.shapes[:, j] * 1e-6 / np.abs(modes.shapes[:3, j]).max()
        t, twists = _oscillate(plat, x, x + t_inv @ shape, np.zeros(6), K_LEG, 0.0)
        omega = 2 * np.pi * modes.frequencies[j]
        sigma, fitted = _fit(t, twists @ mass @ modes.shapes[:, j], 0.0, omega)
        worst = np.max([worst, abs(fitted / omega - 1), abs(sigma) / omega])
    figures("modes: frequency vs simulated free oscillation (rel.)", worst, 1e-7)  # reached 1.9e-09


def test_damping_ratios_match_the_simulated_decay(case, figures):
    """Started on each damped mode (the real part of an eigenvector of the linearized state
    matrix), the simulated platform decays at the damping ratio of ``modes``, to 1e-6."""
    plat, x = case
    modes = plat.modes(x, K_LEG, C_LEG)
    t_inv, mass, jac = np.linalg.inv(twist_transform(x)), plat.twist_mass_matrix(x), plat.jacobian(x)
    state = np.block([[np.zeros((6, 6)), np.eye(6)],
                      [-np.linalg.solve(mass, plat.stiffness_matrix(x, K_LEG, coordinates="twist")),
                       -np.linalg.solve(mass, jac.T @ (C_LEG * jac))]])
    roots, vectors = np.linalg.eig(state)
    worst, seen = 0.0, set()
    for r in np.flatnonzero(roots.imag > 0):
        j = int(np.argmax(np.abs(modes.shapes.T @ mass @ vectors[:6, r])))
        seen.add(j)
        v = vectors[:, r] * 1e-7 / vectors[np.argmax(np.abs(vectors[:3, r])), r]
        t, twists = _oscillate(plat, x, x + t_inv @ v[:6].real, t_inv @ v[6:].real, K_LEG, C_LEG)
        sigma, omega = _fit(t, twists @ mass @ modes.shapes[:, j], roots[r].real, roots[r].imag)
        worst = np.maximum(worst, abs(-sigma / np.hypot(sigma, omega) / modes.damping_ratios[j] - 1))
    assert seen == set(range(6))
    figures("modes: damping ratio vs simulated decay (rel.)", worst, 1e-6)  # reached 6.9e-08


def test_damping_ratios_of_repeated_overdamped_modes():
    """At the motion simulator's home pose the modes come in repeated pairs (its symmetry), and
    with dampers of 4e5 N s/m they are overdamped (zeta about 1.3-2): each repeated pair's
    roots are equal, their eigenvectors mix the pair's modes arbitrarily. The ratios are
    those of the quadratic eigenproblem: each mode's roots -zeta w +- w sqrt(zeta^2 - 1) are
    among the eigenvalues of the linearized state matrix, and the modal damping is nearly
    diagonal (off the diagonal: 6e-6 of it), so each ratio is d_jj / (2 w_j) (its classical
    value) to second order in the coupling. (They were NaN.)"""
    plat = stewart.Platform.preset("motion_simulator")
    x, c = plat.home_pose, 10 * C_LEG
    modes = plat.modes(x, K_LEG, c)
    omega = 2 * np.pi * modes.frequencies
    assert np.all(modes.damping_ratios > 1)
    assert abs(omega[1] / omega[0] - 1) < 1e-12  # a repeated pair
    jac = plat.jacobian(x)
    damping = np.diag(modes.shapes.T @ (c * jac.T @ jac) @ modes.shapes)
    np.testing.assert_allclose(modes.damping_ratios, damping / (2 * omega), rtol=2e-8)  # reached 2.2e-10
    mass, stiffness = plat.twist_mass_matrix(x), plat.stiffness_matrix(x, K_LEG, coordinates="twist")
    state = np.block([[np.zeros((6, 6)), np.eye(6)],
                      [-np.linalg.solve(mass, stiffness), -np.linalg.solve(mass, c * jac.T @ jac)]])
    roots = np.sort(np.linalg.eigvals(state).real)
    zeta = modes.damping_ratios
    ours = np.sort(np.concatenate([omega * (-zeta - np.sqrt(zeta**2 - 1)), omega * (-zeta + np.sqrt(zeta**2 - 1))]))
    np.testing.assert_allclose(ours, roots, rtol=2e-8)  # reached 2.2e-10


def test_modes_solve_the_generalized_eigenproblem(case):
    """``K_t phi = w^2 M_t phi`` with ``phi^T M_t phi = I``; frequencies ascending."""
    plat, x = case
    modes = plat.modes(x, K_LEG)
    mass, stiff = plat.twist_mass_matrix(x), plat.stiffness_matrix(x, K_LEG, coordinates="twist")
    omega2 = (2 * np.pi * modes.frequencies) ** 2
    np.testing.assert_allclose(modes.shapes.T @ mass @ modes.shapes, np.eye(6), atol=2e-14, rtol=2e-9)  # reached 1/42 of it
    np.testing.assert_allclose(stiff @ modes.shapes, mass @ modes.shapes * omega2, rtol=0,
                               atol=5e-14 * np.abs(stiff).max() * np.abs(modes.shapes).max())  # reached 7.3e-16 of it
    assert np.all(np.diff(modes.frequencies) >= 0)
    np.testing.assert_allclose(modes.participation().sum(axis=0), 1.0, rtol=1e-14)  # reached 1.1e-16


def _symmetric(**changes):
    """The motion simulator (a hexapod with three mirror planes), with ``changes``."""
    return stewart.PlatformParams.preset("motion_simulator").replace(**changes)


def test_vertical_mode_of_a_symmetric_platform_by_hand():
    """Massless legs, payload on the axis: the heave mode is pure ``z`` with
    ``w^2 m = sum k u_z^2 - sum tau (1 - u_z^2) / L``, ``tau = m g / (6 u_z)`` (each leg's
    spring and its preload's geometric term, ``d^2 L / dz^2 = (1 - u_z^2) / L``)."""
    params = _massless_legs(_symmetric())
    plat = stewart.Platform(params)
    x = plat.home_pose
    lengths = leg_lengths(params, x)
    u_z = (x[2] + params.platform_points[:, 2] - params.base_points[:, 2]) / lengths
    tau = params.platform_mass * params.gravity / (6 * u_z)
    heave = np.sum(K_LEG * u_z**2 - tau * (1 - u_z**2) / lengths)
    modes = plat.modes(x.tolist(), K_LEG)  # a pose as a list too
    j = modes.motions().index("translation along z")
    assert modes.participation()[2, j] > 1 - 1e-12
    # reached 0
    assert modes.frequencies[j] == pytest.approx(np.sqrt(heave / params.platform_mass) / (2 * np.pi), rel=1e-14)


def test_without_preload_and_leg_mass_the_textbook_model():
    """No gravity (no preload) and massless legs: ``K_t = J_C^T k J_C``, ``K_q = J_E^T k J_E`` and the
    modes of ``(J_C^T k J_C, M_platform)``."""
    params = _massless_legs(_symmetric(gravity=0.0))
    plat = stewart.Platform(params)
    x = plat.home_pose + OFFSET
    jac, jac_e = plat.jacobian(x), euler_jacobian(params, x)
    np.testing.assert_allclose(plat.stiffness_matrix(x, K_LEG, coordinates="twist"), K_LEG * jac.T @ jac, rtol=1e-14,
                               atol=1e-14 * K_LEG)  # reached 1/52 of it
    np.testing.assert_allclose(plat.stiffness_matrix(x, K_LEG), K_LEG * jac_e.T @ jac_e, rtol=5e-14, atol=5e-14 * K_LEG)  # reached 1/55 of it
    inertia = np.zeros((6, 6))
    inertia[:3, :3] = params.platform_mass * np.eye(3)
    rot = stewart.rotation(x)
    inertia[3:, 3:] = rot @ params.platform_inertia_tensor @ rot.T
    textbook = np.sort(np.sqrt(np.linalg.eigvals(np.linalg.solve(inertia, K_LEG * jac.T @ jac)).real)) / (2 * np.pi)
    np.testing.assert_allclose(plat.modes(x, K_LEG).frequencies, textbook, rtol=2e-14)  # reached 4.3e-16


def _heave(params, x):
    """The heave frequency [Hz] of the massless-legged ``params`` at ``x``."""
    modes = stewart.Platform(params).modes(x, 1e6)
    return modes.frequencies[modes.motions().index("translation along z")]


def test_the_preload_softens_a_standing_load_and_stiffens_a_hanging_one():
    """The geometric term is the difference between the loaded and unloaded (no gravity)
    frequencies: legs in compression under a standing load soften the heave mode, legs in tension
    under a hanging one (the platform below the base) stiffen it, by the hand formula's term."""
    params = _massless_legs(_symmetric())
    standing = stewart.Platform(params).home_pose
    hanging = standing * [1, 1, -1, 1, 1, 1]
    for x, sign in ((standing, -1), (hanging, 1)):
        loaded, unloaded = _heave(params, x), _heave(params.replace(gravity=0.0), x)
        assert np.sign(loaded - unloaded) == sign
        lengths = leg_lengths(params, x)
        u_z = (x[2] - params.base_points[:, 2]) / lengths
        tau = params.platform_mass * params.gravity / (6 * u_z)
        geometric = -np.sum(tau * (1 - u_z**2) / lengths)
        mass = params.platform_mass * (2 * np.pi) ** 2
        assert loaded**2 - unloaded**2 == pytest.approx(geometric / mass, rel=5e-12)  # reached 1.0e-13


def test_a_batch_gives_each_rows_result_and_a_mask(case):
    plat, x = case
    poses = x + np.random.default_rng(1).uniform(-0.03, 0.03, (5, 6))
    batch = plat.modes(poses, K_LEG, C_LEG)
    # Each mode's share of each axis: the squares of [dp; r dtheta], r the largest joint radius.
    radius = np.max(np.linalg.norm(plat.params.platform_points, axis=1))
    scaled = batch.shapes * np.array([1, 1, 1, radius, radius, radius])[:, None]
    shares = scaled**2 / np.sum(scaled**2, axis=1, keepdims=True)
    np.testing.assert_allclose(batch.participation(), shares, rtol=1e-14)  # reached: equal
    for i, pose in enumerate(poses):
        one = plat.modes(pose, K_LEG, C_LEG)
        # reached 0 in all four
        np.testing.assert_allclose(batch.frequencies[i], one.frequencies, rtol=1e-14)
        np.testing.assert_allclose(batch.damping_ratios[i], one.damping_ratios, rtol=1e-14)
        np.testing.assert_allclose(plat.compliance(poses, K_LEG)[i], plat.compliance(pose, K_LEG), rtol=1e-14)
        np.testing.assert_allclose(plat.stiffness_matrix(poses, K_LEG)[i], plat.stiffness_matrix(pose, K_LEG), rtol=1e-14)
    poses[2, 2] = 0.0  # in the base plane: J_C singular
    modes, ok = plat.modes(poses, K_LEG, return_mask=True)
    assert ok.tolist() == [True, True, False, True, True]
    assert np.isnan(modes.frequencies[2]).all() and np.isfinite(modes.frequencies[ok]).all()
    lowest, ok2 = stewart.model.stiffness.lowest_frequency(plat, poses, K_LEG, return_mask=True)
    np.testing.assert_array_equal(ok2, ok)
    np.testing.assert_allclose(lowest[ok], modes.frequencies[ok, 0], rtol=1e-14)  # reached 0


def test_compliance_is_the_displacement_under_a_wrench(case):
    """The displacement of a point of the platform under a wrench there, from the pose-coordinate
    stiffness: ``dq = K_q^-1 T^T [f; m + r x f]``, ``dp_c = dp + dtheta x r``."""
    plat, x = case
    point = np.array([0.2, -0.1, 0.6])
    matrix = plat.compliance(x, K_LEG, point=point)
    arm = stewart.rotation(x) @ point
    wrench = np.array([30.0, -20.0, 50.0, 4.0, -7.0, 3.0])
    dq = np.linalg.solve(plat.stiffness_matrix(x, K_LEG),
                         twist_transform(x).T @ np.concatenate([wrench[:3], wrench[3:] + np.cross(arm, wrench[:3])]))
    twist = twist_transform(x) @ dq
    expected = np.concatenate([twist[:3] + np.cross(twist[3:], arm), twist[3:]])
    np.testing.assert_allclose(matrix @ wrench, expected, rtol=5e-15, atol=5e-15 * np.abs(expected).max())  # reached 1/33 of it
    np.testing.assert_allclose(matrix, matrix.T, rtol=0, atol=5e-15 * np.abs(matrix).max())  # reached 9.7e-17
    assert np.linalg.eigvalsh(matrix).min() > 0


def test_named_motions_at_home():
    """The symmetric platform at home: one heave and one yaw mode, two pairs of equal frequency."""
    plat = stewart.Platform.preset("motion_simulator")
    modes = plat.modes(plat.home_pose, K_LEG)
    names = modes.motions()
    assert sorted(names) == sorted(stewart.model.stiffness.MOTION_AXES)
    assert modes.frequencies[0] == pytest.approx(modes.frequencies[1], rel=1e-13)  # reached 0


@pytest.mark.parametrize("kwargs, message", [
    ({"stiffness": 0.0}, "stiffness: must be finite and > 0"),
    ({"stiffness": [1e7] * 5 + [-1.0]}, "stiffness: must be finite and > 0"),
    ({"stiffness": [1e7] * 4}, r"stiffness: expected one value or one per leg \(6\)"),
    ({"stiffness": np.nan}, "stiffness: must be finite"),
    ({"stiffness": np.inf}, r"stiffness: must be finite and > 0 on every leg, got \[inf, "),
    ({"stiffness": -2e7}, r"stiffness: must be finite and > 0 on every leg, got \[-20000000.0, "),
    ({"stiffness": 1e7, "damping": -1.0}, "damping: must be finite and >= 0"),
    ({"stiffness": "stiff"}, "stiffness: expected"),
])
def test_bad_coefficients_are_one_line_errors(kwargs, message):
    plat = stewart.Platform.preset("motion_simulator")
    with pytest.raises(ValueError, match=message) as info:
        plat.modes(plat.home_pose, **kwargs)
    assert "\n" not in str(info.value)


def test_an_undefined_pose_names_the_condition_of_the_model_at_rest():
    """Where the model is undefined, modes names the condition that inverse_dynamics_derivatives
    at rest names: a leg of zero length, and a vertical leg of the paper's model with legs of
    I_yy != I_zz, whose leg frames are undefined there (the statics alone are defined: the
    condition comes from M_t, which holds the legs' inertia)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        params = random_params(np.random.default_rng(5), axisymmetric=False)
    plat = stewart.Platform(params)
    leg = params.base_points[0] - params.platform_points[0]
    poses = {"leg_degenerate": np.r_[leg, 0, 0, 0], "leg_vertical": np.r_[leg + [0, 0, plat.home_pose[2]], 0, 0, 0]}
    for condition, x in poses.items():
        with pytest.raises(stewart.SingularityError) as dynamics:
            plat.inverse_dynamics_derivatives(x, np.zeros(6), np.zeros(6))
        with pytest.raises(stewart.SingularityError, match="^modes: ") as modes:
            plat.modes(x, K_LEG)
        assert dynamics.value.condition == modes.value.condition == condition


def test_a_singular_pose_and_a_pose_that_cannot_be_held():
    plat = stewart.Platform.preset("motion_simulator")
    with pytest.raises(stewart.SingularityError,
                       match=r"^modes: leg Jacobian J_C is singular \(kinematic singularity\)$") as info:
        plat.modes(np.zeros(6), K_LEG)
    assert info.value.condition == "jacobian_singular"
    with pytest.raises(stewart.SingularityError, match=r"^compliance: .*theta") :
        plat.compliance(plat.home_pose + [0, 0, 0, 0, np.pi / 2, 0], K_LEG)
    # Legs of 10 kN/m under 1.5 t hold it at home; 0.3 m aside the preload's geometric term wins.
    poses = np.stack([plat.home_pose, plat.home_pose + [0.3, 0, 0, 0, 0, 0]])
    with pytest.raises(stewart.UnstableError, match=r"^modes: the preloaded legs cannot hold the pose at row\(s\) \[1\]"):
        plat.modes(poses, 1e4)
    with pytest.raises(stewart.UnstableError, match=r"^compliance: the preloaded legs cannot hold the pose: "):
        plat.compliance(poses[1], 1e4)
    assert plat.modes(poses, 1e4, return_mask=True)[1].tolist() == [True, False]
    with pytest.raises(ValueError, match="point: expected three finite coordinates"):
        plat.compliance(plat.home_pose, K_LEG, point=[0, 0])
    with pytest.raises(ValueError, match="coordinates: expected 'pose' or 'twist'"):
        plat.stiffness_matrix(plat.home_pose, K_LEG, coordinates="euler")


def test_the_stiffness_is_given_where_the_legs_cannot_hold_the_pose():
    """0.3 m aside on legs of 10 kN/m (above): the stiffness matrix is given there, the potential's
    complex-step Hessian, with a negative eigenvalue; where the model is undefined it is refused
    naming the row, or NaN and masked."""
    plat = stewart.Platform.preset("motion_simulator")
    x = plat.home_pose + [0.3, 0, 0, 0, 0, 0]
    tau = plat.inverse_dynamics(x, np.zeros(6), np.zeros(6))
    h = 1e-30
    hessian = np.stack([-_static_forces(plat.params, x + 1j * h * e, x, tau, 1e4).imag / h for e in np.eye(6)], axis=1)
    assert np.linalg.eigvalsh(hessian).min() < 0
    poses = np.stack([x, np.zeros(6)])
    stiffness, ok = plat.stiffness_matrix(poses, 1e4, return_mask=True)
    assert ok.tolist() == [True, False] and np.isnan(stiffness[1]).all()
    np.testing.assert_allclose(stiffness[0], hessian, rtol=0, atol=1e-14 * np.abs(hessian).max())  # reached 5.9e-16
    with pytest.raises(stewart.SingularityError, match=r"^stiffness_matrix: leg Jacobian J_C is singular "
                                                        r"\(kinematic singularity\) at row\(s\) \[1\]$"):
        plat.stiffness_matrix(poses, 1e4)


def test_modal_metrics_where_the_legs_hold_the_pose_or_not():
    """On legs of 10 kN/m (above): at home the lowest frequency of ``K_t phi = w^2 M_t phi``
    (scipy, the numeric reference's ``M_t``) and the largest deflection per newton of a point
    under a force there (the spectral norm of the map from force to displacement, from ``K_q`` as
    in the compliance test); NaN and masked 0.3 m aside, where the legs cannot hold the pose, and
    where the model is undefined."""
    plat = stewart.Platform.preset("motion_simulator")
    x, point = plat.home_pose, np.array([0.2, -0.1, 0.6])
    poses = np.stack([x, x + [0.3, 0, 0, 0, 0, 0], np.zeros(6)])
    lowest, largest, ok = stewart.model.stiffness.modal_metrics(plat, poses, 1e4, point)
    assert ok.tolist() == [True, False, False] and np.isnan(lowest[1:]).all() and np.isnan(largest[1:]).all()
    omega2 = eigh(plat.stiffness_matrix(x, 1e4, coordinates="twist"), reference.twist_mass_matrix(plat.params, x),
                  eigvals_only=True)
    assert lowest[0] == pytest.approx(np.sqrt(omega2[0]) / (2 * np.pi), rel=1e-13)  # reached 4.4e-16
    arm, transform = stewart.rotation(x) @ point, twist_transform(x)
    deflections = []
    for force in np.eye(3):
        twist = transform @ np.linalg.solve(plat.stiffness_matrix(x, 1e4),
                                            transform.T @ np.concatenate([force, np.cross(arm, force)]))
        deflections.append(twist[:3] + np.cross(twist[3:], arm))
    assert largest[0] == pytest.approx(np.linalg.norm(np.array(deflections), 2), rel=1e-13)  # reached 2.2e-16


def test_the_legs_stiffness_and_damping_as_parameters(tmp_path):
    """``leg_stiffness`` and ``leg_damping`` of the parameters are the defaults (one value or six,
    through a parameter file); without them the functions need a stiffness."""
    params = stewart.PlatformParams.preset("motion_simulator")
    assert params.leg_stiffness is None and params.leg_damping is None
    springy = params.replace(leg_stiffness=K_LEG, leg_damping=[C_LEG] * 6)
    springy.save(tmp_path / "p.toml")
    loaded = stewart.PlatformParams.load(tmp_path / "p.toml")
    np.testing.assert_array_equal(loaded.leg_stiffness, np.full(6, K_LEG))
    plat, x = stewart.Platform(loaded), stewart.Platform(loaded).home_pose
    own, given = plat.modes(x), stewart.Platform(params).modes(x, K_LEG, C_LEG)
    np.testing.assert_array_equal(own.frequencies, given.frequencies)
    np.testing.assert_array_equal(own.damping_ratios, given.damping_ratios)
    np.testing.assert_array_equal(plat.compliance(x), stewart.Platform(params).compliance(x, K_LEG))
    with pytest.raises(ValueError, match=r"^stiffness: none given, and the parameters have no leg_stiffness"):
        stewart.Platform(params).modes(x)
    with pytest.raises(ValueError, match=r"^leg_stiffness: must be finite and > 0"):
        params.replace(leg_stiffness=[1e7] * 5 + [0.0])
    with pytest.raises(ValueError, match=r"^leg_damping: expected one value or one per leg"):
        params.replace(leg_damping=[1.0, 2.0])


def test_threads_and_blocks_give_the_same_bits(case):
    """A batch over several blocks of the compiled loop on two threads, against one thread and
    against each pose alone: the same frequencies and shapes, bit for bit."""
    plat, x = case
    poses = x + np.random.default_rng(3).uniform(-0.02, 0.02, (100, 6))
    both = stewart.Platform(plat.params, threads=2).modes(poses, K_LEG)
    one = plat.modes(poses, K_LEG)
    np.testing.assert_array_equal(both.frequencies, one.frequencies)
    np.testing.assert_array_equal(both.shapes, one.shapes)
    for i in (0, 31, 32, 99):  # the first and last rows of the blocks of 32
        alone = plat.modes(poses[i], K_LEG)
        np.testing.assert_array_equal(alone.frequencies, one.frequencies[i])
