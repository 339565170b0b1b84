"""Property-based fuzzing of the Python API and the command line: random malformed and edge
inputs at every public function and the studies' commands.

The contract every call must keep, whatever it is given:

* it returns within a few seconds (no hang) and does not crash the interpreter — what
  hands arrays to the compiled kernel as given (the Platform methods, the parameters'
  compiled model) is fuzzed in a separate interpreter, so a crash fails the test;
* it returns finite values only, except rows a ``return_mask`` marks as failed;
* otherwise it raises ``ValueError`` or ``TypeError`` (the package's ``SingularityError``
  and ``ConvergenceError`` are ``ValueError``\\ s) whose message names the argument, or
  for a ``SingularityError`` the condition; it never leaks another exception type or a
  ``RuntimeWarning``;
* valid values in an unusual layout or dtype (big-endian, unaligned, strided, reversed,
  Fortran-ordered, read-only, float32, integers, nested lists) give the same result as
  the same values as a plain C-contiguous float64 array, the independent oracle;
* a ``stewart`` command, run in this process, succeeds or exits with one of its codes and
  no traceback, an input error as one line naming the flag or file the user typed.

The examples are derandomized, so a run is reproducible; ``STEWART_FUZZ_EXAMPLES=N``
raises the number of examples (and draws them at random) for a longer search.
"""

from __future__ import annotations

import atexit
import contextlib
import dataclasses
import functools
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import warnings
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import stewart
import stewart.motion.trajectory
from stewart import ConvergenceError, PlatformParams, SingularityError
from stewart.oracles import reference
from stewart.studies import workspace
from stewart.identification import excitation
from stewart.model import reachability as workspace_reachability
from stewart.studies import envelope, sweep
from stewart.motion.control import leg_masses
from stewart.model.paramfile import dumps_toml
from conftest import LAYOUTS, PLATFORM_METHODS, random_states, valid_arguments

_EXPLORE = int(os.environ.get("STEWART_FUZZ_EXAMPLES", "0"))


def fuzz_settings(examples: int):
    """``examples`` derandomized examples per test (or ``STEWART_FUZZ_EXAMPLES`` random ones);
    a deadline of two seconds an example catches slow paths."""
    return settings(
        max_examples=_EXPLORE or examples,
        derandomize=not _EXPLORE,
        deadline=2000,
        database=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much, HealthCheck.data_too_large],
    )


# ---- inputs ------------------------------------------------------------------------

#: Edge values of a double: signed zero, subnormals, the extremes, non-finite values.
EDGE_FLOATS = [0.0, -0.0, 5e-324, 2.2250738585072014e-308, 1e-300, 1e-8, 0.3, -3.0, 1e6, 1e154, 1e308,
               -1e308, 1.7976931348623157e308, float("nan"), float("inf"), float("-inf")]
SHAPES = [(), (0,), (1,), (5,), (6,), (7,), (0, 6), (1, 6), (2, 6), (3, 6), (3, 5), (6, 1), (6, 6), (2, 3, 6)]
DTYPES = ["<f8", ">f8", "<f4", ">f4", "<f2", "<i8", ">i4", "<u1", "<i1", "<c16", "?", "<m8[s]", "<M8[s]", "<U3"]
#: Python values that are not arrays of numbers.
OBJECTS = [None, {}, {"x": 1.0}, "abc", "", b"\x00", 6.0, 10**400, -(10**400), True, 1 + 2j, [1.0, 2.0],
           [[0.0] * 6, [0.0] * 5], object(), Fraction(1, 3), slice(None), range(6)]


def _deep(depth: int):
    value: list = [0.0] * 6
    for _ in range(depth):
        value = [value]
    return value


#: Valid values in other layouts and dtypes; the oracle is ``np.array(v, dtype=float)``.
ALL_LAYOUTS = {
    **LAYOUTS,
    "float32": lambda a: a.astype(np.float32),
    "big-endian float32": lambda a: a.astype(">f4"),
    "integers": lambda a: np.round(a * 100).astype(np.int64),
}


@st.composite
def layouts(draw, valid: np.ndarray):
    """``valid`` in a random layout, and the oracle's plain float64 form of its values."""
    name = draw(st.sampled_from(sorted(ALL_LAYOUTS)))
    value = ALL_LAYOUTS[name](valid)
    return value, np.array(value, dtype=np.float64)


@st.composite
def arrays(draw):
    """An array of any dtype and shape, with edge values for doubles."""
    dtype = np.dtype(draw(st.sampled_from(DTYPES)))
    shape = draw(st.sampled_from(SHAPES))
    if dtype == np.float64:
        elements = st.one_of(st.sampled_from(EDGE_FLOATS), st.floats(width=64))
        return draw(hnp.arrays(dtype, shape, elements=elements))
    return draw(hnp.arrays(dtype, shape))


@st.composite
def perturbed(draw, valid: np.ndarray):
    """``valid`` with a few entries set to edge values."""
    out = np.array(valid, dtype=float, copy=True)
    flat = out.reshape(-1)
    for _ in range(draw(st.integers(1, 3))):
        flat[draw(st.integers(0, flat.size - 1))] = draw(st.sampled_from(EDGE_FLOATS))
    return out


def junk(valid: np.ndarray | None = None):
    """Malformed or extreme values for an argument whose valid form is ``valid``."""
    options = [arrays(), st.sampled_from(OBJECTS), st.builds(_deep, st.integers(2, 80)),
               st.builds(lambda: np.array([1.0, None, "a", 10**400, Fraction(1, 3), 2.0], dtype=object))]
    if valid is not None:
        options += [perturbed(valid), perturbed(valid), layouts(valid).map(lambda pair: pair[0]),
                    st.just(valid[..., :5]), st.just(np.stack([valid, valid]) if valid.ndim == 1 else valid[:1]),
                    st.just(np.asarray(valid)[..., None, :]), st.just(np.zeros((0, 6)))]
    return st.one_of(*options)


def scalars():
    """Junk and edge values for a scalar argument."""
    return st.one_of(st.sampled_from(EDGE_FLOATS), st.sampled_from(OBJECTS), st.floats(), st.integers(-(2**70), 2**70),
                     arrays())


# ---- the contract ------------------------------------------------------------------


