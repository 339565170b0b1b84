"""The fixed C of the generated model is real C: each template in codegen/templates compiles
on its own (against the generated header) under the strictest flags the model promises, and
the generated source carries it verbatim."""

import os
import pathlib

import pytest
from c_example import CFLAGS, run_command

ROOT = pathlib.Path(__file__).resolve().parent.parent
TEMPLATES = sorted((ROOT / "codegen" / "templates").glob("*.[ch]"))


#: The template every other one follows in the generated source: the lane-wise arithmetic.
LANES = ROOT / "codegen" / "templates" / "lanes.c"


def test_there_are_templates():
    assert [t.name for t in TEMPLATES] == ["control.c", "lanes.c", "public.c", "runtime.c", "vector.c"]


@pytest.mark.parametrize("template", TEMPLATES, ids=lambda t: t.name)
def test_template_compiles_on_its_own(template, tmp_path):
    """Each template after the lane-wise arithmetic, as the generated source has them (one that
    includes the header the units share, which holds the lane-wise arithmetic, on its own)."""
    source = tmp_path / template.name
    shared = '#include "stewart_internal.h"' in template.read_text()
    source.write_text(("" if shared else LANES.read_text()) + ("" if template == LANES else template.read_text()))
    # A template's static helpers are used by the generated functions, not by itself.
    run_command([os.environ.get("CC", "cc"), *CFLAGS, "-Wno-unused-function", "-fsyntax-only",
                 f"-I{ROOT / 'generated'}", source])


@pytest.mark.parametrize("template", TEMPLATES, ids=lambda t: t.name)
def test_generated_source_carries_the_template(template):
    """In the public functions' unit, or in the header the units share."""
    generated = ROOT / "generated"
    assert template.read_text() in (generated / "stewart_model.c").read_text() + (
        generated / "stewart_internal.h").read_text()
