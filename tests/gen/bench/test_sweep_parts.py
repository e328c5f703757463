"""bench sweep's parts that need no synthesis tool (gen/bench/sweep.py): what "cheaper"
means, where a point gets its hardware row (cached, pending as one job per distinct
Verilog, not placed, failed), the cocotb rate only at the default widths, the command line
that reproduces a sweep, the files sweep_bench writes, and how older sweeps without map
records are read. The models and placements are stood in where they are the slow part."""

import json
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import pytest

from bumprtl.gen.bench import sweep as bench_sweep
from bumprtl.gen.bench.sweep import METHOD_CHOICES, SweepOptions, command_line, cost_key
from bumprtl.gen.cli.main import main
from bumprtl.gen.flow.fpga import NOT_PLACED, FpgaError
from bumprtl.rtl.config import Config
from tests.tools.fake_jobs import fake_runner, outcome

DEFAULT = (Config().angle_bits, Config().frac_bits)


def test_cost_key_ranks_dsp_then_bram_then_luts_on_a_device():
    few_dsp = {"cost": {"fpga": {"DSP": 1, "BRAM": 9, "LUT4": 9000}}}
    many_dsp = {"cost": {"fpga": {"DSP": 2, "BRAM": 0, "LUT4": 10}}}
    assert cost_key(few_dsp, "LFE5U-85F") == (1, 9, 9000)
    assert cost_key(few_dsp, "LFE5U-85F") < cost_key(many_dsp, "LFE5U-85F")


def test_cost_key_counts_dividers_and_square_roots_as_arithmetic_units():
    table_heavy = {"cost": {"multipliers": 1, "table_bits": 90_000, "ram_bits": 10, "adders": 3}}
    divider = {"cost": {"multipliers": 1, "dividers": 1, "sqrts": 1, "table_bits": 0,
                        "ram_bits": 0, "adders": 0}}
    assert cost_key(table_heavy) == (1, 90_010, 3)
    assert cost_key(divider) == (3, 0, 0)
    assert cost_key(table_heavy) < cost_key(divider)


class FakePlacement:
    """Placement's interface: ``key`` (the Verilog digest), ``cached`` row or None,
    ``args`` for the job, ``store`` of a job's value."""
    rows = {}

    def __init__(self, component, label, device):
        self.label, self.device = label, device
        self.key = component["key"]
        if component.get("raise"):
            raise FpgaError(component["raise"])
        self.cached = FakePlacement.rows.get(self.key)

    def args(self):
        return (self.key, self.label)

    def store(self, value):
        return {**value["row"], "unit": self.label, "stored": True}


def _placed(job):
    key, _label = job.args
    if key == "bad":
        return outcome(error="x" * 400)
    return outcome({"row": {"fmax_mhz": 50.0, "LUT4": 7}})


FakeRunner = fake_runner(_placed)


def test_points_get_their_rows_from_the_cache_one_job_per_verilog_or_their_error(monkeypatch):
    monkeypatch.setattr(bench_sweep, "Placement", FakePlacement)
    monkeypatch.setattr(bench_sweep, "Runner", FakeRunner)
    FakeRunner.jobs = []
    FakePlacement.rows = {"old": {"fmax_mhz": 80.0, "unit": "x"}}
    opts = SimpleNamespace(fpga=True, device="LFE5U-85F", scheduler=None, jobs=1)
    ctx = SimpleNamespace(pending=[])
    hardware = {"cached": {"key": "old"}, "a": {"key": "new"}, "b": {"key": "new"},
                "bad": {"key": "bad"}, "nofit": {"key": "z", "raise": "does not fit\nmore"}}
    points = {}
    for name, comp in hardware.items():
        points[name] = {"method": name, "cost": {}, "speed": {}}
        bench_sweep._hardware(points[name], Config(), lambda cfg, target, c=comp: c, "unit",
                              ctx, opts)
    # a method the registry marks not placeable (none is today): its reason, no placement
    monkeypatch.setattr(bench_sweep, "NOT_PLACED", {**NOT_PLACED, "toy": "toy: no ECP5 form"})
    points["np"] = {"method": "toy", "cost": {}, "speed": {}}
    bench_sweep._hardware(points["np"], Config(), None, "unit", ctx, opts)
    assert points["np"]["cost"]["fpga_error"] == "toy: no ECP5 form"
    assert points["nofit"]["cost"]["fpga_error"] == "does not fit"          # its first line
    assert points["cached"]["cost"]["fpga"]["fmax_mhz"] == 80.0
    assert points["cached"]["speed"]["hw_pix_s"] == 80e6                  # 1 pixel a clock
    assert [p["method"] for p, _ in ctx.pending] == ["a", "b", "bad"]
    bench_sweep.place_pending(ctx, opts, progress=False)
    assert len(FakeRunner.jobs) == 2                                     # new, bad: once each
    assert points["a"]["cost"]["fpga"] == {"fmax_mhz": 50.0, "LUT4": 7, "unit": "a_unit",
                                           "stored": True}
    assert points["b"]["cost"]["fpga"] == {"fmax_mhz": 50.0, "LUT4": 7, "unit": "b_unit"}
    assert points["a"]["speed"]["hw_pix_s"] == points["b"]["speed"]["hw_pix_s"] == 50e6
    assert points["bad"]["cost"]["fpga_error"] == "x" * 300 and "fpga" not in points["bad"]["cost"]
    FakeRunner.jobs = []
    bench_sweep.place_pending(SimpleNamespace(pending=[]), opts, progress=False)
    assert FakeRunner.jobs == []


