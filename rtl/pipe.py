"""Free-running pipes with credit flow control at their edges (docs/architecture.md,
Interfaces and The credit loop).

The datapath never stops: every register, product and memory read of a unit is clocked
every cycle (no clock enable), and a valid bit travels with each pixel; a bubble is a pixel
with valid low. Flow control lives only at the edges (:class:`CreditEdge`): the input takes
a pixel only while a credit is free, and a FIFO behind the last stage, one entry per
credit, gives the credit back when its pixel leaves. A unit on its own (``credit=True``,
the default) has its own edge; inside a ``BumpPipeline`` (rtl/pipeline.py) the units are
built with ``credit=False`` and chained valid to valid, and the pipeline has the one edge.
Either way the ports obey the stream rules: ``o.valid`` and ``o.payload`` come from the
FIFO's output register and never depend on ``o.ready``; ``i.ready`` is a register ("a
credit is free") and never depends on ``i.valid`` or ``o.ready`` in the same cycle.
"""

from amaranth.hdl import Array, Assert, Const, Elaboratable, Fragment, Module, Shape, Signal, Value
from amaranth.lib import stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.config import BumpError

# The registered elements a Pipe builds, and the targets that build them (rtl/targets.py);
# the names are also read from here by the units.
from bumprtl.rtl.targets import (
    DP16KD_MODES,
    ECP5,
    PRODUCT_LATENCY,
    RAM_LATENCY,
    ROM_LATENCY,
    WIDE_PRODUCT_LATENCY,
    RegisteredProduct,
    RegisteredRAM,
    RegisteredROM,
    WideProduct,
    dp16kd_initvals,
    dp16kd_rom_block,
    fits_dsp,
    limb_products,
    product_latency,
    read_port,
)

__all__ = ["Pipe", "PipeUnit", "MemoryRecords", "unit_memory_records", "CreditEdge", "EDGE_LATENCY", "CREDIT_RETURN", "min_fifo_depth", "check_fifo_depth", "CreditFIFO", "add_credit_edge",
           "RegisteredProduct", "WideProduct", "RegisteredROM",
           "RegisteredRAM", "read_port", "dp16kd_rom_block", "fits_dsp", "product_latency",
           "limb_products", "PRODUCT_LATENCY",
           "WIDE_PRODUCT_LATENCY", "ROM_LATENCY", "RAM_LATENCY", "ECP5", "dp16kd_initvals",
           "DP16KD_MODES", "pipe_observer"]

# Cycles from a pixel written into the edge's FIFO to the same pixel offered at ``o``:
# the write (the FIFO's memory), its prefetch register, then its output register.
EDGE_LATENCY = 3
# Cycles from a pixel taken at ``o`` to its credit free at ``i``: the credit count is a
# register, so the credit is counted the cycle after the pixel leaves.
CREDIT_RETURN = 1
# Bits of the FIFO's word read at one copy of its read pointer (CreditFIFO).
READ_SLICE = 16
# Address bits of one bank of the FIFO's memory (CreditFIFO): 16 words, one ECP5 LUT RAM
# (TRELLIS_DPR16X4) deep, so a bank's read reaches its prefetch register through no
# multiplexer.
BANK_BITS = 4
# The widest FIFO word kept in banks: each bank's prefetch register multiplies the flip-flops
# every load of the FIFO's control reaches, and past this width they spread the FIFO so far
# that the control's routes bind instead of the multiplexer they save; a wider FIFO reads its
# whole memory through the multiplexer into one prefetch register.
BANKED_WIDTH_MAX = 8 * READ_SLICE


def min_fifo_depth(latency):
    """The least FIFO depth (= credits) that keeps a pipe of ``latency`` stages at one pixel
    a clock while the sink takes one a clock: a credit spent in cycle t comes back in cycle
    t + latency + EDGE_LATENCY + CREDIT_RETURN (the pixel's stages, the FIFO, the count), so
    that many pixels are between the input and the credit count at once
    (docs/architecture.md, The credit loop)."""
    return latency + EDGE_LATENCY + CREDIT_RETURN


