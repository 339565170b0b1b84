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
    /* reached 3.9e-15 (gcc and clang, x86-64 and aarch64: make test-ports) */
    check(status == STEWART_OK && err <= 1e-13, what, name, err);
}

/* Column k of the Jacobian of f (nout outputs) along input in[which][k], by central
 * differences: (f(+h) - f(-h)) / 2h with h = 1e-5 max(1, |in|).  Its error is O(h^2) times
 * the third derivative from truncation plus O(eps / h) times |f| from round-off, about 1e-9
 * of the Jacobian's scale for these smooth functions of O(1) inputs (reached 1.8e-9 on every
 * port): the checks allow 1e-7. */
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
    check(err <= 1e-7, what, name, err);
}


/* The batch functions against the single-state ones: every function with a batch variant, as
 * (p, inputs[3], out) and (p, n, inputs[3], out, status). */
typedef int (*row_fn)(const stewart_params *, const double *const *, double *);
typedef int (*batch_fn)(const stewart_params *, size_t, const double *const *, double *, int *);

#define BATCHED_1(name)                                                                        \
    static int row_##name(const stewart_params *p, const double *const *in, double *out) {     \
        return stewart_##name(p, in[0], out);                                                  \
    }                                                                                          \
    static int batch_##name(const stewart_params *p, size_t n, const double *const *in,         \
                            double *out, int *status) {                                        \
        return stewart_batch_##name(p, n, in[0], out, status);                                 \
    }
#define BATCHED_2(name)                                                                        \
    static int row_##name(const stewart_params *p, const double *const *in, double *out) {     \
        return stewart_##name(p, in[0], in[1], out);                                           \
    }                                                                                          \
    static int batch_##name(const stewart_params *p, size_t n, const double *const *in,         \
                            double *out, int *status) {                                        \
        return stewart_batch_##name(p, n, in[0], in[1], out, status);                          \
    }
#define BATCHED_3(name)                                                                        \
    static int row_##name(const stewart_params *p, const double *const *in, double *out) {     \
        return stewart_##name(p, in[0], in[1], in[2], out);                                    \
    }                                                                                          \
    static int batch_##name(const stewart_params *p, size_t n, const double *const *in,         \
                            double *out, int *status) {                                        \
        return stewart_batch_##name(p, n, in[0], in[1], in[2], out, status);                   \
    }
BATCHED_1(leg_lengths)
BATCHED_1(jacobian)
BATCHED_2(leg_rates)
BATCHED_1(mass_matrix)
BATCHED_1(twist_mass_matrix)
BATCHED_2(coriolis_matrix)
BATCHED_2(coriolis_vector)
BATCHED_1(gravity_vector)
BATCHED_3(inverse_dynamics)
BATCHED_3(forward_dynamics)
BATCHED_3(regressor)
/* The calibration's functions: xd stands for the encoder readings, and its first three for a target. */
BATCHED_2(leg_residuals)
BATCHED_2(target_positions)
BATCHED_2(target_jacobian)

#define MAX_ROWS 1003
#define MAX_SIZE 228 /* doubles of the largest output row (the RK4 step with its Jacobians) */
#define RK4_DT 1e-3

/* A derivative function, [primal (6); three 6 x 6 Jacobians] (114 doubles) a row. */
#define BATCHED_DERIVATIVES(name)                                                                    \
    static int row_##name(const stewart_params *p, const double *const *in, double *out) {           \
        return stewart_##name(p, in[0], in[1], in[2], out, out + 6, out + 42, out + 78);               \
    }                                                                                                \
    static int batch_##name(const stewart_params *p, size_t n, const double *const *in, double *out,  \
                            int *status) {                                                           \
        static double y[MAX_ROWS * 6], a[MAX_ROWS * 36], b[MAX_ROWS * 36], c[MAX_ROWS * 36];            \
        int first = stewart_batch_##name(p, n, in[0], in[1], in[2], y, a, b, c, status);               \
        for (size_t r = 0; r < n; ++r) {                                                             \
            memcpy(out + 114 * r, y + 6 * r, sizeof(double[6]));                                     \
            memcpy(out + 114 * r + 6, a + 36 * r, sizeof(double[36]));                               \
            memcpy(out + 114 * r + 42, b + 36 * r, sizeof(double[36]));                              \
            memcpy(out + 114 * r + 78, c + 36 * r, sizeof(double[36]));                              \
        }                                                                                            \
        return first;                                                                                \
    }
