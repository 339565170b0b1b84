"""The rotary family (issue 40) against the independent model of tests/rotary_oracle.py on
random asymmetric rigs (tilted motor axes, axes reversed, a payload off-centre with a full
tensor), against complex-step derivatives, and by hand on symmetric rigs."""

import numpy as np
import pytest
import scipy.integrate

import stewart
import rotary_oracle as oracle

H = 1e-30  # complex step


def _turn(v, axis, angle):
    axis = axis / np.linalg.norm(axis)
    return v * np.cos(angle) + np.cross(axis, v) * np.sin(angle) + axis * (axis @ v) * (1 - np.cos(angle))


def random_rig(seed):
    """simrig100 made asymmetric: each motor axis and crank zero turned together by up to 0.2 rad
    about a random axis, two axes reversed (their branch with them, so that the rig stays in
    its assembly), the base and platform points moved by 1 cm, a payload off-centre with
    products of inertia, masses and inertias drawn."""
    rng = np.random.default_rng(seed)
    rig = stewart.RotaryParams.preset("simrig100")
    axes, zero, branch = rig.motor_axes.copy(), rig.crank_zero.copy(), rig.crank_branch.copy()
    for i in range(6):
        turn, angle = rng.normal(size=3), rng.uniform(-0.2, 0.2)
        axes[i], zero[i] = _turn(axes[i], turn, angle), _turn(zero[i], turn, angle)
    for i in rng.choice(6, 2, replace=False):
        axes[i], branch[i] = -axes[i], -branch[i]
    tensor = np.diag(rng.uniform(6.0, 9.0, 3))
    tensor[0, 1] = tensor[1, 0] = rng.uniform(-0.5, 0.5)
    tensor[1, 2] = tensor[2, 1] = rng.uniform(-0.5, 0.5)
    crank_mass, crank_com = rng.uniform(0.5, 2.0), rng.uniform(-0.02, 0.08)
    return rig.replace(motor_axes=axes, crank_zero=zero, crank_branch=branch,
                       base_points=rig.base_points + rng.normal(scale=0.01, size=(6, 3)),
                       platform_points=rig.platform_points + rng.normal(scale=0.01, size=(6, 3)),
                       platform_mass=rng.uniform(60.0, 140.0), platform_inertia=tensor,
                       platform_com=rng.uniform(-0.05, 0.05, 3) + [0.0, 0.0, 0.3],
                       crank_mass=crank_mass, crank_com_distance=crank_com,
                       crank_inertia=crank_mass * crank_com ** 2 + rng.uniform(0.05, 0.5),
                       rod_mass=rng.uniform(0.3, 1.5), rod_com_distance=rng.uniform(0.1, 0.4),
                       rod_inertia=rng.uniform(0.005, 0.05), gravity=9.81)


def random_states(rig, seed, n=8):
    """n states near the rig's home whose poses every crank reaches."""
    rng = np.random.default_rng(seed)
    home = stewart.RotaryPlatform(rig).home
    rows = []
    while len(rows) < n:
        x = home + np.concatenate([rng.uniform(-0.02, 0.02, 3), rng.uniform(-0.05, 0.05, 3)])
        if oracle.crank_angles(rig, x) is not None:
            rows.append((x, rng.normal(scale=0.3, size=6), rng.normal(scale=2.0, size=6)))
    return [np.array(a) for a in zip(*rows)]


RIGS = [random_rig(seed) for seed in range(3)] + [stewart.RotaryParams.preset("desktop_servo")]


@pytest.fixture(params=range(len(RIGS)), ids=lambda k: f"rig{k}")
def rig(request):
    return RIGS[request.param]


def test_crank_angles_and_branches_against_oracle(rig, figures):
    x, _, _ = random_states(rig, 1)
    alpha = stewart.RotaryPlatform(rig).crank_angles(x)
    error = np.max(np.abs(alpha - np.array([oracle.crank_angles(rig, row) for row in x])))
    figures("rotary: crank angles against atan2/acos and the branch's sign", error, 1e-13)  # reached 1.0e-15


