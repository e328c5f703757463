"""The ECP5 lowering of the registered elements (docs/architecture.md, Interfaces): every
MULT18X18D and DP16KD the design instantiates, the DP16KD modes a table is stored in and
the block counts that follow from them. :class:`ECP5Lowering` has a method per primitive,
as the generic target (rtl/targets.Generic) has; ``rtl/targets.ECP5`` is the two together,
so a primitive this lowering leaves falls back to the generic form. The elements
(rtl/targets.py, rtl/lee.BlockROM) hold their contract only, never this code.
"""

from amaranth.hdl import Cat, ClockSignal, Const, Instance, Mux, Shape, Signal, Value, signed

__all__ = ["ECP5Lowering", "DSP_WIDTH", "BRAM_WORDS", "BRAM_WIDTH", "DP16KD_MODES",
           "ROM_MAX_BLOCKS", "SPREAD_BLOCKS", "NEAR_BLOCKS", "fits_dsp", "rom_blocks", "is_spread",
           "rom_spread", "stored_words", "dp16kd", "dp16kd_rom_block", "dp16kd_initvals"]

# Width of one signed DSP input (ECP5's MULT18X18D): fits_dsp's default.
DSP_WIDTH = 18
# One DP16KD as 1024 x 18 with its output register (REGMODE OUTREG): a table's first choice.
BRAM_WORDS = 1024
BRAM_WIDTH = 18
# DP16KD data widths (one port) and their depths: 18 Kbit as 1024 x 18 ... 16384 x 1; the
# third field is the address shift (the word address sits on AD[13:shift]).
DP16KD_MODES = ((18, 1024, 4), (9, 2048, 3), (4, 4096, 2), (2, 8192, 1), (1, 16384, 0))
# Most DP16KD blocks side by side that one ROM of more than 1024 words is given on ECP5:
# an 8193 x 17 table (the quarter-wave sine of 15-bit angles at B = 16 stored whole) is nine
# x2 blocks, read without an output multiplexer (the generic form, which Yosys maps with
# one, is slower: docs/report.md).
ROM_MAX_BLOCKS = 9
# A memory of more DP16KD than this side by side is "spread" over the die: its reads take a
# second address register (sincos.near_sine, bumpfetch.BumpMapFetch), so the address does
# not cross the spread in the cycle that computes it. The threshold is the widest
# memory whose rows place without it (bumprtl report fpga, docs/report.md).
SPREAD_BLOCKS = 8
# A quarter-wave sine ROM of more DP16KD than this side by side has its reads take a second
# address register beside its blocks (sincos.near_sine): without it the angle -> mirrored
# address route to the blocks is a worst path at 200 MHz even for a ROM of one to four
# blocks (the address register sits at the block RAM, the angle's adder far from it;
# docs/report.md), so every sine ROM takes it.
NEAR_BLOCKS = 0


def fits_dsp(*shapes, width=DSP_WIDTH):
    """Every shape is one signed ``width``-bit DSP input (an unsigned one needs a zero bit)."""
    return all(Shape.cast(s).width + (not Shape.cast(s).signed) <= width for s in shapes)


def _limbs(value, step):
    """(shift, limb) pairs of ``value`` in ``step``-bit limbs, low first: every limb unsigned
    but the top one of a signed value, which keeps the sign (sum of limb << shift = value)."""
    shape = value.shape()
    limbs = [(lo, value[lo:lo + step]) for lo in range(0, shape.width, step)]
    if shape.signed:
        limbs[-1] = (limbs[-1][0], limbs[-1][1].as_signed())
    return limbs


def stored_words(init):
    """Words of the table ``init`` its DP16KD blocks hold: all of them, but for a table of
    2**n + 1 words whose word 0 is 0, the first 2**n (the last word sits in a flip-flop, read
    when the address wraps to word 0)."""
    n = len(init) - 1
    return n if n >= 1 and n & (n - 1) == 0 and init[0] == 0 else len(init)


