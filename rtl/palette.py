"""PaletteLUT: the per-pixel half of Tarini et al.'s palette method (Sec. 5, step 2).

Blend arithmetic shared with the golden model (``sim/golden/fixed/palette_lut.py``): 8-bit
channels (``cfg.color_bits``, 255 = 1.0); a product of two channel values is
``x * a / 255`` rounded to nearest, exactly, by the divide-by-255 identity
``round(t / 255) = round_shift(t + round_shift(t, 8), 8)`` for ``t = x * a <= 255**2``
(:func:`fixed.round_shift`). Eq. 2 is then within 1 LSB of float64, eq. 1 within 1.5.

Each frame the host shades the ``sN`` quantized normals into a colour table (Sec. 5.1) and
writes it here; per pixel only a table lookup remains, optionally blended with a base
colour by eq. 2 (Sec. 7.2).
"""

from amaranth.hdl import Mux, Signal, unsigned
from amaranth.lib import data
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import Q, mul_round, round_shift, saturate
from bumprtl.rtl.pipe import RAM_LATENCY, PipeUnit

__all__ = ["PaletteLUT", "READ_LATENCY", "rgba_layout", "index_bits", "mul8", "blend_eq1", "blend_eq2", "CHANNELS"]

CHANNELS = ("r", "g", "b", "a")

# Stages of a lookup: the synchronous RAM read and the register of its data
# (rtl/pipe.RegisteredRAM).
READ_LATENCY = RAM_LATENCY


def index_bits(cfg: Config):
    """Width of a palette index: enough for ``palette_size`` entries."""
    return max(1, (cfg.palette_size - 1).bit_length())


def _u8(cfg):
    return Q(cfg.color_bits, 0, signed=False)


def mul8(x, a, cfg: Config = Config()):
    """``x * a / 255`` of two ``color_bits`` values (255 = 1.0), rounded to nearest."""
    b = cfg.color_bits
    t = mul_round(x, a, 0)
    return round_shift(t + round_shift(t, b), b)


def blend_eq2(entry, base, cfg: Config = Config()):
    """Eq. 2 (Sec. 7.2, one pass): ``r = ro * ai + (1 - ro) * ri`` per colour channel,
    ``a = ao``. ``entry`` and ``base`` map r, g, b, a to integers or int arrays."""
    top = (1 << cfg.color_bits) - 1
    out = {c: saturate(mul8(base[c], entry["a"], cfg) + mul8(entry[c], top - base[c], cfg), _u8(cfg))
           for c in CHANNELS[:3]}
    return {**out, "a": base["a"]}


def blend_eq1(entry, base, cfg: Config = Config()):
    """Eq. 1 (Sec. 7.1, exact specular): ``p = ro * ai``, ``r = p + (1 - p) * ri``."""
    top = (1 << cfg.color_bits) - 1
    out = {}
    for c in CHANNELS[:3]:
        p = mul8(base[c], entry["a"], cfg)
        out[c] = saturate(p + mul8(entry[c], top - p, cfg), _u8(cfg))
    return {**out, "a": base["a"]}


def rgba_layout(cfg: Config):
    """One colour-table entry: ``color_bits`` per channel, r in the low bits."""
    return data.StructLayout({c: unsigned(cfg.color_bits) for c in CHANNELS})


def _channels(word, cfg):
    """A packed rgba word as a dict of channel slices (r in the low bits)."""
    b = cfg.color_bits
    return {c: word[n * b:(n + 1) * b] for n, c in enumerate(CHANNELS)}


