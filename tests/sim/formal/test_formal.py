"""The quick subset of `make formal` (sim/formal/) in `make test`: SinCos's order, latency
and credit loop and one scene pipeline's order, palette double buffer and credit loop
proved by k-induction, PaletteLUT's double buffer proved and covered, three broken units caught (a credit edge whose i.ready reads
o.ready, the palette pipeline's old bank wiring, a unit dropping a pixel), and the lemma
bookkeeping without sby. The rest (the other broken units here, marked ``formal``, and
simulated at their ports in make test: test_broken_units_simulated.py; every
unit and scene pipeline in the table) is `make formal`."""

from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from amaranth.back import rtlil

from bumprtl.gen.formal import run as formal_run
from bumprtl.gen.formal.run import check, check_mutant
from bumprtl.rtl.pipe import CreditFIFO, Pipe
from bumprtl.sim.formal.contract import CHUNK, StreamContract, find_edge, observe_pipes
from bumprtl.sim.formal.mutants import EDGE_MUTATIONS, MUTANTS, Glitcher
from bumprtl.sim.formal.targets import SMALL, TARGETS, Config, Target

_REGISTER = Pipe.register


# order (16 s, the slowest of the three) in make formal only: make formal's own run proves it
# on every unit, and make test keeps an order proof on the palette scene's pipeline below
@pytest.mark.parametrize("prop", [pytest.param("order", marks=pytest.mark.formal), "latency", "credit"])
def test_sincos_contract_is_proved_by_induction(prop, build_dir):
    row = check(TARGETS["sincos"], prop, build_dir)
    assert row.result == "proved", row
    assert row.lemmas > 0              # the chain's lemmas were found and asserted


# the dropping unit is here so that a weakened order assumption (no pixel ever enters: the
# proofs pass vacuously) fails make test too: its order no longer fails
QUICK_MUTANTS = ("credit_early", "uncarried_bank", "drop")


# the double buffer's proof in make formal: make test keeps the unit built to break it
# (uncarried_bank, below) and checks in the Amaranth simulator that each pixel reads the
# bank of its acceptance (tests/rtl/test_palette.py)
@pytest.mark.parametrize("prop", ["order", pytest.param("bank", marks=pytest.mark.formal), "credit"])
def test_scene_pipeline_is_proved_by_induction(prop, build_dir):
    """The palette scene pipeline (fetch -> LUT, two layers behind one credit edge): order
    with the tags of its stages and FIFO entries, the double buffer (each pixel reads the
    bank in front when the pipeline accepted it) with the lemmas about the bank bits in
    flight and the table's watched entry, and the credit loop's invariant."""
    row = check(TARGETS["pipeline_palette"], prop, build_dir)
    assert row.result == "proved", row
    assert row.lemmas > 0


def test_the_lut_alones_double_buffer_is_proved_and_exercised(build_dir):
    """The bank property on PaletteLUT alone (seconds, where the scene pipeline's takes
    longer): proved with its lemmas, and its own covers reach a swap seen through the unit
    (a property that never sees a swap would prove vacuously)."""
    row = check(TARGETS["palette"], "bank", build_dir)
    assert row.result == "proved" and row.lemmas > 0, row
    assert check(TARGETS["palette"], "bank_cover", build_dir).result == "covered"


@pytest.mark.parametrize("name", [pytest.param(n, marks=() if n in QUICK_MUTANTS else pytest.mark.formal)
                                  for n in MUTANTS])
def test_broken_unit_fails_its_property(name, build_dir):
    """Each property can fail: the unit built to break it gives a counterexample trace."""
    row = check_mutant(name, build_dir)
    assert row.result == "fails as expected", row
    assert Path(row.trace).is_file()
    assert row.detail.startswith(MUTANTS[name][1]), row.detail    # that property, no other


def test_every_edge_mutation_is_a_broken_unit():
    """Each mutation of the credit edge is one of the broken units checked above."""
    mutations = {cls.mutation for cls, _prop in MUTANTS.values() if hasattr(cls, "mutation")}
    assert mutations == set(EDGE_MUTATIONS)


# order's cover in make test (with the dropping unit: its assumption is the one that went
# vacuous); the others in make formal (pytest marker formal)
@pytest.mark.parametrize("prop", ["order"] + [pytest.param(p, marks=pytest.mark.formal)
                                              for p in ("latency", "hold", "ready", "credit")])