@contextlib.contextmanager
def time_limit(seconds: float):
    """Fail a call that runs longer than ``seconds`` (a hang), as a ``TimeoutError``."""

    def expire(signum, frame):
        raise TimeoutError(f"no answer after {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _arrays_in(result):
    if isinstance(result, dict):
        result = tuple(result.values())
    if isinstance(result, tuple):
        for item in result:
            yield from _arrays_in(item)
    elif isinstance(result, (np.ndarray, float, np.floating)):
        yield np.asarray(result)


def _finite(result) -> bool:
    return all(np.all(np.isfinite(arr)) for arr in _arrays_in(result))


def kept_contract(call, names, mask=False):
    """Run ``call``; return ``("ok", result)`` or ``("error", message)`` after checking the
    contract (module docstring). ``names`` are the argument names a message may name;
    with ``mask`` the result is ``(values, ok)`` and only rows with ``ok`` must be finite."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        try:
            with time_limit(20):
                result = call()
        except (ValueError, TypeError) as exc:
            message = str(exc)
            if isinstance(exc, (SingularityError, ConvergenceError)):
                assert message, "a SingularityError must name the condition"
            else:
                assert any(name in message for name in names), f"{message!r} names none of {names}"
            return "error", f"{type(exc).__name__}: {message}"
    if mask:
        values, ok = result
        ok = np.asarray(ok).reshape(-1)
        rows = np.concatenate([np.reshape(v, (ok.size, np.size(v) // max(ok.size, 1))) for v in _arrays_in(values)],
                              axis=1)
        assert np.all(np.isfinite(rows[ok])), "a row marked ok is not finite"
        assert np.all(np.isnan(rows[~ok])), "a failed row is not NaN"
    else:
        assert _finite(result), f"non-finite result without a mask: {result!r}"
    return "ok", result


def same_outcome(got, expected, rtol=0.0):
    """The oracle check: equal results (to ``rtol``), or the same error."""
    assert got[0] == expected[0], (got, expected)
    if got[0] == "error":
        assert got[1] == expected[1]
        return
    got_arrays, expected_arrays = list(_arrays_in(got[1])), list(_arrays_in(expected[1]))
    assert len(got_arrays) == len(expected_arrays)
    for a, b in zip(got_arrays, expected_arrays):
        np.testing.assert_allclose(a, b, rtol=rtol, atol=0)


# ---- Platform (the compiled kernel), in its own interpreter --------------------------

PLAT = stewart.Platform.preset("narayan2017")
TWO_THREADS = stewart.Platform(PLAT.params, threads=2)
PARAMS = PLAT.params
SINGLE = valid_arguments(PLAT)
BATCH = valid_arguments(PLAT, 3, seed=1)


@st.composite
def platform_calls(draw):
    """A Platform method and its arguments: some valid, some in another layout, some junk."""
    method = draw(st.sampled_from(sorted(PLATFORM_METHODS)))
    names = PLATFORM_METHODS[method]
    valid = draw(st.sampled_from([SINGLE, BATCH]))
    args, plain, fuzzed = [], [], False
    for name in names:
        kind = draw(st.sampled_from(["valid", "layout", "junk"]))
        if kind == "valid":
            args.append(valid[name])
            plain.append(valid[name])
        elif kind == "layout":
            value, oracle = draw(layouts(valid[name]))
            args.append(value)
            plain.append(oracle)
        else:
            args.append(draw(junk(valid[name])))
            fuzzed = True
    return method, names, args, None if fuzzed else plain


#: Examples run so far by the isolated fuzz functions below, printed for the parent test.
EXAMPLES_RUN = 0


def _example() -> None:
    global EXAMPLES_RUN
    EXAMPLES_RUN += 1


@fuzz_settings(400)
@given(platform_calls(), st.booleans(), st.booleans())
def fuzz_platform(call, return_mask, threads):
    """Every Platform method, on one thread or two, with and without ``return_mask``."""
    _example()
    method, names, args, plain = call
    plat = TWO_THREADS if threads else PLAT
    options = {"return_mask": True} if return_mask and method not in ("joint_reactions", "forward_kinematics") else {}
    got = kept_contract(lambda: getattr(plat, method)(*args, **options), names, mask=bool(options))
    if plain is not None:
        same_outcome(got, kept_contract(lambda: getattr(PLAT, method)(*plain, **options), names, mask=bool(options)))


@fuzz_settings(300)
@given(st.one_of(junk(SINGLE["x"]), junk(BATCH["x"])).filter(lambda v: not isinstance(getattr(v, "dtype", v), complex)
                                                                 and getattr(getattr(v, "dtype", None), "kind", "") != "c"))
def fuzz_one_definition_of_a_state(x):
    """The kernel and the numpy kinematics accept and refuse the same real inputs, with the
    same message (one definition, ``stewart.model.arguments.state_array``), and agree where both answer."""
    _example()
    kernel = kept_contract(lambda: PLAT.jacobian(x), ("x",))
    numpy = kept_contract(lambda: stewart.jacobian(PARAMS, x), ("x",))
    refused = [outcome[1] for outcome in (kernel, numpy) if outcome[0] == "error" and outcome[1].startswith("ValueError: x:")
               and "leg" not in outcome[1]]
    if refused:
        assert kernel == numpy, (kernel, numpy)
    elif kernel[0] == numpy[0] == "ok":
        # J_C's entries are unit vectors and moment arms, bounded whatever the pose: reached 3.3e-16
        np.testing.assert_allclose(kernel[1], numpy[1], rtol=0, atol=3e-14)


#: A general model (a payload off-centre) with friction in every leg, and its valid arguments.
GENERAL = stewart.Platform(PARAMS.with_payload(0.5, [0.01, -0.02, 0.03], [1e-3, 2e-3, 3e-3]).replace(
    viscous_friction=np.full(6, 20.0), coulomb_friction=np.full(6, 1.5)))
GENERAL_SINGLE, GENERAL_BATCH = valid_arguments(GENERAL), valid_arguments(GENERAL, 3, seed=2)
#: Platform methods beyond :data:`conftest.PLATFORM_METHODS`'s kernel functions: the regressor,
#: the friction the Python layer adds, RK4 steps (with their Jacobians) and the derivatives,
#: fuzzed on the preset and on :data:`GENERAL`.
EXTRA_METHODS = {
    "regressor": ("x", "xd", "xdd"),
    "friction_forces": ("x", "xd"),
    "actuator_forces": ("x", "xd", "xdd"),
    "rk4_step": ("x", "xd", "tau", "dt"),
    "inverse_dynamics_derivatives": ("x", "xd", "xdd"),
    "forward_dynamics_derivatives": ("x", "xd", "tau"),
}


@fuzz_settings(80)
@given(st.sampled_from(sorted(EXTRA_METHODS)), st.booleans(), st.booleans(), st.booleans(), st.data())
def fuzz_platform_extras(method, general, return_mask, jacobians, data):
    """The regressor, friction and actuator forces, RK4 steps and the derivatives, with and
    without ``return_mask``: the contract, and the oracle for valid values in other layouts."""
    _example()
    plat = GENERAL if general else PLAT
    valid = data.draw(st.sampled_from([GENERAL_SINGLE, GENERAL_BATCH] if general else [SINGLE, BATCH]))
    names = EXTRA_METHODS[method]
    args, plain, fuzzed = [], [], False
    for name in names:
        kind = data.draw(st.sampled_from(["valid", "layout", "junk"]))
        if name == "dt":
            value = 1e-3 if kind != "junk" else data.draw(scalars())
            args.append(value)
            plain.append(value)
            fuzzed |= kind == "junk"
        elif kind == "valid":
            args.append(valid[name])
            plain.append(valid[name])
        elif kind == "layout":
            value, oracle = data.draw(layouts(valid[name]))
            args.append(value)
            plain.append(oracle)
        else:
            args.append(data.draw(junk(valid[name])))
            fuzzed = True
    options = {"return_mask": True} if return_mask else {}
    if method == "rk4_step":
        options["jacobians"] = jacobians
    got = kept_contract(lambda: getattr(plat, method)(*args, **options), names, mask=return_mask)
    if not fuzzed:
        same_outcome(got, kept_contract(lambda: getattr(plat, method)(*plain, **options), names, mask=return_mask))


#: Fuzz functions that reach the compiled kernel; ``test_isolated`` runs each in a fresh
#: interpreter, so that a crash (the kernel once segfaulted on 0-d arrays) fails the test.
ISOLATED = ["fuzz_platform", "fuzz_one_definition_of_a_state", "fuzz_controllers", "fuzz_parameter_fields",
            "fuzz_platform_extras"]


@pytest.mark.slow
@pytest.mark.parametrize("name", ISOLATED)
def test_isolated(name):
    result = subprocess.run(
        [sys.executable, "-c", f"import test_fuzz; test_fuzz.{name}(); print(test_fuzz.EXAMPLES_RUN)"],
        capture_output=True, text=True, timeout=600, cwd=Path(__file__).parent,
        env={**os.environ, "PYTHONPATH": str(Path(__file__).parent)},
    )
    assert result.returncode == 0, f"exit {result.returncode}\n{result.stdout}\n{result.stderr[-5000:]}"
    assert int(result.stdout.split()[-1]) > 0


# ---- the numpy modules: kinematics, reference, Newton-Euler ------------------------

KINEMATICS = {
    "rotation": (stewart.rotation, ("x",)),
    "euler_rate_jacobian": (stewart.euler_rate_jacobian, ("x",)),
    "twist_transform": (stewart.twist_transform, ("x",)),
    "leg_vectors": (stewart.leg_vectors, ("params", "x")),
    "leg_lengths": (stewart.leg_lengths, ("params", "x")),
    "leg_unit_vectors": (stewart.leg_unit_vectors, ("params", "x")),
    "jacobian": (stewart.jacobian, ("params", "x")),
    "euler_jacobian": (stewart.euler_jacobian, ("params", "x")),
    "leg_velocities": (stewart.leg_velocities, ("params", "x", "xd")),
    "forward_kinematics": (stewart.forward_kinematics, ("params", "lengths", "guess")),
    "reference.mass_matrix": (reference.mass_matrix, ("params", "x")),
    "reference.coriolis_matrix": (reference.coriolis_matrix, ("params", "x", "xd")),
    "reference.coriolis_vector": (reference.coriolis_vector, ("params", "x", "xd")),
    "reference.gravity_vector": (reference.gravity_vector, ("params", "x")),
    "reference.inverse_dynamics": (reference.inverse_dynamics, ("params", "x", "xd", "xdd")),
    "reference.forward_dynamics": (reference.forward_dynamics, ("params", "x", "xd", "tau")),
    "reference.momenta": (reference.momenta, ("params", "x", "xd")),
    "reference.body_terms": (reference.body_terms, ("params", "x", "xd")),
    "reference.partial_velocity_jacobians": (reference.partial_velocity_jacobians, ("params", "x")),
    "reference.rotational_inertias": (reference.rotational_inertias, ("params", "x")),
    "newton_euler.inverse_dynamics": (stewart.oracles.newton_euler.inverse_dynamics, ("params", "x", "xd", "xdd")),
    "newton_euler.joint_reactions": (stewart.oracles.newton_euler.joint_reactions, ("params", "x", "xd", "xdd")),
}
NOT_PARAMS = [None, {}, PARAMS.to_dict(), PLAT, "narayan2017", 1.0]


@fuzz_settings(250)
@given(st.sampled_from(sorted(KINEMATICS)), st.data())
def test_numpy_functions_keep_the_contract(function, data):
    call, names = KINEMATICS[function]
    valid = data.draw(st.sampled_from([SINGLE, BATCH]))
    args, plain, fuzzed = [], [], False
    for name in names:
        if name == "params":
            value = data.draw(st.sampled_from([PARAMS] * 4 + NOT_PARAMS))
            args.append(value)
            plain.append(value)
            fuzzed |= value is not PARAMS
            continue
        kind = data.draw(st.sampled_from(["valid", "layout", "junk"]))
        if kind == "valid":
            args.append(valid[name])
            plain.append(valid[name])
        elif kind == "layout":
            value, oracle = data.draw(layouts(valid[name]))
            args.append(value)
            plain.append(oracle)
        else:
            args.append(data.draw(junk(valid[name])))
            fuzzed = True
    got = kept_contract(lambda: call(*args), names)
    if not fuzzed:
        # entry by entry, and an entry may cancel: another layout's order of the sums moved one of
        # reference.momenta's by 2.5e-14 of itself (2.1e-16 at most on the examples of another run)
        same_outcome(got, kept_contract(lambda: call(*plain), names), rtol=1e-12)


@fuzz_settings(60)
@given(st.one_of(st.sampled_from(EDGE_FLOATS), scalars()), st.sampled_from([PARAMS] * 3 + NOT_PARAMS))
def test_home_pose_keeps_the_contract(leg_length, params):
    kept_contract(lambda: stewart.home_pose(params, leg_length), ("params", "leg_length"))


@fuzz_settings(60)
@given(scalars(), st.one_of(scalars(), st.integers(-5, 20)))
def test_forward_kinematics_options_keep_the_contract(tol, max_iter):
    kept_contract(lambda: stewart.forward_kinematics(PARAMS, SINGLE["lengths"], tol=tol, max_iter=max_iter),
                  ("tol", "max_iter"))


# ---- parameters and parameter files ------------------------------------------------

FIELDS = [field.name for field in dataclasses.fields(PlatformParams)]


@fuzz_settings(250)
@given(st.dictionaries(st.sampled_from(FIELDS), st.one_of(scalars(), st.builds(_deep, st.integers(2, 80))),
                       min_size=1, max_size=3))
def fuzz_parameter_fields(changes):
    """PlatformParams fields, then the compiled model of what they accept (isolated)."""
    _example()
    outcome = kept_contract(lambda: PARAMS.replace(**changes), FIELDS)
    if outcome[0] == "ok":
        params = outcome[1]
        assert _finite(tuple(v for v in dataclasses.astuple(params) if isinstance(v, (np.ndarray, float))))
        kept_contract(lambda: stewart.Platform(params).inverse_dynamics(*(valid_arguments(PLAT)[n] for n in ("x", "xd", "xdd"))),
                      ("x",))


@fuzz_settings(150)
@given(st.one_of(
    st.dictionaries(st.one_of(st.sampled_from(FIELDS), st.text(max_size=5), st.integers()), scalars(), max_size=14),
    st.builds(lambda extra: {**PARAMS.to_dict(), **extra},
              st.dictionaries(st.one_of(st.sampled_from(FIELDS), st.text(max_size=5)), scalars(), max_size=2)),
    st.sampled_from(OBJECTS),
))
def test_from_dict_keeps_the_contract(data):
    names = FIELDS + ["data", "parameter field"]
    kept_contract(lambda: PlatformParams.from_dict(data), names)


def _mutated(text: bytes, edits) -> bytes:
    out = bytearray(text)
    for position, byte, action in edits:
        position %= max(len(out), 1)
        if action == 0:
            out.insert(position, byte)
        elif action == 1 and out:
            del out[position]
        elif out:
            out[position] = byte
    return bytes(out)


VALID_FILES = {
    "toml": dumps_toml(PARAMS.to_dict()).encode(),
    "json": json.dumps(PARAMS.to_dict()).encode(),
}


@fuzz_settings(250)
@given(
    st.sampled_from(["toml", "json"]),
    st.one_of(
        st.lists(st.tuples(st.integers(0, 10**6), st.integers(0, 255), st.integers(0, 2)), min_size=1, max_size=8),
        st.binary(max_size=200),
        st.integers(10, 200_000),
    ),
)
def test_parameter_files_keep_the_contract(fmt, content):
    if isinstance(content, list):
        text = _mutated(VALID_FILES[fmt], content)
    elif isinstance(content, int):  # nesting
        text = (b"a = " if fmt == "toml" else b"") + b"[" * content + b"]" * content
    else:
        text = content
    with tempfile.TemporaryDirectory() as directory:
        path = Path(directory) / f"params.{fmt}"
        path.write_bytes(text)
        kept_contract(lambda: PlatformParams.load(path), (str(path),))


PI = PARAMS.inertial_vector()
GENERAL_PI = GENERAL.params.inertial_vector()


def _scaled(vector: np.ndarray, factor: float) -> np.ndarray:
    with np.errstate(over="ignore", invalid="ignore"):
        return vector * factor


@fuzz_settings(120)
@given(st.dictionaries(st.sampled_from(FIELDS), scalars(), max_size=2),
       st.one_of(st.sampled_from([PI, GENERAL_PI]), perturbed(PI), perturbed(GENERAL_PI), junk(PI),
                 st.builds(_scaled, st.sampled_from([PI, GENERAL_PI]), st.sampled_from(EDGE_FLOATS))))
def test_inertial_vectors_keep_the_contract(changes, pi):
    """inertial_vector of any parameter set that is accepted is finite, and
    with_inertial_vector takes a vector back to parameters with that vector (the oracle) or
    refuses it naming ``pi``."""
    outcome = kept_contract(lambda: PARAMS.replace(**changes), FIELDS)
    params = outcome[1] if outcome[0] == "ok" else PARAMS
    own = kept_contract(params.inertial_vector, ())
    assert own[0] == "ok" and own[1].shape == PI.shape
    back = kept_contract(lambda: params.with_inertial_vector(pi), ("pi",))
    if back[0] == "ok":
        # reached 1.3e-16 (relative) and 2.6e-19 of the largest entry; the atol for an entry
        # that cancels (a moment about the centre of mass, from one about the origin)
        np.testing.assert_allclose(back[1].inertial_vector(), pi, rtol=1e-14, atol=1e-14 * np.max(np.abs(pi)))


# ---- controllers and trajectories --------------------------------------------------

CONTROLLERS = {
    "PID": (stewart.PID, ("kp", "ki", "kd")),
    "ComputedTorque": (stewart.ComputedTorque, ("kp", "kd")),
    "Actuators": (stewart.Actuators, ("force_limit", "viscous", "coulomb", "coulomb_velocity")),
    "PID.tuned": (stewart.PID.tuned, ("platform", "bandwidth_hz")),
    "ComputedTorque.tuned": (stewart.ComputedTorque.tuned, ("bandwidth_hz",)),
    "leg_masses": (leg_masses, ("platform", "x")),
}
VALID_CONTROL = {"kp": 100.0, "ki": np.full(6, 5.0), "kd": 10.0, "force_limit": np.inf, "viscous": 1.0,
                 "coulomb": 0.5, "coulomb_velocity": 1e-3, "platform": PLAT, "bandwidth_hz": 3.0, "x": PLAT.home_pose}


@fuzz_settings(200)
@given(st.sampled_from(sorted(CONTROLLERS)), st.data())
def fuzz_controllers(name, data):
    """Controllers, actuators and their tuning, which evaluates the compiled model (isolated)."""
    _example()
    build, names = CONTROLLERS[name]
    args = []
    for arg in names:
        if data.draw(st.booleans()):
            args.append(VALID_CONTROL[arg])
        elif arg == "platform":
            args.append(data.draw(st.sampled_from([PARAMS] + NOT_PARAMS)))
        else:
            args.append(data.draw(st.one_of(scalars(), junk(np.full(6, 10.0)))))
    outcome = kept_contract(lambda: build(*args), names)
    if outcome[0] == "ok" and name != "leg_masses":
        for field, value in dataclasses.asdict(outcome[1]).items():
            if value is None:  # an Actuators value left to the platform's parameters
                continue
            value = np.asarray(value)
            if field == "force_limit":  # +inf: no limit
                value = value[~np.isposinf(value)]
            assert np.all(np.isfinite(value)), (field, value)


@fuzz_settings(200)
@given(st.data())
def test_trajectories_keep_the_contract(data):
    home = PLAT.home_pose
    if data.draw(st.booleans()):
        names = ("start", "goal", "duration", "profile")
        args = [
            data.draw(st.one_of(st.just(home), junk(home))),
            data.draw(st.one_of(st.just(home + 0.01), junk(home))),
            data.draw(st.one_of(st.just(2.0), scalars())),
            data.draw(st.sampled_from(["sinusoidal", "quintic", "cubic", None, 1, ["quintic"]])),
        ]
        outcome = kept_contract(lambda: stewart.PointToPoint(*args), names)
    else:
        names = ("times", "poses")
        poses = random_states(PARAMS, 4, np.random.default_rng(3))[0]
        times = np.array([0.0, 0.5, 1.2, 2.0])
        args = [data.draw(st.one_of(st.just(times), junk(None), perturbed(times))),
                data.draw(st.one_of(st.just(poses), junk(poses)))]
        outcome = kept_contract(lambda: stewart.SampledTrajectory(*args), names)
    if outcome[0] == "ok":
        t = data.draw(st.one_of(st.sampled_from(EDGE_FLOATS), scalars(), hnp.arrays(np.float64, (5,))))
        kept_contract(lambda: outcome[1].sample(t), ("t",))


# ---- identification, envelopes, workspaces, sweeps, excitation, the instruction-set path ----

HOME = PLAT.home_pose
_AMPLITUDES = np.array([0.003] * 3 + [0.02] * 3)[:, None]
_RNG = np.random.default_rng(0)
#: A periodic motion that excites every base parameter.
EXCITING = stewart.motion.trajectory.FourierTrajectory(HOME, 2.0, _RNG.normal(size=(6, 3)) * _AMPLITUDES,
                                                _RNG.normal(size=(6, 3)) * _AMPLITUDES)


@functools.cache
def _identify():
    """stewart.identification.identify, imported when first needed (scipy.signal takes a second to import,
    which each interpreter of ``test_isolated`` would pay)."""
    from stewart.identification import identify

    return identify


@functools.cache
def _log():
    """A 2 s log of :data:`GENERAL` (the preset with a payload and friction) following
    :data:`EXCITING` at 100 Hz."""
    return _identify().synthetic_measurements(GENERAL, EXCITING, rate=100.0)


NOT_PLATFORMS = [PARAMS, None, "narayan2017", {}, 1.0]
#: Sample counts and seeds: small ones that run in milliseconds, and ones refused.
SMALL_COUNTS = st.one_of(st.integers(1, 300),
                         st.sampled_from([0, -1, 10**13, 2**70, 1.5, "10", True, None, np.int64(40), np.float64(3.0)]))
SEEDS = st.one_of(st.integers(0, 3), st.sampled_from([-1, 2**70, 1.5, "1", None, True, np.uint8(2)]))
#: Steps of time: ordinary ones, and edge values and junk (no positive step below 1e-5 s but the
#: edge values, so that a step that is accepted samples a short move in milliseconds).
STEPS = st.one_of(st.sampled_from([0.01, 0.002]), st.sampled_from(EDGE_FLOATS), st.sampled_from(OBJECTS), arrays(),
                  st.floats(max_value=0.0), st.floats(min_value=1e-5, max_value=1e6))


def _mostly(draw) -> bool:
    """True three times in four (Hypothesis draws small integers most)."""
    return draw(st.integers(0, 3)) < 3


def _platform(draw, valid=PLAT, *others):
    """``valid`` mostly, else one of ``others`` or what is not a platform."""
    return valid if _mostly(draw) else draw(st.sampled_from(list(others) + NOT_PLATFORMS))


def _pick(draw, valid, *more):
    """``valid`` mostly, else junk for it (or one of ``more``)."""
    if _mostly(draw):
        return valid
    options = [junk(valid)] if isinstance(valid, np.ndarray) else [scalars()]
    if isinstance(valid, np.ndarray) and valid.dtype.kind == "f":
        options += [perturbed(valid), st.builds(_scaled, st.just(valid), st.sampled_from(EDGE_FLOATS))]
    if more:
        options.append(st.sampled_from(more))
    return draw(st.one_of(*options))


@settings(fuzz_settings(25), deadline=10_000)  # an identification that runs takes about half a second
@given(st.data())
def test_identification_keeps_the_contract(data):
    """Measurements from any columns, then identify from any platform, filter and cut-off:
    finite estimates, or a ValueError naming the argument."""
    draw, identify, good = data.draw, _identify(), _log()
    columns = (_pick(draw, good.t), _pick(draw, good.lengths), _pick(draw, good.forces))
    made = kept_contract(lambda: identify.Measurements(*columns), ("t", "lengths", "forces", "measurements"))
    if made[0] == "ok":
        assert 0 < made[1].rate < np.inf
    log = made[1] if made[0] == "ok" else draw(st.sampled_from([good, None, good.t, "log.csv"]))
    platform = _platform(draw)
    options = {"filter": draw(st.sampled_from(["savgol", "butterworth"])) if _mostly(draw) else
               draw(st.sampled_from(["median", None, 3, ["savgol"]])),
               "cutoff": _pick(draw, 10.0, 5.0, 49.0, 50.0, 1e-310)}
    outcome = kept_contract(lambda: identify.identify(platform, log, **options),
                            ("platform", "measurements", "filter", "cutoff", "t"))
    if outcome[0] == "ok":
        result = outcome[1]
        assert _finite((result.estimates, result.standard_errors, result.residual_rms, result.condition_number))


#: A half-second vehicle log at 50 Hz: a braking and a turn setting in.
_T = np.arange(26) * 0.02
CUEING_LOG = (_T, np.column_stack([-3.0 * np.tanh(4 * _T), 2.0 * _T, np.full(26, 9.81)]),
              np.column_stack([np.zeros(26), 0.1 * _T, 0.3 * _T]))


@settings(fuzz_settings(150), deadline=10_000)  # the first example imports stewart.cueing (scipy.signal)
@given(st.data())
def test_vehicle_logs_keep_the_contract(data):
    """A VehicleLog from any columns and name: finite columns with time rising at one rate, or a
    ValueError naming the log and the column (or the name)."""
    draw = data.draw
    t, f, w = (_pick(draw, value) for value in CUEING_LOG)
    name = draw(st.sampled_from(["fuzz log"] * 3 + [None, 3, b"log"]))
    outcome = kept_contract(lambda: stewart.cueing.VehicleLog(t, f, w, name=name), ("fuzz log", "name"))
    if outcome[0] == "ok":
        log = outcome[1]
        assert log.t.shape == (len(log.t),) and log.f.shape == log.w.shape == (len(log.t), 3)
        steps = np.diff(log.t)
        # the log's own test of an even rate: the steps may differ by that much
        assert np.all(steps > 0) and np.allclose(steps, log.dt, rtol=stewart.cueing.log.RATE_TOLERANCE, atol=0)


@settings(fuzz_settings(40), deadline=10_000)  # an MPC run takes about a tenth of a second
@given(st.sampled_from(["washout", "mpc"]), st.data())
def test_cueing_keeps_the_contract(method, data):
    """Washout and MPC cueing of any log (a VehicleLog of any columns, a path, or no log), on any
    platform with any settings and flags: a finite reference, or an error naming the argument;
    a reference reported inside every limit is inside."""
    draw, cueing = data.draw, stewart.cueing
    columns = tuple(_pick(draw, value) for value in CUEING_LOG)
    made = kept_contract(lambda: cueing.VehicleLog(*columns, name="fuzz log"), ("fuzz log",))
    log = made[1] if made[0] == "ok" else draw(st.sampled_from(OBJECTS + ["no-such-log.csv", Path("no-such-log.csv")]))
    settings_type = cueing.WashoutParams if method == "washout" else cueing.MPCParams
    params = None if _mostly(draw) else draw(st.sampled_from([settings_type(), *OBJECTS, PARAMS]))
    flags = {"simulate": draw(st.sampled_from([False] * 3 + [True, None, "yes", 1]))}
    if method == "mpc":
        flags["progress"] = draw(st.sampled_from([False] * 3 + [None, "no"]))
    function = getattr(cueing, method)
    outcome = kept_contract(lambda: function(log, _platform(draw), params, **flags),
                            ("log", "platform", "params", "simulate", "progress", "no-such-log.csv"))
    if outcome[0] == "ok":
        result = outcome[1]
        assert _finite((result.poses, result.velocities, result.accelerations))
        if result.exit_code == 0:
            assert result.inside and not result.beyond_limits and not result.problems


MOVE = stewart.PointToPoint(HOME, HOME + [0.01, 0, 0, 0, 0.02, 0], 0.002)
BOX = {"lower": HOME - 0.01, "upper": HOME + 0.01, "velocity": np.full(6, 0.1), "acceleration": np.full(6, 1.0)}


@fuzz_settings(40)
@given(st.sampled_from(["box", "trajectories", "around"]), st.data())
def test_envelopes_keep_the_contract(kind, data):
    """A box, trajectories or the box around a move from any values, then its envelope for any
    platform, sample count and seed: finite peaks (or -inf where no state counted), or a
    ValueError naming the argument."""
    draw = data.draw
    if kind == "box":
        fields = {name: _pick(draw, valid) for name, valid in BOX.items()}
        spec = kept_contract(lambda: envelope.Box(**fields), tuple(fields))
    elif kind == "trajectories":
        motions = draw(st.sampled_from([[MOVE], [MOVE, EXCITING], (), [HOME], MOVE, None, [MOVE, 3]]))
        spec = kept_contract(lambda: envelope.Trajectories(motions, draw(STEPS)), ("motions", "dt"))
    else:
        motion, margin = draw(st.sampled_from([MOVE] * 3 + [HOME, None])), _pick(draw, 0.2)
        spec = kept_contract(lambda: envelope.Box.around(motion, margin, draw(STEPS)), ("motion", "margin", "dt"))
    if spec[0] != "ok":
        return
    samples = draw(SMALL_COUNTS.filter(lambda n: n is not None)) if kind != "trajectories" else \
        draw(st.sampled_from([None] * 4 + [10, 0]))
    platform = _platform(draw, PLAT, GENERAL, GENERAL.params)
    options = {"samples": samples, "seed": draw(SEEDS), "chunk_size": draw(st.sampled_from([64, 1000, 0, 1.5, None])),
               "progress": False}
    outcome = kept_contract(lambda: envelope.envelope(platform, spec[1], **options),
                            ("platform", "spec", "samples", "seed", "chunk_size"))
    if outcome[0] == "ok":
        result = outcome[1]
        counted = result.states - result.outside_stroke - result.singular
        peaks = result.peak.value
        assert np.all(np.isfinite(peaks)) if counted else np.all(np.isneginf(peaks)), (counted, peaks)


REGIONS = {"translational": np.array([[-0.05, 0.05], [-0.05, 0.05], [0.2, 0.35]]),
           "orientation": np.array([[-0.3, 0.3], [-0.3, 0.3], [-0.3, 0.3]])}
GRIDS = st.one_of(st.integers(-1, 10), st.sampled_from([1001, 10**6, 2.0, "5", None, True]))


@fuzz_settings(50)
@given(st.sampled_from(["translational", "orientation", "slice", "reachability", "position_bounds"]), st.data())
def test_workspaces_keep_the_contract(kind, data):
    """The workspaces, slices, reachability and position bounds for any platform, region,
    sample count or grid: finite volumes and margins (NaN margins only when nothing is
    reachable), or a ValueError naming the argument."""
    draw = data.draw
    platform = _platform(draw, PLAT, PARAMS, GENERAL.params)
    if kind in ("translational", "orientation"):
        fixed = {"orientation": _pick(draw, np.zeros(3))} if kind == "translational" else \
            {"position": draw(st.one_of(st.none(), st.just(HOME[:3]), junk(HOME[:3])))}
        region = draw(st.sampled_from([None, REGIONS[kind]]))
        region = region if region is None or draw(st.integers(0, 2)) else _pick(draw, region)
        counts = {"samples": draw(SMALL_COUNTS)} if draw(st.booleans()) else {"grid": draw(GRIDS)}
        if draw(st.integers(0, 5)) == 0:
            counts = {"samples": draw(SMALL_COUNTS), "grid": draw(GRIDS)}
        study = workspace.translational_workspace if kind == "translational" else workspace.orientation_workspace
        options = {**fixed, **counts, "region": region, "seed": draw(SEEDS),
                   "chunk_size": draw(st.sampled_from([20_000, 50, 0, -1, 2.5])), "progress": False}
        outcome = kept_contract(lambda: study(platform, **options), ("platform", *options))
        if outcome[0] == "ok":
            result = outcome[1]
            assert _finite((result.volume, result.volume_error)) and 0 <= result.volume
            margins = (result.margin_min, result.margin_mean, result.margin_max)
            assert _finite(margins) if result.reachable else np.all(np.isnan(margins))
    elif kind == "slice":
        options = {"axes": draw(st.sampled_from(["xy", "x,z", ("psi", "theta"), "xx", "ab", None, 5, ["y", "z"]])),
                   "at": draw(st.one_of(st.none(), scalars())),
                   "region": draw(st.one_of(st.none(), st.just(REGIONS["translational"][:2]),
                                                junk(REGIONS["translational"][:2]),
                                                perturbed(REGIONS["translational"][:2]))),
                   "resolution": draw(st.one_of(st.integers(-1, 12), st.sampled_from([2001, 10**6, 1.5, "3"])))}
        outcome = kept_contract(lambda: workspace.workspace_slice(platform, **options), ("platform", *options))
        if outcome[0] == "ok":
            result = outcome[1]
            assert np.all(np.isfinite(result.margin) | (result.flags != 0)) and _finite((result.u, result.v))
    elif kind == "reachability":
        poses = draw(st.one_of(st.just(BATCH["x"]), junk(BATCH["x"]), perturbed(BATCH["x"])))
        outcome = kept_contract(lambda: workspace.reachability(platform, poses), ("platform", "poses"))
        if outcome[0] == "ok":
            assert np.all((outcome[1].flags == 0) <= np.isfinite(outcome[1].margin))
    else:
        orientation = _pick(draw, np.zeros(3))
        kept_contract(lambda: workspace.position_bounds(platform, orientation), ("platform", "params", "orientation",
                                                                              "region"))


SWEEP = {"preset": "narayan2017", "parameters": {"base_radius": [0.09, 0.11]},
         "envelope": {"lower": [0] * 6, "upper": [0.0, 0.0, 0.01, 0.0, 0.0, 0.0], "velocity": [0.1] + [0] * 5,
                      "acceleration": [1] + [0] * 5, "samples": 20},
         "workspace": {"samples": 50}, "pareto": {"x": "workspace_volume", "y": "peak_force"}}
#: Values a TOML file can hold, small enough for a sweep to run in milliseconds.
TOML_VALUES = st.recursive(
    st.one_of(st.integers(-3, 4), st.floats(), st.sampled_from(EDGE_FLOATS), st.text(max_size=6), st.booleans(),
              st.sampled_from(["random", "grid", "narayan2017", "peak_force", "base_radius", "stroke"])),
    lambda inner: st.one_of(st.lists(inner, max_size=3), st.dictionaries(
        st.sampled_from(["low", "high", "count", "samples", "x", "y", "lower", "upper", "base_radius", "payload_mass"]),
        inner, max_size=3)),
    max_leaves=6)



@fuzz_settings(150)
@given(st.data())
def test_clearances_keep_the_contract(data):
    """Any plate radius, base clearance and leg diameter, any platform and poses: the platform's
    gaps above the base (finite) and the legs' crossings of the plate (NaN below it, else
    finite and >= 0), and the workspace check of them; or an error naming the field or
    argument."""
    draw = data.draw
    fields = ("plate_radius", "base_clearance", "leg_diameter")
    changes = {name: draw(st.one_of(st.none(), st.floats(0.01, 1.0), scalars())) for name in fields}
    outcome = kept_contract(lambda: PARAMS.replace(**changes), fields)
    if outcome[0] != "ok":
        return
    platform = _platform(draw, outcome[1], PLAT)
    poses = draw(st.one_of(st.just(BATCH["x"]), st.just(SINGLE["x"]), junk(BATCH["x"]), perturbed(BATCH["x"])))

    def measured():
        crossings = workspace_reachability.plate_crossings(platform, poses)
        assert np.all(np.isnan(crossings) | (crossings >= 0.0))
        return workspace_reachability.base_gaps(platform, poses), np.nan_to_num(crossings, nan=-1.0, posinf=np.inf)

    kept_contract(measured, ("params", "poses"))
    checked = kept_contract(lambda: workspace.reachability(platform, poses).flags, ("platform", "poses"))
    if checked[0] == "ok" and outcome[1].base_clearance is not None and platform is outcome[1]:
        gaps = workspace_reachability.base_gaps(platform, np.atleast_2d(poses))
        assert np.all((checked[1] & workspace_reachability.BELOW_BASE != 0) == (gaps < outcome[1].base_clearance))

@fuzz_settings(40)
@given(st.lists(st.tuples(st.sampled_from([("preset",), ("method",), ("designs",), ("seed",), ("params",), ("bogus",),
                                           ("parameters",), ("parameters", "base_radius"), ("parameters", "stroke"),
                                           ("parameters", "payload_mass"), ("envelope",), ("envelope", "upper"),
                                           ("envelope", "velocity"), ("envelope", "samples"), ("workspace",),
                                           ("workspace", "samples"), ("pareto",), ("pareto", "x")]),
                          st.one_of(TOML_VALUES, st.just(None))), max_size=3))
def test_sweeps_keep_the_contract(changes):
    """A sweep file's fields set to any TOML values (or left out), then the sweep: finite
    metrics (a NaN margin only with no reachable pose, a -inf peak only with no state
    counted, the modal metrics NaN as the file gives no leg stiffness), or a ValueError naming
    the field."""
    spec = json.loads(json.dumps(SWEEP))
    for path, value in changes:
        table = spec
        for key in path[:-1]:  # a field within a table: the table, made anew if it is not one
            if not isinstance(table.get(key), dict):
                table[key] = {}
            table = table[key]
        if value is None:
            table.pop(path[-1], None)
        else:
            table[path[-1]] = value
    fields = ("data", "preset", "params", "method", "designs", "seed", "parameters", "envelope", "workspace", "pareto")
    parsed = kept_contract(lambda: sweep.parse(spec), fields)
    if parsed[0] == "ok" and len(parsed[1].designs) <= 4:
        run = kept_contract(lambda: sweep.sweep(parsed[1], progress=False), ("spec",))
        assert run[0] == "ok", run
        metrics = run[1].metrics
        for name, values in metrics.items():
            if name == "margin_mean":
                allowed = np.isnan(values) & (metrics["workspace_volume"] == 0)
            elif name in sweep.MODAL_METRICS:
                assert parsed[1].stiffness is None and np.all(np.isnan(values)), (name, values)
                continue
            else:
                allowed = np.isneginf(values) if name.startswith("peak_") else np.zeros(values.shape, bool)
            assert np.all(np.isfinite(values) | allowed), (name, values)


@functools.cache
def _excitation_base():
    """The preset's base parameters (computed once, not by each design)."""
    from stewart.identification.base_parameters import base_parameters

    return base_parameters(PLAT)


