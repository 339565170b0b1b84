"""Design sweeps: geometry and mass parameters varied over a grid or at random, each design
sized by its workspace, its force and joint-load envelope and its singularity margin.

A sweep is described by a TOML file (:func:`load`)::

    preset = "narayan2017"      # the parameter set every design starts from (or params = "file.toml")
    method = "grid"             # "grid": every combination of the values; "random": `designs` draws
    designs = 50                # random only: how many designs
    seed = 0                    # of the random designs and of every design's samples

    [parameters]                # what varies; each a number (held), a list of values, or a range
    base_radius = {low = 0.08, high = 0.12, count = 3}   # grid: count values; random: uniform
    platform_spacing = [10.0, 20.0]

    [envelope]                  # the motion every design must make, as offsets from its home pose
    lower = [-0.01, -0.01, -0.01, -0.05, -0.05, -0.05]   # [m, rad]
    upper = [0.01, 0.01, 0.01, 0.05, 0.05, 0.05]
    velocity = [0.1, 0.1, 0.1, 0.3, 0.3, 0.3]            # [m/s, rad/s]
    acceleration = [1.0, 1.0, 1.0, 3.0, 3.0, 3.0]        # [m/s^2, rad/s^2]
    samples = 100000

    [workspace]
    samples = 20000             # Monte-Carlo poses of the translational workspace at zero rotation

    [modes]                     # optional: legs as preloaded springs (stewart.model.stiffness)
    stiffness = 2e7             # N/m, one value or one per leg

    [pareto]                    # the two metrics of the Pareto-front figure
    x = "workspace_volume"
    y = "peak_force"

The design parameters (:data:`PARAMETERS`):

* ``base_radius``, ``platform_radius`` [m]: the mean distance of the joint centres from their
  centroid (in the x-y plane of {B}, {P}); each joint's distance is scaled by the same factor;
* ``base_spacing``, ``platform_spacing`` [deg]: the angle between the two joints of each pair
  (joints are paired by angle, neighbour with neighbour, the pairing with the smaller gaps),
  moved symmetrically about the pair's centre angle;
* ``stroke`` [m]: the leg stroke, ``leg_length_limits = (min, min + stroke)``;
  ``min_leg_length`` [m] the shortest leg length (both default to the starting set's limits);
* ``payload_mass`` [kg]: added to the platform, its inertia scaled with the mass.

The metrics of each design (:data:`METRICS`): the volume of the translational workspace
(:func:`stewart.studies.workspace.translational_workspace`) with its sampling error, the mean
singularity margin over it (Gosselin & Angeles' global conditioning index) and the margin at
the home pose; the peaks over all legs of the envelope (:mod:`stewart.studies.envelope`) of the box
around the home pose; with ``[modes] stiffness`` (or the parameters' ``leg_stiffness``), the
lowest natural frequency over the
workspace's reachable samples and the largest translational compliance there (the reachable
samples the preloaded legs cannot hold are counted in ``unheld``); without it these three
are NaN, and a Pareto axis that names one is an error. Every design draws the same samples
(common random numbers), so the differences between designs are not sampling noise. Each design is one task of
:mod:`stewart.studies.execution` (on a Dask cluster with ``client=``).

Unknown names and bad values raise ``ValueError`` naming the field (``parameters.radius``).
"""

from __future__ import annotations

import csv
import itertools
import json
import os
import tomllib
from dataclasses import dataclass

import numpy as np

from . import envelope as envelope_module
from . import execution, workspace
from ..model import kinematics
from ..model.params import PlatformParams
from ..model.stiffness import leg_coefficients

__all__ = ["Sweep", "SweepSpec", "load", "sweep", "design_params", "pareto_front", "PARAMETERS", "METRICS"]

#: The design parameters with their units.
PARAMETERS = {"base_radius": "m", "platform_radius": "m", "base_spacing": "deg", "platform_spacing": "deg",
              "stroke": "m", "min_leg_length": "m", "payload_mass": "kg"}