BATCHED_DERIVATIVES(inverse_dynamics_derivatives)
BATCHED_DERIVATIVES(forward_dynamics_derivatives)

/* The static forces and their Jacobian, [tau_s (6); dtau_s/dx (36)] (42 doubles) a row. */
static int row_static_force_derivatives(const stewart_params *p, const double *const *in, double *out) {
    return stewart_static_force_derivatives(p, in[0], out, out + 6);
}

static int batch_static_force_derivatives(const stewart_params *p, size_t n, const double *const *in, double *out,
                                          int *status) {
    static double tau[MAX_ROWS * 6], dtau[MAX_ROWS * 36];
    int first = stewart_batch_static_force_derivatives(p, n, in[0], tau, dtau, status);
    for (size_t r = 0; r < n; ++r) {
        memcpy(out + 42 * r, tau + 6 * r, sizeof(double[6]));
        memcpy(out + 42 * r + 6, dtau + 36 * r, sizeof(double[36]));
    }
    return first;
}

/* The RK4 step of RK4_DT with its Jacobians, [xn; xdn; A; B] (228 doubles) a row. */
static int row_rk4_step_derivatives(const stewart_params *p, const double *const *in, double *out) {
    return stewart_rk4_step_derivatives(p, in[0], in[1], in[2], RK4_DT, out, out + 6, out + 12, out + 156);
}

static int batch_rk4_step_derivatives(const stewart_params *p, size_t n, const double *const *in, double *out,
                                      int *status) {
    static double xn[MAX_ROWS * 6], xdn[MAX_ROWS * 6], A[MAX_ROWS * 144], B[MAX_ROWS * 72];
    int first = stewart_batch_rk4_step_derivatives(p, n, in[0], in[1], in[2], RK4_DT, xn, xdn, A, B, status);
    for (size_t r = 0; r < n; ++r) {
        memcpy(out + 228 * r, xn + 6 * r, sizeof(double[6]));
        memcpy(out + 228 * r + 6, xdn + 6 * r, sizeof(double[6]));
        memcpy(out + 228 * r + 12, A + 144 * r, sizeof(double[144]));
        memcpy(out + 228 * r + 156, B + 72 * r, sizeof(double[72]));
    }
    return first;
}

/* The RK4 step of RK4_DT, [xn; xdn] a row. */
static int row_rk4_step(const stewart_params *p, const double *const *in, double *out) {
    return stewart_rk4_step(p, in[0], in[1], in[2], RK4_DT, out, out + 6);
}

static int batch_rk4_step(const stewart_params *p, size_t n, const double *const *in, double *out, int *status) {
    static double xn[MAX_ROWS * 6], xdn[MAX_ROWS * 6];
    int first = stewart_batch_rk4_step(p, n, in[0], in[1], in[2], RK4_DT, xn, xdn, status);
    for (size_t r = 0; r < n; ++r) {
        memcpy(out + 12 * r, xn + 6 * r, sizeof(double[6]));
        memcpy(out + 12 * r + 6, xdn + 6 * r, sizeof(double[6]));
    }
    return first;
}

/* The terms of the equation of motion, [M; Vxd; G; JC] (84 doubles) a row. */
static int row_all_terms(const stewart_params *p, const double *const *in, double *out) {
    return stewart_all_terms(p, in[0], in[1], out, out + 36, out + 42, out + 48);
}