@settings(fuzz_settings(10), deadline=10_000)  # a design that runs takes about half a second
@given(st.data())
def test_excitation_keeps_the_contract(data):
    """design_excitation from any arguments (a few SLSQP iterations): a finite design, or a
    ValueError naming the argument."""
    draw = data.draw

    def choose(valid, odd):
        return valid if _mostly(draw) else draw(odd)

    options = {"period": _pick(draw, 2.0), "harmonics": choose(2, GRIDS),
               "centre": choose(None, st.one_of(st.just(HOME), junk(HOME), perturbed(HOME))),
               "periods": choose(1, GRIDS), "samples": choose(None, st.sampled_from([12, 0, 1, 1.5])),
               "starts": choose(1, st.sampled_from([0, 1001, "1"])), "seed": draw(SEEDS),
               "max_iterations": choose(1, st.sampled_from([2, 0, 10**6, None])),
               **{name: draw(scalars()) for name in
                  ("max_leg_velocity", "max_leg_acceleration", "force_limit", "min_margin", "stroke_margin")
                  if not _mostly(draw)}}
    platform = _platform(draw)
    outcome = kept_contract(lambda: excitation.design_excitation(platform, base=_excitation_base(), **options),
                            ("platform", *options, "centre"))
    if outcome[0] == "ok":
        design = outcome[1]
        assert _finite((design.condition, design.initial_condition, design.scaled))
        assert _finite(design.trajectory.sample(np.linspace(0, design.trajectory.duration, 7)))


