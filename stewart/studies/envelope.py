"""Force and joint-load envelopes: the sizing table of a platform for a motion specification.

For every state ``(x, xdot, xddot)`` of a motion specification the envelope evaluates, per
leg ``i``,

* the actuator force ``tau_i`` (``tau = J_C^-T (M xddot + V xdot + G)``, eqs. 5, 18-23, 72-76,
  by the compiled kernel),
* the leg velocity ``Ldot_i`` (``Ldot = J_C T xdot``, eqs. 5, 8, 18) and the actuator power
  ``tau_i Ldot_i``,
* the magnitudes of the universal-joint force (base on leg, at ``B_i``) and of the
  spherical-joint force (leg on platform, at ``P_i``), the joint reactions of the compiled
  kernel (:meth:`stewart.Platform.joint_reactions`, equal to the Newton-Euler solution
  :func:`stewart.oracles.newton_euler.joint_reactions`),

and keeps the peak of each magnitude with the state where it occurs (:class:`Envelope`).
States whose legs leave the stroke limits (``params.leg_length_limits``) or where the model
is undefined (a singular ``J_C``) are counted and left out.

A motion specification is

* a :class:`Box`: poses in a box with per-axis velocity and acceleration bounds. The
  worst case is searched by sampling: poses uniformly in the box, velocities and
  accelerations at random vertices of their bound boxes (each component at ``+bound`` or
  ``-bound``). At a fixed pose and velocity the forces (actuator and joint) are affine in
  ``xddot`` and the leg velocities linear in ``xdot``, so the largest magnitude over the
  acceleration box lies at one of its vertices and that over the velocity box, for the leg
  velocities, too; the poses and the velocity's quadratic (Coriolis) terms are sampled.
  Every reported peak is attained by a state of the box: it is a lower bound of the true
  worst case that approaches it as the sample count grows (the tests compare it with dense
  grids of small boxes);
* :class:`Trajectories`: moves with ``sample(t) -> (x, xdot, xddot)`` (the package's
  :class:`~stewart.PointToPoint` and :class:`~stewart.SampledTrajectory`, the latter also
  from CSV files), sampled every ``dt`` seconds from 0 to their duration.

For a rotary rig (a :class:`~stewart.RotaryParams` or :class:`~stewart.RotaryPlatform`, issue 40)
the quantities are, per motor, the motor torque ``|tau_i|`` (``J_alpha^T tau = M_t T xddot + V
xdot + G``), the crank speed ``|alpha_dot_i|`` (``alpha_dot = J_alpha T xdot``) and the mechanical
power ``|tau_i alpha_dot_i|``, from the generated rotary batch functions
(:class:`stewart.model.compiled.RotaryPeaks`); states with a crank outside
``params.crank_angle_limits`` are left out as the linear legs outside their stroke are, and those
a crank cannot reach as singular. The torques are affine in ``xddot`` and the speeds linear in
``xdot``, so a box's vertices serve as they do for the legs.

The states are generated and reduced chunk by chunk (:mod:`stewart.studies.execution`), locally or
on a Dask cluster (``client=``), with the same result for the same seed. Within a chunk the
compiled model evaluates them and keeps the running peaks in C (:class:`stewart.model.compiled.Peaks`),
a box's states generated there too, so that no array is allocated per state.
"""

from __future__ import annotations

import csv
import json
import os
import threading
from dataclasses import dataclass

import numpy as np

from ..model.kinematics import POSE_AXES, POSE_UNITS
from ..model import arguments
from ..model import compiled
from . import execution
from ..model.errors import WrongTypeError
from .execution import Peak
from ..model.params import platform_params
from ..model.params import PlatformParams
from ..model.rotary_params import RotaryParams

__all__ = ["Box", "Trajectories", "Envelope", "envelope", "QUANTITIES", "ROTARY_QUANTITIES", "AXES", "study_job",
           "from_partials"]

#: The pose coordinates, in the order of a state, with their units.
AXES = tuple(zip(POSE_AXES, POSE_UNITS, strict=True))

#: The enveloped quantities (each one column per leg, in the order stewart.model.compiled.Peaks
#: computes them), with their units.
QUANTITIES = tuple(zip(compiled.PEAK_QUANTITIES, ("N", "m/s", "W", "N", "N"), strict=True))

