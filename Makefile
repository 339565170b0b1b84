# Every target sets up what it needs: a .venv in the checkout, the package with its
# development extras, the compiled kernel.
PYTHON ?= python3
CC ?= cc
VENV := .venv
PY := $(VENV)/bin/python
UV := $(VENV)/bin/uv
INSTALLED := $(VENV)/.installed
BUILD_REQUIRES := $(VENV)/build-requires.txt
KERNEL := build/.kernel-built
KERNEL_SOURCES := stewart/_kernel.pyx stewart/_kernel.pxd stewart/_simulate.pxi stewart/_envelope.pxi stewart/_modes.pxi \
	stewart/_cueing.pxi stewart/_cueing_rows.pxi stewart/_rotary.pxi stewart/_rotary_envelope.pxi stewart/_rotary_simulate.pxi stewart/_cueing_rotary.pxi \
	$(wildcard generated/*) setup.py
# Python keeps the bytecode of what it imports (in .venv and the checkout's __pycache__/, both
# ignored by git), whatever the environment says: the test suite starts some thirty interpreters
# (its workers, the examples, the isolated fuzzers, the import and SIMD-path checks), and without
# the cache each compiles scipy's, matplotlib's and the package's sources anew (the tests that
# start them take a third longer).
unexport PYTHONDONTWRITEBYTECODE
# The build's first copy of the model (setup.py's MODEL_LIBRARY), which the C test links.
MODEL_LIBRARY := build/libstewart_model.a
C_TEST := tests/c/test_model
# The model's rounding flags (STEWART_ROUNDING_FLAGS of the generated header).
ROUNDING = $(shell sed -n 's/^\#define STEWART_ROUNDING_FLAGS "\(.*\)"/\1/p' generated/stewart_model.h)

.PHONY: all test test-acados acados-env test-cueing-sweep mutation coverage test-peers test-ports test-control test-wheels demo generate build dist bench validate docs serve-docs clean

all: build

# The environment is set up by uv (installed into it by pip), which installs the same
# packages as pip in a fraction of the time.
$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q uv

# pyproject.toml's [build-system] requires, one a line: the editable install builds without
# isolation (in .venv, where it is fast and sees the same numpy and scipy), and uv installs
# no build requirements then, so the bootstrap installs them first, from this one list.
$(BUILD_REQUIRES): pyproject.toml | $(PY)
	$(PY) -c "import tomllib; print(*tomllib.load(open('pyproject.toml', 'rb'))['build-system']['requires'], sep='\n')" > $@

# The editable install compiles the extensions into the checkout (it builds them afresh
# each time it runs: on a fresh checkout, and when pyproject.toml changes).
$(INSTALLED): $(BUILD_REQUIRES)
	$(UV) pip install -q --python $(PY) -r $(BUILD_REQUIRES)
	$(UV) pip install -q --python $(PY) --no-build-isolation -e ".[dev]"
	touch $@

# Recompiles, in the checkout (-b .), only an extension older than its sources or setup.py's
# depends; the generator leaves unchanged files alone. After changing STEWART_MARCH, run
# `make clean` first.
$(KERNEL): $(INSTALLED) $(KERNEL_SOURCES)
	$(PY) setup.py -q build_ext -b .
	mkdir -p build && touch $@

build: $(KERNEL)

# The C test, linked with the model as the build compiled it (make test-ports compiles it anew
# with other compilers and for other CPUs).
$(C_TEST): tests/c/test_model.c tests/c/reference_values.h $(KERNEL)
	$(CC) -std=c99 -O2 $(ROUNDING) -Wall -Wextra -pedantic -Igenerated -Itests/c tests/c/test_model.c $(MODEL_LIBRARY) -lm -o $@

# Every test but the comparisons with the heavy peer models (make test-peers) and those of make
# test-ports (the other builds, and the wheels of make test-wheels). Of the packaging check it
# runs the sdist's: the complete source and nothing else.
SUITE := -m "not peers and not ports and not packaging and not control"
test: build $(C_TEST)
	./$(C_TEST)
	$(VENV)/bin/lint-imports
	$(PY) -m pytest -q $(SUITE)

# acados (nonlinear MPC on the exported model, docs/acados.md) in an environment of its own,
# .venv-acados: the PyPI package comma-deps-acados ships acados's libraries, its Python
# template and its template renderer (t_renderer), with a casadi 3.6.7 of its own built for
# CPython 3.12 that would replace the casadi>=3.8 of .venv. So .venv-acados runs on Python
# 3.12 (python3.12 on the PATH, else pyenv's newest 3.12, or PYTHON312=...), with the package
# installed editable (its extension compiled for 3.12 beside .venv's). stewart.acados points
# acados at the package's install directory (ACADOS_SOURCE_DIR), so that it never offers to
# download a renderer.
ACADOS_VENV := .venv-acados
ACADOS_PY := $(ACADOS_VENV)/bin/python
ACADOS_INSTALLED := $(ACADOS_VENV)/.installed
ACADOS_PACKAGE := comma-deps-acados==0.2.2.post104
# The first of these that runs as CPython 3.12 (a pyenv shim on the PATH may not: its version
# is not selected).
PYTHON312 ?= $(shell for py in "$$(command -v python3.12)" $$(ls -d $${PYENV_ROOT:-$$HOME/.pyenv}/versions/3.12*/bin/python3.12 2>/dev/null | sort -rV); do \
	[ -n "$$py" ] && "$$py" -c 'import sys; assert sys.version_info[:2] == (3, 12)' >/dev/null 2>&1 && { echo "$$py"; break; }; done)

