"""``make demo``: the seed paper's move on its platform, under PID and computed torque.

Narayan Rao et al. (2017) move their platform from an initial pose to a target pose in
5 s along a sinusoidal velocity profile with joint-space PID. This demo makes that move
from the home pose on the ``narayan2017`` preset with the compiled model, then the same
move with computed torque; prints peak forces and tracking errors; writes the paper's
figures as PNG; repeats the paper's leg-inertia study; runs an identification study
(:func:`identification_run`): the platform carrying a payload the identifier does not know,
with friction in its legs, follows a designed excitation trajectory; its logged leg lengths
and forces, with noise, give back the base parameters; a sizing study (:func:`sizing_run`):
workspace slices, the force and joint-load envelope of the move and of a box around it with a
20 % margin, and a small sweep of the joint radii; a cueing study (:func:`cueing_run`):
washout against MPC cueing on the shipped maneuvers, closed loop, on the seed paper's platform
and on ``motion_simulator``; a calibration study (:func:`calibration_run`): the platform as
built, with a hidden geometry error, measured by a tracker at designed poses, calibrated, and
checked on held-out poses; a modal study (:func:`modal_run`) of the ``motion_simulator``
preset on legs of a realistic stiffness: its frequencies at home, a map of the lowest frequency
over the workspace, and how much the payload's preload and the legs' inertia move each
frequency; and a sim-racing rig (:func:`sim_racing_run`): the rotary ``simrig100`` cueing a GT
car's lap by MPC within its limits, and its motors sized along the reference it plays.
"""

from __future__ import annotations

import argparse
import dataclasses
import os

import numpy as np

import stewart
from stewart.oracles import reference
from stewart.model.presets import LEG_STIFFNESS, narayan2017_target_pose

MOVE_DURATION = 5.0
#: Widening of the box around the move for the sizing envelope (each range and rate bound).
SIZING_MARGIN = 0.2
SIZING_SAMPLES = 500_000
#: The machine the identification study logs: a payload unknown to the identifier (mass [kg],
#: centre of mass in {P} [m], principal moments [kg m^2]) and friction in each leg.
PAYLOAD = (2.0, (0.02, -0.01, 0.03), (0.02, 0.03, 0.025))
VISCOUS_FRICTION = (12.0, 15.0, 10.0, 14.0, 11.0, 13.0)   # N s/m
COULOMB_FRICTION = (1.5, 2.0, 1.2, 1.8, 1.6, 1.4)         # N
#: Measurement noise of the log: a linear encoder's [m] and a load cell's [N] standard deviation.
NOISE_LENGTH = 1e-6
NOISE_FORCE = 0.2
#: The calibration study: the built machine's joint error [m] and offset error [m] (uniform
#: bounds), the poses measured and held out, a tracker's noise [m, rad] and an encoder's [m].
CALIBRATION_ERRORS = (1e-3, 2e-3)
CALIBRATION_POSES, HELD_OUT_POSES = 40, 20
TRACKER_NOISE = (1e-5, 1e-4)
#: The checkout's examples/ (make demo runs from a checkout or an unpacked sdist).
EXAMPLES = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "examples")
SWEEP_FILE = os.path.join(EXAMPLES, "sweep.toml")
MANEUVER_DIR = os.path.join(EXAMPLES, "cueing")
#: The vehicle log of the sim-racing rig's section (:func:`sim_racing_run`), in MANEUVER_DIR.
RACING_LAP = "racing_lap.csv"


def _row(label: str, values, fmt: str = "{:>10.4f}", width: int = 34) -> str:
    return f"  {label:<{width}}" + "".join(fmt.format(v) for v in values)