def test_a_row_without_fmax_gives_no_hardware_speed():
    point = {"cost": {}, "speed": {}}
    bench_sweep._fill(point, {"LUT4": 3, "fmax_mhz": None})
    assert point["cost"]["fpga"]["LUT4"] == 3 and "hw_pix_s" not in point["speed"]


def test_sim_rate_is_the_slower_unit_rounded(monkeypatch, tmp_path):
    seen = []

    def rate(cfg, sim, unit, samples, work):
        seen.append((sim, unit, work))
        return {"rotation": 1234.6, "illumination": 999.4}[unit], 1.0

    monkeypatch.setattr(bench_sweep, "unit_sim_rate", rate)
    cfg = Config(angle_bits=12, frac_bits=13)
    assert bench_sweep.sim_rate(cfg, tmp_path) == 999
    assert [s[:2] for s in seen] == [("verilator", "rotation"), ("verilator", "illumination")]
    assert all(w == tmp_path / "sim" / "exact_a12_b13_p256_s1" for *_, w in seen)


@pytest.mark.parametrize("widths, sim, fpga, sim_rate, placed", [
    (DEFAULT, True, False, True, True),         # asked; _hardware itself reads --fpga
    ((12, 13), True, True, False, False),       # --fpga-points default: default widths only
    (DEFAULT, False, True, False, True),
])
def test_perpixel_point_measures_sim_and_hardware_where_asked(widths, sim, fpga, sim_rate,
                                                             placed, monkeypatch):
    monkeypatch.setattr(bench_sweep, "perpixel_error", lambda ctx, cfg: {})
    monkeypatch.setattr(bench_sweep, "perpixel_speed", lambda ctx, cfg: {"golden_mpix_s": 1.0})
    monkeypatch.setattr(bench_sweep, "unit_cost", lambda units, cfg, work: {"multipliers": 1})
    monkeypatch.setattr(bench_sweep, "sim_rate", lambda cfg, work: 4242)
    hw = []
    monkeypatch.setattr(bench_sweep, "_hardware",
                        lambda point, cfg, fn, label, ctx, opts: hw.append((fn, label)))
    grid = bench_sweep.GRIDS["default"]
    ctx = SimpleNamespace(grid=grid, work=Path("w"))
    opts = SimpleNamespace(sim=sim, fpga=fpga, fpga_points="default")
    p = bench_sweep.perpixel_point(ctx, "exact", *widths, opts)
    assert p["status"] == "ok" and p["cost"]["map_bits_per_texel"] == 2 * widths[0]
    assert (p["speed"].get("sim_pix_s") == 4242) == sim_rate
    assert hw == ([(bench_sweep._pipeline, "pipeline")] if placed else [])


def test_command_line_names_every_flag_that_shapes_the_sweep():
    assert command_line(SweepOptions()) == "bumprtl bench sweep"
    opts = SweepOptions(quick=True, methods=("lee", "palette"), maps=("moon:64",), fpga=True,
                        device="LFE5U-25F", fpga_points="diagonal", sim=True)
    assert command_line(opts) == ("bumprtl bench sweep --quick --methods lee palette --maps "
                                  "moon:64 --fpga --device LFE5U-25F --fpga-points diagonal --sim")
    assert command_line(SweepOptions(methods=tuple(reversed(METHOD_CHOICES)))) == \
        "bumprtl bench sweep"


def _data(grid):
    point = {"method": "exact", "angle_bits": 10, "frac_bits": 11, "status": "ok",
             "error": {"random": {"max": 3}, "scenes": {}},
             "speed": {"golden_mpix_s": 2.0},
             "cost": {"multipliers": 6, "adders": 20, "table_bits": 100, "ram_bits": 0,
                      "map_bits_per_texel": 20, "fpga_error": "nextpnr: no room"}}
    return {"grid": grid.__dict__, "maps": [], "seed": 11, "float64_conventional_mpix_s": 1.5,
            "points": [point]}


