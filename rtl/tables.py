"""ROM contents, generated in one place and used by both the RTL (``Memory(init=...)``)
and the golden model.

Every table is a plain numpy integer array computed from a :class:`Config`.
"""

import functools

import numpy as np

from bumprtl.rtl.config import Config

__all__ = ["quarter_sine", "sine_circle", "sin_lookup", "cos_lookup", "specular_index_bits", "specular_table",
           "phong_coefficients", "lee_asin_index_bits", "lee_asin_table", "lee_reciprocal_bits",
           "lee_reciprocal_table", "lee_atan_mantissa_bits", "lee_atan_ratio_bits", "lee_atan_depth",
           "lee_atan_table", "lee_prop_index_bits", "lee_prop_table", "kim_reciprocal_bits",
           "kim_reciprocal_table"]


def quarter_sine(cfg: Config) -> np.ndarray:
    """Quarter-wave sine ROM (docs/architecture.md, Number formats).

    Entry ``i`` (0 <= i <= 2**k) holds ``round(sin(i * 90deg / 2**k) * 2**B)``: the sine of
    ``i`` binary-angle steps, rounded to nearest, so ``rom[0] == 0`` and
    ``rom[2**k] == 2**B`` (exactly 1.0). Values are non-negative; the sign and the mirrored
    index of the other three quadrants are produced in logic.
    """
    i = np.arange(cfg.sincos_depth, dtype=np.float64)
    return np.rint(np.sin(i * (np.pi / 2) / (1 << cfg.k)) * cfg.one).astype(np.int64)


@functools.lru_cache(maxsize=32)
def sine_circle(cfg: Config) -> np.ndarray:
    """``sin`` of every binary angle of the circle, read through the quarter-wave ROM exactly
    as the RTL does it (mirrored index in quadrants 1 and 3, negated in 2 and 3). A cache
    for the golden model: one gather per lookup instead of the symmetry logic."""
    rom = quarter_sine(cfg)
    a = np.arange(cfg.full_circle, dtype=np.int64)
    quadrant = a >> cfg.k
    index = a & ((1 << cfg.k) - 1)
    mirrored = (quadrant & 1) == 1          # quadrants 1 and 3 read the ROM backwards
    value = rom[np.where(mirrored, (1 << cfg.k) - index, index)]
    # int32: the values need B + 2 <= 26 bits, and int32 gathers are faster than int64 ones.
    table = np.where(quadrant >= 2, -value, value).astype(np.int32)  # quadrants 2, 3 negative
    table.flags.writeable = False
    return table


def sin_lookup(cfg: Config, angle) -> np.ndarray:
    """``sin`` of binary angles, bit-exact with the RTL's quarter-wave read.

    ``angle`` is any integer array; it is taken modulo the full circle (angle sums wrap).
    Returns int32 values with ``frac_bits`` fractional bits.
    """
    a = np.asarray(angle)
    if a.dtype.kind not in "iu":
        a = a.astype(np.int64)
    return sine_circle(cfg)[a & (cfg.full_circle - 1)]


def cos_lookup(cfg: Config, angle) -> np.ndarray:
    """``cos(a) = sin(a + 90 deg)``: a quarter circle is ``2**k`` binary-angle steps."""
    return sin_lookup(cfg, np.asarray(angle, dtype=np.int64) + (1 << cfg.k))


# --- Illumination back end (Lee Sec. 3.2 / Fig. 8: diffuse and specular tables) -------------

def specular_index_bits(cfg: Config) -> int:
    """Address bits of the specular table: the clamped N'.H' with ``spec_index_bits``
    fractional bits (at most ``frac_bits``). At the default 10, 2**10 + 1 entries x 8 bits
    fit one ECP5 DP16KD (2048 x 9), so the read has no multiplexer between block RAMs."""
    return min(cfg.frac_bits, cfg.spec_index_bits)


def specular_table(cfg: Config) -> np.ndarray:
    """``cos^n`` table (eq. 2's (N'.H)^n): entry i = round(255 * (i / 2**s)**n), i = 0..2**s."""
    s = specular_index_bits(cfg)
    x = np.arange((1 << s) + 1, dtype=np.float64) / (1 << s)
    return np.rint(255.0 * x ** cfg.spec_exponent).astype(np.int64)


def phong_coefficients(cfg: Config):
    """(KA, KD, KS): eq. (2)'s ka, kd, ks as integers. color8 = (KA + KD d8 + KS s8) / 256,
    so KA = round(255 * 256 * ka) and KD, KS = round(256 * k) (8 fractional bits)."""
    return (int(round(255 * 256 * cfg.ka)), int(round(256 * cfg.kd)),
            int(round(256 * cfg.ks)) if cfg.specular else 0)


# --- Lee et al. 2003: the vector-rotation ROMs of Fig. 7 (rtl/lee.py) -----------------------
# Angles out of these tables are binary-angle codes (full circle = 2**(k+2)); fractions carry
# frac_bits = B fractional bits. Each table is indexed by a magnitude; signs, quadrants and
# the errata's branch fixes are logic in rtl/lee.py and sim/golden/fixed/lee.py.

def _angle_code(rad, cfg: Config):
    return np.rint(rad * (cfg.full_circle / (2 * np.pi))).astype(np.int64)


