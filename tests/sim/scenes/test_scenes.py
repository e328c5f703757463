import numpy as np
import pytest

from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.common import polar_to_cartesian
from bumprtl.sim.golden.conventional import conventional
from bumprtl.sim.golden.exact import exact
from bumprtl.sim.scenes import SCENES, light_direction, load_scene
from bumprtl.sim.scenes.heightfields import height_to_normals
from bumprtl.sim.scenes.imaging import compose, psnr


@pytest.mark.parametrize("name", list(SCENES))
def test_scene_shapes_ranges_and_texel_lookup(name):
    s = load_scene(name, size=64)
    assert s.px.shape == (64, 64) and s.mask.shape == (64, 64) and s.mask.any()
    assert s.b_phi_map.shape == (64, 64)
    assert np.array_equal(s.px.b_phi, s.b_phi_map[s.v, s.u])
    assert np.array_equal(s.px.b_theta, s.b_theta_map[s.v, s.u])
    assert s.u.min() >= 0 and s.u.max() < 64 and s.v.min() >= 0 and s.v.max() < 64
    assert np.all(s.b_theta_map < np.pi / 2)          # bump normals face outwards


def test_normals_of_a_tilted_plane_are_constant_and_exact():
    """h = a * u (texels): slope a per texel along u -> n' = normalize(0, -a, 1)."""
    t, a = 32, 0.01
    height = np.tile(np.arange(t) * a, (t, 1))
    height[:, -1] = height[:, -2] + a                   # keep the slope at the seam...
    phi, theta = height_to_normals(height, strength=1.0)
    inner = (slice(None), slice(1, t - 2))              # ...and look away from the wrap
    expect = np.array([0.0, -a, 1.0]) / np.sqrt(1 + a * a)
    got = polar_to_cartesian(phi[inner], theta[inner])
    assert np.allclose(got, expect, atol=1e-12)


def test_sinusoid_normals_match_analytic_derivative():
    t, k = 256, 3
    u = np.arange(t)
    height = np.tile(np.sin(2 * np.pi * k * u / t), (t, 1))
    phi, theta = height_to_normals(height, strength=1.0)
    slope = np.cos(2 * np.pi * k * u / t) * 2 * np.pi * k / t     # dh/du per texel
    # Central differences: sin(w)/w relative error, w = 2 pi k / t.
    w = 2 * np.pi * k / t
    n = polar_to_cartesian(phi[0], theta[0])
    assert np.allclose(-n[:, 1] / n[:, 2], slope * np.sin(w) / w, atol=1e-12)
    assert np.max(np.abs(-n[:, 1] / n[:, 2] - slope)) < slope.max() * w * w / 6 * 1.01


def test_light_direction_closed_forms():
    assert np.allclose(light_direction(90, 0), [0, -1, 0])     # from the viewer
    assert np.allclose(light_direction(0, 90), [0, 0, 1])      # from the top


def test_exact_renders_identically_to_conventional():
    s = load_scene("globe", size=128)
    ref, img = compose(s, conventional(s.px).color), compose(s, exact(s.px).color)
    assert psnr(ref, img) == float("inf")


@pytest.mark.parametrize("kwargs, words", [
    ({"name": "marble"}, ["scene", "bricks", "globe"]),
    ({"name": "bricks", "size": 100}, ["size", "power of two"]),
    ({"name": "bricks", "light_elevation": 120}, ["light_elevation", "[-90, 90]"]),
    ({"name": "bricks", "light": "spot"}, ["light", "directional"]),
])
def test_bad_scene_arguments_are_named(kwargs, words):
    with pytest.raises(BumpError) as e:
        load_scene(**kwargs)
    for w in words:
        assert w in str(e.value)


def test_bad_height_map():
    with pytest.raises(BumpError, match="square"):
        height_to_normals(np.zeros((4, 5)))
    with pytest.raises(BumpError, match="NaN"):
        height_to_normals(np.full((4, 4), np.nan))
