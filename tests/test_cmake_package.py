"""The CMake and pkg-config package ``stewart c-export`` writes (stewart/io/cmake.py), and the C++
example controller built on it (examples/cpp_controller).

make test checks the files and that a consumer's ``find_package(stewart CONFIG)`` configures
(seconds); the tests marked ``control`` (make test-control, which CI runs) build, install and
link the library with gcc and with clang, and run the example controller: its forces equal
:meth:`stewart.Platform.inverse_dynamics` and its loop equals :func:`stewart.simulate` under
:class:`~stewart.motion.control.ComputedTorque`, bit for bit, and it allocates nothing in its loop.
"""

from __future__ import annotations

import dataclasses
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import stewart
from stewart.io import capi, cmake
from stewart.model.kinematics import home_pose
from stewart.model.platform import friction_law
from stewart.motion.control import Actuators, ComputedTorque
from stewart.motion.trajectory import PointToPoint

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "cpp_controller"
CONSUMER = """\
cmake_minimum_required(VERSION 3.16)
project(consumer LANGUAGES C)
find_package(stewart {version} CONFIG REQUIRED)
add_executable(consumer {example})
target_link_libraries(consumer PRIVATE stewart::stewart)
add_executable(consumer_shared {example})
target_link_libraries(consumer_shared PRIVATE stewart::shared)
get_target_property(includes stewart::stewart INTERFACE_INCLUDE_DIRECTORIES)
message(STATUS "stewart includes: ${{includes}}")
message(STATUS "stewart rounding: ${{stewart_ROUNDING_FLAGS}}")
"""
C_EXAMPLE = ROOT / "examples" / "c" / "inverse_dynamics.c"
#: (C compiler, C++ compiler) of the build matrix.
COMPILERS = {"gcc": ("gcc", "g++"), "clang": ("clang", "clang++")}
#: The seed paper's move (the docs' simulation, make docs): from home to this pose in 5 s.
TARGET = [0.04565, -0.0102, 0.192, -0.0863, 0.1046, 0.0960]


def _params() -> stewart.PlatformParams:
    """The seed paper's platform with leg friction, which the controller adds back."""
    return dataclasses.replace(stewart.PlatformParams.preset("narayan2017"), viscous_friction=np.full(6, 40.0),
                               coulomb_friction=np.linspace(1.0, 3.5, 6), coulomb_velocity=0.01)


def _cmake(*args, env=None, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run(["cmake", *map(str, args)], capture_output=True, text=True, env=env, cwd=cwd)


def _consumer(directory: Path, version: str = stewart.__version__) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "CMakeLists.txt").write_text(CONSUMER.format(version=version, example=C_EXAMPLE.as_posix()))
    return directory


def test_export_writes_the_package_files(tmp_path):
    params = stewart.PlatformParams.preset("narayan2017")
    written = capi.export(tmp_path, params)
    names = [Path(p).name for p in written]
    assert names[-6:] == [cmake.PROJECT, cmake.TARGETS, cmake.CONFIG, cmake.CONFIG_VERSION, cmake.PKG_CONFIG,
                          cmake.VERSION_SCRIPT]
    assert f"project(stewart VERSION {stewart.__version__} LANGUAGES C)" in (tmp_path / cmake.PROJECT).read_text()
    assert f'set(PACKAGE_VERSION "{stewart.__version__}")' in (tmp_path / cmake.CONFIG_VERSION).read_text()
    assert f"Version: {stewart.__version__}\n" in (tmp_path / cmake.PKG_CONFIG).read_text()
    # The version script exports exactly the functions the header declares, by an independent
    # count: every "stewart_name(" in the header that is not a macro or in a comment.
    header = (tmp_path / capi.HEADER).read_text()
    code = re.sub(r"/\*.*?\*/", "", header, flags=re.S)
    declared = set(re.findall(r"\b(stewart_\w+)\s*\(", "\n".join(l for l in code.splitlines()
                                                                 if not l.startswith("#"))))
    script = (tmp_path / cmake.VERSION_SCRIPT).read_text()
    exported = set(re.findall(r"^    (\w+);$", script, flags=re.M))
    assert exported == declared and "stewart_inverse_dynamics" in exported and len(exported) > 70
    assert "local:\n    *;" in script


