"""The palette method's preprocessing (sim/golden/float/palette.py, palette_quantize.py)
against closed forms and the properties Tarini et al. Sec. 4-5 state: the least-squares
normal of a paraboloid (exact: the central difference of a quadratic is its derivative),
the validators refusing exactly what their docstrings say, every quantized texel a unit
table normal nearest to its own (to its dithered copy with dithering), Lloyd's iterations
never raising the weighted error, the material component kept apart and unnormalized."""

import numpy as np
import pytest

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.common import polar_to_cartesian
from bumprtl.sim.golden.float.palette import (
    MATERIAL_SCALE,
    Material,
    check_normal_map,
    color_table,
    displacement_to_normals,
    frame_directions,
    lookup,
    mipmap_indices,
    nearest_spacing,
    quantize_normal_map,
)
from bumprtl.sim.golden.float.palette_quantize import (
    bayer_offsets,
    distinct,
    kmeans,
    median_cut,
    nearest,
)


def _normals(t, seed=0, spread=0.6):
    rng = np.random.default_rng(seed)
    n = np.concatenate([rng.normal(0, spread, (t, t, 2)), np.ones((t, t, 1))], -1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# --- Sec. 4.1: displacement -> normals --------------------------------------------------------

@pytest.mark.parametrize("scale", [1.0, 0.25, 3.0])
def test_paraboloid_normals_are_its_gradient_in_the_interior(scale):
    """h = c ((r - r0)**2 + (col - c0)**2): the cross's least-squares plane has slopes
    (dh/dr, dh/dcol) = 2 c (r - r0, col - c0) exactly (a quadratic's central difference), so
    N = normalize(-s dh/dr, -s dh/dcol, 1) with s = scale; at the apex N = +z."""
    t, c = 16, 0.05
    r, col = np.indices((t, t), dtype=np.float64)
    h = c * ((r - 7) ** 2 + (col - 9) ** 2)
    n = displacement_to_normals(h, scale)
    want = _unit(np.stack([-scale * 2 * c * (r - 7), -scale * 2 * c * (col - 9), np.ones_like(h)], -1))
    assert np.allclose(n[1:-1, 1:-1], want[1:-1, 1:-1], atol=1e-12)
    assert np.allclose(n[7, 9], [0, 0, 1], atol=1e-15)
    assert np.allclose(np.linalg.norm(n, axis=-1), 1, atol=1e-15)


def test_a_constant_height_and_a_periodic_ramp_along_columns():
    """A flat map: +z everywhere (any scale). h = sin(2 pi col / T) wraps: N tilts only in
    y, by the central difference s (sin(w (c + 1)) - sin(w (c - 1))) / 2 = s sin(w) cos(w c)."""
    assert np.allclose(displacement_to_normals(np.full((8, 8), 5.0), 4.0), [0, 0, 1], atol=1e-13)
    t = 16
    w = 2 * np.pi / t
    col = np.arange(t)[None, :].repeat(t, 0)
    n = displacement_to_normals(np.sin(w * col), 2.0)
    slope = 2.0 * np.sin(w) * np.cos(w * col)
    assert np.allclose(n, _unit(np.stack([np.zeros_like(slope), -slope, np.ones_like(slope)], -1)), atol=1e-12)


@pytest.mark.parametrize("height, words", [
    (np.zeros((4, 4, 1)), "got shape (4, 4, 1)"),
    (np.zeros(4), "got shape (4,)"),
    (np.zeros((0, 4)), "got shape (0, 4)"),
])
def test_height_maps_that_are_not_2d_are_refused_by_shape(height, words):
    with pytest.raises(BumpError) as e:
        displacement_to_normals(height)
    assert str(e.value) == f"height must be a non-empty 2-D map, {words}"


def test_a_non_square_height_map_is_fitted_wrapping_each_axis_by_its_own_length():
    """An (H, W) map (a non-square map, texture_height < texture_size): the fit of a
    column-only ramp of period W is the square map's, row by row; each axis wraps by its own
    length (a roll by H along rows, by W along columns leaves the normals unchanged)."""
    rng = np.random.default_rng(3)
    h = rng.random((8, 16))
    n = displacement_to_normals(h, 2.0)
    assert n.shape == (8, 16, 3)
    assert np.allclose(displacement_to_normals(np.roll(h, (3, 5), (0, 1)), 2.0),
                       np.roll(n, (3, 5), (0, 1)), atol=1e-12)
    ramp = np.sin(2 * np.pi * np.arange(16) / 16)
    square = displacement_to_normals(np.tile(ramp, (16, 1)), 2.0)
    assert np.allclose(displacement_to_normals(np.tile(ramp, (8, 1)), 2.0), square[:8], atol=1e-12)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_height_map_with_a_non_finite_value_is_refused(bad):
    h = np.zeros((4, 4))
    h[2, 1] = bad
    with pytest.raises(BumpError, match="^height contains NaN or infinity$"):
        displacement_to_normals(h)


# --- check_normal_map --------------------------------------------------------------------------

def test_check_normal_map_returns_the_unit_vectors_of_any_non_zero_lengths():
    rng = np.random.default_rng(1)
    n = rng.normal(size=(5, 5, 3)) * rng.uniform(1e-9, 1e3, (5, 5, 1))
    got = check_normal_map(n)
    assert np.allclose(np.linalg.norm(got, axis=-1), 1, atol=1e-15)
    assert np.allclose(got * np.linalg.norm(n, axis=-1, keepdims=True), n, rtol=1e-12)
    one = check_normal_map(np.array([[[0.0, 0.0, 2.0]]]))           # 1 x 1 is square
    assert one.tolist() == [[[0.0, 0.0, 1.0]]]
    tiny = check_normal_map(np.array([[[1e-12, 0.0, 0.0]]]))        # short but not zero
    assert tiny.tolist() == [[[1.0, 0.0, 0.0]]]


@pytest.mark.parametrize("shape", [(4, 4, 4), (4, 4, 2), (4, 4), (4, 4, 3, 1), (4, 3, 3), (0, 0, 3)])
def test_check_normal_map_refuses_every_other_shape_naming_it(shape):
    with pytest.raises(BumpError) as e:
        check_normal_map(np.ones(shape), name="tbl")
    assert str(e.value) == f"tbl must be a non-empty square (T, T, 3) map, got shape {shape}"


def test_check_normal_map_names_the_first_zero_texel_row_then_column():
    n = _normals(6)
    n[3, 1] = 0.0
    n[4, 0] = 0.0
    with pytest.raises(BumpError) as e:
        check_normal_map(n, name="m")
    assert str(e.value) == "m has a zero-length normal at texel (3, 1)"
    n = _normals(6)
    n[2, 4, 0] = np.inf
    with pytest.raises(BumpError, match="^m contains NaN or infinity$"):
        check_normal_map(n, name="m")


# --- Sec. 4: quantization ----------------------------------------------------------------------

def _check_nearest(vectors, table, idx):
    d = np.linalg.norm(vectors[:, None, :] - table[None], axis=-1)
    assert np.allclose(d[np.arange(len(vectors)), idx], d.min(-1), rtol=0, atol=1e-14)


@pytest.mark.parametrize("quantizer", ["median-cut", "kmeans"])
@pytest.mark.parametrize("size", [16, 37])
def test_every_texel_gets_a_unit_table_normal_nearest_to_it(quantizer, size):
    """Sec. 4: the table has sN unit normals (not the exact case), each index is in it and
    names the entry nearest to the texel's (normalized) normal; the map keeps its shape."""
    n = 2.5 * _normals(12, seed=3)                       # not unit: check_normal_map's job
    q = quantize_normal_map(n, size, quantizer)
    assert not q.exact and q.size == size == len(q.table) and q.distinct == 144
    assert q.indices.shape == (12, 12) and q.indices.min() >= 0 and q.indices.max() < size
    assert np.allclose(np.linalg.norm(q.table, axis=1), 1, atol=1e-15)
    _check_nearest(_unit(n).reshape(-1, 3), q.table, q.indices.ravel())
    assert q.materials is None


def test_dithering_picks_the_entry_nearest_to_the_bayer_moved_normal():
    """Sec. 4, Fig. 4: each normal moved by its Bayer offset times the spacing of the table
    around its nearest entry (the distance to that entry's nearest other entry), then
    renormalized, gets the entry nearest to the moved normal."""
    n = _normals(8, seed=4, spread=0.3)
    q = quantize_normal_map(n, 16, "median-cut", dither=True)
    flat = n.reshape(-1, 3)
    d = np.linalg.norm(q.table[:, None] - q.table[None], axis=-1)
    spacing = np.sort(d, axis=1)[:, 1]
    own = np.argmin(np.linalg.norm(flat[:, None] - q.table[None], axis=-1), axis=1)
    moved = _unit(flat + spacing[own][:, None] * bayer_offsets((8, 8)).reshape(-1, 3))
    _check_nearest(moved, q.table, q.indices.ravel())
    assert np.array_equal(nearest_spacing(q.table), spacing)
    plain = quantize_normal_map(n, 16, "median-cut")
    assert np.array_equal(plain.table, q.table) and not np.array_equal(plain.indices, q.indices)


@pytest.mark.parametrize("materials, words", [
    (np.zeros((8, 7), np.int64), "shape (8, 7) dtype int64"),
    (np.zeros((8, 8)), "shape (8, 8) dtype float64"),
    (np.full((8, 8), -1), "shape (8, 8) dtype int64"),
])
def test_materials_must_be_a_non_negative_integer_map_like_the_normals(materials, words):
    with pytest.raises(BumpError) as e:
        quantize_normal_map(_normals(8), 16, materials=materials)
    assert str(e.value) == ("materials must be a (T, T) map of non-negative integers like the "
                            f"normals, got {words}")


def test_materials_are_kept_apart_sorted_and_read_back_as_integers():
    """Sec. 6: the material a fourth component MATERIAL_SCALE apart, so no entry mixes two;
    the table sorted by material (intervals); materials 0 and 2 (none of 1) read back."""
    n = _normals(8, seed=5)
    mats = np.where(np.arange(8)[:, None] < 3, 2, 0) + np.zeros(8, np.int64)
    for quantizer in ("median-cut", "kmeans"):
        q = quantize_normal_map(n, 16, quantizer, materials=mats.astype(np.uint8))
        assert q.materials.dtype == np.int64 and set(q.materials.tolist()) == {0, 2}
        assert np.all(np.diff(q.materials) >= 0)
        assert np.array_equal(q.materials[q.indices], mats)
        assert np.allclose(np.linalg.norm(q.table, axis=1), 1, atol=1e-15)


def test_dithering_keeps_each_texels_material():
    """Sec. 6 with Sec. 4's dithering: the Bayer offset moves the normal only (then
    renormalized), never the material component, so every texel still gets an entry of
    its own material, even between neighbouring material ids (40 and 41)."""
    n = _normals(16, seed=6, spread=0.4)
    mats = 40 + (np.arange(16)[:, None] + np.arange(16)[None, :]) % 2
    q = quantize_normal_map(n, 16, "median-cut", dither=True, materials=mats)
    assert not q.exact and set(q.materials.tolist()) == {40, 41}
    assert np.array_equal(q.materials[q.indices], mats)


def test_renormalizing_keeps_the_material_component():
    """Representatives are renormalized on the sphere in their first three components only:
    a box of one material keeps MATERIAL_SCALE x that material as its fourth."""
    pts = np.array([[1.0, 0, 0, 0], [0.8, 0.6, 0, 0], [0, 0.6, 0.8, 8.0], [0, 0, 1.0, 8.0]])
    w = np.array([1.0, 1.0, 1.0, 3.0])
    for table in (median_cut(pts, w, 2), kmeans(pts, w, 2)):
        table = table[np.argsort(table[:, 3])]
        assert table[:, 3].tolist() == [0.0, 8.0]
        assert np.allclose(np.linalg.norm(table[:, :3], axis=1), 1)
        assert np.allclose(table[0, :3], _unit([1.8, 0.6, 0])) and np.allclose(table[1, :3], _unit([0, 0.6, 3.8]))


def test_lloyd_iterations_never_raise_the_weighted_error():
    """Lloyd's algorithm: assigning each point its nearest centre and moving each centre to
    its members' mean never raises the weighted squared error (renormalizing onto the
    sphere neither, for unit points: the nearest unit vector to a mean is its direction);
    zero iterations are the median cut."""
    rng = np.random.default_rng(6)
    pts, w = distinct(_unit(rng.normal(size=(600, 3)) * [1, 1, 0.3] + [0, 0, 0.8]), rng.uniform(0.5, 3, 600))

    def sse(t):
        return float(np.sum(w * np.sum((pts - t[nearest(pts, t)]) ** 2, axis=1)))
    errs = [sse(kmeans(pts, w, 16, iterations=i)) for i in range(6)]
    assert errs[0] == sse(median_cut(pts, w, 16))
    assert all(b <= a * (1 + 1e-12) for a, b in zip(errs, errs[1:], strict=False)), errs
    assert errs[-1] < 0.98 * errs[0]


def test_an_empty_centre_is_reseeded_at_the_point_worst_served():
    """Four unit normals on an arc (angles 0, 0.1, 0.5, 0.55 rad, weights 3, 1, 0.5, 2):
    median cut's box {0.1, 0.5} has its mean (0.23 rad) nearer to no point than the other
    entries are, so Lloyd's first step empties it; it is re-seeded at the point then worst
    served (0.1 rad, 0.075 rad from the nearest moved centre), and the table ends as the
    point at 0 rad, that point, and the weighted mean of the last two."""
    a = np.array([0.0, 0.1, 0.5, 0.55])
    pts = np.stack([np.cos(a), np.sin(a), np.zeros(4)], -1)
    w = np.array([3.0, 1.0, 0.5, 2.0])
    mc = median_cut(pts, w, 3)
    d = np.linalg.norm(pts[:, None] - mc[None], axis=-1)
    assert len(set(np.argmin(d, axis=1).tolist())) == 2                  # one entry serves no point
    one = kmeans(pts, w, 3, iterations=1)
    assert any(np.array_equal(row, pts[1]) for row in one)
    final = kmeans(pts, w, 3)
    mean = _unit(w[2] * pts[2] + w[3] * pts[3])
    want = sorted(map(tuple, np.round([pts[0], pts[1], mean], 12)))
    assert sorted(map(tuple, np.round(final, 12))) == want

    def sse(t):
        return float(np.sum(w * np.min(np.sum((pts[:, None] - t[None]) ** 2, axis=-1), axis=1)))
    assert sse(final) < sse(mc)


def _lloyd_step(pts, w, table):
    """One step of the documented k-means: each point to its nearest centre, each centre
    to the renormalized weighted mean of its members, each emptied centre to one of the
    points worst served by the moved centres (worst first)."""
    idx = np.argmin(np.sum((pts[:, None] - table[None]) ** 2, axis=-1), axis=1)
    moved = table.copy()
    empty = []
    for j in range(len(table)):
        if np.any(idx == j):
            m = np.sum(w[idx == j, None] * pts[idx == j], axis=0)
            moved[j] = m / np.linalg.norm(m)
        else:
            empty.append(j)
    err = np.sum((pts - moved[idx]) ** 2, axis=1)
    order = np.argsort(err)[::-1]
    assert len(set(np.round(err[order[:len(empty) + 1]], 12))) == len(empty) + 1   # no ties
    moved[empty] = pts[order[:len(empty)]]
    return moved, empty


@pytest.mark.parametrize("angles, weights, size", [
    ([0.0, 0.1, 0.5, 0.55], [3.0, 1.0, 0.5, 2.0], 3),                   # the first entry empties
    ([0.0, -0.1, -0.5, -0.55], [3.0, 1.0, 0.5, 2.0], 3),                # mirrored
    ([0.06, 0.08, 0.1, 0.39, 0.44, 0.48, 0.7], [1.0, 2.9, 0.5, 0.7, 1.6, 2.6, 0.3], 3),   # the last
    ([0.05, 0.07, 0.38, 0.41, 0.46, 0.68, 0.78], [1.9, 0.5, 0.8, 3.3, 2.5, 1.4, 3.5], 5),  # two
])
def test_one_kmeans_step_is_lloyds_with_emptied_centres_reseeded(angles, weights, size):
    """kmeans(iterations=1) from median cut's table is one Lloyd step with each emptied
    centre re-seeded at a point worst served (a step worked here; median cut of these
    arcs empties the entries named)."""
    a, w = np.array(angles), np.array(weights)
    pts = np.stack([np.cos(a), np.sin(a), np.zeros(len(a))], -1)
    want, empty = _lloyd_step(pts, w, median_cut(pts, w, size))
    assert empty
    got = kmeans(pts, w, size, iterations=1)
    assert sorted(map(tuple, np.round(got, 12))) == sorted(map(tuple, np.round(want, 12)))


def test_median_cut_never_cuts_between_equal_coordinates():
    """The cut lies between distinct values of the longest axis: three points at x = 0 and
    two at x = 1 split 3 | 2 even where the weighted median falls among the three."""
    pts = np.array([[0, 0, 1.0], [0, 0.05, 1.0], [0, 0.1, 1.0], [1.0, 0, 1.0], [1.0, 0.1, 1.0]])
    for w in (np.ones(5), np.array([1.0, 1.0, 1.0, 0.5, 0.5]), np.array([0.2, 0.2, 0.2, 5.0, 5.0])):
        table = median_cut(pts, w, 2)
        want = [_unit(np.average(pts[:3], axis=0, weights=w[:3])), _unit(np.average(pts[3:], axis=0, weights=w[3:]))]
        assert sorted(map(tuple, np.round(table, 12))) == sorted(map(tuple, np.round(want, 12)))


def test_median_cut_of_as_many_entries_as_points_is_every_point():
    rng = np.random.default_rng(7)
    pts = _unit(rng.normal(size=(20, 3)))
    table = median_cut(pts, rng.uniform(0.1, 5, 20), 20)
    assert np.allclose(np.sort(table, axis=0), np.sort(pts, axis=0), atol=1e-15)


def test_distinct_with_all_weights_zero_is_empty_and_weights_are_summed():
    v = np.array([[0, 0, 1.0], [0, 0, 1.0], [1.0, 0, 0]])
    uniq, counts = distinct(v, np.zeros(3))
    assert uniq.shape == (0, 3) and counts.shape == (0,)
    uniq, counts = distinct(v, np.array([0.25, 0.5, 2]))
    assert dict(zip(map(tuple, uniq), counts.tolist(), strict=False)) == {(0, 0, 1): 0.75, (1, 0, 0): 2.0}


# --- Sec. 5: mipmaps, lookup, colour tables -----------------------------------------------------

def test_mipmaps_stop_at_the_first_odd_size_and_pick_nearest_to_each_blocks_mean():
    n = _normals(12, seed=8)
    q = quantize_normal_map(n, 16, "median-cut")
    levels = mipmap_indices(q)
    assert [lv.shape for lv in levels] == [(12, 12), (6, 6), (3, 3)]
    for k in (1, 2):
        up = q.table[levels[k - 1]]
        t = levels[k].shape[0]
        mean = _unit(up.reshape(t, 2, t, 2, 3).mean(axis=(1, 3))).reshape(-1, 3)
        _check_nearest(mean, q.table, levels[k].ravel())


def test_mipmaps_of_a_map_with_materials_keep_each_blocks_material():
    """Sec. 5.2 with Sec. 6: where each 2x2 block holds one material, the next level's
    entry is of that material and, among its entries, the one nearest to the block's
    renormalized mean normal."""
    n = _normals(8, seed=9)
    mats = (np.arange(8)[:, None] // 2 + np.arange(8)[None, :] // 2) % 2 * 3        # per 2x2 block
    q = quantize_normal_map(n, 16, "median-cut", materials=mats)
    levels = mipmap_indices(q)
    assert [lv.shape for lv in levels] == [(8, 8), (4, 4), (2, 2), (1, 1)]
    block_mats = mats[::2, ::2]
    assert np.array_equal(q.materials[levels[1]], block_mats)
    mean = _unit(q.table[levels[0]].reshape(4, 2, 4, 2, 3).mean(axis=(1, 3)))
    for (r, c), m in np.ndenumerate(block_mats):
        own = np.flatnonzero(q.materials == m)
        d = np.linalg.norm(q.table[own] - mean[r, c], axis=1)
        assert levels[1][r, c] == own[np.argmin(d)], (r, c)
    # mixed blocks: the mean (normal renormalized, material averaged) picks the entry
    # nearest to it, the material being MATERIAL_SCALE apart per id
    wide = _normals(16, seed=10, spread=3.0)                 # blocks whose means are short
    mixed = np.random.default_rng(3).integers(0, 2, (16, 16))
    q = quantize_normal_map(wide, 64, "median-cut", materials=mixed)
    levels = mipmap_indices(q)
    table4 = np.concatenate([q.table, MATERIAL_SCALE * q.materials[:, None]], -1)
    mean = table4[levels[0]].reshape(8, 2, 8, 2, 4).mean(axis=(1, 3))
    mean[..., :3] = _unit(mean[..., :3])
    want = np.argmin(np.linalg.norm(mean[:, :, None] - table4[None, None], axis=-1), axis=-1)
    assert np.array_equal(levels[1], want)


def test_lookup_accepts_exactly_the_table_indices():
    """Indices in [0, len(table) - 1]: both ends read their rows; -1 and len(table) are
    refused naming the index and the range; non-integer indices are refused."""
    table = np.arange(12).reshape(3, 4)
    assert lookup(np.array([[0, 2], [1, 0]]), table).tolist() == [[table[0].tolist(), table[2].tolist()],
                                                                  [table[1].tolist(), table[0].tolist()]]
    assert lookup(np.array([], np.int64), table).shape == (0, 4)
    for bad in (3, -1):
        with pytest.raises(BumpError) as e:
            lookup(np.array([0, bad, 1]), table)
        assert str(e.value) == f"index {bad} is outside the table: allowed [0, 2]"
    with pytest.raises(BumpError, match="^indices must be integers, got dtype float64$"):
        lookup(np.array([0.0, 1.0]), table)


def test_colour_table_needs_parameters_for_every_material_it_names():
    table = _normals(2).reshape(-1, 3)
    params = [Material(), Material(kd=0.2)]
    ok = color_table(table, "lambert", [0, 0, 1.0], [0, 0, 1.0], materials=np.array([0, 1, 1, 0]),
                     material_params=params)
    assert ok.shape == (4, 4)
    with pytest.raises(BumpError) as e:
        color_table(table, "lambert", [0, 0, 1.0], [0, 0, 1.0], materials=np.array([0, 2, 1, 0]),
                    material_params=params)
    assert str(e.value) == "material 2 has no parameters: allowed [0, 1]"
    with pytest.raises(BumpError) as e:
        color_table(table, "Lambert", [0, 0, 1.0], [0, 0, 1.0])
    assert str(e.value) == "lighting must be one of lambert, phong, chrome, toon, got 'Lambert'"


def test_lambert_and_phong_tables_of_unnormalized_inputs_are_eq_2():
    """Sec. 5.1 items 1-2: RGB = (ka + kd sum clamp(N.L)) x colour (+ ks sum clamp(N.H)**n
    with H = normalize(L + V) for phong), alpha the Lambert intensity, all clamped to
    [0, 1]; table, lights and view normalized first."""
    mat = Material(ka=0.05, kd=0.6, ks=0.3, spec_exponent=8, color=(1.0, 0.5, 0.25))
    table = _normals(3, seed=9).reshape(-1, 3)
    lights = np.array([[0, 0, 3.0], [0.6, 0, 0.8], [-1.0, 0.2, -0.1]])      # the last mostly behind
    view = np.array([0, 1.2, 1.6])
    lu, vu = _unit(lights), _unit(view)
    lam = mat.ka + mat.kd * np.clip(table @ lu.T, 0, 1).sum(-1)
    spec = mat.ks * (np.clip(table @ _unit(lu + vu).T, 0, 1) ** 8).sum(-1)
    col = np.array(mat.color)
    got = color_table(5 * table, "lambert", lights, view, material_params=[mat])
    assert np.allclose(got[:, :3], np.clip(lam[:, None] * col, 0, 1)) and np.allclose(got[:, 3], np.clip(lam, 0, 1))
    got = color_table(table, "phong", lights, view, material_params=[mat])
    assert np.allclose(got[:, :3], np.clip(lam[:, None] * col + spec[:, None], 0, 1))


def test_chrome_is_the_environment_of_the_view_reflected_about_the_normal():
    """Sec. 5.1 item 6: the colour is the landscape's in the direction R = 2 (N.V) N - V,
    which depends on R's height z alone (world z up): normals reflecting V to directions
    of one z but other azimuths get one colour; blue is the largest channel above the
    horizon, brown (red over blue) below; the lights play no part."""
    rng = np.random.default_rng(10)
    view = _unit([0.3, -0.4, 0.5])
    z = np.concatenate([rng.uniform(-0.95, 0.95, 38), [-0.99, 0.99]])      # and near both poles
    az = rng.uniform(0, 2 * np.pi, (2, 40))
    reflected = [np.stack([np.sqrt(1 - z * z) * np.cos(a), np.sqrt(1 - z * z) * np.sin(a), z], -1) for a in az]
    normals = [_unit(r + view) for r in reflected]            # the normal halving V and R
    c0 = color_table(normals[0], "chrome", [0, 0, 1.0], view)
    c1 = color_table(normals[1], "chrome", [1.0, 0, 0], view)
    assert np.allclose(c0[:, :3], c1[:, :3], atol=1e-12)
    up, down = z > 0.05, z < -0.05
    assert np.all(c0[up, 2] > c0[up, 0]) and np.all(c0[up, 2] >= c0[up, 1])      # blue the most
    assert np.all(c0[down, 0] > c0[down, 2])
    order = np.argsort(z[up])
    assert not np.allclose(c0[up][order[0], :3], c0[up][order[-1], :3])  # it does vary with z


def test_frame_view_is_the_reflection_of_the_light_about_the_half_vector():
    """V = 2 (L.H) H - L: then H is the half vector normalize(L + V) and |V| = 1."""
    from bumprtl.sim.scenes import load_scene
    scene = load_scene("bumps", size=16)
    l, v = frame_directions(scene)
    assert np.allclose(np.linalg.norm(l), 1) and np.allclose(np.linalg.norm(v), 1)
    px, m = scene.px, scene.mask
    h = _unit(np.stack([np.sin(px.h_theta) * np.cos(px.h_phi), np.sin(px.h_theta) * np.sin(px.h_phi),
                        np.cos(px.h_theta)], -1)[m].mean(0))
    assert np.allclose(_unit(l[0] + v[0]), h)


# --- Sec. 5 on a scene: the object-space normal map -------------------------------------------

def _tangent(n_phi, n_theta):
    """M = R_y(-th_N) R_z(-ph_N) (Lee Sec. 3.1.1), built here."""
    cp, sp, ct, st = np.cos(n_phi), np.sin(n_phi), np.cos(n_theta), np.sin(n_theta)
    rz = np.array([[cp, sp, 0], [-sp, cp, 0], [0, 0, 1.0]])
    ry = np.array([[ct, 0, -st], [0, 1.0, 0], [st, 0, ct]])
    return ry @ rz


def test_world_normal_map_sums_each_texels_pixels_and_turns_unused_ones_by_the_mean_frame():
    """Per used texel the sum over its covered pixels of M^T N' (counts = those pixels);
    an unused texel (count 0) holds its map N' turned by the frame of the covered pixels'
    mean N (normalized); distinct_normals counts the distinct directions of the used texels."""
    from bumprtl.sim.golden.float.palette import distinct_normals, world_normal_map
    from bumprtl.sim.scenes import load_scene
    scene = load_scene("bumps", size=64, texture_size=16, geometry="sphere")
    t = scene.texture_size
    normals, counts = world_normal_map(scene)
    assert normals.shape == (t, t, 3) and counts.shape == (t, t)
    px, m = scene.px, scene.mask
    want = np.zeros((t, t, 3))
    want_counts = np.zeros((t, t), np.int64)
    for i in zip(*np.nonzero(m), strict=False):
        world = _tangent(px.n_phi[i], px.n_theta[i]).T @ polar_to_cartesian(px.b_phi[i], px.b_theta[i])
        want[scene.v[i], scene.u[i]] += world
        want_counts[scene.v[i], scene.u[i]] += 1
    used = want_counts > 0
    assert np.array_equal(counts, want_counts) and 0 < used.sum() < t * t
    assert np.allclose(normals[used], want[used], atol=1e-12)
    mean = polar_to_cartesian(px.n_phi[m], px.n_theta[m]).mean(0)
    mean /= np.linalg.norm(mean)
    frame = _tangent(np.arctan2(mean[1], mean[0]) % (2 * np.pi), np.arccos(mean[2]))
    fallback = polar_to_cartesian(scene.b_phi_map, scene.b_theta_map) @ frame
    assert np.allclose(normals[~used], fallback[~used], atol=1e-12)
    unit = want[used] / np.linalg.norm(want[used], axis=-1, keepdims=True)
    assert distinct_normals(scene) == len(np.unique(unit, axis=0))


def test_a_palette_holding_every_normal_renders_the_exact_dots():
    """With sN at least the distinct normals, render_palette's N'.L and N'.H are the
    per-texel normal's dot with the frame's L and H = normalize(L + V); the colour is the
    mean of the 8-bit table's RGB of each pixel's entry."""
    from bumprtl.sim.golden.common import to_8bit
    from bumprtl.sim.golden.float.palette import distinct_normals, render_palette, world_normal_map
    from bumprtl.sim.scenes import load_scene
    scene = load_scene("bumps", size=32)
    cfg = Config()
    normals, _ = world_normal_map(scene)
    n = normals / np.linalg.norm(normals, axis=-1, keepdims=True)
    size = max(16, distinct_normals(scene))
    r = render_palette(scene, cfg, size, "median-cut")
    l, v = frame_directions(scene)
    h = _unit(l[0] + v[0])
    texel = n[scene.v, scene.u]
    assert np.allclose(r.ndotl, texel @ l[0], atol=1e-12) and np.allclose(r.ndoth, texel @ h, atol=1e-12)
    assert np.allclose(r.diffuse, np.clip(texel @ l[0], 0, 1), atol=1e-12)
    table = color_table(texel.reshape(-1, 3), "phong", l, v, cfg)
    rgb = to_8bit(table)[:, :3].reshape(texel.shape) / 255.0
    assert np.allclose(r.color, rgb.mean(-1), atol=1e-12)


def test_toon_shades_three_bands_rising_with_lambert_and_a_white_highlight():
    """Sec. 5.1 item 4: three intensity bands, non-decreasing with the Lambert intensity,
    times the material colour; a hard highlight is white (1, 1, 1), and only normals near H
    get it."""
    light = np.array([0, 0, 1.0])
    view = _unit([0.6, 0, 0.8])
    h = _unit(light + view)
    angle = np.linspace(0, np.pi / 2, 400)
    table = np.stack([np.sin(angle), np.zeros_like(angle), np.cos(angle)], -1)   # N.L = cos
    plain = color_table(table, "toon", light, view, material_params=[Material(ks=0.0, color=(1.0, 0.5, 0.25))])
    levels = np.unique(np.round(plain[:, 0], 12))
    assert len(levels) == 3
    order = np.argsort(plain[:, 3])
    assert np.all(np.diff(plain[order, 0]) >= 0)
    assert np.allclose(plain[:, 1], plain[:, 0] * 0.5) and np.allclose(plain[:, 2], plain[:, 0] * 0.25)
    shiny = color_table(np.concatenate([table, h[None]]), "toon", light, view,
                        material_params=[Material(ks=0.5, spec_exponent=64)])
    assert np.allclose(shiny[-1, :3], 1.0)
    far = table @ h < 0.9
    assert np.all(shiny[:-1][far, 0] < 1.0) and len(np.unique(np.round(shiny[:-1][far, 0], 12))) <= 3


def test_the_blend_layout_clamps_a_highlight_summed_over_lights_to_1():
    """Sec. 7.1/7.2 layout: RGB the specular sum ks sum clamp(N.H)**n clamped to [0, 1]
    (two full highlights sum to 2), alpha the Lambert intensity clamped likewise."""
    light = np.array([[0, 0, 1.0], [0, 0, 1.0]])
    view = np.array([0, 0, 1.0])
    table = np.array([[0, 0, 1.0], _unit([1.0, 0, 1.0])])
    c = color_table(table, "phong", light, view, blend=True,
                    material_params=[Material(ka=0.5, kd=1.0, ks=1.0, spec_exponent=4)])
    assert np.allclose(c[0], [1.0, 1.0, 1.0, 1.0])
    h = 1 / np.sqrt(2)
    assert np.allclose(c[1, :3], min(1.0, 2 * h ** 4)) and np.allclose(c[1, 3], min(1.0, 0.5 + 2 * h))


def test_render_palette_dithers_when_asked():
    """render_palette(dither=True) shades the dithered index map (Sec. 4, Fig. 4): its
    colours are palette_rgb's of the map quantized with dithering, not of the plain one."""
    from bumprtl.sim.golden.float.palette import palette_rgb, render_palette, world_normal_map
    from bumprtl.sim.scenes import load_scene
    scene = load_scene("bumps", size=32)
    cfg = Config()
    normals, counts = world_normal_map(scene)
    dithered = quantize_normal_map(normals, 16, "median-cut", True, weights=counts)
    plain = quantize_normal_map(normals, 16, "median-cut", False, weights=counts)
    assert not np.array_equal(dithered.indices, plain.indices)
    got = render_palette(scene, cfg, 16, "median-cut", dither=True).color
    assert np.array_equal(got, palette_rgb(scene, cfg, qmap=dithered)[0].mean(-1))
    assert not np.array_equal(got, render_palette(scene, cfg, 16, "median-cut").color)


def test_the_chrome_environment_is_a_colour_brown_below_and_blue_above():
    """Tarini et al. Fig. 7's landscape (_environment): every direction's colour is in
    [0, 1], brown (r > g > b) below the horizon and blue (b > g > r) above it."""
    from bumprtl.sim.golden.float.palette import _environment
    rng = np.random.default_rng(7)
    r = rng.normal(size=(4000, 3))
    r /= np.linalg.norm(r, axis=1, keepdims=True)
    r = np.concatenate([r, [[1, 0, 0], [0, 0, 1], [0, 0, -1], [0, 1, -1e-9]]])
    c = _environment(r)
    assert c.shape == (len(r), 3) and (c >= 0).all() and (c <= 1).all()
    below = (r[:, 2] < -1e-3) & (r[:, 2] > -1 + 1e-6)       # straight down is black
    above = r[:, 2] >= 0
    assert ((c[below, 0] > c[below, 1]) & (c[below, 1] > c[below, 2])).all()
    assert ((c[above, 2] > c[above, 1]) & (c[above, 1] > c[above, 0])).all()
