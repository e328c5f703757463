"""SceneConfig: built-in scenes, TOML files, and bad input naming the key."""

import dataclasses
import math

import pytest

from bumprtl.gen.cli.main import main
from bumprtl.rtl import methods
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.scene import HardwareScene
from bumprtl.sim.scenes.config import BUILTIN, SceneConfig, load_scene_config


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


def test_flat_map_and_lights_follow_the_registry(monkeypatch):
    """A flat map and several lights need a method whose registry record rotates N' (one
    n'' shared); the scene reads ``Method.rotates_normal``, never the method's name."""
    for keys, field in (({"lights": 2}, "lights"), ({"bump_map": "flat"}, "bump_map")):
        with pytest.raises(BumpError) as e:
            SceneConfig(method="lee", **keys)
        assert e.value.field == field and "'exact'" in str(e.value)
    assert SceneConfig(method="lee", lights=2, shading="palette").lights == 2
    for name, rotates in (("lee", True), ("exact", False)):
        monkeypatch.setitem(methods.METHODS, name,
                            dataclasses.replace(methods.METHODS[name], rotates_normal=rotates))
    assert SceneConfig(method="lee", lights=2, bump_map="flat").rotation == "per-polygon"
    with pytest.raises(BumpError, match="lights = 2 needs method = 'lee'"):
        SceneConfig(lights=2)


# SceneConfig's ranges (its docstring), each refused one step outside on both sides with the
# key named (BumpError.field, not the wording) and accepted at both ends; the Config keys a
# scene passes on keep their names. texture_size is a power of two, so its neighbours
# outside are also the next powers of two; mip_levels runs to log2(T) + 1.
SCENE_RANGES = [
    ("lights", 1, 8, [0, 9], {}),
    ("texture_size", 16, 4096, [15, 4097, 8, 8192], {}),
    ("mip_levels", 1, 7, [0, 8], {"texture_size": 64}),
    ("mip_levels", 1, 5, [0, 6], {"texture_size": 16}),
    ("texture_height", 16, 64, [15, 65, 8, 128, 48], {"texture_size": 64}),
    ("mip_levels", 1, 5, [0, 6], {"texture_size": 64, "texture_height": 16}),
    ("angle_bits", 4, 16, [3, 17], {}),
    ("spec_index_bits", 4, 16, [3, 17], {}),
    ("spec_exponent", 1, 1024, [0, 1025], {}),
    ("palette_size", 16, 16384, [15, 16385], {}),
]


@pytest.mark.parametrize("key, lo, hi, outside, base", SCENE_RANGES,
                         ids=[f"{r[0]}-{r[1]}-{r[2]}" for r in SCENE_RANGES])
def test_every_scene_range_is_checked_on_both_sides(key, lo, hi, outside, base):
    for value in (lo, hi):
        assert getattr(load_scene_config({"name": "t", **base, key: value}), key) == value
    for value in outside:
        with pytest.raises(BumpError) as e:
            load_scene_config({"name": "t", **base, key: value})
        assert e.value.field == key, (value, str(e.value))


@pytest.mark.parametrize("key, value", [("bump_map", "bumpy"), ("shading", "flat"),
                                        ("addressing", "mirror"), ("specular", "yes"),
                                        ("texture", 1), ("rotation", "sideways"),
                                        ("geometry", "cube"), ("normal_convention", "left")])
def test_bad_choice_names_the_key(key, value):
    with pytest.raises(BumpError) as e:
        load_scene_config({"name": "t", key: value})
    assert e.value.field == key


# Every numeric scene key at both ends of its documented range (SceneConfig's docstring;
# the Config keys a scene passes on: Config's), each end accepted and one step past it
# refused with the key named; floats also at the nearest float outside. The lower end of
# frac_bits depends on angle_bits (k - 1 for k = angle_bits - 2, at least 4), so angle_bits
# is given. height_scale is the open range (0, inf): the ends themselves are refused.
SCENE_ENDS = [
    ("lights", 1, 8, [0, 9], {}),
    ("angle_bits", 4, 16, [3, 17], {}),
    ("frac_bits", 9, 24, [8, 25], {"angle_bits": 12}),
    ("frac_bits", 13, 24, [12, 25], {"angle_bits": 16}),
    ("frac_bits", 4, 24, [3, 25], {"angle_bits": 4}),
    ("tag_bits", 0, 32, [-1, 33], {}),
    ("spec_exponent", 1, 1024, [0, 1025], {}),
    ("spec_index_bits", 4, 16, [3, 17], {}),
    ("palette_size", 16, 16384, [15, 16385], {}),
    *[(k, 0.0, 1.0, [-1e-9, 1 + 1e-9, math.nextafter(0.0, -1), math.nextafter(1.0, 2)], {})
      for k in ("ka", "kd", "ks")],
    *[("mip_levels", 1, t.bit_length(), [0, t.bit_length() + 1], {"texture_size": t})
      for t in (16, 32, 64, 128, 256, 512, 1024, 2048, 4096)],
    *[("texture_height", 16, t, [8, 2 * t], {"texture_size": t}) for t in (16, 4096)],
    *[("mip_levels", 1, h.bit_length(), [0, h.bit_length() + 1],
       {"texture_size": 4096, "texture_height": h}) for h in (16, 1024)],
]


