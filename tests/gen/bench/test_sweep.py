"""bench sweep: Pareto front on toy sets, and one tiny sweep through the real models
(errors re-derived from the models, invalid widths recorded, missing baselines reported)."""

import json
from types import SimpleNamespace

import numpy as np
import pytest

from bumprtl.gen.bench import skip as bench_skip
from bumprtl.gen.bench import sweep as bench_sweep
from bumprtl.gen.bench.sweep import (
    Grid,
    error_lsb,
    map_key,
    pareto_front,
    parse_maps,
    sweep,
)
from bumprtl.gen.cli.main import main
from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.accuracy import diffuse_error_lsb, term_errors_lsb
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.methods import BASELINES, datapath_fixed
from bumprtl.sim.scenes.config import load_scene_config

DEFAULT_WIDTHS = (Config().angle_bits, Config().frac_bits)


def _front(pairs):
    pts = [{"x": x, "y": y} for x, y in pairs]
    return sorted(pareto_front(pts, lambda p: p["x"], lambda p: p["y"]))


def test_pareto_toy():
    #            0       1       2       3 (dominated by 1)  4 (None: skipped)
    assert _front([(1, 10), (2, 3), (5, 1), (3, 4)]) == [0, 1, 2]
    assert _front([(1, 1), (2, 2), (3, 3)]) == [0]


def test_pareto_duplicates_and_none():
    pts = [{"x": 1, "y": 1}, {"x": 1, "y": 1}, {"x": None, "y": 0}, {"x": 0, "y": 5}]
    assert sorted(pareto_front(pts, lambda p: p["x"], lambda p: p["y"])) == [0, 3]


def test_pareto_random_against_brute_force():
    rng = np.random.default_rng(3)
    pairs = [tuple(v) for v in rng.integers(0, 20, (60, 2))]
    front = _front(pairs)
    for i, (x, y) in enumerate(pairs):
        better = any(x2 <= x and y2 <= y and (x2, y2) != (x, y) for x2, y2 in pairs)
        assert (i in front) == (not better and pairs.index((x, y)) == i)


def test_error_lsb_is_worst_of_sets():
    p = {"error": {"random": {"max": 2}, "adversarial": {"max": 5},
                   "scenes": {"a": {"max_lsb": 7}, "b": {"reason": "skipped"}}}}
    assert error_lsb(p) == 7
    assert error_lsb({"error": {}}) is None
    # with per-channel sets the colour's count, not the diffuse's
    p = {"error": {"random": {"max": 9}, "channels": {"diffuse": {"random": {"max": 9}},
                                                      "color": {"random": {"max": 1},
                                                                "adversarial": {"max": 3}}},
                   "scenes": {"a": {"max_lsb": 2}}}}
    assert error_lsb(p) == 3


def _tiny_sweep(work, methods):
    grid = Grid(angle_bits=(6, 14), frac_bits=(5,), palette_sizes=(16,), samples=300,
                maps=(("bumps", 16),), adversarial=4000)
    opts = SimpleNamespace(methods=methods, fpga=False, sim=False, device="LFE5U-85F")
    return sweep(grid, opts, work, seed=4, progress=False)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """Our methods' points (the baselines' are make regress's, below: their costs against
    their structure are tests/rtl/test_baselines_*'s in make test)."""
    return _tiny_sweep(tmp_path_factory.mktemp("sweep"), ("exact", "palette"))


def test_tiny_sweep_points(tiny):
    by = {(p["method"], p.get("angle_bits"), p.get("palette_size")): p for p in tiny["points"]}
    exact6 = by[("exact", 6, None)]
    assert exact6["status"] == "ok"
    # the same vectors through the model directly give the same numbers
    cfg = Config(angle_bits=6, frac_bits=5)
    err = diffuse_error_lsb(datapath_fixed, PixelInputs.random(300, np.random.default_rng(4)), cfg)
    assert exact6["error"]["random"]["max"] == err.max()
    colour = term_errors_lsb(datapath_fixed, PixelInputs.random(300, np.random.default_rng(4)), cfg)["color"]
    assert exact6["error"]["channels"]["color"]["random"]["max"] == colour.max()
    assert error_lsb(exact6) >= colour.max()            # recommend ranks on the colour
    assert exact6["cost"]["multipliers"] > 0 and exact6["cost"]["table_bits"] > 0
    assert exact6["speed"]["golden_mpix_s"] > 0