def leg_inertia_study(params: stewart.PlatformParams, trajectory, dt: float = 1e-3) -> dict[str, np.ndarray]:
    """Peak actuator force per leg along ``trajectory`` (inverse dynamics at every ``dt``)
    for the full model, with massless legs, and with the legs' rotation neglected (leg
    masses kept, leg rotational inertias zero)."""
    variants = {
        "full model": params,
        "massless legs": params.replace(cylinder_mass=0.0, piston_mass=0.0,
                                        cylinder_inertia=(0, 0, 0), piston_inertia=(0, 0, 0)),
        "leg rotation neglected (leg masses kept)": params.replace(cylinder_inertia=(0, 0, 0),
                                                                   piston_inertia=(0, 0, 0)),
    }
    times = np.arange(int(round(trajectory.duration / dt)) + 1) * dt
    x, xd, xdd = trajectory.sample(times)
    return {name: np.max(np.abs(stewart.Platform(p).inverse_dynamics(x, xd, xdd)), axis=0)
            for name, p in variants.items()}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m stewart.cli.demo", description=__doc__)
    parser.add_argument("--out", default=os.path.join("out", "demo"), help="directory for the figures")
    parser.add_argument("--no-plots", action="store_true", help="skip the figures")
    parser.add_argument("--modes-only", action="store_true", help="only the modal study (and its figures)")
    args = parser.parse_args(argv)
    if args.modes_only:
        modal = modal_run()
        if not args.no_plots:
            _written(args.out, plot_modal(modal, args.out))
        return

    plat = stewart.Platform.preset("narayan2017")
    params = plat.params
    home = plat.home_pose
    print(f"Platform {params.name!r}: {stewart.presets()[params.name]}")
    print(f"  masses: platform {params.platform_mass:.4f} kg, cylinder {params.cylinder_mass:.4f} kg, "
          f"piston {params.piston_mass:.4f} kg; leg lengths {params.leg_length_limits[0]}-"
          f"{params.leg_length_limits[1]} m")
    print(_row("home pose [m, rad]", home))
    print(_row("leg lengths at home [m]", plat.leg_lengths(home)))

    xd = np.array([0.02, -0.01, 0.05, 0.3, -0.2, 0.1])
    xdd = np.array([0.3, 0.1, -0.5, 2.0, 1.0, -1.5])
    print("\nInverse dynamics at home, moving (xdot, xddot below):")
    print(_row("xdot [m/s, rad/s]", xd))
    print(_row("xddot [m/s^2, rad/s^2]", xdd))
    print(_row("tau, numeric reference [N]", reference.inverse_dynamics(params, home, xd, xdd)))
    print(_row("tau, compiled kernel [N]", plat.inverse_dynamics(home, xd, xdd)))

    target = narayan2017_target_pose()
    move = stewart.PointToPoint(home, target, MOVE_DURATION, "sinusoidal")
    print(f"\nThe paper's move: home -> target in {MOVE_DURATION:g} s, sinusoidal velocity profile")
    print(_row("target pose [m, rad]", target))
    print(_row("leg lengths at target [m]", plat.leg_lengths(target)))
    runs = {
        "PID": stewart.simulate(plat, move, stewart.PID.tuned(plat)),
        "computed torque": stewart.simulate(plat, move, stewart.ComputedTorque.tuned()),
    }
    print(f"\n  {'':<34}" + "".join(f"{name:>22}" for name in runs))
    summaries = {name: run.summary() for name, run in runs.items()}
    for leg in range(6):
        print(f"  {f'peak force, leg {leg} [N]':<34}" + "".join(f"{s['peak_force'][leg]:>22.3f}" for s in summaries.values()))
    rows = [
        ("final position error [m]", "final_position_error", "{:>22.2e}"),
        ("final angle error [rad]", "final_angle_error", "{:>22.2e}"),
        ("RMS position error [m]", "rms_position_error", "{:>22.2e}"),
        ("RMS angle error [rad]", "rms_angle_error", "{:>22.2e}"),
    ]
    for label, key, fmt in rows:
        print(f"  {label:<34}" + "".join(fmt.format(s[key]) for s in summaries.values()))
    timing = [f"{1e3 * s['wall_time']:.1f} ms / {s['simulated_time']:g} s" for s in summaries.values()]
    print(f"  {'wall time / simulated time':<34}" + "".join(f"{v:>22}" for v in timing))
    print(f"  {'outcome':<34}" + "".join(f"{run.outcome:>22}" for run in runs.values()))
    for name, run in runs.items():
        for problem in run.problems:
            print(f"  {name}: {problem}")

    study = leg_inertia_study(params, move)
    print("\nLeg-inertia study: peak actuator force per leg over the move [N] (inverse dynamics)")
    print(f"  {'':<42}" + "".join(f"{f'leg {k}':>10}" for k in range(6)) + f"{'max':>10}")
    full = study["full model"]
    for name, peaks in study.items():
        change = "" if name == "full model" else f"   ({100 * (np.max(peaks) / np.max(full) - 1):+.1f}% of max)"
        print(f"  {name:<42}" + "".join(f"{v:>10.3f}" for v in peaks) + f"{np.max(peaks):>10.3f}{change}")

    ident = identification_run(params, move, short=True)
    sizing = sizing_run(params, move)
    cueing_rows = cueing_run([params.name, "motion_simulator"])
    calibration = calibration_run(params)
    modal = modal_run()

    if not args.no_plots:
        from stewart.io.plots import plot_bars, plot_run, plot_workspace_slices

        paths = []
        for name, run in runs.items():
            paths += plot_run(run, args.out, prefix=name.replace(" ", "_").lower())
        paths.append(plot_bars(
            [f"leg {k}" for k in range(6)], study, "peak actuator force [N]",
            f"{params.name}: peak actuator force per leg, three models of the legs",
            os.path.join(args.out, "leg_inertia_study.png"), xlabel="leg",
            caption=f"largest |force| of each leg over the seed paper's {MOVE_DURATION:g} s move (home to target, "
                    "sinusoidal profile), by inverse dynamics along the reference path",
            value_format="{:.2f}"))
        paths.append(plot_identification(ident, os.path.join(args.out, "identification_held_out.png")))
        paths.append(plot_workspace_slices(sizing["slices"], os.path.join(args.out, "workspace_slices.png")))
        paths.append(sizing["move"].plot(os.path.join(args.out, "envelope_move.png")))
        paths.append(sizing["box"].plot(os.path.join(args.out, "envelope_margin_box.png")))
        if sizing["sweep"] is not None:
            paths.append(sizing["sweep"].plot(os.path.join(args.out, "sweep_pareto.png")))
        from stewart.cueing import comparison

        for preset, rows in cueing_rows.items():
            braking = next(r for r in rows if r["name"] == "hard_braking")
            paths.append(comparison.plot(braking, preset, os.path.join(args.out, f"cueing_{preset}.png")))
        from stewart.calibration.figures import plot_calibration

        paths += plot_calibration(calibration["result"], args.out, calibration["held_out"])
        _written(args.out, paths + plot_modal(modal, args.out))
    sim_racing_run(args.out, plots=not args.no_plots)