SIMD = stewart.build_info()


@fuzz_settings(30)
@given(st.one_of(st.sampled_from(SIMD["compiled"] + SIMD["supported"] + ["", "avx1024", "AVX2", "scalar "]),
                 st.text(max_size=8), st.sampled_from(OBJECTS)))
def test_set_simd_keeps_the_contract(path):
    """Any path name: the path it names runs (the same results, bit for bit), or a
    TypeError or ValueError naming ``path``; the path in use stays otherwise."""
    before = stewart.build_info()["simd"]
    expected = PLAT.inverse_dynamics(BATCH["x"], BATCH["xd"], BATCH["xdd"])
    try:
        outcome = kept_contract(lambda: stewart.set_simd(path), ("path",))
        now = stewart.build_info()["simd"]
        if outcome[0] == "ok":
            assert outcome[1] == before and now == (path or SIMD["supported"][-1])
        else:
            assert now == before
        assert np.array_equal(PLAT.inverse_dynamics(BATCH["x"], BATCH["xd"], BATCH["xdd"]), expected)
    finally:
        stewart.set_simd(before)


# ---- the command line: the studies' commands -------------------------------------------------

#: Where the command-line fuzz tests read and write their files (one directory a process,
#: removed at its exit).
CLI_DIR = Path(tempfile.mkdtemp(prefix="stewart-fuzz-"))
atexit.register(shutil.rmtree, CLI_DIR, ignore_errors=True)
#: Exit codes of the ``stewart`` command (``stewart --help``; not 130, Ctrl-C).
CLI_EXIT_CODES = {0, 1, 2, 3, 4, 5, 6}
#: Values a corrupted flag gets: small numbers, edge values, junk (no count large enough to run long).
CLI_VALUES = ["0", "-1", "1", "2", "3", "0.5", "nan", "inf", "-inf", "1e308", "5e-324", "1e-310", "abc", "", "--",
              "1e400", "0x10", "savgol", "motion_simulator"]
