"""Test vectors for the datapath units: random valid pixels, the edge cases and the extreme
corners, as the flattened input payloads the RTL takes (binary-angle codes).

:func:`corner_codes` is the one corner generator of every bit-exact streaming test: the
datapath benches take it through :func:`edge_codes`, the pipeline's through
``sim/golden/fixed/pipeline.random_inputs`` (which gives every light the same corner row)."""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.fixed.common import quantize_pixels

__all__ = ["TINY", "corner_codes", "range_corners", "edge_codes", "random_codes", "as_payloads", "concat_codes"]

KEYS = ("n.phi", "n.theta", "l.phi", "l.theta", "h.phi", "h.theta", "b.phi", "b.theta")

# The tiny configuration of the exhaustive walks: k = 2 (4-bit angles, 16 codes each), B = 4,
# and 16-bit tags, so up to 16^4 vectors are numbered each once. ``TINY.replace(method=...)``.
TINY = Config(angle_bits=4, frac_bits=4, tag_bits=16)


def random_codes(n, cfg: Config, seed=0):
    return quantize_pixels(PixelInputs.random(n, np.random.default_rng(seed)), cfg)


def corner_codes(cfg: Config):
    """The extreme corners of the angle inputs, every term at its maximum or its minimum at
    once (so a carry only saturating inputs reach is reached): head-on (L = H = N and
    N' = N: theta_A = 0, so N'.L = N'.H = 1 exactly) and behind (L = H = -N), for N at
    both ends of its fields (phi 0 and ``full_circle - 1``, theta 0 and 180 degrees, the
    last theta on the grid) and at 90 degrees, N' at both ends of phi; and every field at
    code 0, and at its last code, at once. Widths from ``cfg``."""
    full, q = cfg.full_circle, cfg.full_circle // 4
    ends = {k: (0, 2 * q if k.endswith("theta") else full - 1) for k in KEYS}
    rows = [tuple(ends[k][0] for k in KEYS), tuple(ends[k][1] for k in KEYS)]
    for n_phi in ends["n.phi"]:
        for n_theta in (*ends["n.theta"], q):
            for b_phi in ends["b.phi"]:
                rows.append((n_phi, n_theta, n_phi, n_theta, n_phi, n_theta, b_phi, 0))
                back = ((n_phi + 2 * q) % full, 2 * q - n_theta)            # L = H = -N
                rows.append((n_phi, n_theta, *back, *back, b_phi, 0))
    arr = np.array(rows, dtype=np.int32)
    return {k: arr[:, i] for i, k in enumerate(KEYS)}


def range_corners(ranges):
    """The corners of independent integer fields, ``{field: (lo, hi)}`` (their ranges from
    the Config or the sidecar): every field at ``lo`` at once, every field at ``hi`` at once,
    then each field alone at ``hi`` (the rest at ``lo``) and alone at ``lo`` (the rest at
    ``hi``). Dict of int64 arrays."""
    keys = list(ranges)
    lo = np.array([ranges[k][0] for k in keys], np.int64)
    hi = np.array([ranges[k][1] for k in keys], np.int64)
    rows = [lo, hi]
    for i in range(len(keys)):
        rows += [np.where(np.arange(len(keys)) == i, hi, lo), np.where(np.arange(len(keys)) == i, lo, hi)]
    arr = np.stack(rows)
    return {k: arr[:, i] for i, k in enumerate(keys)}


def edge_codes(cfg: Config):
    """The corners (:func:`corner_codes`), then theta 0, 90, 180 degrees; azimuth wrap (ph_A
    just below 0 and ph_N just above, and the reverse); L = N; grazing light; light below
    the horizon; in all combinations with a few N and N' directions."""
    full, q = cfg.full_circle, cfg.full_circle // 4
    thetas = [0, 1, q - 1, q, q + 1, 2 * q - 1, 2 * q]            # 0, 90, 180 degrees
    phis = [0, 1, full - 1, q, 2 * q, 3 * q]
    rows = []
    for n_phi in phis:
        for n_theta in thetas:
            for b_theta in (0, q // 3, q - 1):
                b_phi = (n_phi * 7 + b_theta) % full
                lights = [(n_phi, n_theta),                        # L = N
                          ((n_phi + q) % full, q),                 # grazing (in the xy-plane)
                          ((n_phi + 1) % full, min(2 * q, n_theta + q)),  # 90 deg from N
                          ((n_phi - 1) % full, 2 * q - 1),         # below the world horizon
                          ((full - 1 - n_phi) % full, q // 2)]     # azimuth wraps past 360
                for l_phi, l_theta in lights:
                    rows.append((n_phi, n_theta, l_phi, l_theta, (l_phi + n_phi) // 2 % full,
                                 (l_theta + n_theta) // 2, b_phi, b_theta))
    arr = np.array(rows, dtype=np.int32)
    return concat_codes(corner_codes(cfg), {k: arr[:, i] for i, k in enumerate(KEYS)})


def as_payloads(codes, cfg: Config, keys=None):
    """Dict of arrays -> list of payload dicts (with a running tag)."""
    keys = [k for k in (keys or codes) if cfg.specular or not k.startswith("h.")]
    n = len(next(iter(codes.values())))
    mask = (1 << cfg.tag_bits) - 1
    cols = {k: np.asarray(codes[k]).tolist() for k in keys}
    return [{**{k: cols[k][i] for k in keys}, "tag": i & mask} for i in range(n)]


def concat_codes(*codes):
    """Code dicts with the same keys, one after the other."""
    return {k: np.concatenate([np.asarray(c[k]) for c in codes]) for k in codes[0]}