def lee_asin_index_bits(cfg: Config) -> int:
    """Address bits of the asin ROM: |s| = |sin X + sin Y| / 2 in [0, 1] with this many
    fractional bits (the angle resolution, and no more bits than s carries)."""
    return min(cfg.k + 2, cfg.frac_bits + 1)


def lee_asin_table(cfg: Config) -> np.ndarray:
    """Eq. 7's Sin^-1: entry i = asin(i / 2**a) as a binary angle (0 .. 90 deg), i = 0 .. 2**a."""
    a = lee_asin_index_bits(cfg)
    return _angle_code(np.arcsin(np.arange((1 << a) + 1) / (1 << a)), cfg)


def lee_reciprocal_bits(cfg: Config) -> int:
    """Width of the 1/|sin| ROM values: k integer bits (1/sin of one angle step is
    2**(k+2) / 2pi < 2**k) and B fractional bits."""
    return cfg.k + cfg.frac_bits


def lee_reciprocal_table(cfg: Config) -> np.ndarray:
    """Quarter-wave 1/sin (eqs 9 and 27's 1/(2 sin Z), 1/(2 cos Z); Sec. 4.1 reads them
    straight from Z): entry i = 1/sin(i * 90deg / 2**k) with B fractional bits, i = 0 .. 2**k,
    saturated at the largest value of lee_reciprocal_bits (erratum 8: 1/sin 0 is unbounded)."""
    i = np.arange(cfg.sincos_depth, dtype=np.float64)
    top = (1 << lee_reciprocal_bits(cfg)) - 1
    with np.errstate(divide="ignore"):
        r = cfg.one / np.sin(i * (np.pi / 2) / (1 << cfg.k))
    return np.rint(np.minimum(r, top)).astype(np.int64)


def lee_atan_mantissa_bits(cfg: Config) -> int:
    """Mantissa bits M of the atan ROM's floating-point address (relative step 2**-M:
    the atan error stays below 2**-(M+2) rad, under half an angle step)."""
    return cfg.k - 2


def lee_atan_ratio_bits(cfg: Config) -> int:
    """Width W of the ratio |y / sin Z| fed to the atan address: k integer bits (the
    saturated 1/sin bounds it by 2**k) and k fractional bits."""
    return 2 * cfg.k


def lee_atan_depth(cfg: Config) -> int:
    """Entries of the atan ROM: (W - M + 1) * 2**M (one 2**M block per exponent)."""
    m = lee_atan_mantissa_bits(cfg)
    return (lee_atan_ratio_bits(cfg) - m + 1) << m


def lee_atan_table(cfg: Config) -> np.ndarray:
    """Eq. 9's Tan^-1 of a ratio t >= 0 given as a floating-point address (rtl/lee.py
    ``ratio_index``): address (e + 1) * 2**M + f stands for the ratios q * 2**e .. (q+1) * 2**e
    (q = 2**M + f, in units of 2**-k; exponent block 0 is linear), and holds atan of the middle
    of that interval, so the address's truncation rounds to nearest. Binary angles 0 .. 90 deg."""
    m = lee_atan_mantissa_bits(cfg)
    idx = np.arange(lee_atan_depth(cfg), dtype=np.int64)
    e = np.maximum((idx >> m) - 1, 0)
    q = idx - (e << m)
    t = (q + 0.5) * np.exp2(e) / (1 << cfg.k)
    return _angle_code(np.arctan(t), cfg)


def lee_prop_index_bits(cfg: Config) -> int:
    """Address bits of T_prop: |y_k| in [0, 1] with k + 2 fractional bits."""
    return cfg.k + 2


def lee_prop_table(cfg: Config) -> np.ndarray:
    """T_prop, eq. 26: theta_prop = 1 - acos(y_k) / 90deg for y_k = i / 2**p, i = 0 .. 2**p,
    with B fractional bits (erratum 4: indexed by |y_k| clamped to [0, 1])."""
    p = lee_prop_index_bits(cfg)
    y = np.arange((1 << p) + 1, dtype=np.float64) / (1 << p)
    return np.rint((1.0 - np.arccos(y) / (np.pi / 2)) * cfg.one).astype(np.int64)


# --- Kim et al. 2001 baseline: the Cartesian -> polar divide (rtl/baselines/kim.py) ---------

def kim_reciprocal_bits(cfg: Config) -> int:
    """Address bits R of the reciprocal ROM: the mantissa bits of the normalized divisor
    (relative step 2**-R, so the ratio's relative error is at most 2**-(R+1))."""
    return min(cfg.k, cfg.frac_bits)


def kim_reciprocal_table(cfg: Config) -> np.ndarray:
    """1/P for a divisor P in [1, 2) (its leading one at bit B): entry i holds
    round(2**B / (1 + (i + 0.5) / 2**R)), the reciprocal of the middle of the interval the
    R mantissa bits i select, i = 0 .. 2**R - 1, with B fractional bits (width B + 1)."""
    r = kim_reciprocal_bits(cfg)
    i = np.arange(1 << r, dtype=np.float64)
    return np.rint(cfg.one / (1.0 + (i + 0.5) / (1 << r))).astype(np.int64)
