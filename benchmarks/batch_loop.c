/* The C batch loop: each batched function over n states on one core, as the single-state
 * function called row by row and as the batch function (STEWART_LANES states per vector
 * instruction).  Compiled at bench time with one copy of the model into a shared library per
 * instruction-set path (benchmarks/batch_loop.py), which loads every copy into one process and
 * times them interleaved, each call from Python through ctypes.
 *
 * batch_loop_run(f, batch, p, n, x, xd, third, out, status) runs function f (the order of
 * NAMES) on n states, row by row or as the batch function, into out (each output's n rows one
 * after the other) and returns the rows that failed; p is the flat parameter vector
 * (stewart_params holds doubles only, so the vector is its memory image).  batch_loop_worst
 * compares two such outputs.
 */
#include <math.h>
#include <stddef.h>

#include "stewart_model.h"

enum { ID, FD, M, VXD, G, IDD, FDD, RK4D, REG, NFUNCTIONS };
/* The sizes of each function's outputs (a row's), at most four. */
static const int WIDTH[NFUNCTIONS][4] = {{6}, {6}, {36}, {6}, {6}, {6, 36, 36, 36}, {6, 36, 36, 36},
                                         {6, 6, 144, 72}, {192}};
/* Time step of the RK4 step. */
static const double DT = 1e-3;

int batch_loop_lanes(void) { return stewart_batch_lanes(); }

int batch_loop_functions(void) { return NFUNCTIONS; }

/* The doubles of a row's outputs of function f. */
int batch_loop_width(int f) { return WIDTH[f][0] + WIDTH[f][1] + WIDTH[f][2] + WIDTH[f][3]; }

/* Output k of function f on n states, in out: the n rows of each output one after the other. */
static double *part(int f, int k, double *out, size_t n) {
    for (int j = 0; j < k; ++j) out += (size_t)WIDTH[f][j] * n;
    return out;
}

int batch_loop_run(int f, int batch, const double *params, size_t n, const double *x, const double *xd,
                   const double *third, double *out, int *status) {
    const stewart_params *p = (const stewart_params *)params;
    double *o[4];
    int failures = 0;
    for (int k = 0; k < 4; ++k) o[k] = part(f, k, out, n);
    if (batch) {
        switch (f) {
        case ID: stewart_batch_inverse_dynamics(p, n, x, xd, third, o[0], status); break;
        case FD: stewart_batch_forward_dynamics(p, n, x, xd, third, o[0], status); break;
        case M: stewart_batch_mass_matrix(p, n, x, o[0], status); break;
        case VXD: stewart_batch_coriolis_vector(p, n, x, xd, o[0], status); break;
        case G: stewart_batch_gravity_vector(p, n, x, o[0], status); break;
        case IDD: stewart_batch_inverse_dynamics_derivatives(p, n, x, xd, third, o[0], o[1], o[2], o[3], status); break;
        case FDD: stewart_batch_forward_dynamics_derivatives(p, n, x, xd, third, o[0], o[1], o[2], o[3], status); break;
        case RK4D: stewart_batch_rk4_step_derivatives(p, n, x, xd, third, DT, o[0], o[1], o[2], o[3], status); break;
        default: stewart_batch_regressor(p, n, x, xd, third, o[0], status); break;
        }
        for (size_t i = 0; i < n; ++i) failures += status[i] != STEWART_OK;
        return failures;
    }
    for (size_t i = 0; i < n; ++i) {
        const double *a = x + 6 * i, *b = xd + 6 * i, *c = third + 6 * i;
        double *r[4];
        int st;
        for (int k = 0; k < 4; ++k) r[k] = o[k] + (size_t)WIDTH[f][k] * i;
        switch (f) {
        case ID: st = stewart_inverse_dynamics(p, a, b, c, r[0]); break;
        case FD: st = stewart_forward_dynamics(p, a, b, c, r[0]); break;
        case M: st = stewart_mass_matrix(p, a, r[0]); break;
        case VXD: st = stewart_coriolis_vector(p, a, b, r[0]); break;
        case G: st = stewart_gravity_vector(p, a, r[0]); break;
        case IDD: st = stewart_inverse_dynamics_derivatives(p, a, b, c, r[0], r[1], r[2], r[3]); break;
        case FDD: st = stewart_forward_dynamics_derivatives(p, a, b, c, r[0], r[1], r[2], r[3]); break;
        case RK4D: st = stewart_rk4_step_derivatives(p, a, b, c, DT, r[0], r[1], r[2], r[3]); break;
        default: st = stewart_regressor(p, a, b, c, r[0]); break;
        }
        failures += st != STEWART_OK;
    }
    return failures;
}

/* The worst difference of the outputs b of function f on n states from a, relative to each
 * row's largest |a| (per output), over the rows a gives a value for. */
double batch_loop_worst(int f, size_t n, const double *a, const double *b) {
    double worst = 0.0;
    for (int k = 0; k < 4 && WIDTH[f][k]; ++k) {
        const int width = WIDTH[f][k];
        const double *u0 = part(f, k, (double *)a, n), *v0 = part(f, k, (double *)b, n);
        for (size_t i = 0; i < n; ++i) {
            const double *u = u0 + (size_t)width * i, *v = v0 + (size_t)width * i;
            double scale = 0.0, err = 0.0;
            for (int j = 0; j < width; ++j) scale = fabs(u[j]) > scale ? fabs(u[j]) : scale;
            for (int j = 0; j < width; ++j) {
                double e = fabs(u[j] - v[j]) / (scale > 0.0 ? scale : 1.0);
                if (!(e <= err)) err = e;
            }
            if (!(err <= worst) && !isnan(u[0])) worst = err;
        }
    }
    return worst;
}
