"""Random states of a platform, for studies, identification and checks."""

import numpy as np

from . import kinematics
from .params import PlatformParams

__all__ = ["random_states"]


def random_states(params: PlatformParams, n: int, rng: np.random.Generator):
    """``n`` poses around home (within 8% of the home height and 0.2 rad), with rates and
    accelerations of matching scale: ``(x, xd, xdd)``, each ``(n, 6)``."""
    home = kinematics.home_pose(params)
    scale = home[2]
    sigma = np.array([0.04 * scale] * 3 + [0.1] * 3)
    x = home + rng.uniform(-2, 2, size=(n, 6)) * sigma
    xd = rng.normal(size=(n, 6)) * np.array([0.2 * scale] * 3 + [0.5] * 3)
    xdd = rng.normal(size=(n, 6)) * np.array([2 * scale] * 3 + [5.0] * 3)
    return x, xd, xdd
