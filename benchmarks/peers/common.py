"""Helpers shared by the peer models: the runtime parameter vector, the C compiler
and timing."""

from __future__ import annotations

import importlib.util
import os
import shutil
import signal
import subprocess
import time

import numpy as np

from stewart import _kernel

#: The members of the C struct ``stewart_params``, (name, shape) in order: the generator's
#: parameter schema. The flat parameter vector holds them in this order, each row-major.
PARAM_FIELDS = _kernel.PARAM_FIELDS
#: Length of the flat parameter vector.
PARAM_COUNT = sum(int(np.prod(shape)) for _, shape in PARAM_FIELDS)

#: The compiler flags of our extension (setup.py), used for every peer's C too.
CFLAGS = ["-O3", f"-march={os.environ.get('STEWART_MARCH', 'native')}"]


def param_vector(params) -> np.ndarray:
    """``params`` as the flat vector of :data:`PARAM_COUNT` doubles (``stewart_params`` order)."""
    return np.concatenate([np.ravel(np.asarray(getattr(params, _kernel.PARAM_SOURCES[name]), float))
                           for name, _ in PARAM_FIELDS])


def unpack(p) -> dict:
    """Split a flat parameter vector (numpy, casadi or a list of symbols) into its fields:
    a scalar, a slice of n entries, or a list of row slices."""
    fields, start = {}, 0
    for name, shape in PARAM_FIELDS:
        size = int(np.prod(shape))
        if not shape:
            fields[name] = p[start]
        elif len(shape) == 1:
            fields[name] = p[start:start + size]
        else:
            fields[name] = [p[start + k:start + k + shape[1]] for k in range(0, size, shape[1])]
        start += size
    return fields


def peer_available(module: str) -> bool:
    """True if ``module`` can be imported (without importing it)."""
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def compiler() -> str:
    cc = os.environ.get("CC", "cc")
    if shutil.which(cc) is None:
        raise RuntimeError(f"no C compiler ({cc}) found")
    return cc


def compile_c(sources, output, *, shared=False, include=(), extra=(), timeout=None) -> float:
    """Compile ``sources`` with :data:`CFLAGS`; returns the wall time in seconds.

    With ``timeout`` (seconds) a compilation still running then is stopped, the
    compiler's own subprocesses too, and ``subprocess.TimeoutExpired`` is raised."""
    cmd = [compiler(), "-std=c99", *CFLAGS, *(f"-I{d}" for d in include), *map(str, sources), "-o", str(output),
           *extra, "-lm"]
    if shared:
        cmd[1:1] = ["-shared", "-fPIC"]
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        _, stderr = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)  # the driver and cc1, its child
        proc.communicate()
        raise
    if proc.returncode != 0:
        raise RuntimeError(f"compiling {sources} failed:\n{stderr[-3000:]}")
    return time.perf_counter() - start


def relative_error(a, b) -> float:
    """max |a - b| / max |b| over the whole array (b is the reference)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))
