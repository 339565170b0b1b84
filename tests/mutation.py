"""make mutation: mutation testing of the application packages with cosmic-ray (issue 38).

For each package it copies the checkout (the sources, the compiled extensions, the tests and
what they read; not .venv, .git, build/ or out/) to ``out/mutation/<package>/work``, so that
cosmic-ray's in-place mutations never touch the checkout, lists every mutant there
(``cosmic-ray init``), sets aside the equivalent ones, draws a sample of the rest, runs the
package's fast topic tests on each sampled mutant (``cosmic-ray exec``, one mutant at a time,
pytest with ``-x -n 0``; the work copy first on ``PYTHONPATH``, for the interpreters the tests
start too) and writes ``out/mutation/report.md``: per package the mutants in all, the equivalent,
those sampled, killed, timed out, survived, the kill rate against the 90 % target, then each
surviving mutant with its file, line and change. Two packages run at a time (``--jobs``).

Equivalent mutants (they change nothing a user can see) are never sampled:
- a mutant inside an annotation, which ``from __future__ import annotations`` leaves a string;
- a mutant listed in the table under "Equivalent mutants" in ``docs/checks.md``, matched by
  file, operator and the mutated line's code (not its number, which edits elsewhere move), each
  with its one-line reason. An entry no mutant matches any more is reported as stale.

The sample is stable: each mutant's rank is a hash of the seed, its file, operator and line's
code, so killing a survivor keeps the rest of the sample, and calling one equivalent lets the
next in rank in. A mutant on a line marked ``# pragma: no mutate`` or in a file of ``EXCLUDED``
is never run and counts as a survivor. A timeout (the tests running past ``TIMEOUT_FACTOR``
times the unmutated run) counts as killed, and is reported apart. The run exits 1 when a
package misses the target.

    .venv/bin/python tests/mutation.py [--packages stiffness,reachability] [--sample 80] [--seed 38]
"""

from __future__ import annotations

import argparse
import ast
import concurrent.futures
import datetime
import glob
import hashlib
import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "out" / "mutation"

# package: (the files or folders mutated, the fast topic tests that run on each mutant)
PACKAGES = {
    "stiffness": (["stewart/model/stiffness.py"], ["tests/test_stiffness.py"]),
    "reachability": (["stewart/model/reachability.py"], ["tests/test_clearance.py", "tests/test_workspace.py"]),
    "control": (["stewart/motion/control.py"], ["tests/test_simulation.py"]),
    "cueing": (["stewart/cueing"], ["tests/test_cueing*.py", "tests/test_washout_limiter.py"]),
    "calibration": (["stewart/calibration"], ["tests/test_calibration.py"]),
    "identification": (["stewart/identification"],
                       ["tests/test_identify.py", "tests/test_excitation.py", "tests/test_base_parameters.py",
                        "tests/test_regressor.py"]),
    "studies": (["stewart/studies"],
                ["tests/test_sweep.py", "tests/test_workspace.py", "tests/test_stiffness_studies.py",
                 "tests/test_envelope.py", "tests/test_execution.py"]),
}
# Mutants run per package by default: about an hour in all on 2 cores, two packages at a time.
SAMPLE = {"stiffness": 100, "reachability": 100, "control": 60, "cueing": 60, "calibration": 60,
          "identification": 60, "studies": 60}
# Files of a package left out of the run: their mutants count as survivors.
EXCLUDED: dict[str, list[str]] = {}
COPIED = ["stewart", "tests", "generated", "examples", "docs", "benchmarks", "codegen",
          "pyproject.toml", "setup.py", "mkdocs.yml", "README.md", "CHANGELOG.md", "LICENSE", "MANIFEST.in"]
TIMEOUT_FACTOR = 3.0
PRAGMA = re.compile(r".*#.*pragma:.*no mutate.*")


CHECKS = ROOT / "docs" / "checks.md"
TARGET = 0.90


