import dataclasses

import numpy as np
import pytest

from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.common import polar_to_cartesian
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.exact import exact
from bumprtl.sim.scenes import (
    REFERENCE_TEXTURE_SIZE,
    SCENES,
    bump_strength,
    light_direction,
    load_scene,
)
from bumprtl.sim.scenes.heightfields import (
    BRICK_BEVEL,
    HEIGHTFIELDS,
    brick_lines,
    height_to_normals,
    smooth_noise,
)
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
    assert s.u.dtype == s.v.dtype == np.int64 and s.mask.dtype == bool
    assert s.height.shape == (64, 64) and s.b_theta_map.dtype == np.float64
    assert s.albedo is None or (s.albedo.shape == (64, 64, 3) and 0 <= s.albedo.min()
                                and s.albedo.max() <= 1)
    assert s.name == name and s.geometry in ("plane", "sphere", "cylinder")


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


@pytest.mark.parametrize("pname, lo, hi", [("light_elevation", -90, 90),
                                           ("light_azimuth", -360, 360)])
def test_light_angles_accepted_at_both_ends_and_refused_past_them(pname, lo, hi):
    """light_elevation in [-90, 90] and light_azimuth in [-360, 360] degrees, closed ranges:
    both ends accepted, the nearest floats outside refused naming the parameter."""
    for val in (lo, hi, float(lo), float(hi)):
        load_scene("bumps", size=16, **{pname: val})
    for val in (np.nextafter(lo, -np.inf), np.nextafter(hi, np.inf), float("nan")):
        with pytest.raises(BumpError) as e:
            load_scene("bumps", size=16, **{pname: val})
        assert pname in str(e.value) and f"[{lo}, {hi}]" in str(e.value)


def test_bad_height_map():
    with pytest.raises(BumpError, match="non-empty 2-D array"):
        height_to_normals(np.zeros((4, 5, 1)))
    assert height_to_normals(np.zeros((4, 8)))[0].shape == (4, 8)   # a W x H map: H rows
    with pytest.raises(BumpError, match="NaN"):
        height_to_normals(np.full((4, 4), np.nan))


def _screen(size):
    """Pixel centres: screen x to the right, screen z up, in (-1, 1) (independent of the code)."""
    c = (np.arange(size) + 0.5) / size * 2 - 1
    return np.meshgrid(c, -c)


def _vec(phi, theta):
    return polar_to_cartesian(phi, theta)


@pytest.mark.parametrize("name", ["bumps", "globe", "cylinder"])
@pytest.mark.parametrize("light", ["directional", "point"])
def test_halfway_is_light_plus_viewer(name, light):
    s = load_scene(name, size=32, light_elevation=20, light_azimuth=-70, light=light)
    h = _vec(s.px.h_phi, s.px.h_theta)
    want = _vec(s.px.l_phi, s.px.l_theta) + [0, -1, 0]      # viewer along -y (orthographic)
    assert np.allclose(h, want / np.linalg.norm(want, axis=-1, keepdims=True), atol=1e-12)


def test_world_normals_of_each_geometry():
    sx, sz = _screen(64)
    plane = load_scene("bumps", size=64)
    assert plane.mask.all() and np.allclose(_vec(plane.px.n_phi, plane.px.n_theta), [0, -1, 0])
    globe = load_scene("globe", size=64)
    assert np.array_equal(globe.mask, sx ** 2 + sz ** 2 < 1)
    n = _vec(globe.px.n_phi, globe.px.n_theta)[globe.mask]
    m = globe.mask
    assert np.allclose(n, np.stack([sx[m], -np.sqrt(1 - sx[m] ** 2 - sz[m] ** 2), sz[m]], -1))
    cyl = load_scene("cylinder", size=64)
    n = _vec(cyl.px.n_phi, cyl.px.n_theta)
    assert np.allclose(n, np.stack([sx, -np.sqrt(1 - sx ** 2), 0 * sx], -1))


