"""The cueing runs: :func:`washout` (the classical washout's filters,
:mod:`~stewart.cueing.classical`, and its limiter) and :func:`mpc` (the receding-horizon
planner, :mod:`~stewart.cueing.planner`) turn a vehicle's log into a platform reference,
checked against the workspace and the legs' speed and force limits and, on request, run
through the closed loop (:func:`simulate_reference`); :func:`perceived` is the vestibular
model's view of a log or a platform motion."""

from __future__ import annotations

import os

import numpy as np

from ..model.errors import WrongTypeError
from ..model.platform import as_platform
from ..model.reachability import reachability
from ..motion.trajectory import SampledTrajectory
from . import limiter, metrics, planner, rotary, vestibular
from . import log as log_module
from .classical import WashoutParams, reference_poses
from .log import VehicleLog
from .result import CueingResult
from .settings import MPCParams

__all__ = ["washout", "mpc", "perceived", "simulate_reference", "BANDWIDTH_HZ", "STEPS_PER_SAMPLE"]

#: The closed loop a reference runs through (:func:`simulate_reference`, ``simulate=True``):
#: computed torque at this bandwidth [Hz], RK4 at this many steps per log sample.
BANDWIDTH_HZ = 5.0
STEPS_PER_SAMPLE = 10


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
    ``params`` (default :meth:`WashoutParams.for_platform`). Unless ``params.limiter_enabled``
    is False, the poses are limited to the workspace (:func:`stewart.cueing.limiter.limit`;
    ``result.limiting`` says where and how much). Every pose is checked with
    :func:`stewart.reachability`; with ``simulate`` (and a reference inside the workspace)
    the reference is run through :func:`stewart.simulate` under computed torque
    (:func:`simulate_reference`) and the achieved motion's perception is compared too."""
    log, plat = _arguments(log, platform, params, WashoutParams, simulate=simulate)
    if params is None:
        params = WashoutParams.for_platform(plat)
    home = rotary.home(plat)
    poses, _ = reference_poses(log, params, home)
    limiting = None
    if params.limiter_enabled:
        poses, limiting = limiter.limit(log.t, poses, home, plat, margin=params.limiter_margin,
                                        ramp_time=params.limiter_ramp_time)
    reference = SampledTrajectory(log.t, poses)
    _, velocities, accelerations = reference.sample(log.t)
    result = _result("washout", log, plat, params, reference, poses, velocities, accelerations)
    result.limiting = limiting
    if rotary.is_rotary(plat):
        _check_limits(result, plat, *rotary.motor_limits(plat)[::-1])
    return _finish(result, plat, simulate)


def mpc(log, platform, params: MPCParams | None = None, *, simulate: bool = False,
        progress: bool = False) -> CueingResult:
    """Model-predictive cueing (:mod:`stewart.cueing.planner`) of ``log`` (a :class:`VehicleLog`
    or a CSV path) on ``platform`` with ``params`` (default :meth:`MPCParams.for_platform`;
    ``params.preview`` says whether the log's future is used). The reference is the
    receding horizon's motion, checked pose by pose with :func:`stewart.reachability` and
    against the leg-speed and force limits with the exact kinematics and inverse dynamics;
    the report adds the time per step (``solve_time_s``). ``simulate`` as for
    :func:`washout`."""
    log, plat = _arguments(log, platform, params, MPCParams, simulate=simulate, progress=progress)
    params = MPCParams.for_platform(plat) if params is None else params.for_platform_of(plat)
    run = planner.plan(log, plat, params, progress=progress)
    result = _result("mpc", log, plat, params, SampledTrajectory(log.t, run.x, run.v), run.x, run.v, run.u)
    result.solver = {"preview": params.preview, "steps": params.steps, "horizon_s": params.duration,
                     "solve_time_s": _stats(run.step_time), "qp_time_s": _stats(run.solve_time),
                     "qp_iterations": _stats(run.iterations), "qp_failures": run.failures,
                     "qp_levels": {level: run.level.count(level) for level in planner.LEVELS},
                     "qp_tightened": run.tightened}
    brakes = result.solver["qp_levels"]["brake"]
    if brakes:
        result.problems.append(f"at {brakes} of {len(run.step_time)} steps no plan held the machine's limits: the "
                               f"platform braked within the present sample's force limits")
    if run.failures:
        flags = sorted({flag for flag in run.status if flag not in planner.SOLVED})
        result.problems.append(f"the QP solver (DAQP) found no solution at {run.failures} of {len(run.step_time)} "
                               f"steps, exit flag(s) {flags} (the last plan's input was kept)")
    if rotary.is_rotary(plat):
        torque, speed = rotary.motor_limits(plat)
        _check_limits(result, plat, np.minimum(speed, params.leg_velocity), np.minimum(torque, params.force))
    else:
        _check_limits(result, plat, params.leg_velocity, params.force)
    return _finish(result, plat, simulate)