def check_fifo_depth(latency, depth=None):
    """``depth`` (None: :func:`min_fifo_depth` ``(latency)``); BumpError naming both numbers
    when it is below that minimum or not an int."""
    need = min_fifo_depth(latency)
    if depth is None:
        return need
    if not isinstance(depth, int) or isinstance(depth, bool) or depth < need:
        raise BumpError(f"fifo_depth must be an int >= {need}, the minimum for a pipe of "
                        f"latency {latency} (latency + {EDGE_LATENCY} FIFO stages + "
                        f"{CREDIT_RETURN} credit return), got {depth!r}")
    return depth


class MemoryRecords:
    """An elaboration's platform that collects what every unit's :class:`Pipe` built, so
    that elaborating a unit changes nothing of the unit: ``Fragment.get(unit, records)``,
    then :meth:`of` ``(unit)`` is the unit's memories (:attr:`Pipe.memories`; a unit that is
    no PipeUnit answers with its own ``memories`` attribute, e.g. the texel cache's). Its
    ``pipe_observer`` is None: it records, it observes nothing."""

    pipe_observer = None

    def __init__(self):
        self._units = {}

    def record(self, unit, memories):
        self._units[id(unit)] = (unit, memories)

    def of(self, unit):
        """name -> {kind, depth, width, bits} of ``unit``'s memories in this elaboration."""
        found = self._units.get(id(unit))
        return dict(found[1]) if found is not None else dict(getattr(unit, "memories", {}))


def unit_memory_records(component):
    """``(fragment, records)``: ``component`` elaborated once with a :class:`MemoryRecords`."""
    records = MemoryRecords()
    return Fragment.get(component, records), records


def pipe_observer(platform):
    """The observer of the pipes an elaboration builds: the ``pipe_observer`` attribute of
    the ``platform`` it was given (the formal contract's, sim/formal/contract.py), else None.
    Every unit passes it to its :class:`Pipe`; ``platform`` reaches every submodule's
    ``elaborate``, so one elaboration's observer sees only its own pipes."""
    return getattr(platform, "pipe_observer", None)


