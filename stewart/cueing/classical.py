"""Classical washout (Conrad & Schmidt 1970; Reid & Nahon 1985, "Flight simulation motion-base
drive algorithms: part 1", UTIAS report 296), linear and per axis.

From the vehicle's specific force ``f`` and angular velocity ``w`` (vehicle frame, see
:mod:`stewart.cueing.log`), with ``a = k_t (f - [0, 0, g])`` the scaled acceleration:

* translation, per axis, the high-pass ``H_t(s) = s^2 / (s^2 + 2 zeta_t w_t s + w_t^2)``
  (second order), times ``s / (s + w_b)`` (third order, the default: the platform returns
  to its neutral position under a sustained acceleration); the position is
  ``H_t(s) / s^2`` of ``a``;
* rotation, per axis, ``H_r(s) = s^2 / (s^2 + 2 zeta_r w_r s + w_r^2)`` of ``k_r w``; the
  angle is ``H_r(s) / s`` of it (small angles: the body rates are taken as the rates of
  roll ``phi``, pitch ``theta`` and yaw ``psi``);
* tilt coordination: the low-pass ``L(s) = w_c^2 / (s^2 + 2 zeta_c w_c s + w_c^2)`` of
  ``a_x`` and ``a_y``, turned into the tilt that gravity makes felt as that force,
  ``theta = -asin(L a_x / g)``, ``phi = asin(L a_y / g)``; the tilt is limited to
  ``max_angle`` and its rate to ``rate_limit`` (about 3 deg/s, below the canals' threshold,
  Reid & Nahon 1985; Telban & Cardullo 2005), so the rider feels the force, not the rotation.

The filters are linear: a glitch in the log or a maneuver harder than their design can take
the reference out of the workspace. The limiter (:mod:`stewart.cueing.limiter`, on by
default) then scales the excursion from home smoothly, so that the reference stays inside.

The settings (:class:`WashoutParams`) come from a TOML file or from
:meth:`WashoutParams.for_platform`, which scales the translational cut-offs to the
platform's workspace. The filters are :mod:`scipy.signal` transfer functions
(:func:`filters`), simulated with :func:`scipy.signal.lsim`.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import optimize, signal

from .._modules import moved_names
from ..io import tomlfile
from ..model import reachability
from . import rotary, vestibular

__all__ = ["WashoutParams", "filters", "reference_poses", "DESIGN_ACCELERATION"]

#: The acceleration step [m/s^2] whose translational excursion the defaults fit into
#: :data:`EXCURSION_SHARE` of the workspace: hard braking, ~9 m/s^2, at the default gain 0.5.
DESIGN_ACCELERATION = 4.5
#: The share of the free stroke along one axis that the design step may use (the rest
#: is left to the other axes and to tilt).
EXCURSION_SHARE = 0.35

_SECTIONS = {
    "translation": ("gain", "cutoff", "damping", "order", "break_frequency"),
    "rotation": ("gain", "cutoff", "damping"),
    "tilt": ("cutoff", "damping", "rate_limit", "max_angle"),
    "limiter": ("enabled", "margin", "ramp_time"),
}


@dataclass(frozen=True)
class WashoutParams:
    """Washout settings. Per-axis values are ``(x, y, z)`` (translation) or ``(roll, pitch,
    yaw)`` (rotation); cut-offs in rad/s; ``tilt_rate_limit`` in rad/s and ``tilt_max_angle``
    in rad (the TOML file gives these two in degrees). ``limiter_enabled``,
    ``limiter_margin`` (a share of the excursion from home) and ``limiter_ramp_time`` [s] set
    the limiter that keeps the reference in the workspace (:mod:`stewart.cueing.limiter`)."""

    translation_gain: tuple = (0.5, 0.5, 0.5)
    translation_cutoff: tuple = (1.0, 1.0, 1.0)
    translation_damping: float = 1.0
    translation_order: int = 3
    translation_break_frequency: float = 0.2
    rotation_gain: tuple = (0.5, 0.5, 0.5)
    rotation_cutoff: tuple = (1.0, 1.0, 1.0)
    rotation_damping: float = 1.0
    tilt_cutoff: float = 1.5
    tilt_damping: float = 1.0
    tilt_rate_limit: float = vestibular.TILT_RATE_LIMIT
    tilt_max_angle: float = math.radians(10.0)
    gravity: float = 9.81
    limiter_enabled: bool = True
    limiter_margin: float = 0.1
    limiter_ramp_time: float = 1.0
    source: str = field(default="defaults", compare=False)

    def __post_init__(self):
        for name in ("translation_gain", "translation_cutoff", "rotation_gain", "rotation_cutoff"):
            value = np.broadcast_to(np.asarray(getattr(self, name), dtype=float), (3,))
            strict = "cutoff" in name
            if not np.all(np.isfinite(value)) or np.any(value <= 0 if strict else value < 0):
                raise ValueError(f"{self.source}: {name.replace('_', '.', 1)}: must be "
                                 f"{'> 0' if strict else '>= 0'}, got {value.tolist()}")
            object.__setattr__(self, name, tuple(float(v) for v in value))
        for name in ("translation_damping", "rotation_damping", "tilt_cutoff", "tilt_damping",
                     "tilt_rate_limit", "translation_break_frequency", "gravity", "limiter_ramp_time"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{self.source}: {name.replace('_', '.', 1)}: must be a number > 0, got {value!r}")
        if not isinstance(self.limiter_enabled, bool):
            raise ValueError(f"{self.source}: limiter.enabled: must be true or false, got {self.limiter_enabled!r}")
        margin = self.limiter_margin
        if not (isinstance(margin, (int, float)) and not isinstance(margin, bool) and 0 <= margin < math.inf):
            raise ValueError(f"{self.source}: limiter.margin: must be a number >= 0, got {margin!r}")
        if not (isinstance(self.tilt_max_angle, (int, float)) and 0 <= self.tilt_max_angle < math.pi / 2):
            raise ValueError(f"{self.source}: tilt.max_angle: must be in [0, 90) deg, "
                             f"got {math.degrees(self.tilt_max_angle)!r}")
        if self.translation_order not in (2, 3):
            raise ValueError(f"{self.source}: translation.order: must be 2 or 3, got {self.translation_order!r}")

    @classmethod
    def for_platform(cls, platform, **overrides) -> "WashoutParams":
        """The defaults with each translational cut-off ``w_t`` set so that a step of
        :data:`DESIGN_ACCELERATION` moves the platform at most :data:`EXCURSION_SHARE` of its
        free stroke along that axis (:func:`~stewart.model.reachability.axis_excursions`), and
        the tilt limit at half the smaller of the roll and pitch excursions (at most 10 deg)."""
        base = replace(cls(), **overrides)  # (a bad value's error names the settings' source)
        rig = rotary.rotary_rig(platform)  # (a rotary rig's excursions within its cranks' angles and reach)
        excursions = reachability.axis_excursions(platform) if rig is None else rotary.axis_excursions(rig)
        cutoffs = []
        for i in range(3):
            if "translation_cutoff" in overrides:
                break
            target = EXCURSION_SHARE * excursions[i] / max(base.translation_gain[i] * DESIGN_ACCELERATION, 1e-12)

            def excess(w, i=i):
                trial = replace(base, translation_cutoff=(w, w, w))
                return _step_peak(filters(trial)[f"position_{'xyz'[i]}"]) - target
            cutoffs.append(optimize.brentq(excess, 0.05, 50.0, xtol=1e-6))
        changes = {"source": overrides.get("source", "defaults")}
        if cutoffs:
            changes["translation_cutoff"] = tuple(cutoffs)
        if "tilt_max_angle" not in overrides:
            changes["tilt_max_angle"] = min(math.radians(10.0), 0.5 * min(excursions[3], excursions[4]))
        return replace(base, **changes)

    @classmethod
    def load(cls, path, platform=None) -> "WashoutParams":
        """Settings from a TOML file with sections ``[translation]``, ``[rotation]``, ``[tilt]``
        and ``[limiter]`` (keys as in :data:`_SECTIONS`; ``tilt.rate_limit`` in deg/s and
        ``tilt.max_angle`` in deg); what it leaves out comes from :meth:`for_platform` (or
        the plain defaults without ``platform``)."""
        path = os.fspath(path)
        overrides = {}
        for (section, key), value in tomlfile.read_sections(path, _SECTIONS).items():
            if section == "tilt" and key in ("rate_limit", "max_angle"):
                if not isinstance(value, (int, float)) or value < 0:
                    raise ValueError(f"{path}: [tilt] {key}: must be a number >= 0, got {value!r}")
                value = math.radians(value)
            overrides[f"{section}_{key}"] = value
        overrides["source"] = path
        try:
            if platform is not None:
                return cls.for_platform(platform, **overrides)
            return cls(**overrides)
        except TypeError as exc:
            raise ValueError(f"{path}: {exc}") from None

    def to_dict(self) -> dict:
        """The settings under the TOML file's section and key names (degrees for the tilt limits)."""
        out = {}
        for section, keys in _SECTIONS.items():
            out[section] = {}
            for key in keys:
                value = getattr(self, f"{section}_{key}")
                if section == "tilt" and key in ("rate_limit", "max_angle"):
                    value = math.degrees(value)
                out[section][key] = list(value) if isinstance(value, tuple) else value
        return out