TARGET = ["0.01", "0", "0.27", "0", "0.02", "0"]


#: The input files of the command-line fuzz tests (:func:`_write_cli_files`).
FILES = {name: str(CLI_DIR / name) for name in ("log.csv", "bad.csv", "general.toml", "massless.toml", "broken.toml",
                                                "sweep.toml", "sweep_list.toml", "sweep_bad.toml")}


@functools.cache
def _write_cli_files() -> None:
    """Write :data:`FILES`, once, when a command-line test first runs."""
    files = FILES
    _log().to_csv(files["log.csv"])
    Path(files["bad.csv"]).write_text("t,L0\n0,1\n")
    GENERAL.params.save(files["general.toml"])
    PARAMS.replace(platform_mass=0.0, platform_inertia=(0, 0, 0), cylinder_mass=0.0, cylinder_inertia=(0, 0, 0),
                   piston_mass=0.0, piston_inertia=(0, 0, 0)).save(files["massless.toml"])
    Path(files["broken.toml"]).write_text("platform_mass = [\n")
    good = ('preset = "narayan2017"\n[parameters]\nbase_radius = [0.09, 0.11]\n[envelope]\nlower = [0, 0, 0, 0, 0, 0]\n'
            'upper = [0, 0, 0.01, 0, 0, 0]\nvelocity = [0.1, 0, 0, 0, 0, 0]\nacceleration = [1, 0, 0, 0, 0, 0]\n'
            'samples = 20\n[workspace]\nsamples = 50\n')
    Path(files["sweep.toml"]).write_text(good)
    Path(files["sweep_list.toml"]).write_text('workspace = ["samples"]\n'
                                              + good.replace("[workspace]\nsamples = 50\n", ""))
    Path(files["sweep_bad.toml"]).write_text(good.replace("base_radius = [0.09, 0.11]", "base_radius = [1.0]"))