class Pipe:
    """Valid chain and delay lines of a free-running ``depth``-stage pipe into stream ``o``.

    Parameters
    ----------
    m : Module
    valid : Value
        The valid bit of the pixel entering stage 1 this cycle.
    o : stream interface
        Its ``valid`` is driven with the last stage's valid bit; the unit drives
        ``o.payload`` from the pipe's registers. ``o.ready`` is never read.
    depth : int
        Number of register stages from the input to ``o`` (the latency).
    target : None or ECP5
        Passed to every RegisteredROM and RegisteredProduct built through the pipe.
    observer : None or object
        Told what the pipe builds, for assertions about it (the formal contract's lemmas):
        ``pipe(pipe)`` once the valid chain exists, ``register(pipe, name, reg)`` for every
        register, ``memory(pipe, name, memory)`` and ``ram(pipe, name, unit)`` for every
        memory, and the RAM's ``ram_built(unit, memory)`` when its generic form elaborates.
        None (the default) builds the same hardware and tells no one.

    Every register is loaded every cycle (no enable); only the valid bits are reset, the
    payload registers are ``reset_less`` (a pixel's payload is read only with its valid
    bit). Every element's ``en`` is :attr:`en`, the constant 1.

    ``memories`` records every memory built through the pipe (:meth:`rom`, :meth:`memory`):
    name -> {kind ("rom", or "ram" when written through a port), depth, width, bits}.
    """

    en = Const(1, 1)      # the enable of every element: the pipe never stops

    def __init__(self, m, valid, o, depth, target=None, observer=None):
        if depth < 1:
            raise ValueError(f"pipeline depth must be >= 1, got {depth}")
        self.m, self.o = m, o
        self.depth = depth
        self.target = target
        self.observer = observer
        self.memories = {}
        self.valid = [Value.cast(valid)]
        for n in range(1, depth + 1):
            v = Signal(name=f"stage{n}_valid")
            m.d.sync += v.eq(self.valid[-1])
            self.valid.append(v)
        m.d.comb += o.valid.eq(self.valid[depth])
        if observer is not None:
            observer.pipe(self)

    def register(self, value, name):
        """``value`` delayed by one register (loaded every cycle)."""
        value = Value.cast(value)
        reg = Signal(value.shape(), name=name, reset_less=True)
        self.m.d.sync += reg.eq(value)
        if self.observer is not None:
            self.observer.register(self, name, reg)
        return reg

    def _record(self, name, depth, width):
        self.memories[name] = {"kind": "rom", "depth": depth, "width": width, "bits": depth * width}

    def rom(self, init, shape, name, ports=2):
        """A :class:`RegisteredROM` with ``ports`` read ports, read every cycle."""
        unit = RegisteredROM(init, shape, ports, name, target=self.target)
        self.m.submodules[name] = unit
        self.m.d.comb += unit.en.eq(self.en)
        self._record(name, unit.depth, unit.width)
        return unit

    def ram(self, name, depth, shape, init=None, writable=True):
        """A :class:`RegisteredRAM` read every cycle; the caller drives its ``r_addr`` and
        write port (none when not ``writable``) and reads ``r_data`` RAM_LATENCY stages
        later."""
        unit = RegisteredRAM(depth, shape, name, init, target=self.target, writable=writable)
        self.m.submodules[name] = unit
        self.m.d.comb += unit.en.eq(self.en)
        self._record(name, depth, unit.width)
        self.memories[name]["kind"] = "ram" if writable else "rom"     # written through a port
        if self.observer is not None:
            self.observer.ram(self, name, unit)
        return unit

    def memory(self, name, memory):
        """Add an Amaranth ``Memory`` as submodule ``name`` and record its size."""
        self.m.submodules[name] = memory
        self._record(name, memory.depth, Shape.cast(memory.shape).width)
        if self.observer is not None:
            self.observer.memory(self, name, memory)
        return memory

    def multiply(self, a, b, name):
        """``a * b`` PRODUCT_LATENCY stages later (:class:`RegisteredProduct`)."""
        a, b = Value.cast(a), Value.cast(b)
        const = b.value if isinstance(b, Const) else None
        unit = RegisteredProduct(a.shape(), b.shape(), name, b_const=const, target=self.target)
        self.m.submodules[name] = unit
        self.m.d.comb += [unit.a.eq(a), unit.en.eq(self.en)]
        if const is None:
            self.m.d.comb += unit.b.eq(b)
        return unit.p

    def wide_multiply(self, a, b, name):
        """``a * b`` WIDE_PRODUCT_LATENCY stages later (:class:`WideProduct`)."""
        a, b = Value.cast(a), Value.cast(b)
        unit = WideProduct(a.shape(), b.shape(), name, target=self.target)
        self.m.submodules[name] = unit
        self.m.d.comb += [unit.a.eq(a), unit.b.eq(b), unit.en.eq(self.en)]
        return unit.p

    def multiplier(self, *shapes):
        """The registered product for operands of ``shapes``: :meth:`multiply` when they fit
        one DSP input (:func:`fits_dsp`), else :meth:`wide_multiply`;
        :func:`product_latency` ``(*shapes)`` stages either way."""
        return self.multiply if fits_dsp(*shapes) else self.wide_multiply

    def delay(self, value, stages, name):
        """``value`` delayed by ``stages`` registers (0 returns it as is)."""
        for n in range(stages):
            value = self.register(value, f"{name}_d{n + 1}")
        return value


