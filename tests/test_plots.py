"""Figures of a run: titles name the platform and the controller."""

from types import SimpleNamespace

import pytest

pytest.importorskip("matplotlib")
from stewart.io.plots import run_title  # noqa: E402


@pytest.mark.parametrize("metadata, title", [
    ({"platform": "narayan2017", "controller": "PID", "dt": 1e-3}, "narayan2017, PID"),
    ({"platform": "lab hexapod", "controller": "computed torque"}, "lab hexapod, computed torque"),
    ({"controller": "PID"}, "PID"),
    ({}, ""),
])
def test_titles_come_from_the_run_metadata(metadata, title):
    assert run_title(SimpleNamespace(metadata=metadata)) == title
