"""The single source of truth for every width, table size and method choice.

The RTL, the golden models, the testbenches, the emitter and the reports all read a
:class:`Config`; nothing else holds a width. Number formats (docs/architecture.md, Number formats):

* angles are unsigned binary angles of ``angle_bits = k + 2`` bits: the full circle is
  ``2**angle_bits`` steps, so sums wrap for free;
* sin/cos values are signed with ``frac_bits = B`` fractional bits (``1.0 == 2**B``),
  ``B + 2`` bits wide so that both +1.0 and -1.0 are representable;
* outputs are ``out_bits``-bit unsigned intensities after clamping.
"""

from dataclasses import asdict, dataclass, fields

from bumprtl.rtl.errors import BumpError, ConfigError
from bumprtl.rtl.methods import METHODS

__all__ = ["Config", "ConfigError", "BumpError", "ANGLE_BITS_RANGE", "FRAC_BITS_MAX",
           "TWO_LIGHT_WIDTHS", "frac_bits_floor", "check_int",
           "check_pow2", "is_pow2"]

ANGLE_BITS_RANGE = (4, 16)      # angle_bits, inclusive
FRAC_BITS_MAX = 24              # frac_bits <= 24 keeps every product inside 64 bits
# (angle_bits, frac_bits) of the built-in two-light scenes: with two lights their specular
# terms add, and the narrowest widths whose proven bound is 1 LSB on every channel at n = 16
# are these (one light: Config's defaults). tests/sim/golden/fixed/test_channels.py checks
# both against sim/golden/fixed/exact.faithful_widths.
TWO_LIGHT_WIDTHS = (15, 16)


def frac_bits_floor(angle_bits):
    """The fewest fractional bits a Config with ``angle_bits`` accepts: B >= k - 1 (and 4)."""
    return max(4, angle_bits - 3)


def _check_int(name, value, lo, hi, why=""):
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConfigError(f"{name} must be an integer in [{lo}, {hi}], got {value!r}", name)
    if not lo <= value <= hi:
        extra = f" ({why})" if why else ""
        raise ConfigError(f"{name} = {value} is out of range: allowed [{lo}, {hi}]{extra}", name)


# the same check for the configurations of units outside this module (rtl/globe.GlobeConfig),
# so every out-of-range parameter is refused in the same words
check_int = _check_int


def is_pow2(x):
    """``x`` is an integer (never a bool) and a power of two >= 1."""
    return isinstance(x, int) and not isinstance(x, bool) and x >= 1 and not x & (x - 1)


def check_pow2(name, value, lo, hi):
    """ConfigError naming ``name`` unless ``value`` is a power of two in [lo, hi]."""
    if not is_pow2(value) or not lo <= value <= hi:
        raise ConfigError(f"{name} must be a power of two in [{lo}, {hi}], got {value!r}", name)


