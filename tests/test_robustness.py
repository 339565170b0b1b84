"""Regression tests for malformed and extreme input found by random calls: each case here
once crashed the interpreter, returned a wrong or non-finite value silently, or raised a
foreign exception type. The broad random search is in ``test_fuzz.py``."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

import stewart
from stewart.studies import envelope, sweep, workspace
from stewart.oracles import exactness, reference
from stewart.identification import excitation, identify
from stewart.model.arguments import MAX_THREADS
from stewart.motion.control import leg_masses
from conftest import LAYOUTS, PLATFORM_METHODS, valid_arguments

PLAT = stewart.Platform.preset("narayan2017")
PARAMS = PLAT.params
CALLS = [(method, name) for method, names in PLATFORM_METHODS.items() for name in names]


def _call(method, args):
    return getattr(PLAT, method)(*args)


def _run_isolated(code: str) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter, so that a crash fails the test instead of pytest."""
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300
    )


def _assert_same(result, expected):
    if isinstance(result, tuple):
        for r, e in zip(result, expected):
            np.testing.assert_array_equal(r, e)
    else:
        np.testing.assert_array_equal(result, expected)


@pytest.mark.parametrize("batch", [None, 4], ids=["one state", "batch"])
@pytest.mark.parametrize("layout", sorted(LAYOUTS))
@pytest.mark.parametrize("method, name", CALLS)
def test_every_layout_reads_the_same_values(method, name, layout, batch):
    """Big-endian data once passed the kernel's float64 test and was read unswapped
    (leg lengths of 7.3e20 m instead of 0.285 m)."""
    valid = valid_arguments(PLAT, batch)
    names = PLATFORM_METHODS[method]
    expected = _call(method, [valid[n] for n in names])
    args = [LAYOUTS[layout](valid[n]) if n == name else valid[n] for n in names]
    _assert_same(_call(method, args), expected)


def test_big_endian_leg_lengths_are_right():
    x = PLAT.home_pose
    np.testing.assert_allclose(PLAT.leg_lengths(x.astype(">f8")), PLAT.leg_lengths(x), rtol=0)
    assert np.all(np.abs(PLAT.leg_lengths(x.astype(">f8")) - 0.285) < 0.001)


