"""The compiled kernel (generated C through Cython) against the numeric reference, hand
calculations and its own batch/single and forward/inverse consistency."""

import warnings

import numpy as np
import pytest

import stewart
from stewart.oracles import reference as ref
from stewart.oracles.physics import relative_error
from conftest import random_params, random_states

FUNCTIONS = [
    ("leg_lengths", 1),
    ("jacobian", 1),
    ("mass_matrix", 1),
    ("gravity_vector", 1),
    ("coriolis_matrix", 2),
    ("coriolis_vector", 2),
    ("inverse_dynamics", 3),
]


def _reference(params, name, args):
    source = ref if hasattr(ref, name) else stewart.model.kinematics
    return getattr(source, name)(params, *args)


def _param_sets():
    rng = np.random.default_rng(20)
    sets = [(name, stewart.PlatformParams.preset(name)) for name in sorted(stewart.presets())]
    sets += [(f"random axisymmetric {k}", random_params(rng)) for k in range(3)]
    sets += [(f"random general-inertia {k}", random_params(rng, axisymmetric=False)) for k in range(2)]
    return sets


@pytest.mark.parametrize("label, params", _param_sets(), ids=lambda v: v if isinstance(v, str) else "")
def test_kernel_matches_reference(label, params, figures):
    rng = np.random.default_rng(21)
    n = 1000 if label in stewart.presets() else 300
    x, xd, xdd = random_states(params, n, rng)
    plat = stewart.Platform(params)
    args = (x, xd, xdd)
    worst = 0.0
    for name, arity in FUNCTIONS:
        got = getattr(plat, name)(*args[:arity])
        worst = np.maximum(worst, relative_error(got, _reference(params, name, args[:arity])))
    tau = ref.inverse_dynamics(params, x, xd, xdd)
    worst = np.maximum(worst, relative_error(plat.forward_dynamics(x, xd, tau), xdd))
    figures(f"kernel vs reference, all functions ({label})", worst, 1e-12)  # reached 2.4e-14


def test_leg_rates_match_the_numpy_kinematics(figures):
    rng = np.random.default_rng(26)
    worst = 0.0
    for label, params in _param_sets():
        x, xd, _ = random_states(params, 300, rng)
        plat = stewart.Platform(params)
        L, Ld = plat.leg_rates(x, xd)
        worst = np.max([worst, relative_error(L, stewart.model.kinematics.leg_lengths(params, x)),
                        relative_error(Ld, stewart.model.kinematics.leg_velocities(params, x, xd))])
        # One state at a time gives the rows of the batch.
        single = plat.leg_rates(x[0], xd[0])
        np.testing.assert_array_equal(single[0], L[0])
        np.testing.assert_array_equal(single[1], Ld[0])
    figures("kernel leg_rates vs numpy leg_lengths, leg_velocities (all parameter sets)", worst, 5e-14)  # reached 7.8e-16


def test_leg_accelerations_match_the_numpy_kinematics(figures):
    """Platform.leg_accelerations (forward mode along time in the generated C) against the numpy
    closed form u_i . a_i + (|v_i|^2 - Ldot_i^2) / L_i of stewart.model.kinematics."""
    rng = np.random.default_rng(27)
    worst = 0.0
    for label, params in _param_sets():
        x, xd, xdd = random_states(params, 300, rng)
        plat = stewart.Platform(params)
        Ldd = plat.leg_accelerations(x, xd, xdd)
        assert Ldd.shape == (300, 6)
        worst = np.maximum(worst, relative_error(Ldd, stewart.model.kinematics.leg_accelerations(params, x, xd, xdd)))
        # One state at a time gives the rows of the batch.
        np.testing.assert_array_equal(plat.leg_accelerations(x[0], xd[0], xdd[0]), Ldd[0])
    figures("kernel leg_accelerations vs numpy leg_accelerations (all parameter sets)", worst, 5e-14)  # reached 8.1e-16