def _arguments(log, platform, params, settings: type, **flags) -> tuple[VehicleLog, object]:
    """The log (read when ``log`` is a path) and the platform of a cueing call, its
    ``params`` (``settings`` or ``None``) and boolean ``flags`` checked:
    :class:`~stewart.WrongTypeError` naming the argument otherwise."""
    for name, value in flags.items():
        if not isinstance(value, (bool, np.bool_)):
            raise WrongTypeError(f"{name}: expected True or False, got {type(value).__name__} {value!r:.40}")
    if params is not None and not isinstance(params, settings):
        raise WrongTypeError(f"params: expected a stewart.cueing.{settings.__name__} or None, got "
                             f"{type(params).__name__}")
    plat = rotary.rotary_rig(platform)
    plat = as_platform(platform) if plat is None else plat
    if isinstance(log, (str, os.PathLike)):
        log = log_module.read(log)
    elif not isinstance(log, VehicleLog):
        raise WrongTypeError(f"log: expected a stewart.cueing.VehicleLog or the path of a CSV log, got "
                             f"{type(log).__name__}")
    return log, plat


def _stats(values) -> dict:
    values = np.asarray(values, dtype=float)
    return {"median": float(np.median(values)), "max": float(np.max(values))}


def _result(method, log, plat, params, reference, poses, velocities, accelerations) -> CueingResult:
    seen_vehicle = vestibular.vehicle(log)
    seen_platform = vestibular.platform_motion(log.t, poses, velocities, accelerations, params.gravity)
    if rotary.is_rotary(plat):
        reach = rotary.check_poses(plat, poses)
        leg_speeds, _ = plat.crank_rates(poses, velocities, return_mask=True)
        forces, _ = plat.inverse_dynamics(poses, velocities, accelerations, return_mask=True)
        names = ("crank_speed", "torque")
    else:
        reach = reachability(plat, poses, name="reference")
        _, leg_speeds = plat.leg_rates(poses, velocities)
        forces = plat.inverse_dynamics(poses, velocities, accelerations)
        names = ("leg_velocity", "force")
    result = CueingResult(method, plat.params.name or "unnamed", log, params, reference, poses, velocities,
                          accelerations, seen_vehicle, seen_platform, metrics.compare(seen_vehicle, seen_platform),
                          reach)
    # (a rotary pose out of a crank's reach gives NaN rows, which the workspace check reports)
    result.peaks = {names[0]: float(np.nanmax(np.abs(leg_speeds), initial=0.0)),
                    names[1]: float(np.nanmax(np.abs(forces), initial=0.0))}
    if not result.inside:
        result.problems.append("the reference leaves the workspace: " + reach.message("pose", log.t))
    return result


