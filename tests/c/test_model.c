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

int main(void) {
    double worst = 0.0;
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
    }

    /* Both kernel families: axisymmetric legs and the general ones with the cylinder frame. */
    check(general > 0 && general < NCASES, "cases with general (non-axisymmetric) legs", "", general);

    /* Status codes: outputs are NaN whenever a status is returned. */
    const stewart_params *p = &CASES[0].params;
    const double zero[6] = {0, 0, 0, 0, 0, 0};
    double out[6], out36[36];
    int st = stewart_inverse_dynamics(p, zero, zero, zero, out); /* platform in the base plane */
    check(st == STEWART_ERR_JACOBIAN_SINGULAR && isnan(out[0]), "status: singular J_C", CASES[0].name, st);
    double tilted[6];
    memcpy(tilted, CASES[0].x, sizeof tilted);
    tilted[4] = acos(0.0);
    st = stewart_forward_dynamics(p, tilted, zero, zero, out);
    check(st == STEWART_ERR_EULER_SINGULAR && isnan(out[5]), "status: theta = 90 deg", CASES[0].name, st);
    double bad[6];
    memcpy(bad, CASES[0].x, sizeof bad);
    bad[2] = NAN;
    st = stewart_gravity_vector(p, bad, out);
    check(st == STEWART_ERR_NONFINITE && isnan(out[2]), "status: non-finite input", CASES[0].name, st);
    /* A leg of zero length: P_0 on B_0, no rotation. */
    double collapsed[6] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < 3; ++k) collapsed[k] = p->base_points[0][k] - p->platform_points[0][k];
    st = stewart_jacobian(p, collapsed, out36);
    check(st == STEWART_ERR_LEG_DEGENERATE && isnan(out36[0]), "status: zero-length leg (jacobian)", CASES[0].name, st);
    st = stewart_inverse_dynamics(p, collapsed, zero, zero, out);
    check(st == STEWART_ERR_LEG_DEGENERATE, "status: zero-length leg (inverse dynamics)", CASES[0].name, st);
    st = stewart_leg_lengths(p, collapsed, out);
    check(st == STEWART_OK && out[0] == 0.0, "status: zero-length leg is a length", CASES[0].name, st);

    /* A vertical leg: singular with general leg inertia only (and not for G, J_C). */
    const reference_case *gc = &CASES[0];
    for (int c = 0; c < NCASES; ++c) {
        if (!stewart_is_axisymmetric(&CASES[c].params)) { gc = &CASES[c]; break; }
    }
    const stewart_params *g = &gc->params;
    double upright[6] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < 3; ++k) upright[k] = g->base_points[2][k] - g->platform_points[2][k];
    upright[2] += 0.3;
    st = stewart_mass_matrix(g, upright, out36);
    check(!stewart_is_axisymmetric(g) && st == STEWART_ERR_LEG_VERTICAL && isnan(out36[35]),
          "status: vertical leg, general inertia", gc->name, st);
    st = stewart_forward_dynamics(g, upright, zero, zero, out);
    check(st == STEWART_ERR_LEG_VERTICAL, "status: vertical leg, general inertia (forward dynamics)", gc->name, st);
    st = stewart_gravity_vector(g, upright, out);
    check(st == STEWART_OK, "status: vertical leg, gravity needs no leg frame", gc->name, st);
    stewart_params axisymmetric = *g;
    axisymmetric.cylinder_inertia[2] = axisymmetric.cylinder_inertia[1];
    axisymmetric.piston_inertia[2] = axisymmetric.piston_inertia[1];
    st = stewart_mass_matrix(&axisymmetric, upright, out36);
    check(st == STEWART_OK, "status: vertical leg, axisymmetric inertia", gc->name, st);

    /* A massless platform with massless legs: M_t = 0. */
    stewart_params massless = *p;
    massless.platform_mass = massless.cylinder_mass = massless.piston_mass = 0.0;
    for (int k = 0; k < 3; ++k) {
        massless.platform_inertia[k] = massless.cylinder_inertia[k] = massless.piston_inertia[k] = 0.0;
    }
    st = stewart_forward_dynamics(&massless, CASES[0].x, zero, zero, out);
    check(st == STEWART_ERR_MASS_SINGULAR && isnan(out[0]), "status: massless platform", CASES[0].name, st);
    st = stewart_inverse_dynamics(&massless, CASES[0].x, zero, zero, out);
    check(st == STEWART_OK, "status: massless platform, inverse dynamics", CASES[0].name, st);

    /* Overflow: a leg's length, or a result. */
    double far[6];
    memcpy(far, CASES[0].x, sizeof far);
    far[0] = 1e200;
    st = stewart_mass_matrix(p, far, out36);
    check(st == STEWART_ERR_NONFINITE, "status: overflowing leg length", CASES[0].name, st);
    const double huge[6] = {1e308, 1e308, 1e308, 1e308, 1e308, 1e308};
    st = stewart_forward_dynamics(p, CASES[0].x, zero, huge, out);
    check(st == STEWART_ERR_NONFINITE && isnan(out[0]), "status: overflowing result", CASES[0].name, st);

    /* Precedence: the legs before the steps, cos(theta) before M_t. */
    st = stewart_forward_dynamics(&massless, tilted, zero, zero, out);
    check(st == STEWART_ERR_EULER_SINGULAR, "precedence: theta = 90 deg before M_t", CASES[0].name, st);
    stewart_params pinned = *p; /* platform point 0 at the platform's origin: P_0 = p in any orientation */
    for (int k = 0; k < 3; ++k) pinned.platform_points[0][k] = 0.0;
    double pinned_x[6] = {p->base_points[0][0], p->base_points[0][1], p->base_points[0][2], 0, acos(0.0), 0};
    st = stewart_forward_dynamics(&pinned, pinned_x, zero, zero, out);
    check(st == STEWART_ERR_LEG_DEGENERATE, "precedence: zero-length leg before theta = 90 deg", CASES[0].name, st);
    st = stewart_inverse_dynamics(g, (const double[6]){0, 0, 0, 0, 0, 0}, zero, zero, out);
    check(st == STEWART_ERR_JACOBIAN_SINGULAR, "status: singular J_C, general inertia", gc->name, st);

    /* Every status code has its own message. */
    for (int a = STEWART_OK; a <= STEWART_ERR_MASS_SINGULAR; ++a) {
        check(strcmp(stewart_status_message(a), "unknown status") != 0, "status message", "", a);
        for (int b = STEWART_OK; b < a; ++b) {
            check(strcmp(stewart_status_message(a), stewart_status_message(b)) != 0, "distinct messages", "", a);
        }
    }
    check(strcmp(stewart_status_message(-1), "unknown status") == 0, "unknown status message", "", -1);

    printf("generated C vs numeric reference: worst relative error %.3e over %d states\n", worst, NCASES);
    printf("%d passed, %d failed\n", passed, failed);
    return failed != 0;
}
