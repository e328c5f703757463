"""SceneConfig's documented rules that test_config.py leaves unasserted: the derived
properties, each key's type errors, the picture keys, where a scene's keys come from (a
dict, a built-in name, a TOML file) and how overrides, flags and defaults merge."""


import numpy as np
import pytest

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.scenes import SCENES
from bumprtl.sim.scenes.config import BUILTIN, SceneConfig, flag_name, load_scene_config
from bumprtl.sim.scenes.usermap import DEFAULT_HEIGHT_SCALE, write_png


def _refused(key=None, **keys):
    """The one-line SceneError of SceneConfig(**keys), checked to name ``key``."""
    with pytest.raises(BumpError) as e:
        SceneConfig(**keys)
    msg = str(e.value)
    assert "\n" not in msg
    if key is not None:
        assert key in msg, (key, msg)
    return e.value


def _heights(path, t=16, rows=None):
    """A .npy height map of ``rows`` x ``t`` texels that is not flat."""
    rows = t if rows is None else rows
    np.save(path, np.add.outer(np.arange(float(rows)), np.arange(float(t))) % 5 / 4)
    return str(path)


# --- derived properties -------------------------------------------------------------------

def test_picture_is_the_map_file_or_the_image():
    """picture: the user's map file when one is given, else the procedural image's name;
    map_file: (key, path) of the map, None without one."""
    plain = SceneConfig(image="wood")
    assert plain.map_file is None and plain.picture == "wood"
    for key in ("height_map", "normal_map"):
        scene = SceneConfig(**{key: "maps/m.png"})
        assert scene.map_file == (key, "maps/m.png") and scene.picture == "maps/m.png"


@pytest.mark.parametrize("k", range(4, 13))
def test_texture_bits_is_log2_of_the_texture_size(k):
    """texture_bits addresses a texel row by bit slicing: log2(T) bits for T = 2**k."""
    assert SceneConfig(texture_size=2 ** k).texture_bits == k


def test_scene_argument_reproduces_the_scene():
    """scene: the --scene argument is the scene's name (a built-in name or a file path)."""
    for name in BUILTIN:
        assert load_scene_config(name).scene == name


def test_flag_name_is_the_key_with_dashes():
    """flag_name: '--' and the key with '_' written '-'."""
    assert flag_name("texture_size") == "--texture-size"
    assert flag_name("normal_convention") == "--normal-convention"
    assert flag_name("lights") == "--lights"


def test_config_carries_every_datapath_key():
    """config passes method, widths, terms, lights, specular and palette size on as given."""
    keys = dict(method="exact", angle_bits=12, frac_bits=14, tag_bits=3, spec_exponent=32,
                spec_index_bits=8, ka=0.05, kd=0.6, ks=0.35, lights=3, specular=False,
                palette_size=64)
    cfg = SceneConfig(**keys).config
    assert isinstance(cfg, Config)
    for key, value in keys.items():
        assert getattr(cfg, key) == value, key
    assert SceneConfig(method="lee").config.method == "lee"


@pytest.mark.parametrize("texture, shading, blend", [(True, "palette", True), (True, "per-pixel", False),
                                                     (False, "palette", False),
                                                     (False, "per-pixel", False)])
def test_palette_blend_needs_a_texture_and_palette_shading(texture, shading, blend):
    """The palette's eq. 2 blend stage is built only for a colour texture under palette shading."""
    assert SceneConfig(texture=texture, shading=shading).config.palette_blend is blend


