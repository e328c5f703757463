"""The colour-texture blend: Phong shading with a textured albedo (``texture = true``).

Per colour channel c, with the texel colour tex_c fetched from block RAM at the same
(u, v[, level]) as the bump map (rtl/bumpfetch.py), summed over the m lights (Lee eq. 2):

    lit    = clamp(round((KA + KD sum d_j) / 256), 0, 255)       ambient + diffuse intensity
    spec   = clamp(round((KS sum s_j) / 256), 0, 255)            specular intensity
    out_c  = clamp(tex_c * lit / 255 + spec, 0, 255)             (tex_c * lit / 255 rounded)

i.e. out_c = ka tex_c + kd diffuse tex_c + ks specular: the base colour modulates the
Lambertian term and the highlight is added on top. This is the shape of Tarini et al.'s
eq. 2 (Sec. 7.2, ``r = ro ai + (1 - ro) ri``, base colour times the Lambertian shade plus a
specular term), and the product is the palette blend's own :func:`rtl.palette.mul8`
(x * a / 255 rounded to nearest, exactly), so the two blends share one arithmetic.

:func:`texture_blend` runs on Amaranth values (with ``reg`` = a pipeline register) and on
int64 arrays (``reg`` = identity) in ``sim/golden/fixed/pipeline.py``: one function, so the
RTL and the golden model cannot drift apart.

Error against float64 (same d_j, s_j, tex_c): three roundings of half an LSB each (lit,
spec, the product) plus the coefficient quantization of KA, KD, KS: see
:func:`blend_error_bound_lsb`.
"""

import numpy as np
from amaranth.hdl import Module, Mux, Value, ValueCastable, unsigned
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.palette import mul8
from bumprtl.rtl.pipe import StallPipe
from bumprtl.rtl.tables import phong_coefficients

__all__ = ["RGB", "rgb_layout", "texture_blend", "blend_error_bound_lsb", "TextureBlend",
           "TexelDelay", "BLEND_LATENCY"]

RGB = ("r", "g", "b")

# Registers of texture_blend: light sums, coefficient products, lit/spec rounding, the
# texel product (mul8), the output sum.
BLEND_LATENCY = 5


def rgb_layout(cfg: Config):
    """One texel of the colour texture: ``color_bits`` per channel, r in the low bits."""
    return data.StructLayout({c: unsigned(cfg.color_bits) for c in RGB})


def _identity(value, name):
    return value


def _sat(x, top):
    """min(x, top) of a non-negative value (Amaranth or int64): every term here is unsigned."""
    if isinstance(x, (Value, ValueCastable)):
        x = Value.cast(x)
        if x.shape().width <= top.bit_length():          # cannot exceed top (one light)
            return x
        return Mux(x > top, top, x)[:top.bit_length()]
    return np.minimum(np.asarray(x, np.int64), top)


def texture_blend(diffuse, specular, texel, cfg: Config, reg=_identity):
    """The blend of the module docstring for m lights.

    ``diffuse``, ``specular``: lists of the lights' 8-bit intensities (Illumination's
    outputs); ``texel``: {r, g, b} 8-bit. ``reg(value, name)`` is called after each stage
    (a pipeline register in the RTL, identity in the golden model). Returns ``(out, d, s)``:
    {r, g, b} and the light sums min(255, sum d_j), min(255, sum s_j).
    """
    u8 = (1 << cfg.color_bits) - 1
    ka, kd, ks = phong_coefficients(cfg)
    d = reg(sum(diffuse[1:], diffuse[0]), "diffuse_sum")                        # stage 1
    s = reg(sum(specular[1:], specular[0]), "specular_sum")
    tex = {c: reg(texel[c], f"texel_{c}_d1") for c in RGB}
    kd_term, ks_term = reg(d * kd, "kd_sum"), reg(s * ks, "ks_sum")             # stage 2
    tex = {c: reg(tex[c], f"texel_{c}_d2") for c in RGB}
    lit = reg(_sat(round_shift(ka + kd_term, 8), u8), "lit")               # stage 3
    spec = reg(_sat(round_shift(ks_term, 8), u8), "spec")
    tex = {c: reg(tex[c], f"texel_{c}_d3") for c in RGB}
    prod = {c: reg(mul8(tex[c], lit, cfg), f"albedo_{c}") for c in RGB}         # stage 4
    spec = reg(spec, "spec_d4")
    out = {c: reg(_sat(prod[c] + spec, u8), f"color_{c}") for c in RGB}    # stage 5
    return out, _sat(d, u8), _sat(s, u8)


