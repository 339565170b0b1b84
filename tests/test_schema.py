"""One parameter schema: a field added to it reaches every generated artifact, and a parameter
set whose fields differ from it is refused instead of being copied in part."""

import dataclasses
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import stewart
from stewart.io import capi
from stewart._kernel import PARAM_FIELDS, PARAM_INPUTS, PARAM_SOURCES, PARAMS_LEFT_OUT, Kernel

ROOT = pathlib.Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from codegen import csource, kinematics, model, pxd, pymodule, schema  # noqa: E402

DUMMY = schema.ParamField("dummy_offsets", "d_O", (2, 4), "a field no kernel uses")


def test_the_compiled_kernel_carries_the_generators_schema():
    assert PARAM_FIELDS == tuple((f.name, f.shape) for f in schema.PARAM_FIELDS)
    assert PARAMS_LEFT_OUT == schema.LEFT_OUT
    fields = {f.name for f in dataclasses.fields(stewart.PlatformParams)}
    assert fields == set(PARAM_INPUTS) | set(PARAMS_LEFT_OUT)
    assert PARAM_SOURCES == {f.name: f.source or f.name for f in schema.PARAM_FIELDS}


def test_a_new_field_reaches_every_generated_artifact(tmp_path):
    fields = schema.PARAM_FIELDS + (DUMMY,)
    header = csource.header(fields, model.FUNCTIONS, [("kernel", 1)], schema.INERTIAL_PARAMETERS)
    assert "    double dummy_offsets[2][4];" in header
    check = csource.params_finite(fields)
    assert "all_finite(&p->dummy_offsets[0][0], 8)" in check
    text = pxd.pxd(fields, model.FUNCTIONS)
    assert "        double dummy_offsets[2][4]\n" in text
    assert "p.dummy_offsets[i0][i1] = value[i0, i1]" in text
    tables = pymodule.module(fields, schema.LEFT_OUT, model.FUNCTIONS, schema.INERTIAL_PARAMETERS)
    assert "    ('dummy_offsets', (2, 4)),\n" in tables
    members = dict((member, symbol) for symbol, member in kinematics.Params(fields).members())
    assert [members[f"dummy_offsets[{i}][{k}]"].name for i in range(2) for k in range(4)] == [
        f"d_O{i}_{k}" for i in range(2) for k in range(4)]
    # The header with the new member and the finiteness check over it are valid C.
    (tmp_path / "stewart_model.h").write_text(header)
    (tmp_path / "check.c").write_text(
        '#include <math.h>\n#include "stewart_model.h"\n'
        "static int all_finite(const double *v, int n)\n{\n    int k, ok = 1;\n"
        "    for (k = 0; k < n; ++k) {\n        ok &= isfinite(v[k]) != 0;\n    }\n    return ok;\n}\n"
        + check + "int use(const stewart_params *p)\n{\n    return params_finite(p);\n}\n")
    subprocess.run([os.environ.get("CC", "cc"), "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror",
                    "-fsyntax-only", str(tmp_path / "check.c")], check=True)


def _params_with(extra=(), without=()):
    """The narayan2017 parameters as an instance of a dataclass with the PlatformParams
    fields (and the properties the struct's members are copied from), plus the fields
    ``extra`` and less those named in ``without``."""
    params = stewart.PlatformParams.preset("narayan2017")
    names = [f.name for f in dataclasses.fields(params) if f.name not in without]
    derived = {source: property(lambda self, source=source: getattr(params, source))
               for source in PARAM_SOURCES.values() if source not in names}
    cls = dataclasses.make_dataclass("Params", names + [name for name, _ in extra], namespace=derived)
    return cls(**{name: getattr(params, name) for name in names}, **dict(extra))


@pytest.mark.parametrize("extra, without, message", [
    ((("dummy_offsets", np.zeros((2, 4))),), (), r"\['dummy_offsets'\] not in it"),
    ((), ("gravity",), r"\['gravity'\] missing"),
])
def test_the_kernel_refuses_parameters_that_differ_from_the_schema(extra, without, message):
    with pytest.raises(TypeError, match=message):
        Kernel(_params_with(extra, without))


def test_the_kernel_takes_the_members_from_the_parameters():
    """Any dataclass with the schema's fields fills the struct as a PlatformParams does, and
    G (eqs. 72-76) is linear in the gravity member it was given."""
    params = stewart.PlatformParams.preset("narayan2017")
    x = stewart.home_pose(params)
    g = Kernel(params).gravity_vector(x)
    assert np.array_equal(Kernel(_params_with()).gravity_vector(x), g)
    lunar = Kernel(params.replace(gravity=1.62)).gravity_vector(x)
    # reached 2.5e-17 (on a 0.03 N m moment; the 118.6 N force exact)
    np.testing.assert_allclose(lunar, g * 1.62 / params.gravity, rtol=0, atol=2e-15)


def test_the_parameter_header_refuses_a_field_outside_the_schema():
    with pytest.raises(TypeError, match="dummy_offsets"):
        capi.params_initializer(_params_with((("dummy_offsets", np.zeros((2, 4))),)))
