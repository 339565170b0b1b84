/* CasADi's generated inverse dynamics over n states in a plain C loop, the loop of the peers'
 * driver (peers/driver.c) as a function: compiled with CasADi's C into a shared library per
 * instruction-set path (benchmarks/batch_loop.py), and called through ctypes beside our batch
 * loop in the same process.
 *
 * casadi_loop(p, n, rows, out): rows holds n rows of 18 doubles (x, xd, xdd), out receives n
 * rows of 6 (tau); returns the rows CasADi reported failed, or -1 if the work arrays could not
 * be allocated.
 */
#include <stdlib.h>

#include "casadi_stewart.h"

int casadi_loop(const double *p, size_t n, const double *rows, double *out) {
    casadi_int sz_arg, sz_res, sz_iw, sz_w;
    stewart_casadi_id_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
    const casadi_real **arg = malloc((sz_arg > 4 ? sz_arg : 4) * sizeof *arg);
    casadi_real **res = malloc((sz_res > 1 ? sz_res : 1) * sizeof *res);
    casadi_int *iw = malloc((sz_iw > 0 ? sz_iw : 1) * sizeof *iw);
    casadi_real *w = malloc((sz_w > 0 ? sz_w : 1) * sizeof *w);
    int failures = -1;
    if (arg && res && iw && w) {
        failures = 0;
        arg[3] = p;
        for (size_t i = 0; i < n; ++i) {
            arg[0] = rows + 18 * i;
            arg[1] = rows + 18 * i + 6;
            arg[2] = rows + 18 * i + 12;
            res[0] = out + 6 * i;
            failures += stewart_casadi_id(arg, res, iw, w, 0) != 0;
        }
    }
    free(arg);
    free(res);
    free(iw);
    free(w);
    return failures;
}
