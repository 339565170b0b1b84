"""Excitation trajectories for identification: periodic Fourier series in pose space that
make the base parameters as well determined as the machine's limits allow.

:func:`design_excitation` chooses the amplitudes of a :class:`~stewart.motion.trajectory.FourierTrajectory`
about a centre pose (Swevers et al. 1997) to minimize the condition number of the stacked
base regressor over one period,

    W = [ Y_b(x(t_1), x'(t_1), x''(t_1)); ...; Y_b(x(t_K), x'(t_K), x''(t_K)) ],   (6K x r)

``Y_b = base.reduce(platform.regressor(...))`` (:mod:`stewart.identification.base_parameters`), each column
divided by its Euclidean norm first: the parameters have different units, and the
condition number of the column-normalized matrix is within a factor ``sqrt(r)`` of the
smallest over all column scalings (van der Sluis 1969), so it measures how well the data
determine the parameters whatever their units. The noise on the estimates grows with it
(the least-squares error bound ``|d beta| / |beta| <= cond(W) |d tau| / |tau|``).

The amplitudes are the variables of scipy's SLSQP from seeded random starts, subject at
every design sample to

* the stroke: every leg length within ``params.leg_length_limits`` less ``stroke_margin``
  times the stroke at either end (room for the tracking error of a real run);
* the leg velocity ``|L'_i| <= max_leg_velocity`` and acceleration
  ``|L''_i| <= max_leg_acceleration`` (:func:`stewart.model.kinematics.leg_accelerations`);
* the actuator force ``|tau_i| <= force_limit``, ``tau = Y pi`` with the platform's own
  parameters (friction included when they set it);
* the singularity margin of :mod:`stewart.studies.workspace` (``1 / cond J_C``, unit free) at least
  ``min_margin`` (by default :data:`MARGIN_FRACTION` of the centre pose's own margin).

By default the series also starts and ends at rest at the centre pose (``x(0) = centre``,
``x'(0) = x''(0) = 0``: three linear conditions per coordinate on the amplitudes, solved
for exactly), so a machine can run it from standstill and repeat it ``periods`` times.

The optimizer sees the constraints at its samples only. The result is checked on a grid
:data:`CHECK_DENSITY` times denser per harmonic, with every test of
:func:`stewart.model.reachability.reachability`; where it oversteps a limit there, the amplitudes
are scaled down until every constraint holds with the relative slack
:data:`CHECK_SLACK`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..model.kinematics import POSE_AXES
from ..model import arguments, kinematics
from ..io import csvfile
from ..model.platform import Platform, as_platform
from ..motion.trajectory import FourierTrajectory
from ..model.reachability import margins, reachability

__all__ = ["Excitation", "Limits", "limits", "design_excitation", "condition_number", "DEFAULT_PERIOD", "DEFAULT_HARMONICS", "DEFAULT_STARTS", "DEFAULT_ITERATIONS", "DEFAULT_RATE",
           "SAMPLES_PER_HARMONIC",
           "STROKE_MARGIN", "VELOCITY_PER_STROKE", "ACCELERATION_PER_STROKE", "MARGIN_FRACTION", "CHECK_DENSITY",
           "CHECK_SLACK"]

#: Default period of the series [s] and number of harmonics.
DEFAULT_PERIOD = 10.0
DEFAULT_HARMONICS = 5
#: Default random starts of the optimizer, SLSQP iterations per start, and sample rate of
#: the machine CSV [Hz].
DEFAULT_STARTS = 4
DEFAULT_ITERATIONS = 100
DEFAULT_RATE = 1000.0
#: Design samples per period per harmonic (the default ``samples`` is this times ``harmonics``).
SAMPLES_PER_HARMONIC = 20
#: Default fraction of the stroke kept free at either end of it.
STROKE_MARGIN = 0.05
#: Default leg velocity limit, in strokes per second, and acceleration limit, in strokes per second^2.
VELOCITY_PER_STROKE = 1.0
ACCELERATION_PER_STROKE = 10.0
#: Default smallest singularity margin (1 / cond J_C, :mod:`stewart.studies.workspace`), as a
#: fraction of the centre pose's.
MARGIN_FRACTION = 0.5
#: Samples per period per harmonic of the grid the result is checked on.
CHECK_DENSITY = 200
#: Relative slack every limit keeps on the check grid (``|L'| <= (1 - CHECK_SLACK) max_leg_velocity`` ...).
CHECK_SLACK = 1e-3
#: Relative step of the forward differences of the objective and the constraints.
_STEP = 1e-6

POSE = list(POSE_AXES)


@dataclass(frozen=True)
class Limits:
    """The limits an excitation keeps to: leg lengths ``(low, high)`` [m] (the stroke less
    its margin), leg velocity [m/s], leg acceleration [m/s^2], actuator force [N] (inf for
    none) and the smallest singularity margin."""

    lengths: tuple[float, float]
    leg_velocity: float
    leg_acceleration: float
    force: float
    margin: float

    def slack(self, lengths, rates, accelerations, forces, margins) -> np.ndarray:
        """The relative slack of every constraint kind at each state, ``(..., 5)``:
        stroke, velocity, acceleration, force and margin; a limit holds where it is >= 0."""
        low, high = self.lengths
        half = 0.5 * (high - low)
        with np.errstate(over="ignore"):  # a limit of 5e-324: a slack of -inf (broken) or +inf (ample)
            stroke = np.min(np.minimum(lengths - low, high - lengths), axis=-1) / half
            return np.stack([
                stroke,
                1.0 - np.max(np.abs(rates), axis=-1) / self.leg_velocity,
                1.0 - np.max(np.abs(accelerations), axis=-1) / self.leg_acceleration,
                1.0 - np.max(np.abs(forces), axis=-1) / self.force,
                margins / self.margin - 1.0,
            ], axis=-1)

    #: The names of the constraint kinds, in the order of :meth:`slack`.
    KINDS = ("stroke", "leg velocity", "leg acceleration", "actuator force", "singularity margin")


def _positive(name: str, value, default: float) -> float:
    if value is None:
        return default
    number = arguments.reals(name, value)
    if number.ndim != 0 or not float(number) > 0:
        raise ValueError(f"{name}: must be a positive number, got {value!r}")
    return float(number)


def limits(platform: Platform, centre, *, stroke_margin=None, max_leg_velocity=None, max_leg_acceleration=None,
           force_limit=None, min_margin=None) -> Limits:
    """The :class:`Limits` of ``platform`` about the pose ``centre`` with the defaults of
    :func:`design_excitation`."""
    return _limits(as_platform(platform), centre, stroke_margin, max_leg_velocity, max_leg_acceleration, force_limit,
                   min_margin)


def _limits(platform: Platform, centre, stroke_margin, max_leg_velocity, max_leg_acceleration, force_limit,
            min_margin) -> Limits:
    """:func:`limits` of the compiled ``platform``."""
    params = platform.params
    if params.leg_length_limits is None:
        raise ValueError("platform: its parameters set no leg_length_limits; an excitation needs the stroke")
    low, high = params.leg_length_limits
    stroke = high - low
    fraction = STROKE_MARGIN if stroke_margin is None else arguments.real("stroke_margin", stroke_margin)
    if not 0 <= fraction < 0.5:
        raise ValueError(f"stroke_margin: must be from 0 to below 0.5 (a fraction of the stroke), got {fraction}")
    default = MARGIN_FRACTION * float(reachability(platform, centre, name="centre").margin[0])
    margin = _positive("min_margin", min_margin, default)
    if margin >= 1:
        raise ValueError(f"min_margin: must be below 1 (the margin of an isotropic pose), got {margin}")
    force = math.inf if force_limit is None else _positive("force_limit", force_limit, math.inf)
    return Limits((low + fraction * stroke, high - fraction * stroke),
                  _positive("max_leg_velocity", max_leg_velocity, VELOCITY_PER_STROKE * stroke),
                  _positive("max_leg_acceleration", max_leg_acceleration, ACCELERATION_PER_STROKE * stroke),
                  force, margin)


def condition_number(matrix: np.ndarray) -> np.ndarray:
    """The condition number of ``matrix`` (``(..., m, r)``) with each column divided by its
    Euclidean norm (inf where a column is zero or the columns are dependent)."""
    norms = np.linalg.norm(matrix, axis=-2, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        values = np.linalg.svd(np.nan_to_num(matrix / norms), compute_uv=False)
        out = values[..., 0] / values[..., -1]
    return np.where(np.all(norms > 0, axis=(-2, -1)) & np.isfinite(out), out, np.inf)


def _log_condition(matrix: np.ndarray) -> np.ndarray:
    """``log`` of :func:`condition_number` for a batch ``(m, rows, r)``, from the eigenvalues
    of the column-normalized Gram matrix (``cond^2 = lambda_max / lambda_min``; several
    times faster than the SVD, and accurate while the condition number is far below
    ``1 / sqrt(eps)``, about 1e8). Dependent columns give a large finite value, so that the
    optimizer can still compare."""
    gram = np.swapaxes(matrix, -1, -2) @ matrix
    scale = np.sqrt(np.diagonal(gram, axis1=-2, axis2=-1))
    scale = np.where(scale > 0, scale, 1.0)
    values = np.linalg.eigvalsh(gram / scale[..., :, None] / scale[..., None, :])
    floor = np.finfo(float).eps * matrix.shape[-1]
    return 0.5 * np.log(np.maximum(values[..., -1], floor) / np.maximum(values[..., 0], floor))


@dataclass(frozen=True)
class Excitation:
    """A designed excitation trajectory and what it achieves.

    ``trajectory`` is the :class:`~stewart.motion.trajectory.FourierTrajectory`; ``condition`` the
    column-normalized condition number of its stacked base regressor over the design
    samples and ``initial_condition`` that of the random start it was optimized from;
    ``base_names`` the base parameters it excites; ``limits`` the :class:`Limits` it keeps
    to and ``peaks`` what it reaches on the check grid (``leg_length_min``,
    ``leg_length_max``, ``leg_velocity``, ``leg_acceleration``, ``force``,
    ``margin_min``); ``feasible`` whether every constraint holds there (with the checks of
    :func:`stewart.model.reachability.reachability`); ``scaled`` the factor the optimizer's
    amplitudes were scaled by to get there (1 when they already held); ``iterations`` the
    SLSQP iterations of the best start; ``starts`` the starts tried.
    """

    trajectory: FourierTrajectory
    condition: float
    initial_condition: float
    base_names: tuple[str, ...]
    limits: Limits
    peaks: dict
    feasible: bool
    scaled: float
    iterations: int
    starts: int
    platform: str = "unnamed"
    problems: list = field(default_factory=list)

    def describe(self) -> str:
        """One line: the platform, the series and the condition number."""
        traj = self.trajectory
        return (f"excitation for platform {self.platform}: {traj.harmonics} harmonics, period {traj.period:g} s, "
                f"{traj.periods} period(s); condition number {self.condition:.4g} (start {self.initial_condition:.4g}) "
                f"over {len(self.base_names)} base parameters")

    def machine_table(self, platform: Platform, rate: float) -> tuple[list[str], np.ndarray]:
        """The columns and rows a machine controller follows, sampled at ``rate`` [Hz] over
        the whole trajectory: ``t``, the pose, the leg lengths ``L0..L5`` and their rates
        ``L0_dot..L5_dot`` (the column names of a simulation's CSV)."""
        rate = _positive("rate", rate, 0.0)
        traj = self.trajectory
        count = int(round(traj.duration * rate))
        if count < 2 or count > 100_000_000:
            raise ValueError(f"rate: {rate:g} Hz gives {count} samples over {traj.duration:g} s; need 2 to 1e8")
        t = np.arange(count + 1) / rate
        t[-1] = min(t[-1], traj.duration)
        x, xd, _ = traj.sample(t)
        names = ["t"] + POSE + [f"L{i}" for i in range(6)] + [f"L{i}_dot" for i in range(6)]
        rows = np.column_stack([t, x, platform.leg_lengths(x), kinematics.leg_velocities(platform.params, x, xd)])
        return names, rows

    def to_csv(self, path, platform: Platform, rate: float = DEFAULT_RATE) -> None:
        """Write :meth:`machine_table` as CSV (SI units; a ``#`` comment line gives
        :meth:`describe`). :meth:`stewart.SampledTrajectory.from_csv` and ``stewart simulate
        --trajectory`` read it back."""
        names, rows = self.machine_table(platform, rate)
        csvfile.write(path, names, rows, self.describe(), fmt="%.12g")

    def save(self, path) -> None:
        """Write the trajectory's amplitudes (:meth:`FourierTrajectory.save`, ``.toml`` or ``.json``)."""
        self.trajectory.save(path)

    def summary(self) -> dict:
        traj = self.trajectory
        return {"platform": self.platform, "period": traj.period, "harmonics": traj.harmonics,
                "periods": traj.periods, "condition": self.condition, "initial_condition": self.initial_condition,
                "base_parameters": list(self.base_names), "feasible": self.feasible, "scaled": self.scaled,
                "iterations": self.iterations, "starts": self.starts, "peaks": self.peaks,
                "limits": {"leg_length_min": self.limits.lengths[0], "leg_length_max": self.limits.lengths[1],
                           "leg_velocity": self.limits.leg_velocity,
                           "leg_acceleration": self.limits.leg_acceleration,
                           "force": None if math.isinf(self.limits.force) else self.limits.force,
                           "margin": self.limits.margin},
                "problems": list(self.problems)}


class _Series:
    """The amplitudes of a Fourier series as a linear function of the optimizer's variables
    ``z``, and the states it passes at given times: ``coefficients = scale * (N z)`` per
    coordinate, ``N`` an orthonormal basis of the amplitudes that start at rest (or the
    identity)."""

    def __init__(self, harmonics: int, period: float, scale: np.ndarray, rest: bool):
        from scipy.linalg import null_space

        orders = np.arange(1, harmonics + 1, dtype=float)
        self.harmonics, self.period, self.scale = harmonics, period, scale
        if rest:  # x(0) = centre, x'(0) = 0, x''(0) = 0 on [sine | cosine] amplitudes
            conditions = np.zeros((3, 2 * harmonics))
            conditions[0, harmonics:] = 1.0
            conditions[1, :harmonics] = orders
            conditions[2, harmonics:] = orders**2
            self.basis = null_space(conditions)
        else:
            self.basis = np.eye(2 * harmonics)
        self.width = self.basis.shape[1]

    def amplitudes(self, z: np.ndarray) -> np.ndarray:
        """``(..., 6, 2 n)``: sine then cosine amplitudes per coordinate from ``z`` ``(..., 6 w)``."""
        z = z.reshape(z.shape[:-1] + (6, self.width))
        return np.einsum("kw,...jw->...jk", self.basis, z) * self.scale[:, None]

    def trajectory(self, centre, z, periods: int = 1) -> FourierTrajectory:
        amp = self.amplitudes(z)
        return FourierTrajectory(centre, self.period, amp[:, :self.harmonics], amp[:, self.harmonics:], periods)

    def states(self, centre, z: np.ndarray, times: np.ndarray):
        """Pose, velocity and acceleration for each row of ``z`` ``(m, 6 w)`` at ``times``
        ``(K,)``: three ``(m, K, 6)`` arrays."""
        n = self.harmonics
        rates = 2.0 * np.pi / self.period * np.arange(1, n + 1)
        phase = times[:, None] * rates
        sin, cos = np.sin(phase), np.cos(phase)
        # (K, 2n) rows of the basis functions and their two derivatives.
        rows = (np.hstack([sin, cos]), np.hstack([cos * rates, -sin * rates]),
                np.hstack([-sin * rates**2, -cos * rates**2]))
        amp = self.amplitudes(z)  # (m, 6, 2n)
        out = [np.einsum("kc,mjc->mkj", r, amp) for r in rows]
        out[0] = out[0] + centre
        return tuple(out)


class _Problem:
    """The objective (log of :func:`condition_number`) and the constraint slacks of a
    series at fixed times, evaluated for a batch of variable vectors at once."""

    def __init__(self, platform, base, limits, series, centre, times, inertial):
        self.platform, self.base, self.limits, self.series = platform, base, limits, series
        self.centre, self.times, self.inertial = centre, times, inertial
        self._cache: dict = {}
        self._values: dict = {}

    def evaluate(self, z: np.ndarray, reachable: bool = True):
        """``(log cond, slacks (m, K, 5), reachable (m,))`` for ``z`` ``(m, 6 w)``; with
        ``reachable=False`` the third is None and only the singularity margin of the
        reachability checks is computed (the slacks are the same)."""
        x, xd, xdd = (a.reshape(-1, 6) for a in self.series.states(self.centre, z, self.times))
        m, k = len(z), len(self.times)
        if reachable:
            check = reachability(self.platform, x)
            margin = check.margin
        else:
            margin = margins(self.platform, x)
        regressor, computed = self.platform.regressor(x, xd, xdd, return_mask=True)
        regressor = np.where(np.asarray(computed)[:, None, None], regressor, np.nan)
        forces = regressor @ self.inertial
        with np.errstate(all="ignore"):
            lengths = kinematics.leg_lengths(self.platform.params, x)
            rates = kinematics.leg_velocities(self.platform.params, x, xd)
            accelerations = kinematics.leg_accelerations(self.platform.params, x, xd, xdd)
            slack = self.limits.slack(lengths, rates, accelerations, forces, margin).reshape(m, k, 5)
        stacked = np.nan_to_num(self.base.reduce(regressor).reshape(m, k * 6, -1), nan=0.0)
        cond = _log_condition(stacked)
        # A ratio to a limit near the smallest double overflows, to -inf where the limit is
        # broken and to +inf where it holds; NaN is undefined, a broken limit. SLSQP needs
        # finite values.
        slack = np.nan_to_num(slack, nan=-1.0, posinf=1.0, neginf=-1.0)
        return cond, slack, check.ok.reshape(m, k).all(axis=1) if reachable else None

    def _value(self, z: np.ndarray):
        """The objective and the flat constraint slacks of ``z`` (the last point asked for
        is kept: SLSQP asks for both, and for the derivatives at the points it accepts)."""
        key = z.tobytes()
        if key not in self._values:
            cond, slack, _ = self.evaluate(z[None], reachable=False)
            self._values = {key: (cond[0], slack.reshape(-1))}
        return self._values[key]

    def _gradient(self, z: np.ndarray):
        """Forward differences of :meth:`_value`, only where SLSQP asks for them: most of
        the points it tries in its line searches need the values alone (about a quarter
        need derivatives), and the 6 w shifted points cost 6 w times the values."""
        key = z.tobytes()
        if key not in self._cache:
            cond0, flat0 = self._value(z)
            steps = _STEP * np.maximum(1.0, np.abs(z))
            cond, slack, _ = self.evaluate(z + np.diag(steps), reachable=False)
            flat = slack.reshape(len(steps), flat0.size)
            self._cache = {key: ((cond - cond0) / steps, ((flat - flat0) / steps[:, None]).T)}
        return self._cache[key]

    def condition(self, z) -> float:
        """:func:`condition_number` of the stacked base regressor of ``z``."""
        x, xd, xdd = (a[0] for a in self.series.states(self.centre, z[None], self.times))
        reduced = self.base.reduce(self.platform.regressor(x, xd, xdd))
        return float(condition_number(reduced.reshape(-1, reduced.shape[-1])))

    def objective(self, z):
        return self._value(z)[0]

    def objective_gradient(self, z):
        return self._gradient(z)[0]

    def constraints(self, z):
        return self._value(z)[1]

    def constraints_jacobian(self, z):
        return self._gradient(z)[1]


def _largest_feasible(problem: _Problem, z: np.ndarray, slack: float, steps: int = 30) -> float:
    """The largest factor ``s`` in [0, 1] (by bisection) with every constraint of ``s z``
    at least ``slack`` and every state reachable (0 if none)."""

    def holds(s):
        _, slacks, ok = problem.evaluate(s * z[None])
        return bool(ok[0] and np.all(slacks >= slack))

    if holds(1.0):
        return 1.0
    low, high = 0.0, 1.0
    for _ in range(steps):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if holds(mid) else (low, mid)
    return low


def _centre(platform: Platform, centre) -> np.ndarray:
    if centre is None:
        return platform.home_pose
    centre = arguments.states("centre", centre)
    if centre.shape != (6,):
        raise ValueError(f"centre: expected one pose, shape (6,), got {centre.shape}")
    return centre


def design_excitation(platform: Platform, *, period: float = DEFAULT_PERIOD, harmonics: int = DEFAULT_HARMONICS,
                      centre=None, periods: int = 1, samples: int | None = None, starts: int = DEFAULT_STARTS, seed: int = 0,
                      max_leg_velocity=None, max_leg_acceleration=None, force_limit=None, min_margin=None,
                      stroke_margin=None, friction: bool = True, rest: bool = True, max_iterations: int = DEFAULT_ITERATIONS,
                      base=None, progress: bool = False) -> Excitation:
    """An excitation trajectory for ``platform`` (see the module docstring).

    ``period`` [s] and ``harmonics`` fix the series, about ``centre`` (default: the home
    pose), run ``periods`` times. ``samples`` design samples per period (default
    :data:`SAMPLES_PER_HARMONIC` per harmonic) carry the objective and the constraints;
    ``starts`` random starts (seeded by ``seed``) get at most ``max_iterations`` SLSQP
    iterations each and the best feasible result is kept.

    Limits (defaults in brackets, ``stroke = max - min leg length``): ``stroke_margin``
    (:data:`STROKE_MARGIN` of the stroke at either end), ``max_leg_velocity``
    [:data:`VELOCITY_PER_STROKE` strokes/s], ``max_leg_acceleration``
    [:data:`ACCELERATION_PER_STROKE` strokes/s^2], ``force_limit`` [none] in N and
    ``min_margin`` [:data:`MARGIN_FRACTION` of the centre pose's margin].

    ``base`` is the :class:`~stewart.identification.base_parameters.BaseParameters` to excite (default
    ``base_parameters(platform, friction=friction)``); ``rest`` makes the series start and
    end at rest at ``centre``. Bad arguments raise ``ValueError`` naming them; a centre
    outside the limits raises :class:`~stewart.model.reachability.WorkspaceError` or ``ValueError``.
    """
    from scipy.optimize import minimize

    from .base_parameters import base_parameters

    platform = as_platform(platform)
    period = _positive("period", period, DEFAULT_PERIOD)
    harmonics = arguments.count("harmonics", harmonics, 100)
    if rest and harmonics < 2:
        raise ValueError(f"harmonics: a series that starts at rest needs at least 2, got {harmonics}")
    periods = arguments.count("periods", periods, 1_000_000)
    samples = SAMPLES_PER_HARMONIC * harmonics if samples is None else arguments.count("samples", samples, 100_000)
    starts = arguments.count("starts", starts, 1000)
    max_iterations = arguments.count("max_iterations", max_iterations, 100_000)
    seed = arguments.seed(seed)
    centre = _centre(platform, centre)
    bounds = _limits(platform, centre, stroke_margin, max_leg_velocity, max_leg_acceleration, force_limit, min_margin)
    base = base_parameters(platform, friction=friction) if base is None else base
    if 6 * samples < len(base.names):
        raise ValueError(f"samples: {samples} samples give {6 * samples} equations for {len(base.names)} base "
                         "parameters; give more")

    stroke = bounds.lengths[1] - bounds.lengths[0]
    radius = float(np.max(np.linalg.norm(platform.params.platform_points, axis=1)))
    scale = np.array([stroke] * 3 + [stroke / radius] * 3) / harmonics
    series = _Series(harmonics, period, scale, rest)
    times = np.arange(samples) * (period / samples)
    problem = _Problem(platform, base, bounds, series, centre, times, platform.params.inertial_vector())

    _, at_centre, ok = problem.evaluate(np.zeros((1, 6 * series.width)))
    if not ok[0] or np.any(at_centre < 0):
        kind = Limits.KINDS[int(np.argmin(np.min(at_centre[0], axis=0)))]
        raise ValueError(f"centre: the centre pose at rest is outside the limits ({kind}); choose another "
                         "centre or wider limits")

    rng = np.random.default_rng(seed)
    best = None
    from tqdm.auto import tqdm

    for _ in tqdm(range(starts), desc="excitation starts", disable=not progress):
        direction = rng.normal(size=6 * series.width)
        guess = direction * 0.5 * _largest_feasible(problem, direction, 0.0)
        initial = guess
        solution = minimize(problem.objective, guess, jac=problem.objective_gradient, method="SLSQP",
                            constraints=[{"type": "ineq", "fun": problem.constraints,
                                          "jac": problem.constraints_jacobian}],
                            options={"maxiter": max_iterations, "ftol": 1e-6})
        z = solution.x
        if not np.all(problem.constraints(z) >= -1e-6):  # stopped short of feasibility: scale it back in
            z = z * _largest_feasible(problem, z, 0.0)
        value = problem.objective(z)
        if best is None or value < best[0]:
            best = (value, initial, z, int(solution.nit), direction)

    _, start, z, iterations, direction = best
    check = _Problem(platform, base, bounds, series, centre,
                     np.arange(CHECK_DENSITY * harmonics) * (period / (CHECK_DENSITY * harmonics)),
                     platform.params.inertial_vector())
    factor = _largest_feasible(check, z, CHECK_SLACK)
    z = factor * z
    condition, initial = (problem.condition(v) for v in (z, start))
    if not np.isfinite(condition):
        raise ValueError(_no_motion(problem, direction))
    trajectory = series.trajectory(centre, z, periods)
    peaks, problems = _peaks(platform, trajectory, check.times, bounds)
    return Excitation(trajectory, condition, initial, tuple(base.names), bounds, peaks, not problems, factor,
                      iterations, starts, platform.params.name or "unnamed", problems)


#: The argument of :func:`design_excitation` that sets each kind of limit (:attr:`Limits.KINDS`).
_LIMIT_ARGUMENTS = ("stroke_margin", "max_leg_velocity", "max_leg_acceleration", "force_limit", "min_margin")


def _no_motion(problem: _Problem, direction: np.ndarray) -> str:
    """Why the design does not move (its condition number is inf): the arguments of the limits
    that a motion 2^-30 times the random start ``direction`` already breaks."""
    _, slack, _ = problem.evaluate(2.0**-30 * direction[None])
    names = ", ".join(_LIMIT_ARGUMENTS[k] for k in range(len(_LIMIT_ARGUMENTS)) if np.min(slack[0, :, k]) < 0)
    return (f"{names or 'centre'}: the limits leave no motion about the centre, so the design excites nothing "
            "(condition number inf); widen them")


def _peaks(platform: Platform, trajectory: FourierTrajectory, times: np.ndarray, bounds: Limits):
    """What ``trajectory`` reaches at ``times`` and the limits it oversteps (sentences)."""
    params = platform.params
    x, xd, xdd = trajectory.series(times)
    check = reachability(platform, x)
    lengths = platform.leg_lengths(x)
    rates = kinematics.leg_velocities(params, x, xd)
    accelerations = kinematics.leg_accelerations(params, x, xd, xdd)
    forces = platform.regressor(x, xd, xdd) @ params.inertial_vector()
    peaks = {"leg_length_min": float(lengths.min()), "leg_length_max": float(lengths.max()),
             "leg_velocity": float(np.abs(rates).max()), "leg_acceleration": float(np.abs(accelerations).max()),
             "force": float(np.abs(forces).max()), "margin_min": float(check.margin.min())}
    slack = bounds.slack(lengths, rates, accelerations, forces, check.margin)
    problems = [f"{kind} limit exceeded at t = {times[np.argmin(slack[:, k])]:.4g} s"
                for k, kind in enumerate(Limits.KINDS) if np.min(slack[:, k]) < 0]
    if not check.ok.all():
        problems.append(check.message("sample", times))
    return peaks, problems

