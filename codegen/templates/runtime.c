/* The helpers of the public functions (codegen/templates/runtime.c, copied verbatim by the
 * generator into stewart_internal.h, which the model's units share).  Every public function
 * checks its inputs are finite (all_finite, params_finite), runs its kernel, checks the legs
 * (check_legs), runs its steps (each returns a status: the solvers, check_euler,
 * pose_accelerations, split_jacobians) and finishes (finish, finish_all).  Compiles on its own against stewart_model.h. */
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

/* The legs' tests, in order (codegen/conditions.py): STEWART_ERR_LEG_DEGENERATE if a
 * leg has L2[i] < STEWART_DEGENERATE_TOL (or NaN), STEWART_ERR_NONFINITE if a leg's L2[i]
 * overflows, (h2 != NULL: the kernels in the frames {C_i}) STEWART_ERR_LEG_VERTICAL if a leg
 * has h2[i] = l_x^2 + l_y^2 < STEWART_VERTICAL_TOL * L2[i], and (n2 != NULL: the general
 * model) STEWART_ERR_GIMBAL_LOCK if a leg has n2[i] = |a_i x l_i|^2 < STEWART_GIMBAL_TOL *
 * L2[i]; else STEWART_OK. */
static int check_legs(const double L2[6], const double h2[6], const double n2[6])
{
    int i;
    for (i = 0; i < 6; ++i) {
        if (!(L2[i] >= STEWART_DEGENERATE_TOL)) {
            return STEWART_ERR_LEG_DEGENERATE;
        }
    }
    for (i = 0; i < 6; ++i) {
        if (!(L2[i] <= DBL_MAX)) {
            return STEWART_ERR_NONFINITE;
        }
    }
    for (i = 0; h2 != NULL && i < 6; ++i) {
        if (!(h2[i] >= STEWART_VERTICAL_TOL * L2[i])) {
            return STEWART_ERR_LEG_VERTICAL;
        }
    }
    for (i = 0; n2 != NULL && i < 6; ++i) {
        if (!(n2[i] >= STEWART_GIMBAL_TOL * L2[i])) {
            return STEWART_ERR_GIMBAL_LOCK;
        }
    }
    return STEWART_OK;
}

/* STEWART_OK unless cos(theta) is too small for the Euler-rate map J_A to be inverted. */
static int check_euler(const double ctheta[1])
{
    return fabs(ctheta[0]) >= STEWART_EULER_TOL ? STEWART_OK : STEWART_ERR_EULER_SINGULAR;
}

/* xdd = [y_v; J_A^-1 y_w] from the twist acceleration y = T xdd, for n columns (6 rows of
 * n, row-major; y and xdd may not overlap). */
static int pose_accelerations(const double JAinv[9], int n, const double *y, double *xdd)
{
    int i, c;
    for (c = 0; c < n; ++c) {
        for (i = 0; i < 3; ++i) {
            xdd[i * n + c] = y[i * n + c];
            xdd[(3 + i) * n + c] = JAinv[3 * i] * y[3 * n + c] + JAinv[3 * i + 1] * y[4 * n + c]
                + JAinv[3 * i + 2] * y[5 * n + c];
        }
    }
    return STEWART_OK;
}

/* The three 6 x 6 blocks of columns of Y (6 x 18, row-major). */
static int split_jacobians(const double Y[108], double a[36], double b[36], double c[36])
{
    int i, j;
    for (i = 0; i < 6; ++i) {
        for (j = 0; j < 6; ++j) {
            a[6 * i + j] = Y[18 * i + j];
            b[6 * i + j] = Y[18 * i + 6 + j];
            c[6 * i + j] = Y[18 * i + 12 + j];
        }
    }
    return STEWART_OK;
}

/* Final status: an error, or NONFINITE for a non-finite output; fills the
 * output with NaN unless STEWART_OK. */
static int finish(int status, double *out, int n)
{
    int k;
    if (status == STEWART_OK && !all_finite(out, n)) {
        status = STEWART_ERR_NONFINITE;
    }
    if (status != STEWART_OK) {
        for (k = 0; k < n; ++k) {
            out[k] = NAN;
        }
    }
    return status;
}

/* finish() over the `count` outputs out[k] of n[k] doubles: all NaN unless every one is finite. */
static int finish_all(int status, int count, double *const out[], const int n[])
{
    int k;
    for (k = 0; k < count && status == STEWART_OK; ++k) {
        if (!all_finite(out[k], n[k])) {
            status = STEWART_ERR_NONFINITE;
        }
    }
    for (k = 0; k < count; ++k) {
        finish(status, out[k], n[k]);
    }
    return status;
}
