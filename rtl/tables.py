"""ROM contents, generated in one place and used by both the RTL (``Memory(init=...)``)
and the golden model.

Every table is a plain numpy integer array computed from a :class:`Config`.
"""

import functools

import numpy as np

from .config import Config

__all__ = ["quarter_sine", "sine_circle", "sin_lookup", "cos_lookup", "specular_index_bits", "specular_table",
           "phong_coefficients"]


def quarter_sine(cfg: Config) -> np.ndarray:
    """Quarter-wave sine ROM (DESIGN §4).

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
    # int32: the values need B + 2 <= 26 bits, and int32 gathers are 2-3x faster.
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
    """Address bits of the specular table: the clamped N'.H' with at most 12 fractional bits
    (2**12 + 1 entries x 8 bits = one ECP5 block RAM at most)."""
    return min(cfg.frac_bits, 12)


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