def _check_unit(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
        raise ConfigError(f"{name} must be a number in [0, 1], got {value!r}", name)


@dataclass(frozen=True)
class Config:
    """Widths, table sizes and method of one generated datapath.

    Parameters
    ----------
    angle_bits : int
        Binary-angle width ``k + 2`` (full circle = ``2**angle_bits``); 4 to 16. The default,
        14, with ``frac_bits`` 15, are the narrowest widths whose proven bound
        (``predicted_error_bound_lsb``, docs/fixed_point.md) is 1 LSB against float64 on every
        output channel (diffuse, specular, colour, texture blend) of one light at n = 16;
        13-bit angles cannot prove it (their rounding alone can move the specular term by
        1.08 LSB, and measured 2 LSB end to end). Two lights need :data:`TWO_LIGHT_WIDTHS`.
    frac_bits : int
        Fractional bits ``B`` of sin/cos and dot products; ``k - 1`` to 24. The default, 15,
        is the fewest that prove 1 LSB on every channel with 14-bit angles.
    method : str
        A name of the method registry (rtl/methods.py, ``METHODS``): ``"exact"``
        (the exact angular method of docs/architecture.md), ``"lee"`` (Lee et al., errata
        fixed) or a Table 1 baseline, ``"peercy"``, ``"ernst"``, ``"kim"`` (cost comparison
        only, not in scenes).
    tag_bits : int
        Width of the side-band tag that rides along with every pixel; 0 to 32.
    out_bits : int
        Width of the clamped output intensities; always 8 (8-bit outputs).
    spec_exponent : int
        Phong exponent ``n`` of the specular table ``cos^n``; 1 to 1024.
    spec_index_bits : int
        Address bits of the specular table (at most ``frac_bits`` are used); 4 to 16. 10 (the
        default) fits one ECP5 block RAM; more bits lower the specular error at the cost of more
        block RAM and a slower table read (docs/fixed_point.md has the measured comparison,
        ``bumprtl bench accuracy --spec-index-bits N``).
    ka, kd, ks : float
        Ambient, diffuse and specular coefficients of eq. (2), each in [0, 1].
    lights : int
        Number of lights sharing one rotated normal; 1 to 8.
    specular : bool
        Whether the H path and the specular table are built.
    palette_size : int
        Number of quantized normals ``sN`` of the palette method (Tarini et al.); 16 to 16384.
    color_bits : int
        Bits per colour channel of the palette colour table; 8.
    palette_blend : bool
        Whether PaletteLUT has the eq. 2 blend stage (Tarini Sec. 7.2) with a base-colour input.
    """

    angle_bits: int = 14
    frac_bits: int = 15
    method: str = "exact"
    tag_bits: int = 16
    out_bits: int = 8
    spec_exponent: int = 16
    spec_index_bits: int = 10
    ka: float = 0.1
    kd: float = 0.7
    ks: float = 0.2
    lights: int = 1
    specular: bool = True
    palette_size: int = 256
    color_bits: int = 8
    palette_blend: bool = False

    def __post_init__(self):
        _check_int("angle_bits", self.angle_bits, *ANGLE_BITS_RANGE, "k = angle_bits - 2 must be >= 2")
        k = self.angle_bits - 2
        _check_int("frac_bits", self.frac_bits, frac_bits_floor(self.angle_bits), FRAC_BITS_MAX,
                   f"B >= k - 1 = {k - 1} so that sin of one angle step is at least "
                   f"half an LSB; B <= {FRAC_BITS_MAX} keeps every product inside 64 bits")
        if self.method not in METHODS:
            raise ConfigError(f"method must be one of {', '.join(METHODS)}, got {self.method!r}",
                              "method")
        _check_int("tag_bits", self.tag_bits, 0, 32)
        _check_int("out_bits", self.out_bits, 8, 8, "outputs are 8-bit intensities")
        _check_int("spec_exponent", self.spec_exponent, 1, 1024)
        _check_int("spec_index_bits", self.spec_index_bits, 4, 16)
        for name in ("ka", "kd", "ks"):
            _check_unit(name, getattr(self, name))
        _check_int("lights", self.lights, 1, 8)
        if not isinstance(self.specular, bool):
            raise ConfigError(f"specular must be true or false, got {self.specular!r}", "specular")
        _check_int("palette_size", self.palette_size, 16, 16384)
        _check_int("color_bits", self.color_bits, 8, 8)
        if not isinstance(self.palette_blend, bool):
            raise ConfigError(f"palette_blend must be true or false, got {self.palette_blend!r}",
                              "palette_blend")

    # Derived facts: read-only, never stored.
    @property
    def k(self):
        """Quarter-wave index bits: the ROM covers 0..90 degrees in ``2**k`` steps."""
        return self.angle_bits - 2

    @property
    def full_circle(self):
        return 1 << self.angle_bits

    @property
    def sincos_depth(self):
        """Quarter-wave ROM entries: ``2**k + 1`` (the +1 holds sin 90 deg = 1.0)."""
        return (1 << self.k) + 1

    @property
    def sincos_width(self):
        """Signed width of a sin/cos value: B fractional bits, one integer bit, sign."""
        return self.frac_bits + 2

    @property
    def one(self):
        """The integer that represents 1.0 in a value with ``frac_bits`` fractional bits."""
        return 1 << self.frac_bits

    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        unknown = set(changes) - {f.name for f in fields(self)}
        if unknown:
            raise ConfigError(f"unknown Config field(s): {', '.join(sorted(unknown))}",
                              sorted(unknown)[0])
        return Config(**{**asdict(self), **changes})

    def to_dict(self):
        return asdict(self)

