"""stewart: the complete dynamic model of a 6-DOF Stewart platform (Lopes & Pires 2011).

The public API: :class:`Platform` (the compiled model), :class:`PlatformParams` and its
presets, the kinematics functions, the numeric reference model :mod:`stewart.oracles.reference`,
simulation under control (:func:`simulate`, trajectories, controllers), the exact
derivatives and the model as CasADi functions for optimal control
(:mod:`stewart.motion.casadi_functions`, :mod:`stewart.motion.optimize`), the errors raised for inputs
where the model is undefined (:mod:`stewart.model.conditions`), the generated C model's files
for C programs (:func:`c_include_dir`, :func:`c_sources`, :mod:`stewart.io.capi`), the
platform as a standalone MuJoCo model (:func:`to_mjcf`, :mod:`stewart.io.mjcf`), and how
the compiled model was built and which of its instruction-set paths runs
(:func:`build_info`).

The package is organised by job: :mod:`stewart.model` (parameters, kinematics, the
:class:`Platform` facade, reachability), :mod:`stewart.motion` (trajectories, control,
simulation, optimization), :mod:`stewart.identification`, :mod:`stewart.calibration`
(the geometry of a built machine), :mod:`stewart.studies`
(workspaces, envelopes, sweeps), :mod:`stewart.io` (files, plots, the C export, MuJoCo),
:mod:`stewart.oracles` (the independent models and checks the tests use) and
:mod:`stewart.cli`. The names below are imported on first use, so that ``import stewart``
is fast and :mod:`stewart.model`'s data model imports without the compiled extension.

**The namespace's rule.** The top level holds the public functions, classes and errors and
the sub-packages, nothing else; a module is reached through its sub-package (``from
stewart.studies import envelope``, or ``stewart.studies.envelope`` after ``import stewart``:
each sub-package imports its modules on first use). The flat module paths of 0.1.0
(:data:`MOVED`) are deprecated aliases of their new paths until 0.3.0. A public name that
changes goes through the same deprecation, recorded in CHANGELOG.md.
"""

import ast
import importlib
from typing import TYPE_CHECKING

from ._modules import moved_module, moved_modules

__version__ = "0.2.0"

if TYPE_CHECKING:  # the public names: what `__getattr__` imports on first use
    from . import calibration, cueing, identification, io, model, motion, oracles, studies
    from .io.capi import c_include_dir, c_sources
    from .model.compiled import build_info, set_simd
    from .model.errors import ConvergenceError, SimdPathError, SingularityError, UnstableError, WrongTypeError
    from .model.kinematics import (
        encoder_readings,
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
    from .io.mjcf import to_mjcf
    from .model.params import NonAxisymmetricLegWarning, PlatformParams
    from .model.platform import (
        AllTerms,
        EulerRateJacobianPartials,
        ForwardDynamicsDerivatives,
        InverseDynamicsDerivatives,
        JointCosines,
        LegResidualJacobians,
        LegUnitVectors,
        ModalStiffness,
        Platform,
        RiderSignals,
        RotationPartials,
        StaticForceDerivatives,
        Step,
        StepDerivatives,
    )
    from .motion.control import PID, Actuators, ComputedTorque, OpenLoop
    from .motion.simulation import SimulationInterrupted, SimulationResult, simulate
    from .motion.trajectory import PointToPoint, SampledTrajectory
    from .model.presets import presets
    from .model.rotary import RotaryPlatform
    from .model.rotary_params import RotaryParams
    from .model.stiffness import Modes
    from .model.reachability import WorkspaceError, reachability


def _public_names() -> dict[str, tuple[str, str]]:
    """{public name: (module, attribute)} from the imports under ``TYPE_CHECKING`` above."""
    with open(__file__, encoding="utf-8") as f:
        tree = ast.parse(f.read())
    block = next(node for node in tree.body if isinstance(node, ast.If) and getattr(node.test, "id", "") == "TYPE_CHECKING")
    return {alias.asname or alias.name: (f"{__name__}.{node.module}" if node.module else __name__, alias.name)
            for node in block.body for alias in node.names}


_PUBLIC = _public_names()
__all__ = list(_PUBLIC)


#: The module paths of 0.1.0 that 0.2.0 moved into the sub-packages: deprecated aliases of
#: their new paths until 0.3.0 (``import stewart.envelope`` and ``stewart.envelope`` work,
#: with a ``DeprecationWarning`` naming the new path; :mod:`stewart._modules` holds the
#: mechanism, which the sub-packages' moved paths share).
MOVED = {
    **{name: f"stewart.model.{name}" for name in ("conditions", "errors", "kinematics", "paramfile", "params",
                                                   "platform", "stiffness")},
    **{name: f"stewart.motion.{name}" for name in ("casadi_functions", "control", "optimize", "simulation",
                                                    "trajectory")},
    **{name: f"stewart.identification.{name}" for name in ("base_parameters", "excitation", "identify")},
    **{name: f"stewart.io.{name}" for name in ("capi", "csvfile", "mjcf", "plots")},
    **{name: f"stewart.oracles.{name}" for name in ("exactness", "newton_euler", "reference", "validation")},
    "checks": "stewart.oracles.physics",
    **{name: f"stewart.studies.{name}" for name in ("envelope", "execution", "sweep", "workspace")},
}


moved_modules(__name__, MOVED, since="0.2.0")


def __getattr__(name: str):
    """Import a public name on first use (a function, class or sub-package of the package)."""
    if name in MOVED:
        return moved_module(f"{__name__}.{name}", 2)
    if name not in _PUBLIC:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module, attribute = _PUBLIC[name]
    if module == __name__:  # a sub-package of this one
        value = importlib.import_module(f"{module}.{attribute}")
    else:
        parent = importlib.import_module(module)
        value = getattr(parent, attribute) if hasattr(parent, attribute) else importlib.import_module(f"{module}.{attribute}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
