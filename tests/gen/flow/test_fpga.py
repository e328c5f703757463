"""The ECP5 flow: one small unit in make test, every design behind `make fpga`."""

import numpy as np
import pytest
from amaranth.sim import Simulator

from bumprtl.gen.cli.main import main
from bumprtl.gen.flow import fpga
from bumprtl.gen.flow.resources import count_unit
from bumprtl.rtl.config import Config
from bumprtl.rtl.pipe import ECP5
from bumprtl.sim.amaranth_stream import assert_bit_exact, simulate_stream
from bumprtl.sim.golden.methods import PER_PIXEL, datapath_fixed
from bumprtl.sim.golden.vectors import TINY, as_payloads, random_codes


# a real placement (nextpnr, ~10 s of CPU): make fpga runs it beside the other placements
@pytest.mark.fpga
def test_sincos_places_on_the_smallest_device(build_dir):
    # 12-bit angles: the 1025-word table is one block RAM (at 13 bits Yosys splits the
    # generic table over three blocks and adds registers of its own to select between them)
    cfg = Config(angle_bits=12, frac_bits=13)
    row = fpga.fpga_unit("sincos", cfg, "LFE5U-25F", build_dir)
    coarse = count_unit("sincos", cfg, build_dir / "coarse")
    # every register bit becomes one FF: the datapath's and the credit edge's
    assert row["FF"] == coarse.register_bits + coarse.edge_register_bits
    assert row["DSP"] == 0                            # no multiplier in sincos
    assert row["BRAM"] >= 1                           # the quarter-wave ROM stays a block RAM
    assert row["LUT4"] > 0 and row["fmax_mhz"] > 0
    assert row["target_mhz"] == fpga.lpf_mhz() == 200


def test_unknown_device_names_the_choices(build_dir):
    with pytest.raises(fpga.FpgaError, match="device must be one of LFE5U-25F, LFE5U-45F, LFE5U-85F"):
        fpga.fpga_unit("sincos", Config(), "LFE5U-12F", build_dir)


def test_nextpnr_error_is_shown(build_dir):
    # a 64k x 18 RAM needs 64 DP16KD; the LFE5U-25F has 56: nextpnr cannot place it
    big = build_dir / "big.v"
    big.write_text("module big(input clk, input [15:0] a, output reg [17:0] d);\n"
                   "  reg [17:0] mem [0:65535];\n"
                   "  always @(posedge clk) begin mem[a] <= {a, 2'b01}; d <= mem[a ^ 16'h5555]; end\n"
                   "endmodule\n")
    with pytest.raises(fpga.FpgaError, match="nextpnr-ecp5 failed.*ERROR.*DP16KD"):
        fpga.place_and_route(big, "big", "LFE5U-25F", build_dir)


@pytest.mark.fpga
def test_report_fpga_every_design(build_dir):
    """Through the shared digest cache (build/fpga_cache, as `bumprtl report fpga`): placed
    once cold, then a rerun of make fpga only looks the rows up."""
    out = build_dir / "report.md"
    assert main(["report", "fpga", "--device", "LFE5U-85F", "--samples", "2000",
                 "--out", str(out)]) == 0
    text = out.read_text()
    for design in PER_PIXEL:
        for row in ("setup", "illumination", "pipeline"):
            assert f"| {design}_{row} |" in text
    assert "| kim_pipeline |" in text
    for design in fpga.NOT_PLACED:                  # said why, never a silent gap
        assert f"| {design}_pipeline |" not in text and design in text.split("## Notes")[1]


