"""Every public function of the compiled model on one batch, saved for comparison between the
instruction-set paths (``tests/test_build.py`` runs it once per path, in a subprocess with
``STEWART_SIMD`` set)::

    python tests/simd_paths.py OUT.npz [THREADS]

The batch has a size that is no multiple of a vector width and singular rows mixed in: a
leg of zero length (every function fails there) and theta = 90 deg (forward dynamics and
the RK4 step fail there). OUT.npz holds, per function, each output array and the mask
(``return_mask=True``), and the message of the error the call raises without the mask; and
``build_info``, the path that ran.
"""

import json
import sys

import numpy as np

import stewart
from stewart.cli import bench

#: Batch size: no multiple of 2, 4 or 8.
ROWS = 1003
#: The legs' stiffnesses of the modal stiffness [N/m].
SPRINGS = np.linspace(1e6, 2e6, 6)
#: Rows made singular.
DEGENERATE_ROW, EULER_ROW = 17, 5


def batch(params):
    """(x, xd, xdd, tau) with the singular rows."""
    x, xd, xdd = bench.states(params, ROWS, seed=1)
    tau = stewart.Platform(params).inverse_dynamics(x, xd, xdd)
    x[EULER_ROW, 4] = np.pi / 2
    # Platform point 0 on base point 0: leg 0 has zero length.
    x[DEGENERATE_ROW, :3] = params.base_points[0] - params.platform_points[0]
    x[DEGENERATE_ROW, 3:] = 0.0
    return x, xd, xdd, tau


def calls(plat, x, xd, xdd, tau):
    """name -> call(return_mask) of every public function of the model."""
    return {
        "leg_lengths": lambda m: plat.leg_lengths(x, return_mask=m),
        "jacobian": lambda m: plat.jacobian(x, return_mask=m),
        "leg_rates": lambda m: plat.leg_rates(x, xd, return_mask=m),
        "mass_matrix": lambda m: plat.mass_matrix(x, return_mask=m),
        "twist_mass_matrix": lambda m: plat.twist_mass_matrix(x, return_mask=m),
        "coriolis_matrix": lambda m: plat.coriolis_matrix(x, xd, return_mask=m),
        "coriolis_vector": lambda m: plat.coriolis_vector(x, xd, return_mask=m),
        "gravity_vector": lambda m: plat.gravity_vector(x, return_mask=m),
        "all_terms": lambda m: plat.all_terms(x, xd, return_mask=m),
        "inverse_dynamics": lambda m: plat.inverse_dynamics(x, xd, xdd, return_mask=m),
        "forward_dynamics": lambda m: plat.forward_dynamics(x, xd, tau, return_mask=m),
        "inverse_dynamics_derivatives": lambda m: plat.inverse_dynamics_derivatives(x, xd, xdd, return_mask=m),
        "static_force_derivatives": lambda m: plat.static_force_derivatives(x, return_mask=m),
        "forward_dynamics_derivatives": lambda m: plat.forward_dynamics_derivatives(x, xd, tau, return_mask=m),
        "rk4_step": lambda m: plat.rk4_step(x, xd, tau, 1e-3, return_mask=m),
        "rk4_step_jacobians": lambda m: plat.rk4_step(x, xd, tau, 1e-3, jacobians=True, return_mask=m),
        "joint_reactions": lambda m: plat.joint_reactions(x, xd, xdd, return_mask=m),
        "regressor": lambda m: plat.regressor(x, xd, xdd, return_mask=m),
        # (the calibration's functions: xd stands for encoder readings, xdd's first three for targets)
        "leg_residuals": lambda m: plat.leg_residuals(x, xd, return_mask=m),
        "leg_residual_jacobians": lambda m: plat.leg_residual_jacobians(x, return_mask=m),
        "target_positions": lambda m: plat.target_positions(x, xdd[..., :3], return_mask=m),
        "target_jacobian": lambda m: plat.target_jacobian(x, xdd[..., :3], return_mask=m),
        "rotation": lambda m: plat.rotation(x, return_mask=m),
        "rotation_partials": lambda m: plat.rotation(x, partials=True, return_mask=m),
        "euler_rate_jacobian": lambda m: plat.euler_rate_jacobian(x, return_mask=m),
        "euler_rate_jacobian_partials": lambda m: plat.euler_rate_jacobian(x, partials=True, return_mask=m),
        "inverse_euler_rate_jacobian": lambda m: plat.inverse_euler_rate_jacobian(x, return_mask=m),
        "leg_vectors": lambda m: plat.leg_vectors(x, return_mask=m),
        "leg_unit_vectors": lambda m: plat.leg_unit_vectors(x, return_mask=m),
        "leg_unit_vector_gradients": lambda m: plat.leg_unit_vectors(x, gradients=True, return_mask=m),
        "modal_stiffness": lambda m: plat.modal_stiffness(x, SPRINGS, return_mask=m),
        "joint_cosines": lambda m: plat.joint_cosines(x, return_mask=m),
        "rider_signals": lambda m: plat.rider_signals(x, xd, xdd, return_mask=m),
    }


def main(out, threads=1):
    plat = stewart.Platform.preset("narayan2017", threads=threads)
    arrays = {}
    for name, call in calls(plat, *batch(plat.params)).items():
        result, mask = call(True)
        parts = [result] if isinstance(result, np.ndarray) else list(result)
        for k, part in enumerate(parts):
            arrays[f"{name}.{k}"] = np.asarray(part)
        arrays[f"{name}.mask"] = mask
        try:
            call(False)
            arrays[f"{name}.error"] = np.array("")
        except stewart.SingularityError as exc:
            arrays[f"{name}.error"] = np.array(str(exc))
    arrays["build_info"] = np.array(json.dumps(stewart.build_info()))
    np.savez(out, **arrays)


if __name__ == "__main__":
    main(sys.argv[1], *map(int, sys.argv[2:]))
