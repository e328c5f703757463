"""The pipeline model's stimulus helpers (sim/golden/fixed/pipeline.py) keep what their
docstrings promise: texel coordinates over the whole signed port range, levels past the
last, the angles of every light (N only where the map varies), consecutive tags centred on
the middle of the tag range; random maps with N' in the upper tangent hemisphere or indices
over the whole index port; payload lists pixel by pixel."""

import numpy as np
import pytest

from bumprtl.rtl.bumpfetch import coord_bits, level_bits, memory_depth
from bumprtl.rtl.layouts import light_keys
from bumprtl.rtl.palette import index_bits
from bumprtl.sim.golden.fixed.pipeline import (
    as_payload_list,
    combine_lights_fixed,
    corner_inputs,
    fetch_fixed,
    random_inputs,
    random_map,
    unpack_texels,
)
from bumprtl.sim.golden.methods import illumination_fixed, rotation_fixed
from bumprtl.sim.scenes.config import load_scene_config


@pytest.mark.parametrize("name", ["default", "full", "two-lights", "flat", "palette"])
def test_random_inputs_cover_the_ports(name):
    scene = load_scene_config(name, {"texture_size": 16})
    n = 4000
    got = random_inputs(scene, n, np.random.default_rng(1))
    assert all(v.dtype == np.int64 and v.shape == (n,) for v in got.values())
    has_uv = scene.shading == "palette" or scene.bump_map == "varying" or scene.texture
    if has_uv:
        half = 1 << (coord_bits(scene) - 1)
        for c in ("u", "v"):
            assert got[c].min() == -half and got[c].max() == half - 1, c      # both ends reached
    else:
        assert "u" not in got and "v" not in got
    if scene.mip_levels > 1:
        assert got["level"].min() == 0 and got["level"].max() == (1 << level_bits(scene)) - 1
    else:
        assert "level" not in got
    keys = [k for lk in light_keys(scene.config) for k in lk.values()] if scene.shading == "per-pixel" else []
    for k in keys:
        hi = scene.config.full_circle // 2 if k.endswith("theta") else scene.config.full_circle - 1
        assert got[k].min() >= 0 and got[k].max() <= hi and len(np.unique(got[k])) > n // 4, k
    if len(keys) > 4:                                  # each light its own angles
        assert not np.array_equal(got[keys[0]], got[keys[len(keys) // 2]])
    with_n = scene.shading == "per-pixel" and scene.bump_map == "varying"
    assert ("n.phi" in got) == with_n and ("n.theta" in got) == with_n
    mask = (1 << scene.tag_bits) - 1
    assert np.array_equal(np.diff(got["tag"]) & mask, np.ones(n - 1, np.int64))
    assert got["tag"][n // 2] == (mask + 1) // 2 and got["tag"].min() >= 0 and got["tag"].max() <= mask
    expected = {"tag"} | ({"u", "v"} if has_uv else set()) | ({"level"} if scene.mip_levels > 1 else set()) \
        | set(keys) | ({"n.phi", "n.theta"} if with_n else set())
    assert set(got) == expected


def test_tags_flip_the_top_bit_in_any_two_pixel_run():
    scene = load_scene_config("default", {"texture_size": 16, "tag_bits": 4})
    for n in (2, 3, 16, 17):
        tags = random_inputs(scene, n, np.random.default_rng(n))["tag"]
        assert len({int(t) >> 3 for t in tags}) == 2, n


def test_random_maps_hold_upper_hemisphere_normals_or_any_index():
    rng = np.random.default_rng(2)
    scene = load_scene_config("full", {"texture_size": 16})
    words = random_map(scene, rng)
    assert len(words) == memory_depth(scene)
    t = unpack_texels(words, scene)
    full = 1 << scene.angle_bits
    assert t["b.phi"].min() >= 0 and t["b.phi"].max() <= full - 1 and np.ptp(t["b.phi"]) > 0.9 * full
    q = full // 4                                                                 # 0 .. 90 deg
    assert t["b.theta"].min() >= 0 and t["b.theta"].max() <= q and np.ptp(t["b.theta"]) > 0.9 * q
    assert abs(t["b.theta"].mean() - q / 2) < 0.1 * q
    pal = load_scene_config("palette", {"texture_size": 16})
    idx = random_map(pal, rng)
    top = 1 << index_bits(pal.config)
    assert len(idx) == memory_depth(pal) and idx.min() >= 0 and idx.max() <= top - 1
    assert np.ptp(idx) > 0.9 * top and abs(idx.mean() - top / 2) < 0.1 * top


def test_payload_lists_are_the_pixels_one_by_one():
    inputs = {"a": np.array([1, 2, 3]), "b": np.array([7, 8, 9])}
    assert as_payload_list(inputs) == [{"a": 1, "b": 7}, {"a": 2, "b": 8}, {"a": 3, "b": 9}]


def test_light_sums_saturate_and_round_once():
    """diffuse = min(255, round(255 D)), specular = min(255, round(S / 2**F)), D and S
    summed over the lights before any rounding."""
    from bumprtl.rtl.tables import SPEC_FRAC_BITS
    scene = load_scene_config("two-lights", {"texture_size": 16})
    one = scene.config.one
    a = {"diffuse_fine": np.array([one // 2, one, 0, 1]), "specular_fine": np.array([3, 255 << SPEC_FRAC_BITS, 0, 1 << (SPEC_FRAC_BITS - 1)])}
    b = {"diffuse_fine": np.array([one // 2, one, 0, 0]), "specular_fine": np.array([1, 255 << SPEC_FRAC_BITS, 0, 0])}
    out = combine_lights_fixed([a, b], scene)
    assert out["diffuse"].tolist() == [255, 255, 0, 0]
    assert out["specular"].tolist() == [0, 255, 0, 1]
    assert out["color"][1] == 255 and out["color"][2] == round(255 * scene.config.ka)



@pytest.mark.parametrize("name", ["two-lights", "full"])
def test_corners_lead_and_light_every_light_head_on_at_once(name):
    """random_inputs starts with corner_inputs, whose coordinates (0, the last texel, both
    ends of the port) all read a corner texel of random_map (N' = N); there some row has
    every light head-on at once, so the light sum reaches its maximum (m lights x 2**F:
    the carry into the sum's top bit)."""
    scene = load_scene_config(name, {"texture_size": 16})
    rng = np.random.default_rng(2)
    words, corners = random_map(scene, rng), corner_inputs(scene)
    n = len(corners["u"])
    got = random_inputs(scene, n + 5, rng)
    assert all((got[k][:n] == c).all() for k, c in corners.items())
    b = unpack_texels(fetch_fixed(corners["u"], corners["v"], corners.get("level"), words, scene), scene)
    assert (b["b.theta"] == 0).all()
    total = 0
    for keys in light_keys(scene.config):
        light = {**b, **{k: corners[k] for k in ("n.phi", "n.theta")},
                 **{own: corners[key] for own, key in keys.items()}}
        total = total + illumination_fixed(rotation_fixed(light, scene.config), scene.config)["diffuse_fine"]
    assert total.max() == scene.lights << scene.frac_bits and total.min() == 0
