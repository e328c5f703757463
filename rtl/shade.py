"""The illumination back end every method shares (Lee Sec. 3.2, Fig. 8).

The back end turns the dot products N'.L' and N'.H' into the diffuse and specular terms
(unrounded, and rounded to 8 bits for their ports) and the Phong sum of eq. (2), rounded
once from the unrounded terms; the specular cos^n is an interpolated table (Fig. 8's
specular table, rtl/tables.specular_table). It is shared by every method and mirrored
operation for operation by ``sim/golden/fixed/common.shade_fixed``. A method's
illumination datapath is an :class:`IlluminationDatapath` (its dot products, then
:func:`shade_stages`); the ``Illumination`` entry point (rtl/illumination.py) picks the
method's class from the registry (rtl/methods.py).
"""

from amaranth.hdl import Mux, signed, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import round_shift, select_constant
from bumprtl.rtl.layouts import shade_layout
from bumprtl.rtl.pipe import PRODUCT_LATENCY, ROM_LATENCY, PipeUnit
from bumprtl.rtl.tables import (
    COLOR_FRAC_BITS,
    KD_FRAC_BITS,
    KS_FRAC_BITS,
    SPEC_FRAC_BITS,
    phong_coefficients,
    specular_base,
    specular_index_bits,
    specular_step_bits,
    specular_table,
)

__all__ = ["IlluminationDatapath", "BackEnd", "SHADE_LATENCY", "shade_stages"]

# Registers of shade_stages: clamp (CLAMP_STAGES), table offset (and the 8-bit diffuse), the two table
# addresses, table read and table output register (ROM_LATENCY), the two table words once
# more, the word difference, the interpolation product (PRODUCT_LATENCY), the interpolated
# specular, the Phong products KS s and KD d (PRODUCT_LATENCY; d waits beside the table),
# the Phong sum, its rounding and clamp. The registers on both sides of the block RAM let
# a table placed far from its arithmetic spend a whole cycle on each route.
CLAMP_STAGES = 2        # the sign and x > 1.0 registered beside x, then the select
FINE_STAGE = CLAMP_STAGES + 2 + ROM_LATENCY + 2 + PRODUCT_LATENCY + 1     # specular_fine's
SHADE_LATENCY = FINE_STAGE + PRODUCT_LATENCY + 2


def _clamp01(pipe, x, cfg, name):
    """clamp(x, 0, 1.0) of a signed value with frac_bits fractional bits, as unsigned B+1,
    CLAMP_STAGES registers later: first x's sign and x > 1.0 (a carry chain) registered
    beside x's low bits, then the select as AND/OR terms of those registers
    (:func:`~bumprtl.rtl.fixed.select_constant`, and 0 where negative)."""
    w = cfg.frac_bits + 1
    negative = pipe.register(x[-1], f"{name}_negative")
    over = pipe.register(x > cfg.one, f"{name}_over")
    low = pipe.register(x[:w], f"{name}_low")
    clamped = select_constant(over, cfg.one, low, w) & (~negative).replicate(w)
    return pipe.register(clamped, name)