#: A rotary rig's enveloped quantities (each one column per motor), with their units.
ROTARY_QUANTITIES = tuple(zip(compiled.ROTARY_PEAK_QUANTITIES, ("N m", "rad/s", "W"), strict=True))

_ROTARY_LABELS = {"torque": "motor torque |tau|", "speed": "crank speed |alpha_dot|",
                  "power": "mechanical power |tau alpha_dot|"}

_LABELS = {"force": "actuator force |tau|", "velocity": "leg velocity |Ldot|", "power": "actuator power |tau Ldot|",
           "universal_joint": "universal-joint force", "spherical_joint": "spherical-joint force"}

#: Samples of a box unless told otherwise.
DEFAULT_SAMPLES = 1_000_000
#: Most states a study may draw (a box's ``samples``, or a trajectory's duration over ``dt``).
MAX_STATES = 10**12


def _bounds(name: str, value) -> np.ndarray:
    arr = arguments.reals(name, value)
    if arr.shape != (6,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected six finite numbers (x, y, z, psi, theta, phi), got {np.shape(value)}")
    return arr


@dataclass(frozen=True)
class Box:
    """Poses with ``lower <= x <= upper`` (per axis; an axis with ``lower == upper`` is held),
    velocities ``|xdot| <= velocity`` and accelerations ``|xddot| <= acceleration`` per axis
    (Euler angles and their rates, rad, rad/s, rad/s^2). ``ValueError`` naming the field for
    an empty box (an upper bound below the lower one) or a negative rate bound."""

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray

    def __post_init__(self):
        fields = {name: _bounds(name, getattr(self, name)) for name in ("lower", "upper", "velocity", "acceleration")}
        inverted = np.flatnonzero(fields["upper"] < fields["lower"])
        if inverted.size:
            axis = AXES[inverted[0]][0]
            raise ValueError(f"upper: below lower on axis {axis} ({fields['upper'][inverted[0]]:g} < "
                             f"{fields['lower'][inverted[0]]:g}): the box is empty")
        with np.errstate(over="ignore"):
            wide = np.flatnonzero(~np.isfinite(fields["upper"] - fields["lower"]))
        if wide.size:
            raise ValueError(f"upper: the box's width on axis {AXES[wide[0]][0]} overflows double precision "
                             f"({fields['lower'][wide[0]]:g} to {fields['upper'][wide[0]]:g})")
        for name in ("velocity", "acceleration"):
            if np.any(fields[name] < 0):
                raise ValueError(f"{name}: bounds must be >= 0, got {fields[name].tolist()}")
        for name, arr in fields.items():
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)

    @classmethod
    def around(cls, motion, margin: float = 0.2, dt: float = 0.01) -> "Box":
        """The box around a trajectory's states (sampled every ``dt`` s) widened by
        ``margin``: each pose range by ``margin`` times its width on either side, the peak
        speed and acceleration of each axis times ``1 + margin``."""
        duration = _duration("motion", motion)
        margin = arguments.real("margin", margin)
        if margin < 0:
            raise ValueError(f"margin: must be >= 0, got {margin}")
        dt = _step(dt)
        x, xd, xdd = arguments.sampled("motion", motion, _sample_times(_sample_count("the motion", duration, dt), dt))
        low, high = x.min(axis=0), x.max(axis=0)
        with np.errstate(over="ignore", invalid="ignore"):  # the Box refuses what overflows, naming the bound
            pad = margin * (high - low)
            bounds = (low - pad, high + pad, (1 + margin) * np.abs(xd).max(axis=0),
                      (1 + margin) * np.abs(xdd).max(axis=0))
        try:
            return cls(*bounds)
        except ValueError as exc:
            raise ValueError(f"margin: the box around the motion is too large: {exc}") from None

    def count(self, samples: int | None) -> int:
        if samples is None:
            return DEFAULT_SAMPLES
        if isinstance(samples, (bool, np.bool_)) or not isinstance(samples, (int, np.integer)) or samples < 1:
            raise ValueError(f"samples: expected a whole number >= 1, got {samples!r}")
        if samples > MAX_STATES:
            raise ValueError(f"samples: at most {MAX_STATES:.0e} states, got {samples!r}")
        return int(samples)

    def draws(self, chunk: execution.Chunk):
        """The chunk's random numbers from its generator: ``(n, 6)`` uniform numbers for the
        poses and ``(n,)`` 12 random bits each for the rates' signs."""
        rng = chunk.rng()
        return rng.random((chunk.size, 6)), rng.integers(0, 1 << 12, chunk.size, dtype=np.uint16)

    def states(self, chunk: execution.Chunk):
        """The chunk's samples ``(x, xd, xdd)``: uniform poses, velocities and accelerations at
        random vertices (:func:`stewart.model.compiled.box_states` of :meth:`draws`)."""
        return compiled.box_states(*self.draws(chunk), self)

    def add_to(self, peaks, chunk: execution.Chunk) -> None:
        """Evaluate the chunk's samples into ``peaks`` (:class:`stewart.model.compiled.Peaks`),
        generating them as it goes from the draws of :meth:`draws` (the uniform numbers into
        this thread's buffer, :func:`_uniforms`)."""
        rng = chunk.rng()
        uniform = _uniforms(rng, chunk.size)
        peaks.add_box(uniform, rng.integers(0, 1 << 12, chunk.size, dtype=np.uint16), self, chunk.start)


