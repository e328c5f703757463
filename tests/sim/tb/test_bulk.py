"""The bulk path (sim/tb/bulk.py): stimulus and outputs as arrays, the clock inside the
simulator, the build cached by the Verilog's digest.

`make test`: the coverage frame (sim/tb/bulk_frame.py) of the default pipeline and of two
palette scenes under every traffic pattern, bit-exact against the golden model, and a
rendered frame byte-exact from the cached build; a wrong golden value fails and a deadlock
ends in a timeout that counts the pixels in and out (both on the sincos unit, the smallest
build); bad stimulus is refused before the build. `make regress`: >= 10^7 vectors through each
emitted unit and the default pipeline under every traffic pattern on Verilator (this
replaces the per-cycle 10^6-vector runs, keeping their units, methods, patterns and the
pipeline's stress cases).
"""

import os

import numpy as np
import pytest

from bumprtl.gen.flow.units import emit_unit
from bumprtl.gen.render.rtl import emit_pipeline, scene_stimulus, scene_texels
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.methods import PER_PIXEL
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.rtl.tables import cos_lookup, sin_lookup
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb import bulk
from bumprtl.sim.tb.bulk import (
    SIMULATORS,
    TRAFFIC,
    SimulationTimeout,
    check_stimulus,
    decode_words,
    encode_words,
    run_bulk,
)
from bumprtl.sim.tb.bulk_frame import coverage_frame
from bumprtl.sim.tb.bulk_shards import run_bulk_shards
from bumprtl.sim.tb.bulk_sources import pipeline_map

# Icarus is ~1000x slower than Verilator on the pipeline: a smaller frame, the same patterns.
FRAME = {"icarus": 16, "verilator": 64}


def _frame(size):
    scene = load_scene_config("default")
    inputs, words, polygon, table, base = scene_stimulus(scene, size)
    texels = scene_texels(scene, base)
    return scene, inputs, words, polygon, table, texels


# Verilator's run of this test is in make regress (its Icarus run stays in make test, and
# Verilator's builds of the same units run in the other tests of make test).
ICARUS_HERE = [pytest.param(s, marks=pytest.mark.regress if s == "verilator" else ()) for s in SIMULATORS]


@pytest.mark.parametrize("sim", ICARUS_HERE)
def test_bulk_pipeline_frame_equals_golden(sim, build_dir):
    """The default scene's emitted pipeline under all four traffic patterns: the coverage
    frame (sim/tb/bulk_frame.py: map words written through the host port first, then L, H,
    N and texels over their whole ranges, near +-N'' where cos^n is steep, tags over the
    whole tag range, the table-sensitivity pixels after them) has every output field equal to
    the golden model's (checked in cocotb and here); no stall means one pixel per clock, stalls
    cost cycles. Then the rendered frame's pixels through the same build (a second run of the
    cached build, the memories as emitted) equal the golden render's, the outputs
    gen/render/rtl.golden_render makes its image of (render_rtl itself:
    tests/sim/tb/test_tb_pipeline.py). The netlist mutants of the scene pipelines run this
    frame (tests/mutants/netlist.py)."""
    size = FRAME[sim]
    scene, render, words, _, _, texels = _frame(size)
    v, j = emit_pipeline(scene, words, texels, build_dir, None, write_port=True)
    meta = load_sidecar(j)
    frame = coverage_frame(scene, words, texels, n=size * size)
    n = len(frame.inputs["tag"])
    assert n > size * size                                # the table-sensitivity pixels
    golden = frame.expected(meta)
    r = run_bulk(sim, v, j, build_dir / f"bulk_{sim}", tuple(TRAFFIC), inputs=frame.inputs,
                 expected=golden, setup=frame.setup(meta), between=frame.between(meta))
    outs, cycles = r.outputs, r.cycles
    assert r.checked
    assert set(golden) == set(meta.output_fields)
    latency = meta.latency
    for pattern in TRAFFIC:
        assert r.pixels[pattern] == n
        assert np.array_equal(outs[pattern]["tag"], frame.inputs["tag"]), pattern
        for field, want in golden.items():
            assert np.array_equal(outs[pattern][field], want), (pattern, field)
    assert cycles["no_stall"] <= n + latency + 2
    for pattern in ("input_gaps", "backpressure", "both"):
        assert cycles[pattern] > 1.2 * n, pattern
    want = pipeline_fixed(render, scene, words, None, texels)
    r = run_bulk(sim, v, j, build_dir / f"render_{sim}", inputs=render,
                 expected={k: want[k] for k in golden if k != "tag"})
    assert r.cached                                       # the same Verilog: built once
    for field in golden:
        got = r.outputs["no_stall"][field]
        assert np.array_equal(got, render["tag"] if field == "tag" else want[field]), field


SINCOS = Config(angle_bits=12)