def sim_racing_run(out: str, plots: bool = True) -> None:
    """A sim-racing rig, the rotary ``simrig100`` (100 kg of driver and seat, 750 W servos at
    50:1), plays a GT car's flying lap (examples/cueing/racing_lap.csv) by MPC cueing, its plans
    holding the motors' torque and speed and every limit of the rig's workspace (cranks, rods,
    ball joints, clearance), and its motors are sized along the reference it plays, at the motor
    through the gearbox: the two commands a rig builder runs, in this process. A command's
    nonzero exit ends the demo with it."""
    from stewart.cli import main as stewart_main

    lap = os.path.relpath(os.path.join(MANEUVER_DIR, RACING_LAP))
    if not os.path.isfile(lap):
        print(f"\nSim-racing rig: skipped, {lap} not found (make demo runs from a checkout)")
        return
    os.makedirs(out, exist_ok=True)
    reference = os.path.join(out, "racing_lap_simrig100.csv")
    print("\nSim-racing rig simrig100 (rotary): a GT car's 59 s lap by MPC cueing, then motor sizing of the "
          "reference it plays", flush=True)
    for argv in (["cueing", lap, "--preset", "simrig100", "--method", "mpc", "--output", reference],
                 ["motor-sizing", reference, "--preset", "simrig100", "--gear-ratio", "50",
                  *(["--plot", out] if plots else [])]):
        print("$ stewart " + " ".join(argv), flush=True)
        try:
            stewart_main(argv)
        except SystemExit as exc:
            if exc.code:
                raise SystemExit(f"make demo: stewart {argv[0]} exited with code {exc.code}") from None