def test_placements_are_cached_by_verilog(tmp_path, monkeypatch):
    """report fpga and bench sweep share placements: the same Verilog is placed once, a
    different one (another config) again."""
    import json

    from bumprtl.gen.flow.units import build_unit
    from bumprtl.rtl.config import Config
    calls = []

    def fake(v_path, top, device, work, lpf=fpga.LPF, seed=1):
        calls.append(v_path.read_text())
        (work / f"{top}.pnr.json").write_text(json.dumps({"utilization": {}}))
        return {"unit": top, "fmax_mhz": 1.0}

    monkeypatch.setattr(fpga, "place_and_route", fake)
    unit = lambda b: build_unit("sincos", Config(angle_bits=6, frac_bits=b), ECP5())[0]
    first = fpga.place_component(unit(5), "sincos", "LFE5U-25F", tmp_path)
    assert fpga.place_component(unit(5), "sincos", "LFE5U-25F", tmp_path) == first
    assert len(calls) == 1
    fpga.place_component(unit(6), "sincos", "LFE5U-25F", tmp_path)
    assert len(calls) == 2 and calls[0] != calls[1]
    renamed = fpga.place_component(unit(5), "other_name", "LFE5U-25F", tmp_path)
    assert len(calls) == 2 and renamed["unit"] == "other_name"    # same hardware, placed once


def test_critical_path_names_the_endpoints_and_splits_the_delay():
    """nextpnr's report JSON -> 'start -> end (logic + routing)', mapped-cell suffixes cut."""
    step = lambda cell, port, kind, delay: {"from": {"cell": cell, "port": port},
                                            "to": {"cell": cell, "port": port},
                                            "type": kind, "delay": delay}
    report = {"critical_paths": [{"from": "posedge clk", "to": "posedge clk", "path": [
        step("rotation.n_c4_angle_TRELLIS_FF_Q_3", "Q", "clk-to-q", 0.5),
        step("rotation.x_LUT4_Z", "F", "routing", 1.25),
        step("rotation.x_LUT4_Z", "F", "logic", 0.25),
        step("rotation.sine_rom1.bram", "ADB13", "setup", 0.25)]}]}
    assert fpga.critical_path(report) == ("rotation.n_c4_angle.Q -> rotation.sine_rom1.bram.ADB13 "
                                          "(1.00 ns logic + 1.25 ns routing)")
    assert fpga.critical_path({}) is None


def _fake_place_and_route(calls):
    """A stand-in for the tools: exact_setup fails, the others get Fmax 100 + seed."""
    import json

    def fake(v_path, top, device, work, lpf=fpga.LPF, seed=1):
        calls.append(top)
        if top == "exact_setup":
            raise fpga.FpgaError("nextpnr-ecp5 failed (status 1): ERROR: no room")
        (work / f"{top}.pnr.json").write_text(json.dumps({"utilization": {}}))
        return {"unit": top, "LUT4": 1, "FF": 2, "DSP": 0, "BRAM": 0, "fmax_mhz": 100.0 + seed,
                "target_mhz": 150.0, "met": False, "seed": seed,
                "critical_path": f"a -> b seed {seed}"}
    return fake


def test_report_fpga_seeds_minimum_and_failed_placement(tmp_path, monkeypatch):
    """--seeds: each row's Fmax is the minimum over the seeds; a placement that fails is
    written on its row with the reason, the other rows still placed (the job layer's local
    cluster in threads of this process, so the patched tools are the ones it runs)."""
    from bumprtl.gen.report import fpga as report
    from bumprtl.gen.tools import jobs

    monkeypatch.setattr(jobs, "LOCAL_PROCESSES", False)
    monkeypatch.setattr(jobs, "LOG_DIR", tmp_path / "job_logs")
    monkeypatch.setattr(fpga, "place_and_route", _fake_place_and_route([]))
    monkeypatch.setattr(report, "accuracy", lambda d, cfg, n: {"max": 1, "mean": 0.1})
    # small stand-ins, a different one per row (the same hardware would be one job)
    from bumprtl.gen.flow.units import build_unit
    monkeypatch.setattr(report, "_component", lambda design, row, cfg: build_unit(
        "sincos", Config(angle_bits=6, frac_bits=5 if row == "setup" else 6), ECP5())[0])
    out = tmp_path / "report.md"
    assert main(["report", "fpga", "--seeds", "3,2", "--unit", "exact_setup", "--unit",
                 "exact_pipeline", "--out", str(out), "--work", str(tmp_path), "--jobs", "2"]) == 0
    text = out.read_text()
    assert "| exact_pipeline | 1 | 2 | 0 | 0 | 102.0 |" in text          # min over seeds 2, 3
    assert "| exact_setup | not placed: nextpnr-ecp5 failed (status 1): ERROR: no room |" in text
    assert "--seeds 3,2" in text and "a -> b seed 2" in text
    assert "result error: nextpnr-ecp5 failed" in (
        jobs.LOG_DIR / "place-LFE5U-85F-exact_setup-seed3.log").read_text()


