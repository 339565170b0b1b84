"""The commands and examples of the README and of the documentation's pages run as written.

The pages are those of ``mkdocs.yml``'s ``nav``, read in its order after the README, as one
session:

* Every ``stewart ...`` line of their ``sh`` blocks runs through :func:`stewart.cli.main`, in
  order, in one temporary directory holding a copy of ``examples/`` (so a command may read
  what an earlier one wrote, as in a shell session), and exits with 0, or with the
  code its comment names ("exit code 3"). ``stewart bench`` runs with ``--batch 2000
  --preset narayan2017`` added (the full run takes minutes; every preset runs the same
  code); its JSON and its table are checked here, the one run of the command in the suite. The numbers that ``ik``, ``id`` and ``fd`` print or write
  are compared with the Python API.
* Their ``python`` blocks run in order in one namespace (a page's examples continue the
  README's tour). A statement followed by a comment ``# SomeError: message`` must raise that
  error with that message (``...`` matches anything).
* The generated sample of ``stewart validate`` lists the checks that command runs today.
"""

from __future__ import annotations

import ast
import json
import pathlib
import re
import shlex
import shutil

import numpy as np
import pytest

import stewart
from stewart import cli

ROOT = pathlib.Path(__file__).resolve().parent.parent
if not (ROOT / "examples").is_dir() or not (ROOT / "mkdocs.yml").is_file():
    pytest.skip("needs the checkout (README.md, mkdocs.yml, docs/ and examples/)", allow_module_level=True)


def nav_pages() -> list[str]:
    """The pages of ``mkdocs.yml``'s ``nav`` (``- Title: page.md``), in its order, as paths."""
    nav = (ROOT / "mkdocs.yml").read_text().split("\nnav:", 1)[1]
    return [f"docs/{name}" for name in re.findall(r"^\s*- [^\n]*?:\s*(\S+\.md)\s*$", nav, re.M)]


#: The files whose commands and examples run, in order: the README, then the site's pages.
PAGES = ["README.md", *nav_pages()]
TEXTS = {name: (ROOT / name).read_text() for name in PAGES}


def blocks(language: str, pages=PAGES) -> list[tuple[str, str]]:
    """(page, block) of every ``language`` block of ``pages``, in order."""
    return [(page, block) for page in pages
            for block in re.findall(rf"^```{language}\n(.*?)^```", TEXTS[page], re.S | re.M)]


def commands() -> list[tuple[str, list[str], int]]:
    """(line, argv after ``stewart``, expected exit code) of every command of the pages."""
    out = []
    for _, block in blocks("sh"):
        for line in block.splitlines():
            words = shlex.split(line, comments=True)
            if words[:1] == ["stewart"]:
                argv = words[1:]
            elif words[:3] == ["python", "-m", "stewart"]:
                argv = words[3:]
            else:
                continue
            code = re.search(r"#.*\bexit (?:code|status) (\d+)", line)
            out.append((line.strip(), argv, int(code.group(1)) if code else 0))
    return out


COMMANDS = commands()


@pytest.fixture(scope="module")
def session_dir(tmp_path_factory):
    directory = tmp_path_factory.mktemp("readme-session")
    shutil.copytree(ROOT / "examples", directory / "examples")
    return directory


@pytest.fixture
def in_examples_dir(session_dir, monkeypatch):
    monkeypatch.chdir(session_dir)
    return session_dir


def run_cli(argv) -> int:
    try:
        code = cli.main(list(argv))
    except SystemExit as stop:
        code = stop.code
    return 0 if code is None else code if isinstance(code, int) else 1


def option(argv, flag, n=1):
    """The value(s) given to ``flag``, or None."""
    if flag not in argv:
        return None
    k = argv.index(flag)
    return argv[k + 1] if n == 1 else [float(v) for v in argv[k + 1:k + 1 + n]]


def numeric_rows(text: str) -> np.ndarray:
    """The printed lines made of numbers only, as rows."""
    rows = []
    for line in text.splitlines():
        try:
            rows.append([float(v) for v in line.split()])
        except ValueError:
            continue
    return np.array([r for r in rows if r])


def expected_numbers(argv) -> np.ndarray | None:
    """What the Python API gives for an ``ik``, ``id`` or ``fd`` command line."""
    command = argv[0]
    if command not in ("ik", "id", "fd"):
        return None
    plat = stewart.Platform.load(option(argv, "--params")) if option(argv, "--params") else \
        stewart.Platform.preset(option(argv, "--preset") or "narayan2017")
    if option(argv, "--input"):
        data = np.loadtxt(option(argv, "--input"), delimiter=",", comments="#", ndmin=2)
    else:
        extra = {"ik": [], "id": ["--vel", "--acc"], "fd": ["--vel", "--force"]}[command]
        data = np.atleast_2d(np.concatenate([option(argv, f, 6) for f in ["--pose", *extra]]))
    if command == "ik":  # the encoder readings: leg lengths less the offsets
        return plat.leg_lengths(data) - plat.params.leg_length_offsets
    if command == "id":
        return plat.inverse_dynamics(data[:, :6], data[:, 6:12], data[:, 12:])
    return plat.forward_dynamics(data[:, :6], data[:, 6:12], data[:, 12:])


