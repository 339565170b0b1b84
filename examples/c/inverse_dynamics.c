/* inverse_dynamics.c -- the actuator forces of a Stewart platform in motion, from plain C.
 *
 * Uses the generated model (stewart_model.h and its source files) and the parameters of a
 * platform written by the Python package (stewart_platform_params.h). Build and run:
 *
 *   stewart c-export cdir --preset narayan2017
 *   cc -std=c99 -O2 -Icdir examples/c/inverse_dynamics.c cdir/stewart_model*.c -lm -o inverse_dynamics
 *   ./inverse_dynamics
 *
 * (from Python: stewart.io.capi.export("cdir", stewart.PlatformParams.preset("narayan2017"))).
 * It prints the state and the six leg forces, one line each, to full precision.
 */
#include <stdio.h>

#include "stewart_model.h"
#include "stewart_platform_params.h"

static void print_vector(const char *name, const double v[6])
{
    int i;
    printf("%-4s", name);
    for (i = 0; i < 6; i++)
        printf(" %.17g", v[i]);
    printf("\n");
}

int main(void)
{
    /* Pose [x, y, z, psi, theta, phi] (m, rad), its rates and accelerations. */
    const double x[6] = {0.01, -0.005, 0.28, 0.05, -0.03, 0.02};
    const double xd[6] = {0.02, 0.01, -0.03, 0.1, -0.2, 0.05};
    const double xdd[6] = {0.5, -0.2, 1.0, 0.3, 0.1, -0.4};
    double tau[6];

    int status = stewart_inverse_dynamics(&stewart_platform_params, x, xd, xdd, tau);
    if (status != STEWART_OK) {
        fprintf(stderr, "inverse dynamics failed: %s\n", stewart_status_message(status));
        return 1;
    }
    print_vector("x", x);
    print_vector("xd", xd);
    print_vector("xdd", xdd);
    print_vector("tau", tau); /* N, along each leg, positive pushing the platform up */
    return 0;
}