#: The metrics of a design: unit, and +1 where more is better, -1 where less is.
METRICS = {"workspace_volume": ("m^3", 1), "workspace_volume_error": ("m^3", -1),
           "margin_mean": ("", 1), "home_margin": ("", 1),
           "peak_force": ("N", -1), "peak_velocity": ("m/s", -1), "peak_power": ("W", -1),
           "peak_universal_joint": ("N", -1), "peak_spherical_joint": ("N", -1),
           "outside_stroke": ("", -1),
           "lowest_frequency": ("Hz", 1), "largest_compliance": ("m/N", -1), "unheld": ("", -1)}

#: The metrics that need the legs' stiffness (``[modes] stiffness``).
MODAL_METRICS = ("lowest_frequency", "largest_compliance", "unheld")

_TOP = {"preset", "params", "method", "designs", "seed", "parameters", "envelope", "workspace", "modes", "pareto"}
_ENVELOPE = {"lower", "upper", "velocity", "acceleration", "samples"}


def _layout(points: np.ndarray, radius: float | None, spacing: float | None) -> np.ndarray:
    """Joint centres with the mean radius ``radius`` and the pair angle ``spacing`` [deg]."""
    centre = points[:, :2].mean(axis=0)
    rel = points[:, :2] - centre
    dist = np.hypot(rel[:, 0], rel[:, 1])
    angle = np.arctan2(rel[:, 1], rel[:, 0])
    if radius is not None:
        dist = dist * radius / dist.mean()
    if spacing is not None:
        order = np.argsort(angle)
        pairings = [[(order[(k + 2 * j) % 6], order[(k + 2 * j + 1) % 6]) for j in range(3)] for k in (0, 1)]
        gaps = [[np.mod(angle[b] - angle[a], 2 * np.pi) for a, b in pairs] for pairs in pairings]
        best = int(np.argmin([sum(g) for g in gaps]))
        angle = angle.copy()
        for (a, b), gap in zip(pairings[best], gaps[best]):
            mid = angle[a] + gap / 2
            angle[a], angle[b] = mid - np.radians(spacing) / 2, mid + np.radians(spacing) / 2
    out = points.copy()
    out[:, :2] = centre + dist[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    return out


def design_params(base: PlatformParams, design: dict) -> PlatformParams:
    """The parameter set of one design: ``base`` with the :data:`PARAMETERS` of ``design``."""
    changes = {}
    if "base_radius" in design or "base_spacing" in design:
        changes["base_points"] = _layout(base.base_points, design.get("base_radius"), design.get("base_spacing"))
    if "platform_radius" in design or "platform_spacing" in design:
        changes["platform_points"] = _layout(base.platform_points, design.get("platform_radius"),
                                             design.get("platform_spacing"))
    if "stroke" in design or "min_leg_length" in design:
        limits = base.leg_length_limits
        if limits is None and not {"stroke", "min_leg_length"} <= design.keys():
            raise ValueError("parameters: the starting set has no leg_length_limits; give both stroke and "
                             "min_leg_length")
        low = design.get("min_leg_length", limits[0] if limits else None)
        changes["leg_length_limits"] = (low, low + design.get("stroke", limits[1] - limits[0] if limits else 0))
    if "payload_mass" in design:
        mass = base.platform_mass + design["payload_mass"]
        changes["platform_mass"] = mass
        changes["platform_inertia"] = base.platform_inertia * (mass / base.platform_mass)
    return base.replace(**changes)


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep description (:func:`load`): the starting parameters, the designs (one
    dict of parameter values each), the envelope box offsets and sample counts, the seed and
    the two Pareto metrics."""

    base: PlatformParams
    designs: tuple
    offsets: envelope_module.Box
    envelope_samples: int
    workspace_samples: int
    seed: int
    pareto: tuple[str, str]
    stiffness: np.ndarray | None = None

    @property
    def metric_names(self) -> tuple[str, ...]:
        """The :data:`METRICS` this sweep gives: the :data:`MODAL_METRICS` only with the legs'
        stiffness (``[modes] stiffness``, or ``leg_stiffness`` in the parameters)."""
        modal = self.stiffness is not None or self.base.leg_stiffness is not None
        return tuple(name for name in METRICS if modal or name not in MODAL_METRICS)


def _number(field: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
        raise ValueError(f"{field}: expected a finite number, got {value!r}")
    return float(value)


def _whole(field: str, value, least: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise ValueError(f"{field}: expected a whole number >= {least}, got {value!r}")
    return value


def _table(field: str, value, example: str) -> dict:
    """``value`` if it is a table (a dict); ``ValueError`` naming ``field`` otherwise."""
    if not isinstance(value, dict):
        raise ValueError(f"{field}: expected a table ({example}), got {type(value).__name__} {value!r:.60}")
    return value


def _unknown(field: str, table: dict, known) -> None:
    extra = sorted(set(table) - set(known))
    if extra:
        where = f"{field}.{extra[0]}" if field else extra[0]
        raise ValueError(f"{where}: unknown name; known: {', '.join(sorted(known))}")


def _values(field: str, value, method: str, rng: np.random.Generator | None, count: int):
    """The values of one parameter: a grid's list, or ``count`` random draws."""
    if isinstance(value, dict):
        _unknown(field, value, {"low", "high", "count"})
        if "low" not in value or "high" not in value:
            raise ValueError(f"{field}: a range needs low and high")
        low, high = _number(f"{field}.low", value["low"]), _number(f"{field}.high", value["high"])
        if high < low:
            raise ValueError(f"{field}.high: below low ({high:g} < {low:g}): the range is empty")
        if method == "grid":
            if "count" not in value:
                raise ValueError(f"{field}.count: a grid range needs count")
            return np.linspace(low, high, _whole(f"{field}.count", value["count"])).tolist()
        if "count" in value:
            raise ValueError(f"{field}.count: random designs take designs = N, not a count per parameter")
        return rng.uniform(low, high, count).tolist() if rng is not None else None
    if isinstance(value, list):
        if not value:
            raise ValueError(f"{field}: the list of values is empty")
        values = [_number(f"{field}[{k}]", v) for k, v in enumerate(value)]
        return values if method == "grid" else rng.choice(values, count).tolist()
    number = _number(field, value)
    return [number] if method == "grid" else [number] * count


def _offsets(table: dict) -> envelope_module.Box:
    _unknown("envelope", table, _ENVELOPE)
    missing = [k for k in ("lower", "upper", "velocity", "acceleration") if k not in table]
    if missing:
        raise ValueError(f"envelope.{missing[0]}: missing")
    try:
        return envelope_module.Box(*(table[k] for k in ("lower", "upper", "velocity", "acceleration")))
    except ValueError as exc:
        raise ValueError(f"envelope.{exc}") from None


def parse(data: dict, where: str = "") -> SweepSpec:
    """A :class:`SweepSpec` from the table of a sweep file (see the module docstring)."""
    _table("data", data, "the sweep file's fields")
    _unknown("", data, _TOP)
    if "preset" in data and "params" in data:
        raise ValueError("params: give preset or params, not both")
    try:
        if "params" in data:
            path = os.path.join(os.path.dirname(where), str(data["params"])) if where else str(data["params"])
            base = PlatformParams.load(path)
        else:
            base = PlatformParams.preset(str(data.get("preset", "narayan2017")))
    except (ValueError, OSError) as exc:
        raise ValueError(f"{'params' if 'params' in data else 'preset'}: {exc}") from None
    method = data.get("method", "grid")
    if method not in ("grid", "random"):
        raise ValueError(f"method: expected \"grid\" or \"random\", got {method!r}")
    seed = _whole("seed", data.get("seed", 0), 0)
    if method == "random" and "designs" not in data:
        raise ValueError("designs: random designs need a count, designs = N")
    count = _whole("designs", data["designs"]) if method == "random" else 1
    if method == "grid" and "designs" in data:
        raise ValueError("designs: a grid has one design per combination; use method = \"random\" for a count")
    params = _table("parameters", data.get("parameters", {}), "[parameters] with base_radius = ... and the like")
    if not params:
        raise ValueError("parameters: name at least one design parameter")
    _unknown("parameters", params, PARAMETERS)
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(2**31,)))
    values = {name: _values(f"parameters.{name}", params[name], method, rng, count) for name in sorted(params)}
    if method == "grid":
        designs = tuple(dict(zip(values, combo)) for combo in itertools.product(*values.values()))
    else:
        designs = tuple({name: values[name][k] for name in values} for k in range(count))
    for k, design in enumerate(designs):
        try:
            kinematics.home_pose(design_params(base, design))  # every design stands at a home pose
        except ValueError as exc:
            raise ValueError(f"parameters: design {k} ({design}) is not a valid platform: {exc}") from None
    env = data.get("envelope")
    if env is None:
        raise ValueError("envelope: missing (lower, upper, velocity, acceleration around the home pose)")
    _table("envelope", env, "[envelope] with lower, upper, velocity, acceleration around the home pose")
    work = _table("workspace", data.get("workspace", {}), "[workspace] with samples = N")
    _unknown("workspace", work, {"samples"})
    modes = _table("modes", data.get("modes", {}), "[modes] with stiffness = K (N/m)")
    _unknown("modes", modes, {"stiffness"})
    stiffness = None
    if "stiffness" in modes:
        stiffness = leg_coefficients("modes.stiffness", modes["stiffness"], positive=True)
    pareto = _table("pareto", data.get("pareto", {}), "[pareto] with x and y, two metrics")
    _unknown("pareto", pareto, {"x", "y"})
    axes = (pareto.get("x", "workspace_volume"), pareto.get("y", "peak_force"))
    for key, name in zip(("x", "y"), axes):
        if not isinstance(name, str) or name not in METRICS:
            raise ValueError(f"pareto.{key}: unknown metric {name!r}; known: {', '.join(METRICS)}")
        if name in MODAL_METRICS and stiffness is None and base.leg_stiffness is None:
            raise ValueError(f"pareto.{key}: {name} needs the legs' stiffness: [modes] stiffness = K (N/m), or "
                             "leg_stiffness in the parameters")
    return SweepSpec(base, designs, _offsets(env), _whole("envelope.samples", env.get("samples", 100_000)),
                     _whole("workspace.samples", work.get("samples", 20_000)), seed, axes, stiffness)


