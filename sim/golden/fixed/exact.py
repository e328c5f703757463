"""Bit-exact int64 model of the ``exact`` datapath (rtl/exact.py), vectorized.

Scales (all integers carry ``frac_bits`` = B fractional bits; no rounding until the dot):
  n.x4 = 4 n''x, n.y2 = 2 n''y, n.z4 = 4 n''z     (product-to-sum sums, docs/architecture.md)
  a.p2 = 2 p, a.y2 = 2 y, a.z = cos th_A          per vector A in {L, H}
  N'.A' = (n.x4 a.p2 + 2 n.y2 a.y2 + 2 n.z4 a.z) / 8, one rounding back to B bits.
"""

import functools
import itertools

import numpy as np

from bumprtl.rtl.config import ANGLE_BITS_RANGE, FRAC_BITS_MAX, Config, frac_bits_floor
from bumprtl.rtl.exact import vectors  # L, and H with specular: the RTL's own list
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.tables import cos_lookup, sin_lookup
from bumprtl.sim.golden.fixed.common import (
    BOUND_CHANNELS,
    channel_bound,
    input_angle_error,
    shade_fixed,
)

__all__ = ["rotation_fixed", "illumination_fixed", "dot_fixed", "vectors", "dot_error_bound",
           "predicted_error_bound_lsb"]


# A test hook, None outside sim/tb/bulk_frame.py's search for table-sensitivity pixels (which
# restores it): ``f(k, angle, value) -> value`` sees the k-th quarter-wave ROM read of a
# rotation_fixed call (k = 0, 1, ... in the order of the code below), ``angle`` the sine's
# binary angle (a cosine's plus a quarter circle), ``value`` the signed word read; what it
# returns replaces the word. None changes nothing.
TABLE_READ = None

# A test hook like TABLE_READ, None outside sim/tb/bulk_frame.py's search for dot-sensitivity
# pixels: ``f(v, acc) -> acc`` sees each dot_fixed call's unrounded sum (``v`` the vector,
# "l" or "h", in the order illumination_fixed computes them, light after light); what it
# returns is rounded instead.
DOT_SUM = None


def rotation_fixed(codes, cfg: Config):
    """VectorRotation (exact): n'' of the bump normal and p, y, cos th of L and H."""
    s, c = (lambda a: sin_lookup(cfg, a)), (lambda a: cos_lookup(cfg, a))
    if TABLE_READ is not None:
        k, q = itertools.count(), 1 << cfg.k
        s = lambda a: TABLE_READ(next(k), a, sin_lookup(cfg, a))
        c = lambda a: TABLE_READ(next(k), np.asarray(a) + q, cos_lookup(cfg, a))
    t, bt, bp = codes["n.theta"], codes["b.theta"], codes["b.phi"]
    a, b = bt + bp, bt - bp                   # a = th_N' + ph_N', b = th_N' - ph_N'
    out = {
        "n.x4": s(a + t) + s(a - t) + s(b + t) + s(b - t) + 2 * (s(t + bt) + s(t - bt)),
        "n.y2": c(b) - c(a),
        "n.z4": -(c(a - t) - c(a + t) + c(b - t) - c(b + t)) + 2 * (c(bt - t) + c(bt + t)),
    }
    for v in vectors(cfg):
        th, d = codes[f"{v}.theta"], codes[f"{v}.phi"] - codes["n.phi"]
        x, y = th + d, th - d                 # X = th_A + D, Y = th_A - D (binary angles wrap)
        out[f"{v}.p2"] = s(x) + s(y)
        out[f"{v}.y2"] = c(y) - c(x)
        out[f"{v}.z"] = c(th)
    return out


def dot_fixed(rot, v, cfg: Config):
    """N'.A' with B fractional bits: (x4 p2 + 2 y2 y2 + 2 z4 z) / 8 / 2**B, rounded once."""
    wide = lambda key: rot[key].astype(np.int64)          # products need up to 2B + 8 bits
    acc = (wide("n.x4") * rot[f"{v}.p2"] + 2 * wide("n.y2") * rot[f"{v}.y2"]
           + 2 * wide("n.z4") * rot[f"{v}.z"])
    if DOT_SUM is not None:
        acc = DOT_SUM(v, acc)
    return round_shift(acc, cfg.frac_bits + 3)


def illumination_fixed(rot, cfg: Config):
    """Illumination (exact): ndotl, ndoth and 8-bit diffuse, specular, color."""
    ndotl = dot_fixed(rot, "l", cfg)
    ndoth = dot_fixed(rot, "h", cfg) if cfg.specular else np.zeros_like(ndotl)
    return {"ndotl": ndotl, "ndoth": ndoth, **shade_fixed(ndotl, ndoth, cfg)}