static int batch_all_terms(const stewart_params *p, size_t n, const double *const *in, double *out, int *status) {
    static double M[MAX_ROWS * 36], Vxd[MAX_ROWS * 6], G[MAX_ROWS * 6], JC[MAX_ROWS * 36];
    int first = stewart_batch_all_terms(p, n, in[0], in[1], M, Vxd, G, JC, status);
    for (size_t r = 0; r < n; ++r) {
        memcpy(out + 84 * r, M + 36 * r, sizeof(double[36]));
        memcpy(out + 84 * r + 36, Vxd + 6 * r, sizeof(double[6]));
        memcpy(out + 84 * r + 42, G + 6 * r, sizeof(double[6]));
        memcpy(out + 84 * r + 48, JC + 36 * r, sizeof(double[36]));
    }
    return first;
}

/* The calibration residuals' partials, [dr_dtheta (6 x 7); dr_dx (6 x 6)] (78 doubles) a row. */
static int row_leg_residual_jacobians(const stewart_params *p, const double *const *in, double *out) {
    return stewart_leg_residual_jacobians(p, in[0], out, out + 42);
}

static int batch_leg_residual_jacobians(const stewart_params *p, size_t n, const double *const *in, double *out,
                                        int *status) {
    static double own[MAX_ROWS * 42], pose[MAX_ROWS * 36];
    int first = stewart_batch_leg_residual_jacobians(p, n, in[0], own, pose, status);
    for (size_t r = 0; r < n; ++r) {
        memcpy(out + 78 * r, own + 42 * r, sizeof(double[42]));
        memcpy(out + 78 * r + 42, pose + 36 * r, sizeof(double[36]));
    }
    return first;
}

/* The joint reactions, [tau; f_base; f_platform; n_base] (60 doubles) a row. */
static int row_joint_reactions(const stewart_params *p, const double *const *in, double *out) {
    return stewart_joint_reactions(p, in[0], in[1], in[2], out, out + 6, out + 24, out + 42);
}

static int batch_joint_reactions(const stewart_params *p, size_t n, const double *const *in, double *out,
                                 int *status) {
    static double tau[MAX_ROWS * 6], fb[MAX_ROWS * 18], fp[MAX_ROWS * 18], nb[MAX_ROWS * 18];
    int first = stewart_batch_joint_reactions(p, n, in[0], in[1], in[2], tau, fb, fp, nb, status);
    for (size_t r = 0; r < n; ++r) {
        memcpy(out + 60 * r, tau + 6 * r, sizeof(double[6]));
        memcpy(out + 60 * r + 6, fb + 18 * r, sizeof(double[18]));
        memcpy(out + 60 * r + 24, fp + 18 * r, sizeof(double[18]));
        memcpy(out + 60 * r + 42, nb + 18 * r, sizeof(double[18]));
    }
    return first;
}

static const struct {
    const char *name;
    row_fn row;
    batch_fn batch;
    int size;
} BATCHED[] = {
    {"leg_lengths", row_leg_lengths, batch_leg_lengths, 6},
    {"jacobian", row_jacobian, batch_jacobian, 36},
    {"leg_rates", row_leg_rates, batch_leg_rates, 12},
    {"mass_matrix", row_mass_matrix, batch_mass_matrix, 36},
    {"twist_mass_matrix", row_twist_mass_matrix, batch_twist_mass_matrix, 36},
    {"coriolis_matrix", row_coriolis_matrix, batch_coriolis_matrix, 36},
    {"coriolis_vector", row_coriolis_vector, batch_coriolis_vector, 6},
    {"gravity_vector", row_gravity_vector, batch_gravity_vector, 6},
    {"all_terms", row_all_terms, batch_all_terms, 84},
    {"inverse_dynamics", row_inverse_dynamics, batch_inverse_dynamics, 6},
    {"forward_dynamics", row_forward_dynamics, batch_forward_dynamics, 6},
    {"regressor", row_regressor, batch_regressor, 192},
    {"rk4_step", row_rk4_step, batch_rk4_step, 12},
    {"joint_reactions", row_joint_reactions, batch_joint_reactions, 60},
    {"inverse_dynamics_derivatives", row_inverse_dynamics_derivatives, batch_inverse_dynamics_derivatives, 114},
    {"forward_dynamics_derivatives", row_forward_dynamics_derivatives, batch_forward_dynamics_derivatives, 114},
    {"static_force_derivatives", row_static_force_derivatives, batch_static_force_derivatives, 42},
    {"rk4_step_derivatives", row_rk4_step_derivatives, batch_rk4_step_derivatives, 228},
    {"leg_residuals", row_leg_residuals, batch_leg_residuals, 6},
    {"leg_residual_jacobians", row_leg_residual_jacobians, batch_leg_residual_jacobians, 78},
    {"target_positions", row_target_positions, batch_target_positions, 3},
    {"target_jacobian", row_target_jacobian, batch_target_jacobian, 18},
};