def test_point_light_direction_per_pixel():
    """A point light three units away in the light direction (plane at y = 0)."""
    sx, sz = _screen(32)
    s = load_scene("bumps", size=32, light_elevation=35, light_azimuth=120, light="point")
    to_light = 3 * light_direction(35, 120) - np.stack([sx, 0 * sx, sz], -1)
    want = to_light / np.linalg.norm(to_light, axis=-1, keepdims=True)
    assert np.allclose(_vec(s.px.l_phi, s.px.l_theta), want, atol=1e-12)
    d = load_scene("bumps", size=32, light_elevation=35, light_azimuth=120)
    assert np.allclose(_vec(d.px.l_phi, d.px.l_theta), light_direction(35, 120))


@pytest.mark.parametrize("name", ["bumps", "globe", "cylinder"])
def test_slopes_facing_the_light_are_brighter(name):
    """Light from the right (azimuth 0) brightens texels whose height falls to the right
    (dh/du < 0); light from the top (azimuth 90) those whose height rises down the screen
    (dh/dv > 0). Brightening = N'.L minus N.L of the unbumped surface, near the middle of
    the image where u runs to the right. Catches a mirrored tangent frame or texture
    mapping on every geometry."""
    sx, sz = _screen(128)
    for azimuth, axis, brighter_sign in ((0, 1, -1), (90, 0, +1)):
        s = load_scene(name, size=128, light_elevation=40, light_azimuth=azimuth)
        flat = dataclasses.replace(s.px, b_theta=np.zeros_like(s.px.b_theta))
        gain = conventional(s.px).ndotl - conventional(flat).ndotl
        slope = (np.roll(s.height, -1, axis) - np.roll(s.height, 1, axis))[s.v, s.u]
        near = s.mask & (np.abs(sx) < 0.5) & (np.abs(sz) < 0.5)
        r = np.corrcoef(brighter_sign * slope[near], gain[near])[0, 1]
        assert r > 0.8, (azimuth, r)


def test_texture_size_is_independent_of_image_size():
    s = load_scene("moon", size=32, texture_size=128)
    assert s.height.shape == s.b_phi_map.shape == (128, 128) and s.px.shape == (32, 32)
    assert s.u.max() < 128 and s.v.max() < 128 and s.u.max() > 64
    assert np.array_equal(s.px.b_theta, s.b_theta_map[s.v, s.u])


def test_bump_maps_are_central_differences_of_the_height():
    s = load_scene("text", size=64)
    strength = SCENES["text"][2]
    phi, theta = height_to_normals(s.height, strength)
    assert np.array_equal(phi, s.b_phi_map) and np.array_equal(theta, s.b_theta_map)
    assert s.height.std() > 0.05                   # the text is really there


def test_image_scenes_ship_inside_the_wheel():
    """brick, gravel, moon load from scikit-image's package directory (no download)."""
    from pathlib import Path

    import skimage.data
    here = Path(skimage.data.__file__).parent
    for name in ("brick", "gravel", "moon"):
        assert (here / f"{name}.png").is_file()


def test_smooth_noise_is_normalized_and_tiles():
    n = smooth_noise(128)
    assert abs(n.mean()) < 1e-12 and abs(n.std() - 1) < 1e-12
    inner = max(np.abs(np.diff(n, axis=a)).max() for a in (0, 1))
    seam = max(np.abs(n[0] - n[-1]).max(), np.abs(n[:, 0] - n[:, -1]).max())
    assert seam <= inner                            # no step at the wrap: the map tiles


@pytest.mark.parametrize("kwargs, words", [
    ({"name": "bricks", "texture_size": 24}, ["texture_size", "power of two"]),
    ({"name": "bricks", "size": 8}, ["size", "[16, 4096]"]),
    ({"name": "bricks", "light_azimuth": 400.0}, ["light_azimuth", "[-360, 360]"]),
    ({"name": "bricks", "light_elevation": float("nan")}, ["light_elevation"]),
    ({"name": "bricks", "light_elevation": True}, ["light_elevation"]),
])
def test_more_bad_scene_arguments(kwargs, words):
    with pytest.raises(BumpError) as e:
        load_scene(**kwargs)
    assert all(w in str(e.value) for w in words)


