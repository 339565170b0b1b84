"""Identification: a built platform's base inertial and friction parameters from measured
leg lengths and actuator forces.

The forces are linear in the inertial parameters (:meth:`stewart.Platform.regressor`), and
measurements determine the base parameters ``beta`` (:mod:`stewart.identification.base_parameters`). From a
log of leg lengths and forces sampled at a known rate, :func:`identify`

1. finds the poses by forward kinematics (Newton-Raphson from the home pose) from the logged
   leg lengths, which are the machine's encoder readings: the parameters'
   ``leg_length_offsets`` are added to them (:func:`stewart.forward_kinematics` with
   ``encoder=True``);
2. differentiates them with a zero-phase filter: a Savitzky-Golay filter whose window spans
   about one period of the cut-off (``filter="savgol"``, polynomial order 4), or a 4th-order
   Butterworth low-pass run forwards and backwards (``filtfilt``) followed by central
   differences (``filter="butterworth"``). The poses are differentiated rather than the leg
   lengths because the regressor takes pose rates. The forces are not filtered: they enter
   the least squares linearly, so their noise averages out without bias, while smoothing them
   would blur the Coulomb friction's turn at each reversal of a leg into a bias. The samples
   within one filter window of either end are dropped, within three for the Butterworth
   filter: its start-up transients at the ends of the log last longer (its slowest poles, of
   damping 0.38, decay by e^-2.4 a period of the cut-off);
3. stacks the base regressor of the remaining samples and solves weighted least squares
   (:func:`estimate`): a first ordinary solve gives each leg's residual variance, and each
   leg's equations are then weighted by its inverse standard deviation (legs with noisier
   load cells count less). The covariance of the estimates is ``s^2 (A^T A)^-1`` of the
   weighted system, ``s^2`` its residual variance; the relative standard deviation of an
   estimate is its standard error over its magnitude, in %.

Noise in the leg lengths, differentiated twice, reaches the regressor and biases the
estimates (errors in variables) in proportion to the cut-off's square and more: a cut-off a
few times the trajectory's highest frequency keeps that bias below the standard errors.

A trajectory that does not excite every base parameter gives a stacked regressor whose
condition number (:func:`excitation_condition`: each column in units of its size over random
motion of the workspace) exceeds :data:`MAX_CONDITION`: that is an error, never a silent fit.

:func:`synthetic_measurements` simulates a logged run: a platform following a trajectory
(the forces its actuators deliver, :meth:`stewart.Platform.actuator_forces`, with friction)
with leg lengths from inverse kinematics, plus seeded Gaussian noise.
"""

from __future__ import annotations

import dataclasses
import os
import warnings

import numpy as np
import scipy.signal

from ..model import arguments
from ..io import csvfile
from ..model.errors import ConvergenceError, WrongTypeError
from .base_parameters import BaseParameters, base_parameters
from ..model.params import NonAxisymmetricLegWarning, PlatformParams
from ..model.platform import Platform, as_platform

__all__ = ["Measurements", "Identification", "identify", "estimate", "synthetic_measurements",
           "MAX_CONDITION", "FILTERS", "COLUMNS", "excitation_condition", "differentiate", "validation"]

#: The columns of a measurement file: time [s], six leg lengths [m], six actuator forces [N].
COLUMNS = ["t"] + [f"L{i}" for i in range(6)] + [f"F{i}" for i in range(6)]
#: Most condition number of the stacked base regressor (`excitation_condition`) of an
#: identification; above it the trajectory does not excite every base parameter.
MAX_CONDITION = 1e4
#: The differentiating filters.
FILTERS = ("savgol", "butterworth")
#: Fewest samples an identification uses after the filter's ends are dropped, per base parameter.
SAMPLES_PER_PARAMETER = 10


