"""Deliberately broken units: each must fail one property of the stream contract, so every
property is shown to be able to fail (tests/sim/formal/test_formal.py, ``make formal``).

Built around :class:`~bumprtl.rtl.sincos.SinCos` (and PaletteLUT for the bank property);
rtl/ is never edited and nothing is patched: the credit mutants put a broken copy of the
credit edge (:class:`BrokenEdge`, one mutation each) around SinCos's free-running chain
(``credit=False``), the way a scene pipeline puts its one edge around its units.
"""

from amaranth.hdl import Module, Mux, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.palette import PaletteLUT
from bumprtl.rtl.pipe import EDGE_LATENCY, CreditEdge, CreditFIFO, min_fifo_depth
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sincos import SinCos
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config

__all__ = ["MUTANTS", "EDGE_MUTATIONS", "BrokenEdge", "BrokenEdgeSinCos", "Dropper",
           "Duplicator", "Glitcher", "ExtraStage", "Spontaneous", "SwapAheadPalette",
           "UncarriedBankPipeline"]

# mutation of the credit edge -> what is broken
EDGE_MUTATIONS = {
    "late": "a pixel's credit is counted two cycles after it leaves, not one",
    "early": "the credit of a pixel leaving is free in the same cycle (i.ready reads o.ready)",
    "twice": "a pixel leaving gives two credits back",
    "ungated": "i.ready is 1: the input is not gated by the credits",
    "read_unready": "the FIFO is read whether or not the consumer is ready",
    "one_more": "the credit count starts at depth + 1",
}


class BrokenEdge(CreditEdge):
    """rtl/pipe.py's CreditEdge with one mutation of :data:`EDGE_MUTATIONS`: the same
    members and attributes (``credits``, ``level``), the same FIFO (submodule ``fifo``)."""

    def __init__(self, layout, latency, mutation):
        if mutation not in EDGE_MUTATIONS:
            raise ValueError(f"mutation must be one of {', '.join(EDGE_MUTATIONS)}, got {mutation!r}")
        super().__init__(layout, latency)
        self.mutation = mutation
        if mutation == "one_more":        # room for depth + 1
            self.credits = Signal(range(self.depth + 2), init=self.depth + 1, name="credits")

    def elaborate(self, platform):
        m = Module()
        mutation = self.mutation
        m.submodules.fifo = fifo = CreditFIFO(len(self.core.payload.as_value()), self.depth)
        m.d.comb += self.level.eq(fifo.level)
        free = Signal(init=1, name="credit_free")
        take = self.i_valid & self.i_ready
        give = self.o.valid & self.o.ready
        if mutation == "late":
            late = Signal(name="give_late")
            m.d.sync += late.eq(give)
            give = late
        elif mutation == "twice":
            give = give << 1
        after = Signal.like(self.credits, name="credits_next")
        m.d.comb += after.eq(self.credits - take + give)
        m.d.sync += [self.credits.eq(after), free.eq(after != 0)]
        ready = {"early": free | give, "ungated": 1}.get(mutation, free)
        m.d.comb += [self.i_ready.eq(ready), self.core.ready.eq(1),
                     fifo.w_en.eq(self.core.valid), fifo.w_data.eq(self.core.payload),
                     self.o.valid.eq(fifo.r_rdy), self.o.payload.eq(fifo.r_data),
                     fifo.r_en.eq(1 if mutation == "read_unready" else self.o.ready)]
        return m


class BrokenEdgeSinCos(wiring.Component):
    """SinCos's free-running chain (``credit=False``) behind a :class:`BrokenEdge`: a unit
    with SinCos's ports, ``latency``, ``port_latency`` and ``fifo_depth``."""

    mutation = None

    def __init__(self, cfg):
        self.inner, self.cfg = SinCos(cfg, credit=False), cfg
        self.latency = self.inner.latency
        self.port_latency = self.latency + EDGE_LATENCY
        self.fifo_depth = min_fifo_depth(self.latency)
        super().__init__({"i": In(stream.Signature(self.inner.i.payload.shape())),
                          "o": Out(stream.Signature(self.inner.o.payload.shape()))})

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = self.inner
        m.submodules.edge = edge = BrokenEdge(self.o.payload.shape(), self.latency, self.mutation)
        m.d.comb += [edge.i_valid.eq(self.i.valid), self.i.ready.eq(edge.i_ready),
                     inner.i.valid.eq(self.i.valid & edge.i_ready),
                     inner.i.payload.eq(self.i.payload),
                     edge.core.valid.eq(inner.o.valid), edge.core.payload.eq(inner.o.payload)]
        wiring.connect(m, edge.o, wiring.flipped(self.o))
        return m


