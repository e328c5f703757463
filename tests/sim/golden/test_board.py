"""The board's inputs and golden frames (sim/golden/board.py, docs/board.md) against closed
forms: the light of step s and light j at elevation 45 deg and azimuth 30 + 360 s / steps +
120 j deg (H the half vector with the viewer), the plane's normal (0, -1, 0), the screen
position's texel, the running tag, and a flat map's frame shaded by Phong's eq. (2) in
float64."""

import dataclasses

import numpy as np
import pytest

from bumprtl.rtl.layouts import light_keys
from bumprtl.rtl.video import MODES
from bumprtl.sim.golden.board import frame_inputs, golden_frame, light_table, plane_constants
from bumprtl.sim.scenes.config import load_scene_config

SMALL = {"angle_bits": 10, "texture_size": 16}


def _vector(phi_code, theta_code, bits):
    """The unit vector of two binary-angle codes (phi about +z from +x, theta from +z)."""
    phi, theta = (2 * np.pi * c / (1 << bits) for c in (phi_code, theta_code))
    return np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])


def _light(step, steps, j):
    el, az = np.radians(45.0), np.radians(30.0 + 360.0 * step / steps + 120.0 * j)
    # right = +x, up the screen = +z, toward the viewer = -y
    return np.array([np.cos(el) * np.cos(az), -np.sin(el), np.cos(el) * np.sin(az)])


@pytest.mark.parametrize("name, overrides", [("default", SMALL), ("two-lights", {"texture_size": 16})])
def test_light_table_holds_each_lights_l_and_h_of_every_step(name, overrides):
    scene = load_scene_config(name, overrides)
    steps, bits = 12, scene.angle_bits
    table = light_table(scene, steps)
    assert len(table) == steps
    keys = light_keys(scene.config)
    assert len(keys) == scene.lights
    # one code step of each angle: the vector within half a step of both (sqrt(2) / 2 steps)
    tol = 2 * np.pi / (1 << bits) * 0.75
    view = np.array([0.0, -1.0, 0.0])
    for s, entry in enumerate(table):
        assert set(entry) == {k for own in keys for k in own.values()}
        for j, own in enumerate(keys):
            l = _light(s, steps, j)
            got = _vector(entry[own["l.phi"]], entry[own["l.theta"]], bits)
            assert np.linalg.norm(got - l) < tol, (s, j, got, l)
            if scene.specular:
                h = (l + view) / np.linalg.norm(l + view)
                got = _vector(entry[own["h.phi"]], entry[own["h.theta"]], bits)
                assert np.linalg.norm(got - h) < tol, (s, j, got, h)
    # the default length is one step a frame over a whole turn
    assert len(light_table(scene)) == 256


def test_plane_normal_faces_the_viewer():
    """N = (0, -1, 0): phi = 270 deg, theta = 90 deg, i.e. 3/4 and 1/4 of the full circle."""
    for bits in (10, 12):
        scene = load_scene_config("default", {**SMALL, "angle_bits": bits})
        assert plane_constants(scene) == {"n.phi": 3 << (bits - 2), "n.theta": 1 << (bits - 2)}


@pytest.mark.parametrize("zoom, frame, width, height", [(0, 0, 16, 16), (1, 5, 16, 16),
                                                         (0, 2, 32, 16)])
def test_frame_inputs_are_the_screen_texels_the_constants_and_the_frames_light(zoom, frame,
                                                                                width, height):
    """The plane tiles the map over the screen: u wraps by the map's width, v by its height
    (a 32 x 16 map: texture_height 16)."""
    scene = load_scene_config("default", {**SMALL, "texture_size": width,
                                          "texture_height": height})
    mode = dataclasses.replace(MODES["test"], zoom=zoom)
    table = light_table(scene, 4)
    got = frame_inputs(scene, mode, frame, table)
    n = mode.h_active * mode.v_active
    y, x = np.divmod(np.arange(n), mode.h_active)          # raster order
    assert mode.v_active > height                           # v wraps within the frame
    assert np.array_equal(got["u"], (x // 2 ** zoom) % width)
    assert np.array_equal(got["v"], (y // 2 ** zoom) % height)
    light = table[frame % 4]
    assert set(got) == {"u", "v", "tag", "n.phi", "n.theta", *light}
    for k, c in {**plane_constants(scene), **light}.items():
        assert np.array_equal(got[k], np.full(n, c)), k
    assert np.array_equal(got["tag"], (np.arange(n) + frame * n) % (1 << scene.tag_bits))


def test_frame_tags_wrap_at_tag_bits_and_mip_scenes_get_level_0():
    scene = load_scene_config("default", {**SMALL, "tag_bits": 8, "mip_levels": 2})
    mode = MODES["test"]
    n = mode.h_active * mode.v_active                         # 768: past 2**8
    got = frame_inputs(scene, mode, 3, light_table(scene, 2))
    assert np.array_equal(got["tag"], (np.arange(n) + 3 * n) % 256)
    assert got["tag"].max() == 255 and got["tag"].min() == 0
    assert np.array_equal(got["level"], np.zeros(n))


def test_flat_map_frame_is_phong_of_the_45_degree_light(tmp_path):
    """A normal map of (0, 0, 1) everywhere (but one tilted texel, as a map must have bumps) leaves N' = N, and the light turns about the
    viewing axis, so every pixel of every frame has N.L = sin 45 deg and N.H = cos 22.5 deg:
    eq. (2) in float64, to 8 bits, within the proven 1 LSB; R = G = B (no texture)."""
    from bumprtl.gen.render.rtl import scene_memories

    path = tmp_path / "flat.npy"
    normals = np.zeros((16, 16, 3))
    normals[..., 2] = 1.0
    normals[15, 15] = (0.6, 0.0, 0.8)
    np.save(path, normals)
    scene = load_scene_config("default", {**SMALL, "normal_map": str(path)})
    cfg = scene.config
    want = 255 * (cfg.ka + cfg.kd * np.sin(np.pi / 4) + cfg.ks * np.cos(np.pi / 8) ** cfg.spec_exponent)
    words, texels, _ = scene_memories(scene)
    table = light_table(scene, 8)
    mode = MODES["test"]
    for frame in (0, 3):
        img = golden_frame(scene, mode, frame, table, words, texels)
        assert img.shape == (mode.v_active, mode.h_active, 3) and img.dtype == np.uint8
        flat = np.ones((mode.v_active, mode.h_active), bool)
        flat[15::16, 15::16] = False                          # texel (15, 15)
        assert np.all(img[flat] == img[0, 0, 0]), frame
        assert abs(int(img[0, 0, 0]) - want) <= 1, (img[0, 0, 0], want)
        assert np.all(img[15, 15] != img[0, 0])               # the tilted texel is seen
