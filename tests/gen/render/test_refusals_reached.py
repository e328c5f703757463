"""The render functions' refusals that no other test reached (docs/coverage.md's per-branch
list): a method without a float64 model or without a fixed-point model is named, with the
methods allowed, before anything is rendered."""

import pytest

from bumprtl.gen.render.images import FIXED_METHODS, fixed_image, shade_scene
from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.scenes.config import load_scene_config


def test_shade_scene_refuses_a_method_without_a_float64_model():
    with pytest.raises(BumpError, match="method must be one of .*got 'cordic'"):
        shade_scene(None, "cordic", Config(), progress=False)


def test_fixed_image_refuses_a_method_without_a_fixed_point_model():
    with pytest.raises(BumpError, match="--method cordic has no fixed-point model") as e:
        fixed_image(load_scene_config("default"), "cordic", 16)
    assert all(m in str(e.value) for m in FIXED_METHODS)
