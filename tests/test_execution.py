"""Chunked studies (stewart.studies.execution): the chunking, the reductions against brute force over
the whole study, and the same result on a pool of threads and on a 2-worker Dask cluster."""

from __future__ import annotations

import re
import threading
from dataclasses import dataclass

import numpy as np
import pytest

import stewart
from stewart.studies import execution
from stewart.studies.execution import Chunk, Peak


@dataclass(frozen=True)
class ForcePeaks:
    """Random states around the home pose; the peak |tau| per leg, the count and the sum of tau."""

    params: stewart.PlatformParams

    def states(self, chunk: Chunk):
        rng = chunk.rng()
        home = stewart.home_pose(self.params)
        scale = np.array([0.03 * home[2]] * 3 + [0.08] * 3)
        x = home + rng.uniform(-1, 1, (chunk.size, 6)) * scale
        xd = rng.uniform(-1, 1, (chunk.size, 6)) * scale * 4
        xdd = rng.uniform(-1, 1, (chunk.size, 6)) * scale * 40
        return x, xd, xdd

    def __call__(self, chunk: Chunk):
        x, xd, xdd = self.states(chunk)
        tau = stewart.Platform(self.params).inverse_dynamics(x, xd, xdd)
        return {"peak": Peak.of(np.abs(tau), np.hstack([x, xd, xdd]), chunk.start),
                "count": chunk.size, "sum": tau.sum(axis=0)}


@pytest.fixture(scope="module")
def job():
    return ForcePeaks(stewart.PlatformParams.preset("narayan2017"))


def test_chunks_cover_the_study_once_in_order():
    parts = execution.chunks(10_007, 1000, seed=3)
    assert [c.index for c in parts] == list(range(11))
    assert np.array_equal(np.concatenate([np.arange(c.start, c.stop) for c in parts]), np.arange(10_007))
    assert parts[-1].size == 7 and execution.chunks(0, 10) == []


def test_chunk_generator_is_the_spawned_child():
    children = np.random.SeedSequence(42).spawn(5)
    for chunk in execution.chunks(50, 10, seed=42):
        expected = np.random.default_rng(children[chunk.index]).random(4)
        assert np.array_equal(chunk.rng().random(4), expected)


@pytest.mark.parametrize("kwargs, field", [({"chunk_size": 0}, "chunk_size"), ({"seed": -1}, "seed"),
                                           ({"seed": 1.5}, "seed"), ({"n_states": -3}, "n_states")])
def test_bad_arguments_name_the_argument(kwargs, field):
    args = {"n_states": 10, **kwargs}
    with pytest.raises(ValueError, match=f"^{field}: "):
        execution.chunks(**args)


def test_peak_against_whole_array_argmax():
    rng = np.random.default_rng(0)
    values = rng.normal(size=(1000, 4))
    values[rng.integers(0, 1000, 50), rng.integers(0, 4, 50)] = np.nan
    states = rng.normal(size=(1000, 3))
    merged = Peak.empty(4, 3)
    for start in range(0, 1000, 128):
        merged = merged.merge(Peak.of(values[start:start + 128], states[start:start + 128], start))
    rows = np.nanargmax(values, axis=0)
    assert np.array_equal(merged.index, rows)
    assert np.array_equal(merged.value, values[rows, np.arange(4)])
    assert np.array_equal(merged.state, states[rows])


def test_peak_ties_go_to_the_first_state_and_nan_only_columns_are_empty():
    values = np.array([[1.0, np.nan], [3.0, np.nan], [3.0, np.nan]])
    states = np.arange(6.0).reshape(3, 2)
    late, early = Peak.of(values[2:], states[2:], 2), Peak.of(values[:2], states[:2], 0)
    for peak in (early.merge(late), late.merge(early)):
        assert peak.index.tolist() == [1, -1] and peak.value[0] == 3.0 and peak.value[1] == -np.inf
        assert np.array_equal(peak.state[0], states[1]) and np.all(np.isnan(peak.state[1]))


