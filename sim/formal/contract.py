"""The stream contract as Amaranth properties, in a formal-only wrapper around a unit.

:class:`StreamContract` elaborates a unit (a ``wiring.Component`` with ``i``/``o``
``amaranth.lib.stream`` ports and a ``tag`` payload field) inside a top that drives nothing:
every input of the unit (``i.valid``, ``i.payload``, ``o.ready``, host ports, ``rst``) is a
free input of the model, so the solver plays every producer, consumer and host there is.
One wrapper checks one property (:data:`PROPERTIES`):

``hold``     o.payload and o.valid are held while ``o.valid & ~o.ready`` (stream rule 2);
``ready``    ``i.ready`` is high while ``o.valid`` is low: a slow consumer never stops the
             pipe from filling (the mutation ``adv = o.ready`` of rtl/pipe.py fails it);
``order``    every accepted input comes out exactly once and in order: the inputs carry
             consecutive tags (assumed), the n-th output must carry tag n;
``quiet``    no output without an input: with nothing in flight (accepted minus delivered
             is 0, counted from reset) ``o.valid`` is low;
``latency``  with ``o.ready`` held high the output is the input ``latency`` cycles later,
             valid for valid and tag for tag (no bubble added, none removed);
``cover``    vacuity check: a transfer, a stall and a transfer after a stall are reachable.
``bank``     PaletteLUT's double buffer (units with ``swap``/``w_*``/``bank`` ports, and
             palette scene pipelines with ``lut_*`` ports): a pixel reads the entry of the
             bank that was in front in the cycle it was accepted (by the pipeline, at its
             input, ahead of the fetch), whatever the host writes (the writes the unit
             took: ``lut_w_en & lut_w_ready`` for a pipeline) or swaps while it is in flight
             or stalled. The swap strobe is the frame boundary (the host strobes it between frames; PaletteLUT
             has no frame signal of its own), so all pixels of a frame read one bank and a
             swap strobed while the last pixels of a frame are still in the pipe takes
             effect only for the pixels accepted after it. A symbolic entry (any address,
             fixed for the trace) is shadowed in both banks and one symbolic pixel reading
             it is followed to the output.

k-induction needs the contract to be inductive, so the wrapper also asserts *lemmas* about
the unit's own pipeline registers: the number of valid stages equals the pixels in flight,
the tag held in each valid stage is the one the order says, units that run in lock step
have equal valid chains; for a scene pipeline (units in lock step on copies of one
registered enable, an output buffer behind the last unit: ``BumpPipeline.buffer``) every
copy of the enable is (buffer holds at most one pixel less than its depth), the buffer's
occupancy counts as pixels in flight and its entries, oldest first, hold the tags that
follow the order (with ``o.ready`` held high, ``latency``: the buffer stays empty); and
(``bank``) the shadows are the table's watched entries (two
asynchronous read ports added to the memory while it elaborates), the bank bits in flight
are what the pipeline's ``lut_w_ready`` counters count, and the watched pixel sits where
its position says with the bank of its acceptance. It finds those registers through the
observer every :class:`bumprtl.rtl.pipe.StallPipe` takes (:class:`PipeObserver`, passed
in with the elaboration's platform by :func:`observe_pipes`: the valid chain and the
``tag`` delay line of every pipe, keyed by its input valid), so no unit carries
formal-only code and nothing is patched. ``lemmas=False`` leaves them out (plain BMC, and the broken
units of :mod:`bumprtl.sim.formal.mutants`, whose failure must be the property itself).
"""

import re

from amaranth.hdl import (
    Assert,
    Assume,
    Const,
    Cover,
    Elaboratable,
    Fragment,
    Module,
    Mux,
    Signal,
    Value,
    ValueCastable,
)
from amaranth.lib import wiring

__all__ = ["PROPERTIES", "StreamContract", "PipeObserver", "observe_pipes", "pipeline_layers"]

PROPERTIES = ("hold", "ready", "order", "quiet", "latency", "cover", "bank")

_TAG_REG = re.compile(r"(tag|bank|oor)_d(\d+)$")
CHUNK = 12          # stages per ghost counter of one long pipe (quiet's occupancy lemma)