OUT = {name: str(CLI_DIR / "out" / name) for name in ("a.csv", "a.json", "a.toml", "a.xml", "report.json", "c")}
(CLI_DIR / "out").mkdir()
(CLI_DIR / "cwd").mkdir()
#: Paths a positional argument or a file flag may get instead of a good one.
BAD_PATHS = [str(CLI_DIR / "missing.csv"), str(CLI_DIR), FILES["bad.csv"], FILES["broken.toml"], "", "-",
             str(CLI_DIR / "nowhere" / "x")]
PARAMS_FLAGS = [["--params", FILES["general.toml"]], ["--params", FILES["massless.toml"]],
                ["--params", FILES["broken.toml"]], ["--params", BAD_PATHS[0]], ["--preset", "motion_simulator"],
                ["--preset", "bogus"]]


@dataclasses.dataclass
class Command:
    """A command's good arguments: ``positional`` ones, ``flags`` with their values (those in
    ``required`` always given, the others sometimes left out; each value sometimes corrupted)."""

    positional: list
    flags: dict
    required: tuple = ()
    examples: int = 10
    deadline: int = 10_000  # ms an example (a hang ends at 20 s, time_limit)


COMMANDS = {
    "identify": Command([FILES["log.csv"]], {"--cutoff": ["10"], "--filter": ["butterworth"], "--no-friction": [],
                                             "--validate": [FILES["log.csv"]], "--report": [OUT["report.json"]],
                                             "--output": [OUT["a.toml"]]}, examples=6, deadline=10_000),
    "excitation": Command([], {"--period": ["2"], "--harmonics": ["2"], "--starts": ["1"], "--max-iterations": ["1"],
                               "--samples": ["12"], "--periods": ["1"], "--rate": ["20"], "--seed": ["0"],
                               "--centre": ["0", "0", "0.28", "0", "0", "0"], "--max-leg-velocity": ["0.5"],
                               "--force-limit": ["1000"], "--stroke-margin": ["0.1"], "--min-margin": ["0.01"],
                               "--csv": [OUT["a.csv"]], "--output": [OUT["a.toml"]], "--json": []},
                          required=("--harmonics", "--starts", "--max-iterations"), examples=4, deadline=10_000),
    "envelope": Command([], {"--target": TARGET, "--move-time": ["0.05"], "--dt": ["0.01"], "--margin": ["0.1"],
                             "--samples": ["50"], "--seed": ["1"], "--chunk-size": ["64"], "--csv": [OUT["a.csv"]],
                             "--json": [OUT["a.json"]], "--no-progress": []},
                        required=("--samples", "--no-progress"), examples=15),
    "envelope (box)": Command([], {"--lower": ["0", "0", "0.25", "0", "0", "0"],
                                   "--upper": ["0.01", "0", "0.3", "0", "0", "0.1"], "--velocity": ["0.1"] * 6,
                                   "--acceleration": ["1"] * 6, "--samples": ["50"], "--no-progress": []},
                              required=("--samples", "--no-progress"), examples=15),
    "workspace": Command([], {"--samples": ["200"], "--seed": ["1"], "--orientation": ["0", "0", "0.1"],
                              "--region": ["-0.05", "0.05", "-0.05", "0.05", "0.2", "0.35"], "--chunk-size": ["100"],
                              "--universal-max-angle": ["40"], "--leg-diameter": ["0.01"], "--csv": [OUT["a.csv"]],
                              "--json": [], "--no-progress": []}, required=("--samples",), examples=15),
    "workspace (orientation)": Command([], {"--kind": ["orientation"], "--grid": ["5"],
                                            "--position": ["0", "0", "0.28"],
                                            "--region": ["-0.3", "0.3", "-0.3", "0.3", "-0.3", "0.3"], "--json": []},
                                       required=("--kind", "--grid"), examples=10),
    "sweep": Command([FILES["sweep.toml"]], {"--json": [OUT["a.json"]], "--csv": [OUT["a.csv"]], "--no-progress": []},
                     examples=8),
    "export-mjcf": Command([], {"--output": [OUT["a.xml"]], "--pose": ["0", "0", "0.28", "0", "0.02", "0"],
                                "--solver": ["default"]}, examples=15),
    "c-export": Command([OUT["c"]], {}, examples=6),
    "export-acados": Command([OUT["c"]], {"--dt": ["0.01"], "--integrator": ["rk4"]}, required=("--dt",), examples=6),
    "optimize": Command([], {"--target": TARGET, "--move-time": ["1"], "--intervals": ["3"], "--max-iterations": ["40"],
                             "--force-limit": ["1000"], "--json": [], "--csv": [OUT["a.csv"]]},
                        required=("--intervals", "--max-iterations"), examples=6),
    "exactness": Command([], {"--states": ["10"], "--seed": ["0"], "--json": []}, required=("--states",), examples=8),
}
#: Other files a positional argument may name.
POSITIONAL_FILES = {"sweep": [FILES["sweep_list.toml"], FILES["sweep_bad.toml"], FILES["log.csv"]],
                    "identify": [FILES["general.toml"]]}


