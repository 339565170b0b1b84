"""Nonlinear MPC with acados on the exact model, from a ``stewart export-acados`` directory.

Runs where acados's Python interface is installed: ``make acados-env`` makes ``.venv-acados``
(Python 3.12, the PyPI package ``comma-deps-acados`` with its libraries, template renderer and
its own casadi 3.6.7, which must not replace the casadi of ``stewart optimize``). Importing
this module needs nothing of acados; its functions import it when called, with
``ACADOS_SOURCE_DIR`` pointing at the package's install directory (so acados never offers to
download its renderer).

- :func:`load` reads an export (:mod:`stewart.io.acados_export`): the step, the platform, the
  source and the compiler flags (the model's rounding flags).
- :func:`model` builds the ``AcadosModel``: state ``[x, xd]`` (12), input the six actuator
  forces, generic discrete dynamics (the generated ``rk4_step`` with its Jacobians) and the
  leg lengths as ``con_h`` (CasADi expressions, :func:`stewart.model.kinematics.leg_length_expressions`).
- :func:`tracking_ocp` builds a tracking ``AcadosOcp``: linear least squares on the state
  and on the forces' distance from the reference's inverse dynamics, force bounds, the legs'
  stroke, optional pose bounds, a horizon of ``horizon`` steps, SQP-RTI, Gauss-Newton.
- :func:`solver` generates and compiles it (``AcadosOcpSolver``) in the export's directory.
- :class:`Tracker` runs it as a controller (one RTI step a call: preparation, then feedback)
  and :func:`closed_loop` closes the loop on the package's own RK4 step
  (:meth:`stewart.Platform.rk4_step`) as the plant.
"""

from __future__ import annotations

import contextlib
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..io import acados_export
from ..model import arguments, kinematics
from ..model.params import PlatformParams
from ..model.platform import Platform

__all__ = ["Export", "Weights", "load", "template", "model", "tracking_ocp", "solver", "Tracker", "ClosedLoop",
           "closed_loop"]

NX, NU = acados_export.STATE_SIZE, acados_export.INPUT_SIZE


def template():
    """acados's Python interface (``acados_template``), ``ACADOS_SOURCE_DIR`` set to acados's
    install directory and ``ACADOS_PYTHON_INTERFACE_PATH`` to its template's when unset; :class:`ImportError` naming ``make acados-env`` without it, and
    :class:`RuntimeError` when its template renderer is missing (rather than acados's prompt to
    download one)."""
    try:
        import acados as package  # comma-deps-acados: acados.DIR is its install directory
    except ImportError:
        package = None
    if package is not None and hasattr(package, "DIR"):
        os.environ.setdefault("ACADOS_SOURCE_DIR", package.DIR)
        os.environ.setdefault("ACADOS_PYTHON_INTERFACE_PATH", package.TEMPLATE_DIR)
        _preload(package.LIB_DIR)
        from acados import acados_template as interface
    else:
        try:
            import acados_template as interface
        except ImportError:
            raise ImportError("stewart.acados needs acados's Python interface: run it in .venv-acados (make "
                              "acados-env installs comma-deps-acados on Python 3.12), see docs/realtime.md") from None
    renderer = interface.get_tera_exec_path()
    if not (os.path.isfile(renderer) and os.access(renderer, os.X_OK)):
        raise RuntimeError(f"acados's template renderer is not at {renderer} (ACADOS_SOURCE_DIR="
                           f"{os.environ.get('ACADOS_SOURCE_DIR')!r}): point ACADOS_SOURCE_DIR at acados's install "
                           "directory, which holds bin/t_renderer")
    return interface


#: acados's libraries in the order they need each other (the wheel's carry no run path).
_LIBRARIES = ("libblasfeo.so", "libhpipm.so", "libqpOASES_e.so.3.1", "libacados.so")


def _preload(directory: str) -> None:
    """Load acados's libraries from ``directory``, each by its path and global, so that the
    solvers acados builds find them (by their names) without ``LD_LIBRARY_PATH``."""
    import ctypes

    for name in _LIBRARIES:
        path = os.path.join(directory, name)
        if os.path.isfile(path):
            ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)


@dataclass(frozen=True)
class Export:
    """An export-acados directory: where it is, its platform, step and compiler flags."""

    directory: str
    params: PlatformParams
    dt: float
    integrator: str
    source: str
    functions: dict
    compile_flags: str


