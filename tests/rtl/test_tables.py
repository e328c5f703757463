import math
from fractions import Fraction

import numpy as np
import pytest

from bumprtl.rtl.config import Config
from bumprtl.rtl.tables import (
    blend_coefficients,
    cos_lookup,
    phong_coefficients,
    quarter_line,
    quarter_sine,
    quarter_sine_above_line,
    sin_lookup,
    specular_step_bits,
    specular_table,
)


@pytest.mark.parametrize("angle_bits, frac_bits", [(8, 8), (12, 13), (14, 16)])
def test_rom_within_half_ulp_of_float64(angle_bits, frac_bits):
    cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
    rom = quarter_sine(cfg)
    exact = np.sin(np.arange(cfg.sincos_depth) * (np.pi / 2) / (1 << cfg.k)) * cfg.one
    assert rom.shape == (cfg.sincos_depth,)
    assert np.max(np.abs(rom - exact)) <= 0.5
    assert rom[0] == 0 and rom[-1] == cfg.one


@pytest.mark.parametrize("angle_bits, frac_bits", [(8, 8), (12, 13)])
def test_full_circle_lookup_within_half_ulp(angle_bits, frac_bits):
    """Symmetry done in logic must not add error: every angle of the circle, sin and cos."""
    cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
    a = np.arange(cfg.full_circle)
    rad = a * 2 * np.pi / cfg.full_circle
    assert np.max(np.abs(sin_lookup(cfg, a) - np.sin(rad) * cfg.one)) <= 0.5
    assert np.max(np.abs(cos_lookup(cfg, a) - np.cos(rad) * cfg.one)) <= 0.5


def test_lookup_wraps_like_binary_angles():
    cfg = Config()
    a = np.arange(-5, 5)
    assert np.array_equal(sin_lookup(cfg, a), sin_lookup(cfg, a + 3 * cfg.full_circle))


# --- independent float64 oracles of the tables the RTL and the golden model share ------------
# rtl/tables.py feeds both the RTL's ROMs and the golden model, so the bit-exact tests cannot
# see a wrong entry: each table is checked here against its definition, computed entry by
# entry with exact rationals (fractions) or math, never by calling the function under test.

@pytest.mark.parametrize("spec_index_bits, frac_bits, exponent", [
    (10, 13, 16), (4, 13, 1), (6, 10, 3), (13, 13, 2), (8, 13, 1024), (10, 16, 128)])
def test_specular_table_is_cos_n_rounded_to_nearest(spec_index_bits, frac_bits, exponent):
    """Eq. (2)'s (N'.H)^n with F = 9 fractional bits: word j = 255 2**9 (x0 + j 2**-t)**n
    rounded to nearest, j = 0 .. 2**s, s = min(B, spec_index_bits), within half an LSB of the
    exact rational; the step 2**-t (s <= t <= B) is the finest at which every word below
    x0 = 1 - 2**(s - t) would round to 0 (so word 0 is 0), and word 2**s is N'.H = 1."""
    # 12-bit angles admit every B here (B >= 9); the table does not depend on the angle width
    cfg = Config(angle_bits=12, frac_bits=frac_bits, spec_index_bits=spec_index_bits,
                 spec_exponent=exponent)
    s, scale = min(frac_bits, spec_index_bits), 255 * 2 ** 9
    below = lambda t: scale * (1 - Fraction(1, 2 ** (t - s))) ** exponent < Fraction(1, 2)
    t = max([s] + [t for t in range(s + 1, frac_bits + 1) if below(t)])
    table = specular_table(cfg)
    assert specular_step_bits(cfg) == t
    assert len(table) == (1 << s) + 1 and table[0] == 0 and table[-1] == scale
    x0 = 1 - Fraction(1, 2 ** (t - s))
    for j, got in enumerate(table.tolist()):
        exact = scale * (x0 + Fraction(j, 2 ** t)) ** exponent
        assert abs(got - exact) <= Fraction(1, 2), (j, got, float(exact))


@pytest.mark.parametrize("ka, kd, ks", [(0.1, 0.7, 0.2), (0.0, 1.0, 1.0), (0.33, 0.47, 0.61),
                                        (0.47, 0.33, 0.47), (0.999, 0.0039, 0.0059), (1.0, 0.5, 0.0)])
