"""ROM contents, generated in one place and used by both the RTL (``Memory(init=...)``)
and the golden model.

Every table is a plain numpy integer array computed from a :class:`Config`.
"""

import numpy as np

from .config import Config

__all__ = ["quarter_sine", "sin_lookup", "cos_lookup"]


def quarter_sine(cfg: Config) -> np.ndarray:
    """Quarter-wave sine ROM (DESIGN §4).

    Entry ``i`` (0 <= i <= 2**k) holds ``round(sin(i * 90deg / 2**k) * 2**B)``: the sine of
    ``i`` binary-angle steps, rounded to nearest, so ``rom[0] == 0`` and
    ``rom[2**k] == 2**B`` (exactly 1.0). Values are non-negative; the sign and the mirrored
    index of the other three quadrants are produced in logic.
    """
    i = np.arange(cfg.sincos_depth, dtype=np.float64)
    return np.rint(np.sin(i * (np.pi / 2) / (1 << cfg.k)) * cfg.one).astype(np.int64)


def sin_lookup(cfg: Config, angle) -> np.ndarray:
    """``sin`` of binary angles through the quarter-wave ROM, exactly as the RTL does it.

    ``angle`` is any integer array; it is taken modulo the full circle (angle sums wrap).
    Returns int64 values with ``frac_bits`` fractional bits.
    """
    rom = quarter_sine(cfg)
    a = np.asarray(angle, dtype=np.int64) & (cfg.full_circle - 1)
    quadrant = a >> cfg.k
    index = a & ((1 << cfg.k) - 1)
    mirrored = (quadrant & 1) == 1          # quadrants 1 and 3 read the ROM backwards
    value = rom[np.where(mirrored, (1 << cfg.k) - index, index)]
    return np.where(quadrant >= 2, -value, value)  # quadrants 2 and 3 are negative


def cos_lookup(cfg: Config, angle) -> np.ndarray:
    """``cos(a) = sin(a + 90 deg)``: a quarter circle is ``2**k`` binary-angle steps."""
    return sin_lookup(cfg, np.asarray(angle, dtype=np.int64) + (1 << cfg.k))
