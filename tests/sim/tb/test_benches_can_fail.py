"""Each cocotb bench make test relies on fails on a design one output bit away from the
emitted one (tests/sim/tb/broken.py: the same ports, one bit of the payload inverted): a
bench whose comparison was weakened, whose model was swapped for the design's own output,
or whose failures were not counted would pass it. Icarus, a few pixels a pattern."""

import pytest

from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.config import Config
from bumprtl.sim.tb.runner import run_cocotb

from .broken import flip_output_bit


@pytest.mark.parametrize("unit", ["rotation", "illumination"])
def test_the_datapath_bench_fails_on_a_flipped_output_bit(unit, build_dir):
    v, j = emit_unit(unit, Config(), build_dir / "rtl")
    bad = flip_output_bit(v, build_dir / "broken", bit=3)
    with pytest.raises(AssertionError, match=r"of 4 cocotb tests failed on icarus; see .*result.xml"):
        run_cocotb("icarus", bad, "bumprtl.sim.tb.tb_datapath", build_dir / "icarus",
                   {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 10})


def test_the_palette_bench_fails_on_a_flipped_output_bit(build_dir):
    v, j = emit_unit("palette", Config(palette_size=200, palette_blend=True, tag_bits=8),
                     build_dir / "rtl")
    bad = flip_output_bit(v, build_dir / "broken", bit=0)
    with pytest.raises(AssertionError, match=r"of 4 cocotb tests failed on icarus; see .*result.xml"):
        run_cocotb("icarus", bad, "bumprtl.sim.tb.tb_palette", build_dir / "icarus",
                   {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 10})


def test_the_broken_copy_runs_clean_without_its_flip(build_dir):
    """The wrapper alone (bit flipped twice is no flip: the helper applied to its own
    output) passes the bench: the failures above come from the flipped bit, not from the
    wrapper."""
    v, j = emit_unit("illumination", Config(), build_dir / "rtl")
    once = flip_output_bit(v, build_dir / "once", bit=3)
    twice = flip_output_bit(once, build_dir / "twice", bit=3)
    run = run_cocotb("icarus", twice, "bumprtl.sim.tb.tb_datapath", build_dir / "icarus",
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 10})
    assert run.failures == 0 and run.tests > 0