def rom_blocks(words, width):
    """DP16KD blocks side by side of a ``words`` x ``width`` table in the mode
    :meth:`ECP5Lowering.rom_mode` picks (one x18 block up to 1024 words, else the widest mode
    that holds the words); 0 when no mode holds it."""
    if words <= BRAM_WORDS:
        return 1 if width <= BRAM_WIDTH else 0
    mode = next((m for m in DP16KD_MODES if m[1] >= words), None)
    return 0 if mode is None else -(-width // mode[0])


def is_spread(words, width):
    """A ``words`` x ``width`` memory spans more than SPREAD_BLOCKS block RAMs side by side
    (:func:`rom_blocks`): the rule of ``RegisteredROM.spread`` and ``RegisteredRAM.spread``,
    and of the latencies that depend on it before any memory is built."""
    return rom_blocks(words, width) > SPREAD_BLOCKS


def rom_spread(init, width, ports):
    """A ROM of contents ``init``, ``width`` bits and ``ports`` read ports is spread
    (:func:`is_spread`): at most two ports (a DP16KD's) and its :func:`stored_words` too many
    blocks side by side."""
    return ports <= 2 and is_spread(stored_words(init), width)


def dp16kd_initvals(words, width):
    """INITVAL_00..3F of one DP16KD in ``width`` mode holding ``words`` (word w at address w):
    the array is 1024 rows of 18 bits, an x18 word a row, an x9 word half a row (low half
    first), an x4/x2/x1 word in the low 8 bits of 9-bit unit w / (8 / width); each INITVAL
    holds 16 rows in 20-bit slots (sim/ecp5/dp16kd.v models the same layout; Yosys' own
    block-RAM mapping agrees, tests/sim/ecp5/test_postsynth.py)."""
    flat = 0
    for w, x in enumerate(words):
        x = int(x) & ((1 << width) - 1)
        if width in (18, 9):
            pos = w * width
        else:
            per = 8 // width
            pos = (w // per) * 9 + width * (w % per)
        flat |= x << pos
    params = {}
    for row in range(64):
        value = 0
        for n in range(16):
            value |= ((flat >> (18 * (row * 16 + n))) & ((1 << 18) - 1)) << (20 * n)
        params[f"p_INITVAL_{row:02X}"] = Const(value, 320)
    return params


def dp16kd(bits, words, regmode_a, regmode_b, **ports):
    """One DP16KD in its x``bits`` mode (:data:`DP16KD_MODES`) holding ``words``
    (:func:`dp16kd_initvals`), port A's output register ``regmode_a`` and port B's
    ``regmode_b`` ("OUTREG" or "NOREG"), synchronous reset, no chip-select decode, normal
    write mode, GSR off; ``ports``: its connections, as an Instance's ``i_``/``o_`` keyword
    arguments. Every DP16KD of the design is built here."""
    return Instance("DP16KD", **dp16kd_initvals(words, bits),
                    p_DATA_WIDTH_A=bits, p_DATA_WIDTH_B=bits, p_REGMODE_A=regmode_a,
                    p_REGMODE_B=regmode_b, p_RESETMODE="SYNC", p_ASYNC_RESET_RELEASE="SYNC",
                    p_CSDECODE_A="0b000", p_CSDECODE_B="0b000", p_WRITEMODE_A="NORMAL",
                    p_WRITEMODE_B="NORMAL", p_GSR="DISABLED", **ports)


def dp16kd_rom_block(m, name, words, bits, shift, en, reads):
    """One DP16KD (submodule ``name``) holding ``words`` in its x``bits`` mode
    (:data:`DP16KD_MODES`: word address on AD[13:shift]), read through one or both ports,
    each with its output register (REGMODE OUTREG), both enabled by ``en``. ``reads``:
    (side "A" or "B", word address, signal name) per port; an address one bit wider than the
    mode's wraps to word 0 (the spill word of :func:`stored_words`). Returns {side: 18-bit
    data}."""
    zero = Const(0, 1)
    ports, outs = {}, {}
    for side, word, label in reads:
        addr, dout = Signal(14, name=label), Signal(18, name=f"{label}_do")
        m.d.comb += addr[shift:].eq(word)                 # x{bits}: the word address
        ports.update({f"i_CLK{side}": ClockSignal(), f"i_CE{side}": en,
                      f"i_OCE{side}": en, f"i_WE{side}": zero, f"i_RST{side}": zero})
        ports.update({f"i_CS{side}{n}": zero for n in range(3)})
        ports.update({f"i_AD{side}{n}": addr[n] for n in range(14)})
        ports.update({f"i_DI{side}{n}": zero for n in range(18)})
        ports.update({f"o_DO{side}{n}": dout[n] for n in range(18)})
        outs[side] = dout
    m.submodules[name] = dp16kd(bits, words, "OUTREG", "OUTREG", **ports)
    return outs


def _rom_columns(m, rom, mode, sides, name):
    """The first ``words`` of ``rom``'s table in DP16KD blocks of ``mode`` (bits, words,
    shift) side by side for the width, read through ``sides`` ((side, port) pairs), the
    block of column c named ``name(c)``: yields (lo, hi, {side: 18-bit data}) per column,
    the column's bits lo..hi - 1."""
    bits, words, shift = mode
    for col in range(-(-rom.width // bits)):
        lo, hi = col * bits, min(rom.width, (col + 1) * bits)
        yield lo, hi, dp16kd_rom_block(m, name(col),
                                       [(x >> lo) & ((1 << (hi - lo)) - 1) for x in rom.init[:words]],
                                       bits, shift, rom.en,
                                       [(side, port.addr, f"{port.addr.name}_{side}{col}")
                                        for side, port in sides])


def _spill_select(m, rom, port, words):
    """A register, enabled by ``rom.en``, that is high when the data of ``port`` is the spill
    word's (:func:`stored_words`): its address was ``words``, ROM_LATENCY enabled cycles
    before (the blocks read word 0 then)."""
    last = Signal(name=f"{port.addr.name}_last")
    last_d = Signal(name=f"{port.addr.name}_last_d")
    with m.If(rom.en):
        m.d.sync += [last.eq(port.addr == words), last_d.eq(last)]
    return last_d


class ECP5Lowering:
    """The ECP5 forms of the registered elements, a method per primitive as in
    ``rtl/targets.Generic``, whose methods (reached through ``super()``) build whatever this
    leaves: mixed in before it as ``rtl/targets.ECP5``. Products become MULT18X18D blocks
    with their own input and output registers, which Yosys ``synth_ecp5`` does not infer
    from the generic netlist (a DSP block used without its registers adds its own delay to
    the cycle); tables become DP16KD block RAMs with their output registers (REGMODE
    OUTREG: the clock-to-out of an unregistered block RAM leaves the cycle)."""
    dsp_width = DSP_WIDTH
    bram_words = BRAM_WORDS
    bram_width = BRAM_WIDTH

    def product(self, m, unit):
        """One MULT18X18D with its input and output registers when the operands fit one DSP
        input; else (not a constant) one block per pair of 17-bit limbs (:meth:`split`),
        their shifted sum left to the cycle that reads ``p``; a constant operand: the generic
        form."""
        if fits_dsp(unit.a.shape(), unit.b.shape(), width=self.dsp_width):
            a, b, p = Signal(signed(18)), Signal(signed(18)), Signal(signed(36))
            m.d.comb += [a.eq(unit.a), b.eq(unit.b), unit.p.eq(p)]       # sign/zero-extend
            ports = {f"i_A{n}": a[n] for n in range(18)}
            ports.update({f"i_B{n}": b[n] for n in range(18)})
            ports.update({f"i_C{n}": Const(0, 1) for n in range(18)})
            ports.update({f"o_P{n}": p[n] for n in range(36)})
            regs = {f"p_REG_{r}_{k}": v for r in ("INPUTA", "INPUTB", "OUTPUT")
                    for k, v in (("CLK", "CLK0"), ("CE", "CE0"), ("RST", "RST0"))}
            m.submodules.dsp = Instance(
                "MULT18X18D", **regs, p_GSR="DISABLED", p_RESETMODE="SYNC",
                i_SIGNEDA=Const(1, 1), i_SIGNEDB=Const(1, 1), i_SOURCEA=Const(0, 1),
                i_SOURCEB=Const(0, 1), i_CLK0=ClockSignal(), i_CE0=unit.en, i_RST0=Const(0, 1),
                **ports)
        elif not isinstance(unit.b, Const):
            self.limb_sum(m, unit)
        else:
            super().product(m, unit)

    def split(self, a, b):
        """Every operand wider than one DSP input in 17-bit limbs (:func:`_limbs`)."""
        width = self.dsp_width
        return [[(0, v)] if fits_dsp(v.shape(), width=width) else _limbs(v, width - 1)
                for v in (a, b)]

    def rom_mode(self, rom):
        """(data bits, words, address shift) of the DP16KD mode of ROM ``rom``: one block
        (x18) up to 1024 words (1025 with the spill word of :func:`stored_words`), else the
        widest mode (:data:`DP16KD_MODES`) holding the words, blocks side by side for the
        width, at most :data:`ROM_MAX_BLOCKS`; None: the generic form (more than two ports,
        or too big)."""
        words = stored_words(rom.init)
        if len(rom.ports) > 2:
            return None
        if words <= self.bram_words:
            return DP16KD_MODES[0] if rom.width <= self.bram_width else None
        mode = next((m for m in DP16KD_MODES if m[1] >= words), None)
        if mode is None or -(-rom.width // mode[0]) > ROM_MAX_BLOCKS:
            return None
        return mode

    def ram_mode(self, ram):
        """(data bits, depth, address shift) of the DP16KD mode of RAM ``ram``: the widest
        that holds its depth; None: the generic form."""
        return next((m for m in DP16KD_MODES if m[1] >= ram.depth), None)

    def rom(self, m, rom):
        """DP16KD blocks in the mode :meth:`rom_mode` picks, side by side for the width,
        with both ports and their output registers; a spill word in a flip-flop, OR'ed in
        when the address wrapped to word 0. No mode: the generic form."""
        mode = self.rom_mode(rom)
        if mode is None:
            super().rom(m, rom)
            return
        words = mode[1]
        sides = list(zip("AB", rom.ports + rom.ports[:1], strict=False))[:max(2, len(rom.ports))]
        douts = {side: Signal(rom.width, name=f"{port.addr.name}_do{side}") for side, port in sides}
        for lo, hi, outs in _rom_columns(m, rom, mode, sides, lambda c: f"bram{c}" if c else "bram"):
            for side, dout in outs.items():
                m.d.comb += douts[side][lo:hi].eq(dout[:hi - lo])
        for side, port in sides[:len(rom.ports)]:
            data = douts[side]
            if rom.depth > words:               # the last word: address wrapped to word 0 (= 0)
                last_d = _spill_select(m, rom, port, words)
                data = data | Mux(last_d, rom.init[words], 0)
            m.d.comb += port.data.eq(data)

    def block_rom(self, m, rom):
        """The tables :meth:`rom` leaves to Yosys' block-RAM inference (more than two read
        ports, wider than 18 bits, deeper than 1024 words), which maps them without the
        block RAM's output register: each pair of read ports gets the table in the widest
        DP16KD mode holding ``depth - 1`` words, blocks side by side for the width, each
        with its output register; a last word past the mode's depth sits in a flip-flop.
        Else :meth:`rom`."""
        mode = next((md for md in DP16KD_MODES if md[1] >= rom.depth - 1), None)
        if self.rom_mode(rom) is not None or mode is None:
            self.rom(m, rom)
            return
        words = mode[1]
        for group in range(0, len(rom.ports), 2):
            ports = rom.ports[group:group + 2]
            columns = [[] for _ in ports]
            for lo, hi, outs in _rom_columns(m, rom, mode, list(zip("AB", ports, strict=False)),
                                             lambda c, g=group // 2: f"bram{g}_{c}"):
                for out, dout in zip(columns, outs.values(), strict=False):
                    out.append(dout[:hi - lo])
            for port, out in zip(ports, columns, strict=False):
                data = Cat(*out)
                if rom.depth > words:           # the last word: the address wrapped to word 0
                    last_d = _spill_select(m, rom, port, words)
                    data = Mux(last_d, rom.init[words], data)
                m.d.comb += port.data.eq(data)

    def ram(self, m, ram):
        """DP16KD blocks in the mode :meth:`ram_mode` picks, side by side for the width:
        port A writes, port B reads with its output register (REGMODE_B OUTREG); returns
        None (no Memory). No mode: the generic form."""
        mode = self.ram_mode(ram)
        if mode is None:
            return super().ram(m, ram)
        bits, _, shift = mode
        zero, one = Const(0, 1), Const(1, 1)
        w_addr, r_addr = Signal(14, name=f"{ram.name}_ada"), Signal(14, name=f"{ram.name}_adb")
        m.d.comb += [w_addr[shift:].eq(ram.w_addr), r_addr[shift:].eq(ram.r_addr)]
        if bits == 18:
            m.d.comb += w_addr[:2].eq(0b11)            # x18 mode: AD[1:0] are the byte enables
        w_data, r_data = Value.cast(ram.w_data), Signal(ram.width)
        m.d.comb += ram.r_data.eq(r_data)
        for col in range(-(-ram.width // bits)):
            lo, hi = col * bits, min(ram.width, (col + 1) * bits)
            dout = Signal(18, name=f"{ram.name}_do{col}")
            din = Signal(18, name=f"{ram.name}_di{col}")
            m.d.comb += [din.eq(w_data[lo:hi]), r_data[lo:hi].eq(dout[:hi - lo])]
            ports = dict(i_CLKA=ClockSignal(), i_CEA=one, i_OCEA=one, i_WEA=ram.w_en,
                         i_RSTA=zero, i_CLKB=ClockSignal(), i_CEB=ram.en, i_OCEB=ram.en,
                         i_WEB=zero, i_RSTB=zero)
            for side, addr in (("A", w_addr), ("B", r_addr)):
                ports.update({f"i_CS{side}{n}": zero for n in range(3)})
                ports.update({f"i_AD{side}{n}": addr[n] for n in range(14)})
            ports.update({f"i_DIA{n}": din[n] for n in range(18)})
            ports.update({f"i_DIB{n}": zero for n in range(18)})
            ports.update({f"o_DOB{n}": dout[n] for n in range(18)})
            m.submodules[f"bram{col}"] = dp16kd(
                bits, [(x >> lo) & ((1 << (hi - lo)) - 1) for x in ram.init], "NOREG", "OUTREG",
                **ports)
        return None