@st.composite
def command_lines(draw, name):
    """The arguments of a ``stewart`` command: its good ones, some left out or corrupted, and
    a few more flags of its own with random values."""
    command = COMMANDS[name]
    argv = [name.split()[0]]
    for value in command.positional:
        argv.append(value if _mostly(draw) else draw(st.sampled_from(BAD_PATHS + POSITIONAL_FILES.get(name, []))))
    for flag, values in command.flags.items():
        if flag not in command.required and not _mostly(draw):
            continue
        argv.append(flag)
        argv += [value if _mostly(draw) else draw(st.sampled_from(CLI_VALUES + BAD_PATHS[:2])) for value in values]
    if not _mostly(draw):
        argv += draw(st.sampled_from(PARAMS_FLAGS))
    extra = st.one_of(st.sampled_from(sorted(command.flags) + ["--bogus", "--params", "--preset"]),
                      st.sampled_from(CLI_VALUES))
    return argv + draw(st.lists(extra, max_size=draw(st.sampled_from([0, 0, 0, 3]))))


def run_command(argv: list[str]) -> tuple[int, str, str]:
    """Exit code, stdout and stderr of ``stewart argv`` run in this process, as in test_cli, in
    a directory of its own (a corrupted file name is relative: the command writes there)."""
    from stewart.cli import main

    _write_cli_files()
    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings(), contextlib.chdir(CLI_DIR / "cwd"), contextlib.redirect_stdout(out), \
            contextlib.redirect_stderr(err), time_limit(20):
        warnings.simplefilter("error", RuntimeWarning)
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        try:
            main(argv)
            code = 0
        except SystemExit as exc:
            code = exc.code
    return code, out.getvalue(), err.getvalue()


