"""The stream contract as Amaranth properties, in a formal-only wrapper around a unit.

:class:`StreamContract` elaborates a unit (a ``wiring.Component`` with ``i``/``o``
``amaranth.lib.stream`` ports and a ``tag`` payload field) inside a top that drives nothing:
every input of the unit (``i.valid``, ``i.payload``, ``o.ready``, host ports, ``rst``) is a
free input of the model, so the solver plays every producer, consumer and host there is.
One wrapper checks one property (:data:`PROPERTIES`):

``hold``     o.payload and o.valid are held while ``o.valid & ~o.ready`` (stream rule 2);
``ready``    ``i.ready`` is high exactly while fewer than ``fifo_depth`` pixels are accepted
             and not yet delivered (counted at the ports up to the last cycle): it depends
             on the past only, never on ``o.ready`` or ``i.valid`` in the same cycle, and a
             slow consumer stops the input only once every credit is spent;
``order``    every accepted input comes out exactly once and in order: the inputs carry
             consecutive tags (assumed), the n-th output must carry tag n;
``quiet``    no output without an input: with nothing in flight (accepted minus delivered
             is 0, counted from reset) ``o.valid`` is low;
``latency``  with ``o.ready`` held high the output is the input ``port_latency`` cycles
             later, valid for valid and tag for tag (no bubble added, none removed);
``credit``   the credit loop of the unit's :class:`~bumprtl.rtl.pipe.CreditEdge`: in every
             cycle credits + pixels in the free-running chain (its valid stages 1..latency)
             + the FIFO's occupancy = ``fifo_depth``, ``i.ready`` = (credits != 0), and the
             FIFO never overflows (a write only while it has room, occupancy <= depth);
``cover``    vacuity check: a transfer, a stall and a transfer after a stall are reachable.
``bank``     PaletteLUT's double buffer (units with ``swap``/``w_*``/``bank`` ports, and
             palette scene pipelines with ``lut_*`` ports): a pixel reads the entry of the
             bank that was in front in the cycle it was accepted (by the pipeline, at its
             input, ahead of the fetch), whatever the host writes (the writes the unit
             took: ``lut_w_en & lut_w_ready`` for a pipeline) or swaps while it is in flight
             or stalled. The swap strobe is the frame boundary (the host strobes it between
             frames; PaletteLUT has no frame signal of its own), so all pixels of a frame
             read one bank and a swap strobed while the last pixels of a frame are still in
             the pipe takes effect only for the pixels accepted after it. A symbolic entry
             (any address, fixed for the trace) is shadowed in both banks and one symbolic
             pixel reading it is followed to the output.

k-induction needs the contract to be inductive, so the wrapper also asserts *lemmas* about
the unit's own registers: the credit loop's invariant (above) with the pixels of the chain
counted in runs of at most CHUNK stages (a ghost counter each, equal to its valid stages),
the FIFO's head registers (output, prefetch) each full whenever its memory holds two or
more, its pointers a queue of its memory's occupancy, the pixels accepted and not delivered = valid stages + FIFO occupancy, the tags
held in the valid stages and the FIFO's entries (oldest first) the ones the order says; with
``o.ready`` held high (``latency``) stage n holds the input of n cycles ago, the FIFO's
memory at most the pixel written in the last cycle and its prefetch register the one before; units of one layer of a scene pipeline (fed one
valid) have equal valid chains; and (``bank``) the shadows are the table's watched entries,
the bank bits in flight are what the pipeline's ``lut_w_ready`` counters count, and the
watched pixel sits where its position says with the bank of its acceptance. The chain's
registers come from the observer every :class:`bumprtl.rtl.pipe.Pipe` takes
(:class:`PipeObserver`, passed in with the elaboration's platform by :func:`observe_pipes`:
the valid chain and the ``tag`` delay line of every pipe, keyed by the module it builds
into); the edge, its FIFO and the FIFO's memory are found in the elaborated fragment (by
their origins), and the FIFO's entries are read through asynchronous read ports added to
that memory. No unit carries formal-only code and nothing is patched. ``lemmas=False``
leaves the lemmas out (plain BMC, and the broken units of
:mod:`bumprtl.sim.formal.mutants`, whose failure must be the property itself).
"""

import re

from amaranth.hdl import (
    Assert,
    Assume,
    Const,
    Cover,
    Elaboratable,
    Fragment,
    MemoryInstance,
    Module,
    Mux,
    Signal,
    Value,
)
from amaranth.lib import data
from amaranth.lib.fifo import SyncFIFOBuffered
from amaranth.utils import ceil_log2

from bumprtl.rtl.cache import TextureCache
from bumprtl.rtl.pipe import CreditEdge, CreditFIFO
from bumprtl.sim.formal.rules import component_inputs

__all__ = ["PROPERTIES", "StreamContract", "PipeObserver", "observe_pipes", "pipeline_layers",
           "find_edge", "find_cache", "CHUNK"]

PROPERTIES = ("hold", "ready", "order", "quiet", "latency", "credit", "cover", "bank")

_TAG_REG = re.compile(r"(tag|bank|oor)_d(\d+)$")
CHUNK = 12          # stages per ghost counter of the chain (the pixels-in-flight lemmas)