@pytest.mark.parametrize("method", PER_PIXEL)
def test_placed_pipeline_runs_free_behind_one_credit_edge_bit_exact(method):
    """pipeline_component (the rotation -> illumination pipe report fpga places): bit-exact
    with the golden datapath under input gaps and backpressure with i.ready exactly a free
    credit (simulate_stream's credit rule), i.ready never a function of o.ready in the
    cycle, and with o.ready held low it takes exactly fifo_depth pixels (its credits)."""
    cfg = TINY.replace(method=method)
    codes = random_codes(300, cfg, np.random.default_rng(3))
    inputs = as_payloads(codes, cfg)
    dut = fpga.pipeline_component(cfg)
    out, _ = simulate_stream(dut, inputs, "both", seed=5, pipe_handshake=True)
    want = datapath_fixed(codes, cfg)
    assert_bit_exact(out, want, inputs)
    dut = fpga.pipeline_component(cfg)
    taken, seen = 0, []

    async def bench(ctx):
        nonlocal taken
        for _cycle in range(dut.latency + 10):
            ctx.set(dut.i.valid, 1)
            ctx.set(dut.o.ready, 0)
            ready0 = ctx.get(dut.i.ready)
            ctx.set(dut.o.ready, 1)                 # the same cycle: i.ready must not change
            ready1 = ctx.get(dut.i.ready)
            ctx.set(dut.o.ready, 0)
            seen.append((ready0, ready1, ctx.get(dut.o.valid)))
            taken += ready0
            await ctx.tick()
    sim = Simulator(dut)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    assert all(r0 == r1 for r0, r1, _ in seen)
    assert taken == dut.fifo_depth


def test_the_same_hardware_is_placed_once_per_run(tmp_path, monkeypatch):
    """Two rows with the same hardware under two labels (Peercy's and Ernst's pipelines) in
    one run are one placement job; each row gets its own label; a second run reads the cache
    and starts no job."""
    from bumprtl.gen.flow.units import build_unit
    from bumprtl.gen.report import fpga as report
    from bumprtl.gen.tools import jobs

    calls = []
    monkeypatch.setattr(jobs, "LOCAL_PROCESSES", False)
    monkeypatch.setattr(jobs, "LOG_DIR", tmp_path / "job_logs")
    monkeypatch.setattr(fpga, "place_and_route", _fake_place_and_route(calls))
    monkeypatch.setattr(report, "_component", lambda design, row, cfg: build_unit(
        "sincos", Config(angle_bits=6, frac_bits=5), ECP5())[0])
    args = report.FpgaRun(device="LFE5U-25F", work=tmp_path, jobs=2)
    tasks = [((label, "x", "pipeline"), 1) for label in ("peercy_like", "ernst_like")]
    rows = report.place_all(Config(), args, tasks)
    assert calls == ["peercy_like"]
    assert {r["unit"] for r in rows.values()} == {"peercy_like", "ernst_like"}
    assert report.place_all(Config(), args, tasks) == rows and len(calls) == 1


