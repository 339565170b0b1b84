"""stewart: the complete dynamic model of a 6-DOF Stewart platform (Lopes & Pires 2011).

The public API: :class:`Platform` (the compiled model), :class:`PlatformParams` and its
presets, the kinematics functions, the numeric reference model :mod:`stewart.reference`,
simulation under control (:func:`simulate`, trajectories, controllers), the exact
derivatives and the model as CasADi functions for optimal control
(:mod:`stewart.casadi_functions`, :mod:`stewart.optimize`), the errors raised for inputs
where the model is undefined (:mod:`stewart.conditions`), the generated C model's files
for C programs (:func:`c_include_dir`, :func:`c_sources`, :mod:`stewart.capi`), the
platform as a standalone MuJoCo model (:func:`to_mjcf`, :mod:`stewart.mjcf`), and how
the compiled model was built and which of its instruction-set paths runs
(:func:`build_info`).
"""

from . import (capi, casadi_functions, conditions, exactness, kinematics, mjcf, newton_euler, optimize, reference,
               workspace)
from .capi import c_include_dir, c_sources
from ._kernel import build_info, set_simd
from .errors import ConvergenceError, SimdPathError, SingularityError, WrongTypeError
from .kinematics import (
    euler_jacobian,
    euler_rate_jacobian,
    forward_kinematics,
    home_pose,
    jacobian,
    leg_lengths,
    leg_unit_vectors,
    leg_vectors,
    leg_velocities,
    rotation,
    twist_transform,
)
from .mjcf import to_mjcf
from .params import NonAxisymmetricLegWarning, PlatformParams
from .platform import AllTerms, ForwardDynamicsDerivatives, InverseDynamicsDerivatives, Platform, Step, StepDerivatives
from .control import PID, Actuators, ComputedTorque, OpenLoop
from .simulation import SimulationInterrupted, SimulationResult, simulate
from .trajectory import PointToPoint, SampledTrajectory
from .presets import presets
from .workspace import WorkspaceError, reachability

__all__ = [
    "Platform",
    "AllTerms",
    "InverseDynamicsDerivatives",
    "ForwardDynamicsDerivatives",
    "Step",
    "StepDerivatives",
    "PlatformParams",
    "NonAxisymmetricLegWarning",
    "presets",
    "simulate",
    "SimulationResult",
    "SimulationInterrupted",
    "PointToPoint",
    "SampledTrajectory",
    "PID",
    "ComputedTorque",
    "OpenLoop",
    "Actuators",
    "kinematics",
    "reference",
    "newton_euler",
    "exactness",
    "SingularityError",
    "SimdPathError",
    "WrongTypeError",
    "conditions",
    "casadi_functions",
    "optimize",
    "ConvergenceError",
    "WorkspaceError",
    "workspace",
    "reachability",
    "rotation",
    "euler_rate_jacobian",
    "twist_transform",
    "leg_vectors",
    "leg_lengths",
    "leg_unit_vectors",
    "jacobian",
    "euler_jacobian",
    "leg_velocities",
    "home_pose",
    "forward_kinematics",
    "capi",
    "mjcf",
    "to_mjcf",
    "c_include_dir",
    "c_sources",
    "build_info",
    "set_simd",
]

__version__ = "0.1.0"