def test_torques_against_virtual_power(rig, figures):
    x, xd, xdd = random_states(rig, 2)
    tau = stewart.RotaryPlatform(rig).inverse_dynamics(x, xd, xdd)
    expected = np.array([oracle.torques(rig, *state) for state in zip(x, xd, xdd)])
    error = np.max(np.abs(tau - expected)) / np.max(np.abs(expected))
    figures("rotary: motor torques against virtual power (relative)", error, 1e-13)  # reached 1.3e-15


def test_jacobian_against_complex_step(rig, figures):
    x, xd, _ = random_states(rig, 3)
    model = stewart.RotaryPlatform(rig)
    JP, J = model.pose_jacobian(x), model.jacobian(x)
    worst = 0.0
    for row, jp in zip(x, JP):
        alpha = oracle.crank_angles(rig, row)
        step = np.array([oracle.complex_crank_angles(rig, row + 1j * H * e, alpha).imag / H for e in np.eye(6)]).T
        worst = np.maximum(worst, np.max(np.abs(jp - step)) / np.max(np.abs(step)))
    figures("rotary: J_alpha T against complex step (relative)", worst, 1e-13)  # reached 8.4e-16
    # the twist's J_alpha gives the oracle's crank rates from the twist [v; omega]
    twist = np.concatenate([xd[:, :3], [oracle.angular_velocity(r[3:], v[3:]) for r, v in zip(x, xd)]], axis=1)
    expected = np.array([oracle.crank_rates(rig, *state) for state in zip(x, xd)])
    error = np.max(np.abs(np.einsum("nij,nj->ni", J, twist) - expected)) / np.max(np.abs(expected))
    figures("rotary: J_alpha t against the crank rates by hand (relative)", error, 5e-14)  # reached 6.4e-16
    error = np.max(np.abs(model.crank_rates(x, xd) - expected)) / np.max(np.abs(expected))
    figures("rotary: crank rates against the crank rates by hand (relative)", error, 5e-14)  # reached 6.4e-16


def test_power_balance(rig, figures):
    """dE/dt (complex step of the oracle's T + V along the motion) = tau . alpha_dot."""
    x, xd, xdd = random_states(rig, 4)
    model = stewart.RotaryPlatform(rig)
    tau, rates = model.inverse_dynamics(x, xd, xdd), model.crank_rates(x, xd)
    worst = 0.0
    for row, v, a, t, r in zip(x, xd, xdd, tau, rates):
        power = oracle.energy(rig, row + 1j * H * v, v + 1j * H * a, oracle.crank_angles(rig, row)).imag / H
        worst = np.maximum(worst, abs(power - t @ r) / (np.abs(t) @ np.abs(r)))
    figures("rotary: power balance dE/dt = tau . alpha_dot (relative)", worst, 1e-13)  # reached 6.8e-15


def test_energy_is_conserved_without_torque(figures):
    rig = RIGS[0]
    model = stewart.RotaryPlatform(rig)
    x0 = model.home + [0.005, -0.004, 0.01, 0.02, -0.01, 0.015]
    s0 = np.concatenate([x0, [0.05, 0.0, -0.05, 0.1, 0.0, -0.1]])
    zero = np.zeros(6)
    sol = scipy.integrate.solve_ivp(lambda t, s: np.concatenate([s[6:], model.forward_dynamics(s[:6], s[6:], zero)]),
                                    (0.0, 0.1), s0, method="DOP853", rtol=1e-12, atol=1e-13)
    energies = [oracle.energy(rig, s[:6], s[6:], oracle.crank_angles(rig, s[:6])) for s in sol.y.T]
    drift = np.max(np.abs(np.array(energies) - energies[0])) / abs(energies[0])
    figures("rotary: energy drift, DOP853 0.1 s, tau = 0 (relative)", drift, 2e-12)  # reached 2.2e-14


