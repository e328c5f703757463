"""The resource counter on hand-written Amaranth modules whose contents are known."""

import json
import re

import pytest
from amaranth.hdl import Module, signed, unsigned
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from bumprtl.gen.flow import resources
from bumprtl.gen.flow.resources import (
    count_component,
    count_netlist,
    count_verilog,
    multiplier_pairs,
)
from bumprtl.gen.flow.units import emit_unit
from bumprtl.gen.tools.toolchain import roms_as_readmemh
from bumprtl.gen.tools.yosys import SynthesisError
from bumprtl.rtl.config import BumpError, Config


class Known(wiring.Component):
    """One 9x7 multiplier, two adders (one a subtractor), one 100 x 12 ROM, one comparator,
    a constant multiply by 3 and one by 4 (a shift); every result registered."""

    a: In(signed(9))
    b: In(signed(7))
    c: In(unsigned(10))
    d: In(unsigned(10))
    addr: In(unsigned(7))
    prod: Out(signed(16))
    total: Out(unsigned(11))
    lt: Out(1)
    rom_data: Out(unsigned(12))
    scaled: Out(unsigned(13))

    def elaborate(self, platform):
        m = Module()
        m.submodules.rom = rom = Memory(shape=unsigned(12), depth=100,
                                        init=[(i * 37) % 4096 for i in range(100)])
        port = rom.read_port()
        m.d.comb += port.addr.eq(self.addr)
        m.d.sync += [self.prod.eq(self.a * self.b),
                     self.total.eq((self.c + self.d) - self.addr),
                     self.lt.eq(self.c < self.d),
                     self.scaled.eq(self.c * 3 + self.d * 4),
                     self.rom_data.eq(port.data)]
        return m


@pytest.fixture(scope="module")
def known(tmp_path_factory):
    return count_component(Known(), "known", tmp_path_factory.mktemp("known"))


def test_multipliers_by_operand_widths(known):
    assert known.multipliers == ["9x7"]
    assert len(known.const_multipliers) == 1      # c * 3; d * 4 is a shift
    assert multiplier_pairs(known.multipliers) == [(7, 9)]
    assert multiplier_pairs(["18x2", "9x7", "7x9"]) == [(2, 18), (7, 9), (7, 9)]  # operand order


def test_adders_and_comparators(known):
    # (c + d) - addr is two adders; c * 3 + d * 4 adds a third (the constant product's sum)
    assert len(known.adders) == 3
    assert known.comparators and len(known.comparators) == 1
    assert known.dividers == [] and known.sqrts == 0


def test_rom_depth_width_bits(known):
    assert [(t["depth"], t["width"], t["bits"], t["read_ports"]) for t in known.tables] == \
        [(100, 12, 1200, 1)]
    assert known.rams == []


def test_register_bits(known):
    # the five registered outputs (prod, total, lt, scaled, rom_data); the ROM's own read
    # register stays inside the $mem_v2 and is not counted
    assert known.register_bits == 16 + 11 + 1 + 13 + 12


class Single(wiring.Component):
    """Exactly one multiplier, two adders and one ROM, nothing else."""

    x: In(unsigned(8))
    y: In(unsigned(8))
    z: In(unsigned(8))
    o: Out(unsigned(24))

    def elaborate(self, platform):
        m = Module()
        m.submodules.rom = rom = Memory(shape=unsigned(8), depth=256, init=range(256))
        port = rom.read_port(domain="comb")
        m.d.comb += [port.addr.eq(self.z), self.o.eq(self.x * self.y + self.z + port.data)]
        return m


def test_one_multiplier_two_adders_one_rom(build_dir):
    c = count_component(Single(), "single", build_dir)
    s = c.summary()
    assert (s["multipliers"], s["adders"], s["tables"], s["table_bits"]) == (1, 2, 1, 256 * 8)
    assert (s["const_multipliers"], s["comparators"], s["register_bits"]) == (0, 0, 0)


def test_missing_file_is_one_line_error(build_dir):
    with pytest.raises(BumpError, match="does not exist"):
        count_verilog(build_dir / "nope.v", "nope")


def test_yosys_error_is_shown(build_dir):
    bad = build_dir / "bad.v"
    bad.write_text("module bad(input a, output b); assign b = a +; endmodule\n")
    with pytest.raises(SynthesisError, match="yosys failed.*ERROR"):
        count_verilog(bad, "bad", build_dir)


