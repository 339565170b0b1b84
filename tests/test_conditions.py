"""One singularity policy: the compiled kernel and the numpy modules (reference, Newton-Euler,
kinematics, control) agree on where the model is undefined, and raise the same
``SingularityError.condition``, with the generated C's tolerances.

The constructed states each meet one condition (or two, for the order of precedence); the
property test draws random platforms and random states, near-singular ones included, and
asks both sides the same question. The independent source of each test's truth is the
construction (a leg of exactly zero length, a vertical leg, a platform in the base plane,
theta = 90 deg, a massless platform) and, in the property test, the numpy model.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import stewart
from stewart import _kernel
from stewart.model import conditions
from stewart.oracles import newton_euler, reference
from stewart.motion.control import leg_masses
from conftest import random_params, random_states

ROOT = Path(__file__).resolve().parent.parent
PARAMS = stewart.PlatformParams.preset("narayan2017")
ZERO = np.zeros(6)
NAMES = ["ok", "nonfinite", "leg_degenerate", "jacobian_singular", "euler_singular", "leg_vertical", "mass_singular",
         "gimbal_lock"]


def replaced(params, **changes):
    """``params.replace(**changes)``, quietly for non-axisymmetric legs."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        return params.replace(**changes)


def general(params):
    """``params`` with non-axisymmetric leg inertia (the C's general kernels)."""
    return replaced(params, piston_inertia=(1e-4, 6e-4, 5e-4))


def massless(params):
    return replaced(params, platform_mass=0.0, platform_inertia=(0, 0, 0), cylinder_mass=0.0,
                    cylinder_inertia=(0, 0, 0), piston_mass=0.0, piston_inertia=(0, 0, 0))


def home():
    return stewart.home_pose(PARAMS)


def zero_leg():
    """Leg 0 of exactly zero length: P_0 on B_0, no rotation."""
    return np.concatenate([PARAMS.base_points[0] - PARAMS.platform_points[0], ZERO[:3]])


#: PARAMS with platform point 0 at the platform's origin, so that P_0 = p in any orientation.
PINNED = PARAMS.replace(platform_points=np.vstack([ZERO[:3], PARAMS.platform_points[1:]]))


def vertical_leg(angles=(0.0, 0.0, 0.0)):
    """Leg 2 vertical, 0.28 m long, in the orientation ``angles``."""
    rotated = stewart.rotation(np.concatenate([ZERO[:3], angles])) @ PARAMS.platform_points[2]
    return np.concatenate([PARAMS.base_points[2] - rotated + [0, 0, 0.28], angles])


def tilted(x=None):
    """``x`` (default home) with theta = 90 deg."""
    return (home() if x is None else x) + [0, 0, 0, 0, np.pi / 2, 0]


THETA_90 = (0.0, np.pi / 2, 0.0)


FLAT = ZERO  # the platform in the base plane: every leg horizontal, J_C of rank 3


# ---- the table -----------------------------------------------------------------------

def test_the_table_lists_every_status_code_in_order():
    assert [name for _, (name, _, _) in sorted(_kernel.CONDITIONS.items())] == NAMES
    assert list(conditions.CONDITIONS) == NAMES
    assert [c.code for c in conditions.CONDITIONS.values()] == list(range(len(NAMES)))
    for code, (name, message, _) in _kernel.CONDITIONS.items():
        assert message == _kernel.status_message(code) and message != "unknown status"
    header = (ROOT / "generated" / "stewart_model.h").read_text()
    enum = {name: int(value) for name, value in re.findall(r"(STEWART_\w+) = (\d+),", header)}
    assert enum == {("STEWART_" if s.name == "OK" else "STEWART_ERR_") + s.name: s.value for s in conditions.Status}