def load(directory: Any) -> Export:
    """Read the export in ``directory`` (written by ``stewart export-acados`` or
    :func:`stewart.io.acados_export.export`)."""
    path = Path(directory).resolve()
    settings_path = path / acados_export.SETTINGS_FILE
    if not settings_path.is_file():
        raise FileNotFoundError(f"directory: {path} holds no {acados_export.SETTINGS_FILE}; write it with "
                                "stewart export-acados DIR --preset NAME --dt DT")
    settings = json.loads(settings_path.read_text(encoding="ascii"))
    params = PlatformParams.load(path / settings["params"])
    return Export(str(path), params, float(settings["dt"]), settings["integrator"], settings["source"],
                  dict(settings["functions"]), acados_export.compile_flags(path))


def _export(export: Export | Any) -> Export:
    return export if isinstance(export, Export) else load(export)


def model(export: Export | Any, name: str = "stewart"):
    """acados's ``AcadosModel`` of the export: ``x = [pose; pose rates]`` (12), ``u`` the six
    forces [N], generic discrete dynamics from the export's C source and ``con_h_expr`` the
    six leg lengths."""
    export = _export(export)
    if not (isinstance(name, str) and name.isidentifier()):
        raise ValueError(f"name: a C identifier, got {name!r}")
    interface = template()
    import casadi

    acados_model = interface.AcadosModel()
    acados_model.name = name
    acados_model.x = casadi.SX.sym("x", NX)
    acados_model.u = casadi.SX.sym("u", NU)
    acados_model.dyn_ext_fun_type = "generic"
    acados_model.dyn_generic_source = export.source  # copied by acados from the export's directory (see solver)
    acados_model.dyn_disc_fun = export.functions["dyn_disc_fun"]
    acados_model.dyn_disc_fun_jac = export.functions["dyn_disc_fun_jac"]
    pose = [acados_model.x[k] for k in range(6)]
    acados_model.con_h_expr = casadi.vertcat(*kinematics.leg_length_expressions(export.params, pose, casadi))
    return acados_model


@dataclass(frozen=True)
class Weights:
    """The tracking cost's weights, per unit squared: the position [1/m^2], the Euler angles
    [1/rad^2], the pose rates [1/(m/s)^2, 1/(rad/s)^2] and the forces' distance from the
    reference's inverse dynamics [1/N^2]; the terminal cost weighs the state ``terminal`` times."""

    position: float = 1e6
    angle: float = 1e6
    rate: float = 1e2
    force: float = 1e-6
    terminal: float = 1.0

    def __post_init__(self):
        for name in ("position", "angle", "rate", "force", "terminal"):
            value = arguments.real(name, getattr(self, name))
            if not 0.0 <= value < np.inf:
                raise ValueError(f"{name}: a weight must be finite and >= 0, got {value}")
            object.__setattr__(self, name, value)
        if self.force <= 0:
            raise ValueError(f"force: must be > 0 (the QP's Hessian in the forces), got {self.force}")

    def stage(self) -> np.ndarray:
        return np.diag([self.position] * 3 + [self.angle] * 3 + [self.rate] * 6 + [self.force] * NU)

    def final(self) -> np.ndarray:
        return self.terminal * self.stage()[:NX, :NX]


def _limits(name: str, value, count: int) -> np.ndarray:
    limit = np.broadcast_to(arguments.reals(name, value), (count,)).astype(float)
    if not np.all(limit > 0):
        raise ValueError(f"{name}: must be > 0, got {limit.tolist()}")
    return limit


