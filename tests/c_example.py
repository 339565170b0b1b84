"""The shipped C example, ``examples/c/inverse_dynamics.c``: compile it with the model's C
files, run it, and compare the forces it prints with the package's at the state it prints.

Used by ``test_capi.py`` in the checkout and by ``installed_smoke.py`` in the fresh
virtual environments of the packaging check.
"""

from __future__ import annotations

import os
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

import stewart
from stewart.oracles.physics import relative_error

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "c" / "inverse_dynamics.c"
#: The strictest portable C the README promises the model compiles under.
CFLAGS = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]
#: The example and the compiled kernel run the same C under other flags: rounding only.
RTOL = 1e-12


def run_command(command, **kwargs) -> str:
    """Run ``command`` (without the caller's PYTHONPATH, PYTHONHOME or VIRTUAL_ENV) and return
    its output; a non-zero exit fails with the command and all it printed."""
    command = [str(c) for c in command]
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    done = subprocess.run(command, capture_output=True, text=True, env=env, **kwargs)
    assert done.returncode == 0, f"{' '.join(command)}: exit {done.returncode}\n{done.stdout}{done.stderr}"
    return done.stdout


def run_example(include_dirs, sources, workdir, libraries=()) -> dict[str, np.ndarray]:
    """Compile the example and the model's units ``sources``, one compiler per core as ``make
    -j`` would, link them (and the archives ``libraries``, e.g. the model as the build compiled
    it) and run it; its printed lines ``name v0 ... v5`` as arrays by name."""
    exe = Path(workdir) / "inverse_dynamics"
    compiler = os.environ.get("CC", "cc")
    units = [EXAMPLE, *map(Path, sources)]
    objects = [Path(workdir) / f"{k}_{unit.stem}.o" for k, unit in enumerate(units)]
    with ThreadPoolExecutor(os.cpu_count() or 1) as pool:
        list(pool.map(lambda job: run_command([compiler, *CFLAGS, *(f"-I{d}" for d in include_dirs), "-c", job[0],
                                               "-o", job[1]]), zip(units, objects)))
    run_command([compiler, *objects, *libraries, "-lm", "-o", exe])
    lines = (line.split() for line in run_command([exe]).splitlines())
    return {name: np.array(values, dtype=float) for name, *values in lines}


def check_example(params, include_dirs, sources, workdir, libraries=()) -> float:
    """Run the example built for ``params`` (with the model's units ``sources``, or its archive
    in ``libraries``) and return its forces' error relative to the largest force of
    :meth:`stewart.Platform.inverse_dynamics` at the same state."""
    printed = run_example(include_dirs, sources, workdir, libraries)
    assert sorted(printed) == ["tau", "x", "xd", "xdd"] and all(v.shape == (6,) for v in printed.values())
    want = stewart.Platform(params).inverse_dynamics(printed["x"], printed["xd"], printed["xdd"])
    error = relative_error(printed["tau"][None], want[None])
    assert error <= RTOL, f"C example: tau {printed['tau']} against {want} (relative error {error:.2e})"
    return error
