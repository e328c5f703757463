"""Per-pixel geometry of a turning globe (docs/globe.md): a screen position in, the normal in
the pipeline's polar angles and the texel of a latitude-longitude map out.

The globe is a sphere of radius R pixels seen orthographically, centred on the screen, its
pole up the screen. A pixel at offset (x, y) from the centre, x to the right and **y up the
screen**, is inside iff ``x**2 + y**2 < R**2`` (the rim itself, ``r**2 == R**2``, is
outside); ``z = sqrt(R**2 - r**2)`` points toward the viewer. The normal is given in the
scenes' world frame (sim/scenes: x right, y away from the viewer, z up the screen), as the
software ``sphere`` geometry and the board's light table give theirs: ``N = (x, -z, y) / R``,
in polar form (rtl/layouts.polar_layout) ``theta = acos(y / R)`` (the colatitude) and ``phi =
atan2(-z, x) = lambda + 3/4 turn`` with ``lambda = atan2(x, z)`` the longitude seen from the
viewer. The map is W x H texels (W = 2H, or W = H as the software sphere's square maps):
``u = floor((lambda + rotation) / 2pi * W) mod W``, ``v = floor(theta / pi * H)`` clamped to
[0, H - 1] (v grows down the screen: row 0 is the north pole). The tangent frame the
pipeline rotates the bump vector from (T along increasing theta, B along increasing phi) is
then the map's (v, u) directions, as on the software sphere.

Method, one register stage per step, fixed latency, one pixel a clock:

* ``x**2``, ``y**2`` in registered products, their sum ``r2`` and ``R**2 - r2``;
* ``z`` by a non-restoring integer square root of ``R**2 - r2`` shifted left by ``2 F``, one
  root bit a stage (``floor(sqrt(.) * 2**F)``, exact);
* ``lambda`` by a CORDIC vectoring chain of ``iterations`` stages on (z, x) with ``F``
  fraction bits below a pixel, its angle sum in binary angles of ``angle_frac_bits`` bits
  from :func:`cordic_angles` (the gain is irrelevant to the angle) starting at the
  rotation; ``phi`` is that sum less the rotation plus 3/4 turn, one addition later;
* ``theta`` and ``v`` from two ROMs indexed by y (:func:`theta_table`, :func:`v_table`,
  float64 contents): they depend on y alone;
* with ``mip_levels`` L > 1, the mip ``level`` of the texel footprint: ``rho = max(du/dx,
  dv/dy)`` with ``du/dx = W / (2 pi z)`` and ``dv/dy = H / (pi s)``, ``s = sqrt(R**2 -
  y**2)``, and ``level`` = log2 rho rounded to the nearest level, clamped to [0, L - 1]
  (:func:`level_of`, OpenGL's nearest-mipmap rule). The x part counts the
  constants of :func:`level_thresholds` the root is at or below: the stage after the
  radicand ``d = R**2 - r**2`` compares d with their form on it
  (:func:`level_radicand_limits`), the next counts, and the count rides beside the root
  and the CORDIC chain; the y part
  (:func:`level_y_table`, float64 contents, only where it can raise the level: W = H)
  rides in spare bits of the v ROM's word; the larger of the two is taken at the output.
  The latency does not change.

Every output field but ``inside`` and ``tag`` is 0 outside the globe; on the column x = 0
the longitude is exactly 0 (``atan2(0, z)``), so ``phi`` is exactly 3/4 turn there and ``u``
the rotation's own texel. The bit-exact model is sim/golden/globe.py, which also derives the
error bound against float64.
"""

import math
from dataclasses import dataclass, field

import numpy as np
from amaranth.hdl import Cat, Const, Mux, Value, signed, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config, ConfigError, check_int, check_pow2
from bumprtl.rtl.layouts import polar_layout
from bumprtl.rtl.pipe import PRODUCT_LATENCY, ROM_LATENCY, PipeUnit

__all__ = ["GlobeConfig", "GlobeGeometry", "cordic_angles", "v_table", "theta_table",
           "level_thresholds", "level_radicand_limits", "level_y_table", "level_y_used",
           "level_of", "latitude_words",
           "globe_in_layout", "globe_out_layout", "RADIUS_RANGE", "MAP_WIDTH_RANGE",
           "FRAC_BITS_RANGE", "GUARD_BITS_RANGE", "COORD_BITS_MAX", "DATAPATH_BITS",
           "sqrt_stages", "cordic_stages", "fit_signed", "phi_offset"]

