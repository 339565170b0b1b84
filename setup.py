"""Build script: the pure-Python package plus the Cython kernel over the generated C.

Portable by default: on x86-64 the model (its units, generated/stewart_model*.c, and its
table of functions, generated/stewart_target.c) is compiled once per target into the one
extension -- ``baseline`` (x86-64), and ``avx2`` (x86-64-v3: AVX2, FMA) and ``avx512``
(x86-64-v4) where the building CPU runs them, all units of all targets side by side -- and
the kernel runs the best copy the CPU supports, chosen at import (``STEWART_SIMD`` forces
one; ``stewart.build_info()`` tells which). ``STEWART_TARGETS=all`` compiles every target
the compiler can build, whatever the building CPU runs: for a wheel that goes to other
machines. A target the compiler cannot build (its flags, or its level in
``__builtin_cpu_supports``) is left out. On any
other CPU (aarch64: NEON is its baseline) one baseline copy is compiled, with the
compiler's default target.

``STEWART_MARCH`` (e.g. ``native``) builds one copy for that ``-march`` instead: faster
to build, but it runs only on CPUs with that instruction set.

Batches run on OpenMP threads when the compiler has OpenMP (a test compile tells); without
it (or with ``STEWART_OPENMP=0``) the kernel splits batches over plain threads. A wheel built
here is tagged for the plain platform (``linux_x86_64``), not ``manylinux``: it claims to
run on this platform's C library, on any CPU of its architecture.
"""

import fnmatch
import glob
import os
import platform
import re
import subprocess
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from Cython.Build import cythonize
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.errors import CCompilerError, CompileError, LinkError
from setuptools.modified import newer_group

#: The portable targets on x86-64: (name, -march, the x86-64 level the CPU needs), the one
#: that runs everywhere first.
X86_TARGETS = (("baseline", "x86-64", ""), ("avx2", "x86-64-v3", "x86-64-v3"), ("avx512", "x86-64-v4", "x86-64-v4"))
#: The optimisation of the model's copies; no debug information (Python's CFLAGS ask for -g),
#: which adds about a fifth to the model's compile time.
OPTIMIZE = ["-O3", "-g0"]
#: The optimisation of the Cython wrapper (stewart._kernel's own C: Python glue and the loops
#: around the model's calls): at -O1 it compiles in half the time of -O3 (7 s of CPU instead of
#: 14), for 1-4 % more instructions in its loops (callgrind, the model's included: 500 RK4
#: steps 25.7 M against 25.1 M, the envelope's peaks of 20000 states 59.8 M against 57.4 M).
WRAPPER_OPTIMIZE = ["-O1", "-g0"]
#: The model's rounding (STEWART_ROUNDING_FLAGS of the generated header): its operations as
#: written, so that a state gives the same bits on every instruction set. Every extension is
#: compiled with them.
with open("generated/stewart_model.h", encoding="ascii") as header:
    EXACT = re.search(r'#define STEWART_ROUNDING_FLAGS "(.*)"', header.read()).group(1).split()
#: The model, compiled once per target: its units (the rotary family's, stewart_rotary*.c, beside
#: them) and its table; what its copies depend on.
MODEL_SOURCES = (sorted(glob.glob("generated/stewart_model*.c")) + sorted(glob.glob("generated/stewart_rotary*.c"))
                 + ["generated/stewart_target.c"])
MODEL = MODEL_SOURCES + ["generated/stewart_model.h", "generated/stewart_internal.h", "generated/stewart_dispatch.h",
                         "generated/stewart_rotary.h", "generated/stewart_rotary_internal.h",
                         "generated/stewart_rotary_dispatch.h"]
#: The units whose compile time is mostly GCC's register allocation (LRA's hard register
#: assignment: 62 % of the 7.6 s of stewart_rotary_inverse_dynamics_derivatives_x3.c at avx2),
#: and the limit on the reload pseudos LRA considers there (default 500), which takes that unit
#: to 4.2 s; it only allocates registers (the operations, their rounding, are the same), and
#: the rotary torque derivatives' batches ran at the same speed (docs/rotary.md). Compilers
#: without it (the probe in build_extensions) build these units without it.
ALLOCATION_UNITS = "generated/stewart_rotary_inverse_dynamics_derivatives_*.c"
ALLOCATION = ["--param=lra-max-considered-reload-pseudos=50"]
#: The units of the public functions (their argument checks, the steps between the kernels and
#: the batch loops over the kernels' blocks), compiled at -O2: GCC's -O3 passes take them from
#: 0.9 to 2.7 s (stewart_model.c) and from 0.7 to 1.7 s (stewart_rotary.c) of CPU per copy, with
#: no gain in their batches' speed (benchmarks.rotary_kernel and stewart bench, same figures
#: within their intervals); the kernels' units keep -O3. The operations, and their rounding, are
#: the same at either level (STEWART_ROUNDING_FLAGS).
GLUE_UNITS = ("generated/stewart_model.c", "generated/stewart_rotary.c")
GLUE_OPTIMIZE = ["-O2"]
#: Every compile hands its assembly to the assembler through a pipe, not a temporary file (a
#: way of building, not a flag of the model's: build_info does not list it).
PIPE = ["-pipe"]
#: The first copy of the model (the one that runs everywhere, with the public names), as a
#: static library for the C test (tests/c), which links it instead of compiling the model again.
MODEL_LIBRARY = ("stewart_model", "build")

