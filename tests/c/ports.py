"""The generated C and its C test (tests/c/test_model.c) under other compilers and targets
than make test's: clang for x86-64, and gcc and clang for aarch64, run under qemu-user.

    python tests/c/ports.py [PORT ...]      # make test-ports; no PORT: all of them
    python tests/c/ports.py --tools TOOL ...  # install the tools missing (make test-control)

The model's rounding flags (STEWART_ROUNDING_FLAGS of the generated header) are GCC's
spellings; ROUNDING_SPELLING says them for each compiler, and a probe shows that with them
the compiler does not contract ``a * b + c`` into a fused multiply-add on a target that has
one (and that it does without them, so that the probe can tell). The model's units are
generated/*.c but stewart_target.c (the table of setup.py's per-target copies), found afresh
on each run, each compiled on its own, side by side on every core, with the flags of the
Makefile's C test.

A tool a port needs and does not find is installed with apt-get when this runs as root (as
on CI's clean machine; STEWART_PORTS_INSTALL=0 never installs); a port that still cannot
run prints ``SKIPPED: <port>: <reason>``. A port that fails to build, or whose test fails,
makes the exit status non-zero. Standard library only.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import Future, ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
GENERATED = ROOT / "generated"
TEST = ROOT / "tests" / "c" / "test_model.c"
OUT = ROOT / "build" / "ports"
#: The Makefile's C test flags but the rounding (its $(C_TEST) rule).
CFLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic"]
AARCH64_SYSROOT = "/usr/aarch64-linux-gnu"
#: Seconds the C test may take (about 2 s natively, 2-3 min under qemu on 2 cores).
TEST_TIMEOUT = 1800

#: The one place that says the header's rounding flags (GCC spellings) for each compiler.
#: GCC: as written (-ffp-contract=off: GCC keeps a * b + c unfused under -std=c99 anyway, but
#: its GNU modes, the default, contract into FMA wherever the target has one, and aarch64 has
#: it in its baseline). Clang (14): -ffp-contract=off as written (its default, "on", fuses
#: a * b + c within an expression, whatever -std says, on any target with FMA);
#: GCC's -fno-tree-slp-vectorize is its own -fno-slp-vectorize (clang 14 takes GCC's spelling
#: as an alias too; its own is said here so that a clang dropping the alias still gets it).
#: A flag not listed goes as written; every flag is checked to be accepted (-Werror).
ROUNDING_SPELLING: dict[str, dict[str, str]] = {
    "gcc": {},
    "clang": {"-fno-tree-slp-vectorize": "-fno-slp-vectorize"},
}
#: Fused multiply-add instructions in assembly, by architecture.
FMA_INSTRUCTIONS = {"x86_64": r"\bvf[n]?m(add|sub)\w*", "aarch64": r"\bf[n]?m(add|sub|la|ls)\b"}
#: Flags that give the contraction probe a target with FMA (aarch64 has it in its baseline).
FMA_TARGET = {"x86_64": ["-march=x86-64-v3"], "aarch64": []}
PROBE = "double f(double a, double b, double c) { return a * b + c; }\n"


@dataclass
class Requirement:
    """Something a port needs: a description, whether it is here, the Debian package with it."""
    what: str
    present: object  # () -> bool
    package: str


def _tool(name: str, package: str) -> Requirement:
    return Requirement(name, lambda: shutil.which(name) is not None, package)


def _qemu() -> list[str]:
    qemu = shutil.which("qemu-aarch64") or shutil.which("qemu-aarch64-static")
    return [qemu or "qemu-aarch64", "-L", AARCH64_SYSROOT]


AARCH64_LIBC = Requirement("aarch64 C library (libc6-dev-arm64-cross)",
                           lambda: Path(AARCH64_SYSROOT, "include", "stdio.h").is_file(), "libc6-dev-arm64-cross")
QEMU = Requirement("qemu-aarch64", lambda: bool(shutil.which("qemu-aarch64") or shutil.which("qemu-aarch64-static")),
                   "qemu-user")


@dataclass
class Port:
    name: str
    family: str  # a key of ROUNDING_SPELLING
    arch: str  # a key of FMA_INSTRUCTIONS
    compiler: list[str]
    needs: list[Requirement]
    runner: object = staticmethod(lambda: [])  # () -> the command prefix that runs its programs


#: In the order their units are compiled: the quick ones first, so that their tests (under qemu)
#: run while aarch64 gcc, which takes several times clang's time over the model, compiles.
PORTS = [
    Port("clang-x86_64", "clang", "x86_64", ["clang"], [_tool("clang", "clang")]),
    # clang cross-compiles with the GNU cross toolchain's C library, start files and linker.
    Port("clang-aarch64", "clang", "aarch64", ["clang", "--target=aarch64-linux-gnu"],
         [_tool("clang", "clang"), _tool("aarch64-linux-gnu-gcc", "gcc-aarch64-linux-gnu"), AARCH64_LIBC, QEMU],
         _qemu),
    Port("gcc-aarch64", "gcc", "aarch64", ["aarch64-linux-gnu-gcc"],
         [_tool("aarch64-linux-gnu-gcc", "gcc-aarch64-linux-gnu"), AARCH64_LIBC, QEMU], _qemu),
]


def rounding_flags() -> list[str]:
    """STEWART_ROUNDING_FLAGS of the generated header (GCC spellings)."""
    header = (GENERATED / "stewart_model.h").read_text(encoding="ascii")
    return re.search(r'#define STEWART_ROUNDING_FLAGS "(.*)"', header).group(1).split()


def spelled(family: str, flags: list[str]) -> list[str]:
    return [ROUNDING_SPELLING[family].get(flag, flag) for flag in flags]


def model_sources() -> list[Path]:
    """The model's translation units: generated/*.c but the table of setup.py's per-target
    copies (stewart_target.c)."""
    return sorted(p for p in GENERATED.glob("*.c") if p.name != "stewart_target.c")


def run(command, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run([str(c) for c in command], capture_output=True, text=True, **kwargs)


def install(packages: list[str]) -> str | None:
    """Install Debian packages with apt-get; None, or why not."""
    if os.environ.get("STEWART_PORTS_INSTALL", "1") == "0":
        return "not installing (STEWART_PORTS_INSTALL=0)"
    if not hasattr(os, "geteuid") or os.geteuid() != 0 or not shutil.which("apt-get"):
        return "not root with apt-get, cannot install"
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    lock = ["-o", "DPkg::Lock::Timeout=600"]
    print(f"installing {' '.join(packages)} (apt-get)", flush=True)
    command = ["apt-get", *lock, "install", "-y", "-q", "--no-install-recommends", *packages]
    done = run(command, env=env)
    if done.returncode != 0:  # a clean machine has no package lists yet
        run(["apt-get", *lock, "update", "-q"], env=env)
        done = run(command, env=env)
    if done.returncode != 0:
        return f"apt-get install {' '.join(packages)} failed: {(done.stderr or done.stdout).strip()[-300:]}"
    return None


def missing(port: Port) -> list[Requirement]:
    return [need for need in port.needs if not need.present()]


def provide(ports: list[Port]) -> dict[str, str]:
    """Install what the ports lack; {port name: why it cannot run} for those still lacking."""
    packages = sorted({need.package for port in ports for need in missing(port)})
    why = install(packages) if packages else None
    skipped = {}
    for port in ports:
        lacking = missing(port)
        if lacking:
            skipped[port.name] = f"{', '.join(n.what for n in lacking)} not found" + (f"; {why}" if why else "")
    return skipped


def describe(port: Port) -> str:
    """The compiler's version and its target triple (and the emulator that runs the test)."""
    version = run([*port.compiler, "--version"]).stdout.splitlines()
    target = run([*port.compiler, "-dumpmachine"]).stdout.strip()
    runner = run([port.runner()[0], "--version"]).stdout.splitlines() if port.runner() else []
    return f"{version[0] if version else '?'} -> {target}" + (f", run by {runner[0]}" if runner else "")


