"""Speed of chunked studies (``python -m benchmarks.studies``, and in ``make bench``): an
envelope (:mod:`stewart.studies.envelope`, a box with velocity and acceleration bounds) in this
process and on a 2-worker Dask ``LocalCluster``, an envelope of 10^7 states, the cost of
one chunk and Dask's overhead per task, each target marked met or missed, and from these
the estimate of a large sweep on a cluster (:func:`estimate`)."""

from __future__ import annotations

import argparse
import time

import numpy as np

import stewart
from stewart.cli import bench
from stewart.studies import envelope, execution

#: States of the throughput runs, and of the large envelope.
STATES = 10_000_000
LARGE = 10_000_000
#: Most seconds for an envelope of LARGE states on this machine's two cores.
LARGE_SECONDS = 5.0
#: Least throughput of the 2-worker LocalCluster as a fraction of the in-process run.
CLUSTER_RATIO = 0.85
#: Tasks of the Dask overhead measurement.
OVERHEAD_TASKS = 400


def _box(params) -> envelope.Box:
    home = stewart.home_pose(params)
    offsets = np.array([0.01, 0.01, 0.01, 0.05, 0.05, 0.05])
    return envelope.Box(home - offsets, home + offsets, np.full(6, 0.1), np.full(6, 1.0))


def _rate(fn, states: int) -> float:
    start = time.perf_counter()
    fn()
    return states / (time.perf_counter() - start)


def _noop(chunk):
    return chunk.size


#: Alternated runs of the throughput comparison (the median of each side is reported).
RUNS = 5


def _cluster_rate(job, states: int) -> tuple[float, float, float]:
    """Median states per second of ``job`` on a 2-worker LocalCluster (Dask's defaults: one
    worker process with one thread per core) and in process, alternated, :data:`RUNS` runs
    each; and Dask's wall time per task."""
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        execution.run(job, 4 * execution.DEFAULT_CHUNK_SIZE, seed=0, client=client, progress=False)  # warm up
        local, remote = [], []
        for _ in range(RUNS):
            local.append(_rate(lambda: execution.run(job, states, seed=0, progress=False), states))
            remote.append(_rate(lambda: execution.run(job, states, seed=0, client=client, progress=False), states))
        start = time.perf_counter()
        execution.run(_noop, OVERHEAD_TASKS, chunk_size=1, client=client, progress=False)
        overhead = (time.perf_counter() - start) / OVERHEAD_TASKS
    return float(np.median(remote)), float(np.median(local)), overhead


def figures(preset: str = "narayan2017", states: int = STATES, large: int = LARGE) -> dict:
    """States per second in process and on a 2-worker LocalCluster; the time of an envelope of
    ``large`` states; one chunk's time on one thread and Dask's wall time per task."""
    params = stewart.PlatformParams.preset(preset)
    box = _box(params)
    job = envelope._EnvelopeJob(params, box)
    chunk = execution.chunks(execution.DEFAULT_CHUNK_SIZE, execution.DEFAULT_CHUNK_SIZE, 0)[0]
    out = {"preset": preset, "states": states, "chunk_size": execution.DEFAULT_CHUNK_SIZE,
           "chunk_s": bench.median_time(lambda: job(chunk), 1, 5)}
    out["cluster_states_per_s"], out["local_states_per_s"], out["task_overhead_s"] = _cluster_rate(job, states)
    out["ratio"] = out["cluster_states_per_s"] / out["local_states_per_s"]
    start = time.perf_counter()
    envelope.envelope(params, box, samples=large, progress=False)
    out["large_states"], out["large_s"] = large, time.perf_counter() - start
    return out


def _mark(ok: bool) -> str:
    return "met" if ok else "MISSED"


def rows(fig: dict) -> list[tuple[str, str, str, str]]:
    """(measure, figure, target, met) rows."""
    return [
        ("envelope, in process (2 threads)", f"{fig['local_states_per_s'] / 1e6:.3f} M states/s", "", ""),
        ("envelope, 2-worker LocalCluster (Dask's defaults)",
         f"{fig['cluster_states_per_s'] / 1e6:.3f} M states/s ({fig['ratio']:.0%} of in process)",
         f">= {CLUSTER_RATIO:.0%}", _mark(fig["ratio"] >= CLUSTER_RATIO)),
        (f"envelope of {fig['large_states']:.0e} states, in process", f"{fig['large_s']:.1f} s",
         f"<= {LARGE_SECONDS:g} s", _mark(fig["large_s"] <= LARGE_SECONDS)),
        (f"one chunk of {fig['chunk_size']} states, 1 thread", f"{fig['chunk_s'] * 1e3:.1f} ms", "", ""),
        ("Dask wall time per task (2 workers)", f"{fig['task_overhead_s'] * 1e3:.2f} ms", "", ""),
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
    table = [("measure", "figure", "target", "")] + rows(fig)
    widths = [max(len(r[k]) for r in table) for k in range(4)]
    lines = ["| " + " | ".join(c.ljust(w) for c, w in zip(r, widths)) + " |" for r in table]
    lines.append("")
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
