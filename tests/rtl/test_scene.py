"""rtl/scene.HardwareScene: the hardware's switches, checked where they are defined."""

import warnings

import pytest

from bumprtl.rtl.bumpfetch import BumpMapFetch
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.pipeline import BumpPipeline, LightSum
from bumprtl.rtl.scene import HardwareScene


@pytest.mark.parametrize("keys, field", [
    ({"texture_size": 48}, "texture_size"),
    ({"texture_size": 8}, "texture_size"),
    ({"texture_size": True}, "texture_size"),
    ({"texture_size": 16, "mip_levels": 6}, "mip_levels"),
    ({"mip_levels": 0}, "mip_levels"),
    ({"texture_size": 64, "texture_height": 128}, "texture_height"),
    ({"texture_size": 64, "texture_height": 48}, "texture_height"),
    ({"texture_size": 64, "texture_height": 8}, "texture_height"),
    ({"texture_size": 64, "texture_height": True}, "texture_height"),
    ({"texture_size": 64, "texture_height": 16, "mip_levels": 6}, "mip_levels"),
    ({"shading": "gouraud"}, "shading"),
    ({"bump_map": "bumpy"}, "bump_map"),
    ({"addressing": "mirror"}, "addressing"),
    ({"texture": 1}, "texture"),
    ({"rotation": "sideways"}, "rotation"),
    ({"shading": "palette", "rotation": "per-pixel"}, "rotation"),
    ({"config": {"angle_bits": 13}}, "config"),
])
def test_a_bad_switch_names_its_field(keys, field):
    with pytest.raises(BumpError) as e:
        HardwareScene(**keys)
    assert e.value.field == field
    assert field in str(e.value) and "\n" not in str(e.value)


def test_texture_height_range_and_the_map_size_it_gives():
    """texture_height: a power of two in [16, texture_size] (the message names both ends);
    mip levels stop at the height's last (log2 H + 1); None is the square map."""
    with pytest.raises(BumpError) as e:
        HardwareScene(texture_size=64, texture_height=128)
    assert str(e.value) == ("texture_height must be a power of two in [16, 64] (the map's "
                            "height, at most its width texture_size = 64), got 128")
    with pytest.raises(BumpError, match=r"mip_levels must be an integer in \[1, 5\] for a "
                                        r"64 x 16 map, got 6"):
        HardwareScene(texture_size=64, texture_height=16, mip_levels=6)
    s = HardwareScene(texture_size=64, texture_height=16, mip_levels=5)
    assert (s.map_height, s.height_bits, s.texture_bits, s.square) == (16, 4, 6, False)
    assert [s.level_size(n) for n in range(5)] == [(64, 16), (32, 8), (16, 4), (8, 2), (4, 1)]
    square = HardwareScene(texture_size=32)
    assert (square.texture_height, square.map_height, square.height_bits, square.square) == \
        (None, 32, 5, True)
    assert s.replace(texture_height=None).map_height == 64


def test_the_top_mip_level_is_allowed_and_rotation_is_derived():
    s = HardwareScene(texture_size=16, mip_levels=5)
    assert (s.texture_bits, s.rotation) == (4, "per-pixel")
    assert HardwareScene(bump_map="flat").rotation == "per-polygon"
    assert HardwareScene(shading="palette", bump_map="flat").rotation == "none"


def test_lights_and_widths_come_from_the_config():
    s = HardwareScene(config=Config(lights=2, specular=False, angle_bits=12))
    assert (s.lights, s.specular, s.angle_bits, s.tag_bits) == (2, False, 12, s.config.tag_bits)


@pytest.mark.parametrize("unit", ["BumpPipeline", "BumpMapFetch", "LightSum"])
def test_a_scene_unit_refuses_anything_but_a_hardware_scene(unit):
    """A duck-typed look-alike (e.g. sim/'s SceneConfig) is refused by name."""
    cls = {"BumpPipeline": BumpPipeline, "BumpMapFetch": BumpMapFetch, "LightSum": LightSum}[unit]

    class LookAlike:
        def __getattr__(self, name):
            return getattr(HardwareScene(config=Config(lights=2)), name)

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(TypeError, match=f"{unit} takes a HardwareScene.*got LookAlike"):
            cls(LookAlike())
    unit = cls(HardwareScene(config=Config(lights=2)))
    unit._MustUse__silence = True
    assert unit.scene.lights == 2 if hasattr(unit, "scene") else unit.lights == 2


def test_replace_changes_switches_and_config_fields_and_checks_them():
    s = HardwareScene(shading="palette", texture_size=32)
    t = s.replace(tag_bits=9, texture_size=16, shading="per-pixel")
    assert (t.config.tag_bits, t.texture_size, t.rotation) == (9, 16, "per-pixel")
    assert t.config.replace(tag_bits=s.config.tag_bits) == s.config
    with pytest.raises(BumpError) as e:
        s.replace(mip_levels=7)
    assert e.value.field == "mip_levels"


def test_every_unit_a_scene_pipeline_builds_says_why_it_is_there():
    """The sidecar's list of built units gives each its reason (the scene key and the
    paper's equation it serves): a non-empty sentence for every unit of every built-in
    scene, the texture blend's naming its lights where there are several."""
    from bumprtl.rtl.pipeline import BumpPipeline
    from bumprtl.sim.scenes.config import BUILTIN, load_scene_config
    for name in BUILTIN:
        scene = load_scene_config(name)
        pipeline = BumpPipeline(scene.hardware)
        pipeline._MustUse__silence = True
        for entry in pipeline.built:
            assert isinstance(entry["why"], str) and len(entry["why"].split()) >= 3, (name, entry)
        assert [e["unit"] for e in pipeline.built] == list(pipeline.units), name
    full = BumpPipeline(load_scene_config({"name": "x", "texture": True, "image": "bricks",
                                           "lights": 2}).hardware)
    full._MustUse__silence = True
    blend = next(e for e in full.built if e["unit"] == "blend")
    assert blend["why"].startswith("texture = true") and "summed over the 2 lights" in blend["why"]