def test_defaults_of_a_scene():
    """SceneConfig's documented defaults: bricks, one light, specular, varying map, per-pixel
    shading and rotation, no texture, T = 64, wrap, one mip level, OpenGL normals, the
    image's own geometry, height_scale 4, no resampling."""
    s = SceneConfig()
    assert (s.name, s.image, s.lights, s.specular, s.bump_map, s.shading, s.rotation, s.texture,
            s.texture_size, s.addressing, s.mip_levels) == (
        "default", "bricks", 1, True, "varying", "per-pixel", "per-pixel", False, 64, "wrap", 1)
    assert (s.normal_convention, s.geometry, s.height_scale, s.resample) == ("opengl", None, 4.0, False)
    assert (s.height_map, s.normal_map) == (None, None)
    assert s.height_scale == DEFAULT_HEIGHT_SCALE
    for key in ("method", "angle_bits", "frac_bits", "tag_bits", "spec_exponent",
                "spec_index_bits", "ka", "kd", "ks", "palette_size"):
        assert getattr(s, key) == getattr(Config(), key), key


# --- each key's type and range ------------------------------------------------------------

@pytest.mark.parametrize("value", [64.0, "64", True, None])
def test_texture_size_must_be_an_integer(value):
    """texture_size is an int power of two: a float, a string, a bool are refused naming it."""
    assert _refused("texture_size", texture_size=value).field == "texture_size"


@pytest.mark.parametrize("value", [True, 1.0, "1", -1])
def test_mip_levels_must_be_an_integer_from_one(value):
    """mip_levels is an integer in [1, log2(T) + 1]; True (== 1) and 1.0 are not integers."""
    e = _refused("mip_levels", mip_levels=value)
    assert e.field == "mip_levels" and "[1, 7]" in str(e)


@pytest.mark.parametrize("value", [0, -1, -8])
def test_lights_below_one_are_refused_naming_the_range(value):
    """A scene needs at least one light: the refusal names lights and [1, 8]."""
    e = _refused("lights", lights=value)
    assert e.field == "lights" and "[1, 8]" in str(e) and str(value) in str(e)


def test_no_light_is_refused_by_the_scene_itself():
    """lights = 0: the scene's own refusal (a scene needs at least one light)."""
    assert "needs at least one light" in str(_refused("lights", lights=0))


@pytest.mark.parametrize("value", ["2", 2.0, None])
def test_lights_must_be_an_integer(value):
    assert _refused("lights", lights=value).field == "lights"


def test_one_light_is_allowed_with_either_method():
    """Several lights need a method that rotates N'; one light does not."""
    for method in ("exact", "lee"):
        assert SceneConfig(method=method, lights=1).lights == 1
    assert SceneConfig(method="exact", lights=8).lights == 8


def test_a_baseline_method_is_refused_in_a_scene():
    """The Table 1 baselines are valid Configs but built for the cost comparison only."""
    for method in ("peercy", "ernst", "kim"):
        Config(method=method)
        msg = str(_refused("method", method=method))
        assert "exact, lee" in msg and repr(method) in msg


def test_a_datapath_error_names_the_scene_and_the_key():
    """A key Config refuses is reported for the scene by name, with Config's field."""
    e = _refused("ka", name="mine", ka=1.5)
    assert str(e).startswith("scene 'mine': ") and e.field == "ka" and "[0, 1]" in str(e)


@pytest.mark.parametrize("key", ["height_map", "normal_map"])
@pytest.mark.parametrize("value", [3, b"a.png", ""])
def test_a_map_must_be_a_non_empty_path_string(key, value):
    """height_map / normal_map: a file path (a non-empty string)."""
    msg = str(_refused(key, **{key: value}))
    assert "file path" in msg and repr(value) in msg


@pytest.mark.parametrize("value", [None, 3, "Bricks", ""])
def test_image_must_be_a_procedural_scene(value):
    """Without a map, image must name one of SCENES; the message lists them and the maps."""
    msg = str(_refused("image", image=value))
    assert msg.startswith("image must be one of " + ", ".join(SCENES) + " (or give height_map")
    assert repr(value) in msg


