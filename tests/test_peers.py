"""Agreement of the peer models (benchmarks/peers) with our kernel. CasADi's (in the dev
extra) run in ``make test``; the heavy ones, MuJoCo's and the sympy routes' (a minute and a
half of compiling), are marked ``peers`` (``make test-peers``). Each test is skipped when its
peer is not installed (``pip install .[peers]``)."""

from __future__ import annotations

import pathlib
import sys

import numpy as np
import pytest

import stewart
from stewart.cli import bench

ROOT = pathlib.Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.peers.common import param_vector  # noqa: E402
from stewart.oracles.physics import relative_error  # noqa: E402


@pytest.mark.parametrize("preset", sorted(stewart.presets()))
def test_casadi_matches_kernel(preset, figures):
    pytest.importorskip("casadi")
    from benchmarks.peers import casadi_model

    plat = stewart.Platform.preset(preset)
    funcs = casadi_model.build()
    pvec = param_vector(plat.params)
    x, xd, xdd = bench.states(plat.params, 40, seed=7)
    tau = plat.inverse_dynamics(x, xd, xdd)
    xdd_ours = plat.forward_dynamics(x, xd, tau)
    tau_c = np.array([casadi_model.evaluate(funcs["inverse_dynamics"], x[i], xd[i], xdd[i], pvec) for i in range(40)])
    xdd_c = np.array([casadi_model.evaluate(funcs["forward_dynamics"], x[i], xd[i], tau[i], pvec) for i in range(40)])
    figures(f"CasADi tau vs kernel, {preset}", relative_error(tau_c, tau), 2e-11)  # reached 3.4e-13
    figures(f"CasADi xdd vs kernel, {preset}", relative_error(xdd_c, xdd_ours), 1e-13)  # reached 1.9e-15


def test_casadi_general_legs_match_reference(figures):
    """The frame form of the leg inertia ({C_i}) against the numeric reference."""
    pytest.importorskip("casadi")
    import warnings

    from benchmarks.peers import casadi_model
    from stewart.oracles import reference

    base = stewart.PlatformParams.preset("motion_simulator")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        params = base.replace(cylinder_inertia=(0.6, 3.0, 2.5), piston_inertia=(0.35, 1.4, 1.1))
    funcs = casadi_model.build(general=True)
    x, xd, xdd = bench.states(params, 5, seed=3)
    tau_ref = reference.inverse_dynamics(params, x, xd, xdd)
    tau_c = np.array([casadi_model.evaluate(funcs["inverse_dynamics"], x[i], xd[i], xdd[i], param_vector(params))
                      for i in range(5)])
    figures("CasADi tau vs reference, non-axisymmetric legs", relative_error(tau_c, tau_ref), 5e-14)  # reached 7.7e-16


@pytest.mark.peers
def test_mujoco_model_is_the_same_platform():
    """The MJCF's total mass and the static forces: our gravity-balancing forces hold
    MuJoCo's platform at home to within the soft constraint's regularisation."""
    mujoco = pytest.importorskip("mujoco")
    from benchmarks.peers import mujoco_model

    plat = stewart.Platform.preset("narayan2017")
    p = plat.params
    model = mujoco_model.model(mujoco_model.comparable(p), setting="tight")
    # reached 0 (the file's 17 digits, summed in MuJoCo's order)
    assert model.body_mass.sum() == pytest.approx(p.platform_mass + 6 * (p.cylinder_mass + p.piston_mass), rel=1e-14)
    data = mujoco.MjData(model)
    data.ctrl[:] = plat.inverse_dynamics(plat.home_pose, np.zeros(6), np.zeros(6))
    mujoco.mj_forward(model, data)
    platform_acc = data.qacc[-6:-3]
    assert np.max(np.abs(platform_acc)) < 5e-3 * p.gravity  # reached 6.1e-4 m/s^2, 6.2e-5 g


@pytest.mark.peers
@pytest.mark.slow
def test_sympy_routes_match_kernel(figures, tmp_path):
    """autowrap (and PyDy, when installed) on our generator's expressions; the compile
    dominates the time (marked slow)."""
    pytest.importorskip("sympy")
    pytest.importorskip("Cython")
    from benchmarks.peers import sympy_route
    from benchmarks.peers.common import peer_available

    plat = stewart.Platform.preset("narayan2017")
    pvec = param_vector(plat.params)
    x, xd, xdd = bench.states(plat.params, 10, seed=5)
    tau = plat.inverse_dynamics(x, xd, xdd)
    exprs = sympy_route.expressions()
    built = sympy_route.build_pydy(exprs, str(tmp_path)) if peer_available("pydy") else \
        sympy_route.build_autowrap(exprs, str(tmp_path))
    tau_s = np.array([built["id"][0](x[i], xd[i], xdd[i], pvec) for i in range(10)])
    xdd_s = np.array([built["fd"][0](x[i], xd[i], tau[i], pvec) for i in range(10)])
    # reached 1.4e-15 and 3.2e-15 by autowrap (PyDy, when installed, evaluates the same expressions)
    figures("sympy route tau vs kernel", relative_error(tau_s, tau), 1e-13)
    figures("sympy route xdd vs kernel", relative_error(xdd_s, xdd), 2e-13)


def test_casadi_compact_step_matches_rk4_step(figures):
    """The JIT anchor's RK4 step (CasADi's model with its 6x6 solve kept a call) against the
    package's compiled RK4 step at random states and forces."""
    pytest.importorskip("casadi")
    from benchmarks.peers import casadi_optimize

    plat = stewart.Platform.preset("narayan2017")
    dt = 0.1
    step = casadi_optimize.compact_step(plat.params, dt)
    x, xd, xdd = bench.states(plat.params, 20, seed=11)
    tau = plat.inverse_dynamics(x, xd, xdd)
    ours = np.array([np.concatenate(plat.rk4_step(x[i], xd[i], tau[i], dt)) for i in range(20)])
    theirs = np.array([np.asarray(step(np.concatenate([x[i], xd[i]]), tau[i])).ravel() for i in range(20)])
    figures("CasADi compact RK4 step vs rk4_step", relative_error(theirs, ours), 1e-13)  # reached 5.4e-16