def probe_contraction(port: Port, flags: list[str]) -> str | None:
    """None if the compiler takes ``flags`` (-Werror) and, with them, keeps a * b + c unfused
    on a target with FMA; otherwise what went wrong."""
    fused = re.compile(FMA_INSTRUCTIONS[port.arch])
    with tempfile.TemporaryDirectory() as tmp:
        source = Path(tmp, "probe.c")
        source.write_text(PROBE, encoding="ascii")

        def assembly(extra):
            done = run([*port.compiler, *CFLAGS, *FMA_TARGET[port.arch], "-Werror", *extra, "-S", "-o", "-", source])
            if done.returncode != 0:
                raise RuntimeError(f"{' '.join(extra)}: {done.stderr.strip()}")
            return done.stdout

        try:
            control, kept = assembly(["-ffp-contract=fast"]), assembly(flags)
        except RuntimeError as error:
            return f"the compiler refuses the flags: {error}"
    if not fused.search(control):
        return "probe cannot tell: no FMA even with -ffp-contract=fast"
    if fused.search(kept):
        return f"contracts a * b + c into an FMA with {' '.join(flags)}"
    return None


def compile_unit(port: Port, flags: list[str], source: Path, obj: Path) -> tuple[float, str]:
    """Compile one translation unit; (seconds, the compiler's warnings). Raises on error."""
    start = time.perf_counter()
    done = run([*port.compiler, *CFLAGS, *flags, f"-I{GENERATED}", f"-I{TEST.parent}", "-c", source, "-o", obj])
    if done.returncode != 0:
        raise RuntimeError(f"{source.name}: {done.stderr.strip()}")
    return time.perf_counter() - start, done.stderr.strip()


