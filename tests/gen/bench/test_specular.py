"""bumprtl bench specular's candidates: each computes 255 x^n as it says, on every N'.H of
the B-bit grid (the bench's 'term max' column), and the kept one is the RTL's."""

import numpy as np
import pytest

from bumprtl.gen.bench.specular import CANDIDATES, candidate_fine
from bumprtl.rtl.config import Config
from bumprtl.rtl.tables import SPEC_FRAC_BITS, specular_table_error_lsb
from bumprtl.sim.golden.fixed.common import specular_fine_fixed


@pytest.mark.parametrize("exponent", [1, 16, 1024])
def test_candidates_term_error(exponent):
    cfg = Config(spec_exponent=exponent)
    h = np.arange(cfg.one + 1)
    x = h / cfg.one
    exact = 255 * x ** exponent
    err = {name: np.abs(candidate_fine(name, h, cfg) / 2 ** SPEC_FRAC_BITS - exact).max()
           for name in CANDIDATES}
    # nearest entry: half an index step times the largest slope 255 n, plus the word's rounding
    for name, s in (("nearest 2^10 (before)", 10), ("nearest 2^12", 12)):
        assert err[name] <= 255 * exponent * 2.0 ** -(s + 1) + 0.5
    assert np.array_equal(candidate_fine("interpolated, finer near 1 (kept)", h, cfg),
                          specular_fine_fixed(h, cfg))
    assert err["interpolated, finer near 1 (kept)"] <= specular_table_error_lsb(cfg) < 0.02
    # squaring: every product rounded to B bits, a relative error of about n 2**-B at x = 1
    assert err["repeated squaring"] <= 255 * exponent * 2.0 ** -cfg.frac_bits
    if exponent == 1024:            # plain interpolation's chord error grows as n**2
        assert err["interpolated"] > 10 > 100 * err["interpolated, finer near 1 (kept)"]


def test_bench_table_costs_follow_the_candidates_structure(monkeypatch, tmp_path, run_cli):
    """bench specular's cost columns against closed forms: a nearest table of 2^s + 1
    8-bit words (2048 a DP16KD), the interpolated tables 2^index_bits + 1 words of 8 + F
    bits (1024 a DP16KD) and one multiplier, squaring floor(log2 n) + popcount(n) - 1
    multipliers; five rows per exponent; the Illumination count printed as counted."""
    from bumprtl.gen.bench import specular
    from bumprtl.rtl.tables import specular_index_bits

    counted = []

    class Counts:
        def summary(self):
            return {"multipliers": 11, "const_multipliers": 12, "tables": 13, "table_bits": 14,
                    "table_reads": 15, "adders": 16, "register_bits": 17}

    real = specular.adversarial_pixels              # a smaller search: the columns are the test
    monkeypatch.setattr(specular, "adversarial_pixels", lambda cfg, channel: real(
        cfg, candidates=2000, keep=20, channel=channel))
    monkeypatch.setattr(specular, "count_unit",
                        lambda unit, cfg, work: counted.append((unit, cfg, work)) or Counts())
    monkeypatch.chdir(tmp_path)                         # the tools' log: build/bench/
    r = run_cli(["bench", "specular", "--spec-exponent", "16", "5", "--samples", "300",
                 "--work", tmp_path])
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert out.splitlines()[0] == "bumprtl bench specular --samples 300 --spec-exponent 16 5"
    rows = [line.strip("| ").split(" | ") for line in out.splitlines()
            if line.startswith("| ") and line[2].isdigit()]
    assert [(r[0], r[1]) for r in rows] == [(str(n), c) for n in (16, 5) for c in CANDIDATES]
    sib = specular_index_bits(Config())
    interp = (f"{(1 << sib) + 1} x {8 + SPEC_FRAC_BITS}", str(-(-(1 << sib) // 1024)), "1")
    want = {"nearest 2^10 (before)": ("1025 x 8", "1", "0"),
            "nearest 2^12": ("4097 x 8", "2", "0"),
            "interpolated": interp, "interpolated, finer near 1 (kept)": interp}
    for n, name, words, blocks, mults, term, *_ in rows:
        n = int(n)
        squaring = ("none", "0", str(n.bit_length() - 1 + bin(n).count("1") - 1))
        assert (words, blocks, mults) == want.get(name, squaring), name
        if name.endswith("(kept)"):
            assert float(term) <= specular_table_error_lsb(Config(spec_exponent=n)) + 5e-4
    assert rows[4][4] == "4" and rows[9][4] == "3"          # 16 = 2^4; 5 = 4 + 1
    assert counted == [("illumination", Config(), tmp_path)]
    assert ("multipliers 11, const_multipliers 12, tables 13, table_bits 14, table_reads 15, "
            "adders 16, register_bits 17") in out