def test_python_tolerances_are_the_generated_ones():
    """The tolerances are the compiled header's macros, read through the kernel's table (the
    very objects, not copies), and the header's macros are the generator's table."""
    from codegen import conditions as table

    header = (ROOT / "generated" / "stewart_model.h").read_text()
    macros = dict(re.findall(r"#define (STEWART_\w+_TOL) (\S+)", header))
    assert sorted(macros) == sorted(c.macro for c in table.CONDITIONS if c.macro)
    literal = {"DBL_MIN": np.finfo(float).tiny}
    for row in table.CONDITIONS:
        condition = conditions.CONDITIONS[row.name]
        assert condition.tolerance is _kernel.CONDITIONS[condition.code][2]
        if row.macro:
            value = literal.get(macros[row.macro], None) or float(macros[row.macro])
            assert condition.tolerance == value
        else:
            assert condition.tolerance is None
    assert conditions.JACOBIAN_TOL is _kernel.CONDITIONS[conditions.Status.JACOBIAN_SINGULAR][2]
    assert conditions.VERTICAL_TOL is _kernel.CONDITIONS[conditions.Status.LEG_VERTICAL][2]
    assert conditions.EULER_TOL is _kernel.CONDITIONS[conditions.Status.EULER_SINGULAR][2]
    assert conditions.MASS_TOL is _kernel.CONDITIONS[conditions.Status.MASS_SINGULAR][2]
    assert conditions.DEGENERATE_TOL is _kernel.CONDITIONS[conditions.Status.LEG_DEGENERATE][2]


# ---- the measures, by hand ---------------------------------------------------------------

def test_hadamard_ratio_by_hand():
    rng = np.random.default_rng(1)
    q, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    scaled = q * [[1.0], [2.0], [1e-3], [5.0], [1.0], [7.0]]  # rows orthogonal, then scaled
    np.testing.assert_allclose(conditions.hadamard_ratio(scaled), 1.0, rtol=1e-15)  # reached 0: a few ulp
    skew = np.eye(6)
    skew[1, 0] = 1.0  # rows e_0 and e_0 + e_1: |det| = 1, norms 1 and sqrt(2)
    np.testing.assert_allclose(conditions.hadamard_ratio(skew), 1 / np.sqrt(2), rtol=1e-15)
    assert conditions.hadamard_ratio(np.ones((6, 6))) < 1e-15


def test_ldl_pivots_are_the_squares_of_the_cholesky_diagonal():
    rng = np.random.default_rng(2)
    a = rng.normal(size=(3, 6, 6))
    spd = a @ np.swapaxes(a, -1, -2) + 0.1 * np.eye(6)
    chol = np.linalg.cholesky(spd)
    np.testing.assert_allclose(conditions.ldl_pivots(spd), np.diagonal(chol, axis1=-2, axis2=-1) ** 2, rtol=1e-13)  # reached 2.9e-15
    assert (conditions.mass_codes(spd) == conditions.Status.OK).all()
    semidefinite = spd.copy()
    semidefinite[0] = a[0][:, :5] @ a[0][:, :5].T  # rank 5
    assert conditions.mass_codes(semidefinite)[0] == conditions.Status.MASS_SINGULAR


def test_reference_twist_mass_matrix_is_the_kernels():
    """``reference.twist_mass_matrix`` (sum_b J_b^T I_b J_b) against the kernel's M_t, and
    M_t T against the reference's M, for axisymmetric and general leg inertia."""
    rng = np.random.default_rng(3)
    for params in (PARAMS, general(PARAMS), random_params(rng), random_params(rng, axisymmetric=False)):
        x = random_states(params, 20, rng)[0]
        m_t = reference.twist_mass_matrix(params, x)
        np.testing.assert_allclose(m_t, np.swapaxes(m_t, -1, -2), rtol=0, atol=5e-16 * np.abs(m_t).max())  # reached 9.3e-18
        scale = np.abs(m_t).max(axis=(1, 2))[:, None, None]
        assert np.all(np.abs(m_t - stewart.Platform(params).twist_mass_matrix(x)) <= 2e-14 * scale)  # reached 3.2e-16
        t_mat = stewart.twist_transform(x)
        mass = reference.mass_matrix(params, x)
        # reached 1.3e-17
        assert np.all(np.abs(m_t @ t_mat - mass) <= 1e-15 * np.abs(mass).max(axis=(1, 2))[:, None, None])


# ---- every status code, constructed, in the kernel and the numpy modules -------------

