"""Motion cueing: a vehicle's motion (:mod:`~stewart.cueing.log`) turned into a platform
reference that a rider perceives (:mod:`~stewart.cueing.vestibular`) as close to the
vehicle's as the platform's limits allow. The runs are in :mod:`~stewart.cueing.runners`:
:func:`washout` the classical washout (its filters in :mod:`~stewart.cueing.classical`, its
limiter in :mod:`~stewart.cueing.limiter`), :func:`mpc` model-predictive cueing within the
legs' stroke, speed and force (the receding-horizon planner :mod:`~stewart.cueing.planner`
over the prediction model of :mod:`~stewart.cueing.horizon`, with the settings of
:mod:`~stewart.cueing.settings`), :func:`simulate_reference` a reference run through the
closed loop and :func:`perceived` the vestibular model's view of a log or a platform motion;
:mod:`~stewart.cueing.metrics` compares the two, :mod:`~stewart.cueing.result` holds a run's
report and :mod:`~stewart.cueing.comparison` sets the two methods side by side.

The module paths ``stewart.cueing.washout`` (now :mod:`~stewart.cueing.classical`: the name
is the function :func:`washout`), ``stewart.cueing.prediction`` (now
:mod:`~stewart.cueing.horizon`) and ``stewart.cueing.predictive`` (now
:mod:`~stewart.cueing.planner`) are deprecated aliases of their new paths until 0.3.0."""

from __future__ import annotations

from .._modules import moved_modules, on_first_use
from .classical import WashoutParams
from .log import VehicleLog
from .log import read as read_log
from .result import CueingResult
from .runners import mpc, perceived, simulate_reference, washout
from .settings import MPCParams

__all__ = ["VehicleLog", "WashoutParams", "MPCParams", "CueingResult", "read_log", "washout", "mpc", "perceived",
           "simulate_reference"]

moved_modules(__name__, {"washout": "stewart.cueing.classical", "prediction": "stewart.cueing.horizon",
                         "predictive": "stewart.cueing.planner"})
__getattr__ = on_first_use(__name__, __path__)
