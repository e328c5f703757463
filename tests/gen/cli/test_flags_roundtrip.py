"""gen/cli/flags.py against what it promises: every Config field has a flag whose value
reaches the Config unchanged, flags that were not given (or that a parser does not have)
keep the defaults, a scene takes the Config and map flags, the ``extra`` keys, their flags'
names and the ``defaults`` it is given, and the help says what docs/scenes.md says, in
lower case like argparse's own."""

import argparse
import dataclasses
import re
from pathlib import Path

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
from bumprtl.sim.scenes.config import SceneConfig, load_scene_config
from tests.gen.cli.conftest import config_parser

ROOT = Path(__file__).resolve().parents[3]
FIELDS = [f.name for f in dataclasses.fields(Config)]
# a valid value other than the default for each field (out_bits and color_bits allow one)
OTHER = dict(angle_bits=12, frac_bits=13, method="lee", tag_bits=0, out_bits=8, spec_exponent=1024,
             spec_index_bits=16, ka=0.0, kd=1.0, ks=0.375, lights=8, specular=False,
             palette_size=16384, color_bits=8, palette_blend=True)


def _flag(name):
    return "--" + name.replace("_", "-")


def _argv(values):
    """The command line that asks for ``values`` ({field: value})."""
    argv = []
    for name, value in values.items():
        if isinstance(value, bool):
            argv.append(_flag(name) if value else "--no-" + name.replace("_", "-"))
        else:
            argv += [_flag(name), str(value)]
    return argv



def test_other_values_cover_every_field():
    assert set(OTHER) == set(FIELDS)


@pytest.mark.parametrize("name", FIELDS)
def test_each_config_flag_round_trips_into_the_config(name):
    """``--field VALUE`` (``--field`` / ``--no-field`` for a switch) gives the Config with
    that field, of the field's type, and every other field at its default."""
    got = config_from_args(config_parser().parse_args(_argv({name: OTHER[name]})))
    assert got == Config(**{name: OTHER[name]})
    assert type(getattr(got, name)) is type(getattr(Config(), name))


def test_all_config_flags_at_once_round_trip():
    """A Config written as flags and read back is the same Config, also over a base."""
    cfg = Config(**OTHER)
    assert config_from_args(config_parser().parse_args(_argv(OTHER))) == cfg
    assert config_from_args(config_parser().parse_args(_argv(OTHER)), Config(angle_bits=16)) == cfg


def test_both_spellings_of_a_switch_override_the_base():
    """``--specular`` sets True and ``--no-specular`` False whatever the base says."""
    p = config_parser()
    assert config_from_args(p.parse_args(["--specular"]), Config(specular=False)).specular is True
    assert config_from_args(p.parse_args(["--no-specular"]), Config()).specular is False
    assert config_from_args(p.parse_args(["--palette-blend"])).palette_blend is True


@pytest.mark.parametrize("argv, field", [
    (["--angle-bits", "3"], "angle_bits"), (["--frac-bits", "25"], "frac_bits"),
    (["--tag-bits", "33"], "tag_bits"), (["--ks", "1.5"], "ks"), (["--method", "cordic"], "method"),
    (["--lights", "9"], "lights"), (["--palette-size", "15"], "palette_size"),
    (["--out-bits", "9"], "out_bits"), (["--angle-bits", "12", "--frac-bits", "8"], "frac_bits")])
def test_a_config_flag_out_of_range_is_refused_naming_its_field(argv, field):
    """A value the Config refuses is a BumpError naming the field (not an argparse error)."""
    args = config_parser().parse_args(argv)
    with pytest.raises(BumpError) as e:
        config_from_args(args)
    assert e.value.field == field and field in str(e.value)


