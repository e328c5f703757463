"""The datapath units' test vectors (sim/golden/vectors.py): payloads as the RTL takes them."""

import numpy as np
import pytest

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.methods import illumination_fixed, rotation_fixed
from bumprtl.sim.golden.vectors import (
    TINY,
    as_payloads,
    concat_codes,
    corner_codes,
    edge_codes,
    random_codes,
    range_corners,
)


def test_payloads_number_the_pixels_with_a_tag_that_wraps_at_tag_bits():
    """Payload i carries the input codes of pixel i and the running tag i mod 2**tag_bits
    (the testbenches match outputs to inputs by it); without specular there is no H."""
    cfg = TINY.replace(tag_bits=3)
    codes = concat_codes(random_codes(10, cfg, seed=1), random_codes(10, cfg, seed=2))
    payloads = as_payloads(codes, cfg)
    assert [p["tag"] for p in payloads] == [i % 8 for i in range(20)]
    for i, p in enumerate(payloads):
        assert all(p[k] == codes[k][i] for k in codes)
    plain = as_payloads(codes, cfg.replace(specular=False))
    assert all(not any(k.startswith("h.") for k in p) for p in plain)
    assert [p["tag"] for p in plain] == [i % 8 for i in range(20)]


def test_edge_codes_reach_the_poles_the_equator_and_the_azimuth_wrap():
    """theta 0, 90 and 180 degrees and phi at both sides of 0 for N and L, every code on the
    grid of the Config."""
    cfg = Config()
    codes = edge_codes(cfg)
    q, full = cfg.full_circle // 4, cfg.full_circle
    for v in ("n", "l"):
        assert {0, q, 2 * q} <= set(codes[f"{v}.theta"].tolist())
        assert {0, 1, full - 1} <= set(codes[f"{v}.phi"].tolist())
    for k, c in codes.items():
        hi = 2 * q if k.endswith("theta") else full - 1
        assert c.min() >= 0 and c.max() <= hi, k


@pytest.mark.parametrize("cfg", [TINY, Config(angle_bits=9, frac_bits=10)], ids=["tiny", "9-bit"])
def test_corners_reach_both_ends_of_every_field_and_both_extremes_of_the_dots(cfg):
    """corner_codes (the corners every bit-exact streaming test starts with, widths from the
    Config): every field at code 0 and at its last code (phi full_circle - 1, theta 180
    degrees), in one row each; some row with N'.L = N'.H = 1 exactly (head-on: the diffuse
    and specular terms at their maximum) and some with the light straight behind (0); the
    edge cases start with them."""
    codes = corner_codes(cfg)
    full, q = cfg.full_circle, cfg.full_circle // 4
    rows = np.stack([codes[k] for k in codes], axis=1)
    assert (rows == 0).all(axis=1).any()
    assert (rows == [2 * q if k.endswith("theta") else full - 1 for k in codes]).all(axis=1).any()
    out = illumination_fixed(rotation_fixed({k: v.astype(np.int64) for k, v in codes.items()}, cfg), cfg)
    one = 1 << cfg.frac_bits
    assert out["ndotl"].max() == one and out["ndoth"].max() == one
    assert out["diffuse_fine"].max() == one and out["diffuse"].max() == 255
    assert out["diffuse_fine"].min() == 0 and out["ndotl"].min() < 0
    edges = edge_codes(cfg)
    assert all((edges[k][:len(c)] == c).all() for k, c in codes.items())


def test_range_corners_put_every_field_at_both_ends_together_and_alone():
    """All low, all high, then each field alone high and alone low."""
    got = range_corners({"a": (0, 7), "b": (-4, 3), "c": (1, 1)})
    rows = list(zip(*(got[k].tolist() for k in ("a", "b", "c")), strict=True))
    assert rows[:2] == [(0, -4, 1), (7, 3, 1)]
    assert rows[2:4] == [(7, -4, 1), (0, 3, 1)] and rows[4:6] == [(0, 3, 1), (7, -4, 1)]
    assert len(rows) == 8 and all(v.dtype == np.int64 for v in got.values())
