"""cocotb testbench for the emitted rotation.v / illumination.v (either method).

The unit and its Config come from the sidecar; stimulus is the edge cases, (exact method)
the pixels whose dot products sit next to a rounding carry (sim/tb/bulk_sources.py's
rounding_codes), then random valid pixels (BUMPRTL_SAMPLES of them); the golden model is
the method's in sim/golden/fixed/.
"""

import cocotb
import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.methods import get, illumination_fixed, rotation_fixed
from bumprtl.sim.golden.vectors import as_payloads, edge_codes, random_codes
from bumprtl.sim.tb.bulk_sources import rounding_codes
from bumprtl.sim.tb.stream import PATTERNS, load_sidecar, run_stream, samples


def _stimulus(unit, cfg, n, seed, fields):
    """``(payloads, model)``: the input payloads, and the golden model of the output
    ``fields`` (the sidecar's output port fields) for the inputs the DUT accepted."""
    edges, rand = edge_codes(cfg), random_codes(n, cfg, seed=seed)
    near = rounding_codes(cfg, seed) or {k: [] for k in edges}    # exact: rounding carries
    codes = {k: np.concatenate([edges[k], near[k], rand[k]]).astype(np.int64) for k in edges}
    codes = get(cfg.method).from_angle_codes(codes, cfg)   # Cartesian for Peercy, Ernst
    if unit == "rotation":
        return as_payloads(codes, cfg), lambda acc: _golden(acc, cfg, rotation_fixed, fields)
    rot = rotation_fixed(codes, cfg)
    return as_payloads(rot, cfg), lambda acc: _golden(acc, cfg, illumination_fixed, fields)


def _golden(accepted, cfg, model, fields):
    keys = [k for k in accepted[0] if k != "tag"]
    arrays = {k: np.array([a[k] for a in accepted], dtype=np.int64) for k in keys}
    out = model(arrays, cfg)
    return [{**{k: int(v[n]) for k, v in out.items() if k in fields}, "tag": a["tag"]}
            for n, a in enumerate(accepted)]


@cocotb.test()
@cocotb.parametrize(pattern=list(PATTERNS))
async def datapath_matches_golden(dut, pattern):
    meta = load_sidecar()
    cfg = Config(**meta.config)
    fields = {k for k in meta.output_fields if k != "tag"}
    inputs, model = _stimulus(meta.unit, cfg, samples(1000), len(pattern), fields)
    await run_stream(dut, meta, inputs, model, pattern)