def test_leg_accelerations_are_the_rate_of_the_leg_rates(figures):
    """Along the motion x(t) = x + xd t + xdd t^2 / 2 (constant pose accelerations), Lddot(0) is
    the time derivative of the kernel's Ldot(t): central differences of leg_rates, Richardson-
    extrapolated (error O(h^4))."""
    rng = np.random.default_rng(28)
    worst = 0.0
    for label, params in _param_sets():
        x, xd, xdd = random_states(params, 100, rng)
        plat = stewart.Platform(params)

        def rates(t):
            return plat.leg_rates(x + xd * t + xdd * t * t / 2, xd + xdd * t)[1]

        def central(h):
            return (rates(h) - rates(-h)) / (2 * h)

        h = 1e-3
        worst = np.maximum(worst, relative_error(plat.leg_accelerations(x, xd, xdd), (4 * central(h / 2) - central(h)) / 3))
    figures("kernel leg_accelerations vs d/dt of kernel leg_rates (Richardson, all parameter sets)", worst, 1e-9)  # reached 2.9e-11


def test_leg_accelerations_fail_where_the_numpy_kinematics_fail():
    """A leg of zero length is the same SingularityError in the kernel and in numpy."""
    params = stewart.PlatformParams.preset("narayan2017")
    collapsed = np.concatenate([params.base_points[0] - params.platform_points[0], np.zeros(3)])
    rates = np.full(6, 0.1)
    with pytest.raises(stewart.SingularityError) as kernel:
        stewart.Platform(params).leg_accelerations(collapsed, rates, rates)
    with pytest.raises(stewart.SingularityError) as numpy:
        stewart.model.kinematics.leg_accelerations(params, collapsed, rates, rates)
    assert kernel.value.condition == numpy.value.condition == "leg_degenerate"


def test_leg_rates_report_a_zero_length_leg():
    params = stewart.PlatformParams.preset("narayan2017")
    plat = stewart.Platform(params)
    home, xd = plat.home_pose, np.ones(6)
    # Platform point 0 on base point 0 (no rotation): leg 0 has zero length.
    collapsed = np.concatenate([np.asarray(params.base_points[0]) - np.asarray(params.platform_points[0]), np.zeros(3)])
    with pytest.raises(stewart.SingularityError, match=r"leg_rates: a leg has zero length at row\(s\) \[1\]"):
        plat.leg_rates(np.stack([home, collapsed]), xd)
    (L, Ld), ok = plat.leg_rates(np.stack([home, collapsed, home]), xd, return_mask=True)
    assert ok.tolist() == [True, False, True] and L.shape == Ld.shape == (3, 6)
    assert np.all(np.isnan(L[1])) and np.all(np.isnan(Ld[1]))
    np.testing.assert_array_equal(L[0], plat.leg_lengths(home))


def test_twist_mass_matrix_is_the_references_m_t_inverse_and_positive_definite(figures):
    rng = np.random.default_rng(27)
    worst = 0.0
    for label, params in _param_sets():
        x, _, _ = random_states(params, 100, rng)
        m_twist = stewart.Platform(params).twist_mass_matrix(x)
        worst = np.maximum(worst, relative_error(m_twist, ref.mass_matrix(params, x) @ np.linalg.inv(stewart.twist_transform(x))))
        np.testing.assert_array_equal(m_twist, np.swapaxes(m_twist, -1, -2))
        assert np.all(np.linalg.eigvalsh(m_twist)[:, 0] > 0), label
    figures("kernel twist_mass_matrix vs reference M T^-1 (all parameter sets)", worst, 2e-14)  # reached 4.5e-16


def test_all_terms_equal_the_separate_calls(figures):
    rng = np.random.default_rng(28)
    worst = 0.0
    for label, params in _param_sets():
        x, xd, _ = random_states(params, 100, rng)
        plat = stewart.Platform(params)
        terms = plat.all_terms(x, xd)
        assert terms._fields == ("mass_matrix", "coriolis_vector", "gravity_vector", "jacobian")
        worst = np.max([worst, relative_error(terms.mass_matrix, plat.mass_matrix(x)),
                        relative_error(terms.coriolis_vector, plat.coriolis_vector(x, xd)),
                        relative_error(terms.gravity_vector, plat.gravity_vector(x)),
                        relative_error(terms.jacobian, plat.jacobian(x))])
        single = plat.all_terms(x[0], xd[0])  # the single-state function, the batch on one row
        for got, batch in zip(single, terms):
            np.testing.assert_array_equal(got, batch[0])
    # the same kernels run in one call: the same bits
    figures("kernel all_terms vs the separate kernels (all parameter sets)", worst, 0.0)  # reached 0