#: Each thread's buffer of a box's uniform numbers, reused from chunk to chunk: a new array of
#: megabytes per chunk would be mapped and faulted in afresh where the allocator returns
#: memory to the system early (Dask's workers, with their MALLOC_TRIM_THRESHOLD_). It holds
#: at most _UNIFORMS_ROWS states (6 MB); larger chunks draw into an array of their own.
_UNIFORMS = threading.local()
_UNIFORMS_ROWS = 1 << 17


def _uniforms(rng: np.random.Generator, n: int) -> np.ndarray:
    """``rng.random((n, 6))``, into this thread's buffer when it fits (the same numbers)."""
    if n > _UNIFORMS_ROWS:
        return rng.random((n, 6))
    buffer = getattr(_UNIFORMS, "buffer", None)
    if buffer is None:
        buffer = _UNIFORMS.buffer = np.empty((_UNIFORMS_ROWS, 6))
    return rng.random(out=buffer[:n])


def _duration(name: str, motion) -> float:
    """The duration of ``motion`` (named ``name``), a trajectory: an object with ``sample(t)``
    and a finite ``duration`` >= 0 [s]."""
    duration = arguments.real(f"{name}: its duration", arguments.trajectory(name, motion).duration)
    if duration < 0:
        raise ValueError(f"{name}: its duration must be >= 0, got {duration}")
    return duration


def _step(dt) -> float:
    dt = arguments.real("dt", dt)
    if not dt > 0:
        raise ValueError(f"dt: must be a positive number of seconds, got {dt}")
    return dt


def _sample_count(name: str, duration: float, dt: float) -> int:
    """How many samples every ``dt`` seconds from 0 to ``duration`` (of the trajectory ``name``);
    ``ValueError`` naming ``dt`` for more than :data:`MAX_STATES`."""
    with np.errstate(over="ignore"):
        count = np.floor(duration / dt) + 1
    if not count <= MAX_STATES:
        raise ValueError(f"dt: {dt:g} s samples {name} ({duration:g} s) {count:.3g} times, more than {MAX_STATES:.0e}")
    return int(count)


def _sample_times(count: int, dt: float) -> np.ndarray:
    return np.arange(count) * dt


@dataclass(frozen=True)
class Trajectories:
    """Moves with ``sample(t) -> (x, xdot, xddot)`` and a ``duration``, each sampled every
    ``dt`` seconds from 0 to its duration."""

    motions: tuple
    dt: float = 0.001

    def __post_init__(self):
        try:
            motions = tuple(self.motions)
        except TypeError:
            raise WrongTypeError(f"motions: expected a sequence of trajectories, got {type(self.motions).__name__}") \
                from None
        if not motions:
            raise ValueError("motions: need at least one trajectory")
        durations = [_duration(f"motions: item {k}", motion) for k, motion in enumerate(motions)]
        dt = _step(self.dt)
        counts = [_sample_count(f"trajectory {k}", duration, dt) for k, duration in enumerate(durations)]
        if sum(counts) > MAX_STATES:
            raise ValueError(f"dt: {dt:g} s samples the trajectories {sum(counts):.3g} times, more than "
                             f"{MAX_STATES:.0e}")
        object.__setattr__(self, "motions", motions)
        object.__setattr__(self, "dt", dt)
        object.__setattr__(self, "_counts", tuple(counts))

    @property
    def offsets(self) -> np.ndarray:
        """Index of each trajectory's first sample in the study, and the total count at the end."""
        return np.concatenate([[0], np.cumsum(self._counts)])

    def count(self, samples: int | None) -> int:
        if samples is not None:
            raise ValueError("samples: trajectories are sampled every dt seconds; give dt instead")
        return int(self.offsets[-1])

    def states(self, chunk: execution.Chunk):
        """The chunk's samples ``(x, xd, xdd)``."""
        offsets = self.offsets
        parts = []
        for k, motion in enumerate(self.motions):
            lo, hi = max(chunk.start, offsets[k]), min(chunk.stop, offsets[k + 1])
            if lo < hi:
                parts.append(arguments.sampled(f"motions: item {k}", motion, (np.arange(lo, hi) - offsets[k]) * self.dt))
        return tuple(np.concatenate(arrays) for arrays in zip(*parts))

    def add_to(self, peaks, chunk: execution.Chunk) -> None:
        """Evaluate the chunk's samples into ``peaks`` (:class:`stewart.model.compiled.Peaks`)."""
        peaks.add(*(np.ascontiguousarray(a, dtype=float) for a in self.states(chunk)), chunk.start)


