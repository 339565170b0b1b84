/* Batch driver: one model function called over N states from a plain C loop, timed.
 *
 * Built at bench time twice with the same flags as our extension (-O3 -march=native):
 *   -DPEER_CASADI  with CasADi's generated C (stewart_casadi_id / stewart_casadi_fd, or
 *                  the functions named by -DPEER_ID=NAME -DPEER_FD=NAME),
 *   otherwise      with our generated/stewart_model.c.
 *
 * usage: driver MODE INPUT OUTPUT REPEATS
 *   MODE   id (inverse dynamics: third input is xdd) or fd (forward dynamics: tau)
 *   INPUT  binary: int64 N, int64 NP, NP doubles of parameters (stewart_params order:
 *          every member, row-major), then N rows of 18 doubles (x, xd, third input)
 *   OUTPUT binary: N rows of OUT_WIDTH doubles (tau or xdd; -DOUT_WIDTH=W for a CasADi
 *          function with a wider output, such as a value and its Jacobian)
 * Prints the median over REPEATS passes of the time per state, in seconds.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifndef OUT_WIDTH
#define OUT_WIDTH 6
#endif

#ifdef PEER_CASADI
#include "casadi_stewart.h"
#ifndef PEER_ID
#define PEER_ID stewart_casadi_id
#endif
#ifndef PEER_FD
#define PEER_FD stewart_casadi_fd
#endif
#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
#else
#include "stewart_model.h"
#endif

#include "../timing.h"

int main(int argc, char **argv) {
    if (argc != 5) {
        fprintf(stderr, "usage: %s id|fd INPUT OUTPUT REPEATS\n", argv[0]);
        return 2;
    }
    int fd_mode = strcmp(argv[1], "fd") == 0;
    int repeats = atoi(argv[4]);
    FILE *in = fopen(argv[2], "rb");
    if (!in) { perror(argv[2]); return 1; }
    int64_t n64, np64;
    if (fread(&n64, sizeof n64, 1, in) != 1 || fread(&np64, sizeof np64, 1, in) != 1) return 1;
    size_t n = (size_t)n64, np = (size_t)np64;
    double *p = malloc((np > 0 ? np : 1) * sizeof(double));
    if (!p || fread(p, sizeof(double), np, in) != np) return 1;
    double *rows = malloc(n * 18 * sizeof(double)), *out = malloc(n * OUT_WIDTH * sizeof(double));
    if (!rows || !out || fread(rows, sizeof(double), n * 18, in) != n * 18) return 1;
    fclose(in);

#ifdef PEER_CASADI
    casadi_int sz_arg, sz_res, sz_iw, sz_w;
    int (*fn)(const casadi_real **, casadi_real **, casadi_int *, casadi_real *, int) =
        fd_mode ? PEER_FD : PEER_ID;
    if (fd_mode) CAT(PEER_FD, _work)(&sz_arg, &sz_res, &sz_iw, &sz_w);
    else CAT(PEER_ID, _work)(&sz_arg, &sz_res, &sz_iw, &sz_w);
    const casadi_real **arg = malloc((sz_arg > 4 ? sz_arg : 4) * sizeof *arg);
    casadi_real **res = malloc((sz_res > 1 ? sz_res : 1) * sizeof *res);
    casadi_int *iw = malloc((sz_iw > 0 ? sz_iw : 1) * sizeof *iw);
    casadi_real *w = malloc((sz_w > 0 ? sz_w : 1) * sizeof *w);
    arg[3] = p;
#else
    /* stewart_params holds doubles only, so the flat vector is its memory image. */
    stewart_params sp;
    if (np * sizeof(double) != sizeof sp) {
        fprintf(stderr, "%s: %zu parameters, stewart_params holds %zu\n", argv[2], np, sizeof sp / sizeof(double));
        return 1;
    }
    memcpy(&sp, p, sizeof sp);
#endif

    double *times = malloc((size_t)(repeats > 0 ? repeats : 1) * sizeof(double));
    int failures = 0;
    for (int rep = 0; rep < repeats; ++rep) {
        double start = now();
        for (size_t i = 0; i < n; ++i) {
            const double *r = rows + 18 * i;
#ifdef PEER_CASADI
            arg[0] = r;
            arg[1] = r + 6;
            arg[2] = r + 12;
            res[0] = out + OUT_WIDTH * i;
            failures += fn(arg, res, iw, w, 0) != 0;
#else
            failures += (fd_mode ? stewart_forward_dynamics(&sp, r, r + 6, r + 12, out + 6 * i)
                                 : stewart_inverse_dynamics(&sp, r, r + 6, r + 12, out + 6 * i)) != 0;
#endif
        }
        times[rep] = (now() - start) / (double)n;
    }
    qsort(times, (size_t)repeats, sizeof(double), cmp);
    FILE *o = fopen(argv[3], "wb");
    if (!o || fwrite(out, sizeof(double), n * OUT_WIDTH, o) != n * OUT_WIDTH) return 1;
    fclose(o);
    printf("%.6e %d\n", times[repeats / 2], failures);
    return 0;
}
