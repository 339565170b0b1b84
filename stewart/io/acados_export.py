"""The platform's one-step map as acados's generic discrete dynamics (``stewart export-acados``).

acados takes external C dynamics as a "generic" discrete model (``dyn_ext_fun_type =
'generic'``, ``integrator_type = 'DISCRETE'``): C functions ``int f(void **in, void **out,
void *params)`` whose inputs are the state ``x`` and the input ``u`` (``in[0]``, ``in[1]``,
``struct blasfeo_dvec_args``) and whose outputs are the next state (``out[0]``, a
``struct blasfeo_dvec_args``) and, for the ``_jac`` function, ``[B^T; A^T]`` (``out[1]``, a
``struct blasfeo_dmat_args`` of ``nu + nx`` rows and ``nx`` columns: row ``j < nu`` holds
``d x+ / d u_j``, row ``nu + k`` holds ``d x+ / d x_k``).

:func:`export` writes, into one directory, the model's C files with the platform's parameter
header (:func:`stewart.io.capi.export`), :data:`SOURCE`, whose functions (:data:`FUNCTIONS`)
evaluate the generated ``stewart_rk4_step_derivatives`` on the state ``[x, xd]`` (12) under
the six actuator forces (the input) held over ``dt``, the platform's parameter file
(:data:`PARAMS_FILE`) and :data:`SETTINGS_FILE` (the step, the function names and the
compiler flags: the model's rounding flags, so that acados evaluates the same bits as
:meth:`stewart.Platform.rk4_step`). acados compiles one source file per model, so
:data:`SOURCE` includes the model's source files; the compiler needs ``-I`` the directory,
which the flags of :data:`SETTINGS_FILE` hold. Only first derivatives are given: acados's
Gauss-Newton Hessian (``hessian_approx = 'GAUSS_NEWTON'``), not its exact one.

:mod:`stewart.acados` (in acados's own environment, ``make acados-env``) builds acados's
model and a tracking OCP from such a directory.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from ..model import arguments
from ..model.params import PlatformParams
from . import capi

__all__ = ["export", "source", "compile_flags", "SOURCE", "SETTINGS_FILE", "PARAMS_FILE", "FUNCTIONS",
           "INTEGRATORS", "STATE_SIZE", "INPUT_SIZE"]

#: The C source acados compiles (its ``dyn_generic_source``).
SOURCE = "stewart_acados.c"
#: The step, the function names and the compiler flags, for :mod:`stewart.acados`.
SETTINGS_FILE = "stewart_acados.json"
#: The platform's parameters (TOML, :meth:`stewart.PlatformParams.load` reads it).
PARAMS_FILE = "platform.toml"
#: acados's model fields and the C functions of :data:`SOURCE` they name.
FUNCTIONS = {"dyn_disc_fun": "stewart_acados_dyn_disc_fun", "dyn_disc_fun_jac": "stewart_acados_dyn_disc_fun_jac"}
#: The one-step maps an export can hold: the classic RK4 step of :meth:`stewart.Platform.rk4_step`.
INTEGRATORS = ("rk4",)
#: The state [x, xd] and the input (the six actuator forces [N]).
STATE_SIZE, INPUT_SIZE = 12, 6


def compile_flags(directory: Any) -> str:
    """acados's ``ext_fun_compile_flags`` for an export in ``directory``: ``-O2``, the model's
    rounding flags (:func:`stewart.io.capi.c_flags`) and ``-I`` the directory (absolute)."""
    path = os.path.abspath(os.fspath(directory))
    if any(c.isspace() or c in "\"'\\$#;" for c in path):
        raise ValueError(f"directory: acados's Makefile cannot take the path {path!r} (no spaces, quotes, $, # or ;)")
    return " ".join(["-O2", *capi.c_flags(), f"-I{path}"])


def source(params: PlatformParams, dt: float, integrator: str = "rk4") -> str:
    """The text of :data:`SOURCE` for ``params`` and the step ``dt`` [s]."""
    dt, integrator = _checked(params, dt, integrator)
    label = "unnamed" if params.name is None else params.name
    includes = "".join(f'#include "{Path(path).name}"\n' for path in capi.c_sources())
    return _TEMPLATE.format(label=ascii(label).replace("*/", "* /"), dt=repr(dt), includes=includes,
                            fun=FUNCTIONS["dyn_disc_fun"], fun_jac=FUNCTIONS["dyn_disc_fun_jac"],
                            params_header=capi.PARAMS_HEADER, nx=STATE_SIZE, nu=INPUT_SIZE)


def export(directory: Any, params: PlatformParams, dt: float, integrator: str = "rk4") -> list[str]:
    """Write the model's C files, ``stewart_platform_params.h``, :data:`SOURCE`,
    :data:`PARAMS_FILE` and :data:`SETTINGS_FILE` for ``params`` and the step ``dt`` [s] into
    ``directory`` (created if needed). Returns the paths written."""
    dt, integrator = _checked(params, dt, integrator)
    flags = compile_flags(directory)
    written = capi.export(directory, params)
    target = Path(directory)
    text = source(params, dt, integrator)
    (target / SOURCE).write_text(text, encoding="ascii", newline="\n")
    params.save(target / PARAMS_FILE)
    settings = {"dt": dt, "integrator": integrator, "source": SOURCE, "params": PARAMS_FILE,
                "functions": FUNCTIONS, "compile_flags": flags, "nx": STATE_SIZE, "nu": INPUT_SIZE}
    (target / SETTINGS_FILE).write_text(json.dumps(settings, indent=2) + "\n", encoding="ascii", newline="\n")
    return written + [str(target / name) for name in (SOURCE, PARAMS_FILE, SETTINGS_FILE)]


def _checked(params: PlatformParams, dt: Any, integrator: Any) -> tuple[float, str]:
    if not isinstance(params, PlatformParams):
        raise TypeError(f"params: expected a stewart.PlatformParams, got {type(params).__name__}")
    dt = arguments.real("dt", dt)
    if not 0.0 < dt < float("inf"):
        raise ValueError(f"dt: must be a positive finite number of seconds, got {dt}")
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator: expected one of {list(INTEGRATORS)}, got {integrator!r}")
    return dt, integrator


_TEMPLATE = """\
/* stewart_acados.c -- acados generic discrete dynamics of the platform {label}.
 *
 * Written by stewart export-acados (stewart.io.acados_export). The state is s = [x; xd]
 * ({nx}: the pose [x, y, z, psi, theta, phi] and its rates), the input u the six actuator
 * forces [N], held over STEWART_ACADOS_DT seconds; the next state is one classic RK4 step of
 * the generated model, stewart_rk4_step_derivatives, with the platform's parameters of
 * {params_header}: the same bits as stewart.Platform.rk4_step when compiled with the model's
 * rounding flags (STEWART_ROUNDING_FLAGS).
 *
 * acados's generic functions: in[0] x, in[1] u (struct blasfeo_dvec_args); out[0] the next
 * state (struct blasfeo_dvec_args); out[1] (the _jac function) [B^T; A^T] (struct
 * blasfeo_dmat_args, nu + nx rows, nx columns). They return the model's status (0 when
 * STEWART_OK; the outputs are then NaN otherwise).
 */