@dataclass(frozen=True)
class _EnvelopeJob(execution.ModelJob):
    """One chunk of an envelope: generate the states, evaluate, reduce (:mod:`stewart.studies.execution`),
    with the compiled model built once per process (:class:`~stewart.studies.execution.ModelJob`)."""

    params: PlatformParams | RotaryParams
    spec: Box | Trajectories

    def __call__(self, chunk: execution.Chunk):
        if isinstance(self.params, RotaryParams):
            peaks = compiled.RotaryPeaks(self.platform.kernel, self.params.crank_angle_limits)
        else:
            peaks = compiled.Peaks(self.platform.kernel, self.params.leg_length_limits)
        self.spec.add_to(peaks, chunk)
        return {"peak": Peak(peaks.value, peaks.state, peaks.index), "states": chunk.size,
                "outside_stroke": peaks.outside, "singular": peaks.singular}


@dataclass(frozen=True)
class Envelope:
    """The peaks of an envelope: ``peak`` a :class:`~stewart.studies.execution.Peak` over the
    ``6 * len(QUANTITIES)`` columns (quantity-major, leg-minor; the state of a peak is
    ``[x, xdot, xddot]``), ``states`` the states drawn, ``outside_stroke`` and ``singular``
    those left out. A ``rotary`` rig's columns are those of :data:`ROTARY_QUANTITIES`, one per
    motor, and its ``outside_stroke`` counts the states with a crank outside its angle limits."""

    peak: Peak
    states: int
    outside_stroke: int
    singular: int
    platform: str = ""
    rotary: bool = False

    @property
    def quantities(self) -> tuple:
        """(name, unit) of the enveloped quantities: :data:`QUANTITIES` or :data:`ROTARY_QUANTITIES`."""
        return ROTARY_QUANTITIES if self.rotary else QUANTITIES

    @property
    def member(self) -> str:
        """What a column belongs to: ``"leg"``, or a rotary rig's ``"motor"``."""
        return "motor" if self.rotary else "leg"

    @property
    def outside_words(self) -> str:
        """What the states left out as :attr:`outside_stroke` are outside of."""
        return "outside the crank angle limits" if self.rotary else "outside the stroke"

    def value(self, quantity: str) -> np.ndarray:
        """The six legs' (motors') peaks of one quantity of :attr:`quantities`."""
        k = [name for name, _ in self.quantities].index(quantity)
        return self.peak.value[6 * k:6 * k + 6]

    def rows(self) -> list[dict]:
        """The sizing table: one row per quantity and leg with the peak, its unit, the study
        index of the state causing it and that state."""
        out = []
        names = [f"{a}" for a, _ in AXES] + [f"{a}_dot" for a, _ in AXES] + [f"{a}_ddot" for a, _ in AXES]
        for k, (quantity, unit) in enumerate(self.quantities):
            for leg in range(6):
                col = 6 * k + leg
                row = {"quantity": quantity, self.member: leg, "peak": float(self.peak.value[col]), "unit": unit,
                       "state_index": int(self.peak.index[col])}
                row.update(zip(names, self.peak.state[col].tolist()))
                out.append(row)
        return out

    def summary(self) -> dict:
        outside = "outside_crank_limits" if self.rotary else "outside_stroke"
        return {"platform": self.platform, "states": self.states, outside: self.outside_stroke,
                "singular": self.singular}

    def to_csv(self, path) -> None:
        rows = self.rows()
        with open(path, "w", newline="") as fh:
            fh.write("# " + ", ".join(f"{k} = {v}" for k, v in self.summary().items()) + "\n")
            writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)

    def to_json(self, path) -> None:
        with open(path, "w") as fh:
            json.dump({**self.summary(), "peaks": self.rows()}, fh, indent=1)

    def plot(self, path) -> str:
        """A figure of the peaks per leg, one panel per quantity."""
        from ..io.plots import pyplot

        plt = pyplot()
        quantities, labels = self.quantities, _ROTARY_LABELS if self.rotary else _LABELS
        fig, axes = plt.subplots(1, len(quantities), figsize=(3 * len(quantities), 3.6), constrained_layout=True)
        legs = np.arange(6)
        for ax, (quantity, unit) in zip(axes, quantities):
            ax.bar(legs, self.value(quantity), color="tab:blue")
            ax.set_title(labels[quantity], fontsize=10)
            ax.set_xlabel(self.member)
            ax.set_ylabel(f"peak [{unit}]")
            ax.set_xticks(legs)
            ax.grid(True, axis="y", alpha=0.3)
        fig.suptitle(f"Envelope of {self.platform or 'the platform'}: peaks over {self.states:,} states "
                     f"({self.outside_stroke:,} {self.outside_words}, {self.singular:,} singular, left out)")
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        fig.savefig(path, dpi=90)
        plt.close(fig)
        return path