class PipeObserver:
    """What the contract learns of a unit's pipes while it elaborates: passed to every
    :class:`~bumprtl.rtl.pipe.Pipe` as its ``observer`` (through the elaboration's
    platform, :func:`bumprtl.rtl.pipe.pipe_observer`). ``seen`` maps ``id(the Module the
    pipe builds into) -> {"valid": [valid into stage 1, stage1, ...], "o": the stream the
    last stage drives, "tags": {n: tag register of stage n}, "banks": {n: bank register of
    stage n}, "oors": {n: oor register of stage n}, "memories": {name: [comb read port,
    ...]}, "reads": {name: [read data 1, 2 stages after the address]}}`` (the unit's
    fragment has that Module among its origins: :meth:`StreamContract._record`);
    ``read_ports``: that many asynchronous read ports are added to every memory a pipe adds
    with ``Pipe.memory`` or ``Pipe.ram`` (generic form), for assertions about its contents.
    One observer per elaboration: nothing process-wide, so elaborations may run in parallel
    threads (``make formal -j 2``)."""

    def __init__(self, read_ports=0):
        self.read_ports, self.seen, self._rams = read_ports, {}, {}
        self.counters = {}               # (id(unit), name) -> [Signal]: a unit's own counters

    def counter(self, unit, name, signals):
        """``unit`` built the counters ``signals`` named ``name`` (a scene pipeline's
        per-bank counters of the pixels before its palette LUT, ``lut_pending``)."""
        self.counters[(id(unit), name)] = list(signals)

    def pipe(self, pipe):
        self.seen[id(pipe.m)] = {"valid": list(pipe.valid), "o": pipe.o, "tags": {}, "banks": {},
                                 "oors": {}, "memories": {}, "reads": {}}

    def _record(self, pipe):
        return self.seen[id(pipe.m)]

    def register(self, pipe, name, reg):
        match = _TAG_REG.match(str(name))
        if match:
            self._record(pipe)[match.group(1) + "s"][int(match.group(2))] = reg

    def memory(self, pipe, name, mem):
        if self.read_ports:
            self._record(pipe)["memories"][name] = [mem.read_port(domain="comb")
                                                    for _ in range(self.read_ports)]

    def ram(self, pipe, name, unit):
        if self.read_ports:
            rec = self._record(pipe)
            self._rams[id(unit)] = (rec["memories"].setdefault(name, []),
                                    rec["reads"].setdefault(name, []))

    def ram_built(self, unit, mem):
        """The generic form of a RAM a pipe added has elaborated: its Memory ``mem``."""
        if id(unit) in self._rams:
            ports, reads = self._rams[id(unit)]
            reads.extend([mem.read_ports[0].data, unit.r_data])
            ports.extend(mem.read_port(domain="comb") for _ in range(self.read_ports))


class _Observing(str):
    """The platform an observed elaboration is given: it carries the observer, and with
    ``formal`` it is the string "formal", for which amaranth.lib.fifo's FIFOs add their own
    assertions (their pointers in range and a queue of their occupancy: lemmas of the FIFO
    behind every credit edge)."""

    def __new__(cls, observer, formal=False):
        platform = super().__new__(cls, "formal" if formal else "")
        platform.pipe_observer = observer
        return platform


def observe_pipes(dut, read_ports=0, formal=False):
    """Elaborate ``dut`` with a :class:`PipeObserver` (and, with ``formal``, the library's
    own FIFO assertions): ``(fragment, observer)``."""
    observer = PipeObserver(read_ports)
    fragment = Fragment.get(dut, _Observing(observer, formal))
    return fragment, observer


def _origins(fragment, found=None):
    """``id(elaboratable or Module) -> fragment`` over the elaborated tree."""
    found = {} if found is None else found
    for obj in fragment.origins or ():
        found[id(obj)] = fragment
    for sub, _name, _src_loc in fragment.subfragments:
        _origins(sub, found)
    return found


def _subfragment(fragment, name):
    return next((sub for sub, n, _ in fragment.subfragments if n == name), None)


class _Edge:
    """A :class:`~bumprtl.rtl.pipe.CreditEdge` found in an elaborated fragment, with its
    FIFO (``rtl/pipe.CreditFIFO``, or ``SyncFIFOBuffered``: an inner queue in memory, then
    registers outside it, ``heads``: (valid, data) oldest first, the output register
    ``r_rdy``/``r_data`` first, CreditFIFO's prefetch register after it) and that memory:
    ``banks``, (elaborated MemoryInstance, to add read ports to; its ``lib.memory.Memory``;
    the logical address of its word 0) for each bank (CreditFIFO's ``storage0``, ...;
    SyncFIFOBuffered's one ``storage``), and ``produce``/``consume``, the queue's write and
    read pointers (logical addresses)."""

    def __init__(self, edge, fragment):
        self.edge = edge
        fifo_fragment = _subfragment(fragment, "fifo")
        self.fifo = fifo_fragment.origins[0] if fifo_fragment is not None else None
        self.banks, self.produce, self.consume = [], None, None
        if isinstance(self.fifo, CreditFIFO):
            found = [_subfragment(fifo_fragment, f"storage{b}") for b in range(len(self.fifo.banks))]
            if all(isinstance(inst, MemoryInstance) for inst in found):
                size = 1 << self.fifo.bank_bits
                self.banks = [(inst, inst.origins[0], b * size) for b, inst in enumerate(found)]
                self.produce, self.consume = self.fifo.write_pointer, self.fifo.read_pointer
        elif isinstance(self.fifo, SyncFIFOBuffered):
            inst = _subfragment(fifo_fragment, "storage")
            if isinstance(inst, MemoryInstance):
                self.banks = [(inst, inst.origins[0], 0)]
                storage = inst.origins[0]
                self.produce = storage.write_ports[0].addr
                self.consume = storage.read_ports[0].addr
        self.inner_depth = sum(memory.depth for _, memory, _ in self.banks)
        self.heads = list(getattr(self.fifo, "heads", None) or
                          ([(self.fifo.r_rdy, self.fifo.r_data)] if self.fifo is not None else []))
        self._slots = None

    @property
    def has_memory(self):
        """The inner queue's memory was found (its entries may be stated)."""
        return bool(self.banks)

    @property
    def outside(self):
        """Pixels in the registers outside the memory (the valid ``heads``)."""
        return sum((valid for valid, _ in self.heads[1:]), self.heads[0][0])

    @property
    def inner_level(self):
        """Entries in the inner queue (the memory): the occupancy less the head registers."""
        return (self.fifo.level - self.outside)[:len(self.fifo.level)]

    def slots(self, m, layout):
        """The inner queue's memory word at every logical address, as ``View(layout)``: one
        asynchronous read port at each constant address of each bank (added once)."""
        if self._slots is None:
            self._slots = []
            for instance, memory, base in self.banks:
                for a in range(memory.depth):
                    word = Signal(len(self.fifo.w_data), name=f"fifo_slot{base + a}")
                    instance.read_port(domain="comb", addr=Const(a, ceil_log2(memory.depth)),
                                       data=word, en=Const(1), transparent_for=())
                    self._slots.append(data.View(layout, word))
        return self._slots

    def holds(self, a):
        """Address ``a`` holds an entry: between the read and the write pointer, around the
        end of the memory when they have wrapped (comparisons only, no subtraction)."""
        produce, consume = self.produce, self.consume
        return Mux(self.inner_level == self.inner_depth, 1,
                   Mux(consume <= produce, (consume <= a) & (a < produce),
                       (a >= consume) | (a < produce)))

    def offset(self, a):
        """How many entries address ``a`` is behind the oldest one (the read pointer's),
        mod the inner depth: ``a`` holds an entry when this is below the inner occupancy."""
        consume = self.consume
        return Mux(a >= consume, a - consume, a + self.inner_depth - consume)


