"""The broken units of sim/formal/mutants.py in the Amaranth simulator: each is broken the way
its docstring says, seen at its ports by the stream checks every unit test uses, and SinCos
itself passes the same checks. make formal proves each one fails its property; make test
runs three of those proofs (tests/sim/formal/test_formal.py), and this file the rest by
simulation, so a broken unit that stopped being broken (and a property that then proves
nothing) fails make test too.

The port checks and the property each one shows (sim/formal/contract.py names them):
``ready`` (and ``credit``, whose port face is the ready rule): i.ready is high exactly
while fewer than fifo_depth pixels are inside (simulate_stream's ``pipe_handshake``);
``order``: every pixel out once, in order (the tags); ``hold``: an offered output is not
withdrawn and keeps its value (the values are SinCos's table); ``quiet``: nothing comes
out before a pixel went in; ``latency``: with nothing stalled, n pixels take n +
port_latency cycles."""

import pytest
from amaranth.sim import Simulator

from bumprtl.rtl.config import Config
from bumprtl.rtl.sincos import SinCos
from bumprtl.rtl.tables import cos_lookup, sin_lookup
from bumprtl.sim.amaranth_stream import simulate_stream
from bumprtl.sim.formal.mutants import MUTANTS
from bumprtl.sim.traffic import fill_hold

# the units built only to read their latency, and those a failed check leaves unsimulated
pytestmark = pytest.mark.filterwarnings("ignore::amaranth.hdl.UnusedElaboratable")

CFG = Config(angle_bits=8, frac_bits=8, tag_bits=8)
# the broken units built around SinCos: all but the two of the bank property, built around
# PaletteLUT (swap_ahead in tests/rtl/test_palette.py, uncarried_bank in make test's quick
# formal run)
AROUND_SINCOS = [name for name, (_cls, prop) in MUTANTS.items() if prop != "bank"]
# the property make formal's run names for the unit -> the port check that shows it
SHOWN_BY = {"ready": "ready", "credit": "ready", "order": "order", "hold": "hold",
            "latency": "latency", "quiet": "quiet"}


def _angles(n):
    return [{"angle": (a * 37) % CFG.full_circle, "tag": a % (1 << CFG.tag_bits)} for a in range(n)]


def port_failures(unit_cls):
    """The port checks ``unit_cls(CFG)`` fails: a dict {check: first message}."""
    failures = {}
    n = 120
    inputs = _angles(n)
    angles = [px["angle"] for px in inputs]
    sin, cos = sin_lookup(CFG, angles).tolist(), cos_lookup(CFG, angles).tolist()
    hold = fill_hold(SinCos(CFG).latency)
    for pattern, seed in (("both", 1), ("backpressure", 2)):
        try:                            # the handshake checked every cycle
            simulate_stream(unit_cls(CFG), inputs, pattern, seed=seed, pipe_handshake=True,
                            hold_first=hold, max_cycles=40 * n)
        except AssertionError as e:
            failures.setdefault("hold" if "withdrawn" in str(e) else "ready", str(e))
        try:                            # what comes out
            out, _ = simulate_stream(unit_cls(CFG), inputs, pattern, seed=seed,
                                     hold_first=hold, max_cycles=40 * n)
        except AssertionError as e:     # fewer pixels out than in
            failures.setdefault("order", f"{pattern}: {e}")
            continue
        tags = [o["tag"] for o in out]
        if tags != [px["tag"] for px in inputs]:
            failures.setdefault("order", f"{pattern}: tags {tags[:8]}...")
        elif [o["sin"] for o in out] != sin or [o["cos"] for o in out] != cos:
            failures.setdefault("hold", f"{pattern}: a value changed on its way out")
    dut = unit_cls(CFG)
    try:
        _, cycles = simulate_stream(dut, inputs, "no_stall", max_cycles=40 * n)
        if cycles != n + dut.port_latency:
            failures.setdefault("latency", f"{cycles} cycles for {n} pixels, port_latency "
                                           f"{dut.port_latency}")
    except AssertionError as e:
        failures.setdefault("order", str(e))
    early = _valid_before_input(unit_cls(CFG))
    if early is not None:
        failures.setdefault("quiet", f"o.valid high in cycle {early} with nothing taken")
    return failures


def _valid_before_input(dut, cycles=40):
    """The first cycle ``dut.o`` offers a pixel while nothing was offered to it (o.ready
    high throughout), or None."""
    seen = []

    async def testbench(ctx):
        ctx.set(dut.o.ready, 1)
        for k in range(cycles):
            _, _, valid = await ctx.tick().sample(dut.o.valid)
            if valid:
                seen.append(k)
                return

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(testbench)
    sim.run()
    return seen[0] if seen else None


def test_sincos_passes_every_port_check():
    """The checks pass on the unit the broken ones are built around (they can pass)."""
    assert port_failures(SinCos) == {}


@pytest.mark.parametrize("name", AROUND_SINCOS)
def test_broken_unit_fails_its_property_at_the_ports(name):
    cls, prop = MUTANTS[name]
    failures = port_failures(cls)
    assert SHOWN_BY[prop] in failures, f"{name} should fail {prop}; fails {failures or 'nothing'}"
