"""One answer per state: on every instruction-set path this CPU runs, a state's results are the
same bit for bit whether it is computed alone, in a batch of any size at any position, or with
any number of threads, and every path gives the same bits as the one that runs everywhere
(the model's rounding, codegen/templates/lanes.c)."""

import numpy as np
import pytest
from simd_paths import ROWS, batch, calls

import stewart

INFO = stewart.build_info()


def _parts(result):
    """The output arrays of a call's result (one array, or a named tuple of them)."""
    return [result] if isinstance(result, np.ndarray) else list(result)


def _results(plat, inputs):
    """{function: (its output arrays, its mask)} of every public function on the batch."""
    return {name: (_parts(out), mask) for name, (out, mask) in
            ((name, call(True)) for name, call in calls(plat, *inputs).items())}


@pytest.fixture(scope="module")
def inputs():
    return batch(stewart.PlatformParams.preset("narayan2017"))


@pytest.fixture(scope="module")
def everywhere(inputs):
    """The results of the path that runs everywhere."""
    previous = stewart.set_simd(INFO["supported"][0])
    try:
        return _results(stewart.Platform.preset("narayan2017"), inputs)
    finally:
        stewart.set_simd(previous)


def _same(got, want, what):
    """Bit for bit: the same float64 bytes (NaN rows included)."""
    assert got.shape == want.shape, what
    assert got.tobytes() == want.tobytes(), f"{what}: {np.sum(got != want)} entries differ"


def test_every_path_gives_the_bits_of_the_baseline(simd_path, inputs, everywhere):
    results = _results(stewart.Platform.preset("narayan2017"), inputs)
    assert stewart.build_info()["simd"] == simd_path
    for name, (parts, mask) in everywhere.items():
        got, got_mask = results[name]
        np.testing.assert_array_equal(got_mask, mask)
        for k, (a, b) in enumerate(zip(got, parts)):
            _same(a, b, f"{simd_path} {name}[{k}]")


def test_a_state_alone_equals_its_row_in_the_batch(simd_path, inputs, everywhere):
    """Each function's single call on every row (singular rows give the NaN of the batch's row)."""
    plat = stewart.Platform.preset("narayan2017")
    x, xd, xdd, tau = inputs
    rows = range(0, ROWS, 7)
    for name, (parts, mask) in everywhere.items():
        for r in rows:
            row = (x[r], xd[r], xdd[r], tau[r])
            out, ok = calls(plat, *row)[name](True)
            assert bool(ok) == bool(mask[r]), (name, r)
            for k, (a, b) in enumerate(zip(_parts(out), parts)):
                _same(np.asarray(a), b[r], f"{simd_path} {name}[{k}] row {r}")


@pytest.mark.parametrize("start, size", [(0, 1), (3, 2), (5, 3), (1, 5), (9, 7), (2, 9), (11, 17), (100, 903)])
def test_any_slice_of_the_batch_gives_the_same_rows(simd_path, inputs, everywhere, start, size):
    """A batch of any size at any offset: its rows in other blocks and lanes."""
    plat = stewart.Platform.preset("narayan2017")
    part = tuple(a[start:start + size] for a in inputs)
    for name, (out, mask) in ((n, c(True)) for n, c in calls(plat, *part).items()):
        want_parts, want_mask = everywhere[name]
        np.testing.assert_array_equal(mask, want_mask[start:start + size])
        for k, (a, b) in enumerate(zip(_parts(out), want_parts)):
            _same(a, b[start:start + size], f"{simd_path} {name}[{k}] rows {start}:{start + size}")


@pytest.mark.parametrize("threads", [2, 3])
def test_threads_give_the_same_rows(simd_path, inputs, everywhere, threads):
    plat = stewart.Platform.preset("narayan2017", threads=threads)
    for name, (parts, mask) in _results(plat, inputs).items():
        want_parts, want_mask = everywhere[name]
        np.testing.assert_array_equal(mask, want_mask)
        for k, (a, b) in enumerate(zip(parts, want_parts)):
            _same(a, b, f"{simd_path} {name}[{k}] on {threads} threads")


def test_set_simd_refuses_a_path_this_cpu_does_not_run():
    with pytest.raises(ValueError, match=r"path='sse1' names no path of this build; valid values: "):
        stewart.set_simd("sse1")
    with pytest.raises(TypeError, match="path must be a str or None, not int"):
        stewart.set_simd(2)
    before = stewart.build_info()["simd"]
    assert stewart.set_simd(None) == before
    assert stewart.build_info()["simd"] == stewart.build_info()["supported"][-1]
    stewart.set_simd(before)