@pytest.mark.parametrize("key, lo, hi, outside, base", SCENE_ENDS,
                         ids=[f"{r[0]}-{r[1]}-{r[2]}" for r in SCENE_ENDS])
def test_every_scene_parameter_at_both_ends(key, lo, hi, outside, base):
    for value in (lo, hi):
        assert getattr(SceneConfig(name="t", **base, **{key: value}), key) == value
    for value in outside:
        with pytest.raises(BumpError) as e:
            SceneConfig(name="t", **base, **{key: value})
        assert e.value.field == key and "\n" not in str(e.value), (value, str(e.value))


def test_height_scale_is_an_open_range():
    """(0, inf): the smallest positive float and the largest finite one are accepted; 0,
    -0.0, a negative number, infinity and NaN are refused, naming height_scale."""
    for h in (math.nextafter(0.0, 1), 1e-9, 4, 1e300, math.nextafter(math.inf, 0)):
        assert SceneConfig(name="t", height_scale=h).height_scale == h
    for h in (0, 0.0, -0.0, -1e-300, -4, math.inf, -math.inf, math.nan, True):
        with pytest.raises(BumpError) as e:
            SceneConfig(name="t", height_scale=h)
        assert e.value.field == "height_scale" and "\n" not in str(e.value), (h, str(e.value))


def test_a_user_map_replaces_the_image():
    """A height or normal map given: the scene's image is None (the map is the picture)."""
    for key in ("height_map", "normal_map"):
        scene = SceneConfig(name="t", **{key: "some/map.png"})
        assert scene.image is None and getattr(scene, key) == "some/map.png"


@pytest.mark.parametrize("keys, rotation, cause", [
    ({"bump_map": "flat"}, "per-pixel", "bump_map"),
    ({"bump_map": "varying"}, "per-polygon", "bump_map"),
    ({"shading": "palette"}, "per-pixel", "shading"),
])
def test_impossible_rotation_names_the_key_that_rules_it_out(keys, rotation, cause):
    """rotation is derived from shading and bump_map; a rotation that contradicts them is
    refused in one line naming rotation, the key that rules it out and the allowed value."""
    allowed = SceneConfig(**keys).rotation
    with pytest.raises(BumpError) as e:
        SceneConfig(**keys, rotation=rotation)
    msg = str(e.value)
    assert "\n" not in msg and "rotation" in msg and cause in msg and repr(allowed) in msg, msg


def test_replace_changes_the_given_keys_only_and_validates_them():
    scene = load_scene_config("default")
    before = scene.to_dict()
    got = scene.replace(texture_size=32, ks=0.25)
    want = {**before, "texture_size": 32, "ks": 0.25}
    assert got.to_dict() == want
    assert scene.to_dict() == before                    # the original is left as it was
    with pytest.raises(BumpError) as e:
        scene.replace(texture_size=48)
    assert e.value.field == "texture_size"


def test_replace_derives_the_rotation_again():
    """The rotation follows bump_map unless given: a flat map's scene turned back to a
    varying map rotates per pixel again (the old per-polygon value is not carried over)."""
    flat = load_scene_config("default", {"bump_map": "flat"})
    assert flat.rotation == "per-polygon"
    assert flat.replace(bump_map="varying").rotation == "per-pixel"
    assert load_scene_config("default").replace(bump_map="flat").rotation == "per-polygon"


