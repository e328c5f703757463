"""The primitives' own ceiling in docs/report.md (gen/report/fpga._ceiling_lines) and the
designs it places (gen/flow/fpga.primitive_component): one primitive between flip-flops."""

import re

import pytest
from amaranth.back import verilog

from bumprtl.gen.flow.fpga import PRIMITIVES, primitive_component
from bumprtl.gen.report.fpga import _ceiling_lines, _edge_lines
from bumprtl.rtl.config import BumpError


def _row(unit, fmax, met, target=200.0):
    return {"unit": unit, "fmax_mhz": fmax, "met": met, "target_mhz": target,
            "critical_path": "a.Q -> b.D (1.00 ns logic + 1.00 ns routing)"}


def test_rows_under_the_target_as_a_share_of_the_lower_ceiling():
    ceilings = {"dp16kd": {**_row("dp16kd_alone", 400.0, True), "fmax_by_seed": {1: 400.0, 2: 410.0}},
                "mult18x18d": {**_row("mult18x18d_alone", 300.0, True), "fmax_by_seed": {1: 300.0}}}
    rows = [_row("scene_a", 150.0, False), _row("scene_b", 250.0, True), _row("scene_c", 199.9, False)]
    text = "\n".join(_ceiling_lines(rows, ceilings))
    assert "| DP16KD |" in text and "| 400.0 | 1: 400.0, 2: 410.0 |" in text
    # the lower ceiling is the DSP's 300 MHz: 150 is half of it, 199.9 two thirds
    assert "lower ceiling (mult18x18d_alone, 300.0 MHz)" in text
    assert "scene_a 150.0 MHz (50 %)" in text and "scene_c 199.9 MHz (67 %)" in text
    assert "scene_b" not in text                                   # met: not listed
    assert _ceiling_lines(rows, {}) == []


@pytest.mark.parametrize("kind, cell, registers", [
    ("dp16kd", "DP16KD", ['.REGMODE_A("OUTREG")']),
    ("mult18x18d", "MULT18X18D", ['.REG_INPUTA_CLK("CLK0")', '.REG_INPUTB_CLK("CLK0")',
                                  '.REG_OUTPUT_CLK("CLK0")'])])
def test_each_primitive_alone_is_its_registered_ecp5_cell(kind, cell, registers):
    text = verilog.convert(primitive_component(kind), name=f"{kind}_alone", emit_src=False)
    assert len(re.findall(rf"^\s*{cell} ", text, re.M)) == 1, text   # one cell, nothing else
    for register in registers:                                   # with its own registers
        assert register in text, register
    assert kind in PRIMITIVES


def test_an_unknown_primitive_is_refused_in_one_line():
    with pytest.raises(BumpError, match="primitive must be one of dp16kd, mult18x18d, got 'lut4'"):
        primitive_component("lut4")


def test_the_credit_edge_alone_section_gives_its_cost_at_the_worst_seed():
    def placed(seed, fmax, lut4):
        return {**_row("credit_edge_alone", fmax, fmax >= 200), "seed": seed, "LUT4": lut4,
                "FF": 300, "DSP": 0, "BRAM": 0}
    text = "\n".join(_edge_lines([placed(2, 310.0, 410), placed(1, 290.5, 400)]))
    assert "## The credit edge on its own" in text
    assert "| credit_edge_alone | 400 | 300 | 0 | 0 | 290.5 | 1: 290.5, 2: 310.0 |" in text
    assert _edge_lines([]) == []


def test_the_credit_edge_alone_is_the_edge_between_registers_and_nothing_else():
    """The default pipeline's edge: its FIFO's LUT RAM and no product or block RAM; every
    input and output of the edge registered (no port reaches it through logic alone)."""
    from amaranth.hdl import signed
    from amaranth.lib import data

    from bumprtl.gen.flow.fpga import edge_component
    layout = data.StructLayout({"color": 24, "tag": signed(6)})
    text = verilog.convert(edge_component(layout, 10, 14), name="edge_alone", emit_src=False)
    assert "MULT18X18D" not in text and "DP16KD" not in text
    assert "credits" in text and "fifo_pre" in text
    assert re.search(r"reg \[32:0\] src", text) and re.search(r"output \[31:0\] o", text)
    with pytest.raises(BumpError, match="fifo_depth must be an int >= 14.*got 13"):
        edge_component(layout, 10, 13).elaborate(None)


def test_no_share_of_the_ceiling_when_every_row_meets_or_no_ceiling_was_timed():
    """The share sentence needs a row under its target and a ceiling with an Fmax: with
    every row met there is nothing to say, and a ceiling of 0 MHz (nextpnr timed none) would
    divide by zero."""
    ceilings = {"dp16kd": {**_row("dp16kd_alone", 400.0, True), "fmax_by_seed": {1: 400.0}}}
    met = [_row("scene_a", 250.0, True), _row("scene_b", 210.0, True)]
    text = "\n".join(_ceiling_lines(met, ceilings))
    assert "| DP16KD |" in text and "share of the lower ceiling" not in text
    untimed = {"dp16kd": {**_row("dp16kd_alone", 0, True), "fmax_by_seed": {1: 0}}}
    text = "\n".join(_ceiling_lines([_row("scene_a", 150.0, False)], untimed))
    assert "| DP16KD |" in text and "share of the lower ceiling" not in text
