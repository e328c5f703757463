"""The never and rel steps of tests/mutants/netlist.py (netlist_rel.py) on small netlists:
never proves a flip under a bit a range never sets (a register a + 2 with a at most 5 stays
at most 7, so its bit 3 is never set) and refuses one under a bit the range does set; rel
proves a reset value no valid payload reads (the register differs only while its stage's
valid bit is 0) and refuses a mutant that changes a valid payload."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import netlist  # noqa: E402
from test_netlist_pdr import (  # noqa: E402
    PIPE,
    RANGE,
    _cell_driving,
    _net_name,
    _prepare,
    payload_mutant,
    reset_value_mutant,
)

# the pipe of test_netlist_pdr with its stage's valid bit named as the step looks for it
PIPE = PIPE.replace("reg v = 0;", "reg stage1_valid = 0;").replace(
    "v <= i__valid;", "stage1_valid <= i__valid;").replace(
    "o__valid <= v;", "o__valid <= stage1_valid;").replace("begin v <= 0;", "begin stage1_valid <= 0;")


def _hold_flip(tmp_path, ctrlbit):
    mod, design = _prepare(tmp_path, RANGE)
    b_ff = _cell_driving(mod, _net_name(mod, "b"))
    hold_mux = _cell_driving(mod, mod["cells"][b_ff]["connections"]["D"])
    assert mod["cells"][hold_mux]["connections"]["B"] == _net_name(mod, "b")
    return design, (f"mutate -mode cnot1 -module pipe -cell {hold_mux} -port B -portbit 0 "
                  f"-ctrlbit {ctrlbit}")


def test_never_proves_a_flip_under_a_bit_a_range_never_sets(tmp_path):
    # b = c = a + 2 <= 7 never sets bit 3, but only the range a <= 5 says so
    design, line = _hold_flip(tmp_path, 3)
    verdict = netlist.equivalence(None, design, line, tmp_path, 60, steps=("never",))
    assert verdict.startswith("equivalent (never:"), verdict


def test_never_refuses_a_flip_under_a_bit_the_range_sets(tmp_path):
    design, line = _hold_flip(tmp_path, 2)            # b = 4 .. 7 sets bit 2
    verdict = netlist.equivalence(None, design, line, tmp_path, 60, steps=("never",))
    assert verdict.startswith("undecided"), verdict
    assert "never: the bounds do not show the control bit inactive" in verdict, verdict


def test_rel_proves_a_reset_value_no_valid_payload_reads(tmp_path):
    design, line = reset_value_mutant(tmp_path, PIPE)
    # the cut cannot state it: its invariant "every register bit equal but R" fails at the
    # payload, masked or not
    cut = netlist.equivalence(None, design, line, tmp_path, 60, steps=("cut",))
    assert cut.startswith("undecided"), cut
    assert "cut: the invariant does not hold at output o__payload" in cut, cut
    verdict = netlist.equivalence(None, design, line, tmp_path, 60, steps=("rel",))
    assert verdict.startswith("equivalent under the stream contract (rel:"), verdict


def test_rel_refuses_a_mutant_that_changes_a_valid_payload(tmp_path):
    design, line = payload_mutant(tmp_path, PIPE)
    verdict = netlist.equivalence(None, design, line, tmp_path, 60, steps=("rel",))
    assert verdict.startswith("undecided"), verdict
    assert "rel: the candidate invariant does not imply the property" in verdict, verdict
