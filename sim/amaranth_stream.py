"""Amaranth-simulator stream helpers shared by every unit test (the Amaranth-simulator
tests of docs/architecture.md, Data flow).

``simulate_stream`` pushes a list of payload dicts through a component's ``i`` stream and
collects the ``o`` stream under one of the traffic patterns of :data:`PATTERNS`
(sim/traffic.py, shared with the cocotb testbenches), then returns the received payload
dicts (with nested layouts flattened to dotted names).
"""

import random
from collections import deque

from amaranth.hdl import Cat, Module, Signal, Value
from amaranth.lib import data
from amaranth.sim import Simulator

from bumprtl.rtl.illumination import Illumination
from bumprtl.rtl.layouts import layout_fields, unpack
from bumprtl.rtl.rotation import VectorRotation
from bumprtl.sim.golden.methods import illumination_fixed, rotation_fixed
from bumprtl.sim.golden.vectors import as_payloads
from bumprtl.sim.traffic import PATTERNS

__all__ = ["PATTERNS", "flatten_payload", "concatenation", "Sampled", "Drive", "simulate_stream", "assert_bit_exact",
           "check_rotation", "check_illumination", "check_datapath"]


def flatten_payload(value, prefix=""):
    """A payload View -> {dotted name: Value}; an ArrayLayout's elements are ``name.j``."""
    out = {}
    for name, _ in value.shape():
        v = value[name]
        if isinstance(v, data.View):
            out.update(flatten_payload(v, f"{prefix}{name}."))
        else:
            out[f"{prefix}{name}"] = v
    return out


def concatenation(signals):
    """``signals`` ({name: Value or View}) as one value: (their concatenation, {name:
    (offset, width)} in it)."""
    values = [Value.cast(v) for v in signals.values()]
    slots, offset = {}, 0
    for name, v in zip(signals, values, strict=True):
        slots[name] = (offset, len(v))
        offset += len(v)
    return Cat(*values), slots


class Sampled:
    """Signals a testbench reads together once a cycle: ``value`` (their concatenation, one
    argument of ``ctx.tick().sample``) and :meth:`cut` (the sampled integer back into the
    signals' values, in ``signals``' order, unsigned). ``signals``: {name: Value or View}."""

    def __init__(self, signals):
        self.value, slots = concatenation(signals)
        self._cuts = [(offset, (1 << width) - 1) for offset, width in slots.values()]

    def cut(self, bits):
        return [bits >> offset & mask for offset, mask in self._cuts]


class Drive:
    """Inputs a testbench drives, set together once a cycle: ``drive[name] = value`` records a
    value (held until changed, as a signal holds it) and ``drive.set(ctx)`` assigns every one
    at once (each ``ctx.set`` settles the whole design again, so a set per input would settle
    it once an input). ``signals``: {name: Value or View}; a value is taken modulo its
    signal's width (two's complement).

    Wired into the simulated top (:func:`driven`), the set is of one signal of its own, which
    drives the inputs through a combinational assignment the simulator compiles; unwired, it
    is of the inputs' concatenation (the same values, the concatenation evaluated by the
    simulator's interpreter each time)."""

    def __init__(self, signals):
        self.cat, self.slots = concatenation(signals)
        self.bits = 0                   # every input 0 until set, wired or not
        self.bus = Signal(len(self.cat), name="drive")
        self.wired = False

    def __setitem__(self, name, value):
        offset, width = self.slots[name]
        mask = ((1 << width) - 1) << offset
        self.bits = (self.bits & ~mask) | ((int(value) << offset) & mask)

    def set(self, ctx):
        ctx.set(self.bus if self.wired else self.cat, self.bits)


def driven(dut, *drives):
    """A top for the simulator: ``dut`` with each :class:`Drive`'s signal assigned to its
    inputs (every Drive given must be set through it from then on)."""
    m = Module()
    m.submodules.dut = dut
    for d in drives:
        m.d.comb += d.cat.eq(d.bus)
        d.wired = True
    return m