class PipeObserver:
    """What the contract learns of a unit's pipes while it elaborates: passed to every
    :class:`~bumprtl.rtl.pipe.StallPipe` as its ``observer`` (through the elaboration's
    platform, :func:`bumprtl.rtl.pipe.pipe_observer`). ``seen`` maps ``id(input valid
    signal) -> {"valid": [i.valid, stage1, ...], "adv": adv, "tags": {n: tag register of
    stage n}, "banks": {n: bank register of stage n}, "oors": {n: oor register of stage n},
    "memories": {name: [comb read port, ...]}, "reads": {name: [read data 1, 2 stages after
    the address]}}``; ``read_ports``: that many asynchronous read ports are added to every
    memory a pipe adds with ``StallPipe.memory`` or ``StallPipe.ram`` (generic form), for
    assertions about its contents. One observer per elaboration: nothing process-wide, so
    elaborations may run in parallel threads (``make formal -j 2``)."""

    def __init__(self, read_ports=0):
        self.read_ports, self.seen, self._rams = read_ports, {}, {}

    def pipe(self, pipe):
        pipe_rec = {"valid": list(pipe.valid), "adv": pipe.adv, "tags": {}, "banks": {},
                    "oors": {}, "memories": {}, "reads": {}, "enables": pipe.enable_copies}
        self.seen[id(pipe.valid[0])] = pipe_rec

    def _record(self, pipe):
        return self.seen[id(pipe.valid[0])]

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


class _Observing:
    """The platform an observed elaboration is given: it carries the observer only."""

    def __init__(self, observer):
        self.pipe_observer = observer


def observe_pipes(dut, read_ports=0):
    """Elaborate ``dut`` with a :class:`PipeObserver`: ``(fragment, seen)``."""
    observer = PipeObserver(read_ports)
    fragment = Fragment.get(dut, _Observing(observer))
    return fragment, observer.seen


