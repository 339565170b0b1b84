"""Chunked evaluation of large studies: in this process over the local cores, or on a Dask cluster.

A study of ``n_states`` states (poses of a workspace, samples of a motion envelope, the
states of one design of a sweep) is split into :class:`Chunk` s of ``chunk_size``
consecutive states. A *job* is a picklable callable ``job(chunk) -> partial`` that builds
the chunk's states itself (from ``chunk.start``, ``chunk.stop`` and the chunk's own random
generator ``chunk.rng()``), evaluates them with the compiled batch kernel and reduces them
on the spot to a small *partial*: a :class:`Peak` (the largest value of each column with
the state where it occurs), a number or array (counts, sums), or a dict / tuple of these.
:func:`run` evaluates every chunk and merges the partials with :func:`combine`.

* Locally (the default) the chunks run on a pool of ``workers`` threads (the kernel's batch
  calls release the GIL), with a tqdm progress bar over states with an ETA
  (``progress=False`` turns it off).
* With ``client=`` a :class:`dask.distributed.Client` (the ``[cluster]`` extra), each chunk
  is one task: a worker receives the job and the chunk (its index and bounds, never an
  array of states), generates and reduces the states, and returns the partial.

The chunking depends on ``n_states`` and ``chunk_size`` only, chunk ``i`` draws its random
numbers from ``SeedSequence(seed, spawn_key=(i,))`` (the ``i``-th child of
``SeedSequence(seed).spawn``), and the partials are merged in chunk order whatever order
they finish in, so the local and the distributed runs return identical results (bit for
bit) for the same seed.
"""

from __future__ import annotations

import os
import threading
import functools
from concurrent.futures import ThreadPoolExecutor
from concurrent.futures import as_completed as threads_completed
from dataclasses import dataclass

import numpy as np

from ..model import arguments

__all__ = ["Chunk", "Peak", "Study", "ModelJob", "chunks", "combine", "run", "run_studies", "DEFAULT_CHUNK_SIZE"]

#: States per chunk unless told otherwise: large enough that a task's overhead (Dask's is of
#: the order of a millisecond) is small against its work, small enough to bound the memory.
DEFAULT_CHUNK_SIZE = 100_000


@dataclass(frozen=True)
class Chunk:
    """States ``start`` to ``stop`` (exclusive) of a study, the ``index``-th chunk, with the
    study's ``seed`` (``None`` for a study that draws no random numbers)."""

    index: int
    start: int
    stop: int
    seed: int | None = None

    @property
    def size(self) -> int:
        return self.stop - self.start

    def rng(self) -> np.random.Generator:
        """The chunk's own random generator: ``SeedSequence(seed, spawn_key=(index,))``."""
        return np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(self.index,)))


def chunks(n_states: int, chunk_size: int = DEFAULT_CHUNK_SIZE, seed: int | None = None) -> list[Chunk]:
    """The chunks of a study of ``n_states`` states: consecutive ranges of ``chunk_size``
    states, the last one shorter. ``ValueError`` naming the argument for a negative count,
    a chunk size below 1 or a seed that is not a non-negative integer."""
    n_states = _count("n_states", n_states, 0)
    chunk_size = _count("chunk_size", chunk_size, 1)
    if seed is not None:
        seed = arguments.seed(seed)
    return [Chunk(i, start, min(start + chunk_size, n_states), seed)
            for i, start in enumerate(range(0, n_states, chunk_size))]


def _count(name: str, value, least: int) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < least:
        raise ValueError(f"{name}: expected a whole number >= {least}, got {value!r}")
    return int(value)