def test_every_page_of_the_docs_is_in_the_nav():
    pages = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").rglob("*.md"))
    assert pages == sorted(PAGES[1:]), "a page missing from mkdocs.yml's nav would escape these tests"


def test_the_readme_shows_commands_on_the_shipped_examples():
    used = " ".join(line for line, _, _ in COMMANDS)
    for name in ("examples/platform.toml", "examples/states.csv", "examples/trajectory.csv"):
        assert name in used
        assert (ROOT / name).is_file()
    for command in ("ik", "id", "fd", "simulate", "validate"):
        assert any(argv[:1] == [command] for _, argv, _ in COMMANDS)


@pytest.mark.slow
@pytest.mark.parametrize("line, argv, code", COMMANDS, ids=[line for line, _, _ in COMMANDS])
def test_readme_command_runs(line, argv, code, in_examples_dir, capsys):
    if argv[:1] == ["bench"]:
        argv = [*argv, "--batch", "2000", "--preset", "narayan2017"]
    assert run_cli(argv) == code, capsys.readouterr()
    out, err = capsys.readouterr()
    if argv[:1] == ["bench"]:
        check_bench(argv, out, err)
    expected = expected_numbers(argv)
    if expected is not None:
        written = option(argv, "--csv")
        got = np.loadtxt(written, delimiter=",", skiprows=1, ndmin=2) if written else numeric_rows(out)
        np.testing.assert_allclose(got, expected, rtol=1e-8, atol=1e-9)
    if option(argv, "--plot"):
        assert len(list(pathlib.Path(option(argv, "--plot")).glob("*.png"))) >= 4
        if argv[0] == "simulate":  # its four figures (tests/test_cli.py leaves --plot to this run)
            for name in ("pose", "error", "forces", "leg_velocities"):
                assert (pathlib.Path(option(argv, "--plot")) / f"simulation_{name}.png").stat().st_size > 10_000


def check_bench(argv, out: str, err: str) -> None:
    """``stewart bench --json``: stdout holds only the JSON, with the figures of every preset
    measured (or of ``--preset``'s), and the table on stderr shows the same measurements."""
    assert "--json" in argv
    figures = json.loads(out)["figures"]
    assert sorted(figures) == ([option(argv, "--preset")] if option(argv, "--preset") else sorted(stewart.presets()))
    for preset, values in figures.items():
        line = next(row for row in err.splitlines() if f"[{preset}] inverse dynamics, C batch loop" in row)
        per_state = float(line.split("us/state")[0].split()[-1])
        assert 0 < per_state < 100  # microseconds per state, a real measurement
        assert per_state == pytest.approx(values["batch_inverse_dynamics_us"], rel=1e-3, abs=1e-3)
        assert f"[{preset}] 5 s move, RK4 at 1 kHz with PID" in err


_RAISES = re.compile(r"#\s*((?:\w+\.)*\w+(?:Error|Exception)):\s*(.*?)\s*$")


def run_python(source: str, namespace: dict, page: str = "README.md") -> int:
    """Run ``source`` statement by statement; returns how many raised as their comment says."""
    lines = source.splitlines()
    raised = 0
    for node in ast.parse(source).body:
        code = compile(ast.Module([node], type_ignores=[]), page, "exec")
        following = lines[node.end_lineno].strip() if node.end_lineno < len(lines) else ""
        expected = _RAISES.match(following)
        if not expected:
            exec(code, namespace)
            continue
        with pytest.raises(Exception) as info:
            exec(code, namespace)
        name, message = expected.groups()
        assert type(info.value).__name__ == name.split(".")[-1], info.value
        pattern = ".*".join(re.escape(part) for part in message.split("..."))
        assert re.fullmatch(pattern, str(info.value)), f"{page} says {message!r}, got {str(info.value)!r}"
        raised += 1
    return raised


@pytest.mark.slow
def test_the_python_tour_runs(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    shutil.copytree(ROOT / "examples", tmp_path / "examples")   # the files the pages' examples read
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    raised = sum(run_python(block, namespace, page) for page, block in blocks("python"))
    assert raised >= 2  # the error messages the tour shows are the ones raised
    assert isinstance(namespace["run"], stewart.SimulationResult)
    assert (tmp_path / "run.csv").is_file() and any((tmp_path / "figures").glob("*.png"))


def test_the_validate_sample_lists_the_checks_stewart_validate_runs():
    from stewart.oracles import validation

    sample = re.search(r"<!-- BEGIN validate\b.*?-->\n(.*?)<!-- END validate -->", TEXTS["docs/checks.md"], re.S)
    assert sample, "docs/checks.md has the generated block of make validate"
    rows = [line.split(" | ")[0].lstrip("| ").replace("\\|", "|") for line in sample.group(1).splitlines()
            if line.startswith("| ") and not line.startswith("| check")]
    checks = validation.run(stewart.PlatformParams.preset("narayan2017"), n_states=5)
    assert rows == [c.name for c in checks]
