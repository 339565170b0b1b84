"""Shared fixtures. ``figures`` records the figure each check reached; they are printed
in a table at the end of the run (docs/checks.md quotes it). The figures travel on the test
reports (``user_properties``), so the table is complete when pytest-xdist runs the tests
in worker processes too."""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest
from hypothesis import settings as hypothesis_settings

import stewart
from stewart.oracles.physics import random_states  # noqa: F401  (re-exported for the tests)

# The property tests draw the same examples on every run (derandomized, no example database
# carried between runs), so that a run is reproducible; STEWART_HYPOTHESIS=explore draws them
# at random for a wider search (a failure prints the example to reproduce it).
hypothesis_settings.register_profile("repeatable", derandomize=True, database=None)
hypothesis_settings.register_profile("explore", derandomize=False, print_blob=True)
hypothesis_settings.load_profile(os.environ.get("STEWART_HYPOTHESIS", "repeatable"))

#: The acados tests (tests/acados/) run in acados's own environment, by make test-acados, which
#: sets STEWART_ACADOS_TESTS: make test's environment has no acados (docs/realtime.md, "Nonlinear MPC with acados").
collect_ignore = [] if os.environ.get("STEWART_ACADOS_TESTS") else ["acados"]


def pytest_configure(config):
    """In a pytest-xdist worker, BLAS (OpenBLAS, numpy's and scipy's) runs on the worker's share
    of the cores, and so do the interpreters its tests start (``OPENBLAS_NUM_THREADS``, unless
    set): with every worker's BLAS on every core, their threads spin against each other on the
    small matrices of the tests (the identification, calibration and derivative tests take half
    as long again). The kernel's own threads are each Platform's ``threads``, as always."""
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    if workers > 1 and "OPENBLAS_NUM_THREADS" not in os.environ:
        from threadpoolctl import threadpool_limits

        share = max(1, (os.cpu_count() or 1) // workers)
        os.environ["OPENBLAS_NUM_THREADS"] = str(share)
        threadpool_limits(share, user_api="blas")


_FIGURES: list[tuple[str, float, float]] = []
_FIGURE = "figure"


@pytest.fixture
def figures(request):
    """``figures(name, value, bound)``: record a check's worst figure and assert it is finite and
    within bound. The worst of several errors is taken with ``np.maximum`` or ``np.max``, which
    keep a NaN, never Python's ``max`` (``max(0.0, nan)`` is 0.0, so a NaN error would pass).

    A bound is a few tens of times (at most about 100) the worst figure its check reaches on
    every path the suite runs (``STEWART_SIMD`` baseline, avx2, avx512), the figure in the
    comment beside it (``# reached ...``), so that a wrong term fails; where it must be looser
    (a solver's or an integrator's tolerance, a statistical test, a claimed margin) the test
    says why."""

    def record(name: str, value: float, bound: float) -> None:
        request.node.user_properties.append((_FIGURE, (name, float(value), float(bound))))
        assert np.isfinite(value), f"{name}: {value} is not finite"
        assert value <= bound, f"{name}: {value:.3e} exceeds {bound:.1e}"

    return record


def pytest_runtest_logreport(report):
    if report.when == "call":
        _FIGURES.extend(tuple(value) for key, value in report.user_properties if key == _FIGURE)


def pytest_terminal_summary(terminalreporter):
    skipped = terminalreporter.stats.get("skipped", [])
    if skipped:
        terminalreporter.section("checks not run (skipped), by reason", yellow=True, bold=True)
        reasons: dict[str, list[str]] = {}
        for report in skipped:
            reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
            reasons.setdefault(reason.removeprefix("Skipped: "), []).append(report.nodeid)
        for reason, nodes in sorted(reasons.items()):
            terminalreporter.write_line(f"{len(nodes):4d}  {reason}  (e.g. {nodes[0]})", yellow=True)
    if not _FIGURES:
        return
    terminalreporter.section("figures reached (worst case per check)")
    width = max(len(name) for name, _, _ in _FIGURES)
    for name, value, bound in sorted(_FIGURES):
        terminalreporter.write_line(f"{name:<{width}}  {value:10.3e}  (bound {bound:.0e})")


#: The tests that must share one worker process (pytest-xdist, ``--dist loadgroup`` in the
#: pyproject's addopts), by the start of ``<file>::<test>`` (or a tuple of such starts, one
#: group): those of a file whose tests share a costly result computed once per process (a
#: module-scoped fixture, a cache), and the commands of the README and the docs, which run in
#: order in one directory. Every other test goes on its own to whichever worker is free.
XDIST_GROUPS = {
    "test_generated.py": "one generator run, which every file's freshness check reads",
    "test_derivatives.py": "the complex-step oracle of each case, computed once",
    "test_excitation.py": "one small excitation design",
    "test_optimize.py": "one IPOPT solve of the seed paper's move",
    "test_packaging.py": "one copy of the source files and one sdist",
    "test_build.py": "the baseline path's results, computed once in a subprocess",
    "test_bitwise.py": "the results of the path that runs everywhere, computed once",
    "test_readme.py::test_readme_command_runs": "a shell session: a command reads what an earlier one wrote",
    ("test_cueing_mpc.py::test_closed_loop_stays_within_limits",
     "test_cueing_mpc.py::test_mpc_beats_washout",
     "test_cueing_mpc.py::test_comparison_figure"): "MPC on each shipped maneuver, planned once",
}


def xdist_group(nodeid: str) -> str | None:
    """The group of :data:`XDIST_GROUPS` the test ``nodeid`` belongs to, or None."""
    path, _, name = nodeid.partition("::")
    key = f"{path.rsplit('/', 1)[-1]}::{name}"
    return next((str(prefix) for prefix in XDIST_GROUPS if key.startswith(prefix)), None)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadgroup`` with the groups of :data:`XDIST_GROUPS`, each a unit of work, and
    every other test a unit of its own. (pytest-xdist's own loadgroup reads ``xdist_group``
    marks through node ids it rewrites, which pytest 9.2 no longer lets it do: it then
    distributes every test on its own, pytest-xdist issue #1386.)"""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class GroupScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return xdist_group(nodeid) or nodeid

    return GroupScheduling(config, log)


PRESETS = sorted(stewart.presets())


@pytest.fixture
def conversions(monkeypatch):
    """``count = conversions("stewart.motion")``: from then on, ``count`` (a Counter) holds the
    calls of the platform converters (:func:`~stewart.model.platform.as_platform`,
    :func:`~stewart.model.params.platform_params`) made by each module of that package, by
    module name, and under ``"compiled"`` the :class:`~stewart.Platform` objects built (a
    ``PlatformParams`` compiled), wherever they are built."""
    import collections
    import sys

    from stewart.model import params as params_module
    from stewart.model import platform as platform_module

    converters = {"as_platform": platform_module.as_platform, "platform_params": params_module.platform_params}
    count = collections.Counter()

    def counting(converter, module_name):
        def convert(*args, **kwargs):
            count[module_name] += 1
            return converter(*args, **kwargs)
        return convert

    build = platform_module.Platform.__init__

    def compiling(self, *args, **kwargs):
        count["compiled"] += 1
        build(self, *args, **kwargs)

    def within(package: str) -> collections.Counter:
        for module_name, module in list(sys.modules.items()):
            if module_name == package or module_name.startswith(package + "."):
                for name, converter in converters.items():
                    if vars(module).get(name) is converter:
                        monkeypatch.setattr(module, name, counting(converter, module_name))
        monkeypatch.setattr(platform_module.Platform, "__init__", compiling)
        return count

    return within


@pytest.fixture(params=PRESETS)
def preset_params(request):
    return stewart.PlatformParams.preset(request.param)


@pytest.fixture(params=PRESETS + [f"random-{k}" for k in range(3)])
def any_params(request):
    """Every preset, and random axisymmetric parameter sets (:func:`random_params`)."""
    if request.param.startswith("random-"):
        params = random_params(np.random.default_rng(300 + int(request.param.split("-")[1])))
        return params.replace(name=request.param)
    return stewart.PlatformParams.preset(request.param)


@pytest.fixture(params=PRESETS + ["random-0"])
def general_params(request):
    """Every preset and a random parameter set made general (:func:`make_general`)."""
    rng = np.random.default_rng(500)
    if request.param.startswith("random-"):
        return make_general(random_params(rng).replace(name=request.param), rng)
    return make_general(stewart.PlatformParams.preset(request.param), rng)


def make_general(params, rng):
    """``params`` with the general model's every feature: universal joints whose first axes are
    the default tangential ones tilted by up to 0.5 rad about the radial direction,
    non-axisymmetric leg inertias (I_yy, I_zz the paper's transverse moment -+ 0.4 times the
    axial one, within the triangle inequality), and a payload of a third of the platform's mass off-centre by a tenth of the
    platform's size with a full inertia tensor."""
    joints = params.with_universal_joints()
    radial = np.cross(joints.universal_joint_axes, [0.0, 0.0, 1.0])
    tilt = rng.uniform(-0.5, 0.5, size=(6, 1))
    axes = np.cos(tilt) * joints.universal_joint_axes + np.sin(tilt) * np.cross(radial, joints.universal_joint_axes)
    size = np.max(np.linalg.norm(params.platform_points, axis=1))
    mass = params.platform_mass / 3.0
    spin = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    tensor = spin @ np.diag(mass * size**2 * np.array([0.05, 0.07, 0.1])) @ spin.T

    def leg(inertia):
        return (inertia[0], inertia[1] - 0.4 * inertia[0], inertia[1] + 0.4 * inertia[0])

    return joints.replace(
        universal_joint_axes=axes / np.linalg.norm(axes, axis=1, keepdims=True),
        cylinder_inertia=leg(params.cylinder_inertia), piston_inertia=leg(params.piston_inertia),
    ).with_payload(mass, rng.normal(size=3) * 0.1 * size, tensor)


def random_params(rng, axisymmetric=True):
    """A random, physically valid parameter set (a hexapod of random size and masses)."""
    radius = rng.uniform(0.1, 2.0)
    base_angles = np.radians(np.array([0, 120, 240])[:, None] + np.array([-1, 1]) * rng.uniform(5, 25)).ravel()
    top_angles = np.radians(np.array([60, 180, 300])[:, None] + np.array([-1, 1]) * rng.uniform(5, 25)).ravel()
    top_angles = np.roll(top_angles, 1)
    base = np.column_stack([np.cos(base_angles), np.sin(base_angles), np.zeros(6)]) * radius
    top_r = radius * rng.uniform(0.5, 0.9)
    top = np.column_stack([np.cos(top_angles), np.sin(top_angles), np.zeros(6)]) * top_r
    base += rng.normal(scale=0.02 * radius, size=(6, 3))
    top += rng.normal(scale=0.02 * radius, size=(6, 3))
    leg = radius * rng.uniform(0.8, 1.5)

    def body_inertia(mass, size):
        a, b = rng.uniform(0.3, 1.0, size=2) * size
        i1 = mass * (a * a + b * b) / 12
        i2 = mass * (a * a + b * b) / 12 if axisymmetric else mass * (a * a + 0.5 * b * b) / 12
        return (mass * b * b / 8, i1, i2)

    m_p = rng.uniform(1, 1000) * radius**3
    m_c, m_s = (rng.uniform(0.02, 0.3) * m_p for _ in range(2))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        return stewart.PlatformParams(
            base_points=base,
            platform_points=top,
            platform_mass=m_p,
            platform_inertia=(m_p * top_r**2 / 4, m_p * top_r**2 / 3, m_p * top_r**2 / 2),
            cylinder_mass=m_c,
            cylinder_inertia=body_inertia(m_c, 0.5 * leg),
            cylinder_com_distance=rng.uniform(0.1, 0.5) * leg,
            piston_mass=m_s,
            piston_inertia=body_inertia(m_s, 0.5 * leg),
            piston_com_distance=rng.uniform(0.1, 0.5) * leg,
            gravity=9.81,
            leg_length_limits=(0.7 * leg, 1.3 * leg),
            name="random",
        )


#: Every array-taking method of :class:`stewart.Platform`, with its state arguments' names.
PLATFORM_METHODS = {
    "leg_lengths": ("x",),
    "jacobian": ("x",),
    "leg_rates": ("x", "xd"),
    "leg_accelerations": ("x", "xd", "xdd"),
    "mass_matrix": ("x",),
    "twist_mass_matrix": ("x",),
    "gravity_vector": ("x",),
    "coriolis_matrix": ("x", "xd"),
    "coriolis_vector": ("x", "xd"),
    "all_terms": ("x", "xd"),
    "inverse_dynamics": ("x", "xd", "xdd"),
    "forward_dynamics": ("x", "xd", "tau"),
    "inverse_dynamics_derivatives": ("x", "xd", "xdd"),
    "static_force_derivatives": ("x",),
    "forward_dynamics_derivatives": ("x", "xd", "tau"),
    "joint_reactions": ("x", "xd", "xdd"),
    "forward_kinematics": ("lengths", "guess"),
    "leg_residuals": ("x", "readings"),
    "leg_residual_jacobians": ("x",),
    "target_positions": ("x", "offsets"),
    "target_jacobian": ("x", "offsets"),
    "rotation": ("x",),
    "euler_rate_jacobian": ("x",),
    "inverse_euler_rate_jacobian": ("x",),
    "leg_vectors": ("x",),
    "leg_unit_vectors": ("x",),
    "modal_stiffness": ("x", "k"),
    "joint_cosines": ("x",),
    "rider_signals": ("x", "xd", "xdd"),
}


def valid_arguments(plat, n=None, seed=0):
    """Valid arguments for every name in :data:`PLATFORM_METHODS`: one state, or ``n`` states."""
    rng = np.random.default_rng(seed)
    x, xd, xdd = random_states(plat.params, 1 if n is None else n, rng)
    if n is None:
        x, xd, xdd = x[0], xd[0], xdd[0]
    return {
        "x": x,
        "xd": xd,
        "xdd": xdd,
        "tau": plat.inverse_dynamics(x, xd, xdd),
        "lengths": plat.leg_lengths(x),
        "guess": x + 1e-3,
        "readings": plat.encoder_readings(x) + 1e-6,
        "offsets": np.full(np.shape(x)[:-1] + (3,), 0.02),
        "k": np.linspace(1e6, 2e6, 6),
    }


def _unaligned(a: np.ndarray) -> np.ndarray:
    raw = np.zeros(a.nbytes + 1, dtype=np.uint8)[1:]
    out = raw.view(a.dtype).reshape(a.shape)
    out[...] = a
    assert not out.flags.aligned or a.size == 0
    return out


def _strided(a: np.ndarray) -> np.ndarray:
    wide = np.zeros(a.shape[:-1] + (2 * a.shape[-1],), dtype=a.dtype)
    wide[..., ::2] = a
    return wide[..., ::2]


def _read_only(a: np.ndarray) -> np.ndarray:
    out = a.copy()
    out.flags.writeable = False
    return out


#: The same float64 values in other memory layouts, which every function must read as
#: the plain C-contiguous array.
LAYOUTS = {
    "big-endian": lambda a: a.astype(">f8"),
    "big-endian unaligned": lambda a: _unaligned(a.astype(">f8")),
    "unaligned": _unaligned,
    "strided": _strided,
    "reversed view": lambda a: np.flip(np.flip(a, -1).copy(), -1),
    "Fortran order": np.asfortranarray,
    "read-only": _read_only,
    "nested lists": lambda a: a.tolist(),
}


@pytest.fixture(params=stewart.build_info()["supported"])
def simd_path(request):
    """Every instruction-set path this CPU runs, in turn: the kernel runs on it during the test
    (:func:`stewart.set_simd`)."""
    previous = stewart.set_simd(request.param)
    yield request.param
    stewart.set_simd(previous)


def inertial_step(params, k: int, step: float, forces):
    """``forces`` of ``params`` with inertial parameter ``k`` (of ``inertial_vector``) moved
    by ``step``, or by ``-step`` where ``step`` leaves the body unphysical: ``(forces,
    signed step)``. One leg moment changed alone makes the legs non-axisymmetric: that
    warning is silenced."""
    for signed in (step, -step):
        changed = params.inertial_vector()
        changed[k] += signed
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
                return forces(params.with_inertial_vector(changed)), signed
        except ValueError:
            continue
    raise AssertionError(f"inertial parameter {k}: neither +-{step:g} keeps the body physical")
