/* The fixed public functions of stewart_model.c (codegen/templates/public.c, copied verbatim by
 * the generator): which kernels a parameter set takes, and the lanes of the batch functions.
 * Compiles on its own against stewart_model.h. */
#include "stewart_model.h"

int stewart_is_axisymmetric(const stewart_params *p)
{
    return p->cylinder_inertia[1] == p->cylinder_inertia[2]
        && p->piston_inertia[1] == p->piston_inertia[2];
}

int stewart_is_paper_model(const stewart_params *p)
{
    int i, k, zero = 1;
    for (i = 0; i < 6; ++i) {
        for (k = 0; k < 3; ++k) {
            zero &= p->universal_joint_axes[i][k] == 0.0;
        }
    }
    for (k = 0; k < 3; ++k) {
        zero &= p->platform_com[k] == 0.0 && p->platform_inertia_products[k] == 0.0;
    }
    return zero;
}

int stewart_batch_lanes(void)
{
    return STEWART_LANES;
}
