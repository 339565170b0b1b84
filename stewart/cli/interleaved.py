"""Timings measured interleaved, and the verdicts they support (``stewart bench``, ``make bench``).

A figure of the bench is never one timing: it is a statistic of **rounds**. A round times
each of its sides once, one after the other in this process (A, B, A, B, ..., the order
reversed every other round so that neither side always runs first), and turns the round's
times into one value: the ratio t_A / t_B, or another function of the round's times. A side
is short (:data:`ROUND_SECONDS`; as long as the slowest side's call where that is longer, at
most :data:`LONG_SECONDS`): the other jobs of a shared machine take the core in slices of
milliseconds, so most rounds run whole between two of them and give the same value as on
an idle machine, and a round they interrupt is an outlier that the median ignores.

- The **figure** is the median of the rounds' values; its **spread** is the distribution-free
  90 % confidence interval of that median (:func:`median_interval`: two order statistics
  of the rounds' values, at the ranks the binomial distribution gives).
- Rounds repeat (at least :data:`MIN_ROUNDS`) until the interval is at most half as wide as
  the median's distance from the target's bound (:func:`settled`), or until the figure's time
  budget runs out; a figure without a target stops when its interval is within 5 % of its
  median.
- A target is **met** when the whole interval lies on its side of the bound, **missed** when
  the whole interval lies beyond it, and **unsettled** when the interval straddles the bound
  (:func:`verdict`).

An absolute figure (µs a state, ms a move, s a build) is measured against the
**yardstick** (:class:`Yardstick`): a fixed numpy workload that shares nothing with the code
under test, timed in the same rounds. The figure is the round's ratio to the yardstick
times the yardstick's cost on the reference machine (:data:`REFERENCE`, recorded once):
what the code would take on that machine.

A figure that needs both cores (two threads, two processes) cannot be rescued that way when
the machine's other jobs hold the second core, and that only ever makes it look worse. Its
rounds also time the yardstick on two threads, each running four calls: the **gauge** is the
median of the machine's two-thread speed-up on it (:func:`parallel_gauge`: 8 t_one / t_two, about
1.9 with both cores free, below 1 on the reference machine under a load of 10 to 12, where
two threads never ran at once for half a millisecond). Below :data:`PARALLEL_FLOOR` a miss
is not trusted and the target is unsettled; a figure that meets its target even so is met.
"""

from __future__ import annotations

import contextlib
import functools
import math
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Callable, NamedTuple, Sequence

import numpy as np

__all__ = ["BUDGET", "ROUND_SECONDS", "LONG_SECONDS", "ANCHOR_SECONDS", "WARM_LIMIT", "MIN_ROUNDS", "MAX_ROUNDS",
           "CONFIDENCE", "INFORMATIVE", "PARALLEL_FLOOR", "Target", "Measurement", "Reference", "REFERENCE",
           "Yardstick", "parallel_gauge", "median_interval", "interval_rank", "verdict", "settled", "per_call",
           "time_calls", "SelfTimed", "Figure", "measure_all", "measure", "reference_cost"]

#: Seconds of rounds a figure with a target may take before it is judged as it stands (a
#: figure without one gets a third of it, ``stewart bench --budget``).
BUDGET = 3.0
#: Seconds each side of a round takes at least (several calls in a row where one is shorter).
ROUND_SECONDS = 2e-4
#: Longest a side of a round is stretched to last as long as the slowest side's call.
LONG_SECONDS = 0.25
#: Seconds of the yardstick's sides beside a job of seconds (generation, a build, an
#: identification): long enough that they get, as the job does, the average share of a busy
#: machine, not the luck of one time slice.
ANCHOR_SECONDS = 0.5
#: Calls shorter than this are made once untimed before each timing of their side.
WARM_LIMIT = 5e-3
#: Rounds before any figure is judged (the 90 % interval of the median of 9 values is
#: bounded by the 2nd and 8th of them).
MIN_ROUNDS = 9
#: Rounds after which a figure stops, settled or not.
MAX_ROUNDS = 2000
#: Confidence of the interval of the median.
CONFIDENCE = 0.90
#: Most relative width of the interval at which a figure without a target stops.
INFORMATIVE = 0.05
#: The least gauge (the yardstick's speed-up on two threads in the same rounds) at which a
#: figure needing both cores can be missed.
PARALLEL_FLOOR = 1.5


