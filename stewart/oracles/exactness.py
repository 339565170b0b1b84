"""How exact is the paper's model? The effect of the legs' spin on the actuator forces.

The paper's legs do not spin about their axes (eq. 29). A real leg hangs from a universal
joint, which turns it about its axis as it swings, at a rate set by the joint's first axis
(:attr:`stewart.PlatformParams.universal_joint_axes`); the legs' axial inertia then enters
the dynamics. :func:`leg_spin_effect` measures, over random states around home
(:func:`stewart.oracles.physics.random_states`), how much the actuator forces of the exact-leg
model differ from the paper's, relative to the paper's, in two parts:

* the dynamic forces ``tau(x, xdot, xddot) - tau(x, 0, 0)``, everything but gravity;
* the velocity-dependent forces ``tau(x, xdot, 0) - tau(x, 0, 0)``.

Each state's change is ``|tau_exact - tau_paper| / |tau_paper|`` (Euclidean norms over the
six legs); the result gives its median and maximum. Both models are evaluated by the
numeric reference (:mod:`stewart.oracles.reference`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..model import arguments
from . import reference
from .physics import random_states
from ..model.params import platform_params
from ..model.params import PlatformParams

__all__ = ["Change", "LegSpinEffect", "leg_spin_effect"]


class Change(NamedTuple):
    """Median and maximum over the states of a relative change."""

    median: float
    max: float


class LegSpinEffect(NamedTuple):
    """The relative change of the actuator forces from the paper's legs to exact legs
    (:func:`leg_spin_effect`)."""

    dynamic: Change
    velocity: Change
    states: int
    assumed_axes: bool


def _force_parts(params: PlatformParams, x, xd, xdd) -> tuple[np.ndarray, np.ndarray]:
    """The dynamic and the velocity-dependent actuator forces (module docstring)."""
    zero = np.zeros_like(x)
    static = reference.inverse_dynamics(params, x, zero, zero)
    return (reference.inverse_dynamics(params, x, xd, xdd) - static,
            reference.inverse_dynamics(params, x, xd, zero) - static)


def leg_spin_effect(params: PlatformParams, n_states: int = 200, seed: int = 0) -> LegSpinEffect:
    """The change of the actuator forces when the legs turn with their universal joints.

    ``params`` with ``universal_joint_axes`` is compared with itself without them; without,
    the exact-leg model is :meth:`PlatformParams.with_universal_joints` (first axes
    horizontal and tangential to the base circle, an assumption: ``assumed_axes`` is then
    True). ``n_states`` random states from ``seed``."""
    params = platform_params(params)
    n_states = arguments.count("n_states", n_states, 10**7)
    seed = arguments.seed(seed)
    assumed = params.universal_joint_axes is None
    exact = params.with_universal_joints() if assumed else params
    paper = exact.replace(universal_joint_axes=None)
    x, xd, xdd = random_states(paper, n_states, np.random.default_rng(seed))
    changes = []
    for part, ours, theirs in zip(("dynamic", "velocity-dependent"), _force_parts(exact, x, xd, xdd),
                                  _force_parts(paper, x, xd, xdd)):
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            ratio = np.linalg.norm(ours - theirs, axis=-1) / np.linalg.norm(theirs, axis=-1)
        if not np.all(np.isfinite(ratio)):
            k = int(np.argmax(~np.isfinite(ratio)))
            raise ValueError(f"params: the paper's {part} forces are zero (a body without mass or inertia?) or "
                             f"overflow at state {k} of {n_states}: their relative change is undefined")
        changes.append(Change(float(np.median(ratio)), float(np.max(ratio))))
    return LegSpinEffect(*changes, states=n_states, assumed_axes=assumed)
