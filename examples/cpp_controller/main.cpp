// main.cpp -- a 1 kHz computed-torque loop over the exported Stewart platform model: the
// controller (computed_torque_controller.hpp) drives a simulated platform (the plant: the
// model's equations of motion under saturated actuators that lose friction,
// stewart_loop_derivative in open loop) along a reference.
//
//   cpp_controller SETTINGS [--plant stages|hold]
//
// SETTINGS holds whitespace-separated fields, each a keyword and its numbers:
//   dt DT  steps N  kp 6  kd 6  force_limit 6
//   model_friction 13 (F_v 6, F_c 6, v_c: what the controller adds back)
//   friction 13 (what the legs lose)  y0 12 (x, xd at the start)
//   refs (2N + 1) x 18 ([x_r, xd_r, xdd_r] at t = 0, dt/2, dt, ...: the half-step grid)
//
// --plant stages (the default) evaluates the controller at each of the four RK4 stages of
// every step, the loop of stewart.simulate (stewart_loop_rk4), whose controller is a
// continuous law: its states and forces equal stewart.simulate's under ComputedTorque bit
// for bit. --plant hold runs the controller once a period and holds its forces over the
// step, as a real 1 kHz controller does (the plant: stewart_loop_rk4 in open loop).
//
// Prints a row per step, "n x(6) xd(6) force(6)" (the state at t_n and the commanded forces
// there), and on stderr the heap allocations counted in the loop by an interposed allocator
// (alloc_counter.c, LD_PRELOAD) and the time the controller's update took.
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "computed_torque_controller.hpp"
#include "stewart_model.h"
#include "stewart_platform_params.h"

namespace {

struct Settings {
    double dt = 0.0;
    std::size_t steps = 0;
    stewart_control::Gains gains{};
    stewart_loop plant{};  // open loop: the actuators' saturation and friction
    stewart_friction model_friction{};
    double y0[12]{};
    std::vector<double> refs;
};

bool read_numbers(std::ifstream &in, double *out, std::size_t n)
{
    for (std::size_t i = 0; i < n; ++i) {
        if (!(in >> out[i])) {
            return false;
        }
    }
    return true;
}

bool read_friction(std::ifstream &in, stewart_friction &f)
{
    return read_numbers(in, f.viscous, 6) && read_numbers(in, f.coulomb, 6) && read_numbers(in, &f.velocity, 1);
}

bool load(const char *path, Settings &s)
{
    std::ifstream in(path);
    std::string key;
    s.plant.mode = STEWART_OPEN_LOOP;
    while (in >> key) {
        bool ok = true;
        if (key == "dt") {
            ok = read_numbers(in, &s.dt, 1);
        } else if (key == "steps") {
            ok = static_cast<bool>(in >> s.steps);
        } else if (key == "kp") {
            ok = read_numbers(in, s.gains.kp, 6);
        } else if (key == "kd") {
            ok = read_numbers(in, s.gains.kd, 6);
        } else if (key == "force_limit") {
            ok = read_numbers(in, s.plant.force_limit, 6);
        } else if (key == "model_friction") {
            ok = read_friction(in, s.model_friction);
        } else if (key == "friction") {
            ok = read_friction(in, s.plant.friction);
        } else if (key == "y0") {
            ok = read_numbers(in, s.y0, 12);
        } else if (key == "refs") {
            s.refs.resize(18 * (2 * s.steps + 1));
            ok = s.steps > 0 && read_numbers(in, s.refs.data(), s.refs.size());
        } else {
            std::fprintf(stderr, "%s: unknown field '%s'\n", path, key.c_str());
            return false;
        }
        if (!ok) {
            std::fprintf(stderr, "%s: field '%s': expected numbers\n", path, key.c_str());
            return false;
        }
    }
    if (!(s.dt > 0.0) || s.steps == 0 || s.refs.size() != 18 * (2 * s.steps + 1)) {
        std::fprintf(stderr, "%s: needs dt > 0, steps > 0 and the refs of every half step\n", path);
        return false;
    }
    return true;
}

using Counter = unsigned long (*)(void);

}  // namespace

