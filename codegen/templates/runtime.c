/* The parameter tests of the public functions (codegen/templates/runtime.c, copied verbatim by
 * the generator into stewart_internal.h, which the model's units share): whether the legs
 * spin (the regressor's kernel variants) and whether the parameters are finite (all_finite,
 * for params_finite).  Compiles on its own against stewart_model.h. */
#include "stewart_model.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

/* ---- fixed helpers ---- */

/* 1 if a universal joint has a first axis (the legs turn with their joints), else 0. */
static int legs_spin(const stewart_params *p)
{
    int i, k, spin = 0;
    for (i = 0; i < 6; ++i) {
        for (k = 0; k < 3; ++k) {
            spin |= p->universal_joint_axes[i][k] != 0.0;
        }
    }
    return spin;
}

static int all_finite(const double *v, int n)
{
    int k, ok = 1;
    for (k = 0; k < n; ++k) {
        ok &= isfinite(v[k]) != 0;
    }
    return ok;
}
