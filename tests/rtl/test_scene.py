"""SceneConfig: built-in scenes, TOML files, and bad input naming the key."""

import pytest

from bumprtl.gen.cli.main import main
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.scene import BUILTIN, SceneConfig, load_scene_config


@pytest.mark.parametrize("name", list(BUILTIN))
def test_builtin_scenes_load(name):
    scene = load_scene_config(name)
    assert scene.name == name and scene.config.lights == scene.lights


def test_toml_file_loads(tmp_path):
    f = tmp_path / "two.toml"
    f.write_text('lights = 2\nspecular = false\naddressing = "clamp"\ntexture_size = 32\n')
    scene = load_scene_config(f)
    assert (scene.lights, scene.specular, scene.addressing, scene.texture_size) == (2, False, "clamp", 32)
    assert scene.rotation == "per-pixel" and not scene.config.specular


@pytest.mark.parametrize("text, key", [
    ("colour = 1", "colour"),                                       # unknown key
    ('shading = "palette"\nrotation = "per-pixel"', "rotation"),    # palette + per-pixel rotation
    ('bump_map = "flat"\nrotation = "per-pixel"', "rotation"),
    ("lights = 0", "lights"),
    ("lights = 9", "lights"),
    ("texture_size = 100", "texture_size"),                         # not a power of two
    ("texture_size = 8", "texture_size"),
    ("mip_levels = 8\ntexture_size = 64", "mip_levels"),
    ('addressing = "mirror"', "addressing"),
    ('specular = "yes"', "specular"),
    ('method = "lee"\nlights = 2', "lights"),
    ('method = "lee"\nbump_map = "flat"', "bump_map"),
    ("angle_bits = 40", "angle_bits"),
    ("lights = [", "TOML"),
])
def test_bad_scene_file_names_the_key(tmp_path, text, key):
    f = tmp_path / "bad.toml"
    f.write_text(text + "\n")
    with pytest.raises(BumpError, match=key) as e:
        load_scene_config(f)
    assert "\n" not in str(e.value)


def test_unknown_builtin_lists_the_choices():
    with pytest.raises(BumpError, match="default"):
        load_scene_config("no-such-scene")


def test_cli_bad_scene_is_one_line_exit_2(tmp_path, capsys):
    f = tmp_path / "bad.toml"
    f.write_text('shading = "palette"\nrotation = "per-pixel"\n')
    assert main(["emit", "pipeline", "--scene", str(f), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "rotation" in err[0]


def test_derived_rotation():
    assert SceneConfig(bump_map="flat").rotation == "per-polygon"
    assert SceneConfig(shading="palette").rotation == "none"
    assert SceneConfig().rotation == "per-pixel"
