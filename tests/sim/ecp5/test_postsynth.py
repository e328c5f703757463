"""Post-synthesis simulation: Yosys ``synth_ecp5`` netlists (LUT4, TRELLIS_FF, CCU2C, DP16KD,
MULT18X18D, ...) run under Icarus with Yosys' cells_sim.v and the sim/ecp5 models.

make test: Yosys' own block-RAM mapping of a ROM in the x4 mode (x9 and x2: make fpga)
agrees with the DP16KD model's word layout (rtl/ecp5.dp16kd_initvals packs the same way), and
rtl/pipe.RegisteredRAM's ECP5 form equals its generic form under random writes and reads;
the default scene's BumpPipeline after synth_ecp5 renders one 16 x 16 frame bit-exact.
make fpga: the ECP5 form of the exact rotation -> illumination pipeline and of the default
scene's BumpPipeline, synthesized, bit-exact against the golden model on 10^4 pixels under
random backpressure and input gaps (cocotb on Icarus, sim/tb/tb_pipeline.py; the traffic
patterns "both" and "backpressure" of sim/traffic.py)."""

import json
import time

import numpy as np
import pytest
from amaranth.back import verilog
from amaranth.hdl import unsigned

from bumprtl.gen.flow.emit import port_table
from bumprtl.gen.flow.fpga import pipeline_component
from bumprtl.gen.render.rtl import scene_stimulus, write_stimulus
from bumprtl.rtl.config import Config
from bumprtl.rtl.pipe import ECP5, RAM_LATENCY, RegisteredRAM
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sidecar import from_facts, ports_from_table
from bumprtl.sim.ecp5 import (
    ecp5_lockstep,
    enabled_delay,
    postsynth_sources,
    run_vectors,
    synth_netlist,
)
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.golden.methods import illumination_fixed, rotation_fixed
from bumprtl.sim.golden.vectors import random_codes
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.runner import run_cocotb


def _ram_vectors(depth, width, n, seed, writes=True):
    rng = np.random.default_rng(seed)
    en = (rng.random(n) < 0.7).astype(int)
    r_addr = rng.integers(0, depth, n)
    r_addr[: min(n, depth)] = np.arange(min(n, depth))          # every word once, then random
    w_en = (rng.random(n) < (0.2 if writes else 0)).astype(int)
    w_addr = rng.integers(0, depth, n)
    w_data = rng.integers(0, 1 << width, n)
    return en, r_addr, w_en, w_addr, w_data


def _ram_reference(init, en, r_addr, w_en, w_addr, w_data):
    """Each clock: the read (old word on a same-word write) then the write; r_data after
    RAM_LATENCY enabled clocks."""
    mem, reads = list(init), []
    for k in range(len(en)):
        reads.append(mem[r_addr[k]])
        if w_en[k]:
            mem[w_addr[k]] = int(w_data[k])
    return enabled_delay(reads, en, RAM_LATENCY - 1)


@pytest.mark.parametrize("depth, width", [(4096, 24), (5120, 24), (4096, 8), (1024, 18), (300, 5)])
def test_registered_ram_ecp5_form(depth, width, build_dir):
    """DP16KD blocks (x4 / x2 / x4 / x18 / x18 modes) equal the generic Memory and a list
    model under random reads, host writes and a random enable."""
    rng = np.random.default_rng(depth + width)
    init = rng.integers(0, 1 << width, depth).tolist()
    n = depth + 1500
    en, r_addr, w_en, w_addr, w_data = _ram_vectors(depth, width, n, seed=width)
    make = lambda t: RegisteredRAM(depth, unsigned(width), "ram", init, target=t)
    assert ECP5().ram_mode(make(ECP5())) is not None
    abits = (depth - 1).bit_length()
    ports = lambda u: [u.en, u.r_addr, u.r_data, u.w_en, u.w_addr, u.w_data]
    generic, ecp5 = ecp5_lockstep(make, {"ram_en": (1, en), "ram_r_addr": (abits, r_addr),
                                         "ram_w_en": (1, w_en), "ram_w_addr": (abits, w_addr),
                                         "ram_w_data": (width, w_data)},
                                  {"ram_r_data": width}, build_dir, ports=ports)
    want = _ram_reference(init, en, r_addr, w_en, w_addr, w_data)
    filled = [k for k in range(n) if want[k] is not None]
    assert [ecp5["ram_r_data"][k] for k in filled] == [want[k] for k in filled]
    assert [generic["ram_r_data"][k] for k in filled] == [want[k] for k in filled]


@pytest.mark.parametrize("depth, width", [pytest.param(4096, 4, marks=pytest.mark.fpga),
                                          pytest.param(2048, 9, marks=pytest.mark.fpga),
                                          pytest.param(8192, 2, marks=pytest.mark.fpga)])
def test_yosys_bram_mapping_agrees_with_the_model(depth, width, build_dir):
    """A plain Verilog ROM that Yosys maps to one DP16KD in the x4 / x9 / x2 mode reads every
    word back through the DP16KD model: the model's INITVAL layout is Yosys' own."""
    rng = np.random.default_rng(depth)
    init = rng.integers(0, 1 << width, depth).tolist()
    abits = (depth - 1).bit_length()
    text = (f"module rom(input clk, input rst, input [{abits - 1}:0] a, output reg [{width - 1}:0] d);\n"
            f"  reg [{width - 1}:0] mem [0:{depth - 1}];\n  initial begin\n"
            + "".join(f"    mem[{k}] = {width}'d{x};\n" for k, x in enumerate(init))
            + "  end\n  always @(posedge clk) d <= mem[a];\nendmodule\n")
    netlist = synth_netlist(text, "rom", build_dir / "synth")
    assert "DP16KD" in netlist.read_text()
    sources, includes = postsynth_sources(build_dir / "sim")
    out = run_vectors([netlist, *sources], "rom", {"a": (abits, np.arange(depth))}, {"d": width},
                      build_dir / "sim", includes=includes)["d"]
    assert out == init


