"""Kinematic calibration of a built machine: its joint centres and leg length offsets (the 42
geometric parameters of :mod:`~stewart.calibration.geometry`) from poses or points measured
by an external device (:mod:`~stewart.calibration.measurements`), by least squares on
inverse-kinematics residuals (:mod:`~stewart.calibration.fit`), with the identifiability of
the data (:mod:`~stewart.calibration.identifiability`) and measurement poses designed for
it (:mod:`~stewart.calibration.design`)."""

from .._modules import on_first_use
from .fit import Calibration, StrokeExcess, calibrate
from .identifiability import Identifiability, UnidentifiableError
from .measurements import CalibrationData, perturbed_geometry, simulate_measurements

__getattr__ = on_first_use(__name__, __path__)

__all__ = ["calibrate", "Calibration", "CalibrationData", "Identifiability", "StrokeExcess", "UnidentifiableError",
           "perturbed_geometry", "simulate_measurements"]
