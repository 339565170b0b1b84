"""Exceptions raised for inputs where the model is undefined, for an argument of the wrong
type, and for an environment that names no instruction-set path of the build."""

from __future__ import annotations

import sys

__all__ = ["SingularityError", "ConvergenceError", "WrongTypeError", "SimdPathError", "UnstableError"]


def row_list(rows) -> str:
    """The first ten of ``rows`` for a message, with ``...`` when there are more."""
    rows = list(rows)
    return f"{rows[:10]}{' ...' if len(rows) > 10 else ''}"


class SingularityError(ValueError):
    """The model is undefined at this state: a singular J_C, theta = +-90 deg in forward
    dynamics, a vertical leg with non-axisymmetric leg inertia, a degenerate leg, a
    singular mass matrix (a massless platform) or a result that overflows.

    ``rows`` holds the indices of the offending states in a batch (``[0]`` for one state);
    ``condition`` names the condition (of the first offending row), one of
    :data:`stewart.model.conditions.CONDITIONS`: ``"nonfinite"``, ``"leg_degenerate"``,
    ``"jacobian_singular"``, ``"euler_singular"``, ``"leg_vertical"`` or ``"mass_singular"``.
    """

    def __init__(self, message: str, rows=None, condition: str | None = None):
        super().__init__(message)
        self.rows = [] if rows is None else list(rows)
        self.condition = condition

    @classmethod
    def at_rows(cls, function: str, condition: str, message: str, rows, batch: bool) -> "SingularityError":
        """The error of ``function`` for ``condition`` (described by ``message``) at ``rows``
        of a batch (``batch``) or at one state: ``"<function>: <message>[ at row(s) [...]]"``."""
        rows = list(rows)
        where = f" at row(s) {row_list(rows)}" if batch else ""
        return cls(f"{function}: {message}{where}", rows=rows, condition=condition)


class ConvergenceError(ValueError):
    """An iterative solve (forward kinematics) did not converge; ``rows`` as above."""

    def __init__(self, message: str, rows=None):
        super().__init__(message)
        self.rows = [] if rows is None else list(rows)


class WrongTypeError(TypeError, ValueError):
    """An argument that is not the kind of object the function takes (a
    :class:`~stewart.PlatformParams` where a :class:`~stewart.Platform` belongs, ``None``
    ...), named in the message with what to pass instead. It is a ``TypeError``, and a
    ``ValueError`` as every other check of an argument raises, so that ``except ValueError``
    catches any bad input."""


class SimdPathError(SystemExit):
    """``STEWART_SIMD`` names no instruction-set path of the build, or one this CPU lacks: a
    mistake in the environment, found when ``stewart`` is imported.  It is reported as the
    ``stewart`` command reports a usage error: one line on stderr (:meth:`report`), exit
    code 2, no traceback.  ``message`` is the line."""

    #: The exit code (a usage error, as argparse and the ``stewart`` command give it).
    CODE = 2

    def __init__(self, message: str):
        super().__init__(self.CODE)
        self.message = message

    def __str__(self) -> str:
        return self.message

    @classmethod
    def report(cls, message: str) -> "SimdPathError":
        """Print ``stewart: error: <message>`` to stderr; the error to raise."""
        print(f"stewart: error: {message}", file=sys.stderr)
        return cls(message)


class UnstableError(ValueError):
    """A pose that the preloaded leg springs cannot hold: the stiffness matrix there is not
    positive definite, so the static equilibrium is unstable (the preload buckles the
    platform) and it has no modes of oscillation (:mod:`stewart.model.stiffness`); ``rows``
    as for :class:`SingularityError`."""

    def __init__(self, message: str, rows=None):
        super().__init__(message)
        self.rows = [] if rows is None else list(rows)
