"""Kim, Lee and Park 2001 (Lee et al. ref. 9) as real RTL at the same Config widths: the
polar-coordinate baseline of Lee et al. Table 1, bit-exact with ``sim/golden/fixed/kim.py``
(which calls the helpers below on int64 arrays where the RTL calls them on Amaranth values).

Kim 2001 is known here only through the Lee paper: its setup does "transformation
computations in the polar coordinate system" with 31 multipliers, 6 LUTs and 18 adders, and
its illumination takes the inner products with angles, Lee eqs (3)/(4),
N'.A = cos th_A cos th_N' + sin th_A sin th_N' cos(ph_A - ph_N'), with 6 multipliers,
12 LUTs and 5 adders for L and H. What follows the paper and what is guessed:

* **Followed**: L and H are taken from polar to Cartesian, rotated by the reference-frame
  matrix of N, M = R_y(-th_N) R_z(-ph_N) (sim/golden/common.tangent_rotation; a matrix
  rebuilt per pixel, as Lee Sec. 4.3 says of ref. 9), and brought back to polar angles
  (ph_A', th_A'); the illumination is eqs (3)/(4) per vector and the diffuse/specular
  tables of eq. (2) (the shared back end, rtl/shade.py, as for every method).
* **Guessed** (the paper gives no datapath): how the polar angles are recovered without a
  divider or square root, since Table 1 lists neither for Kim. ph_A' = atan2(y', x') by
  octant: the smaller of |x'|, |y'| over the larger through a reciprocal ROM on the
  normalized larger one (a leading-one shift, no divider) and Lee's floating-point-address
  atan ROM; then rho = sin th_A' = p cos a0 + q sin a0 (the projection on the found
  azimuth, no square root) and th_A' = asin(rho) when rho <= |z'|, 90 deg - asin(|z'|)
  otherwise, mirrored to 180 deg - th when z' < 0 (Lee's asin ROM, always read where it
  is not steep). A plain acos(z') would lose half the bits near the poles (an error of
  sqrt(2 u) rad), so it is not used.

Poles (th_A' = 0 or 180 deg, where ph_A' is undefined): x' = y' = 0 gives p = q = 0, ratio 0
and ph_A' = 0 exactly; any tiny (x', y') gives some definite azimuth, and the product
sin th_A' sin th_N' cos(ph_A' - ph_N') of eq. (3) makes its value irrelevant there.

Setup (:class:`KimRotation`, Table 1's "illumination environment setup"), per pixel:

======================  =====================================================================
element                 hardware here
======================  =====================================================================
sin & cos LUT of N      ``n_sincos_rom``: quarter-wave ROM, 4 reads (sin/cos ph_N, th_N)
matrix M (4 mult)       ct cp, ct sp, st cp, st sp; the other entries are -st, -sp, cp, 0, ct
per vector A in {L, H}:
sin & cos LUT           ``{a}_sincos_rom``: 6 reads (sin/cos th_A, ph_A; sin/cos a0)
polar -> Cartesian      x = sin th cos ph, y = sin th sin ph (2 mult), z = cos th
M A (8 mult, 5 add)     x' = m00 x + m01 y - st z, y' = cp y - sp x, z' = m20 x + m21 y + ct z
divide (1 mult)         ``{a}_recip_rom`` (tables.kim_reciprocal_table) x the smaller
atan (octant)           ``{a}_atan_rom`` (tables.lee_atan_table at lee.ratio_index)
rho (2 mult, 1 add)     p cos a0 + q sin a0
asin                    ``{a}_asin_rom`` (tables.lee_asin_table)
======================  =====================================================================

That is 4 + 2 x 13 = 30 multipliers (Table 1: 31), 1 + 2 x 4 = 9 tables (Table 1: 6; the
sin & cos ROM with several reads counts once, as in rtl/lee.py) and 2 x 6 = 12 signal
adders (Table 1: 18). The octant and quadrant logic (|x'|, |y'|, the swaps, 90 - a,
180 - a, negation), the leading-one normalizer and the clamps of x', y', z' to [-1, 1]
are comparators, constant adders and multiplexers the paper does not count. M could be
skipped altogether (R_z(-ph_N) is the angle difference ph_A - ph_N, the trick of Lee and
of rtl/exact.py); Kim's matrix is kept because Table 1 counts it.

Illumination per vector: ``{a}_sincos_rom`` with 3 reads (sin/cos th_A', cos(ph_A' - ph_N')),
shared ``b_sincos_rom`` (sin/cos th_N'), 3 multipliers (cos cos, sin sin, x cos), 2 adders
(ph_A' - ph_N', the sum): Table 1's 6 multipliers; 8 reads in 3 ROMs plus the specular
table against its 12 LUTs; 4 adders plus the back end's Phong sum against its 5.

Timing: both units run at 1 pixel per clock, pipelined with registers only (the golden
model's arithmetic and tables): the sin/cos and table reads and the ECP5 forms of the
tables are rtl/lee.py's (lee.sine_value, lee.rom_read, lee.BlockROM), every product is a
RegisteredProduct, and the helpers' ``stage`` hooks cut the long carry and mux chains
(identity in the golden model). ``latency`` is the sum of the stages listed in each class.
The reads are sequential within a pixel (1/p -> atan -> sin/cos a0 and asin), which makes
the setup deep, not slow.
"""