def test_forward_inverse_round_trip(preset_params, figures):
    rng = np.random.default_rng(22)
    plat = stewart.Platform(preset_params)
    x, xd, xdd = random_states(preset_params, 1000, rng)
    back = plat.forward_dynamics(x, xd, plat.inverse_dynamics(x, xd, xdd))
    figures(f"kernel FD(ID(xdd)) vs xdd ({preset_params.name})", relative_error(back, xdd), 1e-12)  # reached 1.7e-14


def test_batch_equals_loop_of_single_calls(preset_params):
    rng = np.random.default_rng(23)
    plat = stewart.Platform(preset_params)
    threaded = stewart.Platform(preset_params, threads=2)
    x, xd, xdd = random_states(preset_params, 64, rng)
    args = (x, xd, xdd)
    for name, arity in FUNCTIONS + [("forward_dynamics", 3)]:
        batch = getattr(plat, name)(*args[:arity])
        loop = np.array([getattr(plat, name)(*(a[k] for a in args[:arity])) for k in range(len(x))])
        # each row alone, as the single-state functions give it, bit for bit (tests/test_batch.py)
        np.testing.assert_array_equal(batch, loop)
        np.testing.assert_array_equal(getattr(threaded, name)(*args[:arity]), batch)


def test_single_row_broadcasts_against_batch(preset_params):
    plat = stewart.Platform(preset_params)
    x, xd, _ = random_states(preset_params, 5, np.random.default_rng(24))
    tau = np.full(6, 10.0)
    np.testing.assert_array_equal(plat.forward_dynamics(x, xd, tau), plat.forward_dynamics(x, xd, np.tile(tau, (5, 1))))


def test_statics_of_symmetric_hexapod_by_hand():
    """Massless legs, level platform centred over a 3-fold symmetric base: each leg
    carries m_P g / 6 vertically, i.e. tau = m_P g / (6 u_z) with u_z = z / L."""
    params = stewart.PlatformParams.preset("motion_simulator").replace(
        cylinder_mass=0.0, piston_mass=0.0, cylinder_inertia=(0, 0, 0), piston_inertia=(0, 0, 0)
    )
    plat = stewart.Platform(params)
    x = plat.home_pose
    lengths = plat.leg_lengths(x)
    expected = params.platform_mass * 9.81 / 6 * lengths / x[2]
    zero = np.zeros(6)
    np.testing.assert_allclose(plat.inverse_dynamics(x, zero, zero), expected, rtol=1e-13)  # reached 1.1e-15
    weight = params.platform_mass * 9.81
    # reached 0; a bound of a few ulp of the weight
    np.testing.assert_allclose(plat.gravity_vector(x), [0, 0, weight, 0, 0, 0], rtol=0, atol=2e-15 * weight)


def test_statics_with_leg_weights_balance_total_weight():
    """With leg masses, J_C^T tau = G and the vertical force the legs put on the
    platform lies between the platform's weight and the whole machine's weight."""
    params = stewart.PlatformParams.preset("narayan2017")
    plat = stewart.Platform(params)
    x = plat.home_pose
    zero = np.zeros(6)
    tau = plat.inverse_dynamics(x, zero, zero)
    weight = plat.gravity_vector(x)
    np.testing.assert_allclose(plat.jacobian(x).T @ tau, weight, rtol=0, atol=2e-15 * weight[2])  # reached 4.1e-17
    lift = (plat.jacobian(x).T @ tau)[2]
    total = (params.platform_mass + 6 * (params.cylinder_mass + params.piston_mass)) * 9.81
    assert params.platform_mass * 9.81 < lift < total


def test_singular_states_raise_or_mask_never_nan():
    plat = stewart.Platform.preset("narayan2017")
    home = plat.home_pose
    flat = np.zeros(6)  # platform in the base plane: J_C singular
    tilted = home + [0, 0, 0, 0, np.pi / 2, 0]
    zero = np.zeros(6)
    with pytest.raises(stewart.SingularityError, match=r"inverse_dynamics: .*J_C.* at row\(s\) \[1\]") as info:
        plat.inverse_dynamics(np.stack([home, flat]), zero, zero)
    assert info.value.rows == [1]
    with pytest.raises(stewart.SingularityError, match="theta"):
        plat.forward_dynamics(tilted, zero, zero)
    out, ok = plat.inverse_dynamics(np.stack([home, flat, home]), zero, zero, return_mask=True)
    assert ok.tolist() == [True, False, True]
    assert np.all(np.isfinite(out[ok])) and np.all(np.isnan(out[~ok]))
    tau, ok_one = plat.forward_dynamics(tilted, zero, zero, return_mask=True)
    assert ok_one is False and np.all(np.isnan(tau))
    tau, ok_one = plat.forward_dynamics(home, zero, zero, return_mask=True)
    assert ok_one is True and np.all(np.isfinite(tau))
    # Defined there: mass matrix and gravity at theta = 90 deg.
    assert np.all(np.isfinite(plat.mass_matrix(tilted)))


