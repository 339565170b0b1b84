/* The model's evaluation (codegen/templates/vector.c, copied verbatim by the generator into
 * stewart_internal.h, which the model's units share): STEWART_LANES states evaluated at once,
 * one per lane of a GCC/Clang vector of doubles (its arithmetic: codegen/templates/lanes.c).
 * The generated kernels (vkernel_*), the solvers (vbareiss_*, vldl_*) and the block functions
 * of the public functions (vblock_*) work on structure-of-arrays blocks: entry k of the
 * block's states is one vector.  Every status test becomes a lane mask (all bits set: true),
 * and every step returns the status of each lane (0: STEWART_OK), merged so that a lane keeps
 * its first error.  batch_rows carries a batch of row-major states through a block function,
 * block by block, with the transposes, the finiteness tests and the NaN rows of the failed
 * states; a single-state function is its batch function on one row. */
#include "stewart_model.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

/* The statuses `status`, with `next` in the lanes still STEWART_OK (a lane keeps its first error). */
static stewart_vl vmerge(stewart_vl status, stewart_vl next)
{
    return status | ((status == 0) & next);
}

/* Lanes whose n entries v[k] are all finite. */
static stewart_vl vfinite(const stewart_vd *v, int n)
{
    stewart_vl ok = ~vnone();
    int k;
    for (k = 0; k < n; ++k) {
        ok &= vabs(v[k]) <= DBL_MAX;
    }
    return ok;
}

/* The legs' tests, in order (codegen/conditions.py), lane by lane: STEWART_ERR_LEG_DEGENERATE
 * if a leg has L2[i] < STEWART_DEGENERATE_TOL (or NaN), STEWART_ERR_NONFINITE if a leg's L2[i]
 * overflows, (h2 != NULL: the kernels in the frames {C_i}) STEWART_ERR_LEG_VERTICAL if a leg
 * has h2[i] = l_x^2 + l_y^2 < STEWART_VERTICAL_TOL * L2[i], and (n2 != NULL: the general
 * model) STEWART_ERR_GIMBAL_LOCK if a leg has n2[i] = |a_i x l_i|^2 < STEWART_GIMBAL_TOL *
 * L2[i]; else STEWART_OK. */
static stewart_vl vcheck_legs(const stewart_vd L2[6], const stewart_vd *h2, const stewart_vd *n2)
{
    stewart_vl degenerate = vnone(), overflow = vnone(), vertical = vnone(), gimbal = vnone();
    int i;
    for (i = 0; i < 6; ++i) {
        degenerate |= ~(L2[i] >= STEWART_DEGENERATE_TOL);
        overflow |= ~(L2[i] <= DBL_MAX);
        if (h2 != NULL) {
            vertical |= ~(h2[i] >= STEWART_VERTICAL_TOL * L2[i]);
        }
        if (n2 != NULL) {
            gimbal |= ~(n2[i] >= STEWART_GIMBAL_TOL * L2[i]);
        }
    }
    return vmerge(vmerge(vmerge(degenerate & STEWART_ERR_LEG_DEGENERATE, overflow & STEWART_ERR_NONFINITE),
                         vertical & STEWART_ERR_LEG_VERTICAL), gimbal & STEWART_ERR_GIMBAL_LOCK);
}

/* STEWART_OK unless cos(theta) is too small for the Euler-rate map J_A to be inverted, lane
 * by lane. */
static stewart_vl vcheck_euler(const stewart_vd ctheta[1])
{
    return ~(vabs(ctheta[0]) >= STEWART_EULER_TOL) & STEWART_ERR_EULER_SINGULAR;
}

/* xdd = [y_v; J_A^-1 y_w] from the twist acceleration y = T xdd, for n columns (6 rows of
 * n, row-major; y and xdd may not overlap), over a block. */
static stewart_vl vpose_accelerations(const stewart_vd JAinv[9], int n, const stewart_vd *y, stewart_vd *xdd)
{
    int i, c;
    for (c = 0; c < n; ++c) {
        for (i = 0; i < 3; ++i) {
            xdd[i * n + c] = y[i * n + c];
            xdd[(3 + i) * n + c] = JAinv[3 * i] * y[3 * n + c] + JAinv[3 * i + 1] * y[4 * n + c]
                + JAinv[3 * i + 2] * y[5 * n + c];
        }
    }
    return vnone();
}

/* n zeros, over a block. */
static stewart_vl vzero(stewart_vd *a, int n)
{
    int i;
    for (i = 0; i < n; ++i)
        a[i] = vsplat(0.0);
    return vnone();
}

