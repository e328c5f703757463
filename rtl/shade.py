"""The illumination back end every method shares (Lee Sec. 3.2, Fig. 8).

The back end turns the dot products N'.L' and N'.H' into 8-bit diffuse and specular
intensities and the Phong sum of eq. (2); it is shared by every method and mirrored
operation for operation by ``sim/golden/fixed/common.shade_fixed``. A method's
illumination datapath is an :class:`IlluminationDatapath` (its dot products, then
:func:`shade_stages`); the ``Illumination`` entry point (rtl/illumination.py) picks the
method's class from the registry (rtl/methods.py).
"""

from amaranth.hdl import Mux, signed, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.layouts import shade_layout
from bumprtl.rtl.pipe import PRODUCT_LATENCY, ROM_LATENCY, PipeUnit
from bumprtl.rtl.tables import phong_coefficients, specular_index_bits, specular_table

__all__ = ["IlluminationDatapath", "BackEnd", "SHADE_LATENCY", "shade_stages"]

# Registers of shade_stages: clamp, round (diffuse, table index), table read and table
# output register (ROM_LATENCY), Phong products (operand and product registers,
# PRODUCT_LATENCY), Phong sum, rounding and clamp.
SHADE_LATENCY = 4 + ROM_LATENCY + PRODUCT_LATENCY


def _clamp01(x, cfg):
    """clamp(x, 0, 1.0) of a signed value with frac_bits fractional bits, as unsigned B+1."""
    return Mux(x[-1], 0, Mux(x > cfg.one, cfg.one, x))[:cfg.frac_bits + 1]


def shade_stages(m, pipe, cfg: Config, ndotl, ndoth):
    """Eq. (2) from the dot products; returns (diffuse, specular, color), SHADE_LATENCY
    ``adv`` stages after ``ndotl``/``ndoth`` (signed, ``frac_bits`` fractional bits).

    diffuse  = round(255 clamp(N'.L))                    (constant multiply)
    specular = cos^n table[round(clamp(N'.H) 2**s)]      (block-RAM table, Fig. 8)
    color    = clamp(round((KA + KD diffuse + KS specular) / 256), 0, 255)
    """
    b = cfg.frac_bits
    d = pipe.register(_clamp01(ndotl, cfg), "diffuse_clamped")                   # stage 1
    # 255 d as (d << 8) - d: a carry chain instead of a DSP block (same integers as d * 255).
    diffuse = pipe.register(round_shift((d << 8) - d, b)[:8], "diffuse")         # stage 2
    if cfg.specular:
        s_bits = specular_index_bits(cfg)
        h = pipe.register(_clamp01(ndoth, cfg), "spec_clamped")                  # stage 1
        index = pipe.register(round_shift(h, b - s_bits), "spec_index")           # stage 2
        rom = pipe.rom(specular_table(cfg).tolist(), unsigned(8), "specular_table", ports=1)
        m.d.comb += rom.ports[0].addr.eq(index)                                   # stage 2
        specular = rom.ports[0].data                                              # 2 + ROM
    else:
        specular = 0
    diffuse = pipe.delay(diffuse, ROM_LATENCY, "diffuse_d")                       # 2 + ROM
    ka, kd, ks = phong_coefficients(cfg)
    kd_term = pipe.multiply(diffuse, kd, "kd_diffuse")                            # + PRODUCT
    ks_term = pipe.multiply(specular, ks, "ks_specular") if cfg.specular else 0
    # round_shift(KA + kd + ks, 8) as two 2-operand stages: KA and the rounding half are
    # one constant added in the second.
    terms = pipe.register(kd_term + ks_term, "phong_terms")                       # + 1
    total = (terms + (ka + 128)) >> 8
    color = pipe.register(Mux(total > 255, 255, total)[:8], "color")              # + 2
    diffuse = pipe.delay(diffuse, PRODUCT_LATENCY + 2, "diffuse_out")
    specular = pipe.delay(specular, PRODUCT_LATENCY + 2, "specular_out") if cfg.specular else 0
    return diffuse, specular, color


class IlluminationDatapath(PipeUnit):
    """The shell every method's illumination datapath shares: the method's ``dots`` gives
    N'.L' and N'.H' (signed, ``frac_bits`` fractional bits) ``dot_latency`` stages after the
    input, :func:`shade_stages` does eq. (2), and the tag rides along.

    A ``wiring.Component`` (:class:`pipe.PipeUnit`): ``i`` carries ``in_layout``, ``o``
    ``layouts.shade_layout(cfg)`` (diffuse, specular, color, tag); ``latency`` =
    ``dot_latency`` + SHADE_LATENCY; 1 pixel per clock. Subclasses set ``dot_latency`` and
    implement ``dots(m, pipe, payload) -> {"l": .., "h": ..}``.
    """

    dot_latency = None

    def __init__(self, cfg: Config, in_layout, target=None):
        super().__init__(cfg, in_layout, shade_layout(cfg), target)

    @property
    def latency(self):
        return self.dot_latency + SHADE_LATENCY

    def build(self, m, pipe):
        i, o = self.i.payload, self.o.payload
        dots = self.dots(m, pipe, i)
        diffuse, specular, color = shade_stages(m, pipe, self.cfg, dots["l"], dots.get("h", 0))
        m.d.comb += [o.diffuse.eq(diffuse), o.specular.eq(specular), o.color.eq(color),
                     o.tag.eq(pipe.delay(i.tag, self.latency, "tag"))]


class BackEnd(IlluminationDatapath):
    """The shared back end of eq. (2) alone: N'.L' and N'.H' arrive on the stream (signed,
    ``frac_bits`` fractional bits) and take one register; what a method's illumination adds
    to it is its count minus this one's (tests/rtl/test_baselines_*.py)."""

    dot_latency = 1

    def __init__(self, cfg: Config, target=None):
        b = cfg.frac_bits
        super().__init__(cfg, data.StructLayout({"l": signed(b + 2), "h": signed(b + 2),
                                                 "tag": unsigned(cfg.tag_bits)}), target)

    def dots(self, m, pipe, payload):
        return {v: pipe.register(payload[v], f"{v}_dot") for v in ("l", "h")}