def tracking_ocp(export: Export | Any, horizon: int = 20, *, force_limit, weights: Weights | None = None,
                 stroke=True, pose_limits=None, name: str = "stewart", qp_solver: str = "PARTIAL_CONDENSING_HPIPM",
                 nlp_solver: str = "SQP_RTI", code_export_directory: str | None = None):
    """A tracking ``AcadosOcp`` over ``horizon`` steps of the export's ``dt``.

    The stage cost is ``|[x; xd; u] - yref|^2_W`` (:class:`Weights`), the terminal cost on the
    state; the references are set per step (:class:`Tracker`). ``|u_i| <= force_limit`` [N]
    (one value or one per leg) are plain bounds; ``stroke`` bounds the leg lengths (``con_h``):
    ``True`` the platform's ``leg_length_limits``, a ``(min, max)`` pair, or ``None``;
    ``pose_limits`` ``(6,)`` bounds ``|x_k - x_home|`` per pose coordinate (``None``: free).
    The solver is ``nlp_solver`` (SQP-RTI) with a Gauss-Newton Hessian and ``qp_solver``.
    """
    export = _export(export)
    horizon = arguments.count("horizon", horizon, 10_000)
    weights = Weights() if weights is None else weights
    if not isinstance(weights, Weights):
        raise TypeError(f"weights: expected a stewart.acados.Weights, got {type(weights).__name__}")
    limit = _limits("force_limit", force_limit, NU)
    interface = template()
    ocp = interface.AcadosOcp()
    ocp.model = model(export, name)
    ocp.dims.N = horizon
    ocp.solver_options.tf = horizon * export.dt
    ocp.solver_options.integrator_type = "DISCRETE"
    ocp.solver_options.nlp_solver_type = nlp_solver
    ocp.solver_options.hessian_approx = "GAUSS_NEWTON"
    ocp.solver_options.qp_solver = qp_solver
    ocp.solver_options.ext_fun_compile_flags = export.compile_flags
    ocp.code_export_directory = code_export_directory or os.path.join(export.directory, f"c_generated_code_{name}")

    ocp.cost.cost_type = "LINEAR_LS"
    ocp.cost.cost_type_e = "LINEAR_LS"
    ocp.cost.W = weights.stage()
    ocp.cost.W_e = weights.final()
    ocp.cost.Vx = np.vstack([np.eye(NX), np.zeros((NU, NX))])
    ocp.cost.Vu = np.vstack([np.zeros((NX, NU)), np.eye(NU)])
    ocp.cost.Vx_e = np.eye(NX)
    home = Platform(export.params).home_pose
    ocp.cost.yref = np.concatenate([home, np.zeros(6), np.zeros(NU)])
    ocp.cost.yref_e = np.concatenate([home, np.zeros(6)])

    ocp.constraints.x0 = np.concatenate([home, np.zeros(6)])
    ocp.constraints.idxbu = np.arange(NU)
    ocp.constraints.lbu, ocp.constraints.ubu = -limit, limit
    if stroke is True:
        stroke = export.params.leg_length_limits
    if stroke is not None:
        low, high = arguments.reals("stroke", stroke)
        if not 0 < low < high < np.inf:
            raise ValueError(f"stroke: need 0 < min < max, got ({low}, {high})")
        ocp.constraints.lh, ocp.constraints.uh = np.full(6, low), np.full(6, high)
    else:
        ocp.model.con_h_expr = None
    if pose_limits is not None:
        bound = _limits("pose_limits", pose_limits, 6)
        ocp.constraints.idxbx = np.arange(6)
        ocp.constraints.lbx, ocp.constraints.ubx = home - bound, home + bound
    return ocp


def solver(ocp, export: Export | Any, *, build: bool = True):
    """acados's ``AcadosOcpSolver`` of ``ocp``, generated and (with ``build``) compiled in
    ``ocp.code_export_directory``; acados copies the dynamics' source from the export's
    directory, so the work runs there."""
    export = _export(export)
    interface = template()
    json_file = os.path.join(ocp.code_export_directory, f"{ocp.model.name}_ocp.json")
    os.makedirs(ocp.code_export_directory, exist_ok=True)
    with contextlib.chdir(export.directory):
        return interface.AcadosOcpSolver(ocp, json_file=json_file, build=build, generate=build, verbose=False)


