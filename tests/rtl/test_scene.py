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
