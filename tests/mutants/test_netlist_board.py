"""The board units' bench of tests/mutants/netlist.py (netlist_board.py): on the mutated
netlist it runs as ``make mutate-rtl`` does, the unmutated design (mutsel = 0) matches its
oracle in every cycle and a sample of Yosys's mutations is killed by it, so the oracle is
neither wrong about the design nor blind to its bugs. The timing in make test (a few
seconds); the buffer, the TMDS encoder and the pixel source, whose benches build the
default pipeline or run longer, in make regress."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import netlist  # noqa: E402
import netlist_board as nb  # noqa: E402


@pytest.mark.parametrize("target", [
    "board:timing",
    pytest.param("board:buffer", marks=pytest.mark.regress),
    pytest.param("board:tmds", marks=pytest.mark.regress),
    pytest.param("board:source", marks=pytest.mark.regress)])
def test_the_bench_passes_the_design_and_kills_mutants(tmp_path, target):
    rtl = tmp_path / "rtl"
    v, design, bench = nb.bench(target, rtl, 3)
    lines = netlist.mutation_list(v, design.module, 4, 3, rtl)
    mv, _ = netlist.mutated_netlist(v, design, lines, rtl, passes=("pmuxtree",))
    bench.build(mv, rtl)
    assert bench.run(tmp_path / "run0", 0) == "passed"
    said = [bench.run(tmp_path / f"run{i}", i) for i in range(1, len(lines) + 1)]
    assert any(s.startswith("killed: ") for s in said), said


def test_a_wrong_oracle_kills_the_design(tmp_path):
    # the timing's oracle with de one cycle late: the unmutated design no longer matches
    # (the bench compares what it claims to)
    rtl = tmp_path / "rtl"
    v, design, bench = nb.bench("board:timing", rtl, 3)
    bench.expected["de"] = [0] + bench.expected["de"][:-1]
    lines = netlist.mutation_list(v, design.module, 1, 3, rtl)
    mv, _ = netlist.mutated_netlist(v, design, lines, rtl, passes=("pmuxtree",))
    bench.build(mv, rtl)
    assert bench.run(tmp_path / "run0", 0).startswith("killed: de at cycle ")
