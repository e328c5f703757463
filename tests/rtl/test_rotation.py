"""VectorRotation and Illumination in the Amaranth simulator, bit for bit against the
fixed-point golden model (sim/golden/fixed/), under every traffic pattern of
sim/traffic.py. The volume (10^6 vectors) is on Verilator in `make regress`; here every
pattern gets the edge cases and 1 000 random vectors."""

import numpy as np
import pytest

from bumprtl.rtl.config import Config
from bumprtl.sim.amaranth_stream import check_illumination, check_rotation
from bumprtl.sim.golden.methods import PER_PIXEL
from bumprtl.sim.golden.vectors import TINY, concat_codes, edge_codes, random_codes
from bumprtl.sim.traffic import PATTERNS

METHODS = list(PER_PIXEL)              # exact, lee


# each datapath without stalls and under "both" (gaps and backpressure at once) in make
# test, under each alone in make regress
@pytest.mark.parametrize("method, pattern", [
    (m, p) if p in ("no_stall", "both") else
    pytest.param(m, p, marks=pytest.mark.regress) for m in METHODS for p in PATTERNS])
def test_rotation_and_illumination_bit_exact(method, pattern):
    """The edge cases and 400 random vectors (a seed per pattern; the random volume is the
    cocotb runs' and make regress's); without stalls one pixel per clock."""
    cfg = Config(method=method)
    seed = list(PATTERNS).index(pattern)
    codes = concat_codes(edge_codes(cfg), random_codes(400, cfg, seed=seed))
    latency, cycles = check_rotation(cfg, codes, pattern)
    check_illumination(cfg, codes, pattern)
    total = len(codes["n.phi"])
    if pattern == "no_stall":                 # 1 pixel per clock: latency + N cycles
        assert cycles == total + latency
    else:
        assert cycles > total


@pytest.mark.parametrize("method", METHODS)
def test_tiny_config_exhaustive_per_output_support(method):
    """k = 2 (4-bit angles). Every output field depends on at most three input angles
    (n'' on th_N, ph_N', th_N'; a vector's terms on th_A and ph_A - ph_N). 4096 vectors walk
    all 16^3 combinations of the first three and, at the same time, all 16^2 of each
    vector's pair, so every field sees every value of its inputs."""
    cfg = TINY.replace(method=method)
    idx = np.arange(4096, dtype=np.int32)
    d1, d2, d3 = idx & 15, (idx >> 4) & 15, idx >> 8
    codes = {"n.theta": d1, "b.phi": d2, "b.theta": d3, "n.phi": (d3 * 5) & 15,
             "l.theta": d1, "l.phi": (d2 + d3 * 5) & 15, "h.theta": d2, "h.phi": (d1 + d3 * 5) & 15}
    check_rotation(cfg, codes, "no_stall")
    check_illumination(cfg, codes, "no_stall")


@pytest.mark.parametrize("specular", [True, False])
def test_configurations(specular):
    """Narrow and wide widths, specular on and off: the edge cases and 300 random vectors
    each (the random volume at the default widths: the tests above and the cocotb runs)."""
    for cfg in (Config(angle_bits=8, frac_bits=9, specular=specular, spec_exponent=3),
                Config(angle_bits=14, frac_bits=16, specular=specular, spec_exponent=128)):
        codes = concat_codes(edge_codes(cfg), random_codes(300, cfg, seed=3))
        check_rotation(cfg, codes, "backpressure")
        check_illumination(cfg, codes, "input_gaps")
