"""The washout's limiter: the classical washout's poses brought back into the workspace,
smoothly, where they would leave it (:func:`limit`).

The washout's filters are linear; a glitch in the log (a 30 g spike for a few samples) or a
maneuver harder than its design moves the reference out of the workspace. The limiter
scales the excursion from home, all six axes together, by ``s(t)`` in ``(0, 1]``::

    limited(t) = home + s(t) (pose(t) - home)

so the reference keeps its direction (the cue's shape, smaller) and returns to the washout's
own poses once it is back inside. ``s`` comes in three steps:

1. **Need.** A pose is *inside the margin* when its excursion stretched by ``1 + margin``
   stays in the workspace: every point of the ray from home to ``home + (1 + margin) (pose -
   home)`` reachable (:func:`stewart.reachability`: stroke, joint cones, clearance, plate,
   conditioning; on a rotary rig :func:`stewart.cueing.rotary.check_poses`: every limit of the
   rotary workspace, the cones included, and the cranks' reach; checked at :data:`RAY_POINTS` points of the ray, then the first crossing
   found by bisection to :data:`RAY_TOLERANCE`). Where the ray leaves the workspace at
   ``c (pose - home)``, the pose needs ``s <= c / (1 + margin)``; inside the margin, 1.
2. **Envelope.** The needed deficit ``1 - s`` is spread by a moving maximum over
   ``ramp_time`` (centred: the whole log is known), then smoothed by a Hann window of the
   same length, so the scale starts going down ``ramp_time`` ahead of the need (half of it
   from the maximum, half from the window) and comes back as long after it. A Hann-weighted mean of maxima whose windows all cover
   ``t`` is at least the need at ``t``, so ``s`` never exceeds the need; and a drop ``D`` of
   the scale takes ``s`` a rate of at most about ``2 D / ramp_time`` and a second derivative of
   at most about ``2 pi D / ramp_time^2``: continuous pose rates, bounded accelerations.
   Where no need lies within ``ramp_time``, the deficit is exactly 0 and the pose is
   the washout's own, bit for bit.
3. **Check.** The limited poses are checked with :func:`stewart.reachability`; a pose still
   outside (a workspace not star-shaped about home along that ray) has its need tightened
   by :data:`TIGHTEN` and the envelope is made again (at most :data:`MAX_PASSES` passes;
   a reference still outside after them is reported outside, as without the limiter).

Every row's ray is checked in one batch call of :func:`stewart.reachability` (``RAY_POINTS``
poses a sample; 8 to 15 us a pose): the shipped 28 s take-off roll at 100 Hz is limited in
0.3 s on ``narayan2017`` and 0.5 s on ``motion_simulator``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage, signal

from ..model.kinematics import POSE_AXES
from ..model.reachability import FLAG_NAMES, FLAGS, reachability
from . import rotary

__all__ = ["Limiting", "limit", "RAY_POINTS", "RAY_TOLERANCE", "TIGHTEN", "MAX_PASSES"]

#: Points of each ray from home checked before the bisection (a workspace that leaves and
#: re-enters the ray between two of them is caught by the final check).
RAY_POINTS = 8
#: The bisection's width of the crossing, as a share of the stretched excursion.
RAY_TOLERANCE = 1e-6
#: Factor applied to the need of a limited pose the final check finds outside.
TIGHTEN = 0.9
#: Passes of envelope and check before a reference still outside is left to the report.
MAX_PASSES = 8


@dataclass(frozen=True)
class Limiting:
    """What :func:`limit` did to a reference at times ``t``: ``scale`` ``(N,)`` the factor
    ``s(t)`` applied to the excursion from home (1 where the poses are untouched), ``need``
    ``(N,)`` the largest scale each pose allowed, ``limits`` ``(N,)`` the
    :attr:`~stewart.Reachability.flags` of the workspace's boundary where each ray crosses
    it, or where the final check found a limited pose outside (0 inside the margin), ``shift`` ``(N, 6)`` the limited poses minus the washout's,
    ``margin`` and ``ramp_time`` the settings and ``passes`` the envelopes made."""

    t: np.ndarray
    scale: np.ndarray
    need: np.ndarray
    limits: np.ndarray
    shift: np.ndarray
    margin: float
    ramp_time: float
    passes: int
    rotary: bool = False  # ``limits`` in :data:`stewart.cueing.rotary.FLAG_NAMES` bits

    @property
    def active(self) -> np.ndarray:
        """Where the limiter changed the pose, ``(N,)`` bool."""
        return self.scale < 1.0

    def intervals(self) -> list[dict]:
        """Each stretch of limited samples: ``start_s``, ``end_s``, the smallest scale
        ``min_scale`` and its time ``at_s``, and the workspace limits that bound it
        (``limits``, names as :data:`stewart.model.reachability.FLAG_NAMES`)."""
        edges = np.diff(np.concatenate([[0], self.active.astype(np.int8), [0]]))
        out = []
        for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
            k = a + int(np.argmin(self.scale[a:b]))
            bits = np.bitwise_or.reduce(self.limits[a:b])
            names = rotary.FLAG_NAMES if self.rotary else FLAG_NAMES
            out.append({"start_s": float(self.t[a]), "end_s": float(self.t[b - 1]),
                        "min_scale": float(self.scale[k]), "at_s": float(self.t[k]),
                        "limits": [name for bit, name in names.items() if bits & bit]})
        return out

    def report(self) -> dict:
        """The report's ``limiter`` entry: the settings, whether and how long it limited
        (``limited``, ``limited_s``), the smallest scale, the largest shift of each pose axis
        from the washout's pose (m, rad) and the :meth:`intervals`."""
        dt = float(self.t[1] - self.t[0])
        return {"enabled": True, "margin": self.margin, "ramp_time": self.ramp_time,
                "limited": bool(self.active.any()), "limited_s": float(np.count_nonzero(self.active) * dt),
                "min_scale": float(np.min(self.scale)),
                "max_shift": dict(zip(POSE_AXES, np.max(np.abs(self.shift), axis=0).tolist())),
                "passes": self.passes, "intervals": self.intervals()}

    def summary(self) -> str:
        """One line for the command line."""
        spans = self.intervals()
        if not spans:
            return f"limiter: not needed (every pose inside the {self.margin:g} margin)"
        where = "; ".join(f"{s['start_s']:.3g}-{s['end_s']:.3g} s down to {s['min_scale']:.3g} at {s['at_s']:.3g} s "
                          f"({', '.join(s['limits'])})" for s in spans)
        return f"limiter: scaled the excursion from home {where}"


