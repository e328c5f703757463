"""The emitted TextureCache under cocotb on Icarus and Verilator against cocotbext-axi's
AxiRamRead holding the tiled image (sim/tb/tb_cache.py): random input gaps, output
backpressure, AR and R pauses, memory latencies 2, 20 and 60 cycles; texels and the AR
request stream bit-exact with the golden cache model. The Verilog is lint-clean."""

import json
from dataclasses import asdict

import pytest

from bumprtl.gen.flow.emit import flat_verilog, lint
from bumprtl.rtl.cache import CacheGeometry, TextureCache
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb
from bumprtl.sim.tb.tb_cache import TAG_BITS

# 28-bit N' texels on a 32-bit bus, 8 sets x 2 ways (evictions within a few hundred pixels);
# 8-bit palette indices on a 64-bit bus, 4 ways of 8 x 8 lines (make regress).
GEOMETRIES = {"angles32": CacheGeometry(64, 3, 28, sets=8, ways=2, base=0x1000),
              "index64": CacheGeometry(128, 4, 8, sets=4, ways=4, block=8, data_bits=64)}


def emit_cache(geom, path):
    """The cache's Verilog, flattened by Yosys as every composed unit (ports i, o, axi with
    Amaranth's flattened names), at ``path``."""
    dut = TextureCache(geom, extra={"tag": TAG_BITS})
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(flat_verilog(dut, path.stem))
    return path


@pytest.mark.parametrize("sim,name", [*[(s, "angles32") for s in SIMULATORS],
                                      *[pytest.param(s, "index64", marks=pytest.mark.regress)
                                        for s in SIMULATORS]])
def test_cache_cocotb_against_axi_ram(sim, name, build_dir):
    geom = GEOMETRIES[name]
    v = emit_cache(geom, build_dir / "rtl" / "texture_cache.v")
    assert lint(v) == []
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_cache", build_dir / sim,
                     {"BUMPRTL_CACHE": json.dumps(asdict(geom)), "BUMPRTL_SAMPLES": 200})
    assert (run.tests, run.failures) == (3, 0)
