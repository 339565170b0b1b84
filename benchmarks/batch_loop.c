/* The C batch loop: each batched function over N states, on one core, as the single-state
 * function called row by row and as the batch function (STEWART_LANES states per vector
 * instruction), side by side in one run.  Built at bench time with the flags of our
 * extension (benchmarks/batch_loop.py).
 *
 * usage: batch_loop INPUT REPEATS
 *   INPUT  binary: int64 N, int64 NP, NP doubles of parameters (stewart_params order:
 *          every member, row-major), then N rows of 18 doubles (x, xd, xdd)
 * Prints the lanes, then per function a line: name, the median over REPEATS passes of the
 * time per state of the row-by-row loop and of the batch function (s), the worst difference of
 * their outputs relative to each row's largest output, and the rows either reports failed.
 * The derivative functions run on the first ND states (forward dynamics and the RK4 step with
 * the forces inverse dynamics gives).  Then a line per derivative function, "ratio", its name,
 * the function it differentiates, and the median and quartiles of the ratio of their batch
 * times per state on those ND states, RATIO_PAIRS pairs timed in alternation, each in the
 * thread's CPU time.
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "stewart_model.h"

#include "timing.h"

enum { ID, FD, M, VXD, G, IDD, FDD, RK4D, REG, NFUNCTIONS };
static const char *const NAMES[NFUNCTIONS] = {"inverse_dynamics", "forward_dynamics", "mass_matrix",
                                              "coriolis_vector", "gravity_vector", "inverse_dynamics_derivatives",
                                              "forward_dynamics_derivatives", "rk4_step_derivatives", "regressor"};
/* The sizes of each function's outputs (a row's), at most four. */
static const int WIDTH[NFUNCTIONS][4] = {{6}, {6}, {36}, {6}, {6}, {6, 36, 36, 36}, {6, 36, 36, 36},
                                         {6, 6, 144, 72}, {192}};
/* The derivative functions (IDD, FDD, RK4D) run on the first ND states; the regressor on all, as
 * inverse dynamics, which it is compared with. */
enum { ND = 10000 };
/* Pairs of each ratio of a derivative function's time over its function's. */
enum { RATIO_PAIRS = 31 };
/* Time step of the RK4 step. */
static const double DT = 1e-3;

/* Output k of function f on n states, in out: the n rows of each output one after the other. */
static double *part(int f, int k, double *out, size_t n) {
    for (int j = 0; j < k; ++j) out += (size_t)WIDTH[f][j] * n;
    return out;
}