import itertools

import numpy as np
from amaranth.hdl import C, Cat, Mux, Value, ValueCastable

from bumprtl.rtl.config import Config
from bumprtl.rtl.exact import vectors
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.layouts import pixel_layout
from bumprtl.rtl.lee import (
    ROM_STAGES,
    SINE_STAGES,
    ratio_index,
    rom_read,
    rotated_layout,
    sine_rom,
    sine_value,
)
from bumprtl.rtl.pipe import PRODUCT_LATENCY, PipeUnit
from bumprtl.rtl.shade import IlluminationDatapath
from bumprtl.rtl.sincos import REGISTERED_SINE_LATENCY, sine_read
from bumprtl.rtl.tables import (
    kim_reciprocal_bits,
    kim_reciprocal_table,
    lee_asin_index_bits,
    lee_asin_table,
    lee_atan_table,
)

__all__ = ["KimRotation", "KimIllumination", "rotated_layout", "matrix_entries", "cartesian",
           "transform", "octant", "normalize", "reciprocal_address", "ratio_of",
           "phi_from_octant", "rho_of", "theta_select", "asin_address", "theta_from_octant",
           "dot_terms", "dot_sum"]


# --- Arithmetic shared with sim/golden/fixed/kim.py (Amaranth values or int64 arrays) -------

def _hdl(x):
    return isinstance(x, (Value, ValueCastable))


def _select(cond, a, b):
    return Mux(cond, a, b) if _hdl(cond) else np.where(cond, a, b)


def _fit(x, width, signed=True):
    """The low ``width`` bits of an HDL value whose range is known to fit (a no-op on arrays)."""
    if not _hdl(x):
        return x
    return x[:width].as_signed() if signed else x[:width]


def _abs(x):
    return abs(x) if _hdl(x) else np.abs(x)


def _clamp_unit(x, cfg: Config):
    """clamp(x, -1, 1): a rotated unit vector's coordinate never leaves [-1, 1]."""
    one = cfg.one
    return _fit(_select(x > one, one, _select(x < -one, -one, x)), cfg.frac_bits + 2)


def _times(a, b):
    return a * b


def _same(value, name):
    """The golden model's stage: none (the RTL passes a registering one, Pipe.register)."""
    return value


# Every helper that multiplies takes ``mul``: the plain product for the golden model, a
# registered product (Pipe.multiply, PRODUCT_LATENCY stages) in the RTL. All the terms a
# helper adds are products, so they arrive together. A helper that takes ``stage(value,
# name)`` calls it on every value that crosses one of its steps: nothing in the golden
# model, a register in the RTL (the arithmetic is the same either way).

def matrix_entries(st, ct, sp, cp, cfg: Config, mul=_times):
    """The four product entries of M = R_y(-th_N) R_z(-ph_N) =
    [[ct cp, ct sp, -st], [-sp, cp, 0], [st cp, st sp, ct]], each rounded to B bits."""
    b = cfg.frac_bits
    return tuple(_fit(round_shift(mul(u, w), b), b + 2)
                 for u, w in ((ct, cp), (ct, sp), (st, cp), (st, sp)))


def cartesian(st, sp, cp, cfg: Config, mul=_times):
    """Polar -> Cartesian x = sin th cos ph, y = sin th sin ph, rounded to B bits (z = cos th
    is a ROM value)."""
    b = cfg.frac_bits
    return _fit(round_shift(mul(st, cp), b), b + 2), _fit(round_shift(mul(st, sp), b), b + 2)