@pytest.fixture(scope="module")
def sincos_rtl(tmp_path_factory):
    """The sincos unit's Verilog and sidecar, emitted once for the four tests below that
    read them (each emission is a Yosys run of ~2.5 s; the runs stay in each test's own
    directory, and the bulk build is cached by the Verilog's digest either way)."""
    return emit_unit("sincos", SINCOS, tmp_path_factory.mktemp("sincos") / "rtl")


def _sincos(sincos_rtl, n=256):
    """The sincos unit (the bulk path's smallest build), ``n`` angles and their golden values."""
    cfg = SINCOS
    v, j = sincos_rtl
    angle = np.random.default_rng(5).integers(0, cfg.full_circle, n)
    tag = np.arange(n) & ((1 << cfg.tag_bits) - 1)
    golden = {"sin": sin_lookup(cfg, angle), "cos": cos_lookup(cfg, angle), "tag": tag}
    return v, j, {"angle": angle, "tag": tag}, golden


def test_bulk_fails_on_one_wrong_golden_value(build_dir, sincos_rtl):
    """The check can fail: one corrupted golden value is reported with its pattern, output
    index and field (the sincos unit on Icarus: a one-second build)."""
    v, j, inputs, golden = _sincos(sincos_rtl)
    assert run_bulk("icarus", v, j, build_dir / "bulk", ("backpressure",), inputs=inputs,
                    expected=golden).checked                       # the true values pass
    golden["sin"] = golden["sin"].copy()
    golden["sin"][77] ^= 1
    with pytest.raises(AssertionError, match=r"output 77 field sin: RTL -?\d+ != golden -?\d+"):
        run_bulk("icarus", v, j, build_dir / "bulk", ("backpressure",), inputs=inputs,
                 expected=golden)


@pytest.mark.parametrize("sim", ICARUS_HERE)
def test_bulk_deadlock_ends_in_a_timeout(sim, build_dir, sincos_rtl):
    """Output ready never rises: the unit fills and stops. The run ends (it never hangs)
    with a timeout naming the pixels that went in and came out."""
    v, j, inputs, _ = _sincos(sincos_rtl)
    with pytest.raises(SimulationTimeout,
                       match=r"deadlock\): pattern stuck: [1-9]\d* pixels went in, 0 came out of 256"):
        run_bulk(sim, v, j, build_dir / "bulk", patterns=("stuck",), inputs=inputs,
                 traffic={"stuck": (0.0, 1.0)}, idle_limit=500)


def test_bulk_refuses_stimulus_that_does_not_match_the_sidecar(build_dir, monkeypatch, sincos_rtl):
    """Fields and widths are checked against the sidecar before any build."""
    v, j = sincos_rtl
    monkeypatch.setattr(bulk, "build", lambda *a, **k: pytest.fail("built before the check"))
    n = 10
    good = {"angle": np.arange(n), "tag": np.arange(n)}
    cases = [({"angle": np.arange(n)}, r"lacks field 'tag'"),
             ({**good, "phase": np.arange(n)}, r"'phase' is not an input field of sincos.json"),
             ({**good, "angle": np.r_[np.arange(n - 1), 1 << 12]},
              r"'angle' needs 13 bits \(values 0\.\.4096\), sincos.json i__payload field 'angle' "
              r"is 12 bits \(unsigned, 0\.\.4095\)"),
             ({**good, "tag": np.arange(n + 1)}, r"fields differ in length: \[10, 11\]"),
             ({**good, "tag": np.array([-1] * n)}, r"'tag' needs \d+ bits \(values -1\.\.-1\)"),
             ({**good, "angle": np.arange(n) * 0.5}, r"'angle' must be an integer array")]
    for inputs, message in cases:
        with pytest.raises(BumpError, match=message):
            run_bulk("verilator", v, j, build_dir / "bulk", inputs=inputs)
    with pytest.raises(BumpError, match=r"'angle' is 16 bits wide, sincos.json i__payload "
                                        r"field 'angle' is 12 bits"):
        run_bulk("verilator", v, j, build_dir / "bulk", inputs=good, widths={"angle": 16})
    assert check_stimulus(load_sidecar(j), good) == n


