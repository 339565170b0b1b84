"""The regressor: actuator forces linear in the inertial parameters, tau = Y pi.

Y is derived in the parallel-axis form (`codegen.dynamics.inertial_force`), apart from the
momentum form of the inverse dynamics, so ``Y @ pi`` is checked against the kernel's inverse
dynamics, against the numpy reference, and column by column against the change of the
inverse dynamics when one parameter changes (the forces are linear in pi).
"""

from __future__ import annotations

import mpmath

import numpy as np
import pytest

import stewart
from stewart import Platform, PlatformParams
from stewart.oracles import reference as ref
from stewart.oracles.physics import random_states, relative_error
from stewart.model.params import INERTIAL_NAMES, NUM_INERTIAL, NUM_RIGID_BODY

from conftest import inertial_step, random_params
from test_general_kernels import random_general

RELATIVE = 1e-13  # reached 2.1e-15
COLUMN = INERTIAL_NAMES.index


def _exact_law(rates, viscous, coulomb, velocity):
    """The friction law F_v Ld + F_c tanh(Ld / v_c) of each leg at ``rates`` (N, 6) in 40
    digits, rounded once to floats."""
    with mpmath.workdps(40):
        return np.array([[float(mpmath.mpf(fv) * mpmath.mpf(r) + mpmath.mpf(fc) * mpmath.tanh(mpmath.mpf(r) / velocity))
                          for r, fv, fc in zip(row, viscous, coulomb)] for row in rates])


def _with_friction(params, rng):
    return params.replace(viscous_friction=rng.uniform(10.0, 200.0, 6), coulomb_friction=rng.uniform(5.0, 50.0, 6),
                          coulomb_velocity=rng.uniform(1e-3, 1e-2))


def _platforms():
    rng = np.random.default_rng(7)
    out = [(name, PlatformParams.preset(name)) for name in stewart.presets()]
    out += [(f"random-{k}", random_params(rng)) for k in range(2)]
    out += [(f"general-{k}", random_general(k)) for k in range(2)]
    out.append(("payload, no joint axes", PlatformParams.preset("narayan2017").with_payload(50.0, [0.1, 0.0, 0.1],
                                                                                        [2.0, 3.0, 4.0])))
    return out


@pytest.mark.parametrize("label,params", _platforms(), ids=[label for label, _ in _platforms()])
def test_regressor_times_pi_is_the_actuator_force(label, params, figures):
    rng = np.random.default_rng(11)
    plat = Platform(_with_friction(params, rng))
    x, xd, xdd = random_states(plat.params, 1000, rng)
    Y, ok = plat.regressor(x, xd, xdd, return_mask=True)
    tau, ok_tau = plat.actuator_forces(x, xd, xdd, return_mask=True)
    assert Y.shape == (1000, 6, NUM_INERTIAL)
    assert np.array_equal(ok, ok_tau) and ok.sum() > 900
    err = relative_error(Y[ok] @ plat.params.inertial_vector(), tau[ok])
    figures(f"regressor Y pi vs inverse dynamics + friction ({label})", err, RELATIVE)
    # the numpy reference, on fewer states
    got = Y[ok][:40] @ plat.params.inertial_vector()
    want = ref.inverse_dynamics(plat.params, x[ok][:40], xd[ok][:40], xdd[ok][:40]) + plat.friction_forces(
        x[ok][:40], xd[ok][:40])
    figures(f"regressor Y pi vs the numpy reference ({label})", relative_error(got, want), RELATIVE)


@pytest.mark.parametrize("label,params", _platforms()[:1] + _platforms()[-3:-1],
                         ids=[label for label, _ in _platforms()[:1] + _platforms()[-3:-1]])