def test_forward_dynamics_inverts_inverse_dynamics(rig, figures):
    x, xd, xdd = random_states(rig, 5)
    model = stewart.RotaryPlatform(rig)
    back = model.forward_dynamics(x, xd, model.inverse_dynamics(x, xd, xdd))
    figures("rotary: forward dynamics of inverse dynamics (relative)",
            np.max(np.abs(back - xdd)) / np.max(np.abs(xdd)), 1e-12)  # reached 6.8e-14
    # the terms: M xdd + G equals the torques' generalized force at rest
    tau0 = model.inverse_dynamics(x, np.zeros_like(xd), xdd)
    lhs = np.einsum("nij,nj->ni", model.mass_matrix(x), xdd) + model.gravity_vector(x)
    rhs = np.einsum("nji,nj->ni", model.jacobian(x), tau0)
    figures("rotary: M xdd + G = J_alpha^T tau at rest (relative)",
            np.max(np.abs(lhs - rhs)) / np.max(np.abs(rhs)), 1e-14)  # reached 2.3e-16
    Mt = model.twist_mass_matrix(x)
    assert np.array_equal(Mt, np.swapaxes(Mt, 1, 2))
    assert np.all(np.linalg.eigvalsh(Mt) > 0.0)


def test_forward_kinematics_of_inverse_kinematics(rig, figures):
    x, _, _ = random_states(rig, 6)
    model = stewart.RotaryPlatform(rig)
    back = model.forward_kinematics(model.crank_angles(x))
    figures("rotary: forward kinematics of the crank angles (m, rad)", np.max(np.abs(back - x)), 1e-12)  # reached 4.9e-14
    assert np.array_equal(model.forward_kinematics(model.crank_angles(x[0]), guess=x[0]), x[0])


def test_inverse_dynamics_derivatives_against_complex_step(rig, figures):
    x, xd, xdd = random_states(rig, 9, n=3)
    model = stewart.RotaryPlatform(rig)
    result = model.inverse_dynamics_derivatives(x, xd, xdd)
    assert type(result).__name__ == "InverseDynamicsDerivatives"
    assert np.array_equal(result.tau, model.inverse_dynamics(x, xd, xdd))
    worst = 0.0
    for k, state in enumerate(zip(x, xd, xdd)):
        for slot, name in enumerate(("dtau_dx", "dtau_dxd", "dtau_dxdd")):
            step = np.array([oracle.torques(rig, *(s + 1j * H * e if j == slot else s for j, s in enumerate(state))).imag / H
                             for e in np.eye(6)]).T
            worst = np.maximum(worst, np.max(np.abs(getattr(result, name)[k] - step)) / np.max(np.abs(step)))
    figures("rotary: torques' Jacobians against complex step of the oracle (relative)", worst, 2e-13)  # reached 4.0e-15


def test_forward_dynamics_derivatives_against_complex_step(rig, figures):
    """xdd and its Jacobians against complex step of the oracle's forward dynamics (the torques
    inverted by their affine dependence on xdd), on states with random torques."""
    x, xd, xdd = random_states(rig, 10, n=3)
    model = stewart.RotaryPlatform(rig)
    torque = model.inverse_dynamics(x, xd, xdd)
    result = model.forward_dynamics_derivatives(x, xd, torque)
    assert type(result).__name__ == "ForwardDynamicsDerivatives"
    assert np.array_equal(result.xdd, model.forward_dynamics(x, xd, torque))
    worst = 0.0
    for k, state in enumerate(zip(x, xd, torque)):
        for slot, name in enumerate(("dxdd_dx", "dxdd_dxd", "dxdd_dtau")):
            step = np.array([oracle.forward_dynamics(rig, *(s + 1j * H * e if j == slot else s
                                                            for j, s in enumerate(state))).imag / H
                             for e in np.eye(6)]).T
            worst = np.maximum(worst, np.max(np.abs(getattr(result, name)[k] - step)) / np.max(np.abs(step)))
    figures("rotary: forward dynamics' Jacobians against complex step of the oracle (relative)", worst, 5e-14)  # reached 5.2e-15