def _written(out: str, paths: list[str]) -> None:
    print(f"\nFigures written to {os.path.abspath(out)}:")
    for path in paths:
        print(f"  {os.path.basename(path)}")


#: The preset of the modal study and its legs' stiffness [N/m] (:data:`LEG_STIFFNESS`).
MODAL_PRESET = "motion_simulator"


def _matched(modes: stewart.Modes, reference_modes: stewart.Modes, mass: np.ndarray) -> np.ndarray:
    """The frequencies of ``modes`` in the order of ``reference_modes``: each reference mode
    takes the mode of the largest mass-weighted overlap ``|phi_ref^T M_t phi|``."""
    overlap = np.abs(reference_modes.shapes.T @ mass @ modes.shapes)
    return modes.frequencies[np.argmax(overlap, axis=1)]


def modal_run() -> dict:
    """The modes of :data:`MODAL_PRESET` at home on legs of its :data:`LEG_STIFFNESS`: the
    frequencies and dominant motions, the same modes without the payload's preload (no gravity:
    the legs unloaded, the masses kept) and with massless legs, and the lowest frequency over the
    translational workspace and its slices through home; prints the tables, returns the results."""
    from stewart.model.reachability import limits_in_force
    from stewart.studies import workspace

    plat = stewart.Platform.preset(MODAL_PRESET)
    k = LEG_STIFFNESS[MODAL_PRESET]
    home = plat.home_pose
    full = plat.modes(home, k)
    variants = {
        "no preload (legs unloaded)": stewart.Platform(plat.params.replace(gravity=0.0)),
        "massless legs": stewart.Platform(plat.params.replace(cylinder_mass=0.0, piston_mass=0.0,
                                                              cylinder_inertia=(0, 0, 0), piston_inertia=(0, 0, 0))),
    }
    mass = plat.twist_mass_matrix(home)
    frequencies = {"full model": full.frequencies}
    frequencies.update({name: _matched(v.modes(v.home_pose, k), full, mass) for name, v in variants.items()})
    print(f"\nModal study: {MODAL_PRESET} at home on legs of {k:g} N/m, preloaded to hold its "
          f"{plat.params.platform_mass:g} kg (stewart.Platform.modes)")
    print(f"  {'mode':<6}{'dominant motion':<24}" + "".join(f"{name:>30}" for name in frequencies))
    for j, motion in enumerate(full.motions()):
        cells = [f"{frequencies['full model'][j]:.3f} Hz"]
        for name in variants:
            change = frequencies[name][j] / full.frequencies[j] - 1
            cells.append(f"{frequencies[name][j]:.3f} Hz ({100 * change:+.2f} %)")
        print(f"  {j + 1:<6}{motion:<24}" + "".join(f"{cell:>30}" for cell in cells))
    work = workspace.translational_workspace(plat, samples=20_000, seed=0, stiffness=k, progress=False)
    print(f"  over the translational workspace ({work.reachable} reachable of {work.samples:,} samples; "
          f"{limits_in_force(plat.params)}):")
    print(f"  lowest frequency {work.frequency_min:.2f} Hz at {np.round(work.frequency_min_pose[:3], 3).tolist()} m, "
          f"largest compliance {work.compliance_max:.3g} m/N at {np.round(work.compliance_max_pose[:3], 3).tolist()} m")
    slices = [workspace.workspace_slice(plat, axes, resolution=81, stiffness=k) for axes in ("xy", "xz", "yz")]
    return {"modes": full, "frequencies": frequencies, "workspace": work, "slices": slices, "stiffness": k}