def find_edge(fragment):
    """The one CreditEdge of an elaborated unit or pipeline (:class:`_Edge`), or None when
    there is none or more than one."""
    found = [(frag.origins[0], frag) for frag in _origins(fragment).values()
             if frag.origins and isinstance(frag.origins[0], CreditEdge)]
    found = list({id(e): (e, f) for e, f in found}.values())
    return _Edge(*found[0]) if len(found) == 1 else None


def find_cache(fragment):
    """The one :class:`~bumprtl.rtl.cache.TextureCache` of an elaborated pipeline (a
    ``map_memory = "axi"`` scene's, in front of its credit edge), or None."""
    found = {id(f.origins[0]): f.origins[0] for f in _origins(fragment).values()
             if f.origins and isinstance(f.origins[0], TextureCache)}
    return next(iter(found.values())) if len(found) == 1 else None


def pipeline_layers(dut):
    """The layers of a :class:`~bumprtl.rtl.pipeline.BumpPipeline` (units fed one valid;
    the first unit of each layer carries the tag), or ``[[dut]]`` for a single unit."""
    layers = getattr(dut, "_layers", None)
    if layers is None or not hasattr(dut, "units"):
        return [[dut]]
    return [[dut.units[name] for name in layer] for layer in layers]


class _Built(Elaboratable):
    """An already elaborated fragment as a submodule."""

    def __init__(self, fragment):
        self.fragment = fragment

    def elaborate(self, platform):
        return self.fragment


