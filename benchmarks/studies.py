"""Speed of chunked studies (``python -m benchmarks.studies``, and in ``make bench``): an
envelope (:mod:`stewart.studies.envelope`, a box with velocity and acceleration bounds) in this
process and on a 2-worker Dask ``LocalCluster``, an envelope of 10^7 states, the cost of
one chunk and Dask's overhead per task, each target met, missed or unsettled (rounds against
their anchors, :mod:`stewart.cli.interleaved`), and from these the estimate of a large sweep
on a cluster (:func:`estimate`)."""

from __future__ import annotations

import argparse
import time

import numpy as np

import stewart
from stewart.cli import bench
from stewart.cli.interleaved import ANCHOR_SECONDS, Target, parallel_gauge
from stewart.studies import envelope, execution

from .report import target_table

#: States of the throughput runs, and of the large envelope.
STATES = 10_000_000
LARGE = 10_000_000
#: Most seconds for an envelope of LARGE states on this machine's two cores.
LARGE_SECONDS = 5.0
#: Least throughput of the 2-worker LocalCluster as a fraction of the in-process run.
CLUSTER_RATIO = 0.85
#: Tasks of the Dask overhead measurement (one timing: a figure without a target).
OVERHEAD_TASKS = 400


def _box(params) -> envelope.Box:
    home = stewart.home_pose(params)
    offsets = np.array([0.01, 0.01, 0.01, 0.05, 0.05, 0.05])
    return envelope.Box(home - offsets, home + offsets, np.full(6, 0.1), np.full(6, 1.0))


def _noop(chunk):
    return chunk.size


#: Rounds of the throughput comparison (each runs the envelope in process and on the cluster),
#: and of the large envelope.
RUNS = 5
LARGE_RUNS = 2
CLUSTER_TARGET = Target(CLUSTER_RATIO, False, "in process")
LARGE_TARGET = Target(LARGE_SECONDS, True)


def figures(preset: str = "narayan2017", states: int = STATES, large: int = LARGE,
            rounds: bench.Rounds | None = None) -> dict:
    """The envelope's throughput on a 2-worker LocalCluster over its throughput in process
    (Dask's defaults: one worker process with one thread per core), :data:`RUNS` rounds of
    both, with the gauge; the time of an envelope of ``large`` states in process against the
    yardstick, with the gauge; one chunk's time on one thread; and Dask's wall time per
    task (one timing of :data:`OVERHEAD_TASKS` empty tasks, as measured)."""
    from distributed import Client, LocalCluster

    rounds = rounds or bench.Rounds()
    params = stewart.PlatformParams.preset(preset)
    box = _box(params)
    job, _ = envelope.study_job(params, box, states)
    chunk = execution.chunks(execution.DEFAULT_CHUNK_SIZE, execution.DEFAULT_CHUNK_SIZE, 0)[0]
    out = {"preset": preset, "states": states, "chunk_size": execution.DEFAULT_CHUNK_SIZE, "large_states": large}
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        execution.run(job, 4 * execution.DEFAULT_CHUNK_SIZE, seed=0, client=client, progress=False)  # warm up
        local = lambda: execution.run(job, states, seed=0, progress=False)  # noqa: E731
        remote = lambda: execution.run(job, states, seed=0, client=client, progress=False)  # noqa: E731
        rounds.add("ratio", [local, remote, rounds.one, rounds.two], lambda tl, tr, y, y2: tl / tr,
                   gauge=lambda tl, tr, y, y2: parallel_gauge(y, y2), target=CLUSTER_TARGET, numbers=[1, 1, None, None],
                   seconds=ANCHOR_SECONDS, min_rounds=RUNS)
        rounds.job("large_s", lambda: envelope.envelope(params, box, samples=large, progress=False), LARGE_RUNS,
                   target=LARGE_TARGET)
        rounds.absolute("chunk_s", lambda: job(chunk), unit=1.0)
        out.update(bench.figures_of(rounds.measure()))
        start = time.perf_counter()
        execution.run(_noop, OVERHEAD_TASKS, chunk_size=1, client=client, progress=False)
        out["task_overhead_s"] = (time.perf_counter() - start) / OVERHEAD_TASKS
    seconds = out["spread"]["ratio"]["seconds"]
    out["local_states_per_s"], out["cluster_states_per_s"] = states / seconds[0], states / seconds[1]
    return out


def rows(fig: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, figure, spread, target, verdict) rows."""
    ratio = bench.measure_row("envelope, 2-worker LocalCluster (Dask's defaults) over in process (2 threads)",
                              "ratio", bench.as_measurement(fig, "ratio"), 100.0, "%", ".0f", CLUSTER_TARGET)
    return [
        ("envelope, in process (2 threads), as measured", f"{fig['local_states_per_s'] / 1e6:.3f} M states/s", "",
         "", ""),
        ("envelope, 2-worker LocalCluster (Dask's defaults), as measured",
         f"{fig['cluster_states_per_s'] / 1e6:.3f} M states/s", "", "", ""),
        ratio,
        bench.measure_row(f"envelope of {fig['large_states']:.0e} states, in process", "large_s",
                          bench.as_measurement(fig, "large_s"), 1.0, "s", ".1f", LARGE_TARGET),
        bench.measure_row(f"one chunk of {fig['chunk_size']} states, 1 thread", "chunk_s",
                          bench.as_measurement(fig, "chunk_s"), 1e3, "ms", ".1f"),
        ("Dask wall time per task (2 workers), as measured", f"{fig['task_overhead_s'] * 1e3:.2f} ms", "", "", ""),
    ]


def estimate(fig: dict, designs: float = 1e4, states: float = 1e6, nodes: int = 100, cores: int = 2,
             chunk_size: float | None = None) -> dict:
    """The time of a sweep of ``designs`` x ``states`` states on ``nodes`` nodes of ``cores``
    cores like this machine's, in chunks of ``chunk_size`` states (default: the measured
    chunk size): the work (one chunk's measured time per core) spread over every core, and
    the scheduler's share (the measured wall time per task, paid one task after another
    on the scheduler); the run takes at least the larger of the two."""
    chunk_size = chunk_size or fig["chunk_size"]
    per_state = fig["chunk_s"] / fig["chunk_size"]
    tasks = designs * states / chunk_size
    compute = designs * states * per_state / (nodes * cores)
    scheduler = tasks * fig["task_overhead_s"]
    return {"tasks": tasks, "compute_s": compute, "scheduler_s": scheduler, "total_s": max(compute, scheduler),
            "efficiency": compute / max(compute, scheduler)}


def format_rows(fig: dict) -> str:
    lines = [target_table(rows(fig)), ""]
    lines.append("A sweep of 1e4 designs x 1e6 states on 100 nodes of 2 cores like this one:")
    for size in (fig["chunk_size"], 1e6):
        est = estimate(fig, chunk_size=size)
        lines.append(f"  chunks of {size:.0e} states: {est['tasks']:.1e} tasks, work {est['compute_s'] / 60:.1f} min "
                     f"over the cores, scheduler {est['scheduler_s'] / 60:.1f} min; about "
                     f"{est['total_s'] / 60:.1f} min ({est['efficiency']:.0%} of the cores busy)")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.studies", description=__doc__)
    parser.add_argument("--preset", default="narayan2017")
    parser.add_argument("--states", type=int, default=STATES, help="states of the throughput runs")
    parser.add_argument("--large", type=int, default=LARGE, help="states of the large envelope")
    args = parser.parse_args(argv)
    print(format_rows(figures(args.preset, args.states, args.large)))


if __name__ == "__main__":
    main()