def transform(mat, n, a, cfg: Config, mul=_times, stage=_same):
    """A' = M A: each coordinate one sum of full products, rounded once and clamped to
    [-1, 1]. ``mat`` = (m00, m01, m20, m21), ``n`` = (st, ct, sp, cp) of N, ``a`` = (x, y, z).
    ``stage`` after the first sums and after the rounding."""
    (m00, m01, m20, m21), (st, ct, sp, cp), (x, y, z) = mat, n, a
    b = cfg.frac_bits
    terms = ((mul(m00, x) + mul(m01, y), mul(st, z)), (mul(cp, y), mul(sp, x)),
             (mul(m20, x) + mul(m21, y), mul(ct, z)))
    (u0, w0), (u1, w1), (u2, w2) = ((stage(u, f"{c}_u"), stage(w, f"{c}_w"))
                                    for (u, w), c in zip(terms, "xyz", strict=False))
    sums = (u0 - w0, u1 - w1, u2 + w2)
    return tuple(_clamp_unit(stage(round_shift(t, b), f"{c}_rounded"), cfg)
                 for t, c in zip(sums, "xyz", strict=False))


def octant(x, y, stage=_same):
    """(swap, p, q): swap = |y| > |x|, p = max(|x|, |y|), q = min(|x|, |y|); ``stage``
    after the magnitudes."""
    ax, ay = stage(_abs(x), "abs_x"), stage(_abs(y), "abs_y")
    swap = ay > ax
    return swap, _select(swap, ay, ax), _select(swap, ax, ay)