def test_sincos_properties_are_exercised(prop, build_dir):
    """Each property's own cover (its assumptions in force) is reached: two pixels enter
    and leave in order, a pixel goes through the latency, a pixel is held through a stall,
    a pixel is taken while the output is stalled, every credit is spent, the FIFO fills and
    i.ready falls and rises again. A proof of a property whose assumption shuts every pixel
    out would pass; this fails."""
    row = check(TARGETS["sincos"], f"{prop}_cover", build_dir)
    assert row.result == "covered", row


@pytest.mark.formal
def test_a_vacuous_order_assumption_fails_its_cover(build_dir):
    """The cover can fail: order with an assumption that lets no pixel in (the kind of
    change that left the order proofs green) does not reach its cover."""
    from amaranth.hdl import Assume

    from bumprtl.gen.tools.sby import run_sby

    class NoPixelEnters(StreamContract):
        def _order(self, m, i, o, take_in, take_out, stages):
            m.d.comb += Assume(~i.valid)
            super()._order(m, i, o, take_in, take_out, stages)

    dut = TARGETS["sincos"].unit()
    top = NoPixelEnters(dut, "order", lemmas=False)
    res = run_sby(top, build_dir, "vacuous_order", mode="cover", depth=dut.latency + 6)
    assert res.status == "FAIL" and not res.passed, res.status
    assert top.exercised == ["order: two pixels enter and leave in order"]

# make formal (marker formal): its sby run paid for make test's order cover and dropping unit
@pytest.mark.formal
def test_runner_names_the_property_and_trace_and_exits_1(monkeypatch, build_dir, capsys):
    from bumprtl.gen.tools import jobs
    broken = Target("broken", lambda bits: Glitcher(Config(**SMALL)), ("hold",))
    monkeypatch.setitem(formal_run.TARGETS, "broken", broken)
    monkeypatch.setattr(jobs, "LOCAL_PROCESSES", False)    # the job sees the patched TARGETS
    rc = formal_run.main(["broken", "--no-mutants", "--out", str(build_dir)])
    err = capsys.readouterr().err
    assert rc == 1
    assert "FAILED: broken property hold" in err and "hold: o.valid/o.payload changed" in err
    trace = err.split("counterexample: ")[1].split()[0]
    assert Path(trace).is_file() and trace.endswith(".vcd")


def test_lemmas_come_from_the_units_own_registers():
    """The order lemmas cover every stage and every FIFO entry: per stage of SinCos's chain
    its tag and its ghost count (each stage's against the next one's, the last one's
    against the FIFO's youngest), two per address of its edge's FIFO memory (rtl/pipe.CreditFIFO: the
    next power of two words at least ``fifo_depth``; the output register is the property
    itself; the oldest entry, and each entry after the one before it), plus the next input
    tag; and the credit loop's invariant is among them."""
    top = StreamContract(TARGETS["sincos"].unit(), "order")
    rtlil.convert(top, name="top", ports=top.free_inputs())
    said = Counter(top.lemma_names)
    assert said["a valid stage holds the tag it entered with"] == top.dut.latency
    assert said["the ghost tags of neighbouring stages differ by the older one's valid"] == \
        top.dut.latency - 1
    assert said["the next pixel into the chain is one past stage 1's ghost tag"] == 1
    assert said["the FIFO's youngest is the one before stage L's"] == 1
    words = 1 << (top.dut.fifo_depth - 1).bit_length()
    assert said["the FIFO's entries hold consecutive tags"] == words
    assert said["the FIFO's oldest entry holds the tag after the output's"] == words
    assert said["next input tag is one past the youngest in flight"] == 1
    assert said["credit: credits + pixels in the chain + FIFO occupancy != depth"] == 1


