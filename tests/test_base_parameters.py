"""Base parameters: Y pi == Y_b beta on states they were not computed from, the parameters
that never act left out, the rank the same for any seed and sample count, and the lumping
a hand calculation gives (the pistons' masses move to the spherical joints on the platform)."""

from __future__ import annotations


import numpy as np
import pytest

import stewart
from stewart import Platform, PlatformParams
from stewart.identification.base_parameters import base_parameters
from stewart.model import kinematics
from stewart.oracles import reference as ref
from stewart.oracles.physics import random_states, relative_error
from stewart.model.params import INERTIAL_NAMES, NUM_RIGID_BODY

from conftest import inertial_step
from test_general_kernels import random_general


def _platforms():
    general = PlatformParams.preset("narayan2017").with_universal_joints().with_payload(20.0, [0.05, 0.0, 0.1],
                                                                                        [1.0, 2.0, 3.0])
    return [(name, PlatformParams.preset(name)) for name in stewart.presets()] + [
        ("general, payload", general), ("random general", random_general(3))]


@pytest.mark.parametrize("label,params", _platforms(), ids=[label for label, _ in _platforms()])
def test_base_regressor_reproduces_the_forces(label, params, figures):
    plat = Platform(params.replace(viscous_friction=np.full(6, 50.0), coulomb_friction=np.full(6, 20.0)))
    base = base_parameters(plat, seed=1)
    x, xd, xdd = random_states(plat.params, 500, np.random.default_rng(99))  # not the states of the fit
    Y, ok = plat.regressor(x, xd, xdd, return_mask=True)
    pi = plat.params.inertial_vector()
    err = relative_error(base.reduce(Y[ok]) @ base.values(pi), Y[ok] @ pi)
    figures(f"base parameters: Y_b beta vs Y pi on fresh states ({label})", err, 5e-13)  # reached 7.9e-15
    # each column is kept or is a combination of those kept; the stacked base regressor has full rank
    stack = base.reduce(Y[ok]).reshape(-1, base.rank)
    assert np.linalg.matrix_rank(stack / np.linalg.norm(stack, axis=0)) == base.rank
    assert base.rank == len(base.names) and base.matrix.shape == (base.rank, len(INERTIAL_NAMES))


def test_parameters_that_never_act_are_left_out_and_known_lumps():
    base = base_parameters(Platform.preset("narayan2017"))
    unused = [name for name, used in zip(base.columns, np.any(base.matrix, axis=0)) if not used]
    assert unused == ["cylinder.m", "cylinder.Ixx", "piston.Ixx"]
    assert "never act: cylinder.m, cylinder.Ixx, piston.Ixx" in base.describe()
    # a piston's mass acts at its spherical joint P_i, a point of the platform: the six add to
    # the platform's mass, and m_S sum p_i to its first moment (hand calculation)
    params = PlatformParams.preset("narayan2017")
    row = base.names.index("platform.m + 6 piston.m")
    assert base.matrix[row, INERTIAL_NAMES.index("piston.m")] == 6.0
    mx = base.matrix[:, INERTIAL_NAMES.index("platform.mx")].argmax()
    assert np.isclose(base.matrix[mx, INERTIAL_NAMES.index("piston.m")], params.platform_points[:, 0].sum(),
                      rtol=0, atol=2e-14)  # reached 3.9e-16 (of a sum 6.2e-3)
    # the legs' transverse moments act only as cylinder + piston
    assert "cylinder.Iyy + piston.Iyy" in base.names and "cylinder.Izz + piston.Izz" in base.names


def reference_regressor_rank(params, states=40, seed=7):
    """``(rigid, with friction)``: the numerical rank (SVD) of the regressor of the numeric
    reference's inverse dynamics (not the kernel's regressor), its columns the changes of the
    forces per unit change of each rigid-body parameter (exact up to round-off: the forces are
    linear in them), and the friction law's ``Ldot_i`` and ``tanh(Ldot_i / v_c)`` on leg ``i``
    from the numpy kinematics. Columns under 1e-8 of the largest never act (the cylinders'
    masses and the legs' axial moments, zero up to round-off); the singular values of the
    rest, each scaled to unit norm, either exceed 1e-2 or stay under 1e-9 (the lumps: the
    pistons' masses into the platform's, the legs' transverse moments as cylinder + piston),
    and the rank counts those over 1e-6. A hand count gives the same: 20 rigid-body
    parameters, 3 that never act and 3 lumps leave 14; friction adds 2 per leg, 26."""
    rng = np.random.default_rng(seed)
    x, xd, xdd = random_states(params, states, rng)
    pi, size = params.inertial_vector(), np.max(np.abs(params.platform_points))
    tau = ref.inverse_dynamics(params, x, xd, xdd)
    columns = []
    for k, name in enumerate(INERTIAL_NAMES[:NUM_RIGID_BODY]):
        body, entry = name.split(".")
        mass = pi[INERTIAL_NAMES.index(f"{body}.m")]
        moments = max(abs(pi[INERTIAL_NAMES.index(f"{body}.I{axis}")]) for axis in ("xx", "yy", "zz"))
        step = 1e-4 * {"m": mass, "I": moments}.get(entry[0], mass * size)
        moved, signed = inertial_step(params, k, step, lambda p: ref.inverse_dynamics(p, x, xd, xdd))
        columns.append(((moved - tau) / signed).ravel())
    rates = kinematics.leg_velocities(params, x, xd)
    for law in (rates, np.tanh(rates / params.coulomb_velocity)):
        columns += [(law[:, [i]] * np.eye(6)[i]).ravel() for i in range(6)]
    norms = np.linalg.norm(columns, axis=1)
    acts = norms >= 1e-8 * np.max(norms)
    ranks = []
    for count in (NUM_RIGID_BODY, len(columns)):
        kept = np.array(columns)[:count][acts[:count]] / norms[:count][acts[:count], None]
        singular = np.linalg.svd(kept.T, compute_uv=False)
        assert not np.any((singular > 1e-9 * singular[0]) & (singular < 1e-2 * singular[0])), singular
        ranks.append(int(np.sum(singular > 1e-6 * singular[0])))
    return tuple(ranks)


def test_rank_does_not_depend_on_the_samples_and_friction_can_be_left_out():
    plat = Platform.preset("motion_simulator")
    rigid_rank, rank = reference_regressor_rank(plat.params)
    assert (rigid_rank, rank) == (14, 26)  # the hand count of reference_regressor_rank
    ranks = {base_parameters(plat, samples=n, seed=s).rank for n, s in ((30, 0), (200, 1), (500, 2))}
    assert ranks == {rank}
    rigid = base_parameters(plat, friction=False)
    assert rigid.rank == rigid_rank and rigid.columns == INERTIAL_NAMES[:NUM_RIGID_BODY]
    assert np.array_equal(rigid.values(plat.params.inertial_vector()),
                          rigid.values(plat.params.inertial_vector()[:NUM_RIGID_BODY]))


def test_bad_arguments():
    plat = Platform.preset("narayan2017")
    with pytest.raises(ValueError, match="samples"):
        base_parameters(plat, samples=3)
    with pytest.raises(ValueError, match="pi: expected"):
        base_parameters(plat).values(np.zeros(7))
