"""rtl/tmds.Serializer in the Amaranth simulator: the pixel domain's 10-bit words leave the
shift domain (5 x the pixel clock, two bits a cycle for the DDR registers, ``o0`` first)
bit 0 first, every word exactly once and in order, the lanes in step, at several phases
of the shift clock against the pixel clock (the PLL's outputs are aligned; the serializer
assumes only the 1:5 ratio). The words change every pixel, each lane's differently, so a
word loaded a pixel early or late, twice or not at all, or a lane a shift cycle off
another, breaks the match."""

import pytest
from amaranth.hdl import Elaboratable, Module, Signal
from amaranth.sim import Simulator

from bumprtl.rtl.tmds import Serializer

LANES = 4
SHIFT_NS = 2.0                                  # the pixel clock is 5 x slower
CYCLES = 400                                    # shift cycles simulated: 80 pixels


def word(n, lane):
    """The word lane ``lane`` is given in pixel ``n`` (changing every pixel)."""
    return (n * 0x2B5 + lane * 0x111 + (n * n) % 7) & 0x3FF


class Words(Elaboratable):
    """A pixel counter and the lanes' words from it, registered in the pixel domain."""

    def __init__(self):
        self.n = Signal(16)
        self.words = [Signal(10, name=f"word{k}") for k in range(LANES)]
        self.ser = Serializer(self.words)

    def elaborate(self, platform):
        m = Module()
        m.submodules.ser = self.ser
        m.d.sync += self.n.eq(self.n + 1)
        for k, w in enumerate(self.words):   # word(n + 1, k) after the edge that makes n + 1
            m.d.sync += w.eq((self.n + 1) * 0x2B5 + k * 0x111 + (self.n + 1) * (self.n + 1) % 7)
        return m


def serial_bits(phase_ns):
    """Every lane's serial bits (o0 then o1 of each shift cycle)."""
    dut = Words()
    bits = [[] for _ in range(LANES)]

    async def bench(ctx):
        for _ in range(CYCLES):
            await ctx.tick("shift")
            o0, o1 = ctx.get(dut.ser.o0), ctx.get(dut.ser.o1)
            for k in range(LANES):
                bits[k] += [(o0 >> k) & 1, (o1 >> k) & 1]

    sim = Simulator(dut)
    sim.add_clock(5 * SHIFT_NS * 1e-9)
    sim.add_clock(SHIFT_NS * 1e-9, phase=phase_ns * 1e-9, domain="shift")
    sim.add_testbench(bench)
    sim.run()
    return bits


def alignment(bits, lane, count=60):
    """(bit offset, first pixel) where ``count`` consecutive words of ``lane`` start in
    ``bits``, or None."""
    for start in range(0, 40):
        for n0 in range(0, 12):
            if all(bits[lane][start + 10 * i + j] == (word(n0 + i, lane) >> j) & 1
                   for i in range(count) for j in range(10)):
                return start, n0
    return None


@pytest.mark.parametrize("phase_ns", [0.0, 0.6, 1.0, 1.4])
def test_every_word_leaves_once_in_order_bit_0_first(phase_ns):
    bits = serial_bits(phase_ns)
    found = [alignment(bits, k) for k in range(LANES)]
    assert None not in found, f"a lane's words not found in its serial bits at {phase_ns} ns"
    # where pixel 0's word would start: equal on every lane (lane 0's first word is its
    # reset value, 0, so its match may start a word earlier than the others')
    zero = [start - 10 * n0 for start, n0 in found]
    assert zero == [zero[0]] * LANES, f"the lanes are not in step: {found}"
    assert zero[0] % 2 == 0, "a word must start on o0 (the DDR register's first half)"


def test_a_word_out_of_place_is_found():
    """The check above can fail: one bit flipped, or the stream a shift cycle late."""
    bits = serial_bits(0.0)
    start, n0 = alignment(bits, 0)
    flipped = list(bits[0])
    flipped[start + 10 * 30 + 3] ^= 1
    assert alignment([flipped], 0) is None
    doubled = bits[0][:start + 10 * 20] + bits[0][start + 10 * 19:]   # word 19 twice
    assert alignment([doubled], 0) is None
