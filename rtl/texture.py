"""The colour-texture blend: Phong shading with a textured albedo (``texture = true``).

Per colour channel c, with the texel colour tex_c fetched from block RAM at the same
(u, v[, level]) as the bump map (rtl/bumpfetch.py), summed over the m lights (Lee eq. 2),
from the illumination units' unrounded terms d_j = clamp(N'.L_j) (B fractional bits) and
s_j = 255 (N'.H_j)^n (SPEC_FRAC_BITS fractional bits; rtl/shade.py):

    lit    = min(1, ka + kd sum d_j)                  with LIT_FRAC_BITS fractional bits
    spec   = ks sum s_j                               8-bit LSB, LIT_FRAC_BITS fractional bits
    out_c  = min(255, round(tex_c lit + spec))        rounded once, at the end

i.e. out_c = tex_c (ka + kd diffuse) + ks specular: the base colour modulates the
Lambertian term and the highlight is added on top. This is the shape of Tarini et al.'s
eq. 2 (Sec. 7.2, ``r = ro ai + (1 - ro) ri``, base colour times the Lambertian shade plus a
specular term); with tex_c / 255 as the albedo, tex_c lit is the albedo times 255 lit with
no division. The 8-bit diffuse and specular outputs are the light sums rounded once,
min(255, round(255 sum d_j)) and min(255, round(sum s_j / 2**F)).

:func:`texture_blend` runs on Amaranth values (with ``reg`` = a pipeline register) and on
int64 arrays (``reg`` = identity) in ``sim/golden/fixed/pipeline.py``: one function, so the
RTL and the golden model cannot drift apart.

Error against float64 (same d_j, s_j, tex_c): the one rounding at the end plus the
coefficients' quantization and the floors of the products: :func:`blend_error_bound_lsb`.
"""

import numpy as np
from amaranth.hdl import Mux, Value, ValueCastable, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import round_shift, select_constant
from bumprtl.rtl.pipe import ECP5, PipeUnit
from bumprtl.rtl.tables import (
    KS_FRAC_BITS,
    LIT_FRAC_BITS,
    SPEC_FRAC_BITS,
    blend_coefficients,
    coefficient_error_lsb,
)

__all__ = ["RGB", "rgb_layout", "texture_blend", "sum_product", "blend_error_bound_lsb",
           "TextureBlend", "TexelDelay", "BLEND_LATENCY", "SUMS8_STAGE"]

RGB = ("r", "g", "b")

# Registers of texture_blend: light sums, coefficient products, their sums (kd's shifted,
# and spec), lit (registered before it is the albedo product's operand), the texel product
# (operand and product registers), the output sum (taken from the DSP's output alone), its
# rounding and clamp.
BLEND_LATENCY = 9
# The stage texture_blend's 8-bit light sums leave at (255 D at 2, rounded at 3, clamped at 4).
SUMS8_STAGE = 4


def rgb_layout(cfg: Config):
    """One texel of the colour texture: ``color_bits`` per channel, r in the low bits."""
    return data.StructLayout({c: unsigned(cfg.color_bits) for c in RGB})


def _identity(value, name):
    return value


# Widest unsigned operand of one MULT18X18D (18 bits signed: an unsigned value needs a zero bit).
DSP_OPERAND_BITS = ECP5.dsp_width - 1
# Most products one light sum times a coefficient is split into (more: one product of the sum).
MAX_SPLIT = 2


def _narrow(x, bits):
    """``x`` (< 2**bits) as ``bits`` bits: an Amaranth sum carries a bit an addition."""
    if isinstance(x, (Value, ValueCastable)) and Value.cast(x).shape().width > bits:
        return Value.cast(x)[:bits]
    return x