def _postsynth_stream(component, label, inputs, build_dir, patterns, polygon=None):
    """Synthesize ``component`` (ECP5 form), stream ``inputs`` (flattened payload arrays)
    through its netlist under cocotb/Icarus (sim/ecp5.postsynth_sources says why not
    Verilator); {pattern: {field: array}}. The synthesis, build and run wall times are
    printed (pytest -s) and written to ``build_dir/timing.json``."""
    t0 = time.perf_counter()
    text = verilog.convert(component, name=label, emit_src=False)
    netlist = synth_netlist(text, label, build_dir / "synth")
    synth_s = time.perf_counter() - t0
    sidecar = build_dir / f"{label}.json"
    from_facts(label, f"post-synthesis {label}", port_table(component),
               {"config": {}, "latency": component.port_latency, "fifo_depth": component.fifo_depth,
                "throughput": 1}).dump(sidecar)
    stim, result = build_dir / "stimulus.npz", build_dir / "result.npz"
    write_stimulus(stim, inputs, polygon, None)
    sources, includes = postsynth_sources(build_dir / "cells")
    run = run_cocotb("icarus", netlist, "bumprtl.sim.tb.tb_pipeline", build_dir / "icarus",
                     {"BUMPRTL_SIDECAR": sidecar, "BUMPRTL_STIMULUS": stim, "BUMPRTL_RESULT": result,
                      "BUMPRTL_PATTERNS": ",".join(patterns), "BUMPRTL_PROGRESS": 0},
                     sources=sources, includes=includes)
    pixels = len(next(iter(inputs.values()))) * len(patterns)
    timing = {"synth_s": round(synth_s, 1), "build_s": round(run.build_s, 1),
              "sim_s": round(run.run_s, 1), "pixels": pixels, "patterns": list(patterns)}
    (build_dir / "timing.json").write_text(json.dumps(timing))
    print(f"\npost-synthesis {label}: {timing}")
    res = dict(np.load(result))
    return {p: {k[len(p) + 1:]: v for k, v in res.items() if k.startswith(p + ".")
                and not k.endswith(".cycles")} for p in patterns}


PATTERNS = ["both", "backpressure"]


@pytest.mark.fpga
def test_postsynth_exact_pipeline_bit_exact(build_dir):
    """exact rotation -> illumination (the exact_pipeline row of report fpga) after
    synth_ecp5: 10^4 random pixels per traffic pattern, every field bit-exact."""
    cfg = Config(method="exact")
    n = 10_000
    codes = random_codes(n, cfg, seed=5)
    inputs = {**{k: np.asarray(v) for k, v in codes.items()},
              "tag": np.arange(n) & ((1 << cfg.tag_bits) - 1)}
    comp = pipeline_component(cfg, ECP5())
    fields = list(ports_from_table(port_table(comp))["i__payload"].fields)
    inputs = {k: inputs[k] for k in fields}
    outs = _postsynth_stream(comp, "exact_pipeline", inputs, build_dir, PATTERNS)
    golden = illumination_fixed(rotation_fixed({k: v for k, v in inputs.items() if k != "tag"}, cfg), cfg)
    for pattern in PATTERNS:
        out = outs[pattern]
        assert out["tag"].tolist() == inputs["tag"].tolist(), pattern
        compared = [f for f in out if f in golden]
        assert "diffuse" in compared
        for field in compared:
            assert np.array_equal(out[field], golden[field]), (pattern, field)


@pytest.mark.parametrize("size, n, patterns", [
    pytest.param(16, 256, ["both"], marks=pytest.mark.fpga),   # a quick case: one 16 x 16 frame
    pytest.param(128, 10_000, PATTERNS, marks=pytest.mark.fpga)])
def test_postsynth_scene_pipeline_bit_exact(size, n, patterns, build_dir):
    """The default scene's BumpPipeline (fetch -> rotation -> illumination, bump map in
    DP16KD blocks, products in MULT18X18D) after synth_ecp5: the first ``n`` pixels of a
    ``size`` x ``size`` render per traffic pattern bit-exact against
    sim/golden/fixed/pipeline.py."""
    scene = load_scene_config("default")
    inputs, words, polygon, table, base = scene_stimulus(scene, size)
    inputs = {k: v[:n] for k, v in inputs.items()}
    comp = BumpPipeline(scene.hardware, init=words, target=ECP5())
    outs = _postsynth_stream(comp, "scene_default", inputs, build_dir, patterns, polygon)
    golden = pipeline_fixed(inputs, scene, words, polygon, None)
    assert len(inputs["tag"]) == n
    for pattern in patterns:
        out = outs[pattern]
        assert out["tag"].tolist() == inputs["tag"].tolist(), pattern
        for field, want in golden.items():
            assert np.array_equal(out[field], want), (pattern, field)
