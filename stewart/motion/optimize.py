"""Minimum-effort point-to-point moves by trajectory optimization over the compiled model.

:func:`minimum_effort_move` moves the platform from rest at one pose to rest at another in a
given time with the least actuator effort ``sum_k |tau_k|^2 dt``, subject to the legs' stroke
limits and a per-leg force limit. It is a direct multiple-shooting transcription: the state
``s = [x; xd]`` at ``N + 1`` nodes and constant actuator forces ``tau_k`` on each of the
``N`` intervals are the unknowns, and one RK4 step of the forward dynamics per interval
(:meth:`stewart.Platform.rk4_step`, the step ``stewart.simulate`` integrates) links the
nodes. IPOPT solves it with the exact first derivatives of the compiled model
(:mod:`stewart.motion.casadi_functions`) and a limited-memory quasi-Newton Hessian.

The result's forces, applied with :class:`stewart.OpenLoop` in a fixed-step RK4
simulation with the same step, reproduce its states. CasADi (with IPOPT) is the optional
``opt`` extra.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..model.kinematics import POSE_AXES
from ..model import arguments
from . import casadi_functions
from ..io import csvfile
from ..model.platform import Platform, as_platform
from .trajectory import PointToPoint
from ..model.reachability import WorkspaceError, reachability

__all__ = ["MinimumEffortMove", "minimum_effort_move", "initial_guess", "solve_move"]


@dataclass(frozen=True)
class MinimumEffortMove:
    """A solved (or failed) minimum-effort move.

    ``t`` holds the ``N + 1`` node times; ``x`` and ``xd`` the poses and pose rates there,
    ``(N + 1, 6)``; ``tau`` the constant actuator forces on each interval, ``(N, 6)``;
    ``lengths`` the leg lengths at the nodes. ``effort`` is ``sum_k |tau_k|^2 dt`` [N^2 s].
    ``ok`` is IPOPT's success flag and ``status`` its return status; ``iterations`` and
    ``solve_seconds`` describe the solve."""

    t: np.ndarray
    x: np.ndarray
    xd: np.ndarray
    tau: np.ndarray
    lengths: np.ndarray
    effort: float
    ok: bool
    status: str
    iterations: int
    solve_seconds: float

    platform: str = "unnamed"

    @property
    def dt(self) -> float:
        """The interval length [s]."""
        return float(self.t[1] - self.t[0])

    def describe(self) -> str:
        """One line: the platform, the solver's verdict, the effort and the iterations."""
        return (f"minimum-effort move, platform {self.platform}: {self.status}, effort {self.effort:.6g} N^2 s, "
                f"{self.iterations} IPOPT iterations, {self.solve_seconds:.3g} s")

    def to_csv(self, path) -> None:
        """Write the nodes as CSV (SI units), with the column names of a simulation's CSV:
        ``t``, the pose, its rates (``x_dot`` ...), the leg lengths ``L0`` ... ``L5`` and the
        forces ``force0`` ... ``force5`` held from each node to the next (the last row
        repeats the last interval's); a ``#`` comment line gives :meth:`describe`."""
        pose = list(POSE_AXES)
        names = (["t"] + pose + [f"{name}_dot" for name in pose] + [f"L{k}" for k in range(6)]
                 + [f"force{k}" for k in range(6)])
        held = np.vstack([self.tau, self.tau[-1:]])
        csvfile.write(path, names, np.column_stack([self.t, self.x, self.xd, self.lengths, held]),
                      self.describe())


def _force_bounds(force_limit, n: int) -> tuple[np.ndarray, np.ndarray]:
    if force_limit is None:
        limit = np.full(6, np.inf)
    else:
        limit = np.broadcast_to(arguments.reals("force_limit", force_limit), (6,)).astype(float)
        if not np.all(limit > 0):
            raise ValueError(f"force_limit: must be > 0 (N), got {limit.tolist()}")
    return np.tile(-limit, n), np.tile(limit, n)


