"""Named results shared by the compiled model (:class:`~stewart.Platform`) and the
independent models that check it (:mod:`stewart.oracles`)."""

from typing import NamedTuple

import numpy as np

__all__ = ["JointReactions"]


class JointReactions(NamedTuple):
    """Actuator forces and joint forces of the Newton-Euler solution, all in {B}.

    tau : (..., 6) actuator force along each leg, positive pushing the platform away.
    base : (..., 6, 3) force the base exerts on leg i at its universal joint B_i.
    platform : (..., 6, 3) force leg i exerts on the platform at its spherical joint P_i.
    base_moment : (..., 6, 3) moment the base exerts on leg i through its universal joint,
        along ``a_i x y_i`` (zero in the paper's model).
    """

    tau: np.ndarray
    base: np.ndarray
    platform: np.ndarray
    base_moment: np.ndarray
