/* The actuators and the closed loop (codegen/templates/control.c, copied verbatim by the
 * generator into stewart_model.c after the public functions it calls): the legs' friction
 * forces (vector.c's friction law), the force saturation, the control laws (joint-space PID,
 * task-space computed torque, open loop) and the closed loop's fixed-step RK4 (the classic
 * step of vector.c's RK4_STAGE and RK4_UPDATE, that of stewart_rk4_step).
 * Compiles on its own against stewart_internal.h. */
#include "stewart_internal.h"

#include <math.h>
#include <stddef.h>

/* The force leg k loses to friction at the leg rate Ld: the friction law of vector.c's
 * vfriction_force (that of the regressor's columns) on one rate. */
static double friction_force(const stewart_friction *f, int k, double Ld)
{
    return vfriction_force(vsplat(Ld), f->viscous[k], f->coulomb[k], f->velocity)[0];
}

int stewart_batch_friction_forces(const stewart_friction *f, size_t n, const double *Ld, double *friction, int *status)
{
    const int params_ok = all_finite(f->viscous, 6) && all_finite(f->coulomb, 6) && isfinite(f->velocity);
    int first = STEWART_OK;
    size_t r;
    for (r = 0; r < n; ++r) {
        const double *rate = Ld + 6 * r;
        double *out = friction + 6 * r;
        int k, ok = params_ok;
        for (k = 0; k < 6; ++k) {
            out[k] = friction_force(f, k, rate[k]);
            ok &= isfinite(out[k]) != 0;
        }
        for (k = 0; !ok && k < 6; ++k) {
            out[k] = NAN;
        }
        if (status != NULL) {
            status[r] = ok ? STEWART_OK : STEWART_ERR_NONFINITE;
        }
        if (first == STEWART_OK && !ok) {
            first = STEWART_ERR_NONFINITE;
        }
    }
    return first;
}

int stewart_friction_forces(const stewart_friction *f, const double *Ld, double *friction)
{
    return stewart_batch_friction_forces(f, 1, Ld, friction, NULL);
}

/* The force within +-limit: the commanded force saturated by its actuator. */
static double saturated(double force, double limit)
{
    if (force > limit) {
        return limit;
    }
    if (force < -limit) {
        return -limit;
    }
    return force;
}

int stewart_loop_derivative(const stewart_params *p, const stewart_loop *loop, const double *y, const double *ref,
                            const double *feedforward, double *ydot, double *force, double *L, double *Ld)
{
    double LLd[12], Lr[6], Ldr[6], acc[6], applied[6];
    int k, status = stewart_leg_rates(p, y, y + 6, LLd);
    for (k = 0; k < 6; ++k) {
        L[k] = LLd[k];
        Ld[k] = LLd[6 + k];
    }
    if (status != STEWART_OK) {
        return status;
    }
    if (loop->mode == STEWART_PID) {
        /* Joint space: the leg-length error, its integral (the state's last 6) and its rate. */
        status = stewart_leg_rates(p, ref, ref + 6, LLd);
        for (k = 0; k < 6; ++k) {
            Lr[k] = LLd[k];
            Ldr[k] = LLd[6 + k];
        }
        if (status != STEWART_OK) {
            return status;
        }
        for (k = 0; k < 6; ++k) {
            ydot[12 + k] = Lr[k] - L[k];
            force[k] = (loop->kp[k] * (Lr[k] - L[k]) + loop->ki[k] * y[12 + k]
                        + loop->kd[k] * (Ldr[k] - Ld[k]) + feedforward[k]);
        }
    } else if (loop->mode == STEWART_COMPUTED_TORQUE) {
        /* Task space: the inverse dynamics of the reference acceleration corrected by the pose
         * error and its rate, plus the model's friction at the measured leg rates. */
        for (k = 0; k < 6; ++k) {
            ydot[12 + k] = 0.0;
            acc[k] = ref[12 + k] + loop->kd[k] * (ref[6 + k] - y[6 + k]) + loop->kp[k] * (ref[k] - y[k]);
        }
        status = stewart_inverse_dynamics(p, y, y + 6, acc, force);
        if (status != STEWART_OK) {
            return status;
        }
        for (k = 0; k < 6; ++k) {
            force[k] += friction_force(&loop->model_friction, k, Ld[k]) + feedforward[k];
        }
    } else {
        for (k = 0; k < 6; ++k) {
            ydot[12 + k] = 0.0;
            force[k] = feedforward[k];
        }
    }
    for (k = 0; k < 6; ++k) {
        applied[k] = saturated(force[k], loop->force_limit[k]);
        applied[k] -= friction_force(&loop->friction, k, Ld[k]);
    }
    for (k = 0; k < 6; ++k) {
        ydot[k] = y[6 + k];
    }
    return stewart_forward_dynamics(p, y, y + 6, applied, ydot + 6);
}

int stewart_loop_rk4(const stewart_params *p, const stewart_loop *loop, double *y, const double *refs,
                     const double *feedforward, double dt, size_t start, size_t stop, double min_length,
                     double max_length, double *states, double *forces, double *lengths, double *rates,
                     size_t *step, int *leg)
{
    double k[4][18], t[18], scratch[18], Lnew[6];
    int status = STEWART_OK, i, j, stage;
    size_t n;
    *leg = -1;
    for (n = start; n < stop; ++n) {
        for (j = 0; j < 18; ++j) {
            states[18 * n + j] = y[j];
        }
        /* Stage s at t_n + c_s dt: the reference and feed-forward rows 2n, 2n + 1, 2n + 1, 2n + 2. */
        for (stage = 0; stage < 4 && status == STEWART_OK; ++stage) {
            const size_t row = 2 * n + (size_t)(stage + 1) / 2;
            if (stage) {
                for (j = 0; j < 18; ++j) {
                    t[j] = RK4_STAGE(y[j], RK4_FRACTION(stage) * dt, k[stage - 1][j]);
                }
            }
            status = stage ? stewart_loop_derivative(p, loop, t, refs + 18 * row, feedforward + 6 * row, k[stage],
                                                     scratch, scratch + 6, scratch + 12)
                           : stewart_loop_derivative(p, loop, y, refs + 18 * row, feedforward + 6 * row, k[0],
                                                     forces + 6 * n, lengths + 6 * n, rates + 6 * n);
        }
        if (status != STEWART_OK) {
            break;
        }
        for (j = 0; j < 18; ++j) {
            y[j] = RK4_UPDATE(y[j], dt, k[0][j], k[1][j], k[2][j], k[3][j]);
            if (!isfinite(y[j])) {
                status = STEWART_STOP_NONFINITE;
            }
        }
        if (status == STEWART_OK) {
            stewart_leg_lengths(p, y, Lnew);
            for (i = 0; i < 6; ++i) {
                if (Lnew[i] < min_length) {
                    status = STEWART_STOP_LEG_SHORT;
                    *leg = i;
                } else if (Lnew[i] > max_length) {
                    status = STEWART_STOP_LEG_LONG;
                    *leg = i;
                }
            }
        }
        if (status != STEWART_OK) {
            ++n;
            break;
        }
    }
    *step = n;
    return status;
}