def equivalent_table(path: Path = CHECKS) -> dict[tuple[str, str, str], str]:
    """The mutants called equivalent in docs/checks.md: (file, operator, code) -> reason.

    The table under the heading "Equivalent mutants" has the columns file:line, operator,
    the mutated line's code (in backticks) and why the mutant changes nothing a user can see;
    a ``|`` inside a cell is written ``\\|``."""
    lines = path.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("#") and "Equivalent mutants" in line)
    table = {}
    for line in lines[start + 1:]:
        if line.startswith("#"):
            break
        if not line.startswith("| `"):
            continue
        cells = [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
        where, operator, source, reason = cells
        if not reason:
            raise SystemExit(f"mutation: {path.name}: no reason given for {where} {operator}")
        table[(where.strip("`").split(":")[0], "core/" + operator.strip("`"), source.strip("`"))] = reason
    return table


EQUIVALENT = equivalent_table()


def annotation_spans(text: str) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """The (start, end) positions of every annotation in a module: the arguments', the returns'
    and those of annotated assignments, which ``from __future__ import annotations`` never runs."""
    spans = []
    for node in ast.walk(ast.parse(text)):
        notes = []
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            args = node.args
            every = args.posonlyargs + args.args + args.kwonlyargs + [a for a in (args.vararg, args.kwarg) if a]
            notes = [a.annotation for a in every if a.annotation] + ([node.returns] if node.returns else [])
        elif isinstance(node, ast.AnnAssign):
            notes = [node.annotation]
        spans += [((n.lineno, n.col_offset), (n.end_lineno, n.end_col_offset)) for n in notes]
    return spans


def rank(item, source: str, seed: int) -> str:
    """A mutant's place in the sample: a hash of what it is, not of where it sits."""
    m = item.mutations[0]
    return hashlib.sha256(f"{seed}|{m.module_path}|{m.operator_name}|{source}|{m.start_pos[1]}".encode()).hexdigest()


def work_copy(directory: Path) -> None:
    if directory.exists():
        shutil.rmtree(directory)
    directory.mkdir(parents=True)
    ignore = shutil.ignore_patterns("__pycache__", ".hypothesis", ".pytest_cache")
    for name in COPIED:
        source = ROOT / name
        if source.is_dir():
            shutil.copytree(source, directory / name, ignore=ignore)
        elif source.exists():
            shutil.copy2(source, directory / name)
    if not list((directory / "stewart").glob("_kernel*.so")):
        sys.exit("mutation: no compiled stewart/_kernel*.so in the checkout: run make build first")


def test_command(work: Path, tests: list[str]) -> list[str]:
    files = sorted({f for pattern in tests for f in glob.glob(pattern, root_dir=work)})
    return ["env", f"PYTHONPATH={work}", sys.executable, "-m", "pytest", "-q", "-x", "-n", "0",
            "-p", "no:cacheprovider", *files]


def run_package(name: str, sample: int, seed: int) -> dict:
    from cosmic_ray.work_db import WorkDB, use_db
    from cosmic_ray.work_item import TestOutcome, WorkerOutcome, WorkResult

    paths, tests = PACKAGES[name]
    folder = OUT / name
    work = folder / "work"
    work_copy(work)
    command = test_command(work, tests)

    started = time.monotonic()
    baseline = subprocess.run(command, cwd=work, capture_output=True, text=True)
    baseline_s = time.monotonic() - started
    if baseline.returncode != 0:
        sys.exit(f"mutation: {name}'s tests fail unmutated:\n{baseline.stdout[-3000:]}")
    probe = subprocess.run(["env", f"PYTHONPATH={work}", sys.executable, "-c", "import stewart; print(stewart.__file__)"],
                           cwd=work, capture_output=True, text=True, check=True).stdout.strip()
    assert Path(probe).is_relative_to(work), f"the tests import {probe}, not the work copy"

    timeout = max(30.0, TIMEOUT_FACTOR * baseline_s)
    config = folder / "config.toml"
    config.write_text(
        "[cosmic-ray]\n"
        f"module-path = {json.dumps(paths)}\n"
        f"timeout = {timeout:.0f}\n"
        "excluded-modules = []\n"
        f"test-command = {json.dumps(' '.join(command))}\n\n"
        "[cosmic-ray.distributor]\n"
        'name = "local"\n'
    )
    session = folder / "session.sqlite"
    session.unlink(missing_ok=True)
    subprocess.run(["cosmic-ray", "init", str(config), str(session)], cwd=work, check=True,
                   executable=str(Path(sys.executable).parent / "cosmic-ray"))

    excluded = {str(Path(p)) for p in EXCLUDED.get(name, [])}
    sources: dict[str, list[str]] = {}
    annotated: dict[str, list[tuple]] = {}

    def code(mutation) -> str:
        path = str(mutation.module_path)
        if path not in sources:
            text = (work / path).read_text()
            sources[path] = text.splitlines()
            annotated[path] = annotation_spans(text)
        return sources[path][mutation.start_pos[0] - 1].strip()

    def not_run(item) -> str | None:
        mutation = item.mutations[0]
        if str(mutation.module_path) in excluded:
            return "excluded file"
        return "pragma: no mutate" if PRAGMA.match(code(mutation)) else None

    def equivalent(item) -> str | None:
        mutation = item.mutations[0]
        line = code(mutation)
        if any(start <= tuple(mutation.start_pos) and tuple(mutation.end_pos) <= end
               for start, end in annotated[str(mutation.module_path)]):
            return "annotation"
        key = (str(mutation.module_path), mutation.operator_name, line)
        if key in documented:
            used.add(key)
            return documented[key]
        return None

    documented = {k: v for k, v in EQUIVALENT.items() if k[0].startswith(tuple(paths))}
    used: set = set()
    with use_db(str(session), mode=WorkDB.Mode.open) as db:
        items = list(db.work_items)
        total = len(items)
        marked = sum(not_run(item) is not None for item in items)
        reasons = {item.job_id: equivalent(item) for item in items}
        candidates = [item for item in items if reasons[item.job_id] is None]
        chosen = sorted(candidates, key=lambda item: rank(item, code(item.mutations[0]), seed))[:sample]
        chosen.sort(key=lambda item: (str(item.mutations[0].module_path), item.mutations[0].start_pos,
                                      item.mutations[0].operator_name, item.mutations[0].occurrence))
        db.clear()
        db.add_work_items(chosen)
        for item in chosen:
            reason = not_run(item)
            if reason:
                db.set_result(item.job_id, WorkResult(worker_outcome=WorkerOutcome.SKIPPED, output=reason))
    annotations = sum(r == "annotation" for r in reasons.values())
    stale = sorted(f"{k[0]} {k[1]}: `{k[2]}`" for k in set(documented) - used)
    print(f"mutation: {name}: {total} mutants, {total - len(candidates)} equivalent, {len(chosen)} sampled "
          f"(seed {seed}), "
          f"timeout {timeout:.0f} s", flush=True)

    subprocess.run(["cosmic-ray", "exec", str(config), str(session)], cwd=work, check=True,
                   executable=str(Path(sys.executable).parent / "cosmic-ray"))

    counts = {"killed": 0, "timeout": 0, "survived": 0, "not run": 0, "incompetent": 0}
    survivors = []
    with use_db(str(session), mode=WorkDB.Mode.open) as db:
        items = {item.job_id: item for item in db.work_items}
        for job_id, result in db.results:
            mutation = items[job_id].mutations[0]
            where = f"{mutation.module_path}:{mutation.start_pos[0]}"
            if result.worker_outcome == WorkerOutcome.SKIPPED:
                counts["not run"] += 1
                survivors.append({"where": where, "operator": mutation.operator_name, "change": result.output})
            elif result.worker_outcome != WorkerOutcome.NORMAL or result.test_outcome == TestOutcome.INCOMPETENT:
                counts["incompetent"] += 1   # the mutation could not be run: counted as killed (the tests stop)
            elif result.test_outcome == TestOutcome.KILLED:
                counts["timeout" if result.output == "timeout" else "killed"] += 1
            else:
                counts["survived"] += 1
                survivors.append({"where": where, "operator": mutation.operator_name,
                                  "change": changed_lines(result.diff or "")})
    survivors.sort(key=lambda s: (s["where"].split(":")[0], int(s["where"].split(":")[1])))
    summary = {
        "package": name, "paths": paths, "tests": tests, "mutants": total, "marked": marked,
        "annotations": annotations, "documented": total - len(candidates) - annotations, "stale": stale,
        "sampled": len(chosen), "seed": seed, **counts, "survivors": survivors,
        "baseline_s": round(baseline_s, 1), "minutes": round((time.monotonic() - started) / 60, 1),
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
    }
    (folder / "summary.json").write_text(json.dumps(summary, indent=1))
    return summary


def changed_lines(diff: str) -> str:
    """The mutated line of a unified diff, `old -> new`."""
    old = [line[1:].strip() for line in diff.splitlines() if line.startswith("-") and not line.startswith("---")]
    new = [line[1:].strip() for line in diff.splitlines() if line.startswith("+") and not line.startswith("+++")]
    return f"`{' '.join(old)}` -> `{' '.join(new)}`"


def rate(s: dict) -> float:
    killed = s["killed"] + s["timeout"] + s["incompetent"]
    return killed / s["sampled"] if s["sampled"] else float("nan")


def report() -> Path:
    rows, details = [], []
    for name in PACKAGES:
        path = OUT / name / "summary.json"
        if not path.exists():
            continue
        s = json.loads(path.read_text())
        killed = s["killed"] + s["timeout"] + s["incompetent"]
        verdict = "met" if rate(s) >= TARGET else "missed"
        rows.append(f"| {name} | {s['mutants']} | {s['annotations']} + {s['documented']} | {s['marked']} "
                    f"| {s['sampled']} | {s['killed']} | {s['timeout']} | {s['incompetent']} "
                    f"| {s['survived'] + s['not run']} | {killed}/{s['sampled']} = {rate(s):.0%} {verdict} "
                    f"| {s['minutes']} | {s['date']} |")
        details.append(f"\n## {name}: {len(s['survivors'])} surviving\n\n"
                       f"Mutated: {', '.join(s['paths'])}; tests: {' '.join(s['tests'])}; seed {s['seed']}.\n")
        details.extend(f"- `{v['where']}` {v['operator']}: {v['change']}" for v in s["survivors"])
        details.extend(f"- stale entry in docs/checks.md (no mutant matches it): {v}" for v in s["stale"])
    text = ("# Mutation testing (make mutation, cosmic-ray)\n\n"
            "Equivalent: mutants inside annotations + those docs/checks.md calls equivalent, never sampled. "
            "Killed counts timeouts and mutants the tests could not run (incompetent); survived counts the "
            "mutants on `# pragma: no mutate` lines and in excluded files (marked), which are never run. "
            f"Target: {TARGET:.0%} of the sampled mutants killed.\n\n"
            "| package | mutants | equivalent | marked | sampled | killed | timeout | incompetent | survived "
            "| kill rate | minutes | date |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n"
            + "\n".join(rows) + "\n" + "\n".join(details) + "\n")
    out = OUT / "report.md"
    out.write_text(text)
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--packages", default=",".join(PACKAGES), help="comma-separated, of: " + ", ".join(PACKAGES))
    parser.add_argument("--sample", type=int, default=None,
                        help="mutants run per package at most (default: each package's own, about an hour in all)")
    parser.add_argument("--seed", type=int, default=38, help="the sample's seed (default 38)")
    parser.add_argument("--jobs", type=int, default=2, help="packages run at a time (default 2)")
    args = parser.parse_args(argv)
    names = [n for n in args.packages.split(",") if n]
    unknown = set(names) - set(PACKAGES)
    if unknown:
        parser.error(f"unknown packages {sorted(unknown)}; known: {', '.join(PACKAGES)}")
    if args.jobs < 1 or (args.sample is not None and args.sample < 1):
        parser.error("--jobs and --sample must be at least 1")

    def one(name: str) -> dict:
        s = run_package(name, args.sample or SAMPLE[name], args.seed)
        print(f"mutation: {name}: killed {s['killed'] + s['timeout'] + s['incompetent']}/{s['sampled']} sampled "
              f"({rate(s):.0%}) of {s['mutants']} mutants in {s['minutes']} min", flush=True)
        return s

    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        summaries = list(pool.map(one, names))
    print(f"mutation: report in {report().relative_to(ROOT)}", flush=True)
    missed = [f"{s['package']} {rate(s):.0%}" for s in summaries if not rate(s) >= TARGET]
    stale = [f"{s['package']}: {v}" for s in summaries for v in s["stale"]]
    if stale:
        print("mutation: stale entries in docs/checks.md:\n  " + "\n  ".join(stale), flush=True)
    if missed:
        sys.exit(f"mutation: below the {TARGET:.0%} target: {', '.join(missed)}")


if __name__ == "__main__":
    main()