def test_two_maps_are_refused_before_either_is_read():
    """height_map and normal_map together: one line saying to give one, from a dict of keys
    as from SceneConfig (the files are not opened: they need not exist)."""
    for make in (lambda: SceneConfig(height_map="a.png", normal_map="b.png"),
                 lambda: load_scene_config({"name": "t", "height_map": "a.png", "normal_map": "b.png"})):
        with pytest.raises(BumpError) as e:
            make()
        assert str(e.value).startswith("give height_map or normal_map, not both")


def test_a_map_that_is_no_path_is_refused_before_it_is_read():
    with pytest.raises(BumpError, match="height_map must be a file path"):
        load_scene_config({"name": "t", "height_map": 3})


def test_an_impossible_rotation_says_why():
    """The refusal names the rotation, the reason (palette shading's colour table, or the
    bump map) and the one allowed rotation."""
    msg = str(_refused("rotation", shading="palette", rotation="per-pixel"))
    assert msg == ("rotation = 'per-pixel' is impossible with shading = 'palette' looks normals "
                   "up in a colour table: allowed rotation = 'none'")
    msg = str(_refused("rotation", bump_map="flat", rotation="none"))
    assert msg == "rotation = 'none' is impossible with bump_map = 'flat': allowed rotation = 'per-polygon'"


def test_replace_validates_a_given_rotation():
    """replace derives the rotation again unless one is given; a given one is checked."""
    scene = load_scene_config("default")
    with pytest.raises(BumpError, match="rotation = 'per-polygon' is impossible"):
        scene.replace(rotation="per-polygon")
    assert scene.replace(bump_map="flat", rotation="per-polygon").rotation == "per-polygon"


def test_every_procedural_image_and_geometry_is_accepted():
    for image in SCENES:
        assert SceneConfig(image=image).image == image
    for geometry in ("plane", "sphere", "cylinder"):
        assert SceneConfig(geometry=geometry).geometry == geometry
    assert SceneConfig(normal_convention="directx").normal_convention == "directx"


def test_a_users_map_with_a_flat_bump_map_needs_palette_shading():
    """A flat bump map stores no map, so a user's map refuses it, naming the map's key;
    palette shading looks normals up per texel and takes the map with bump_map = 'flat'."""
    for key in ("height_map", "normal_map"):
        msg = str(_refused(key, bump_map="flat", **{key: "m.png"}))
        assert msg.startswith(key) and "bump_map = 'varying'" in msg
        scene = SceneConfig(bump_map="flat", shading="palette", **{key: "m.png"})
        assert scene.rotation == "none" and getattr(scene, key) == "m.png"


@pytest.mark.parametrize("keys, rotation", [({}, "per-pixel"), ({"bump_map": "flat"}, "per-polygon"),
                                            ({"shading": "palette"}, "none"),
                                            ({"shading": "palette", "bump_map": "flat"}, "none")])
def test_a_rotation_that_agrees_with_the_scene_is_accepted(keys, rotation):
    """rotation given explicitly is kept when it is the derived one."""
    assert SceneConfig(rotation=rotation, **keys).rotation == rotation


def test_height_scale_accepts_integers():
    """height_scale is a positive finite number: an int is one."""
    assert SceneConfig(height_scale=2).height_scale == 2


# --- where the keys come from -------------------------------------------------------------

def test_a_toml_scene_is_named_by_its_path_unless_it_names_itself(tmp_path):
    """A scene file without a name key is named by its path (the --scene argument)."""
    f = tmp_path / "mine.toml"
    f.write_text("lights = 2\n")
    scene = load_scene_config(f)
    assert scene.name == str(f) and scene.scene == str(f) and scene.lights == 2
    f.write_text('name = "shiny"\nks = 0.5\n')
    assert load_scene_config(f).name == "shiny"
    assert load_scene_config(str(f)).ks == 0.5