def test_public_functions_refuses_a_header_without_functions():
    with pytest.raises(ValueError, match="declares no stewart_"):
        cmake.package_files("1.2.3", "/* nothing */\n#define STEWART_X 1\n")
    assert cmake.public_functions("int stewart_a(void);\nconst char *stewart_b(int s);\ntypedef int (*stewart_c)(int);\n"
                                  "#define stewart_d(x) x\n") == ["stewart_a", "stewart_b"]


@pytest.mark.slow
def test_consumer_finds_the_exported_package(tmp_path):
    """find_package(stewart CONFIG) with stewart_DIR at the exported directory configures, with
    the include path and the rounding flags; a newer version asked for is refused."""
    capi.export(tmp_path / "exp", stewart.PlatformParams.preset("narayan2017"))
    consumer = _consumer(tmp_path / "consumer")
    done = _cmake("-S", consumer, "-B", tmp_path / "b", f"-Dstewart_DIR={tmp_path / 'exp'}", "-DSTEWART_MARCH=none")
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"stewart includes: $<BUILD_INTERFACE:{tmp_path / 'exp'}>" in done.stdout
    assert "stewart rounding: -ffp-contract=off;-fno-tree-slp-vectorize" in done.stdout
    major, minor, _ = stewart.__version__.split(".")
    newer = _consumer(tmp_path / "newer", f"{major}.{int(minor) + 1}")
    done = _cmake("-S", newer, "-B", tmp_path / "nb", f"-Dstewart_DIR={tmp_path / 'exp'}")
    assert done.returncode != 0 and f"version: {stewart.__version__}" in done.stderr
    assert "The version found is not compatible with the version requested" in done.stderr


# ---- make test-control: the builds ----------------------------------------------------------

def _compilers(name: str) -> dict[str, str]:
    cc, cxx = COMPILERS[name]
    missing = [tool for tool in (cc, cxx, "cmake", "pkg-config") if shutil.which(tool) is None]
    assert not missing, f"{missing} not found: make test-control installs them (apt-get)"
    return dict(os.environ, CC=cc, CXX=cxx)


@pytest.fixture(scope="module", params=sorted(COMPILERS))
def installed(request, tmp_path_factory):
    """The exported package of :func:`_params`, built by the compiler and installed:
    (export directory, prefix, environment with CC and CXX)."""
    env = _compilers(request.param)
    root = tmp_path_factory.mktemp(f"package-{request.param}")
    capi.export(root / "exp", _params())
    for command in (["-S", root / "exp", "-B", root / "build", "-DCMAKE_BUILD_TYPE=Release"],
                    ["--build", root / "build", "-j", str(os.cpu_count() or 1)],
                    ["--install", root / "build", "--prefix", root / "prefix"]):
        done = _cmake(*command, env=env)
        assert done.returncode == 0, f"cmake {command}: {done.stdout[-3000:]}{done.stderr[-3000:]}"
    return root / "exp", root / "prefix", env


def _output(command, env=None) -> str:
    done = subprocess.run([str(c) for c in command], capture_output=True, text=True, env=env)
    assert done.returncode == 0, f"{command}: exit {done.returncode}\n{done.stdout}{done.stderr}"
    return done.stdout


def _printed(output: str) -> dict[str, np.ndarray]:
    return {name: np.array(values, dtype=float) for name, *values in (line.split() for line in output.splitlines())}