def dot_error_bound(cfg: Config):
    """|N'.A' computed - exact N'.A' of the same (rounded) angles| <= (1.5 + sqrt(3)/2 + 1/2
    + 1.3 u) u, u = 2**-B: the ROM values are off by at most u/2 each, so n'' (4 values / 4 +
    2 / 2, 2 / 2, 4 / 4 + 2 / 2) is off by at most sqrt(1 + 1/4 + 1) u = 1.5 u, the vector
    terms (p, y, cos th_A) by sqrt(3)/2 u; both exact vectors are unit vectors, so the dot
    moves by at most the sum (Cauchy-Schwarz), 1.3 u**2 covers the product of the two errors,
    and the dot's one rounding adds u/2."""
    u = 2.0 ** -cfg.frac_bits
    return (1.5 + np.sqrt(3) / 2 + 0.5 + 1.3 * u) * u


@functools.lru_cache(maxsize=64)
def faithful_widths(cfg: Config):
    """``(angle_bits, frac_bits)``: the narrowest widths (fewest angle bits, then fewest
    fractional bits) at which :func:`predicted_error_bound_lsb` proves every output channel
    (diffuse, specular, colour, the texture blend; summed over ``cfg.lights`` lights) within
    1 LSB of float64 end to end, ``cfg``'s other fields kept; None if no widths in the
    Config's range do.

    Two errors of the specular term grow with the Phong exponent n (docs/fixed_point.md):
    the inputs' rounding to the angle grid moves 255 cos^n by up to about
    255 n cos^(n-1)(a) sin(a) D, largest at sin a = 1 / sqrt(n), so it grows as sqrt(n) (each
    factor 4 in n halves the step D must have: one more angle bit), and the dot product's
    own error (a few 2^-B) times the slope 255 n of cos^n near N'.H' = 1 grows as n (each
    factor 2: one more fractional bit). The bound falls as either width grows, so an angle
    width that does not reach 1 LSB at the widest B reaches it at none."""
    lo, hi = ANGLE_BITS_RANGE
    for angle_bits in range(lo, hi + 1):
        if not _faithful(cfg.replace(angle_bits=angle_bits, frac_bits=FRAC_BITS_MAX)):
            continue
        return angle_bits, next(b for b in range(frac_bits_floor(angle_bits), FRAC_BITS_MAX + 1)
                                if _faithful(cfg.replace(angle_bits=angle_bits, frac_bits=b)))
    return None


def _faithful(cfg: Config):
    return all(predicted_error_bound_lsb(cfg, c, cfg.lights) <= 1 for c in BOUND_CHANNELS)


def predicted_error_bound_lsb(cfg: Config, channel="diffuse", lights=1):
    """Proven worst case of one output ``channel`` (``diffuse``, ``specular``, ``color``, or
    ``blend``, the texture blend's colour) of the exact datapath against float64 on
    unquantized inputs, in 8-bit LSB (|8-bit output - round(255 x float64)|), summed over
    ``lights`` lights for the light sum and the blend.

    * input rounding: the angle alpha between N' and A (A = L or H) moves by at most
      D = 2 sqrt(5) delta, delta = pi / 2**(k+2) (common.input_angle_error: exact, not only
      first order), so N'.A' of the rounded angles lies in [cos(alpha + D), cos(alpha - D)];
    * arithmetic: the computed dot is within E = :func:`dot_error_bound` of that;
    * so the unrounded terms 255 clamp(x) and 255 clamp(x)**n are off by at most the largest
      change of those functions over that interval, maximized over alpha on a fine grid of
      intervals (common.term_bounds_lsb, rigorous because both are monotone); the specular
      term adds its table's rounding and interpolation (rtl/tables.specular_table_error_lsb);
    * eq. 2's colour and the blend take the unrounded terms and round once: kd and ks times
      those errors plus the coefficients' quantization (common.channel_bounds_lsb);
    * the 8-bit rounding of both sides turns an error e before it into at most floor(e) + 1.
    Where the widths make 1 LSB impossible (the specular term of a large n: its slope 255 n
    times the angle grid's and the ROMs' error) this is the larger bound, and the sidecar
    states it. Measured maxima stay under it and reach at least half of it
    (tests/sim/golden/fixed/test_exact.py, test_channels.py).
    """
    return channel_bound(cfg, channel, input_angle_error(cfg), dot_error_bound(cfg), lights)