class Target(NamedTuple):
    """A performance target: ``figure <= bound`` (``at_most``) or ``figure >= bound``, the
    figure measured against ``anchor`` (what its rounds time beside it)."""

    bound: float
    at_most: bool
    anchor: str = "the yardstick"

    def met(self, value: float) -> bool:
        """Whether one value is on the target's side of the bound (the bound itself is)."""
        return value <= self.bound if self.at_most else value >= self.bound


def median_interval(values: Sequence[float], confidence: float = CONFIDENCE) -> tuple[float, float]:
    """The distribution-free confidence interval of the median of ``values``: their k-th
    smallest and k-th largest, for the largest k (:func:`interval_rank`) whose interval covers
    the median with at least ``confidence``."""
    ordered = sorted(values)
    if not ordered:
        raise ValueError("no values")
    k = interval_rank(len(ordered), confidence)
    return ordered[k - 1], ordered[len(ordered) - k]


@functools.lru_cache(maxsize=None)
def interval_rank(n: int, confidence: float = CONFIDENCE) -> int:
    """The largest k <= (n + 1) / 2 for which the k-th smallest and k-th largest of n values
    enclose their distribution's median with probability >= ``confidence``: how many of the
    values fall below the median is binomial (n, 1/2), so that probability is
    1 - 2 P(B <= k - 1). Fewer than 5 values reach 90 % with no k: their interval is their
    range (k = 1, probability 1 - 2^(1-n))."""
    def p(i: int) -> float:  # P(B = i)
        return math.exp(math.lgamma(n + 1) - math.lgamma(i + 1) - math.lgamma(n - i + 1) - n * math.log(2.0))

    k, below = 1, p(0)  # below = P(B <= k - 1)
    while k + 1 <= (n + 1) // 2 and 1.0 - 2.0 * (below + p(k)) >= confidence:
        below += p(k)
        k += 1
    return k


def verdict(target: Target, low: float, high: float, gauge: float | None = None) -> str:
    """``met``, ``missed`` or ``unsettled`` for a figure whose interval is [low, high]; a
    figure needing both cores whose ``gauge`` is below :data:`PARALLEL_FLOOR` is not missed
    but unsettled."""
    if target.met(high if target.at_most else low):
        return "met"
    if not target.met(low if target.at_most else high):
        return "missed" if gauge is None or gauge >= PARALLEL_FLOOR else "unsettled"
    return "unsettled"


def settled(median: float, low: float, high: float, target: Target | None) -> bool:
    """Whether rounds may stop: the interval at most half as wide as the median's distance
    from the target's bound (so it lies on one side of it), or, without a target, within
    :data:`INFORMATIVE` of the median."""
    if target is None:
        return high - low <= INFORMATIVE * abs(median)
    return high - low <= 0.5 * abs(median - target.bound)


class Measurement(NamedTuple):
    """A figure: the median of its rounds' values and the interval of that median, the
    rounds, each side's median seconds a call, and for a figure needing both cores the
    median gauge of its rounds (else None)."""

    median: float
    low: float
    high: float
    rounds: int
    seconds: tuple[float, ...] = ()
    gauge: float | None = None

    @classmethod
    def of(cls, values: Sequence[float], seconds: tuple[float, ...] = (),
           gauges: Sequence[float] | None = None) -> "Measurement":
        low, high = median_interval(values)
        gauge = float(np.median(gauges)) if gauges else None
        return cls(float(np.median(values)), float(low), float(high), len(values), seconds, gauge)

    def verdict(self, target: Target) -> str:
        """``met``, ``missed`` or ``unsettled`` (:func:`verdict`)."""
        return verdict(target, self.low, self.high, self.gauge)


def time_calls(fn: Callable[[], object], number: int, clock: Callable[[], float] = time.perf_counter) -> float:
    """Seconds a call of ``fn``, over ``number`` calls in a row."""
    start = clock()
    for _ in range(number):
        fn()
    return (clock() - start) / number


def per_call(fn: Callable[[], object], trials: int = 3) -> float:
    """Seconds a call of ``fn`` takes, the shortest of ``trials`` timings of calls in a row
    lasting at least a millisecond (or one call each), after one call that warms it up: the
    shortest, because a timing the machine's other jobs interrupted would stretch every side
    of the figure's rounds, and long sides are interrupted more often."""
    fn()
    number = 1
    while True:
        took = time_calls(fn, number) * number
        if took >= 1e-3 or number >= 10**6:
            break
        number = max(2 * number, math.ceil(number * 1.2e-3 / max(took, 1e-9)))
    return min([took / number] + [time_calls(fn, number) for _ in range(trials - 1)])