$(ACADOS_INSTALLED): pyproject.toml $(BUILD_REQUIRES)
	@test -n "$(PYTHON312)" && "$(PYTHON312)" -c 'import sys; assert sys.version_info[:2] == (3, 12)' 2>/dev/null || { \
		echo "make acados-env: no Python 3.12 found (tried python3.12 on the PATH and pyenv's versions; acados's wheel, $(ACADOS_PACKAGE), vendors a casadi built for CPython 3.12): put python3.12 on the PATH, install it with 'pyenv install 3.12', or run make acados-env PYTHON312=/path/to/python3.12" >&2; exit 1; }
	"$(PYTHON312)" -m venv $(ACADOS_VENV)
	$(ACADOS_PY) -m pip install -q uv
	$(ACADOS_VENV)/bin/uv pip install -q --python $(ACADOS_PY) -r $(BUILD_REQUIRES) $(ACADOS_PACKAGE) "pytest>=7" "pytest-xdist>=3" "hypothesis>=6"
	$(ACADOS_VENV)/bin/uv pip install -q --python $(ACADOS_PY) --no-build-isolation -e .
	$(ACADOS_PY) -c "import acados; acados.smoketest()"
	touch $@

acados-env: $(ACADOS_INSTALLED)

# The NMPC tests (tests/acados/, in .venv-acados): acados's evaluation of the exported dynamics
# against rk4_step bit for bit, its first QP against the model's linearization, and SQP-RTI
# closed loops on the package's simulator (the extension for .venv-acados's Python recompiled
# first when its sources changed). It fails, never skips, when acados cannot be set up.
test-acados: $(ACADOS_INSTALLED)
	$(ACADOS_PY) setup.py -q build_ext -b .
	STEWART_ACADOS_TESTS=1 $(ACADOS_PY) -m pytest -q -n 0 -p no:cacheprovider tests/acados

# MPC cueing on 40 random vehicle logs (tests/test_cueing_limits.py; make test runs 4), on the
# two presets in turn, each reference and closed loop checked against every limit (minutes).
test-cueing-sweep: build
	STEWART_CUEING_SWEEP=40 $(PY) -m pytest -q tests/test_cueing_limits.py -k random_logs

# Mutation testing of the application packages (cosmic-ray, tests/mutation.py): each
# package's fast topic tests on a sample of its mutants (fixed seed), in a copy of the checkout
# under out/mutation/, with the report in out/mutation/report.md (about an hour on 2 cores;
# not part of make test). MUTATION_ARGS="--packages stiffness,cueing --sample 40" narrows it.
MUTATION_ARGS ?=
mutation: build
	nice $(PY) tests/mutation.py $(MUTATION_ARGS)

# make test's pytest run with the package's line coverage (a third longer: coverage's tracer).
coverage: build
	$(PY) -m pytest -q $(SUITE) --cov=stewart --cov-report=term

