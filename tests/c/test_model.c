/* Checks the generated C model on its own (no Python): its results against values
 * saved from the numeric reference (reference_values.h), for axisymmetric and general
 * leg inertias, and its status codes.
 * Built and run by `make test`; prints "N passed, M failed" and exits non-zero on failure. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "stewart_model.h"
#include "reference_values.h"

#define NCASES ((int)(sizeof CASES / sizeof CASES[0]))

static int passed = 0, failed = 0;

/* Worst |got - want| relative to the largest |want|, over n entries. */
static double rel_error(const double *got, const double *want, int n) {
    double err = 0.0, scale = 0.0;
    for (int k = 0; k < n; ++k) {
        if (fabs(want[k]) > scale) scale = fabs(want[k]);
    }
    for (int k = 0; k < n; ++k) {
        double e = fabs(got[k] - want[k]) / scale;
        if (!(e <= err)) err = e; /* NaN counts as the worst */
    }
    return err;
}

static void check(int ok, const char *what, const char *name, double value) {
    if (ok) {
        ++passed;
    } else {
        ++failed;
        printf("FAILED %s (%s): %.3e\n", what, name, value);
    }
}

static void check_values(const char *what, const char *name, int status, const double *got,
                         const double *want, int n, double *worst) {
    double err = rel_error(got, want, n);
    if (err > *worst) *worst = err;
    check(status == STEWART_OK && err <= 1e-10, what, name, err);
}

/* Column k of the Jacobian of f (nout outputs) along input in[which][k], by central
 * differences: (f(+h) - f(-h)) / 2h with h = 1e-5 max(1, |in|).  Its error is O(h^2) times
 * the third derivative from truncation plus O(eps / h) times |f| from round-off, about 1e-9
 * of the Jacobian's scale for these smooth functions of O(1) inputs: the checks allow 1e-6. */
typedef int (*three_input_fn)(const stewart_params *, const double *, const double *, const double *,
                              double, double *);

static void fd_column(three_input_fn f, const stewart_params *p, const double in[3][6], double dt,
                      int which, int k, int nout, double *column) {
    double plus[3][6], minus[3][6], fp[12], fm[12];
    memcpy(plus, in, sizeof plus);
    memcpy(minus, in, sizeof minus);
    double h = 1e-5 * (fabs(in[which][k]) > 1.0 ? fabs(in[which][k]) : 1.0);
    plus[which][k] += h;
    minus[which][k] -= h;
    f(p, plus[0], plus[1], plus[2], dt, fp);
    f(p, minus[0], minus[1], minus[2], dt, fm);
    for (int i = 0; i < nout; ++i) column[i] = (fp[i] - fm[i]) / (2.0 * h);
}

static int id_fn(const stewart_params *p, const double *x, const double *xd, const double *xdd, double dt,
                 double *out) {
    (void)dt;
    return stewart_inverse_dynamics(p, x, xd, xdd, out);
}

static int fd_fn(const stewart_params *p, const double *x, const double *xd, const double *tau, double dt,
                 double *out) {
    (void)dt;
    return stewart_forward_dynamics(p, x, xd, tau, out);
}

static int step_fn(const stewart_params *p, const double *x, const double *xd, const double *tau, double dt,
                   double *out) {
    return stewart_rk4_step(p, x, xd, tau, dt, out, out + 6);
}

/* A Jacobian given as three blocks of 6 columns, block b the columns firsts[b] ... of
 * jac[b] (row-major, widths[b] columns), against central differences of f along the
 * inputs in[0], in[1], in[2] in turn. */
static void check_jacobian(const char *what, const char *name, three_input_fn f, const stewart_params *p,
                           const double in[3][6], double dt, int nout, const int firsts[3],
                           const int widths[3], const double *const jac[3], double *worst) {
    double want[12 * 18], got[12 * 18], column[12];
    for (int b = 0, c = 0; b < 3; ++b) {
        for (int k = 0; k < 6; ++k, ++c) {
            fd_column(f, p, in, dt, b, k, nout, column);
            for (int i = 0; i < nout; ++i) {
                want[i * 18 + c] = column[i];
                got[i * 18 + c] = jac[b][i * widths[b] + firsts[b] + k];
            }
        }
    }
    double err = rel_error(got, want, nout * 18);
    if (err > *worst) *worst = err;
    check(err <= 1e-6, what, name, err);
}

