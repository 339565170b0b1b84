"""Base parameters: Y pi == Y_b beta on states they were not computed from, the parameters
that never act left out, the rank the same for any seed and sample count, and the lumping
a hand calculation gives (the pistons' masses move to the spherical joints on the platform)."""

from __future__ import annotations

import numpy as np
import pytest

import stewart
from stewart import Platform, PlatformParams
from stewart.identification.base_parameters import base_parameters
from stewart.oracles.physics import random_states, relative_error
from stewart.model.params import INERTIAL_NAMES, NUM_RIGID_BODY

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
    figures(f"base parameters: Y_b beta vs Y pi on fresh states ({label})", err, 1e-12)
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
                      rtol=1e-9, atol=1e-12)
    # the legs' transverse moments act only as cylinder + piston
    assert "cylinder.Iyy + piston.Iyy" in base.names and "cylinder.Izz + piston.Izz" in base.names


def test_rank_does_not_depend_on_the_samples_and_friction_can_be_left_out():
    plat = Platform.preset("motion_simulator")
    ranks = {base_parameters(plat, samples=n, seed=s).rank for n, s in ((30, 0), (200, 1), (500, 2))}
    assert ranks == {26}
    rigid = base_parameters(plat, friction=False)
    assert rigid.rank == 14 and rigid.columns == INERTIAL_NAMES[:NUM_RIGID_BODY]
    assert np.array_equal(rigid.values(plat.params.inertial_vector()),
                          rigid.values(plat.params.inertial_vector()[:NUM_RIGID_BODY]))


def test_bad_arguments():
    plat = Platform.preset("narayan2017")
    with pytest.raises(ValueError, match="samples"):
        base_parameters(plat, samples=3)
    with pytest.raises(ValueError, match="pi: expected"):
        base_parameters(plat).values(np.zeros(7))