def test_bulk_build_options_are_checked_before_the_build(build_dir, monkeypatch, sincos_rtl):
    """Verilator's C++ clock and DPI I/O are refused on Icarus, and a bad option on either
    simulator, in one line naming the option, before anything is built."""
    v, j = sincos_rtl
    monkeypatch.setattr(bulk, "build", lambda *a, **k: pytest.fail("built before the check"))
    good = {"angle": np.arange(4), "tag": np.arange(4)}
    cases = [("icarus", {"clock": "cxx"}, r"clock 'cxx' needs Verilator's C\+\+ build; on "
                                          r"icarus clock must be 'verilog'"),
             ("icarus", {"io": "dpi"}, r"io 'dpi' needs Verilator's C\+\+ build"),
             ("icarus", {"opt_fast": "-O2"}, r"opt_fast and extra are Verilator build options"),
             ("verilator", {"clock": "vpi"}, r"clock must be one of verilog, cxx, got 'vpi'"),
             ("verilator", {"io": "mmap"}, r"io must be one of file, dpi, got 'mmap'"),
             ("verilator", {"opt_fast": "-O3 -march=native"}, r"opt_fast must be one g\+\+ flag")]
    for sim, opts, message in cases:
        with pytest.raises(BumpError, match=message):
            run_bulk(sim, v, j, build_dir / "bulk", inputs=good, **opts)
    assert bulk.build_options("verilator") == {**bulk.DEFAULTS["verilator"], "extra": ()}


def test_bulk_codec_round_trip():
    """Fields straddling 32-bit limbs, signed and unsigned, through the stimulus encoding
    ($fread: big-endian bytes) and the output decoding ($fwrite %u: little-endian limbs)."""
    fields = {"a": (0, 7, True), "b": (7, 30, False), "c": (37, 63, False), "d": (100, 4, True)}
    width = 104
    rng = np.random.default_rng(5)
    arrays = {"a": rng.integers(-64, 64, 100), "b": rng.integers(0, 1 << 30, 100),
              "c": rng.integers(0, 1 << 62, 100), "d": rng.integers(-8, 8, 100)}
    data = encode_words(fields, width, arrays)
    assert len(data) == 100 * 13
    words = [int.from_bytes(data[13 * i:13 * i + 13], "big") for i in range(100)]
    limbs = b"".join(w.to_bytes(16, "little") for w in words)       # the %u layout
    back = decode_words(fields, width, limbs)
    for k in fields:
        assert np.array_equal(back[k], arrays[k]), k


# --- make regress: >= 10^7 vectors per unit on Verilator --------------------------------------

REGRESS_VECTORS = 10_000_000
PER_PATTERN = REGRESS_VECTORS // len(TRAFFIC)          # x 4 patterns = 10^7 through the unit


# BUMPRTL_BULK_SHARDS=N splits each run into N jobs of gen/tools/jobs.py (sim/tb/bulk_shards.py),
# on a local cluster or on $BUMPRTL_SCHEDULER's workers (docs/scale.md); 1 (the default):
# one run here, as before.
SHARDS = int(os.environ.get("BUMPRTL_BULK_SHARDS", "1"))


def _regress(unit_v, unit_j, source, build_dir):
    if SHARDS > 1 or os.environ.get("BUMPRTL_SCHEDULER"):
        r = run_bulk_shards("verilator", unit_v, unit_j, tuple(TRAFFIC), source, SHARDS)
        assert r["checked"]
        assert sum(r["pixels"].values()) >= REGRESS_VECTORS
        return r
    r = run_bulk("verilator", unit_v, unit_j, build_dir / "bulk", patterns=tuple(TRAFFIC),
                 source=source, keep=False)
    assert r.checked
    assert sum(r.pixels.values()) >= REGRESS_VECTORS
    return r


@pytest.mark.regress
@pytest.mark.parametrize("unit", ["rotation", "illumination"])
@pytest.mark.parametrize("method", PER_PIXEL)
def test_bulk_regress_datapath_1e7_verilator(unit, method, build_dir):
    """The edge cases, then random pixels, bit-exact against the unit's golden model."""
    v, j = emit_unit(unit, Config(method=method), build_dir / "rtl")
    _regress(v, j, {"kind": "datapath", "n": PER_PATTERN, "seed": 1}, build_dir)


@pytest.mark.regress
def test_bulk_regress_palette_1e7_verilator(build_dir):
    """sN = 200 (out-of-range indices occur) with the eq. 2 blend."""
    v, j = emit_unit("palette", Config(palette_size=200, palette_blend=True, tag_bits=8),
                     build_dir / "rtl")
    _regress(v, j, {"kind": "palette", "n": PER_PATTERN, "seed": 1}, build_dir)


@pytest.mark.regress
def test_bulk_regress_sincos_1e7_verilator(build_dir):
    v, j = emit_unit("sincos", Config(), build_dir / "rtl")
    _regress(v, j, {"kind": "sincos", "n": PER_PATTERN, "seed": 1}, build_dir)


@pytest.mark.regress
def test_bulk_regress_pipeline_1e7_verilator(build_dir):
    """The default pipeline with a stress-case bump map: chunks of stress vectors (every
    case of sim/golden/stress.py through the fetch unit) and of random payloads over the
    whole port ranges, under all four traffic patterns."""
    scene = load_scene_config("default")
    v, j = emit_pipeline(scene, pipeline_map(scene, 0), None, build_dir, None)
    _regress(v, j, {"kind": "pipeline", "n": PER_PATTERN, "seed": 1, "map_seed": 0}, build_dir)
