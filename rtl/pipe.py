"""Stall-safe pipeline bookkeeping shared by every unit (docs/architecture.md, Interfaces).

A unit on its own advances its whole pipe when the output is empty or being taken,
``adv = ~o.valid | o.ready``; every register, including the ROM read ports, is enabled by
``adv``, so a stall freezes the pipe and never drops a lookup. ``o.valid`` comes straight
from a register and never depends on ``o.ready`` (stream rule 1). Inside a
``BumpPipeline`` (rtl/pipeline.py) the units run in *lock-step mode* instead: ``adv`` is
an enable the pipeline gives (a register of its own), so the stall rule is not a chain of
``o.valid`` terms across the units.
"""

from amaranth.hdl import Const, Module, Mux, Shape, Signal, Value
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

# The registered elements a StallPipe builds, and the targets that build them (rtl/targets.py);
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

__all__ = ["StallPipe", "PipeUnit", "RegisteredProduct", "WideProduct", "RegisteredROM",
           "RegisteredRAM", "read_port", "dp16kd_rom_block", "fits_dsp", "product_latency",
           "limb_products", "lockstep_buffer", "lockstep_enables", "BUFFER_DEPTH", "PRODUCT_LATENCY",
           "WIDE_PRODUCT_LATENCY", "ROM_LATENCY", "RAM_LATENCY", "ECP5", "dp16kd_initvals",
           "DP16KD_MODES", "pipe_observer"]


def pipe_observer(platform):
    """The observer of the pipes an elaboration builds: the ``pipe_observer`` attribute of
    the ``platform`` it was given (the formal contract's, sim/formal/contract.py), else None.
    Every unit passes it to its :class:`StallPipe`; ``platform`` reaches every submodule's
    ``elaborate``, so one elaboration's observer sees only its own pipes."""
    return getattr(platform, "pipe_observer", None)


