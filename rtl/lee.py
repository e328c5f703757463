"""Lee et al. 2003 in hardware: the vector rotation of Fig. 7 and the illumination of Fig. 8,
errata 1-6 and 8 repaired (docs/architecture.md, Errata of Lee et al.): :class:`LeeRotation` and
:class:`LeeIllumination`, what ``rotation.VectorRotation`` and ``illumination.Illumination``
build when ``cfg.method == "lee"`` (rtl/methods.py). Bit-exact with
``sim/golden/fixed/lee.py``, which calls the small helpers below on int64 arrays where the
RTL calls them on Amaranth values, so both do the same arithmetic.

Mapping to the paper (Sec. 4 and Table 1), per vector A in {L, H}:

=====================  ==================================================================
paper element          hardware here
=====================  ==================================================================
sin & cos LUT          ``{a}_sincos_rom``: one quarter-wave ROM, 4 read ports (sin X, sin Y,
                       cos X, cos Y), sign/mirroring in logic (:func:`sine_value`)
Sin^-1 table (eq. 7)   ``{a}_asin_rom``: asin of |s|, tables.lee_asin_table
1/sin table (eq. 9)    ``{a}_inv_sin_rom``: quarter-wave 1/|sin Z|, saturating (erratum 8)
1/cos table (eq. 27)   ``{a}_inv_cos_rom``: the same contents read at Z + 90 deg
Tan^-1 table (eq. 9)   ``{a}_atan_rom``: atan of the ratio at a floating-point address
T_prop (eq. 26)        ``{a}_prop_rom``: theta_prop of |y_k|, tables.lee_prop_table
3 multipliers          |y2| x 1/|sin Z|, |y2| x 1/|cos Z|, (90 - |Z|) x theta_prop
8 adders               D, X, Y (eq. 6); sin X + sin Y, cos Y - cos X; Z = th_x - th_N;
                       90 - |Z|; |Z| + (90 - |Z|) theta_prop (eq. 19)
=====================  ==================================================================

That is Sec. 4.1's "six tables, three multipliers, and eight adders" per vector and Table 1's
12 tables, 6 multipliers, 16 adders for L and H. The errata need logic the paper does not
count: |s2|, the asin sign, 180 - th_x (erratum 6), |y2|, |Z| (erratum 5), the atan2
quadrant 180 -/+ atan (erratum 3), the clamp of y_k (erratum 4) and the address encoders.
Illumination per vector: three cosine tables (``{a}_cos_plus_rom``, ``{a}_cos_minus_rom``,
``{a}_cos_phi_rom``), six adders (th_A' + th_N', th_A' - th_N', ph_A' - ph_N', the two
brackets, the sum) and one multiplier: Table 1's 6 cosine tables and 2 multipliers; adders
12 here against the paper's 11 (Table 1) or 13 (Sec. 4.2, erratum 9). The diffuse and
specular tables of Fig. 8 are the shared back end of rtl/shade.py (diffuse there is a
constant multiply by 255, specular the cos^n block-RAM table).

Timing: both units are pipelined at 1 pixel per clock with registers only (the arithmetic
and the tables are the golden model's): every table read is registered before and after
the block RAM (:func:`rom_read`, :func:`sine_value`, sincos.sine_read), every product is a
registered DSP product, and long carry and mux chains are cut by the ``stage`` hooks of the
shared helpers (identity in the golden model). The tables wider or deeper than one DP16KD,
the sin & cos ROM with four reads and every product whose operands are wider than a DSP input
(the two by a 1/sin, 1/cos word always; eq. 19's and eq. 24's when the widths outgrow 18
bits) have ECP5 forms of their own here (:class:`BlockROM`; ``pipe.WideProduct``, whose limbs'
sum is registered) with the same generic form, so gen/flow/resources.py counts them as
before. Each unit's ``latency`` is the sum of its stages (the class docstrings list them; a
product's stages follow the widths, ``pipe.product_latency``); the tables' addresses depend on
the previous table's output within the pixel, which makes the setup deep, not slow.
"""

