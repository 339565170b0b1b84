"""The prediction model of MPC cueing (:mod:`stewart.cueing.planner`): the platform as a double
integrator in its pose coordinates, what a rider at {P}'s origin senses of it, and the
vestibular model (:mod:`stewart.cueing.vestibular`) in discrete time.

* The input over a prediction interval of length ``h`` is the pose acceleration ``u``
  (``xddot``, Euler coordinates), held: ``p+ = p + h v + h^2/2 u``, ``v+ = v + h u``, exact.
* The rider's signals :func:`~stewart.cueing.vestibular.platform_signals`, ``f = R^T (a +
  g e_z)`` and ``w = R^T J_A [psi', theta', phi']`` (eq. 8), are taken at the interval's
  midpoint (``x + h/2 v + h^2/8 u``, ``v + h/2 u``) and linearized there with their exact
  derivatives (:func:`signals_and_jacobians`).
* The vestibular transfer functions, per channel, as first-order sections discretized
  with the signal held over the interval (zero-order hold): :class:`VestibularStates`. The MPC carries the *difference* of the platform's and the
  vehicle's vestibular states, whose output is the perceived error.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from . import vestibular

__all__ = ["VestibularStates", "signals_and_jacobians", "midpoint"]


class VestibularStates:
    """The vestibular model of all six channels as one diagonal state space: otoliths (2
    states each) for ``fx, fy, fz``, canals (3 states each) for ``wx, wy, wz``, in the order
    of :data:`~stewart.cueing.vestibular.CHANNELS`. Each transfer function, strictly proper
    with distinct real poles, is split into first-order sections ``r_i / (s - p_i)``
    (:func:`scipy.signal.residue`), each a state ``z_i' = p_i z_i + |p_i| u`` read as
    ``r_i / |p_i| z_i``: states of the size of the signal, whatever their time constant,
    so the QP is well scaled. ``C`` ``(6, n)`` gives the perceived signals."""

    def __init__(self):
        sections = [_sections(vestibular.otolith())] * 3 + [_sections(vestibular.canal())] * 3
        self.n = int(sum(len(p) for p, _ in sections))
        self.A = np.zeros((self.n, self.n))
        self.B = np.zeros((self.n, 6))
        self.C = np.zeros((6, self.n))
        start = 0
        for j, (poles, gains) in enumerate(sections):
            k = np.arange(start, start + len(poles))
            self.A[k, k] = poles
            self.B[k, j] = np.abs(poles)
            self.C[j, k] = gains / np.abs(poles)
            start += len(poles)
        self.block = np.eye(self.n, dtype=bool)  # the nonzero pattern of A (diagonal)

    def discrete(self, h: float) -> tuple[np.ndarray, np.ndarray]:
        """``(Ad, Bd)`` of the zero-order-hold discretization over ``h`` seconds (exact for
        the diagonal ``A``: ``e^{p h}`` and ``(e^{p h} - 1) / p`` times ``B``)."""
        poles = np.diag(self.A)
        decay = np.exp(poles * h)
        return np.diag(decay), ((decay - 1.0) / poles)[:, None] * self.B

    def steady_state(self, y) -> np.ndarray:
        """The states ``(n,)`` at rest under the constant signals ``y`` ``(6,)``."""
        return -(self.B @ np.asarray(y, dtype=float)) / np.diag(self.A)


def _sections(tf: signal.TransferFunction) -> tuple[np.ndarray, np.ndarray]:
    """Poles and residues of a strictly proper transfer function with distinct real poles."""
    residues, poles, direct = signal.residue(tf.num, tf.den)
    if np.any(direct) or np.any(np.abs(poles.imag) > 0) or len(set(np.round(poles.real, 12))) < len(poles):
        raise ValueError("vestibular model: need a strictly proper transfer function with distinct real poles")
    return poles.real, residues.real


def midpoint(p, v, u, h):
    """Pose and rates at the middle of an interval of length ``h`` under acceleration ``u``."""
    return p + 0.5 * h * v + 0.125 * h * h * u, v + 0.5 * h * u


def rotation_and_partials(x) -> np.ndarray:
    """``R = Rz(psi) Ry(theta) Rx(phi)`` of poses ``x`` ``(N, 6)`` and its partials in psi,
    theta and phi, entry by entry: ``(4, N, 3, 3)``."""
    cps, sps = np.cos(x[:, 3]), np.sin(x[:, 3])
    cth, sth = np.cos(x[:, 4]), np.sin(x[:, 4])
    cph, sph = np.cos(x[:, 5]), np.sin(x[:, 5])
    r = np.zeros((4, len(x), 3, 3))
    r[0, :, 0] = np.stack([cps * cth, cps * sth * sph - sps * cph, cps * sth * cph + sps * sph], -1)
    r[0, :, 1] = np.stack([sps * cth, sps * sth * sph + cps * cph, sps * sth * cph - cps * sph], -1)
    r[0, :, 2] = np.stack([-sth, cth * sph, cth * cph], -1)
    r[1, :, 0] = -r[0, :, 1]
    r[1, :, 1] = r[0, :, 0]
    r[2, :, 0] = np.stack([-cps * sth, cps * cth * sph, cps * cth * cph], -1)
    r[2, :, 1] = np.stack([-sps * sth, sps * cth * sph, sps * cth * cph], -1)
    r[2, :, 2] = np.stack([-cth, -sth * sph, -sth * cph], -1)
    r[3, :, :, 1] = r[0, :, :, 2]
    r[3, :, :, 2] = -r[0, :, :, 1]
    return r


def joint_cosines_and_gradients(x, base_points, platform_points, neutral):
    """The cosines of the universal- and spherical-joint angles at poses ``x`` ``(N, 6)``
    (:func:`stewart.model.reachability.joint_angles`: the leg's unit vector ``u_i`` against
    its neutral axis ``a_i`` fixed in {B}, and against ``R a_i`` for the spherical joint
    fixed in {P}), ``(N, 12)``, and their exact gradients in the pose ``(N, 12, 6)``: with
    ``l_i = p + R p_i - b_i``, ``du/dl = (I - u u^T) / |l|``, ``dl/dp = I``,
    ``dl/dangle = dR/dangle p_i``."""
    x = np.atleast_2d(x)
    n = len(x)
    r = rotation_and_partials(x)
    rp = np.einsum("knab,ib->knia", r, platform_points)                    # R p_i and partials (4, N, 6, 3)
    legs = x[:, None, :3] + rp[0] - base_points
    length = np.linalg.norm(legs, axis=-1)
    u = legs / length[..., None]
    dl = np.zeros((n, 6, 3, 6))
    dl[:, :, :, :3] = np.eye(3)
    dl[:, :, :, 3:] = np.transpose(rp[1:], (1, 2, 3, 0))
    proj = (np.eye(3) - u[..., :, None] * u[..., None, :]) / length[..., None, None]
    du = proj @ dl                                                        # (N, 6, 3, 6)
    spherical_axis = np.einsum("nab,ib->nia", r[0], neutral)              # R a_i
    cos = np.concatenate([np.einsum("nia,ia->ni", u, neutral), np.einsum("nia,nia->ni", u, spherical_axis)], 1)
    grad = np.zeros((n, 12, 6))
    grad[:, :6] = np.einsum("ia,niaj->nij", neutral, du)
    grad[:, 6:] = np.einsum("nia,niaj->nij", spherical_axis, du)
    grad[:, 6:, 3:] += np.einsum("nia,knab,ib->nik", u, r[1:], neutral)
    return cos, grad


def signals_and_jacobians(x, v, u, gravity):
    """The rider's specific force and angular velocity ``y = [f; w]`` ``(N, 6)`` for poses
    ``x``, pose rates ``v`` and pose accelerations ``u`` ``(N, 6)``, and their exact
    Jacobians ``dy/dx``, ``dy/dv``, ``dy/du`` ``(N, 6, 6)``: ``f = R^T (a + g e_z)`` with
    ``R = Rz(psi) Ry(theta) Rx(phi)`` and ``w = E [psi', theta', phi']`` with ``E = R^T J_A``
    (:func:`stewart.cueing.vestibular.platform_signals`)."""
    x, v, u = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (x, v, u))
    n = len(x)
    r = rotation_and_partials(x)
    cth, sth = np.cos(x[:, 4]), np.sin(x[:, 4])
    cph, sph = np.cos(x[:, 5]), np.sin(x[:, 5])
    b = u[:, :3].copy()
    b[:, 2] += gravity
    y = np.empty((n, 6))
    dy_dx = np.zeros((n, 6, 6))
    dy_dv = np.zeros((n, 6, 6))
    dy_du = np.zeros((n, 6, 6))
    rtb = np.einsum("knji,nj->kni", r, b)                  # R^T b and its partials
    y[:, :3] = rtb[0]
    dy_dx[:, :3, 3:] = np.transpose(rtb[1:], (1, 2, 0))
    dy_du[:, :3, :3] = np.transpose(r[0], (0, 2, 1))
    e = np.zeros((3, n, 3, 3))                             # E and its partials in theta, phi
    e[0, :, 0, 0], e[0, :, 0, 2] = -sth, 1.0
    e[0, :, 1, 0], e[0, :, 1, 1] = cth * sph, cph
    e[0, :, 2, 0], e[0, :, 2, 1] = cth * cph, -sph
    e[1, :, 0, 0], e[1, :, 1, 0], e[1, :, 2, 0] = -cth, -sth * sph, -sth * cph
    e[2, :, 1, 0], e[2, :, 1, 1] = cth * cph, -sph
    e[2, :, 2, 0], e[2, :, 2, 1] = -cth * sph, -cph
    er = np.einsum("knij,nj->kni", e, v[:, 3:])
    y[:, 3:] = er[0]
    dy_dx[:, 3:, 4] = er[1]
    dy_dx[:, 3:, 5] = er[2]
    dy_dv[:, 3:, 3:] = e[0]
    return y, dy_dx, dy_dv, dy_du