def sum_product(terms, width, k, mul, name):
    """k sum_j t_j for m terms t_j < 2**width, as sum over groups of mul(sum of the group, k):
    exact in integers (distributivity), each group sum narrowed to the bits it needs.

    Widths: a group of g terms sums below g 2**width, so it is one DSP operand (at most
    DSP_OPERAND_BITS = 17 unsigned bits, the coefficients KD, KS <= 17 bits) while
    width + ceil(log2 g) <= 17. Diffuse terms are B + 1 bits: at B = 13 all 8 lights' sum
    is one DSP; at B = 16 one DSP a light. Specular terms (8 + F = 17 bits): one DSP a light.
    Up to MAX_SPLIT products are summed after their registers (one adder); with more, or a
    term wider than 17 bits, it is one product of the whole sum (fabric, still exact)."""
    g = 1 << max(0, DSP_OPERAND_BITS - width)
    groups = [terms[i:i + g] for i in range(0, len(terms), g)]
    if len(groups) > MAX_SPLIT or width > DSP_OPERAND_BITS:
        groups = [terms]
    prods = [mul(_narrow(sum(grp[1:], grp[0]), width + (len(grp) - 1).bit_length()), k,
                 name if len(groups) == 1 else f"{name}{n}") for n, grp in enumerate(groups)]
    return sum(prods[1:], prods[0])


def _sat(x, top):
    """min(x, top) of a non-negative value (Amaranth or int64): every term here is unsigned."""
    if isinstance(x, (Value, ValueCastable)):
        x = Value.cast(x)
        if x.shape().width <= top.bit_length():          # cannot exceed top (one light)
            return x
        return Mux(x > top, top, x)[:top.bit_length()]
    return np.minimum(np.asarray(x, np.int64), top)


def texture_blend(diffuse, specular, texel, cfg: Config, reg=_identity, mul=None):
    """The blend of the module docstring for m lights.

    ``diffuse``, ``specular``: lists of the lights' unrounded terms (Illumination's
    ``diffuse_fine``, ``specular_fine``); ``texel``: {r, g, b} 8-bit. ``reg(value, name)`` is
    called after each stage (a pipeline register in the RTL, identity in the golden model).
    ``mul(value, other, name)`` is value * other two stages after its operands (default
    reg(reg(value) * reg(other)); the RTL's Pipe.multiply: one DSP block whose operand
    registers stand for the stage-1 (stage-5) registers the products read).
    Returns ``(out, diffuse8, specular8)``: {r, g, b} and the light sums rounded to 8 bits,
    min(255, round(255 sum d_j)) and min(255, round(sum s_j / 2**F)), these two
    :data:`SUMS8_STAGE` stages after the input (out: BLEND_LATENCY).
    """
    if mul is None:
        def mul(value, other, name):
            other = other if isinstance(other, int) else reg(other, f"{name}_b")
            return reg(reg(value, f"{name}_a") * other, name)
    u8, b, gl = (1 << cfg.color_bits) - 1, cfg.frac_bits, LIT_FRAC_BITS
    ka, kd, ks = blend_coefficients(cfg)
    d = reg(sum(diffuse[1:], diffuse[0]), "diffuse_sum")                        # stage 1
    s = reg(sum(specular[1:], specular[0]), "specular_sum")
    tex = {c: reg(texel[c], f"texel_{c}_d1") for c in RGB}
    kd_term = sum_product(diffuse, b + 1, kd, mul, "kd_sum")                    # stage 2
    ks_term = sum_product(specular, 8 + SPEC_FRAC_BITS, ks, mul, "ks_sum")
    d255 = reg((d << 8) - d, "diffuse255")                                      # the 8-bit sums:
    s8 = reg(round_shift(s, SPEC_FRAC_BITS), "specular8_round")                 # 255 D, rounded,
    tex = {c: reg(tex[c], f"texel_{c}_d2") for c in RGB}                        # then clamped
    # The products' sums (of up to MAX_SPLIT products) alone in a cycle after the products'
    # registers, then ka and the clamp: lit is registered before it is the albedo product's
    # operand, so no DSP output reaches another DSP's input within a cycle.
    kd_sum = reg(kd_term >> b, "kd_lit")                                        # stage 3
    spec = reg(ks_term >> (KS_FRAC_BITS + SPEC_FRAC_BITS - gl), "spec")
    d8, s8 = reg(round_shift(d255, b), "diffuse8_round"), reg(s8, "specular8_round_d3")
    d8, s8 = reg(_sat(d8, u8), "diffuse8"), reg(_sat(s8, u8), "specular8")      # stage 4
    # min(1, ka + kd_sum) in two stages, one carry chain each: the sum beside the compare
    # kd_sum > 1 - ka (the same test), then the select as AND/OR terms (select_constant)
    top = 1 << gl
    over = reg(kd_sum > top - ka, "lit_over")                                   # stage 4
    lit = reg(select_constant(over, top, reg(ka + kd_sum, "lit_sum"), gl + 1), "lit")  # 5
    for n in (3, 4, 5):
        tex = {c: reg(tex[c], f"texel_{c}_d{n}") for c in RGB}
    prod = {c: mul(tex[c], lit, f"albedo_{c}") for c in RGB}                    # stage 7
    for n in (4, 5, 6, 7):
        spec = reg(spec, f"spec_d{n}")
    shade = {c: reg(prod[c] + spec, f"shade_{c}") for c in RGB}                  # stage 8
    out = {c: reg(_sat(round_shift(shade[c], gl), u8), f"color_{c}") for c in RGB}  # 9
    return out, d8, s8