def _broken_edge(mutation):
    return type(f"BrokenEdgeSinCos_{mutation}", (BrokenEdgeSinCos,), {"mutation": mutation,
                "__doc__": f"SinCos behind a broken edge: {EDGE_MUTATIONS[mutation]}."})


class _Around(wiring.Component):
    """A unit with SinCos's ports around a SinCos, passing everything through; subclasses
    break one thing."""

    def __init__(self, cfg):
        self.inner = SinCos(cfg)
        self.cfg = cfg
        super().__init__(dict(self.inner.signature.members))

    @property
    def latency(self):
        return self.inner.latency

    @property
    def port_latency(self):
        return self.inner.port_latency

    @property
    def fifo_depth(self):
        return self.inner.fifo_depth

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = self.inner
        wiring.connect(m, wiring.flipped(self.i), inner.i)
        wiring.connect(m, inner.o, wiring.flipped(self.o))
        return m


class Dropper(_Around):
    """Accepts the pixel with tag 1 but never passes it on. Breaks ``order`` and ``latency``."""

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = self.inner
        m.d.comb += [inner.i.payload.eq(self.i.payload), self.i.ready.eq(inner.i.ready),
                     inner.i.valid.eq(self.i.valid & (self.i.payload.tag != 1))]
        wiring.connect(m, inner.o, wiring.flipped(self.o))
        return m


class Duplicator(_Around):
    """Delivers the pixel with tag 1 twice. Breaks ``order`` (and ``quiet`` when it was
    the last one in flight)."""

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = self.inner
        wiring.connect(m, wiring.flipped(self.i), inner.i)
        again = Signal(name="again")
        held = Signal.like(inner.o.payload.as_value(), name="held")
        m.d.comb += self.o.payload.eq(Mux(again, held, inner.o.payload.as_value()))
        m.d.comb += [self.o.valid.eq(again | inner.o.valid), inner.o.ready.eq(~again & self.o.ready)]
        with m.If(again & self.o.ready):
            m.d.sync += again.eq(0)
        with m.Elif(inner.o.valid & self.o.ready & (inner.o.payload.tag == 1)):
            m.d.sync += [again.eq(1), held.eq(inner.o.payload.as_value())]
        return m


class Glitcher(_Around):
    """Flips a bit of ``sin`` after the output has been stalled a cycle. Breaks ``hold``."""

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = self.inner
        wiring.connect(m, wiring.flipped(self.i), inner.i)
        stalled = Signal(name="stalled")
        m.d.sync += stalled.eq(inner.o.valid & ~self.o.ready)
        m.d.comb += [self.o.valid.eq(inner.o.valid), inner.o.ready.eq(self.o.ready),
                     self.o.payload.eq(inner.o.payload),
                     self.o.payload.sin.eq(inner.o.payload.sin ^ stalled)]
        return m


class ExtraStage(_Around):
    """A correct elastic output register after SinCos (one more cycle than
    ``port_latency`` says): a bubble the unit does not own up to. Breaks ``latency`` only."""

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = self.inner
        wiring.connect(m, wiring.flipped(self.i), inner.i)
        adv = ~self.o.valid | self.o.ready
        m.d.comb += inner.o.ready.eq(adv)
        with m.If(adv):
            m.d.sync += [self.o.valid.eq(inner.o.valid), self.o.payload.eq(inner.o.payload)]
        return m


class Spontaneous(_Around):
    """Comes out of reset with ``o.valid`` high (a stage register initialised to 1).
    Breaks ``quiet`` (and ``order``)."""

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = self.inner
        wiring.connect(m, wiring.flipped(self.i), inner.i)
        boot = Signal(init=1, name="boot")
        with m.If(self.o.ready):
            m.d.sync += boot.eq(0)
        m.d.comb += [self.o.valid.eq(boot | inner.o.valid), inner.o.ready.eq(~boot & self.o.ready),
                     self.o.payload.eq(inner.o.payload)]
        return m