def test_forward_dynamics_derivatives_invert_the_torques_derivatives(rig, figures):
    """At xdd = forward_dynamics(x, xd, tau): dxdd/dtau = (dtau/dxdd)^-1 and dxdd/dq =
    -(dtau/dxdd)^-1 dtau/dq for q = x, xd (implicit differentiation of tau(x, xd, xdd) = tau)."""
    x, xd, xdd = random_states(rig, 11)
    model = stewart.RotaryPlatform(rig)
    torque = model.inverse_dynamics(x, xd, xdd)
    fd = model.forward_dynamics_derivatives(x, xd, torque)
    inv = model.inverse_dynamics_derivatives(x, xd, fd.xdd)
    worst = 0.0
    for expected, got in ((np.linalg.inv(inv.dtau_dxdd), fd.dxdd_dtau),
                          (-np.linalg.solve(inv.dtau_dxdd, inv.dtau_dx), fd.dxdd_dx),
                          (-np.linalg.solve(inv.dtau_dxdd, inv.dtau_dxd), fd.dxdd_dxd)):
        worst = max(worst, np.max(np.abs(got - expected)) / np.max(np.abs(expected)))
    figures("rotary: forward dynamics' Jacobians against the torques' (relative)", worst, 5e-14)  # reached 6.3e-15


#: The RK4 step of the tests [s]: a 1 kHz control loop's.
DT = 1e-3


def test_rk4_step_against_the_oracles_rk4(rig, figures):
    """The step and its increment against a numpy RK4 over the oracle's forward dynamics; the
    Jacobians alone give the same step."""
    x, xd, xdd = random_states(rig, 12, n=4)
    model = stewart.RotaryPlatform(rig)
    torque = model.inverse_dynamics(x, xd, xdd)
    torque += np.random.default_rng(0).normal(scale=0.1 * np.max(np.abs(torque)), size=torque.shape)
    step = model.rk4_step(x, xd, torque, DT)
    assert type(step).__name__ == "Step"
    expected = np.array([oracle.rk4_step(rig, *state, DT) for state in zip(x, xd, torque)])
    got = np.concatenate([step.x, step.xd], axis=1)
    start = np.concatenate([x, xd], axis=1)
    figures("rotary: RK4 step's increment against numpy RK4 of the oracle (relative)",
            np.max(np.abs((got - start) - (expected - start))) / np.max(np.abs(expected - start)), 1e-13)  # reached 1.2e-14
    with_jacobians = model.rk4_step(x, xd, torque, DT, jacobians=True)
    assert type(with_jacobians).__name__ == "StepDerivatives"
    assert np.array_equal(with_jacobians.x, step.x) and np.array_equal(with_jacobians.xd, step.xd)


def test_rk4_step_jacobians_against_complex_step(figures):
    """A = d(x+, xd+)/d(x, xd) and B = d(x+, xd+)/dtorque against complex step of the oracle's
    RK4 step, on an asymmetric rig and on desktop_servo (a state each: 18 complex RK4 steps of
    the oracle's forward dynamics per state)."""
    worst = 0.0
    for rig in (RIGS[0], RIGS[3]):
        x, xd, xdd = random_states(rig, 13, n=1)
        model = stewart.RotaryPlatform(rig)
        torque = model.inverse_dynamics(x, xd, xdd)
        step = model.rk4_step(x, xd, torque, DT, jacobians=True)
        for k in range(len(x)):
            A = np.array([oracle.rk4_step(rig, x[k] + 1j * H * e[:6], xd[k] + 1j * H * e[6:], torque[k], DT).imag / H
                          for e in np.eye(12)]).T
            B = np.array([oracle.rk4_step(rig, x[k], xd[k], torque[k] + 1j * H * e, DT).imag / H
                          for e in np.eye(6)]).T
            for got, expected in ((step.A[k], A), (step.B[k], B)):
                worst = max(worst, np.max(np.abs(got - expected)) / np.max(np.abs(expected)))
    figures("rotary: RK4 step's A and B against complex step of the oracle's RK4 (relative)", worst, 2e-14)  # reached 1.8e-15


def test_rk4_step_refuses_a_bad_time_step():
    model = stewart.RotaryPlatform.preset("desktop_servo")
    args = (model.home, np.zeros(6), np.zeros(6))
    for dt, message in ((0.0, "positive"), (-1e-3, "positive"), (np.nan, "finite"), (np.inf, "finite"),
                        ("abc", "expected"), (1e-3 + 1j, "complex"), ([1e-3, 2e-3], "one number")):
        with pytest.raises(ValueError, match=rf"^dt: .*{message}"):
            model.rk4_step(*args, dt)
        with pytest.raises(ValueError, match=rf"^dt: .*{message}"):
            model.rk4_step(*args, dt, jacobians=True)
    # any real number type of a positive step is taken as its float
    assert np.array_equal(model.rk4_step(*args, np.float32(1e-3)).xd, model.rk4_step(*args, float(np.float32(1e-3))).xd)


