"""Quarter-wave sine/cosine unit: the toolchain vertical slice (docs/architecture.md, Number formats)."""

from amaranth.hdl import Cat, Const, Mux, signed, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.pipe import ROM_LATENCY, PipeUnit
from bumprtl.rtl.tables import quarter_sine, quarter_sine_above_line
from bumprtl.rtl.targets import NEAR_BLOCKS, is_spread, rom_blocks

__all__ = ["SinCos", "registered_quarter_wave_rom", "sine_read",
           "REGISTERED_SINE_LATENCY", "spread_sine", "near_sine", "registered_sine_latency", "sine_line",
           "sine_rom_table"]

# sine_read: angle register, folded index, address register, ROM read,
# block-RAM output register, data register, its copy, sign.
REGISTERED_SINE_LATENCY = 3 + ROM_LATENCY + 3


def _width(words):
    return max(1, int(max(words)).bit_length())


def sine_line(cfg: Config):
    """The registered quarter-wave ROM stores the sine minus the line under it
    (tables.quarter_sine_above_line, B - 2 bits) where that takes fewer DP16KD side by side
    (targets.rom_blocks) than the sine itself (B + 1 bits): 15-bit angles at B = 16, seven
    8192 x 2 blocks instead of nine. :func:`sine_read` (``line``) adds the line back, a shift
    of the ROM address, in the sign's stage: the values read are the same."""
    words = 1 << cfg.k
    return (rom_blocks(words, _width(quarter_sine_above_line(cfg)))
            < rom_blocks(words, cfg.frac_bits + 1))


def sine_rom_table(cfg: Config):
    """(words, width) of the registered quarter-wave ROM of ``cfg``: tables.quarter_sine, or
    where :func:`sine_line` holds tables.quarter_sine_above_line."""
    if sine_line(cfg):
        table = quarter_sine_above_line(cfg)
        return table, _width(table)
    return quarter_sine(cfg), cfg.frac_bits + 1


def spread_sine(cfg: Config):
    """The registered quarter-wave ROM (2**k words and the spill word, :func:`sine_rom_table`)
    is spread over more than targets.SPREAD_BLOCKS block RAMs (16-bit angles at B = 16:
    fourteen 16384 x 1 blocks of the sine above its line): its clock enable is a flip-flop of
    its own (pipe.Pipe.rom)."""
    return is_spread(1 << cfg.k, sine_rom_table(cfg)[1])


def near_sine(cfg: Config):
    """The registered quarter-wave ROM spans more than targets.NEAR_BLOCKS block RAMs side by
    side (every ROM at NEAR_BLOCKS = 0), so :func:`sine_read` gives its reads a second
    address register beside the blocks (``near``)."""
    return rom_blocks(1 << cfg.k, sine_rom_table(cfg)[1]) > NEAR_BLOCKS


def registered_sine_latency(cfg: Config):
    """Stages of :func:`sine_read` through the quarter-wave ROM of ``cfg``:
    REGISTERED_SINE_LATENCY, one more where its reads take a near address register
    (:func:`near_sine`)."""
    return REGISTERED_SINE_LATENCY + near_sine(cfg)


def registered_quarter_wave_rom(pipe, cfg: Config, name, ports=2):
    """The quarter-wave sine ROM (:func:`sine_rom_table`) as a :class:`pipe.RegisteredROM`
    (read, output register; DP16KD with both ports on ECP5), read by :func:`sine_read`
    with ``line=sine_line(cfg)``."""
    table, width = sine_rom_table(cfg)
    return pipe.rom(table.tolist(), unsigned(width), name, ports)


