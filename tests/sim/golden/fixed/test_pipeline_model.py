"""The pipeline's bit-exact model (sim/golden/fixed/pipeline.py) against what it models,
computed here: the fetch's word address (base of the level + v_l T_l + u_l, wrapped or
clamped), the texel word's fields, and the outputs of one light, two lights and the colour
texture against float64 of N'' . L and N'' . H on the same angles (N'' = N' turned out of
N's tangent frame), within the proven error bounds."""

import numpy as np
import pytest

from bumprtl.rtl.bumpfetch import memory_depth
from bumprtl.sim.golden.fixed.pipeline import (
    fetch_fixed,
    map_words,
    pipeline_fixed,
    polygon_fixed,
    random_inputs,
    random_map,
    unpack_texels,
)
from bumprtl.sim.scenes.config import load_scene_config


@pytest.mark.parametrize("addressing", ["wrap", "clamp"])
def test_fetch_reads_the_word_at_base_plus_row_times_side_plus_column(addressing):
    scene = load_scene_config("default", {"texture_size": 16, "mip_levels": 3, "addressing": addressing})
    depth = memory_depth(scene)
    assert depth == 16 * 16 + 8 * 8 + 4 * 4
    words = np.arange(depth) * 7 + 3                        # word i is 7 i + 3
    rng = np.random.default_rng(1)
    u, v = rng.integers(-40, 40, 500), rng.integers(-40, 40, 500)
    level = rng.integers(0, 5, 500)                         # 3 and 4: past the last, read level 2
    got = fetch_fixed(u, v, level, words, scene)
    bases = {0: 0, 1: 256, 2: 256 + 64}
    for i in range(500):
        lv = min(int(level[i]), 2)
        side = 16 >> lv
        cu, cv = int(u[i]) // 2 ** lv, int(v[i]) // 2 ** lv      # floor for negatives
        if addressing == "wrap":
            cu, cv = cu % side, cv % side
        else:
            cu, cv = min(max(cu, 0), side - 1), min(max(cv, 0), side - 1)
        assert got[i] == 7 * (bases[lv] + cv * side + cu) + 3, (u[i], v[i], level[i])
    assert np.array_equal(fetch_fixed(u, v, None, words, scene), fetch_fixed(u, v, np.zeros(500, int), words, scene))


def test_texel_words_and_the_memory_image():
    scene = load_scene_config("default", {"texture_size": 16, "mip_levels": 2})
    bits = scene.angle_bits
    w = np.array([5 | 9 << bits, (1 << bits) - 1, ((1 << bits) - 1) << bits])
    got = unpack_texels(w, scene)
    assert sorted(got) == ["b.phi", "b.theta"]
    assert list(got["b.phi"]) == [5, (1 << bits) - 1, 0] and list(got["b.theta"]) == [9, 0, (1 << bits) - 1]
    pal = load_scene_config("palette", {"texture_size": 16})
    assert list(unpack_texels([3, 200], pal)) == ["index"]
    a, b = np.arange(256).reshape(16, 16), 1000 + np.arange(64).reshape(8, 8)
    words = map_words([a, b], scene)
    assert np.array_equal(words, np.concatenate([a.ravel(), b.ravel()]))     # row v, column u
    with pytest.raises(ValueError):
        map_words([a], scene)


def _unit(phi, theta):
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1)


def _world(n_phi, n_theta, b):
    """R_z(ph_N) R_y(th_N) b: N' out of N's tangent frame."""
    ct, st, cp, sp = np.cos(n_theta), np.sin(n_theta), np.cos(n_phi), np.sin(n_phi)
    x = ct * b[..., 0] + st * b[..., 2]
    z = -st * b[..., 0] + ct * b[..., 2]
    return np.stack([cp * x - sp * b[..., 1], sp * x + cp * b[..., 1], z], -1)


def _reference(scene, inputs, b_phi, b_theta):
    """float64 per light of clamp(N''.L) and clamp(N''.H)^n on the input codes' angles."""
    cfg = scene.config
    a = lambda key: inputs[key] * 2 * np.pi / cfg.full_circle
    nw = _world(a("n.phi"), a("n.theta"), _unit(b_phi * 2 * np.pi / cfg.full_circle,
                                               b_theta * 2 * np.pi / cfg.full_circle))
    d, s = [], []
    for j in range(scene.lights):
        pre = "" if j == 0 else f"extra_lights.{j - 1}."
        d.append(np.clip(np.einsum("ni,ni->n", nw, _unit(a(pre + "l.phi"), a(pre + "l.theta"))), 0, 1))
        s.append(np.clip(np.einsum("ni,ni->n", nw, _unit(a(pre + "h.phi"), a(pre + "h.theta"))), 0, 1)
                 ** cfg.spec_exponent if cfg.specular else np.zeros(len(nw)))
    return d, s


