"""Exceptions raised for inputs where the model is undefined."""

from __future__ import annotations

__all__ = ["SingularityError", "ConvergenceError"]


class SingularityError(ValueError):
    """The model is undefined at this state: a singular J_C, theta = +-90 deg in forward
    dynamics, a vertical leg with non-axisymmetric leg inertia, or a degenerate leg.

    ``rows`` holds the indices of the offending states in a batch (``[0]`` for one state).
    """

    def __init__(self, message: str, rows=None):
        super().__init__(message)
        self.rows = [] if rows is None else list(rows)


class ConvergenceError(ValueError):
    """An iterative solve (forward kinematics) did not converge; ``rows`` as above."""

    def __init__(self, message: str, rows=None):
        super().__init__(message)
        self.rows = [] if rows is None else list(rows)
