"""cocotb on the emitted rotation/illumination Verilog, Icarus and Verilator, bit-exact
against the golden model. Verilator carries the random volume of `make test` (the
Amaranth-simulator tests, tests/rtl/test_rotation.py, run the edge cases and 1 000 random
vectors per pattern); long runs (>= 10^7 vectors on Verilator, bulk path) are `make regress`."""

import pytest

from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.methods import PER_PIXEL
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb
from bumprtl.sim.traffic import PATTERNS

METHODS = list(PER_PIXEL)              # exact, lee
# Random vectors per traffic pattern (plus the edge cases): a Verilator run costs little
# beside its build, an Icarus run more; the volume that reaches ROM entries few vectors hit
# (10^7 vectors per unit and method) is make regress's bulk path (tests/sim/tb/test_bulk.py).
SAMPLES = {"icarus": 250, "verilator": 4000}


def _cases():
    """Every method and unit on Icarus; on Verilator our exact method in make test and lee's
    build (its twelve ROMs) in make regress beside its 10^7 bulk vectors."""
    for method in METHODS:
        for unit in ("rotation", "illumination"):
            for sim in SIMULATORS:
                # regress: lee on Verilator and lee's rotation on Icarus too (make test keeps
                # its illumination there; tests/rtl/test_lee.py runs the rotation bit-exact in
                # the Amaranth simulator); exact rotation on Verilator (its Icarus run stays,
                # and the scene pipelines run it on Verilator in make test); exact illumination
                # on Icarus (its Verilator run stays, and make test streams it on Icarus
                # inside the default and full scenes' pipelines: test_bulk, test_tb_pipeline)
                slow = (sim, method) == ("verilator", "lee") or (sim, method, unit) in (
                    ("verilator", "exact", "rotation"), ("icarus", "lee", "rotation"),
                    ("icarus", "exact", "illumination"))
                marks = pytest.mark.regress if slow else ()
                yield pytest.param(sim, unit, method, marks=marks, id=f"{method}-{unit}-{sim}")


@pytest.mark.parametrize("sim,unit,method", _cases())
def test_datapath_cocotb(sim, unit, method, build_dir):
    v, j = emit_unit(unit, Config(method=method), build_dir / "rtl")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_datapath", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": SAMPLES[sim]})
    assert (run.tests, run.failures) == (len(PATTERNS), 0)


# Table 1 baselines: one short run per simulator (edge cases + 200 random pixels per pattern),
# each unit on one of them; the Amaranth-simulator tests cover the rest (tests/rtl/test_baselines_*,
# the setups bit-exact under stalls in make test), so the setups' Icarus runs (their square-root,
# divider and reciprocal pipelines: thousands of flip-flops an event-driven simulator steps one
# by one) are make regress, and so is Kim's illumination (the shared back end of Peercy's, which
# make test runs, behind eqs (3)/(4)).
@pytest.mark.parametrize("sim,unit,method", [
    pytest.param("icarus", "rotation", "kim", marks=pytest.mark.regress),
    pytest.param("verilator", "illumination", "kim", marks=pytest.mark.regress),
    pytest.param("icarus", "rotation", "peercy", marks=pytest.mark.regress),
    ("verilator", "illumination", "peercy")])
def test_baseline_cocotb(sim, unit, method, build_dir):
    v, j = emit_unit(unit, Config(method=method), build_dir / "rtl")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_datapath", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 200})
    assert (run.tests, run.failures) == (len(PATTERNS), 0)


# `make regress` pushes >= 10^7 vectors through each unit and method on the bulk path
# (tests/sim/tb/test_bulk.py), which replaced the per-cycle 10^6-vector runs here.
