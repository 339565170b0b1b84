"""Write tests/c/reference_values.h: states and the numeric reference's results for them,
which tests/c/test_model.c checks the generated C against with no Python involved.

Run from the repository root: ``python tests/c/make_reference_values.py``.
"""

import os
import sys
import warnings

import numpy as np

import stewart
from stewart.io import capi
from stewart.oracles import reference as ref

HERE = os.path.dirname(os.path.abspath(__file__))
STATES_PER_PRESET = 4


def _array(values) -> str:
    return "{" + ", ".join(f"{v:.17g}" for v in np.ravel(values)) + "}"


def _general_legs(params: stewart.PlatformParams) -> stewart.PlatformParams:
    """``params`` with leg inertias I_zz = I_yy + axial / 2 (not axisymmetric, within the
    triangle inequality): the C model's general kernels, with the cylinder frame {C_i}."""
    def skewed(inertia):
        return [inertia[0], inertia[1], inertia[1] + 0.5 * inertia[0]]

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stewart.NonAxisymmetricLegWarning)
        return params.replace(cylinder_inertia=skewed(params.cylinder_inertia),
                              piston_inertia=skewed(params.piston_inertia))


def main() -> None:
    rng = np.random.default_rng(2011)
    cases = []
    for name, params in [(f"{name}{label}", variant(stewart.PlatformParams.preset(name)))
                         for label, variant in (("", lambda p: p), (" (general legs)", _general_legs))
                         for name in sorted(stewart.presets())]:
        home = stewart.home_pose(params)
        for _ in range(STATES_PER_PRESET):
            x = home + rng.uniform(-1, 1, 6) * np.array([0.05 * home[2]] * 3 + [0.15] * 3)
            xd = rng.normal(size=6) * np.array([0.2 * home[2]] * 3 + [0.5] * 3)
            xdd = rng.normal(size=6) * np.array([2 * home[2]] * 3 + [5.0] * 3)
            tau = ref.inverse_dynamics(params, x, xd, xdd)
            fields = [
                capi.params_initializer(params), _array(x), _array(xd), _array(xdd), _array(tau),
                _array(stewart.leg_lengths(params, x)), _array(stewart.leg_velocities(params, x, xd)),
                _array(stewart.jacobian(params, x)),
                _array(ref.mass_matrix(params, x)),
                _array(ref.mass_matrix(params, x) @ np.linalg.inv(stewart.twist_transform(x))),
                _array(ref.coriolis_matrix(params, x, xd)),
                _array(ref.coriolis_vector(params, x, xd)), _array(ref.gravity_vector(params, x)),
            ]
            cases.append(f"    {{\"{name}\",\n     " + ",\n     ".join(fields) + "}")
    text = (
        "/* Values from the numeric reference (stewart.oracles.reference) for tests/c/test_model.c.\n"
        " * Written by tests/c/make_reference_values.py; do not edit. */\n"
        "typedef struct {\n"
        "    const char *name;\n    stewart_params params;\n"
        "    double x[6], xd[6], xdd[6], tau[6];\n"
        "    double L[6], Ld[6], JC[36], M[36], Mt[36], V[36], Vxd[6], G[6];\n"
        "} reference_case;\n\n"
        f"static const reference_case CASES[{len(cases)}] = {{\n" + ",\n".join(cases) + "\n};\n"
    )
    with open(os.path.join(HERE, "reference_values.h"), "w") as fh:
        fh.write(text)


if __name__ == "__main__":
    sys.exit(main())