@dataclasses.dataclass(frozen=True)
class Measurements:
    """A log of a platform's legs: times ``t`` ``(n,)`` [s], leg lengths ``(n, 6)`` [m] (the
    encoder readings: true lengths less the parameters' ``leg_length_offsets``) and
    actuator forces ``(n, 6)`` [N]; checked (finite, time strictly increasing at a constant rate)."""

    t: np.ndarray
    lengths: np.ndarray
    forces: np.ndarray

    def __post_init__(self):
        t = arguments.reals("t", self.t)
        lengths, forces = arguments.reals("lengths", self.lengths), arguments.reals("forces", self.forces)
        if t.ndim != 1 or lengths.shape != (len(t), 6) or forces.shape != (len(t), 6):
            raise ValueError(f"measurements: need t (n,), lengths (n, 6) and forces (n, 6), got {t.shape}, "
                             f"{lengths.shape} and {forces.shape}")
        bad = np.flatnonzero(~(np.isfinite(t) & np.all(np.isfinite(lengths), axis=1) & np.all(np.isfinite(forces), axis=1)))
        if bad.size:
            raise ValueError(f"measurements: sample(s) {bad[:5].tolist()} hold NaN or inf")
        if len(t) < 3:
            raise ValueError(f"measurements: too few samples ({len(t)})")
        with np.errstate(over="ignore", invalid="ignore"):
            steps = np.diff(t)
            rate = (len(t) - 1) / (t[-1] - t[0])
        if np.any(steps <= 0.0):
            k = int(np.argmax(steps <= 0.0))
            raise ValueError(f"measurements: the time column is not increasing at sample {k + 1} "
                             f"(t = {t[k]:g} then {t[k + 1]:g})")
        if not (np.all(np.isfinite(steps)) and 0.0 < rate < np.inf):
            raise ValueError(f"t: the time steps ({steps[0]:g} s first) give no finite sampling rate (rate "
                             f"{rate:g} Hz); give the times in seconds")
        if np.max(np.abs(steps - steps.mean())) > 1e-6 * steps.mean():
            raise ValueError("measurements: the samples are not evenly spaced in time (the filters need a constant rate)")
        for name, value in (("t", t), ("lengths", lengths), ("forces", forces)):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "_rate", float(rate))

    @property
    def rate(self) -> float:
        """Samples per second (finite and positive: checked)."""
        return self._rate

    @classmethod
    def from_csv(cls, path) -> "Measurements":
        """Read a CSV file with the :data:`COLUMNS` (a header picks them by name)."""
        data = csvfile.read(path, COLUMNS)
        try:
            return cls(data[:, 0], data[:, 1:7], data[:, 7:13])
        except ValueError as exc:
            raise ValueError(f"{os.fspath(path)}: {exc}") from None

    def to_csv(self, path, comment: str | None = None) -> None:
        csvfile.write(path, COLUMNS, np.column_stack([self.t, self.lengths, self.forces]),
                      comment or "time [s], leg lengths [m], actuator forces [N]", fmt="%.17g")


