"""The prediction model of MPC cueing (:mod:`stewart.cueing.planner`): the platform as a double
integrator in its pose coordinates, what a rider at {P}'s origin senses of it, and the
vestibular model (:mod:`stewart.cueing.vestibular`) in discrete time.

* The input over a prediction interval of length ``h`` is the pose acceleration ``u``
  (``xddot``, Euler coordinates), held: ``p+ = p + h v + h^2/2 u``, ``v+ = v + h u``, exact.
* The rider's signals :func:`~stewart.cueing.vestibular.platform_signals`, ``f = R^T (a +
  g e_z)`` and ``w = R^T J_A [psi', theta', phi']`` (eq. 8), are taken at the interval's
  midpoint (``x + h/2 v + h^2/8 u``, ``v + h/2 u``) and linearized there with their exact
  derivatives (:meth:`stewart.Platform.rider_signals`, generated from the derivation).
* The vestibular transfer functions, per channel, as first-order sections discretized
  with the signal held over the interval (zero-order hold): :class:`VestibularStates`. The MPC carries the *difference* of the platform's and the
  vehicle's vestibular states, whose output is the perceived error.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy import signal

from ..model.params import PlatformParams
from ..model.platform import Platform
from . import vestibular

__all__ = ["VestibularStates", "midpoint"]


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


#: The numpy prediction kinematics this module held, now the model's generated functions:
#: deprecated, each through a platform of the geometry and gravity it names (the rotation and the
#: rider's signals depend on none of the rest), until 0.3.0.
_DEPRECATED = {
    "rotation_and_partials": "stewart.Platform.rotation(x, partials=True)",
    "signals_and_jacobians": "stewart.Platform.rider_signals",
    "joint_cosines_and_gradients": "stewart.Platform.joint_cosines",
}


def _platform(**changes) -> Platform:
    return Platform(PlatformParams.preset("motion_simulator").replace(**changes))


def _rotation_and_partials(x) -> np.ndarray:
    """``(4, N, 3, 3)``: ``R`` of the poses ``x`` ``(N, 6)`` and its partials in psi, theta, phi."""
    return np.stack(_platform().rotation(np.atleast_2d(x), partials=True))


def _signals_and_jacobians(x, v, u, gravity):
    """``(y, dy/dx, dy/dv, dy/du)`` of the rider's signals, ``(N, 6)`` and ``(N, 6, 6)``."""
    return tuple(_platform(gravity=gravity).rider_signals(*(np.atleast_2d(a) for a in (x, v, u))))


def _joint_cosines_and_gradients(x, base, joints, neutral):
    """The joints' cosines ``(N, 12)`` and their pose gradients ``(N, 12, 6)`` of the platform
    whose base and platform joints are ``base`` and ``joints`` ``(6, 3)``."""
    plat = _platform(base_points=base, platform_points=joints)
    return tuple(plat.joint_cosines(np.atleast_2d(x), neutral))


def __getattr__(name: str):
    if name not in _DEPRECATED:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    warnings.warn(f"{__name__}.{name} is deprecated: use {_DEPRECATED[name]} (generated, with exact Jacobians); "
                  "it goes in 0.3.0", DeprecationWarning, stacklevel=2)
    return globals()[f"_{name}"]