@pytest.mark.parametrize("values, states", [(np.zeros(4), np.zeros((4, 2))), (np.zeros((4, 1)), np.zeros((4, 2, 2))),
                                            (np.zeros((4, 1)), np.zeros((3, 2)))])
def test_peak_of_mismatched_arrays_names_them(values, states):
    message = f"values, states: need (n, m) and (n, k) arrays, got {values.shape} and {states.shape}"
    with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
        Peak.of(values, states)


def test_local_run_equals_brute_force(job):
    n, size = 2500, 400
    result = execution.run(job, n, seed=7, chunk_size=size, progress=False)
    x, xd, xdd = (np.concatenate(parts) for parts in
                  zip(*(job.states(c) for c in execution.chunks(n, size, seed=7))))
    tau = np.abs(stewart.Platform(job.params).inverse_dynamics(x, xd, xdd))
    rows = np.argmax(tau, axis=0)
    assert result["count"] == n
    assert np.array_equal(result["peak"].index, rows)
    assert np.array_equal(result["peak"].value, tau[rows, np.arange(6)])
    assert np.array_equal(result["peak"].state, np.hstack([x, xd, xdd])[rows])


def test_result_does_not_depend_on_the_thread_count(job):
    one = execution.run(job, 3000, seed=1, chunk_size=500, workers=1, progress=False)
    two = execution.run(job, 3000, seed=1, chunk_size=500, workers=2, progress=False)
    assert np.array_equal(one["peak"].state, two["peak"].state)
    assert np.array_equal(one["sum"], two["sum"])


def test_dask_cluster_matches_the_local_run(job, simd_path):
    distributed = pytest.importorskip("distributed")
    local = execution.run(job, 3000, seed=5, chunk_size=500, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        remote = execution.run(job, 3000, seed=5, chunk_size=500, client=client, progress=False)
    assert remote["count"] == local["count"] == 3000
    assert np.array_equal(remote["sum"], local["sum"])
    for field in ("value", "state", "index"):
        assert np.array_equal(getattr(remote["peak"], field), getattr(local["peak"], field))


class _Meets:
    """Chunks that wait for each other: they finish only when ``parties`` run at the same time."""

    def __init__(self, parties):
        self.barrier = threading.Barrier(parties, timeout=10)

    def __call__(self, chunk: Chunk):
        self.barrier.wait()
        return chunk.size


def test_local_run_uses_a_thread_per_core_by_default(monkeypatch):
    """workers=None: as many threads as os.cpu_count() says (three chunks that wait for each
    other at a barrier of three finish only on three threads at once)."""
    monkeypatch.setattr(execution.os, "cpu_count", lambda: 3)
    assert execution.run(_Meets(3), 3, chunk_size=1, progress=False) == 3
    monkeypatch.setattr(execution.os, "cpu_count", lambda: None)  # unknown: one thread
    assert execution.run(lambda chunk: chunk.size, 2, chunk_size=1, progress=False) == 2


class _FailsFirst:
    def __init__(self):
        self.calls = 0

    def __call__(self, chunk: Chunk):
        self.calls += 1
        if chunk.index == 0:
            raise ValueError("chunk 0 failed")
        return chunk.size


def test_a_failed_chunk_raises_and_cancels_the_rest():
    job = _FailsFirst()
    with pytest.raises(ValueError, match="chunk 0 failed"):
        execution.run(job, 50, chunk_size=1, workers=1, progress=False)
    assert job.calls <= 2


class _Recording:
    """A Dask client that records the futures it is asked to cancel."""

    def __init__(self, client):
        self.client, self.cancelled = client, []

    def map(self, *args, **kwargs):
        self.futures = self.client.map(*args, **kwargs)
        return self.futures

    def gather(self, futures):
        return self.client.gather(futures)

    def cancel(self, futures):
        self.cancelled.extend(futures)
        self.client.cancel(futures)


def test_a_failed_chunk_on_dask_raises_and_cancels_the_tasks():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        recording = _Recording(client)
        with pytest.raises(ValueError, match="chunk 0 failed"):
            execution.run(_FailsFirst(), 50, chunk_size=1, client=recording, progress=False)
    assert len(recording.futures) == 50 and recording.cancelled == recording.futures
