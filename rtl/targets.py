"""The elaboration targets and the registered elements they build (docs/architecture.md,
Interfaces): a product, a wide product, a ROM and a RAM, each enabled by one ``en`` (a
StallPipe's ``adv``, rtl/pipe.py), and a target object per target with a method per
primitive: :class:`Generic` (``target=None``: what every simulator runs and ``bumprtl
emit`` writes) and :class:`ECP5` (MULT18X18D and DP16KD blocks with their registers, for
the ECP5 flow). An element asks its target (:func:`form`) to build it; no element compares
target names.
"""

from amaranth.hdl import (
    ClockSignal,
    Const,
    Elaboratable,
    Instance,
    Module,
    Mux,
    Shape,
    Signal,
    Value,
    signed,
)
from amaranth.lib import wiring
from amaranth.lib.memory import Memory, ReadPort

__all__ = ["Generic", "ECP5", "GENERIC", "form", "RegisteredProduct", "WideProduct",
           "RegisteredROM", "RegisteredRAM", "read_port", "dp16kd_rom_block", "dp16kd_initvals",
           "fits_dsp", "product_latency", "limb_products", "DP16KD_MODES", "ROM_MAX_BLOCKS",
           "SPREAD_BLOCKS", "NEAR_BLOCKS", "rom_blocks", "is_spread",
           "DSP_WIDTH", "PRODUCT_LATENCY", "WIDE_PRODUCT_LATENCY", "ROM_LATENCY", "RAM_LATENCY"]

# Width of one signed DSP input (ECP5's MULT18X18D): fits_dsp's default.
DSP_WIDTH = 18
# Stages of StallPipe.multiply: operand registers, product register.
PRODUCT_LATENCY = 2
# Stages of a RegisteredROM read: the synchronous read, the output register.
ROM_LATENCY = 2
# Stages of a RegisteredRAM read: the same two.
RAM_LATENCY = 2


class RegisteredProduct(Elaboratable):
    """``p = a * b`` two ``en`` cycles after ``a``/``b`` (operand registers, product
    register): exactly the registers of an ECP5 MULT18X18D with REG_INPUTA/B and
    REG_OUTPUT, so on ECP5 (``target`` :class:`ECP5`) the whole product is one DSP block
    and the generic form (plain ``*`` between flip-flops) is what every simulator runs.
    Operands wider than one DSP input (not a constant) are split on ECP5 as in
    :class:`WideProduct`, one registered block per pair of limbs, but the limbs' shifted sum
    is left to the cycle that reads ``p`` (the latency stays PRODUCT_LATENCY; a unit that can
    spend a stage takes WideProduct instead)."""

    def __init__(self, a_shape, b_shape, name, b_const=None, target=None):
        """``b_const``: ``b`` is this constant (no operand register; a constant multiply
        stays one in the netlist counts of gen/flow/resources.py)."""
        self.target = target               # None (generic) or ECP5
        self.a = Signal(a_shape, name=f"{name}_a")
        self.b = Signal(b_shape, name=f"{name}_b") if b_const is None else Const(b_const, b_shape)
        self.en = Signal(name=f"{name}_en")
        self.p = Signal((self.a * self.b).shape(), name=name)

    def elaborate(self, platform):
        m = Module()
        form(self.target).product(m, self)
        return m


# Stages of a WideProduct: a RegisteredProduct, then two more registers (the limbs' sums).
WIDE_PRODUCT_LATENCY = PRODUCT_LATENCY + 2


def _limbs(value, step):
    """(shift, limb) pairs of ``value`` in ``step``-bit limbs, low first: every limb unsigned
    but the top one of a signed value, which keeps the sign (sum of limb << shift = value)."""
    shape = value.shape()
    limbs = [(lo, value[lo:lo + step]) for lo in range(0, shape.width, step)]
    if shape.signed:
        limbs[-1] = (limbs[-1][0], limbs[-1][1].as_signed())
    return limbs


