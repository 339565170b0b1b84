# Every target sets up what it needs: a .venv in the checkout, the package with its
# development extras, the compiled kernel.
PYTHON ?= python3
CC ?= cc
VENV := .venv
PY := $(VENV)/bin/python
INSTALLED := $(VENV)/.installed
KERNEL := build/.kernel-built
KERNEL_SOURCES := stewart/_kernel.pyx stewart/_kernel.pxd stewart/_simulate.pyx stewart/_envelope.pyx generated/stewart_model.c \
	generated/stewart_model.h generated/stewart_model.pxd generated/stewart_dispatch.h generated/stewart_target.c setup.py
C_TEST := tests/c/test_model
# The model's rounding flags (STEWART_ROUNDING_FLAGS of the generated header).
ROUNDING = $(shell sed -n 's/^\#define STEWART_ROUNDING_FLAGS "\(.*\)"/\1/p' generated/stewart_model.h)

.PHONY: all test test-peers demo generate build bench validate readme clean

all: build

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip

# The editable install compiles the extensions into the checkout (pip builds them afresh
# each time it runs: on a fresh checkout, and when pyproject.toml changes).
$(INSTALLED): $(PY) pyproject.toml
	$(PY) -m pip install -q --upgrade "setuptools>=77" wheel "Cython>=3.0" "numpy>=1.24"
	$(PY) -m pip install -q --no-build-isolation -e ".[dev]"
	touch $@

# Recompiles, in the checkout (-b .), only an extension older than its sources or setup.py's
# depends; the generator leaves unchanged files alone. After changing STEWART_MARCH, run
# `make clean` first.
$(KERNEL): $(INSTALLED) $(KERNEL_SOURCES)
	$(PY) setup.py -q build_ext -b .
	mkdir -p build && touch $@

build: $(KERNEL)

$(C_TEST): tests/c/test_model.c tests/c/reference_values.h generated/stewart_model.c generated/stewart_model.h
	$(CC) -std=c99 -O2 $(ROUNDING) -Wall -Wextra -pedantic -Igenerated -Itests/c tests/c/test_model.c generated/stewart_model.c -lm -o $@

# Every test but the comparisons with the peer models (make test-peers), with coverage.
test: build $(C_TEST)
	./$(C_TEST)
	$(PY) -m pytest -q -m "not peers" --cov=stewart --cov-report=term

# The agreement of the benchmarks' peer models with the kernel: the sympy route runs with
# the dev extra (a minute and a half of compiling); CasADi, PyDy and MuJoCo with the peers
# extra (.venv/bin/pip install --no-build-isolation -e ".[dev,peers]"), skipped without it.
test-peers: build
	$(PY) -m pytest -q -m peers

demo: build
	$(PY) -m stewart.demo

generate: $(INSTALLED)
	$(PY) -m codegen

bench: build
	$(PY) -m benchmarks

validate: build
	$(PY) -m stewart validate --preset narayan2017
	$(PY) -m stewart validate --preset motion_simulator

# Rewrite the README's measured figures (tests, validate; performance from the last make bench).
readme: build
	$(PY) -m benchmarks.readme

clean:
	rm -rf build *.egg-info stewart/*.so stewart/_kernel.c stewart/_simulate.c .pytest_cache $(C_TEST)
