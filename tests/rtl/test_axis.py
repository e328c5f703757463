"""AxisWrapper's parameters at both ends of their documented ranges (rtl/axis.py): tag_bits
in [0, MAX_TAG_BITS] (the wrapper adds tlast as one more tag bit), tdata_width a multiple of
8, at least 8 and at least the wider payload. A toy unit with a 4-bit payload reaches the
lower end (8) that no real unit's payload does; the emitted units reach the payload ends."""

import pytest
from amaranth.hdl import Module, unsigned
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.axis import MAX_TAG_BITS, AxisError, AxisWrapper
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.rotation import VectorRotation


class Toy(wiring.Component):
    """A wire: ``payload_bits`` of data and a tag, in and out."""

    def __init__(self, cfg, payload_bits=4):
        layout = data.StructLayout({"x": unsigned(payload_bits), "tag": unsigned(cfg.tag_bits)})
        super().__init__({"i": In(stream.Signature(layout)), "o": Out(stream.Signature(layout))})

    def elaborate(self, platform):
        m = Module()
        m.d.comb += [self.o.valid.eq(self.i.valid), self.o.payload.eq(self.i.payload),
                     self.i.ready.eq(self.o.ready)]
        return m


def _refused(make, word):
    with pytest.raises(BumpError) as e:
        make()
    assert isinstance(e.value, AxisError) and "\n" not in str(e.value) and word in str(e.value), str(e.value)


def test_tag_bits_ends():
    assert MAX_TAG_BITS == 31                  # Config's 32 minus the tlast bit
    for tag in (0, MAX_TAG_BITS):
        w = AxisWrapper(Toy, Config(tag_bits=tag))
        assert w.tag_bits == tag and len(w.unit.i.payload.tag) == tag + 1
        assert ("s_axis_tuser" in w.signature.members) == (tag > 0)
    _refused(lambda: AxisWrapper(Toy, Config(tag_bits=MAX_TAG_BITS + 1)), "tag_bits = 32")


def test_tdata_width_lower_end_and_byte_multiples():
    assert AxisWrapper(Toy, Config(tag_bits=4), tdata_width=8).tdata_width == 8
    assert AxisWrapper(Toy, Config(tag_bits=4)).tdata_width == 8           # the default
    assert AxisWrapper(Toy, Config(tag_bits=4), tdata_width=16).tdata_width == 16
    for bad in (0, -8, 7, 9, 12, 8.0, True, "8"):
        _refused(lambda bad=bad: AxisWrapper(Toy, Config(tag_bits=4), tdata_width=bad), "tdata_width")


@pytest.mark.parametrize("bits", [8, 9, 16, 17])
def test_tdata_width_payload_end(bits):
    """The narrowest byte multiple that holds the payload is accepted, 8 bits less refused."""
    need = (bits + 7) // 8 * 8
    build = lambda cfg: Toy(cfg, bits)
    assert AxisWrapper(build, Config(tag_bits=3), tdata_width=need).tdata_width == need
    assert AxisWrapper(build, Config(tag_bits=3)).tdata_width == need
    if need > 8:
        _refused(lambda: AxisWrapper(build, Config(tag_bits=3), tdata_width=need - 8), "too narrow")


def test_tdata_width_payload_end_of_a_real_unit():
    """The rotation: the wider of its tag-less payloads rounded up to bytes is the end."""
    cfg = Config(tag_bits=6)
    unit = VectorRotation(cfg.replace(tag_bits=7))
    unit._MustUse__silence = True
    bits = max(sum(len(v) for k, v in _leaves(s.payload) if k != "tag") for s in (unit.i, unit.o))
    need = (bits + 7) // 8 * 8
    w = AxisWrapper(VectorRotation, cfg, tdata_width=need)
    w._MustUse__silence = w.unit._MustUse__silence = True
    assert w.tdata_width == need
    _refused(lambda: AxisWrapper(VectorRotation, cfg, tdata_width=need - 8), "too narrow")


def _leaves(view, prefix=""):
    """(dotted name, Value) of every leaf field of a payload view."""
    for name, _ in view.shape():
        member = view[name]
        if isinstance(member, data.View):
            yield from _leaves(member, f"{prefix}{name}.")
        else:
            yield f"{prefix}{name}", member


def test_without_tuser_tlast_alone_carries_the_tag_through():
    """tag_bits = 0: no tuser port; tdata and tlast pass the (combinational) toy unit."""
    from amaranth.sim import Simulator

    w = AxisWrapper(Toy, Config(tag_bits=0))
    assert "m_axis_tuser" not in w.signature.members
    seen = []

    async def bench(ctx):
        for data_in, last in ((0x5, 1), (0xA, 0)):
            ctx.set(w.s_axis_tdata, data_in)
            ctx.set(w.s_axis_tlast, last)
            ctx.set(w.s_axis_tvalid, 1)
            ctx.set(w.m_axis_tready, 1)
            seen.append((ctx.get(w.m_axis_tvalid), ctx.get(w.m_axis_tdata) & 0xF,
                         ctx.get(w.m_axis_tlast), ctx.get(w.s_axis_tready)))
            await ctx.delay(1e-8)

    sim = Simulator(w)                  # the wrapper drives the unit's clock from aclk
    sim.add_testbench(bench)
    sim.run()
    assert seen == [(1, 0x5, 1, 1), (1, 0xA, 0, 1)]