def test_replace_with_a_map_drops_the_scenes_picture_and_other_map(tmp_path):
    import numpy as np

    heights = tmp_path / "h.npy"
    np.save(heights, np.add.outer(np.arange(16.0), np.arange(16.0)) % 5 / 4)
    normals = tmp_path / "n.npy"
    n = np.zeros((16, 16, 3))
    n[..., 2] = 1.0
    n[3, 4] = (0.6, 0.0, 0.8)
    np.save(normals, n)
    scene = load_scene_config("default", {"texture_size": 16})
    assert scene.image == "bricks"
    mine = scene.replace(height_map=str(heights))
    assert (mine.image, mine.height_map, mine.normal_map) == (None, str(heights), None)
    other = mine.replace(normal_map=str(normals))
    assert (other.image, other.height_map, other.normal_map) == (None, None, str(normals))
    # a change that is not a map keeps the map
    assert mine.replace(ks=0.3).height_map == str(heights)


@pytest.mark.parametrize("keys, words", [
    ({"name": 3}, ["name", "string", "3"]),
    ({"bump_map": "bumpy"}, ["bump_map", "varying, flat", "'bumpy'"]),
    ({"shading": "gouraud"}, ["shading", "per-pixel, palette", "'gouraud'"]),
    ({"addressing": "mirror"}, ["addressing", "wrap, clamp", "'mirror'"]),
    ({"specular": 1}, ["specular", "true or false", "1"]),
    ({"texture": None}, ["texture", "true or false", "None"]),
    ({"resample": "no"}, ["resample", "true or false", "'no'"]),
    ({"lights": 0}, ["lights", "[1, 8]", "0"]),
    ({"texture_size": 48}, ["texture_size", "power of two", "[16, 4096]", "48"]),
    ({"mip_levels": 8}, ["mip_levels", "[1, 7]", "64", "8"]),
    ({"angle_bits": 40}, ["angle_bits", "[4, 16]", "40"]),
    ({"method": "kim"}, ["method", "exact, lee", "'kim'"]),
    ({"method": "lee", "bump_map": "flat"}, ["bump_map = 'flat'", "method = 'exact'", "'lee'"]),
    ({"method": "lee", "lights": 2}, ["lights = 2", "method = 'exact'", "lee"]),
    ({"height_map": ""}, ["height_map", "file path", "''"]),
    ({"height_map": "a.png", "normal_map": "b.png"}, ["height_map", "normal_map", "not both"]),
    ({"image": "nope"}, ["image", "bricks", "globe", "height_map", "'nope'"]),
    ({"normal_convention": "up"}, ["normal_convention", "opengl, directx", "'up'"]),
    ({"geometry": "torus"}, ["geometry", "plane, sphere, cylinder", "'torus'"]),
    ({"height_scale": 0.0}, ["height_scale", "positive finite", "0.0"]),
    ({"height_map": "a.png", "bump_map": "flat"}, ["height_map", "bump_map = 'varying'"]),
    ({"rotation": "per-polygon"}, ["rotation = 'per-polygon'", "bump_map = 'varying'", "'per-pixel'"]),
    ({"rotation": "diagonal"}, ["rotation", "per-pixel, per-polygon, none", "'diagonal'"]),
    ({"shading": "palette", "rotation": "per-pixel"}, ["rotation = 'per-pixel'", "shading = 'palette'",
                                                       "colour table", "'none'"]),
])
def test_every_refusal_names_the_key_the_value_and_what_is_allowed(keys, words):
    """One line naming the parameter, the value given and the allowed values or range (the
    CLI prints it as it is)."""
    with pytest.raises(BumpError) as e:
        SceneConfig(**keys)
    msg = str(e.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, (w, msg)


def test_a_users_map_sets_the_texture_size_and_refuses_a_second_picture(tmp_path):
    """A map without texture_size gives the map's own size (the scene's default 64 does not
    apply to it); a scene file naming an image and a map, or a height map with
    normal_convention, is refused naming both keys."""
    import numpy as np

    path = tmp_path / "h.npy"
    np.save(path, np.add.outer(np.arange(32.0), np.arange(32.0)) % 7 / 6)
    assert load_scene_config("default", {"height_map": str(path)}).texture_size == 32
    f = tmp_path / "both.toml"
    f.write_text(f'image = "wood"\nheight_map = "{path}"\n')
    with pytest.raises(BumpError) as e:
        load_scene_config(f)
    assert "image = 'wood'" in str(e.value) and "height_map" in str(e.value)
    with pytest.raises(BumpError) as e:
        load_scene_config("default", {"height_map": str(path), "normal_convention": "directx"})
    assert "normal_convention" in str(e.value) and "normal map" in str(e.value)


def test_a_users_map_at_another_texture_size_is_resampled_or_refused(tmp_path):
    import numpy as np

    path = tmp_path / "h.npy"
    np.save(path, np.add.outer(np.arange(16.0), np.arange(16.0)) % 5 / 4)
    scene = load_scene_config("default", {"height_map": str(path), "texture_size": 32, "resample": True})
    assert scene.texture_size == 32
    with pytest.raises(BumpError) as e:
        load_scene_config("default", {"height_map": str(path), "texture_size": 32})
    assert "texture_size = 32" in str(e.value) and "16x16" in str(e.value)


def test_a_scene_files_map_path_is_relative_to_the_file(tmp_path, monkeypatch):
    import numpy as np

    (tmp_path / "maps").mkdir()
    np.save(tmp_path / "maps" / "h.npy", np.add.outer(np.arange(16.0), np.arange(16.0)) % 5 / 4)
    f = tmp_path / "scene.toml"
    f.write_text('height_map = "maps/h.npy"\n')
    monkeypatch.chdir(tmp_path / "maps")                    # not where the file is
    scene = load_scene_config(f)
    assert scene.height_map == str(tmp_path / "maps" / "h.npy") and scene.texture_size == 16


def test_messages_name_the_source_of_the_key():
    """An unknown key or a contradicting flag names where the key came from: a scene given
    as keys, a built-in scene, a TOML file."""
    with pytest.raises(BumpError, match=r"unknown key 'nosuch' in scene: allowed keys"):
        load_scene_config({"name": "t", "nosuch": 1})
    with pytest.raises(BumpError, match=r"--lights 1 contradicts lights = 2 in built-in scene "
                                        r"'two-lights': drop one"):
        load_scene_config("two-lights", overrides={"lights": 1}, flags={"lights": "--lights"})


def test_a_scene_config_loads_as_itself_and_takes_overrides():
    """load_scene_config of a SceneConfig gives the same scene, also with overrides that
    agree with it (its rotation derived again), and refuses one that contradicts it."""
    for scene in (load_scene_config("textured"),
                  load_scene_config({"name": "t", "lights": 2, "addressing": "clamp"})):
        assert load_scene_config(scene) == scene
    textured = load_scene_config("textured")
    assert load_scene_config(textured, overrides={"lights": 1, "image": "bricks"}) == textured
    with pytest.raises(BumpError, match=r"--lights 2 contradicts lights = 1"):
        load_scene_config(textured, overrides={"lights": 2})


def test_only_a_second_picture_clashes_with_the_scenes_picture(tmp_path):
    """A flag for any other key leaves a scene's picture alone; a second picture (a map
    beside the scene's image) is refused, naming both."""
    assert load_scene_config("textured", overrides={"lights": 2}).lights == 2
    with pytest.raises(BumpError, match=r"--height-map .* contradicts image = 'bricks' in "
                                        r"built-in scene 'textured': give the picture once"):
        load_scene_config("textured", overrides={"height_map": str(tmp_path / "h.png")},
                          flags={"height_map": "--height-map"})


def test_defaults_fill_only_the_keys_nothing_sets():
    """``defaults`` are used where neither the source nor an override sets a key; a default
    of None sets nothing (the scene's own default holds)."""
    assert load_scene_config({"name": "t"}, defaults={"texture_size": 32}).texture_size == 32
    assert load_scene_config({"name": "t", "texture_size": 128},
                             defaults={"texture_size": 32}).texture_size == 128
    assert load_scene_config({"name": "t"}, overrides={"texture_size": 16},
                             defaults={"texture_size": 32}).texture_size == 16
    own = SceneConfig().texture_size
    assert load_scene_config({"name": "t"}, defaults={"texture_size": None}).texture_size == own


@pytest.mark.parametrize("name", BUILTIN)
def test_the_scene_composes_its_hardware(name):
    """``SceneConfig.hardware`` carries the switches the hardware reads and nothing of the
    map's source: two scenes that differ only in picture or geometry build the same hardware."""
    scene = load_scene_config(name)
    hw = scene.hardware
    assert isinstance(hw, HardwareScene) and hw.config == scene.config
    for key in ("name", "shading", "bump_map", "rotation", "texture", "texture_size",
                "addressing", "mip_levels", "lights", "specular", "texture_bits"):
        assert getattr(hw, key) == getattr(scene, key), key
    other = scene.replace(image="wood" if scene.image != "wood" else "bricks",
                          geometry="sphere")
    assert other.hardware == hw
    assert scene.replace(texture_size=32).hardware != hw
