"""Deliberately broken units: each must fail one property of the stream contract, so every
property is shown to be able to fail (tests/sim/formal/test_mutants.py, ``make formal``).

Built around :class:`~bumprtl.rtl.sincos.SinCos` (and PaletteLUT for the bank property);
rtl/ is never edited: the stall-enable mutation swaps ``StallPipe.__init__`` for the
duration of one elaboration only.
"""

import contextlib
from types import SimpleNamespace

from amaranth.hdl import Module, Mux, Signal
from amaranth.lib import wiring

from bumprtl.rtl.palette import PaletteLUT
from bumprtl.rtl.pipe import Pipe as StallPipe  # (being reworked for the credit edge)
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sincos import SinCos
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config

__all__ = ["MUTANTS", "EagerStallSinCos", "Dropper", "Duplicator", "Glitcher", "ExtraStage",
           "Spontaneous", "SwapAheadPalette", "UncarriedBankPipeline"]


_INIT = StallPipe.__init__


def _eager_init(self, m, i, o, depth, *args, **kwargs):
    """StallPipe.__init__ with the mutation ``adv = o.ready`` (instead of ``~o.valid | o.ready``):
    the real __init__ runs into a scratch module (so every other attribute is as usual),
    then the valid chain is built again with the mutated enable."""
    scratch = Module()
    scratch._MustUse__silence = True
    port = lambda: SimpleNamespace(valid=Signal(), ready=Signal())
    _INIT(self, scratch, port(), port(), depth, *args, **kwargs)
    self.m = m
    self.adv = Signal(name="adv")
    m.d.comb += [self.adv.eq(o.ready), i.ready.eq(self.adv)]
    self.valid = [i.valid]
    for n in range(1, depth + 1):
        v = Signal(name=f"stage{n}_valid")
        with m.If(self.adv):
            m.d.sync += v.eq(self.valid[-1])
        self.valid.append(v)
    m.d.comb += o.valid.eq(self.valid[depth])


@contextlib.contextmanager
def eager_stall():
    """rtl/pipe.py's stall enable mutated to ``adv = o.ready`` while the block runs."""
    init = StallPipe.__init__
    StallPipe.__init__ = _eager_init
    try:
        yield
    finally:
        StallPipe.__init__ = init


class EagerStallSinCos(SinCos):
    """SinCos elaborated with ``adv = o.ready``: an empty pipe no longer fills while the
    consumer is slow. Breaks ``ready`` (and only that: nothing is lost, duplicated or
    changed)."""

    def elaborate(self, platform):
        with eager_stall():
            return super().elaborate(platform)


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
    """A correct elastic output register after SinCos (one more cycle than ``latency``
    says): a bubble the unit does not own up to. Breaks ``latency`` only."""

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

    def _elaborate_palette(self, m):
        lut, f = self.units["palette"], self.units["fetch"]
        m.d.comb += f.i.valid.eq(self.i.valid)
        m.d.comb += [f.i.payload[name].eq(self.i.payload[name]) for name, _ in self.i.payload.shape()]
        m.d.comb += [lut.i.valid.eq(f.o.valid),
                     lut.i.payload.index.eq(f.o.payload.index), lut.i.payload.tag.eq(f.o.payload.tag),
                     lut.i.payload.bank.eq(lut.bank)]           # the bank at the LUT, not at entry
        m.d.comb += [self.lut_w_ready.eq(1), lut.w_en.eq(self.lut_w_en),
                     lut.w_addr.eq(self.lut_w_addr), lut.w_data.eq(self.lut_w_data),
                     lut.swap.eq(self.lut_swap), self.lut_bank.eq(lut.bank)]


# mutant -> the property it must fail
MUTANTS = {
    "eager_stall": (EagerStallSinCos, "ready"),
    "drop": (Dropper, "order"),
    "duplicate": (Duplicator, "order"),
    "glitch": (Glitcher, "hold"),
    "extra_stage": (ExtraStage, "latency"),
    "spontaneous": (Spontaneous, "quiet"),
    "swap_ahead": (SwapAheadPalette, "bank"),
    "uncarried_bank": (UncarriedBankPipeline, "bank"),
}
