"""Golden model of the palette method (Tarini et al.): preprocessing, colour tables, renders."""

import numpy as np
import pytest

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.common import shade
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.palette import (
    Material,
    color_table,
    displacement_to_normals,
    lookup,
    mipmap_indices,
    quantize_normal_map,
    render_palette,
    world_normal_map,
)
from bumprtl.sim.golden.float.palette_quantize import QUANTIZERS
from bumprtl.sim.scenes import load_scene
from bumprtl.sim.scenes.imaging import compose, max_diff, psnr


def random_normals(t, seed=0, spread=0.6):
    rng = np.random.default_rng(seed)
    n = np.concatenate([rng.normal(0, spread, (t, t, 2)), np.ones((t, t, 1))], -1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def sse(normals, qmap):
    return float(np.sum((normals - qmap.table[qmap.indices]) ** 2))


# --- Sec. 4.1: displacement -> normal map --------------------------------------------------

def test_least_squares_cross_is_central_difference():
    rng = np.random.default_rng(1)
    h = rng.uniform(0, 1, (16, 16))
    n = displacement_to_normals(h, scale=3.0)
    d_row = 3.0 * (np.roll(h, -1, 0) - np.roll(h, 1, 0)) / 2
    d_col = 3.0 * (np.roll(h, -1, 1) - np.roll(h, 1, 1)) / 2
    ref = np.stack([-d_row, -d_col, np.ones_like(h)], -1)
    assert np.allclose(n, ref / np.linalg.norm(ref, axis=-1, keepdims=True), atol=1e-12)


def test_least_squares_plane_is_exact_with_3x3_stencil():
    r, c = np.indices((32, 32), dtype=float)
    h = 0.2 * r - 0.1 * c                     # a plane: interior normals all the same
    stencil = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)]
    n = displacement_to_normals(h, offsets=stencil)[2:-2, 2:-2]
    want = np.array([-0.2, 0.1, 1.0]) / np.linalg.norm([-0.2, 0.1, 1.0])
    assert np.allclose(n, want, atol=1e-12)


# --- Sec. 4: quantization -------------------------------------------------------------------

@pytest.mark.parametrize("quantizer", list(QUANTIZERS))
def test_quantizer_gives_table_and_nearest_indices(quantizer):
    n = random_normals(24)
    q = quantize_normal_map(n, 64, quantizer)
    assert q.table.shape == (64, 3) and q.indices.shape == (24, 24)
    assert np.allclose(np.linalg.norm(q.table, axis=1), 1)
    d = np.linalg.norm(n[:, :, None, :] - q.table[None, None], axis=-1)   # brute force
    assert np.allclose(d[np.arange(24)[:, None], np.arange(24), q.indices], d.min(-1))
    assert len(np.unique(q.indices)) > 48        # the table is used, not a few entries


def test_kmeans_never_worse_than_median_cut_and_error_falls_with_size():
    n = random_normals(32, seed=2)
    errs = {s: sse(n, quantize_normal_map(n, s, "median-cut")) for s in (16, 64, 256)}
    assert errs[16] > errs[64] > errs[256]
    for s in (16, 64):
        assert sse(n, quantize_normal_map(n, s, "kmeans")) <= errs[s]


def test_palette_as_large_as_distinct_normals_is_lossless():
    base = random_normals(4, seed=3).reshape(-1, 3)           # 16 distinct normals
    n = base[np.random.default_rng(0).integers(0, 16, (20, 20))]
    q = quantize_normal_map(n, 16, "kmeans")
    assert np.allclose(q.table[q.indices], n, atol=1e-12)


def _closed_form_map(k=8, tile=2):
    """A (k * tile)^2 map of k^2 distinct unit normals in closed form: texel (i, j) has the
    normal at azimuth 2 pi (i mod k) / k and polar angle 0.1 + 0.5 (j mod k) / k."""
    i, j = np.indices((k * tile, k * tile)) % k
    az, pol = 2 * np.pi * i / k, 0.1 + 0.5 * j / k
    return np.stack([np.cos(az) * np.sin(pol), np.sin(az) * np.sin(pol), np.cos(pol)], -1)


