"""The command line and rotary rigs: every command either serves them (its ``--preset`` offers
the rotary presets) or refuses a rotary rig's parameter file in one line naming itself."""

import argparse

import pytest

import stewart
from stewart.cli import build_parser
from stewart.model.rotary_presets import presets as rotary_presets

from cli_run import call


def _commands():
    """(name, serves rotary rigs, the arguments argparse requires) of every command with
    ``--params``: missing files for the positionals, ``1`` for required options."""
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    found = []
    for name, parser in sub.choices.items():
        options = {o for a in parser._actions for o in a.option_strings}
        if "--params" not in options:
            continue
        preset = next(a for a in parser._actions if "--preset" in a.option_strings)
        required = [str(p) for a in parser._actions if not a.option_strings and a.nargs not in ("?", "*")
                    for p in [a.dest]]
        required += [w for a in parser._actions if a.option_strings and a.required
                     for w in [a.option_strings[0]] + ["1"] * (a.nargs if isinstance(a.nargs, int) else 1)]
        found.append((name, set(rotary_presets()) <= set(preset.choices), required))
    return found


COMMANDS = _commands()


def _rotary_only():
    """The commands of rotary rigs only: their ``--preset`` defaults to a rotary preset."""
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return sorted(name for name, parser in sub.choices.items() for a in parser._actions
                  if "--preset" in a.option_strings and a.default in rotary_presets())


ROTARY_ONLY = _rotary_only()


def test_commands_found():
    names = {name for name, _, _ in COMMANDS}
    assert {"id", "simulate", "cueing", "envelope", "workspace", "c-export"} <= names


@pytest.mark.parametrize("name", [n for n, serves, _ in COMMANDS if not serves])
def test_linear_only_commands_refuse_rotary_files(name, tmp_path):
    """Before reading anything else: one line on stderr naming the file and the command, exit 2."""
    path = tmp_path / "rig.toml"
    stewart.RotaryParams.preset("simrig100").save(path)
    required = next(args for n, _, args in COMMANDS if n == name)
    args = [a if a.startswith("-") or a == "1" else tmp_path / f"missing-{a}" for a in required]
    result = call(name, *args, "--params", path)
    assert result.returncode == 2, (name, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert lines == [f"stewart {name}: error: --params {path}: a rotary rig's parameter file "
                     f'(kind = "rotary"); stewart {name} serves linear platforms only'], result.stderr
    assert result.stdout == ""


@pytest.mark.parametrize("name", [n for n, serves, _ in COMMANDS if not serves])
def test_linear_only_commands_offer_linear_presets_only(name):
    result = call(name, "--preset", "simrig100")
    assert result.returncode == 2 and "invalid choice: 'simrig100'" in result.stderr


def test_presets_lists_both_families():
    out = call("presets").stdout
    for name in list(stewart.presets()) + list(rotary_presets()):
        assert any(line.split()[0] == name for line in out.splitlines()), name
    assert sum("rotary rig:" in line for line in out.splitlines()) == len(rotary_presets())


def test_rotary_only_commands_found():
    assert {"motor-sizing", "servo-angles", "fk"} <= set(ROTARY_ONLY)
    assert set(ROTARY_ONLY) <= {name for name, serves, _ in COMMANDS if serves}


@pytest.mark.parametrize("name", ROTARY_ONLY)
def test_rotary_only_commands_refuse_linear_platforms(name, tmp_path):
    """Before reading anything else: one line on stderr naming the preset or file, exit 2."""
    path = tmp_path / "linear.toml"
    stewart.PlatformParams.preset("narayan2017").save(path)
    required = next(args for n, _, args in COMMANDS if n == name)
    args = [a if a.startswith("-") or a == "1" else tmp_path / f"missing-{a}" for a in required]
    for given, what in ((["--params", path], f"--params {path}: a linear platform's parameter file"),
                        (["--preset", "narayan2017"], "--preset narayan2017: a linear platform")):
        result = call(name, *args, *given)
        assert result.returncode == 2, (name, result.stderr)
        assert result.stderr.strip().splitlines() == [f"stewart {name}: error: {what}; stewart {name} serves "
                                                      "rotary rigs only"], result.stderr
        assert result.stdout == ""