@dataclass(frozen=True)
class Peak:
    """The largest value of each of ``m`` quantities over a set of states, with the state
    where it occurs: ``value`` ``(m,)``, ``state`` ``(m, k)`` (the state's row, e.g. the
    pose, velocity and acceleration side by side) and ``index`` ``(m,)`` (the state's index
    in the study; -1 and ``value = -inf`` with a NaN state when no state had a finite value).
    For a smallest value, take the peak of the negated quantity."""

    value: np.ndarray
    state: np.ndarray
    index: np.ndarray

    @classmethod
    def of(cls, values, states, start: int = 0) -> "Peak":
        """The peak of each column of ``values`` ``(n, m)`` over its rows, with the rows of
        ``states`` ``(n, k)`` where they occur; ``start`` is the study index of row 0. NaN
        values (states where the model is undefined) are skipped; at a tie the first row wins."""
        values = np.asarray(values, dtype=float)
        states = np.asarray(states, dtype=float)
        if values.ndim != 2 or states.ndim != 2 or len(values) != len(states):
            raise ValueError(f"values, states: need (n, m) and (n, k) arrays, got {values.shape} and {states.shape}")
        if len(values) == 0:
            return cls.empty(values.shape[1], states.shape[1])
        clean = np.where(np.isnan(values), -np.inf, values)
        rows = np.argmax(clean, axis=0)
        value = clean[rows, np.arange(values.shape[1])]
        found = value > -np.inf
        state = np.where(found[:, None], states[rows], np.nan)
        return cls(value, state, np.where(found, rows + start, -1))

    @classmethod
    def empty(cls, m: int, k: int) -> "Peak":
        """The peak over no states: ``-inf`` everywhere."""
        return cls(np.full(m, -np.inf), np.full((m, k), np.nan), np.full(m, -1))

    def merge(self, other: "Peak") -> "Peak":
        """The peak over both sets of states; at a tie, the lower study index wins."""
        later = (other.value > self.value) | ((other.value == self.value) & (other.index >= 0)
                                              & ((self.index < 0) | (other.index < self.index)))
        return Peak(np.where(later, other.value, self.value),
                    np.where(later[:, None], other.state, self.state),
                    np.where(later, other.index, self.index))


def combine(a, b):
    """Merge two partial reductions of the same shape: :class:`Peak` s by :meth:`Peak.merge`,
    dicts key by key, tuples and lists item by item, numbers and arrays by addition (counts,
    sums), ``None`` with anything by the other."""
    if a is None:
        return b
    if b is None:
        return a
    if isinstance(a, Peak):
        return a.merge(b)
    if isinstance(a, dict):
        if a.keys() != b.keys():
            raise ValueError(f"partials: different keys {sorted(a)} and {sorted(b)}")
        return {key: combine(a[key], b[key]) for key in a}
    if isinstance(a, (tuple, list)):
        return type(a)(combine(x, y) for x, y in zip(a, b, strict=True))
    return a + b


def _progress(total: int, desc: str, enabled: bool):
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, unit="states", unit_scale=True, disable=not enabled,
                mininterval=0.25, leave=False)


def run(job, n_states: int, *, seed: int | None = None, chunk_size: int = DEFAULT_CHUNK_SIZE, client=None,
        workers: int | None = None, progress: bool = True, desc: str = "states"):
    """Evaluate ``job`` (a picklable callable ``job(chunk) -> partial``, see the module
    docstring) over the :func:`chunks` of a study of ``n_states`` states and return the
    :func:`combine` d partial (``None`` for ``n_states = 0``).

    ``client``: a :class:`dask.distributed.Client` to run each chunk as a task on its
    cluster; ``None`` (the default) runs the chunks here on ``workers`` threads (default:
    the number of cores). ``progress`` shows a progress bar (named ``desc``) over the
    states with an ETA. The result does not depend on where the chunks ran. An exception
    in a chunk is raised here, and the chunks not yet started are cancelled.
    """
    return run_studies([Study(job, n_states, seed, chunk_size)], client=client, workers=workers, progress=progress,
                       desc=desc)[0]


@dataclass(frozen=True)
class Study:
    """One study of :func:`run_studies`: its ``job``, number of states, seed and chunk size
    (the arguments of :func:`run`)."""

    job: object
    n_states: int
    seed: int | None = None
    chunk_size: int = DEFAULT_CHUNK_SIZE


