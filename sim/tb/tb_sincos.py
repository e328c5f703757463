"""cocotb testbench for the emitted ``sincos.v``: every output against the numpy table."""

import cocotb
import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.rtl.tables import cos_lookup, sin_lookup
from bumprtl.sim.tb.stream import PATTERNS, load_sidecar, run_stream, samples


def model(cfg):
    def expected(accepted):
        a = np.array([x["angle"] for x in accepted], dtype=np.int64)
        s, c = sin_lookup(cfg, a), cos_lookup(cfg, a)
        return [{"sin": int(s[n]), "cos": int(c[n]), "tag": x["tag"]}
                for n, x in enumerate(accepted)]
    return expected


@cocotb.test()
@cocotb.parametrize(pattern=list(PATTERNS))
async def sincos_matches_table(dut, pattern):
    meta = load_sidecar()
    cfg = Config(**meta.config)
    rng = np.random.default_rng(7)
    n = samples(500)
    angles = rng.integers(0, cfg.full_circle, n)
    # Quadrant boundaries and their neighbours first: the mirrored-index corner cases.
    edges = [(q << cfg.k) + d for q in range(4) for d in (-1, 0, 1)]
    angles = np.concatenate([np.array(edges) % cfg.full_circle, angles])
    inputs = [{"angle": int(a), "tag": n & ((1 << cfg.tag_bits) - 1)} for n, a in enumerate(angles)]
    await run_stream(dut, meta, inputs, model(cfg), pattern)
