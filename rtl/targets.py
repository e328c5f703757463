"""The elaboration targets and the registered elements they build (docs/architecture.md,
Interfaces): a product, a wide product, a ROM and a RAM, each enabled by one ``en`` (the
enclosing Pipe's constant 1, rtl/pipe.py), and a target object per target with a method per
primitive: :class:`Generic` (``target=None``: what every simulator runs and ``bumprtl
emit`` writes) and :class:`ECP5` (rtl/ecp5.py's MULT18X18D and DP16KD blocks with their
registers, for the ECP5 flow). An element holds its contract (ports, latency, contents)
and asks its target (:func:`form`) to build it: no element holds a target's code or
compares target names, so a target is added without editing one.
"""

import functools

from amaranth.hdl import Const, Elaboratable, Module, Shape, Signal
from amaranth.lib import wiring
from amaranth.lib.memory import Memory, MemoryData, ReadPort

from bumprtl.rtl.ecp5 import (
    DP16KD_MODES,
    DSP_WIDTH,
    NEAR_BLOCKS,
    ROM_MAX_BLOCKS,
    SPREAD_BLOCKS,
    ECP5Lowering,
    dp16kd_initvals,
    dp16kd_rom_block,
    fits_dsp,
    is_spread,
    rom_blocks,
    rom_spread,
)

__all__ = ["Generic", "ECP5", "GENERIC", "form", "RegisteredProduct", "WideProduct",
           "RegisteredROM", "RegisteredRAM", "rom_data", "read_port", "dp16kd_rom_block",
           "dp16kd_initvals",
           "fits_dsp", "product_latency", "limb_products", "DP16KD_MODES", "ROM_MAX_BLOCKS",
           "SPREAD_BLOCKS", "NEAR_BLOCKS", "rom_blocks", "is_spread",
           "DSP_WIDTH", "PRODUCT_LATENCY", "WIDE_PRODUCT_LATENCY", "ROM_LATENCY", "RAM_LATENCY"]

# Stages of Pipe.multiply: operand registers, product register.
PRODUCT_LATENCY = 2
# Stages of a RegisteredROM read: the synchronous read, the output register.
ROM_LATENCY = 2
# Stages of a RegisteredRAM read: the same two.
RAM_LATENCY = 2



@functools.lru_cache(maxsize=512)
def rom_data(shape, init):
    """The MemoryData of a read-only table (``shape`` a Shape, ``init`` a tuple of its rows):
    one per (shape, contents), made once however many designs elaborate the table (Amaranth
    checks each row as it is set). Shared only because nothing writes it: a simulator keeps
    one state per MemoryData, and a netlist one memory per Memory all the same."""
    return MemoryData(shape=shape, depth=len(init), init=init)


class RegisteredProduct(Elaboratable):
    """``p = a * b`` two ``en`` cycles after ``a``/``b`` (operand registers, product
    register): exactly the registers of an ECP5 MULT18X18D with REG_INPUTA/B and
    REG_OUTPUT, so on ECP5 (``target`` :class:`ECP5`) the whole product is one DSP block
    and the generic form (plain ``*`` between flip-flops) is what every simulator runs.
    Operands wider than one DSP input (not a constant) are split on ECP5
    (``ECP5Lowering.product``, rtl/ecp5.py) as in :class:`WideProduct`, one registered block per pair of limbs, but the limbs' shifted sum
    is left to the cycle that reads ``p`` (the latency stays PRODUCT_LATENCY; a unit that can
    spend a stage takes WideProduct instead)."""

    def __init__(self, a_shape, b_shape, name, b_const=None, target=None):
        """``b_const``: ``b`` is this constant (no operand register; a constant multiply
        stays one in the netlist counts of gen/flow/resources.py)."""
        self.target = target               # None (generic) or a target: form(target)
        self.a = Signal(a_shape, name=f"{name}_a")
        self.b = Signal(b_shape, name=f"{name}_b") if b_const is None else Const(b_const, b_shape)
        self.en = Signal(name=f"{name}_en")
        self.p = Signal((self.a * self.b).shape(), name=name)

    def elaborate(self, platform):
        m = Module()
        form(self.target).product(m, self)
        return m


