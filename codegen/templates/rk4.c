/* The discrete-time dynamics of stewart_model.c (codegen/templates/rk4.c, carried verbatim
 * by the generator after the generated public functions): one classic RK4 step of the state
 * s = [x; xd] under constant tau, ds/dt = f(s) = [xd; xdd(x, xd, tau)], with the operations
 * of the simulator's RK4 loop (stewart/_simulate.pyx, open loop with constant feed-forward,
 * no friction, no force limit), and its exact Jacobians by the chain rule through the four
 * stages with the forward-dynamics Jacobians.  Compiles on its own against stewart_model.h. */
#include "stewart_model.h"

#include <math.h>
#include <stddef.h>

/* The stage state t = s + h k (k == NULL: t = s, the first stage) and, when S != NULL, its
 * Jacobians S = dt/ds = E + h K, U = dt/dtau = h KB (K, KB: those of k). */
static void rk4_stage_state(const double s[12], double h, const double *k, const double *K,
                            const double *KB, double t[12], double *S, double *U)
{
    int i, j;
    for (i = 0; i < 12; ++i) {
        t[i] = k == NULL ? s[i] : s[i] + h * k[i];
    }
    for (i = 0; S != NULL && i < 12; ++i) {
        for (j = 0; j < 12; ++j) {
            S[12 * i + j] = (i == j ? 1.0 : 0.0) + h * K[12 * i + j];
        }
        for (j = 0; j < 6; ++j) {
            U[6 * i + j] = h * KB[6 * i + j];
        }
    }
}

/* The stage derivative k = f(t) = [t_xd; xdd(t_x, t_xd, tau)] and, when jac, its Jacobians
 * K = df/dt S and KB = df/dt U + df/dtau for the stage state's S = dt/ds and U = dt/dtau
 * (S == NULL: S = E, U = 0, the first stage); df/dt = [[0, E], [dxdd/dx, dxdd/dxd]],
 * df/dtau = [0; dxdd/dtau]. */
static int rk4_stage(const stewart_params *p, const double t[12], const double tau[6], int jac,
                     const double *S, const double *U, double k[12], double *K, double *KB)
{
    double ax[36], axd[36], atau[36];
    int i, j, m, status;
    for (i = 0; i < 6; ++i) {
        k[i] = t[6 + i];
    }
    if (!jac) {
        return stewart_forward_dynamics(p, t, t + 6, tau, k + 6);
    }
    status = stewart_forward_dynamics_derivatives(p, t, t + 6, tau, k + 6, ax, axd, atau);
    for (i = 0; i < 6; ++i) {
        for (j = 0; j < 12; ++j) {
            double sum = 0.0;
            if (S == NULL) {
                K[12 * i + j] = j == 6 + i ? 1.0 : 0.0;
                sum = j < 6 ? ax[6 * i + j] : axd[6 * i + j - 6];
            } else {
                K[12 * i + j] = S[12 * (6 + i) + j];
                for (m = 0; m < 6; ++m) {
                    sum += ax[6 * i + m] * S[12 * m + j] + axd[6 * i + m] * S[12 * (6 + m) + j];
                }
            }
            K[12 * (6 + i) + j] = sum;
        }
        for (j = 0; j < 6; ++j) {
            double sum = atau[6 * i + j];
            KB[6 * i + j] = U == NULL ? 0.0 : U[6 * (6 + i) + j];
            for (m = 0; U != NULL && m < 6; ++m) {
                sum += ax[6 * i + m] * U[6 * m + j] + axd[6 * i + m] * U[6 * (6 + m) + j];
            }
            KB[6 * (6 + i) + j] = sum;
        }
    }
    return status;
}

/* Every output NaN unless the status is STEWART_OK and they are all finite. */
static int rk4_finish(int status, double xn[6], double xdn[6], double *A, double *B)
{
    double *out[4] = {xn, xdn, A, B};
    const int n[4] = {6, 6, 144, 72};
    int i, k;
    for (i = 0; i < 4 && status == STEWART_OK; ++i) {
        for (k = 0; out[i] != NULL && k < n[i]; ++k) {
            if (!isfinite(out[i][k])) {
                status = STEWART_ERR_NONFINITE;
            }
        }
    }
    for (i = 0; i < 4 && status != STEWART_OK; ++i) {
        for (k = 0; out[i] != NULL && k < n[i]; ++k) {
            out[i][k] = NAN;
        }
    }
    return status;
}

/* The step, and A, B unless A == NULL: stages k_1 = f(s), k_2 = f(s + dt/2 k_1),
 * k_3 = f(s + dt/2 k_2), k_4 = f(s + dt k_3), s+ = s + dt/6 (k_1 + 2 k_2 + 2 k_3 + k_4). */
static int rk4(const stewart_params *p, const double x[6], const double xd[6], const double tau[6],
               double dt, double xn[6], double xdn[6], double *A, double *B)
{
    static const double fraction[4] = {0.0, 0.5, 0.5, 1.0};
    static const double weight[4] = {1.0, 2.0, 2.0, 1.0};
    double s[12], t[12], k[4][12], S[144], U[72], K[2][144], KB[2][72];
    int i, j, stage, status = isfinite(dt) ? STEWART_OK : STEWART_ERR_NONFINITE;
    const int jac = A != NULL;
    for (i = 0; i < 6; ++i) {
        s[i] = x[i];
        s[6 + i] = xd[i];
    }
    for (i = 0; jac && i < 144; ++i) {
        A[i] = 0.0;
    }
    for (i = 0; jac && i < 72; ++i) {
        B[i] = 0.0;
    }
    for (stage = 0; stage < 4 && status == STEWART_OK; ++stage) {
        const int prev = (stage + 1) % 2, cur = stage % 2;
        const double h = fraction[stage] * dt;
        rk4_stage_state(s, h, stage ? k[stage - 1] : NULL, stage ? K[prev] : NULL, stage ? KB[prev] : NULL,
                        t, jac && stage ? S : NULL, U);
        status = rk4_stage(p, t, tau, jac, stage ? S : NULL, stage ? U : NULL, k[stage], K[cur], KB[cur]);
        for (i = 0; jac && i < 144; ++i) {
            A[i] += weight[stage] * K[cur][i];
        }
        for (i = 0; jac && i < 72; ++i) {
            B[i] += weight[stage] * KB[cur][i];
        }
    }
    if (status == STEWART_OK) {
        for (i = 0; i < 12; ++i) {
            t[i] = s[i] + dt / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
        }
        for (i = 0; i < 6; ++i) {
            xn[i] = t[i];
            xdn[i] = t[6 + i];
        }
        for (i = 0; jac && i < 12; ++i) {
            for (j = 0; j < 12; ++j) {
                A[12 * i + j] = (i == j ? 1.0 : 0.0) + dt / 6.0 * A[12 * i + j];
            }
            for (j = 0; j < 6; ++j) {
                B[6 * i + j] = dt / 6.0 * B[6 * i + j];
            }
        }
    }
    return rk4_finish(status, xn, xdn, A, B);
}

int stewart_rk4_step(const stewart_params *p, const double x[6], const double xd[6], const double tau[6],
                     double dt, double xn[6], double xdn[6])
{
    return rk4(p, x, xd, tau, dt, xn, xdn, NULL, NULL);
}

int stewart_rk4_step_derivatives(const stewart_params *p, const double x[6], const double xd[6],
                                 const double tau[6], double dt, double xn[6], double xdn[6],
                                 double A[144], double B[72])
{
    return rk4(p, x, xd, tau, dt, xn, xdn, A, B);
}