@pytest.mark.parametrize("size", [64, 65, 16384])
@pytest.mark.parametrize("quantizer", list(QUANTIZERS))
def test_palette_at_least_the_distinct_normals_stores_each_exactly(size, quantizer):
    """sN >= the number of distinct normals (64 here, by construction) is valid: the table
    is the 64 normals, every texel looks up its own normal exactly (against the closed form),
    nothing is quantized, with or without dithering; one entry fewer quantizes."""
    n = _closed_form_map()
    for dither in (False, True):
        q = quantize_normal_map(n, size, quantizer, dither=dither)
        assert q.exact and q.distinct == 64 and q.table.shape == (64, 3)
        assert np.abs(q.table[q.indices] - n).max() < 1e-15
        assert len(np.unique(q.indices)) == 64
    fewer = quantize_normal_map(n, 63, quantizer)
    assert not fewer.exact and fewer.table.shape == (63, 3)
    assert np.abs(fewer.table[fewer.indices] - n).max() > 1e-3


def test_palette_storing_every_normal_keeps_materials_apart():
    n = _closed_form_map(k=4, tile=4)                                  # 16 distinct normals
    mats = (np.arange(16)[:, None] + np.zeros(16, int)) // 8           # each normal in both
    q = quantize_normal_map(n, 64, "median-cut", materials=mats)
    assert q.exact and q.distinct == 32 and len(q.table) == 32
    assert np.array_equal(q.materials[q.indices], mats)
    assert np.abs(q.table[q.indices] - n).max() < 1e-15


def test_dithering_keeps_block_means_closer():
    """Ordered dithering trades per-texel error for a better local average (Fig. 4)."""
    t = 32
    phi = np.linspace(0, 0.8, t)[None, :].repeat(t, 0)
    n = np.stack([np.sin(phi), np.zeros_like(phi), np.cos(phi)], -1)   # a smooth ramp
    n[..., 1] = np.linspace(-0.3, 0.3, t)[:, None]
    n /= np.linalg.norm(n, axis=-1, keepdims=True)

    def block_error(q):
        rec = q.table[q.indices].reshape(8, 4, 8, 4, 3).mean((1, 3))
        return np.abs(rec - n.reshape(8, 4, 8, 4, 3).mean((1, 3))).mean()
    plain = quantize_normal_map(n, 16, "median-cut")
    dith = quantize_normal_map(n, 16, "median-cut", dither=True)
    assert not np.array_equal(plain.indices, dith.indices)
    assert block_error(dith) < block_error(plain)


def test_materials_never_share_an_entry():
    n = random_normals(16, seed=4)
    mats = (np.arange(16)[:, None] + np.zeros(16, int)) // 8          # top half 0, bottom 1
    q = quantize_normal_map(n, 32, "median-cut", materials=mats)
    assert np.array_equal(q.materials[q.indices], mats)
    assert np.all(np.diff(q.materials) >= 0)                           # sorted: intervals


def test_mipmap_levels_pick_nearest_to_mean():
    n = random_normals(8, seed=5)
    q = quantize_normal_map(n, 16, "median-cut")
    levels = mipmap_indices(q)
    assert [lv.shape[0] for lv in levels] == [8, 4, 2, 1]
    mean = q.table[q.indices[:2, :2]].reshape(-1, 3).mean(0)
    mean /= np.linalg.norm(mean)
    assert levels[1][0, 0] == np.argmin(np.linalg.norm(q.table - mean, axis=1))


# --- Sec. 5.1 / 6 / 7.3: colour tables ---------------------------------------------------------

def test_phong_table_is_the_per_pixel_shade_of_the_table_normals():
    cfg = Config()
    table = random_normals(4, seed=6).reshape(-1, 3)
    l = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    v = np.array([0.0, 0.0, 1.0])
    h = (l + v) / np.linalg.norm(l + v)
    c = color_table(table, "phong", l, v, cfg)
    assert np.allclose(c[:, 0], shade(table @ l, table @ h, cfg).color)
    assert np.allclose(c[:, 3], np.clip(cfg.ka + cfg.kd * np.clip(table @ l, 0, 1), 0, 1))


def test_lambert_several_lights_add_up():
    cfg = Config()
    table = random_normals(4, seed=7).reshape(-1, 3)
    lights = np.array([[0, 0, 1.0], [1.0, 0, 0], [0, 0.6, 0.8]])
    c = color_table(table, "lambert", lights, [0, 0, 1.0], cfg)
    want = cfg.ka + cfg.kd * sum(np.clip(table @ l, 0, 1) for l in lights)
    assert np.allclose(c[:, 0], np.clip(want, 0, 1))


