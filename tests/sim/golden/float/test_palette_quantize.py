"""Tarini et al.'s quantizers (sim/golden/float/palette_quantize.py) on cases small enough
to work out by hand: the median cut's split at the weighted median of the longest axis and
its weighted, renormalized means; k-means keeping a converged table; distinct rows and
their weights; the Bayer offsets."""

import numpy as np
import pytest

from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.float.palette_quantize import (
    PALETTE_MAX,
    PALETTE_MIN,
    bayer_offsets,
    check_palette_size,
    distinct,
    kmeans,
    median_cut,
    nearest,
    stores_every_normal,
)

# two pairs of unit normals; by x: (0,0,1) w2, (0,.6,.8) w2 | (.8,.6,0) w3, (1,0,0) w1
POINTS = np.array([[1.0, 0, 0], [0.8, 0.6, 0], [0, 0, 1.0], [0, 0.6, 0.8]])
WEIGHTS = np.array([1.0, 3.0, 2.0, 2.0])
# the weighted means renormalized: (0, .3, .9) / |.| and (.85, .45, 0) / |.|
WANT = [np.array([0, 0.3, 0.9]) / np.sqrt(0.9), np.array([0.85, 0.45, 0]) / np.sqrt(0.925)]


def _as_set(table):
    return sorted(map(tuple, np.round(table, 12)))


def test_median_cut_splits_at_the_weighted_median_of_the_longest_axis():
    table = median_cut(POINTS, WEIGHTS, 2)
    assert table.shape == (2, 3)
    assert _as_set(table) == _as_set(WANT)
    assert np.allclose(np.linalg.norm(table, axis=1), 1)
    # size 1: the weighted mean of everything; size 4: every point
    all_mean = (WEIGHTS @ POINTS) / np.linalg.norm(WEIGHTS @ POINTS)
    assert np.allclose(median_cut(POINTS, WEIGHTS, 1), [all_mean])
    assert _as_set(median_cut(POINTS, WEIGHTS, 4)) == _as_set(POINTS)


def test_median_cut_splits_the_box_of_largest_weighted_spread_first():
    """Two boxes after the first cut (x = 0, 0.1 | x = 10, 14); the third entry comes from
    the box whose squared spread times weight is larger (16 x 2 against 0.01 x 2)."""
    pts = np.array([[0.0, 1, 0], [0.1, 1, 0], [10.0, 1, 0], [14.0, 1, 0]])
    w = np.ones(4)
    unit = lambda v: np.asarray(v) / np.linalg.norm(v)
    assert _as_set(median_cut(pts, w, 2)) == _as_set([unit([0.05, 1, 0]), unit([12.0, 1, 0])])
    assert _as_set(median_cut(pts, w, 3)) == _as_set([unit([0.05, 1, 0]), unit(pts[2]), unit(pts[3])])
    # weight moves the median: three times the weight on x = 0 cuts it off alone
    w3 = np.array([3.0, 1, 1, 1])
    assert _as_set(median_cut(pts, w3, 2)) == _as_set([unit(pts[0]), unit([24.1 / 3, 1, 0])])


def test_kmeans_keeps_a_converged_table_and_assigns_the_nearest():
    table = kmeans(POINTS, WEIGHTS, 2)
    assert _as_set(table) == _as_set(WANT)
    idx = nearest(POINTS, table)
    assert idx.dtype == np.int64
    assert idx[0] == idx[1] != idx[2] == idx[3]


def test_kmeans_moves_centres_to_the_weighted_means_of_their_members():
    """Median cut on the x axis puts (.6,.8,0) with (1,0,0); its nearest centre afterwards
    is the other one, so Lloyd's iterations move the centres to the better partition."""
    pts = np.array([[1.0, 0, 0], [0.96, 0.28, 0], [0.6, 0.8, 0], [0, 1.0, 0], [0.28, 0.96, 0]])
    w = np.array([1.0, 1.0, 1.0, 1.0, 1.0])
    sse = lambda t: float(np.sum(w * np.sum((pts - t[nearest(pts, t)]) ** 2, axis=1)))
    mc, km = median_cut(pts, w, 2), kmeans(pts, w, 2)
    assert sse(km) <= sse(mc)
    groups = nearest(pts, km)
    for g in set(groups.tolist()):
        m = pts[groups == g].mean(0)
        assert any(np.allclose(row, m / np.linalg.norm(m)) for row in km)


def test_distinct_sums_the_weights_of_equal_rows_and_drops_weight_zero():
    v = np.array([[0, 0, 1.0], [1.0, 0, 0], [0, 0, 1.0], [0, 1.0, 0]])
    uniq, counts = distinct(v)
    assert _as_set(uniq) == _as_set([[0, 0, 1], [1, 0, 0], [0, 1, 0]])
    assert dict(zip(map(tuple, uniq), counts, strict=False)) == {(0, 0, 1): 2, (1, 0, 0): 1, (0, 1, 0): 1}
    uniq, counts = distinct(v, [0.5, 0, 2.0, 1.0])
    assert dict(zip(map(tuple, uniq), counts, strict=False)) == {(0, 0, 1): 2.5, (0, 1, 0): 1.0}


def test_palette_size_range_and_lossless_case():
    for ok in (PALETTE_MIN, PALETTE_MAX, np.int64(64)):
        check_palette_size(ok)
    for bad in (PALETTE_MIN - 1, PALETTE_MAX + 1, 64.0, True):
        with pytest.raises(BumpError, match=r"palette_size must be an integer in \[16, 16384\]"):
            check_palette_size(bad)
    assert stores_every_normal(16, 16) and stores_every_normal(17, 16) and not stores_every_normal(15, 16)


def test_bayer_offsets_are_the_4x4_matrix_per_component():
    off = bayer_offsets((8, 8))
    assert off.shape == (8, 8, 3)
    levels = (np.arange(16) + 0.5) / 16 - 0.5
    for c in range(3):
        block = off[:4, :4, c]
        assert np.allclose(np.sort(block.ravel()), levels)        # each level once a block
        assert np.array_equal(off[4:, 4:, c], block) and np.array_equal(off[:4, 4:, c], block)
    assert off[0, 0, 0] == 0.5 / 16 - 0.5 and off[0, 1, 0] == 8.5 / 16 - 0.5   # Bayer's first row
    assert np.array_equal(off[..., 1], off[..., 0].T)
    assert np.array_equal(off[:4, :4, 2], np.roll(off[:4, :4, 0], (-2, -1), axis=(0, 1)))
