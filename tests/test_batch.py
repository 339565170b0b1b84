"""The batch functions (``stewart_batch_<name>``, ``_kernel.LANES`` states at once) against
the single-state functions, one state at a time: on batches whose sizes are not multiples of the
lanes, with singular rows mixed in, every row's values (bit for bit), its mask, and the error a
batch raises are those of the rows evaluated alone."""

import warnings

import numpy as np
import pytest

import stewart
from stewart import _kernel
from stewart.model.errors import SingularityError

W = _kernel.LANES
PARAMS = stewart.PlatformParams.preset("narayan2017")
#: Non-axisymmetric leg inertia: the general kernels, with the leg frame.
with warnings.catch_warnings():
    warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
    GENERAL = PARAMS.replace(piston_inertia=(1e-4, 6e-4, 5e-4))
ZERO = np.zeros(6)

#: (method, inputs) of every Kernel method with a batch function.
METHODS = [("leg_lengths", 1), ("jacobian", 1), ("leg_rates", 2), ("leg_accelerations", 3), ("mass_matrix", 1),
           ("twist_mass_matrix", 1),
           ("coriolis_matrix", 2), ("coriolis_vector", 2), ("gravity_vector", 1), ("all_terms", 2),
           ("inverse_dynamics", 3), ("forward_dynamics", 3), ("rk4_step", 3), ("inverse_dynamics_derivatives", 3),
           ("forward_dynamics_derivatives", 3), ("rk4_step_jacobians", 3)]
SIZES = [1, W - 1, W + 1, 1003]


def singular_states(params):
    """States at which the model is undefined, with what they break: the platform in the base
    plane (J_C singular), leg 0 of zero length, theta = 90 deg (forward dynamics), leg 2
    vertical (the general leg inertia's frame).  (A non-finite input is an error of the whole
    call, see `test_batch_error_names_the_rows_alone_fail_at`.)"""
    collapsed = np.concatenate([params.base_points[0] - params.platform_points[0], ZERO[:3]])
    upright = np.concatenate([params.base_points[2] - params.platform_points[2] + [0, 0, 0.28], ZERO[:3]])
    tilted = stewart.home_pose(params).copy()
    tilted[4] = np.pi / 2
    return [ZERO, collapsed, tilted, upright]


def batch(params, n, seed=0):
    """n rows of (x, xd, xdd or tau) around the home pose, a singular state every 7th row."""
    rng = np.random.default_rng(seed)
    x = stewart.home_pose(params) + 0.05 * rng.uniform(-1, 1, (n, 6))
    rates = [rng.uniform(-0.5, 0.5, (n, 6)), rng.uniform(-0.5, 0.5, (n, 6))]
    singular = singular_states(params)
    for k, row in enumerate(range(3, n, 7)):
        x[row] = singular[k % len(singular)]
    return [x] + rates


#: Time step of the RK4 steps (Kernel.rk4_step's scalar input).
DT = 1e-3


def call(kernel, method, inputs, **kwargs):
    """Kernel.<method> on the inputs (and the RK4 step's DT; "rk4_step_jacobians": the RK4 step
    with its Jacobians)."""
    if method.startswith("rk4_step"):
        return kernel.rk4_step(*inputs, DT, jacobians=method == "rk4_step_jacobians", **kwargs)
    return getattr(kernel, method)(*inputs, **kwargs)


def rows_alone(kernel, method, inputs):
    """Each row through the scalar function alone: (values, mask)."""
    values, mask = [], []
    for row in zip(*inputs):
        value, ok = call(kernel, method, row, return_mask=True)
        values.append(value)
        mask.append(ok)
    stacked = [np.stack(part) for part in zip(*values)] if isinstance(values[0], tuple) else np.stack(values)
    return stacked, np.array(mask)


def assert_rows_equal(got, want, mask):
    """got == want bit for bit (a one-state function is its batch function on one state, the
    same compiled code: docs/c.md), NaN rows where the mask is False."""
    for g, w in (zip(got, want) if isinstance(got, tuple) else [(got, want)]):
        assert np.isnan(g[~mask]).all()
        np.testing.assert_array_equal(g[mask], w[mask])


@pytest.mark.parametrize("params", [PARAMS, GENERAL], ids=["axisymmetric", "general"])
@pytest.mark.parametrize("method, arity", METHODS, ids=[m for m, _ in METHODS])
@pytest.mark.parametrize("n", SIZES)
def test_batch_equals_rows_alone(params, method, arity, n):
    kernel = _kernel.Kernel(params)
    inputs = batch(params, n)[:arity]
    want, want_mask = rows_alone(kernel, method, inputs)
    got, mask = call(kernel, method, inputs, return_mask=True)
    np.testing.assert_array_equal(mask, want_mask)
    assert_rows_equal(got, want, mask)


def test_batches_hold_every_singular_state():
    """The batches above mix in failing rows for each condition the model reports."""
    conditions = set()
    for params in (PARAMS, GENERAL):
        kernel = _kernel.Kernel(params)
        x, xd, xdd = batch(params, 1003)
        for method, arity in (("inverse_dynamics", 3), ("forward_dynamics", 3), ("mass_matrix", 1)):
            for row in range(3, 1003, 7):
                try:
                    getattr(kernel, method)(*[a[row] for a in (x, xd, xdd)[:arity]])
                except SingularityError as error:
                    conditions.add(error.condition)
    assert conditions == {"jacobian_singular", "leg_degenerate", "euler_singular", "leg_vertical"}


@pytest.mark.parametrize("method, arity", [("inverse_dynamics", 3), ("forward_dynamics", 3), ("mass_matrix", 1),
                                           ("rk4_step", 3), ("inverse_dynamics_derivatives", 3),
                                           ("rk4_step_jacobians", 3)])
def test_batch_error_names_the_rows_alone_fail_at(method, arity):
    kernel = _kernel.Kernel(GENERAL)
    x, xd, xdd = batch(GENERAL, 3 * W + 5)
    x[-3] = np.nan  # not finite: the error names the argument
    inputs = (x, xd, xdd)[:arity]
    with pytest.raises(ValueError, match="x") as info:
        call(kernel, method, inputs)
    assert not isinstance(info.value, SingularityError)
    x[-3] = x[0]
    _, mask = rows_alone(kernel, method, inputs)
    conditions = []
    for row in np.flatnonzero(~mask):
        with pytest.raises(SingularityError) as alone:
            call(kernel, method, [a[row] for a in inputs])
        conditions.append(alone.value.condition)
    with pytest.raises(SingularityError) as info:
        call(kernel, method, inputs)
    assert info.value.rows == np.flatnonzero(~mask).tolist()
    assert info.value.condition == conditions[0]


@pytest.mark.parametrize("threads", [1, 2])
def test_batch_with_a_broadcast_row_and_threads(threads):
    """One row against a batch, split over threads: as the rows alone."""
    kernel = _kernel.Kernel(PARAMS, threads=threads)
    x, xd, xdd = batch(PARAMS, 2000)
    want, want_mask = rows_alone(kernel, "inverse_dynamics", (x, np.broadcast_to(xd[0], x.shape), xdd))
    got, mask = kernel.inverse_dynamics(x, xd[0], xdd, return_mask=True)
    np.testing.assert_array_equal(mask, want_mask)
    assert_rows_equal(got, want, mask)