#: (id, params, function, x, second and third argument, condition)
CASES = [
    ("zero leg: jacobian", PARAMS, "jacobian", zero_leg(), (), "leg_degenerate"),
    ("zero leg: mass_matrix", PARAMS, "mass_matrix", zero_leg(), (), "leg_degenerate"),
    ("zero leg: twist_mass_matrix", general(PARAMS), "twist_mass_matrix", zero_leg(), (), "leg_degenerate"),
    ("zero leg: gravity_vector", PARAMS, "gravity_vector", zero_leg(), (), "leg_degenerate"),
    ("zero leg: inverse_dynamics", PARAMS, "inverse_dynamics", zero_leg(), (ZERO, ZERO), "leg_degenerate"),
    ("zero leg: forward_dynamics", PARAMS, "forward_dynamics", zero_leg(), (ZERO, ZERO), "leg_degenerate"),
    ("vertical leg: mass_matrix", general(PARAMS), "mass_matrix", vertical_leg(), (), "leg_vertical"),
    ("vertical leg: coriolis_vector", general(PARAMS), "coriolis_vector", vertical_leg(), (np.ones(6),),
     "leg_vertical"),
    ("vertical leg: inverse_dynamics", general(PARAMS), "inverse_dynamics", vertical_leg(), (ZERO, ZERO),
     "leg_vertical"),
    ("vertical leg: forward_dynamics", general(PARAMS), "forward_dynamics", vertical_leg(), (ZERO, ZERO),
     "leg_vertical"),
    ("vertical leg, axisymmetric", PARAMS, "inverse_dynamics", vertical_leg(), (ZERO, ZERO), "ok"),
    ("vertical leg: gravity needs no leg frame", general(PARAMS), "gravity_vector", vertical_leg(), (), "ok"),
    ("vertical leg: jacobian needs no leg frame", general(PARAMS), "jacobian", vertical_leg(), (), "ok"),
    ("flat: inverse_dynamics", PARAMS, "inverse_dynamics", FLAT, (ZERO, ZERO), "jacobian_singular"),
    ("flat, general legs", general(PARAMS), "inverse_dynamics", FLAT, (ZERO, ZERO), "jacobian_singular"),
    ("flat: forward_dynamics needs no J_C^-1", PARAMS, "forward_dynamics", FLAT, (ZERO, ZERO), "ok"),
    ("theta 90: forward_dynamics", PARAMS, "forward_dynamics", tilted(), (ZERO, ZERO), "euler_singular"),
    ("theta 90: inverse_dynamics needs no J_A^-1", PARAMS, "inverse_dynamics", tilted(), (ZERO, ZERO), "ok"),
    ("massless: forward_dynamics", massless(PARAMS), "forward_dynamics", home(), (ZERO, ZERO), "mass_singular"),
    ("overflowing tau", PARAMS, "forward_dynamics", home(), (ZERO, np.full(6, 1e308)), "nonfinite"),
    ("overflowing xdd", PARAMS, "inverse_dynamics", home(), (ZERO, np.full(6, 1e308)), "nonfinite"),
    ("overflowing leg", PARAMS, "mass_matrix", home() * [1e200, 1, 1, 1, 1, 1], (), "nonfinite"),
    ("overflowing leg: inverse_dynamics", PARAMS, "inverse_dynamics", home() * [1e200, 1, 1, 1, 1, 1],
     (ZERO, ZERO), "nonfinite"),
    # Precedence: the legs before the steps, theta before M_t.
    ("zero leg and theta 90", PINNED, "forward_dynamics", np.concatenate([PINNED.base_points[0], THETA_90]),
     (ZERO, ZERO), "leg_degenerate"),
    ("vertical leg and theta 90", general(PARAMS), "forward_dynamics", vertical_leg(THETA_90), (ZERO, ZERO),
     "leg_vertical"),
    ("massless and theta 90", massless(PARAMS), "forward_dynamics", tilted(), (ZERO, ZERO), "euler_singular"),
    ("flat and general legs", general(PARAMS), "inverse_dynamics", FLAT, (ZERO, ZERO), "jacobian_singular"),
    ("zero leg and massless", massless(PARAMS), "forward_dynamics", zero_leg(), (ZERO, ZERO), "leg_degenerate"),
]