def solve_move(dynamics, lengths, start, target, duration: float, intervals: int, *, initial_guess,
               force_limit=None, stroke=None, tolerance: float = 1e-8, max_iterations: int = 1000,
               solver_options: dict | None = None):
    """Solve the move's NLP for any model given as CasADi functions over the whole horizon:
    ``dynamics(S, U) -> S_next`` (one step over ``duration / intervals`` of each column of
    ``S`` (12 x N) under the column of ``U`` (6 x N)) and ``lengths(X) -> L`` (6 x (N + 1)).
    Returns
    ``(states (N+1, 12), forces (N, 6), effort, stats, seconds)``. The benchmarks solve the
    same NLP with CasADi's own model through this function; ``solver_options`` are added to
    ``nlpsol``'s options (the benchmarks' ``jit``). ``seconds`` is the solve's wall time,
    the NLP's construction (and any JIT compile) before it."""
    import casadi as ca

    n = intervals
    dt = duration / n
    states = ca.MX.sym("s", 12, n + 1)
    forces = ca.MX.sym("tau", 6, n)
    defects = states[:, 1:] - dynamics(states[:, :-1], forces)
    constraints = [ca.vec(defects)]
    lower, upper = [np.zeros(12 * n)], [np.zeros(12 * n)]
    if stroke is not None:
        constraints.append(ca.vec(lengths(states[:6, :])))
        lower.append(np.full(6 * (n + 1), stroke[0]))
        upper.append(np.full(6 * (n + 1), stroke[1]))
    effort = ca.sumsqr(forces) * dt
    nlp = {"x": ca.vertcat(ca.vec(states), ca.vec(forces)), "f": effort, "g": ca.vertcat(*constraints)}
    options = {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes", "ipopt.tol": tolerance,
               "ipopt.max_iter": max_iterations, "ipopt.hessian_approximation": "limited-memory"}
    solver = ca.nlpsol("minimum_effort_move", "ipopt", nlp, options | dict(solver_options or {}))
    # The end points are fixed by bounds: at rest at the start and at the target.
    state_lower = np.full((12, n + 1), -np.inf)
    state_upper = np.full((12, n + 1), np.inf)
    for column, pose in ((0, start), (n, target)):
        state_lower[:, column] = state_upper[:, column] = np.concatenate([pose, np.zeros(6)])
    force_lower, force_upper = _force_bounds(force_limit, n)
    guess_states, guess_forces = initial_guess
    started = time.perf_counter()
    solution = solver(
        x0=np.concatenate([guess_states.T.ravel(order="F"), guess_forces.T.ravel(order="F")]),
        lbx=np.concatenate([state_lower.ravel(order="F"), force_lower]),
        ubx=np.concatenate([state_upper.ravel(order="F"), force_upper]),
        lbg=np.concatenate(lower), ubg=np.concatenate(upper),
    )
    seconds = time.perf_counter() - started
    w = np.asarray(solution["x"]).ravel()
    solved_states = w[: 12 * (n + 1)].reshape(n + 1, 12)
    solved_forces = w[12 * (n + 1):].reshape(n, 6)
    return solved_states, solved_forces, float(solution["f"]), solver.stats(), seconds


def initial_guess(platform: Platform, start, target, duration: float, intervals: int):
    """``(states (N+1, 12), forces (N, 6))``: the quintic :class:`stewart.PointToPoint` move
    at the nodes, and its inverse-dynamics forces at the middle of each interval (zero where
    undefined)."""
    return _initial_guess(as_platform(platform), start, target, duration, intervals)


def _initial_guess(platform: Platform, start, target, duration: float, intervals: int):
    """:func:`initial_guess` of the compiled ``platform``."""
    t = np.linspace(0.0, duration, intervals + 1)
    move = PointToPoint(start, target, duration, "quintic")
    x, xd, _ = move.sample(t)
    forces, _ = platform.inverse_dynamics(*move.sample(0.5 * (t[:-1] + t[1:])), return_mask=True)
    return np.hstack([x, xd]), np.nan_to_num(forces)


def minimum_effort_move(platform: Platform, target, duration: float, intervals: int = 50, *, start=None,
                        force_limit=None, tolerance: float = 1e-8, max_iterations: int = 1000) -> MinimumEffortMove:
    """The least-effort move from rest at ``start`` (default: the home pose) to rest at
    ``target`` in ``duration`` seconds, over ``intervals`` RK4 steps, within the legs' stroke
    (``params.leg_length_limits``, when set) and ``|tau_i| <= force_limit`` [N] (a scalar or
    one value per leg; default: unlimited).

    The initial guess is :func:`initial_guess`. Raises :class:`stewart.WorkspaceError` when
    ``start`` or ``target`` is outside the workspace; an unsolved problem is returned with
    ``ok = False``. Under gravity the least effort may lift the platform on the way, to
    where its legs stand steeper and carry its weight with less force."""
    platform = as_platform(platform)
    start = platform.home_pose if start is None else arguments.states("start", start)
    target = arguments.states("target", target)
    for name, pose in (("start", start), ("target", target)):
        if pose.ndim != 1:
            raise ValueError(f"{name}: expected one pose of shape (6,), got {pose.shape}")
        reach = reachability(platform, pose, name=name)
        if not reach.ok.all():
            raise WorkspaceError(f"{name}: {'; '.join(reach.reasons(0))}", reach)
    duration = arguments.real("duration", duration)
    if not duration > 0:
        raise ValueError(f"duration: must be > 0 s, got {duration}")
    intervals = arguments.count("intervals", intervals, 100_000)
    tolerance = arguments.real("tolerance", tolerance)
    if not tolerance > 0:
        raise ValueError(f"tolerance: must be > 0, got {tolerance}")
    max_iterations = arguments.count("max_iterations", max_iterations, 1_000_000)

    t = np.linspace(0.0, duration, intervals + 1)
    guess = _initial_guess(platform, start, target, duration, intervals)
    dt = duration / intervals
    states, forces, effort, stats, seconds = solve_move(
        casadi_functions.rk4_step(platform, dt, intervals), casadi_functions.leg_lengths(platform, intervals + 1),
        start, target,
        duration, intervals, initial_guess=guess, force_limit=force_limit,
        stroke=platform.params.leg_length_limits, tolerance=tolerance, max_iterations=max_iterations)
    return MinimumEffortMove(
        t=t, x=states[:, :6], xd=states[:, 6:], tau=forces,
        lengths=platform.leg_lengths(states[:, :6], return_mask=True)[0], effort=effort,
        ok=bool(stats["success"]), status=str(stats["return_status"]), iterations=int(stats["iter_count"]),
        solve_seconds=seconds, platform=platform.params.name or "unnamed")