#include "blasfeo/include/blasfeo_common.h"
#include "blasfeo/include/blasfeo_d_aux.h"
#include "acados/utils/external_function_generic.h"

#include "stewart_model.h"
#include "{params_header}"

/* The model's source files, in this one unit: acados compiles one source file per model. */
{includes}
#define STEWART_ACADOS_DT {dt}
#define STEWART_ACADOS_NX {nx}
#define STEWART_ACADOS_NU {nu}

static int stewart_acados_step(void **in, void **out, int with_jacobians)
{{
    struct blasfeo_dvec_args *x_in = (struct blasfeo_dvec_args *) in[0];
    struct blasfeo_dvec_args *u_in = (struct blasfeo_dvec_args *) in[1];
    struct blasfeo_dvec_args *next = (struct blasfeo_dvec_args *) out[0];
    double s[STEWART_ACADOS_NX], u[STEWART_ACADOS_NU], sn[STEWART_ACADOS_NX];
    double A[STEWART_ACADOS_NX * STEWART_ACADOS_NX], B[STEWART_ACADOS_NX * STEWART_ACADOS_NU];
    int i, status;

    for (i = 0; i < STEWART_ACADOS_NX; i++)
        s[i] = blasfeo_dvecex1(x_in->x, x_in->xi + i);
    for (i = 0; i < STEWART_ACADOS_NU; i++)
        u[i] = blasfeo_dvecex1(u_in->x, u_in->xi + i);
    if (with_jacobians)
        status = stewart_rk4_step_derivatives(&stewart_platform_params, s, s + 6, u, STEWART_ACADOS_DT,
                                              sn, sn + 6, A, B);
    else
        status = stewart_rk4_step(&stewart_platform_params, s, s + 6, u, STEWART_ACADOS_DT, sn, sn + 6);
    for (i = 0; i < STEWART_ACADOS_NX; i++)
        blasfeo_dvecin1(sn[i], next->x, next->xi + i);
    if (with_jacobians) {{
        struct blasfeo_dmat_args *jac = (struct blasfeo_dmat_args *) out[1];
        /* B and A are row-major (row = output): read column-major they are B^T (nu x nx) and
         * A^T (nx x nx), the blocks of [B^T; A^T]. */
        blasfeo_pack_dmat(STEWART_ACADOS_NU, STEWART_ACADOS_NX, B, STEWART_ACADOS_NU, jac->A, jac->ai, jac->aj);
        blasfeo_pack_dmat(STEWART_ACADOS_NX, STEWART_ACADOS_NX, A, STEWART_ACADOS_NX, jac->A,
                          jac->ai + STEWART_ACADOS_NU, jac->aj);
    }}
    return status;
}}

/* The next state. */
int {fun}(void **in, void **out, void *params)
{{
    (void) params;
    return stewart_acados_step(in, out, 0);
}}

/* The next state and [B^T; A^T]. */
int {fun_jac}(void **in, void **out, void *params)
{{
    (void) params;
    return stewart_acados_step(in, out, 1);
}}
"""