class CreditFIFO(Elaboratable):
    """The credit edge's FIFO of ``depth`` pixels of ``width`` bits, with
    ``amaranth.lib.fifo``'s port names (``w_en``, ``w_data``, ``w_rdy``, ``r_en``,
    ``r_data``, ``r_rdy``, ``level``) and no full check on writes: its owner's credits
    guarantee room (``w_rdy`` is stated for the proofs).

    Its inner queue is ``2**ceil(log2(depth))`` words in banks of at most
    ``2**BANK_BITS`` (:attr:`banks`, submodules ``storage0``, ``storage1``, ...: each one
    LUT RAM deep on ECP5; one bank of them all when ``width`` exceeds BANKED_WIDTH_MAX),
    word ``a`` in bank ``a >> bank_bits``; it is written at
    :attr:`write_pointer`, which wraps by overflow, and read asynchronously at
    :attr:`read_pointer` (the control a copy per READ_SLICE bits of the word). Each bank's
    read lands in a prefetch register of its own beside it (``pre_data`` is the one the
    registered bank select names, ``pre_valid`` its valid bit), so no bank multiplexer sits
    between a LUT RAM and a register; the prefetched pixel moves on into the output
    register ``r_data``/``r_rdy``. Each of the two loads when it is empty or its pixel
    moves on. ``level`` counts the memory's pixels and both registers'. Written to an empty
    FIFO in cycle t, a pixel is offered in cycle t + 3 (EDGE_LATENCY)."""

    def __init__(self, width, depth):
        self.width, self.depth = width, depth
        self.bits = (depth - 1).bit_length()
        self.bank_bits = min(self.bits, BANK_BITS) if width <= BANKED_WIDTH_MAX else self.bits
        self.banks = [Memory(shape=width, depth=1 << self.bank_bits, init=[],
                             attrs={"ram_style": "distributed"})
                      for _ in range(1 << (self.bits - self.bank_bits))]
        self.w_en, self.w_rdy = Signal(), Signal()
        self.w_data = Signal(width)
        self.r_en, self.r_rdy = Signal(), Signal(name="fifo_head_valid")
        self.r_data = Signal(width, name="fifo_head", reset_less=True)
        self.pre_valid = Signal(name="fifo_pre_valid")
        self.pre_data = Signal(width, name="fifo_pre")
        self.level = Signal(range(depth + 1))
        self.count = Signal(self.bits + 1, name="fifo_count")      # pixels in the memory
        self.stored = Signal(name="fifo_stored")                    # count != 0
        self.write_pointer = Signal(self.bits, name="fifo_write")
        self.read_pointer = Signal(self.bits, name="fifo_read")
        # Output register first, then the prefetch register: the pixels outside the memory,
        # oldest first, as (valid, data).
        self.heads = [(self.r_rdy, self.r_data), (self.pre_valid, self.pre_data)]

    def _bank_is(self, pointer, b):
        """1 when ``pointer`` addresses bank ``b`` (always, with one bank): a bit of the
        one-hot decode of its high bits (an equality with 0 would be Verilog's ``!`` of a
        vector, which lint refuses)."""
        if len(self.banks) == 1:
            return Const(1, 1)
        return (Const(1, len(self.banks)) << pointer[self.bank_bits:])[b]

    def elaborate(self, platform):
        m, bits, bb = Module(), self.bits, self.bank_bits
        wp = self.write_pointer
        m.d.comb += [self.w_rdy.eq(self.count != (1 << bits)),
                     self.level.eq(self.count + self.pre_valid + self.r_rdy)]
        m.d.sync += wp.eq(wp + self.w_en)                       # wrap: the credits leave room
        # LUT RAM banks (their reads are asynchronous): a block RAM would put the load on
        # its CE
        n = len(self.banks)
        for b, bank in enumerate(self.banks):
            m.submodules[f"storage{b}"] = bank
            wport = bank.write_port()
            m.d.comb += [wport.addr.eq(wp[:bb]), wport.data.eq(self.w_data),
                         wport.en.eq(self.w_en & self._bank_is(wp, b))]
        # Each READ_SLICE bits of the word have a control of their own: a read pointer, a
        # count, a bank select and copies of the registers' valid bits, each its own
        # register (so no tool merges them), whose loads reach only that slice's LUT RAMs,
        # prefetch and output bits: one load would otherwise fan out to every bit of a
        # wide pixel. Slice 0's copies are the FIFO's (``read_pointer``, ``count``, ...).
        pres = [Signal(self.width, name=f"fifo_pre_bank{b}", reset_less=True) for b in range(n)]
        copies = []
        for k, lo in enumerate(range(0, self.width, READ_SLICE)):
            hi = min(lo + READ_SLICE, self.width)
            if k == 0:
                rp, count, stored = self.read_pointer, self.count, self.stored
                pre_valid, r_rdy = self.pre_valid, self.r_rdy
            else:
                rp = Signal(bits, name=f"fifo_read{k}")
                count = Signal.like(self.count, name=f"fifo_count{k}")
                stored = Signal(name=f"fifo_stored{k}")
                pre_valid = Signal(name=f"fifo_pre_valid{k}")
                r_rdy = Signal(name=f"fifo_head_valid{k}")
            select = Signal(bits - bb, name=f"fifo_pre_bank_select{k}" if k
                            else "fifo_pre_bank_select") if n > 1 else None
            out_load = pre_valid & (~r_rdy | self.r_en)               # prefetch -> output
            load = stored & (~pre_valid | out_load)                   # memory -> prefetch
            for b, bank in enumerate(self.banks):
                rport = bank.read_port(domain="comb")
                m.d.comb += rport.addr.eq(rp[:bb])
                with m.If(load & self._bank_is(rp, b)):
                    m.d.sync += pres[b][lo:hi].eq(rport.data[lo:hi])
            if n > 1:
                with m.If(load):
                    m.d.sync += select.eq(rp[bb:])
                m.d.comb += self.pre_data[lo:hi].eq(Array(pre[lo:hi] for pre in pres)[select])
            else:
                m.d.comb += self.pre_data[lo:hi].eq(pres[0][lo:hi])
            m.d.sync += [rp.eq(rp + load), count.eq(count + self.w_en - load)]
            with m.If(out_load):
                m.d.sync += self.r_data[lo:hi].eq(self.pre_data[lo:hi])
            with m.If(self.w_en & ~load):
                m.d.sync += stored.eq(1)
            with m.Elif(load & ~self.w_en):
                m.d.sync += stored.eq(count != 1)
            with m.If(load):
                m.d.sync += pre_valid.eq(1)
            with m.Elif(out_load):
                m.d.sync += pre_valid.eq(0)
            with m.If(out_load):
                m.d.sync += r_rdy.eq(1)
            with m.Elif(self.r_en):
                m.d.sync += r_rdy.eq(0)
            copies.append((rp, count, stored, pre_valid, r_rdy) + ((select,) if n > 1 else ()))
        if platform == "formal":         # as amaranth.lib.fifo states its own pointers
            rp = self.read_pointer
            m.d.comb += [Assert(self.stored == (self.count != 0)),
                         Assert(wp == (rp + self.count)[:bits]),
                         Assert(self.count + self.pre_valid + self.r_rdy <= self.depth),
                         # each register fills before the one behind it holds two
                         Assert(self.pre_valid | (self.count <= 1)),
                         Assert(self.r_rdy | (self.count <= 1))]
            m.d.comb += [Assert(a == b) for copy in copies[1:]
                         for a, b in zip(copy, copies[0], strict=True)]
        return m


