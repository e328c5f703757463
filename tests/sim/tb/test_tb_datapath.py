"""cocotb on the emitted rotation/illumination Verilog, Icarus and Verilator, bit-exact
against the golden model. Long runs (>= 10^6 vectors on Verilator) are `make regress`."""

import pytest

from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.config import Config
from bumprtl.rtl.methods import PER_PIXEL
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb
from bumprtl.sim.traffic import PATTERNS

METHODS = list(PER_PIXEL)              # exact, lee


@pytest.mark.parametrize("sim", SIMULATORS)
@pytest.mark.parametrize("unit", ["rotation", "illumination"])
@pytest.mark.parametrize("method", METHODS)
def test_datapath_cocotb(sim, unit, method, build_dir):
    v, j = emit_unit(unit, Config(method=method), build_dir / "rtl")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_datapath", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 1500})
    assert (run.tests, run.failures) == (len(PATTERNS), 0)


# Table 1 baselines: one short run per simulator (edge cases + 200 random pixels per pattern),
# each unit on one of them; the Amaranth-simulator tests cover the rest (tests/rtl/test_baselines_*).
@pytest.mark.parametrize("sim,unit,method", [("verilator", "rotation", "kim"),
                                             ("icarus", "illumination", "kim"),
                                             ("icarus", "rotation", "peercy"),
                                             ("verilator", "illumination", "peercy")])
def test_baseline_cocotb(sim, unit, method, build_dir):
    v, j = emit_unit(unit, Config(method=method), build_dir / "rtl")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_datapath", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 200})
    assert (run.tests, run.failures) == (len(PATTERNS), 0)


@pytest.mark.regress
@pytest.mark.parametrize("unit", ["rotation", "illumination"])
@pytest.mark.parametrize("method", METHODS)
def test_datapath_regress_1e6_verilator(unit, method, build_dir):
    v, j = emit_unit(unit, Config(method=method), build_dir / "rtl")
    run_cocotb("verilator", v, "bumprtl.sim.tb.tb_datapath", build_dir / "verilator",
               {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 250_000})   # x 4 patterns = 10^6