@dataclasses.dataclass(frozen=True)
class Identification:
    """The result of :func:`identify` (or :func:`estimate`)."""

    base: BaseParameters
    estimates: np.ndarray         # beta, (r,)
    standard_errors: np.ndarray   # (r,)
    residual_rms: np.ndarray      # per leg [N], of the unweighted residual
    condition_number: float       # of the stacked base regressor (`excitation_condition`)
    samples: int                  # samples used
    prior: PlatformParams         # the parameters the geometry and the unidentifiable values come from

    @property
    def relative_std(self) -> np.ndarray:
        """Standard error over |estimate|, in % (inf for an estimate of zero)."""
        with np.errstate(divide="ignore"):
            return 100.0 * self.standard_errors / np.abs(self.estimates)

    def params(self) -> PlatformParams:
        """Physical parameters consistent with the estimates: the prior's inertial vector pi0
        corrected by the least change that reproduces them, pi0 + K^+ (beta - K pi0); what the
        measurements cannot determine stays as in the prior. ``ValueError`` when no physical
        body has these values. Without joint axes the legs' I_yy and I_zz are identified apart
        and may differ (no :class:`stewart.NonAxisymmetricLegWarning` is given for that)."""
        K = self.base.matrix
        pi0 = self.prior.inertial_vector()
        p = K.shape[1]
        pi = pi0.copy()
        pi[:p] = pi0[:p] + np.linalg.pinv(K) @ (self.estimates - K @ pi0[:p])
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", NonAxisymmetricLegWarning)
                return self.prior.with_inertial_vector(pi)
        except ValueError as exc:
            raise ValueError(f"the identified values are not physical ({exc}); excite the platform better, "
                             "or start from a prior closer to the machine") from None

    def predict(self, x, xd, xdd) -> np.ndarray:
        """Forces ``Y_b beta`` at states, from the platform the identification was for."""
        from ..model.platform import Platform

        return self.base.reduce(Platform(self.prior).regressor(x, xd, xdd)[..., :len(self.base.columns)]) @ self.estimates

    def table(self) -> str:
        """The estimates as a text table."""
        width = max(len(n) for n in self.base.names)
        lines = [f"{'base parameter':<{width}}  {'estimate':>12}  {'std error':>10}  {'rel. std':>8}"]
        for name, value, error, rel in zip(self.base.names, self.estimates, self.standard_errors, self.relative_std):
            lines.append(f"{name:<{width}}  {value:12.6g}  {error:10.3g}  {rel:7.2f}%")
        lines.append(f"condition number {self.condition_number:.3g}, {self.samples} samples, residual RMS per leg "
                     f"[N]: {', '.join(f'{v:.3g}' for v in self.residual_rms)}")
        return "\n".join(lines)

    def summary(self) -> dict:
        """The result as plain Python (the report file)."""
        return {"base_parameters": [{"name": n, "estimate": float(v), "standard_error": float(e),
                                     "relative_std_percent": float(r)}
                                    for n, v, e, r in zip(self.base.names, self.estimates, self.standard_errors,
                                                          self.relative_std)],
                "condition_number": float(self.condition_number), "samples": self.samples,
                "residual_rms": self.residual_rms.tolist(), "never_act": [
                    name for name, used in zip(self.base.columns, np.any(self.base.matrix, axis=0)) if not used]}


def excitation_condition(base: BaseParameters, A: np.ndarray) -> float:
    """The condition number of a stacked base regressor ``A`` ``(m, r)`` with each column in
    units of its size over random motion (:attr:`BaseParameters.scale`): large when the
    trajectory leaves a combination of base parameters unexcited."""
    return _condition(_gram(A / base.scale))


def _gram(A: np.ndarray) -> np.ndarray:
    return A.T @ A


def _condition(gram: np.ndarray) -> float:
    """cond(A) from A^T A: the square root of its eigenvalues' ratio (inf when singular)."""
    eig = np.linalg.eigvalsh(gram)
    return float(np.sqrt(eig[-1] / eig[0])) if eig[0] > 0.0 else np.inf


def estimate(platform, x, xd, xdd, forces, *, friction: bool = True, base: BaseParameters | None = None,
             samples: int = 200) -> Identification:
    """Weighted least squares for the base parameters from states ``x, xd, xdd`` ``(n, 6)`` and
    the measured forces ``(n, 6)`` (see the module's text); ``base`` from :func:`base_parameters`
    (``samples`` states) unless given."""
    platform = as_platform(platform)
    x, xd, xdd = (arguments.states(n, v) for n, v in (("x", x), ("xd", xd), ("xdd", xdd)))
    forces = arguments.states("forces", forces)
    base = base or base_parameters(platform, samples=samples, friction=friction)
    return _estimate(platform, x, xd, xdd, forces, base)