OPENMP_PROBE = """#include <omp.h>
int main(void) { return omp_get_max_threads() > 0 ? 0 : 1; }
"""
LEVEL_PROBE = """int main(void) { __builtin_cpu_init(); return !__builtin_cpu_supports("%s"); }
"""
#: STEWART_TARGETS: which x86-64 targets to compile, by value.
TARGET_CHOICES = {"cpu": "the targets the building CPU runs (the default)",
                  "all": "every target the compiler builds (a wheel for other machines)"}


class BuildKernel(build_ext):
    """build_ext that first probes the compiler (OpenMP, the targets), then compiles the model
    once per target, and the Cython wrapper beside it, and links them into stewart._kernel."""

    def _builds(self, code, flags, link=False, run=False):
        """Whether the compiler builds the C program ``code`` with ``flags`` (and links it, and
        it exits with 0 when run)."""
        with tempfile.TemporaryDirectory() as tmp:
            source = os.path.join(tmp, "probe.c")
            with open(source, "w", encoding="ascii") as f:
                f.write(code)
            try:
                objects = self.compiler.compile([source], output_dir=tmp, extra_postargs=flags)
                if link or run:
                    self.compiler.link_executable(objects, "probe", output_dir=tmp, extra_postargs=flags)
            except (CCompilerError, CompileError, LinkError):
                return False
            if run:
                return subprocess.run([self.compiler.executable_filename("probe", output_dir=tmp)]).returncode == 0
        return True

    def _targets(self):
        """(name, flags, level) of every copy of the model to compile."""
        march = os.environ.get("STEWART_MARCH")
        if march:
            return [(re.sub(r"\W", "_", march), OPTIMIZE + EXACT + [f"-march={march}"], "")]
        if platform.machine().lower() not in ("x86_64", "amd64"):
            return [("baseline", OPTIMIZE + EXACT, "")]
        choice = os.environ.get("STEWART_TARGETS", "cpu")
        if choice not in TARGET_CHOICES:
            raise SystemExit(f"STEWART_TARGETS={choice!r}: use " + " or ".join(
                f"{name} ({meaning})" for name, meaning in TARGET_CHOICES.items()))
        targets = [(name, OPTIMIZE + EXACT + [f"-march={arch}"], level) for name, arch, level in X86_TARGETS]
        return [targets[0]] + [t for t in targets[1:]
                               if self._builds(LEVEL_PROBE % t[2], t[1], link=True, run=choice == "cpu")]

    def build_extensions(self):
        self.openmp = os.environ.get("STEWART_OPENMP", "1") != "0" and self._builds(
            OPENMP_PROBE, ["-fopenmp"], link=True)
        self.targets = self._targets()
        self.allocation = ALLOCATION if self._builds("int main(void) { return 0; }\n", ALLOCATION + ["-Werror"]) else []
        # The wrapper runs on every CPU the base copy runs on, with the same rounding.
        wrapper = WRAPPER_OPTIMIZE + [flag for flag in self.targets[0][1] if flag not in OPTIMIZE]
        openmp = ["-fopenmp"] if self.openmp else []
        tables = [("STEWART_TABLES", " ".join(f"X({name})" for name, _, _ in self.targets))]
        if any(level for _, _, level in self.targets):
            tables.append(("STEWART_CPU_LEVELS", "1"))
        for ext in self.extensions:
            ext.extra_compile_args = wrapper + openmp + PIPE
            ext.extra_link_args = openmp
            ext.define_macros = ext.define_macros + tables
        super().build_extensions()

    def build_extension(self, ext):
        """Build stewart._kernel: the units of the model's copies compile side by side, one
        job per core, while this thread runs Cython on the wrapper and compiles its C; then
        the link. An extension newer than its sources and depends is left alone (e.g. the one
        the editable install just built), and so are the model's objects."""
        path = self.get_ext_fullpath(ext.name)
        if not (self.force or not os.path.exists(self._library()) or newer_group(ext.sources + ext.depends, path)):
            return
        with ThreadPoolExecutor(os.cpu_count() or 1) as pool:
            units = self._compile_model(pool)
            sources = cythonize([ext], force=self.force, language_level=3, include_path=["generated"])[0].sources
            objects = self.compiler.compile(sources, output_dir=self.build_temp, macros=ext.define_macros,
                                            include_dirs=ext.include_dirs, debug=self.debug,
                                            extra_postargs=ext.extra_compile_args, depends=ext.depends)
            objects += self._model_objects(units)
        self.compiler.link_shared_object(
            objects, path, libraries=self.get_libraries(ext), library_dirs=ext.library_dirs,
            runtime_library_dirs=ext.runtime_library_dirs, extra_postargs=ext.extra_link_args,
            export_symbols=self.get_export_symbols(ext), debug=self.debug, build_temp=self.build_temp,
            target_lang=ext.language)

    def _compile_model(self, pool):
        """Compile the model once per target on ``pool``, every unit of every copy side by side,
        each copy into its own directory, the largest units first (so that the last ones to
        finish are short); {(copy index, source): the future of its object files}."""
        def compile_unit(job):
            index, source = job
            name, flags, level = self.targets[index]
            macros = [("STEWART_TARGET", name), ("STEWART_TARGET_LEVEL", f'"{level}"'),
                      ("STEWART_TARGET_FLAGS", '"' + " ".join(flags) + '"')]
            if index > 0:  # the first copy keeps the public names; the others are renamed
                macros.append(("STEWART_PREFIX", f"stewart_{name}"))
            output_dir = os.path.join(self.build_temp, name)
            objects = self.compiler.object_filenames([source], output_dir=output_dir)
            if not self.force and not newer_group(MODEL + ["setup.py"], objects[0]):
                return objects  # compiled already, from the same sources
            if fnmatch.fnmatch(source, ALLOCATION_UNITS):
                flags = flags + self.allocation
            if source in GLUE_UNITS:
                flags = flags + GLUE_OPTIMIZE
            return self.compiler.compile([source], output_dir=output_dir, macros=macros,
                                         include_dirs=["generated"], extra_postargs=flags + PIPE, depends=MODEL)
        jobs = sorted(((index, source) for index in range(len(self.targets)) for source in MODEL_SOURCES),
                      key=lambda job: -os.path.getsize(job[1]))
        return {job: pool.submit(compile_unit, job) for job in jobs}

    def _model_objects(self, units):
        """The object files of the model's copies once ``units`` (of ``_compile_model``) are
        compiled, the copies in order; the first copy is also archived (MODEL_LIBRARY)."""
        copies = [[obj for source in MODEL_SOURCES for obj in units[index, source].result()]
                  for index in range(len(self.targets))]
        library, directory = MODEL_LIBRARY
        self.compiler.create_static_lib(copies[0], library, output_dir=directory)
        return [obj for objects in copies for obj in objects]

    def _library(self):
        """The path of MODEL_LIBRARY."""
        library, directory = MODEL_LIBRARY
        return self.compiler.library_filename(library, output_dir=directory)


