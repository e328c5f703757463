"""The shared pieces of the bit-exact models (sim/golden/fixed/common.py) against exact
integer arithmetic and their docstrings: angle codes rounded to nearest with the full
circle wrapping to 0 (every code, both sides of it), the back end's clamps of the dots to
[0, 1], the polar units passing N' through and shading the dots they compute, the term
bounds growing with both errors."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bumprtl.rtl.config import Config, ConfigError
from bumprtl.rtl.tables import SPEC_FRAC_BITS
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.fixed.common import (
    BOUND_CHANNELS,
    angle_codes,
    check_channel,
    polar_illumination_fixed,
    polar_rotation_fixed,
    quantize_pixels,
    shade_fixed,
    term_bounds_lsb,
)


@pytest.mark.parametrize("angle_bits", [4, 9, 14])
def test_every_code_and_anything_within_half_a_step_rounds_to_it(angle_bits):
    """c 2 pi / 2**bits + f steps -> c for |f| < 1/2, every c in [0, 2**bits]; the full
    circle (c = 2**bits) is code 0, and so is anything just below 0."""
    cfg = Config(angle_bits=angle_bits, frac_bits=max(4, angle_bits - 3))
    full = cfg.full_circle
    step = 2 * np.pi / full
    c = np.arange(full + 1)
    for f in (0.0, 0.4999, -0.4999, 0.25):
        got = angle_codes((c + f) * step, cfg)
        assert got.dtype == np.int32
        assert np.array_equal(got, c % full), f
    assert angle_codes(-0.3 * step, cfg) == 0
    assert angle_codes(-0.7 * step, cfg) == full - 1              # wraps below 0 too


@settings(max_examples=300, deadline=None)
@given(st.integers(4, 16), st.integers(0, 1 << 16), st.integers(-4999, 4999))
def test_angle_codes_agree_with_integer_rounding(bits, code, frac):
    """round(x full / (2 pi)) mod full for x = (code + frac / 10**4) steps, in exact
    integers (frac strictly inside half a step)."""
    cfg = Config(angle_bits=bits, frac_bits=max(4, bits - 3))
    full = cfg.full_circle
    code %= full + 1
    x = (code + frac / 10_000) * 2 * np.pi / full
    assert int(angle_codes(x, cfg)) == code % full


def test_quantize_pixels_keys_each_field_like_the_payload():
    """n_phi -> "n.phi", ..., b_theta -> "b.theta", each the angle codes of that field."""
    cfg = Config()
    px = PixelInputs.random(50, np.random.default_rng(2))
    codes = quantize_pixels(px, cfg)
    assert list(codes) == ["n.phi", "n.theta", "l.phi", "l.theta", "h.phi", "h.theta", "b.phi", "b.theta"]
    for key, value in codes.items():
        field = key.replace(".", "_")
        assert np.array_equal(value, angle_codes(getattr(px, field), cfg)), key


def test_the_back_end_clamps_both_dots_to_0_and_1():
    """diffuse_fine = clamp(N'.L, 0, 1) with B fractional bits; N'.H clamped likewise before
    the table: a dot below 0 shades as 0, above 1 as 1 (eq. 2's max(0, .) and the unit
    range of a dot of unit vectors)."""
    cfg = Config()
    one = cfg.one
    dots = np.array([-one, -1, 0, one // 3, one, one + 1, 3 * one])
    out = shade_fixed(dots, dots, cfg)
    want = np.array([0, 0, 0, one // 3, one, one, one])
    assert np.array_equal(out["diffuse_fine"], want)
    ref = shade_fixed(want, want, cfg)
    for k in ("diffuse", "specular", "color", "specular_fine"):
        assert np.array_equal(out[k], ref[k]), k
    assert out["diffuse"].tolist() == [0, 0, 0, 85, 255, 255, 255]
    assert out["specular_fine"][4] == 255 << SPEC_FRAC_BITS and out["specular_fine"][0] == 0
    assert out["color"][4] == 255 and out["color"][0] == round(255 * cfg.ka)


def test_polar_units_pass_n_prime_through_and_shade_the_dots_they_compute():
    """polar_rotation_fixed: rotate() of (A, N) for L and H, N' unchanged (int64);
    polar_illumination_fixed: illuminate() of (A', N') per vector, then shade_fixed of
    those dots (ndoth 0 without specular)."""
    calls = []

    def rotate(a_phi, a_theta, n_phi, n_theta, cfg):
        calls.append("r")
        return a_phi + 1000 * n_phi, a_theta + 1000 * n_theta

    codes = {k: np.array([i + 1, i + 2]) for i, k in enumerate(
        ["n.phi", "n.theta", "l.phi", "l.theta", "h.phi", "h.theta", "b.phi", "b.theta"])}
    cfg = Config()
    rot = polar_rotation_fixed(rotate, codes, cfg)
    assert rot["l.phi"].tolist() == [3 + 1000, 4 + 2000] and rot["h.theta"].tolist() == [6 + 2000, 7 + 3000]
    assert rot["b.phi"].tolist() == [7, 8] and rot["b.theta"].tolist() == [8, 9]
    assert rot["b.phi"].dtype == np.int64 and rot["b.theta"].dtype == np.int64 and calls == ["r", "r"]
    dots = {"l": np.array([cfg.one // 2, -5]), "h": np.array([cfg.one, cfg.one // 4])}

    def illuminate(a_phi, a_theta, b_phi, b_theta, cfg):
        key = "l" if np.array_equal(a_phi, rot["l.phi"]) else "h"
        assert np.array_equal(b_phi, rot["b.phi"]) and np.array_equal(b_theta, rot["b.theta"])
        return dots[key]

    out = polar_illumination_fixed(illuminate, rot, cfg)
    want = shade_fixed(dots["l"], dots["h"], cfg)
    assert np.array_equal(out["ndotl"], dots["l"]) and np.array_equal(out["ndoth"], dots["h"])
    for k, v in want.items():
        assert np.array_equal(out[k], v), k
    plain = Config(specular=False)
    rot_plain = polar_rotation_fixed(rotate, {k: v for k, v in codes.items() if not k.startswith("h.")}, plain)
    assert "h.phi" not in rot_plain
    out = polar_illumination_fixed(lambda *a: dots["l"], rot_plain, plain)
    assert out["ndoth"].tolist() == [0, 0] and not out["specular"].any()


def test_term_bounds_grow_with_each_error_and_vanish_without_them():
    """No error: diffuse within the bound's own grid (255 x pi / 2**16: the slope 1 of cos
    times one piece) and specular the table's error plus as little; a larger angle or
    additive error gives a strictly larger bound."""
    cfg = Config()
    from bumprtl.rtl.tables import specular_table_error_lsb
    grid = 255 * np.pi / (1 << 16)
    zero = term_bounds_lsb(cfg, 0.0, 0.0)
    assert 0.9 * grid <= zero["diffuse"] <= grid
    assert 0 < zero["specular"] - specular_table_error_lsb(cfg) <= cfg.spec_exponent * grid
    prev = zero
    for a, e in ((1e-4, 0), (1e-4, 1e-4), (1e-3, 1e-4), (1e-3, 1e-3), (1e-2, 1e-3)):
        t = term_bounds_lsb(cfg, a, e)
        assert t["diffuse"] > prev["diffuse"] and t["specular"] > prev["specular"], (a, e)
        prev = t
    # an error as large as the whole range: diffuse spans all of 255, specular 255 + table
    big = term_bounds_lsb(cfg, np.pi, 2.0)
    assert big["diffuse"] == pytest.approx(255.0) and big["specular"] == pytest.approx(255 + specular_table_error_lsb(cfg))


def test_check_channel_accepts_exactly_the_bound_channels():
    for c in BOUND_CHANNELS:
        check_channel(c)
    assert BOUND_CHANNELS == ("diffuse", "specular", "color", "blend")
    for bad in ("Diffuse", "", "colour", None):
        with pytest.raises(ConfigError) as e:
            check_channel(bad)
        assert str(e.value) == f"channel must be one of diffuse, specular, color, blend, got {bad!r}"
