"""The command line's Config and map flags reach the scene (gen/cli/flags.py): Python
mutants (docs/mutation.md, make mutate-py) that survived the CLI's other tests."""

import pytest

from bumprtl.gen.cli.flags import scene_from_args
from bumprtl.gen.cli.main import build_parser, main


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


@pytest.mark.parametrize("argv, flag", [
    (["emit", "pipeline", "--angle-bits", "twelve"], "--angle-bits"),
    (["emit", "pipeline", "--texture-size", "1.5"], "--texture-size"),
    (["emit", "pipeline", "--no-such-flag"], "--no-such-flag"),
])
def test_a_bad_flag_is_one_error_line_on_stderr_exit_2(capsys, argv, flag):
    """A flag argparse refuses: exit status 2, stdout empty (a pipe of the output stays
    clean), and on stderr one line ``bumprtl: error: ...`` naming the flag."""
    with pytest.raises(SystemExit) as e:
        main(argv)
    assert e.value.code == 2
    out, err = capsys.readouterr()
    assert out == ""
    errors = err.splitlines()
    assert len(errors) == 1 and errors[0].startswith("bumprtl: error:") and flag in errors[0], err
