"""Run ``driver.c``: a model function over N states from a C loop, timed in C."""

from __future__ import annotations

import pathlib
import subprocess

import numpy as np

from .common import compile_c

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent


def build_ours(workdir) -> pathlib.Path:
    """The driver linked with our generated C (generated/stewart_model*.c)."""
    exe = pathlib.Path(workdir) / "driver_ours"
    compile_c([HERE / "driver.c", *sorted((ROOT / "generated").glob("stewart_model*.c"))], exe,
              include=[ROOT / "generated"])
    return exe


def build_casadi(workdir, c_source, *, function=None, width: int = 6, timeout=None,
                 extra=()) -> tuple[pathlib.Path, float]:
    """The driver linked with CasADi's generated C: its ``stewart_casadi_id`` and
    ``stewart_casadi_fd``, or the one ``function`` for both modes, returning ``width``
    doubles a state, compiled with the ``extra`` flags after the peers' own (a path's flags).
    Returns the executable and the compile time (``timeout``: see :func:`compile_c`)."""
    exe = pathlib.Path(workdir) / f"driver_{function or 'casadi'}"
    extra = ["-DPEER_CASADI", f"-DOUT_WIDTH={width}", *extra]
    if function:
        extra += [f"-DPEER_ID={function}", f"-DPEER_FD={function}"]
    seconds = compile_c([HERE / "driver.c", c_source], exe, include=[pathlib.Path(c_source).parent], extra=extra,
                        timeout=timeout)
    return exe, seconds


def run(exe, mode: str, pvec, x, xd, third, repeats: int = 7, width: int = 6) -> tuple[float, np.ndarray]:
    """Median time per state [s] over ``repeats`` passes, and the (N, width) outputs."""
    workdir = pathlib.Path(exe).parent
    n = len(x)
    inp, out = workdir / f"in_{mode}.bin", workdir / f"out_{mode}.bin"
    with open(inp, "wb") as fh:
        fh.write(np.int64(n).tobytes())
        fh.write(np.int64(len(pvec)).tobytes())
        fh.write(np.ascontiguousarray(pvec, dtype=np.float64).tobytes())
        fh.write(np.ascontiguousarray(np.hstack([x, xd, third]), dtype=np.float64).tobytes())
    proc = subprocess.run([str(exe), mode, str(inp), str(out), str(repeats)], capture_output=True, text=True,
                          check=True)
    seconds, failures = proc.stdout.split()
    if int(failures):
        raise RuntimeError(f"{exe.name} {mode}: {failures} states failed")
    return float(seconds), np.fromfile(out, dtype=np.float64).reshape(n, width)
