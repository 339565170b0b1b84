"""Measurement files of a built platform for ``stewart calibrate``: the seed paper's platform
as built (every joint coordinate off by up to 1 mm, every encoder zero by up to 2 mm, hidden
from the calibration), measured at 60 designed poses by a laser tracker (10 um, 100 urad per
coordinate) with its encoders (1 um): the first 40 poses to calibrate from, the other 20
held out, and the same 40 poses seen by a tracker that measures three targets on the
platform instead of its pose.

Run from the repository root: ``python examples/calibration.py [--out DIR]`` (default
``examples/calibration``, the files shipped there), then for example
``stewart calibrate examples/calibration/measurements.csv --validate examples/calibration/held_out.csv``.
"""

import argparse
import os

import stewart
from stewart.calibration import perturbed_geometry, simulate_measurements
from stewart.calibration.design import design_poses
from stewart.cli import demo

#: The three targets' positions in {P} [m] (stewart calibrate --target-offset X Y Z, in order).
TARGETS = ((0.0, 0.0, 0.02), (0.05, 0.0, 0.02), (0.0, 0.05, 0.02))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default=os.path.join("examples", "calibration"), help="directory for the files")
    args = parser.parse_args()
    nominal = stewart.PlatformParams.preset("narayan2017")
    built = perturbed_geometry(nominal, joint_error=demo.CALIBRATION_ERRORS[0], offset_error=demo.CALIBRATION_ERRORS[1])
    noise = {"position_std": demo.TRACKER_NOISE[0], "angle_std": demo.TRACKER_NOISE[1],
             "length_std": demo.NOISE_LENGTH}
    poses = design_poses(nominal, demo.CALIBRATION_POSES + demo.HELD_OUT_POSES).poses
    measured, held = poses[:demo.CALIBRATION_POSES], poses[demo.CALIBRATION_POSES:]
    os.makedirs(args.out, exist_ok=True)
    files = {"measurements.csv": simulate_measurements(built, measured, seed=1, **noise),
             "held_out.csv": simulate_measurements(built, held, seed=2, **noise),
             "points.csv": simulate_measurements(built, measured, target_offsets=TARGETS, seed=3, **noise)}
    for name, data in files.items():
        path = os.path.join(args.out, name)
        data.to_csv(path, f"{nominal.name} as built (examples/calibration.py): {data.kind} measured in {{B}} "
                          "[m, rad] and encoder readings [m]")
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