class SwapAheadPalette(wiring.Component):
    """An elastic register stage in front of a PaletteLUT that does not carry the swap with
    the pixel (the shape of a fetch stage ahead of the LUT): a swap strobed while a pixel
    waits in that stage changes the bank it reads. Breaks ``bank``."""

    def __init__(self, cfg):
        self.inner, self.cfg = PaletteLUT(cfg), cfg
        super().__init__(dict(self.inner.signature.members))

    @property
    def latency(self):
        return self.inner.latency + 1

    @property
    def port_latency(self):
        return self.inner.port_latency + 1

    @property
    def fifo_depth(self):
        return self.inner.fifo_depth

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = self.inner
        valid = Signal(name="ahead_valid")
        payload = Signal.like(self.i.payload.as_value(), name="ahead_payload")
        adv = ~valid | inner.i.ready
        m.d.comb += [self.i.ready.eq(adv), inner.i.valid.eq(valid), inner.i.payload.eq(payload)]
        with m.If(adv):
            m.d.sync += [valid.eq(self.i.valid), payload.eq(self.i.payload)]
        wiring.connect(m, inner.o, wiring.flipped(self.o))
        m.d.comb += [inner.w_en.eq(self.w_en), inner.w_addr.eq(self.w_addr),
                     inner.w_data.eq(self.w_data), inner.swap.eq(self.swap), self.bank.eq(inner.bank)]
        return m


class UncarriedBankPipeline(BumpPipeline):
    """The palette scene pipeline (``palette_size``/``tag_bits`` of ``cfg``, 16^2 map) wired
    the way it was before the bank rode with the pixel: the LUT reads the bank in front when
    the pixel reaches it, behind the fetch, and host writes are never held back
    (``lut_w_ready`` always high). Breaks ``bank``."""

    def __init__(self, cfg):
        keys = {**BUILTIN["palette"], "texture_size": 16, "palette_size": cfg.palette_size,
                "angle_bits": cfg.angle_bits, "frac_bits": cfg.frac_bits,
                "spec_index_bits": cfg.spec_index_bits, "tag_bits": cfg.tag_bits}
        super().__init__(load_scene_config(keys).hardware)

    def _elaborate_palette(self, m, platform):
        lut, f = self.units["palette"], self.units["fetch"]
        m.d.comb += f.i.valid.eq(self.i.valid & self.i.ready)
        m.d.comb += [f.i.payload[name].eq(self.i.payload[name]) for name, _ in self.i.payload.shape()]
        m.d.comb += [lut.i.valid.eq(f.o.valid),
                     lut.i.payload.index.eq(f.o.payload.index), lut.i.payload.tag.eq(f.o.payload.tag),
                     lut.i.payload.bank.eq(lut.bank)]           # the bank at the LUT, not at entry
        m.d.comb += [self.lut_w_ready.eq(1), lut.w_en.eq(self.lut_w_en),
                     lut.w_addr.eq(self.lut_w_addr), lut.w_data.eq(self.lut_w_data),
                     lut.swap.eq(self.lut_swap), self.lut_bank.eq(lut.bank)]


# mutant -> the property it must fail
MUTANTS = {
    "credit_late": (_broken_edge("late"), "ready"),
    "credit_early": (_broken_edge("early"), "ready"),
    "credit_twice": (_broken_edge("twice"), "credit"),
    "ungated": (_broken_edge("ungated"), "credit"),
    "read_unready": (_broken_edge("read_unready"), "hold"),
    "credit_one_more": (_broken_edge("one_more"), "credit"),
    "drop": (Dropper, "order"),
    "duplicate": (Duplicator, "order"),
    "glitch": (Glitcher, "hold"),
    "extra_stage": (ExtraStage, "latency"),
    "spontaneous": (Spontaneous, "quiet"),
    "swap_ahead": (SwapAheadPalette, "bank"),
    "uncarried_bank": (UncarriedBankPipeline, "bank"),
}