def test_config_from_args_reads_only_the_flags_the_parser_has():
    """With ``fields`` the parser has some flags only; the rest of the Config keeps the base
    (a Namespace without the attribute is a flag not given)."""
    p = config_parser(fields=["angle_bits"])
    assert config_from_args(p.parse_args(["--angle-bits", "12"])) == Config(angle_bits=12)
    assert config_from_args(argparse.Namespace()) == Config()
    base = Config(ks=0.5)
    assert config_from_args(argparse.Namespace(lights=2), base) == base.replace(lights=2)


def test_a_config_flag_with_a_wrong_type_is_an_argparse_error():
    """Each non-switch flag converts its value to the field's type: a word for an integer
    or a number is refused by the parser."""
    p = config_parser()
    for flag in ("--angle-bits", "--ka", "--palette-size"):
        with pytest.raises(argparse.ArgumentError):
            p.parse_args([flag, "twelve"])


def test_map_overrides_of_a_namespace_without_map_flags_is_empty():
    """A command without the map flags gives no map keys; the given ones come back as keys."""
    assert map_overrides(argparse.Namespace()) == {}
    assert map_overrides(argparse.Namespace(texture_size=32, angle_bits=12)) == {"texture_size": 32}


def test_scene_from_args_without_any_flags_is_the_source():
    """No flag given, or a Namespace without the flags, gives the scene as the source has it."""
    p = config_parser()
    add_map_flags(p)
    assert scene_from_args(p.parse_args([]), "default") == load_scene_config("default")
    assert scene_from_args(argparse.Namespace(), "default") == load_scene_config("default")


def test_scene_from_args_takes_extra_keys_and_defaults():
    """``extra`` keys apply like flags; ``defaults`` fill only keys nothing else sets."""
    ns = argparse.Namespace()
    assert scene_from_args(ns, {}, extra={"texture_size": 32}).texture_size == 32
    assert scene_from_args(ns, {}, defaults={"texture_size": 32}).texture_size == 32
    assert scene_from_args(ns, {"texture_size": 128}, defaults={"texture_size": 32}).texture_size == 128
    assert scene_from_args(argparse.Namespace(texture_size=16), {},
                           defaults={"texture_size": 32}).texture_size == 16


def test_an_extra_key_that_contradicts_the_source_names_the_flag_that_set_it():
    """``flags`` names the flag of each ``extra`` key in the message (else --key)."""
    ns = argparse.Namespace()
    with pytest.raises(BumpError) as e:
        scene_from_args(ns, {"texture_size": 32}, extra={"texture_size": 64},
                        flags={"texture_size": "--map-side"})
    assert str(e.value).startswith("--map-side 64 ") and "texture_size = 32" in str(e.value)
    with pytest.raises(BumpError) as e:
        scene_from_args(ns, {"texture_size": 32}, extra={"texture_size": 64})
    assert str(e.value).startswith("--texture-size 64 ")


@pytest.mark.parametrize("name", sorted(set(FIELDS) - {f.name for f in dataclasses.fields(SceneConfig)}))
def test_a_config_flag_the_scene_decides_is_one_line_naming_flag_and_source(name):
    """A Config field that is not a scene key is refused for a scene: the message names the
    flag and the source and says where the scene keys are."""
    p = config_parser()
    with pytest.raises(BumpError) as e:
        scene_from_args(p.parse_args(_argv({name: OTHER[name]})), "default")
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(_flag(name) + " ")
    assert "'default'" in msg and "sim/scenes/config.py" in msg


def _words(text):
    return " ".join(text.split())


def _map_parser():
    p = argparse.ArgumentParser(prog="t")
    add_map_flags(p)
    return p, {a.dest: a for a in p._actions if a.dest in MAP_FLAGS}


def _docs_section():
    text = (ROOT / "docs/scenes.md").read_text()
    return _words(text.split("## Your own bump map", 1)[1].split("\n## ", 1)[0])


