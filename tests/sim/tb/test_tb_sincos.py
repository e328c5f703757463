"""cocotb on the emitted sincos.v under both simulators (a missing one fails, never skips)."""

import pytest

from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.config import Config
from bumprtl.sim.tb.runner import run_cocotb
from bumprtl.sim.traffic import PATTERNS


# Both widths on both simulators; the wide ROM's Verilator build (its C++ compile) is make regress.
@pytest.mark.parametrize("sim, angle_bits, frac_bits", [
    ("icarus", 12, 13), pytest.param("verilator", 12, 13, marks=pytest.mark.regress),
    ("icarus", 8, 8), ("verilator", 8, 8)])
def test_sincos_cocotb(sim, angle_bits, frac_bits, build_dir):
    v, j = emit_unit("sincos", Config(angle_bits=angle_bits, frac_bits=frac_bits), build_dir / "rtl")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_sincos", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 600})
    assert (run.tests, run.failures) == (len(PATTERNS), 0)


def test_missing_simulator_fails_with_install_hint(monkeypatch, tmp_path):
    """A simulator that is not on PATH is an error naming the install command, never a skip."""
    from bumprtl.gen.tools import toolchain
    monkeypatch.setattr(toolchain.shutil, "which", lambda *a, **k: None)
    v, _ = emit_unit("sincos", Config(angle_bits=8, frac_bits=8), tmp_path)
    with pytest.raises(toolchain.ToolMissing, match="apt-get install -y iverilog"):
        run_cocotb("icarus", v, "bumprtl.sim.tb.tb_sincos", tmp_path / "icarus")
