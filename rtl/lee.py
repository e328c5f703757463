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
                       cos X, cos Y), sign/mirroring in logic (rtl/sincos.sine_read)
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
"""

import numpy as np
from amaranth.hdl import Mux, Value, ValueCastable, unsigned
from amaranth.lib import data
from amaranth.lib.memory import Memory

from bumprtl.rtl.config import Config
from bumprtl.rtl.exact import vectors
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.layouts import pixel_layout, polar_layout
from bumprtl.rtl.pipe import PipeUnit
from bumprtl.rtl.shade import IlluminationDatapath
from bumprtl.rtl.sincos import quarter_wave_rom, sine_read
from bumprtl.rtl.tables import (lee_asin_index_bits, lee_asin_table, lee_atan_mantissa_bits,
                     lee_atan_ratio_bits, lee_atan_table, lee_prop_index_bits, lee_prop_table,
                     lee_reciprocal_bits, lee_reciprocal_table)

__all__ = ["LeeRotation", "LeeIllumination", "rotated_layout",
           "below_horizon", "quarter_address", "ratio_index", "asin_address", "prop_address",
           "phi_quadrant",
           "magnitude", "theta_from_prop"]


# --- Arithmetic shared with sim/golden/fixed/lee.py (Amaranth values or int64 arrays) -------

def _select(cond, a, b):
    if isinstance(cond, (Value, ValueCastable)):
        return Mux(cond, a, b)
    return np.where(cond, a, b)


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


def ratio_index(p, cfg: Config):
    """Floating-point address of the atan ROM for a ratio ``p`` < 2**W (k fractional bits):
    ``p`` itself below 2**(M+1), else e * 2**M + (p >> e) where the leading one of ``p`` is
    bit M + e (a priority encoder: W - M - 1 comparators and muxes)."""
    m = lee_atan_mantissa_bits(cfg)
    index = p
    for e in range(1, lee_atan_ratio_bits(cfg) - m):
        index = _select(p >= (1 << (m + e)), (e << m) + (p >> e), index)
    return index


def asin_address(s2, cfg: Config):
    """Eq. 7's asin ROM address: |s| = |s2| / 2 (s2 = sin X + sin Y, B fractional bits)
    rounded to lee_asin_index_bits fractional bits."""
    magnitude_s2 = abs(s2) if isinstance(s2, (Value, ValueCastable)) else np.abs(s2)
    return round_shift(magnitude_s2, cfg.frac_bits + 1 - lee_asin_index_bits(cfg))


def prop_address(product, cfg: Config):
    """T_prop address: |y_k| = |y2| (1/|cos Z|) / 2 rounded to p fractional bits and clamped
    to 1.0 (erratum 4). ``product`` = |y2| x 1/|cos Z| has 2B fractional bits."""
    p = lee_prop_index_bits(cfg)
    y_k = round_shift(product, 2 * cfg.frac_bits + 1 - p)
    return _select(y_k > (1 << p), 1 << p, y_k)


def magnitude(z, cfg: Config):
    """(Z < 0, |Z|) of a binary angle read as signed, [-180, 180) deg (erratum 5's |Z|)."""
    negative = (z >> (cfg.k + 1)) & 1
    return negative, _select(negative, cfg.full_circle - z, z)


def phi_quadrant(atan, z_negative, y_negative, cfg: Config):
    """atan2(y, sin Z) from atan(|y / sin Z|) (erratum 3): 180 - a when sin Z < 0, negated
    when y < 0. 0/0 reads atan(0) = 0 (the ratio is 0)."""
    half_turn = _select(z_negative, (1 << (cfg.k + 1)) - atan, atan)
    return _wrap(_select(y_negative, -half_turn, half_turn), cfg)


def theta_from_prop(abs_z, prop, cfg: Config):
    """Eq. 19 with erratum 5: th_A' = |Z| + (90 - |Z|) theta_prop, rounded to the angle grid."""
    return abs_z + round_shift(((1 << cfg.k) - abs_z) * prop, cfg.frac_bits)


# --- The datapaths ---------------------------------------------------------------------------

def rotated_layout(cfg: Config):
    """Rotation output: L' and H' (H' only with specular) in the tangent frame of N, the bump
    normal N' passed through, all as polar binary angles, and the tag."""
    fields = {v: polar_layout(cfg) for v in vectors(cfg)}
    fields["b"] = polar_layout(cfg)
    fields["tag"] = pixel_layout(cfg)["tag"].shape
    return data.StructLayout(fields)


def _rom(pipe, name, table, width):
    return pipe.memory(name, Memory(shape=unsigned(width), depth=len(table), init=table.tolist()))


def _read(m, pipe, rom, address):
    """One synchronous read, enabled by ``adv``: the data is one stage after ``address``."""
    port = rom.read_port(domain="sync")
    m.d.comb += [port.en.eq(pipe.adv), port.addr.eq(address)]
    return port.data


class LeeRotation(PipeUnit):
    """VectorRotation datapath, lee method (Fig. 7 once per vector; see the module table),
    whatever ``cfg.method`` says; a ``wiring.Component``.

    Input ``pixel_layout(cfg)``; output :func:`rotated_layout`. Stages per vector:
    1-2 sin/cos X, Y; 3 asin; 4 1/sin Z, 1/cos Z; 5 products; 6 atan, T_prop; 7 ph', th'.
    Latency 7; 1 pixel per clock.
    """

    latency = 7

    def __init__(self, cfg: Config, target=None):
        super().__init__(cfg, pixel_layout(cfg), rotated_layout(cfg), target)

    def build(self, m, pipe):
        px, o = self.i.payload, self.o.payload
        for v in vectors(self.cfg):
            phi, theta = self._rotate(m, pipe, v, px[v], px.n)
            m.d.comb += [o[v].phi.eq(phi), o[v].theta.eq(theta)]
        m.d.comb += [o.b.eq(pipe.delay(px.b, self.latency, "b")),
                     o.tag.eq(pipe.delay(px.tag, self.latency, "tag"))]

    def _rotate(self, m, pipe, v, a, n):
        cfg, k, b = self.cfg, self.cfg.k, self.cfg.frac_bits
        d = a.phi - n.phi                                                  # adder 1
        x, y = a.theta + d, a.theta - d                                    # adders 2, 3 (eq. 6)
        sincos = pipe.memory(f"{v}_sincos_rom", quarter_wave_rom(cfg))
        sx, sy, cx, cy = (sine_read(m, pipe, sincos.read_port(domain="sync"), angle, cfg, f"{v}_{nm}")
                          for nm, angle in (("sin_x", x), ("sin_y", y),
                                            ("cos_x", x + (1 << k)), ("cos_y", y + (1 << k))))
        s2 = sx + sy                                                       # adder 4: 2 s (eq. 7)
        asin_rom = _rom(pipe, f"{v}_asin_rom", lee_asin_table(cfg), k + 1)
        asin = _read(m, pipe, asin_rom, asin_address(s2, cfg))
        s_negative = pipe.register(s2[-1], f"{v}_s_negative")              # stage 3
        y2 = pipe.register(cy - cx, f"{v}_y2")                             # adder 5: 2 sin th sin D
        below = pipe.delay(below_horizon(a.theta, cfg), 3, f"{v}_below")
        theta_n = pipe.delay(n.theta, 3, f"{v}_theta_n")
        theta_x = Mux(s_negative, -asin, asin)
        theta_x = Mux(below, (1 << (k + 1)) - theta_x, theta_x)            # erratum 6
        z = _wrap(theta_x - theta_n, cfg)                                  # adder 6: Z
        inv = lee_reciprocal_table(cfg)
        width = lee_reciprocal_bits(cfg)
        inv_sin = _read(m, pipe, _rom(pipe, f"{v}_inv_sin_rom", inv, width), quarter_address(z, cfg))
        inv_cos = _read(m, pipe, _rom(pipe, f"{v}_inv_cos_rom", inv, width),
                        quarter_address(z + (1 << k), cfg))                # stage 4
        z = pipe.register(z, f"{v}_z")
        y2 = pipe.register(y2, f"{v}_y2_4")
        ay2 = abs(y2)
        ratio = pipe.register(ay2 * inv_sin, f"{v}_ratio") >> (2 * b + 1 - k)   # stage 5
        product = pipe.register(ay2 * inv_cos, f"{v}_yk_product")
        atan = _read(m, pipe, _rom(pipe, f"{v}_atan_rom", lee_atan_table(cfg), k + 1),
                     ratio_index(ratio, cfg))
        prop = _read(m, pipe, _rom(pipe, f"{v}_prop_rom", lee_prop_table(cfg), b + 1),
                     prop_address(product, cfg))                            # stage 6
        z = pipe.delay(z, 2, f"{v}_z")
        y_negative = pipe.delay(y2[-1], 2, f"{v}_y_negative")
        z_negative, abs_z = magnitude(z, cfg)
        phi = pipe.register(phi_quadrant(atan, z_negative, y_negative, cfg), f"{v}_phi")
        theta = pipe.register(_wrap(theta_from_prop(abs_z, prop, cfg), cfg), f"{v}_theta")
        return phi, theta                                                   # stage 7


class LeeIllumination(IlluminationDatapath):
    """Illumination datapath, lee method (Fig. 8), whatever ``cfg.method`` says: eq. 24 with erratum 2 per vector,
    N'.A' = ((c- + c+) 2**B + (c- - c+) c_phi) / 2**(B+1), one rounding, where
    c+- = cos(th_A' +- th_N') and c_phi = cos(ph_A' - ph_N'); then the shared back end.

    Input :func:`rotated_layout`; output ``shade_layout(cfg)``.
    Latency 4 (cosines, product, sum) + SHADE_LATENCY; 1 pixel per clock.
    """

    dot_latency = 4

    def __init__(self, cfg: Config, target=None):
        super().__init__(cfg, rotated_layout(cfg), target)

    def dots(self, m, pipe, payload):
        return {v: self._dot(m, pipe, v, payload[v], payload.b) for v in vectors(self.cfg)}

    def _dot(self, m, pipe, v, a, n):
        cfg = self.cfg
        angles = {"plus": a.theta + n.theta, "minus": a.theta - n.theta, "phi": a.phi - n.phi}
        c = {}
        for name, angle in angles.items():                                 # 3 cosine tables
            rom = pipe.memory(f"{v}_cos_{name}_rom", quarter_wave_rom(cfg))
            c[name] = sine_read(m, pipe, rom.read_port(domain="sync"), angle + (1 << cfg.k), cfg,
                                f"{v}_cos_{name}")                          # stage 2
        first = pipe.register(c["minus"] + c["plus"], f"{v}_first")       # stage 3
        second = pipe.register((c["minus"] - c["plus"]) * c["phi"], f"{v}_second")
        return pipe.register(round_shift((first << cfg.frac_bits) + second, cfg.frac_bits + 1),
                             f"{v}_dot")                                    # stage 4
