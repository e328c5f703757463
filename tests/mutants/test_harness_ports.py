"""The harness's record of a target (harness_ports.Design): read from an emitted sidecar
through bumprtl.rtl.sidecar.load, its module the Verilog's top; written and read back in its
own file, which is no sidecar and which a sidecar cannot pass for."""

import re
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness_ports as hp  # noqa: E402

from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.config import Config
from bumprtl.rtl.sidecar import Port, load


@pytest.fixture(scope="module")
def sincos(tmp_path_factory):
    return emit_unit("sincos", Config(angle_bits=8, frac_bits=9),
                     tmp_path_factory.mktemp("sincos"))


def test_the_design_of_a_sidecar_is_the_verilogs_top_and_ports(sincos):
    v, j = sincos
    design = hp.Design.from_sidecar(j)
    text = v.read_text()
    header = re.search(rf"^module {design.module}\((.*?)\);(.*?)^endmodule", text, re.M | re.S)
    assert header, design.module
    # every port of the top, with the width the Verilog declares
    declared = {name: int(msb) + 1 if msb else 1 for _, msb, name in re.findall(
        r"^\s*(input|output) (?:wire |reg )?(?:\[(\d+):0\] )?(\w+);", header.group(2), re.M)}
    assert {n: p.width for n, p in design.ports.items()} == \
        {n: declared[n] for n in re.findall(r"\w+", header.group(1))}
    assert design.names("in") == sorted(n for n, p in load(j).ports.items() if p.dir == "in")


def test_a_record_reads_back_as_written_and_is_not_a_sidecar(tmp_path, sincos):
    design = hp.Design("top", {"clk": Port("in", 1), "o__payload": Port("out", 12),
                               "i__valid": Port("in", 1)})
    path = design.dump(tmp_path)
    written = path.read_text()
    assert path.name == hp.FILE and not path.name.endswith(f"{design.module}.json")
    assert hp.Design.load(tmp_path) == design
    # a sidecar copied under the record's name is refused, naming the file
    (tmp_path / hp.FILE).write_text(Path(sincos[1]).read_text())
    with pytest.raises(ValueError, match=f"{hp.FILE}: not a harness record"):
        hp.Design.load(tmp_path)
    # and so is a record of the same shape that does not say it is the harness's
    (tmp_path / hp.FILE).write_text(written.replace(hp.FORMAT, "a sidecar"))
    with pytest.raises(ValueError, match=f"{hp.FILE}: not a harness record"):
        hp.Design.load(tmp_path)


def test_a_board_units_design_adds_the_clock_and_reset():
    from amaranth.hdl import Signal
    design = hp.Design.from_signals("unit", [(Signal(4, name="q"), "out"),
                                             (Signal(name="de"), "in")])
    assert design.ports == {"clk": Port("in", 1), "rst": Port("in", 1), "q": Port("out", 4),
                            "de": Port("in", 1)}
    assert design.declaration("q") == "  output wire [3:0] q;"
    assert design.declaration("de") == "  input wire de;"