def parse(output: str) -> dict[str, str]:
    """The C test's summary lines."""
    found = {}
    for key, pattern in (("counts", r"(\d+) passed, (\d+) failed"),
                         ("batch", r"batches \((\d+) lanes\) vs the single-state functions: worst relative difference (\S+)"),
                         ("reference", r"generated C vs numeric reference: worst relative error (\S+)")):
        match = re.search(pattern, output)
        if match:
            found[key] = match.groups()
    return found


def finish(port: Port, flags: list[str], sources: list[Path], futures: list[Future], start: float) -> str:
    """Wait for the port's units, link and run its test; "passed: ..." or "FAILED: ..."."""
    out = OUT / port.name
    try:
        timed = [future.result() for future in futures]
    except RuntimeError as error:
        return f"FAILED: compile: {error}"
    built = time.perf_counter() - start
    warnings = [w for _, text in timed for w in text.splitlines() if "warning:" in w]
    exe = out / "test_model"
    done = run([*port.compiler, *CFLAGS, *flags, *(out / f"{src.stem}.o" for src in sources), "-lm", "-o", exe])
    if done.returncode != 0:
        return f"FAILED: link: {done.stderr.strip()}"
    t0 = time.perf_counter()
    try:
        done = run([*port.runner(), exe], timeout=TEST_TIMEOUT)
    except (OSError, subprocess.TimeoutExpired) as error:
        return f"FAILED: run: {error}"
    ran = time.perf_counter() - t0
    found = parse(done.stdout)
    summary = f"{found['counts'][0]} passed, {found['counts'][1]} failed" if "counts" in found else "no summary line"
    if "batch" in found:
        summary += f"; batches ({found['batch'][0]} lanes) vs single states: worst difference {found['batch'][1]}"
    if "reference" in found:
        summary += f"; vs reference: worst {found['reference'][0]}"
    summary += (f"; built {built:.0f} s after the start ({len(sources)} units, {sum(t for t, _ in timed):.0f} s "
                f"summed over its compiles), test ran {ran:.1f} s" + (" under qemu" if port.runner() else ""))
    if warnings:
        summary += f"; {len(warnings)} compiler warning(s), the first: {warnings[0]}"
    if done.returncode == 0 and "counts" in found and found["counts"][1] == "0":
        return "passed: " + summary
    print(f"{port.name}: the test printed:\n{done.stdout[-3000:]}{done.stderr[-2000:]}", flush=True)
    return f"FAILED: exit {done.returncode}; {summary}"