@pytest.mark.control
def test_installed_library_links_from_cmake_and_pkg_config(installed, tmp_path):
    exp, prefix, env = installed
    lib = prefix / "lib"
    version = stewart.__version__
    shared = lib / f"libstewart.so.{version}"
    assert shared.is_file() and (lib / "libstewart.a").is_file()
    assert os.readlink(lib / "libstewart.so") == f"libstewart.so.{version.rsplit('.', 1)[0]}"
    assert sorted(p.name for p in (prefix / "include" / "stewart").iterdir()) == [capi.HEADER, capi.PARAMS_HEADER]
    # Only the header's functions leave the shared library.
    symbols = _output(["nm", "-D", "--defined-only", shared]).split()
    exported = {s for s in symbols[2::3]}
    assert exported == set(cmake.public_functions((exp / capi.HEADER).read_text()))
    soname = _output(["readelf", "-d", shared])
    assert f"Library soname: [libstewart.so.{version.rsplit('.', 1)[0]}]" in soname

    consumer = _consumer(tmp_path / "consumer")
    for command in (["-S", consumer, "-B", tmp_path / "b", f"-DCMAKE_PREFIX_PATH={prefix}"], ["--build", tmp_path / "b"]):
        done = _cmake(*command, env=env)
        assert done.returncode == 0, done.stdout + done.stderr
    # The shared library found through the build tree's run path, then (pkg-config) the run-time
    # linker's path.
    runs = [_output([tmp_path / "b" / "consumer"]), _output([tmp_path / "b" / "consumer_shared"])]
    assert "libstewart.so" in _output(["ldd", tmp_path / "b" / "consumer_shared"])
    pkg_env = dict(env, PKG_CONFIG_PATH=str(lib / "pkgconfig"))
    flags = _output(["pkg-config", "--cflags", "--libs", "stewart"], pkg_env).split()
    assert [flag[:2] for flag in flags] == ["-I", "-L", "-l"] and flags[2] == "-lstewart"
    assert Path(flags[0][2:]).resolve() == prefix / "include" / "stewart" and Path(flags[1][2:]).resolve() == lib
    assert _output(["pkg-config", "--modversion", "stewart"], pkg_env).strip() == version
    _output([env["CC"], "-std=c99", C_EXAMPLE, *flags, "-o", tmp_path / "pc_example"])
    runs.append(_output([tmp_path / "pc_example"], dict(env, LD_LIBRARY_PATH=str(lib))))
    for output in runs:
        printed = _printed(output)
        want = stewart.Platform(_params()).inverse_dynamics(printed["x"], printed["xd"], printed["xdd"])
        np.testing.assert_array_equal(printed["tau"], want)  # bit for bit
        assert np.all(np.abs(want) > 1.0)


def _simulated(dt: float = 1e-3, duration: float = 1.0):
    """The seed paper's move, shortened, under ComputedTorque with saturating, lossy actuators:
    (platform, controller, result, the reference on the half-step grid, the settings text for
    the example, steps)."""
    params = _params()
    platform = stewart.Platform(params)
    start = home_pose(params)
    trajectory = PointToPoint(start, TARGET, duration)
    controller = ComputedTorque(kp=np.full(6, 900.0), kd=np.full(6, 60.0))
    actuators = Actuators(force_limit=np.full(6, 60.0), viscous=np.full(6, 45.0), coulomb=np.full(6, 2.5))
    x0 = start + np.array([0.004, -0.003, 0.002, 0.01, -0.01, 0.005])  # off the reference: the feedback works
    result = stewart.simulate(platform, trajectory, controller, dt=dt, actuators=actuators, x0=x0, xd0=np.zeros(6))
    steps = len(result.t) - 1
    x_r, xd_r, xdd_r = trajectory.sample(np.arange(2 * steps + 1) * (dt / 2))
    refs = np.hstack([x_r, xd_r, xdd_r])

    def numbers(values):
        return " ".join(repr(float(v)) for v in np.ravel(values))

    model = friction_law(params)
    legs = actuators.friction(params)
    text = "\n".join([f"dt {dt!r}", f"steps {steps}", f"kp {numbers(controller.kp)}", f"kd {numbers(controller.kd)}",
                      f"force_limit {numbers(actuators.force_limit * np.ones(6))}",
                      f"model_friction {numbers(model[0])} {numbers(model[1])} {model[2]!r}",
                      f"friction {numbers(legs[0])} {numbers(legs[1])} {legs[2]!r}",
                      f"y0 {numbers(x0)} {numbers(np.zeros(6))}", f"refs {numbers(refs)}", ""])
    return platform, controller, result, refs, text, steps


@pytest.fixture(scope="module")
def simulated():
    return _simulated()


@pytest.fixture(scope="module")
def example(installed, tmp_path_factory) -> Path:
    """The example controller built by the compiler of ``installed`` against its install."""
    _, prefix, env = installed
    build = tmp_path_factory.mktemp("example")
    for command in (["-S", EXAMPLE, "-B", build, f"-DCMAKE_PREFIX_PATH={prefix}", "-DCMAKE_BUILD_TYPE=Release"],
                    ["--build", build]):
        done = _cmake(*command, env=env)
        assert done.returncode == 0, done.stdout + done.stderr
    return build


