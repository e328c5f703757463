"""The never step's exhaustive fallback (tests/mutants/netlist_rel.reach) on small designs
written here: a count bounded only by its relation to a second register (pixels inside and
credits always summing to 4, as a credit FIFO's count is bounded by the credits it shares
with the pipe), which no upper bound on one register states, is decided by enumerating the
cone's reachable states; a bit that is reachable, a register without an initial value and a
cone too large to enumerate each leave the step undecided, never "equivalent"."""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import netlist  # noqa: E402
import netlist_cone as nc  # noqa: E402
import netlist_rel as nrel  # noqa: E402

# inside + credits == 4 in every reachable state: a pixel enters only on a free credit and
# leaves only when one is inside. inside never exceeds 4, so inside == 5 (bits 2 and 0) is
# never reached; inside <= inside + 1 is all an upper bound on inside alone can say.
CREDITS = """
module product(input clk, input rst, input take, input give, output target, output spare);
  reg [2:0] inside = 0;
  reg [2:0] credits = 4;
  wire in = take && credits != 0;
  wire out = give && inside != 0;
  always @(posedge clk)
    if (rst) begin inside <= 0; credits <= 4; end
    else begin inside <= inside + in - out; credits <= credits - in + out; end
  assign target = TARGET;
  assign spare = credits[0];
endmodule
"""


def _reach(tmp_path, verilog, active=True, timeout=60):
    (tmp_path / "d.v").write_text(verilog)
    netlist.yosys(["read_verilog d.v", "prep -top product", "write_json d.json"], tmp_path)
    text = (tmp_path / "d.json").read_text()
    assert "target" in json.loads(text)["modules"]["product"]["ports"]
    return nrel.reach(text, active, tmp_path, nc.yosys_log, timeout)


def test_reach_proves_a_bound_only_a_relation_states(tmp_path):
    verdict, how = _reach(tmp_path, CREDITS.replace("TARGET", "inside[2] & inside[0]"))
    assert verdict == "equivalent", how
    # 5 states: inside = 0 .. 4 (credits follows it)
    assert "all 5 reachable states" in how, how


def test_reach_finds_a_bit_the_relation_does_set(tmp_path):
    verdict, how = _reach(tmp_path, CREDITS.replace("TARGET", "inside[2]"))   # inside = 4
    assert verdict == "undecided" and "(active) in a reachable state" in how, how


def test_reach_checks_the_inactive_value_of_a_cnot0(tmp_path):
    # cnot0: active while the control bit is 0; inside[2] | inside[1] | inside[0] is 0 at reset
    verdict, how = _reach(tmp_path, CREDITS.replace("TARGET", "|inside"), active=False)
    assert verdict == "undecided" and "is 0 (active)" in how, how
    verdict, how = _reach(tmp_path, CREDITS.replace("TARGET", "!(inside[2] & inside[0])"),
                          active=False)
    assert verdict == "equivalent", how


def test_a_register_without_an_initial_value_starts_at_either(tmp_path):
    loose = CREDITS.replace("reg [2:0] inside = 0;", "reg [2:0] inside;").replace(
        "reg [2:0] credits = 4;", "reg [2:0] credits;")
    verdict, how = _reach(tmp_path, loose.replace("TARGET", "inside[2] & inside[0]"))
    assert verdict == "undecided", how


def test_a_cone_too_large_is_left_undecided(tmp_path):
    wide = f"""
module product(input clk, input [{nrel.REACH_LATCHES}:0] d, output target);
  reg [{nrel.REACH_LATCHES}:0] r = 0;
  always @(posedge clk) r <= d;
  assign target = &r;
endmodule
"""
    verdict, how = _reach(tmp_path, wide)
    assert verdict == "undecided" and "too large to enumerate" in how, how