def test_unknown_top_shows_yosys_message(build_dir):
    ok = build_dir / "ok.v"
    ok.write_text("module ok(input a, output b); assign b = a; endmodule\n")
    with pytest.raises(SynthesisError, match="ERROR.*nothere"):
        count_verilog(ok, "nothere", build_dir)


def test_zero_initialised_ram_counts_the_same_without_its_init(tmp_path):
    """strip_zero_init drops only all-zero memory inits: the palette RAM is still counted as
    its 2 x sN x 32 bits (double-buffered), and a ROM's non-zero contents are kept."""
    from bumprtl.gen.flow.resources import strip_zero_init
    from bumprtl.gen.flow.units import emit_unit
    from bumprtl.rtl.config import Config
    v, _ = emit_unit("palette", Config(palette_size=64), tmp_path / "pal")
    text = v.read_text()
    stripped = strip_zero_init(text)
    init = "mem[127] = 32'd0;"                     # the last zero of the init block
    assert init in text and init not in stripped
    counts = count_verilog(v, "palette", tmp_path / "a")
    assert counts.rams == [{"name": "table.mem", "depth": 128, "width": 32, "bits": 4096, "read_ports": 1}]
    rom, _ = emit_unit("sincos", Config(angle_bits=6, frac_bits=5), tmp_path / "rom")
    words = lambda t: [l for l in t.splitlines() if re.search(r"\] = \d+'[dh]0*[1-9a-f]", l)]
    assert words(rom.read_text()) and \
        words(strip_zero_init(rom.read_text())) == words(rom.read_text())  # non-zero contents stay


def _macc(products, addends=(), y_width=16):
    """A hand-written $macc_v2 cell: ``products`` = [(A bits, B bits)], ``addends`` = [C bits]
    (a bit is a net number or a constant "0"/"1", LSB first)."""
    pack = lambda widths: sum(w << (16 * i) for i, w in enumerate(widths))
    return {"type": "$macc_v2", "port_directions": {"Y": "output"},
            "parameters": {"NPRODUCTS": len(products), "NADDENDS": len(addends),
                           "A_WIDTHS": pack([len(a) for a, _ in products]),
                           "B_WIDTHS": pack([len(b) for _, b in products]),
                           "C_WIDTHS": pack([len(c) for c in addends]), "Y_WIDTH": y_width},
            "connections": {"A": [x for a, _ in products for x in a],
                            "B": [x for _, b in products for x in b],
                            "C": [x for c in addends for x in c], "Y": list(range(100, 100 + y_width))}}


def test_macc_terms_classified_by_their_operands():
    """The counting rules on a netlist written by hand (Yosys usually turns a product by a
    power of two into a shift before the counter sees it): a signal x signal product is a
    multiplier, x 3 a constant multiplier, x 4 a shift (a signal term, no multiplier), x 0
    nothing; T signal terms are T - 1 adders, a constant addend one constant adder."""
    sig = lambda n, w: list(range(n, n + w))
    const = lambda v, w: ["1" if v >> i & 1 else "0" for i in range(w)]
    cell = _macc([(sig(2, 6), sig(10, 5)), (sig(20, 6), const(3, 3)), (sig(30, 6), const(4, 3)),
                  (sig(40, 6), const(0, 3))], addends=[sig(50, 8), const(5, 4)])
    netlist = {"modules": {"top": {"ports": {"y": {"direction": "output", "bits": sig(100, 16)}},
                                   "cells": {"m": cell}}}}
    counts = count_netlist(netlist, "top")
    assert counts.multipliers == ["6x5"] and counts.const_multipliers == [6]
    assert counts.adders == [16] * 3 and counts.const_adders == [16]    # 4 signal terms


