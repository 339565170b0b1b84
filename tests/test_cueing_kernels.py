"""The generated kernels of MPC cueing's prediction: ``Platform.joint_cosines`` (the joints'
cosines and their pose gradient) and ``Platform.rider_signals`` (the rider's specific force and
angular velocity with their Jacobians).

The oracles are the numpy formulations MPC cueing used before they were generated (the rotation
partials written entry by entry, from the anchor of the MPC step's benchmark,
``benchmarks/cueing_anchor.py``; the gradient of the unit leg vector by hand, here), the
joint angles of :func:`stewart.model.reachability.joint_angles` and the signals of
:func:`stewart.cueing.vestibular.platform_signals`, and complex-step derivatives of a complex
numpy evaluation (no cancellation: exact to round-off).
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest

import stewart
from stewart.cueing import vestibular
from stewart.model.reachability import joint_angles, neutral_axes
from benchmarks.cueing_anchor import rotation_and_partials
from conftest import PRESETS, make_general

STATES = 64


def states(plat, rng, n=STATES):
    x = plat.home_pose + rng.normal(0.0, [0.04, 0.04, 0.03, 0.1, 0.1, 0.1], (n, 6))
    return x, rng.normal(0.0, 0.5, (n, 6)), rng.normal(0.0, 3.0, (n, 6))


def joint_cosines_oracle(x, base_points, platform_points, neutral):
    """The cosines ``(N, 12)`` and their gradient ``(N, 12, 6)`` by hand: ``l_i = p + R p_i -
    b_i``, ``du/dl = (I - u u^T) / |l|``, ``dl/dp = I``, ``dl/dangle = dR/dangle p_i``."""
    n = len(x)
    r = rotation_and_partials(x)
    rp = np.einsum("knab,ib->knia", r, platform_points)
    legs = x[:, None, :3] + rp[0] - base_points
    length = np.linalg.norm(legs, axis=-1)
    u = legs / length[..., None]
    dl = np.zeros((n, 6, 3, 6))
    dl[:, :, :, :3] = np.eye(3)
    dl[:, :, :, 3:] = np.transpose(rp[1:], (1, 2, 3, 0))
    du = (np.eye(3) - u[..., :, None] * u[..., None, :]) / length[..., None, None] @ dl
    spherical_axis = np.einsum("nab,ib->nia", r[0], neutral)
    cos = np.concatenate([np.einsum("nia,ia->ni", u, neutral), np.einsum("nia,nia->ni", u, spherical_axis)], 1)
    grad = np.zeros((n, 12, 6))
    grad[:, :6] = np.einsum("ia,niaj->nij", neutral, du)
    grad[:, 6:] = np.einsum("nia,niaj->nij", spherical_axis, du)
    grad[:, 6:, 3:] += np.einsum("nia,knab,ib->nik", u, r[1:], neutral)
    return cos, grad


def signals(x, v, u, gravity):
    """``y = [R^T (a + g e_z); E w]`` with ``E = R^T J_A`` written out, for complex inputs too."""
    r = rotation_and_partials(x)[0]
    cth, sth, cph, sph = np.cos(x[:, 4]), np.sin(x[:, 4]), np.cos(x[:, 5]), np.sin(x[:, 5])
    b = u[:, :3] + np.array([0.0, 0.0, gravity])
    rates = v[:, 3:]
    w = np.stack([-sth * rates[:, 0] + rates[:, 2], cth * sph * rates[:, 0] + cph * rates[:, 1],
                  cth * cph * rates[:, 0] - sph * rates[:, 1]], -1)
    return np.concatenate([np.einsum("nji,nj->ni", r, b), w], 1)


def complex_step(f, args, k, step=1e-30):
    """The Jacobian ``(N, m, 6)`` of ``f(*args)`` in ``args[k]`` by complex steps."""
    columns = []
    for j in range(6):
        shifted = [a.astype(complex) for a in args]
        shifted[k][:, j] += 1j * step
        columns.append(f(*shifted).imag / step)
    return np.stack(columns, -1)


@pytest.fixture(params=PRESETS + ["general"])
def platform(request):
    if request.param == "general":
        return stewart.Platform(make_general(stewart.PlatformParams.preset("motion_simulator"),
                                             np.random.default_rng(7)))
    return stewart.Platform.preset(request.param)


def test_joint_cosines_against_the_numpy_formulation(platform, figures):
    x, _, _ = states(platform, np.random.default_rng(1))
    neutral = neutral_axes(platform)
    cos, grad = platform.joint_cosines(x)
    cos0, grad0 = joint_cosines_oracle(x, platform.params.base_points, platform.params.platform_points, neutral)
    figures("cosines vs numpy", np.max(np.abs(cos - cos0)), 1e-14)     # reached 4.4e-16
    figures("gradient vs numpy", np.max(np.abs(grad - grad0)), 2e-13)  # reached 2.4e-15
    universal, spherical = joint_angles(platform.params, x)
    figures("cosines vs joint_angles", np.max(np.abs(cos - np.cos(np.concatenate([universal, spherical], 1)))),
            3e-14)  # reached 4.4e-16


def test_joint_cosines_gradient_by_complex_step(platform, figures):
    x, _, _ = states(platform, np.random.default_rng(2))
    neutral = neutral_axes(platform)
    pp = platform.params

    def cosines(xc):
        return joint_cosines_oracle(xc, pp.base_points, pp.platform_points, neutral)[0]

    # the oracle's cosines are complex-analytic: its gradient output is not used here
    def analytic(xc):
        r = rotation_and_partials(xc)[0]
        legs = xc[:, None, :3] + np.einsum("nab,ib->nia", r, pp.platform_points) - pp.base_points
        u = legs / np.sqrt(np.sum(legs * legs, -1))[..., None]
        return np.concatenate([np.einsum("nia,ia->ni", u, neutral),
                               np.einsum("nia,nab,ib->ni", u, r, neutral)], 1)

    assert np.max(np.abs(analytic(x) - cosines(x))) < 1e-15
    grad = platform.joint_cosines(x).dcosines_dx
    figures("gradient vs complex step", np.max(np.abs(grad - complex_step(analytic, [x], 0))), 2e-13)  # reached 2e-15


def test_joint_cosines_other_axes_and_shapes(platform, figures):
    rng = np.random.default_rng(3)
    x, _, _ = states(platform, rng, 5)
    axes = rng.normal(size=(6, 3))
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    cos, grad = platform.joint_cosines(x, axes)
    cos0, grad0 = joint_cosines_oracle(x, platform.params.base_points, platform.params.platform_points, axes)
    worst = np.maximum(np.max(np.abs(cos - cos0)), np.max(np.abs(grad - grad0)))
    figures("other axes", worst, 1e-13)  # reached 1.9e-15
    one = platform.joint_cosines(x[2], axes)
    assert one.cosines.shape == (12,) and one.dcosines_dx.shape == (12, 6)
    np.testing.assert_array_equal(one.cosines, cos[2])  # a state alone: the batch's row, bit for bit
    np.testing.assert_array_equal(one.dcosines_dx, grad[2])
    with pytest.raises(ValueError, match="axes"):
        platform.joint_cosines(x, axes[:5])
    with pytest.raises(ValueError, match="axes"):
        platform.joint_cosines(x, np.full((6, 3), np.nan))


def test_rider_signals_against_platform_signals_and_complex_step(platform, figures):
    x, v, u = states(platform, np.random.default_rng(4))
    g = platform.params.gravity
    out = platform.rider_signals(x, v, u)
    f, w = vestibular.platform_signals(x, v, u, g)
    figures("signals vs platform_signals", np.max(np.abs(out.y - np.concatenate([f, w], 1))), 1e-13)  # reached 1.8e-15
    for k, jac in enumerate((out.dy_dx, out.dy_dxd, out.dy_dxdd)):
        oracle = complex_step(lambda *a: signals(*a, g), [x, v, u], k)
        figures(f"Jacobian {k} vs complex step", np.max(np.abs(jac - oracle)), 3e-13)  # reached 5.3e-15
    # at rest, level: f = [0, 0, g], w = 0
    rest = platform.rider_signals(platform.home_pose, np.zeros(6), np.zeros(6)).y
    np.testing.assert_array_equal(rest, [0.0, 0.0, g, 0.0, 0.0, 0.0])


@pytest.mark.parametrize("name", ["rotation_and_partials", "signals_and_jacobians", "joint_cosines_and_gradients"])
def test_the_prediction_kinematics_kept_as_deprecated_names_give_what_they_gave(name):
    """The numpy functions the prediction model held (their formulation kept in
    benchmarks.cueing_anchor) still answer under their old paths, from the generated functions,
    with a DeprecationWarning naming what replaces them."""
    from benchmarks import cueing_anchor

    plat = stewart.Platform.preset("narayan2017")
    x, v, u = states(plat, np.random.default_rng(5), 20)
    args = {"rotation_and_partials": (x,), "signals_and_jacobians": (x, v, u, 9.5),
            "joint_cosines_and_gradients": (x, plat.params.base_points, plat.params.platform_points,
                                            neutral_axes(plat))}[name]
    with pytest.warns(DeprecationWarning) as caught:
        old = getattr(importlib.import_module("stewart.cueing.prediction"), name)  # the module's old path too
    assert any(str(w.message).startswith(f"stewart.cueing.horizon.{name} is deprecated: use stewart.Platform.")
               for w in caught)
    got, want = old(*args), getattr(cueing_anchor, name)(*args)
    for g, w in zip(got, want):
        assert g.shape == w.shape
        assert np.max(np.abs(g - w)) <= 1e-13  # reached 2.3e-15