def outcome(call):
    """``("ok", None)``, or ``(condition, (message, rows))`` of the SingularityError raised."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            call()
        except stewart.SingularityError as exc:
            return exc.condition, (str(exc), exc.rows)
    return "ok", None


def same(kernel, numpy):
    """The same condition and rows, and (but for a non-finite result, which the numpy side
    describes more closely) the same message."""
    assert kernel[0] == numpy[0], (kernel, numpy)
    if kernel[0] != "ok":
        assert kernel[1][1] == numpy[1][1], (kernel, numpy)
        assert kernel[0] == "nonfinite" or kernel[1][0] == numpy[1][0], (kernel, numpy)


def kernel_call(params, function, x, *args):
    return lambda: getattr(stewart.Platform(params), function)(x, *args)


def reference_call(params, function, x, *args):
    module = stewart.model.kinematics if function == "jacobian" else reference
    return lambda: getattr(module, function)(params, x, *args)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_kernel_and_reference_meet_the_same_condition(case):
    _, params, function, x, args, condition = case
    kernel = outcome(kernel_call(params, function, x, *args))
    numpy = outcome(reference_call(params, function, x, *args))
    assert kernel[0] == numpy[0] == condition, (kernel, numpy)
    same(kernel, numpy)
    if condition not in ("ok", "nonfinite"):
        message = conditions.CONDITIONS[condition].message
        assert kernel[1] == (f"{function}: {message}", [0])


def test_a_batch_fails_with_its_first_bad_rows_condition():
    """Rows: fine, theta = 90 deg, a zero-length leg, fine, a vertical leg (general legs)."""
    params = general(PARAMS)
    x = np.stack([home(), tilted(), zero_leg(), home(), vertical_leg()])
    for function in ("forward_dynamics", "inverse_dynamics"):
        kernel = outcome(kernel_call(params, function, x, np.zeros((5, 6)), np.zeros((5, 6))))
        numpy = outcome(reference_call(params, function, x, np.zeros((5, 6)), np.zeros((5, 6))))
        same(kernel, numpy)
    first = outcome(kernel_call(params, "forward_dynamics", x, np.zeros((5, 6)), np.zeros((5, 6))))
    assert first[0] == "euler_singular" and first[1][1] == [1, 2, 4]
    assert first[1][0].startswith("forward_dynamics: theta = +-90 deg") and first[1][0].endswith("[1, 2, 4]")
    second = outcome(kernel_call(params, "inverse_dynamics", x, np.zeros((5, 6)), np.zeros((5, 6))))
    assert second[0] == "leg_degenerate" and second[1][1] == [2, 4]


@pytest.mark.parametrize("x, condition", [(zero_leg(), "leg_degenerate"), (FLAT, "jacobian_singular"),
                                          (tilted(), "ok")])
def test_newton_euler_meets_the_kernels_condition(x, condition):
    kernel = outcome(kernel_call(PARAMS, "inverse_dynamics", x, ZERO, ZERO))
    ne = outcome(lambda: newton_euler.joint_reactions(PARAMS, x, ZERO, ZERO))
    assert kernel[0] == ne[0] == condition


def test_control_and_forward_kinematics_use_the_jacobian_test():
    with pytest.raises(stewart.SingularityError) as info:
        leg_masses(stewart.Platform(PARAMS), FLAT)
    assert info.value.condition == "jacobian_singular"
    # From a guess in the base plane, J_E is singular at once: no step is taken.
    lengths = stewart.leg_lengths(PARAMS, home())
    assert conditions.jacobian_codes(stewart.euler_jacobian(PARAMS, FLAT))[0] == conditions.Status.JACOBIAN_SINGULAR
    with pytest.raises(stewart.ConvergenceError):
        stewart.forward_kinematics(PARAMS, lengths, guess=FLAT)
    # reached 0: the default guess, home, already has the lengths
    np.testing.assert_allclose(stewart.forward_kinematics(PARAMS, lengths), home(), rtol=0, atol=1e-15)


def test_non_finite_inputs_are_value_errors_naming_the_argument_on_both_sides():
    bad = home().copy()
    bad[2] = np.nan
    for call in (kernel_call(PARAMS, "forward_dynamics", bad, ZERO, ZERO),
                 reference_call(PARAMS, "forward_dynamics", bad, ZERO, ZERO)):
        with pytest.raises(ValueError, match="^x: contains NaN or inf") as info:
            call()
        assert not isinstance(info.value, stewart.SingularityError)


# ---- property: random platforms, random and near-singular states ---------------------

FUNCTIONS = {  # function: its arguments after x
    "jacobian": 0, "mass_matrix": 0, "twist_mass_matrix": 0, "gravity_vector": 0,
    "coriolis_vector": 1, "inverse_dynamics": 2, "forward_dynamics": 2,
}


def _near(value, tolerance, factor):
    """Whether ``value`` lies within ``factor`` of ``tolerance`` (either side): there the two
    sides' round-off may fall either way, and neither is wrong."""
    return tolerance / factor <= value <= tolerance * factor