#: The Debian package of each tool ``--tools`` can install.
TOOL_PACKAGES = {"gcc": "gcc", "g++": "g++", "clang": "clang", "clang++": "clang", "pkg-config": "pkgconf",
                 "cmake": "cmake", "nm": "binutils", "readelf": "binutils"}


def provide_tools(tools: list[str]) -> int:
    """Install the Debian packages of the ``tools`` not found (``TOOL_PACKAGES``); 0, or 1 with
    why not (the tests that need them then fail naming them)."""
    unknown = [tool for tool in tools if tool not in TOOL_PACKAGES]
    if unknown:
        print(f"--tools: unknown tool(s) {unknown}; the tools: {sorted(TOOL_PACKAGES)}")
        return 2
    lacking = [tool for tool in tools if shutil.which(tool) is None]
    why = install(sorted({TOOL_PACKAGES[tool] for tool in lacking})) if lacking else None
    still = [tool for tool in tools if shutil.which(tool) is None]
    if still:
        print(f"{', '.join(still)} not found" + (f"; {why}" if why else ""))
        return 1
    return 0


def main(argv: list[str]) -> int:
    if argv[:1] == ["--tools"]:
        return provide_tools(argv[1:])
    chosen = [p for p in PORTS if not argv or p.name in argv]
    unknown = set(argv) - {p.name for p in PORTS}
    if unknown:
        print(f"unknown port(s) {sorted(unknown)}; the ports: {[p.name for p in PORTS]}")
        return 2
    sources = [*model_sources(), TEST]
    gcc_flags = rounding_flags()
    print(f"the model: {len(sources) - 1} units in generated/ ({', '.join(s.name for s in sources[:-1])}); "
          f"its rounding flags (GCC's): {' '.join(gcc_flags)}", flush=True)

    skipped = provide(chosen)
    results: dict[str, str] = {}  # port name: "passed: ..." or "FAILED: ..."
    ready = []
    for port in chosen:
        if port.name in skipped:
            continue
        flags = spelled(port.family, gcc_flags)
        problem = probe_contraction(port, flags)
        print(f"{port.name}: {describe(port)}; rounding flags {' '.join(flags)}; "
              f"contraction probe: {problem or 'no FMA with them (FMA without)'}", flush=True)
        if problem:
            results[port.name] = f"FAILED: rounding flags: {problem}"
            continue
        ready.append((port, flags))

    # The units side by side, one compiler per core: port by port (PORTS' order), each port's
    # largest units first; each port links and runs its test as soon as its own units are compiled.
    start = time.perf_counter()
    by_size = sorted(sources, key=lambda src: -src.stat().st_size)
    jobs = [(port, flags, src) for port, flags in ready for src in by_size]
    with ThreadPoolExecutor(os.cpu_count() or 1) as compilers, ThreadPoolExecutor(len(ready) or 1) as finishers:
        for port, _ in ready:
            shutil.rmtree(OUT / port.name, ignore_errors=True)
            (OUT / port.name).mkdir(parents=True)
        futures = {(port.name, src): compilers.submit(compile_unit, port, flags, src, OUT / port.name / f"{src.stem}.o")
                   for port, flags, src in jobs}
        finishing = {finishers.submit(finish, port, flags, sources, [futures[port.name, src] for src in sources],
                                      start): port for port, flags in ready}
        for done in as_completed(finishing):
            results[finishing[done].name] = done.result()
            print(f"{finishing[done].name}: {done.result()}", flush=True)

    print("\nports of the generated C (tests/c/test_model.c):")
    for port in chosen:
        if port.name in skipped:
            print(f"SKIPPED: {port.name}: {skipped[port.name]}")
        else:
            print(f"{port.name}: {results[port.name]}")
    return 1 if any(result.startswith("FAILED") for result in results.values()) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
