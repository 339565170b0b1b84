"""Property-based fuzzing of the Python API: random malformed and edge inputs at every
public function.

The contract every call must keep, whatever it is given:

* it returns within a few seconds (no hang) and does not crash the interpreter — the
  compiled kernel is fuzzed in a separate interpreter, so a crash fails the test;
* it returns finite values only, except rows a ``return_mask`` marks as failed;
* otherwise it raises ``ValueError`` or ``TypeError`` (the package's ``SingularityError``
  and ``ConvergenceError`` are ``ValueError``\\ s) whose message names the argument, or
  for a ``SingularityError`` the condition; it never leaks another exception type or a
  ``RuntimeWarning``;
* valid values in an unusual layout or dtype (big-endian, unaligned, strided, reversed,
  Fortran-ordered, read-only, float32, integers, nested lists) give the same result as
  the same values as a plain C-contiguous float64 array, the independent oracle.

The examples are derandomized, so a run is reproducible; ``STEWART_FUZZ_EXAMPLES=N``
raises the number of examples (and draws them at random) for a longer search.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
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
from stewart import ConvergenceError, PlatformParams, SingularityError, reference
from stewart.control import leg_masses
from stewart.paramfile import dumps_toml
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
    same message (one definition, ``_checks.state_array``), and agree where both answer."""
    _example()
    kernel = kept_contract(lambda: PLAT.jacobian(x), ("x",))
    numpy = kept_contract(lambda: stewart.jacobian(PARAMS, x), ("x",))
    refused = [outcome[1] for outcome in (kernel, numpy) if outcome[0] == "error" and outcome[1].startswith("ValueError: x:")
               and "leg" not in outcome[1]]
    if refused:
        assert kernel == numpy, (kernel, numpy)
    elif kernel[0] == numpy[0] == "ok":
        np.testing.assert_allclose(kernel[1], numpy[1], rtol=1e-9, atol=1e-12)


#: Fuzz functions that reach the compiled kernel; ``test_isolated`` runs each in a fresh
#: interpreter, so that a crash (the kernel once segfaulted on 0-d arrays) fails the test.
ISOLATED = ["fuzz_platform", "fuzz_one_definition_of_a_state", "fuzz_controllers", "fuzz_parameter_fields"]


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
    "newton_euler.inverse_dynamics": (stewart.newton_euler.inverse_dynamics, ("params", "x", "xd", "xdd")),
    "newton_euler.joint_reactions": (stewart.newton_euler.joint_reactions, ("params", "x", "xd", "xdd")),
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
