"""Kinematic calibration: the 42 geometric parameters of a built machine by weighted least
squares on inverse-kinematics residuals (Zhuang & Roth 1993; Masory, Wang & Zhuang 1993),
solved by ``scipy.optimize.least_squares`` with the exact Jacobian of
:mod:`stewart.calibration.geometry`.

**Pose data.** The unknowns are the 42 parameters. The six residuals ``e + delta - |l(x)|``
of a pose share the noise of its measured pose, so they are weighted together (generalized
least squares): by the inverse Cholesky factor of their covariance, the encoders' and the
measured pose's carried to the leg lengths to first order (effective variance),
``C = sigma_L^2 I + g diag(sigma_x^2) g^T``, with ``g = d|l|/dx`` (6 x 6) at the nominal
geometry.

**Point data.** The platform's poses are not measured, so they join the unknowns (six per
pose, started from forward kinematics of the nominal geometry); the residuals are the legs'
(weight ``1/sigma_L``) and the targets' positions ``q - (t + R c)`` (weight ``1/sigma_p``).
{P} is then fixed only by the targets: with one target, or targets on one line, turning
{P} about the target (the line) and every pose back leaves every residual unchanged. That
gauge is fixed by requiring that the platform joints do not turn about the targets relative
to the nominal, ``sum_i (p0_i - c) x (p_i - p0_i) . w = 0`` for each such axis ``w``:
equations the solution satisfies exactly (the fit moves the parameters only in the
directions they leave free), so they change no estimate of a determined quantity. With
three targets not on one line there is no gauge.

**Measured poses and the stroke.** A measured pose is where the built machine was, and the
stroke ends are where calibration data says most, so the nominal geometry (the one being
corrected) does not judge it by the stroke alone. Before the fit, a pose is
refused (:class:`~stewart.WorkspaceError`) only when it is grossly outside the nominal
workspace: a leg past the stroke by more than :data:`GROSS_STROKE_FRACTION` of it (far more
than the millimetres a built machine's joints and encoder zeros are off by: a wrong row, file
or unit), a singular pose, one in another assembly mode or below the base. After the fit,
every leg of every measurement is judged with the calibrated geometry, its length the
reading plus the calibrated offset: the legs past the stroke are reported
(:attr:`Calibration.beyond_stroke`, :meth:`Calibration.stroke_warning`) with how far and the
standard uncertainty of that length, a warning and never a refusal (the parameters'
``leg_length_limits`` are the design's, not necessarily the built machine's).

**Standard errors** come from the covariance ``s^2 (J^T J)^-1`` of the weighted Jacobian
``J`` at the solution, ``s^2`` the weighted sum of squares over the degrees of freedom
(Bard 1974, ch. 7); ``s`` near 1 says the standard deviations given were right. Data that
leaves a combination undetermined (:mod:`stewart.calibration.identifiability`) is an
:class:`~stewart.calibration.identifiability.UnidentifiableError`, never a fit.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.sparse

from ..model import arguments
from ..model.params import platform_params
from ..model.errors import ConvergenceError
from ..model.kinematics import forward_kinematics
from ..model.params import PlatformParams
from ..model.reachability import LEG_TOO_LONG, LEG_TOO_SHORT, WorkspaceError, reachability
from . import geometry
from .geometry import NUM_PARAMETERS, PARAMETER_NAMES
from .identifiability import Identifiability, UnidentifiableError, identifiability, scaled_svd
from .measurements import CalibrationData

__all__ = ["calibrate", "Calibration", "StrokeExcess", "DEFAULT_POSITION_STD", "DEFAULT_ANGLE_STD",
           "DEFAULT_LENGTH_STD", "GROSS_STROKE_FRACTION", "STROKE_SIGNIFICANCE"]

#: Default standard deviations: a laser tracker's position [m] and orientation [rad], an encoder [m].
DEFAULT_POSITION_STD = 1e-5
DEFAULT_ANGLE_STD = 1e-4
DEFAULT_LENGTH_STD = 1e-6
#: A measured pose whose nominal leg lengths pass the stroke by more than this fraction of it
#: (``max - min`` of ``leg_length_limits``) is refused before the fit.
GROSS_STROKE_FRACTION = 0.05
#: A calibrated leg length past the stroke by more than this many standard uncertainties is
#: beyond what the measurement's noise explains (:meth:`Calibration.stroke_warning`).
STROKE_SIGNIFICANCE = 3.0


@dataclass(frozen=True)
class StrokeExcess:
    """A leg past the stroke at a measurement, judged with the calibrated geometry: the
    measurement's ``row`` (its first row for point data) and ``leg``, the leg's ``length``
    (the encoder reading plus the calibrated offset) [m], the ``limit`` it passes [m], the
    ``excess`` past it (positive) [m] and the standard ``uncertainty`` of the length [m] (the
    reading's and the calibrated offset's, :attr:`Calibration.covariance`)."""

    row: int
    leg: int
    length: float
    limit: float
    excess: float
    uncertainty: float


@dataclass(frozen=True)
class Calibration:
    """The result of :func:`calibrate`.

    ``nominal`` and ``params`` are the parameter sets before and after (the calibrated one
    differs in ``base_points``, ``platform_points`` and ``leg_length_offsets`` only);
    ``names``, ``nominal_values``, ``estimates`` and ``standard_errors`` are the 42
    parameters (:data:`~stewart.calibration.geometry.PARAMETER_NAMES`) [m], ``covariance``
    (42, 42) [m^2] that of the estimates (module docstring);
    ``identifiability`` that of the weighted Jacobian at the solution; ``rms_before`` and
    ``rms_after`` the RMS residual of each leg [m] (and, for point data, of the target
    distance [m]) with the nominal and with the calibrated geometry; ``sigma`` the
    estimated scale ``s`` of the weighted residuals (near 1 when the standard deviations
    given were right) on ``dof`` degrees of freedom; ``poses`` the poses of the
    measurements (measured, or estimated for point data); ``beyond_stroke`` the legs past
    the stroke with the calibrated geometry (:class:`StrokeExcess`, largest excess first)."""

    nominal: PlatformParams
    params: PlatformParams
    kind: str
    estimates: np.ndarray
    covariance: np.ndarray
    identifiability: Identifiability
    rms_before: np.ndarray
    rms_after: np.ndarray
    sigma: float
    dof: int
    poses: np.ndarray
    evaluations: int
    names: tuple[str, ...] = PARAMETER_NAMES
    residual_names: tuple[str, ...] = field(default=tuple(f"L{i}" for i in range(6)))
    beyond_stroke: tuple[StrokeExcess, ...] = ()

    @property
    def nominal_values(self) -> np.ndarray:
        return geometry.parameter_vector(self.nominal)

    @property
    def standard_errors(self) -> np.ndarray:
        """The square roots of the diagonal of ``covariance`` (42,) [m]."""
        return np.sqrt(np.diag(self.covariance))

    def summary(self) -> dict:
        """The JSON report: every parameter's nominal value, estimate and standard error, the
        condition number and the residuals."""
        return {
            "kind": self.kind, "measurements": int(len(self.poses)), "condition_number": self.identifiability.condition,
            "sigma": self.sigma, "dof": self.dof, "function_evaluations": self.evaluations,
            "parameters": [{"name": n, "nominal": float(a), "estimate": float(b), "standard_error": float(c)}
                           for n, a, b, c in zip(self.names, self.nominal_values, self.estimates,
                                                 self.standard_errors)],
            "rms_before": dict(zip(self.residual_names, self.rms_before.tolist())),
            "rms_after": dict(zip(self.residual_names, self.rms_after.tolist())),
            "beyond_stroke": [asdict(excess) for excess in self.beyond_stroke],
        }

    def stroke_warning(self) -> str | None:
        """One line on the legs measured past the stroke with the calibrated geometry (None
        when there are none): how many, the largest excess with its uncertainty, and how many
        are past by more than :data:`STROKE_SIGNIFICANCE` standard uncertainties."""
        if not self.beyond_stroke:
            return None
        worst = self.beyond_stroke[0]
        rows = len({excess.row for excess in self.beyond_stroke})
        significant = sum(e.excess > STROKE_SIGNIFICANCE * e.uncertainty for e in self.beyond_stroke)
        low, high = self.params.leg_length_limits
        verdict = (f"{significant} of them by more than {STROKE_SIGNIFICANCE:g} standard uncertainties: the "
                   "leg_length_limits given may not be the built machine's, or those rows are wrong"
                   if significant else "all within their uncertainty")
        return (f"with the calibrated geometry {len(self.beyond_stroke)} leg(s) of {rows} measurement(s) lie past "
                f"the stroke {low:g}-{high:g} m, by up to {1e6 * worst.excess:.4g} um (row {worst.row}, leg "
                f"{worst.leg}, {worst.length:.7g} m, standard uncertainty {1e6 * worst.uncertainty:.4g} um); "
                f"{verdict}")

    def table(self) -> str:
        """The parameters as a text table [mm]: nominal, estimate, change, standard error."""
        lines = [f"{'parameter':<24}{'nominal':>12}{'estimate':>12}{'change':>10}{'std err':>10}  [mm]"]
        for name, nom, est, err in zip(self.names, self.nominal_values, self.estimates, self.standard_errors):
            lines.append(f"{name:<24}{1e3 * nom:>12.4f}{1e3 * est:>12.4f}{1e3 * (est - nom):>10.4f}{1e3 * err:>10.4f}")
        return "\n".join(lines)


def calibrate(platform, data: CalibrationData, *, position_std: float = DEFAULT_POSITION_STD,
              angle_std: float = DEFAULT_ANGLE_STD, length_std: float = DEFAULT_LENGTH_STD) -> Calibration:
    """Calibrate the geometry of ``platform`` (a :class:`~stewart.Platform` or
    :class:`~stewart.PlatformParams`, the nominal) from the :class:`CalibrationData`
    ``data``, whose poses or points have the standard deviations ``position_std`` [m] and
    ``angle_std`` [rad] per coordinate and whose encoder readings ``length_std`` [m].

    ``ValueError`` naming the problem for too few measurements or poses grossly outside the
    nominal workspace (a :class:`~stewart.WorkspaceError`; the module docstring says which,
    and how the others are judged after the fit); an
    :class:`~stewart.calibration.identifiability.UnidentifiableError` saying what to measure
    when the data cannot determine every parameter; a :class:`~stewart.model.errors.ConvergenceError`
    when the least squares stop without converging (never a result)."""
    nominal = platform_params(platform, "platform")
    if not isinstance(data, CalibrationData):
        raise ValueError(f"data: expected a stewart.calibration.CalibrationData, got {type(data).__name__}")
    stds = {name: arguments.real(name, value) for name, value in
            (("position_std", position_std), ("angle_std", angle_std), ("length_std", length_std))}
    for name, value in stds.items():
        if not (value > 0.0 and 0.0 < value * value < np.inf):  # its square weighs the residuals
            raise ValueError(f"{name}: must be a positive number whose square is a finite, nonzero float, "
                             f"got {value}")
    problem = _Problem(nominal, data, **stds)
    free = problem.free_directions
    gauged = free if problem.gauges else None
    ident = identifiability(problem.data_jacobian(problem.theta0), PARAMETER_NAMES, gauged)
    if not ident.identifiable:
        raise UnidentifiableError(_unidentifiable_message(ident, problem), ident)
    # The fit moves the parameters in the directions the gauge of point data leaves free only:
    # theta = free x + fixed, ``fixed`` the part of the nominal the gauge equations hold (zero,
    # and theta = x exactly, without a gauge), so that every theta tried meets them.
    fixed = problem.theta0 - free @ (free.T @ problem.theta0)
    fit = scipy.optimize.least_squares(lambda x: problem.residuals(free @ x + fixed), free.T @ problem.theta0,
                                       jac=lambda x: problem.data_jacobian(free @ x + fixed) @ free, method="lm",
                                       x_scale="jac", ftol=1e-12, xtol=1e-12, gtol=1e-12)
    if not fit.success:  # the evaluations ran out (status 0): the last point tried is no estimate
        raise ConvergenceError(f"{data.source}: the least squares did not converge: {fit.message} "
                               f"({fit.nfev} evaluations, status {fit.status}); no calibration")
    theta = free @ fit.x + fixed
    jac = problem.data_jacobian(theta) @ free
    if not problem.poses_converged:  # point data: the poses at the estimate are no least-squares poses
        raise ConvergenceError(f"{data.source}: the platform's poses at the estimate did not converge in "
                               f"{_POSE_ITERATIONS} Gauss-Newton iterations; no calibration")
    dof = len(jac) - problem.unknowns
    sigma = float(np.sqrt(2.0 * fit.cost / dof))
    norms = np.sqrt(np.sum(jac * jac, axis=0))
    sv, vt = scaled_svd(jac / norms)  # identifiable: every column and singular value is nonzero
    covariance = free @ (((vt.T / sv**2) @ vt) / np.outer(norms, norms)) @ free.T * sigma**2
    first_rows = np.unique(problem.pose_of_row, return_index=True)[1]
    beyond = _beyond_stroke(nominal.leg_length_limits, problem.readings + theta[36:42], first_rows,
                            np.sqrt((sigma * stds["length_std"]) ** 2 + np.diag(covariance)[36:42]))
    return Calibration(
        nominal=nominal, params=geometry.with_parameters(nominal, theta).replace(
            name=f"{nominal.name or 'platform'} (calibrated)"),
        kind=data.kind, estimates=theta, covariance=covariance,
        identifiability=identifiability(problem.data_jacobian(theta), PARAMETER_NAMES, gauged), rms_before=problem.rms(problem.theta0),
        rms_after=problem.rms(theta), sigma=sigma, dof=int(dof), poses=problem.poses_at(theta)[problem.pose_of_row],
        evaluations=int(fit.nfev), residual_names=problem.residual_names, beyond_stroke=beyond)


def _beyond_stroke(limits, lengths, rows, uncertainty) -> tuple[StrokeExcess, ...]:
    """The :class:`StrokeExcess` of every leg whose ``lengths`` (K, 6) lie outside ``limits``
    (none without limits), largest excess first; ``rows`` (K,) the measurements' rows,
    ``uncertainty`` (6,) each leg's standard uncertainty."""
    if limits is None:
        return ()
    low, high = limits
    found = []
    for limit, past in ((low, low - lengths), (high, lengths - high)):
        for k, i in zip(*np.nonzero(past > 0.0)):
            found.append(StrokeExcess(int(rows[k]), int(i), float(lengths[k, i]), limit, float(past[k, i]),
                                      float(uncertainty[i])))
    return tuple(sorted(found, key=lambda e: -e.excess))