def simulate_stream(dut, inputs, pattern="no_stall", seed=0, max_cycles=None, vcd=None,
                    pipe_handshake=False, models=(), hold_first=0):
    """Drive ``inputs`` into ``dut.i``; return ``(outputs, cycles)`` from ``dut.o``.

    Each input is a dict ``{field: int}`` (dotted names for nested layouts). Outputs come
    back as dicts of ints in the same naming. Valid never waits on ready; the payload is held
    until it is taken (stream rules). ``pipe_handshake``: also assert, every cycle, the
    credit rule of a unit or pipeline with a credit edge (rtl/pipe.CreditEdge): ``i.ready``
    is high exactly while fewer than ``dut.fifo_depth`` pixels are inside (taken at ``i``
    before this cycle and not taken at ``o`` before it), and an output offered and not taken
    is offered again the next cycle (a ready that waits on ``o.ready``, or a credit lost or
    made, is bit-exact and fails only this check). ``models``: bench models run beside the
    stream's testbench, each with an async ``process`` and the :class:`Drive` of its inputs
    as ``drive``, wired into the top (a memory model on another port, sim/axi_memory.py).
    ``hold_first``: ``o.ready`` low for the first this many cycles, whatever the pattern
    (long enough, every credit is spent before the pattern's stalls drain the unit: random
    stalls alone never fill its FIFO, :func:`bumprtl.sim.traffic.fill_hold`).
    """
    gap_p, bp_p = PATTERNS[pattern]
    rng = random.Random(seed)
    outputs = []
    limit = max_cycles or 20 * (len(inputs) + 50)
    state = {"cycles": 0, "inside": 0, "held": False}

    # the payload's fields, the input's valid and the output's ready in one ctx.set a cycle;
    # a field not offered holds its last value, as before its first pixel
    drive = Drive({**flatten_payload(dut.i.payload), "i.valid": dut.i.valid,
                   "o.ready": dut.o.ready})

    # the output's payload read as one value a cycle, cut into its fields; the handshake's
    # four bits as another (two samples a cycle, the ports looked up once)
    o_payload, o_fields = Value.cast(dut.o.payload), layout_fields(dut.o.payload.shape())
    handshake = Sampled({"i.valid": dut.i.valid, "i.ready": dut.i.ready,
                         "o.valid": dut.o.valid, "o.ready": dut.o.ready})
    fifo_depth = dut.fifo_depth if pipe_handshake else None

    async def testbench(ctx):
        pending = deque(inputs)
        offered = None
        while len(outputs) < len(inputs):
            if offered is None and pending and rng.random() >= gap_p:
                offered = pending.popleft()
                for name, value in offered.items():
                    drive[name] = value
            drive["i.valid"] = offered is not None
            drive["o.ready"] = rng.random() >= bp_p and state["cycles"] >= hold_first
            drive.set(ctx)
            _, _, bits, o_bits = await ctx.tick().sample(handshake.value, o_payload)
            i_valid, i_ready, o_valid, o_ready = handshake.cut(bits)
            if pipe_handshake:
                inside = state["inside"]
                assert bool(i_ready) == (inside < fifo_depth), (
                    f"cycle {state['cycles']}: i.ready {i_ready} with {inside} pixels inside "
                    f"and {fifo_depth} credits (ready must be exactly a free credit)")
                assert o_valid or not state["held"], (
                    f"cycle {state['cycles']}: an output offered and not taken was withdrawn")
                state["inside"] += bool(i_valid and i_ready) - bool(o_valid and o_ready)
                state["held"] = bool(o_valid and not o_ready)
            if offered is not None and i_ready:
                offered = None
            if o_valid and o_ready:
                outputs.append(unpack(o_fields, int(o_bits)))
            state["cycles"] += 1
            assert state["cycles"] < limit, f"timeout after {limit} cycles ({len(outputs)} outputs)"

    sim = Simulator(driven(dut, drive, *(model.drive for model in models)))
    sim.add_clock(1e-8)
    sim.add_testbench(testbench)
    for model in models:
        sim.add_testbench(model.process, background=True)
    if vcd:
        with sim.write_vcd(vcd):
            sim.run()
    else:
        sim.run()
    return outputs, state["cycles"]


def assert_bit_exact(out, golden, inputs):
    """Every output field equals the golden model's array, and the tags come out in order,
    each once (nothing lost or duplicated)."""
    assert len(out) == len(inputs)
    assert [o["tag"] for o in out] == [i["tag"] for i in inputs]
    for field in out[0]:
        if field != "tag":
            got = [o[field] for o in out]
            bad = [n for n, (g, e) in enumerate(zip(got, golden[field], strict=False)) if g != e]
            assert not bad, (f"{field}: {len(bad)} mismatches, first at {bad[0]}: RTL {got[bad[0]]} "
                             f"golden {golden[field][bad[0]]} (input {inputs[bad[0]]})")


def check_rotation(cfg, codes, pattern="no_stall", seed=0):
    """``VectorRotation(cfg)`` on the input ``codes``, bit for bit against the golden model
    (sim/golden/fixed/); returns ``(latency, cycles)``."""
    inputs = as_payloads(codes, cfg)
    dut = VectorRotation(cfg)
    out, cycles = simulate_stream(dut, inputs, pattern, seed=seed, pipe_handshake=True)
    assert_bit_exact(out, rotation_fixed(codes, cfg), inputs)
    return dut.port_latency, cycles


def check_illumination(cfg, codes, pattern="no_stall", seed=0):
    """``Illumination(cfg)`` on the golden rotation output of ``codes``, bit for bit against
    the golden model; returns ``(latency, cycles)``."""
    rot = rotation_fixed(codes, cfg)
    inputs = as_payloads(rot, cfg)
    dut = Illumination(cfg)
    out, cycles = simulate_stream(dut, inputs, pattern, seed=seed, pipe_handshake=True)
    assert_bit_exact(out, illumination_fixed(rot, cfg), inputs)
    return dut.port_latency, cycles


def check_datapath(cfg, codes, pattern="no_stall", seed=0):
    """Both units bit-exact (the illumination on the golden rotation output); returns
    ``cycles - latency`` of each (the pixel count when nothing stalls)."""
    rot = check_rotation(cfg, codes, pattern, seed)
    ill = check_illumination(cfg, codes, pattern, seed + 1)
    return rot[1] - rot[0], ill[1] - ill[0]
