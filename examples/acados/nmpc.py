"""Nonlinear MPC with acados on the exact model: SQP-RTI tracks the seed paper's 5 s move on
narayan2017, with the package's RK4 step as the plant, and prints the tracking error.

Run in acados's environment (make acados-env; docs/acados.md):

    .venv-acados/bin/python examples/acados/nmpc.py [--out DIR]

It exports the model (stewart export-acados's files) into DIR (default: a temporary
directory), builds a tracking OCP of 20 steps of 20 ms with the actuators' force limit, the
legs' stroke (con_h) and SQP-RTI, and runs it for 5.5 s.
"""

from __future__ import annotations

import argparse
import tempfile

import numpy as np

import stewart
import stewart.acados as nmpc
from stewart.io import acados_export
from stewart.motion.trajectory import PointToPoint

TARGET = [0.04565, -0.0102, 0.192, -0.0863, 0.1046, 0.0960]  # the seed paper's move (stewart simulate --target)
FORCE_LIMIT = 60.0  # N per leg
HORIZON, DT = 20, 0.02


def main(out: str) -> None:
    params = stewart.PlatformParams.preset("narayan2017")
    acados_export.export(out, params, DT)               # = stewart export-acados OUT --preset narayan2017 --dt 0.02
    export = nmpc.load(out)
    ocp = nmpc.tracking_ocp(export, HORIZON, force_limit=FORCE_LIMIT)
    solver = nmpc.solver(ocp, export)                   # generates and compiles the solver in OUT
    platform = stewart.Platform(params)
    move = PointToPoint(platform.home_pose, np.array(TARGET), 5.0)
    tracker = nmpc.Tracker(solver, export, move, HORIZON)
    # Start 5 mm off the move's start: the forces meet their limit while the loop catches up.
    x0 = np.concatenate([platform.home_pose + [0.005, -0.005, -0.005, 0, 0, 0], np.zeros(6)])
    run = nmpc.closed_loop(tracker, 5.5, FORCE_LIMIT, plant_steps=20, x0=x0)
    s = run.summary
    print(f"NMPC (acados SQP-RTI, {HORIZON} steps of {DT * 1e3:g} ms) on narayan2017, {s['steps']} steps:")
    print(f"  largest position error {s['max_position_error'] * 1e3:.3f} mm, after 1 s "
          f"{run.position_error[run.t >= 1.0].max() * 1e3:.2e} mm, at the end {s['final_position_error'] * 1e3:.2e} mm")
    print(f"  largest angle error {s['max_angle_error']:.2e} rad, at the end {s['final_angle_error']:.2e} rad")
    print(f"  largest force {np.max(np.abs(run.forces)):.3f} N of the limit {FORCE_LIMIT:g} N")
    print(f"  RTI step (preparation + feedback), median {s['median_rti_step'] * 1e3:.3f} ms, "
          f"max {run.step_times.max() * 1e3:.3f} ms")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", help="directory of the export and the solver (default: a temporary one)")
    args = parser.parse_args()
    if args.out:
        main(args.out)
    else:
        with tempfile.TemporaryDirectory() as tmp:
            main(tmp)
