"""rtl/scene.HardwareScene: the hardware's switches, checked where they are defined."""

import pytest

from bumprtl.rtl.config import BumpError, Config
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
    assert (s.lights, s.specular, s.angle_bits) == (2, False, 12)