def _call(job, chunk):
    """``job(chunk)``: one task of :func:`run_studies` on a Dask worker."""
    return job(chunk)


def run_studies(studies, *, client=None, workers: int | None = None, progress: bool = True,
                desc: str = "states") -> list:
    """Evaluate several :class:`Study` s as one set of tasks, one per chunk of each study (on
    ``workers`` threads here, or on the cluster of ``client``, as :func:`run`), and return
    each study's :func:`combine` d partial, in the order of ``studies``: the same as
    :func:`run` of each study alone, bit for bit. One progress bar (named ``desc``) counts
    the states of all the studies."""
    studies = list(studies)
    tasks = [(k, chunk) for k, study in enumerate(studies)
             for chunk in chunks(study.n_states, study.chunk_size, study.seed)]
    bar = _progress(sum(chunk.size for _, chunk in tasks), desc, progress)
    results: list = [None] * len(tasks)
    try:
        if client is None:
            workers = (os.cpu_count() or 1) if workers is None else _count("workers", workers, 1)
            failed = threading.Event()  # set by a failing chunk: the chunks after it do not start

            def run_chunk(k, chunk):
                if failed.is_set():
                    return None
                try:
                    return studies[k].job(chunk)
                except BaseException:
                    failed.set()
                    raise

            with ThreadPoolExecutor(max_workers=min(workers, max(len(tasks), 1))) as pool:
                futures = {pool.submit(run_chunk, *task): t for t, task in enumerate(tasks)}
                try:
                    for future in threads_completed(futures):
                        t = futures[future]
                        results[t] = future.result()
                        bar.update(tasks[t][1].size)
                except BaseException:  # a failed chunk or Ctrl-C: the chunks not started are dropped
                    failed.set()
                    for future in futures:
                        future.cancel()
                    raise
        else:
            from distributed import as_completed

            futures = client.map(_call, [studies[k].job for k, _ in tasks], [chunk for _, chunk in tasks],
                                 pure=False)
            order = {future.key: chunk for future, (_, chunk) in zip(futures, tasks)}
            try:
                for future in as_completed(futures):
                    if future.status != "finished":
                        future.result()  # raises the chunk's error
                    bar.update(order[future.key].size)
                # The partials stay on the workers until all are done, then come in one batch.
                results = client.gather(futures)
            except BaseException:
                client.cancel(futures)
                raise
    finally:
        bar.close()
    totals: list = [None] * len(studies)
    for (k, _), partial in zip(tasks, results):  # each study's partials in chunk order
        totals[k] = combine(totals[k], partial)
    return totals


class ModelJob:
    """A job that evaluates the compiled model of its ``params`` (a field of the job's
    dataclass, a :class:`~stewart.PlatformParams` or :class:`~stewart.RotaryParams`):
    :attr:`platform`, the :class:`~stewart.Platform` (or :class:`~stewart.RotaryPlatform`), is
    built once per process, on first use, and shared by the chunks the process runs. A job sent to a Dask worker is pickled without it (only the
    parameters travel) and builds it there."""

    @functools.cached_property
    def platform(self):
        """The compiled model of ``params`` (one per process and parameter set)."""
        return _compiled(self.params)

    def __getstate__(self):
        state = dict(self.__dict__)
        state.pop("platform", None)
        return state


@functools.lru_cache(maxsize=8)
def _compiled(params):
    """``Platform(params)`` (``RotaryPlatform(params)`` for a rotary rig), built once per
    process: the jobs of the same parameters (the tasks a Dask worker unpickles one by one)
    share it."""
    from ..model.platform import Platform
    from ..model.rotary import RotaryPlatform
    from ..model.rotary_params import RotaryParams

    return RotaryPlatform(params) if isinstance(params, RotaryParams) else Platform(params)