def _run_example(build: Path, settings: Path, *args) -> tuple[np.ndarray, str]:
    """The example's rows (step, x, xd, commanded forces) and what it said on stderr, run with
    the interposed allocator."""
    env = dict(os.environ, LD_PRELOAD=str(build / "liballoc_counter.so"))
    done = subprocess.run([build / "cpp_controller", settings, *args], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    return np.loadtxt(done.stdout.splitlines(), ndmin=2), done.stderr


@pytest.mark.control
def test_cpp_controller_equals_simulate_and_allocates_nothing(example, simulated, tmp_path):
    platform, controller, result, refs, text, steps = simulated
    build = example
    settings = tmp_path / "settings.txt"
    settings.write_text(text)
    rows, log = _run_example(build, settings)
    assert rows.shape == (steps, 1 + 18) and np.array_equal(rows[:, 0], np.arange(steps))
    x, xd, forces = rows[:, 1:7], rows[:, 7:13], rows[:, 13:19]
    # The loop is stewart.simulate's, bit for bit: the states and the commanded forces.
    np.testing.assert_array_equal(x, result.x[:steps])
    np.testing.assert_array_equal(xd, result.xd[:steps])
    np.testing.assert_array_equal(forces, result.commanded_forces[:steps])
    # The forces are the package's inverse dynamics of the law's acceleration (at stage 0 of
    # each step: the reference's even rows), plus the model's friction, bit for bit.
    ref = refs[0:2 * steps:2]
    acc = ref[:, 12:] + controller.kd * (ref[:, 6:12] - xd) + controller.kp * (ref[:, :6] - x)
    np.testing.assert_array_equal(forces, platform.inverse_dynamics(x, xd, acc) + (platform.friction_forces(x, xd) + 0.0))
    assert np.all(platform.friction_forces(x[1:], xd[1:]) != 0.0)  # the model's friction is in the law
    # Saturation and the feedback were exercised: the start is off the reference, some
    # commanded forces exceed the actuators' limit.
    assert np.max(np.abs(forces)) > 60.0
    # No heap allocation in the loop; the interposed allocator counted those of initialization.
    counted = re.search(r"allocations: (\d+) at initialization, (\d+) in the loop", log)
    assert counted, log
    assert int(counted.group(1)) > 0 and int(counted.group(2)) == 0


@pytest.mark.control
def test_cpp_controller_holding_its_forces_converges_to_simulate(example, tmp_path):
    """--plant hold, the real 1 kHz loop: the controller once a period, its forces held over the
    step. stewart.simulate's law is continuous (evaluated at every RK4 stage), so the two differ
    by the hold, O(dt): at 1 ms by 1.1e-4 m at most over the move (a hundredth of the tracking
    error), halving with the step (measured 2.01 and 2.00 from 1 ms to 0.25 ms)."""
    differences = []
    for dt in (1e-3, 5e-4):
        _, _, result, _, text, steps = _simulated(dt)
        settings = tmp_path / f"settings_{dt}.txt"
        settings.write_text(text)
        rows, log = _run_example(example, settings, "--plant", "hold")
        assert rows.shape == (steps, 19) and "0 in the loop" in log
        differences.append(np.max(np.abs(rows[:, 1:7] - result.x[:steps])))
        tracking = np.max(np.abs(result.x - result.reference))
        assert 0.0 < differences[-1] < 0.02 * tracking
    assert 1.9 < differences[0] / differences[1] < 2.1


@pytest.mark.control
def test_cpp_controller_refuses_bad_settings(example, tmp_path):
    """The example's own arguments: a bad plant, a bad file, a short reference: exit 2, one line."""
    settings = tmp_path / "settings.txt"
    for text, args, message in [("dt 0.001 steps 2 refs 1 2 3", (), "field 'refs': expected numbers"),
                                ("dt 0.001 steps 1 bogus 3", (), "unknown field 'bogus'"),
                                ("steps 1", (), "needs dt > 0"),
                                ("dt 0.001", ("--plant", "later"), "--plant: expected stages or hold, got 'later'")]:
        settings.write_text(text)
        done = subprocess.run([example / "cpp_controller", settings, *args], capture_output=True, text=True)
        assert done.returncode == 2 and message in done.stderr and len(done.stderr.splitlines()) == 1, done.stderr