def test_zero_dimensional_arrays_are_refused_by_name():
    """A 0-d array once made the kernel read ``shape[-1]`` of a shape with no entries: a segfault."""
    result = _run_isolated(
        f"""
        import numpy as np, stewart, sys
        sys.path.insert(0, {str(__import__("pathlib").Path(__file__).parent)!r})
        from conftest import PLATFORM_METHODS, valid_arguments
        plat = stewart.Platform.preset("narayan2017")
        valid = valid_arguments(plat)
        view = np.zeros((3, 6))
        zero_d = {{"zeros(())": np.zeros(()), "array(6.0)": np.array(6.0), "empty(())": np.empty(()),
                  "view": view[0, 0, ...]}}
        for method, names in PLATFORM_METHODS.items():
            for name in names:
                for label, bad in zero_d.items():
                    args = [bad if n == name else valid[n] for n in names]
                    try:
                        getattr(plat, method)(*args)
                    except ValueError as exc:
                        assert str(exc).startswith(name + ": expected shape"), (method, name, label, exc)
                    else:
                        raise AssertionError((method, name, label, "accepted"))
        print("refused", sum(len(n) for n in PLATFORM_METHODS.values()) * len(zero_d))
        """
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == f"refused {len(CALLS) * 4}"


@pytest.mark.parametrize(
    "threads, message",
    [
        (100000, f"threads: must be from 1 to {MAX_THREADS}, got 100000"),
        (2**31, f"threads: must be from 1 to {MAX_THREADS}"),
        (0, "threads: must be from 1"),
        (-3, "threads: must be from 1"),
        (2.5, "threads: expected an integer, got float 2.5"),
        (2.0, "threads: expected an integer"),
        (True, "threads: expected an integer"),
        ("4", "threads: expected an integer"),
        (None, "threads: expected an integer"),
    ],
)
def test_thread_counts_are_validated(threads, message):
    with pytest.raises(ValueError, match=message):
        stewart.Platform(PARAMS, threads=threads)


def test_most_threads_allowed_run():
    """``threads=100000`` was accepted once and the first batch crashed in libgomp."""
    result = _run_isolated(
        f"""
        import numpy as np, stewart
        plat = stewart.Platform.preset("narayan2017")
        many = stewart.Platform(plat.params, threads=np.int64({MAX_THREADS}))
        x = plat.home_pose + np.linspace(0, 0.01, 3 * {MAX_THREADS})[:, None]
        assert many.threads == {MAX_THREADS}
        assert np.array_equal(many.inverse_dynamics(x, 0 * x, 0 * x), plat.inverse_dynamics(x, 0 * x, 0 * x))
        print("ok")
        """
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"


class _Exploding:
    def __array__(self, *args, **kwargs):
        raise RuntimeError("no array here")


def _deep(depth: int):
    value: list = []
    for _ in range(depth):
        value = [value]
    return value


X = PLAT.home_pose
ZERO = np.zeros(6)


@pytest.mark.parametrize(
    "call, message",
    [
        # OverflowError once
        (lambda: PARAMS.replace(platform_mass=10**400), "platform_mass: 1000.* is too large for a float"),
        (lambda: PARAMS.replace(base_points=[[10**400, 0, 0]] * 6), "base_points: .* too large"),
        (lambda: stewart.ComputedTorque.tuned(10**400), "bandwidth_hz: .* too large"),
        (lambda: stewart.ComputedTorque.tuned(1e300), "bandwidth_hz: 1e\\+300 Hz is too high"),
        (lambda: stewart.PID.tuned(PLAT, 1e300), "bandwidth_hz: 1e\\+300 Hz is too high"),
        (lambda: stewart.PointToPoint(X, X, 1.0).sample(10**400), "t: .* too large"),
        (lambda: stewart.home_pose(PARAMS, 10**400), "leg_length: .* too large"),
        # AttributeError once
        (lambda: stewart.PID.tuned({}), "platform: expected a stewart.Platform, got dict"),
        (lambda: leg_masses(None), "platform: expected a stewart.Platform"),
        (lambda: stewart.leg_lengths({}, X), "params: expected a stewart.PlatformParams, got dict"),
        (lambda: stewart.jacobian(None, X), "params: expected a stewart.PlatformParams, got NoneType"),
        (lambda: stewart.home_pose(None), "params: expected a stewart.PlatformParams"),
        (lambda: stewart.forward_kinematics({}, [0.3] * 6), "params: expected a stewart.PlatformParams"),
        (lambda: reference.mass_matrix(None, X), "params: expected a stewart.PlatformParams"),
        (lambda: reference.rotational_inertias({}, X), "params: expected a stewart.PlatformParams"),
        (lambda: reference.forward_dynamics("narayan2017", X, ZERO, ZERO), "params: expected a stewart.PlatformParams, got str"),
        (lambda: stewart.oracles.newton_euler.joint_reactions(None, X, ZERO, ZERO), "params: expected a stewart.PlatformParams"),
        (lambda: stewart.Actuators(force_limit="abc"), "force_limit: expected a number"),
        (lambda: stewart.Actuators(viscous="abc"), "viscous: expected a number"),
        (lambda: stewart.Actuators(coulomb_velocity="fast"), "coulomb_velocity: expected a number"),
        (lambda: stewart.PID("a", 1, 1), "kp: expected a number"),
        (lambda: stewart.ComputedTorque(1, [1, 2]), "kd: expected one value or one per leg"),
        (lambda: stewart.PlatformParams.from_dict(None), "data: expected a mapping"),
        (lambda: stewart.PlatformParams.from_dict({1: 2}), "unknown parameter field"),
        (lambda: stewart.Platform.preset(["narayan2017"]), "name: expected a preset name"),
        # TypeError or ValueError without the argument's name once
        (lambda: PLAT.leg_lengths(_Exploding()), "x: cannot be read as an array"),
        (lambda: stewart.leg_lengths(PARAMS, _deep(100)), "x: cannot be read as an array"),
        (lambda: PARAMS.replace(platform_mass="5"), "platform_mass: expected a number"),
        (lambda: PARAMS.replace(platform_mass=True), "platform_mass: expected a number"),
        (lambda: stewart.PointToPoint(X, X, "1"), "duration: expected a number"),
        (lambda: stewart.PointToPoint(X, X, 1.0, profile=["quintic"]), "profile: expected one of"),
        (lambda: stewart.forward_kinematics(PARAMS, [0.3] * 6, max_iter=2.5), "max_iter: expected an integer"),
        (lambda: stewart.forward_kinematics(PARAMS, [0.3] * 6, tol="small"), "tol: expected a number"),
        (lambda: stewart.forward_kinematics(PARAMS, np.full((3, 6), 0.3), np.zeros((2, 6))), "guess: expected one pose"),
    ],
)
def test_wrong_input_raises_a_named_value_error(call, message):
    with pytest.raises(ValueError, match=message):
        call()


@pytest.mark.parametrize("fmt", ["json", "toml"])
def test_deeply_nested_parameter_files_are_refused(tmp_path, fmt):
    """JSON and TOML nested 10^5 deep once raised RecursionError."""
    path = tmp_path / f"deep.{fmt}"
    path.write_text(("a = " if fmt == "toml" else "") + "[" * 100_000 + "]" * 100_000)
    with pytest.raises(ValueError, match=f"deep.{fmt}: not a valid {fmt.upper()} file"):
        stewart.PlatformParams.load(path)


@pytest.mark.parametrize(
    "text, message",
    [
        (b"\xff\xfe{", "not a valid JSON file"),
        (b'{"platform_mass": 1' + b"0" * 5000 + b"}", "not a valid JSON file"),
        (b'{"platform_mass": {"a": 1}}', "missing parameter field"),
    ],
)
def test_broken_json_names_the_file(tmp_path, text, message):
    path = tmp_path / "broken.json"
    path.write_bytes(text)
    with pytest.raises(ValueError, match=f"broken.json: .*{message}"):
        stewart.PlatformParams.load(path)


def test_wrong_field_types_in_a_file_name_the_field(tmp_path):
    data = PARAMS.to_dict()
    data["platform_mass"] = {"kg": 1}
    path = tmp_path / "typed.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="typed.json: platform_mass: expected a number, got dict"):
        stewart.PlatformParams.load(path)


TIME_LIKE = {
    "timedelta64": np.zeros(6, dtype="m8[s]"),
    "datetime64": np.zeros(6, dtype="M8[s]"),
    "bool": np.zeros(6, dtype=bool),
    "str": np.array(["0"] * 6),
    "object": np.array([object()] * 6),
}


def _public_calls(bad):
    """Every public function that takes a state, with ``bad`` as its state argument:
    ``(argument name, call, whether complex values are meaningful there)``."""
    x, z = X, ZERO
    yield "x", lambda: stewart.leg_lengths(PARAMS, bad), False
    yield "x", lambda: stewart.rotation(bad), True
    yield "x", lambda: stewart.twist_transform(bad), True
    yield "xd", lambda: stewart.leg_velocities(PARAMS, x, bad), False
    yield "x", lambda: stewart.oracles.frames.leg_lengths(PARAMS, bad), True
    yield "xd", lambda: stewart.oracles.frames.leg_velocities(PARAMS, x, bad), True
    yield "lengths", lambda: stewart.forward_kinematics(PARAMS, bad), False
    yield "x", lambda: reference.mass_matrix(PARAMS, bad), False
    yield "tau", lambda: reference.forward_dynamics(PARAMS, x, z, bad), True
    yield "xdd", lambda: stewart.oracles.newton_euler.inverse_dynamics(PARAMS, x, z, bad), False
    yield "start", lambda: stewart.PointToPoint(bad, x, 1.0), False
    yield "poses", lambda: stewart.SampledTrajectory([0.0, 1.0], np.stack([bad, bad])), False
    yield "kp", lambda: stewart.PID(bad, 1.0, 1.0), False
    yield "base_points", lambda: PARAMS.replace(base_points=np.stack([bad[:3]] * 6)), False
    valid = valid_arguments(PLAT)
    for method, names in PLATFORM_METHODS.items():
        yield names[-1], lambda m=method, n=names: _call(m, [valid[k] for k in n[:-1]] + [bad]), False


@pytest.mark.parametrize("kind", sorted(TIME_LIKE))
def test_non_numbers_are_refused_everywhere(kind):
    """timedelta64 arrays were once taken as numbers by the numpy functions."""
    for name, call, _ in _public_calls(TIME_LIKE[kind]):
        with pytest.raises(ValueError, match=f"^{name}: expected "):
            call()


def test_complex_states_are_refused_where_not_meaningful():
    """Complex values make sense only for complex-step derivatives: in the oracles' kinematics,
    the reference's inverse and forward dynamics, and the functions of the orientation alone
    (a complex step, from the generated partials)."""
    for name, call, complex_ok in _public_calls(X + 1e-30j):
        if complex_ok:
            assert np.iscomplexobj(call())
        else:
            with pytest.raises(ValueError, match=f"^{name}: expected real numbers, got complex"):
                call()


def _zero_leg_pose():
    """A pose with leg 0 of zero length: P_0 on B_0, no rotation."""
    x = X.copy()
    x[:3] = PARAMS.base_points[0] - PARAMS.platform_points[0]
    np.testing.assert_allclose(stewart.leg_lengths(PARAMS, x)[0], 0.0, atol=1e-15)
    return x


@pytest.mark.parametrize(
    "call",
    [
        lambda x: stewart.leg_unit_vectors(PARAMS, x),
        lambda x: stewart.jacobian(PARAMS, x),
        lambda x: reference.mass_matrix(PARAMS, x),
        lambda x: reference.partial_velocity_jacobians(PARAMS, x),
        lambda x: reference.forward_dynamics(PARAMS, x, ZERO, ZERO),
        lambda x: stewart.oracles.newton_euler.joint_reactions(PARAMS, x, ZERO, ZERO),
        lambda x: PLAT.mass_matrix(x),
    ],
)
def test_zero_length_legs_raise_singularity_error(call):
    """reference.mass_matrix once returned NaN with a RuntimeWarning for a zero-length leg."""
    with pytest.raises(stewart.SingularityError, match="a leg has zero length") as info:
        call(_zero_leg_pose())
    assert info.value.condition == "leg_degenerate"


@pytest.mark.parametrize(
    "call",
    [
        lambda: stewart.leg_unit_vectors(PARAMS, X * 1e308),
        lambda: stewart.leg_lengths(PARAMS, X * 1e308),
        lambda: stewart.oracles.newton_euler.joint_reactions(PARAMS, X, np.full(6, 1e200), ZERO),
        lambda: stewart.oracles.newton_euler.inverse_dynamics(PARAMS, X, np.full(6, 1e200), ZERO),
        lambda: reference.forward_dynamics(PARAMS, X, ZERO, np.full(6, 1e308)),
        lambda: reference.inverse_dynamics(PARAMS, X, ZERO, np.full(6, 1e308)),
        lambda: reference.coriolis_vector(PARAMS, X, np.full(6, 1e200)),
        lambda: PLAT.forward_dynamics(X, ZERO, np.full(6, 1e308)),
        lambda: stewart.PointToPoint(X, X + 0.1, 1e-200),
        lambda: stewart.SampledTrajectory([0.0, 1e-300], [X, X + 0.1]),
    ],
)
def test_overflow_is_an_error_not_a_silent_inf(call):
    with pytest.raises(ValueError, match="too large|too short|overflows|non-finite"):
        call()


def test_massless_platform_is_a_singularity_in_reference_and_kernel():
    """The reference once raised numpy's LinAlgError for a singular mass matrix."""
    massless = PARAMS.replace(
        platform_mass=0.0, platform_inertia=(0, 0, 0), cylinder_mass=0.0, cylinder_inertia=(0, 0, 0),
        piston_mass=0.0, piston_inertia=(0, 0, 0),
    )
    for call in (lambda: reference.forward_dynamics(massless, X, ZERO, ZERO),
                 lambda: stewart.Platform(massless).forward_dynamics(X, ZERO, ZERO)):
        with pytest.raises(stewart.SingularityError, match="mass matrix") as info:
            call()
        assert info.value.condition == "mass_singular"


# ---- bad input to the studies, identification, simulation and the command line -----------------

_HOME = PLAT.home_pose
_MOVE = stewart.PointToPoint(_HOME, _HOME + [0.01, 0, 0, 0, 0.02, 0], 1.0)
_MASSLESS = PARAMS.replace(platform_mass=0.0, platform_inertia=(0, 0, 0), cylinder_mass=0.0,
                           cylinder_inertia=(0, 0, 0), piston_mass=0.0, piston_inertia=(0, 0, 0))
#: A reachable target pose for the command line.
TARGET = ["0.01", "0", "0.27", "0", "0", "0"]
_SWEEP = {"preset": "narayan2017", "parameters": {"base_radius": 0.1},
          "envelope": {"lower": [-0.01] * 6, "upper": [0.01] * 6, "velocity": [0.1] * 6, "acceleration": [1.0] * 6}}


def _log(t=None):
    """A short logged run of the preset (201 samples at 200 Hz), its times replaced by ``t``."""
    log = identify.synthetic_measurements(PLAT, _MOVE, rate=200)
    return log if t is None else identify.Measurements(t, log.lengths, log.forces)


@pytest.mark.parametrize("controller", [stewart.PID(1e300, 1e300, 1e300), stewart.ComputedTorque(1e300, 1e300)],
                         ids=["PID", "computed torque"])
def test_gains_no_machine_realises_end_the_adaptive_run_at_once(controller):
    """Gains of 1e300 once shrank DOP853's step to 1e-298 s at t = 0 (scipy's smallest step
    there is 5e-323 s), and the run went on for the 240000 evaluations of its budget."""
    import time

    import scipy.integrate  # noqa: F401  (imported before the clock starts)

    start = time.perf_counter()
    run = stewart.simulate(PLAT, _MOVE, controller, method="adaptive", duration=0.01)
    assert time.perf_counter() - start < 2.0
    assert run.outcome == "failed" and not run.completed and run.exit_code == 4
    assert run.reason.startswith("the adaptive solver's steps fell below 1e-09 s after t = 0.0000 s")
    assert run.problems == [run.reason] and np.all(np.isfinite(run.x))


@pytest.mark.parametrize("call, error, message", [
    # OverflowError once
    (lambda: _log(np.arange(201) * 5e-324), ValueError, r"^t: the time steps \(4.94066e-324 s first\) give no "
                                                         r"finite sampling rate \(rate inf Hz\)"),
    (lambda: identify.identify(PLAT, _log(), cutoff=1e-310), ValueError,
     "^cutoff: 1e-310 Hz is too low for the sampling rate 200 Hz: the filter window overflows"),
    (lambda: envelope.envelope(PLAT, envelope.Trajectories([_MOVE], 5e-324)), ValueError,
     r"^dt: 4.94066e-324 s samples trajectory 0 \(1 s\) inf times, more than 1e\+12"),
    (lambda: envelope.Box.around(_MOVE, 0.2, 5e-324), ValueError,
     r"^dt: 4.94066e-324 s samples the motion \(1 s\) inf times"),
    # AttributeError once
    (lambda: sweep.parse(dict(_SWEEP, workspace=[])), ValueError,
     r"^workspace: expected a table \(\[workspace\] with samples = N\), got list \[\]"),
    (lambda: sweep.parse(dict(_SWEEP, pareto=[])), ValueError, r"^pareto: expected a table"),
    (lambda: sweep.parse(dict(_SWEEP, pareto={"x": ["peak_force"]})), ValueError, "^pareto.x: unknown metric"),
    (lambda: identify.identify(None, _log()), TypeError, "^platform: expected a stewart.Platform, got NoneType$"),
    (lambda: identify.identify({}, _log()), TypeError, "^platform: expected a stewart.Platform, got dict$"),
    (lambda: envelope.Box.around(_HOME), TypeError,
     "^motion: expected an object with sample.t. and duration .* got ndarray$"),
    # inf or NaN once
    (lambda: envelope.envelope(PLAT, envelope.Box(_HOME - 0.01, _HOME + 0.01, [1e150] * 6,
                                                                  [1e150] * 6), samples=100, progress=False),
     ValueError, r"^spec: the power of leg 0 overflows double precision at state 0 of the study"),
    (lambda: exactness.leg_spin_effect(_MASSLESS, 20), ValueError,
     "^params: the paper's dynamic forces are zero .* at state 0 of 20: their relative change is undefined$"),
    (lambda: workspace.translational_workspace(PLAT, region=[[0, 1e150]] * 3, samples=100), ValueError,
     r"^region: the box's volume overflows double precision"),
    (lambda: PARAMS.replace(platform_com=[1e200, 0, 0]), ValueError,
     r"^platform_mass, platform_inertia, platform_com: too large for double precision: the inertial parameter "
     r"platform.Ixx \(inertial_vector\) overflows$"),
    (lambda: PARAMS.replace(platform_inertia=np.full((3, 3), 1e308)), ValueError,
     "^platform_inertia: too large for double precision"),
])
def test_bad_input_to_the_studies_is_a_named_error(call, error, message):
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(error, match=message):
            call()


def test_wrong_types_are_type_errors_and_value_errors():
    """A wrong kind of object raises stewart.WrongTypeError, a TypeError as the call is
    wrong and a ValueError as every other bad argument (one except clause catches all)."""
    for call in (lambda: identify.identify({}, _log()), lambda: stewart.PID.tuned(None),
                 lambda: stewart.simulate("narayan2017", _MOVE), lambda: stewart.leg_lengths(None, _HOME)):
        with pytest.raises(stewart.WrongTypeError) as info:
            call()
        assert isinstance(info.value, TypeError) and isinstance(info.value, ValueError)


def test_a_platform_argument_is_a_platform_or_its_parameters():
    """Every function that takes a platform takes a stewart.Platform or its PlatformParams
    (stewart.model), with the same result: those that evaluate the compiled model compile
    the parameters, those that work on the parameters take the Platform's."""
    pid, pid_from_params = stewart.PID.tuned(PLAT), stewart.PID.tuned(PARAMS)
    for gain in ("kp", "ki", "kd"):
        np.testing.assert_array_equal(getattr(pid_from_params, gain), getattr(pid, gain))
    np.testing.assert_array_equal(leg_masses(PARAMS), leg_masses(PLAT))
    np.testing.assert_array_equal(reference.forward_dynamics(PLAT, X, ZERO, ZERO),
                                  reference.forward_dynamics(PARAMS, X, ZERO, ZERO))
    np.testing.assert_array_equal(stewart.leg_lengths(PLAT, _HOME), stewart.leg_lengths(PARAMS, _HOME))
    np.testing.assert_array_equal(stewart.jacobian(PLAT, _HOME), stewart.jacobian(PARAMS, _HOME))
    log, from_params = _log(), identify.synthetic_measurements(PARAMS, _MOVE, rate=200)
    np.testing.assert_array_equal(from_params.lengths, log.lengths)
    np.testing.assert_array_equal(from_params.forces, log.forces)
    run, from_params = stewart.simulate(PLAT, _MOVE), stewart.simulate(PARAMS, _MOVE)
    assert run.ok and from_params.ok
    np.testing.assert_array_equal(from_params.x, run.x)
    np.testing.assert_array_equal(from_params.forces, run.forces)


def _friction_platform(viscous):
    return stewart.Platform(PARAMS.replace(viscous_friction=[viscous] * 6, coulomb_friction=[1.0] * 6))


@pytest.mark.parametrize("method, viscous, xd", [("friction_forces", 1000.0, 1e306), ("actuator_forces", 1e300, 1e10)])
def test_friction_that_overflows_is_a_failed_row(method, viscous, xd):
    """friction_forces(x, 1e306) with viscous friction once returned inf with the mask True,
    as actuator_forces did with viscous_friction 1e300."""
    plat = _friction_platform(viscous)
    call = getattr(plat, method)
    args = (_HOME, np.full(6, xd)) + ((np.zeros(6),) if method == "actuator_forces" else ())
    values, ok = call(*args, return_mask=True)
    assert ok is False and np.all(np.isnan(values))
    with pytest.raises(stewart.SingularityError, match=f"^{method}: non-finite result at row.s. \\[0\\]") as info:
        call(*args)
    assert info.value.condition == "nonfinite" and info.value.rows == [0]
    batch = (np.stack([_HOME] * 3), np.array([np.zeros(6), np.full(6, xd), np.ones(6)])) + args[2:]
    values, ok = call(*batch, return_mask=True)
    assert ok.tolist() == [True, False, True]
    assert np.all(np.isnan(values[1])) and np.all(np.isfinite(values[[0, 2]]))
    np.testing.assert_array_equal(values[[0, 2]], call(*(a[[0, 2]] if a.ndim == 2 else a for a in batch)))


def test_measurements_rate_is_finite():
    """Measurements.rate was inf for subnormal time steps."""
    log = _log()
    assert log.rate == pytest.approx(200.0, rel=1e-14) and np.isfinite(log.rate)  # reached 0
    with pytest.raises(ValueError, match="^t: the time steps"):
        _log(np.linspace(-1.0, 1.0, 201) * 1e308)


@pytest.mark.parametrize("argv, message", [
    (["identify", "{log}", "--cutoff", "1e-310"], "stewart identify: error: --cutoff: 1e-310 Hz is too low"),
    (["envelope", "--target", *TARGET, "--dt", "1e-310"], "stewart envelope: error: --dt: 1e-310 s samples"),
    (["envelope", "--target", *TARGET, "--dt", "1e-310", "--margin", "0.1"], "stewart envelope: error: --dt: "),
    (["envelope", "--lower", *"000000", "--upper", "0", "0", "0.3", "0", "0", "0", "--velocity", *["1e150"] * 6,
      "--acceleration", *["1e150"] * 6, "--samples", "100"],
     "stewart envelope: error: --velocity, --acceleration: the power of leg 0 overflows double precision"),
    (["sweep", "{sweep}"], "stewart sweep: error: {sweep}: workspace: expected a table"),
    (["exactness", "--params", "{massless}", "--states", "10"],
     "stewart exactness: error: --params {massless}: the paper's dynamic forces are zero"),
    (["exactness", "--seed", "-1"], "stewart exactness: error: --seed: expected a whole number >= 0, got -1"),
    (["identify", "{log}", "--output", "0"], "stewart identify: error: --output 0: give a .toml or .json file name"),
    (["identify", "{log}", "--preset", "motion_simulator"],
     "stewart identify: error: {log}: the leg lengths are not this platform's"),
])
def test_commands_refuse_bad_input_in_one_line(argv, message, tmp_path, capsys):
    """These printed tracebacks once."""
    from stewart.cli import main

    files = {"log": tmp_path / "log.csv", "sweep": tmp_path / "sweep.toml", "massless": tmp_path / "massless.toml"}
    _log().to_csv(files["log"])
    files["sweep"].write_text('preset = "narayan2017"\nworkspace = ["samples"]\n[parameters]\nbase_radius = [0.09]\n'
                              "[envelope]\nlower = [0, 0, 0, 0, 0, 0]\nupper = [0, 0, 0, 0, 0, 0]\n"
                              "velocity = [0.1, 0, 0, 0, 0, 0]\nacceleration = [1, 0, 0, 0, 0, 0]\n")
    _MASSLESS.save(files["massless"])
    argv = [a.format(**files) for a in argv] + (["--no-progress"] if argv[0] in ("envelope", "sweep") else [])
    with pytest.raises(SystemExit) as info:
        main(argv)
    out, err = capsys.readouterr()
    assert info.value.code == 2 and "Traceback" not in out + err
    assert len(err.strip().splitlines()) == 1 and err.startswith(message.format(**files)), err



@pytest.mark.parametrize("call, message", [
    (lambda: workspace.workspace_slice(PLAT, None), "^axes: expected two of x, y, z or two of psi, theta, phi, got None"),
    (lambda: exactness.leg_spin_effect(PARAMS, 10, seed=-1), r"^seed: expected a whole number >= 0, got -1$"),
    (lambda: excitation.design_excitation(PLAT, harmonics=2, starts=1, max_iterations=1, seed=True),
     "^seed: expected a whole number >= 0, got True$"),
    (lambda: sweep.parse(dict(_SWEEP, parameters={"base_radius": 1.0})),
     r"^parameters: design 0 \({'base_radius': 1.0}\) is not a valid platform: leg_length: "),
    (lambda: identify.identify(PLAT, identify.Measurements(_log().t, _log().lengths, _log().forces * 1e306)),
     r"^forces: too large for double precision"),
    (lambda: identify.identify(stewart.Platform.preset("motion_simulator"), _log()),
     "^measurements: the leg lengths are not this platform's .forward_kinematics: no pose found"),
    (lambda: PARAMS.replace(piston_com_distance=1e200), "^piston_mass, piston_inertia, piston_com_distance: too large "
                                                        "for double precision"),
    (lambda: PARAMS.with_inertial_vector(np.where(np.arange(32) == 15, 2.2e-308, PARAMS.inertial_vector())),
     "^pi: no physical body: piston_mass, piston_inertia, piston_com_distance: too large"),
])
def test_bad_input_found_by_the_fuzz_tests_is_a_named_error(call, message):
    """Each once raised TypeError, IndexError, OverflowError or numpy's own ValueError, or
    failed later, in the sweep's run."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(ValueError, match=message):
            call()


def test_no_poses_have_no_reachability():
    """An empty batch of poses once raised IndexError."""
    for params in (PARAMS, PARAMS.replace(leg_diameter=0.01)):
        check = stewart.reachability(params, np.zeros((0, 6)))
        assert check.flags.shape == check.margin.shape == (0,) and check.lengths.shape == (0, 6)


def test_limits_that_leave_no_motion_are_named():
    """A leg-velocity limit of 5e-324 m/s once gave a design that does not move, reported as
    feasible with a condition number of inf; a tiny smallest margin (ample at every pose)
    once made the centre pose break its limit."""
    from stewart.identification.base_parameters import base_parameters

    base = base_parameters(PLAT)
    options = dict(period=2.0, harmonics=2, starts=1, max_iterations=1, base=base)
    with pytest.raises(ValueError, match="^max_leg_velocity: the limits leave no motion about the centre, so the "
                                         r"design excites nothing \(condition number inf\)"):
        excitation.design_excitation(PLAT, max_leg_velocity=5e-324, **options)
    design = excitation.design_excitation(PLAT, min_margin=5e-324, **options)
    assert np.isfinite(design.condition) and design.feasible


def test_an_unsolved_move_says_so_on_stderr_with_json(capsys):
    """stewart optimize --json once exited 4 with nothing on stderr."""
    pytest.importorskip("casadi")
    from stewart.cli import main

    with pytest.raises(SystemExit) as info:
        main(["optimize", "--target", *TARGET, "--move-time", "1", "--intervals", "3", "--max-iterations", "1",
              "--json"])
    out, err = capsys.readouterr()
    assert info.value.code == 4 and json.loads(out)["ok"] is False
    assert err.startswith("stewart optimize: error: IPOPT did not solve the problem") and err.count("\n") == 1