def test_bad_height_map_dtype_and_strength():
    with pytest.raises(BumpError, match="dtype"):
        height_to_normals(np.full((4, 4), "a"))
    with pytest.raises(BumpError, match="strength"):
        height_to_normals(np.zeros((4, 4)), strength=-1.0)


# --- Every procedural scene reads as itself at every allowed map size ----------------------
# Pictures of the scene on a T x T map, rendered at S = min(T, 256) pixels (one texel per
# pixel up to 256), float64 conventional. 2048 and 4096 (a 4096^2 map takes a minute to
# build on the 2-core machine) run in `make regress`.
MAP_SIZES = [16, 32, 64, 128, 256, 512, 1024,
             pytest.param(2048, marks=pytest.mark.regress), pytest.param(4096, marks=pytest.mark.regress)]


def _shade(name, t, azimuth=30.0):
    s = load_scene(name, size=min(t, 256), texture_size=t, light_azimuth=azimuth, light_elevation=45)
    return s, conventional(s.px).color


def _line_margin(profiles, size, half):
    """(smallest feature at a line, largest feature away from every line) of 1-D picture
    profiles: feature = |profile - median|; 'at' = within ``half`` pixels (wrapping)."""
    at_line, away = np.inf, 0.0
    y = np.arange(size) + 0.5
    for p, lines in profiles:
        d = np.abs(p - np.median(p))
        dist = np.array([np.abs((y - c + size / 2) % size - size / 2) for c in lines])
        at_line = min(at_line, *(d[di <= half].max() for di in dist))
        far = dist.min(0) > half
        away = max(away, d[far].max() if far.any() else 0.0)
    return at_line, away


@pytest.mark.parametrize("t", MAP_SIZES)
def test_bricks_show_mortar_lines_where_the_bricks_are(t):
    """The picture's strongest row features sit on the 8 course lines and, inside each
    course, its strongest column features on the 4 joints of that course (running bond:
    odd courses shifted half a brick), at every map size: in the mortar colour and in the
    relief (light from the top for the courses, from the right for the joints). Only at
    T = 16, where a course is 2 texels, the courses show in colour alone: the central
    difference of a 2-periodic height profile is zero."""
    size = min(t, 256)
    k = t / size                                   # texels per pixel
    rows, joints = brick_lines(t)
    ramp = max(BRICK_BEVEL * t / 16, 1.0)           # the bevel, texels
    half = max(1.5, (ramp + 2) / k)                 # a line's reach in pixels
    to_px = lambda c: (c + 0.5) / k                 # texel coordinate -> pixel coordinate
    s, top = _shade("bricks", t, azimuth=90)
    colour = compose(s, top)[..., 1].astype(float)  # mortar is grey: far more green than brick
    at, away = _line_margin([(colour.mean(1), [to_px(r) for r in rows])], size, half)
    assert at > 20 and at > 2 * away, ("colour rows", at, away)
    if t > 16:
        at, away = _line_margin([(top.mean(1), [to_px(r) for r in rows])], size, half)
        assert at > 0.2 and at > 2 * away, ("relief rows", at, away)
    _, side = _shade("bricks", t, azimuth=0)
    centre = (np.arange(size) + 0.5) * k - 0.5      # texel coordinate of each pixel row
    profiles = []
    for course, js in enumerate(joints):
        inside = (centre >= rows[course] + ramp - 1e-9) & (centre <= rows[course] + t / 8 - ramp + 1e-9)
        profiles.append((side[inside].mean(0), [to_px(j) for j in js]))
    at, away = _line_margin(profiles, size, half)
    assert at > 0.2 and at > 2 * away, ("relief joints", at, away)