def load(path) -> SweepSpec:
    """Read and check a sweep file (TOML); ``ValueError`` naming the field otherwise."""
    with open(path, "rb") as fh:
        try:
            data = tomllib.load(fh)
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(f"{os.fspath(path)}: not a TOML file ({exc})") from None
    return parse(data, os.fspath(path))


def _studies(spec: SweepSpec, k: int) -> tuple[PlatformParams, np.ndarray, list[execution.Study]]:
    """The parameters and home pose of design ``k`` of ``spec``, its two studies (the
    envelope of the box around its home pose, and its translational workspace: the jobs,
    counts, seeds and chunk sizes that :func:`~stewart.studies.envelope.envelope` and
    :func:`~stewart.studies.workspace.translational_workspace` run)."""
    params = design_params(spec.base, spec.designs[k])
    home = kinematics.home_pose(params)
    box = envelope_module.Box(home + spec.offsets.lower, home + spec.offsets.upper, spec.offsets.velocity,
                              spec.offsets.acceleration)
    env_job, env_states = envelope_module.study_job(params, box, spec.envelope_samples)
    fixed = np.zeros(3)
    work_job, work_states = workspace.study_job(params, "translational", fixed, workspace.position_bounds(params, fixed),
                                           spec.workspace_samples, None, spec.stiffness)
    return params, home, [execution.Study(env_job, env_states, spec.seed),
                          execution.Study(work_job, work_states, spec.seed, workspace.CHUNK_SIZE)]