@pytest.mark.parametrize("specular", [True, False])
def test_phong_coefficients_round_to_nearest(ka, kd, ks, specular):
    """Eq. (2)'s ka, kd, ks for the Phong sum in 8-bit LSB with 9 fractional bits: KA =
    255 ka 2**9, KD = 255 kd 2**9 (times clamp(N'.L) with B fractional bits), KS = ks 2**16
    (times the 17-bit specular, 0 without specular); the blend's KA = ka 2**16, KD = kd 2**16;
    each within half an LSB."""
    cfg = Config(ka=ka, kd=kd, ks=ks, specular=specular)
    got = phong_coefficients(cfg) + blend_coefficients(cfg)[:2]
    exact = (255 * 512 * Fraction(ka), 255 * 512 * Fraction(kd),
             65536 * Fraction(ks) if specular else 0, 65536 * Fraction(ka), 65536 * Fraction(kd))
    for g, e in zip(got, exact, strict=False):
        assert isinstance(g, int) and abs(g - e) <= Fraction(1, 2), (got, exact)


@pytest.mark.parametrize("angle_bits, frac_bits", [(4, 4), (8, 9), (12, 13), (16, 24)])
def test_quarter_sine_entries_from_math_sin(angle_bits, frac_bits):
    """Entry i = sin(i 90 deg / 2**k) 2**B rounded to nearest, i = 0 .. 2**k, from math.sin
    per entry (ties cannot occur: sin of a non-zero rational multiple of pi/2 below 1 is
    irrational)."""
    cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
    k = angle_bits - 2
    want = [math.floor(math.sin(i * (math.pi / 2) / (1 << k)) * (1 << frac_bits) + 0.5)
            for i in range((1 << k) + 1)]
    assert quarter_sine(cfg).tolist() == want


@pytest.mark.parametrize("angle_bits, frac_bits", [(6, 4), (13, 11), (14, 15), (15, 16), (16, 13),
                                                   (16, 24)])
def test_sine_above_line_is_the_sine_minus_a_shift(angle_bits, frac_bits):
    """quarter_line(i) = floor(i 2**B / 2**k) in Python integers; the ROM's sine above it adds
    back to quarter_sine, is never negative (sin x >= 2x/pi on [0, pi/2]) and stays below
    0.2106 2**B + 1, B - 2 bits (max(sin x - 2x/pi) = sqrt(1 - 4/pi**2) - 2 acos(2/pi)/pi)."""
    cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
    k, depth = angle_bits - 2, cfg.sincos_depth
    line = quarter_line(cfg, np.arange(depth))
    assert line.tolist() == [(i * (1 << frac_bits)) // (1 << k) for i in range(depth)]
    above = quarter_sine_above_line(cfg)
    assert (above + line).tolist() == quarter_sine(cfg).tolist()
    peak = math.sqrt(1 - 4 / math.pi ** 2) - 2 * math.acos(2 / math.pi) / math.pi
    assert 0.2105 < peak < 0.2106
    assert above.min() == 0 and above[0] == 0 and above[-1] == 0
    assert above.max() <= peak * (1 << frac_bits) + 1
    assert int(above.max()).bit_length() <= frac_bits - 2


@pytest.mark.parametrize("step_bits", [6, 7, 9, 10])
def test_every_table_step_reads_its_own_words_from_x0_to_one(step_bits):
    """``bumprtl bench specular``'s candidate steps (``step_bits`` t other than the RTL's):
    the fine specular of the golden model reads the table of that step from its own x0 =
    1 - 2**(s - t): word 0, round(255 x0**n 2**F), at and below x0, 255 2**F at N'.H = 1
    (word 2**s), and within one table step's interpolation of 255 h**n 2**F between them."""
    from bumprtl.rtl.tables import SPEC_FRAC_BITS, specular_base, specular_index_bits
    from bumprtl.sim.golden.fixed.common import specular_fine_fixed

    cfg = Config(angle_bits=10, frac_bits=10, spec_index_bits=6, spec_exponent=32)
    s, one = specular_index_bits(cfg), cfg.one
    x0 = one - (1 << (cfg.frac_bits - step_bits + s))          # typed from the docstring
    assert specular_base(cfg, step_bits) == x0
    h = np.arange(max(x0 - 8, 0), one + 1)
    fine = specular_fine_fixed(h, cfg, step_bits)
    assert fine[h == one][0] == 255 << SPEC_FRAC_BITS
    word0 = round(255 * (x0 / one) ** cfg.spec_exponent * (1 << SPEC_FRAC_BITS))
    assert np.all(fine[h <= x0] == word0)
    exact = 255 * (h / one) ** cfg.spec_exponent * (1 << SPEC_FRAC_BITS)
    step = 255 * (1 << SPEC_FRAC_BITS) * (1 - (1 - 2.0 ** -step_bits) ** cfg.spec_exponent)
    assert np.all(np.abs(fine - exact)[h > x0] <= step)
