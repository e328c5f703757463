"""The Peercy/Ernst fixed-point golden model (sim/golden/fixed/peercy.py) against float64:
the stated error bound (predicted_error_bound_lsb and its first-order dot-product bound),
the encoder, the integer square root, and width/symmetry properties of the normalization
over the whole input range (Hypothesis)."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from bumprtl.rtl.baselines.peercy import component_width, square_bits
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import PixelInputs, polar_to_cartesian, to_8bit
from bumprtl.sim.golden.fixed import peercy as fixed_peercy
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.methods import datapath_fixed, encode_pixels, get


def _errors(cfg, samples=20_000, seed=11):
    px = PixelInputs.random(samples, np.random.default_rng(seed))
    fixed = datapath_fixed(fixed_peercy.encode(px, cfg), cfg)
    ref = conventional(px, cfg)
    diffuse = np.abs(fixed["diffuse"].astype(np.int64) - to_8bit(ref.diffuse).astype(np.int64))
    ndotl_u = np.abs(fixed["ndotl"] - ref.ndotl * cfg.one)       # in units of u = 2**-B
    return diffuse, ndotl_u


@pytest.mark.parametrize("cfg", [Config(method="peercy"),
                                 Config(method="peercy", angle_bits=8, frac_bits=8),
                                 Config(method="peercy", frac_bits=20)], ids=["B13", "B8", "B20"])
def test_diffuse_within_the_predicted_bound(cfg):
    """20 000 random valid pixels: |diffuse8 - round(255 clamp(N'.L'))| <= the bound of the
    docstring, and N'.L' itself within its first-order (5/2 + 2 sqrt 3) u + 2 u**2."""
    diffuse, ndotl_u = _errors(cfg)
    assert diffuse.max() <= fixed_peercy.predicted_error_bound_lsb(cfg)
    u = 2.0 ** -cfg.frac_bits
    assert ndotl_u.max() <= 2.5 + 2 * np.sqrt(3) + 2 * u


def test_the_bound_is_not_vacuous_at_narrow_widths():
    """At B = 8 the bound is several LSB and the datapath does err by more than 1 LSB."""
    cfg = Config(method="peercy", angle_bits=8, frac_bits=8)
    diffuse, _ = _errors(cfg)
    assert 1 < diffuse.max() <= fixed_peercy.predicted_error_bound_lsb(cfg) < 255


def test_ernst_is_peercy_per_pixel():
    px = PixelInputs.random(500, np.random.default_rng(3))
    cfg = Config(method="ernst")
    a = datapath_fixed(encode_pixels(px, cfg), cfg)
    peercy = Config(method="peercy")
    b = datapath_fixed(fixed_peercy.encode(px, peercy), peercy)
    assert all(np.array_equal(a[k], b[k]) for k in b)
    ref, ern = conventional(px, cfg), get("ernst").reference(px, cfg)
    assert np.abs(ern.ndotl - ref.ndotl).max() < 1e-12
    assert np.abs(ern.ndoth - ref.ndoth).max() < 1e-12


def test_encode_rounds_each_component_to_nearest():
    px = PixelInputs.random(300, np.random.default_rng(4))
    cfg = Config(method="peercy")
    codes = fixed_peercy.encode(px, cfg)
    b = cfg.frac_bits
    exact = polar_to_cartesian(px.l_phi, px.l_theta) * 2.0 ** b
    for i, a in enumerate("xyz"):
        assert np.abs(codes[f"l.{a}"] - exact[..., i]).max() <= 0.5
    # the frame rows: N = (sin th cos ph, sin th sin ph, cos th), B = (-sin ph, cos ph, 0)
    assert np.array_equal(codes["n.z"], np.rint(np.cos(px.n_theta) * 2.0 ** b))
    assert np.array_equal(codes["b.x"], np.rint(-np.sin(px.n_phi) * 2.0 ** b))
    assert not np.any(codes["b.z"])
    assert "h.x" not in fixed_peercy.encode(px, cfg.replace(specular=False))


def test_from_angle_codes_gives_exact_axes():
    """theta 0 and 90 degrees and phi 0 are exact in Cartesian codes."""
    cfg = Config(method="peercy")
    q = cfg.full_circle // 4
    z = np.zeros(1, np.int64)
    codes = {"n.phi": z, "n.theta": z, "l.phi": z, "l.theta": z + q, "h.phi": z + q,
             "h.theta": z + q, "b.phi": z, "b.theta": z}
    c = fixed_peercy.from_angle_codes(codes, cfg)
    one = cfg.one
    assert [int(c[f"l.{a}"][0]) for a in "xyz"] == [one, 0, 0]
    assert [int(c[f"h.{a}"][0]) for a in "xyz"] == [0, one, 0]
    assert [int(c[f"t.{a}"][0]) for a in "xyz"] == [one, 0, 0]        # T = +x when N = +z
    assert [int(c[f"np.{a}"][0]) for a in "xyz"] == [0, 0, one]


def test_isqrt_is_floor_sqrt():
    rng = np.random.default_rng(5)
    roots = rng.integers(1, 1 << 30, 2000)
    x = np.concatenate([roots * roots + d for d in (-1, 0, 1)] +
                       [rng.integers(0, 1 << 61, 2000), np.array([0, 1, 2, 3, 4])])
    assert fixed_peercy.isqrt(x).tolist() == [math.isqrt(int(v)) for v in x]


# --- properties of the normalization over any input code -------------------------------------

PEERCY = Config(method="peercy")            # the widths the Hypothesis properties draw from
B = PEERCY.frac_bits
CODE = st.integers(-(1 << (B + 1)), (1 << (B + 1)) - 1)


def _transformed(frame, a):
    """The setup's transformed components (before normalization), unsliced."""
    from bumprtl.rtl.fixed import round_shift
    return [round_shift(sum(np.int64(r[i]) * a[i] for i in range(3)), B) for r in frame]


@given(st.lists(CODE, min_size=12, max_size=12))
def test_widths_hold_every_input(values):
    """The slices of rtl/baselines/peercy.py lose nothing: |a_t| < 2**(B+4), s < 2**(2B+9),
    |A_n| components fit signed(B + 2)."""
    frame = [values[0:3], values[3:6], values[6:9]]
    at = _transformed(frame, values[9:12])
    assert all(abs(int(x)) < 1 << (component_width(PEERCY) - 1) for x in at)
    s = sum(int(x) ** 2 for x in at)
    assert s < 1 << square_bits(PEERCY)
    an = fixed_peercy.normalize_fixed([np.array([x]) for x in at], PEERCY)
    assert all(-(1 << (B + 1)) <= int(x[0]) < 1 << (B + 1) for x in an)


@given(st.lists(st.integers(-(1 << (B + 3)), 1 << (B + 3)), min_size=3, max_size=3))
def test_normalization_is_odd_and_unit_length(at):
    """Negating A_t negates A_n (round half away from zero); for |A_t| >= 1/2 the result
    has length 1 within the floored root (relative 2**-(B+1) / |A_t| <= u) and the three
    quotient roundings (sqrt 3 / 2 u): 2 u in all."""
    pos = fixed_peercy.normalize_fixed([np.array([x]) for x in at], PEERCY)
    neg = fixed_peercy.normalize_fixed([np.array([-x]) for x in at], PEERCY)
    assert [int(p[0]) for p in pos] == [-int(n[0]) for n in neg]
    if sum(x * x for x in at) >= (1 << (2 * B)) // 4:
        length = math.sqrt(sum(int(p[0]) ** 2 for p in pos))
        assert abs(length - (1 << B)) <= 2.0
