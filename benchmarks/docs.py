"""Rewrite the documentation's measured figures from the commands that measure them
(``make docs``, before it builds the site), so that none is copied by hand.

Each generated block sits between ``<!-- BEGIN name ... -->`` and ``<!-- END name -->``
in its page of ``docs/`` (:data:`PAGES`) and starts with the date, the machine and the
command that produced it:

``validate`` (``docs/checks.md``)
    the report of ``stewart validate`` for both presets (what ``make validate`` prints),
    as one table;
``checks`` (``docs/checks.md``)
    the table of figures that ``make test`` prints at the end of its pytest run
    (``tests/conftest.py``), verbatim (from a run now, or from ``--pytest-output``, the
    saved output of one);
``mujoco`` (``docs/mujoco.md``)
    how closely the MuJoCo export reproduces the model
    (:func:`benchmarks.peers.mujoco_model.export_figures`; needs MuJoCo);
``performance`` (``docs/performance.md``)
    our own rows of the last ``make bench`` run, read from its JSON figures
    (``out/benchmarks.json``), each target met, missed or unsettled;
``exactness`` (``docs/exactness.md``)
    what ``stewart exactness`` measures for both presets (the legs' spin), as one table;
``arms`` (``docs/rotary.md``)
    the output of ``stewart workspace --preset simrig100 --arms`` at the rig's home height and
    at :data:`ARMS_HEIGHT`, with their figures (``docs/images/arms_*.png``).

Everything apart from the measured numbers, the date and the machine is deterministic.
``python -m benchmarks.docs validate checks`` rewrites only those blocks.
"""

from __future__ import annotations

import argparse
import datetime
import json
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
BENCH_JSON = ROOT / "out" / "benchmarks.json"
SECTIONS = ("validate", "checks", "mujoco", "performance", "exactness", "arms")
#: The page of ``docs/`` that holds each generated block.
PAGES = {"validate": "checks.md", "checks": "checks.md", "mujoco": "mujoco.md",
         "performance": "performance.md", "exactness": "exactness.md", "arms": "rotary.md"}
#: The platform height [m] of simrig100 at which the arms study shows a preview's swing.
ARMS_HEIGHT = 0.483
#: The presets ``make validate`` reports on, in its order.
VALIDATE_PRESETS = ("narayan2017", "motion_simulator")
#: The preset whose kernel rows the performance page's table shows (all presets count
#: in its line of targets met, missed and unsettled).
PERFORMANCE_PRESET = "narayan2017"
_SUMMARY = "figures reached (worst case per check)"


def today() -> str:
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")


def machine_line(machine: dict) -> str:
    """``2-core AMD EPYC, Linux x86_64, Python 3.11.7, cc (Debian 12.2.0...) 12.2.0`` from
    a bench run's machine record (:func:`benchmarks.report.machine`)."""
    arch = machine["platform"].split("-with-")[0].rsplit("-", 1)[-1]
    line = (f"{machine['cpus']}-core {machine['processor']}, {machine['platform'].split('-')[0]} {arch}, "
            f"Python {machine['python']}, numpy {machine['numpy']}, {machine['compiler']}, "
            f"-march={machine['march']}")
    load = machine.get("load_average")
    return line if load is None else f"{line}, load average {load:.1f} at the start"


def where() -> str:
    """Today's date and this machine, for the blocks whose figures do not depend on its load."""
    from .report import machine

    return f"{today()}, {machine_line({**machine(), 'load_average': None})}"


def validate_block() -> str:
    """The ``stewart validate`` checks of both presets as one Markdown table."""
    from stewart import PlatformParams
    from stewart.oracles import validation

    reports = {name: validation.run(PlatformParams.preset(name)) for name in VALIDATE_PRESETS}
    names = [c.name for c in reports[VALIDATE_PRESETS[0]]]
    lines = [f"Sample output of `make validate` (`stewart validate --preset NAME`, 200 random states, seed 0), "
             f"{where()}:", "",
             "| check | " + " | ".join(VALIDATE_PRESETS) + " | bound | result |",
             "|---|" + "---|" * (len(VALIDATE_PRESETS) + 2)]
    for k, name in enumerate(names):
        checks = [reports[p][k] for p in VALIDATE_PRESETS]
        assert all(c.name == name for c in checks), "stewart validate runs the same checks for every preset"
        verdict = "ok" if all(c.passed for c in checks) else "FAIL"
        lines.append(f"| {_cell(name)} | " + " | ".join(f"{c.worst:.1e}" for c in checks)
                     + f" | {checks[0].bound:.0e} | {verdict} |")
    return "\n".join(lines)


