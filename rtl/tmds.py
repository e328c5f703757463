"""DVI 1.0 TMDS: the 8b/10b encoder with DC balance and the 10:1 serializer of the board
top (docs/board.md).

:class:`TMDSEncoder` is the encoder of the DVI 1.0 specification, section 3.3.3 (its flow
chart written out): a transition-minimizing stage (XOR or XNOR chain, whichever leaves
fewer transitions, flagged in bit 8), then the DC balance on a running disparity ``cnt``
(bit 9 set when the 8 data bits are sent inverted). In blanking (``de`` low) it sends one of
the four control symbols (:data:`CONTROL`) for ``c1 c0`` and resets the disparity. Two
pixel-clock stages; the word is sent bit 0 first.

:class:`Serializer` turns the pixel-domain words of every lane into two bits per cycle of
the ``shift`` domain (5 x the pixel clock), for DDR output registers (ECP5 ODDRX1F: ``o0``
goes out while the shift clock is high, ``o1`` while it is low). The pixel domain toggles a
bit every pixel; the shift domain loads the next words two or three shift cycles after the
toggle arrives (two synchronizer flip-flops and a registered load), when the words have
been stable for at least a whole shift cycle and stay so for at least one more: no
assumption on the phase of the two clocks beyond their 1:5 ratio.
"""

from amaranth.hdl import Cat, Const, Elaboratable, Module, Mux, Signal, signed

__all__ = ["CONTROL", "CLOCK_WORD", "TMDSEncoder", "Serializer"]

# c1 c0 -> the 10-bit control symbol (bit 0 sent first), DVI 1.0 section 3.3.3
CONTROL = {0b00: 0b1101010100, 0b01: 0b0010101011, 0b10: 0b0101010100, 0b11: 0b1010101011}
# The clock lane: five zeros then five ones, so the clock falls where a word's bit 0 starts.
CLOCK_WORD = 0b1111100000


def _ones(bits):
    return sum(bits[i] for i in range(len(bits)))


class TMDSEncoder(Elaboratable):
    """8-bit ``data``, ``de``, control ``c0``/``c1`` in; the 10-bit ``q`` two cycles later."""

    latency = 2

    def __init__(self):
        self.data = Signal(8)
        self.de = Signal()
        self.c0 = Signal()
        self.c1 = Signal()
        self.q = Signal(10, init=CONTROL[0])

    def elaborate(self, platform):
        m = Module()
        d = self.data
        n1d = _ones(d)
        use_xnor = (n1d > 4) | ((n1d == 4) & ~d[0])
        # the XOR and XNOR chains apart (each bit names the one before it once), then the choice
        q_xor, q_xnor = [d[0]], [d[0]]
        for i in range(1, 8):
            q_xor.append(q_xor[-1] ^ d[i])
            q_xnor.append(~(q_xnor[-1] ^ d[i]))
        chain_xor, chain_xnor = Signal(8, name="chain_xor"), Signal(8, name="chain_xnor")
        m.d.comb += [chain_xor.eq(Cat(*q_xor)), chain_xnor.eq(Cat(*q_xnor))]
        qm = Mux(use_xnor, chain_xnor, chain_xor)
        # stage 1: q_m, its ones count, and the control path
        q_m = Signal(9, name="q_m")
        n1 = Signal(range(9), name="q_m_ones")
        de1, ctl1 = Signal(name="de1"), Signal(2, name="ctl1")
        m.d.sync += [q_m.eq(Cat(qm, ~use_xnor)), n1.eq(_ones(qm)), de1.eq(self.de),
                     ctl1.eq(Cat(self.c0, self.c1))]
        # stage 2: DC balance on the running disparity (ones minus zeros sent so far)
        cnt = Signal(signed(5), name="disparity")
        diff = Signal(signed(5), name="ones_minus_zeros")
        m.d.comb += diff.eq((n1 << 1) - 8)               # N1 - N0 of q_m[0:8]
        data8, flag = q_m[:8], q_m[8]
        with m.If(~de1):
            m.d.sync += cnt.eq(0)
            with m.Switch(ctl1):
                for code, word in CONTROL.items():
                    with m.Case(code):
                        m.d.sync += self.q.eq(word)
        with m.Elif(~cnt.any() | ~diff.any()):
            m.d.sync += self.q.eq(Cat(Mux(flag, data8, ~data8), flag, ~flag))
            m.d.sync += cnt.eq(Mux(flag, cnt + diff, cnt - diff))
        with m.Elif(((cnt > 0) & (diff > 0)) | ((cnt < 0) & (diff < 0))):
            m.d.sync += self.q.eq(Cat(~data8, flag, Const(1, 1)))
            m.d.sync += cnt.eq(cnt + (flag << 1) - diff)
        with m.Else():
            m.d.sync += self.q.eq(Cat(data8, flag, Const(0, 1)))
            m.d.sync += cnt.eq(cnt - ((~flag).as_unsigned() << 1) + diff)
        return m


class Serializer(Elaboratable):
    """``words``: pixel-domain 10-bit signals (one per lane) -> ``o0[k]``, ``o1[k]``: lane
    k's two bits of each ``shift`` cycle (registered), bit 0 of a word first.

    Each lane has its own toggle (pixel domain), its own two synchronizer flip-flops and
    its own registered load (shift domain): the load of lane k is ``t1 ^ t2`` of its chain
    a shift cycle late, a flip-flop driving only that lane's ten multiplexers, so every
    shift-domain path is one flip-flop, one LUT, one flip-flop with a fan-out of ten (the
    chains differ in their own feedback, so synthesis cannot merge them). The load comes
    two or three shift cycles after the pixel edge that changed the words, of the five
    the words stay. No shift-domain register has a reset (their initial values hold until
    the first load): at 371 MHz a synchronous reset is a route from the reset synchronizer
    to every register's LSR input as long as the period, and nothing needs it, the loads
    following the toggles within three shift cycles."""

    def __init__(self, words):
        self.words = list(words)
        self.o0 = Signal(len(self.words), reset_less=True)
        self.o1 = Signal(len(self.words), reset_less=True)

    def elaborate(self, platform):
        m = Module()
        for k, word in enumerate(self.words):
            toggle = Signal(name=f"pixel_toggle{k}")
            m.d.sync += toggle.eq(~toggle)
            t1 = Signal(name=f"toggle{k}_s1", reset_less=True)
            t2 = Signal(name=f"toggle{k}_s2", reset_less=True)
            load = Signal(name=f"load{k}", reset_less=True)
            m.d.shift += [t1.eq(toggle), t2.eq(t1), load.eq(t1 ^ t2)]
            init = int(word.init) if hasattr(word, "init") else 0
            sr = Signal(8, init=init >> 2, name=f"shift{k}", reset_less=True)
            with m.If(load):
                m.d.shift += [sr.eq(word[2:]), self.o0[k].eq(word[0]), self.o1[k].eq(word[1])]
            with m.Else():
                m.d.shift += [sr.eq(sr >> 2), self.o0[k].eq(sr[0]), self.o1[k].eq(sr[1])]
        return m