@pytest.mark.parametrize("name, overrides", [("default", {"texture_size": 16}),
                                             ("two-lights", {"texture_size": 16}),
                                             ("full", {"texture_size": 16})])
def test_outputs_are_the_float64_shading_of_the_fetched_normal(name, overrides):
    scene = load_scene_config(name, overrides)
    cfg = scene.config
    rng = np.random.default_rng(3)
    words = random_map(scene, rng)
    texels = rng.integers(0, 1 << 24, memory_depth(scene)) if scene.texture else None
    inputs = random_inputs(scene, 600, rng)
    out = pipeline_fixed(inputs, scene, words, None, texels)
    b = unpack_texels(fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"), words, scene), scene)
    d, s = _reference(scene, inputs, b["b.phi"], b["b.theta"])
    D, S = sum(d), sum(s)
    tol = scene.lights                                     # 1 LSB a light (the proven bound)
    assert np.abs(out["diffuse"] - np.minimum(np.rint(255 * D), 255)).max() <= tol
    assert np.abs(out["specular"] - np.minimum(np.rint(255 * S), 255)).max() <= tol
    if scene.texture:
        tex = fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"), texels, scene)
        lit = np.minimum(1.0, cfg.ka + cfg.kd * D)
        for n, c in enumerate("rgb"):
            texel = (tex >> (8 * n)) & 0xFF
            want = np.rint(255 * np.clip(texel / 255 * lit + cfg.ks * S, 0, 1))
            assert np.abs(out[f"color.{c}"] - want).max() <= tol + 1, c
        assert "color" not in out
    else:
        want = np.rint(255 * np.clip(cfg.ka + cfg.kd * D + cfg.ks * S, 0, 1))
        assert np.abs(out["color"] - want).max() <= tol
    if scene.lights == 1:
        assert {"diffuse_fine", "specular_fine"} <= set(out)


def test_a_flat_map_uses_the_polygon_registers():
    scene = load_scene_config("default", {"bump_map": "flat", "texture_size": 16})
    rng = np.random.default_rng(5)
    inputs = random_inputs(scene, 400, rng)
    full = scene.config.full_circle
    n_phi, n_theta, b_phi, b_theta = 1000, 3000, 5000, 1500
    poly = polygon_fixed(n_phi, n_theta, b_phi, b_theta, scene)
    out = pipeline_fixed(inputs, scene, None, poly)
    flat = {**inputs, "n.phi": np.full(400, n_phi), "n.theta": np.full(400, n_theta)}
    d, s = _reference(scene, flat, np.full(400, b_phi), np.full(400, b_theta))
    assert np.abs(out["diffuse"] - np.rint(255 * d[0])).max() <= 1
    assert np.abs(out["specular"] - np.rint(255 * s[0])).max() <= 1
    assert full == 1 << scene.angle_bits


def test_palette_shading_returns_the_fetched_index_and_texel():
    scene = load_scene_config("palette", {"texture_size": 16, "texture": True})
    rng = np.random.default_rng(6)
    words = random_map(scene, rng)
    texels = rng.integers(0, 1 << 24, memory_depth(scene))
    inputs = random_inputs(scene, 200, rng)
    out = pipeline_fixed(inputs, scene, words, None, texels)
    assert sorted(out) == ["index", "texel"]
    want = fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"), words, scene)
    assert np.array_equal(out["index"], want)
    assert np.array_equal(out["texel"], fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"), texels, scene))


def test_two_full_lights_saturate_every_output_at_255():
    from bumprtl.rtl.tables import SPEC_FRAC_BITS
    from bumprtl.sim.golden.fixed.pipeline import combine_lights_fixed

    scene = load_scene_config("two-lights", {"texture_size": 16})
    one = scene.config.one
    full = {"diffuse_fine": np.array([one, one // 2]), "specular_fine": np.array([255 << SPEC_FRAC_BITS, 0])}
    out = combine_lights_fixed([full, full], scene)
    assert list(out["diffuse"]) == [255, 255] and list(out["specular"]) == [255, 0]
    assert out["color"][0] == 255
    half = {"diffuse_fine": np.array([one // 4]), "specular_fine": np.array([10 << SPEC_FRAC_BITS])}
    out = combine_lights_fixed([half, half], scene)
    assert (out["diffuse"][0], out["specular"][0]) == (128, 20)          # round(255 / 2) = 128