def _step_peak(system) -> float:
    """The largest ``|y|`` of the unit step response of ``system`` over 60 s, every 10 ms: the
    step held between samples is exact under a zero-order hold, so the discretized filter
    (run by ``lfilter``) gives the samples of the continuous response."""
    dt, n = 0.01, 6001
    num, den, _ = signal.cont2discrete((system.num, system.den), dt, method="zoh")
    return float(np.max(np.abs(signal.lfilter(np.ravel(num), den, np.ones(n)))))


def _second_order(w: float, zeta: float) -> np.ndarray:
    return np.array([1.0, 2.0 * zeta * w, w * w])


def filters(params: WashoutParams) -> dict[str, signal.TransferFunction]:
    """The washout's linear filters: ``translation_{x,y,z}`` (acceleration high-pass),
    ``position_{x,y,z}`` (high-pass / s^2), ``rotation_{x,y,z}`` (rate high-pass),
    ``angle_{x,y,z}`` (high-pass / s) and ``tilt`` (the low-pass)."""
    out = {}
    for i, axis in enumerate("xyz"):
        den = _second_order(params.translation_cutoff[i], params.translation_damping)
        num = np.array([1.0, 0.0, 0.0])
        if params.translation_order == 3:
            den = np.polymul(den, [1.0, params.translation_break_frequency])
            num = np.array([1.0, 0.0, 0.0, 0.0])
        out[f"translation_{axis}"] = signal.TransferFunction(num, den)
        out[f"position_{axis}"] = signal.TransferFunction(num[:-2] if len(num) > 3 else [1.0], den)
        rden = _second_order(params.rotation_cutoff[i], params.rotation_damping)
        out[f"rotation_{axis}"] = signal.TransferFunction([1.0, 0.0, 0.0], rden)
        out[f"angle_{axis}"] = signal.TransferFunction([1.0, 0.0], rden)
    w = params.tilt_cutoff
    out["tilt"] = signal.TransferFunction([w * w], _second_order(w, params.tilt_damping))
    return out


