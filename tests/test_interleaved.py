"""The bench's measuring engine (:mod:`stewart.cli.interleaved`) on given timings: the interval
of the median against the binomial distribution (scipy's, and by hand), the verdicts of
given samples, when rounds stop, the order in which they run. Nothing here times anything:
the sides are labels, and a fake timer and clock feed the rounds their times."""

import itertools

import numpy as np
import pytest
from scipy import stats

from stewart.cli import interleaved
from stewart.cli.interleaved import MIN_ROUNDS, Figure, Measurement, SelfTimed, Target


def binomial_rank(n: int, confidence: float = 0.90) -> int:
    """The largest k <= (n + 1) / 2 whose order statistics x_(k), x_(n+1-k) cover the median
    with probability 1 - 2 P(B <= k - 1) >= confidence, B binomial (n, 1/2) (scipy's), or 1."""
    ranks = [k for k in range(1, (n + 1) // 2 + 1) if 1 - 2 * stats.binom.cdf(k - 1, n, 0.5) >= confidence]
    return max(ranks, default=1)


@pytest.mark.parametrize("n", [1, 2, 4, 5, 6, 9, 10, 17, 20, 51, 100, 333, 2000])
def test_the_interval_of_the_median_has_the_binomial_ranks(n):
    assert interleaved.interval_rank(n) == binomial_rank(n)


def test_the_interval_of_ten_values_by_hand():
    """n = 10: P(B <= 1) = 11/1024, so x_(2)..x_(9) covers the median with 1 - 22/1024 = 0.979;
    P(B <= 2) = 56/1024, so x_(3)..x_(8) only with 1 - 112/1024 = 0.891 < 0.90."""
    values = [7.0, 3.0, 9.0, 1.0, 5.0, 8.0, 2.0, 10.0, 4.0, 6.0]
    assert interleaved.median_interval(values) == (2.0, 9.0)
    # Five values: their range, which covers the median with 1 - 2/32 = 0.94.
    assert interleaved.median_interval([5.0, 1.0, 4.0, 2.0, 3.0]) == (1.0, 5.0)
    # Fewer than five cannot reach 90 %: their range all the same.
    assert interleaved.median_interval([2.0, 1.0]) == (1.0, 2.0)
    with pytest.raises(ValueError):
        interleaved.median_interval([])


AT_MOST, AT_LEAST = Target(0.4, True), Target(1.8, False)


@pytest.mark.parametrize("target, samples, expected", [
    (AT_MOST, [0.30, 0.31, 0.32, 0.33, 0.35, 0.36, 0.37, 0.38, 0.39], "met"),
    (AT_MOST, [0.41, 0.42, 0.43, 0.44, 0.45, 0.46, 0.47, 0.48, 0.49], "missed"),
    (AT_MOST, [0.36, 0.37, 0.38, 0.39, 0.40, 0.41, 0.42, 0.43, 0.44], "unsettled"),
    (AT_MOST, [0.40] * 9, "met"),  # the bound itself is met
    # One round in nine above the bound: outside the 2nd..8th order statistics, still met.
    (AT_MOST, [0.30, 0.31, 0.32, 0.33, 0.35, 0.36, 0.37, 0.38, 0.90], "met"),
    # Two above: the 8th is, and the interval straddles.
    (AT_MOST, [0.30, 0.31, 0.32, 0.33, 0.35, 0.36, 0.37, 0.80, 0.90], "unsettled"),
    (AT_LEAST, [1.9, 2.0, 2.1, 1.95, 1.85, 2.05, 1.99, 1.91, 1.87], "met"),
    (AT_LEAST, [1.2, 1.3, 1.1, 1.25, 1.35, 1.15, 1.05, 1.4, 1.0], "missed"),
    (AT_LEAST, [1.7, 1.75, 1.79, 1.8, 1.81, 1.85, 1.9, 1.6, 1.95], "unsettled"),
])
def test_the_verdict_of_given_samples(target, samples, expected):
    assert Measurement.of(samples).verdict(target) == expected


def test_a_miss_needing_both_cores_is_unsettled_when_the_second_core_was_busy():
    """The gauge (the yardstick's speed-up on two threads) below PARALLEL_FLOOR: load only ever
    makes a two-core figure look worse, so its miss is not trusted and its meet is."""
    slow, fast = [1.0, 1.1, 1.2, 1.05, 1.15, 1.0, 1.1, 1.2, 1.05], [1.9, 2.0, 1.95, 1.92, 1.97, 1.9, 2.0, 1.93, 1.96]
    floor = interleaved.PARALLEL_FLOOR
    assert Measurement.of(slow, gauges=[floor - 0.4] * 9).verdict(AT_LEAST) == "unsettled"
    assert Measurement.of(slow, gauges=[floor + 0.3] * 9).verdict(AT_LEAST) == "missed"
    assert Measurement.of(slow, gauges=[floor] * 9).verdict(AT_LEAST) == "missed"
    assert Measurement.of(fast, gauges=[floor - 0.4] * 9).verdict(AT_LEAST) == "met"
    assert Measurement.of(slow).gauge is None and Measurement.of(slow, gauges=[1.0, 3.0, 2.0]).gauge == 2.0


class Side:
    """A side of a round that a fake timer times: its name and the seconds its timings give."""

    def __init__(self, name, seconds):
        self.name, self.seconds = name, itertools.cycle(seconds)

    def __call__(self):
        raise AssertionError("a side is timed by the fake timer, never called")


class Fake:
    """A timer and a clock: each timing takes the side's next seconds (times its number of
    calls) on the clock, and is logged."""

    def __init__(self):
        self.now, self.log = 0.0, []

    def timer(self, side, number):
        seconds = next(side.seconds)
        self.now += seconds * number
        self.log.append(side.name)
        return seconds

    def clock(self):
        return self.now


def run(figures):
    fake = Fake()
    return interleaved.measure_all(figures, timer=fake.timer, clock=fake.clock), fake


def test_rounds_stop_at_the_minimum_when_far_from_the_bound():
    a, b = Side("a", [1e-3]), Side("b", [2e-3])
    (m,), _ = run([Figure([a, b], lambda ta, tb: ta / tb, target=Target(5.0, True), numbers=[1, 1])])
    assert (m.rounds, m.median, m.low, m.high) == (MIN_ROUNDS, 0.5, 0.5, 0.5)
    assert m.seconds == (1e-3, 2e-3) and m.verdict(Target(5.0, True)) == "met"


def test_rounds_straddling_the_bound_run_until_the_budget_and_stay_unsettled():
    """Ratios 4 and 6 in turn about a bound of 5 never settle. A round takes 0.05 s or 0.07 s
    of the fake clock (a side of 0.04 or 0.06 s, and one of 0.01 s): 8 pairs of rounds take
    0.96 s, the 17th round ends past the budget of 1 s."""
    a, b = Side("a", [0.04, 0.06]), Side("b", [0.01])
    (m,), _ = run([Figure([a, b], lambda ta, tb: ta / tb, target=Target(5.0, True), numbers=[1, 1], budget=1.0)])
    assert m.rounds == 17 and (m.low, m.high) == pytest.approx((4.0, 6.0))
    assert m.verdict(Target(5.0, True)) == "unsettled"


def test_rounds_stop_at_the_most_and_a_figure_without_target_when_informative():
    a, b = Side("a", [0.04, 0.06]), Side("b", [0.01])
    (m,), _ = run([Figure([a, b], lambda ta, tb: ta / tb, target=Target(5.0, True), numbers=[1, 1], budget=1e9,
                          max_rounds=30)])
    assert m.rounds == 30
    # Without a target: 4 and 6 are 40 % of the median apart, more than INFORMATIVE: the budget.
    (m,), _ = run([Figure([a, b], lambda ta, tb: ta / tb, numbers=[1, 1], budget=1.0)])
    assert m.rounds == 17
    # Within INFORMATIVE (5 %) of the median: the minimum.
    c = Side("c", [0.040, 0.041])
    (m,), _ = run([Figure([c, b], lambda ta, tb: ta / tb, numbers=[1, 1], budget=1e9)])
    assert m.rounds == MIN_ROUNDS


def test_sides_alternate_their_order_and_figures_take_turns():
    a, b = Side("a", [1e-3]), Side("b", [2e-3])
    c, d = Side("c", [0.04, 0.06]), Side("d", [0.01])
    first = Figure([a, b], lambda ta, tb: ta / tb, target=Target(5.0, True), numbers=[1, 1])
    second = Figure([c, d], lambda tc, td: tc / td, target=Target(5.0, True), numbers=[1, 1], budget=1.0)
    (m1, m2), fake = run([first, second])
    assert fake.log[:8] == ["a", "b", "c", "d", "b", "a", "d", "c"]
    # The first figure settles after its ninth round; the second goes on alone to its budget.
    assert m1.rounds == MIN_ROUNDS and m2.rounds == 17
    assert fake.log[4 * MIN_ROUNDS:4 * MIN_ROUNDS + 4] == ["d", "c", "c", "d"]


def test_a_gauge_and_a_side_that_times_itself():
    a, b = Side("a", [3e-3]), Side("b", [1e-3])
    itself = SelfTimed(lambda: 2e-3)
    (m,), fake = run([Figure([a, itself, b], lambda ta, ts, tb: ta / tb, gauge=lambda ta, ts, tb: ts / tb,
                             numbers=[1, None, 1])])
    assert m.median == pytest.approx(3.0) and m.gauge == pytest.approx(2.0)
    assert m.seconds == pytest.approx((3e-3, 2e-3, 1e-3)) and "itself" not in fake.log


def test_the_gauge_is_the_yardsticks_speedup_on_two_threads():
    """Two threads each run CALLS_EACH calls: with both cores free they take as long as that
    many calls on one thread, a speed-up of 2; taking turns on one core, twice as long."""
    one, each = 1.3e-4, interleaved.Yardstick.CALLS_EACH
    assert interleaved.parallel_gauge(one, each * one) == pytest.approx(2.0, rel=1e-15)
    assert interleaved.parallel_gauge(one, 2 * each * one) == pytest.approx(1.0, rel=1e-15)


def test_the_yardstick_runs_a_fixed_workload():
    """One call: PASSES passes of b = sqrt(a); b = a / b; b = b a; b = b + a over its arrays,
    which leave b = a^(3/2) + a (numpy directly on the same a); two threads each run a call
    on arrays of their own."""
    for threads in (1, 2):
        stick = interleaved.Yardstick(threads)
        stick()
        for a, b in stick.arrays:
            np.testing.assert_allclose(b, a**1.5 + a, rtol=1e-15, atol=0)  # reached 2.8e-16 (numpy 2.4.6)
    with pytest.raises(ValueError):
        interleaved.Yardstick(3)
