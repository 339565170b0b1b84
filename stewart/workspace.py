"""Which poses the platform can reach: the one test used before a simulation and by the
command line's ``ik``, ``id`` and ``fd``.

A pose is reachable when

* every leg length is finite (a pose like ``z = 1e308`` overflows) and lies within
  ``params.leg_length_limits`` (when the set has limits);
* every spherical joint lies above the highest universal joint (the platform is above the base);
* ``J_C`` (eq. 5) is well conditioned: its condition number, with the rotational columns
  divided by the platform radius so that it does not depend on the units, is at most
  :data:`CONDITION_LIMIT` (the actuator forces that hold a load grow with it);
* the ZYX Euler angles are regular: ``|cos theta|`` is at least ``1 / CONDITION_LIMIT``
  (``T`` of eq. 18 is singular at ``theta = +-90 deg``);
* ``det J_C`` has the sign of the assembly mode the platform is in (by default the home
  pose's). ``det J_C`` is continuous, so a pose where it has the other sign is separated
  from the platform by a singularity (``det J_C = 0``): it belongs to another assembly
  mode and cannot be reached without passing one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _checks, kinematics
from .params import PlatformParams

__all__ = ["WorkspaceError", "Reachability", "reachability", "CONDITION_LIMIT"]

#: Largest unit-free condition number of ``J_C`` (and of the Euler-angle map) accepted.
CONDITION_LIMIT = 1e3

LEG_TOO_SHORT = 1
LEG_TOO_LONG = 2
BELOW_BASE = 4
SINGULAR = 8
EULER_SINGULAR = 16
OTHER_ASSEMBLY_MODE = 32
OUT_OF_RANGE = 64


class WorkspaceError(ValueError):
    """A pose, a target or a trajectory lies outside the workspace.

    ``rows`` are the offending rows (for a trajectory, the sample indices), ``times`` their
    times when known, and ``reachability`` the full :class:`Reachability`.
    """

    def __init__(self, message: str, reachability: "Reachability", times=None):
        super().__init__(message)
        self.reachability = reachability
        self.rows = np.flatnonzero(~reachability.ok).tolist()
        self.times = None if times is None else [float(times[r]) for r in self.rows]


@dataclass(frozen=True)
class Reachability:
    """Per-row result of :func:`reachability`.

    ``flags`` holds one integer per pose, a sum of the problem bits (0 for a reachable
    pose); ``lengths`` the leg lengths; ``condition`` the unit-free condition number of
    ``J_C`` where it exceeds :data:`CONDITION_LIMIT`, else an upper bound of it below the
    limit; ``ok`` is ``flags == 0``.
    """

    flags: np.ndarray
    lengths: np.ndarray
    condition: np.ndarray
    limits: tuple[float, float] | None

    @property
    def ok(self) -> np.ndarray:
        return self.flags == 0

    def _reason(self, bit: int, row: int) -> str:
        lengths = self.lengths[row]
        if bit == OUT_OF_RANGE:
            return "the pose is out of numeric range (its leg lengths overflow)"
        if bit == LEG_TOO_SHORT:
            legs = np.flatnonzero(lengths < self.limits[0]).tolist()
            return (f"leg(s) {legs} shorter than the minimum length {self.limits[0]:g} m "
                    f"({', '.join(f'{lengths[i]:.6g}' for i in legs)} m)")
        if bit == LEG_TOO_LONG:
            legs = np.flatnonzero(lengths > self.limits[1]).tolist()
            return (f"leg(s) {legs} longer than the maximum length {self.limits[1]:g} m "
                    f"({', '.join(f'{lengths[i]:.6g}' for i in legs)} m)")
        if bit == BELOW_BASE:
            return "the platform is not above the base"
        if bit == SINGULAR:
            return f"J_C is singular or nearly so (condition number {self.condition[row]:.3g} > {CONDITION_LIMIT:g})"
        if bit == EULER_SINGULAR:
            return "theta = +-90 deg, where the Euler angles are singular"
        return "det J_C has the other sign: the pose is in another assembly mode, beyond a singularity"

    def reasons(self, row: int) -> list[str]:
        """Human sentences for the problems of one row."""
        return [self._reason(bit, row) for bit in _BITS if self.flags[row] & bit]

    def message(self, what: str = "pose", times=None) -> str:
        """One line: how many rows are outside, and for each kind of problem the first row
        (or time) where it occurs and how many rows share it."""
        bad = np.flatnonzero(~self.ok)
        if bad.size == 0:
            return f"every {what} is reachable"
        parts = []
        for bit in _BITS:
            rows = np.flatnonzero(self.flags & bit)
            if rows.size:
                where = f"t = {float(times[rows[0]]):.4g} s" if times is not None else f"row {rows[0]}"
                more = f" and {rows.size - 1} more" if rows.size > 1 else ""
                parts.append(f"{self._reason(bit, rows[0])} at {where}{more}")
        return f"{bad.size} of {len(self.flags)} {what}(s) outside the workspace: " + "; ".join(parts)


_BITS = (OUT_OF_RANGE, LEG_TOO_SHORT, LEG_TOO_LONG, BELOW_BASE, SINGULAR, EULER_SINGULAR, OTHER_ASSEMBLY_MODE)


def _platform_radius(params: PlatformParams) -> float:
    points = params.platform_points
    return float(np.max(np.sqrt(np.sum((points - points.mean(axis=0)) ** 2, axis=1))))


def assembly_mode(platform, pose) -> float:
    """The sign of ``det J_C`` at ``pose``: +1 or -1 (0 at a singularity)."""
    with np.errstate(all="ignore"):
        return float(np.nan_to_num(np.sign(np.linalg.det(kinematics.jacobian(_params(platform), pose)))))


def _params(platform) -> PlatformParams:
    params = getattr(platform, "params", platform)
    if not isinstance(params, PlatformParams):
        raise ValueError(f"platform: expected a stewart.Platform or PlatformParams, got {type(platform).__name__}")
    return params


def reachability(platform, poses, *, mode: float | None = None, name: str = "poses") -> Reachability:
    """Check ``poses`` (``(6,)`` or ``(N, 6)``) against the workspace of ``platform`` (a
    :class:`~stewart.Platform` or :class:`~stewart.PlatformParams`).

    ``mode`` is the sign of ``det J_C`` of the assembly mode the poses must lie in
    (default: the home pose's, see :func:`assembly_mode`). Returns a :class:`Reachability`
    with one row per pose.
    """
    from .platform import Platform

    plat = platform if isinstance(platform, Platform) else Platform(_params(platform))
    x = np.atleast_2d(_checks.states(name, poses))
    if np.iscomplexobj(x):
        raise ValueError(f"{name}: expected real poses")
    if mode is None:
        mode = assembly_mode(plat, plat.home_pose)
    blocks = [_block(plat, x[i:i + _BLOCK], mode) for i in range(0, len(x), _BLOCK)]
    flags, lengths, condition = (np.concatenate(parts) for parts in zip(*blocks))
    return Reachability(flags=flags, lengths=lengths, condition=condition, limits=plat.params.leg_length_limits)


_BLOCK = 50_000  # poses checked at a time (bounds the memory of long trajectories)


def _condition(jac: np.ndarray, det: np.ndarray) -> np.ndarray:
    """Condition numbers of a batch of 6x6 matrices (inf where singular or non-finite).

    Guggenheimer, Edelman & Johnson's bound ``2 / |det J| (|J|_F / sqrt 6)^6`` (SIAM J.
    Numer. Anal. 32, 1995) exceeds the 2-norm condition number and costs no more than the
    determinant; only rows where it exceeds :data:`CONDITION_LIMIT` get the exact value
    from an SVD, so the other rows hold the bound.
    """
    with np.errstate(all="ignore"):
        out = 2.0 / np.abs(det) * (np.sum(jac * jac, axis=(1, 2)) / 6.0) ** 3
    exact = np.flatnonzero(~(out <= CONDITION_LIMIT))
    finite = exact[np.all(np.isfinite(jac[exact]), axis=(1, 2))]
    out[exact] = np.inf
    if finite.size:
        out[finite] = np.linalg.cond(jac[finite])
    return out


def _block(plat, x: np.ndarray, mode: float):
    params = plat.params
    lengths = plat.leg_lengths(x, return_mask=True)[0]
    flags = np.where(np.all(np.isfinite(lengths), axis=1), 0, OUT_OF_RANGE)
    limits = params.leg_length_limits
    if limits is not None:
        flags |= np.where(np.any(lengths < limits[0], axis=1), LEG_TOO_SHORT, 0)
        flags |= np.where(np.any(lengths > limits[1], axis=1), LEG_TOO_LONG, 0)
    # Height of each spherical joint, p_z + (R p_i)_z, with the last row of R (eq. 3).
    sth, cth = np.sin(x[:, 4:5]), np.cos(x[:, 4:5])
    sph, cph = np.sin(x[:, 5:6]), np.cos(x[:, 5:6])
    p = params.platform_points
    joint_heights = x[:, 2:3] - sth * p[:, 0] + cth * sph * p[:, 1] + cth * cph * p[:, 2]
    flags |= np.where(np.min(joint_heights, axis=1) <= np.max(params.base_points[:, 2]), BELOW_BASE, 0)
    with np.errstate(all="ignore"):
        jac = plat.jacobian(x, return_mask=True)[0]
        jac[..., 3:] /= _platform_radius(params)
        det = np.linalg.det(np.nan_to_num(jac))
        condition = _condition(jac, det)
    flags |= np.where(~(condition <= CONDITION_LIMIT), SINGULAR, 0)
    flags |= np.where(np.abs(np.cos(x[:, 4])) < 1.0 / CONDITION_LIMIT, EULER_SINGULAR, 0)
    flags |= np.where(np.sign(det) * mode < 0, OTHER_ASSEMBLY_MODE, 0)
    return flags, lengths, condition