def _metrics(params: PlatformParams, home: np.ndarray, env_total: dict, work_total: dict, studies) -> dict:
    """The :data:`METRICS` of one design from its studies' combined partials (the modal ones
    NaN without a stiffness: :attr:`SweepSpec.metric_names` leaves them out)."""
    env = envelope_module.from_partials(env_total, params)
    work_study = studies[1]
    work = workspace.from_partials(work_study.job, work_total, work_study.n_states, True, work_study.seed)
    metrics = {"workspace_volume": work.volume, "workspace_volume_error": work.volume_error,
               "margin_mean": work.margin_mean,
               "home_margin": float(workspace.reachability(params, home).margin[0]),
               "outside_stroke": env.outside_stroke / env.states,
               "lowest_frequency": work.frequency_min, "largest_compliance": work.compliance_max,
               "unheld": float(work.unheld) if work.stiffness is not None else float("nan")}
    for quantity, _ in envelope_module.QUANTITIES:
        metrics[f"peak_{quantity}"] = float(np.max(env.value(quantity)))
    return metrics


@dataclass(frozen=True)
class Sweep:
    """The result of a sweep: ``designs`` (dicts of parameter values) and ``metrics`` (one
    array per name of :attr:`SweepSpec.metric_names`, one entry per design), with the Pareto
    axes."""

    designs: tuple
    metrics: dict
    pareto_axes: tuple[str, str]
    platform: str = ""

    def front(self, x: str | None = None, y: str | None = None) -> np.ndarray:
        """Mask of the designs on the Pareto front of metrics ``x`` and ``y`` (default: the spec's)."""
        x, y = x or self.pareto_axes[0], y or self.pareto_axes[1]
        return pareto_front(self.metrics[x] * METRICS[x][1], self.metrics[y] * METRICS[y][1])

    def rows(self) -> list[dict]:
        front = self.front()
        return [{"design": k, **design, **{m: float(v[k]) for m, v in self.metrics.items()}, "pareto": bool(front[k])}
                for k, design in enumerate(self.designs)]

    def to_csv(self, path) -> None:
        rows = self.rows()
        with open(path, "w", newline="") as fh:
            fh.write(f"# design sweep of {self.platform}; units: " + ", ".join(
                f"{k} [{u}]" for k, u in {**PARAMETERS, **{m: METRICS[m][0] for m in self.metrics}}.items() if u)
                + "\n")
            writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)

    def to_json(self, path) -> None:
        with open(path, "w") as fh:
            json.dump({"platform": self.platform, "pareto": list(self.pareto_axes), "designs": self.rows()}, fh,
                      indent=1)

    def plot(self, path) -> str:
        """The Pareto-front figure of the two Pareto metrics: every design, the front joined."""
        from ..io.plots import pyplot

        plt = pyplot()
        x, y = self.pareto_axes
        xs, ys, front = self.metrics[x], self.metrics[y], self.front()
        fig, ax = plt.subplots(figsize=(7, 5), constrained_layout=True)
        ax.scatter(xs[~front], ys[~front], color="tab:gray", label="dominated designs")
        order = np.flatnonzero(front)[np.argsort(xs[front])]
        ax.plot(xs[order], ys[order], "o-", color="tab:red", label="Pareto front")
        for k in order:
            ax.annotate(str(k), (xs[k], ys[k]), textcoords="offset points", xytext=(4, 4), fontsize=8)
        for setter, name in ((ax.set_xlabel, x), (ax.set_ylabel, y)):
            unit, sense = METRICS[name]
            setter(f"{name.replace('_', ' ')}{f' [{unit}]' if unit else ''} ({'higher' if sense > 0 else 'lower'} "
                   f"is better)")
        ax.set_title(f"Design sweep of {self.platform or 'the platform'}: {len(self.designs)} designs")
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.savefig(path, dpi=90)
        plt.close(fig)
        return path


