"""How close a platform's perceived motion is to a vehicle's, per channel
(``fx, fy, fz`` [m/s^2], ``wx, wy, wz`` [rad/s], :data:`~stewart.cueing.vestibular.CHANNELS`):

* ``perceived_error_rms``: RMS of perceived platform minus perceived vehicle;
* ``correlation``: Pearson's coefficient of the two (None where either is constant);
* ``delay_s``: the lag of the platform's signal that maximizes the cross-correlation,
  within +-2 s (positive: the platform comes late);
* ``false_cue_s``: how long the platform's perceived signal is above the perception
  threshold (:data:`~stewart.cueing.vestibular.THRESHOLDS`) while the vehicle's is below it,
  or the two have opposite signs.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from .vestibular import CHANNELS, THRESHOLDS, Perceived

__all__ = ["compare", "MAX_DELAY"]

#: The largest lag searched for ``delay_s`` [s].
MAX_DELAY = 2.0


def _delay(a: np.ndarray, b: np.ndarray, dt: float) -> float | None:
    a, b = a - a.mean(), b - b.mean()
    if not (np.any(a) and np.any(b)):
        return None
    xc = signal.correlate(b, a, mode="full")
    lags = signal.correlation_lags(len(b), len(a), mode="full")
    keep = np.abs(lags) * dt <= MAX_DELAY
    return float(lags[keep][np.argmax(xc[keep])] * dt)


def compare(vehicle: Perceived, platform: Perceived) -> dict[str, dict[str, float | None]]:
    """The metrics of the module docstring: ``{metric: {channel: value}}``."""
    v, p = vehicle.channels, platform.channels
    t = vehicle.t
    dt = float(t[1] - t[0])
    out = {"perceived_error_rms": {}, "correlation": {}, "delay_s": {}, "false_cue_s": {}}
    for j, name in enumerate(CHANNELS):
        a, b = v[:, j], p[:, j]
        out["perceived_error_rms"][name] = float(np.sqrt(np.mean((b - a) ** 2)))
        corr = None
        if np.std(a) > 0 and np.std(b) > 0:
            corr = float(np.corrcoef(a, b)[0, 1])
        out["correlation"][name] = corr
        out["delay_s"][name] = _delay(a, b, dt)
        th = THRESHOLDS[name]
        if name == "fz":  # about 1 g: the cue is the change from rest
            a, b = a - a[0], b - b[0]
        false = (np.abs(b) > th) & ((np.abs(a) <= th) | (np.sign(a) == -np.sign(b)))
        out["false_cue_s"][name] = float(np.count_nonzero(false) * dt)
    return out