def test_an_unknown_key_in_a_file_names_the_file_and_the_first_key(tmp_path):
    """The first unknown key (sorted) and the file it came from; the allowed keys listed."""
    f = tmp_path / "bad.toml"
    f.write_text("zebra = 1\nalpha = 2\n")
    with pytest.raises(BumpError) as e:
        load_scene_config(f)
    msg = str(e.value)
    assert msg.startswith(f"unknown key 'alpha' in scene file {f}: allowed keys are name, image, ")
    assert "texture_size" in msg and "resample" in msg


def test_a_file_that_is_not_utf8_is_not_valid_toml(tmp_path):
    f = tmp_path / "latin.toml"
    f.write_bytes(b'name = "caf\xe9"\n')
    with pytest.raises(BumpError, match=r"scene file .*latin\.toml: not valid TOML"):
        load_scene_config(f)


@pytest.mark.parametrize("what", ["missing", "directory"])
def test_a_scene_that_is_no_file_lists_the_built_in_scenes(tmp_path, what):
    """Neither a built-in name nor a file: the message lists every built-in scene."""
    source = tmp_path / "nothing.toml" if what == "missing" else tmp_path
    with pytest.raises(BumpError) as e:
        load_scene_config(source)
    msg = str(e.value)
    assert msg.startswith("scene must be a TOML file or one of " + ", ".join(BUILTIN))
    assert msg.endswith(f"got {str(source)!r}")


def test_an_absolute_map_path_in_a_file_is_kept(tmp_path):
    """Only a relative map path is relative to the TOML file's directory."""
    (tmp_path / "maps").mkdir()
    (tmp_path / "scenes").mkdir()
    path = _heights(tmp_path / "maps" / "h.npy")
    f = tmp_path / "scenes" / "s.toml"
    f.write_text(f'height_map = "{path}"\n')
    scene = load_scene_config(f)
    assert scene.height_map == path and scene.texture_size == 16


def test_a_normal_map_path_in_a_file_is_relative_to_the_file(tmp_path, monkeypatch):
    n = np.zeros((16, 16, 3))
    n[..., 2] = 1.0
    n[2, 5] = (0.6, 0.0, 0.8)
    (tmp_path / "maps").mkdir()
    np.save(tmp_path / "maps" / "n.npy", n)
    f = tmp_path / "scene.toml"
    f.write_text('normal_map = "maps/n.npy"\n')
    monkeypatch.chdir(tmp_path / "maps")
    scene = load_scene_config(f)
    assert scene.normal_map == str(tmp_path / "maps" / "n.npy") and scene.image is None


def test_the_built_in_scenes_are_the_documented_classes():
    """docs/scenes.md: full = two lights, texture, two mip levels at the two-light widths;
    diffuse has no specular; flat one N' per polygon; palette Tarini's shading; textured a
    colour texture on the bricks."""
    full = load_scene_config("full")
    assert (full.lights, full.texture, full.mip_levels) == (2, True, 2)
    assert (full.angle_bits, full.frac_bits) == (15, 16)
    assert load_scene_config("two-lights").lights == 2
    assert load_scene_config("diffuse").specular is False
    assert load_scene_config("flat").rotation == "per-polygon"
    assert load_scene_config("palette").rotation == "none"
    textured = load_scene_config("textured")
    assert textured.texture is True and textured.image == "bricks"


# --- overrides, flags and defaults ----------------------------------------------------------

def test_none_means_not_given_in_the_source_and_the_overrides():
    """A key set to None is not set: the scene's default holds and no contradiction is seen."""
    assert load_scene_config({"name": "t", "lights": None}).lights == 1
    assert load_scene_config("two-lights", overrides={"lights": None}).lights == 2
    assert load_scene_config({"name": "t", "lights": None}, overrides={"lights": 3}).lights == 3


def test_overrides_set_keys_the_source_leaves_open():
    """An override of a key the source does not set applies; one that agrees is no clash."""
    scene = load_scene_config("default", {"texture_size": 32, "addressing": "clamp"})
    assert (scene.texture_size, scene.addressing, scene.name) == (32, "clamp", "default")
    assert load_scene_config("two-lights", {"lights": 2}).lights == 2
    assert load_scene_config({"name": "t"}, {"image": "wood"}).image == "wood"