def test_a_run_stopped_early_keeps_the_placements_it_finished(tmp_path, monkeypatch):
    """Each placement is stored as it ends: when the run stops after the first of two jobs
    (here the Runner raises after reporting it), a second run reads that one from the cache
    and places only the other."""
    from bumprtl.gen.flow.units import build_unit
    from bumprtl.gen.report import fpga as report
    from bumprtl.gen.tools import jobs

    calls = []
    monkeypatch.setattr(jobs, "LOCAL_PROCESSES", False)
    monkeypatch.setattr(jobs, "LOG_DIR", tmp_path / "job_logs")
    monkeypatch.setattr(fpga, "place_and_route", _fake_place_and_route(calls))
    monkeypatch.setattr(report, "_component", lambda design, row, cfg: build_unit(
        "sincos", Config(angle_bits=6, frac_bits=5 + (design == "b")), ECP5())[0])
    args = report.FpgaRun(device="LFE5U-25F", work=tmp_path, jobs=1)
    tasks = [(("first", "a", "pipeline"), 1), (("second", "b", "pipeline"), 1)]
    real_run = jobs.Runner.run

    def stopped(self, job_iter, desc="jobs", on_done=None):
        first = [next(iter(job_iter))]
        real_run(self, first, desc, on_done)
        raise KeyboardInterrupt                         # the user stops the run here

    monkeypatch.setattr(jobs.Runner, "run", stopped)
    with pytest.raises(KeyboardInterrupt):
        report.place_all(Config(), args, tasks)
    assert calls == ["first"]
    monkeypatch.setattr(jobs.Runner, "run", real_run)
    rows = report.place_all(Config(), args, tasks)
    assert calls == ["first", "second"]                 # the first came from the cache
    assert {r["unit"] for r in rows.values()} == {"first", "second"}


def test_report_fpga_places_the_default_scene_with_its_map_behind_the_cache(tmp_path, monkeypatch):
    """The scene_default_axi row: the default scene's BumpPipeline with map_memory = "axi"
    (the AXI4 read port as top-level ports, no map write port), placed at the scene seeds
    like the other scene rows, with a note line saying what it places."""
    from bumprtl.gen.flow.units import build_unit
    from bumprtl.gen.report import fpga as report
    from bumprtl.gen.tools import jobs
    from bumprtl.rtl.cache import AxiMapFetch

    assert ("scene_default_axi", "exact", "scene_axi:default") in report.fpga_units(Config())
    pipeline = report._component(None, "scene_axi:default", Config())
    members = pipeline.signature.members
    assert "axi" in members and "map_w_en" not in members
    assert {"araddr", "arvalid", "arready", "rdata", "rlast", "rready"} <= set(members["axi"].signature.members)
    assert isinstance(pipeline.units["fetch"], AxiMapFetch)
    for unit in (pipeline, *pipeline.units.values()):
        unit._MustUse__silence = True

    monkeypatch.setattr(jobs, "LOCAL_PROCESSES", False)
    monkeypatch.setattr(jobs, "LOG_DIR", tmp_path / "job_logs")
    calls = []
    monkeypatch.setattr(fpga, "place_and_route", _fake_place_and_route(calls))
    monkeypatch.setattr(report, "accuracy", lambda d, cfg, n: {"max": 1, "mean": 0.1})
    monkeypatch.setattr(report, "_component", lambda design, row, cfg: build_unit(
        "sincos", Config(angle_bits=6, frac_bits=5 + (row == "scene_axi:default")), ECP5())[0])
    out = tmp_path / "report.md"
    assert main(["report", "fpga", "--unit", "scene_default_axi", "--scene-seeds", "2,3",
                 "--out", str(out), "--work", str(tmp_path)]) == 0
    text = out.read_text()
    assert "| scene_default_axi | 1 | 2 | 0 | 0 | 102.0 |" in text and "2: 102.0, 3: 103.0" in text
    notes = text.split("## Notes")[1].splitlines()
    note = [ln for ln in notes if ln.startswith("- scene_default_axi: ")]
    assert len(note) == 1 and 'map_memory = "axi"' in note[0] and "AXI4 read port" in note[0]