extensions = [
    # The model's array wrapper with the simulation loop and the envelope's reduction
    # (stewart/_simulate.pxi, stewart/_envelope.pxi), the modes (stewart/_modes.pxi, calling
    # LAPACK through scipy.linalg.cython_lapack) and MPC cueing's step (stewart/_cueing.pxi and
    # its rows, stewart/_cueing_rows.pxi, calling BLAS through scipy.linalg.cython_blas), included, linked with the copies of the
    # model (BuildKernel, which also runs Cython on it).
    Extension(
        "stewart._kernel", sources=["stewart/_kernel.pyx"],
        include_dirs=["generated", np.get_include()],
        define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
        libraries=["m"],
        # Rebuild (build_ext compares times) when the wrapper's included files and declarations,
        # the model, its header or this script change. generated/stewart_model.pxd, the model's
        # Cython declarations, is cimported by stewart/_kernel.pxd.
        depends=["stewart/_kernel.pxd", "stewart/_simulate.pxi", "stewart/_envelope.pxi", "stewart/_modes.pxi",
                 "stewart/_cueing.pxi", "stewart/_cueing_rows.pxi", "stewart/_rotary.pxi",
                 "stewart/_rotary_envelope.pxi", "stewart/_rotary_simulate.pxi", "stewart/_cueing_rotary.pxi"] + MODEL
        + ["generated/stewart_model.pxd", "generated/stewart_rotary.pxd", "setup.py"],
    ),
]

setup(ext_modules=extensions, cmdclass={"build_ext": BuildKernel})