def pipeline_layers(dut):
    """The lock-step layers of a :class:`~bumprtl.rtl.pipeline.BumpPipeline` (first unit
    of each layer carries the tag), or ``[[dut]]`` for a single unit."""
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
    dut : wiring.Component with ``i``/``o`` streams whose payloads have a ``tag`` field.
    prop : str
    latency : int, optional
        Defaults to ``dut.latency``.
    layers : list of lists of units, optional
        The lock-step layers the pixels pass (default :func:`pipeline_layers`).
    lemmas : bool
        Assert the pipeline-register lemmas that make the property k-inductive.
    """

    def __init__(self, dut, prop, latency=None, layers=None, lemmas=True):
        if prop not in PROPERTIES:
            raise ValueError(f"property must be one of {', '.join(PROPERTIES)}, got {prop!r}")
        self.dut, self.prop, self.lemmas = dut, prop, lemmas
        self.latency = dut.latency if latency is None else latency
        self.layers = layers if layers is not None else pipeline_layers(dut)
        self.lemma_count = 0
        self.messages = {}
        self.exercised = []          # what each property's covers show (_exercise)
        self._free = []
        if prop == "bank":
            if getattr(dut, "cfg", None) is None or dut.cfg.palette_blend:
                raise ValueError("bank: a PaletteLUT without the blend stage")
            self.watch_addr = Signal(len(self._host("w_addr")), name="watch_addr")  # any constant
            self.watch_pick = Signal(name="watch_pick")                    # any sequence
            self._free = [self.watch_addr, self.watch_pick]

    # --- the unit's pipeline registers ------------------------------------------------------
    def _stages(self, pipes):
        """Chain stages input -> output: ``[(valid, tag or None)]``, and the lock-step pairs
        ``[(lead valid, other valid)]``. A scene pipeline's output buffer adds its entries
        (oldest last: nearest the output) as the last layer's stages."""
        stages, lockstep = [], []
        self._layer_stages, self._layer_takes, self._buffer_stages = [], [], 0
        self._lead_pipes = []
        for layer in self.layers:
            recs = [pipes.get(id(unit.i.valid)) for unit in layer]
            lead = recs[0]
            if lead is None:             # not built on a StallPipe: no lemmas (BMC only)
                return [], []
            for n in range(1, len(lead["valid"])):
                stages.append((lead["valid"][n], lead["tags"].get(n)))
            self._layer_stages.append(len(lead["valid"]) - 1)
            self._lead_pipes.append(lead)
            unit = layer[0]
            self._layer_takes.append((unit.i.valid & unit.i.ready, unit.o.valid & unit.o.ready))
            for rec in recs[1:]:
                if rec is not None:
                    lockstep += list(zip(lead["valid"][1:], rec["valid"][1:], strict=False))
        if self.buffer is not None:
            count, entries = self.buffer["count"], self.buffer["entries"]
            for n in reversed(range(len(entries))):
                stages.append((count > n, entries[n].tag))
            self._layer_stages.append(len(entries))
            last = self.layers[-1][0].o
            self._layer_takes.append((last.valid & last.ready, self.dut.o.valid & self.dut.o.ready))
            self._buffer_stages = len(entries)
        return stages, lockstep

    def _buffer_lemmas(self, m):
        """The output buffer's count is at most its depth and every copy of the enable is
        (count < depth): the units run exactly while the buffer has room for two."""
        count, entries = self.buffer["count"], self.buffer["entries"]
        self._lemma(m, count <= len(entries), "the output buffer holds at most its depth")
        copies = [*self.buffer["runs"].values(),
                  *(c for rec in self._pipes.values() for c in rec.get("enables", ()))]
        for run in copies:
            self._lemma(m, run == (count < len(entries)),
                        "every copy of the enable = the output buffer has room")

    def free_inputs(self):
        """Every input of the unit (``i.valid``, ``i.payload``, ``o.ready``, host ports) and
        the clock and reset: the model's free inputs, chosen by the solver in every cycle."""
        ports = []
        for _path, member, value in self.dut.signature.flatten(self.dut):
            if member.flow == wiring.In:
                ports.append(value.as_value() if isinstance(value, ValueCastable) else Value.cast(value))
        return ports + self._free

    def _check(self, m, test, message, src_loc_at=1):
        """``Assert(test)``; sby names a failed one by its source line, ``messages`` maps
        that line back to ``message``."""
        check = Assert(test, message, src_loc_at=src_loc_at)
        self.messages[f"{check.src_loc[0]}:{check.src_loc[1]}"] = message
        m.d.comb += check

    def _lemma(self, m, test, what):
        self.lemma_count += 1
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
        ports = 2 if self.prop == "bank" else 0          # the watched entry of both banks
        if self.lemmas:
            fragment, pipes = observe_pipes(dut, ports)
        else:
            fragment, pipes = Fragment.get(dut, platform), {}
        self._pipes = pipes
        m.submodules.dut = _Built(fragment)
        i, o = dut.i, dut.o
        take_in = i.valid & i.ready
        take_out = o.valid & o.ready
        self.buffer = getattr(dut, "buffer", None) if self.lemmas else None
        stages, lockstep = self._stages(pipes) if self.lemmas else ([], [])
        if self.lemmas:
            for lead, other in lockstep:
                self._lemma(m, lead == other, "lock-step units have equal valid chains")
            if self.buffer is not None and stages:
                self._buffer_lemmas(m)
        getattr(self, f"_{self.prop}")(m, i, o, take_in, take_out, stages)
        return m

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
        self._check(m, o.valid | i.ready, "ready: i.ready low while o.valid low")
        self._exercise(m, ~o.valid & take_in, "ready: a pixel taken while the output is empty")

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

    def _occupancy(self, m, take_in, take_out, stages):
        # Wide enough for every pixel that can be in flight (at most one per stage) even
        # without the lemmas (BMC), where a wrapping counter would be a false failure.
        width = (max(len(stages), self.latency) + 2).bit_length() + 1
        occ = Signal(width, name="in_flight")
        m.d.sync += occ.eq(occ + take_in - take_out)
        runs = self._runs(stages) if self.lemmas and stages else []
        if runs:
            # One ghost counter per run of stages equal to its valid stages, and their sum
            # equal to the whole count: small sums instead of one long one (counting is what
            # SAT solvers find hard).
            total = Const(0, width)
            for name, took, gave, first, count, what in runs:
                occ_r = Signal(width, name=f"in_flight_{name}")
                m.d.sync += occ_r.eq(occ_r + took - gave)
                _ahead, in_run = self._ahead(m, width, stages[first:first + count], f"{name}_")
                self._lemma(m, occ_r == in_run, what)
                total = (total + occ_r)[:width]
            self._lemma(m, occ == total, "pixels in flight = sum over the runs")
        elif self.lemmas and stages:
            _ahead, total = self._ahead(m, width, stages)
            self._lemma(m, occ == total, "valid stages = pixels in flight")
        return occ

    def _runs(self, stages):
        """The runs of the occupancy lemma, ``(name, took, gave, first stage, stages, what)``:
        a pipeline's layers (each counted by its lead unit's handshakes; the output buffer's
        by the last unit's output and the pipeline's); one long StallPipe (Kim's setup: 46
        stages at the formal widths) in runs of CHUNK stages, each gaining valid[first - 1]
        and losing valid[last] on every adv (valid[n] <= valid[n - 1]; valid[0] is i.valid
        and adv is i.ready). None of them (one count over every stage) for a short pipe."""
        if len(self._layer_takes) > 1:
            starts = [sum(self._layer_stages[:n]) for n in range(len(self._layer_stages))]
            return [(f"layer{n}", took, gave, first, count,
                     "valid stages of a layer = its pixels in flight")
                    for n, ((took, gave), first, count)
                    in enumerate(zip(self._layer_takes, starts, self._layer_stages, strict=False))]
        if len(stages) > CHUNK and len(self._lead_pipes) == 1:
            valid, adv = self._lead_pipes[0]["valid"], self._lead_pipes[0]["adv"]
            runs = []
            for first in range(1, len(valid), CHUNK):
                last = min(first + CHUNK, len(valid)) - 1
                runs.append((f"stages{first}_{last}", adv & valid[first - 1], adv & valid[last],
                             first - 1, last - first + 1,
                             "valid stages of a run = its pixels in flight"))
            return runs
        return []

    def _quiet(self, m, i, o, take_in, take_out, stages):
        occ = self._occupancy(m, take_in, take_out, stages)
        self._check(m, ~o.valid | (occ != 0), "quiet: o.valid with nothing in flight")
        self._exercise(m, take_out, "quiet: a pixel leaves")

    def _order(self, m, i, o, take_in, take_out, stages):
        bits = len(i.payload.tag)
        n_in, n_out = Signal(bits, name="tag_in"), Signal(bits, name="tag_out")
        m.d.sync += [n_in.eq(n_in + take_in), n_out.eq(n_out + take_out)]
        m.d.comb += Assume(~i.valid | (i.payload.tag == n_in))
        self._check(m, ~o.valid | (o.payload.tag == n_out), "order: output tag out of sequence")
        self._exercise(m, take_out & (n_out == 1), "order: two pixels enter and leave in order")
        if self.lemmas and stages:
            # Consecutive valid stages hold consecutive tags, the one nearest the output
            # holds n_out and the next input gets one past the youngest: a chain of muxes
            # from the output backwards (no counting, which SAT solvers find hard).
            expect = n_out
            for j in reversed(range(len(stages))):
                valid, tag = stages[j]
                if tag is None:
                    return
                self._lemma(m, ~valid | (tag == expect), "valid stages hold consecutive tags")
                nxt = Signal(bits, name=f"tag_after_stage{j + 1}")
                m.d.comb += nxt.eq(Mux(valid, tag + 1, expect))
                expect = nxt
            self._lemma(m, n_in == expect, "next input tag is one past the youngest in flight")

    def _latency(self, m, i, o, take_in, take_out, stages):
        """o.ready held high: the valid chain and the tags are a plain delay line."""
        m.d.comb += Assume(o.ready)
        self._check(m, i.ready, "latency: i.ready low with o.ready held high")
        valid, tag = [i.valid], [i.payload.tag]
        for n in range(1, self.latency + 1):
            v, t = Signal(name=f"ref_valid{n}"), Signal.like(i.payload.tag, name=f"ref_tag{n}")
            m.d.sync += [v.eq(valid[-1]), t.eq(tag[-1])]
            valid.append(v)
            tag.append(t)
        self._check(m, o.valid == valid[-1], "latency: o.valid is not i.valid delayed by latency")
        self._check(m, ~o.valid | (o.payload.tag == tag[-1]),
                           "latency: o.tag is not i.tag delayed by latency")
        self._exercise(m, take_out, "latency: a pixel enters and leaves")
        if self.buffer is not None and stages:
            self._lemma(m, self.buffer["count"] == 0, "the output buffer stays empty")
            stages = stages[:len(stages) - self._buffer_stages]
        if self.lemmas and len(stages) == self.latency:
            for n, (v, t) in enumerate(stages, start=1):
                self._lemma(m, v == valid[n], "stage n valid = i.valid n cycles ago")
                if t is not None:
                    self._lemma(m, ~v | (t == tag[n]), "stage n tag = i.tag n cycles ago")

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
        occ = self._occupancy(m, take_in, take_out, stages)
        watching, ahead = Signal(name="watching"), Signal.like(occ, name="watch_ahead")
        expected = Signal(word, name="watch_expected")
        # Which index the watched pixel looks up: a PaletteLUT's input carries it; a scene
        # pipeline's fetch finds it, so the pixel is followed to the LUT's input (``match``:
        # it looked up the watched entry).
        lut = getattr(dut, "units", {}).get("palette")
        if lut is None:
            start = take_in & (i.payload.index == sel) & ~watching & pick
            match = Const(1)
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
        rec = self._pipes.get(id((dut if lut is None else lut).i.valid))
        ports = rec["memories"].get("table") if rec else None
        if not ports:
            return
        for b, port in enumerate(ports):
            m.d.comb += port.addr.eq(sel + b * size)
            self._lemma(m, shadow[b] == port.data, "the shadow of the watched entry is the table's")
        # The LUT's stages, input -> output, with the entry each holds: the table is read
        # at the LUT's input, so stage n < depth holds its n-th read register (an in-range
        # index: oor low), the last stage (depth) the output colour.
        unit = dut if lut is None else lut
        reads = rec["reads"].get("table", [])
        depth = len(rec["valid"]) - 1
        lut_stages = [(rec["valid"][n], ~rec["oors"][n] & (reads[n - 1] == expected))
                      for n in range(1, min(depth - 1, len(reads)) + 1)]
        if len(lut_stages) != depth - 1:
            return                       # a stage whose entry is not known: no lemmas
        lut_stages.append((rec["valid"][-1], unit.o.payload.color.as_value() == expected))

        def in_lut(offset, matched):
            """The watched pixel is in a LUT stage with ``offset`` + (valid stages downstream)
            pixels ahead of it, holding its entry if ``matched``."""
            found, downstream = Const(0), Const(0, len(occ))
            for v, holds in reversed(lut_stages):
                found = found | (v & (offset + downstream == ahead) & (~matched | holds))
                downstream = downstream + v
            return found

        if lut is None:
            self._lemma(m, ~watching | in_lut(0, Const(1)),
                        "the watched pixel waits in the LUT with its entry")
            return
        fetch = self._pipes[id(dut.units["fetch"].i.valid)]
        valid = fetch["valid"][1:]
        banks = [fetch["banks"][n] for n in range(1, len(valid) + 1)]
        for b, pending in enumerate(dut.lut_pending):
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
        count, entries = self.buffer["count"], self.buffer["entries"]
        in_flight = Const(0, len(occ))
        for v, _ in lut_stages:
            in_flight = in_flight + v
        self._lemma(m, ~waiting_f | (ahead == ahead_f + in_flight + count), "pixels ahead of it")
        # Past the LUT: in the output buffer (entry ``ahead``) or in a LUT stage behind the
        # buffered pixels.
        there = Const(0, word)
        for n in reversed(range(len(entries))):
            there = Mux(ahead == n, entries[n].color.as_value(), there)
        self._lemma(m, ~(watching & ~before) | (((ahead < count) & (~match | (there == expected))) |
                                                ((ahead >= count) & in_lut(count, match))),
                    "past the LUT it waits in the output buffer or the LUT with its entry")
        self._lemma(m, watching | ~before, "only the watched pixel is followed")