def shade_stages(m, pipe, cfg: Config, ndotl, ndoth):
    """Eq. (2) from the dot products; returns {diffuse, specular, color, diffuse_fine,
    specular_fine}, SHADE_LATENCY pipe stages after ``ndotl``/``ndoth`` (signed,
    ``frac_bits`` fractional bits). With d = clamp(N'.L), h = clamp(N'.H) (B fractional bits):

    diffuse_fine  = d                                                    (B fractional bits)
    specular_fine = T[j] + floor((T[j+1] - T[j]) f / 2**r),  h - x0 = j 2**r + f
                    (the cos^n table of rtl/tables.py, F = SPEC_FRAC_BITS fractional bits,
                    linear interpolation with the r = B - t bits below its step; 0 below x0)
    diffuse       = round(255 d),   specular = round(specular_fine / 2**F)   (8-bit ports)
    color         = min(255, round((KA + floor(KD d / 2**B) + floor(KS s / 2**16)) / 2**G))
    The Phong sum takes the unrounded terms and rounds once (G = COLOR_FRAC_BITS).
    """
    b, f, g = cfg.frac_bits, SPEC_FRAC_BITS, COLOR_FRAC_BITS
    ka, kd, ks = phong_coefficients(cfg)
    d = _clamp01(pipe, ndotl, cfg, "diffuse_clamped")                           # stage C
    # 255 d as (d << 8) - d: a carry chain instead of a DSP block (same integers as d * 255).
    diffuse = pipe.register(round_shift((d << 8) - d, b)[:8], "diffuse")         # stage C + 1
    # d waits beside the table path (and leaves as diffuse_fine); KD d is taken where KS s is
    d_late = pipe.delay(d, FINE_STAGE - CLAMP_STAGES, "diffuse_fine_d")          # FINE_STAGE
    kd_term = pipe.multiply(d_late, kd, "kd_diffuse")                            # + PRODUCT
    if cfg.specular:
        s_bits, r = specular_index_bits(cfg), b - specular_step_bits(cfg)
        x0 = specular_base(cfg)
        h = _clamp01(pipe, ndoth, cfg, "spec_clamped")                            # stage C
        # h - x0, or 0 below x0 (word 0 of the table is 0 there)
        offset = Mux(h < x0, 0, h - x0)[:b + 1] if x0 else h
        above = pipe.register(offset, "spec_offset")                            # stage C + 1
        rom = pipe.rom(specular_table(cfg).tolist(), unsigned(8 + f), "specular_table", ports=2)
        j = above[r:]
        # word j + 1; at j = 2**s (h = 1, so the fraction is 0) any word will do: j's low
        # s bits + 1 = word 1 keeps the address inside the table.
        m.d.comb += [rom.ports[0].addr.eq(pipe.register(j, "spec_addr0")),        # stage C + 2
                     rom.ports[1].addr.eq(pipe.register(j[:s_bits] + 1, "spec_addr1"))]
        # both words registered beside the block RAM before any arithmetic
        t0 = pipe.register(rom.ports[0].data, "spec_word0")                       # 3 + ROM + 1
        if r:
            t1 = pipe.register(rom.ports[1].data, "spec_word1")
            frac = pipe.delay(above[:r], 1 + ROM_LATENCY + 2, "spec_frac")
            step = pipe.register(t1 - t0, "spec_step")                            # + 1
            product = pipe.multiply(step, frac, "spec_interp")                    # + PRODUCT
            t0 = pipe.delay(t0, 1 + PRODUCT_LATENCY, "spec_word")
            fine = pipe.register((t0 + (product >> r))[:8 + f], "specular_fine")  # + 1
        else:
            fine = pipe.delay(t0, 2 + PRODUCT_LATENCY, "specular_fine")
        specular = pipe.register(round_shift(fine, f)[:8], "specular")          # + 1
        ks_term = pipe.multiply(fine, ks, "ks_specular")                          # + PRODUCT
        ks_term = ks_term >> (KS_FRAC_BITS + f - g)
        specular = pipe.delay(specular, SHADE_LATENCY - FINE_STAGE - 1, "specular_out")
        fine = pipe.delay(fine, SHADE_LATENCY - FINE_STAGE, "specular_fine_out")
    else:
        ks_term, specular, fine = 0, 0, 0
    # round_shift(KA + kd + ks, G) as two 2-operand stages: KA and the rounding half are
    # one constant added in the second.
    terms = pipe.register((kd_term >> (KD_FRAC_BITS + b - g)) + ks_term, "phong_terms")  # + 1
    total = (terms + (ka + (1 << (g - 1)))) >> g
    color = pipe.register(Mux(total > 255, 255, total)[:8], "color")              # + 2
    return {"diffuse": pipe.delay(diffuse, SHADE_LATENCY - CLAMP_STAGES - 1, "diffuse_out"),
            "specular": specular, "color": color,
            "diffuse_fine": pipe.delay(d_late, SHADE_LATENCY - FINE_STAGE, "diffuse_fine_out"),
            "specular_fine": fine}


class IlluminationDatapath(PipeUnit):
    """The shell every method's illumination datapath shares: the method's ``dots`` gives
    N'.L' and N'.H' (signed, ``frac_bits`` fractional bits) ``dot_latency`` stages after the
    input, :func:`shade_stages` does eq. (2), and the tag rides along.

    A ``wiring.Component`` (:class:`pipe.PipeUnit`): ``i`` carries ``in_layout``, ``o``
    ``layouts.shade_layout(cfg)`` (diffuse, specular, color, diffuse_fine, specular_fine,
    tag); ``latency`` =
    ``dot_latency`` + SHADE_LATENCY; 1 pixel per clock. Subclasses set ``dot_latency`` and
    implement ``dots(m, pipe, payload) -> {"l": .., "h": ..}``.
    """

    dot_latency = None

    def __init__(self, cfg: Config, in_layout, target=None, credit=True, fifo_depth=None):
        super().__init__(cfg, in_layout, shade_layout(cfg), target, credit, fifo_depth)

    @property
    def latency(self):
        return self.dot_latency + SHADE_LATENCY

    def build(self, m, pipe):
        i, o = self.i.payload, pipe.o.payload
        dots = self.dots(m, pipe, i)
        shade = shade_stages(m, pipe, self.cfg, dots["l"], dots.get("h", 0))
        m.d.comb += [o[k].eq(v) for k, v in shade.items()]
        m.d.comb += o.tag.eq(pipe.delay(i.tag, self.latency, "tag"))


class BackEnd(IlluminationDatapath):
    """The shared back end of eq. (2) alone: N'.L' and N'.H' arrive on the stream (signed,
    ``frac_bits`` fractional bits) and take one register; what a method's illumination adds
    to it is its count minus this one's (tests/rtl/test_baselines_*.py)."""

    dot_latency = 1

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        b = cfg.frac_bits
        super().__init__(cfg, data.StructLayout({"l": signed(b + 2), "h": signed(b + 2),
                                                 "tag": unsigned(cfg.tag_bits)}), target, credit, fifo_depth)

    def dots(self, m, pipe, payload):
        return {v: pipe.register(payload[v], f"{v}_dot") for v in ("l", "h")}