def test_derivatives_and_rk4_step_mask_the_rows_out_of_reach():
    """A pose no crank reaches (20 cm above the hand rig's) in a batch: a NaN row and a False
    mask with return_mask, the other rows as alone; without the mask SingularityError naming
    the crank and the row."""
    model = stewart.RotaryPlatform(_hand_rig(1))
    x = np.array([[0.0, 0.0, 0.3, 0.0, 0.0, 0.0], [0.0, 0.0, 0.5, 0.0, 0.0, 0.0], [0.01, 0.0, 0.3, 0.0, 0.02, 0.0]])
    xd, torque = np.zeros((3, 6)), np.ones((3, 6))
    calls = {"forward_dynamics_derivatives": lambda rows, **o: model.forward_dynamics_derivatives(*rows, **o),
             "rk4_step": lambda rows, **o: model.rk4_step(*rows, DT, **o),
             "rk4_step_jacobians": lambda rows, **o: model.rk4_step(*rows, DT, jacobians=True, **o)}
    for name, call in calls.items():
        result, ok = call((x, xd, torque), return_mask=True)
        assert ok.tolist() == [True, False, True], name
        assert all(np.isnan(part[1]).all() and np.isfinite(part[[0, 2]]).all() for part in result), name
        for k in (0, 2):
            assert _same(call((x[k], xd[k], torque[k])), _rows(result, k)), name
        with pytest.raises(stewart.SingularityError, match=r"crank 0 cannot reach the pose.*\b1\b"):
            call((x, xd, torque))


def _rk4(model, x, xd, torque, **options):
    return model.rk4_step(x, xd, torque, DT, **options)


FUNCTIONS = {"crank_angles": 1, "jacobian": 1, "pose_jacobian": 1, "crank_rates": 2, "mass_matrix": 1,
             "twist_mass_matrix": 1, "gravity_vector": 1, "inverse_dynamics": 3, "forward_dynamics": 3,
             "inverse_dynamics_derivatives": 3, "joint_cosines": 1, "cueing_rows": 2,
             "forward_dynamics_derivatives": 3, "rk4_step": 3, "rk4_step_jacobians": 3}


@pytest.mark.parametrize("name", FUNCTIONS)
def test_alone_as_in_a_batch_bit_for_bit_on_every_path(name):
    """One state alone, in a batch at any position and in a part of a batch gives the same bits,
    on every instruction-set path this CPU runs (each held to the first)."""
    rig = RIGS[1]
    x, xd, xdd = random_states(rig, 7, n=13)
    model = stewart.RotaryPlatform(rig)
    tau = model.inverse_dynamics(x, xd, xdd)
    inputs = {"crank_rates": (x, xd), "cueing_rows": (x, xd), "inverse_dynamics": (x, xd, xdd), "forward_dynamics": (x, xd, tau),
              "inverse_dynamics_derivatives": (x, xd, xdd), "forward_dynamics_derivatives": (x, xd, tau),
              "rk4_step": (x, xd, tau), "rk4_step_jacobians": (x, xd, tau)}.get(name, (x,))
    function = {"rk4_step": lambda *a: _rk4(model, *a),
                "rk4_step_jacobians": lambda *a: _rk4(model, *a, jacobians=True)}.get(name) or getattr(model, name)
    first = None
    previous = stewart.set_simd(None)
    try:
        for path in stewart.build_info()["supported"]:
            stewart.set_simd(path)
            batch = function(*inputs)
            for k in (0, 6, 12):
                assert _same(function(*(a[k] for a in inputs)), _rows(batch, k)), (path, k)
            assert _same(function(*(a[5:9] for a in inputs)), _rows(batch, slice(5, 9))), path
            first = batch if first is None else first
            assert _same(first, batch), f"{name}: {path} differs from the first path"
    finally:
        stewart.set_simd(previous)