def blend_error_bound_lsb(cfg: Config, lights=1):
    """Bound on |out_c - 255 clamp(tex_c / 255 min(1, ka + kd D) + ks S)| in 8-bit LSB, for
    the unrounded sums D = sum d_j, S = sum s_j / (255 2**F) given exactly (before any
    clamp): the final rounding (1/2) plus the coefficients' quantization and the products'
    floors (rtl/tables.coefficient_error_lsb; a texel scales lit's error by at most 255)."""
    return 0.5 + coefficient_error_lsb(cfg, lights, blend=True)


class TextureBlend(PipeUnit):
    """m lights' diffuse and specular terms and the texel colour -> the RGB pixel.

    Input {d: ArrayLayout(unsigned(B + 1), lights), s: ArrayLayout(unsigned(8 + F), lights)
    (light j's ``diffuse_fine`` and ``specular_fine`` at index j), texel: rgb, tag}; output
    {diffuse, specular, color: rgb, tag} (diffuse, specular = the light sums rounded to 8
    bits). Latency ``BLEND_LATENCY``; 1 pixel per clock; bit-exact with ``texture_blend`` on
    int arrays.
    """

    latency = BLEND_LATENCY

    def __init__(self, cfg: Config, lights=1, target=None, credit=True, fifo_depth=None):
        self.lights = lights
        u8, tag = unsigned(8), unsigned(cfg.tag_bits)
        fields = {"d": data.ArrayLayout(unsigned(cfg.frac_bits + 1), lights),
                  "s": data.ArrayLayout(unsigned(8 + SPEC_FRAC_BITS), lights),
                  "texel": rgb_layout(cfg), "tag": tag}
        out = {"diffuse": u8, "specular": u8, "color": rgb_layout(cfg), "tag": tag}
        super().__init__(cfg, data.StructLayout(fields), data.StructLayout(out), target, credit,
                         fifo_depth)

    def build(self, m, pipe):
        px = self.i.payload
        color, d, s = texture_blend([px.d[j] for j in range(self.lights)],
                                    [px.s[j] for j in range(self.lights)],
                                    {c: px.texel[c] for c in RGB}, self.cfg, pipe.register,
                                    pipe.multiply)
        o = pipe.o.payload
        m.d.comb += [o.color[c].eq(color[c]) for c in RGB]
        m.d.comb += [o.diffuse.eq(pipe.delay(d, self.latency - SUMS8_STAGE, "diffuse")),
                     o.specular.eq(pipe.delay(s, self.latency - SUMS8_STAGE, "specular")),
                     o.tag.eq(pipe.delay(px.tag, self.latency, "tag"))]


class TexelDelay(PipeUnit):
    """The fetched texel carried beside a layer of ``latency`` stages (rotation or
    illumination) in lock step, so it meets that pixel's shade at the blend.
    Input/output {texel: rgb}."""


    def __init__(self, cfg: Config, latency, target=None, credit=True, fifo_depth=None):
        self.latency = latency
        layout = data.StructLayout({"texel": rgb_layout(cfg)})
        super().__init__(cfg, layout, layout, target, credit, fifo_depth)

    def build(self, m, pipe):
        m.d.comb += pipe.o.payload.texel.eq(pipe.delay(self.i.payload.texel, self.latency, "texel"))