RADIUS_RANGE = (1, 2047)          # R in pixels: R**2 << 2F stays inside 62 bits (the model's int64)
MAP_WIDTH_RANGE = (4, 32768)      # W, a power of two; H = W / 2 or H = W
FRAC_BITS_RANGE = (4, 20)         # F: fraction bits of the roots and of the CORDIC datapath
# The signed width of the CORDIC datapath and of the root's remainders (I + F + 2) that the
# default F aims at: the carry chains of the unit are this long (the angle sums
# angle_frac_bits), and they bound its clock (docs/globe.md, On the ECP5).
DATAPATH_BITS = 20
GUARD_BITS_RANGE = (1, 8)         # internal angle bits beyond the wider output
COORD_BITS_MAX = 16               # signed width of the x, y offsets


@dataclass(frozen=True)
class GlobeConfig:
    """The globe unit's geometry and widths.

    Parameters
    ----------
    radius : int
        R in pixels, 1 to 2047.
    map_width, map_height : int
        The latitude-longitude map, powers of two with ``map_width == 2 * map_height`` (square
        texels) or ``map_width == map_height`` (the software sphere's square maps); W from 4
        to 32768.
    pipeline : Config
        The pipeline's Config: ``angle_bits`` (the width of n.phi, n.theta and the rotation)
        and ``tag_bits``.
    coord_bits : int
        Signed width of the x and y offsets: ``radius.bit_length() + 1`` to 16.
    frac_bits : None or int
        F, fraction bits (below a pixel) of the square roots and the CORDIC datapaths, 4 to
        20; None: ``DATAPATH_BITS - 2 - I`` (at least 4), which keeps the datapaths
        DATAPATH_BITS wide (:attr:`fraction_bits`).
    guard_bits : int
        Bits of the CORDIC angle sums beyond the wider of ``angle_bits`` and ``log2 W``, 1 to 8.
    iterations : None or int
        CORDIC stages, 2 to ``angle_frac_bits``; None: ``angle_frac_bits - 1`` (the last
        stage whose angle ``atan(2**-i)`` is at least half an internal step).
    mip_levels : int
        L, the levels of the map's mip chain the output ``level`` chooses among, 1 to
        ``log2(map_height) + 1``; 1 (the default): no ``level`` field.
    """

    radius: int = 224
    map_width: int = 2048
    map_height: int = 1024
    pipeline: Config = field(default_factory=Config)
    coord_bits: int = 12
    frac_bits: int | None = None
    guard_bits: int = 8
    iterations: int | None = None
    mip_levels: int = 1

    def __post_init__(self):
        check_int("radius", self.radius, *RADIUS_RANGE)
        for name in ("map_width", "map_height"):
            value = getattr(self, name)
            lo, hi = (MAP_WIDTH_RANGE if name == "map_width"
                      else (MAP_WIDTH_RANGE[0] // 2, MAP_WIDTH_RANGE[1]))
            check_int(name, value, lo, hi, "a power of two")
            check_pow2(name, value, lo, hi)
        if self.map_height not in (self.map_width // 2, self.map_width):
            raise ConfigError(f"map_height must be map_width / 2 = {self.map_width // 2} or "
                              f"map_width = {self.map_width} (a latitude-longitude map), got "
                              f"{self.map_height}", "map_height")
        if not isinstance(self.pipeline, Config):
            raise ConfigError(f"pipeline must be a Config, got {self.pipeline!r}", "pipeline")
        check_int("coord_bits", self.coord_bits, self.int_bits + 1, COORD_BITS_MAX,
                   f"signed offsets must hold +-(radius - 1) = +-{self.radius - 1}")
        if self.frac_bits is not None:
            check_int("frac_bits", self.frac_bits, *FRAC_BITS_RANGE)
        check_int("guard_bits", self.guard_bits, *GUARD_BITS_RANGE)
        if self.iterations is not None:
            check_int("iterations", self.iterations, 2, self.angle_frac_bits,
                       f"angle_frac_bits = {self.angle_frac_bits}")
        check_int("mip_levels", self.mip_levels, 1, self.v_bits + 1,
                  f"a map of height {self.map_height} has log2(map_height) + 1 = "
                  f"{self.v_bits + 1} levels")

    # Derived facts.
    @property
    def int_bits(self):
        """I: bits of the integer part of every magnitude (x, y, r, z < 2**I)."""
        return self.radius.bit_length()

    @property
    def u_bits(self):
        return self.map_width.bit_length() - 1

    @property
    def v_bits(self):
        return self.map_height.bit_length() - 1

    @property
    def level_bits(self):
        """Width of the output ``level``: ``(mip_levels - 1).bit_length()`` (0: no field)."""
        return (self.mip_levels - 1).bit_length()

    @property
    def angle_bits(self):
        return self.pipeline.angle_bits

    @property
    def angle_frac_bits(self):
        """P: bits of the CORDIC angle sums (full circle = 2**P)."""
        return max(self.angle_bits, self.u_bits) + self.guard_bits

    @property
    def cordic_iterations(self):
        return self.angle_frac_bits - 1 if self.iterations is None else self.iterations

    @property
    def fraction_bits(self):
        """F: ``frac_bits``, or by default ``DATAPATH_BITS - 2 - I`` within FRAC_BITS_RANGE."""
        if self.frac_bits is not None:
            return self.frac_bits
        return min(max(DATAPATH_BITS - 2 - self.int_bits, FRAC_BITS_RANGE[0]), FRAC_BITS_RANGE[1])

    @property
    def root_bits(self):
        """Bits of the square root ``floor(sqrt(s) * 2**F)``, s < 2**(2I): I + F, one a stage."""
        return self.int_bits + self.fraction_bits

    @property
    def datapath_bits(self):
        """Signed width of a CORDIC's X and Y: I + F + 2 (a sign, and the gain < 2)."""
        return self.int_bits + self.fraction_bits + 2

    @property
    def cordic_latency(self):
        """Stages of a CORDIC chain (:func:`cordic_stages`): one an iteration, and one more
        for the angle sum, which takes each turn a stage after the turn itself."""
        return self.cordic_iterations + 1

    @property
    def latency(self):
        """Stages from ``i`` to ``o`` (no credit edge): the input register, the squares
        (PRODUCT_LATENCY) and their fabric copies, r2, R**2 - r2, the root, the CORDIC
        chain, phi's addition, the output register."""
        return 1 + PRODUCT_LATENCY + 3 + self.root_bits + self.cordic_latency + 2


def cordic_angles(gcfg: GlobeConfig):
    """The CORDIC's angles ``atan(2**-i)`` for i = 0 .. iterations - 1, in binary angles of
    ``angle_frac_bits`` bits (full circle = 2**P), rounded to nearest: the constants of the
    RTL's chains and of the model's."""
    p = gcfg.angle_frac_bits
    return [int(round(math.atan(2.0 ** -i) * (1 << p) / (2 * math.pi)))
            for i in range(gcfg.cordic_iterations)]


def _rows(gcfg: GlobeConfig, word):
    """``2**(I + 1)`` words indexed by y modulo ``2**(I + 1)`` (two's complement): ``word(y)``
    for ``|y| < R``, 0 for the rest (no pixel inside has them)."""
    r, bits = gcfg.radius, gcfg.int_bits + 1
    ys = [a - (1 << bits) if a >> (bits - 1) else a for a in range(1 << bits)]
    return [word(y) if abs(y) < r else 0 for y in ys]


def v_table(gcfg: GlobeConfig):
    """The v ROM (:func:`_rows`): ``floor(acos(y / R) / pi * H)``
    clamped to [0, H - 1] (float64)."""
    r, h = gcfg.radius, gcfg.map_height
    return _rows(gcfg, lambda y: min(max(math.floor(math.acos(y / r) / math.pi * h), 0), h - 1))


def theta_table(gcfg: GlobeConfig):
    """The theta ROM (:func:`_rows`): ``acos(y / R)`` (float64) in codes
    of ``angle_bits``, rounded to nearest, ties to even (as the pipeline's input codes are
    made, sim/golden/fixed/common.angle_codes)."""
    r, full = gcfg.radius, 1 << gcfg.angle_bits
    return _rows(gcfg, lambda y: round(math.acos(y / r) * (full / (2 * math.pi))) & (full - 1))


def level_step(k):
    """The rho at which level k starts: 2**(k - 1/2) (log2 rho rounded to the nearest)."""
    return 2.0 ** (k - 0.5)


def level_of(rho, levels):
    """The mip level of a footprint of ``rho`` texels a pixel: log2 rho rounded to the
    nearest level, clamped to [0, levels - 1] (OpenGL's nearest-mipmap rule: level 0 up to
    lambda = log2 rho = 1/2, then ceil(lambda + 1/2) - 1), as the count of k in 1 ..
    levels - 1 with ``rho >= 2**(k - 1/2)`` (no logarithm rounded; 2**(k - 1/2) is never
    a float64's exact value of rho in practice, so >= and > agree). Floats and numpy
    arrays alike (an int64 array back)."""
    if isinstance(rho, np.ndarray):
        return sum(((rho >= level_step(k)).astype(np.int64) for k in range(1, levels)),
                   np.zeros(rho.shape, np.int64))
    return sum(1 for k in range(1, levels) if rho >= level_step(k))


def level_thresholds(gcfg: GlobeConfig):
    """The x part's constants, for k = 1 .. mip_levels - 1: ``t_k = floor(T_k 2**F)``
    (float64) with ``T_k = W / (2 pi 2**(k - 1/2))``, the z at or below which ``W / (2 pi
    z) >= 2**(k - 1/2)`` (:func:`level_of`'s rule); decreasing in k. The x part's level is the count of k with ``z_fix <= t_k``
    (``z_fix = floor(z 2**F)``, the unit's root): the RTL's comparisons and the model's.
    That holds wherever ``z <= T_k``, and also where z is above T_k by less than ``2**-F``
    with the same root, where the level is one coarser than the exact one."""
    w, f = gcfg.map_width, gcfg.fraction_bits
    return [math.floor(w * 2.0 ** f / (2 * math.pi * level_step(k)))
            for k in range(1, gcfg.mip_levels)]


def level_radicand_limits(gcfg: GlobeConfig):
    """The RTL's form of :func:`level_thresholds`, on the root's radicand ``d = R**2 - r**2``
    rather than the root: ``c_k = ((t_k + 1)**2 - 1) >> 2F``, the largest d with
    ``floor(sqrt(d 2**(2F))) <= t_k`` (that is ``d 2**(2F) < (t_k + 1)**2``), so ``d <= c_k``
    exactly when ``z_fix <= t_k``."""
    shift = 2 * gcfg.fraction_bits
    return [((t + 1) ** 2 - 1) >> shift for t in level_thresholds(gcfg)]


def level_y_table(gcfg: GlobeConfig):
    """The y part (:func:`_rows`): ``level_of(H / (pi s), mip_levels)`` with ``s = sqrt(R**2 -
    y**2)`` (float64), the level of dv/dy alone."""
    r, h, n = gcfg.radius, gcfg.map_height, gcfg.mip_levels
    return _rows(gcfg, lambda y: level_of(h / (math.pi * math.sqrt(r * r - y * y)), n))


def level_y_used(gcfg: GlobeConfig):
    """Whether the unit reads the y part at all: only a square map's can raise the level
    (for W = 2H, ``dv/dy = W / (2 pi s) <= W / (2 pi z) = du/dx`` as z <= s), and only
    where its table is not all 0."""
    return (gcfg.mip_levels > 1 and gcfg.map_width == gcfg.map_height
            and any(level_y_table(gcfg)))


def latitude_words(gcfg: GlobeConfig):
    """The v ROM's words: :func:`v_table`, with :func:`level_y_table` above its ``v_bits``
    when :func:`level_y_used` (``v_bits + level_bits`` wide then, else ``v_bits``)."""
    if not level_y_used(gcfg):
        return v_table(gcfg)
    return [v | ly << gcfg.v_bits for v, ly in zip(v_table(gcfg), level_y_table(gcfg),
                                                   strict=True)]


def phi_offset(gcfg: GlobeConfig, rotation):
    """What phi's addition adds to the longitude sum (which starts at the rotation): 3/4 turn
    less the rotation (a binary angle of ``angle_bits``), plus half a code step so that the
    codes (the sum's top ``angle_bits`` bits) round to nearest; modulo 2**P. Amaranth values
    and ints alike."""
    P, A = gcfg.angle_frac_bits, gcfg.angle_bits
    base = (3 << (P - 2)) + (1 << (P - A - 1))
    if isinstance(rotation, Value):
        return (Const(base, P) - Cat(Const(0, P - A), rotation))[:P]
    return (base - (rotation << (P - A))) & ((1 << P) - 1)


def globe_in_layout(gcfg: GlobeConfig):
    """``x``, ``y``: signed offsets from the centre (y up); ``rotation``: the globe's turn,
    a binary angle of ``angle_bits``; ``tag``: carried through."""
    return data.StructLayout({"x": signed(gcfg.coord_bits), "y": signed(gcfg.coord_bits),
                              "rotation": unsigned(gcfg.angle_bits),
                              "tag": unsigned(gcfg.pipeline.tag_bits)})


def globe_out_layout(gcfg: GlobeConfig):
    """``inside``; ``n``: the normal's phi and theta codes (rtl/layouts.polar_layout); ``u``,
    ``v``: the texel; ``level``: the mip level (``level_bits``, only when ``mip_levels > 1``);
    ``tag``."""
    fields = {"inside": unsigned(1), "n": polar_layout(gcfg.pipeline),
              "u": unsigned(gcfg.u_bits), "v": unsigned(gcfg.v_bits)}
    if gcfg.mip_levels > 1:
        fields["level"] = unsigned(gcfg.level_bits)
    fields["tag"] = unsigned(gcfg.pipeline.tag_bits)
    return data.StructLayout(fields)


def sqrt_stages(pipe, value, value_bits, frac_bits, name):
    """``floor(sqrt(value << 2 frac_bits))`` of the unsigned ``value`` (its low ``value_bits``
    bits, even) by a non-restoring square root, one root bit a stage: ``value_bits / 2 +
    frac_bits`` stages, one carry chain each (the remainder's sign, registered, picks add or
    subtract). The radicand's bits enter two a stage; past ``value`` they are the zeros of
    the shift. A stage's root bit is the complement of its remainder's sign, read from the
    remainder's register (the sum's top bit goes to that one flip-flop, no inverter in its
    cycle); the bits before it ride in registers of their own."""
    n = value_bits // 2 + frac_bits
    rest = value[:value_bits]
    rem = Const(0, signed(2))
    q = Const(0, 1)                                # the root so far: none before stage 0
    for j in range(n):
        # After stage j the remainder is D_j - q**2 >= 0 or D_j - (q | 1)**2 >= -(2 q + 1)
        # with q < 2**(j + 1), so |rem| < 2**(j + 2): j + 3 signed bits hold it (n + 2 at the
        # last stage); rem << 2 may wrap at that width, the sum it enters does not.
        width = j + 3
        i = n - 1 - j                              # the radicand's pair 2i + 1 .. 2i
        if i >= frac_bits:
            pair = rest[2 * (i - frac_bits):2 * (i - frac_bits) + 2]
        else:
            pair = Const(0, 2)
        negative = rem[-1]
        # rem < 0: (rem << 2 | pair) + (q << 2 | 3); else (rem << 2 | pair) - (q << 2 | 1),
        # the subtraction as the addition of ~(q << 2 | 1) + 1 at the remainder's width
        trial = Cat(Mux(negative, Const(3, 2), Const(1, 2)), q,
                    Const(0, width - 2 - len(q)))[:width]
        shifted = Cat(pair, rem)[:width].as_signed()
        new = (shifted + Mux(negative, trial, ~trial) + ~negative)[:width].as_signed()
        if j:
            older = pipe.register(q, f"{name}_q{j}")          # the root before this bit
        rem = pipe.register(new, f"{name}_rem{j}")
        q = Cat(~rem[-1], older) if j else ~rem[-1]
        if i > frac_bits:
            rest = pipe.register(rest[:2 * (i - frac_bits)], f"{name}_rest{j}")
    return q


def fit_signed(value, width):
    """``value`` (signed, or unsigned: zero-extended) as exactly ``width`` signed bits:
    sign-extended, or its low bits (callers only truncate bits every pixel inside leaves
    equal to the sign)."""
    if len(value) >= width:
        return value[:width].as_signed()
    top = value[-1] if value.shape().signed else Const(0, 1)
    return Cat(value, top.replicate(width - len(value))).as_signed()


def cordic_stages(pipe, x, y, acc, angles, width, name):
    """CORDIC vectoring: ``len(angles)`` stages turn (x, y) toward the +x axis by
    ``atan(2**-i)`` each, the way the sign of y says, and the angle sum adds each turn to
    ``acc`` (an unsigned binary angle, wrapping) a stage later: ``len(angles) + 1`` stages
    give ``acc + atan2(y, x)`` to within the bound of sim/golden/globe.error_bound_rad
    (``acc`` is taken beside ``x`` and ``y``). ``x``, ``y`` signed ``width`` bits; the
    shifts truncate (arithmetic shift right).

    The sum is ``acc + sum(s_i a_i)`` with s_i = +1 (y >= 0) or -1, kept as
    ``acc - sum(a_i) + sum(up_i 2 a_i)``: it starts at ``acc - sum(a_i)`` and each stage
    adds ``2 a_i`` or nothing, an operand whose bits are a registered copy ``up_i`` of the
    decision or 0, so the sum's carry chain takes the decision straight into its cells
    (no select ahead of it), and the sign of y drives the two chains of x and y and that
    copy only."""
    p = len(acc)
    mask = (1 << p) - 1
    acc = pipe.register((acc + ((-sum(angles)) & mask))[:p], f"{name}_sum_base")
    for i, a in enumerate(angles):
        down = y[-1]                                   # y < 0: turn up, subtract the angle
        xs, ys = x >> i, y >> i
        # y >= 0: x + (y >> i), y - (x >> i), acc + a; y < 0: the other way
        nx = (x + Mux(down, ~ys, ys) + down)[:width].as_signed()
        ny = (y + Mux(down, xs, ~xs) + ~down)[:width].as_signed()
        up = pipe.register(~down, f"{name}_up{i}")
        x = pipe.register(nx, f"{name}_x{i}")
        y = pipe.register(ny, f"{name}_y{i}")
        twice = (2 * a) & mask
        operand = Cat(*[up if twice >> b & 1 else Const(0, 1) for b in range(p)])
        acc = pipe.register((acc + operand)[:p], f"{name}_sum{i}")
    return acc


def _count(bits):
    """The number of set bits among ``bits`` (1-bit values), summed in pairs."""
    values = [Value.cast(b) for b in bits]
    while len(values) > 1:
        pairs = [values[n] + values[n + 1] for n in range(0, len(values) - 1, 2)]
        values = pairs + values[len(values) - len(values) % 2:]
    return values[0]


class GlobeGeometry(PipeUnit):
    """The globe's per-pixel geometry (module docstring).

    Parameters
    ----------
    gcfg : GlobeConfig
    target : None or pipe.ECP5
        Elaboration target of the squares and the v ROM (None: the generic form).
    credit, fifo_depth
        As every :class:`pipe.PipeUnit`.

    Members
    -------
    i : In(stream.Signature(globe_in_layout(gcfg)))
        x, y (signed, y up), rotation (a binary angle), tag.
    o : Out(stream.Signature(globe_out_layout(gcfg)))
        inside, n.phi, n.theta (codes of ``angle_bits``), u, v, level (when
        ``mip_levels > 1``), tag; bit-exact with sim/golden/globe.globe_fixed.

    Latency ``gcfg.latency`` (:attr:`GlobeConfig.latency`); one pixel per clock.
    """

    def __init__(self, gcfg: GlobeConfig, target=None, credit=True, fifo_depth=None):
        self.gcfg = gcfg
        self.latency = gcfg.latency
        super().__init__(gcfg.pipeline, globe_in_layout(gcfg), globe_out_layout(gcfg),
                         target, credit, fifo_depth)

    def build(self, m, pipe):
        g = self.gcfg
        I, F, P, A = g.int_bits, g.fraction_bits, g.angle_frac_bits, g.angle_bits
        w, chain = g.datapath_bits, g.cordic_latency
        p = self.i.payload
        # stage 1: the inputs
        x = pipe.register(p.x, "x")
        y = pipe.register(p.y, "y")
        rot = pipe.register(p.rotation, "rotation")
        # stages 2 .. 1 + PRODUCT_LATENCY: the squares; a fabric copy of each (the route
        # from a DSP's output ends in a flip-flop); then r2, then R**2 - r2
        xx = pipe.register(pipe.multiply(x, x, "xx"), "xx_copy")
        yy = pipe.register(pipe.multiply(y, y, "yy"), "yy_copy")
        r2 = pipe.register((xx + yy).as_unsigned()[:2 * g.coord_bits], "r2")
        rr = g.radius * g.radius
        inside = pipe.register(r2 < rr, "inside")
        d = pipe.register((Const(rr, 2 * I) - r2)[:2 * I], "d")      # outside: masked below
        start = 1 + PRODUCT_LATENCY + 3                                 # the root's input stage
        z_root = sqrt_stages(pipe, d, 2 * I, F, "z")
        roots = start + g.root_bits
        done = roots + chain                                             # the sum's stage

        # lambda = atan2(x, z) + rotation: stages roots + 1 .. done
        x_root = pipe.delay(x[:I + 1].as_signed(), roots - 1, "x_root")   # |x| < R inside
        lam0 = Cat(Const(0, P - A), pipe.delay(rot, roots - 1, "rotation_root"))
        lam = cordic_stages(pipe, fit_signed(z_root, w),
                            fit_signed(Cat(Const(0, F), x_root).as_signed(), w),
                            lam0, cordic_angles(g), w, "lambda")
        # phi = lambda - rotation + 3/4 turn (+ half a code step): stage done + 1
        offset = pipe.register(phi_offset(g, pipe.delay(rot, done - 2, "rotation_offset")),
                               "phi_offset")
        phi = pipe.register((lam + offset)[:P], "phi_sum")
        lam = pipe.register(lam[P - g.u_bits:], "lambda_u")
        # x == 0 as ~|x (an equality with 0 would be Verilog's ! of a vector, which lint refuses)
        x_zero = pipe.delay(pipe.register(~x.any(), "x_zero"), done - 1, "x_zero")
        inside = pipe.delay(inside, done + 1 - start, "inside")
        # u of x = 0 is the rotation's top log2 W bits (below them, zeros): only those ride on
        low = max(A - g.u_bits, 0)
        rot_done = pipe.delay(rot[low:], done, "rotation_done")
        # the latitude ROMs (v and theta by y; two, each in a block RAM mode with its output
        # register): their address registered at done - ROM_LATENCY, their words at done + 1
        at = done - ROM_LATENCY
        address = pipe.register(pipe.delay(y[:I + 1], at - 2, "y_rom"), "rom_address")
        level_y = level_y_used(g)                    # the y part's level above v in its word
        v_rom = pipe.rom(latitude_words(g), unsigned(g.v_bits + g.level_bits * level_y),
                         "v_rom", ports=1)
        theta_rom = pipe.rom(theta_table(g), unsigned(A), "theta_rom", ports=1)
        m.d.comb += [v_rom.ports[0].addr.eq(address), theta_rom.ports[0].addr.eq(address)]
        v_word = pipe.register(v_rom.ports[0].data, "v_word")
        theta_word = pipe.register(theta_rom.ports[0].data, "theta_word")
        # the output stage (done + 2): codes, texel, 0 outside
        u_rot = (Cat(Const(0, P - A + low), rot_done) >> (P - g.u_bits))[:g.u_bits]
        o, zero = pipe.o.payload, Const(0)
        m.d.comb += [
            o.inside.eq(pipe.register(inside, "inside_out")),
            o.n.phi.eq(pipe.register(Mux(inside, Mux(x_zero, Const(3 << (A - 2), A), phi[P - A:]),
                                         zero), "phi_out")),
            o.n.theta.eq(pipe.register(Mux(inside, theta_word, zero), "theta_out")),
            o.u.eq(pipe.register(Mux(inside, Mux(x_zero, u_rot, lam), zero), "u_out")),
            o.v.eq(pipe.register(Mux(inside, v_word[:g.v_bits], zero), "v_out")),
            o.tag.eq(pipe.delay(p.tag, self.latency, "tag")),
        ]
        if g.mip_levels > 1:
            # the x part: z_fix <= t_k as the radicand against its limit (the root's bits,
            # which drive the CORDIC's first stage, take no more load), the stage after d (one
            # carry chain each), their count the next, then carried beside the root and the
            # CORDIC chain to the output stage
            below = [pipe.register(d <= c, f"level_below{k}")
                     for k, c in enumerate(level_radicand_limits(g), 1)]
            level = pipe.register(_count(below)[:g.level_bits], "level_x")
            level = pipe.delay(level, g.root_bits + chain - 1, "level_x")
            if level_y:
                word = v_word[g.v_bits:]
                level = Mux(word > level, word, level)
            m.d.comb += o.level.eq(pipe.register(Mux(inside, level, zero), "level_out"))