class Tracker:
    """One NMPC step a call on a built ``solver``: the references of the next ``horizon`` steps
    of a ``trajectory`` (``sample(t) -> (x, xd, xdd)``) with the inverse dynamics of the
    reference as the forces' reference, the measured state as the initial state, then RTI's
    preparation and feedback phases; returns the first input (the six forces)."""

    def __init__(self, ocp_solver, export: Export | Any, trajectory, horizon: int):
        self.solver = ocp_solver
        self.export = _export(export)
        self.platform = Platform(self.export.params)
        self.trajectory = trajectory
        self.horizon = horizon
        self.step_times: list[float] = []

    def reference(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """The stage references ``(horizon, 18)`` and the terminal one ``(12,)`` from ``t``."""
        times = t + self.export.dt * np.arange(self.horizon + 1)
        x, xd, xdd = self.trajectory.sample(times)
        tau = self.platform.inverse_dynamics(x, xd, xdd)
        stages = np.hstack([x, xd, tau])
        return stages[:-1], stages[-1, :NX]

    def warm_start(self, state: np.ndarray, t: float) -> None:
        """Set every node's state and input to the reference (a first guess)."""
        stages, final = self.reference(t)
        for k in range(self.horizon):
            self.solver.set(k, "x", stages[k, :NX])
            self.solver.set(k, "u", stages[k, NX:])
        self.solver.set(self.horizon, "x", final)

    def set_reference(self, t: float) -> None:
        stages, final = self.reference(t)
        for k in range(self.horizon):
            self.solver.set(k, "yref", stages[k])
        self.solver.set(self.horizon, "yref", final)

    def __call__(self, state: np.ndarray, t: float) -> np.ndarray:
        self.set_reference(t)
        started = time.perf_counter()
        self.solver.options_set("rti_phase", 1)
        self.solver.solve()
        self.solver.set(0, "lbx", state)
        self.solver.set(0, "ubx", state)
        self.solver.options_set("rti_phase", 2)
        status = self.solver.solve()
        self.step_times.append(time.perf_counter() - started)
        if status not in (0, 2):  # 2: the iteration limit, one iteration in RTI
            raise RuntimeError(f"acados: RTI step at t = {t:g} s failed with status {status}")
        return self.solver.get(0, "u")


@dataclass
class ClosedLoop:
    """A closed-loop run: times, states ``[x, xd]`` and the forces applied, the reference's
    poses, the tracking error (norms of the position [m] and Euler-angle [rad] errors) and the
    RTI steps' wall times [s]."""

    t: np.ndarray
    states: np.ndarray
    forces: np.ndarray
    reference: np.ndarray
    position_error: np.ndarray
    angle_error: np.ndarray
    step_times: np.ndarray
    force_limit: np.ndarray
    summary: dict = field(default_factory=dict)


def closed_loop(tracker: Tracker, duration: float, force_limit, *, plant_steps: int = 1, x0=None) -> ClosedLoop:
    """Run ``tracker`` for ``duration`` seconds, one NMPC step every ``dt`` of its export, on
    the plant :meth:`stewart.Platform.rk4_step` (``plant_steps`` RK4 steps per control step,
    the forces held), from ``x0`` (default: the trajectory's start at its velocity)."""
    dt = tracker.export.dt
    duration = arguments.real("duration", duration)
    steps = int(round(duration / dt))
    if not steps >= 1:
        raise ValueError(f"duration: need at least one step of {dt:g} s, got {duration}")
    plant_steps = arguments.count("plant_steps", plant_steps, 10_000)
    limit = _limits("force_limit", force_limit, NU)
    platform = tracker.platform
    if x0 is None:
        pose, rate, _ = tracker.trajectory.sample(0.0)
        x0 = np.concatenate([pose, rate])
    state = arguments.reals("x0", x0).astype(float)
    if state.shape != (NX,):
        raise ValueError(f"x0: need the state [x, xd] (12,), got shape {state.shape}")
    tracker.warm_start(state, 0.0)
    t = dt * np.arange(steps + 1)
    states, forces = np.empty((steps + 1, NX)), np.empty((steps, NU))
    states[0] = state
    for k in range(steps):
        forces[k] = tracker(states[k], t[k])
        x, xd = states[k, :6], states[k, 6:]
        for _ in range(plant_steps):
            x, xd = platform.rk4_step(x, xd, forces[k], dt / plant_steps)
        states[k + 1] = np.concatenate([x, xd])
    reference = tracker.trajectory.sample(t)[0]
    position_error = np.linalg.norm(states[:, :3] - reference[:, :3], axis=1)
    angle_error = np.linalg.norm(states[:, 3:6] - reference[:, 3:], axis=1)
    step_times = np.asarray(tracker.step_times[-steps:])
    summary = {"steps": steps, "dt": dt, "max_position_error": float(position_error.max()),
               "max_angle_error": float(angle_error.max()), "rms_position_error": float(np.sqrt(np.mean(position_error ** 2))),
               "final_position_error": float(position_error[-1]), "final_angle_error": float(angle_error[-1]),
               "max_force_ratio": float(np.max(np.abs(forces) / limit)),
               "median_rti_step": float(np.median(step_times))}
    return ClosedLoop(t, states, forces, reference, position_error, angle_error, step_times, limit, summary)
