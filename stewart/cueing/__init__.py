"""Motion cueing: a vehicle's motion (:mod:`~stewart.cueing.log`) turned into a platform
reference that a rider perceives (:mod:`~stewart.cueing.vestibular`) as close to the
vehicle's as the platform's limits allow. :func:`washout` is the classical washout
(:mod:`~stewart.cueing.washout`); :func:`perceived` the vestibular model's view of a log
or a platform motion; :mod:`~stewart.cueing.metrics` compares the two."""

from __future__ import annotations

import numpy as np

from ..model.platform import as_platform
from ..model.reachability import reachability
from ..motion.trajectory import SampledTrajectory
from . import log as log_module
from . import metrics, vestibular
from .log import VehicleLog
from .result import CueingResult
from .washout import WashoutParams, reference_poses

__all__ = ["VehicleLog", "WashoutParams", "CueingResult", "read_log", "washout", "perceived", "simulate_reference"]

read_log = log_module.read


def perceived(motion, gravity: float = 9.81) -> vestibular.Perceived:
    """The perceived specific force and angular velocity of ``motion``: a
    :class:`VehicleLog`, a :class:`~stewart.motion.simulation.SimulationResult` (its ``t``,
    ``x``, ``xd``; the acceleration from differences of ``xd``) or a tuple ``(t, poses,
    velocities, accelerations)`` of platform motion (rider at {P}'s origin)."""
    if isinstance(motion, VehicleLog):
        return vestibular.vehicle(motion)
    if hasattr(motion, "xd") and hasattr(motion, "x"):
        t, x, xd = motion.t, motion.x, motion.xd
        return vestibular.platform_motion(t, x, xd, np.gradient(xd, t, axis=0), gravity)
    t, x, xd, xdd = motion
    return vestibular.platform_motion(t, x, xd, xdd, gravity)


def washout(log, platform, params: WashoutParams | None = None, *, simulate: bool = False) -> CueingResult:
    """The classical washout's reference for ``log`` (a :class:`VehicleLog` or a CSV path) on
    ``platform`` (a :class:`~stewart.Platform` or :class:`~stewart.PlatformParams`) with
    ``params`` (default :meth:`WashoutParams.for_platform`). Every pose is checked with
    :func:`stewart.reachability`; with ``simulate`` (and a reference inside the workspace)
    the reference is run through :func:`stewart.simulate` under computed torque
    (:func:`simulate_reference`) and the achieved motion's perception is compared too."""
    if not isinstance(log, VehicleLog):
        log = log_module.read(log)
    plat = as_platform(platform)
    if params is None:
        params = WashoutParams.for_platform(plat)
    poses, _ = reference_poses(log, params, plat.home_pose)
    reference = SampledTrajectory(log.t, poses)
    _, velocities, accelerations = reference.sample(log.t)
    seen_vehicle = vestibular.vehicle(log)
    seen_platform = vestibular.platform_motion(log.t, poses, velocities, accelerations, params.gravity)
    reach = reachability(plat, poses, name="reference")
    result = CueingResult("washout", plat.params.name or "unnamed", log, params, reference, poses, velocities,
                          accelerations, seen_vehicle, seen_platform, metrics.compare(seen_vehicle, seen_platform),
                          reach)
    if not result.inside:
        result.problems.append("the reference leaves the workspace: " + reach.message("pose", log.t))
    elif simulate:
        simulate_reference(result, plat)
    return result


def simulate_reference(result: CueingResult, platform, bandwidth_hz: float = 5.0, steps_per_sample: int = 10):
    """Run ``result.reference`` through :func:`stewart.simulate` with
    :meth:`ComputedTorque.tuned(bandwidth_hz) <stewart.motion.control.ComputedTorque.tuned>`
    (RK4, ``steps_per_sample`` steps per log sample) and fill ``result.simulation``,
    ``result.achieved`` (perceived, at the log's times) and ``result.achieved_metrics``;
    the run's problems (stroke, force, assembly mode) join ``result.problems``."""
    from ..motion.control import ComputedTorque
    from ..motion.simulation import simulate

    plat = as_platform(platform)
    log = result.log
    sim = simulate(plat, result.reference, ComputedTorque.tuned(bandwidth_hz),
                   dt=log.dt / steps_per_sample, duration=float(log.t[-1]))
    result.simulation = sim
    result.problems += [f"simulation: {p}" for p in sim.problems]
    if sim.completed and len(sim.t) > 2:
        seen = perceived(sim, result.params.gravity)
        inside = log.t <= sim.t[-1]
        at = lambda a: np.column_stack([np.interp(log.t, sim.t, a[:, j]) for j in range(3)])  # noqa: E731
        result.achieved = vestibular.Perceived(log.t, at(seen.f), at(seen.w))
        if np.all(inside):
            result.achieved_metrics = metrics.compare(result.vehicle, result.achieved)
    return result
