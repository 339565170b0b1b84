"""The compiled joint reactions (``Platform.joint_reactions``, generated C) against the
Newton-Euler solution in numpy (stewart.oracles.newton_euler, an independent formulation), and, for
the paper's legs with I_yy != I_zz that Newton-Euler does not model, against the platform's
own Newton and Euler equations."""

from __future__ import annotations

import numpy as np
import pytest

import stewart
from stewart.model import kinematics
from stewart.oracles import frames, newton_euler as ne
from stewart.oracles.physics import COMPLEX_STEP, random_states, relative_error

from conftest import random_params
from test_general_kernels import random_general


def _compare(params, n, seed, figures, label):
    x, xd, xdd = random_states(params, n, np.random.default_rng(seed))
    fast = stewart.Platform(params).joint_reactions(x, xd, xdd)
    exact = ne.joint_reactions(params, x, xd, xdd)
    for name in ("tau", "base", "platform"):
        figures(f"joint reactions vs Newton-Euler, {name} ({label})",
                relative_error(getattr(fast, name), getattr(exact, name)), 1e-13)  # reached 2.4e-15
    scale = np.max(np.linalg.norm(exact.base, axis=-1))  # the moment against the forces' lever
    size = np.max(np.linalg.norm(params.base_points, axis=-1))
    figures(f"joint reactions vs Newton-Euler, base moment ({label})",
            float(np.max(np.abs(fast.base_moment - exact.base_moment)) / (scale * size)), 1e-15)  # reached 1.7e-17
    return fast, exact


def test_paper_model_against_newton_euler(any_params, figures):
    fast, _ = _compare(any_params, 300, 70, figures, any_params.name)
    assert np.all(fast.base_moment == 0.0)  # axisymmetric legs need no moment from their joints


def test_general_model_against_newton_euler(general_params, figures):
    fast, exact = _compare(general_params, 300, 71, figures, f"general {general_params.name}")
    assert np.max(np.linalg.norm(exact.base_moment, axis=-1)) > 0.0


@pytest.mark.parametrize("seed", [0, 1])
def test_random_general_platform_against_newton_euler(seed, figures):
    _compare(random_general(900 + seed), 300, 72 + seed, figures, f"random general {seed}")


def _platform_twist_rates(x, xd, xdd):
    """omega and alpha = d omega / dt of the platform (eq. 8), alpha by complex step."""
    h = COMPLEX_STEP
    omega = np.einsum("nij,nj->ni", frames.euler_rate_jacobian(x), xd[:, 3:])
    moving = np.einsum("nij,nj->ni", frames.euler_rate_jacobian(x + 1j * h * xd), xd[:, 3:] + 1j * h * xdd[:, 3:])
    return omega, moving.imag / h


def test_legs_in_the_papers_frames_balance_the_platform(figures):
    """Legs with I_yy != I_zz in the paper's model (frames of eqs. 43-48), where Newton-Euler
    does not apply: the forces the legs exert on the platform satisfy its Newton and Euler
    equations, m_P (a + g e_z) = sum f_P and I_P alpha + omega x I_P omega = sum r_i x f_P
    (about its centre of mass, the origin of {P}); the universal joints' moment lies along
    each leg and is not zero."""
    params = random_params(np.random.default_rng(73), axisymmetric=False)
    x, xd, xdd = random_states(params, 200, np.random.default_rng(74))
    forces = stewart.Platform(params).joint_reactions(x, xd, xdd)
    rot = frames.rotation(x)
    arms = np.einsum("nij,kj->nki", rot, params.platform_points)
    omega, alpha = _platform_twist_rates(x, xd, xdd)
    inertia = rot @ np.diag(params.platform_inertia) @ np.swapaxes(rot, -1, -2)
    weight = params.platform_mass * (xdd[:, :3] + [0.0, 0.0, params.gravity])
    euler = (np.einsum("nij,nj->ni", inertia, alpha)
             + np.cross(omega, np.einsum("nij,nj->ni", inertia, omega)))
    push = forces.platform.sum(axis=1)
    moment = np.cross(arms, forces.platform).sum(axis=1)
    figures("joint reactions, paper's frames: platform Newton equation", relative_error(push, weight), 5e-14)  # reached 8.0e-16
    scale = np.max(np.abs(moment))
    figures("joint reactions, paper's frames: platform Euler equation",
            float(np.max(np.abs(moment - euler)) / scale), 5e-14)  # reached 1.4e-15
    u = kinematics.leg_unit_vectors(params, x)
    across = np.linalg.norm(np.cross(forces.base_moment, u), axis=-1)
    assert np.max(across) <= 1e-14 * np.max(np.linalg.norm(forces.base_moment, axis=-1))  # reached 1.6e-16
    assert np.max(np.linalg.norm(forces.base_moment, axis=-1)) > 0.0


def test_one_state_and_masked_rows():
    """One state gives the rows of a batch; a singular row comes back NaN with return_mask."""
    params = stewart.PlatformParams.preset("narayan2017")
    plat = stewart.Platform(params)
    x, xd, xdd = random_states(params, 20, np.random.default_rng(75))
    batch = plat.joint_reactions(x, xd, xdd)
    assert [a.shape for a in batch] == [(20, 6), (20, 6, 3), (20, 6, 3), (20, 6, 3)]
    one = plat.joint_reactions(x[5], xd[5], xdd[5])
    for a, b in zip(one, batch):
        np.testing.assert_array_equal(a, b[5])  # the same compiled code: bit for bit
    x[3] = np.r_[np.asarray(params.base_points[0]) - params.platform_points[0], 0.0, 0.0, 0.0]  # leg 0 of length 0
    result, ok = plat.joint_reactions(x, xd, xdd, return_mask=True)
    assert not ok[3] and ok.sum() == 19
    assert all(np.all(np.isnan(a[3])) for a in result)
    with pytest.raises(stewart.SingularityError, match="3"):
        plat.joint_reactions(x, xd, xdd)
