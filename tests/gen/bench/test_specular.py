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
