"""cocotb on the emitted palette.v under both simulators: one build each (blend stage on,
sN = 200 so that out-of-range indices occur), four traffic patterns per build."""

import pytest

from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.config import Config
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb
from bumprtl.sim.traffic import PATTERNS


@pytest.mark.parametrize("sim", SIMULATORS)
def test_palette_cocotb(sim, build_dir):
    cfg = Config(palette_size=200, palette_blend=True, tag_bits=8)
    v, j = emit_unit("palette", cfg, build_dir / "rtl")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_palette", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 500})
    assert (run.tests, run.failures) == (len(PATTERNS), 0)
