"""Q-format helper shared, operation for operation, by the RTL and the golden model.

The same Python function is applied to Amaranth ``Value``s (in ``elaborate``) and to
numpy int64 arrays (in ``sim/golden``), so the two cannot drift apart:

* :func:`round_shift` is round-to-nearest (ties toward +inf): add half an LSB of the
  result, then shift right arithmetically. ``>>`` floors in Amaranth and numpy alike, so
  rounding has to be written out (docs/architecture.md, Number formats).
* :func:`saturate` clamps into a :class:`Q` format; hardware never wraps silently.
"""

from dataclasses import dataclass

import numpy as np
from amaranth.hdl import Const, Mux, Value, ValueCastable, signed, unsigned

__all__ = ["Q", "round_shift", "mul_round", "saturate", "select_constant"]


@dataclass(frozen=True)
class Q:
    """A fixed-point format: ``int_bits`` integer bits (excluding sign), ``frac_bits``
    fractional bits, optional sign bit. ``Q(1, 13)`` holds [-2, 2) in steps of 2**-13."""
    int_bits: int
    frac_bits: int
    signed: bool = True

    def __post_init__(self):
        if self.int_bits < 0 or self.frac_bits < 0 or self.width > 63:
            raise ValueError(f"Q({self.int_bits}, {self.frac_bits}) is not a supported format "
                             f"(bits >= 0, total width <= 63)")

    @property
    def width(self):
        return self.int_bits + self.frac_bits + int(self.signed)

    @property
    def shape(self):
        return signed(self.width) if self.signed else unsigned(self.width)

    @property
    def min(self):
        return -(1 << (self.width - 1)) if self.signed else 0

    @property
    def max(self):
        return (1 << (self.width - 1)) - 1 if self.signed else (1 << self.width) - 1

    @property
    def one(self):
        return 1 << self.frac_bits

    def quantize(self, x):
        """float64 -> nearest representable integer code, saturated (for inputs/tables)."""
        return np.clip(np.rint(np.asarray(x, dtype=np.float64) * self.one), self.min, self.max).astype(np.int64)


def _is_hdl(x):
    return isinstance(x, (Value, ValueCastable))


def round_shift(x, n):
    """``x / 2**n`` rounded to nearest (half up). Works on Amaranth values and int arrays."""
    if n == 0:
        return x
    if n < 0:
        raise ValueError(f"shift must be >= 0, got {n}")
    if not _is_hdl(x):
        x = np.asarray(x)
        if x.dtype != object:          # object arrays: Python ints wider than 64 bits
            x = x.astype(np.int64)
    return (x + (1 << (n - 1))) >> n


def mul_round(a, b, n):
    """``a * b / 2**n`` rounded to nearest: a product brought back to a Q format."""
    if not _is_hdl(a) and not _is_hdl(b):
        a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
    return round_shift(a * b, n)


def saturate(x, q: Q):
    """Clamp ``x`` into format ``q`` (an Amaranth value of ``q.shape``, or an int64 array)."""
    if _is_hdl(x):
        clamped = Mux(x > q.max, q.max, Mux(x < q.min, q.min, x))[:q.width]
        return clamped.as_signed() if q.signed else clamped
    return np.clip(np.asarray(x, dtype=np.int64), q.min, q.max)


def select_constant(cond, constant, x, width):
    """``constant`` where the 1-bit ``cond``, else ``x``, ``width`` bits: AND/OR terms
    (Amaranth), not a multiplexer to a constant, which synthesis turns into a synchronous
    set/reset routed to every bit's LSR pin; ``numpy.where`` on int arrays."""
    if isinstance(x, (Value, ValueCastable)):
        x, cond = Value.cast(x), Value.cast(cond)
        keep = (x & (~cond).replicate(width)) | (Const(constant, width) & cond.replicate(width))
        return keep[:width]
    return np.where(cond, constant, x)