def test_tiny_sweep_invalid_and_missing(tiny):
    by = {(p["method"], p.get("angle_bits")): p for p in tiny["points"]}
    invalid = by[("exact", 14)]                       # B = 5 < k - 1 = 11
    assert invalid["status"] == "invalid" and "frac_bits" in invalid["reason"]
    assert not any(p["method"] in BASELINES for p in tiny["points"])    # not asked for
    palette = by[("palette", None)]
    assert palette["status"] == "ok" and "random" not in palette["error"]
    assert palette["error"]["scenes"][map_key("bumps", 16)]["max_lsb"] == error_lsb(palette)
    (record,) = tiny["maps"]                          # the map it measured on, named and counted
    assert (record["name"], record["size"], record["texels"]) == ("bumps", 16, 256)
    assert 16 < record["distinct_normals"] <= 256
    assert palette["quantizes"] and palette["error"]["scenes"][map_key("bumps", 16)]["quantized"]
    json.dumps(tiny)                                  # the sweep is JSON-serializable


@pytest.mark.regress
def test_tiny_sweep_baselines(tmp_path):
    tiny = _tiny_sweep(tmp_path, ("exact", "baselines"))
    by = {(p["method"], p.get("angle_bits")): p for p in tiny["points"]}
    for name in BASELINES:                              # real points at valid widths
        point = by[(name, 6)]
        assert point["status"] == "ok" and point["cost"]["multipliers"] > 0
        cfg = Config(method=name, angle_bits=6, frac_bits=5)
        err = diffuse_error_lsb(datapath_fixed, PixelInputs.random(300, np.random.default_rng(4)), cfg)
        assert point["error"]["random"]["max"] == err.max()
        assert by[(name, 14)]["status"] == "invalid"
    assert by[("peercy", 6)]["cost"]["dividers"] > 0 and by[("peercy", 6)]["cost"]["sqrts"] > 0
    assert by[("kim", 6)]["cost"]["dividers"] == 0 == by[("exact", 6)]["cost"]["sqrts"]


