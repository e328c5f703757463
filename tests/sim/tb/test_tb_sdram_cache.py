"""The texture cache reading through the SDRAM controller from the datasheet model of the
chip (sim/tb/tb_sdram_cache.py), in place of test_tb_cache.py's AxiRamRead, under cocotb
on Icarus and Verilator: the tiled image written through the controller's AXI write port,
then texels bit-exact with the golden cache model under random input gaps and output
backpressure, no command the datasheet forbids. The Verilog is lint-clean."""

import json
from dataclasses import asdict

import pytest

from bumprtl.gen.flow.emit import flat_verilog, lint
from bumprtl.rtl.sdram import SdramConfig
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb
from bumprtl.sim.tb.tb_sdram_cache import CacheOnSdram
from tests.sim.tb.test_tb_cache import GEOMETRIES

# The board's SDRAM configuration with a short power-up (the model is told); the cache
# geometries of test_tb_cache.py (angles32 on Icarus in make test, the rest in make regress).
SDRAM = {32: SdramConfig("32mb", 100, 2, powerup_cycles=50),
         64: SdramConfig("32mb", 100, 2, data_bits=64, powerup_cycles=50)}


@pytest.mark.parametrize("sim,name", [*[pytest.param(s, "angles32", marks=() if s == "icarus"
                                                   else pytest.mark.regress) for s in SIMULATORS],
                                      *[pytest.param(s, "index64", marks=pytest.mark.regress)
                                        for s in SIMULATORS]])
def test_cache_cocotb_on_sdram(sim, name, build_dir):
    geom = GEOMETRIES[name]
    cfg = SDRAM[geom.data_bits]
    v = build_dir / "rtl" / "cache_on_sdram.v"
    v.parent.mkdir(parents=True, exist_ok=True)
    v.write_text(flat_verilog(CacheOnSdram(geom, cfg), v.stem))
    assert lint(v) == []
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_sdram_cache", build_dir / sim,
                     {"BUMPRTL_CACHE": json.dumps(asdict(geom)),
                      "BUMPRTL_SDRAM": json.dumps(asdict(cfg)), "BUMPRTL_SAMPLES": 200})
    assert (run.tests, run.failures) == (1, 0)