def kept_command_contract(argv: list[str]) -> int:
    """Run a command; check it succeeded, or failed with an exit code of its own, no
    traceback and an error naming the flag (or file) the user typed: argparse's usage and one
    line, or lines of its own (one for an input error)."""
    code, out, err = run_command(argv)
    command = argv[0]
    assert "Traceback" not in out + err, (argv, err)
    assert code in CLI_EXIT_CODES, (argv, code, err)
    if code:
        lines = err.strip().splitlines()
        assert lines, (argv, code, "no message")
        if lines[0].startswith("usage: "):  # argparse's: the usage, then one line naming the argument
            assert code == 2 and lines[-1].startswith(("stewart: error: ", f"stewart {command}: error: ")), (argv, err)
        else:
            assert all(line.startswith(f"stewart {command}: ") for line in lines), (argv, err)
            if code == 2:  # an input error: one line, naming the flag or the file
                message = lines[0].split(": error: ", 1)[1]
                named = ("--", "give ", "DIR ", "DATA.csv: ", "DESIGN.toml: ",
                         *(a for a in argv[1:] if a and not a.startswith("--")))
                assert len(lines) == 1 and message.startswith(named), (argv, err)
    return code


def _command_test(name: str):
    @settings(fuzz_settings(COMMANDS[name].examples), deadline=COMMANDS[name].deadline)
    @given(command_lines(name))
    def test(argv):
        kept_command_contract(argv)

    test.__doc__ = f"``stewart {name}`` with good, missing and corrupted arguments keeps the command-line contract."
    return test


test_cli_identify_keeps_the_contract = _command_test("identify")
test_cli_excitation_keeps_the_contract = _command_test("excitation")
test_cli_envelope_keeps_the_contract = _command_test("envelope")
test_cli_envelope_box_keeps_the_contract = _command_test("envelope (box)")
test_cli_workspace_keeps_the_contract = _command_test("workspace")
test_cli_orientation_workspace_keeps_the_contract = _command_test("workspace (orientation)")
test_cli_sweep_keeps_the_contract = _command_test("sweep")
test_cli_export_mjcf_keeps_the_contract = _command_test("export-mjcf")
test_cli_c_export_keeps_the_contract = _command_test("c-export")
test_cli_export_acados_keeps_the_contract = _command_test("export-acados")
test_cli_optimize_keeps_the_contract = _command_test("optimize")
test_cli_exactness_keeps_the_contract = _command_test("exactness")