import numpy as np
from amaranth.hdl import Module, Mux, Signal, Value, ValueCastable, signed, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.exact import vectors
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.layouts import pixel_layout, polar_layout
from bumprtl.rtl.pipe import (
    ROM_LATENCY,
    WIDE_PRODUCT_LATENCY,
    PipeUnit,
    RegisteredROM,
    product_latency,
)
from bumprtl.rtl.shade import IlluminationDatapath
from bumprtl.rtl.sincos import REGISTERED_SINE_LATENCY, sine_read
from bumprtl.rtl.tables import (
    lee_asin_index_bits,
    lee_asin_table,
    lee_atan_mantissa_bits,
    lee_atan_ratio_bits,
    lee_atan_table,
    lee_prop_index_bits,
    lee_prop_table,
    lee_reciprocal_bits,
    lee_reciprocal_table,
    quarter_sine,
)
from bumprtl.rtl.targets import form

__all__ = ["LeeRotation", "LeeIllumination", "rotated_layout", "BlockROM", "block_rom", "rom_read",
           "ROM_STAGES", "SINE_STAGES", "sine_rom", "sine_value", "prop_operands", "dot_operands",
           "below_horizon", "quarter_address", "ratio_index", "asin_address", "prop_address",
           "phi_quadrant",
           "magnitude", "prop_term", "theta_from_prop"]


# --- Arithmetic shared with sim/golden/fixed/lee.py (Amaranth values or int64 arrays) -------

def _select(cond, a, b):
    if isinstance(cond, (Value, ValueCastable)):
        return Mux(cond, a, b)
    return np.where(cond, a, b)


def _same(value, name):
    """The golden model's stage: none (the RTL passes a registering one, Pipe.register)."""
    return value


def _times(a, b):
    return a * b


def _wrap(x, cfg: Config):
    """A binary angle: modulo the full circle."""
    return x[:cfg.angle_bits] if isinstance(x, (Value, ValueCastable)) else x & (cfg.full_circle - 1)


def below_horizon(theta, cfg: Config):
    """cos th < 0 (erratum 6), i.e. th in (90, 270) deg: codes 2**k + 1 .. 3 * 2**k - 1."""
    return _wrap(theta - ((1 << cfg.k) + 1), cfg) < (1 << (cfg.k + 1)) - 1


def quarter_address(angle, cfg: Config):
    """Quarter-wave ROM address of |sin angle|: the index mirrored in quadrants 1 and 3."""
    a = _wrap(angle, cfg)
    index = a & ((1 << cfg.k) - 1)
    return _select((a >> cfg.k) & 1, (1 << cfg.k) - index, index)