def test_a_placement_job_reports_the_devices_resources_and_its_logs(monkeypatch):
    """place_text with nextpnr stood in: the row gains what the device has of each resource
    the report counts (nextpnr's utilization names: TRELLIS_COMB, MULT18X18D, DP16KD; a
    resource nextpnr does not list is None), and the job returns the synthesis and
    placement logs and report by name, the two logs joined in order."""
    import json

    seen = {}

    def place_and_route(v_path, label, device, work, lpf, seed):
        seen.update(text=v_path.read_text(), lpf=lpf.read_text(), device=device, seed=seed)
        (work / f"{label}.synth.log").write_text("yosys said\n")
        (work / f"{label}.pnr.log").write_text("nextpnr said\n")
        (work / f"{label}.pnr.json").write_text(json.dumps({"utilization": {
            "TRELLIS_COMB": {"used": 10, "available": 83640},
            "MULT18X18D": {"used": 1, "available": 156}}}))
        return {"LUT4": 10, "fmax_mhz": 250.0}

    monkeypatch.setattr(fpga, "place_and_route", place_and_route)
    out = fpga.place_text("module u; endmodule\n", "u", "LFE5U-85F", "FREQUENCY 200 MHz;\n", seed=3)
    assert seen == {"text": "module u; endmodule\n", "lpf": "FREQUENCY 200 MHz;\n",
                    "device": "LFE5U-85F", "seed": 3}
    assert out["row"] == {"LUT4": 10, "fmax_mhz": 250.0,
                          "available": {"LUT4": 83640, "DSP": 156, "BRAM": None}}
    assert sorted(out["files"]) == ["u.pnr.json", "u.pnr.log", "u.synth.log"]
    assert out["log"] == "==== u.synth.log\nyosys said\n\n==== u.pnr.log\nnextpnr said\n"


@pytest.mark.parametrize("achieved, met", [(212.5, True), (175.0, True), (170.25, False), (None, False)])
def test_a_placement_row_holds_the_lpf_target_and_whether_it_was_met(achieved, met, tmp_path,
                                                                      monkeypatch):
    """place_and_route's row from nextpnr's report (the tools stood in: Yosys does nothing,
    nextpnr writes the report): the utilisation columns, Fmax rounded to 0.1 MHz, the target
    read from the LPF's FREQUENCY line (a 175 MHz one here) and met = Fmax >= target."""
    import json

    lpf = tmp_path / "c.lpf"
    lpf.write_text('FREQUENCY PORT "clk" 175 MHZ;\n')
    report = {"utilization": {"TRELLIS_COMB": {"used": 120}, "TRELLIS_FF": {"used": 80},
                              "MULT18X18D": {"used": 2}, "DP16KD": {"used": 1}},
              "fmax": {"clk": {"achieved": achieved}} if achieved is not None else {},
              "critical_paths": []}

    def nextpnr(argv, cwd):
        (cwd / argv[argv.index("--report") + 1]).write_text(json.dumps(report))
    monkeypatch.setattr(fpga, "run_yosys", lambda *a, **k: None)
    monkeypatch.setattr(fpga, "yosys_input", lambda v, work, top: v)
    monkeypatch.setattr(fpga, "require", lambda tool: tool)
    monkeypatch.setattr(fpga, "_nextpnr", nextpnr)
    v = tmp_path / "u.v"
    v.write_text("module u; endmodule\n")
    row = fpga.place_and_route(v, "u", "LFE5U-25F", tmp_path / "w", lpf=lpf, seed=3)
    assert row == {"unit": "u", "device": "LFE5U-25F", "LUT4": 120, "FF": 80, "DSP": 2, "BRAM": 1,
                   "fmax_mhz": None if achieved is None else round(achieved, 1),
                   "target_mhz": 175.0, "met": met, "seed": 3, "critical_path": None}