def _check(plat, poses, name):
    """The workspace's check of ``poses``: :func:`stewart.reachability`, or on a rotary rig
    :func:`stewart.cueing.rotary.check_poses` (every limit of the rotary workspace and each
    crank within its reach)."""
    if rotary.is_rotary(plat):
        return rotary.check_poses(plat, poses)
    return reachability(plat, poses, name=name)


def _ray_need(plat, home: np.ndarray, excursion: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """The largest ``c`` in ``[0, reach]`` up to which the ray ``home + c' excursion`` stays
    reachable (``reach`` itself when the whole ray does) and the flags where it leaves."""
    n = len(excursion)
    steps = reach * np.arange(1, RAY_POINTS + 1) / RAY_POINTS
    grid = home + steps[None, :, None] * excursion[:, None, :]
    ok = _check(plat, grid.reshape(-1, 6), "limiter").ok.reshape(n, RAY_POINTS)
    crossing = np.where(ok.all(axis=1), RAY_POINTS, np.argmin(ok, axis=1))
    need = np.full(n, reach)
    flags = np.zeros(n, dtype=np.int64)
    rows = np.flatnonzero(crossing < RAY_POINTS)
    if rows.size:
        lo = np.where(crossing[rows] > 0, steps[crossing[rows] - 1], 0.0)
        hi = steps[crossing[rows]]
        while np.max(hi - lo) > RAY_TOLERANCE * reach:
            mid = 0.5 * (lo + hi)
            inside = _check(plat, home + mid[:, None] * excursion[rows], "limiter").ok
            lo, hi = np.where(inside, mid, lo), np.where(inside, hi, mid)
        need[rows] = lo
        flags[rows] = _check(plat, home + hi[:, None] * excursion[rows], "limiter").flags
    return need, flags


def _envelope(deficit: np.ndarray, half: int) -> np.ndarray:
    """The moving maximum of ``deficit`` over ``2 half + 1`` samples, smoothed by a Hann
    window as long; exactly 0 where no deficit lies within ``2 half`` samples."""
    window = signal.windows.hann(2 * half + 3)[1:-1]
    spread = ndimage.maximum_filter1d(deficit, 2 * half + 1, mode="nearest")
    return ndimage.convolve1d(spread, window / window.sum(), mode="nearest")


def limit(t, poses, home, platform, *, margin: float, ramp_time: float) -> tuple[np.ndarray, Limiting]:
    """The washout's ``poses`` ``(N, 6)`` at times ``t`` (a constant rate) limited to the
    workspace of ``platform`` about ``home`` with ``margin`` and ``ramp_time`` (module
    docstring), and what was done (:class:`Limiting`)."""
    t = np.asarray(t, dtype=float)
    poses = np.asarray(poses, dtype=float)
    home = np.asarray(home, dtype=float)
    excursion = poses - home
    reach = 1.0 + margin
    stretch, limits = _ray_need(platform, home, excursion, reach)
    need = stretch / reach
    half = max(1, int(round(0.5 * ramp_time / (t[1] - t[0]))))
    passes = 0
    while True:
        passes += 1
        deficit = _envelope(1.0 - need, half)
        # the envelope is at most the need but for round-off, which the minimum takes off;
        # a deficit below round-off of 1 is none: the pose stays the washout's own
        scale = np.where(deficit > 0, np.minimum(1.0 - deficit, need), 1.0)
        limited = np.where((scale < 1.0)[:, None], home + scale[:, None] * excursion, poses)
        check = _check(platform, limited, "limited reference")
        outside = ~check.ok
        limits[outside] |= check.flags[outside]
        if not outside.any() or passes == MAX_PASSES:
            break
        need[outside] = np.minimum(need[outside], TIGHTEN * scale[outside])
    return limited, Limiting(t, scale, need, limits, limited - poses, margin, ramp_time, passes,
                             rotary.is_rotary(platform))