def ratio_index(p, cfg: Config, stage=_same):
    """Floating-point address of the atan ROM for a ratio ``p`` < 2**W (k fractional bits):
    ``p`` itself below 2**(M+1), else e * 2**M + (p >> e) where the leading one of ``p`` is
    bit M + e (a priority encoder: W - M - 1 comparators and muxes, the last true one wins).
    ``stage(value, name)`` cuts the mux chain in two halves (the RTL registers there)."""
    m = lee_atan_mantissa_bits(cfg)
    top = lee_atan_ratio_bits(cfg) - m
    half = max(1, top // 2)
    index = p
    for e in range(1, half):
        index = _select(p >= (1 << (m + e)), (e << m) + (p >> e), index)
    p, index = stage(p, "ratio_p"), stage(index, "ratio_index")
    for e in range(half, top):
        index = _select(p >= (1 << (m + e)), (e << m) + (p >> e), index)
    return index


def asin_address(s2, cfg: Config):
    """Eq. 7's asin ROM address: |s| = |s2| / 2 (s2 = sin X + sin Y, B fractional bits)
    rounded to lee_asin_index_bits fractional bits."""
    magnitude_s2 = abs(s2) if isinstance(s2, (Value, ValueCastable)) else np.abs(s2)
    return round_shift(magnitude_s2, cfg.frac_bits + 1 - lee_asin_index_bits(cfg))


def prop_address(product, cfg: Config, stage=_same):
    """T_prop address: |y_k| = |y2| (1/|cos Z|) / 2 rounded to p fractional bits and clamped
    to 1.0 (erratum 4). ``product`` = |y2| x 1/|cos Z| has 2B fractional bits. ``stage``
    between the rounding and the clamp."""
    p = lee_prop_index_bits(cfg)
    y_k = round_shift(product, 2 * cfg.frac_bits + 1 - p)
    y_k = stage(y_k, "y_k")
    return _select(y_k > (1 << p), 1 << p, y_k)


def magnitude(z, cfg: Config):
    """(Z < 0, |Z|) of a binary angle read as signed, [-180, 180) deg (erratum 5's |Z|)."""
    negative = (z >> (cfg.k + 1)) & 1
    return negative, _select(negative, cfg.full_circle - z, z)


def phi_quadrant(atan, z_negative, y_negative, cfg: Config, stage=_same):
    """atan2(y, sin Z) from atan(|y / sin Z|) (erratum 3): 180 - a when sin Z < 0, negated
    when y < 0. 0/0 reads atan(0) = 0 (the ratio is 0). ``stage`` between the two steps."""
    half_turn = _select(z_negative, (1 << (cfg.k + 1)) - atan, atan)
    half_turn, y_negative = stage(half_turn, "half_turn"), stage(y_negative, "y_negative")
    return _wrap(_select(y_negative, -half_turn, half_turn), cfg)


def prop_term(abs_z, prop, cfg: Config, mul=_times):
    """Eq. 19's (90 - |Z|) theta_prop, rounded to the angle grid (``mul``: the plain product
    for the golden model, a registered one, Pipe.multiply, in the RTL)."""
    return round_shift(mul((1 << cfg.k) - abs_z, prop), cfg.frac_bits)


def theta_from_prop(abs_z, prop, cfg: Config):
    """Eq. 19 with erratum 5: th_A' = |Z| + (90 - |Z|) theta_prop, rounded to the angle grid."""
    return abs_z + prop_term(abs_z, prop, cfg)


# --- The datapaths ---------------------------------------------------------------------------

def rotated_layout(cfg: Config):
    """Rotation output: L' and H' (H' only with specular) in the tangent frame of N, the bump
    normal N' passed through, all as polar binary angles, and the tag."""
    fields = {v: polar_layout(cfg) for v in vectors(cfg)}
    fields["b"] = polar_layout(cfg)
    fields["tag"] = pixel_layout(cfg)["tag"].shape
    return data.StructLayout(fields)


# --- The tables with more read ports than a block RAM ------------------------------------

class BlockROM(RegisteredROM):
    """A :class:`pipe.RegisteredROM`: the same read ports, ROM_LATENCY, and the same generic
    form (one Memory with every read port: one table in gen/flow/resources.py's counts),
    built by its target's ``block_rom`` (``rtl/targets.form``). Its ECP5 form
    (``ECP5Lowering.block_rom``, rtl/ecp5.py) also covers the tables RegisteredROM leaves
    to Yosys' block-RAM inference (more than two read ports, wider than 18 bits, deeper
    than 1024 words): each pair of read ports gets the table in DP16KD blocks with their
    output registers."""

    def elaborate(self, platform):
        m = Module()
        form(self.target).block_rom(m, self)
        return m


def block_rom(pipe, init, shape, name, ports):
    """A :class:`BlockROM` with ``ports`` read ports read every cycle, recorded in the pipe's
    ``memories`` as ``pipe.rom`` records its ROMs."""
    rom = pipe.memory(name, BlockROM(init, shape, ports, name, target=pipe.target))
    pipe.m.d.comb += rom.en.eq(pipe.en)
    return rom


def sine_rom(pipe, cfg: Config, name, ports):
    """The quarter-wave sine ROM (tables.quarter_sine) as a :class:`BlockROM` with ``ports``
    read ports, each read through sincos.sine_read."""
    return block_rom(pipe, quarter_sine(cfg).tolist(), unsigned(cfg.frac_bits + 1), name, ports)


def rom_read(pipe, name, table, width, address):
    """One read of a :class:`BlockROM` at ``address``: the address is registered first and the
    data once more after the ROM's own output register (the routes to the block RAM's
    address pins and from its data pins each get a cycle of their own), so the data comes
    ROM_STAGES pipe stages after ``address``."""
    rom = block_rom(pipe, np.asarray(table).tolist(), unsigned(width), name, ports=1)
    pipe.m.d.comb += rom.ports[0].addr.eq(pipe.register(address, f"{name}_address"))
    return pipe.register(rom.ports[0].data, f"{name}_data")


# rom_read: the address register, the ROM read and its output register, the data register.
ROM_STAGES = 2 + ROM_LATENCY
# sine_value: sincos.sine_read, whose data register before the sign is
# rom_read's.
SINE_STAGES = REGISTERED_SINE_LATENCY


def sine_value(m, pipe, port, angle, cfg: Config, name):
    """``sin(angle)`` through ``port`` of a :func:`sine_rom`, SINE_STAGES pipe stages later:
    sincos.sine_read (angle, folded index, mirrored address, read, output register, the
    word registered once more before the sign's carry chain as :func:`rom_read` does, sign;
    bit-exact with tables.sin_lookup). ``cos(a)`` is ``sin(a + 2**k)``."""
    return sine_read(m, pipe, port, angle, cfg, name)


S, W = SINE_STAGES, WIDE_PRODUCT_LATENCY


def prop_operands(cfg: Config):
    """Shapes of eq. 19's product operands, 90 - |Z| (|Z| of :func:`magnitude`) and a T_prop
    word (B + 1 bits), as :class:`LeeRotation` builds them."""
    abs_z = magnitude(Signal(cfg.angle_bits), cfg)[1]
    return ((1 << cfg.k) - abs_z).shape(), unsigned(cfg.frac_bits + 1)


def dot_operands(cfg: Config):
    """Shapes of eq. 24's product operands, c- - c+ and c_phi (cosines: signed B + 2 bits),
    as :class:`LeeIllumination` builds them."""
    return signed(cfg.sincos_width + 1), signed(cfg.sincos_width)


class LeeRotation(PipeUnit):
    """VectorRotation datapath, lee method (Fig. 7 once per vector; see the module table),
    whatever ``cfg.method`` says; a ``wiring.Component``.

    Input ``pixel_layout(cfg)``; output :func:`rotated_layout`. Every table read is a
    :class:`BlockROM` (DP16KD blocks with their output registers on ECP5) behind an address
    register, every product registered (``pipe.multiply``; the two by a reciprocal, wider
    than a DSP input, ``Pipe.wide_multiply``, and eq. 19's as well when its operands,
    :func:`prop_operands`, outgrow a DSP input), and at most one carry chain or half a mux
    chain lies between two registers. Per vector, in pipe stages (S = SINE_STAGES,
    R = ROM_STAGES, W = WIDE_PRODUCT_LATENCY, P = ``pipe.product_latency`` of
    :func:`prop_operands`: PRODUCT_LATENCY up to angle_bits 15 and B = 16, else W):

    ======================  ======================================================
    stage                   what is registered
    ======================  ======================================================
    S                       sin X, sin Y, cos X, cos Y (:func:`sine_value`)
    S + 1                   s2 = sin X + sin Y, y2 = cos Y - cos X
    S + 2                   |s2| (its sign and |y2| alongside)
    S + 2 + R               asin (address: |s2| rounded, eq. 7)
    S + 3 + R, S + 4 + R    the signed asin, erratum 6's 180 - th_x
    S + 5 + R               Z = th_x - th_N
    S + 6 + R               |Z| and the sign of Z (erratum 5)
    S + 5 + 2R              1/|sin Z|, 1/|cos Z| (addresses: the mirrored quarter index)
    S + 5 + 2R + W          |y2| / |sin Z| and |y2| / |cos Z| (eqs 9, 27)
    S + 6 + 2R + W          half the atan address encoder; y_k rounded
    S + 6 + 3R + W          atan (the encoder's other half); T_prop (y_k clamped)
    S + 8 + 3R + W          ph' (180 -/+ atan, then its sign: erratum 3)
    S + 6 + 3R + W + P      (90 - |Z|) theta_prop (eq. 19)
    S + 7 + 3R + W + P      rounded
    S + 8 + 3R + W + P      th' = |Z| + that: the latency
    ======================  ======================================================

    1 pixel per clock. Each table's address depends on the previous table's output within
    the same pixel (asin -> Z -> 1/sin, 1/cos -> products -> atan, T_prop), so the chain of
    reads is sequential; every link of it has a register of its own.
    """

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        self.prop_latency = product_latency(*prop_operands(cfg))              # P
        self.latency = S + 8 + 3 * ROM_STAGES + W + self.prop_latency
        super().__init__(cfg, pixel_layout(cfg), rotated_layout(cfg), target, credit, fifo_depth)

    def build(self, m, pipe):
        px, o = self.i.payload, pipe.o.payload
        for v in vectors(self.cfg):
            phi, theta = self._rotate(m, pipe, v, px[v], px.n)
            m.d.comb += [o[v].phi.eq(phi), o[v].theta.eq(theta)]
        m.d.comb += [o.b.eq(pipe.delay(px.b, self.latency, "b")),
                     o.tag.eq(pipe.delay(px.tag, self.latency, "tag"))]

    def _rotate(self, m, pipe, v, a, n):
        cfg, k, b = self.cfg, self.cfg.k, self.cfg.frac_bits
        reg, delay, R, P = pipe.register, pipe.delay, ROM_STAGES, self.prop_latency
        mul = pipe.multiplier(*prop_operands(cfg))                      # P stages
        stage = lambda value, name: reg(value, f"{v}_{name}")
        d = a.phi - n.phi                                                  # adder 1
        x, y = a.theta + d, a.theta - d                                    # adders 2, 3 (eq. 6)
        sincos = sine_rom(pipe, cfg, f"{v}_sincos_rom", ports=4)
        sx, sy, cx, cy = (sine_value(m, pipe, port, angle, cfg, f"{v}_{nm}")
                          for port, (nm, angle) in zip(sincos.ports, (
                              ("sin_x", x), ("sin_y", y),
                              ("cos_x", x + (1 << k)), ("cos_y", y + (1 << k))), strict=False))  # S
        s2 = reg(sx + sy, f"{v}_s2")                                       # adder 4: 2 s (eq. 7)
        y2 = reg(cy - cx, f"{v}_y2")                                       # adder 5: 2 sin th sin D
        abs_s2 = reg(abs(s2), f"{v}_abs_s2")                               # S + 2
        asin = rom_read(pipe, f"{v}_asin_rom", lee_asin_table(cfg), k + 1,
                    asin_address(abs_s2, cfg))                             # S + 2 + R
        s_negative = delay(s2[-1], 1 + R, f"{v}_s_negative")
        below = delay(below_horizon(a.theta, cfg), S + 3 + R, f"{v}_below")
        theta_n = delay(n.theta, S + 4 + R, f"{v}_theta_n")
        theta_x = reg(Mux(s_negative, -asin, asin), f"{v}_theta_x")
        theta_x = reg(Mux(below, (1 << (k + 1)) - theta_x, theta_x), f"{v}_theta_x_e6")  # erratum 6
        z = reg(_wrap(theta_x - theta_n, cfg), f"{v}_z")                   # adder 6: Z, S + 5 + R
        inv, width = lee_reciprocal_table(cfg), lee_reciprocal_bits(cfg)
        inv_sin = rom_read(pipe, f"{v}_inv_sin_rom", inv, width, quarter_address(z, cfg))
        inv_cos = rom_read(pipe, f"{v}_inv_cos_rom", inv, width,
                       quarter_address(z + (1 << k), cfg))                 # S + 5 + 2R
        ay2 = delay(abs(y2), 4 + 2 * R, f"{v}_abs_y2")
        ratio = pipe.wide_multiply(ay2, inv_sin, f"{v}_ratio") >> (2 * b + 1 - k)
        product = pipe.wide_multiply(ay2, inv_cos, f"{v}_yk_product")    # S + 5 + 2R + W
        atan = rom_read(pipe, f"{v}_atan_rom", lee_atan_table(cfg), k + 1,
                    ratio_index(ratio, cfg, stage))
        prop = rom_read(pipe, f"{v}_prop_rom", lee_prop_table(cfg), b + 1,
                    prop_address(product, cfg, stage))                    # S + 6 + 3R + W
        z_negative, abs_z = (delay(reg(x, f"{v}_{nm}"), 2 * R + W, f"{v}_{nm}")
                             for x, nm in zip(magnitude(z, cfg), ("z_negative", "abs_z"), strict=False))
        y_negative = delay(y2[-1], 5 + 3 * R + W, f"{v}_y_negative")      # S + 6 + 3R + W
        phi = reg(phi_quadrant(atan, z_negative, y_negative, cfg, stage), f"{v}_phi")
        term = reg(prop_term(abs_z, prop, cfg, lambda x, w: mul(x, w, f"{v}_theta_prop")),
                   f"{v}_theta_term")                                      # S + 7 + 3R + W + P
        theta = reg(_wrap(delay(abs_z, P + 1, f"{v}_abs_z_sum") + term, cfg),  # theta_from_prop's sum
                    f"{v}_theta")
        return delay(phi, P, f"{v}_phi"), theta                           # S + 8 + 3R + W + P


class LeeIllumination(IlluminationDatapath):
    """Illumination datapath, lee method (Fig. 8), whatever ``cfg.method`` says: eq. 24 with erratum 2 per vector,
    N'.A' = ((c- + c+) 2**B + (c- - c+) c_phi) / 2**(B+1), one rounding, where
    c+- = cos(th_A' +- th_N') and c_phi = cos(ph_A' - ph_N'); then the shared back end.

    Input :func:`rotated_layout`; output ``shade_layout(cfg)``. Each cosine table is a
    one-port :func:`sine_rom` (one DP16KD with its output register on ECP5) read
    by sincos.sine_read (angle sum, folded index, address, read, output register, data register, its copy, sign:
    REGISTERED_SINE_LATENCY stages); then c- + c+ and c- - c+ (1), the registered product
    (``pipe.product_latency`` of :func:`dot_operands`: PRODUCT_LATENCY up to B = 15, else a
    ``pipe.WideProduct``, WIDE_PRODUCT_LATENCY, on every target), the sum and its rounding
    (1): ``dot_latency``, plus SHADE_LATENCY; 1 pixel per clock.
    """

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        self.product_latency = product_latency(*dot_operands(cfg))
        self.dot_latency = REGISTERED_SINE_LATENCY + self.product_latency + 2
        super().__init__(cfg, rotated_layout(cfg), target, credit, fifo_depth)

    def dots(self, m, pipe, payload):
        return {v: self._dot(m, pipe, v, payload[v], payload.b) for v in vectors(self.cfg)}

    def _dot(self, m, pipe, v, a, n):
        cfg = self.cfg
        angles = {"plus": a.theta + n.theta, "minus": a.theta - n.theta, "phi": a.phi - n.phi}
        c = {}
        for name, angle in angles.items():                                 # 3 cosine tables
            rom = sine_rom(pipe, cfg, f"{v}_cos_{name}_rom", ports=1)
            c[name] = sine_read(m, pipe, rom.ports[0], angle + (1 << cfg.k), cfg,
                                f"{v}_cos_{name}")
        first = pipe.register(c["minus"] + c["plus"], f"{v}_first")
        diff = pipe.register(c["minus"] - c["plus"], f"{v}_diff")
        mul = pipe.multiplier(*dot_operands(cfg))
        second = mul(diff, pipe.register(c["phi"], f"{v}_cos_phi"), f"{v}_second")
        first = pipe.delay(first, self.product_latency, f"{v}_first")
        return pipe.register(round_shift((first << cfg.frac_bits) + second, cfg.frac_bits + 1),
                             f"{v}_dot")