/* A number in [-1, 1) from the state of a linear congruential generator. */
static double uniform(unsigned long long *state) {
    *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*state >> 11) / 4503599627370496.0 - 1.0;
}

/* n rows of inputs around the case's state, with a singular row every 13: the platform in the
 * base plane (J_C singular), a zero-length leg, theta = 90 deg, a vertical leg, a NaN. */
static void batch_states(const reference_case *rc, size_t n, double in[3][MAX_ROWS][6]) {
    unsigned long long seed = 12345;
    const stewart_params *p = &rc->params;
    for (size_t r = 0; r < n; ++r) {
        for (int k = 0; k < 6; ++k) {
            in[0][r][k] = rc->x[k] + 0.05 * uniform(&seed);
            in[1][r][k] = rc->xd[k] + 0.5 * uniform(&seed);
            in[2][r][k] = rc->xdd[k] + 0.5 * uniform(&seed);
        }
        switch (r % 13) {
        case 3:
            for (int k = 0; k < 6; ++k) in[0][r][k] = 0.0;
            break;
        case 5:
        case 9:
            for (int k = 0; k < 6; ++k) in[0][r][k] = 0.0;
            for (int k = 0; k < 3; ++k) in[0][r][k] = p->base_points[r % 13 == 5 ? 0 : 2][k] - p->platform_points[r % 13 == 5 ? 0 : 2][k];
            in[0][r][2] += r % 13 == 5 ? 0.0 : 0.3;
            break;
        case 7:
            in[0][r][4] = acos(0.0);
            break;
        case 11:
            in[1][r][1] = NAN;
            break;
        }
    }
}

/* Every batch function against its single-state function on the case's batch of n rows: each
 * row's status and outputs as the single-state function gives them for the row alone, bit for
 * bit (at any position in a block of lanes: codegen/templates/vector.c), the first failing
 * row's status as the return value. */
