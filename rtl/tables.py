"""ROM contents, generated in one place and used by both the RTL (``Memory(init=...)``)
and the golden model.

Every table is a plain numpy integer array computed from a :class:`Config`.
"""

import functools

import numpy as np

from bumprtl.rtl.config import Config

__all__ = ["quarter_sine", "quarter_line", "quarter_sine_above_line", "sine_circle", "sin_lookup", "cos_lookup", "specular_index_bits",
           "specular_step_bits", "specular_base", "specular_table", "specular_table_error_lsb",
           "SPEC_FRAC_BITS", "COLOR_FRAC_BITS", "KD_FRAC_BITS", "KS_FRAC_BITS", "LIT_FRAC_BITS",
           "phong_coefficients", "blend_coefficients", "coefficient_error_lsb", "lee_asin_index_bits", "lee_asin_table", "lee_reciprocal_bits",
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


def quarter_line(cfg: Config, index):
    """The straight line under the quarter wave: ``floor(i * 2**B / 2**k)``, 0 at ``i = 0`` and
    exactly 1.0 at ``i = 2**k`` (the RTL computes it as ``(i << B) >> k``: a shift, no
    multiplier). ``sin x >= 2x/pi`` on [0, pi/2], so :func:`quarter_sine` never falls below it."""
    return (np.asarray(index, dtype=np.int64) << cfg.frac_bits) >> cfg.k


def quarter_sine_above_line(cfg: Config) -> np.ndarray:
    """:func:`quarter_sine` minus :func:`quarter_line`: what a quarter-wave ROM stores where
    storing the sine itself would take more block RAMs (rtl/sincos.sine_line). Every entry
    is at least 0 and below ``0.2106 * 2**B + 1`` (``max(sin x - 2x/pi)`` is 0.2105, at
    ``cos x = 2/pi``), so it needs ``B - 2`` bits instead of the sine's ``B + 1``; entries 0
    and ``2**k`` are 0."""
    return quarter_sine(cfg) - quarter_line(cfg, np.arange(cfg.sincos_depth))


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
# Eq. (2) is carried with extra fractional bits and rounded once, at the end (rtl/shade.py):
# the specular term as 255 (N'.H)^n with SPEC_FRAC_BITS fractional bits, the diffuse term as
# clamp(N'.L) with B, the Phong sum with COLOR_FRAC_BITS; only the 8-bit output ports round.

SPEC_FRAC_BITS = 9      # F: fractional bits of the specular table (8 + F = 17 bits a word)
COLOR_FRAC_BITS = 9     # G: fractional bits (of an 8-bit LSB) of eq. 2's Phong sum
KD_FRAC_BITS = 9        # KD = 255 kd 2**9: <= 17 bits, one DSP operand with clamp(N'.L)
KS_FRAC_BITS = 16       # KS = ks 2**16: <= 17 bits, one DSP operand with the 17-bit specular
LIT_FRAC_BITS = 16      # the texture blend's lit = min(1, ka + kd D) (rtl/texture.py)


def specular_index_bits(cfg: Config) -> int:
    """Address bits s of the specular table: 2**s + 1 words (at most ``frac_bits``). At the
    default 10, 1025 words x 17 bits are one ECP5 DP16KD (1024 x 18, the last word in a
    flip-flop: rtl/pipe.RegisteredROM), read through both of its ports."""
    return min(cfg.frac_bits, cfg.spec_index_bits)


def _spec_scale():
    return 255 * (1 << SPEC_FRAC_BITS)


def specular_step_bits(cfg: Config) -> int:
    """t: the table's step is 2**-t in N'.H (s <= t <= B). The table covers
    [x0, 1] = [1 - 2**(s - t), 1] in 2**s steps and is interpolated linearly between them
    with the B - t bits of N'.H below its step; t is the largest for which everything below
    x0 rounds to 0 (255 x0**n 2**F < 1/2), so a large exponent n, whose cos^n is non-zero
    only near N'.H = 1, gets a finer step there (an index finer near 1)."""
    s, b, n = specular_index_bits(cfg), cfg.frac_bits, cfg.spec_exponent
    best = s
    for t in range(s + 1, b + 1):
        if _spec_scale() * (1.0 - 2.0 ** (s - t)) ** n < 0.5:
            best = t
    return best


def specular_base(cfg: Config, step_bits=None) -> int:
    """x0 with B fractional bits: the table's word 0 stands for N'.H = x0 (0 when t = s).
    ``step_bits``: t other than :func:`specular_step_bits` (the candidates of ``bumprtl
    bench specular``)."""
    s = specular_index_bits(cfg)
    t = specular_step_bits(cfg) if step_bits is None else step_bits
    return cfg.one - (1 << (cfg.frac_bits - t + s))


def specular_table(cfg: Config, step_bits=None) -> np.ndarray:
    """``cos^n`` table (eq. 2's (N'.H)^n): word j = round(255 (x0 + j 2**-t)**n 2**F),
    j = 0 .. 2**s, with F = SPEC_FRAC_BITS fractional bits; word 0 is 0 and word 2**s (N'.H =
    1) is 255 2**F. rtl/shade.py reads words j and j + 1 and interpolates."""
    s = specular_index_bits(cfg)
    t = specular_step_bits(cfg) if step_bits is None else step_bits
    x = specular_base(cfg, t) / cfg.one + np.arange((1 << s) + 1, dtype=np.float64) / (1 << t)
    return np.rint(_spec_scale() * x ** cfg.spec_exponent).astype(np.int64)


def specular_table_error_lsb(cfg: Config) -> float:
    """Bound on |specular_fine / 2**F - 255 x**n| (8-bit LSB) for N'.H = x in [0, 1] on the
    grid of B fractional bits: the words' rounding 2**-(F+1); linear interpolation of the
    convex x**n, whose chord lies above it by at most h**2 / 8 max f'' = 2**-2t 255 n (n - 1)
    / 8 (f'' is largest at x = 1); the floor of the interpolation product, 2**-F; below x0 the
    table gives 0 where 255 x**n < 2**-(F+1) (specular_step_bits)."""
    n, t, f = cfg.spec_exponent, specular_step_bits(cfg), SPEC_FRAC_BITS
    chord = 255.0 * n * (n - 1) / 8 * 4.0 ** -t if cfg.frac_bits > t else 0.0
    return 2.0 ** -(f + 1) + chord + (2.0 ** -f if cfg.frac_bits > t else 0.0)


def phong_coefficients(cfg: Config):
    """(KA, KD, KS): eq. (2)'s ka, kd, ks as integers for the Phong sum of rtl/shade.py, in
    8-bit LSB with G = COLOR_FRAC_BITS fractional bits:
    KA = round(255 ka 2**G), KD = round(255 kd 2**KD_FRAC_BITS) (times clamp(N'.L) with B
    fractional bits), KS = round(ks 2**KS_FRAC_BITS) (times the specular with F; 0 without
    specular)."""
    return (int(round(255 * cfg.ka * (1 << COLOR_FRAC_BITS))),
            int(round(255 * cfg.kd * (1 << KD_FRAC_BITS))),
            int(round(cfg.ks * (1 << KS_FRAC_BITS))) if cfg.specular else 0)


def blend_coefficients(cfg: Config):
    """(KA, KD, KS) of the texture blend (rtl/texture.py): lit = min(1, ka + kd D) with
    LIT_FRAC_BITS fractional bits, KA = round(ka 2**16), KD = round(kd 2**16) (times D with B
    fractional bits), KS as in :func:`phong_coefficients`."""
    return (int(round(cfg.ka * (1 << LIT_FRAC_BITS))), int(round(cfg.kd * (1 << LIT_FRAC_BITS))),
            phong_coefficients(cfg)[2])


def coefficient_error_lsb(cfg: Config, lights=1, blend=False):
    """Bound (8-bit LSB) on what the integer Phong sum (``blend``: the texture blend) adds to
    255 (ka + kd D + ks S) for exact D = sum clamp(N'.L_j), S = sum cos^n: the coefficients'
    rounding at their largest inputs (D, S <= m) and the floor of each product (2**-G each,
    2**-LIT_FRAC_BITS in lit, which a texel of 255 scales by 255)."""
    ks = cfg.ks if cfg.specular else 0.0
    ka_i, kd_i, ks_i = phong_coefficients(cfg)
    e_ks = lights * 255 * abs(ks_i / (1 << KS_FRAC_BITS) - ks)
    if not blend:
        g = 2.0 ** -COLOR_FRAC_BITS
        return (abs(ka_i * g - 255 * cfg.ka) + lights * abs(kd_i / (1 << KD_FRAC_BITS) - 255 * cfg.kd)
                + e_ks + 2 * g)
    ka_l, kd_l, _ = blend_coefficients(cfg)
    g = 2.0 ** -LIT_FRAC_BITS
    lit = abs(ka_l * g - cfg.ka) + lights * abs(kd_l * g - cfg.kd) + g
    return 255 * lit + e_ks + g


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