def normalize(p, q, cfg: Config, stage=_same):
    """(p << e, q << e) with e the leading zeros of the B + 1 bit p, so p << e has its leading
    one at bit B (a value in [1, 2)); p = 0 gives (0, 0). A leading-one detector and two
    shifters: the ratio q / p is unchanged and the reciprocal ROM sees a mantissa.
    ``stage`` cuts the chain of muxes in three."""
    b = cfg.frac_bits
    pn, qn = p, q
    cuts = [min(b, (b + 1) * j // 3 + 1) for j in (1, 2)]
    for e in range(1, b + 1):                      # the last (largest) true e wins
        for n in range(cuts.count(e)):
            p, q, pn, qn = (stage(x, f"{nm}{e}_{n}") for x, nm in zip((p, q, pn, qn), ("p", "q", "pn", "qn"), strict=False))
        small = p < (1 << (b + 1 - e))
        pn, qn = _select(small, p << e, pn), _select(small, q << e, qn)
    return _fit(pn, b + 1, signed=False), _fit(qn, b + 1, signed=False)


def reciprocal_address(pn, cfg: Config):
    """The R mantissa bits under the leading one of the normalized divisor."""
    b, r = cfg.frac_bits, kim_reciprocal_bits(cfg)
    return (pn >> (b - r)) & ((1 << r) - 1)


def ratio_of(product, cfg: Config):
    """q / p in units of 2**-k (lee.ratio_index's input) from qn x 1/pn (2B fractional
    bits), truncated: the atan ROM holds atan of each interval's middle."""
    return product >> (2 * cfg.frac_bits - cfg.k)


def phi_from_octant(a0, swap, x_negative, y_negative, cfg: Config, stage=_same):
    """atan2(y', x') from a0 = atan(q / p) in [0, 45] deg: 90 - a0 when |y'| > |x'|,
    180 - that when x' < 0, negated when y' < 0. atan2(0, 0) = 0. ``stage`` after each of
    the first two steps."""
    k = cfg.k
    first = _select(swap, (1 << k) - a0, a0)
    first = stage(first, "phi_first")
    x_negative, y_negative = stage(x_negative, "phi_x_neg"), stage(y_negative, "phi_y_neg")
    half = stage(_select(x_negative, (1 << (k + 1)) - first, first), "phi_half")
    phi = _select(stage(y_negative, "phi_y_neg2"), -half, half)
    return phi[:cfg.angle_bits] if _hdl(phi) else phi & (cfg.full_circle - 1)


def rho_of(p, q, ca0, sa0, cfg: Config, mul=_times):
    """rho = sqrt(x'^2 + y'^2) = p cos a0 + q sin a0 (the projection of (p, q) on the unit
    vector at a0), rounded to B bits."""
    b = cfg.frac_bits
    return _fit(round_shift(mul(p, ca0) + mul(q, sa0), b), b + 3)


def theta_select(rho, z, cfg: Config, stage=_same):
    """(use_rho, z_negative, v): v = min(rho, |z'|) <= 1/sqrt(2) (up to rounding), the
    argument of the asin read where asin is not steep; ``stage`` after |z'|."""
    az, rho, z_negative = stage(_abs(z), "abs_z"), stage(rho, "rho"), stage(z < 0, "z_negative")
    use_rho = rho <= az
    return use_rho, z_negative, _select(use_rho, rho, az)


def asin_address(v, cfg: Config):
    """v (B fractional bits, 0 <= v <= 1) rounded to the asin ROM's a address bits."""
    a, b = lee_asin_index_bits(cfg), cfg.frac_bits
    return round_shift(v, b - a) if a <= b else v << (a - b)


def theta_from_octant(asin, use_rho, z_negative, cfg: Config, stage=_same):
    """th_A' = asin(rho) or 90 - asin(|z'|), mirrored to 180 - th when z' < 0; ``stage``
    between the two."""
    k = cfg.k
    th0 = stage(_select(use_rho, asin, (1 << k) - asin), "th0")
    z_negative = stage(z_negative, "th_z_negative")
    theta = _select(z_negative, (1 << (k + 1)) - th0, th0)
    return theta[:cfg.angle_bits] if _hdl(theta) else theta & (cfg.full_circle - 1)


def dot_terms(st_a, ct_a, st_n, ct_n, cfg: Config, mul=_times):
    """Eq. (3)'s products: cos th_A cos th_N' (kept at 2B fractional bits) and
    sin th_A sin th_N' (rounded to B bits before the third multiply)."""
    return mul(ct_a, ct_n), _fit(round_shift(mul(st_a, st_n), cfg.frac_bits), cfg.frac_bits + 2)


def dot_sum(cc, ss, cphi, cfg: Config, mul=_times):
    """Eq. (3): N'.A = cc + ss cos(ph_A - ph_N'), rounded once to B bits (``cc`` comes with
    the product)."""
    return round_shift(cc + mul(ss, cphi), cfg.frac_bits)


# --- The datapaths ---------------------------------------------------------------------------

def _multiplier(pipe, prefix):
    """``mul`` for the helpers: each product a RegisteredProduct (Pipe.multiply) named
    ``{prefix}_mul{n}``, PRODUCT_LATENCY stages after its operands."""
    count = itertools.count()
    return lambda a, b: pipe.multiply(a, b, f"{prefix}_mul{next(count)}")


def _stage(pipe, prefix):
    """``stage`` for the helpers: one pipe register named ``{prefix}_{name}``."""
    return lambda value, name: pipe.register(value, f"{prefix}_{name}")


S, P, R = SINE_STAGES, PRODUCT_LATENCY, ROM_STAGES


class KimRotation(PipeUnit):
    """VectorRotation datapath, kim method (the module table; a ``wiring.Component``): polar ->
    Cartesian, M, back to polar. Input ``pixel_layout(cfg)``; output :func:`rotated_layout` (L', H', N' passed
    through, polar binary angles, as rtl/lee.py).

    Every sin/cos read is lee.sine_value (S = SINE_STAGES: angle, folded index, address, read, output
    register, data register, its copy, sign), every other table read lee.rom_read (R = ROM_STAGES:
    address register, read, output register, data register), every product a
    RegisteredProduct (P = PRODUCT_LATENCY), and at most one carry chain or half a mux chain
    lies between two registers. Per vector, in pipe stages:

    ========================  ==================================================
    stage                     what is registered
    ========================  ==================================================
    S                         sin/cos of th_N, ph_N, th_A, ph_A
    S + P + 1                 M (4 entries, rounded); x, y (rounded)
    S + 2P + 2, + 3, + 4      M A: the pair sums, the rounding, the clamp
    S + 2P + 5, + 6           |x'|, |y'|; swap, p, q
    S + 2P + 7, + 8           two thirds of the leading-one normalizer
    S + 2P + 8 + R            1/p (address: the normalized mantissa)
    S + 3P + 8 + R            q / p
    S + 3P + 9 + R            half the atan address encoder
    S + 3P + 9 + 2R           a0 = atan(q / p)
    S + 3P + 12 + 2R          ph' (three steps: 90 -, 180 -, sign)
    2S + 3P + 9 + 2R          sin a0, cos a0
    2S + 4P + 10 + 2R         rho (the sum and its rounding)
    2S + 4P + 12 + 2R         |z'|; use_rho, v = min(rho, |z'|)
    2S + 4P + 12 + 3R         asin(v)
    2S + 4P + 14 + 3R         th' (two steps): the latency
    ========================  ==================================================

    1 pixel per clock. The atan address depends on the reciprocal read, and the sin/cos a0
    and asin addresses on the atan read, within the same pixel: the reads are sequential,
    each behind registers of its own.
    """

    latency = 2 * S + 4 * P + 14 + 3 * R

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        super().__init__(cfg, pixel_layout(cfg), rotated_layout(cfg), target, credit, fifo_depth)

    def build(self, m, pipe):
        cfg, k = self.cfg, self.cfg.k
        px, o = self.i.payload, pipe.o.payload
        rom = sine_rom(pipe, cfg, "n_sincos_rom", ports=4)
        n = tuple(sine_value(m, pipe, port, angle, cfg, name)
                  for port, (angle, name) in zip(rom.ports, (
                      (px.n.theta, "n_sin_theta"), (px.n.theta + (1 << k), "n_cos_theta"),
                      (px.n.phi, "n_sin_phi"), (px.n.phi + (1 << k), "n_cos_phi")), strict=False))   # S
        mat = tuple(pipe.register(e, f"m{nm}") for e, nm in
                    zip(matrix_entries(*n, cfg, _multiplier(pipe, "m")), ("00", "01", "20", "21"), strict=False))
        n = tuple(pipe.delay(e, P + 1, f"n_{nm}") for e, nm in zip(n, ("st", "ct", "sp", "cp"), strict=False))
        for v in vectors(cfg):                                                      # S + P + 1
            phi, theta = self._vector(m, pipe, v, px[v], mat, n)
            m.d.comb += [o[v].phi.eq(phi), o[v].theta.eq(theta)]
        m.d.comb += [o.b.eq(pipe.delay(px.b, self.latency, "b")),
                     o.tag.eq(pipe.delay(px.tag, self.latency, "tag"))]

    def _vector(self, m, pipe, v, a, mat, n):
        cfg, k = self.cfg, self.cfg.k
        reg, delay = pipe.register, pipe.delay
        mul, stage = _multiplier(pipe, v), _stage(pipe, v)
        rom = sine_rom(pipe, cfg, f"{v}_sincos_rom", ports=6)
        ports = iter(rom.ports)
        read = lambda angle, name: sine_value(m, pipe, next(ports), angle, cfg, f"{v}_{name}")
        st, ct = read(a.theta, "sin_theta"), read(a.theta + (1 << k), "cos_theta")
        sp, cp = read(a.phi, "sin_phi"), read(a.phi + (1 << k), "cos_phi")          # S
        x, y = (reg(c, f"{v}_{nm}") for c, nm in zip(cartesian(st, sp, cp, cfg, mul), "xy", strict=False))
        z = delay(ct, P + 1, f"{v}_z")                                              # S + P + 1
        xp, yp, zp = (reg(c, f"{v}_{nm}_rot") for c, nm in
                      zip(transform(mat, n, (x, y, z), cfg, mul, stage), "xyz", strict=False))    # S + 2P + 4
        swap, p, q = (reg(c, f"{v}_{nm}") for c, nm in
                      zip(octant(xp, yp, stage), ("swap", "p", "q"), strict=False))              # S + 2P + 6
        x_neg, y_neg = reg(xp < 0, f"{v}_x_negative"), reg(yp < 0, f"{v}_y_negative")
        pn, qn = normalize(p, q, cfg, stage)                                        # S + 2P + 8
        recip = rom_read(pipe, f"{v}_recip_rom", kim_reciprocal_table(cfg), cfg.frac_bits + 1,
                         reciprocal_address(pn, cfg))                               # S + 2P + 8 + R
        product = mul(delay(qn, R, f"{v}_qn"), recip)                               # S + 3P + 8 + R
        a0 = rom_read(pipe, f"{v}_atan_rom", lee_atan_table(cfg), k + 1,
                      ratio_index(ratio_of(product, cfg), cfg, stage))              # S + 3P + 9 + 2R
        phi = reg(phi_from_octant(a0, delay(swap, P + 3 + 2 * R, f"{v}_swap"),
                                  delay(x_neg, P + 4 + 2 * R, f"{v}_x_neg"),
                                  delay(y_neg, P + 4 + 2 * R, f"{v}_y_neg"), cfg, stage),
                  f"{v}_phi")                                                       # S + 3P + 12 + 2R
        a0 = Cat(a0, C(0, cfg.angle_bits - (k + 1)))        # a binary angle, 0 .. 45 deg
        sa0, ca0 = read(a0, "sin_a0"), read(a0 + (1 << k), "cos_a0")                # 2S + 3P + 9 + 2R
        rho = reg(rho_of(delay(p, S + P + 3 + 2 * R, f"{v}_p"), delay(q, S + P + 3 + 2 * R, f"{v}_q"),
                         ca0, sa0, cfg, mul), f"{v}_rho")                           # 2S + 4P + 10 + 2R
        use_rho, z_neg, val = (reg(c, f"{v}_{nm}") for c, nm in zip(
            theta_select(rho, delay(zp, S + 2 * P + 6 + 2 * R, f"{v}_z_rot"), cfg, stage),
            ("use_rho", "z_negative", "asin_arg"), strict=False))                                 # 2S + 4P + 12 + 2R
        asin = rom_read(pipe, f"{v}_asin_rom", lee_asin_table(cfg), k + 1,
                        asin_address(val, cfg))                                     # 2S + 4P + 12 + 3R
        theta = reg(theta_from_octant(asin, delay(use_rho, R, f"{v}_use_rho"),
                                      delay(z_neg, R, f"{v}_z_negative"), cfg, stage),
                    f"{v}_theta")                                                   # 2S + 4P + 14 + 3R
        return delay(phi, S + P + 2 + R, f"{v}_phi"), theta


class KimIllumination(IlluminationDatapath):
    """Illumination datapath, kim method: Lee eqs (3)/(4) per vector,
    N'.A' = cos th_A' cos th_N' + round(sin th_A' sin th_N') cos(ph_A' - ph_N'), rounded once
    to B bits (:func:`dot_terms`, :func:`dot_sum`), then the shared back end.

    Input :func:`rotated_layout`; output ``shade_layout(cfg)``. Latency
    REGISTERED_SINE_LATENCY (sincos.sine_read) + P + 1 (cos cos and sin sin, the rounding)
    + P + 1 (x cos(dph), the sum and its rounding) + SHADE_LATENCY; 1 pixel per clock.
    """

    dot_latency = REGISTERED_SINE_LATENCY + 2 * P + 2

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        super().__init__(cfg, rotated_layout(cfg), target, credit, fifo_depth)

    def dots(self, m, pipe, payload):
        cfg, k = self.cfg, self.cfg.k
        b = payload.b
        rom = sine_rom(pipe, cfg, "b_sincos_rom", ports=2)
        st_n = sine_read(m, pipe, rom.ports[0], b.theta, cfg, "b_sin_theta")
        ct_n = sine_read(m, pipe, rom.ports[1], b.theta + (1 << k), cfg, "b_cos_theta")
        dots = {}
        for v in vectors(cfg):
            a = payload[v]
            mul = _multiplier(pipe, f"{v}_dot")
            rom = sine_rom(pipe, cfg, f"{v}_sincos_rom", ports=3)
            st, ct, cphi = (sine_read(m, pipe, port, angle, cfg, f"{v}_{name}")
                            for port, (angle, name) in zip(rom.ports, (
                                (a.theta, "sin_theta"), (a.theta + (1 << k), "cos_theta"),
                                (a.phi - b.phi + (1 << k), "cos_dphi")), strict=False))          # sin/cos
            cc, ss = dot_terms(st, ct, st_n, ct_n, cfg, mul)                         # + P
            ss = pipe.register(ss, f"{v}_ss")                                       # + P + 1
            cc = pipe.delay(cc, P + 1, f"{v}_cc")                                   # + 2P + 1
            cphi = pipe.delay(cphi, P + 1, f"{v}_cos_dphi")
            dots[v] = pipe.register(dot_sum(cc, ss, cphi, cfg, mul), f"{v}_dot")   # + 2P + 2
        return dots