def test_blend_layout_is_specular_rgb_and_lambert_alpha_sec_7_1():
    """blend=True (Sec. 7.1/7.2, the table a colour texture is blended with): alpha the
    Lambert intensity ka + kd sum clamp(N.L), each of R, G, B the specular sum ks sum
    clamp(N.H)**n with H = normalize(L + V), both clamped to [0, 1]; per material too."""
    cfg = Config()
    table = random_normals(4, seed=11).reshape(-1, 3)
    lights = np.array([[0, 0, 1.0], [0.6, 0, 0.8]])
    view = np.array([0, 0.6, 0.8])
    halfway = [(l + view) / np.linalg.norm(l + view) for l in lights]

    def want(m):
        lambert = m.ka + m.kd * sum(np.clip(table @ l, 0, 1) for l in lights)
        spec = m.ks * sum(np.clip(table @ h, 0, 1) ** m.spec_exponent for h in halfway)
        return np.clip(spec, 0, 1), np.clip(lambert, 0, 1)

    c = color_table(table, "phong", lights, view, cfg, blend=True)
    spec, lambert = want(Material.from_config(cfg))
    assert np.allclose(c[:, :3], spec[:, None]) and np.allclose(c[:, 3], lambert)
    mats = np.arange(len(table)) % 2
    params = [Material(ks=0.0), Material(ka=0.2, kd=0.5, ks=0.6, spec_exponent=4)]
    c = color_table(table, "phong", lights, view, cfg, materials=mats, material_params=params,
                    blend=True)
    for m, p in enumerate(params):
        spec, lambert = want(p)
        sel = mats == m
        assert np.allclose(c[sel, :3], spec[sel, None]) and np.allclose(c[sel, 3], lambert[sel])


@pytest.mark.parametrize("model", ["lambert", "phong", "chrome", "toon"])
def test_every_lighting_model_tints_by_the_material_colour(model):
    """Sec. 7.3, colour as material: without a highlight (ks = 0) an entry's RGB is the
    white material's RGB times the material's colour, channel by channel, in every lighting
    model (Lambert, Phong, chrome's environment, toon's bands); the alpha (Lambert
    intensity) does not depend on the colour."""
    table = random_normals(6, seed=12).reshape(-1, 3)
    lights, view = [[0, 0.6, 0.8]], [0, 0.0, 1.0]
    colour = (0.9, 0.5, 0.2)
    white = color_table(table, model, lights, view, material_params=[Material(ks=0.0)],
                        materials=np.zeros(len(table), np.int64))
    tinted = color_table(table, model, lights, view,
                         material_params=[Material(ks=0.0, color=colour)],
                         materials=np.zeros(len(table), np.int64))
    unclipped = (white[:, :3] < 1).all(-1)
    assert unclipped.sum() >= len(table) // 2
    assert np.allclose(tinted[unclipped, :3], white[unclipped, :3] * colour)
    assert np.allclose(tinted[:, 3], white[:, 3])


def test_a_config_without_specular_gives_a_table_without_highlights():
    """Config(specular=False) builds no H path and no cos^n table; the palette table made
    from it has no specular term either: phong equals lambert, the blend layout's RGB is 0."""
    cfg = Config(specular=False)
    table = random_normals(4, seed=13).reshape(-1, 3)
    lights, view = [[0, 0.6, 0.8]], [0, 0.0, 1.0]
    assert Material.from_config(cfg).ks == 0.0
    phong = color_table(table, "phong", lights, view, cfg)
    assert np.allclose(phong, color_table(table, "lambert", lights, view, cfg))
    assert np.allclose(color_table(table, "phong", lights, view, cfg, blend=True)[:, :3], 0)


def test_chrome_reflects_the_viewer_and_toon_has_few_levels():
    table = np.array([[0, -1.0, 0], [0, -0.6, 0.8], [0, -0.6, -0.8]])
    view = np.array([0, -1.0, 0])
    chrome = color_table(table, "chrome", [0, -1.0, 0], view)
    assert chrome[1, 2] > chrome[1, 0] and chrome[2, 0] > chrome[2, 2]   # sky above, ground below
    toon = color_table(random_normals(16, seed=8).reshape(-1, 3), "toon", [0, 0, 1.0], [0, 0, 1.0])
    assert len(np.unique(toon[:, 0])) <= 4


def test_colour_as_material_sec_7_3():
    table = random_normals(4, seed=9).reshape(-1, 3)
    mats = np.repeat([0, 1], 8)
    red = Material(color=(1.0, 0.0, 0.0), ks=0.0)
    blue = Material(color=(0.0, 0.0, 1.0), ks=0.5, spec_exponent=8)
    c = color_table(table, "phong", [0, 0, 1.0], [0, 0, 1.0], materials=mats, material_params=[red, blue])
    assert np.all(c[:8, 1:3] == 0) and np.all(c[8:, 2] >= c[8:, 0])
    assert np.allclose(c[:8, 0], np.clip(red.ka + red.kd * np.clip(table[:8, 2], 0, 1), 0, 1))


