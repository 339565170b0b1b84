"""stewart.io.csvfile.read: numpy's C reader on well-formed files and the line-by-line reader
on the rest give the numbers Python's float() reads from the text, in the columns asked for."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from stewart.io import csvfile

COLUMNS = ["t", "a", "b"]


def _by_hand(text: str, columns: list[str]) -> np.ndarray:
    """The table by float() of each field of each non-blank, non-comment line, the columns picked
    by a header's names where it names them all."""
    rows, pick = [], None
    for line in text.splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        fields = [f.strip() for f in line.split(",")]
        try:
            float(fields[0])
        except ValueError:
            names = [f.lower() for f in fields]
            pick = [names.index(c) for c in columns] if all(c in names for c in columns) else None
            continue
        values = [float(f) for f in fields]
        rows.append(values if pick is None else [values[i] for i in pick])
    return np.array(rows)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(values=st.lists(st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64), min_size=4, max_size=4),
                       min_size=1, max_size=30),
       header=st.sampled_from([None, "t,a,b,c", "c,b,T,a", "B,c,a,t"]),
       comment=st.booleans(), newline=st.sampled_from(["\n", "\r\n"]), blank=st.sampled_from(["", "   "]),
       fmt=st.sampled_from(["{!r}", "{:.6g}", " {:.17g} "]))
def test_read_gives_the_numbers_of_the_text(tmp_path_factory, values, header, comment, newline, blank, fmt):
    lines = ([header] if header else []) + (["# platform test"] if comment else [])
    lines += [",".join(fmt.format(v) for v in row) for row in values]
    if blank and len(lines) > 2:
        lines.insert(2, blank)
    text = newline.join(lines) + newline
    path = tmp_path_factory.mktemp("csv") / "in.csv"
    path.write_bytes(text.encode())
    columns = COLUMNS if header else ["t", "a", "b", "c"]
    got = csvfile.read(path, columns)
    expected = _by_hand(text, columns)
    assert got.shape == expected.shape and got.dtype == float
    assert np.array_equal(got, expected)  # the same bits


@pytest.mark.parametrize("text, where", [
    ("t,a,b\n0,1,2 # note\n", "line 2, column 3: '2 # note' is not a number"),
    ("t,a,b\n0,1,2\n1,2,inf\n", "line 3, column 3: 'inf' is not a finite number"),
    ("t,a,b\n0,1,2\n1,2\n", "line 3: 2 column(s) where earlier lines have 3"),
    ("t,a,b\n0,1,2\n1,,2\n", "line 3, column 2: '' is not a number"),
])
def test_files_the_fast_reader_leaves_are_explained(tmp_path, text, where):
    path = tmp_path / "in.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match="^" + str(path).replace("\\", "\\\\") + ": ") as info:
        csvfile.read(path, COLUMNS)
    assert where in str(info.value)


def test_a_long_file_reads_as_written(tmp_path):
    rng = np.random.default_rng(3)
    data = np.column_stack([np.arange(5000) / 60.0, rng.normal(size=(5000, 2)) * 10.0 ** rng.integers(-8, 8, (5000, 2))])
    csvfile.write(tmp_path / "long.csv", COLUMNS, data, "platform test", fmt="%.17g")
    assert np.array_equal(csvfile.read(tmp_path / "long.csv", ["b", "t"]), data[:, [2, 0]])