# Stages of a WideProduct: a RegisteredProduct, then three more registers (the limb
# products held, their pair sums, the total).
WIDE_PRODUCT_LATENCY = PRODUCT_LATENCY + 3


class WideProduct(Elaboratable):
    """``p = a * b`` WIDE_PRODUCT_LATENCY ``en`` cycles after ``a``/``b``, for operands wider
    than one DSP input. Generic form: a :class:`RegisteredProduct`, then three registers
    (one product in the counts of gen/flow/resources.py). ECP5 form (``target`` with a
    MULT18X18D): each operand wider than a DSP input in 17-bit limbs (unsigned, the top limb
    of a signed operand signed), one RegisteredProduct per pair of limbs (a MULT18X18D with
    its input and output registers), each limb product copied into a fabric register
    (the DSP's output route ends in a flip-flop, nothing else in its cycle), then their
    shifted sum in two registers, pairs first: exact, since a b = sum_ij a_i b_j
    2**(s_i + s_j), and no more than one 2-operand carry chain in a cycle. Yosys would
    otherwise build the product from DSP blocks without their registers and a carry chain,
    all in one cycle. The target splits the operands (:func:`limb_products`); this element
    only sums."""

    def __init__(self, a_shape, b_shape, name, target=None):
        self.target = target
        self.a = Signal(a_shape, name=f"{name}_a")
        self.b = Signal(b_shape, name=f"{name}_b")
        self.en = Signal(name=f"{name}_en")
        self.p = Signal((self.a * self.b).shape(), name=name)

    def elaborate(self, platform):
        m = Module()
        terms = []
        for n, term in enumerate(limb_products(m, self.a, self.b, self.en, self.target)):
            held = Signal(term.shape(), name=f"limb{n}_q")
            with m.If(self.en):
                m.d.sync += held.eq(term)
            terms.append(held)
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
    enabled by ``en`` and shifted into place (their sum is the product), the operands split
    as ``form(target).split`` says: on ECP5 every operand wider than one DSP input in 17-bit
    limbs (``ECP5Lowering.split``, rtl/ecp5.py), one block per pair of limbs; on the generic
    target the one product."""
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


def product_latency(*shapes):
    """Stages of a registered product of operands of ``shapes``: PRODUCT_LATENCY
    (:meth:`Pipe.multiply`) when they fit one DSP input (:func:`fits_dsp`), else
    WIDE_PRODUCT_LATENCY (:meth:`Pipe.wide_multiply`, which registers the limbs' sum)."""
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
    """A ROM whose ``ports`` read ports (:func:`read_port`) give ``data`` ROM_LATENCY ``en``
    cycles after ``addr`` (synchronous read, then an output register), built by its target's
    ``rom`` (:func:`form`): on ECP5 (``target`` :class:`ECP5`) DP16KD blocks with their
    output registers (``ECP5Lowering.rom``, rtl/ecp5.py: one x18 block up to 1024 words,
    deeper tables in the widest mode that holds them, a spill word in a flip-flop);
    elsewhere (``target=None``) an Amaranth Memory and a register (:meth:`Generic.rom`).
    ``init`` is the contents, ``depth`` and ``width`` the table's size."""

    def __init__(self, init, shape, ports, name, target=None):
        self.init, self.shape, self.name, self.target = [int(x) for x in init], shape, name, target
        self.depth, self.width = len(self.init), Shape.cast(shape).width
        addr_bits = max(1, (len(self.init) - 1).bit_length())
        self.en = Signal(name=f"{name}_en")
        self.ports = [read_port(addr_bits, shape, f"{name}_p{n}") for n in range(ports)]

    @property
    def spread(self):
        """The ECP5 form spans more than SPREAD_BLOCKS block RAMs side by side (on every
        target: the generic form is built alike, so both run the same cycles)."""
        return rom_spread(self.init, self.width, len(self.ports))

    def elaborate(self, platform):
        m = Module()
        form(self.target).rom(m, self)
        return m


class RegisteredRAM(Elaboratable):
    """A RAM with one host write port (``w_en``, ``w_addr``, ``w_data``) and one read port
    whose ``r_data`` comes RAM_LATENCY ``en`` cycles after ``r_addr`` (synchronous read, then
    an output register), as :class:`RegisteredROM`. A read in the cycle of a write to the
    same word returns the old word. Built by its target's ``ram`` (:func:`form`): on ECP5
    (``target`` :class:`ECP5`, depth <= 16384) DP16KD blocks, port A writing, port B
    reading with its output register (``ECP5Lowering.ram``, rtl/ecp5.py); elsewhere an
    Amaranth Memory and a register (:meth:`Generic.ram`). ``writable = False``: no write
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


# --- the targets: one object per target, a method per primitive --------------------------------

class Generic:
    """The generic target (``target=None``): what every simulator runs and ``bumprtl emit``
    writes. A method per primitive builds it into ``m``: :meth:`product` (operand registers
    and a product register), :meth:`split` (the operand limbs of a wide product: none),
    :meth:`rom` and :meth:`ram` (an Amaranth Memory with its registers), :meth:`block_rom`
    (a table with more read ports: the same Memory). A target subclasses it and overrides
    what it builds otherwise (:class:`ECP5`; :meth:`limb_sum` for one whose multipliers are
    narrower than the operands)."""

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

    def limb_sum(self, m, unit):
        """:class:`RegisteredProduct` ``unit`` as the shifted sum of its limb products
        (:func:`limb_products`, the operands split as :meth:`split` says), the sum left to
        the cycle that reads ``p``: for a target whose multipliers are narrower than the
        operands."""
        terms = limb_products(m, unit.a, unit.b, unit.en, self)
        m.d.comb += unit.p.eq(sum(terms[1:], terms[0]))

    def rom(self, m, rom):
        """:class:`RegisteredROM` ``rom``: an Amaranth Memory with a synchronous read port
        per port and an output register."""
        m.submodules.mem = mem = Memory(data=rom_data(rom.shape, tuple(rom.init)))
        for port in rom.ports:
            read = mem.read_port(domain="sync")
            m.d.comb += [read.en.eq(rom.en), read.addr.eq(port.addr)]
            with m.If(rom.en):
                m.d.sync += port.data.eq(read.data)

    def block_rom(self, m, rom):
        """A table with more read ports than a block RAM has (rtl/lee.py's ``BlockROM``):
        the RegisteredROM's own form on this target."""
        self.rom(m, rom)

    def ram(self, m, ram):
        """:class:`RegisteredRAM` ``ram``: an Amaranth Memory (its write port unless not
        ``writable``), a synchronous read and an output register; returns the Memory (a
        target that builds none returns None)."""
        m.submodules.mem = mem = Memory(shape=ram.shape, depth=ram.depth, init=ram.init)
        if ram.writable:
            wp = mem.write_port()
            m.d.comb += [wp.en.eq(ram.w_en), wp.addr.eq(ram.w_addr), wp.data.eq(ram.w_data)]
        rp = mem.read_port(domain="sync")
        m.d.comb += [rp.en.eq(ram.en), rp.addr.eq(ram.r_addr)]
        with m.If(ram.en):
            m.d.sync += ram.r_data.eq(rp.data)
        return mem


GENERIC = Generic()


def form(target):
    """The target object that builds the primitives: ``target``, or :data:`GENERIC` for
    None."""
    return GENERIC if target is None else target


class ECP5(ECP5Lowering, Generic):
    """The ECP5 target, passed as ``target=ECP5()`` to a unit's constructor by the ECP5 flow
    (gen/flow/fpga.py) and threaded down to its Pipe, RegisteredROM and
    RegisteredProduct (``target=None``, the default, is the generic form): the methods of
    rtl/ecp5.py's :class:`ECP5Lowering` (products as MULT18X18D blocks, tables as DP16KD
    block RAMs, each with its registers), the generic form (:class:`Generic`) for whatever
    they leave. Every other flow elaborates the generic form."""