# The agreement of the benchmarks' heavy peer models with the kernel: the sympy route (a
# minute and a half of compiling) and the MuJoCo peer run with the dev extra; PyDy with the
# peers extra (.venv/bin/pip install --no-build-isolation -e ".[dev,peers]"), skipped without
# it. The CasADi peers (the dev extra) run in make test.
test-peers: build
	$(PY) -m pytest -q -m peers

# The generated C and its C test under other compilers and for other CPUs (tests/c/ports.py:
# clang, and gcc and clang for aarch64 run under qemu-user; a missing tool is installed with
# apt-get when run as root, else its port prints SKIPPED), then make test-wheels.
test-ports: build
	$(PY) tests/c/ports.py
	$(PY) -m pytest -q -m ports tests/test_build.py
	$(MAKE) test-wheels

# The CMake package of `stewart c-export` and the C++ example controller (examples/cpp_controller;
# the tests marked control), each built with gcc and with clang: the library built, installed and
# linked from CMake and pkg-config, the example's loop against stewart.simulate bit for bit and
# its allocations counted. The compilers, CMake and pkg-config are installed with apt-get where
# missing (as root; tests/c/ports.py --tools).
test-control: build
	$(PY) tests/c/ports.py --tools gcc g++ clang clang++ cmake pkg-config nm readelf
	$(PY) -m pytest -q -n 0 -m control tests/test_cmake_package.py

# The packaging check's wheels (the tests marked packaging), on each supported Python found
# (python3.X on the PATH, or pyenv's), the running one included: the wheel for other machines
# (STEWART_TARGETS=all: every x86-64 copy of the model) built from the sdist by that Python
# with build isolation, installed into its fresh environment and smoke-tested (the C example
# compiled with the installed C files under the strictest flags); a Python not found is
# SKIPPED (tests/test_packaging.py's STEWART_WHEEL_PYTHONS says which versions).
test-wheels: build
	STEWART_TARGETS=all STEWART_WHEEL_PYTHONS=all $(PY) -m pytest -n 0 -v -rs --durations=0 --durations-min=1 -m packaging tests/test_packaging.py

# The sdist and the wheel for this machine's kind (built from the sdist, with build isolation),
# in dist/: what the README's install section installs without a checkout.
dist: $(INSTALLED)
	rm -rf dist
	$(PY) -m build --installer uv --outdir dist .

demo: build
	$(PY) -m stewart.cli.demo

generate: $(INSTALLED)
	$(PY) -m codegen

# The acados NMPC rows run in .venv-acados (made here when missing; without it they say why).
bench: build
	$(MAKE) acados-env || echo "[bench] make acados-env failed: the acados NMPC rows report it"
	$(PY) -m benchmarks

validate: build
	$(PY) -m stewart validate --preset narayan2017
	$(PY) -m stewart validate --preset motion_simulator

# The documentation (docs/, mkdocs.yml): rewrite its measured figures from the commands that
# measure them (tests, validate, exactness, MuJoCo; performance from the last make bench),
# redraw its figures of the seed paper's move, then build the site into site/, where a broken
# link or reference is an error. (make test builds the site too: tests/test_docs.py.)
DOCS_MOVE := --target 0.04565 -0.0102 0.192 -0.0863 0.1046 0.0960 --controller pid
docs: build
	$(PY) -m benchmarks.docs
	MPLBACKEND=Agg $(PY) -m stewart simulate $(DOCS_MOVE) --plot docs/images/
	MPLBACKEND=Agg $(PY) -m stewart calibrate examples/calibration/measurements.csv \
		--validate examples/calibration/held_out.csv --plot docs/images/
	mkdir -p out
	MPLBACKEND=Agg $(PY) -m stewart cueing examples/cueing/hard_braking.csv --method mpc --simulate --output out/mpc_braking.csv --plot docs/images/mpc/
	MPLBACKEND=Agg $(PY) -m stewart.cli.demo --modes-only --out docs/images/
	$(PY) -m mkdocs build --strict

# The site, rebuilt as its pages change, at http://127.0.0.1:8000.
serve-docs: build
	$(PY) -m mkdocs serve

clean:
	rm -rf build dist *.egg-info stewart/*.so stewart/_kernel.c .pytest_cache site $(C_TEST)