/* M = M_t T, T = blockdiag(E, J_A) (eq. 18), from M_t and J_A (row-major), over a block. */
static stewart_vl vmass_matrix(const stewart_vd Mt[36], const stewart_vd JA[9], stewart_vd M[36])
{
    int i, j;
    for (i = 0; i < 6; ++i) {
        for (j = 0; j < 3; ++j) {
            M[6 * i + j] = Mt[6 * i + j];
            M[6 * i + 3 + j] = Mt[6 * i + 3] * JA[j] + Mt[6 * i + 4] * JA[3 + j] + Mt[6 * i + 5] * JA[6 + j];
        }
    }
    return vnone();
}

/* rhs = J_C^T tau - W (J_C row-major), over a block. */
static stewart_vl vforward_rhs(const stewart_vd JC[36], const stewart_vd tau[6], const stewart_vd W[6], stewart_vd rhs[6])
{
    int i;
    for (i = 0; i < 6; ++i)
        rhs[i] = JC[i] * tau[0] + JC[6 + i] * tau[1] + JC[12 + i] * tau[2] + JC[18 + i] * tau[3]
            + JC[24 + i] * tau[4] + JC[30 + i] * tau[5] - W[i];
    return vnone();
}

/* The 6 x 6 identity in every lane: its rows e_0, ..., e_5 (row-major). */
static stewart_vl videntity(stewart_vd E[36])
{
    int i;
    for (i = 0; i < 36; ++i)
        E[i] = vsplat(i % 7 == 0 ? 1.0 : 0.0);
    return vnone();
}

/* B = A^T of a 6 x 6 matrix (row-major), over a block. */
static stewart_vl vtranspose(const stewart_vd A[36], stewart_vd B[36])
{
    int i, j;
    for (i = 0; i < 6; ++i)
        for (j = 0; j < 6; ++j)
            B[6 * j + i] = A[6 * i + j];
    return vnone();
}

/* The legs' friction law, that of stewart_friction_forces and of the closed loop
 * (codegen/templates/control.c): a leg moving at the rate Ld loses F_v Ld + F_c tanh(Ld / v_c)
 * to friction, a viscous term and a smooth Coulomb term, lane-wise.  vcoulomb_sign is its
 * smooth sign tanh(Ld / v_c), taken as vtanh(Ld (1 / v_c)) (lanes.c: the same bits on every
 * CPU), as the regressor's friction columns (codegen/model.py, regressor_kernel) take it. */
static stewart_vd vcoulomb_sign(stewart_vd Ld, double velocity)
{
    return vtanh(Ld * (1.0 / velocity));
}

/* F_v Ld + F_c tanh(Ld / v_c), summed from +0 (a leg without friction loses +0); the Coulomb
 * term only where F_c != 0. */
static stewart_vd vfriction_force(stewart_vd Ld, double viscous, double coulomb, double velocity)
{
    stewart_vd force = 0.0 + viscous * Ld;
    if (coulomb != 0.0) {
        force += coulomb * vcoulomb_sign(Ld, velocity);
    }
    return force;
}

/* Where the legs do not spin with their joints (p->spinless_legs != 0, eq. 29), the columns a
 * and b of Y (n columns a row), the regressor's columns of the legs' axial moments, which then
 * never act, multiplied by 0, over a block. */
static stewart_vl vspinless_columns(const stewart_params *p, int n, int a, int b, stewart_vd *Y)
{
    int i;
    if (p->spinless_legs != 0.0) {
        for (i = 0; i < 6; ++i) {
            Y[n * i + a] *= 0.0;
            Y[n * i + b] *= 0.0;
        }
    }
    return vnone();
}

/* A block function: the outputs out[j] (size[j] vectors each) of the block of states whose
 * inputs are in[i] (6 vectors each), with the function's scalar input (if it has one);
 * returns each lane's status. */
typedef stewart_vl (*vblock_fn)(const stewart_params *p, double scalar, const stewart_vd *const in[],
                                stewart_vd *const out[]);

/* The classic RK4 step, the one of every integrator of the model (vrk4 here, the closed loop's
 * stewart_loop_rk4 in control.c), on doubles or vectors of doubles: stage s (0-3) evaluates
 * k_s = f(s_0 + RK4_FRACTION(s) dt k_{s-1}) (RK4_STAGE; the first at s_0 itself), and the step
 * is s_0 + dt/6 (k_0 + 2 k_1 + 2 k_2 + k_3) (RK4_UPDATE; RK4_WEIGHT(s) the weight of k_s). */
#define RK4_FRACTION(stage) ((stage) == 0 ? 0.0 : (stage) == 3 ? 1.0 : 0.5)
#define RK4_WEIGHT(stage) ((stage) == 0 || (stage) == 3 ? 1.0 : 2.0)
#define RK4_STAGE(s, h, k) ((s) + (h) * (k))
#define RK4_UPDATE(s, dt, k0, k1, k2, k3) ((s) + (dt) / 6.0 * ((k0) + 2.0 * (k1) + 2.0 * (k2) + (k3)))

