/* The C batch loop: each batched function over N states, on one core, as the scalar
 * function called row by row and as the batch function (STEWART_LANES states per vector
 * instruction), side by side in one run.  Built at bench time with the flags of our
 * extension (benchmarks/batch_loop.py).
 *
 * usage: batch_loop INPUT REPEATS
 *   INPUT  binary: int64 N, int64 NP, NP doubles of parameters (stewart_params order:
 *          every member, row-major), then N rows of 18 doubles (x, xd, xdd)
 * Prints the lanes, then per function a line: name, the median over REPEATS passes of the
 * time per state of the scalar loop and of the batch function (s), the worst difference of
 * their outputs relative to each row's largest output, and the rows either reports failed.
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

enum { ID, FD, M, VXD, G, NFUNCTIONS };
static const char *const NAMES[NFUNCTIONS] = {"inverse_dynamics", "forward_dynamics", "mass_matrix",
                                              "coriolis_vector", "gravity_vector"};
static const int WIDTH[NFUNCTIONS] = {6, 6, 36, 6, 6};

/* Function f on n states: row by row with the scalar function, or with the batch function. */
static int run(int f, int batch, const stewart_params *p, size_t n, const double *x, const double *xd,
               const double *third, double *out, int *status) {
    int failures = 0;
    if (batch) {
        switch (f) {
        case ID: stewart_batch_inverse_dynamics(p, n, x, xd, third, out, status); break;
        case FD: stewart_batch_forward_dynamics(p, n, x, xd, third, out, status); break;
        case M: stewart_batch_mass_matrix(p, n, x, out, status); break;
        case VXD: stewart_batch_coriolis_vector(p, n, x, xd, out, status); break;
        default: stewart_batch_gravity_vector(p, n, x, out, status); break;
        }
        for (size_t i = 0; i < n; ++i) failures += status[i] != STEWART_OK;
        return failures;
    }
    for (size_t i = 0; i < n; ++i) {
        const double *a = x + 6 * i, *b = xd + 6 * i, *c = third + 6 * i;
        double *o = out + (size_t)WIDTH[f] * i;
        int st;
        switch (f) {
        case ID: st = stewart_inverse_dynamics(p, a, b, c, o); break;
        case FD: st = stewart_forward_dynamics(p, a, b, c, o); break;
        case M: st = stewart_mass_matrix(p, a, o); break;
        case VXD: st = stewart_coriolis_vector(p, a, b, o); break;
        default: st = stewart_gravity_vector(p, a, o); break;
        }
        failures += st != STEWART_OK;
    }
    return failures;
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
    double *tau = malloc(n * 6 * sizeof(double)), *out[2] = {malloc(n * 36 * sizeof(double)),
                                                            malloc(n * 36 * sizeof(double))};
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
        double median[2];
        int failures[2];
        for (int batch = 0; batch < 2; ++batch) {
            for (int rep = 0; rep < repeats; ++rep) {
                double start = now();
                failures[batch] = run(f, batch, &p, n, x, xd, f == FD ? tau : xdd, out[batch], status);
                times[rep] = (now() - start) / (double)n;
            }
            qsort(times, (size_t)repeats, sizeof(double), cmp);
            median[batch] = times[repeats / 2];
        }
        double worst = 0.0;
        for (size_t i = 0; i < n; ++i) {
            const double *a = out[0] + (size_t)WIDTH[f] * i, *b = out[1] + (size_t)WIDTH[f] * i;
            double scale = 0.0, err = 0.0;
            for (int k = 0; k < WIDTH[f]; ++k) scale = fabs(a[k]) > scale ? fabs(a[k]) : scale;
            for (int k = 0; k < WIDTH[f]; ++k) {
                double e = fabs(a[k] - b[k]) / (scale > 0.0 ? scale : 1.0);
                if (!(e <= err)) err = e;
            }
            if (!(err <= worst) && !isnan(a[0])) worst = err;
        }
        printf("%s %.6e %.6e %.3e %d %d\n", NAMES[f], median[0], median[1], worst, failures[0], failures[1]);
    }
    return 0;
}