class StallPipe:
    """Valid chain and delay lines of a ``depth``-stage pipe from stream ``i`` to ``o``.

    Parameters
    ----------
    m : Module
    i, o : stream interfaces of the enclosing component (``i`` flipped, ``o`` not)
    depth : int
        Number of register stages between ``i`` and ``o`` (the latency).
    target : None or ECP5
        Passed to every RegisteredROM and RegisteredProduct built through the pipe.
    enable : None or Value
        None (the default): the pipe stalls on its own, ``adv = ~o.valid | o.ready``.
        Given: lock-step mode, ``adv = enable`` and ``o.ready`` is not read: the pipe
        shifts exactly when ``enable`` is high, bubbles included, so units given the same
        enable move as one shift register (``BumpPipeline`` gives every unit a copy of one
        registered enable). ``i.ready`` is ``adv`` in both modes.
    enable_next : None or callable
        Lock-step mode only: ``enable_next(copy)`` is the next state of a copy of the
        registered ``enable`` (:func:`lockstep_buffer` gives it to the units it chains). Given,
        every spread memory the pipe builds (:meth:`rom`, :meth:`ram`; ``spread``: more than
        targets.SPREAD_BLOCKS block RAMs side by side) is enabled by a copy of its own, so no
        one flip-flop drives the clock enables of every such block of a unit.
    observer : None or object
        Told what the pipe builds, for assertions about it (the formal contract's lemmas):
        ``pipe(pipe)`` once the valid chain exists, ``register(pipe, name, reg)`` for every
        register, ``memory(pipe, name, memory)`` and ``ram(pipe, name, unit)`` for every
        memory, and the RAM's ``ram_built(unit, memory)`` when its generic form elaborates.
        None (the default) builds the same hardware and tells no one.

    ``memories`` records every memory built through the pipe (:meth:`rom`, :meth:`memory`):
    name -> {kind ("rom", or "ram" when written through a port), depth, width, bits}. A
    unit keeps it as its own ``memories`` when it elaborates (the memories of
    gen/flow/units.py's sidecar).
    """

    def __init__(self, m, i, o, depth, target=None, enable=None, observer=None, enable_next=None):
        if depth < 1:
            raise ValueError(f"pipeline depth must be >= 1, got {depth}")
        self.m = m
        self.depth = depth
        self.target = target
        self.observer = observer
        self.memories = {}
        self.enable_next = enable_next if enable is not None else None
        self.enable_copies = []
        self.adv = Signal(name="adv")
        adv = ~o.valid | o.ready if enable is None else enable
        m.d.comb += [self.adv.eq(adv), i.ready.eq(self.adv)]
        self.valid = [i.valid]
        for n in range(1, depth + 1):
            v = Signal(name=f"stage{n}_valid")
            with m.If(self.adv):
                m.d.sync += v.eq(self.valid[-1])
            self.valid.append(v)
        m.d.comb += o.valid.eq(self.valid[depth])
        if observer is not None:
            observer.pipe(self)

    def register(self, value, name):
        """``value`` delayed by one ``adv``-enabled register."""
        value = Value.cast(value)
        reg = Signal(value.shape(), name=name)
        with self.m.If(self.adv):
            self.m.d.sync += reg.eq(value)
        if self.observer is not None:
            self.observer.register(self, name, reg)
        return reg

    def _memory_enable(self, name):
        """``adv``, or in lock-step mode with ``enable_next`` a copy of the enable of the
        memory's own (same initial and next state: equal to ``adv`` in every cycle)."""
        if self.enable_next is None:
            return self.adv
        copy = Signal(init=1, name=f"{name}_run", attrs={"keep": 1})
        self.m.d.sync += copy.eq(self.enable_next(copy))
        self.enable_copies.append(copy)
        return copy

    def _record(self, name, depth, width):
        self.memories[name] = {"kind": "rom", "depth": depth, "width": width, "bits": depth * width}

    def rom(self, init, shape, name, ports=2):
        """A :class:`RegisteredROM` with ``ports`` read ports enabled by ``adv``."""
        unit = RegisteredROM(init, shape, ports, name, target=self.target)
        self.m.submodules[name] = unit
        self.m.d.comb += unit.en.eq(self._memory_enable(name) if unit.spread else self.adv)
        self._record(name, unit.depth, unit.width)
        return unit

    def ram(self, name, depth, shape, init=None, writable=True):
        """A :class:`RegisteredRAM` whose read is enabled by ``adv``; the caller drives its
        ``r_addr`` and write port (none when not ``writable``) and reads ``r_data``
        RAM_LATENCY stages later."""
        unit = RegisteredRAM(depth, shape, name, init, target=self.target, writable=writable)
        self.m.submodules[name] = unit
        self.m.d.comb += unit.en.eq(self._memory_enable(name) if unit.spread else self.adv)
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
        """``a * b`` PRODUCT_LATENCY ``adv`` stages later (:class:`RegisteredProduct`)."""
        a, b = Value.cast(a), Value.cast(b)
        const = b.value if isinstance(b, Const) else None
        unit = RegisteredProduct(a.shape(), b.shape(), name, b_const=const, target=self.target)
        self.m.submodules[name] = unit
        self.m.d.comb += [unit.a.eq(a), unit.en.eq(self.adv)]
        if const is None:
            self.m.d.comb += unit.b.eq(b)
        return unit.p

    def wide_multiply(self, a, b, name):
        """``a * b`` WIDE_PRODUCT_LATENCY ``adv`` stages later (:class:`WideProduct`)."""
        a, b = Value.cast(a), Value.cast(b)
        unit = WideProduct(a.shape(), b.shape(), name, target=self.target)
        self.m.submodules[name] = unit
        self.m.d.comb += [unit.a.eq(a), unit.b.eq(b), unit.en.eq(self.adv)]
        return unit.p

    def multiplier(self, *shapes):
        """The registered product for operands of ``shapes``: :meth:`multiply` when they fit
        one DSP input (:func:`fits_dsp`), else :meth:`wide_multiply`;
        :func:`product_latency` ``(*shapes)`` stages either way."""
        return self.multiply if fits_dsp(*shapes) else self.wide_multiply

    def delay(self, value, stages, name):
        """``value`` delayed by ``stages`` ``adv``-enabled registers (0 returns it as is)."""
        for n in range(stages):
            value = self.register(value, f"{name}_d{n + 1}")
        return value


class PipeUnit(wiring.Component):
    """A unit that is one :class:`StallPipe` from stream ``i`` to stream ``o``: the base of
    every method's datapath (rtl/exact.py, rtl/lee.py, rtl/baselines/).

    Parameters
    ----------
    cfg : Config
    in_layout, out_layout : data.Layout
        Payloads of ``i`` and ``o``.
    target : None or ECP5
        Elaboration target of the pipe's ROMs and products (None: the generic form).

    Members: ``i`` In(stream.Signature(in_layout)), ``o`` Out(stream.Signature(out_layout)).
    Subclasses give ``latency`` (the pipe's depth) and ``build(m, pipe)``. After elaboration
    ``memories`` holds the pipe's record of the memories built (name -> depth, width, bits).
    1 pixel per clock when not stalled.

    lockstep : None or Value
        None (the default: the unit stalls on its own) or a 1-bit enable (the
        :class:`StallPipe` ``enable``: lock-step mode; ``BumpPipeline`` gives each unit its
        copy of ``run``, :func:`lockstep_enables`).
    """

    def __init__(self, cfg, in_layout, out_layout, target=None, lockstep=None):
        self.cfg, self.target, self.memories, self.lockstep = cfg, target, {}, lockstep
        super().__init__({"i": In(stream.Signature(in_layout)),
                          "o": Out(stream.Signature(out_layout))})

    def build(self, m, pipe):
        raise NotImplementedError

    def elaborate(self, platform):
        m = Module()
        pipe = StallPipe(m, self.i, self.o, self.latency, self.target, self.lockstep,
                         pipe_observer(platform), getattr(self, "lockstep_next", None))
        self.build(m, pipe)
        self.memories, self.enable_copies = pipe.memories, pipe.enable_copies
        return m