class StreamContract(Elaboratable):
    """Formal wrapper: ``dut`` and the properties of ``prop`` (one of :data:`PROPERTIES`).

    Parameters
    ----------
    dut : wiring.Component with ``i``/``o`` streams whose payloads have a ``tag`` field;
        ``latency`` (its chain's stages), ``port_latency`` and ``fifo_depth`` (its edge's).
    prop : str
    latency : int, optional
        The chain's stages; defaults to ``dut.latency``.
    layers : list of lists of units, optional
        The layers the pixels pass (default :func:`pipeline_layers`).
    lemmas : bool
        Assert the lemmas that make the property k-inductive.
    """

    def __init__(self, dut, prop, latency=None, layers=None, lemmas=True):
        if prop not in PROPERTIES:
            raise ValueError(f"property must be one of {', '.join(PROPERTIES)}, got {prop!r}")
        self.dut, self.prop, self.lemmas = dut, prop, lemmas
        self.latency = dut.latency if latency is None else latency
        self.port_latency = getattr(dut, "port_latency", self.latency)
        self.fifo_depth = getattr(dut, "fifo_depth", None)
        self.layers = layers if layers is not None else pipeline_layers(dut)
        self.lemma_count = 0
        self.lemma_names = []        # what each lemma says, one entry per lemma asserted
        self.messages = {}
        self.exercised = []          # what each property's covers show (_exercise)
        self._free = []
        if prop == "bank":
            if getattr(dut, "cfg", None) is None or dut.cfg.palette_blend:
                raise ValueError("bank: a PaletteLUT without the blend stage")
            self.watch_addr = Signal(len(self._host("w_addr")), name="watch_addr")  # any constant
            self.watch_pick = Signal(name="watch_pick")                    # any sequence
            self._free = [self.watch_addr, self.watch_pick]

    # --- the unit's registers ---------------------------------------------------------------
    def _record(self, unit):
        """The observer's record of ``unit``'s pipe (None when it built none); for the unit
        under test that is a wrapper around one pipe (the broken units), that pipe's."""
        frag = self._frags.get(id(unit))
        for origin in (frag.origins if frag is not None else ()):
            if id(origin) in self._pipes:
                return self._pipes[id(origin)]
        if unit is self.dut and len(self._pipes) == 1:
            return next(iter(self._pipes.values()))
        return None

    def _stages(self):
        """The chain's stages input -> output: ``[(valid, tag or None)]`` (each layer's lead
        unit's stages 1..depth in turn), and the pairs ``[(lead valid, other valid)]`` of
        the units fed one valid. ``self._valid_in``: the valid into stage 1."""
        stages, lockstep = [], []
        self._valid_in = None
        self._lead_records = []
        for layer in self.layers:
            recs = [self._record(unit) for unit in layer]
            lead = recs[0]
            if lead is None:             # not built on a Pipe: no chain (BMC only)
                return [], []
            if self._valid_in is None:
                self._valid_in = lead["valid"][0]
            stages += [(lead["valid"][n], lead["tags"].get(n)) for n in range(1, len(lead["valid"]))]
            self._lead_records.append(lead)
            for rec in recs[1:]:
                if rec is not None:
                    lockstep += list(zip(lead["valid"][1:], rec["valid"][1:], strict=False))
        return stages, lockstep

    def free_inputs(self):
        """Every input of the unit (``i.valid``, ``i.payload``, ``o.ready``, host ports) and
        the clock and reset: the model's free inputs, chosen by the solver in every cycle."""
        return component_inputs(self.dut) + self._free

    def _check(self, m, test, message, src_loc_at=1):
        """``Assert(test)``; sby names a failed one by its source line, ``messages`` maps
        that line back to ``message``."""
        check = Assert(test, message, src_loc_at=src_loc_at)
        self.messages[f"{check.src_loc[0]}:{check.src_loc[1]}"] = message
        m.d.comb += check

    def _lemma(self, m, test, what):
        """A lemma (only with ``lemmas``)."""
        if not self.lemmas:
            return
        self.lemma_count += 1
        self.lemma_names.append(what)
        self._check(m, test, f"lemma ({what})", src_loc_at=2)

    def _exercise(self, m, test, what):
        """A cover of the property's own model (its assumptions in force): the trace that
        shows the property is exercised, not vacuous (run.py's ``<prop>_cover`` checks, in
        sby's cover mode). Ignored by the proofs."""
        self.exercised.append(what)
        m.d.comb += Cover(test)

    def describe(self, location):
        """The message of the assertion sby reports at ``location`` (``file:line ...``)."""
        return self.messages.get(location.split(" ")[0], location)

    def elaborate(self, platform):
        m = Module()
        dut = self.dut
        ports = 2 if self.prop == "bank" and self.lemmas else 0   # the watched entry of both banks
        fragment, observer = observe_pipes(dut, ports, formal=self.lemmas)
        self._pipes, self._counters = observer.seen, observer.counters
        self._frags = _origins(fragment)
        self.edge = find_edge(fragment)
        self.cache = find_cache(fragment)
        m.submodules.dut = _Built(fragment)
        i, o = dut.i, dut.o
        take_in = i.valid & i.ready
        take_out = o.valid & o.ready
        stages, lockstep = self._stages()
        for lead, other in lockstep:
            self._lemma(m, lead == other, "units fed one valid have equal valid chains")
        self._chain, self._chain_valid = self._pixels(m, stages) if stages else (None, None)
        if self.edge is not None and self._chain is not None and self.prop != "credit":
            self._credit_loop(m, self._lemma)
        getattr(self, f"_{self.prop}")(m, i, o, take_in, take_out, stages)
        return m

    # --- the credit loop --------------------------------------------------------------------
    def _width(self, stages=()):
        """Wide enough for every pixel that can be accepted and not delivered (at most
        ``fifo_depth``, one per stage without an edge), even without the lemmas (BMC), where
        a wrapping counter would be a false failure."""
        front = getattr(self.dut, "front_capacity", 0)      # a unit has no cache in front
        return (max(len(stages), self.port_latency, self.fifo_depth or 0) + front + 2).bit_length() + 1

    def _pixels(self, m, stages):
        """The valid stages of the chain, counted in runs of at most CHUNK stages, each run
        by a ghost counter that gains the valid bit entering it and loses the one leaving
        it every cycle (the chain shifts every cycle), tied by a lemma to the run's valid
        stages: ``(sum of the ghost counters, sum of the runs' valid stages)``. The lemmas
        about the chain use the first (small sums of registers: counting is what SAT
        solvers find hard), the ``credit`` property states the second."""
        width = self._width(stages)
        valids = [self._valid_in] + [v for v, _ in stages]
        ghosts, counts = [], []
        for first in range(1, len(valids), CHUNK):
            last = min(first + CHUNK, len(valids)) - 1
            ghost = Signal(width, name=f"in_flight_stages{first}_{last}")
            m.d.sync += ghost.eq(ghost + valids[first - 1] - valids[last])
            _ahead, count = self._ahead(m, width, stages[first - 1:last], f"stages{first}_{last}_")
            self._lemma(m, ghost == count, "valid stages of a run = its ghost counter")
            ghosts.append(ghost)
            counts.append(count)
        total, valid = Signal(width, name="in_chain"), Signal(width, name="valid_in_chain")
        m.d.comb += [total.eq(sum(ghosts)), valid.eq(sum(counts))]
        return total, valid

    def _credit_loop(self, m, claim, chain=None):
        """The credit loop's invariant, each fact through ``claim`` (:meth:`_lemma`, or
        :meth:`_check` for the ``credit`` property): the FIFO never holds more than its
        depth and fills its output register first; credits + pixels in the chain (``chain``;
        default the ghost counters' sum) + FIFO occupancy = depth; ``i.ready`` = credits !=
        0; the FIFO has room when written."""
        edge, fifo = self.edge.edge, self.edge.fifo
        depth = edge.depth
        chain = self._chain if chain is None else chain
        claim(m, edge.level <= depth, "credit: the FIFO holds at most its depth")
        for n, (valid, _) in enumerate(self.edge.heads):
            claim(m, valid | (self.edge.inner_level <= 1),
                  f"credit: the FIFO's head register {n} is full when the memory holds two or more")
        claim(m, edge.credits + chain + edge.level == depth,
              "credit: credits + pixels in the chain + FIFO occupancy != depth")
        claim(m, edge.i_ready == (edge.credits != 0), "credit: i.ready is not credits != 0")
        claim(m, ~fifo.w_en | fifo.w_rdy, "credit: the FIFO written while full")

    def _credit(self, m, i, o, take_in, take_out, stages):
        if self.edge is None or self._chain is None:
            raise ValueError("credit: the unit has no credit edge and chain to check")
        # The statement counts the chain's valid stages; the lemmas (k-induction) the same
        # with the ghost counters of its runs.
        self._lemma(m, self.edge.edge.credits + self._chain + self.edge.edge.level == self.edge.edge.depth,
                    "credits + the runs' ghost counters + FIFO occupancy = depth")
        self._credit_loop(m, self._check, self._chain_valid)
        edge = self.edge.edge
        fell = Signal(name="ready_fell")
        with m.If(~edge.i_ready):
            m.d.sync += fell.eq(1)
        self._exercise(m, edge.credits == 0, "credit: every credit spent")
        self._exercise(m, edge.level == edge.depth, "credit: the FIFO full")
        self._exercise(m, fell & i.ready & take_in, "credit: i.ready falls and rises again")

    def _fifo_lemmas(self, m):
        """The FIFO's pointers are a queue of its inner occupancy: the write pointer is the
        read pointer + inner occupancy (mod the inner depth), both in range."""
        n = self.edge.inner_depth
        produce, consume = self.edge.produce, self.edge.consume
        at = consume + self.edge.inner_level
        self._lemma(m, (produce < n) & (consume < n), "the FIFO's pointers are in range")
        self._lemma(m, produce == Mux(at >= n, at - n, at),
                    "the FIFO's write pointer = read pointer + its inner occupancy")

    def _fifo(self, m):
        """The edge, with the FIFO's pointer lemmas asserted, when its entries may be
        stated (lemmas on, a FIFO with a memory); else None."""
        if self.edge is None or not self.edge.has_memory or not self.lemmas:
            return None
        self._fifo_lemmas(m)
        return self.edge

    def _in_fifo(self, m, field, k):
        """``field`` of the FIFO's ``k``-th oldest pixel: a head register's (oldest first,
        each counted when full), else the inner entry ``k`` less the full heads places
        behind the oldest."""
        edge = self.edge
        layout = self.dut.o.payload.shape()
        behind = (k - edge.outside)[:len(k)]
        width = len(getattr(data.View(layout, edge.heads[0][1]), field).as_value())
        there = Const(0, width)
        for a, word in enumerate(edge.slots(m, layout)):
            there = Mux(edge.offset(a) == behind, getattr(word, field).as_value(), there)
        before = Const(0, len(k))
        value = there
        picks = []
        for valid, reg in edge.heads:
            picks.append((valid & (k == before), getattr(data.View(layout, reg), field).as_value()))
            before = before + valid
        for hit, head in reversed(picks):
            value = Mux(hit, head, value)
        return value

    # --- the properties ---------------------------------------------------------------------
    def _hold(self, m, i, o, take_in, take_out, stages):
        """Rule 2: a pending output keeps its valid and payload until it is taken (a reset
        in between may clear it)."""
        stalled = Signal(name="past_stalled")
        payload = Signal(len(o.payload.as_value()), name="past_payload")
        m.d.sync += [stalled.eq(o.valid & ~o.ready), payload.eq(o.payload.as_value())]
        # ``stalled`` is reset with the unit: a reset in the stalled cycle clears the check.
        self._check(m, ~stalled | (o.valid & (o.payload.as_value() == payload)),
                           "hold: o.valid/o.payload changed while stalled")
        self._exercise(m, stalled & o.valid, "hold: a pixel held through a stall")

    def _ready(self, m, i, o, take_in, take_out, stages):
        occ = self._occupancy(m, take_in, take_out)
        depth = self.fifo_depth
        if depth is None:
            raise ValueError("ready: the unit has no fifo_depth")
        self._check(m, i.ready == (occ < depth),
                    "ready: i.ready is not 'fewer than fifo_depth pixels in flight'")
        self._exercise(m, take_in & o.valid & ~o.ready,
                       "ready: a pixel taken while the output is stalled")

    def _ahead(self, m, width, stages, prefix=""):
        """``ahead[j]``: valid stages downstream of stage ``j``, as comb signals summed from
        the output backwards (linear in the stages); and their total."""
        ahead, run = [None] * len(stages), Const(0, width)
        for j in reversed(range(len(stages))):
            ahead[j] = run
            nxt = Signal(width, name=f"{prefix}valid_from_stage{j + 1}")
            m.d.comb += nxt.eq(run + stages[j][0])
            run = nxt
        return ahead, run

    def _occupancy(self, m, take_in, take_out):
        """Pixels accepted and not delivered, counted at the ports from reset; lemma: the
        chain's valid stages + the FIFO's occupancy (+ the pixels in a texel cache in front
        of the edge)."""
        occ = Signal(self._width(), name="in_flight")
        m.d.sync += occ.eq(occ + take_in - take_out)
        if self.edge is not None and self._chain is not None:
            self._lemma(m, occ == self._in_cache(m, take_in) + self._chain + self.edge.edge.level,
                        "pixels in flight = valid stages + FIFO occupancy" if self.cache is None
                        else "pixels in flight = pixels in the cache + valid stages + FIFO occupancy")
        return occ

    def _in_cache(self, m, take_in):
        """Pixels taken at ``i`` and not yet into the chain: 0, or with a texel cache in
        front of the edge (a ``map_memory = "axi"`` pipeline) a ghost counter, tied by
        lemmas to the cache's lookup registers (the pixel read, its words read, their skid
        register, its words settled, their distances, the pixel looked up), queue, head, data-read and words-read registers, output skid and output register
        (``TextureCache.regs``) and its queue count. Made once per contract."""
        if self.cache is None:
            return Const(0, 1)
        if getattr(self, "_cache_ghost", None) is not None:
            return self._cache_ghost
        c, r = self.cache, self.cache.regs
        ghost = Signal(self._width(), name="in_cache")
        m.d.sync += ghost.eq(ghost + take_in - (c.o.valid & c.o.ready))
        count = (r.in_seq - r.out_seq)[:len(r.in_seq)]
        self._lemma(m, count <= c.geom.queue, "the cache's queue holds at most its entries")
        self._lemma(m, r.count == count, "the cache's queue count = its sequence numbers apart")
        read = r.q_f0 + r.q_f1 + r.q_v2 + r.q_v1
        self._lemma(m, read + r.q_unread == count,
                    "the cache's queue entries read and unread are its queued ones")
        qb = len(r.q_read)
        if qb:
            self._lemma(m, r.q_read == (r.out_seq[:qb] + read)[:qb],
                        "the cache's next queue read is past the entries read")
        self._lemma(m, r.q_avail == (r.q_unread != 0), "the cache's queue has an entry to read")
        self._lemma(m, r.q_en == ~(r.q_f1 & r.q_v2), "the cache's queue read is enabled")
        self._lemma(m, r.head_ok == r.pop_ok, "the cache's queue head may leave as its registers say")
        self._lemma(m, r.hd_stall == (r.hd_valid & r.wd_valid & r.o_skid),
                    "the cache's head register waits behind its full read and skid registers")
        self._lemma(m, ~r.q_f1 | r.q_f0, "the cache's queue fabric registers fill in order")
        self._lemma(m, r.q_wr == r.q_rd ^ (r.q_f0 & ~r.q_f1),
                    "the cache's queue ring writes past its entries")
        self._lemma(m, r.go == (~r.flushing & r.look_valid & (r.count != c.geom.queue)),
                    "the cache's lookup may go: not flushing, a pixel, a free entry")
        self._lemma(m, (r.go_hit == (r.go & r.look_hit)) & (r.go_miss == (r.go & r.miss_ok)),
                    "the cache's lookup's go and hit, go and miss_ok in registers of their own")
        self._lemma(m, ~r.sk_valid | r.ws_valid,
                    "the cache's skid register is full only behind its words settled")
        self._lemma(m, ghost == r.in_valid + r.rw_valid + r.sk_valid + r.ws_valid + r.ds_valid
                    + r.look_valid + count + r.hd_valid + r.rd_valid + r.wd_valid + r.o_skid
                    + c.o.valid,
                    "pixels in the cache = its lookup, queue, read and output registers")
        self._cache_ghost = ghost
        return ghost

    def _quiet(self, m, i, o, take_in, take_out, stages):
        occ = self._occupancy(m, take_in, take_out)
        self._check(m, ~o.valid | (occ != 0), "quiet: o.valid with nothing in flight")
        self._exercise(m, take_out, "quiet: a pixel leaves")

    def _order(self, m, i, o, take_in, take_out, stages):
        bits = len(i.payload.tag)
        n_in, n_out = Signal(bits, name="tag_in"), Signal(bits, name="tag_out")
        m.d.sync += [n_in.eq(n_in + take_in), n_out.eq(n_out + take_out)]
        m.d.comb += Assume(~i.valid | (i.payload.tag == n_in))
        self._check(m, ~o.valid | (o.payload.tag == n_out), "order: output tag out of sequence")
        self._exercise(m, take_out & (n_out == 1), "order: two pixels enter and leave in order")
        edge = self._fifo(m)
        if edge is None or not stages:
            return
        # The FIFO's output register holds n_out (the property), each full head register
        # behind it the next tag, the oldest inner entry (at the read pointer) n_out + the
        # full heads, and every other entry one more than the entry at the address before
        # it: lemmas per address, local (no offsets).
        n = edge.inner_depth
        produce, consume = edge.produce, edge.consume
        inner = edge.inner_level
        slots = edge.slots(m, o.payload.shape())
        after_head = n_out + edge.heads[0][0]
        for k, (valid, reg) in enumerate(edge.heads[1:], start=1):
            tag = data.View(o.payload.shape(), reg).tag
            self._lemma(m, ~valid | (tag == after_head[:bits]),
                        f"the FIFO's head register {k} holds the tag after the ones before it")
            after_head = after_head + valid
        head = Signal(bits, name="tag_fifo_head")
        m.d.comb += head.eq(after_head)
        youngest = head                  # the tag after the FIFO's youngest pixel
        for a, word in enumerate(slots):
            after = (a + 1) % n
            self._lemma(m, ~((consume == a) & (inner != 0)) | (word.tag == head),
                        "the FIFO's oldest entry holds the tag after the output's")
            self._lemma(m, ~(edge.holds(after) & (consume != after)) |
                        (slots[after].tag == (word.tag + 1)[:bits]),
                        "the FIFO's entries hold consecutive tags")
            youngest = Mux((inner != 0) & (produce == after), (word.tag + 1)[:bits], youngest)
        # The chain shifts every cycle, so stage k holds what entered it k cycles ago. A
        # ghost delay line beside it carries the count of pixels that had entered by then
        # (g_k): a valid stage holds tag g_k, g_k = g_(k+1) + valid_(k+1), the next pixel
        # in gets one past g_1's stage, and the FIFO's youngest is the one before stage
        # L's. Each lemma relates two neighbours (a long chain of muxes and adders from
        # the output backwards was too deep for the solver past ~20 stages).
        entry = Signal(bits, name="tag_into_chain")
        m.d.sync += entry.eq(entry + self._valid_in)
        ghosts, prev = [], entry
        for k in range(1, len(stages) + 1):
            g = Signal(bits, name=f"tag_entered_stage{k}")
            m.d.sync += g.eq(prev)
            ghosts.append(g)
            prev = g
        for k, (valid, tag) in enumerate(stages):
            if tag is not None:
                self._lemma(m, ~valid | (tag == ghosts[k]), "a valid stage holds the tag it entered with")
            if k + 1 < len(stages):
                self._lemma(m, ghosts[k] == (ghosts[k + 1] + stages[k + 1][0])[:bits],
                            "the ghost tags of neighbouring stages differ by the older one's valid")
        self._lemma(m, entry == (ghosts[0] + stages[0][0])[:bits],
                    "the next pixel into the chain is one past stage 1's ghost tag")
        self._lemma(m, youngest == ghosts[-1], "the FIFO's youngest is the one before stage L's")
        if self.cache is None:
            self._lemma(m, n_in == entry, "next input tag is one past the youngest in flight")
            return
        # The cache in front of the edge: the tag after the chain's youngest is the next
        # one the cache delivers, the next input's that plus the pixels in the cache.
        c = self.cache
        n_edge = Signal(bits, name="tag_out_of_cache")
        m.d.sync += n_edge.eq(n_edge + (c.o.valid & c.o.ready))
        self._lemma(m, n_edge == entry, "the cache's next pixel is the chain's next")
        self._lemma(m, n_in == (n_edge + self._in_cache(m, take_in))[:bits],
                    "next input tag is one past the youngest in flight")
        self._cache_order(m, n_edge, bits)

    def _cache_order(self, m, n_edge, bits):
        """The tags in the cache, oldest first from ``n_edge`` (the next one it delivers):
        its output register, its words-read and data-read registers, its head register, its
        queue's entries from the read sequence number (read through asynchronous ports added
        to the queue's memory, one per address; the entries read ahead of the pops, in its
        two fabric registers, its output register and its RAM's register, are the entries
        from that number on), then the pixels of its lookup and the stages before it (the
        lookup, the distances, the words settled, the skid, the words read and the pixel
        read), whose carried fields wait in order in a FIFO of their own."""
        c, r, g = self.cache, self.cache.regs, self.cache.geom
        frag = self._frags.get(id(c))
        ram = _subfragment(frag, "queue") if frag is not None else None
        inst = _subfragment(ram, "mem") if ram is not None else None     # its generic form
        if not isinstance(inst, MemoryInstance) or "tag" not in r.rd_extra:
            return
        layout = c.queue_layout(g, c.extra)
        qb = g.queue.bit_length() - 1
        count = (r.in_seq - r.out_seq)[:len(r.in_seq)]
        def consecutive(at, regs):
            """Each register ``(valid, tag, name of its expected tag or None, lemma)`` in
            turn holds the tag ``at``, then one past it for each valid one; returns the tag
            after the last."""
            for valid, tag, name, text in regs:
                if name is not None:
                    named = Signal(bits, name=name)
                    m.d.comb += named.eq(at)
                    at = named
                self._lemma(m, ~valid | (tag == at[:bits]), text)
                at = at + valid
            return at

        after_hd = consecutive(n_edge, [
            (c.o.valid, c.o.payload.tag, None, "the cache's output register holds the chain's next tag"),
            (r.o_skid, r.o_skid_extra["tag"], None,
             "the cache's output skid register holds the tag after its output's"),
            (r.wd_valid, r.wd_extra["tag"], None,
             "the cache's words-read register holds the tag after its output skid's"),
            (r.rd_valid, r.rd_extra["tag"], "tag_cache_read_register",
             "the cache's read register holds the tag after its words-read register's"),
            (r.hd_valid, r.hd_extra["tag"], "tag_cache_head_register",
             "the cache's head register holds the tag after its read register's")])
        at_q = Signal(bits, name="tag_cache_queue_head")
        m.d.comb += at_q.eq(after_hd)
        head = inst.origins[0].read_ports[0].data
        oldest = r.out_seq[:qb] if qb else Const(0, 1)
        for a in range(g.queue):
            word = Signal(len(head.as_value()), name=f"cache_queue_slot{a}")
            inst.read_port(domain="comb", addr=Const(a, max(1, qb)), data=word, en=Const(1),
                           transparent_for=())
            word = data.View(layout, word)
            offset = (Const(a, max(1, qb)) - oldest)[:qb] if qb else Const(0, 1)
            self._lemma(m, ~(offset < count) | (word.tag == (at_q + offset)[:bits]),
                        "the cache's queue holds consecutive tags from its oldest")
            at = oldest
            ring = [Value.cast(f) for f in r.q_fab]
            for valid, held in ((r.q_f0, Mux(r.q_rd, ring[1], ring[0])),
                                (r.q_f1, Mux(r.q_rd, ring[0], ring[1])),
                                (r.q_v2, r.queue.r_data), (r.q_v1, head)):
                self._lemma(m, ~((at == a) & valid) | (Value.cast(held) == word.as_value()),
                            "the cache's queue reads hold its entries in order from its oldest")
                at = (at + valid)[:qb] if qb else at
        # the pixels of the lookup and the stages before it, whose carried fields wait in
        # a FIFO of their own (read through asynchronous ports added to its memory)
        staged = r.look_valid + r.ds_valid + r.ws_valid + r.sk_valid + r.rw_valid + r.in_valid
        self._lemma(m, (r.x_in - r.x_out)[:len(r.x_in)] == staged,
                    "the cache's carried-field FIFO holds the pixels of its lookup stages")
        xinst = _subfragment(frag, "extras")
        if not isinstance(xinst, MemoryInstance):
            return
        first = Signal(bits, name="tag_cache_lookup")
        m.d.comb += first.eq(at_q + count)
        xlayout = data.StructLayout(c.extra)
        for a in range(1 << len(r.x_in)):
            word = Signal(xlayout.size, name=f"cache_extras_slot{a}")
            xinst.read_port(domain="comb", addr=Const(a, len(r.x_in)), data=word, en=Const(1),
                            transparent_for=())
            word = data.View(xlayout, word)
            offset = (Const(a, len(r.x_in)) - r.x_out)[:len(r.x_in)]
            self._lemma(m, ~(offset < staged) | (word.tag == (first + offset)[:bits]),
                        "the cache's carried-field FIFO holds consecutive tags from its lookup's")

    def _latency(self, m, i, o, take_in, take_out, stages):
        """o.ready held high: the valid chain and the tags are a plain delay line."""
        m.d.comb += Assume(o.ready)
        self._check(m, i.ready, "latency: i.ready low with o.ready held high")
        valid, tag = [i.valid], [i.payload.tag]
        for n in range(1, self.port_latency + 1):
            v, t = Signal(name=f"ref_valid{n}"), Signal.like(i.payload.tag, name=f"ref_tag{n}")
            m.d.sync += [v.eq(valid[-1]), t.eq(tag[-1])]
            valid.append(v)
            tag.append(t)
        self._check(m, o.valid == valid[-1],
                    "latency: o.valid is not i.valid delayed by port_latency")
        self._check(m, ~o.valid | (o.payload.tag == tag[-1]),
                    "latency: o.tag is not i.tag delayed by port_latency")
        self._exercise(m, take_out, "latency: a pixel enters and leaves")
        if len(stages) != self.latency:
            return
        for n, (v, t) in enumerate(stages, start=1):
            self._lemma(m, v == valid[n], "stage n valid = i.valid n cycles ago")
            if t is not None:
                self._lemma(m, ~v | (t == tag[n]), "stage n tag = i.tag n cycles ago")
        edge = self._fifo(m)
        if edge is None or self.port_latency != self.latency + len(edge.heads) + 1:
            return
        # The FIFO drains every cycle: its inner queue holds at most the pixel the chain
        # wrote in the last cycle, the head registers the ones before (the prefetch register
        # the one of two cycles ago, the output register's is o's).
        after = valid[self.latency + 1]
        self._lemma(m, edge.inner_level == after, "the FIFO holds the last cycle's pixel only")
        for n, (hv, reg) in enumerate(edge.heads[1:], start=1):
            back = self.latency + 1 + len(edge.heads) - n
            self._lemma(m, hv == valid[back], f"the FIFO's head register {n} holds the pixel of {back} cycles ago")
            self._lemma(m, ~hv | (data.View(o.payload.shape(), reg).tag == tag[back]),
                        f"the FIFO's head register {n} holds the tag of {back} cycles ago")
        for a, word in enumerate(edge.slots(m, o.payload.shape())):
            consume = edge.consume
            self._lemma(m, ~after | (consume != a) | (word.tag == tag[self.latency + 1]),
                        "the FIFO's entry is the chain's output of the last cycle")

    def _cover(self, m, i, o, take_in, take_out, stages):
        stalled = Signal(name="was_stalled")
        m.d.sync += stalled.eq(o.valid & ~o.ready)
        m.d.comb += [Cover(take_out), Cover(o.valid & ~o.ready), Cover(stalled & take_out),
                     Cover(take_in & take_out)]

    def _host(self, name):
        """A palette host port: ``w_en``, ``swap``, ... of a PaletteLUT, ``lut_w_en``, ... of
        a scene pipeline (None when absent, e.g. ``w_ready`` of a unit)."""
        dut = self.dut
        return getattr(dut, name, None) if hasattr(dut, "swap") else getattr(dut, f"lut_{name}", None)

    def _bank(self, m, i, o, take_in, take_out, stages):
        dut, size = self.dut, self.dut.cfg.palette_size
        swap, bank_out = self._host("swap"), self._host("bank")
        w_en, w_addr, w_data = self._host("w_en"), self._host("w_addr"), self._host("w_data")
        w_ready = self._host("w_ready")
        wrote = w_en if w_ready is None else w_en & w_ready        # the writes the unit took
        sel, pick = self.watch_addr, self.watch_pick
        sel_q, first = Signal.like(sel, reset_less=True), Signal(init=1, reset_less=True)
        m.d.sync += [sel_q.eq(sel), first.eq(0)]
        m.d.comb += [Assume(first | (sel == sel_q)), Assume(sel < size)]
        front = Signal(name="ref_front")                 # reset with the unit, like its bank
        with m.If(swap):
            m.d.sync += front.eq(~front)
        self._check(m, bank_out == front, "bank: the bank output is not the front bank")
        word = len(w_data.as_value())
        # The watched entry in bank 0 and bank 1 (memory is not reset, neither are these).
        shadow = [Signal(word, name=f"ref_bank{b}_entry", reset_less=True) for b in (0, 1)]
        with m.If(wrote & (w_addr == sel)):
            with m.If(front):
                m.d.sync += shadow[0].eq(w_data.as_value())
            with m.Else():
                m.d.sync += shadow[1].eq(w_data.as_value())
        occ = self._occupancy(m, take_in, take_out)
        watching, ahead = Signal(name="watching"), Signal.like(occ, name="watch_ahead")
        expected = Signal(word, name="watch_expected")
        # Which index the watched pixel looks up: a PaletteLUT's input carries it; a scene
        # pipeline's fetch finds it, so the pixel is followed to the LUT's input (``match``:
        # it looked up the watched entry).
        lut = getattr(dut, "units", {}).get("palette")
        if lut is None:
            start = take_in & (i.payload.index == sel) & ~watching & pick
            match, before = Const(1), Const(0)
        else:
            start = take_in & ~watching & pick
            take_lut = lut.i.valid & lut.i.ready
            occ_f = Signal.like(occ, name="before_lut")          # accepted, not yet at the LUT
            m.d.sync += occ_f.eq(occ_f + take_in - take_lut)
            before, ahead_f = Signal(name="watch_before_lut"), Signal.like(occ, name="watch_ahead_lut")
            match, wbank = Signal(name="watch_match"), Signal(name="watch_bank")
            at_lut = before & take_lut & (ahead_f == 0)
            with m.If(start):
                m.d.sync += [before.eq(1), ahead_f.eq(occ_f - take_lut), wbank.eq(front)]
            with m.Elif(at_lut):
                m.d.sync += [before.eq(0), match.eq(lut.i.payload.index == sel)]
            with m.Elif(before & take_lut):
                m.d.sync += ahead_f.eq(ahead_f - 1)
        deliver = watching & take_out & (ahead == 0)
        with m.If(start):
            m.d.sync += [watching.eq(1), ahead.eq(occ - take_out),
                         expected.eq(Mux(front, shadow[1], shadow[0]))]
        with m.Elif(deliver):
            m.d.sync += watching.eq(0)
        with m.Elif(watching & take_out):
            m.d.sync += ahead.eq(ahead - 1)
        self._check(m, ~deliver | ~match | (o.payload.color.as_value() == expected),
                    "bank: a pixel read another bank than the one in front when it was accepted")
        swapped = Signal(name="swapped_in_flight")
        with m.If(start):
            m.d.sync += swapped.eq(0)
        with m.Elif(watching & swap):
            m.d.sync += swapped.eq(1)
        m.d.comb += Cover(deliver & match & swapped & (shadow[0] != shadow[1]) & (expected != 0))
        if not self.lemmas:
            return
        # Lemmas (k-induction): the shadows are the memory's entries (read through two
        # asynchronous ports observe_pipes added to the table), and where the watched pixel
        # is, with what it will read.
        rec = self._record(dut if lut is None else lut)
        ports = rec["memories"].get("table") if rec else None
        if not ports or self._fifo(m) is None:
            return
        for b, port in enumerate(ports):
            m.d.comb += port.addr.eq(sel + b * size)
            self._lemma(m, shadow[b] == port.data, "the shadow of the watched entry is the table's")
        # The LUT's stages, input -> output, with the entry each holds: the table is read
        # at the LUT's input, so stage n < depth holds its n-th read register (an in-range
        # index: oor low), the last stage (depth) the chain's output colour.
        reads = rec["reads"].get("table", [])
        depth = len(rec["valid"]) - 1
        lut_stages = [(rec["valid"][n], ~rec["oors"][n] & (reads[n - 1] == expected))
                      for n in range(1, min(depth - 1, len(reads)) + 1)]
        if len(lut_stages) != depth - 1:
            return                       # a stage whose entry is not known: no lemmas
        lut_stages.append((rec["valid"][-1], rec["o"].payload.color.as_value() == expected))

        def in_lut(offset, matched):
            """The watched pixel is in a LUT stage with ``offset`` + (valid stages downstream)
            pixels ahead of it, holding its entry if ``matched``."""
            found, downstream = Const(0), Const(0, len(occ))
            for v, holds in reversed(lut_stages):
                found = found | (v & (offset + downstream == ahead) & (~matched | holds))
                downstream = downstream + v
            return found

        level = self.edge.edge.level
        # Past the LUT: in the FIFO (its entry ``ahead``, oldest first) or in a LUT stage
        # behind the FIFO's pixels.
        self._lemma(m, ~(watching & ~before) | (((ahead < level) & (~match | (self._in_fifo(m, "color", ahead) == expected))) |
                                                ((ahead >= level) & in_lut(level, match))),
                    "past the fetch it waits in the FIFO or the LUT with its entry")
        if lut is None:
            return
        fetch = self._record(dut.units["fetch"])
        valid = fetch["valid"][1:]
        banks = [fetch["banks"][n] for n in range(1, len(valid) + 1)]
        for b, pending in enumerate(self._counters[(id(dut), "lut_pending")]):
            self._lemma(m, pending == sum(v & (bank == b) for v, bank in zip(valid, banks, strict=False)),
                        "the per-bank counters count the fetch stages' bank bits")
        self._lemma(m, occ_f == sum(valid), "pixels before the LUT = valid fetch stages")
        found, downstream = Const(0), Const(0, 4)
        for v, bank in reversed(list(zip(valid, banks, strict=False))):
            found = found | (v & (downstream == ahead_f) & (bank == wbank))
            downstream = downstream + v
        waiting_f = watching & before
        self._lemma(m, ~waiting_f | found,
                    "the watched pixel is in the fetch with the bank of its acceptance")
        self._lemma(m, ~waiting_f | (Mux(wbank, ports[1].data, ports[0].data) == expected),
                    "its entry is unchanged while it waits")
        in_flight = Const(0, len(occ))
        for v, _ in lut_stages:
            in_flight = in_flight + v
        self._lemma(m, ~waiting_f | (ahead == ahead_f + in_flight + level), "pixels ahead of it")
        self._lemma(m, watching | ~before, "only the watched pixel is followed")