static void check_batches(const reference_case *rc, size_t n, double *worst, unsigned *seen) {
    static double in[3][MAX_ROWS][6], got[MAX_ROWS * MAX_SIZE], want[MAX_SIZE];
    static int status[MAX_ROWS];
    batch_states(rc, n, in);
    const double *const rows[3] = {in[0][0], in[1][0], in[2][0]};
    for (size_t f = 0; f < sizeof BATCHED / sizeof BATCHED[0]; ++f) {
        int first = BATCHED[f].batch(&rc->params, n, rows, got, status), want_first = STEWART_OK;
        int same = 1;
        for (size_t r = 0; r < n; ++r) {
            const double *const row[3] = {in[0][r], in[1][r], in[2][r]};
            int st = BATCHED[f].row(&rc->params, row, want);
            if (want_first == STEWART_OK) want_first = st;
            same &= st == status[r];
            *seen |= 1u << st;
            const double *g = got + r * (size_t)BATCHED[f].size;
            if (st != STEWART_OK) {
                for (int k = 0; k < BATCHED[f].size; ++k) same &= isnan(g[k]);
                continue;
            }
            double err = rel_error(g, want, BATCHED[f].size);
            if (!(err <= *worst)) *worst = err;
            same &= memcmp(g, want, sizeof(double) * (size_t)BATCHED[f].size) == 0;
        }
        char what[80];
        snprintf(what, sizeof what, "batch %s, %zu rows", BATCHED[f].name, n);
        check(same && first == want_first, what, rc->name, *worst);
    }
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
        st = stewart_all_terms(p, rc->x, rc->xd, terms, terms + 36, terms + 42, terms + 48);
        check_values("all_terms: M", rc->name, st, terms, rc->M, 36, &worst);
        check_values("all_terms: Vxd", rc->name, st, terms + 36, rc->Vxd, 6, &worst);
        check_values("all_terms: G", rc->name, st, terms + 42, rc->G, 6, &worst);
        check_values("all_terms: JC", rc->name, st, terms + 48, rc->JC, 36, &worst);
        st = stewart_inverse_dynamics(p, rc->x, rc->xd, rc->xdd, out);
        check_values("inverse_dynamics", rc->name, st, out, rc->tau, 6, &worst);
        st = stewart_forward_dynamics(p, rc->x, rc->xd, rc->tau, out);
        check_values("forward_dynamics", rc->name, st, out, rc->xdd, 6, &worst);

        /* The joint reactions: tau as the reference's, and the legs' forces on the platform
         * balance its Newton equation, m_P (a + g e_z) = sum f_P (centre of mass at the origin). */
        double joints[60], push[3] = {0.0, 0.0, 0.0}, weight[3];
        st = stewart_joint_reactions(p, rc->x, rc->xd, rc->xdd, joints, joints + 6, joints + 24, joints + 42);
        check_values("joint_reactions: tau", rc->name, st, joints, rc->tau, 6, &worst);
        for (int i = 0; i < 6; ++i)
            for (int k = 0; k < 3; ++k) push[k] += joints[24 + 3 * i + k];
        for (int k = 0; k < 3; ++k) weight[k] = p->platform_mass * (rc->xdd[k] + (k == 2 ? p->gravity : 0.0));
        check_values("joint_reactions: platform's Newton equation", rc->name, st, push, weight, 3, &worst);

        /* The calibration's functions against the leg lengths and the reference's J_C, with
         * offsets of millimetres: the residuals r of readings e give back L = e + delta - r; per
         * leg, the target at p_i is at b_i + L_i u_i (u_i the first three partials of dr_i/dtheta);
         * the translation columns of dr/dx are -J_C's. */
        stewart_params q = *p;
        double L[6], e[6], r[6], back[6], own[42], pose[36], target[6] = {0.0}, at[3], end[3], u[18], JCu[18];
        for (int i = 0; i < 6; ++i) q.leg_length_offsets[i] = 1e-3 * (i - 2.5);
        stewart_leg_lengths(&q, rc->x, L);
        for (int i = 0; i < 6; ++i) e[i] = L[i] - q.leg_length_offsets[i] + 1e-4 * i;
        st = stewart_leg_residuals(&q, rc->x, e, r);
        for (int i = 0; i < 6; ++i) back[i] = e[i] + q.leg_length_offsets[i] - r[i];
        check_values("leg_residuals: e + delta - r = L", rc->name, st, back, L, 6, &worst);
        st = stewart_leg_residual_jacobians(&q, rc->x, own, pose);
        for (int i = 0; i < 6; ++i) {
            for (int k = 0; k < 3; ++k) target[k] = q.platform_points[i][k];
            int at_status = stewart_target_positions(&q, rc->x, target, at);
            for (int k = 0; k < 3; ++k) {
                end[k] = q.base_points[i][k] + L[i] * own[7 * i + k];
                u[3 * i + k] = -pose[6 * i + k];
                JCu[3 * i + k] = rc->JC[6 * i + k];
            }
            check_values("target_positions at p_i: b_i + L_i u_i", rc->name, st == STEWART_OK ? at_status : st, at,
                         end, 3, &worst);
        }
        check_values("leg_residual_jacobians: dr/dx = -J_C T, translation", rc->name, st, u, JCu, 18, &worst);

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
    double out[6], out36[36];
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

    /* The general model: a leg along its joint's first axis is the joint's gimbal lock,
     * flagged per row in a batch; the paper's model has no joint axes. */
    stewart_params jointed = *g;
    for (int i = 0; i < 6; ++i) {
        for (int k = 0; k < 3; ++k) jointed.universal_joint_axes[i][k] = k == 0 ? 1.0 : 0.0;
    }
    jointed.universal_joint_axes[2][0] = 0.0;
    jointed.universal_joint_axes[2][2] = 1.0;
    jointed.spinless_legs = 0.0; /* the legs spin with their joints */
    check(stewart_is_paper_model(p) && !stewart_is_paper_model(&jointed), "paper model: no joint axes", gc->name, 0);
    st = stewart_mass_matrix(&jointed, upright, out36);
    check(st == STEWART_ERR_GIMBAL_LOCK && isnan(out36[0]), "status: gimbal lock", gc->name, st);
    st = stewart_forward_dynamics(&jointed, upright, zero, zero, out);
    check(st == STEWART_ERR_GIMBAL_LOCK, "status: gimbal lock (forward dynamics)", gc->name, st);
    st = stewart_mass_matrix(&jointed, gc->x, out36);
    check(st == STEWART_OK, "status: the general model away from gimbal lock", gc->name, st);
    {
        double rows[4][6], taus[4][6];
        int statuses[4];
        for (int r = 0; r < 4; ++r) memcpy(rows[r], r == 2 ? upright : gc->x, sizeof rows[r]);
        double rates[4][6] = {{0}};
        stewart_batch_inverse_dynamics(&jointed, 4, rows[0], rates[0], rates[0], taus[0], statuses);
        check(statuses[0] == STEWART_OK && statuses[1] == STEWART_OK && statuses[2] == STEWART_ERR_GIMBAL_LOCK
              && statuses[3] == STEWART_OK && isnan(taus[2][0]) && !isnan(taus[3][0]),
              "status: gimbal lock flagged per row (batch)", gc->name, statuses[2]);
    }

    /* Legs that do not spin whatever their joint axes (spinless_legs): the regressor's columns
     * of the axial moments (12 and 17) are zero, the others those of the spinning legs. */
    {
        double Yspin[192], Yfixed[192];
        stewart_params fixed = jointed;
        fixed.spinless_legs = 1.0;
        int st0 = stewart_regressor(&jointed, gc->x, gc->xd, gc->xdd, Yspin);
        int st1 = stewart_regressor(&fixed, gc->x, gc->xd, gc->xdd, Yfixed);
        int axial = 0, same = 1;
        for (int i = 0; i < 6; ++i) {
            axial |= Yspin[32 * i + 12] != 0.0 || Yspin[32 * i + 17] != 0.0;
            for (int j = 0; j < 32; ++j) {
                same &= (j == 12 || j == 17) ? Yfixed[32 * i + j] == 0.0 : Yfixed[32 * i + j] == Yspin[32 * i + j];
            }
        }
        check(st0 == STEWART_OK && st1 == STEWART_OK && axial && same, "regressor: spinless legs, no axial columns",
              gc->name, st1);
    }

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

    /* Batches of 1, W - 1, W + 1 and 1000 + 3 rows, with singular rows, for every case. */
    double worst_batch = 0.0;
    unsigned seen = 0;
    const size_t lanes = (size_t)stewart_batch_lanes();
    const size_t sizes[] = {1, lanes - 1, lanes + 1, MAX_ROWS};
    for (int c = 0; c < NCASES; ++c) {
        for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; ++k) check_batches(&CASES[c], sizes[k], &worst_batch, &seen);
    }
    const int mixed[] = {STEWART_OK, STEWART_ERR_NONFINITE, STEWART_ERR_LEG_DEGENERATE, STEWART_ERR_JACOBIAN_SINGULAR,
                         STEWART_ERR_EULER_SINGULAR, STEWART_ERR_LEG_VERTICAL};
    for (size_t k = 0; k < sizeof mixed / sizeof mixed[0]; ++k) {
        check((seen >> mixed[k]) & 1u, "batches: rows of this status among the rows", stewart_status_message(mixed[k]), seen);
    }

    printf("generated C vs numeric reference: worst relative error %.3e over %d states\n", worst, NCASES);
    printf("batches (%zu lanes) vs the single-state functions: worst relative difference %.3e\n", lanes, worst_batch);
    printf("derivatives vs central differences of the primal functions: worst relative error %.3e\n", worst_fd);
    printf("%d passed, %d failed\n", passed, failed);
    return failed != 0;
}
