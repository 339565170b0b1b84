"""generated/ is exactly what the generator writes now (same sources, same bytes)."""

import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def test_generated_code_is_fresh_and_deterministic(tmp_path):
    for run in ("a", "b"):
        subprocess.run(
            [sys.executable, "-m", "codegen", "--out", str(tmp_path / run)],
            cwd=ROOT, check=True, capture_output=True, text=True,
        )
    for name in ("stewart_model.h", "stewart_model.c"):
        first = (tmp_path / "a" / name).read_bytes()
        assert first == (tmp_path / "b" / name).read_bytes(), f"{name}: two runs differ"
        assert first == (ROOT / "generated" / name).read_bytes(), (
            f"generated/{name} is stale: run `make generate` and commit the result"
        )
