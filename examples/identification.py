"""Identify a built platform: the seed paper's platform carrying a payload the identifier does
not know, with friction in its legs, follows a designed excitation trajectory (six periods of
five seconds); its log of leg lengths and forces, with encoder and load-cell noise, gives back
the base parameters with their standard errors, and the identified model predicts the forces
of the paper's move, which the identification never saw.

Run from the repository root: ``python examples/identification.py [--out DIR] [--short]``
(``--short``: the shorter design and log that ``make demo`` runs).
"""

import argparse
import os

import stewart
from stewart.cli import demo
from stewart.model.presets import narayan2017_target_pose


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default=os.path.join("out", "identification"), help="directory for the figure")
    parser.add_argument("--short", action="store_true",
                        help="one start of the excitation design, 20 iterations, two periods logged")
    args = parser.parse_args()
    params = stewart.PlatformParams.preset("narayan2017")
    move = stewart.PointToPoint(stewart.Platform(params).home_pose, narayan2017_target_pose(), 5.0, "sinusoidal")
    run = demo.identification_run(params, move, short=args.short)
    os.makedirs(args.out, exist_ok=True)
    print(f"wrote {demo.plot_identification(run, os.path.join(args.out, 'held_out.png'))}")


if __name__ == "__main__":
    main()
