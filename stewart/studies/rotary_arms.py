"""Arms in or arms out (issue 40): how the orientation of a rotary rig's cranks changes the roll
and pitch it reaches.

A 6-RSS rig's motors sit in pairs; each crank, at its zero angle, points either away from the
other motor of its pair (**outwards**, as the presets are built: towards its rod's platform
joint) or towards it (**inwards**). The same motors, cranks, rods and platform give very
different workspaces: the rig builder's "why does the preview swing from 0.3 deg to 7.8 deg of
roll when the arms point inwards instead of outwards?". :func:`arms_study` answers it for a
rig: for each way, the rig with every crank turned that way (:func:`with_arms`), its reachable
roll and pitch ranges about its home pose (each axis alone, by
:func:`stewart.model.rotary_reachability.axis_range`: steps, then bisection to the boundary of
the workspace with every limit of the rig in force), and the slice of its orientation workspace
in pitch and roll at home (:func:`stewart.studies.workspace.workspace_slice`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import arguments
from ..model.rotary_params import RotaryParams, rotary_params
from ..model.rotary_reachability import axis_range, limits_in_force
from .workspace import workspace_slice

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
    """The result of :func:`arms_study`: per way of :data:`ARMS`, ``roll`` and ``pitch`` the
    reachable ``(low, high)`` [rad] about the home pose, ``home`` that pose, and ``slices`` the
    pitch-roll slices of the orientation workspace at home; ``limits`` the limits in force."""

    platform: str
    ways: tuple[str, ...]
    roll: dict
    pitch: dict
    home: dict
    slices: dict
    limits: str

    def summary(self) -> dict:
        """Plain-Python form (for JSON), angles in radians and degrees."""
        return {"platform": self.platform, "limits": self.limits,
                "arms": {way: {"home": self.home[way].tolist(), "roll": list(self.roll[way]),
                               "pitch": list(self.pitch[way]),
                               "roll_deg": np.degrees(self.roll[way]).tolist(),
                               "pitch_deg": np.degrees(self.pitch[way]).tolist()} for way in self.ways}}

    def plot(self, path: str) -> str:
        """The pitch-roll slices side by side, the ends of the roll and pitch ranges marked."""
        from ..io.plots import plot_workspace_slices

        titles = [f"arms {way}: roll {np.degrees(self.roll[way][0]):+.2f}..{np.degrees(self.roll[way][1]):+.2f} deg, "
                  f"pitch {np.degrees(self.pitch[way][0]):+.2f}..{np.degrees(self.pitch[way][1]):+.2f} deg"
                  for way in self.ways]
        marks = [[(self.roll[w][0], 0.0), (self.roll[w][1], 0.0), (0.0, self.pitch[w][0]), (0.0, self.pitch[w][1])]
                 for w in self.ways]
        return plot_workspace_slices([self.slices[w] for w in self.ways], path,
                                     f"{self.platform}: arms in or out, orientation at home (yaw 0)", titles=titles,
                                     marks=marks)


def arms_study(params, *, limit: float = np.radians(45.0), resolution: int = 121, tol: float = 1e-10) -> ArmsStudy:
    """Arms outwards against arms inwards (:class:`ArmsStudy`) for the rig ``params`` (a
    :class:`~stewart.RotaryParams` or :class:`~stewart.RotaryPlatform`): each way's rig
    (:func:`with_arms`), its roll and pitch ranges about its home within ``+-limit`` [rad]
    (:func:`~stewart.model.rotary_reachability.axis_range` to ``tol``), and its pitch-roll slice of
    ``resolution`` cells per axis over ``+-limit``."""
    from ..model.rotary import RotaryPlatform

    params = rotary_params(params)
    limit = arguments.real("limit", limit)
    if not 0.0 < limit <= np.pi / 2:
        raise ValueError(f"limit: need 0 < limit <= pi/2 (radians), got {limit}")
    roll, pitch, home, slices = {}, {}, {}, {}
    for way in ARMS:
        rig = RotaryPlatform(with_arms(params, way))
        home[way] = rig.home
        roll[way] = axis_range(rig, ROLL, limit=limit, step=min(1e-3, limit / 10), tol=tol)
        pitch[way] = axis_range(rig, PITCH, limit=limit, step=min(1e-3, limit / 10), tol=tol)
        slices[way] = workspace_slice(rig, ("phi", "theta"), at=0.0, position=rig.home[:3],
                                      region=[[-limit, limit], [-limit, limit]], resolution=resolution)
    return ArmsStudy(platform=params.name or "unnamed", ways=ARMS, roll=roll, pitch=pitch, home=home, slices=slices,
                     limits=limits_in_force(params))
