"""The command line's Config and map flags reach the scene (gen/cli/flags.py): Python
mutants (docs/mutation.md, make mutate-py) that survived the CLI's other tests."""

from bumprtl.gen.cli.flags import scene_from_args
from bumprtl.gen.cli.main import build_parser


def _scene(*argv):
    args = build_parser().parse_args(["emit", "pipeline", *argv])
    return scene_from_args(args, "default")


def test_texture_size_flag_is_an_integer_that_sets_the_scene():
    assert _scene("--texture-size", "32").texture_size == 32


def test_config_flags_reach_the_scene():
    scene = _scene("--angle-bits", "12", "--frac-bits", "11", "--no-specular", "--tag-bits", "9")
    assert (scene.angle_bits, scene.frac_bits, scene.specular, scene.tag_bits) == (12, 11, False, 9)


def test_the_program_is_named_bumprtl():
    assert build_parser().prog == "bumprtl"