class SelfTimed:
    """A side that times itself: a call returns the seconds its round counts (for a job whose
    own statistic is the figure, e.g. the median step of a plan)."""

    def __init__(self, fn: Callable[[], float]):
        self.fn = fn

    def __call__(self) -> float:
        return float(self.fn())


class Figure:
    """One figure's rounds: its ``sides`` (callables), ``value(*seconds)`` of a round's times
    (and ``gauge(*seconds)`` for a figure needing both cores), its ``target`` and ``budget``
    (seconds of its own rounds), and ``around``, a context (e.g. a SIMD path) its calibration
    and each of its rounds run in. A side without a number (all, by default) runs as many
    calls in a row as last ``seconds``: by default as long as the slowest side's call, at
    least :data:`ROUND_SECONDS` and at most :data:`LONG_SECONDS`, so that the other jobs of
    the machine interrupt every side about as often."""

    def __init__(self, sides: Sequence[Callable[[], object]], value: Callable[..., float], *,
                 target: Target | None = None, budget: float = BUDGET, min_rounds: int = MIN_ROUNDS,
                 max_rounds: int = MAX_ROUNDS, numbers: Sequence[int | None] | None = None,
                 seconds: float | None = None, gauge: Callable[..., float] | None = None,
                 around: Callable[[], contextlib.AbstractContextManager] = contextlib.nullcontext):
        self.sides, self.value, self.gauge, self.target, self.around = list(sides), value, gauge, target, around
        self.budget, self.min_rounds, self.max_rounds, self.seconds = budget, min_rounds, max_rounds, seconds
        self.numbers = list(numbers) if numbers is not None else [None] * len(self.sides)
        self.values: list[float] = []
        self.gauges: list[float] = []
        self.times: list[list[float]] = []
        self.spent = 0.0
        self.warm = [False] * len(self.sides)

    def calibrate(self) -> None:
        """The number of calls of each side without one (:func:`per_call`)."""
        for i, side in enumerate(self.sides):
            if isinstance(side, SelfTimed):
                self.numbers[i] = 1
        with self.around():
            calls = {i: per_call(fn) for i, fn in enumerate(self.sides) if self.numbers[i] is None}
        self.warm = [i in calls and calls[i] < WARM_LIMIT for i in range(len(self.sides))]
        seconds = self.seconds
        if seconds is None:
            seconds = max(ROUND_SECONDS, min(LONG_SECONDS, max(calls.values(), default=0.0)))
        for i, call in calls.items():
            self.numbers[i] = max(1, round(seconds / call))

    def round(self, timer: Callable[[Callable, int], float], clock: Callable[[], float]) -> None:
        """One round: every side timed once, in the order given on even rounds and reversed on
        odd ones, each after one call untimed where a call is shorter than :data:`WARM_LIMIT`
        (the rounds of other figures in between leave the caches to their own code and data,
        and the first call after them would pay for bringing this side's back)."""
        start = clock()
        took = [0.0] * len(self.sides)
        order = range(len(self.sides))
        with self.around():
            for i in (order if len(self.values) % 2 == 0 else reversed(order)):
                side = self.sides[i]
                if isinstance(side, SelfTimed):
                    took[i] = side()
                    continue
                if self.warm[i]:
                    side()
                took[i] = timer(side, self.numbers[i])
        self.values.append(float(self.value(*took)))
        if self.gauge is not None:
            self.gauges.append(float(self.gauge(*took)))
        self.times.append(took)
        self.spent += clock() - start

    def done(self) -> bool:
        """Whether its rounds stop: :func:`settled`, or its budget spent (after ``min_rounds``),
        or ``max_rounds`` reached."""
        if len(self.values) >= self.max_rounds:
            return True
        if len(self.values) < self.min_rounds:
            return False
        low, high = median_interval(self.values)
        return self.spent > self.budget or settled(float(np.median(self.values)), low, high, self.target)

    def result(self) -> Measurement:
        return Measurement.of(self.values, tuple(float(s) for s in np.median(np.array(self.times), axis=0)),
                              self.gauges)