def blend_error_bound_lsb(cfg: Config, lights=1):
    """Bound on |out_c - float64(ka tex + kd D tex + ks S)| in 8-bit LSB for diffuse and
    specular sums D, S (before any clamp): 0.5 per rounding (lit, spec, product) plus the
    quantization of KA, KD, KS at their largest inputs (sums up to 255 m)."""
    ka, kd, ks = phong_coefficients(cfg)
    top = 255 * lights
    coeff = (abs(ka / 256 - 255 * cfg.ka) + abs(kd / 256 - cfg.kd) * top +
             abs(ks / 256 - (cfg.ks if cfg.specular else 0)) * top)
    return 1.5 + coeff


class TextureBlend(wiring.Component):
    """m lights' diffuse and specular and the texel colour -> the RGB pixel.

    Input {d, s: ArrayLayout(unsigned(8), lights) (light j's diffuse and specular at index
    j), texel: rgb, tag}; output {diffuse, specular,
    color: rgb, tag} (diffuse, specular = the saturated light sums). Latency
    ``BLEND_LATENCY``; 1 pixel per clock; bit-exact with ``texture_blend`` on int arrays.
    """

    latency = BLEND_LATENCY

    def __init__(self, cfg: Config, lights=1, target=None):
        self.cfg, self.lights, self.target, self.memories = cfg, lights, target, {}
        u8, tag = unsigned(8), unsigned(cfg.tag_bits)
        per_light = data.ArrayLayout(u8, lights)
        fields = {"d": per_light, "s": per_light, "texel": rgb_layout(cfg), "tag": tag}
        out = {"diffuse": u8, "specular": u8, "color": rgb_layout(cfg), "tag": tag}
        super().__init__({"i": In(stream.Signature(data.StructLayout(fields))),
                          "o": Out(stream.Signature(data.StructLayout(out)))})

    def elaborate(self, platform):
        m = Module()
        pipe = StallPipe(m, self.i, self.o, self.latency, self.target)
        px = self.i.payload
        color, d, s = texture_blend([px.d[j] for j in range(self.lights)],
                                    [px.s[j] for j in range(self.lights)],
                                    {c: px.texel[c] for c in RGB}, self.cfg, pipe.register)
        o = self.o.payload
        m.d.comb += [o.color[c].eq(color[c]) for c in RGB]
        m.d.comb += [o.diffuse.eq(pipe.delay(d, self.latency - 1, "diffuse")),
                     o.specular.eq(pipe.delay(s, self.latency - 1, "specular")),
                     o.tag.eq(pipe.delay(px.tag, self.latency, "tag"))]
        return m


class TexelDelay(wiring.Component):
    """The fetched texel carried beside a layer of ``latency`` stages (rotation or
    illumination) in lock step, so it meets that pixel's shade at the blend.
    Input/output {texel: rgb}."""

    def __init__(self, cfg: Config, latency, target=None):
        self.cfg, self.latency, self.target, self.memories = cfg, latency, target, {}
        layout = data.StructLayout({"texel": rgb_layout(cfg)})
        super().__init__({"i": In(stream.Signature(layout)), "o": Out(stream.Signature(layout))})

    def elaborate(self, platform):
        m = Module()
        pipe = StallPipe(m, self.i, self.o, self.latency, self.target)
        m.d.comb += self.o.payload.texel.eq(pipe.delay(self.i.payload.texel, self.latency, "texel"))
        return m
