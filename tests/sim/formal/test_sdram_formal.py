"""The SDRAM controller's command stream proved against the JEDEC rules by k-induction
(sim/formal/sdram.py): every minimum spacing, the bank rules and the refresh deadline, at
the board's configuration in make test and at the others in make formal; every rule's
cover reached; a controller built with a timing one cycle short is not proved."""

import pytest

from bumprtl.rtl.sdram import SdramController
from bumprtl.sim.formal.sdram import FORMAL_CONFIGS, RULES, cover, prove
from bumprtl.sim.sdram_bench import short_config


@pytest.mark.parametrize("name", [n if n == "32mb_100mhz_cl2" else
                                  pytest.param(n, marks=pytest.mark.formal)
                                  for n in FORMAL_CONFIGS])
def test_command_stream_is_proved_by_induction(name, build_dir):
    top, res = prove(FORMAL_CONFIGS[name], build_dir)
    assert res.passed, (res.status, [top.describe(f) for f in res.failed])
    assert len(top.lemmas) > 20                     # the strengthening is in the model


# make formal: the covers, out of make test's budget; make test proves
# the rules by induction and shows a timing one cycle short fails its rule (below)
@pytest.mark.formal
@pytest.mark.parametrize("name,depth", [("32mb_2mhz_bl1", 25), ("32mb_10mhz_cl2", 30)])
def test_every_rule_is_exercised(name, depth, build_dir):
    """Each rule's command pair is reached from reset (a proof whose monitor never saw an
    ACTIVE would pass too; this fails). At 10 MHz all but the refresh after the mode is
    set (tREFI is 78 cycles there): the 2 MHz configuration reaches that one."""
    top, res = cover(FORMAL_CONFIGS[name], build_dir, depth)
    assert len(top.covers) == 11
    if name == "32mb_2mhz_bl1":
        assert res.passed, (res.status, res.failed)
    else:
        assert len(res.failed) == 1, res.failed


def test_every_rule_is_asserted():
    """Each rule of RULES is checked by at least one assertion of the contract."""
    from amaranth.back import rtlil

    from bumprtl.sim.formal.sdram import SdramCommandContract
    top = SdramCommandContract(FORMAL_CONFIGS["32mb_100mhz_cl2"])
    rtlil.convert(top, name="top", ports=top.free_inputs())
    assert set(top.messages.values()) >= set(RULES)


@pytest.mark.parametrize("timing,rule", [
    ("ras", "pre_t"), pytest.param("wr", "pre_t", marks=pytest.mark.formal),
    pytest.param("rfc", "cmd_t", marks=pytest.mark.formal),
    pytest.param("mrd", "cmd_t", marks=pytest.mark.formal)])
def test_a_timing_one_cycle_short_is_not_proved(timing, rule, build_dir):
    """The controller built with one timing a cycle short, against the true rules: the
    proof fails at the lemma of that timing's timer."""
    cfg = FORMAL_CONFIGS["32mb_100mhz_cl2"]
    top, res = prove(cfg, build_dir, dut=SdramController(short_config(cfg, timing)))
    assert not res.passed
    said = [top.describe(f) for f in res.failed]
    assert any(rule in s for s in said), said
