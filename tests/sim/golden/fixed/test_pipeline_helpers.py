"""Helpers of the pipeline's golden model (sim/golden/fixed/pipeline.py) that the scene
tests reach only through the RTL: the colour-texture words, the random texture memory,
and the once-per-polygon rotation of a flat map's N', each against a closed form."""

import numpy as np
import pytest

from bumprtl.sim.golden.fixed.exact import rotation_fixed
from bumprtl.sim.golden.fixed.pipeline import polygon_fixed, random_texture, unpack_rgb
from bumprtl.sim.scenes.config import load_scene_config


def test_texture_words_hold_red_in_the_low_byte():
    got = unpack_rgb([0x123456, 0xFF0000, 0x0000FF, 0])
    assert sorted(got) == ["b", "g", "r"]
    assert list(got["r"]) == [0x56, 0, 0xFF, 0]
    assert list(got["g"]) == [0x34, 0, 0, 0]
    assert list(got["b"]) == [0x12, 0xFF, 0, 0]


def test_random_texture_fills_every_level_with_24_bit_words():
    rng = np.random.default_rng(4)
    scene = load_scene_config("full", {"texture_size": 16})
    words = random_texture(scene, rng)
    levels = scene.mip_levels
    assert levels == 2 and len(words) == 16 * 16 + 8 * 8
    assert words.min() >= 0 and words.max() < 1 << 24 and words.max() >= 1 << 23
    assert len(np.unique(words)) > len(words) * 0.9
    assert random_texture(load_scene_config("default", {"texture_size": 16}), rng) is None


def _unit(phi, theta):
    return np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])


def test_polygon_rotation_gives_n_dot_l_with_the_per_pixel_light_terms():
    """The polygon registers (x4, y2, z4 of n'') with a pixel's light terms (p2, y2, z) give
    8 * 2**B times N'' . L (the illumination's dot, (x4 p2 + 2 y2 y2 + 2 z4 z) / 8): N'' is
    N' turned out of N's tangent frame (R_z(ph_N) R_y(th_N), built here in float64)."""
    scene = load_scene_config("default", {"bump_map": "flat"})
    cfg = scene.config
    full, one = cfg.full_circle, 1 << cfg.frac_bits
    rng = np.random.default_rng(8)
    for _ in range(40):
        n_phi, b_phi, l_phi = (int(c) for c in rng.integers(0, full, 3))
        n_theta, l_theta = (int(c) for c in rng.integers(0, full // 2, 2))
        b_theta = int(rng.integers(0, full // 4))
        poly = polygon_fixed(n_phi, n_theta, b_phi, b_theta, scene)
        assert set(poly) == {"n_phi", "n.x4", "n.y2", "n.z4"} and poly["n_phi"] == n_phi
        light = rotation_fixed({k: np.asarray(v, np.int64) for k, v in {
            "n.phi": n_phi, "n.theta": n_theta, "b.phi": 0, "b.theta": 0,
            "l.phi": l_phi, "l.theta": l_theta, "h.phi": 0, "h.theta": 0}.items()}, cfg)
        dot = (poly["n.x4"] * int(light["l.p2"]) + 2 * poly["n.y2"] * int(light["l.y2"])
               + 2 * poly["n.z4"] * int(light["l.z"])) / 8 / one / one
        a = lambda c: 2 * np.pi * c / full
        pn, tn = a(n_phi), a(n_theta)
        rz = np.array([[np.cos(pn), -np.sin(pn), 0], [np.sin(pn), np.cos(pn), 0], [0, 0, 1]])
        ry = np.array([[np.cos(tn), 0, np.sin(tn)], [0, 1, 0], [-np.sin(tn), 0, np.cos(tn)]])
        world = rz @ ry @ _unit(a(b_phi), a(b_theta))
        assert dot == pytest.approx(world @ _unit(a(l_phi), a(l_theta)), abs=1e-3)