def test_markdown_and_plot(tiny, tmp_path):
    text = bench_sweep.markdown(tiny, "bumprtl bench sweep --test")
    assert "`bumprtl bench sweep --test`" in text
    assert "exact a6 b5" in text and "invalid" in text
    png = bench_sweep.plot(tiny, tmp_path / "p.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_palette_point_storing_every_normal_is_marked_not_quantizing(tmp_path, monkeypatch):
    """At sN = the map's distinct normals the palette stores each one (``quantized`` false on
    that map, ``quantizes`` false for the point, listed under the table) and its image is
    the reference's within the colour table's rounding; one entry fewer quantizes."""
    monkeypatch.setattr(bench_sweep, "unit_cost", lambda units, cfg, work: {
        "multipliers": 0, "adders": 0, "table_bits": 0, "ram_bits": 0})
    grid = Grid(angle_bits=(), frac_bits=(), palette_sizes=(), samples=10, maps=(("moon", 32),))
    ctx = bench_sweep.Context(grid, 0, tmp_path)
    (record,) = ctx.maps
    n, key = record["distinct_normals"], map_key("moon", 32)
    opts = SimpleNamespace(fpga=False)
    exact, fewer = bench_sweep.palette_point(ctx, n, opts), bench_sweep.palette_point(ctx, n - 1, opts)
    assert not exact["quantizes"] and exact["stores_every_normal_of"] == [key]
    assert exact["error"]["scenes"][key]["quantized"] is False and exact["error"]["scenes"][key]["max_lsb"] <= 1
    assert fewer["quantizes"] and fewer["stores_every_normal_of"] == []
    assert fewer["error"]["scenes"][key]["quantized"] is True
    data = {"grid": grid.__dict__, "maps": ctx.maps, "seed": 0, "float64_conventional_mpix_s": 1.0,
            "points": [exact, fewer]}
    for p in data["points"]:
        p["cost"]["map_bits_per_texel"] = 10
    text = bench_sweep.markdown(data, "bumprtl bench sweep --test")
    assert f"moon (32\N{SUPERSCRIPT TWO}, {n} distinct normals)" in text
    assert f"- palette sN={n}: every normal of moon" in text and f"palette sN={n - 1}: every" not in text


@pytest.mark.parametrize("spec", ["nope:512", "moon:500", "moon:8", "moon:4096", "moon", "moon:x"])
def test_bad_maps_exit_2_naming_the_flag(spec, capsys):
    with pytest.raises(BumpError, match="--maps must be NAME:SIZE"):
        parse_maps([spec])
    assert main(["bench", "sweep", "--maps", spec, "--out", "/nonexistent/x.json"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--maps" in err and "[16, 2048]" in err and len(err.splitlines()) == 1


def test_a_scheduler_without_fpga_is_refused(capsys, tmp_path):
    """--scheduler places the --fpga points as jobs; without --fpga it would change nothing:
    one line naming both flags, exit 2, nothing written."""
    out = tmp_path / "x.json"
    assert main(["bench", "sweep", "--quick", "--scheduler", "tcp://127.0.0.1:8786",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--scheduler" in err[0] and "--fpga" in err[0], err
    assert not out.exists()


def test_parse_maps():
    assert parse_maps(["gravel:1024", "moon:512"]) == (("gravel", 1024), ("moon", 512))
    with pytest.raises(BumpError, match="twice"):
        parse_maps(["moon:512", "moon:512"])


def test_stress_rows_and_markdown():
    from bumprtl.gen.bench.stress import _float_row, markdown, stress_rows
    rows = stress_rows(200, 0, configs=["default"], cases=["below_horizon"])
    by = {r[2]: r[3] for r in rows}
    assert by["lee_printed (float64)"]["nan"] > 0
    assert by["exact (fixed)"]["overflow"] == 0 and by["exact (fixed)"]["diffuse_max_lsb"] <= 1

    def boom(px, cfg):
        raise ZeroDivisionError("model fell over")

    crash = _float_row(boom, None, Config(), None)
    text = markdown(rows + [("default", "below_horizon", "boom (float64)", crash)], "bumprtl bench stress --x", 200)
    assert "`bumprtl bench stress --x`" in text
    assert "**crash**: `ZeroDivisionError: model fell over`" in text
    assert "**crashes** in 1: default / below_horizon" in text


def test_skip_off_pipeline_renders_the_same_image(monkeypatch, tmp_path):
    """Skipping must not change the picture: the unskipped diffuse and flat scenes give the
    same colour bytes; so does the full scene (texture, two lights, mipmaps)."""
    from bumprtl.gen.bench import skip as bench_skip
    from bumprtl.sim.scenes.config import load_scene_config
    monkeypatch.setattr(bench_skip, "_cost", lambda scene, work: {"multipliers": 0})
    rows = {r["scene"]: r for r in bench_skip.skip_rows(["diffuse", "flat", "full"], 16, tmp_path)}
    assert rows["diffuse"]["same_image"] and rows["flat"]["same_image"]
    assert "H path + specular table" in rows["diffuse"]["skipped"]
    assert rows["full"]["status"] == "ok" and rows["full"]["same_image"]   # textured, 2 lights
    off = bench_skip.unskipped(load_scene_config("flat"))
    assert (off.bump_map, off.shading, off.specular) == ("varying", "per-pixel", True)


def test_skip_cost_is_measured_on_the_netlists(tmp_path):
    """bench skip's cost, measured for real once (the test above stands it in): a small
    scene without specular against its unskipped version, both synthesized by Yosys.
    Expected from the exact datapath's structure: 3 two-signal multipliers per vector dotted
    (x4 p2, y2 y2, z4 z), so 3 on and 6 off; the rotation's dual-port sine ROMs,
    ceil((14 + 5 V) / 2) for V vectors (10 on, 12 off), plus the specular table off; every
    sine ROM (2**k + 1) x (B + 1) bits."""
    scene = load_scene_config({"name": "tiny-diffuse", "specular": False, "texture_size": 16,
                               "angle_bits": 6, "frac_bits": 5})
    off = bench_skip.unskipped(scene).replace(name="tiny-off")
    on_cost, off_cost = bench_skip._cost(scene, tmp_path), bench_skip._cost(off, tmp_path)
    assert (on_cost["multipliers"], off_cost["multipliers"]) == (3, 6)
    cfg = scene.config
    assert on_cost["table_bits"] == 10 * cfg.sincos_depth * (cfg.frac_bits + 1)
    assert off_cost["table_bits"] > 12 * cfg.sincos_depth * (cfg.frac_bits + 1)   # + the table
    assert on_cost["ram_bits"] == off_cost["ram_bits"] == 16 * 16 * 2 * cfg.angle_bits  # the map


def test_fpga_points_diagonal_and_all():
    grid = bench_sweep.GRIDS["default"]
    diag = SimpleNamespace(fpga_points="diagonal")
    chosen = [(a, b) for a in grid.angle_bits for b in grid.frac_bits
              if bench_sweep.fpga_selected(grid, a, b, diag)]
    assert chosen == list(zip(grid.angle_bits, grid.frac_bits, strict=False))
    assert [(a, b) for a in grid.angle_bits for b in grid.frac_bits
            if bench_sweep.fpga_selected(grid, a, b, diag, "peercy")] == [DEFAULT_WIDTHS]
    default = SimpleNamespace(fpga_points="default")
    assert [(a, b) for a in grid.angle_bits for b in grid.frac_bits
            if bench_sweep.fpga_selected(grid, a, b, default, "lee")] == [DEFAULT_WIDTHS]
    every = SimpleNamespace(fpga_points="all")
    assert all(bench_sweep.fpga_selected(grid, a, b, every)
               for a in grid.angle_bits for b in grid.frac_bits)


def test_cost_cache_follows_the_verilog(tmp_path, monkeypatch):
    """The cost cache is keyed by the emitted Verilog: a different datapath is counted anew."""
    calls = []
    real = bench_sweep.count_verilog             # the name unit_cost calls
    monkeypatch.setattr(bench_sweep, "count_verilog", lambda *a, **k: calls.append(a) or real(*a, **k))
    cfg = Config(angle_bits=6, frac_bits=5)
    first = bench_sweep.unit_cost(("sincos",), cfg, tmp_path)
    assert bench_sweep.unit_cost(("sincos",), cfg, tmp_path) == first and len(calls) == 1
    from bumprtl.gen.flow import units  # same Config, different Verilog text: counted anew
    monkeypatch.setattr(units, "canonical_command", lambda unit, c, module=None: "changed datapath")
    bench_sweep.unit_cost(("sincos",), cfg, tmp_path)
    assert len(calls) == 2


def test_sim_rate_with_a_relative_work_dir(tmp_path, monkeypatch):
    """--sim measures cocotb pixels/s; a relative --work (the CLI default) must work although
    cocotb runs in its own build directory."""
    from pathlib import Path

    from bumprtl.gen.bench.golden import unit_sim_rate
    monkeypatch.chdir(tmp_path)
    rate, build_s = unit_sim_rate(Config(angle_bits=6, frac_bits=5), "icarus", "rotation", 5, Path("rel"))
    assert rate > 0 and build_s >= 0
    assert (tmp_path / "rel" / "rtl" / "rotation.json").is_file()


def test_stress_rows_at_the_narrowest_widths_are_bit_exact_only_and_none_crashes():
    """Float64 results do not depend on the widths: the narrowest configuration has a row
    per bit-exact method and none for the float64 models; every bit-exact model runs at
    4-bit angles and fractions without raising."""
    from bumprtl.gen.bench.stress import stress_rows
    from bumprtl.sim.golden.methods import METHODS

    rows = stress_rows(100, 0, configs=["narrowest"], cases=["below_horizon"])
    assert sorted(m for _, _, m, _ in rows) == sorted(f"{m} (fixed)" for m in METHODS)
    assert not any("float64" in m for _, _, m, _ in rows)
    assert all("crash" not in stats for *_, stats in rows), rows
