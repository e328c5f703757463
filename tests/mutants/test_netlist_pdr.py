"""The pdr step of tests/mutants/netlist.py (netlist_pdr.py) on small netlists: it proves a
mutant whose equivalence needs a relational invariant (a register that differs only while
its stage's valid bit is 0) and one that needs a range (a register a + 2 with a at most 5
stays at most 7, so its bit 3 is never set), neither of which the cut step can state, and it refuses a mutant
that changes a valid payload."""

import json
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import netlist  # noqa: E402
import netlist_cone as nc  # noqa: E402
from harness_ports import Design  # noqa: E402

from bumprtl.rtl.sidecar import Port

PIPE = """
module pipe(input clk, input rst, input i__valid, input [3:0] i__payload,
            output reg o__valid = 0, output reg [3:0] o__payload = 0);
  reg v = 0;
  reg [3:0] d = 0;
  always @(posedge clk) begin
    v <= i__valid;
    if (i__valid) d <= i__payload + 4'd1;
    o__valid <= v;
    o__payload <= d;
    if (rst) begin v <= 0; d <= 4'd0; o__valid <= 0; end
  end
endmodule
"""

RANGE = """
module pipe(input clk, input en, input hold, input [3:0] x, output [3:0] o);
  reg [3:0] a = 0;
  reg [3:0] c = 0;
  reg [3:0] b = 0;
  always @(posedge clk) begin
    if (en) a <= (x > 4'd5) ? 4'd5 : x;
    c <= a + 4'd2;
    if (!hold) b <= c;
  end
  assign o = b;
endmodule
"""


_PREPARED = {}      # verilog -> (prepped.il, its JSON module): one prep per design a session


def _prepare(tmp_path, verilog):
    if verilog not in _PREPARED:
        (tmp_path / "pipe.v").write_text(verilog)
        nc.run_yosys(["read_verilog pipe.v", "prep -flatten -top pipe", "write_rtlil prepped.il",
                      "write_json prepped.json"], tmp_path, quiet=True)
        _PREPARED[verilog] = ((tmp_path / "prepped.il").read_text(),
                              (tmp_path / "prepped.json").read_text())
    il, js = _PREPARED[verilog]
    (tmp_path / "prepped.il").write_text(il)
    mod = json.loads(js)["modules"]["pipe"]
    ports = {n: Port("in" if p["direction"] == "input" else "out", len(p["bits"]))
             for n, p in mod["ports"].items()}     # a Yosys JSON module's ports
    return mod, Design("pipe", ports)


def _net_name(mod, name):
    return mod["netnames"][name]["bits"]


def _cell_reading(mod, type_, port, bits):
    """The name of the cell of ``type_`` whose ``port`` is ``bits``."""
    return next(n for n, c in mod["cells"].items()
                if c["type"] == type_ and c["connections"].get(port) == bits)


def _cell_driving(mod, bits):
    return next(n for n, c in mod["cells"].items()
                if any(c["connections"].get(q) == bits for q, d in c["port_directions"].items()
                       if d == "output"))


def reset_value_mutant(tmp_path, pipe):
    """``pipe`` prepared, and the mutation inverting bit 2 of ``d``'s reset value: (design,
    the mutate line)."""
    mod, design = _prepare(tmp_path, pipe)
    # the mux that gives d its reset value 0: input B (rst = 1) is the constant 4'b0000
    d_ff = _cell_driving(mod, _net_name(mod, "d"))
    rst_mux = _cell_driving(mod, mod["cells"][d_ff]["connections"]["D"])
    assert mod["cells"][rst_mux]["connections"]["B"] == ["0"] * 4
    return design, f"mutate -mode inv -module pipe -cell {rst_mux} -port B -portbit 2"


def test_pdr_proves_a_reset_value_no_valid_payload_reads(tmp_path):
    design, line = reset_value_mutant(tmp_path, PIPE)
    # pdr alone (the cut's invariant "every register bit equal but R" fails at the payload:
    # test_netlist_rel's reset test); pdr finds "d differs only while v is 0, o__payload
    # only while o__valid is 0"
    verdict = netlist.equivalence(None, design, line, tmp_path, 60, steps=("pdr",))
    assert verdict.startswith("equivalent under the stream contract (pdr:"), verdict


def test_pdr_proves_a_flip_under_a_bit_a_range_never_sets(tmp_path):
    mod, design = _prepare(tmp_path, RANGE)
    b_ff = _cell_driving(mod, _net_name(mod, "b"))
    hold_mux = _cell_driving(mod, mod["cells"][b_ff]["connections"]["D"])
    assert mod["cells"][hold_mux]["connections"]["B"] == _net_name(mod, "b")
    # the held value's bit 0 flipped while its bit 3 is set: b = c = a + 2 <= 7 never sets
    # it, but only the range a <= 5 says so (a's bits 0 to 2 are each set at times)
    line = f"mutate -mode cnot1 -module pipe -cell {hold_mux} -port B -portbit 0 -ctrlbit 3"
    cut = netlist.equivalence(None, design, line, tmp_path, 60, steps=("cut",))
    assert cut.startswith("undecided"), cut
    verdict = netlist.equivalence(None, design, line, tmp_path, 60, steps=("pdr",))
    assert verdict.startswith("equivalent (pdr:"), verdict


def payload_mutant(tmp_path, pipe):
    """``pipe`` prepared, and the mutation inverting bit 0 of its adder's sum, which every
    valid payload carries: (design, the mutate line)."""
    mod, design = _prepare(tmp_path, pipe)
    add = next(n for n, c in mod["cells"].items() if c["type"] == "$add")
    return design, f"mutate -mode inv -module pipe -cell {add} -port Y -portbit 0"


def test_pdr_refuses_a_mutant_that_changes_a_valid_payload(tmp_path):
    design, line = payload_mutant(tmp_path, PIPE)
    verdict = netlist.equivalence(None, design, line, tmp_path, 60, steps=("pdr",))
    assert verdict.startswith("undecided"), verdict
    assert re.search(r"pdr: a counterexample", verdict), verdict