def _box(img, size):
    k = img.shape[0] // size
    return img.reshape(size, k, size, k).mean(axis=(1, 3))


@pytest.mark.parametrize("t", MAP_SIZES)
def test_bumps_wood_and_text_read_as_themselves(t):
    """bumps: the picture's strongest frequency is the egg-crate's 6 x 6 periods per map;
    wood: the picture correlates with the 512^2 map's picture seen at the same resolution
    (box-filtered; r >= 0.45, where aliased rings at 16^2 gave 0.26); text: >= 90 % of the
    picture's shading lies on the letters of the 512^2 map (dilated by a pixel)."""
    size = min(t, 256)
    _, img = _shade("bumps", t)
    f = np.abs(np.fft.fft2(img - img.mean()))
    ky, kx = np.unravel_index(np.argmax(f), f.shape)
    assert {abs((ky + size // 2) % size - size // 2), abs((kx + size // 2) % size - size // 2)} == {6}
    _, img = _shade("wood", t)
    ref = _box(_shade("wood", 512)[1], size)
    assert np.corrcoef(img.ravel(), ref.ravel())[0, 1] >= 0.45
    _, img = _shade("text", t)
    letters = _box((HEIGHTFIELDS["text"](512) < 0.98).astype(float), size) > 0
    near = letters.copy()
    for axis in (0, 1):
        for step in (1, -1):
            near |= np.roll(letters, step, axis)
    d = np.abs(img - np.median(img))
    assert d[near].sum() >= 0.9 * d.sum()


@pytest.mark.parametrize("t", [1024, pytest.param(4096, marks=pytest.mark.regress)])
def test_larger_maps_keep_the_slopes_of_the_reference_size(t):
    """Above 512^2 heights scale with T / 512 (bump_strength), so the relief of a larger map
    of the same scene shades like the 512^2 one (without the scaling: T / 512 times flatter)."""
    assert bump_strength("bumps", t) == SCENES["bumps"][2] * t / REFERENCE_TEXTURE_SIZE
    assert bump_strength("bumps", 64) == bump_strength("bumps", 512) == SCENES["bumps"][2]
    relief = [_shade("bumps", n)[1].std() for n in (512, t)]
    assert abs(relief[1] / relief[0] - 1) < 0.05, relief


def test_texel_coordinates_of_each_geometry():
    """u, v of each covered pixel against the geometry's own parametrization (docs/scenes.md):
    the plane maps the screen once; the globe by longitude phi / 2 pi and colatitude
    theta / pi of its normal; the cylinder's visible half (phi from 180 to 360 deg) carries
    the whole map once across, v down its axis."""
    t, size = 64, 64
    c = (np.arange(size) + 0.5) / size * 2 - 1
    sx, sz = np.meshgrid(c, -c)

    def close(got, want, mask):
        d = np.abs((got - np.floor(want).astype(int)) % t)
        d = np.minimum(d, t - d)[mask]
        assert d.max() <= 1 and np.mean(d == 0) > 0.98

    plane = load_scene("bumps", size=size, texture_size=t)
    close(plane.u, (sx + 1) / 2 * t, plane.mask)
    close(plane.v, (1 - sz) / 2 * t, plane.mask)
    cyl = load_scene("cylinder", size=size, texture_size=t)
    close(cyl.u, t * (1 - np.arccos(np.clip(sx, -1, 1)) / np.pi), cyl.mask)
    close(cyl.v, (1 - sz) / 2 * t, cyl.mask)
    assert cyl.u[5, 0] < 8 and cyl.u[5, -1] > t - 8            # the whole map across
    globe = load_scene("globe", size=size, texture_size=t)
    ny = -np.sqrt(np.clip(1 - sx ** 2 - sz ** 2, 0, 1))
    close(globe.u, t * (np.arctan2(ny, sx) % (2 * np.pi)) / (2 * np.pi), globe.mask)
    close(globe.v, t * np.arccos(np.clip(sz, -1, 1)) / np.pi, globe.mask)
