"""cocotb testbench for the emitted rotation.v / illumination.v (either method).

The unit and its Config come from the sidecar; stimulus is the edge cases plus random
valid pixels (BUMPRTL_SAMPLES of them); the golden model is sim/golden/fixed.py.
"""

import cocotb
import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.fixed.dispatch import illumination_fixed, rotation_fixed
from bumprtl.sim.golden.vectors import as_payloads, edge_codes, random_codes
from bumprtl.sim.tb.stream import PATTERNS, load_sidecar, run_stream, samples


def _stimulus(unit, cfg, n, seed):
    edges, rand = edge_codes(cfg), random_codes(n, cfg, seed=seed)
    codes = {k: np.concatenate([edges[k], rand[k]]) for k in edges}
    if cfg.method in ("peercy", "ernst"):      # Cartesian inputs: the same directions
        from bumprtl.sim.golden.fixed.peercy import from_angle_codes
        codes = from_angle_codes(codes, cfg)
    if unit == "rotation":
        return as_payloads(codes, cfg), lambda acc: _golden(acc, cfg, rotation_fixed)
    rot = rotation_fixed(codes, cfg)
    return as_payloads(rot, cfg), lambda acc: _golden(acc, cfg, illumination_fixed)


def _golden(accepted, cfg, model):
    keys = [k for k in accepted[0] if k != "tag"]
    arrays = {k: np.array([a[k] for a in accepted], dtype=np.int64) for k in keys}
    out = model(arrays, cfg)
    return [{**{k: int(v[n]) for k, v in out.items() if k in _out_fields}, "tag": a["tag"]}
            for n, a in enumerate(accepted)]


_out_fields = set()


@cocotb.test()
@cocotb.parametrize(pattern=list(PATTERNS))
async def datapath_matches_golden(dut, pattern):
    meta = load_sidecar()
    cfg = Config(**meta["config"])
    _out_fields.clear()
    _out_fields.update(k for k in meta["ports"]["o__payload"]["fields"] if k != "tag")
    inputs, model = _stimulus(meta["unit"], cfg, samples(1000), seed=len(pattern))
    await run_stream(dut, meta, inputs, model, pattern)