def mujoco_block() -> str:
    """The MuJoCo export's agreement with the model as one Markdown table."""
    import mujoco

    from .peers.mujoco_model import export_figures

    states = 20
    fig = export_figures(states=states)
    duration = next(iter(fig.values()))["duration_s"]
    lines = [f"`python -m benchmarks.docs mujoco` ({states} random states, seed 0; MuJoCo {mujoco.__version__}), "
             f"{where()}:", "",
             f"| MuJoCo against | ẍ rigid | ẍ soft (tight) | replay {duration:g} s: position | angle | ball-joint gap |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {_cell(label)} | {f['rigid']:.1e} | {f['soft']:.1e} | {f['position_m']:.1e} m | "
              f"{f['angle_rad']:.1e} rad | {f['gap_m']:.1e} m |" for label, f in fig.items()]
    return "\n".join(lines)


def exactness_block() -> str:
    """``stewart exactness`` for both presets as one Markdown table."""
    from stewart import PlatformParams
    from stewart.oracles import exactness

    effects = {name: exactness.leg_spin_effect(PlatformParams.preset(name)) for name in VALIDATE_PRESETS}
    states = effects[VALIDATE_PRESETS[0]].states
    lines = [f"Sample output of `stewart exactness --preset NAME` ({states} random states around home, seed 0; "
             f"first joint axes horizontal and tangential to the base circle), {where()}:", "",
             "| relative change of the actuator forces | " + " | ".join(
                 f"{name} median | {name} max" for name in VALIDATE_PRESETS) + " |",
             "|---|" + "---|---|" * len(VALIDATE_PRESETS)]
    for label, part in (("dynamic forces (all but gravity)", "dynamic"), ("velocity-dependent forces", "velocity")):
        cells = [f"{getattr(effects[n], part).median:.1e} | {getattr(effects[n], part).max:.1e}"
                 for n in VALIDATE_PRESETS]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def arms_block() -> str:
    """``stewart workspace --preset simrig100 --arms`` at the home height and at
    :data:`ARMS_HEIGHT`, verbatim, the figures written into docs/images."""
    import contextlib
    import io

    from stewart.cli import main as stewart_main

    parts = [f"Output of the commands below, {where()}:", ""]
    for extra, folder in (([], "home"), (["--arms-height", str(ARMS_HEIGHT)], "height")):
        argv = ["workspace", "--preset", "simrig100", "--arms", "--resolution", "121", *extra]
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            stewart_main(argv + ["--slices", str(DOCS / "images" / f"arms_{folder}")])
        printed = [line for line in out.getvalue().splitlines() if not line.startswith("written:")]
        parts += ["```text", "$ stewart " + " ".join(argv), *printed, "```", ""]
    return "\n".join(parts)


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def checks_block(pytest_output: str | None = None) -> str:
    """The figures table that ``make test`` prints, from a pytest run now (the same
    selection: every test but the peer comparisons of ``make test-peers``), or from the
    output of a passing run (``make test``'s) when given."""
    if pytest_output is None:
        run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-m", "not peers"],
                             cwd=ROOT, capture_output=True, text=True)
        if run.returncode != 0:
            raise SystemExit(f"pytest failed (exit {run.returncode}); the documentation keeps its figures\n"
                             f"{run.stdout[-3000:]}")
        pytest_output = run.stdout
    table = summary_table(pytest_output)
    return "\n".join([f"Sample of the table `make test` prints, {where()} "
                      "(without the optional peers):", "",
                      f"<details><summary>the worst figure each check reached, and its bound ({len(table)} rows)</summary>", "",
                      "```text", *table, "```", "", "</details>"])


def summary_table(pytest_output: str) -> list[str]:
    """The lines of the figures section of a pytest run's terminal output."""
    lines = pytest_output.splitlines()
    start = next((k for k, line in enumerate(lines) if _SUMMARY in line), None)
    if start is None:
        raise SystemExit("pytest printed no figures table")
    table = []
    for line in lines[start + 1:]:
        if not re.search(r"\(bound [^)]*\)\s*$", line):  # a row ends with its bound
            break
        table.append(line.rstrip())
    return table