/* The stage state t = s + h k of a stage after the first and, when S != NULL, its Jacobians
 * S = dt/ds = E + h K, U = dt/dtau = h KB (K, KB: those of k), over a block. */
static void vrk4_stage_state(const stewart_vd s[12], double h, const stewart_vd k[12], const stewart_vd *K,
                             const stewart_vd *KB, stewart_vd t[12], stewart_vd *S, stewart_vd *U)
{
    int i, j;
    for (i = 0; i < 12; ++i) {
        t[i] = RK4_STAGE(s[i], h, k[i]);
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

/* The Jacobians of the stage derivative k = f(t) = [t_xd; xdd(t_x, t_xd, tau)], K = df/dt S
 * and KB = df/dt U + df/dtau, with df/dt = [[0, E], [dxdd/dx, dxdd/dxd]] and
 * df/dtau = [0; dxdd/dtau], over a block: from the forward-dynamics Jacobians ax = dxdd/dx,
 * axd = dxdd/dxd, atau = dxdd/dtau at the stage state, whose Jacobians are S, U (S == NULL:
 * the first stage, S = E, U = 0). */
static void vrk4_stage_jacobians(const stewart_vd ax[36], const stewart_vd axd[36], const stewart_vd atau[36],
                                 const stewart_vd *S, const stewart_vd *U, stewart_vd K[144], stewart_vd KB[72])
{
    int i, j, m;
    for (i = 0; i < 6; ++i) {
        for (j = 0; j < 12; ++j) {
            stewart_vd sum = vsplat(0.0);
            if (S == NULL) {
                K[12 * i + j] = vsplat(j == 6 + i ? 1.0 : 0.0);
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
            stewart_vd sum = atau[6 * i + j];
            KB[6 * i + j] = U == NULL ? vsplat(0.0) : U[6 * (6 + i) + j];
            for (m = 0; U != NULL && m < 6; ++m) {
                sum += ax[6 * i + m] * U[6 * m + j] + axd[6 * i + m] * U[6 * (6 + m) + j];
            }
            KB[6 * (6 + i) + j] = sum;
        }
    }
}

/* The discrete-time dynamics, over a block of states: one classic RK4 step of the state
 * s = [x; xd] under constant tau, ds/dt = f(s) = [xd; xdd(x, xd, tau)], by RK4_STAGE and
 * RK4_UPDATE, the step of the simulator's closed loop (stewart_loop_rk4 in open loop with
 * constant feed-forward, no friction, no force limit) -- stages k_1 = f(s), k_2 = f(s + dt/2 k_1),
 * k_3 = f(s + dt/2 k_2), k_4 = f(s + dt k_3), s+ = s + dt/6 (k_1 + 2 k_2 + 2 k_3 + k_4) -- and, when `jac`, its exact
 * Jacobians A = ds+/ds, B = ds+/dtau by the chain rule through the four stages with the
 * forward-dynamics Jacobians.  in = {x, xd, tau}, out = {xn, xdn} and, when `jac`,
 * {A, B}; the stages' accelerations by `forward`, the block function of
 * stewart_forward_dynamics (out = {xdd}), or with `jac` of stewart_forward_dynamics_derivatives
 * (out = {xdd, dxdd/dx, dxdd/dxd, dxdd/dtau}), each stage with the checks that function
 * makes of its state and its results.  Every stage runs on every lane; a lane keeps the status
 * of its first failing stage. */
static stewart_vl vrk4(const stewart_params *p, vblock_fn forward, int jac, double dt, const stewart_vd *const in[],
                       stewart_vd *const out[])
{
    stewart_vd s[12], t[12], k[4][12], ax[36], axd[36], atau[36], S[144], U[72], K[2][144], KB[2][72];
    stewart_vd *const A = jac ? out[2] : NULL, *const B = jac ? out[3] : NULL;
    stewart_vl status = vsplat(isfinite(dt) ? 0.0 : 1.0) != 0.0;
    int i, j, stage;
    status &= STEWART_ERR_NONFINITE;
    for (i = 0; i < 6; ++i) {
        s[i] = in[0][i];
        s[6 + i] = in[1][i];
    }
    for (i = 0; jac && i < 144; ++i) {
        A[i] = vsplat(0.0);
    }
    for (i = 0; jac && i < 72; ++i) {
        B[i] = vsplat(0.0);
    }
    for (stage = 0; stage < 4; ++stage) {
        const int prev = (stage + 1) % 2, cur = stage % 2;
        if (stage) {
            vrk4_stage_state(s, RK4_FRACTION(stage) * dt, k[stage - 1], K[prev], KB[prev], t, jac ? S : NULL, U);
        } else {
            for (i = 0; i < 12; ++i) {
                t[i] = s[i];
            }
        }
        for (i = 0; i < 6; ++i) {
            k[stage][i] = t[6 + i];
        }
        status = vmerge(status, ~vfinite(t, 12) & STEWART_ERR_NONFINITE);
        status = vmerge(status, forward(p, 0.0, (const stewart_vd *const[]){t, t + 6, in[2]},
                                        (stewart_vd *const[]){k[stage] + 6, ax, axd, atau}));
        status = vmerge(status, ~vfinite(k[stage] + 6, 6) & STEWART_ERR_NONFINITE);
        if (jac) {
            status = vmerge(status, ~(vfinite(ax, 36) & vfinite(axd, 36) & vfinite(atau, 36)) & STEWART_ERR_NONFINITE);
            vrk4_stage_jacobians(ax, axd, atau, stage ? S : NULL, stage ? U : NULL, K[cur], KB[cur]);
            for (i = 0; i < 144; ++i) {
                A[i] += RK4_WEIGHT(stage) * K[cur][i];
            }
            for (i = 0; i < 72; ++i) {
                B[i] += RK4_WEIGHT(stage) * KB[cur][i];
            }
        }
    }
    for (i = 0; i < 12; ++i) {
        t[i] = RK4_UPDATE(s[i], dt, k[0][i], k[1][i], k[2][i], k[3][i]);
    }
    for (i = 0; i < 6; ++i) {
        out[0][i] = t[i];
        out[1][i] = t[6 + i];
    }
    for (i = 0; jac && i < 12; ++i) {
        for (j = 0; j < 12; ++j) {
            A[12 * i + j] = (i == j ? 1.0 : 0.0) + dt / 6.0 * A[12 * i + j];
        }
        for (j = 0; j < 6; ++j) {
            B[6 * i + j] = dt / 6.0 * B[6 * i + j];
        }
    }
    return status;
}

/* The n rows of a batch through `block`, STEWART_LANES rows at a time (the last block padded
 * with copies of the last row): rows[i] holds input i (n x 6, row-major), results[j] output j
 * (n x size[j]), in[i] and out[j] the block's buffers.  Row r gets its status in status[r] (status may be NULL): STEWART_ERR_NONFINITE when the parameters
 * (params_ok == 0) or its inputs are not finite, else its lane's status, else
 * STEWART_ERR_NONFINITE if an output is not finite; its outputs are NaN unless STEWART_OK.
 * Returns the status of the first row that is not STEWART_OK, or STEWART_OK. */
static int batch_rows(int params_ok, const stewart_params *p, vblock_fn block, double scalar, size_t n,
                      int nin, const double *const rows[], stewart_vd *const in[],
                      int nout, double *const results[], stewart_vd *const out[], const int size[],
                      int *status)
{
    int first = STEWART_OK;
    size_t base;
    for (base = 0; base < n; base += STEWART_LANES) {
        stewart_vl ok = vsplat(params_ok ? 0.0 : 1.0) == 0.0, lanes;
        int i, k, lane, failed;
        for (i = 0; i < nin; ++i) {
            for (lane = 0; lane < STEWART_LANES; ++lane) {
                const double *row = rows[i] + 6 * (base + lane < n ? base + lane : n - 1);
                for (k = 0; k < 6; ++k) {
                    in[i][k][lane] = row[k];
                }
            }
            ok &= vfinite(in[i], 6);
        }
        lanes = vmerge(~ok & STEWART_ERR_NONFINITE, block(p, scalar, (const stewart_vd *const *)in, out));
        ok = lanes == 0;
        for (i = 0; i < nout; ++i) {
            ok &= vfinite(out[i], size[i]);
        }
        lanes = vmerge(lanes, ~ok & STEWART_ERR_NONFINITE);
        failed = 0;
        for (lane = 0; lane < STEWART_LANES; ++lane) {
            failed |= lanes[lane] != 0;
        }
        for (i = 0; failed && i < nout; ++i) {
            for (k = 0; k < size[i]; ++k) {
                out[i][k] = vselect(lanes == 0, out[i][k], vsplat(NAN));
            }
        }
        for (lane = 0; lane < STEWART_LANES && base + lane < n; ++lane) {
            const size_t r = base + lane;
            for (i = 0; i < nout; ++i) {
                double *result = results[i] + size[i] * r;
                for (k = 0; k < size[i]; ++k) {
                    result[k] = out[i][k][lane];
                }
            }
            if (status != NULL) {
                status[r] = (int)lanes[lane];
            }
            if (first == STEWART_OK) {
                first = (int)lanes[lane];
            }
        }
    }
    return first;
}