def plot_modal(run: dict, out: str) -> list[str]:
    """The figures of :func:`modal_run`: the frequencies of the three models of the legs, and the
    lowest frequency on the slices through home."""
    from stewart.io.plots import plot_bars, plot_workspace_slices

    os.makedirs(out, exist_ok=True)
    labels = [f"{j + 1}: {m.replace('translation along', 'along').replace('rotation about', 'about')}"
              for j, m in enumerate(run["modes"].motions())]
    return [
        plot_bars(labels, run["frequencies"], "natural frequency [Hz]",
                  f"{MODAL_PRESET}: natural frequencies at home on legs of {run['stiffness']:g} N/m",
                  os.path.join(out, "modes_at_home.png"), xlabel="mode (dominant motion)",
                  caption="the full model; without the payload's preload (no gravity); with massless legs",
                  value_format="{:.2f}"),
        plot_workspace_slices(run["slices"], os.path.join(out, "modes_frequency_slices.png"),
                              f"{MODAL_PRESET}: lowest natural frequency on slices through home",
                              quantity="frequency"),
    ]


def cueing_run(presets) -> dict[str, list[dict]]:
    """Washout against MPC cueing, closed loop under computed torque, on every maneuver of
    ``examples/cueing/`` for each preset (:func:`stewart.cueing.comparison.compare`)."""
    from stewart.cueing import comparison

    if not os.path.isdir(MANEUVER_DIR):
        print(f"\nCueing: skipped, {MANEUVER_DIR} not found (make demo runs from a checkout)")
        return {}
    logs = sorted(os.path.join(MANEUVER_DIR, f) for f in os.listdir(MANEUVER_DIR)
                  if f.endswith(".csv") and f != RACING_LAP)  # the lap is the sim-racing rig's
    out = {}
    for preset in presets:
        print(f"\nCueing on {preset}: washout (W) against MPC, closed loop; perceived-error RMS of the main "
              "channel [m/s^2 or rad/s], correlation, false cues, RMS of all channels' errors in perception "
              "thresholds, MPC's peak force over its limit, exit codes", flush=True)
        rows = comparison.compare(stewart.Platform.preset(preset), logs)
        print(comparison.format_table(rows))
        time = np.median([r["solve_time_ms"] for r in rows])
        print(f"  MPC: 1 s horizon in 10 intervals, no preview, median time per step {time:.2f} ms")
        out[preset] = rows
    return out


def sizing_run(params: stewart.PlatformParams, move) -> dict:
    """Workspace slices, the envelopes of ``move`` and of the box around it widened by
    :data:`SIZING_MARGIN`, and the sweep of ``examples/sweep.toml`` (when the checkout has
    it); prints the tables and returns the results."""
    from stewart.studies import envelope, sweep, workspace

    print("\nSizing: the translational workspace at zero rotation")
    work = workspace.translational_workspace(params, samples=100_000, seed=0, progress=False)
    print(f"  volume {work.volume * 1e6:.0f} +- {work.volume_error * 1e6:.0f} cm^3, mean singularity margin "
          f"{work.margin_mean:.3f} (the smallest {work.margin_min:.3g})")
    slices = [workspace.workspace_slice(params, axes, resolution=81) for axes in ("xy", "xz", "yz")]

    peaks = {"move": envelope.envelope(params, envelope.Trajectories([move], 1e-3), progress=False),
             "box": envelope.envelope(params, envelope.Box.around(move, SIZING_MARGIN), samples=SIZING_SAMPLES,
                                      progress=False)}
    labels = {"move": f"the move ({peaks['move'].states:,} samples)",
              "box": f"the box around it, +-{SIZING_MARGIN:.0%} ({peaks['box'].states:,} states, "
                     f"{peaks['box'].outside_stroke:,} outside the stroke)"}
    for key, result in peaks.items():
        print(f"\nEnvelope of {labels[key]}: peaks per leg")
        print(f"  {'':<34}" + "".join(f"{f'leg {k}':>10}" for k in range(6)))
        for quantity, unit in envelope.QUANTITIES:
            print(_row(f"{quantity.replace('_', ' ')} [{unit}]", result.value(quantity), "{:>10.3f}"))

    result = None
    if not os.path.exists(SWEEP_FILE):
        print(f"\nSweep of the joint radii: skipped, {SWEEP_FILE} not found (make demo runs from a checkout)")
    else:
        spec = sweep.load(SWEEP_FILE)
        result = sweep.sweep(spec, progress=False)
        front = result.front()
        print(f"\nSweep of the joint radii ({len(spec.designs)} designs, examples/sweep.toml); * on the Pareto "
              f"front of {spec.pareto[0]} and {spec.pareto[1]}")
        print(f"  {'base radius [m]':>16}{'platform radius [m]':>21}{'volume [cm^3]':>15}{'peak force [N]':>16}")
        for k, design in enumerate(spec.designs):
            print(f"{'*' if front[k] else ' ':>2}{design['base_radius']:>16.3f}{design['platform_radius']:>21.3f}"
                  f"{result.metrics['workspace_volume'][k] * 1e6:>15.0f}{result.metrics['peak_force'][k]:>16.2f}")
    return {"workspace": work, "slices": slices, **peaks, "sweep": result}