def _estimate(platform: Platform, x, xd, xdd, forces, base: BaseParameters) -> Identification:
    """:func:`estimate` on the compiled ``platform``, checked states and ``base``."""
    n = len(forces)
    if n * 6 < SAMPLES_PER_PARAMETER * base.rank:
        raise ValueError(f"measurements: too few samples ({n}) for {base.rank} base parameters; "
                         f"need at least {int(np.ceil(SAMPLES_PER_PARAMETER * base.rank / 6))}")
    Y, ok = platform.regressor(x, xd, xdd, return_mask=True)
    if not np.all(ok):
        bad = np.flatnonzero(~ok)
        raise ValueError(f"measurements: the model is undefined at sample(s) {bad[:5].tolist()} (a singular pose)")
    A = base.reduce(Y[..., :len(base.columns)]) / base.scale  # (n, 6, r), columns in units of their size
    grams = np.stack([_gram(A[:, leg]) for leg in range(6)])  # per leg A_i^T A_i
    with np.errstate(over="ignore", invalid="ignore"):
        moments = np.einsum("nlr,nl->lr", A, forces)           # per leg A_i^T f_i
    if not np.all(np.isfinite(moments)):
        raise ValueError("forces: too large for double precision (the least squares overflow)")
    condition = _condition(grams.sum(axis=0))
    if not condition <= MAX_CONDITION:
        raise ValueError(f"measurements: the trajectory does not excite every base parameter (condition number "
                         f"{condition:.3g} > {MAX_CONDITION:.0e}); move every axis, at several speeds")
    # normal equations of the scaled columns (their condition is at most MAX_CONDITION)
    with np.errstate(over="ignore", invalid="ignore"):  # forces near the largest double: refused below
        beta = np.linalg.solve(grams.sum(axis=0), moments.sum(axis=0))
        sigma = np.sqrt(np.mean((forces - A @ beta) ** 2, axis=0))
        weights = 1.0 / np.maximum(sigma, 1e-12 * max(np.max(sigma), np.finfo(float).tiny))
        normal = np.einsum("l,lrs->rs", weights ** 2, grams)
        beta = np.linalg.solve(normal, np.einsum("l,lr->r", weights ** 2, moments))
        residual = (forces - A @ beta) * weights
        dof = max(residual.size - base.rank, 1)
        covariance = np.linalg.inv(normal) * (np.sum(residual ** 2) / dof)
        result = Identification(base=base, estimates=beta / base.scale,
                                standard_errors=np.sqrt(np.diag(covariance)) / base.scale,
                                residual_rms=np.sqrt(np.mean((forces - A @ beta) ** 2, axis=0)),
                                condition_number=condition, samples=n, prior=platform.params)
    if not all(np.all(np.isfinite(v)) for v in (result.estimates, result.standard_errors, result.residual_rms)):
        raise ValueError("forces: too large for double precision (the estimates or their errors overflow)")
    return result


def differentiate(measurements: Measurements, poses: np.ndarray, *, filter: str = "savgol", cutoff: float = 10.0):
    """Zero-phase filtered poses, rates and accelerations, and the measured forces, at the
    samples farther than one filter window from either end (three for the Butterworth filter)."""
    if filter not in FILTERS:
        raise ValueError(f"filter: expected one of {', '.join(FILTERS)}, got {filter!r}")
    cutoff = arguments.real("cutoff", cutoff)
    rate = measurements.rate
    if not 0.0 < cutoff < rate / 2.0:
        raise ValueError(f"cutoff: need 0 < cutoff < {rate / 2:g} Hz (half the sampling rate), got {cutoff:g}")
    dt = 1.0 / rate
    with np.errstate(over="ignore"):
        period = rate / cutoff  # samples in one period of the cut-off, the window's span
    if not np.isfinite(period):
        raise ValueError(f"cutoff: {cutoff:g} Hz is too low for the sampling rate {rate:g} Hz: the filter window "
                         "overflows; raise the cut-off")
    window = max(7, int(round(period)) | 1)
    drop = window if filter == "savgol" else 3 * window  # the samples dropped at either end
    n = len(poses)
    if n < 2 * drop + window:
        raise ValueError(f"measurements: too few samples ({n}) for the filter window of {window} samples; "
                         f"log longer or raise the cut-off")
    if filter == "savgol":
        smooth = lambda v, d=0: scipy.signal.savgol_filter(v, window, 4, deriv=d, delta=dt, axis=0)
        x, xd, xdd = smooth(poses), smooth(poses, 1), smooth(poses, 2)
    else:
        b, a = scipy.signal.butter(4, cutoff / (rate / 2.0))
        low = lambda v: scipy.signal.filtfilt(b, a, v, axis=0)
        x = low(poses)
        xd = np.gradient(x, dt, axis=0)
        xdd = np.gradient(xd, dt, axis=0)
    keep = slice(drop, n - drop)
    return x[keep], xd[keep], xdd[keep], measurements.forces[keep]


