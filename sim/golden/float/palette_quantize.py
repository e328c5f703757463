"""Normal-map quantization of Tarini et al. (Sec. 4): median cut and spherical k-means.

Vectors are rows of ``(n, D)`` arrays: the first three components are a unit normal, an
optional fourth is the material (Sec. 6: "the material as a fourth, discrete component of
the quantized vector"), scaled so far apart that no cluster ever mixes two materials.
Every quantizer works on the *distinct* vectors weighted by how many texels use them
(Sec. 4: "the selection of N takes in account only the normals actually used"), returns a
table of ``size`` representatives (normals renormalized) and assigns each vector the index
of its nearest table entry (Euclidean = angular on the unit sphere).
"""

import heapq
import itertools

import numpy as np
from scipy.spatial import cKDTree

from bumprtl.rtl.config import BumpError

__all__ = ["QUANTIZERS", "PALETTE_MIN", "PALETTE_MAX", "distinct", "median_cut", "kmeans",
           "nearest", "check_palette_size", "stores_every_normal", "bayer_offsets"]

PALETTE_MIN, PALETTE_MAX = 16, 16384


def distinct(vectors, weights=None):
    """Distinct rows of ``vectors`` and their total weights (texel counts by default)."""
    v = np.asarray(vectors, dtype=np.float64)
    w = np.ones(len(v)) if weights is None else np.asarray(weights, dtype=np.float64)
    keep = w > 0
    uniq, inverse = np.unique(v[keep], axis=0, return_inverse=True)
    return uniq, np.bincount(inverse.ravel(), weights=w[keep], minlength=len(uniq))


def check_palette_size(size):
    """``size`` must be an integer in [PALETTE_MIN, PALETTE_MAX]. A palette at least as large
    as a map's number of distinct normals is valid: every normal gets its own entry
    (:func:`stores_every_normal`), nothing is quantized."""
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or \
            not PALETTE_MIN <= size <= PALETTE_MAX:
        raise BumpError(f"palette_size must be an integer in [{PALETTE_MIN}, {PALETTE_MAX}], got {size!r}")


def stores_every_normal(size, n_distinct):
    """True when a palette of ``size`` entries holds each of ``n_distinct`` normals as its own
    entry: the quantizer is not needed and the table is the distinct normals themselves."""
    return size >= n_distinct


def _renormalize(table):
    """Representatives back on the unit sphere (Sec. 4: "remap ... and then renormalize")."""
    out = np.array(table, dtype=np.float64)
    out[:, :3] /= np.linalg.norm(out[:, :3], axis=1, keepdims=True)
    return out


def _split(points, weights):
    """Median cut of one box along its longest axis: two index arrays, both non-empty."""
    extent = points.max(0) - points.min(0)
    axis = int(np.argmax(extent))
    order = np.argsort(points[:, axis], kind="stable")
    vals = points[order, axis]
    steps = np.nonzero(np.diff(vals) > 0)[0] + 1        # cut positions between distinct values
    cum = np.cumsum(weights[order])
    half = cum[-1] / 2
    cut = steps[np.argmin(np.abs(cum[steps - 1] - half))]
    return order[:cut], order[cut:]


def median_cut(points, weights, size):
    """Heckbert's median cut on distinct ``points``: repeatedly split the box with the
    largest weighted squared extent at its weighted median; representatives are the weighted
    means of the boxes. Needs ``size <= len(points)``."""
    ticket = itertools.count()          # tie-breaker: equal priorities pop oldest first

    def entry(idx):
        p = points[idx]
        spread = float(np.max(p.max(0) - p.min(0))) if len(idx) > 1 else 0.0
        return (-spread ** 2 * weights[idx].sum(), next(ticket), idx)
    heap = [entry(np.arange(len(points)))]
    while len(heap) < size:
        _, _, idx = heapq.heappop(heap)
        for part in _split(points[idx], weights[idx]):
            heapq.heappush(heap, entry(idx[part]))
    boxes = [idx for _, _, idx in heap]
    table = np.stack([np.average(points[b], axis=0, weights=weights[b]) for b in boxes])
    return _renormalize(table)


def nearest(vectors, table):
    """Index of the nearest table row for every vector (k-d tree, exact)."""
    _, idx = cKDTree(table).query(np.asarray(vectors, dtype=np.float64), workers=-1)
    return idx.astype(np.int64)


def kmeans(points, weights, size, iterations=12, seed=0):
    """Lloyd's k-means on the sphere: assign to the nearest centre, move each centre to the
    weighted mean of its members, renormalize. Seeded with median cut, so deterministic and
    never worse than median cut in weighted squared error; an empty centre is re-seeded at
    the point worst served. ``seed`` only breaks ties among equally bad points."""
    table = median_cut(points, weights, size)
    rng = np.random.default_rng(seed)
    for _ in range(iterations):
        idx = nearest(points, table)
        wsum = np.bincount(idx, weights=weights, minlength=size)
        sums = np.stack([np.bincount(idx, weights=weights * points[:, d], minlength=size)
                         for d in range(points.shape[1])], axis=1)
        empty = wsum == 0
        moved = _renormalize(np.where(empty[:, None], table, sums / np.where(empty, 1, wsum)[:, None]))
        if empty.any():
            err = np.sum((points - moved[idx]) ** 2, axis=1) + rng.uniform(0, 1e-12, len(points))
            moved[empty] = points[np.argsort(err)[::-1][:int(empty.sum())]]
        if np.array_equal(moved, table):
            break
        table = moved
    return table


QUANTIZERS = {"median-cut": median_cut, "kmeans": kmeans}

# 4x4 Bayer matrix (ordered dithering thresholds in [0, 1)).
_BAYER4 = (np.array([[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]]) + 0.5) / 16


def bayer_offsets(shape):
    """Per-texel ordered-dither offsets in [-0.5, 0.5) for the three normal components:
    the Bayer matrix, transposed and shifted per component so that they decorrelate."""
    rows, cols = np.indices(shape)
    comps = [_BAYER4[rows % 4, cols % 4], _BAYER4[cols % 4, rows % 4],
             _BAYER4[(rows + 2) % 4, (cols + 1) % 4]]
    return np.stack(comps, axis=-1) - 0.5