def identification_run(params: stewart.PlatformParams, held_out, *, short: bool = False, seed: int = 0) -> dict:
    """Identify the platform ``params`` carrying :data:`PAYLOAD` with friction in its legs
    (unknown to the identifier, whose prior is ``params``): design an excitation trajectory
    for the prior (:func:`stewart.identification.excitation.design_excitation`), log the machine following it
    at 500 Hz with :data:`NOISE_LENGTH` and :data:`NOISE_FORCE` of noise, identify, and predict
    the forces of the trajectory ``held_out``. Prints the estimates against the true base
    parameters, in standard errors, and the prediction's RMS error against the true model's
    through the same measurement pipeline (the noise level); returns the results."""
    from stewart.identification.excitation import design_excitation
    from stewart.identification.identify import identify, synthetic_measurements, validation

    prior = stewart.Platform(params)
    machine = stewart.Platform(params.with_payload(*PAYLOAD).replace(
        viscous_friction=VISCOUS_FRICTION, coulomb_friction=COULOMB_FRICTION))
    design = design_excitation(prior, period=5.0, harmonics=4, starts=1 if short else 4,
                               max_iterations=20 if short else 100, periods=2 if short else 6, seed=seed)
    traj = design.trajectory
    cutoff = 10.0 * traj.harmonics / traj.period  # ten times the highest harmonic
    print(f"\nIdentification: {params.name} with a {PAYLOAD[0]:g} kg payload off-centre and friction, "
          f"following an excitation of {traj.harmonics} harmonics over {traj.period:g} s, {traj.periods} periods "
          f"(condition number {design.initial_condition:.0f} at the random start, {design.condition:.0f} designed)")
    log = synthetic_measurements(machine, traj, rate=500.0, noise_length=NOISE_LENGTH, noise_force=NOISE_FORCE,
                                 seed=seed)
    result = identify(prior, log, cutoff=cutoff)
    truth = result.base.values(machine.params.inertial_vector())
    z = (result.estimates - truth) / result.standard_errors
    print(f"  {len(log.t)} samples at 500 Hz, noise {NOISE_LENGTH:g} m and {NOISE_FORCE:g} N; cut-off {cutoff:g} Hz; "
          f"condition number {result.condition_number:.0f}")
    width = max(len(n) for n in result.base.names)
    print(f"  {'base parameter':<{width}}{'true':>13}{'estimate':>13}{'std error':>11}{'error/std':>10}")
    for name, true, value, error, score in zip(result.base.names, truth, result.estimates,
                                              result.standard_errors, z):
        print(f"  {name:<{width}}{true:>13.5g}{value:>13.5g}{error:>11.2g}{score:>10.2f}")
    inside = np.abs(z) <= 2.0
    print(f"  {int(inside.sum())} of {len(z)} estimates within 2 standard errors of the truth "
          f"(about 95 % expected for Gaussian errors)")
    held = synthetic_measurements(machine, held_out, rate=500.0, noise_length=NOISE_LENGTH, noise_force=NOISE_FORCE,
                                  seed=seed + 1)
    t, predicted, measured, rms = validation(result, prior, held, cutoff=cutoff)
    exact = dataclasses.replace(result, estimates=truth)
    _, _, _, floor = validation(exact, prior, held, cutoff=cutoff)
    print(_row("held-out RMS error, identified [N]", rms, "{:>10.3f}"))
    print(_row("held-out RMS error, true model [N]", floor, "{:>10.3f}"))
    return {"design": design, "result": result, "z": z, "t": t, "predicted": predicted, "measured": measured,
            "rms": rms, "floor": floor}