def test_each_column_is_the_change_of_the_inverse_dynamics(label, params, figures):
    """Column k = (tau(pi + d e_k) - tau(pi)) / d exactly (linear), each parameter changed
    alone through `with_inertial_vector`, so each column is checked on its own."""
    rng = np.random.default_rng(3)
    plat = Platform(params)
    x, xd, xdd = random_states(params, 50, rng)
    Y = plat.regressor(x, xd, xdd)
    tau = plat.inverse_dynamics(x, xd, xdd)
    pi = params.inertial_vector()
    size = np.max(np.abs(params.platform_points))
    worst = 0.0
    for k, name in enumerate(INERTIAL_NAMES[:NUM_RIGID_BODY]):
        body, entry = name.split(".")
        group = [pi[COLUMN(f"{body}.{e}")] for e in ("Ixx", "Iyy", "Izz")]
        step = 1e-3 * (pi[COLUMN(f"{body}.m")] * (size if entry != "m" else 1.0) if entry.startswith("m")
                       else max(group))
        moved, signed = inertial_step(params, k, step, lambda p: Platform(p).inverse_dynamics(x, xd, xdd))
        if name == "cylinder.m" or (name.endswith(".Ixx") and body != "platform"
                                    and params.universal_joint_axes is None):
            assert not np.any(Y[..., k])  # never acts: the forces do not change
            worst = np.maximum(worst, relative_error(moved, tau))
        else:
            worst = np.maximum(worst, relative_error(Y[..., k] * signed, moved - tau))
    figures(f"regressor columns vs the change of the inverse dynamics ({label})", worst, 1e-7)  # reached 6.7e-09


def test_columns_that_never_act_are_zero():
    rng = np.random.default_rng(5)
    payload = PlatformParams.preset("motion_simulator").with_payload(10.0, [0.1, 0.2, 0.0], [1.0, 1.0, 1.0])
    # Without joint axes the C model takes a_i = z (spinless_legs set); given along z, the legs spin.
    for params in (PlatformParams.preset("narayan2017"), random_general(0), payload,
                   payload.replace(universal_joint_axes=np.tile([0.0, 0.0, 1.0], (6, 1)))):
        plat = Platform(params)
        Y = plat.regressor(*random_states(params, 200, rng))
        assert not np.any(Y[..., COLUMN("cylinder.m")])
        spin = params.universal_joint_axes is not None
        for body in ("cylinder", "piston"):
            assert np.any(Y[..., COLUMN(f"{body}.Ixx")]) == spin
            assert np.any(Y[..., COLUMN(f"{body}.mb")]) and np.any(Y[..., COLUMN(f"{body}.Iyy")])


def test_friction_columns(figures):
    rng = np.random.default_rng(2)
    params = _with_friction(PlatformParams.preset("narayan2017"), rng)
    plat = Platform(params)
    x, xd, xdd = random_states(params, 100, rng)
    Y = plat.regressor(x, xd, xdd)
    _, rates = plat.leg_rates(x, xd)
    viscous = Y[..., NUM_RIGID_BODY:NUM_RIGID_BODY + 6]
    coulomb = Y[..., NUM_RIGID_BODY + 6:]
    assert np.allclose(viscous, rates[:, :, None] * np.eye(6), rtol=1e-14, atol=1e-15)  # reached 1/45 of it
    assert not np.any(viscous * (1.0 - np.eye(6))) and not np.any(coulomb * (1.0 - np.eye(6)))
    # The smooth sign against tanh(Ld_i / v_c) of the regressor's own rates in 40 digits: it is
    # vtanh(Ld_i (1 / v_c)) (vector.c's friction law), whose argument rounds twice (a relative
    # 2^-52, which moves tanh by at most max |a| sech^2(a) 2^-52 < 0.45 * 2^-52) and whose tanh
    # is within a few 2^-53 of the exact one (lanes.c): 4 * 2^-53 in all, absolute.
    own = np.einsum("nii->ni", viscous)
    sign = np.einsum("nii->ni", coulomb)
    assert np.max(np.abs(sign - _exact_law(own, np.zeros(6), np.ones(6), params.coulomb_velocity))) <= 4 * 2.0 ** -53
    # friction_forces: the same law at the legs' rates, within the same 4 * 2^-53 of its sign
    # times F_c, plus the roundings of F_v Ld, F_c s and their sum (2^-53 of each term, 2^-53 of
    # the sum): (|F_v Ld| + 2 |F_c|) 2^-51 bounds them.
    law = _exact_law(rates, params.viscous_friction, params.coulomb_friction, params.coulomb_velocity)
    bound = (np.abs(params.viscous_friction * rates) + 2 * params.coulomb_friction) * 2.0 ** -51
    error = np.abs(plat.friction_forces(x, xd) - law)
    assert np.all(error <= bound)
    figures("friction_forces vs the law in 40 digits: largest error / its bound", float(np.max(error / bound)), 1.0)  # reached 3.2e-01
    assert not np.any(Platform.preset("narayan2017").friction_forces(x, xd))