def _rows(result, index):
    """Rows ``index`` of a result, an array or a tuple of them."""
    return tuple(part[index] for part in result) if isinstance(result, tuple) else result[index]


def _same(a, b):
    """Results (arrays or tuples of them) equal bit for bit."""
    a, b = (a, b) if isinstance(a, tuple) else ((a,), (b,))
    return len(a) == len(b) and all(np.array_equal(p, q) for p, q in zip(a, b))


def _hand_rig(branch, **changes):
    """Six legs at 60 degrees: motor i at 0.4 m on the x axis turned by 60 i degrees, its crank
    (0.1 m) tangent, a_i = h_i x z, and its platform joint right above the crank tip at alpha = 0;
    rods 0.3 m. At x = (0, 0, 0.3, 0, 0, 0) the loop |e - r u(alpha)| = d reads
    0.02 (1 - cos alpha) = 0.06 sin alpha: alpha = 0, where the rod leaves the tip straight up
    along the tip's motion (branch +1), or tan(alpha / 2) = 3, alpha = 2 atan 3, where
    (P - c) . (a x (c - b)) = 0.1 (0.18 (-0.6) + 0.24 (-0.8)) = -0.03 (branch -1)."""
    angle = np.radians(60.0 * np.arange(6))
    base = 0.4 * np.column_stack([np.cos(angle), np.sin(angle), np.zeros(6)])
    zero = np.column_stack([-np.sin(angle), np.cos(angle), np.zeros(6)])
    values = dict(base_points=base, platform_points=base + 0.1 * zero, motor_axes=np.cross(zero, [0.0, 0.0, 1.0]),
                  crank_zero=zero, crank_branch=[branch] * 6, crank_length=0.1, rod_length=0.3, platform_mass=10.0,
                  platform_inertia=[1.0, 1.0, 2.0], crank_mass=0.0, crank_com_distance=0.0, crank_inertia=0.0,
                  rod_mass=0.0, rod_com_distance=0.0, rod_inertia=0.0)
    values.update(changes)
    return stewart.RotaryParams(**values)


def test_branch_by_hand():
    x = np.array([0.0, 0.0, 0.3, 0.0, 0.0, 0.0])
    assert np.max(np.abs(stewart.RotaryPlatform(_hand_rig(1)).crank_angles(x))) <= 1e-14  # reached 2.2e-16
    other = stewart.RotaryPlatform(_hand_rig(-1)).crank_angles(x)
    assert np.max(np.abs(other - 2.0 * np.arctan(3.0))) <= 1e-14  # reached 4.4e-16
    with pytest.raises(stewart.SingularityError, match="crank 0 cannot reach the pose"):
        stewart.RotaryPlatform(_hand_rig(1)).crank_angles(x + [0.0, 0.0, 0.2, 0.0, 0.0, 0.0])
    angles, ok = stewart.RotaryPlatform(_hand_rig(1)).crank_angles(np.stack([x, x + [0, 0, 0.2, 0, 0, 0]]),
                                                                    return_mask=True)
    assert ok.tolist() == [True, False] and np.isnan(angles[1]).all()


def test_heave_torque_by_hand(figures):
    """simrig100 at its home (cranks horizontal, alpha = 0), massless rods, cranks of mass m_K
    with their centre of mass b_K out, the payload's centre of mass on the z axis: the tips move
    straight up at alpha = 0 (a x h = z), so holding the weight takes on each motor
    tau = m_P g r / 6 + m_K g b_K, whatever the rods' lean (virtual work: 6 tau alpha' = m_P g z',
    alpha' = z' / r)."""
    rig = stewart.RotaryParams.preset("simrig100").replace(rod_mass=0.0, rod_inertia=0.0)
    model = stewart.RotaryPlatform(rig)
    tau = model.inverse_dynamics(model.home, np.zeros(6), np.zeros(6))
    expected = rig.platform_mass * rig.gravity * rig.crank_length / 6 + rig.crank_mass * rig.gravity * rig.crank_com_distance
    figures("rotary: heave torque of simrig100 by hand (relative)", np.max(np.abs(tau / expected - 1.0)), 1e-13)  # reached 1.2e-15