def calibration_run(params: stewart.PlatformParams, seed: int = 0) -> dict:
    """Calibrate the geometry of ``params`` as built: every joint coordinate off by up to
    1 mm and every leg's encoder zero by up to 2 mm (:data:`CALIBRATION_ERRORS`, hidden from
    the calibration), measured by a tracker (:data:`TRACKER_NOISE`) and encoders
    (:data:`NOISE_LENGTH`) at designed poses; prints the estimates' errors in standard
    errors and the held-out pose error of forward kinematics before and after; returns
    the results."""
    from stewart.calibration import calibrate, geometry, perturbed_geometry, simulate_measurements
    from stewart.calibration.design import design_poses
    from stewart.calibration.validation import pose_errors

    built = perturbed_geometry(params, joint_error=CALIBRATION_ERRORS[0], offset_error=CALIBRATION_ERRORS[1],
                               seed=seed)
    noise = {"position_std": TRACKER_NOISE[0], "angle_std": TRACKER_NOISE[1], "length_std": NOISE_LENGTH}
    design = design_poses(params, CALIBRATION_POSES + HELD_OUT_POSES, seed=seed)
    measured = simulate_measurements(built, design.poses[:CALIBRATION_POSES], seed=seed, **noise)
    held = simulate_measurements(built, design.poses[CALIBRATION_POSES:], seed=seed + 1, **noise)
    result = calibrate(params, measured, **noise)
    print(f"\nCalibration: {params.name} as built (joints off by up to {CALIBRATION_ERRORS[0] * 1e3:g} mm, encoder "
          f"zeros by up to {CALIBRATION_ERRORS[1] * 1e3:g} mm), {CALIBRATION_POSES} designed poses measured by a "
          f"tracker ({TRACKER_NOISE[0] * 1e6:g} um, {TRACKER_NOISE[1] * 1e6:g} urad) and the encoders "
          f"({NOISE_LENGTH * 1e6:g} um); condition number {result.identifiability.condition:.0f}")
    truth = geometry.parameter_vector(built)
    z = (result.estimates - truth) / result.standard_errors
    for label, part in (("base_points", slice(0, 18)), ("platform_points", slice(18, 36)),
                        ("leg_length_offsets", slice(36, 42))):
        print(f"  {label:<20} largest error {1e6 * np.max(np.abs(result.nominal_values - truth)[part]):7.0f} um "
              f"nominal, {1e6 * np.max(np.abs(result.estimates - truth)[part]):6.1f} um calibrated "
              f"(standard errors {1e6 * np.min(result.standard_errors[part]):.1f}-"
              f"{1e6 * np.max(result.standard_errors[part]):.1f} um)")
    print(f"  {int(np.sum(np.abs(z) <= 2))} of {len(z)} estimates within 2 standard errors of the truth; a leg's "
          "offset and its base joint along the leg are only weakly separable on this small platform (their "
          "large standard errors), a combination that barely moves the platform:")
    held_out = {"nominal": pose_errors(params, held), "calibrated": pose_errors(result.params, held)}
    for kind, unit in (("position", "um"), ("orientation", "urad")):
        rms = [1e6 * np.sqrt(np.mean(held_out[g][kind] ** 2)) for g in ("nominal", "calibrated")]
        print(f"  held-out RMS {kind} error of forward kinematics: {rms[0]:.1f} {unit} nominal, "
              f"{rms[1]:.1f} {unit} calibrated (the tracker's noise: the measured held-out poses carry it)")
    return {"result": result, "held_out": held_out, "z": z}


def plot_identification(run: dict, path: str) -> str:
    """The held-out prediction of :func:`identification_run` as a figure."""
    from stewart.io.plots import plot_force_prediction

    return plot_force_prediction(run["t"], run["predicted"], run["measured"], path,
                                 "identified model on a held-out move: predicted and measured actuator forces")


if __name__ == "__main__":
    main()