def test_sweep_bench_writes_the_json_the_section_the_plot_and_the_copy(tmp_path, monkeypatch,
                                                                       capsys):
    grids = []

    def fake_sweep(grid, opts, work, progress=True):
        grids.append(grid)
        return _data(grid)

    monkeypatch.setattr(bench_sweep, "sweep", fake_sweep)
    docs = tmp_path / "docs" / "bench.md"
    opts = SweepOptions(quick=True, maps=("moon:32",), out=tmp_path / "o" / "s.json",
                        work=tmp_path / "w", docs=docs, data_copy=tmp_path / "d" / "s.json",
                        no_progress=True)
    assert bench_sweep.sweep_bench(opts) == 0
    assert grids == [replace(bench_sweep.GRIDS["quick"], maps=(("moon", 32),))]
    data = json.loads(opts.out.read_text())
    assert data["command"] == "bumprtl bench sweep --quick --maps moon:32"
    assert json.loads(opts.data_copy.read_text()) == data
    assert (docs.parent / "img" / "bench_pareto.png").read_bytes()[:4] == b"\x89PNG"
    page = docs.read_text()
    assert "## Error, cost and speed sweep" in page and "`bumprtl bench sweep --quick" in page
    assert "FPGA flow failed" in page and "- exact a10 b11: nextpnr: no room" in page
    assert "![error against cost and run time](img/bench_pareto.png)" in page
    out = capsys.readouterr().out
    assert f"wrote {opts.out}" in out and f"wrote {docs}" in out


def test_sweep_bench_without_docs_prints_the_table(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(bench_sweep, "sweep", lambda grid, opts, work, progress=True: _data(grid))
    opts = SweepOptions(out=tmp_path / "s.json", no_progress=True)
    bench_sweep.sweep_bench(opts)
    out = capsys.readouterr().out
    assert "| exact a10 b11 |" in out and not (tmp_path / "img").exists()


def test_an_unknown_device_is_refused_before_the_sweep(tmp_path, capsys):
    out = tmp_path / "s.json"
    assert main(["bench", "sweep", "--quick", "--fpga", "--device", "XC7", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "device must be one of" in err[0] and "'XC7'" in err[0]
    assert not out.exists()


def test_an_older_sweep_without_map_records_is_read_from_its_grid():
    old = {"grid": {"size": 64, "scenes": ["moon", "wood"]}}
    maps = bench_sweep.maps_of(old)
    assert [(m["name"], m["size"], m["texels"], m["distinct_normals"]) for m in maps] == \
        [("moon", 64, 4096, None), ("wood", 64, 4096, None)]
    assert bench_sweep.describe_map(maps[0]) == \
        "moon (64\N{SUPERSCRIPT TWO}, distinct normals not recorded)"
    assert bench_sweep.describe_map({"name": "x", "size": None}) == \
        "x (size not recorded, distinct normals not recorded)"
    # no per-map record: a palette at least as large as the map's texels quantized nothing
    point = {"method": "palette", "palette_size": 4096,
             "error": {"scenes": {"moon": {"max_lsb": 1}, "wood": {"max_lsb": 2},
                                  "gone": {"reason": "skipped"}}}}
    assert bench_sweep.unquantized_maps(point, old) == ["moon", "wood"]
    assert bench_sweep.unquantized_maps({**point, "palette_size": 4095}, old) == []
    assert bench_sweep.unquantized_maps({"method": "exact"}, old) == []
    recorded = {"maps": [{"key": "moon", "name": "moon", "size": 64, "distinct_normals": 100,
                          "texels": 4096}]}
    assert bench_sweep.unquantized_maps({**point, "palette_size": 100}, recorded) == ["moon"]
    assert bench_sweep.unquantized_maps({**point, "palette_size": 99}, recorded) == []


def test_sweep_bench_with_docs_and_no_data_copy_writes_the_page_only(tmp_path, monkeypatch,
                                                                      capsys):
    """--docs without --data-copy (the command line's default): the JSON and the page, no
    copy of the JSON anywhere else."""
    monkeypatch.setattr(bench_sweep, "sweep", lambda grid, opts, work, progress=True: _data(grid))
    docs = tmp_path / "docs" / "bench.md"
    opts = SweepOptions(quick=True, maps=("moon:32",), out=tmp_path / "o" / "s.json",
                        work=tmp_path / "w", docs=docs, no_progress=True)
    assert opts.data_copy is None
    assert bench_sweep.sweep_bench(opts) == 0
    assert "## Error, cost and speed sweep" in docs.read_text()
    jsons = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*.json"))
    assert [str(p) for p in jsons] == [str(opts.out.relative_to(tmp_path))]
    assert f"wrote {docs}" in capsys.readouterr().out