def test_errors_name_the_argument():
    model = stewart.RotaryPlatform.preset("desktop_servo")
    with pytest.raises(ValueError, match="x"):
        model.crank_angles([0.0, 0.0, np.nan, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="xdd"):
        model.inverse_dynamics(model.home, np.zeros(6), np.zeros(5))
    with pytest.raises(stewart.WrongTypeError, match="params"):
        stewart.RotaryPlatform(stewart.PlatformParams.preset("narayan2017"))


def test_massless_legs_reduce_to_the_platforms_statics(figures):
    """Without the cranks' and rods' masses and inertias, at rest the torques hold the platform's
    weight alone: J_alpha^T tau = G = [0, 0, m g, R c x (0, 0, m g)] (the weight at the centre of
    mass R c from {P}'s origin), on a rig with an off-centre payload."""
    rig = RIGS[0].replace(crank_mass=0.0, crank_com_distance=0.0, crank_inertia=0.0, rod_mass=0.0, rod_inertia=0.0)
    model = stewart.RotaryPlatform(rig)
    x, _, _ = random_states(rig, 8)
    weight = np.array([0.0, 0.0, rig.platform_mass * rig.gravity])
    expected = np.array([np.concatenate([weight, np.cross(oracle.rotation(row[3:]) @ rig.platform_com, weight)])
                         for row in x])
    tau = model.inverse_dynamics(x, np.zeros_like(x), np.zeros_like(x))
    for name, value, bound in (("G", model.gravity_vector(x), 5e-16),  # reached 5.3e-18
                               ("J_alpha^T tau", np.einsum("nji,nj->ni", model.jacobian(x), tau), 1e-14)):  # 1.7e-16
        figures(f"rotary: massless legs, {name} against the platform's weight (relative)",
                np.max(np.abs(value - expected)) / np.max(np.abs(expected)), bound)


#: Every array-taking method of RotaryPlatform with its state arguments' names.
ROTARY_METHODS = {"crank_angles": ("x",), "jacobian": ("x",), "mass_matrix": ("x",), "gravity_vector": ("x",),
                  "inverse_dynamics": ("x", "xd", "xdd"), "forward_dynamics": ("x", "xd", "torque"),
                  "inverse_dynamics_derivatives": ("x", "xd", "xdd"), "joint_cosines": ("x", "reference"),
                  "cueing_rows": ("x", "xd", "reference"),
                  "forward_dynamics_derivatives": ("x", "xd", "torque"), "rk4_step": ("x", "xd", "torque", "dt")}


@pytest.mark.parametrize("method", sorted(ROTARY_METHODS))
@pytest.mark.parametrize("bad", ["nan", "inf", "short", "text", "complex", "ragged"])
def test_every_method_refuses_bad_input_naming_the_argument(method, bad):
    """Each argument of each method, made bad in turn, is refused with a ValueError or TypeError
    whose message names it; a good call on the same arguments gives finite results."""
    model = stewart.RotaryPlatform.preset("simrig100")
    names = ROTARY_METHODS[method]
    good = {"x": model.home + 0.01, "xd": np.full(6, 0.1), "xdd": np.full(6, 0.5), "reference": model.home}
    good["torque"] = model.inverse_dynamics(good["x"], good["xd"], good["xdd"])
    good["dt"] = DT
    args = [good[name] for name in names]
    result = getattr(model, method)(*args)
    assert all(np.all(np.isfinite(part)) for part in (result if isinstance(result, tuple) else (result,)))
    for k, name in enumerate(names):
        wrong = list(args)
        if name == "dt":  # a scalar: "short" is a step of zero seconds, "ragged" two steps
            wrong[k] = {"nan": np.nan, "inf": np.inf, "short": 0.0, "text": "abc", "complex": DT + 1j,
                        "ragged": [DT, DT]}[bad]
        else:
            wrong[k] = {"nan": np.where(np.arange(6) == 2, np.nan, args[k]), "inf": np.full(6, np.inf),
                        "short": args[k][:5], "text": "abc", "complex": args[k] + 1j,
                        "ragged": [[0.0] * 6, [0.0] * 5]}[bad]
        with pytest.raises((ValueError, TypeError), match=rf"\b{name}\b"):
            getattr(model, method)(*wrong)