# What docs/scenes.md ("Your own bump map") says of each flag, as the help must say it too.
DOCUMENTED = {
    "height_map": ["8- or 16-bit greyscale PNG (white = 1.0)", "array of heights", "Tarini",
                   "least-squares plane fit", "Sec. 4.1"],
    "normal_map": ["8-bit RGB", "tangent-space normal map", "(T, T, 3)", "re-normalized",
                   "blue = +z out of the surface"],
    "normal_convention": ["opengl", "directx"],
    "geometry": ["plane"],
    "resample": ["power-of-two side in [16, 4096]", "never cropped"],
    "texture_size": ["[16, 4096]"],
}


def test_map_flag_help_says_what_docs_scenes_md_says():
    """Each fragment docs/scenes.md gives for a flag is in the flag's help."""
    _, acts = _map_parser()
    for dest, fragments in DOCUMENTED.items():
        for fragment in fragments:
            assert fragment in _words(acts[dest].help), (dest, fragment)


def test_the_documented_fragments_are_in_docs_scenes_md():
    """DOCUMENTED quotes docs/scenes.md's section "Your own bump map", not the help."""
    docs = _docs_section()
    for fragments in DOCUMENTED.values():
        for fragment in fragments:
            assert fragment in docs, fragment


def test_map_flag_help_states_the_default_last():
    """A map flag with a default ends its help with it, ``(default: ...)``, as argparse's
    own help does: opengl, the scene's own geometry (a map's: plane), 4 texels of relief,
    the map's size."""
    _, acts = _map_parser()
    ends = {"normal_convention": "(default: opengl)", "height_scale": "(default: 4)",
            "geometry": "a map: plane)", "texture_size": "or the scene's)"}
    for dest, end in ends.items():
        help_ = _words(acts[dest].help)
        assert help_.endswith(end) and "(default: " in help_, (dest, help_)


def test_map_flag_help_names_what_the_flag_is_first():
    """The help opens with what the value is (a height map, a tangent-space normal map, the
    green channel, the surface, the texels of relief, resampling, the bump map size T)."""
    _, acts = _map_parser()
    opens = {"height_map": "height map", "normal_map": "tangent-space normal map",
             "normal_convention": "green channel of --normal-map", "geometry": "surface",
             "height_scale": "texels of relief", "resample": "resample",
             "texture_size": "bump map size T"}
    for dest, start in opens.items():
        assert acts[dest].help.startswith(start), (dest, acts[dest].help)


def test_map_flags_are_grouped_under_the_docs_section_title():
    """``--help`` lists the map flags in a group named like docs/scenes.md's section, "your
    own bump map", with the module that reads the maps, in lower case like "options"."""
    p, acts = _map_parser()
    [group] = [g for g in p._action_groups if acts["height_map"] in g._group_actions]
    assert group.title == group.title.lower()
    assert group.title.startswith("your own bump map") and "(sim/scenes/usermap.py)" in group.title
    assert {a.dest for a in group._group_actions} == set(MAP_FLAGS)
    assert group.title + ":" in p.format_help()


# Capitals in a help line: only acronyms, single-letter names (T, S, +Y) and sentence-case words.
ACRONYMS = {"PNG", "RGB"}


def _shouting(text):
    return [w for w in re.findall(r"[A-Z]{2,}", text) if w not in ACRONYMS]


def test_help_texts_are_lower_case_but_acronyms():
    """Help lines, group titles and the description are written in lower case like
    argparse's own (acronyms such as PNG and RGB aside), never in capitals."""
    p, acts = _map_parser()
    texts = [a.help for a in acts.values()] + [g.title for g in p._action_groups]
    texts += [a.help for a in config_parser()._actions if a.dest in FIELDS]
    texts.append(cli_main.build_parser().description)
    for text in texts:
        assert not _shouting(text), text


def test_the_description_names_both_papers_as_pyproject_does():
    """``bumprtl --help`` describes the project with both papers, Lee et al. 2003 (the
    angular operation) and Tarini et al. 2000 (quantized normal maps), in parentheses."""
    d = _words(cli_main.build_parser().description)
    assert re.search(r"\(Lee et al\. 2003 [a-z ]+; Tarini et al\. 2000 [a-z ]+\)\.$", d), d
