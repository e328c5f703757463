"""The texel cache's AXI4 read port proved against the read-channel rules by k-induction
(sim/formal/axi.py): AR held and stable until ARREADY, one line's INCR burst, the address a
line of the image, the beats counted as the port's, RREADY while a burst is outstanding,
the outstanding limit, no orphan beat; every rule's cover reached; each broken manager
fails its rule. The small cache in make test, the other caches and the stream contract
of the map_memory = "axi" pipeline in make formal (marker formal)."""

import pytest
from amaranth.back import rtlil

from bumprtl.gen.formal.run import check, check_axi_mutant
from bumprtl.sim.formal.axi import (
    ASSUMED,
    FORMAL_GEOMETRIES,
    MUTANTS,
    PROVE_ONLY,
    RULES,
    AxiReadContract,
    cover,
    cover_depth,
    geometry,
    prove,
)
from bumprtl.sim.formal.contract import StreamContract
from bumprtl.sim.formal.targets import TARGETS


@pytest.mark.parametrize("name", [n if n == "2beats" else pytest.param(n, marks=pytest.mark.formal)
                                  for n in FORMAL_GEOMETRIES])
def test_axi_rules_are_proved_by_induction(name, build_dir):
    top, res = prove(geometry(name), build_dir)
    assert res.passed, (res.status, [top.describe(f) for f in res.failed])
    assert len(top.lemmas) >= 5                     # the strengthening is in the model


@pytest.mark.formal
def test_the_rules_need_the_lemmas_to_close(build_dir):
    """Without the lemmas the induction at depth 2 does not close (an unreachable state
    with the cache's burst count off the port's breaks a rule): the lemmas carry it."""
    from bumprtl.gen.tools.sby import run_sby
    top = AxiReadContract(geometry("2beats"), lemmas=False)
    res = run_sby(top, build_dir, "no_lemmas", mode="prove", depth=2)
    assert not res.passed and top.lemmas == []


# make formal: the covers; make test proves the rules by induction and breaks one (below)
@pytest.mark.formal
@pytest.mark.parametrize("name", [n for n in FORMAL_GEOMETRIES if n not in PROVE_ONLY])
def test_every_rule_is_exercised(name, build_dir):
    """Each rule's situation is reached from reset with the subordinate's rules assumed (a
    proof whose subordinate never answered would pass too; this fails): an AR held through
    a stall, the image's last line, a burst's last beat, RREADY before ARREADY, the limit
    of bursts outstanding, a beat with the next burst accepted, a missed pixel out."""
    geom = geometry(name)
    top, res = cover(geom, build_dir, cover_depth(geom))
    assert len(top.covers) == len(RULES) + 1
    assert res.passed, (res.status, res.failed)


def test_every_rule_is_asserted_and_every_subordinate_rule_assumed():
    top = AxiReadContract(geometry("2beats"))
    text = rtlil.convert(top, name="top", ports=top.free_inputs())
    assert set(top.messages.values()) >= set(RULES)
    assert sorted(top.assumed) == sorted(ASSUMED)
    assert text.count('FLAVOR "assume"') == len(ASSUMED)


@pytest.mark.parametrize("name", [n if n == "arvalid_drop" else pytest.param(n, marks=pytest.mark.formal)
                                  for n in MUTANTS])
def test_broken_manager_fails_its_rule(name, build_dir):
    """ARVALID dropped before ARREADY, a burst one beat long, an address past the image:
    each gives a counterexample at its rule."""
    row = check_axi_mutant(name, build_dir)
    assert row.result == "fails as expected", row
    assert MUTANTS[name][1] in row.detail.split("; "), row.detail


def test_the_axi_pipeline_counts_the_pixels_in_its_cache():
    """The stream contract of the map_memory = "axi" pipeline finds its cache and ties a
    ghost count of the pixels in it to the cache's registers; the tag is wide enough for
    the pixels the cache holds besides the credits."""
    target = TARGETS["pipeline_default_axi"]
    dut = target.unit()
    # besides its queue: the registers of the pixel read, its words read and their skid
    # register, its words settled and their stamp distances, the pixel looked up, the
    # queue's head, the data read and its words, the output's skid and the output
    assert dut.front_capacity == dut.units["fetch"].capacity == dut.units["fetch"].geom.queue + 11
    assert (1 << len(dut.i.payload.tag)) > dut.fifo_depth + dut.units["fetch"].capacity + 1
    top = StreamContract(dut, "quiet")
    rtlil.convert(top, name="top", ports=top.free_inputs())
    assert top.cache is not None
    assert "pixels in the cache = its lookup, queue, read and output registers" in top.lemma_names
    assert not {"ready", "latency"} & set(target.props)


@pytest.mark.formal
@pytest.mark.parametrize("prop", ["hold", "quiet", "credit", "cover", "hold_cover"])
def test_axi_pipeline_keeps_the_stream_contract(prop, build_dir):
    row = check(TARGETS["pipeline_default_axi"], prop, build_dir)
    assert row.result in ("proved", "covered"), row


def test_the_axi_rows_have_a_section_of_their_own(tmp_path):
    """write_doc puts the texel cache's rows (its AXI port, its broken managers, the cached
    pipeline) in their own section and leaves a section it has no rows for as it was: a run
    of the AXI checks alone does not re-render the stream table with nothing in it."""
    from types import SimpleNamespace

    from bumprtl.gen.formal.doc import write_doc

    def row(unit, prop):
        return SimpleNamespace(unit=unit, prop=prop, result="proved", depth=2, latency=0,
                               lemmas=6, seconds=1.0)

    doc = tmp_path / "formal.md"
    write_doc(doc, [row("sincos", "order")], "-j 2 --doc docs/formal.md", seconds=10, checked=1)
    before = doc.read_text()
    axi_rows = [row("cache_axi_2beats", "axi"), row("mutant axi_long_burst", "axi"),
                row("pipeline_default_axi", "hold")]
    write_doc(doc, axi_rows, "cache_axi_2beats --prop axi --doc docs/formal.md", seconds=3,
              checked=3)
    text = doc.read_text()
    main, axi_part = text.split("<!-- formal axi table:begin -->")
    assert main.strip() == before.strip()                     # the stream table untouched
    assert all(f"| {r.unit} | {r.prop} |" in axi_part for r in axi_rows)
    assert "`python -m bumprtl.gen.formal.run cache_axi_2beats --prop axi --doc docs/formal.md`" \
        in axi_part and "that run: 3 checks in 3 s" in axi_part