class CreditEdge(wiring.Component):
    """The flow control of a free-running pipe of ``latency`` stages: credits at its input,
    a FIFO of ``depth`` entries at its output.

    Members
    -------
    i_valid : In(1)
        The producer offers a pixel (the enclosing component's ``i.valid``).
    i_ready : Out(1)
        A credit is free (a register): the pixel offered is taken, and enters the pipe.
    core : In(stream.Signature(layout))
        The pipe's last stage (``ready`` is 1: the FIFO always has room, see below).
    o : Out(stream.Signature(layout))
        The FIFO's head (:class:`CreditFIFO`): ``valid`` and ``payload`` from its output
        register; ``level`` is its occupancy.

    ``credits`` starts at ``depth``; a pixel taken spends one, a pixel leaving ``o`` gives
    one back (counted the next cycle). In every cycle credits + pixels in the pipe + FIFO
    occupancy = ``depth``, so the FIFO never overflows (sim/formal proves it by induction).
    ``depth`` below :func:`min_fifo_depth` ``(latency)`` is refused (BumpError naming both).
    """

    def __init__(self, layout, latency, depth=None):
        depth = check_fifo_depth(latency, depth)
        self.layout, self.latency, self.depth = layout, latency, depth
        super().__init__({"i_valid": In(1), "i_ready": Out(1),
                          "core": In(stream.Signature(layout)),
                          "o": Out(stream.Signature(layout))})
        self.credits = Signal(range(depth + 1), init=depth, name="credits")
        self.level = Signal(range(depth + 1), name="fifo_level")     # the FIFO's occupancy

    def elaborate(self, platform):
        m = Module()
        m.submodules.fifo = fifo = CreditFIFO(Shape.cast(self.layout).width, self.depth)
        m.d.comb += [fifo.w_en.eq(self.core.valid), fifo.w_data.eq(self.core.payload),
                     fifo.r_en.eq(self.o.ready), self.level.eq(fifo.level)]
        free = Signal(init=1, name="credit_free")           # credits != 0, registered
        take = self.i_valid & free
        give = self.o.valid & self.o.ready
        after = Signal.like(self.credits, name="credits_next")
        m.d.comb += after.eq(self.credits - take + give)
        m.d.sync += self.credits.eq(after)
        # free's next state without after's carry chain: a credit spent and none back
        # leaves one free unless this was the last; one back and none spent frees one
        with m.If(take & ~give):
            m.d.sync += free.eq(self.credits != 1)
        with m.Elif(give & ~take):
            m.d.sync += free.eq(1)
        m.d.comb += [self.i_ready.eq(free), self.core.ready.eq(1),
                     self.o.valid.eq(fifo.r_rdy), self.o.payload.eq(fifo.r_data)]
        return m