def test_one_state_and_batch_agree_and_errors():
    plat = Platform.preset("narayan2017")
    x, xd, xdd = random_states(plat.params, 9, np.random.default_rng(1))
    Y = plat.regressor(x, xd, xdd)
    for r in range(9):
        np.testing.assert_array_equal(plat.regressor(x[r], xd[r], xdd[r]), Y[r])  # the same compiled code
    with pytest.raises(ValueError, match="xd"):
        plat.regressor(x[0], [np.nan] * 6, xdd[0])
    flat = np.zeros(6)  # the platform in the base plane: J_C singular
    with pytest.raises(stewart.SingularityError):
        plat.regressor(flat, xd[0], xdd[0])
    Y, ok = plat.regressor(np.stack([flat, x[1]]), xd[:2], xdd[:2], return_mask=True)
    assert ok.tolist() == [False, True] and np.all(np.isnan(Y[0])) and np.all(np.isfinite(Y[1]))


def test_inertial_vector_round_trip_and_errors():
    params = _with_friction(random_general(1), np.random.default_rng(0))
    pi = params.inertial_vector()
    back = params.with_inertial_vector(pi)
    # reached 0 in all three; a moment divided by the mass and multiplied back may round by an ulp
    assert np.allclose(back.inertial_vector(), pi, rtol=1e-14, atol=0)
    assert np.allclose(back.platform_com, params.platform_com, rtol=1e-14, atol=0)
    assert np.allclose(back.cylinder_com_distance, params.cylinder_com_distance, rtol=1e-14, atol=0)
    assert PlatformParams.inertial_names() == INERTIAL_NAMES and len(set(INERTIAL_NAMES)) == NUM_INERTIAL
    paper = PlatformParams.preset("narayan2017")
    assert paper.with_inertial_vector(paper.inertial_vector()).is_paper_model
    for name, value, match in (("platform.m", -1.0, "platform.m is negative"),
                               ("friction.coulomb_2", -1.0, "friction.coulomb_2"),
                               ("piston.mb", -0.1, "piston.mb"),
                               ("platform.Ixx", -50.0, "no physical body")):
        bad = pi.copy()
        bad[COLUMN(name)] = value
        with pytest.raises(ValueError, match=match):
            params.with_inertial_vector(bad)
    with pytest.raises(ValueError, match="pi: expected 32"):
        params.with_inertial_vector(pi[:5])


def test_friction_fields_are_checked_and_saved(tmp_path):
    params = PlatformParams.preset("narayan2017")
    with pytest.raises(ValueError, match="viscous_friction"):
        params.replace(viscous_friction=[1.0] * 5)
    with pytest.raises(ValueError, match="coulomb_friction"):
        params.replace(coulomb_friction=[-1.0] * 6)
    with pytest.raises(ValueError, match="coulomb_velocity"):
        params.replace(coulomb_velocity=0.0)
    rich = params.replace(viscous_friction=np.arange(6.0), coulomb_friction=np.full(6, 3.0), coulomb_velocity=0.01)
    rich.save(tmp_path / "p.toml")
    loaded = Platform.from_file(tmp_path / "p.toml")
    assert loaded.params == rich