def performance_block(path: pathlib.Path) -> str:
    """Our rows of a ``make bench`` run (its JSON figures) as a Markdown table, and the count
    of its targets met, missed and unsettled over every table."""
    from stewart.cli.bench import count_verdicts

    from .report import our_rows

    results = json.loads(path.read_text())
    if "date" not in results or "machine" not in results:
        raise SystemExit(f"{path}: no date or machine; rerun make bench")
    from . import batch_loop, calibration, cueing, identification, studies

    rows = our_rows(results)
    # The studies (envelopes in process and on Dask), the identification, the calibration and MPC cueing.
    rows += [row for name, module in (("studies", studies), ("identification", identification),
                                      ("calibration", calibration), ("cueing", cueing))
             if name in results for row in module.rows(results[name])]
    prefix = f"[{PERFORMANCE_PRESET}] "
    shown = [(m[len(prefix):], *rest) for m, *rest in rows if m.startswith(prefix)]
    shown += [r for r in rows if not r[0].startswith("[") and (
        not r[0].startswith("operations:") or r[0].endswith(("inverse_dynamics_axisym", "forward_dynamics_axisym")))]
    every = rows + (batch_loop.rows(results["batch_loop"]) if "batch_loop" in results else [])
    lines = [f"Sample output of `make bench` ({PERFORMANCE_PRESET} rows), {results['date']}, "
             f"{machine_line(results['machine'])}; a machine shared with other jobs. Absolute figures are at "
             "the reference machine's speed (measured against the yardstick); the interval is the 90 % "
             "confidence interval of the median over the rounds counted beside it:", "",
             f"| measure ({PERFORMANCE_PRESET}) | median | 90% interval (rounds) | target | verdict |",
             "|---|---|---|---|---|"]
    lines += [f"| {' | '.join(_cell(c) for c in row)} |" for row in shown]
    lines += ["", f"Over every table of that run (every preset, the batch loop): {count_verdicts(every)}."]
    return "\n".join(lines)


def replace_block(text: str, name: str, body: str, page: str = "the page") -> str:
    """``text`` with the block ``name`` replaced by ``body``; the markers must be there."""
    pattern = re.compile(rf"(<!-- BEGIN {name}\b[^>]*-->\n)(.*?)(<!-- END {name} -->)", re.S)
    if not pattern.search(text):
        raise SystemExit(f"{page} has no <!-- BEGIN {name} --> ... <!-- END {name} --> block")
    return pattern.sub(lambda m: m.group(1) + body.rstrip() + "\n" + m.group(3), text, count=1)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.docs", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sections", nargs="*", metavar="SECTION",
                        help=f"blocks to rewrite: {', '.join(SECTIONS)} (default: all; performance only when "
                             f"the bench figures exist)")
    parser.add_argument("--bench-json", type=pathlib.Path, default=BENCH_JSON,
                        help="figures of a make bench run (default out/benchmarks.json)")
    parser.add_argument("--pytest-output", type=pathlib.Path, metavar="FILE",
                        help="the checks block from this saved output of a passing make test instead of a "
                             "pytest run now")
    args = parser.parse_args(argv)
    unknown = sorted(set(args.sections) - set(SECTIONS))
    if unknown:
        parser.error(f"SECTION: unknown {unknown}; choose from {list(SECTIONS)}")
    sections = args.sections or [s for s in SECTIONS if s != "performance" or args.bench_json.exists()]
    if "performance" in sections and not args.bench_json.exists():
        parser.error(f"--bench-json: {args.bench_json} does not exist; run make bench first")
    for name in sections:  # in order, each written at once: the test run reads the validate block
        print(f"[docs] {name} ...", flush=True)
        body = {"validate": validate_block, "mujoco": mujoco_block,
                "checks": lambda: checks_block(args.pytest_output and args.pytest_output.read_text()),
                "exactness": exactness_block, "arms": arms_block,
                "performance": lambda: performance_block(args.bench_json)}[name]()
        page = DOCS / PAGES[name]
        page.write_text(replace_block(page.read_text(), name, body, str(page)))
    print(f"rewrote {', '.join(f'{name} ({PAGES[name]})' for name in sections)} in {DOCS}")


if __name__ == "__main__":
    main()
