// computed_torque_controller.hpp -- a task-space computed-torque controller over the exported
// Stewart platform model (stewart::stewart), shaped like a ros2_control component: on_init
// takes the platform and the gains (and is the only place that may allocate), then every
// control period read() takes the measured state, update() evaluates the law and write()
// hands out the leg forces. No ROS dependency, no heap allocation after on_init, no exceptions.
//
// The law is stewart.motion.control.ComputedTorque's, as stewart.simulate evaluates it
// (stewart_loop_derivative in the generated C):
//
//   acc   = xdd_r + kd (xd_r - xd) + kp (x_r - x)           (per pose coordinate)
//   force = inverse_dynamics(x, xd, acc) + (friction(Ld) + feedforward)
//
// with friction the model's leg friction at the measured leg rates Ld. The forces are the
// commanded ones; the actuators saturate them. Compile with the model's rounding flags
// (stewart_ROUNDING_FLAGS) so that the few operations here round as the generated C's do.
#ifndef STEWART_COMPUTED_TORQUE_CONTROLLER_HPP
#define STEWART_COMPUTED_TORQUE_CONTROLLER_HPP

#include <cmath>

#include "stewart_model.h"

namespace stewart_control {

// As hardware_interface::return_type.
enum class return_type { OK, ERROR };

struct Gains {
    double kp[6];  // 1/s^2 per pose coordinate [x, y, z, psi, theta, phi]
    double kd[6];  // 1/s
};

class ComputedTorqueController {
public:
    // The platform, the gains and the model's leg friction (F_v, F_c, v_c; zeros for none).
    return_type on_init(const stewart_params &params, const Gains &gains, const stewart_friction &model_friction)
    {
        for (int k = 0; k < 6; ++k) {
            if (!std::isfinite(gains.kp[k]) || !std::isfinite(gains.kd[k])) {
                return return_type::ERROR;
            }
        }
        params_ = params;
        gains_ = gains;
        friction_ = model_friction;
        for (int k = 0; k < 6; ++k) {
            x_[k] = xd_[k] = force_[k] = 0.0;
        }
        status_ = STEWART_OK;
        initialized_ = true;
        return return_type::OK;
    }

    // The state interfaces: the measured pose [x, y, z, psi, theta, phi] (m, rad) and its rates.
    return_type read(const double *x, const double *xd)
    {
        for (int k = 0; k < 6; ++k) {
            x_[k] = x[k];
            xd_[k] = xd[k];
        }
        return return_type::OK;
    }

    // The law at the reference [x_r, xd_r, xdd_r] (18) with feed-forward forces (6, N).
    return_type update(const double *reference, const double *feedforward)
    {
        double LLd[12], acc[6], tau[6], friction[6];
        if (!initialized_) {
            return return_type::ERROR;
        }
        status_ = stewart_leg_rates(&params_, x_, xd_, LLd);
        if (status_ != STEWART_OK) {
            return return_type::ERROR;
        }
        for (int k = 0; k < 6; ++k) {
            acc[k] = reference[12 + k] + gains_.kd[k] * (reference[6 + k] - xd_[k])
                     + gains_.kp[k] * (reference[k] - x_[k]);
        }
        status_ = stewart_inverse_dynamics(&params_, x_, xd_, acc, tau);
        if (status_ == STEWART_OK) {
            status_ = stewart_friction_forces(&friction_, LLd + 6, friction);
        }
        if (status_ != STEWART_OK) {
            return return_type::ERROR;
        }
        for (int k = 0; k < 6; ++k) {
            force_[k] = tau[k] + (friction[k] + feedforward[k]);
        }
        return return_type::OK;
    }

    // The command interfaces: the commanded leg forces (N, positive pushing the platform up).
    return_type write(double *forces) const
    {
        for (int k = 0; k < 6; ++k) {
            forces[k] = force_[k];
        }
        return status_ == STEWART_OK ? return_type::OK : return_type::ERROR;
    }

    // The model's status of the last update (stewart_status_message tells it).
    int status() const { return status_; }

private:
    stewart_params params_{};
    Gains gains_{};
    stewart_friction friction_{};
    double x_[6]{}, xd_[6]{}, force_[6]{};
    int status_ = STEWART_OK;
    bool initialized_ = false;
};

}  // namespace stewart_control

#endif  // STEWART_COMPUTED_TORQUE_CONTROLLER_HPP
