"""stewart.io.capi: the generated C files for C programs, and the parameter header."""

import dataclasses
import os
import pathlib

import numpy as np
import pytest

import stewart
from c_example import CFLAGS, EXAMPLE, check_example, run_command
from conftest import random_params
from stewart.io import capi, cmake
from stewart._kernel import PARAM_FIELDS, PARAM_INPUTS, PARAM_SOURCES, PARAMS_LEFT_OUT

ROOT = pathlib.Path(__file__).resolve().parent.parent


def test_c_files_are_the_generators_output():
    # Run from the checkout (an editable install), the package points at generated/ itself.
    assert pathlib.Path(stewart.c_include_dir()) == ROOT / "generated"
    # The rotary family's units (stewart_rotary*.c) are compiled into the extension only: the C
    # programs' API is the linear model's so far.
    units = sorted(p.name for p in (ROOT / "generated").glob("*.c")
                   if p.name != "stewart_target.c" and not p.name.startswith("stewart_rotary"))
    assert stewart.c_sources() == [os.path.join(stewart.c_include_dir(), name)
                                   for name in ["stewart_model.c"] + [u for u in units if u != "stewart_model.c"]]
    assert len(units) > 10  # the public functions, and the kernels family by family


def _model_files():
    """The model's files an export copies: the header, the shared header, the sources."""
    return [capi.HEADER, capi.INTERNAL_HEADER] + [pathlib.Path(path).name for path in stewart.c_sources()]


#: The package files an export writes after them (tests/test_cmake_package.py checks them).
PACKAGE_FILES = [cmake.PROJECT, cmake.TARGETS, cmake.CONFIG, cmake.CONFIG_VERSION, cmake.PKG_CONFIG,
                 cmake.VERSION_SCRIPT]


#: The model as the build compiled it (setup.py's MODEL_LIBRARY: its first copy, with the
#: public names), which the Makefile's C test links too.
MODEL_LIBRARY = ROOT / "build" / "libstewart_model.a"


def _built_model() -> list[pathlib.Path]:
    """The build's archive of the model if it is newer than every file of the model, else
    nothing (the example is then compiled with the model's sources)."""
    if not MODEL_LIBRARY.is_file():
        return []
    newest = max(p.stat().st_mtime for p in (ROOT / "generated").glob("stewart_*.[ch]"))
    return [MODEL_LIBRARY] if MODEL_LIBRARY.stat().st_mtime >= newest else []


def test_c_example_matches_the_package(tmp_path, figures):
    """The example, compiled against the exported header and parameter header, linked with the
    model as the build compiled it (make test's build; without it, or older than generated/,
    compiled here from the exported sources). The exported sources are generated/'s bytes;
    their compile on their own under the strictest flags is the packaging check's
    (installed_smoke.py, make test-wheels) and tests/c/ports.py's."""
    params = stewart.PlatformParams.preset("narayan2017")
    written = capi.export(tmp_path / "c", params)
    assert written == [str(tmp_path / "c" / name) for name in _model_files() + [capi.PARAMS_HEADER] + PACKAGE_FILES]
    for name in _model_files():
        assert (tmp_path / "c" / name).read_bytes() == (ROOT / "generated" / name).read_bytes()
    library = _built_model()
    sources = [] if library else [tmp_path / "c" / pathlib.Path(path).name for path in stewart.c_sources()]
    error = check_example(params, [tmp_path / "c"], sources, tmp_path, library)
    figures("C example (examples/c) against the compiled kernel, relative", error, 1e-12)  # reached 0


def test_docs_show_the_example_as_shipped():
    example = EXAMPLE.read_text()
    assert example[example.index("#include"):] in (ROOT / "docs" / "c.md").read_text()


def test_export_without_params_writes_the_model_and_the_package_only(tmp_path):
    assert capi.export(tmp_path) == [str(tmp_path / name) for name in _model_files() + PACKAGE_FILES]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(_model_files() + PACKAGE_FILES)


def test_export_refuses_other_params(tmp_path):
    with pytest.raises(TypeError, match="params"):
        capi.export(tmp_path, {"platform_mass": 1.0})


def test_params_header_sets_every_member_by_name(tmp_path):
    """A C program reads each struct member by name: every value must come back bit for bit."""
    params = random_params(np.random.default_rng(11)).replace(
        leg_length_limits=(0.1, 3.0), name="test */ platform\n\u00e9"
    )
    (tmp_path / capi.PARAMS_HEADER).write_text(capi.params_header(params), encoding="ascii")
    members = {  # the struct's members, from the generator's parameter schema
        name: [name + "".join(f"[{i}]" for i in index) for index in np.ndindex(*shape)]
        for name, shape in PARAM_FIELDS
    }
    prints = "".join(f'    printf("%a\\n", p->{m});\n' for group in members.values() for m in group)
    (tmp_path / "dump.c").write_text(
        "#include <stdio.h>\n#include \"stewart_platform_params.h\"\n"
        "int main(void)\n{\n    const stewart_params *p = &stewart_platform_params;\n"
        f"{prints}    return 0;\n}}\n"
    )
    exe = tmp_path / "dump"
    run_command([os.environ.get("CC", "cc"), *CFLAGS, f"-I{tmp_path}", f"-I{ROOT / 'generated'}",
                 tmp_path / "dump.c", "-o", exe])
    printed = [float.fromhex(v) for v in run_command([exe]).split()]
    expected = [float(v) for name in members for v in np.ravel(getattr(params, PARAM_SOURCES[name]))]
    assert printed == expected
    # Every field reaches the struct except those the header names as left out.
    fields = {f.name for f in dataclasses.fields(stewart.PlatformParams)}
    assert fields - set(PARAM_INPUTS) == set(PARAMS_LEFT_OUT) == {
        "leg_length_limits", "universal_joint_max_angle", "spherical_joint_max_angle", "leg_diameter",
        "plate_radius", "base_clearance", "name",
        "viscous_friction", "coulomb_friction", "leg_stiffness", "leg_damping"}
    header = capi.params_header(params)
    assert "leg_length_limits = (0.1, 3.0)" in header and "'test * / platform\\n\\xe9'" in header


def test_missing_c_files_are_reported(tmp_path, monkeypatch):
    monkeypatch.setattr(capi, "_LOCATIONS", (tmp_path,))
    with pytest.raises(FileNotFoundError, match="stewart_model.h"):
        stewart.c_include_dir()