class PaletteLUT(PipeUnit):
    """Colour-table lookup, one pixel per clock, double-buffered host-written table.

    Parameters
    ----------
    cfg : Config
        Reads ``palette_size`` (sN), ``color_bits``, ``palette_blend`` and ``tag_bits``.
    target : None or pipe.ECP5
        Elaboration target (None: the generic form every simulator runs).
    bank_in : bool
        The input payload carries ``bank``: the pixel reads that bank instead of the one in
        front. For a unit that samples :attr:`bank` where it accepts the pixel, stages
        upstream (BumpPipeline: at its input, ahead of the fetch), so the pixel reads the
        bank that was in front when *that* unit accepted it; that unit must also hold back
        host writes to a bank its pixels in flight still read (``lut_w_ready``).

    Members
    -------
    i : In(stream.Signature({index: unsigned(ceil log2 sN), [base: rgba], [bank], tag}))
        ``base`` (only with ``palette_blend``) is the base colour ``(ro, go, bo, ao)``;
        ``bank`` (only with ``bank_in``) the bank to read.
    o : Out(stream.Signature({color: rgba, oor: 1, tag}))
        ``color`` is the table entry, or with ``palette_blend`` eq. 2:
        ``r = ro * ai + (1 - ro) * ri`` (products rounded to nearest, see
        :mod:`bumprtl.sim.golden.fixed.palette_lut`), ``a = ao``.
        ``oor`` = 1 when ``index >= sN``: the entry then reads as all zeros (defined,
        never X). Only possible when sN is not a power of two.
    w_en, w_addr, w_data : In
        Host write port: ``w_data`` (rgba) goes to entry ``w_addr`` of the back bank when
        ``w_en``; addresses ``>= sN`` are ignored.
    swap : In(1)
        Strobe: exchanges front and back banks at the end of the cycle (a write in the same
        cycle belongs to the bank being published). A pixel reads the bank that was in front
        in the cycle it was accepted (with ``bank_in``: the bank its payload names), so no
        lookup ever sees a half-written table; swaps may come at any time, also under
        backpressure. The lookup is done in the cycle the pixel is accepted: a write after
        that cannot change it.
    bank : Out(1)
        The current front bank.

    Memory: one block RAM of ``2 * sN`` entries of ``4 * color_bits`` bits (bank b at
    offset ``b * sN``). Latency :data:`READ_LATENCY` = 2 cycles (RAM read, then the read
    data's register: on ECP5 the block RAM's output register, so its clock-to-out is not in
    the blend's or the output's cycle), 3 with the blend stage; throughput 1 pixel per clock
    when not stalled.
    """


    def __init__(self, cfg: Config, target=None, bank_in=False, credit=True, fifo_depth=None):
        self.bank_in = bank_in
        self.latency = READ_LATENCY + cfg.palette_blend
        ib = index_bits(cfg)
        fields = {"index": unsigned(ib)}
        if cfg.palette_blend:
            fields["base"] = rgba_layout(cfg)
        if bank_in:
            fields["bank"] = unsigned(1)
        fields["tag"] = unsigned(cfg.tag_bits)
        out = {"color": rgba_layout(cfg), "oor": unsigned(1), "tag": unsigned(cfg.tag_bits)}
        super().__init__(cfg, data.StructLayout(fields), data.StructLayout(out), target, credit,
                         fifo_depth, {
            "w_en": In(1),
            "w_addr": In(ib),
            "w_data": In(rgba_layout(cfg)),
            "swap": In(1),
            "bank": Out(1),
        })

    @property
    def memory_bits(self):
        return 2 * self.cfg.palette_size * 4 * self.cfg.color_bits

    def build(self, m, pipe):
        cfg, size = self.cfg, self.cfg.palette_size
        # The table's read data is registered (on ECP5 in the block RAM's own output register):
        # the RAM's clock-to-out alone takes most of a cycle.
        table = pipe.ram("table", 2 * size, unsigned(4 * cfg.color_bits))
        front = Signal(name="front")
        with m.If(self.swap):
            m.d.sync += front.eq(~front)
        m.d.comb += self.bank.eq(front)

        m.d.comb += [table.w_en.eq(self.w_en & (self.w_addr < size)),
                     table.w_addr.eq(self.w_addr + Mux(front, 0, size)),     # the back bank
                     table.w_data.eq(self.w_data.as_value())]

        index = self.i.payload.index
        oor_in = index >= size
        read_bank = self.i.payload.bank if self.bank_in else front
        m.d.comb += table.r_addr.eq(Mux(oor_in, 0, index) + Mux(read_bank, size, 0))
        # stage 1: the RAM read, stage 2: its output register; the out-of-range zero after it
        word = table.r_data
        oor = pipe.delay(oor_in, READ_LATENCY, "oor")
        entry = _channels(Mux(oor, 0, word), cfg)
        if cfg.palette_blend:
            base = _channels(pipe.delay(self.i.payload.base.as_value(), READ_LATENCY, "base"), cfg)
            blended = blend_eq2(entry, base, cfg)
            color = {c: pipe.register(blended[c], f"blend_{c}") for c in CHANNELS}
            oor = pipe.register(oor, f"oor_d{READ_LATENCY + 1}")
        else:
            color = entry
        m.d.comb += [getattr(pipe.o.payload.color, c).eq(color[c]) for c in CHANNELS]
        m.d.comb += [pipe.o.payload.oor.eq(oor),
                     pipe.o.payload.tag.eq(pipe.delay(self.i.payload.tag, self.latency, "tag"))]