def envelope(platform, spec, *, samples: int | None = None, seed: int = 0, client=None,
             chunk_size: int = execution.DEFAULT_CHUNK_SIZE, progress: bool = True) -> Envelope:
    """The :class:`Envelope` of ``platform`` (a :class:`~stewart.Platform` or
    :class:`~stewart.PlatformParams`; a rotary rig's :class:`~stewart.RotaryPlatform` or
    :class:`~stewart.RotaryParams`) over ``spec`` (a :class:`Box`, of ``samples`` states,
    default :data:`DEFAULT_SAMPLES`, drawn from ``seed``; or :class:`Trajectories`).
    ``client``, ``chunk_size`` and ``progress`` as in :func:`stewart.studies.execution.run`."""
    job, n = study_job(_params(platform), spec, samples)
    total = execution.run(job, n, seed=seed, chunk_size=chunk_size, client=client, progress=progress,
                          desc="envelope")
    return from_partials(total, job.params)


def _params(platform):
    """The parameters of ``platform``: a rotary rig's, or a linear platform's (:func:`platform_params`)."""
    if isinstance(getattr(platform, "params", None), RotaryParams):
        return platform.params
    return platform if isinstance(platform, RotaryParams) else platform_params(platform, "platform")


def study_job(params: PlatformParams | RotaryParams, spec, samples: int | None) -> tuple[_EnvelopeJob, int]:
    """The job of the envelope of ``params`` over ``spec`` and its number of states: with
    :func:`from_partials`, the seam through which :mod:`stewart.studies.sweep` runs envelopes
    of many designs in one :func:`~stewart.studies.execution.run_all`."""
    if not isinstance(spec, (Box, Trajectories)):
        raise ValueError(f"spec: expected a Box or Trajectories, got {type(spec).__name__}")
    return _EnvelopeJob(params, spec), spec.count(samples)


def from_partials(total: dict, params: PlatformParams | RotaryParams) -> Envelope:
    """The :class:`Envelope` of the combined partials ``total`` of the jobs of :func:`study_job`."""
    peak = total["peak"]
    rotary = isinstance(params, RotaryParams)
    quantities, member = (ROTARY_QUANTITIES, "motor") if rotary else (QUANTITIES, "leg")
    overflow = np.flatnonzero(~(np.isfinite(peak.value) | np.isneginf(peak.value)))  # -inf: no state counted
    if overflow.size:
        column = overflow[0]
        raise ValueError(f"spec: the {quantities[column // 6][0]} of {member} {column % 6} overflows double precision at "
                         f"state {peak.index[column]} of the study (rates too large for the platform)")
    return Envelope(peak, total["states"], total["outside_stroke"], total["singular"], params.name or "", rotary)