def _poses(platform, measurements: Measurements) -> np.ndarray:
    """The poses of the logged leg lengths (forward kinematics from home); a
    :class:`~stewart.ConvergenceError` naming ``measurements`` where none is found."""
    try:
        return platform.forward_kinematics(measurements.lengths, platform.home_pose, encoder=True)
    except ConvergenceError as exc:
        raise ConvergenceError(f"measurements: the leg lengths are not this platform's ({exc})", exc.rows) from None


def _checked_measurements(value) -> Measurements:
    if not isinstance(value, Measurements):
        raise WrongTypeError(f"measurements: expected stewart.identification.identify.Measurements, got {type(value).__name__}")
    return value


def identify(platform, measurements: Measurements, *, filter: str = "savgol", cutoff: float = 10.0,
             friction: bool = True, base: BaseParameters | None = None) -> Identification:
    """The base parameters of ``platform`` (its geometry; its inertial values are the prior)
    from ``measurements`` (see the module's text)."""
    platform = as_platform(platform)
    _checked_measurements(measurements)
    poses = _poses(platform, measurements)
    x, xd, xdd, forces = differentiate(measurements, poses, filter=filter, cutoff=cutoff)
    return _estimate(platform, x, xd, xdd, forces, base or base_parameters(platform, friction=friction))


def validation(result: Identification, platform, measurements: Measurements, *, filter: str = "savgol",
               cutoff: float = 10.0):
    """Predicted against measured forces on a held-out log: ``(t, predicted, measured, rms per leg)``,
    the measured forces filtered as for the identification."""
    if not isinstance(result, Identification):
        raise WrongTypeError(f"result: expected a stewart.identification.identify.Identification, got {type(result).__name__}")
    platform = as_platform(platform)
    _checked_measurements(measurements)
    poses = _poses(platform, measurements)
    x, xd, xdd, forces = differentiate(measurements, poses, filter=filter, cutoff=cutoff)
    window = (len(measurements.t) - len(x)) // 2
    predicted = result.predict(x, xd, xdd)
    return (measurements.t[window:window + len(x)], predicted, forces,
            np.sqrt(np.mean((predicted - forces) ** 2, axis=0)))


def synthetic_measurements(platform, trajectory, *, rate: float = 500.0, noise_length: float = 0.0,
                           noise_force: float = 0.0, seed: int = 0) -> Measurements:
    """A simulated log of ``platform`` following ``trajectory`` (anything with ``duration``
    and ``sample(t) -> (x, xd, xdd)``) for its duration at ``rate`` samples per second: leg
    lengths by inverse kinematics as the encoders read them (less the leg length offsets) and the forces its actuators deliver (rigid body plus
    friction), with Gaussian noise of standard deviation ``noise_length`` [m] and
    ``noise_force`` [N] (seeded)."""
    platform = as_platform(platform)
    rate = arguments.real("rate", rate)
    if not rate > 0.0:
        raise ValueError(f"rate: must be positive, got {rate:g}")
    for name, value in (("noise_length", noise_length), ("noise_force", noise_force)):
        if not arguments.real(name, value) >= 0.0:
            raise ValueError(f"{name}: must be >= 0, got {value}")
    t = np.arange(int(np.floor(trajectory.duration * rate)) + 1) / rate
    x, xd, xdd = trajectory.sample(t)
    rng = np.random.default_rng(arguments.seed(seed))
    lengths = platform.encoder_readings(x) + noise_length * rng.standard_normal((len(t), 6))
    forces = platform.actuator_forces(x, xd, xdd) + noise_force * rng.standard_normal((len(t), 6))
    return Measurements(t, lengths, forces)