def _ties(params, x) -> bool:
    """Whether a measure of the state lies so close to its tolerance that round-off decides
    (a measure the numpy side cannot form, beyond an earlier condition, counts as no tie)."""
    legs = stewart.leg_vectors(params, x)
    with np.errstate(over="ignore", invalid="ignore"):
        length_sq = np.sum(legs * legs, axis=-1)
        horizontal = (legs[:, 0] ** 2 + legs[:, 1] ** 2) / length_sq
    if any(_near(h, conditions.VERTICAL_TOL, 4.0) for h in horizontal):
        return True
    if _near(abs(np.cos(x[4])), conditions.EULER_TOL, 4.0):
        return True
    try:
        if _near(conditions.hadamard_ratio(stewart.jacobian(params, x)), conditions.JACOBIAN_TOL, 4.0):
            return True
        m_t = reference.twist_mass_matrix(params, x)
    except stewart.SingularityError:
        return False
    diag = np.diagonal(m_t)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = conditions.ldl_pivots(m_t) / diag
    return any(_near(r, conditions.MASS_TOL, 100.0) for r in ratios[diag > 0])


@st.composite
def platforms_and_states(draw):
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    params = random_params(rng, axisymmetric=draw(st.booleans()))
    masses = draw(st.sampled_from(["all", "massless platform", "massless"]))
    if masses == "massless platform":
        params = replaced(params, platform_mass=0.0, platform_inertia=(0, 0, 0))
    elif masses == "massless":
        params = massless(params)
    kind = draw(st.sampled_from(["random", "psi", "theta", "theta", "vertical", "vertical", "flat", "flat", "far"]))
    if kind == "flat":  # joints in two planes
        params = replaced(params, base_points=params.base_points * [1, 1, 0],
                          platform_points=params.platform_points * [1, 1, 0])
    x = random_states(params, 1, rng)[0][0]
    small = 10.0 ** draw(st.floats(-17, -1))
    if kind == "theta":  # theta near +-90 deg
        x[4] = draw(st.sampled_from([1, -1])) * (np.pi / 2 - small)
    elif kind == "vertical":  # leg i nearly vertical
        i = draw(st.integers(0, 5))
        x[3:] = 0.0
        x[:3] = params.base_points[i] - params.platform_points[i] + [small, -0.5 * small, x[2]]
    elif kind == "flat":  # the platform nearly in the base plane: J_C nearly of rank 3
        x = np.array([0.0, 0.0, small * x[2], 0.0, 0.0, 0.0])
    elif kind == "far":  # far away: lengths, then results, overflow
        x[:3] *= 10.0 ** draw(st.floats(100, 300))
    elif kind == "psi":  # turned about z by a large angle
        x[3] = draw(st.floats(-np.pi, np.pi))
    return params, x, rng.normal(size=6), rng.normal(size=6) * params.platform_mass


@settings(max_examples=300, derandomize=True, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(platforms_and_states(), st.sampled_from(sorted(FUNCTIONS)))
def test_kernel_and_reference_agree_on_where_the_model_is_defined(drawn, function):
    params, x, second, third = drawn
    assume(not _ties(params, x))
    args = (second, third)[:FUNCTIONS[function]]
    kernel = outcome(kernel_call(params, function, x, *args))
    numpy = outcome(reference_call(params, function, x, *args))
    same(kernel, numpy)
