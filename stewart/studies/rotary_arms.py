"""Arms in or arms out (issue 40): how the orientation of a rotary rig's cranks changes the roll
and pitch it reaches.

A 6-RSS rig's motors sit in pairs; each crank, at its zero angle, points either away from the
other motor of its pair (**outwards**, as the presets are built: towards its rod's platform
joint) or towards it (**inwards**). The same motors, cranks, rods and platform give very
different workspaces: the rig builder's "why does the preview swing from 0.3 deg to 7.8 deg of
roll when the arms point inwards instead of outwards?". :func:`arms_study` answers it for a
rig: for each way, the rig with every crank turned that way (:func:`with_arms`), mounted at a
start pose (the same platform height both ways, as a preview holds it, or each way's own home
with its cranks at zero), its reachable roll and pitch ranges about it (each axis alone, by
:func:`stewart.model.rotary_reachability.axis_range`: steps, then bisection to the boundary of
the workspace with every limit of the rig in force), and the slice of its orientation workspace
in pitch and roll there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import arguments
from ..model.rotary_params import RotaryParams, rotary_params
from ..model.rotary_reachability import axis_range, limits_in_force, reachability
from .workspace import Slice

__all__ = ["ARMS", "arm_directions", "with_arms", "ArmsStudy", "arms_study"]

#: The two ways a crank can point at its zero angle.
ARMS = ("outwards", "inwards")

#: The pose coordinates of roll and pitch (phi and theta of the ZYX Euler angles).
ROLL, PITCH = 5, 4


def arm_directions(params) -> np.ndarray:
    """``(6,)``: +1 where crank ``i`` at its zero angle points away from the other motor of its
    pair (outwards), -1 where it points towards it (inwards); a motor's pair is its nearest
    other motor. ``ValueError`` naming ``params`` for a crank normal to the line of its pair."""
    params = rotary_params(params)
    base = params.base_points
    gaps = np.linalg.norm(base[:, None, :] - base[None, :, :], axis=2) + np.diag(np.full(6, np.inf))
    partner = np.argmin(gaps, axis=1)
    along = np.sum(params.crank_zero * (base - base[partner]), axis=1) / gaps[np.arange(6), partner]
    if np.any(np.abs(along) < 1e-9):
        i = int(np.argmin(np.abs(along)))
        raise ValueError(f"params: crank {i} at its zero angle is normal to the line of its motor pair; "
                         "it points neither inwards nor outwards")
    return np.sign(along)


def with_arms(params, way: str) -> RotaryParams:
    """The rig ``params`` with every crank pointing ``way`` (:data:`ARMS`) at its zero angle: a
    crank pointing the other way is mirrored, its zero direction ``h_i`` and its motor axis
    ``a_i`` both reversed, so that ``a_i x h_i`` (the tip's motion at zero) and the crank's
    branch keep their meaning; the rest of the rig is unchanged."""
    params = rotary_params(params)
    if way not in ARMS:
        raise ValueError(f"way: expected one of {', '.join(ARMS)}, got {way!r}")
    flip = np.where(arm_directions(params) == (1.0 if way == "outwards" else -1.0), 1.0, -1.0)[:, None]
    name = f"{params.name or 'unnamed'}, arms {way}"
    return params.replace(crank_zero=params.crank_zero * flip, motor_axes=params.motor_axes * flip, name=name)


@dataclass(frozen=True)
class ArmsStudy:
    """The result of :func:`arms_study`: per way of :data:`ARMS`, ``start`` the pose about which
    roll and pitch are measured (the rig mounted there, its ball joints centred), ``roll`` and
    ``pitch`` the reachable ``(low, high)`` [rad] about it (None where the rig cannot stand at
    ``start``: ``reasons`` says why), and ``slices`` the pitch-roll slices of the orientation
    workspace at ``start``; ``height`` the platform height both ways were held at (None: each at
    its own home, cranks at zero); ``limits`` the limits in force."""

    platform: str
    ways: tuple[str, ...]
    height: float | None
    start: dict
    roll: dict
    pitch: dict
    reasons: dict
    slices: dict
    limits: str

    def summary(self) -> dict:
        """Plain-Python form (for JSON), angles in radians and degrees."""
        def way(w):
            ranges = {key: None if value[w] is None else list(value[w]) for key, value in
                      (("roll", self.roll), ("pitch", self.pitch))}
            degrees = {f"{key}_deg": None if value is None else np.degrees(value).tolist() for key, value in ranges.items()}
            return {"start": self.start[w].tolist(), **ranges, **degrees, "reasons": self.reasons[w]}

        return {"platform": self.platform, "limits": self.limits, "height": self.height,
                "arms": {w: way(w) for w in self.ways}}

    def plot(self, path: str) -> str:
        """The pitch-roll slices side by side, the ends of the roll and pitch ranges marked."""
        from ..io.plots import plot_workspace_slices

        def title(w):
            if self.roll[w] is None:
                return f"arms {w}: cannot stand at z = {self.start[w][2]:.4g} m"
            (r0, r1), (p0, p1) = np.degrees(self.roll[w]), np.degrees(self.pitch[w])
            return f"arms {w} (z {self.start[w][2]:.3f} m): roll {r0:+.2f}..{r1:+.2f}, pitch {p0:+.2f}..{p1:+.2f} deg"

        marks = [None if self.roll[w] is None else
                 [(self.roll[w][0], 0.0), (self.roll[w][1], 0.0), (0.0, self.pitch[w][0]), (0.0, self.pitch[w][1])]
                 for w in self.ways]
        held = "each at its own home" if self.height is None else f"both at z = {self.height:.4g} m"
        return plot_workspace_slices([self.slices[w] for w in self.ways], path,
                                     f"{self.platform}: arms outwards or inwards, {held}, yaw 0",
                                     titles=[title(w) for w in self.ways], marks=marks)


def _slice(rig, start, limit: float, resolution: int) -> Slice:
    """The pitch-roll slice about ``start`` (yaw and position held) of the rig mounted there."""
    n = arguments.count("resolution", resolution, 2000)
    cells = -limit + 2.0 * limit * (np.arange(n) + 0.5) / n
    theta, phi = np.meshgrid(cells, cells, indexing="ij")
    poses = np.tile(start, (n * n, 1))
    poses[:, 4] += theta.ravel()
    poses[:, 5] += phi.ravel()
    check = reachability(rig, poses, reference=start)
    return Slice(axes=("phi", "theta"), unit="rad", u=start[5] + cells, v=start[4] + cells, at=("psi", float(start[3])),
                 fixed=start[:3].copy(), margin=np.where(check.ok, check.margin, np.nan).reshape(n, n),
                 flags=check.flags.reshape(n, n), platform=rig.params.name or "unnamed",
                 limits=limits_in_force(rig.params), jacobian="J_alpha")


def arms_study(params, *, height: float | None = None, limit: float = np.radians(45.0), resolution: int = 121,
               tol: float = 1e-10) -> ArmsStudy:
    """Arms outwards against arms inwards (:class:`ArmsStudy`) for the rig ``params`` (a
    :class:`~stewart.RotaryParams` or :class:`~stewart.RotaryPlatform`): each way's rig
    (:func:`with_arms`) mounted at its start pose (its ball joints centred there), the level pose
    at ``height`` [m] above the base's origin (as a motion software's preview holds the
    platform when the arms are turned), or with ``height=None`` each way's own home (its cranks
    at zero); its roll and pitch ranges about the start within ``+-limit`` [rad]
    (:func:`~stewart.model.rotary_reachability.axis_range` to ``tol``), and its pitch-roll slice of
    ``resolution`` cells per axis over ``+-limit``."""
    from ..model.rotary import RotaryPlatform

    params = rotary_params(params)
    limit = arguments.real("limit", limit)
    if not 0.0 < limit <= np.pi / 2:
        raise ValueError(f"limit: need 0 < limit <= pi/2 (radians), got {limit}")
    if height is not None:
        height = arguments.real("height", height)
        if not np.isfinite(height):
            raise ValueError(f"height: expected a finite height in metres, got {height}")
    start, roll, pitch, reasons, slices = {}, {}, {}, {}, {}
    for way in ARMS:
        rig = RotaryPlatform(with_arms(params, way))
        start[way] = rig.home if height is None else np.array([0.0, 0.0, height, 0.0, 0.0, 0.0])
        stands = reachability(rig, start[way], reference=start[way])
        reasons[way] = stands.reasons(0)
        roll[way] = pitch[way] = None
        if stands.ok[0]:
            step = min(1e-3, limit / 10)
            roll[way] = axis_range(rig, ROLL, start=start[way], reference=start[way], limit=limit, step=step, tol=tol)
            pitch[way] = axis_range(rig, PITCH, start=start[way], reference=start[way], limit=limit, step=step, tol=tol)
        slices[way] = _slice(rig, start[way], limit, resolution)
    return ArmsStudy(platform=params.name or "unnamed", ways=ARMS, height=height, start=start, roll=roll, pitch=pitch,
                     reasons=reasons, slices=slices, limits=limits_in_force(params))