def _check_limits(result: CueingResult, plat, leg_velocity, force) -> None:
    """Note in ``result`` a reference whose exact leg speeds or forces (on a rotary rig: crank
    speeds and motor torques, against the least of the motors' limits) pass the limits."""
    if rotary.is_rotary(plat):
        result.limits = {"crank_speed": float(np.min(leg_velocity)), "torque": float(np.min(force))}
        units = (("crank_speed", "rad/s"), ("torque", "N m"))
    else:
        result.limits = {"leg_velocity": leg_velocity, "force": force}
        units = (("leg_velocity", "m/s"), ("force", "N"))
    for name, unit in units:
        if result.peaks[name] > result.limits[name]:
            result.beyond_limits = True
            result.problems.append(f"the reference's {name.replace('_', ' ')} reaches {result.peaks[name]:.4g} {unit}, "
                                   f"above the limit {result.limits[name]:.4g} {unit}")


def _finish(result: CueingResult, plat, simulate: bool) -> CueingResult:
    if simulate and result.inside and not result.beyond_limits:
        _closed_loop(result, plat, BANDWIDTH_HZ, STEPS_PER_SAMPLE)
    return result


def simulate_reference(result: CueingResult, platform, bandwidth_hz: float = BANDWIDTH_HZ,
                       steps_per_sample: int = STEPS_PER_SAMPLE) -> CueingResult:
    """Run ``result.reference`` through :func:`stewart.simulate` with
    :meth:`ComputedTorque.tuned(bandwidth_hz) <stewart.motion.control.ComputedTorque.tuned>`
    (RK4, ``steps_per_sample`` steps per log sample) and fill ``result.simulation``,
    ``result.achieved`` (perceived, at the log's times), ``result.achieved_metrics`` and
    ``result.simulation_peaks``; the actuators saturate at ``result.limits["force"]`` (when
    the method has limits); the run's problems (stroke, force, assembly mode, leg speed above
    the limit) join ``result.problems``."""
    rig = rotary.rotary_rig(platform)
    return _closed_loop(result, as_platform(platform) if rig is None else rig, bandwidth_hz, steps_per_sample)


def _closed_loop(result: CueingResult, plat, bandwidth_hz: float, steps_per_sample: int) -> CueingResult:
    """:func:`simulate_reference` on the compiled ``plat``."""
    from ..motion.control import Actuators, ComputedTorque
    from ..motion.simulation import simulate

    log = result.log
    limits = result.limits or {}
    spinning = rotary.is_rotary(plat)  # (a rotary rig: crank rates and motor torques)
    actuators = Actuators(force_limit=limits.get("torque" if spinning else "force", np.inf))
    sim = simulate(plat, result.reference, ComputedTorque.tuned(bandwidth_hz), actuators=actuators,
                   dt=log.dt / steps_per_sample, duration=float(log.t[-1]))
    result.simulation = sim
    result.problems += [f"simulation: {p}" for p in sim.problems]
    if sim.completed and len(sim.t) > 2:
        speeds = sim.leg_velocities if spinning else plat.leg_rates(sim.x, sim.xd)[1]
        speed, unit = ("crank_speed", "rad/s") if spinning else ("leg_velocity", "m/s")
        result.simulation_peaks = {speed: float(np.max(np.abs(speeds))),
                                   "torque" if spinning else "force": float(np.max(np.abs(sim.forces)))}
        if speed in limits and result.simulation_peaks[speed] > limits[speed]:
            result.simulation_beyond_limits = True
            result.problems.append(f"simulation: the {speed.replace('_', ' ')} reaches "
                                   f"{result.simulation_peaks[speed]:.4g} {unit}, above the limit {limits[speed]:.4g} {unit}")
        if spinning:
            check = rotary.check_poses(plat, sim.x)
            if not np.all(check.ok):
                result.simulation_beyond_limits = True
                result.problems.append("simulation: the achieved motion leaves the workspace: "
                                       + check.message("pose", sim.t))
        seen = perceived(sim, result.params.gravity)
        inside = log.t <= sim.t[-1]
        at = lambda a: np.column_stack([np.interp(log.t, sim.t, a[:, j]) for j in range(3)])  # noqa: E731
        result.achieved = vestibular.Perceived(log.t, at(seen.f), at(seen.w))
        if np.all(inside):
            result.achieved_metrics = metrics.compare(result.vehicle, result.achieved)
    return result