class WideProduct(Elaboratable):
    """``p = a * b`` WIDE_PRODUCT_LATENCY ``en`` cycles after ``a``/``b``, for operands wider
    than one DSP input. Generic form: a :class:`RegisteredProduct`, then two registers (one
    product in the counts of gen/flow/resources.py). ECP5 form (``target`` with a
    MULT18X18D): each operand wider than a DSP input in 17-bit limbs (unsigned, the top limb
    of a signed operand signed), one RegisteredProduct per pair of limbs (a MULT18X18D with
    its input and output registers), their shifted sum in the two registers, pairs first:
    exact, since a b = sum_ij a_i b_j 2**(s_i + s_j), and no more than one 2-operand carry
    chain follows a DSP output in a cycle. Yosys would otherwise build the product from DSP
    blocks without their registers and a carry chain, all in one cycle."""

    def __init__(self, a_shape, b_shape, name, target=None):
        self.target = target
        self.a = Signal(a_shape, name=f"{name}_a")
        self.b = Signal(b_shape, name=f"{name}_b")
        self.en = Signal(name=f"{name}_en")
        self.p = Signal((self.a * self.b).shape(), name=name)

    def elaborate(self, platform):
        m = Module()
        terms = limb_products(m, self.a, self.b, self.en, self.target)
        pairs = []
        for n in range(0, len(terms), 2):
            pair = Signal(self.p.shape(), name=f"pair{n // 2}")
            with m.If(self.en):
                m.d.sync += pair.eq(sum(terms[n + 1:n + 2], terms[n]))
            pairs.append(pair)
        with m.If(self.en):
            m.d.sync += self.p.eq(sum(pairs[1:], pairs[0]))
        return m


def limb_products(m, a, b, en, target):
    """The partial products of ``a * b`` as submodules of ``m``, each a RegisteredProduct
    enabled by ``en`` and shifted into place (their sum is the product): on a ``target`` with
    a MULT18X18D every operand wider than one DSP input in 17-bit limbs (:func:`_limbs`),
    one block per pair of limbs; elsewhere the one product."""
    split = form(target).split(a, b)
    terms = []
    for lo_a, limb_a in split[0]:
        for lo_b, limb_b in split[1]:
            name = f"limb{len(terms)}"
            unit = RegisteredProduct(limb_a.shape(), limb_b.shape(), name, target=target)
            m.submodules[name] = unit
            m.d.comb += [unit.a.eq(limb_a), unit.b.eq(limb_b), unit.en.eq(en)]
            terms.append(unit.p << (lo_a + lo_b))
    return terms


def fits_dsp(*shapes, width=DSP_WIDTH):
    """Every shape is one signed ``width``-bit DSP input (an unsigned one needs a zero bit)."""
    return all(Shape.cast(s).width + (not Shape.cast(s).signed) <= width for s in shapes)


def product_latency(*shapes):
    """Stages of a registered product of operands of ``shapes``: PRODUCT_LATENCY
    (:meth:`StallPipe.multiply`) when they fit one DSP input (:func:`fits_dsp`), else
    WIDE_PRODUCT_LATENCY (:meth:`StallPipe.wide_multiply`, which registers the limbs' sum)."""
    return PRODUCT_LATENCY if fits_dsp(*shapes) else WIDE_PRODUCT_LATENCY


def read_port(addr_bits, shape, name):
    """One read port of a :class:`RegisteredROM`: an interface of
    ``amaranth.lib.memory.ReadPort.Signature`` (``addr`` in, ``data`` out, as a Memory's read
    port; its ``en`` is unused, the ROM's own ``en`` enables every port) whose signals are
    named ``{name}_addr`` and ``{name}_data``."""
    signature = ReadPort.Signature(addr_width=addr_bits, shape=shape)
    port = wiring.PureInterface(signature, path=(name,))
    port.addr = Signal(addr_bits, name=f"{name}_addr")
    port.data = Signal(shape, name=f"{name}_data")
    assert signature.is_compliant(port)
    return port


