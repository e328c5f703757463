"""Height fields, scene building and image helpers against the closed forms their docstrings
give: the noise's Fourier interpolation, the brick lines and bevel, the egg-crate, the
normal of a slope, the light direction, the parameter ranges of load_scene, and compose /
psnr / panel."""

import numpy as np
import pytest

from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.common import polar_to_cartesian
from bumprtl.sim.scenes import GEOMETRIES, SCENES, light_direction, load_scene
from bumprtl.sim.scenes.heightfields import (
    BRICK_BEVEL,
    HEIGHTFIELDS,
    brick_lines,
    bricks,
    height_to_normals,
    normals_from_gradient,
    smooth_noise,
)
from bumprtl.sim.scenes.imaging import compose, max_diff, panel, psnr, save_png
from bumprtl.sim.scenes.usermap import BumpMap


def _centres(t):
    return (np.arange(t) + 0.5) / t


# --- height fields ------------------------------------------------------------------------

@pytest.mark.parametrize("t, cells, seed", [(64, 16, 0), (32, 8, 3), (16, 16, 5)])
def test_smooth_noise_interpolates_its_gaussian_grid(t, cells, seed):
    """The Fourier interpolation of a cells x cells grid of Gaussian samples passes through
    the samples: every (T / cells)-th texel is the seed's draw, up to the normalization to
    zero mean and unit deviation (a positive scale and an offset)."""
    coarse = np.random.default_rng(seed).standard_normal((cells, cells))
    fine = smooth_noise(t, cells, seed)
    assert fine.shape == (t, t)
    at = fine[::t // cells, ::t // cells]
    slope, offset = np.polyfit(coarse.ravel(), at.ravel(), 1)
    assert slope > 0 and np.allclose(at, slope * coarse + offset, rtol=0, atol=1e-9)
    assert abs(fine.mean()) < 1e-12 and abs(fine.std() - 1) < 1e-12


def test_smooth_noise_defaults_to_16_cells_of_seed_0():
    assert np.array_equal(smooth_noise(64), smooth_noise(64, cells=16, seed=0))


@pytest.mark.parametrize("t", [16, 32, 64, 128, 512])
def test_brick_lines_closed_form(t):
    """Rows k T/8 - 1/2 and joints (j + k/2) T/4 - 1/2 (mod T: the same four columns in
    every other course, running bond); on a narrow map (bevel 0.12 T/16 at most half a
    texel: T <= 64) half a texel further, on texel centres."""
    rows, joints = brick_lines(t)
    shift = 0.0 if BRICK_BEVEL * t / 16 <= 0.5 else -0.5
    assert (shift == 0.0) == (t <= 64)
    assert rows == [k * t / 8 + shift for k in range(8)]
    assert len(joints) == 8
    for k, js in enumerate(joints):
        assert sorted(js) == sorted(((j + k / 2) * t / 4 + shift) % t for j in range(4)), k


@pytest.mark.parametrize("t", [16, 32, 64])
def test_narrow_bricks_have_mortar_on_the_lines(t):
    """On a narrow map the mortar (height 0) is exactly the texel rows of the course lines
    and, in each course, the columns of its joints; one texel off a line the face is full."""
    h = bricks(t)
    assert h.shape == (t, t) and 0 <= h.min() and h.max() <= 1
    rows, joints = brick_lines(t)
    mortar = np.zeros((t, t), bool)
    for k, r in enumerate(rows):
        mortar[int(r)] = True
        course = slice(int(r), int(r + t / 8))
        for j in joints[k]:
            mortar[course, int(j)] = True
    assert np.all(h[mortar] == 0)
    assert h[~mortar].min() > 0.75                      # the face: 0.9 with a little roughness


@pytest.mark.parametrize("t", [32, 64])
def test_a_narrow_maps_bevel_is_one_texel(t):
    """On a narrow map the bevel widens to one texel: a texel one row off a course line is
    already at the face's full height, as high on average as the rows further in."""
    h = bricks(t)
    rows, joints = brick_lines(t)
    course = t // 8
    dist = np.array([min((i - r) % t for r in rows) for i in range(t)])   # rows below a line
    dist = np.minimum(dist, course - dist)
    keep = np.ones(t, bool)
    for js in joints:
        for j in js:
            keep[[int(j) - 1, int(j), (int(j) + 1) % t]] = False           # off every joint
    near = h[dist == 1][:, keep].mean()
    far = h[dist >= 2][:, keep].mean()
    assert abs(near / far - 1) < 0.02, (near, far)


def test_a_wide_maps_bevel_is_0_12_sixteenths_of_the_map():
    """docs/scenes.md: at 512^2 the bevel of a groove is 0.12/16 of the map, 3.84 texels: a
    texel centre d texels from a line rises d / 3.84 of the way to the face, across a
    course line (rows) and across a joint (columns)."""
    t = 512
    h = bricks(t)
    width = BRICK_BEVEL * t / 16
    rows, joints = brick_lines(t)
    d = np.arange(6) + 0.5                               # texel centres beside a line
    want = np.clip(d / width, 0, 1)
    # on both sides of course line 2 (row 127.5), in a column a quarter brick from the
    # joints of the courses above and below (running bond: theirs are half a brick apart)
    line, col = rows[2], int(joints[2][1] + t / 16)
    for side in (1, -1):
        ramp = h[(line + side * d).astype(int), col]
        assert np.allclose(ramp / ramp[-1], want, rtol=0, atol=0.05), (side, ramp / ramp[-1])
    # on both sides of joint 1 of course 3, in a row at the course's middle
    mid = int(rows[3] + t / 16)
    for side in (1, -1):
        ramp = h[mid, (joints[3][1] + side * d).astype(int)]
        assert np.allclose(ramp / ramp[-1], want, rtol=0, atol=0.05), (side, ramp / ramp[-1])


@pytest.mark.parametrize("t", [32, 512])
def test_brick_faces_are_slightly_rough(t):
    """The faces are 'slightly rough' (many distinct normals): off the grooves the height
    varies a little around a level below 1, never flat and never more than a few percent."""
    h = bricks(t)
    face = h[h > 0.6 * h.max()]
    assert 0.5 < np.median(face) < 1 and len(np.unique(face)) > face.size // 2
    assert 0.002 < face.std() < 0.1


@pytest.mark.parametrize("t", [16, 64])
def test_bumps_is_an_egg_crate_of_6_by_6_periods(t):
    """0.5 + 0.5 sin(2 pi 6 u) sin(2 pi 6 v) at the texel centres u, v = (i + 1/2) / T."""
    u, v = np.meshgrid(_centres(t), _centres(t))
    want = 0.5 + 0.5 * np.sin(2 * np.pi * 6 * u) * np.sin(2 * np.pi * 6 * v)
    assert np.allclose(HEIGHTFIELDS["bumps"](t), want, rtol=0, atol=1e-12)


def test_every_height_field_is_in_the_unit_range():
    """Height fields: T x T, values in [0, 1], not flat."""
    for name, field in HEIGHTFIELDS.items():
        for t in (16, 64, 128):
            h = field(t)
            assert h.shape == (t, t) and h.dtype == np.float64, (name, t)
            assert 0 <= h.min() and h.max() <= 1 and np.ptp(h) > 0.01, (name, t)


def test_text_is_dark_letters_on_a_white_face():
    """Engraved text: the flat face is white (1.0) and covers most of the map; the letters
    are cut into it (dark)."""
    for t in (64, 128):
        h = HEIGHTFIELDS["text"](t)
        assert h.max() == 1.0 and np.mean(h == 1.0) > 0.5 and h.min() < 0.5, t


def test_a_photographs_heights_keep_its_mean_grey():
    """scikit-image's pictures as heights: grey / 255, resampled (not cropped) to T."""
    import skimage.data
    for name in ("brick", "gravel", "moon"):
        whole = getattr(skimage.data, name)() / 255.0
        h = HEIGHTFIELDS[name](64)
        assert h.shape == (64, 64) and abs(h.mean() - whole.mean()) < 5e-4, name
        coarse = whole.reshape(64, 8, 64, 8).mean(axis=(1, 3))
        assert np.corrcoef(h.ravel(), coarse.ravel())[0, 1] > 0.8, name


def test_normals_from_gradient_closed_form():
    """n' = normalize(-dh/dv, -dh/du, 1), phi = atan2(n'y, n'x) in [0, 2 pi), theta = acos(n'z)."""
    rng = np.random.default_rng(21)
    dv, du = rng.normal(size=(2, 40))
    phi, theta = normals_from_gradient(dv, du)
    n = np.stack([-dv, -du, np.ones_like(dv)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    assert np.allclose(polar_to_cartesian(phi, theta), n, rtol=0, atol=1e-12)
    assert np.all((0 <= phi) & (phi < 2 * np.pi)) and np.allclose(theta, np.arccos(n[:, 2]))
    phi0, theta0 = normals_from_gradient([0.0], [0.0])
    assert theta0[0] == 0.0


def test_height_to_normals_is_a_wrapping_central_difference():
    """slope per step = strength (h[i+1] - h[i-1]) / 2 along rows (v) and columns (u), the
    neighbours of an edge texel taken from the other edge."""
    rng = np.random.default_rng(22)
    h = rng.uniform(size=(8, 8))
    s = 2.5
    dv, du = np.zeros_like(h), np.zeros_like(h)
    for i in range(8):
        for j in range(8):
            dv[i, j] = s * (h[(i + 1) % 8, j] - h[(i - 1) % 8, j]) / 2
            du[i, j] = s * (h[i, (j + 1) % 8] - h[i, (j - 1) % 8]) / 2
    phi, theta = height_to_normals(h, s)
    want = np.stack([-dv, -du, np.ones_like(h)], -1)
    want /= np.linalg.norm(want, axis=-1, keepdims=True)
    assert np.allclose(polar_to_cartesian(phi, theta), want, rtol=0, atol=1e-12)
    ints = np.arange(16).reshape(4, 4) % 3
    assert np.allclose(height_to_normals(ints, 2)[1], height_to_normals(ints.astype(float), 2.0)[1])
    assert np.array_equal(height_to_normals(h)[1], height_to_normals(h, 1.0)[1])


@pytest.mark.parametrize("height, strength, words", [
    (np.zeros((4, 4), bool), 1.0, "real-valued array, got dtype bool"),
    (np.zeros((4, 4, 1)), 1.0, "non-empty 2-D array, got shape (4, 4, 1)"),
    (np.zeros((0, 0)), 1.0, "non-empty 2-D array, got shape (0, 0)"),
    (np.zeros((4, 4)), True, "strength must be a positive finite number, got True"),
    (np.zeros((4, 4)), 0.0, "strength must be a positive finite number, got 0.0"),
    (np.zeros((4, 4)), float("inf"), "got inf"),
    (np.zeros((4, 4)), "1", "got '1'"),
    (np.array([[0.0, np.inf], [0.0, 0.0]]), 1.0, "height map contains NaN or infinity"),
])
def test_height_to_normals_refusals(height, strength, words):
    with pytest.raises(BumpError) as e:
        height_to_normals(height, strength)
    assert str(e.value).startswith(words) or str(e.value).endswith(words), str(e.value)


# --- the scene ---------------------------------------------------------------------------------

def test_light_direction_closed_form():
    """cos(el) cos(az) right + cos(el) sin(az) up + sin(el) toward the viewer (-y)."""
    for el, az in ((0, 0), (0, 180), (0, -90), (-90, 10), (30, 45), (60, -120)):
        e, a = np.radians(el), np.radians(az)
        want = [np.cos(e) * np.cos(a), -np.sin(e), np.cos(e) * np.sin(a)]
        assert np.allclose(light_direction(el, az), want, atol=1e-15), (el, az)
    assert np.allclose(light_direction(0, 0), [1, 0, 0])


def test_load_scene_defaults():
    """Defaults: 512 x 512 pixels, a directional light from elevation 45, azimuth 30."""
    s = load_scene("bumps")
    assert s.size == 512 and s.texture_size == 512
    small = load_scene("bumps", size=16)
    want = light_direction(45.0, 30.0)
    assert np.allclose(polar_to_cartesian(small.px.l_phi, small.px.l_theta), want, atol=1e-12)


def _bump(t):
    """A user's map of T x T texels (zeros: no memory is touched until read)."""
    return BumpMap("mine.npy", "normal", np.zeros((t, t)), np.zeros((t, t)), None)


def test_texture_size_defaults_to_the_image_or_the_map():
    """Without texture_size a procedural map is as large as the image, a user's map its own."""
    s = load_scene("bumps", size=32)
    assert s.texture_size == 32 and s.size == 32 and s.height.shape == (32, 32)
    m = load_scene(None, size=16, bump=_bump(64))
    assert m.texture_size == 64 and m.size == 16 and m.name == "mine.npy" and m.height is None


def test_the_largest_map_is_accepted_and_larger_refused():
    """texture_size: a power of two in [16, 4096], both ends included."""
    assert load_scene(None, size=16, bump=_bump(4096)).texture_size == 4096
    assert load_scene(None, size=16, bump=_bump(16)).texture_size == 16
    for tex in (8192, 8, 48, True, 64.0):
        with pytest.raises(BumpError) as e:
            load_scene("bumps", size=16, texture_size=tex)
        assert str(e.value) == f"texture_size must be a power of two in [16, 4096], got {tex!r}"


@pytest.mark.parametrize("size", [8, 8192, 24, True, 16.0, "16"])
def test_the_image_size_is_a_power_of_two_in_range(size):
    with pytest.raises(BumpError) as e:
        load_scene("bumps", size=size)
    assert str(e.value) == f"size must be a power of two in [16, 4096], got {size!r}"


def test_numpy_integers_and_floats_are_accepted():
    s = load_scene("bumps", size=np.int64(16), texture_size=np.int32(32),
                   light_elevation=np.float32(20), light_azimuth=np.int64(-360))
    assert s.size == 16 and s.texture_size == 32


@pytest.mark.parametrize("pname", ["light_elevation", "light_azimuth"])
@pytest.mark.parametrize("value", ["10", None, False])
def test_a_light_angle_must_be_a_number(pname, value):
    with pytest.raises(BumpError) as e:
        load_scene("bumps", size=16, **{pname: value})
    assert str(e.value).startswith(f"{pname} must be in [") and repr(value) in str(e.value)


def test_a_users_map_replaces_the_scene_and_its_size_must_match():
    """With a map, the scene name is ignored; texture_size must be the map's size."""
    assert load_scene("no-such-scene", size=16, bump=_bump(16)).geometry == "plane"
    with pytest.raises(BumpError) as e:
        load_scene(None, size=16, bump=_bump(32), texture_size=16)
    assert str(e.value) == "texture_size = 16 but the map mine.npy has 32x32 texels"


def test_an_unknown_scene_or_geometry_is_refused_listing_the_choices():
    with pytest.raises(BumpError) as e:
        load_scene("marble", size=16)
    assert str(e.value) == f"scene must be one of {', '.join(SCENES)}, got 'marble'"
    with pytest.raises(BumpError) as e:
        load_scene("bumps", size=16, geometry="cube")
    assert str(e.value) == f"geometry must be one of {', '.join(GEOMETRIES)}, got 'cube'"


def test_a_geometry_overrides_the_scenes_own():
    for geometry in GEOMETRIES:
        assert load_scene("globe", size=16, geometry=geometry).geometry == geometry
    assert load_scene("globe", size=16).geometry == "sphere"
    assert load_scene("cylinder", size=16).geometry == "cylinder"


def test_the_colour_textures_follow_the_height():
    """Bricks blend the mortar colour (height 0) into the brick colour (height 1); wood's
    colour brightens with the height; the other scenes have no colour texture."""
    for name in ("bricks", "cylinder", "wood"):
        s = load_scene(name, size=32)
        assert s.albedo is not None and s.albedo.shape == (32, 32, 3), name
        h = np.clip(s.height, 0, 1).ravel()
        a = s.albedo.reshape(-1, 3)
        lo, hi = np.argmin(h), np.argmax(h)
        affine = a[lo] + (h[:, None] - h[lo]) / (h[hi] - h[lo]) * (a[hi] - a[lo])
        assert np.allclose(a, affine, atol=1e-12), name
    bricks_ = load_scene("bricks", size=32)
    mortar, brick = bricks_.albedo[bricks_.height == 0][0], bricks_.albedo[np.argmax(bricks_.height) // 32,
                                                                         np.argmax(bricks_.height) % 32]
    assert mortar[1] > brick[1] and brick[0] > brick[1] > brick[2]    # grey mortar, red brick
    wood = load_scene("wood", size=32)
    assert np.all(np.diff(wood.albedo[np.argsort(wood.height.ravel()) // 32,
                                      np.argsort(wood.height.ravel()) % 32], axis=0) >= -1e-12)
    for name in ("bumps", "text", "moon", "globe"):
        assert load_scene(name, size=16).albedo is None, name


# --- images ----------------------------------------------------------------------------------

def test_compose_multiplies_the_albedo_and_rounds():
    """8-bit RGB = round(255 x intensity x albedo) inside the geometry, black outside."""
    s = load_scene("bricks", size=32, geometry="sphere")
    color = np.linspace(0, 1, 32 * 32).reshape(32, 32)
    img = compose(s, color)
    want = np.clip(np.rint(color[..., None] * s.albedo[s.v, s.u] * 255), 0, 255)
    assert img.dtype == np.uint8 and img.shape == (32, 32, 3)
    assert np.array_equal(img[s.mask], want[s.mask]) and np.all(img[~s.mask] == 0)
    g = load_scene("globe", size=32)
    grey = compose(g, np.full((32, 32), 0.5))
    assert np.all(grey[g.mask] == 128)


def test_psnr_closed_form_for_a_uniform_difference():
    a = np.zeros((4, 4), np.uint8)
    b = np.full((4, 4), 5, np.uint8)
    assert abs(psnr(a, b) - 10 * np.log10(255.0 ** 2 / 25)) < 1e-12
    assert psnr(b, a) == psnr(a, b) and max_diff(a, b) == 5 and isinstance(max_diff(a, b), int)


def test_panel_of_greyscale_images_and_its_gain():
    ref = np.zeros((3, 2), np.uint8)
    img = np.full((3, 2), 7, np.uint8)
    p = panel(ref, img, gain=2)
    assert p.shape == (3, 2 + 4 + 2 + 4 + 2) and p.dtype == np.uint8
    assert np.all(p[:, 2:6] == 255) and np.all(p[:, 8:12] == 255)
    assert np.all(p[:, 12:] == 14) and np.all(p[:, 6:8] == 7) and np.all(p[:, :2] == 0)
    assert np.all(panel(img, ref)[:, 12:] == 70)         # |difference| x 10 by default


def test_save_png_returns_the_path_it_wrote(tmp_path):
    """save_png makes the missing directories (or reuses them) and writes 8-bit pixels,
    also from an integer array of 8-bit values."""
    from PIL import Image
    grey = np.arange(12, dtype=np.uint8).reshape(3, 4)
    path = save_png(str(tmp_path / "a" / "b" / "g.png"), grey)
    assert path == tmp_path / "a" / "b" / "g.png"
    assert np.array_equal(np.asarray(Image.open(path)), grey)
    again = save_png(tmp_path / "a" / "b" / "h.png", np.arange(12).reshape(3, 4) * 20)
    back = np.asarray(Image.open(again))
    assert back.dtype == np.uint8 and np.array_equal(back, np.arange(12).reshape(3, 4) * 20)
