"""Quarter-wave sine/cosine unit: the toolchain vertical slice (docs/architecture.md, Number formats)."""

from amaranth.hdl import Module, Mux, signed, unsigned
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.config import Config
from bumprtl.rtl.pipe import ROM_LATENCY, StallPipe, pipe_observer
from bumprtl.rtl.tables import quarter_sine
from bumprtl.rtl.targets import is_spread

__all__ = ["SinCos", "quarter_wave_rom", "registered_quarter_wave_rom", "sine_read",
           "REGISTERED_SINE_LATENCY", "spread_sine", "registered_sine_latency"]

# sine_read(registered=True): angle register, address register, ROM read, block-RAM
# output register, data register, sign.
REGISTERED_SINE_LATENCY = 2 + ROM_LATENCY + 2


def spread_sine(cfg: Config):
    """The quarter-wave ROM (2**k words and the spill word, B + 1 bits) is spread over more
    than targets.SPREAD_BLOCKS block RAMs (15-bit angles at B = 16: nine 8192 x 2 blocks),
    so :func:`sine_read` gives its reads a second address register (``near``)."""
    return is_spread(1 << cfg.k, cfg.frac_bits + 1)


def registered_sine_latency(cfg: Config):
    """Stages of :func:`sine_read` (registered) through the quarter-wave ROM of ``cfg``:
    REGISTERED_SINE_LATENCY, one more where the ROM is spread (:func:`spread_sine`)."""
    return REGISTERED_SINE_LATENCY + spread_sine(cfg)


def quarter_wave_rom(cfg: Config):
    """The quarter-wave sine ROM as an Amaranth Memory (contents: tables.quarter_sine)."""
    return Memory(shape=unsigned(cfg.frac_bits + 1), depth=cfg.sincos_depth,
                  init=quarter_sine(cfg).tolist())


def registered_quarter_wave_rom(pipe, cfg: Config, name, ports=2):
    """The quarter-wave sine ROM as a :class:`pipe.RegisteredROM` (read, output register;
    one DP16KD with both ports on ECP5)."""
    return pipe.rom(quarter_sine(cfg).tolist(), unsigned(cfg.frac_bits + 1), name, ports)


def sine_read(m, pipe, port, angle, cfg: Config, name, registered=False, angle_stage=True,
              near=False):
    """``sin(angle)`` through one read port of a quarter-wave ROM; the signed Q1.B value
    appears two ``adv`` stages later (ROM read, then sign) from a Memory read port, or
    REGISTERED_SINE_LATENCY stages later from a :class:`pipe.RegisteredROM` port with
    ``registered`` (the angle, the address, ROM read, block-RAM output register, a data
    register, then sign: the angle's adder, the mirrored address ``2**k - i``, the route to
    the block RAM's address pins, its clock-to-out and the route from its data pins, which
    is long where a table spans two blocks side by side, each get a cycle of their own;
    ``angle_stage=False`` when the caller registered ``angle`` itself and counts that
    stage; ``near``: one more address register, a plain copy the placer puts beside the
    ROM's blocks, for a spread ROM: :func:`spread_sine`). ``cos(a)`` is ``sin(a + 2**k)``.

    Quadrants 1 and 3 read the ROM backwards (index ``2**k - i``; entry ``2**k`` is 1.0),
    quadrants 2 and 3 are negative. Bit-exact with :func:`tables.sin_lookup`.
    """
    k = cfg.k
    a = angle[:cfg.angle_bits]
    if registered and angle_stage:
        a = pipe.register(a, f"{name}_angle")
    quadrant, index = a[k:], a[:k]
    address = Mux(quadrant[0], (1 << k) - index, index)
    if registered:             # the block RAM's address pins straight from a flip-flop
        address = pipe.register(address, f"{name}_address")
        if near:
            address = pipe.register(address, f"{name}_address_near")
        m.d.comb += port.addr.eq(address)
        negative = pipe.delay(quadrant[1], 2 + near + ROM_LATENCY, f"{name}_negative")
        value = pipe.register(port.data, f"{name}_data")
    else:
        m.d.comb += [port.addr.eq(address), port.en.eq(pipe.adv)]
        negative = pipe.register(quadrant[1], f"{name}_negative")
        value = port.data
    return pipe.register(Mux(negative, -value, value), name)


class SinCos(wiring.Component):
    """Sine and cosine of a binary angle from one quarter-wave ROM.

    Parameters
    ----------
    cfg : Config
        Reads ``angle_bits`` (k + 2), ``frac_bits`` (B) and ``tag_bits``.
    target : None or pipe.ECP5
        Elaboration target (None: the generic form every simulator runs).

    Members
    -------
    i : In(stream.Signature({angle: unsigned(k+2), tag: unsigned(tag_bits)}))
    o : Out(stream.Signature({sin: signed(B+2), cos: signed(B+2), tag}))
        ``sin``/``cos`` are Q1.B: ``2**B`` is 1.0. Bit-exact with
        :func:`bumprtl.rtl.tables.sin_lookup` / ``cos_lookup``.

    Latency REGISTERED_SINE_LATENCY = 6 cycles (angle, address, ROM read, block-RAM
    output register, data register, sign); throughput 1 angle per clock when not stalled.
    """

    def __init__(self, cfg: Config, target=None):
        self.cfg, self.target, self.memories = cfg, target, {}
        super().__init__({
            "i": In(stream.Signature(data.StructLayout({
                "angle": unsigned(cfg.angle_bits),
                "tag": unsigned(cfg.tag_bits),
            }))),
            "o": Out(stream.Signature(data.StructLayout({
                "sin": signed(cfg.sincos_width),
                "cos": signed(cfg.sincos_width),
                "tag": unsigned(cfg.tag_bits),
            }))),
        })

    @property
    def latency(self):
        return registered_sine_latency(self.cfg)

    def elaborate(self, platform):
        cfg, k = self.cfg, self.cfg.k
        m = Module()
        pipe = StallPipe(m, self.i, self.o, self.latency, self.target,
                         observer=pipe_observer(platform))
        rom = registered_quarter_wave_rom(pipe, cfg, "rom")
        self.memories, self.enable_copies = pipe.memories, pipe.enable_copies
        angle = pipe.register(self.i.payload.angle, "angle")     # one angle stage for both
        outputs = {name: sine_read(m, pipe, port, angle + offset, cfg, f"{name}_value",
                                   registered=True, angle_stage=False, near=spread_sine(cfg))
                   for port, (name, offset) in zip(rom.ports, (("sin", 0), ("cos", 1 << k)))}
        m.d.comb += [
            self.o.payload.sin.eq(outputs["sin"]),
            self.o.payload.cos.eq(outputs["cos"]),
            self.o.payload.tag.eq(pipe.delay(self.i.payload.tag, self.latency, "tag")),
        ]
        return m