def test_a_contradicting_override_names_its_default_flag():
    """Without a flags map, the message names the key's flag (--key-with-dashes), both
    values and the source, in one line."""
    with pytest.raises(BumpError) as e:
        load_scene_config({"name": "t", "texture_size": 128}, {"texture_size": 32})
    assert str(e.value) == "--texture-size 32 contradicts texture_size = 128 in scene: drop one"
    with pytest.raises(BumpError) as e:
        load_scene_config({"name": "t", "texture_size": 128}, {"texture_size": 32},
                          flags={"lights": "-l"})
    assert str(e.value).startswith("--texture-size 32 contradicts")


def test_a_contradiction_names_the_flag_the_user_typed(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text('addressing = "clamp"\n')
    with pytest.raises(BumpError) as e:
        load_scene_config(f, {"addressing": "wrap"}, flags={"addressing": "--addr"})
    assert str(e.value) == f"--addr wrap contradicts addressing = 'clamp' in scene file {f}: drop one"


def test_a_second_picture_by_flag_is_refused_naming_both(tmp_path):
    """A map flag beside the scene's image, an image flag beside the scene's map, and a
    second map beside a map: refused, naming the flag and the scene's picture key."""
    with pytest.raises(BumpError) as e:
        load_scene_config("textured", {"normal_map": "n.png"})
    assert str(e.value) == ("--normal-map n.png contradicts image = 'bricks' in built-in scene "
                            "'textured': give the picture once")
    path = _heights(tmp_path / "h.npy")
    with pytest.raises(BumpError) as e:
        load_scene_config({"name": "t", "height_map": path}, {"image": "wood"})
    assert str(e.value).startswith(f"--image wood contradicts height_map = {path!r} in scene")
    with pytest.raises(BumpError) as e:
        load_scene_config({"name": "t", "height_map": path}, {"normal_map": "n.png"},
                          flags={"normal_map": "--nm"})
    assert str(e.value).startswith(f"--nm n.png contradicts height_map = {path!r}")


def test_an_image_and_a_map_in_one_source_are_refused(tmp_path):
    path = _heights(tmp_path / "h.npy")
    with pytest.raises(BumpError) as e:
        load_scene_config({"name": "t", "image": "wood", "normal_map": path})
    assert str(e.value) == "image = 'wood' and normal_map in scene: give the picture once"


def test_a_scene_config_without_overrides_is_returned_as_is():
    scene = load_scene_config("palette")
    assert load_scene_config(scene) is scene
    assert load_scene_config(scene, {}) is scene


def test_a_scene_config_takes_overrides_of_its_open_keys():
    """The keys a SceneConfig leaves None (geometry, a map) take overrides; its rotation is
    derived again."""
    scene = load_scene_config("flat")
    got = load_scene_config(scene, {"geometry": "sphere"})
    assert got.geometry == "sphere" and got.rotation == "per-polygon" and got.name == "flat"
    assert got.replace(geometry=None).geometry is None           # None: the image's own


def test_defaults_with_a_map_fill_every_key_but_the_texture_size(tmp_path):
    """With a user's map the map's side is the texture size (a default T does not apply),
    but the other defaults still fill the keys nothing sets."""
    path = _heights(tmp_path / "h.npy", 32)
    scene = load_scene_config({"name": "t", "height_map": path},
                              defaults={"texture_size": 64, "lights": 2, "addressing": "clamp"})
    assert (scene.texture_size, scene.lights, scene.addressing) == (32, 2, "clamp")
    given = load_scene_config({"name": "t", "addressing": "wrap"}, defaults={"addressing": "clamp",
                                                                             "lights": 3})
    assert (given.addressing, given.lights) == ("wrap", 3)


def test_a_map_keys_other_maps_key_is_refused(tmp_path):
    """height_scale goes with a height map, normal_convention with a normal map: the other
    map's key (at a non-default value) is refused naming it and the map; at its default,
    or with its own map, it is accepted."""
    n = np.zeros((16, 16, 3))
    n[..., 2] = 1.0
    n[4, 4] = (0.0, 0.6, 0.8)
    np.save(tmp_path / "n.npy", n)
    normals = str(tmp_path / "n.npy")
    heights = _heights(tmp_path / "h.npy")
    with pytest.raises(BumpError) as e:
        load_scene_config({"name": "t", "normal_map": normals, "height_scale": 2.0})
    assert str(e.value) == "height_scale applies to a height map, but scene gives normal_map"
    ok = load_scene_config({"name": "t", "normal_map": normals, "height_scale": DEFAULT_HEIGHT_SCALE,
                            "normal_convention": "directx"})
    assert ok.normal_convention == "directx" and ok.texture_size == 16
    mine = load_scene_config({"name": "t", "height_map": heights, "height_scale": 2.5,
                              "normal_convention": "opengl"})
    assert mine.height_scale == 2.5


def test_a_maps_kind_is_checked_when_the_scene_loads(tmp_path):
    """A height_map must be greyscale and a normal_map RGB: a PNG of the other kind is
    refused at load time with the hint to the other flag."""
    rgb = np.zeros((16, 16, 3), np.uint8)
    rgb[..., 2] = 255
    write_png(tmp_path / "rgb.png", rgb)
    write_png(tmp_path / "grey.png", np.arange(256, dtype=np.uint8).reshape(16, 16))
    with pytest.raises(BumpError, match=r"rgb\.png: RGB PNG .*--normal-map"):
        load_scene_config({"name": "t", "height_map": str(tmp_path / "rgb.png")})
    with pytest.raises(BumpError, match=r"grey\.png: greyscale PNG .*--height-map"):
        load_scene_config({"name": "t", "normal_map": str(tmp_path / "grey.png")})
    assert load_scene_config({"name": "t", "height_map": str(tmp_path / "grey.png")}).texture_size == 16


def test_resample_sizes_a_map_to_the_nearest_allowed_side(tmp_path):
    """A 24 x 24 map is refused naming the nearest allowed size (32, by ratio) unless
    resample = true, which sizes the scene to it."""
    path = _heights(tmp_path / "h24.npy", 24)
    with pytest.raises(BumpError, match="nearest allowed size is 32x32"):
        load_scene_config({"name": "t", "height_map": path})
    assert load_scene_config({"name": "t", "height_map": path, "resample": True}).texture_size == 32
    assert load_scene_config({"name": "t", "height_map": path, "resample": True,
                              "texture_size": 16}).texture_size == 16


@pytest.mark.parametrize("key, keys", [
    ("name", {"name": 3}),
    ("method", {"method": "peercy"}),
    ("height_map", {"height_map": 5}),
    ("normal_map", {"normal_map": ""}),
    ("image", {"image": "no-such-picture"}),
    ("rotation", {"shading": "palette", "rotation": "per-pixel"}),
])
def test_a_refusal_about_one_key_names_it_as_its_field(key, keys):
    """BumpError.field names the refused parameter (rtl/errors.py), not only the wording."""
    assert _refused(key, **keys).field == key


def test_a_palette_scene_of_a_non_square_map_is_refused_naming_texture_height():
    """The palette's quantizer and index mipmaps take square maps (Tarini Sec. 4-5): a
    64 x 32 map with palette shading is refused on texture_height, naming the allowed
    values."""
    e = _refused("texture_height", texture_size=64, texture_height=32, shading="palette")
    assert e.field == "texture_height"
    assert "needs shading = 'per-pixel'" in str(e) and "allowed texture_height = 64 or none" in str(e)