def test_vertical_leg_with_general_inertia_is_reported():
    base = stewart.PlatformParams.preset("narayan2017")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        general = stewart.Platform(base.replace(piston_inertia=(1e-4, 6e-4, 5e-4)))
    x = np.zeros(6)
    x[:3] = base.base_points[2] - base.platform_points[2] + [0, 0, 0.28]  # leg 2 vertical
    zero = np.zeros(6)
    with pytest.raises(stewart.SingularityError, match="vertical"):
        general.inverse_dynamics(x, zero, zero)
    axisymmetric = stewart.Platform(base)
    tau = axisymmetric.inverse_dynamics(x, zero, zero)
    np.testing.assert_allclose(tau, ref.inverse_dynamics(base, x, zero, zero), rtol=2e-13)  # reached 4.9e-15


@pytest.mark.parametrize(
    "args, message",
    [
        ((np.zeros(5), np.zeros(6), np.zeros(6)), r"x: expected shape \(6,\) or \(N, 6\), got \(5,\)"),
        ((np.zeros(6), np.zeros((2, 2, 6)), np.zeros(6)), r"xd: expected shape"),
        ((np.zeros(6), np.zeros(6), ["a"] * 6), "xdd: expected real numbers"),
        ((np.zeros((3, 6)), np.zeros((2, 6)), np.zeros(6)), "matching batch shapes"),
        ((np.zeros((3, 6)), np.zeros(6), np.eye(3, 6) * np.nan), r"xdd: row 0 contains NaN"),
        ((np.zeros(6), np.zeros(6), np.zeros(6) + 1j), "xdd: expected real numbers"),
    ],
)
def test_bad_arguments_are_named(args, message):
    plat = stewart.Platform.preset("narayan2017")
    x = args[0] + plat.home_pose if np.asarray(args[0]).shape[-1:] == (6,) else args[0]
    with pytest.raises(ValueError, match=message):
        plat.inverse_dynamics(x, *args[1:])


def test_any_array_like_is_accepted():
    plat = stewart.Platform.preset("narayan2017")
    home = plat.home_pose
    wide = np.zeros((2, 12))
    wide[:, ::2] = home  # a non-contiguous view
    zero = [0] * 6  # a list of ints
    expected = plat.inverse_dynamics(home, np.zeros(6), np.zeros(6))
    np.testing.assert_array_equal(plat.inverse_dynamics(wide[:, ::2], zero, np.zeros(6, dtype=np.float32))[1], expected)
    np.testing.assert_array_equal(plat.inverse_dynamics(list(home), zero, zero), expected)


def test_platform_api():
    plat = stewart.Platform.preset("narayan2017")
    assert plat.params == stewart.PlatformParams.preset("narayan2017")
    np.testing.assert_array_equal(plat.home_pose, stewart.home_pose(plat.params))
    x = plat.home_pose + [0.01, 0, 0.02, 0.05, 0, 0]
    np.testing.assert_allclose(plat.forward_kinematics(plat.leg_lengths(x)), x, atol=2e-14, rtol=2e-11)  # reached 1/38 of it
    reactions = plat.joint_reactions(plat.home_pose, np.zeros(6), np.zeros(6))
    static = plat.inverse_dynamics(plat.home_pose, np.zeros(6), np.zeros(6))
    np.testing.assert_allclose(reactions.tau, static, rtol=0, atol=2e-15 * np.max(np.abs(static)))  # reached 0
    total = plat.params.platform_mass + 6 * (plat.params.cylinder_mass + plat.params.piston_mass)
    np.testing.assert_allclose(reactions.base.sum(axis=0), [0, 0, total * 9.81], atol=2e-13, rtol=2e-10)  # reached 1/41 of it
    with pytest.raises(ValueError, match="params: expected a stewart.PlatformParams"):
        stewart.Platform({"platform_mass": 1})
    with pytest.raises(ValueError, match="threads: must be from 1 to 256"):
        stewart.Platform(plat.params, threads=0)