class RegisteredROM(Elaboratable):
    """A ROM whose ``ports`` read ports (:func:`read_port`) give ``data`` ROM_LATENCY ``en`` cycles after
    ``addr`` (synchronous read, then an output register). On ECP5 (``target``
    :class:`ECP5`) that is DP16KD blocks (one x18 block up to 1024 words, deeper tables in
    the widest mode that holds them, blocks side by side for the width: :meth:`mode`) with
    both ports and their own output registers (REGMODE OUTREG: the clock-to-out of an
    unregistered block RAM leaves the cycle); a table of 2**n + 1 words whose word 0 is 0
    keeps its last word in a flip-flop (the address wraps to word 0 and the word is OR'ed
    in). Elsewhere (``target=None``): an Amaranth Memory and a register. ``depth`` and
    ``width`` are the table's size."""

    def __init__(self, init, shape, ports, name, target=None):
        self.init, self.shape, self.name, self.target = [int(x) for x in init], shape, name, target
        self.depth, self.width = len(self.init), Shape.cast(shape).width
        addr_bits = max(1, (len(self.init) - 1).bit_length())
        self.en = Signal(name=f"{name}_en")
        self.ports = [read_port(addr_bits, shape, f"{name}_p{n}") for n in range(ports)]

    def _spills(self):
        """A table of 2**n + 1 words whose word 0 is 0 keeps its last word in a flip-flop."""
        n = self.depth - 1
        return n >= 1 and n & (n - 1) == 0 and self.init[0] == 0

    @property
    def spread(self):
        """The ECP5 form spans more than SPREAD_BLOCKS block RAMs side by side (on every
        target: the generic form is built alike, so both run the same cycles)."""
        return len(self.ports) <= 2 and is_spread(self.depth - self._spills(), self.width)

    def mode(self, target):
        """(data bits, words, address shift) of the DP16KD mode of the ECP5 form: one block
        (x18) up to 1024 words (1025 with the spill word), else the widest mode
        (:data:`DP16KD_MODES`) holding the words, blocks side by side for the width, at most
        :data:`ROM_MAX_BLOCKS`; None: the generic form (more than two ports, or too big)."""
        words = self.depth - self._spills()
        if len(self.ports) > 2:
            return None
        if words <= target.bram_words:
            return DP16KD_MODES[0] if self.width <= target.bram_width else None
        mode = next((m for m in DP16KD_MODES if m[1] >= words), None)
        if mode is None or -(-self.width // mode[0]) > ROM_MAX_BLOCKS:
            return None
        return mode

    def elaborate(self, platform):
        m = Module()
        form(self.target).rom(m, self)
        return m

    def generic(self, m):
        """The generic form: an Amaranth Memory with a synchronous read port per port and
        an output register."""
        m.submodules.mem = mem = Memory(shape=self.shape, depth=len(self.init), init=self.init)
        for port in self.ports:
            read = mem.read_port(domain="sync")
            m.d.comb += [read.en.eq(self.en), read.addr.eq(port.addr)]
            with m.If(self.en):
                m.d.sync += port.data.eq(read.data)

    def dp16kd(self, m, bits, words, shift):
        """The ECP5 form in mode (``bits``, ``words``, ``shift``) (:meth:`ECP5.rom`)."""
        sides = list(zip("AB", self.ports + self.ports[:1], strict=False))[:max(2, len(self.ports))]
        douts = {side: Signal(self.width, name=f"{port.addr.name}_do{side}") for side, port in sides}
        for col in range(-(-self.width // bits)):
            lo, hi = col * bits, min(self.width, (col + 1) * bits)
            outs = dp16kd_rom_block(m, f"bram{col}" if col else "bram",
                                    [(x >> lo) & ((1 << (hi - lo)) - 1) for x in self.init[:words]],
                                    bits, shift, self.en,
                                    [(side, port.addr, f"{port.addr.name}_{side}{col}")
                                     for side, port in sides])
            for side, dout in outs.items():
                m.d.comb += douts[side][lo:hi].eq(dout[:hi - lo])
        for side, port in sides[:len(self.ports)]:
            data = douts[side]
            if self.depth > words:              # the last word: address wrapped to word 0 (= 0)
                last = Signal(name=f"{port.addr.name}_last")
                last_d = Signal(name=f"{port.addr.name}_last_d")
                with m.If(self.en):
                    m.d.sync += [last.eq(port.addr == words), last_d.eq(last)]
                data = data | Mux(last_d, self.init[words], 0)
            m.d.comb += port.data.eq(data)


def dp16kd_rom_block(m, name, words, bits, shift, en, reads):
    """One DP16KD (submodule ``name``) holding ``words`` in its x``bits`` mode
    (:data:`DP16KD_MODES`: word address on AD[13:shift]), read through one or both ports,
    each with its output register (REGMODE OUTREG), both enabled by ``en``. ``reads``:
    (side "A" or "B", word address, signal name) per port; an address one bit wider than the
    mode's wraps to word 0 (the spill word of :class:`RegisteredROM`). Returns {side: 18-bit
    data}."""
    zero = Const(0, 1)
    params = dp16kd_initvals(words, bits)
    params.update(p_DATA_WIDTH_A=bits, p_DATA_WIDTH_B=bits, p_REGMODE_A="OUTREG",
                  p_REGMODE_B="OUTREG", p_RESETMODE="SYNC", p_ASYNC_RESET_RELEASE="SYNC",
                  p_CSDECODE_A="0b000", p_CSDECODE_B="0b000", p_WRITEMODE_A="NORMAL",
                  p_WRITEMODE_B="NORMAL", p_GSR="DISABLED")
    outs = {}
    for side, word, label in reads:
        addr, dout = Signal(14, name=label), Signal(18, name=f"{label}_do")
        m.d.comb += addr[shift:].eq(word)                 # x{bits}: the word address
        params.update({f"i_CLK{side}": ClockSignal(), f"i_CE{side}": en,
                       f"i_OCE{side}": en, f"i_WE{side}": zero, f"i_RST{side}": zero})
        params.update({f"i_CS{side}{n}": zero for n in range(3)})
        params.update({f"i_AD{side}{n}": addr[n] for n in range(14)})
        params.update({f"i_DI{side}{n}": zero for n in range(18)})
        params.update({f"o_DO{side}{n}": dout[n] for n in range(18)})
        outs[side] = dout
    m.submodules[name] = Instance("DP16KD", **params)
    return outs


# Most DP16KD blocks side by side that one ROM of more than 1024 words is given on ECP5:
# an 8193 x 17 table (the quarter-wave sine of 15-bit angles at B = 16 stored whole) is nine
# x2 blocks, read without an output multiplexer (the generic form, which Yosys maps with
# one, is slower: docs/report.md).
ROM_MAX_BLOCKS = 9
# A memory of more DP16KD than this side by side is "spread" over the die: it gets an enable
# flip-flop of its own in lock step (pipe.StallPipe.rom / ram) and its reads a second address
# register (sincos.near_sine, bumpfetch.BumpMapFetch), so neither the clock enable nor the
# address crosses the spread in the cycle that computes it. The threshold is the widest
# memory whose rows place without it (bumprtl report fpga, docs/report.md).
SPREAD_BLOCKS = 8
# A quarter-wave sine ROM of more DP16KD than this side by side has its reads take a second
# address register beside its blocks (sincos.near_sine): without it the angle -> mirrored
# address route across the blocks is the worst path of the widest sine ROMs (docs/report.md).
NEAR_BLOCKS = 6

# DP16KD data widths (one port) and their depths: 18 Kbit as 1024 x 18 ... 16384 x 1.
DP16KD_MODES = ((18, 1024, 4), (9, 2048, 3), (4, 4096, 2), (2, 8192, 1), (1, 16384, 0))


def rom_blocks(words, width):
    """DP16KD blocks side by side of a ``words`` x ``width`` table in :meth:`RegisteredROM.mode`'s
    mode (one x18 block up to 1024 words, else the widest mode that holds the words); 0 when
    no mode holds it."""
    if words <= ECP5.bram_words:
        return 1 if width <= ECP5.bram_width else 0
    mode = next((m for m in DP16KD_MODES if m[1] >= words), None)
    return 0 if mode is None else -(-width // mode[0])


def is_spread(words, width):
    """A ``words`` x ``width`` memory spans more than SPREAD_BLOCKS block RAMs side by side
    (:func:`rom_blocks`): the rule of ``RegisteredROM.spread`` and ``RegisteredRAM.spread``,
    and of the latencies that depend on it before any memory is built."""
    return rom_blocks(words, width) > SPREAD_BLOCKS


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


class RegisteredRAM(Elaboratable):
    """A RAM with one host write port (``w_en``, ``w_addr``, ``w_data``) and one read port
    whose ``r_data`` comes RAM_LATENCY ``en`` cycles after ``r_addr`` (synchronous read, then
    an output register), as :class:`RegisteredROM`. A read in the cycle of a write to the
    same word returns the old word. On ECP5 (``target`` :class:`ECP5`, depth <= 16384) it is
    DP16KD blocks in the widest mode (:data:`DP16KD_MODES`) that holds ``depth`` words, side
    by side for the width: port A writes, port B reads with its output register (REGMODE_B
    OUTREG); elsewhere an Amaranth Memory and a register. ``writable = False``: no write
    port at all (a memory whose contents are its ``init``), ``w_*`` unused."""

    def __init__(self, depth, shape, name, init=None, target=None, writable=True):
        self.depth, self.shape, self.name, self.target = depth, shape, name, target
        self.writable = writable
        self.width = Shape.cast(shape).width
        self.init = [int(x) for x in init] if init is not None else []
        self.en = Signal(name=f"{name}_en")
        self.r_addr = Signal(range(depth), name=f"{name}_r_addr")
        self.r_data = Signal(shape, name=f"{name}_r_data")
        self.w_en = Signal(name=f"{name}_w_en")
        self.w_addr = Signal(range(depth), name=f"{name}_w_addr")
        self.w_data = Signal(shape, name=f"{name}_w_data")

    def mode(self):
        """(data width, depth, address shift) of the DP16KD mode used on ECP5, or None."""
        return next((m for m in DP16KD_MODES if m[1] >= self.depth), None)

    @property
    def spread(self):
        """The ECP5 form spans more than SPREAD_BLOCKS block RAMs side by side."""
        return is_spread(self.depth, self.width)

    def elaborate(self, platform):
        m = Module()
        mem = form(self.target).ram(m, self)
        # the formal contract's observer (rtl/pipe.pipe_observer) sees the generic form's Memory
        observer = getattr(platform, "pipe_observer", None)
        if observer is not None and mem is not None:
            observer.ram_built(self, mem)
        return m

    def generic(self, m):
        """The generic form: an Amaranth Memory, a synchronous read and an output register;
        returns the Memory."""
        m.submodules.mem = mem = Memory(shape=self.shape, depth=self.depth, init=self.init)
        if self.writable:
            wp = mem.write_port()
            m.d.comb += [wp.en.eq(self.w_en), wp.addr.eq(self.w_addr), wp.data.eq(self.w_data)]
        rp = mem.read_port(domain="sync")
        m.d.comb += [rp.en.eq(self.en), rp.addr.eq(self.r_addr)]
        with m.If(self.en):
            m.d.sync += self.r_data.eq(rp.data)
        return mem

    def dp16kd(self, m, bits, words, shift):
        """The ECP5 form in mode (``bits``, ``words``, ``shift``) (:meth:`ECP5.ram`)."""
        zero, one = Const(0, 1), Const(1, 1)
        w_addr, r_addr = Signal(14, name=f"{self.name}_ada"), Signal(14, name=f"{self.name}_adb")
        m.d.comb += [w_addr[shift:].eq(self.w_addr), r_addr[shift:].eq(self.r_addr)]
        if bits == 18:
            m.d.comb += w_addr[:2].eq(0b11)            # x18 mode: AD[1:0] are the byte enables
        w_data, r_data = Value.cast(self.w_data), Signal(self.width)
        m.d.comb += self.r_data.eq(r_data)
        for col in range(-(-self.width // bits)):
            lo, hi = col * bits, min(self.width, (col + 1) * bits)
            dout = Signal(18, name=f"{self.name}_do{col}")
            din = Signal(18, name=f"{self.name}_di{col}")
            m.d.comb += [din.eq(w_data[lo:hi]), r_data[lo:hi].eq(dout[:hi - lo])]
            init = [(x >> lo) & ((1 << (hi - lo)) - 1) for x in self.init]
            params = dp16kd_initvals(init, bits)
            params.update(p_DATA_WIDTH_A=bits, p_DATA_WIDTH_B=bits, p_REGMODE_A="NOREG",
                          p_REGMODE_B="OUTREG", p_RESETMODE="SYNC", p_ASYNC_RESET_RELEASE="SYNC",
                          p_CSDECODE_A="0b000", p_CSDECODE_B="0b000", p_WRITEMODE_A="NORMAL",
                          p_WRITEMODE_B="NORMAL", p_GSR="DISABLED")
            params.update(i_CLKA=ClockSignal(), i_CEA=self.w_en, i_OCEA=one, i_WEA=self.w_en,
                          i_RSTA=zero, i_CLKB=ClockSignal(), i_CEB=self.en, i_OCEB=self.en,
                          i_WEB=zero, i_RSTB=zero)
            for side, addr in (("A", w_addr), ("B", r_addr)):
                params.update({f"i_CS{side}{n}": zero for n in range(3)})
                params.update({f"i_AD{side}{n}": addr[n] for n in range(14)})
            params.update({f"i_DIA{n}": din[n] for n in range(18)})
            params.update({f"i_DIB{n}": zero for n in range(18)})
            params.update({f"o_DOB{n}": dout[n] for n in range(18)})
            m.submodules[f"bram{col}"] = Instance("DP16KD", **params)


# --- the targets: one object per target, a method per primitive --------------------------------

class Generic:
    """The generic target (``target=None``): what every simulator runs and ``bumprtl emit``
    writes. A method per primitive builds it into ``m``: :meth:`product` (operand registers
    and a product register), :meth:`split` (the operand limbs of a wide product: none),
    :meth:`rom` and :meth:`ram` (an Amaranth Memory with its registers), :meth:`block_rom`
    (a table with more read ports: the same Memory)."""

    def product(self, m, unit):
        """:class:`RegisteredProduct` ``unit``: operand registers, product register."""
        a = Signal.like(unit.a, name="a_r")
        b = unit.b if isinstance(unit.b, Const) else Signal.like(unit.b, name="b_r")
        with m.If(unit.en):
            m.d.sync += [a.eq(unit.a), unit.p.eq(a * b)]
            if b is not unit.b:
                m.d.sync += b.eq(unit.b)

    def split(self, a, b):
        """The (shift, limb) pairs of each operand of a wide product: each whole."""
        return [[(0, a)], [(0, b)]]

    def rom(self, m, rom):
        """:class:`RegisteredROM` ``rom``."""
        rom.generic(m)

    def block_rom(self, m, rom):
        """A table with more read ports than a block RAM has (rtl/lee.py's ``BlockROM``):
        the RegisteredROM's own form on this target."""
        self.rom(m, rom)

    def ram(self, m, ram):
        """:class:`RegisteredRAM` ``ram``; returns its Memory (None: no Memory)."""
        return ram.generic(m)


GENERIC = Generic()


def form(target):
    """The target object that builds the primitives: ``target``, or :data:`GENERIC` for
    None."""
    return GENERIC if target is None else target


class ECP5(Generic):
    """The ECP5 target, passed as ``target=ECP5()`` to a unit's constructor by the ECP5 flow
    (gen/flow/fpga.py) and threaded down to its StallPipe, RegisteredROM and
    RegisteredProduct (``target=None``, the default, is the generic form): products
    become MULT18X18D blocks with their own input and output registers, which Yosys
    ``synth_ecp5`` does not infer from the generic netlist (a DSP block used without its
    registers adds its own delay to the cycle); tables become DP16KD block RAMs with their
    output registers. Every other flow elaborates the generic form."""
    dsp_width = DSP_WIDTH
    bram_words = 1024            # DP16KD as 1024 x 18 with its output register (REGMODE OUTREG)
    bram_width = 18

    def product(self, m, unit):
        """One MULT18X18D with its input and output registers when the operands fit one DSP
        input; else (not a constant) one block per pair of 17-bit limbs, their shifted sum
        left to the cycle that reads ``p``; a constant operand: the generic form."""
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
            return
        if not isinstance(unit.b, Const):
            terms = limb_products(m, unit.a, unit.b, unit.en, self)
            m.d.comb += unit.p.eq(sum(terms[1:], terms[0]))
            return
        super().product(m, unit)

    def split(self, a, b):
        """Every operand wider than one DSP input in 17-bit limbs (:func:`_limbs`)."""
        width = self.dsp_width
        return [[(0, v)] if fits_dsp(v.shape(), width=width) else _limbs(v, width - 1)
                for v in (a, b)]

    def rom(self, m, rom):
        """DP16KD blocks in the mode :meth:`RegisteredROM.mode` picks, else the generic form."""
        mode = rom.mode(self)
        if mode is not None:
            rom.dp16kd(m, *mode)
        else:
            rom.generic(m)

    def block_rom(self, m, rom):
        """The tables :meth:`rom` leaves to Yosys (more than two read ports, wider than 18
        bits, deeper than 1024 words): each pair of read ports in the widest DP16KD mode
        holding ``depth - 1`` words (``rom.dp16kd_pairs``); else :meth:`rom`."""
        mode = next((md for md in DP16KD_MODES if md[1] >= rom.depth - 1), None)
        if rom.mode(self) is not None or mode is None:
            self.rom(m, rom)
        else:
            rom.dp16kd_pairs(m, *mode)

    def ram(self, m, ram):
        """DP16KD blocks in the widest mode holding the depth, else the generic form."""
        mode = ram.mode()
        if mode is None:
            return ram.generic(m)
        ram.dp16kd(m, *mode)
        return None
