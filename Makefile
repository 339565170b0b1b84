# Every target sets up what it needs: a .venv in the checkout, the package and its
# development extras, the compiled kernel.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
INSTALLED := $(VENV)/.installed

.PHONY: all test demo generate build bench clean

all: build

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip

$(INSTALLED): $(PY) pyproject.toml setup.py
	$(PY) -m pip install -q --upgrade "setuptools>=70.1" wheel "Cython>=3.0" "numpy>=1.24"
	$(PY) -m pip install -q --no-build-isolation -e ".[dev]"
	touch $@

build: $(INSTALLED)

test: build
	$(PY) -m pytest -q

demo: build
	$(PY) -m stewart.demo

generate: $(INSTALLED)
	$(PY) -m codegen

bench: build
	$(PY) -m benchmarks

clean:
	rm -rf build *.egg-info stewart/*.so stewart/_kernel.c .pytest_cache tests/c/test_model out