class _Problem:
    """The weighted residuals of ``data`` as a function of the 42 parameters ``theta`` and
    their exact Jacobian. For point data the poses are eliminated (variable projection,
    Golub & Pereyra 2003): at each ``theta`` every pose is solved by Gauss-Newton on its own
    residuals, and the Jacobian is that of the parameters with each pose's columns projected
    out, ``(I - B_k B_k^+) A_k`` (Kaufman's form), whose normal matrix is the parameters'
    Schur complement: the same identifiability and covariance as the full problem."""

    def __init__(self, nominal: PlatformParams, data: CalibrationData, position_std, angle_std, length_std):
        self.nominal, self.data = nominal, data
        self.theta0 = theta0 = geometry.parameter_vector(nominal)
        self.readings, self.pose_of_row = data.pose_index()
        if data.poses is not None:
            poses = data.poses
        else:
            try:
                poses = forward_kinematics(nominal, self.readings, encoder=True)
            except ConvergenceError as exc:
                raise ValueError(f"{data.source}: the encoder readings of pose(s) {exc.rows[:10]} are not this "
                                 "platform's: forward kinematics finds no pose") from None
        # A measured pose is where the machine was: only a gross excess refuses it (module
        # docstring), not the design limits on the joints' cones and the legs' and the plate's
        # clearance, which the built machine, off the nominal, may pass by its geometry error.
        stroke = nominal.leg_length_limits
        widen = None if stroke is None else GROSS_STROKE_FRACTION * (stroke[1] - stroke[0])
        bounds = nominal.replace(  # (the widened minimum kept positive, as PlatformParams requires)
            universal_joint_max_angle=None, spherical_joint_max_angle=None, leg_diameter=None, plate_radius=None,
            base_clearance=None,
            leg_length_limits=None if stroke is None else (max(stroke[0] - widen, np.finfo(float).tiny),
                                                           stroke[1] + widen))
        reach = reachability(bounds, poses, name=data.source)
        if not np.all(reach.ok):
            grossly = (f" (the stroke {stroke[0]:g}-{stroke[1]:g} m widened by {GROSS_STROKE_FRACTION:g} of it, "
                       f"{widen:.4g} m, for the built machine's geometry errors: check the rows, the file and its "
                       "units)" if np.any(reach.flags & (LEG_TOO_SHORT | LEG_TOO_LONG)) else "")
            raise WorkspaceError(f"{data.source}: {reach.message('measured pose')}{grossly}", reach)
        self.count = len(poses)
        self.gauge = _gauge(nominal, data.target_offsets) if data.points is not None else np.zeros((0, NUM_PARAMETERS))
        self.gauges = len(self.gauge)
        #: The parameter directions the gauge leaves free, (42, 42 - gauges): the covariance
        #: and identifiability are those of the data in these directions (a hard constraint).
        self.free_directions = scipy.linalg.null_space(self.gauge) if self.gauges else np.eye(NUM_PARAMETERS)
        unknowns = NUM_PARAMETERS + (0 if data.poses is not None else 6 * self.count) - self.gauges
        equations = 6 * self.count + (0 if data.points is None else 3 * len(data.points))
        if equations <= unknowns:
            per, what, given = (6, "poses", self.count) if data.points is None else \
                (3, "target measurements", len(data.points))
            raise ValueError(f"{data.source}: too few measurements: {equations} equations for {unknowns} unknowns; "
                             f"measure at least {given + int(np.ceil((unknowns + 1 - equations) / per))} {what}")
        self.unknowns = unknowns
        self.residual_names = tuple(f"L{i}" for i in range(6)) + (() if data.points is None else ("target",))
        #: Each pose's whitening matrix (K, 6, 6) of its six leg residuals: ``W_k`` with
        #: ``W_k C_k W_k^T = I`` for their covariance ``C_k``.
        self.weight_legs = np.broadcast_to(np.eye(6) / length_std, (self.count, 6, 6))
        if data.poses is not None:
            # The measured pose's noise is common to the six legs: C_k = sigma_L^2 I + g diag(sigma_x^2) g^T.
            pose_var = np.array([position_std**2] * 3 + [angle_std**2] * 3)
            g = geometry.leg_pose_jacobian(theta0, poses)
            covariance = length_std**2 * np.eye(6) + np.einsum("kia,a,kja->kij", g, pose_var, g)
            self.weight_legs = np.linalg.inv(np.linalg.cholesky(covariance))
        self.weight_points = 1.0 / position_std
        self.poses = poses
        self._solved = (None, poses)
        #: Whether the last poses solved (point data) met :data:`_POSE_TOLERANCE`.
        self.poses_converged = True
        if data.points is not None:
            # The pose of each data row of the Jacobian (legs, then targets).
            self.row_pose = np.concatenate([np.repeat(np.arange(self.count), 6), np.repeat(self.pose_of_row, 3)])
            self.sum_per_pose = scipy.sparse.csr_matrix(
                (np.ones(len(self.row_pose)), (self.row_pose, np.arange(len(self.row_pose)))),
                shape=(self.count, len(self.row_pose)))

    def poses_at(self, theta) -> np.ndarray:
        """The poses (K, 6): measured, or for point data those that fit best at ``theta``."""
        if self.data.poses is not None:
            return self.data.poses
        if self._solved[0] is not None and np.array_equal(self._solved[0], theta):
            return self._solved[1]
        poses = self._solved[1].copy()
        self.poses_converged = False
        for _ in range(_POSE_ITERATIONS):
            data_rows = self._data_parts(theta, poses, columns=False)
            pose_cols = self._pose_columns(theta, poses)
            normal, gradient = self._per_pose(pose_cols, pose_cols), self._per_pose(pose_cols, data_rows[:, None])
            step = -np.linalg.solve(normal, gradient)[..., 0]
            poses = poses + step
            if np.max(np.abs(step)) <= _POSE_TOLERANCE:
                self.poses_converged = True
                break
        self._solved = (np.array(theta, copy=True), poses)
        return poses

    def _per_pose(self, left, right) -> np.ndarray:
        """``sum over pose k's rows of left^T right``, (K, 6, columns of right)."""
        products = (left[:, :, None] * right[:, None, :]).reshape(len(left), -1)
        return (self.sum_per_pose @ products).reshape(self.count, 6, right.shape[1])

    def _data_parts(self, theta, poses, columns=True):
        """The weighted residuals of the data (legs, then targets) and, with ``columns``, their
        parameter columns ``A`` (rows, 42)."""
        rows = np.einsum("kij,kj->ki", self.weight_legs, geometry.leg_residuals(theta, poses, self.readings)).ravel()
        if self.data.points is not None:
            offsets = self.data.target_offsets[self.data.targets]
            points = self.data.points - geometry.target_positions(poses[self.pose_of_row], offsets)
            rows = np.concatenate([rows, self.weight_points * points.ravel()])
        if not columns:
            return rows
        cols = np.zeros((len(rows), NUM_PARAMETERS))
        cols[:6 * self.count] = np.einsum("kij,kjp->kip", self.weight_legs,
                                          geometry.leg_jacobian(theta, poses)).reshape(-1, NUM_PARAMETERS)
        return rows, cols

    def _pose_columns(self, theta, poses) -> np.ndarray:
        """The columns ``B`` (rows, 6) of each data row's pose (point data)."""
        legs = np.einsum("kij,kjp->kip", self.weight_legs, geometry.leg_pose_jacobian(theta, poses))
        points = geometry.target_pose_jacobian(poses[self.pose_of_row], self.data.target_offsets[self.data.targets])
        return np.concatenate([legs.reshape(-1, 6), self.weight_points * points.reshape(-1, 6)])

    def residuals(self, theta) -> np.ndarray:
        """The weighted residuals of the data."""
        return self._data_parts(theta, self.poses_at(theta), columns=False)

    def data_jacobian(self, theta) -> np.ndarray:
        """The weighted Jacobian of the data's residuals."""
        poses = self.poses_at(theta)
        _, cols = self._data_parts(theta, poses)
        if self.data.points is not None:
            pose_cols = self._pose_columns(theta, poses)
            solved = np.linalg.solve(self._per_pose(pose_cols, pose_cols), self._per_pose(pose_cols, cols))
            cols = cols - np.einsum("ra,rap->rp", pose_cols, solved[self.row_pose])
        return cols

    def rms(self, theta) -> np.ndarray:
        """The RMS residual of each leg, and of the target distance for point data [m]."""
        poses = self.poses_at(theta)
        legs = geometry.leg_residuals(theta, poses, self.readings)
        out = np.sqrt(np.mean(legs * legs, axis=0))
        if self.data.points is None:
            return out
        points = self._data_parts(theta, poses, columns=False)[6 * self.count:] / self.weight_points
        return np.append(out, np.sqrt(3.0 * np.mean(points * points)))