int main(int argc, char **argv)
{
    if (argc < 2 || (argc == 4 && std::strcmp(argv[2], "--plant") != 0) || argc == 3 || argc > 4) {
        std::fprintf(stderr, "usage: %s SETTINGS [--plant stages|hold]\n", argv[0]);
        return 2;
    }
    const bool hold = argc == 4 && std::strcmp(argv[3], "hold") == 0;
    if (argc == 4 && !hold && std::strcmp(argv[3], "stages") != 0) {
        std::fprintf(stderr, "--plant: expected stages or hold, got '%s'\n", argv[3]);
        return 2;
    }
    Settings s;
    if (!load(argv[1], s)) {
        return 2;
    }
    // Initialization: everything the loop needs, allocated here.
    stewart_control::ComputedTorqueController controller;
    if (controller.on_init(stewart_platform_params, s.gains, s.model_friction) != stewart_control::return_type::OK) {
        std::fprintf(stderr, "on_init failed: gains not finite\n");
        return 2;
    }
    const std::size_t n_steps = s.steps;
    std::vector<double> states(12 * n_steps), forces(6 * n_steps), update_ns(n_steps);
    const double zeros[18] = {0.0};
    const double inf = std::numeric_limits<double>::infinity();
    const Counter allocations = reinterpret_cast<Counter>(dlsym(RTLD_DEFAULT, "alloc_counter_total"));
    const unsigned long before = allocations ? allocations() : 0;

    // The loop: no allocation from here on.
    double y[18] = {0.0}, k[4][18], t[18], scratch[18], force[6], held[3 * 6], one[18 + 6 * 3];
    std::size_t done = 0, step = 0;
    int leg = -1, status = STEWART_OK;
    for (int j = 0; j < 12; ++j) {
        y[j] = s.y0[j];
    }
    for (std::size_t n = 0; n < n_steps && status == STEWART_OK; ++n) {
        for (int j = 0; j < 12; ++j) {
            states[12 * n + j] = y[j];
        }
        if (hold) {
            // The controller once a period; its forces held over the step.
            const auto start = std::chrono::steady_clock::now();
            controller.read(y, y + 6);
            controller.update(&s.refs[18 * 2 * n], zeros);
            status = controller.write(force) == stewart_control::return_type::OK ? STEWART_OK : controller.status();
            update_ns[n] = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
            for (int r = 0; r < 3; ++r) {
                for (int j = 0; j < 6; ++j) {
                    held[6 * r + j] = force[j];
                }
            }
            for (int j = 0; j < 6; ++j) {
                forces[6 * n + j] = force[j];
            }
            if (status == STEWART_OK) {
                status = stewart_loop_rk4(&stewart_platform_params, &s.plant, y, &s.refs[18 * 2 * n], held, s.dt, 0, 1,
                                          -inf, inf, one, scratch, scratch + 6, scratch + 12, &step, &leg);
            }
        } else {
            // The controller at each RK4 stage, as stewart_loop_rk4 evaluates its law.
            for (int stage = 0; stage < 4 && status == STEWART_OK; ++stage) {
                const std::size_t row = 2 * n + static_cast<std::size_t>(stage + 1) / 2;
                const double fraction = stage == 0 ? 0.0 : stage == 3 ? 1.0 : 0.5;
                for (int j = 0; j < 18; ++j) {
                    t[j] = stage ? y[j] + fraction * s.dt * k[stage - 1][j] : y[j];
                }
                const auto start = std::chrono::steady_clock::now();
                controller.read(t, t + 6);
                controller.update(&s.refs[18 * row], zeros);
                status = controller.write(force) == stewart_control::return_type::OK ? STEWART_OK : controller.status();
                if (stage == 0) {
                    update_ns[n] = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
                    for (int j = 0; j < 6; ++j) {
                        forces[6 * n + j] = force[j];
                    }
                }
                if (status == STEWART_OK) {
                    status = stewart_loop_derivative(&stewart_platform_params, &s.plant, t, &s.refs[18 * row], force,
                                                     k[stage], scratch, scratch + 6, scratch + 12);
                }
            }
            for (int j = 0; j < 18 && status == STEWART_OK; ++j) {
                y[j] = y[j] + s.dt / 6.0 * (k[0][j] + 2.0 * k[1][j] + 2.0 * k[2][j] + k[3][j]);
                if (!std::isfinite(y[j])) {
                    status = STEWART_STOP_NONFINITE;
                }
            }
        }
        done = status == STEWART_OK ? n + 1 : n;
    }
    const unsigned long after = allocations ? allocations() : 0;

    for (std::size_t n = 0; n < done; ++n) {
        std::printf("%zu", n);
        for (int j = 0; j < 12; ++j) {
            std::printf(" %.17g", states[12 * n + j]);
        }
        for (int j = 0; j < 6; ++j) {
            std::printf(" %.17g", forces[6 * n + j]);
        }
        std::printf("\n");
    }
    double mean = 0.0, worst = 0.0;
    for (std::size_t n = 0; n < done; ++n) {
        mean += update_ns[n] / static_cast<double>(done ? done : 1);
        worst = update_ns[n] > worst ? update_ns[n] : worst;
    }
    std::fprintf(stderr, "steps: %zu of %zu (%s)\n", done, n_steps, status == STEWART_OK ? "ok" : "stopped");
    std::fprintf(stderr, "update: mean %.0f ns, worst %.0f ns\n", mean, worst);
    if (allocations) {
        std::fprintf(stderr, "allocations: %lu at initialization, %lu in the loop\n", before, after - before);
    }
    return status == STEWART_OK ? 0 : 1;
}
