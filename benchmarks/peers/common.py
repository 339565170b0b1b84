"""Helpers shared by the peer models: the runtime parameter vector, the C compiler
and timing."""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import time

import numpy as np

#: Length of the flat parameter vector; the order is the C struct ``stewart_params``:
#: base_points (18, row-major), platform_points (18), platform_mass, platform_inertia (3),
#: cylinder_mass, cylinder_inertia (3), cylinder_com_distance, piston_mass,
#: piston_inertia (3), piston_com_distance, gravity.
PARAM_COUNT = 51

#: The compiler flags of our extension (setup.py), used for every peer's C too.
CFLAGS = ["-O3", f"-march={os.environ.get('STEWART_MARCH', 'native')}"]


def param_vector(params) -> np.ndarray:
    """``params`` as the flat vector of :data:`PARAM_COUNT` doubles (``stewart_params`` order)."""
    out = np.concatenate([
        np.asarray(params.base_points, float).ravel(),
        np.asarray(params.platform_points, float).ravel(),
        [params.platform_mass], params.platform_inertia,
        [params.cylinder_mass], params.cylinder_inertia, [params.cylinder_com_distance],
        [params.piston_mass], params.piston_inertia, [params.piston_com_distance],
        [params.gravity],
    ]).astype(float)
    assert out.shape == (PARAM_COUNT,)
    return out


def unpack(p):
    """Split a flat parameter vector (numpy, casadi or a list of symbols) into its fields."""
    return {
        "base": [p[3 * i:3 * i + 3] for i in range(6)],
        "plat": [p[18 + 3 * i:18 + 3 * i + 3] for i in range(6)],
        "m_P": p[36], "I_P": p[37:40],
        "m_C": p[40], "I_C": p[41:44], "b_C": p[44],
        "m_S": p[45], "I_S": p[46:49], "b_S": p[49],
        "g": p[50],
    }


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


def compile_c(sources, output, *, shared=False, include=(), extra=()) -> float:
    """Compile ``sources`` with :data:`CFLAGS`; returns the wall time in seconds."""
    cmd = [compiler(), "-std=c99", *CFLAGS, *(f"-I{d}" for d in include), *map(str, sources), "-o", str(output),
           *extra, "-lm"]
    if shared:
        cmd[1:1] = ["-shared", "-fPIC"]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"compiling {sources} failed:\n{proc.stderr[-3000:]}")
    return time.perf_counter() - start


def relative_error(a, b) -> float:
    """max |a - b| / max |b| over the whole array (b is the reference)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))