int main(void) {
    double worst = 0.0, worst_fd = 0.0;
    int general = 0;
    for (int c = 0; c < NCASES; ++c) {
        const reference_case *rc = &CASES[c];
        const stewart_params *p = &rc->params;
        double out[36], terms[84];
        int st;
        general += !stewart_is_axisymmetric(p);
        st = stewart_leg_lengths(p, rc->x, out);
        check_values("leg_lengths", rc->name, st, out, rc->L, 6, &worst);
        st = stewart_leg_rates(p, rc->x, rc->xd, out);
        check_values("leg_rates: L", rc->name, st, out, rc->L, 6, &worst);
        check_values("leg_rates: Ldot", rc->name, st, out + 6, rc->Ld, 6, &worst);
        st = stewart_jacobian(p, rc->x, out);
        check_values("jacobian", rc->name, st, out, rc->JC, 36, &worst);
        st = stewart_mass_matrix(p, rc->x, out);
        check_values("mass_matrix", rc->name, st, out, rc->M, 36, &worst);
        st = stewart_twist_mass_matrix(p, rc->x, out);
        check_values("twist_mass_matrix", rc->name, st, out, rc->Mt, 36, &worst);
        st = stewart_coriolis_matrix(p, rc->x, rc->xd, out);
        check_values("coriolis_matrix", rc->name, st, out, rc->V, 36, &worst);
        st = stewart_coriolis_vector(p, rc->x, rc->xd, out);
        check_values("coriolis_vector", rc->name, st, out, rc->Vxd, 6, &worst);
        st = stewart_gravity_vector(p, rc->x, out);
        check_values("gravity_vector", rc->name, st, out, rc->G, 6, &worst);
        st = stewart_all_terms(p, rc->x, rc->xd, terms);
        check_values("all_terms: M", rc->name, st, terms, rc->M, 36, &worst);
        check_values("all_terms: Vxd", rc->name, st, terms + 36, rc->Vxd, 6, &worst);
        check_values("all_terms: G", rc->name, st, terms + 42, rc->G, 6, &worst);
        check_values("all_terms: JC", rc->name, st, terms + 48, rc->JC, 36, &worst);
        st = stewart_inverse_dynamics(p, rc->x, rc->xd, rc->xdd, out);
        check_values("inverse_dynamics", rc->name, st, out, rc->tau, 6, &worst);
        st = stewart_forward_dynamics(p, rc->x, rc->xd, rc->tau, out);
        check_values("forward_dynamics", rc->name, st, out, rc->xdd, 6, &worst);

        /* The derivative functions: their primal outputs equal the primal functions' to the
         * last bit, their Jacobians agree with central differences of the primal functions,
         * and dtau/dxdd dxdd/dtau = E. */
        double tau[6], dtau[3][36], xdd[6], dxdd[3][36], step[12], stepd[12], A[144], B[72];
        double id_in[3][6], fd_in[3][6];
        memcpy(id_in[0], rc->x, sizeof id_in[0]);
        memcpy(id_in[1], rc->xd, sizeof id_in[1]);
        memcpy(id_in[2], rc->xdd, sizeof id_in[2]);
        st = stewart_inverse_dynamics_derivatives(p, rc->x, rc->xd, rc->xdd, tau, dtau[0], dtau[1], dtau[2]);
        stewart_inverse_dynamics(p, rc->x, rc->xd, rc->xdd, out);
        check(st == STEWART_OK && memcmp(tau, out, sizeof tau) == 0, "inverse_dynamics_derivatives: tau",
              rc->name, st);
        check_jacobian("inverse_dynamics_derivatives", rc->name, id_fn, p, (const double (*)[6])id_in, 0.0, 6,
                       (const int[]){0, 0, 0}, (const int[]){6, 6, 6},
                       (const double *const[]){dtau[0], dtau[1], dtau[2]}, &worst_fd);
        memcpy(fd_in[0], rc->x, sizeof fd_in[0]);
        memcpy(fd_in[1], rc->xd, sizeof fd_in[1]);
        memcpy(fd_in[2], tau, sizeof fd_in[2]);
        st = stewart_forward_dynamics_derivatives(p, rc->x, rc->xd, tau, xdd, dxdd[0], dxdd[1], dxdd[2]);
        stewart_forward_dynamics(p, rc->x, rc->xd, tau, out);
        check(st == STEWART_OK && memcmp(xdd, out, sizeof xdd) == 0, "forward_dynamics_derivatives: xdd",
              rc->name, st);
        check_jacobian("forward_dynamics_derivatives", rc->name, fd_fn, p, (const double (*)[6])fd_in, 0.0, 6,
                       (const int[]){0, 0, 0}, (const int[]){6, 6, 6},
                       (const double *const[]){dxdd[0], dxdd[1], dxdd[2]}, &worst_fd);
        double product[36], identity[36];
        for (int i = 0; i < 6; ++i) {
            for (int j = 0; j < 6; ++j) {
                double sum = 0.0;
                for (int m = 0; m < 6; ++m) sum += dtau[2][6 * i + m] * dxdd[2][6 * m + j];
                product[6 * i + j] = sum;
                identity[6 * i + j] = i == j;
            }
        }
        check_values("dtau/dxdd dxdd/dtau = E", rc->name, st, product, identity, 36, &worst);
        const double dt = 1e-3;
        st = stewart_rk4_step_derivatives(p, rc->x, rc->xd, tau, dt, stepd, stepd + 6, A, B);
        int st_step = stewart_rk4_step(p, rc->x, rc->xd, tau, dt, step, step + 6);
        check(st == STEWART_OK && st_step == STEWART_OK && memcmp(step, stepd, sizeof step) == 0,
              "rk4_step_derivatives: step", rc->name, st);
        check_jacobian("rk4_step_derivatives", rc->name, step_fn, p, (const double (*)[6])fd_in, dt, 12,
                       (const int[]){0, 6, 0}, (const int[]){12, 12, 6},
                       (const double *const[]){A, A, B}, &worst_fd);
    }

    /* Both kernel families: axisymmetric legs and the general ones with the cylinder frame. */
    check(general > 0 && general < NCASES, "cases with general (non-axisymmetric) legs", "", general);

    /* Status codes: outputs are NaN whenever a status is returned. */
    const stewart_params *p = &CASES[0].params;
    const double zero[6] = {0, 0, 0, 0, 0, 0};
    double out[6];
    int st = stewart_inverse_dynamics(p, zero, zero, zero, out); /* platform in the base plane */
    check(st == STEWART_ERR_JACOBIAN_SINGULAR && isnan(out[0]), "status: singular J_C", CASES[0].name, st);
    double d[3][36];
    st = stewart_inverse_dynamics_derivatives(p, zero, zero, zero, out, d[0], d[1], d[2]);
    check(st == STEWART_ERR_JACOBIAN_SINGULAR && isnan(out[0]) && isnan(d[0][0]) && isnan(d[1][35])
          && isnan(d[2][17]), "status: singular J_C (derivatives, every output NaN)", CASES[0].name, st);
    double tilted[6];
    memcpy(tilted, CASES[0].x, sizeof tilted);
    tilted[4] = acos(0.0);
    st = stewart_forward_dynamics(p, tilted, zero, zero, out);
    check(st == STEWART_ERR_EULER_SINGULAR && isnan(out[5]), "status: theta = 90 deg", CASES[0].name, st);
    st = stewart_forward_dynamics_derivatives(p, tilted, zero, zero, out, d[0], d[1], d[2]);
    check(st == STEWART_ERR_EULER_SINGULAR && isnan(out[5]) && isnan(d[0][3]) && isnan(d[2][35]),
          "status: theta = 90 deg (derivatives, every output NaN)", CASES[0].name, st);
    double xn[6], xdn[6], A0[144], B0[72];
    st = stewart_rk4_step_derivatives(p, tilted, zero, zero, 1e-3, xn, xdn, A0, B0);
    check(st == STEWART_ERR_EULER_SINGULAR && isnan(xn[0]) && isnan(xdn[0]) && isnan(A0[143]) && isnan(B0[71]),
          "status: theta = 90 deg (RK4 step, every output NaN)", CASES[0].name, st);
    st = stewart_rk4_step(p, CASES[0].x, zero, zero, NAN, xn, xdn);
    check(st == STEWART_ERR_NONFINITE && isnan(xn[0]) && isnan(xdn[5]), "status: non-finite dt", CASES[0].name, st);
    double bad[6];
    memcpy(bad, CASES[0].x, sizeof bad);
    bad[2] = NAN;
    st = stewart_gravity_vector(p, bad, out);
    check(st == STEWART_ERR_NONFINITE && isnan(out[2]), "status: non-finite input", CASES[0].name, st);
    check(strlen(stewart_status_message(STEWART_ERR_JACOBIAN_SINGULAR)) > 0, "status message", "", 0);

    printf("generated C vs numeric reference: worst relative error %.3e over %d states\n", worst, NCASES);
    printf("derivatives vs central differences of the primal functions: worst relative error %.3e\n", worst_fd);
    printf("%d passed, %d failed\n", passed, failed);
    return failed != 0;
}