def measure_all(figures: Sequence[Figure], timer: Callable[[Callable, int], float] = time_calls,
                clock: Callable[[], float] = time.perf_counter) -> list[Measurement]:
    """The figures' rounds, interleaved too: one round of each figure not done in turn, over
    and over, so that each figure's rounds spread over the whole measurement and a spell of
    the machine that slows one kind of code more than another moves few of them."""
    for figure in figures:
        figure.calibrate()
    active = list(figures)
    while active:
        for figure in active:
            figure.round(timer, clock)
        active = [figure for figure in active if not figure.done()]
    return [figure.result() for figure in figures]


def measure(sides: Sequence[Callable[[], object]], value: Callable[..., float], *,
            timer: Callable[[Callable, int], float] = time_calls, clock: Callable[[], float] = time.perf_counter,
            **options) -> Measurement:
    """One :class:`Figure`'s rounds (``options``: its keywords)."""
    return measure_all([Figure(sides, value, **options)], timer, clock)[0]


class Reference(NamedTuple):
    """The yardstick's cost on the reference machine (seconds a call on one thread), and
    that machine."""

    seconds: float
    machine: str


#: The yardstick's cost on the reference machine, the one record every absolute figure is
#: measured against (:func:`reference_cost`: the median of 3000 calls, each after a call
#: untimed as in rounds; the shortest was 1.245e-4 s). That machine is shared and was never
#: idle: the 1-minute load average was 10 on its 2 cores, which a call of 0.13 ms mostly
#: runs between (three runs gave medians within 0.1 % of each other).
REFERENCE = Reference(
    seconds=1.262e-4,
    machine="2-core AMD EPYC (Zen 4, KVM), Linux 6.18, Python 3.11.7, numpy 2.4.6; 2026-11-28")


class Yardstick:
    """The fixed workload absolute figures are measured against: a call runs :data:`PASSES`
    passes of square root, division, product and sum (numpy ufuncs, which release the GIL
    while they compute) over arrays of :data:`SIZE` doubles allocated once (64 KiB each,
    within a core's L2 cache). On two threads, this thread and a second one (started once)
    each run :data:`CALLS_EACH` calls on arrays of their own: the gauge of a figure needing
    both cores (:func:`parallel_gauge`).
    It shares nothing with the code under test, so no change there can move it; its cost on
    the reference machine is :data:`REFERENCE`."""

    SIZE = 8192
    PASSES = 8
    #: Calls each of the two threads runs in a call on two threads (so that handing the work to
    #: the second thread costs a few per cent of it).
    CALLS_EACH = 4

    def __init__(self, threads: int = 1):
        if threads not in (1, 2):
            raise ValueError(f"threads: 1 or 2, not {threads}")
        self.threads = threads
        self.arrays = [(np.linspace(1.0, 2.0, self.SIZE), np.empty(self.SIZE)) for _ in range(threads)]
        self.pool = ThreadPoolExecutor(1) if threads == 2 else None

    def _passes(self, k: int, calls: int = 1) -> None:
        a, b = self.arrays[k]
        for _ in range(calls * self.PASSES):
            np.sqrt(a, out=b)
            np.divide(a, b, out=b)
            np.multiply(b, a, out=b)
            np.add(b, a, out=b)

    def __call__(self) -> None:
        if self.pool is None:
            self._passes(0)
            return
        other = self.pool.submit(self._passes, 1, self.CALLS_EACH)
        self._passes(0, self.CALLS_EACH)
        other.result()


def parallel_gauge(one: float, two: float) -> float:
    """The machine's two-thread speed-up from the seconds of a call of the yardstick on one
    thread and of a call on two (:attr:`Yardstick.CALLS_EACH` calls on each): about 2 with
    both cores free, 1 when the two threads take turns on one core."""
    return one * 2 * Yardstick.CALLS_EACH / two


def reference_cost(calls: int = 3000) -> tuple[float, float]:
    """The median and the shortest of ``calls`` timings of one call of the yardstick, each
    after a call untimed (as in rounds): how :data:`REFERENCE` was recorded."""
    stick = Yardstick(1)
    per_call(stick)
    times = []
    for _ in range(calls):
        stick()
        times.append(time_calls(stick, 1))
    return float(np.median(times)), float(min(times))