def add_credit_edge(m, i, o, latency, depth=None):
    """A :class:`CreditEdge` (submodule ``edge`` of ``m``) between the stream ``i`` (flipped)
    and the stream ``o`` of a free-running chain of ``latency`` stages: ``i.ready`` is its
    free credit, ``o`` its FIFO's head. Returns ``(valid, core)``: the valid bit of the pixel
    entering the chain's first stage (``i.valid`` when taken) and the edge's ``core``
    stream, whose ``valid`` and ``payload`` the chain's last stage drives."""
    m.submodules.edge = edge = CreditEdge(o.payload.shape(), latency, depth)
    m.d.comb += [edge.i_valid.eq(i.valid), i.ready.eq(edge.i_ready)]
    wiring.connect(m, edge.o, wiring.flipped(o))
    return i.valid & edge.i_ready, edge.core


class PipeUnit(wiring.Component):
    """The base of every unit: one free-running :class:`Pipe` from stream ``i`` to stream
    ``o``, with its own :class:`CreditEdge` when ``credit`` (a unit on its own) or none
    (``credit=False``: inside a chain whose owner holds the credits, ``BumpPipeline``).

    Parameters
    ----------
    cfg : Config
    in_layout, out_layout : data.Layout
        Payloads of ``i`` and ``o``.
    target : None or ECP5
        Elaboration target of the pipe's ROMs and products (None: the generic form).
    credit : bool
        True (the default): ``i.ready`` is "a credit is free" and ``o`` is the edge's FIFO
        (:attr:`port_latency` = ``latency`` + EDGE_LATENCY). False: ``i.ready`` is 1 and
        ``o.ready`` is not read: ``o.valid`` is the pixel's valid bit ``latency`` cycles
        after ``i.valid``; the chain's owner must only offer pixels it has a credit for.
    fifo_depth : None or int
        The edge's FIFO depth (None: :func:`min_fifo_depth` of the latency); below that,
        BumpError at construction.
    ports : dict
        More members of the signature (host write ports and the like).

    Subclasses set ``latency`` (the pipe's depth) before calling this constructor and
    give ``build(m, pipe)``, which drives ``pipe.o.payload`` from ``self.i.payload``.
    The edge is the same for every unit, so a unit on its own and a pipeline have one port
    contract. ``elaborate`` changes nothing of the unit: the memories its pipe builds go to
    the platform when that is a :class:`MemoryRecords` (:func:`unit_memory_records`).
    """

    def __init__(self, cfg, in_layout, out_layout, target=None, credit=True, fifo_depth=None,
                 ports=None):
        self.cfg, self.target, self.credit = cfg, target, credit
        self.fifo_depth = None
        if credit:
            try:
                self.fifo_depth = check_fifo_depth(self.latency, fifo_depth)
            except BumpError:
                self._MustUse__silence = True
                raise
        elif fifo_depth is not None:
            self._MustUse__silence = True
            raise BumpError("fifo_depth is given but credit=False (the chain's owner holds "
                            "the FIFO)")
        super().__init__({"i": In(stream.Signature(in_layout)),
                          "o": Out(stream.Signature(out_layout)), **(ports or {})})

    @property
    def port_latency(self):
        """Cycles from a pixel taken at ``i`` to the pixel offered at ``o`` with the FIFO
        empty: ``latency``, plus EDGE_LATENCY with the unit's own edge."""
        return self.latency + (EDGE_LATENCY if self.credit else 0)

    def build(self, m, pipe):
        raise NotImplementedError

    def elaborate(self, platform):
        m = Module()
        if self.credit:
            valid, core = add_credit_edge(m, self.i, self.o, self.latency, self.fifo_depth)
        else:
            core, valid = self.o, self.i.valid
            m.d.comb += self.i.ready.eq(1)
        pipe = Pipe(m, valid, core, self.latency, self.target, pipe_observer(platform))
        self.build(m, pipe)
        if isinstance(platform, MemoryRecords):
            platform.record(self, pipe.memories)
        return m