def sine_read(m, pipe, port, angle, cfg: Config, name, angle_stage=True, near=False,
              line=False, quarters=0):
    """``sin(angle)`` through one read port of a registered quarter-wave ROM
    (:class:`pipe.RegisteredROM`); the signed Q1.B value appears REGISTERED_SINE_LATENCY (+
    ``near``) stages later (the angle, its index folded for the quadrant, the address, ROM
    read, block-RAM output register, a data register beside the block RAM, its copy beside
    the adder, then sign: the angle's adder, the route from a register shared by the reads
    of one angle, the mirrored address ``2**k - i``, the route to the block RAM's address
    pins, its clock-to-out and the route from its data pins, which is long where a table
    spans two blocks side by side or the ROM sits far from its reader, each get a cycle of
    their own; ``angle_stage=False`` when the caller registered ``angle`` itself and counts
    that stage; ``near``: one more address register, a plain copy the placer puts beside the
    ROM's blocks, for a wide ROM: :func:`near_sine`; ``line``: the ROM holds the sine minus
    the line under it, :func:`sine_line`, and the line ``(address << B) >> k``, delayed
    beside the read and signed a stage ahead, is added in the sign's stage, one carry chain
    as the sign alone is: :func:`_sine_above_line`). ``cos(a)`` is ``sin(a + 2**k)``:
    ``quarters`` (0 to 3) quarter turns added to ``angle`` after its register, to the two
    quadrant bits alone (no carry chain behind the angle's adder).

    Quadrants 1 and 3 read the ROM backwards (index ``2**k - i``; entry ``2**k`` is 1.0),
    quadrants 2 and 3 are negative. Bit-exact with :func:`tables.sin_lookup`.
    """
    k = cfg.k
    a = angle[:cfg.angle_bits]
    if angle_stage:
        a = pipe.register(a, f"{name}_angle")
    quadrant, index = a[k:], a[:k]
    if quarters:                                        # angle + quarters * 2**k
        quadrant = (quadrant + quarters)[:2]
    # Each read's own register: the index folded for its quadrant (i ^ q0). A sine and a
    # cosine of one angle differ in it, so no tool merges the two (one register would reach
    # both ROMs' address logic), and the long route to a ROM placed apart passes one LUT.
    # The mirrored address 2**k - i = ~i + 1 is then the folded word + 1.
    folded = pipe.register(Cat(index ^ quadrant[0].replicate(k), quadrant), f"{name}_folded")
    quadrant, word = folded[k:], folded[:k]
    address = pipe.register(Mux(quadrant[0], word + 1, word), f"{name}_address")  # to the pins
    if near:
        address = pipe.register(address, f"{name}_address_near")
    m.d.comb += port.addr.eq(address)
    if line:
        return _sine_above_line(pipe, port, address, quadrant[1], cfg, name, near)
    negative = pipe.delay(quadrant[1], 3 + near + ROM_LATENCY, f"{name}_negative")
    value = pipe.register(pipe.register(port.data, f"{name}_data"), f"{name}_word")
    return pipe.register(Mux(negative, -value, value), name)


def _sine_above_line(pipe, port, address, negative, cfg: Config, name, near):
    """The end of :func:`sine_read` with ``line``: ``+-(line + above)`` from the word read (the
    sine above its line) and the line of its ``address``, in one carry chain: with the
    quadrant's sign ``s`` (0 or -1 in every bit), ``-(a + b) = ~a + ~b + 2``, so the line is
    taken as ``(line ^ s) - 2s`` and the word as ``above ^ s`` in the data register, a stage
    ahead, and the sum is theirs."""
    stages = 3 + near + ROM_LATENCY                    # the quadrant's bit to the sign stage
    at_data = pipe.delay(negative, stages - 2, f"{name}_negative")   # beside the word read
    above = pipe.register(port.data ^ at_data.replicate(len(port.data)), f"{name}_data")
    at_word = pipe.register(at_data, f"{name}_negative_d{stages - 1}")
    above = pipe.register(above, f"{name}_word")       # the route to the adder: a cycle
    negative = pipe.register(at_word, f"{name}_negative_d{stages}")
    width = cfg.sincos_width + 1
    line = ((address << cfg.frac_bits) >> cfg.k)[:cfg.frac_bits + 1]     # 0 .. 2**B
    under = pipe.delay(line, ROM_LATENCY + 1, f"{name}_line")
    under = Cat(under, Const(0, width - len(under)))
    under = pipe.register(Mux(at_word, (~under).as_signed() + 2, under.as_signed())[:width]
                          .as_signed(), f"{name}_signed_line")
    above = Cat(above, negative.replicate(width - len(above)))         # above ^ s
    value = under + above.as_signed()                               # |value| <= 2**B
    return pipe.register(value[:cfg.sincos_width].as_signed(), name)


class SinCos(PipeUnit):
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

    Latency :func:`registered_sine_latency` (angle, folded index, address, [its near
    copy,] ROM read, block-RAM output register, data register, its copy, sign); one angle
    per clock.
    """

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        self.latency = registered_sine_latency(cfg)
        super().__init__(cfg, data.StructLayout({"angle": unsigned(cfg.angle_bits),
                                                 "tag": unsigned(cfg.tag_bits)}),
                         data.StructLayout({"sin": signed(cfg.sincos_width),
                                            "cos": signed(cfg.sincos_width),
                                            "tag": unsigned(cfg.tag_bits)}),
                         target, credit, fifo_depth)

    def build(self, m, pipe):
        cfg = self.cfg
        rom = registered_quarter_wave_rom(pipe, cfg, "rom")
        angle = pipe.register(self.i.payload.angle, "angle")     # one angle stage for both
        outputs = {name: sine_read(m, pipe, port, angle, cfg, f"{name}_value",
                                   angle_stage=False, near=near_sine(cfg),
                                   line=sine_line(cfg), quarters=quarters)
                   for port, (name, quarters) in zip(rom.ports, (("sin", 0), ("cos", 1)), strict=True)}
        m.d.comb += [
            pipe.o.payload.sin.eq(outputs["sin"]),
            pipe.o.payload.cos.eq(outputs["cos"]),
            pipe.o.payload.tag.eq(pipe.delay(self.i.payload.tag, self.latency, "tag")),
        ]