# Entries of the output buffer of :func:`lockstep_buffer`. ``run`` is registered and falls
# the cycle after the buffer fills. Two entries keep the pipe running through a one-cycle
# stall of the consumer and in the cycle a waiting pixel is taken; with one (``run`` = empty)
# every stall would also stop the input for a cycle, which only a full pipe (no input gaps)
# does not notice.
BUFFER_DEPTH = 2


def lockstep_enables(names):
    """The registered enables ``run`` of a lock-step chain of units ``names``: one copy per
    unit (given to its constructor as ``lockstep``) and ``"pipeline"`` for the buffer's and
    ``i.ready``'s own; :func:`lockstep_buffer` drives them."""
    return {name: Signal(init=1, name=f"run_{name}", attrs={"keep": 1})
            for name in ("pipeline", *names)}


def lockstep_buffer(m, units, runs, last, i, o):
    """Units chained in lock step on a registered enable, with an output buffer: the stall
    rule of a chain of units (``BumpPipeline``, the placed rotation -> illumination pipe of
    gen/flow/fpga.py) without a chain of ``o.valid`` terms across them.

    ``units``: name -> unit, each built with ``lockstep=runs[name]`` (run as a
    :class:`StallPipe` in lock-step mode); ``runs``: :func:`lockstep_enables` of the units;
    ``last``: the stream out of the last unit; ``i``, ``o``: the chain's own streams (``i``
    flipped). Every unit has its own copy of the registered enable ``run`` (as ``lockstep``
    and as its ``o.ready``: a pixel leaves a unit whenever the chain runs), so no one
    flip-flop drives every register of the chain. The
    last unit feeds a :data:`BUFFER_DEPTH`-entry buffer, bypassed while empty (the latency
    is the units'). ``i.ready`` = ``run`` = (at most one pixel in the buffer): high whenever
    ``o.valid`` is low, never a function of ``o.ready`` in the same cycle. The caller feeds
    the first unit's ``i.valid`` from ``i.valid`` and chains the units' valid and payload.
    Returns ``{count, entries (oldest first), runs}`` (``runs``: the copies by unit name,
    ``"pipeline"`` for the buffer's and ``i.ready``'s own), read by sim/formal's lemmas."""
    count = Signal(range(BUFFER_DEPTH + 1), name="out_count")
    entries = [Signal(last.payload.shape(), name=f"out_entry{n}") for n in range(BUFFER_DEPTH)]
    runs = {name: runs[name] for name in ("pipeline", *units)}
    run = runs["pipeline"]
    for name, unit in units.items():
        if unit.lockstep is not runs[name]:
            raise ValueError(f"unit {name!r} must be built with lockstep=runs[{name!r}]")
        m.d.comb += unit.o.ready.eq(runs[name])
    held = count != 0
    taken = o.valid & o.ready
    m.d.comb += [i.ready.eq(run), o.valid.eq(held | last.valid),
                 o.payload.eq(Mux(held, entries[0], last.payload))]       # bypass when empty
    # Next run = (the buffer not full next cycle). Each copy counts the pixel leaving the
    # last unit with its own value (all copies are equal): the copies' next states differ in
    # form, so synthesis keeps one register per unit.
    def next_run(copy):
        return count + (last.valid & copy) < BUFFER_DEPTH + taken

    for copy in runs.values():
        m.d.sync += copy.eq(next_run(copy))
    for unit in units.values():     # each spread memory of a unit gets a copy (StallPipe enable_next)
        unit.lockstep_next = next_run
    left = last.valid & run                      # the pixel in the last stage moves on
    m.d.sync += count.eq(count + left - taken)
    pop = held & o.ready
    with m.If(pop):
        m.d.sync += [entries[n].eq(entries[n + 1]) for n in range(BUFFER_DEPTH - 1)]
    slot = Signal.like(count, name="out_slot")   # the first free entry after the pop
    m.d.comb += slot.eq(count - pop)
    for n in range(BUFFER_DEPTH):                # kept unless taken directly (count stays 0)
        with m.If(left & (slot == n if n else ~slot.any())):
            m.d.sync += entries[n].eq(last.payload)
    return {"count": count, "entries": entries, "runs": runs}