#: Gauss-Newton iterations of the poses of point data at one parameter vector (at most).
_POSE_ITERATIONS = 30
#: ... until no coordinate of a pose moves by more than this [m or rad].
_POSE_TOLERANCE = 1e-12


def _gauge(nominal: PlatformParams, offsets: np.ndarray) -> np.ndarray:
    """The rows (g, 42) of the gauge equations of point data: for each axis ``w`` about which
    turning {P} moves no target, ``sum_i w . ((p0_i - c) x (p_i - p0_i)) = 0`` (linear in the
    parameters; ``c`` the targets' centroid), the residual ``G (theta - theta0)``."""
    centre = offsets.mean(axis=0)
    spread = offsets - centre
    skew = np.concatenate([np.array([[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]]) for s in spread])
    axes = scipy.linalg.null_space(skew, rcond=1e-9).T if np.any(spread) else np.eye(3)
    arms = nominal.platform_points - centre
    rows = np.zeros((len(axes), NUM_PARAMETERS))
    for k, w in enumerate(axes):
        rows[k, 18:36] = np.cross(w, arms).ravel()  # w . (a x dp) = (w x a) . dp
    return rows


def _unidentifiable_message(ident: Identifiability, problem: _Problem) -> str:
    data = problem.data
    combos = ident.combinations
    shown = "; ".join(combos[:3]) + (f"; and {len(combos) - 3} more" if len(combos) > 3 else "")
    poses = problem.poses
    if len(np.unique(problem.readings, axis=0)) < 7:
        advice = "measure at least 7 distinct poses spread over the workspace"
    elif np.ptp(poses[:, 3:], axis=0).max() < 1e-3:
        advice = "measure poses that also turn the platform about all three axes (these only translate it)"
    else:
        advice = "measure more poses spread over the workspace's positions and orientations (stewart calibration-poses designs them)"
    return (f"{data.source}: the measurements cannot determine {len(combos)} parameter combination(s), e.g. "
            f"{shown}; {advice}")