# --- bad input ---------------------------------------------------------------------------------

@pytest.mark.parametrize("normals, size, match", [
    (random_normals(8)[:, :6], 16, "square"),
    (np.zeros((0, 0, 3)), 16, "square"),
    (np.where(np.arange(64).reshape(8, 8, 1) == 5, np.nan, random_normals(8)), 16, "NaN"),
    (np.where(np.arange(64).reshape(8, 8, 1) == 5, 0.0, random_normals(8)), 16, "zero-length"),
    (random_normals(8), 8, "palette_size"),
    (random_normals(8), 20000, "palette_size"),
])
def test_bad_input_names_the_parameter(normals, size, match):
    with pytest.raises(BumpError, match=match):
        quantize_normal_map(normals, size)


def test_bad_names_and_indices():
    with pytest.raises(BumpError, match="quantizer"):
        quantize_normal_map(random_normals(8), 16, "octree")
    with pytest.raises(BumpError, match="lighting"):
        color_table(np.eye(3), "cel", [0, 0, 1.0], [0, 0, 1.0])
    with pytest.raises(BumpError, match="outside the table"):
        lookup(np.array([[0, 3]]), np.zeros((3, 4)))
    with pytest.raises(BumpError, match="height"):
        displacement_to_normals(np.zeros((4, 5, 1)))


# --- renders against the per-pixel reference ---------------------------------------------------

def test_palette_psnr_grows_with_size_on_a_small_scene():
    cfg = Config()
    scene = load_scene("wood", size=64)
    ref = compose(scene, conventional(scene.px, cfg).color)
    scores = [psnr(ref, compose(scene, render_palette(scene, cfg, s, "kmeans").color))
              for s in (16, 64, 256, 1024)]
    assert all(a < b for a, b in zip(scores, scores[1:], strict=False)), scores


def test_plane_is_exact_up_to_quantization():
    """With as many palette entries as distinct normals, a plane under a directional light
    renders like the per-pixel reference up to the 8-bit rounding of the table (1 LSB)."""
    cfg = Config()
    scene = load_scene("bumps", size=32)
    normals, counts = world_normal_map(scene)
    n_distinct = len(np.unique(normals[counts > 0], axis=0))
    r = render_palette(scene, cfg, n_distinct, "median-cut")
    ref = compose(scene, conventional(scene.px, cfg).color)
    assert max_diff(ref, compose(scene, r.color)) <= 1


@pytest.mark.parametrize("normals, words", [
    (random_normals(8)[:, :6], "must be a non-empty square (T, T, 3) map, got shape (8, 6, 3)"),
    (np.where(np.arange(64).reshape(8, 8, 1) == 5, np.nan, random_normals(8)), "contains NaN or infinity"),
    (np.where(np.arange(64).reshape(8, 8, 1) == 5, 0.0, random_normals(8)), "has a zero-length normal at texel (0, 5)"),
])
def test_a_bad_normal_map_is_named_normals(normals, words):
    """The message starts with the parameter's name, then says what is wrong and where."""
    with pytest.raises(BumpError) as e:
        quantize_normal_map(normals, 16)
    assert str(e.value) == f"normals {words}"


def test_unused_texels_do_not_shape_the_table():
    """Sec. 4's weights are use counts: a texel of weight 0 still gets an index but does not
    shape the table. Sixteen used directions and a seventeenth unused one fit a palette of 16
    exactly (the table is the sixteen used normals); without the weights the 17 would not."""
    turn = np.arange(17) * 2 * np.pi / 17
    dirs = np.stack([0.6 * np.cos(turn), 0.6 * np.sin(turn), np.full(17, 0.8)], -1)
    texel = np.arange(32 * 32).reshape(32, 32) % 17
    normals, weights = dirs[texel], np.where(texel == 16, 0, 1)
    q = quantize_normal_map(normals, 16, weights=weights)
    assert q.exact and len(q.table) == 16
    assert np.allclose(np.sort(q.table, axis=0), np.sort(dirs[:16], axis=0))
    assert not quantize_normal_map(normals, 16).exact


def test_height_map_sizes_at_the_edges():
    """An empty height map is refused naming its shape; a 1 x 1 map is one flat texel."""
    with pytest.raises(BumpError, match=r"non-empty 2-D map, got shape \(0, 0\)"):
        displacement_to_normals(np.zeros((0, 0)))
    assert np.allclose(displacement_to_normals(np.full((1, 1), 0.3)), [[[0.0, 0.0, 1.0]]])