def _lsim(system, t, u) -> np.ndarray:
    _, y, _ = signal.lsim(system, u, t - t[0])
    return np.asarray(y, dtype=float)


def _rate_limited(target: np.ndarray, limit: float, dt: float) -> np.ndarray:
    out = np.empty_like(target)
    out[0] = target[0]
    step = limit * dt
    for k in range(1, len(target)):
        out[k] = out[k - 1] + min(max(target[k] - out[k - 1], -step), step)
    return out


def reference_poses(log, params: WashoutParams, home) -> tuple[np.ndarray, dict]:
    """The platform poses ``(N, 6)`` the washout gives for ``log`` about the pose ``home``,
    and its parts (``translation``, ``angles`` from the high-pass, ``tilt`` (roll, pitch))."""
    t = log.t
    acc = np.asarray(params.translation_gain) * (log.f - np.array([0.0, 0.0, params.gravity]))
    rates = np.asarray(params.rotation_gain) * log.w
    fs = filters(params)
    position = np.column_stack([_lsim(fs[f"position_{a}"], t, acc[:, i]) for i, a in enumerate("xyz")])
    angles = np.column_stack([_lsim(fs[f"angle_{a}"], t, rates[:, i]) for i, a in enumerate("xyz")])
    g = params.gravity
    low = np.column_stack([_lsim(fs["tilt"], t, acc[:, i]) for i in (0, 1)])
    wanted = np.column_stack([np.arcsin(np.clip(low[:, 1] / g, -1, 1)), -np.arcsin(np.clip(low[:, 0] / g, -1, 1))])
    wanted = np.clip(wanted, -params.tilt_max_angle, params.tilt_max_angle)
    tilt = np.column_stack([_rate_limited(wanted[:, i], params.tilt_rate_limit, log.dt) for i in (0, 1)])
    pose = np.array(home, dtype=float) + np.column_stack([
        position, angles[:, 2], angles[:, 1] + tilt[:, 1], angles[:, 0] + tilt[:, 0]])
    return pose, {"translation": position, "angles": angles, "tilt": tilt}


#: Moved in 0.2.1 (from this module's old path, stewart.cueing.washout), deprecated aliases until 0.3.0.
__getattr__ = moved_names(__name__, {"axis_excursions": "stewart.model.reachability"})
