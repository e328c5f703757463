"""The emitted SdramController under cocotb on Icarus and Verilator, its pins on the
datasheet model of the chip (sim/sdram_model.py: any illegal command or timing violation
fails the test), random AXI traffic from cocotbext-axi's AxiMaster compared with a
Python dict of the bytes written, and data kept across idle refreshes
(sim/tb/tb_sdram.py). The Verilog is lint-clean."""

import json
from dataclasses import asdict

import pytest

from bumprtl.gen.flow.emit import flat_verilog, lint
from bumprtl.rtl.sdram import SdramConfig, SdramController
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb

# The board's clock and CAS latency, a short power-up (the model is told); the 64 MB part
# at CL 3 with bursts of 4 on a 64-bit bus (make regress, longer traffic).
CONFIGS = {"32mb_cl2": SdramConfig("32mb", 100, 2, powerup_cycles=50),
           "64mb_cl3": SdramConfig("64mb", 133, 3, burst=4, data_bits=64, powerup_cycles=50)}


def emit_sdram(cfg, path):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(flat_verilog(SdramController(cfg), path.stem))
    return path


# make test: this bench on Verilator, the cache-on-SDRAM bench on Icarus (one SDRAM bench
# per simulator); make regress: both benches on both.
@pytest.mark.parametrize("sim,name,rounds", [
    *[pytest.param(s, "32mb_cl2", 6, marks=() if s == "verilator" else pytest.mark.regress)
      for s in SIMULATORS],
    *[pytest.param(s, name, 60, marks=pytest.mark.regress)
      for s in SIMULATORS for name in CONFIGS]])
def test_sdram_cocotb_random_traffic(sim, name, rounds, build_dir):
    cfg = CONFIGS[name]
    v = emit_sdram(cfg, build_dir / "rtl" / "sdram_controller.v")
    assert lint(v) == []
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_sdram", build_dir / sim,
                     {"BUMPRTL_SDRAM": json.dumps(asdict(cfg)), "BUMPRTL_SAMPLES": rounds})
    assert (run.tests, run.failures) == (2, 0)