def pareto_front(x, y) -> np.ndarray:
    """Mask of the points not dominated when more of both ``x`` and ``y`` is better (a point
    is dominated by one at least as good in both and better in one); NaN points never are on it."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y)
    better = ((x[None, :] >= x[:, None]) & (y[None, :] >= y[:, None])
              & ((x[None, :] > x[:, None]) | (y[None, :] > y[:, None])) & ok[None, :])
    return ok & ~better.any(axis=1)


def sweep(spec: SweepSpec, *, client=None, progress: bool = True) -> Sweep:
    """Evaluate every design of ``spec`` (:func:`load`), locally or on a Dask ``client``: the
    chunks of every design's envelope and workspace are the tasks of one
    :func:`~stewart.studies.execution.run_studies`, with one progress bar over their states."""
    if not isinstance(spec, SweepSpec):
        raise ValueError(f"spec: expected a SweepSpec (stewart.studies.sweep.load), got {type(spec).__name__}")
    designs = [_studies(spec, k) for k in range(len(spec.designs))]
    totals = execution.run_studies([study for *_, studies in designs for study in studies], client=client,
                                   progress=progress, desc="sweep")
    rows = [_metrics(params, home, *totals[2 * k:2 * k + 2], studies) for k, (params, home, studies) in
            enumerate(designs)]
    metrics = {name: np.array([row[name] for row in rows], dtype=float) for name in spec.metric_names}
    return Sweep(spec.designs, metrics, spec.pareto, spec.base.name or "")