@pytest.mark.parametrize("name", ["sincos", "pipeline_palette"])
def test_the_credit_edge_is_found_in_the_elaborated_unit(name):
    """The contract finds the one CreditEdge of a unit (its own) and of a scene pipeline
    (the one around its units), with its FIFO of ``fifo_depth`` entries and that FIFO's
    memory (rtl/pipe.CreditFIFO: the next power of two words at least ``fifo_depth``)."""
    dut = TARGETS[name].unit()
    fragment, _observer = observe_pipes(dut)
    edge = find_edge(fragment)
    assert edge is not None and edge.edge.depth == dut.fifo_depth
    words = 1 << (dut.fifo_depth - 1).bit_length()
    assert edge.fifo.depth == dut.fifo_depth and edge.inner_depth == words >= dut.fifo_depth
    # in banks of 16 words (rtl/pipe.BANK_BITS), each its own LUT RAM, at logical
    # addresses 0, 16, ...
    assert [(memory.depth, base) for _, memory, base in edge.banks] == \
        [(min(words, 16), b * 16) for b in range(max(1, words // 16))]


@pytest.mark.parametrize("width, banks", [(8, [8]), (73, [16, 16, 16, 16]), (128, [16] * 4),
                                          (129, [64]), (180, [64])])
def test_a_wide_fifo_keeps_one_bank(width, banks):
    """rtl/pipe.CreditFIFO: banks of 16 words up to BANKED_WIDTH_MAX (8 x READ_SLICE) bits,
    one bank of every word above it (here 43 entries: 64 words; 8 entries: 8 words)."""
    fifo = CreditFIFO(width, 43 if width > 8 else 8)
    assert [bank.depth for bank in fifo.banks] == banks and fifo.bank_bits == (banks[0] - 1).bit_length()


# make formal (its runner elaborates contracts in parallel threads) runs it, not make test
@pytest.mark.formal
def test_parallel_elaborations_each_observe_every_stage():
    """make formal elaborates in parallel threads (-j 2): each contract's observer is passed
    to its own elaboration's pipes (no process-wide patch, no lock), so contracts built at
    once get every stage's lemma, as many as built one by one (the textured pipeline once
    lost its illumination's tags, and with them the induction of its order)."""
    def lemmas(name):
        top = StreamContract(TARGETS[name].unit(), "order")
        rtlil.convert(top, name="top", ports=top.free_inputs())
        return top.lemma_count

    names = ["pipeline_default", "sincos", "rotation_exact", "illumination_exact"]
    serial = {n: lemmas(n) for n in set(names)}
    with ThreadPoolExecutor(max_workers=4) as pool:
        parallel = list(pool.map(lemmas, names))
    assert parallel == [serial[n] for n in names], (parallel, serial)


def test_the_observer_sees_only_its_own_elaboration():
    """Two units elaborated at once in two threads: each observer records exactly its own
    unit's pipes (keyed by their input valid), none of the other's; without an observer the
    unit builds the same pipes and nobody records them."""
    a, b = TARGETS["rotation_exact"].unit(), TARGETS["sincos"].unit()
    assert a.latency != b.latency
    with ThreadPoolExecutor(max_workers=2) as pool:
        (_, obs_a), (_, obs_b) = pool.map(observe_pipes, (a, b))
    seen_a, seen_b = obs_a.seen, obs_b.seen
    assert not set(seen_a) & set(seen_b)
    assert [len(r["valid"]) for r in seen_a.values()] == [a.latency + 1]
    assert [len(r["valid"]) for r in seen_b.values()] == [b.latency + 1]
    assert all(r["tags"] for r in [*seen_a.values(), *seen_b.values()])
    assert not Pipe.__dict__.get("_formal")
    assert Pipe.register is _REGISTER                 # Pipe itself is never replaced


def test_a_long_pipe_counts_its_pixels_in_runs():
    """The pixels in a long chain (Kim's setup, 46 stages at the formal widths) are counted
    by a ghost counter per run of CHUNK stages: one count over all 46 stages made the
    induction of quiet run past its 600 s limit."""
    top = StreamContract(TARGETS["rotation_kim"].unit(), "quiet")
    rtlil.convert(top, name="top", ports=top.free_inputs())
    stages = top.dut.latency
    said = Counter(top.lemma_names)
    assert stages > CHUNK
    assert said["valid stages of a run = its ghost counter"] == -(-stages // CHUNK)
    assert said["pixels in flight = valid stages + FIFO occupancy"] == 1


@pytest.mark.formal
def test_kim_setup_is_quiet_by_induction(build_dir):
    row = check(TARGETS["rotation_kim"], "quiet", build_dir)
    assert row.result == "proved" and row.depth == 2, row


def test_the_page_names_the_run_time_beside_the_command(tmp_path):
    """The table's section names the command, and the run's checks and wall time beside it
    (a page reprinted from results.json names none)."""
    from types import SimpleNamespace

    from bumprtl.gen.formal.doc import write_doc
    row = SimpleNamespace(unit="sincos", prop="credit", result="proved", depth=2, latency=6,
                          lemmas=1, seconds=1.5)
    doc = tmp_path / "formal.md"
    write_doc(doc, [row, row], "-j 2 --doc docs/formal.md", seconds=1234.4, checked=2)
    text = doc.read_text()
    assert "`python -m bumprtl.gen.formal.run -j 2 --doc docs/formal.md`" in text
    assert "that run: 2 checks in 1234 s of wall time" in text
    write_doc(doc, [row], "--from-results --doc docs/formal.md")
    assert "that run" not in doc.read_text()