def test_roms_read_through_readmemh_give_the_same_netlist(tmp_path):
    """count_verilog hands Yosys the ROM contents as $readmemh files (roms_as_readmemh):
    the memories' INIT and every count are the same as from the word-by-word initial block."""
    v, _ = emit_unit("sincos", Config(angle_bits=8, frac_bits=9), tmp_path / "rom")
    text = v.read_text()
    fast = roms_as_readmemh(text, tmp_path, "sincos")
    assert "$readmemh(" in fast and len(fast) < len(text)
    inits = {}
    for name, src in (("slow", text), ("fast", fast)):
        (tmp_path / f"{name}.v").write_text(src)
        resources.run_yosys(f"read_verilog {name}.v; hierarchy -top sincos; {resources.SCRIPT}; "
                            f"write_json {name}.json", f"{name}.log", tmp_path)
        netlist = json.loads((tmp_path / f"{name}.json").read_text())
        cells = netlist["modules"]["sincos"]["cells"].values()
        inits[name] = sorted(c["parameters"]["INIT"] for c in cells if c["type"] == "$mem_v2")
        inits[name + "_counts"] = count_netlist(netlist, "sincos")
    assert inits["slow"] == inits["fast"] and inits["fast"] and any("1" in i for i in inits["fast"])
    assert inits["slow_counts"] == inits["fast_counts"]


def test_the_same_design_is_synthesized_once_per_process(tmp_path, monkeypatch):
    """Counts are remembered by the Verilog without its header comments: the same module made
    by another command is not synthesized again; another body is."""
    runs = []
    real = resources.run_yosys
    monkeypatch.setattr(resources, "run_yosys", lambda *a, **k: runs.append(a) or real(*a, **k))
    monkeypatch.setattr(resources, "_COUNTED", {})
    body = ("module twice(input clk, input [7:0] a, input [7:0] b, output reg [15:0] p);\n"
            "  always @(posedge clk) p <= a * b;\nendmodule\n")
    first, second, other = tmp_path / "1.v", tmp_path / "2.v", tmp_path / "3.v"
    first.write_text("// Generated by: one command\n" + body)
    second.write_text("// Generated by: another command\n" + body)
    other.write_text(body.replace("a * b", "a + b"))
    one = count_verilog(first, "twice", tmp_path / "w1")
    assert one.summary()["multipliers"] == 1 and len(runs) == 1
    assert count_verilog(second, "twice", tmp_path / "w2").summary() == one.summary()
    assert len(runs) == 1
    added = count_verilog(other, "twice", tmp_path / "w3").summary()
    assert len(runs) == 2 and added["multipliers"] == 0 and added["adders"] == 1


@pytest.mark.parametrize("addends, const_adders", [
    ([[50, 51, 52]], []),                                        # signal addends only
    ([[50, 51, 52], ["0", "0", "0"]], []),                       # a constant 0 adds nothing
    ([[50, 51, 52], ["1", "0", "0"]], [16]),                     # a constant 1 is an adder
])
def test_a_macc_has_a_constant_adder_only_for_a_nonzero_constant_addend(addends, const_adders):
    cell = _macc([(list(range(2, 8)), list(range(10, 15)))], addends=addends)
    netlist = {"modules": {"top": {"ports": {"y": {"direction": "output", "bits": list(range(100, 116))}},
                                   "cells": {"m": cell}}}}
    counts = count_netlist(netlist, "top")
    assert counts.const_adders == const_adders
    assert counts.adders == [16]                                 # product + the signal addend


@pytest.mark.parametrize("b, multipliers, const_multipliers", [
    (list(range(10, 15)), ["6x5"], []),                         # signal x signal
    (["1", "1", "0"], [], [6]),                                 # x 3: a constant multiplier
    (["0", "0", "1"], [], []),                                  # x 4: a shift
])
def test_a_mul_cell_is_counted_as_a_macc_product_is(b, multipliers, const_multipliers):
    """A ``$mul`` (Yosys writes one before ``alumacc`` turns it into a ``$macc``; a netlist
    from another script may keep it): the same rules as a product of a ``$macc``, on its A
    and B operands."""
    cell = {"type": "$mul", "port_directions": {"Y": "output"},
            "parameters": {"A_WIDTH": 6, "B_WIDTH": len(b), "Y_WIDTH": 11},
            "connections": {"A": list(range(2, 8)), "B": b, "Y": list(range(100, 111))}}
    netlist = {"modules": {"top": {"ports": {"y": {"direction": "output", "bits": list(range(100, 111))}},
                                   "cells": {"m": cell}}}}
    counts = count_netlist(netlist, "top")
    assert counts.multipliers == multipliers and counts.const_multipliers == const_multipliers