/* Function f on n states: row by row with the single-state function, or with the batch function. */
static int run(int f, int batch, const stewart_params *p, size_t n, const double *x, const double *xd,
               const double *third, double *out, int *status) {
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

/* The worst difference of the rows of b from those of a (n rows of `width`), relative to each
 * row's largest |a|, over the rows a gives a value for. */
static double worst_rows(const double *a, const double *b, size_t n, int width) {
    double worst = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double *u = a + (size_t)width * i, *v = b + (size_t)width * i;
        double scale = 0.0, err = 0.0;
        for (int k = 0; k < width; ++k) scale = fabs(u[k]) > scale ? fabs(u[k]) : scale;
        for (int k = 0; k < width; ++k) {
            double e = fabs(u[k] - v[k]) / (scale > 0.0 ? scale : 1.0);
            if (!(e <= err)) err = e;
        }
        if (!(err <= worst) && !isnan(u[0])) worst = err;
    }
    return worst;
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s INPUT REPEATS\n", argv[0]);
        return 2;
    }
    int repeats = atoi(argv[2]);
    if (repeats < 1) repeats = 1;
    FILE *in = fopen(argv[1], "rb");
    if (!in) { perror(argv[1]); return 1; }
    int64_t n64, np64;
    if (fread(&n64, sizeof n64, 1, in) != 1 || fread(&np64, sizeof np64, 1, in) != 1) return 1;
    size_t n = (size_t)n64, np = (size_t)np64;
    stewart_params p;
    /* stewart_params holds doubles only, so the flat vector is its memory image. */
    if (np * sizeof(double) != sizeof p || fread(&p, sizeof(double), np, in) != np) {
        fprintf(stderr, "%s: %zu parameters, stewart_params holds %zu\n", argv[1], np, sizeof p / sizeof(double));
        return 1;
    }
    double *rows = malloc(n * 18 * sizeof(double)), *x = malloc(n * 6 * sizeof(double));
    double *xd = malloc(n * 6 * sizeof(double)), *xdd = malloc(n * 6 * sizeof(double));
    const size_t nd = n < ND ? n : ND, size = n * 192 > nd * 228 ? n * 192 : nd * 228;
    double *tau = malloc(n * 6 * sizeof(double)), *out[2] = {malloc(size * sizeof(double)),
                                                            malloc(size * sizeof(double))};
    double *times = malloc((size_t)repeats * sizeof(double));
    int *status = malloc(n * sizeof(int));
    if (!rows || !x || !xd || !xdd || !tau || !out[0] || !out[1] || !times || !status
        || fread(rows, sizeof(double), n * 18, in) != n * 18) return 1;
    fclose(in);
    for (size_t i = 0; i < n; ++i) {
        memcpy(x + 6 * i, rows + 18 * i, 6 * sizeof(double));
        memcpy(xd + 6 * i, rows + 18 * i + 6, 6 * sizeof(double));
        memcpy(xdd + 6 * i, rows + 18 * i + 12, 6 * sizeof(double));
    }
    stewart_batch_inverse_dynamics(&p, n, x, xd, xdd, tau, status); /* the forces forward dynamics takes */

    printf("lanes %d\n", stewart_batch_lanes());
    for (int f = 0; f < NFUNCTIONS; ++f) {
        const size_t m = f >= IDD && f != REG ? nd : n;
        double median[2];
        int failures[2];
        for (int batch = 0; batch < 2; ++batch) {
            for (int rep = 0; rep < repeats; ++rep) {
                double start = now();
                failures[batch] = run(f, batch, &p, m, x, xd, f == FD || f == FDD || f == RK4D ? tau : xdd,
                                      out[batch], status);
                times[rep] = (now() - start) / (double)m;
            }
            qsort(times, (size_t)repeats, sizeof(double), cmp);
            median[batch] = times[repeats / 2];
        }
        double worst = 0.0;
        for (int k = 0; k < 4 && WIDTH[f][k]; ++k) {
            double e = worst_rows(part(f, k, out[0], m), part(f, k, out[1], m), m, WIDTH[f][k]);
            worst = e > worst ? e : worst;
        }
        printf("%s %.6e %.6e %.3e %d %d\n", NAMES[f], median[0], median[1], worst, failures[0], failures[1]);
    }
    static const int PAIRS[2][2] = {{IDD, ID}, {FDD, FD}};
    double ratios[RATIO_PAIRS];
    for (int k = 0; k < 2; ++k) {
        const int f = PAIRS[k][0], g = PAIRS[k][1];
        const double *third = f == FDD ? tau : xdd;
        for (int rep = 0; rep < RATIO_PAIRS; ++rep) {
            double start = cpu_now();
            run(f, 1, &p, nd, x, xd, third, out[0], status);
            const double derivative = cpu_now() - start;
            start = cpu_now();
            run(g, 1, &p, nd, x, xd, third, out[1], status);
            ratios[rep] = derivative / (cpu_now() - start);
        }
        qsort(ratios, RATIO_PAIRS, sizeof(double), cmp);
        printf("ratio %s %s %.4f %.4f %.4f\n", NAMES[f], NAMES[g], ratios[RATIO_PAIRS / 2], ratios[RATIO_PAIRS / 4],
               ratios[3 * RATIO_PAIRS / 4]);
    }
    return 0;
}
