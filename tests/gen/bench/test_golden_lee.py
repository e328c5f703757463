"""``bumprtl bench golden`` and ``bench lee-widths`` at tiny sizes (gen/bench/golden.py,
lee_widths.py): the rows and columns their help promises, the simulation rate counted over
all four traffic patterns, ``--sim-samples 0`` meaning no simulation, and the lee error
staying in the geometry, not the bits, as the widths grow."""

from types import SimpleNamespace

import pytest

from bumprtl.gen.bench import golden
from bumprtl.gen.bench.lee_widths import WIDTHS
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.methods import PER_PIXEL
from bumprtl.sim.golden.vectors import edge_codes


def _table(text, first):
    return [line.split(" | ") for line in text.splitlines() if line.startswith(first)]


def test_golden_rows_per_method_and_no_simulation_at_zero_samples(monkeypatch, run_cli, tmp_path):
    monkeypatch.chdir(tmp_path)                         # the tools' log: build/bench/golden.log
    called = []
    monkeypatch.setattr(golden, "unit_sim_rate", lambda *a: called.append(a))
    r = run_cli(["bench", "golden", "--pixels", "64", "--sim-samples", "0",
                 "--methods", "lee", "exact"])
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[0] == "bumprtl bench golden --pixels 64 --sim-samples 0"
    rows = [row for row in _table(r.stdout, "| ") if row[0] in ("| lee", "| exact")]
    assert [row[:2] for row in rows] == [["| lee", "64"], ["| exact", "64"]]
    assert all(float(row[2].rstrip(" |")) > 0 for row in rows)
    assert called == [] and "cocotb simulation" not in r.stdout


def test_golden_simulates_every_method_unit_and_simulator(monkeypatch, run_cli, tmp_path):
    monkeypatch.chdir(tmp_path)
    calls = []

    def fake_rate(cfg, sim, unit, samples, work):
        calls.append((cfg.method, unit, sim, samples))
        return 12345.6, 2.25

    monkeypatch.setattr(golden, "unit_sim_rate", fake_rate)
    r = run_cli(["bench", "golden", "--pixels", "32", "--sim-samples", "7", "--methods",
                 "exact", "lee"])
    assert r.returncode == 0, r.stderr
    assert calls == [(m, u, s, 7) for m in ("exact", "lee") for u in ("rotation", "illumination")
                     for s in ("icarus", "verilator")]
    out = r.stdout
    assert "| method | unit | simulator | pixels/s | build s |" in out
    assert "| lee | illumination | verilator | 12,346 | 2.2 |" in out


def test_golden_reports_a_method_whose_model_is_missing(monkeypatch, capsys):
    def rate(cfg, n, repeats=3):
        if cfg.method == "lee":
            raise ImportError("no lee model here")
        return 2e6

    monkeypatch.setattr(golden, "_golden_rate", rate)
    golden.golden_bench(methods=["exact", "lee"], pixels=10, sim_samples=0)
    out = capsys.readouterr().out
    assert "| exact | 10 | 2.00 |" in out
    assert "| lee | - | not available (no lee model here) |" in out


def test_unit_sim_rate_counts_the_four_patterns_and_the_edge_cases(monkeypatch, tmp_path):
    """pixels/s = 4 traffic patterns x (random samples + the edge cases tb_datapath sends)
    over the run's seconds; the build seconds passed through; the sample count reaches the
    testbench."""
    seen = {}
    monkeypatch.setattr(golden, "emit_unit",
                        lambda unit, cfg, out: (out / f"{unit}.v", out / f"{unit}.json"))

    def fake_run(sim, v, module, build, env, opt_fast):
        seen.update(sim=sim, v=v, module=module, build=build, env=env)
        return SimpleNamespace(run_s=2.0, build_s=3.5)

    monkeypatch.setattr(golden, "run_cocotb", fake_run)
    cfg = Config()
    rate, build = golden.unit_sim_rate(cfg, "icarus", "rotation", 100, tmp_path)
    edges = len(edge_codes(cfg)["n.phi"])
    assert rate == pytest.approx(4 * (100 + edges) / 2.0) and build == 3.5
    assert seen["env"]["BUMPRTL_SAMPLES"] == 100 and seen["module"] == "bumprtl.sim.tb.tb_datapath"
    assert seen["build"] == tmp_path / "icarus_rotation" and seen["v"].name == "rotation.v"


def test_golden_rate_is_pixels_over_the_best_time(monkeypatch):
    times = iter([5.0, 2.0, 4.0])
    monkeypatch.setattr(golden, "_timed", lambda fn: next(times))
    assert golden._golden_rate(Config(method=PER_PIXEL[0]), 1000) == 500.0


def test_lee_widths_rows_follow_the_widths_and_the_error_is_the_geometrys(run_cli, tmp_path,
                                                                            monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = run_cli(["bench", "lee-widths", "--samples", "400", "--seed", "3"])
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == "bumprtl bench lee-widths --samples 400 --seed 3"
    assert lines[1].startswith("400 random valid inputs (seed 3)")
    float_mean = float(lines[2].split("mean ")[1].split(",")[0])
    rows = [line.strip("| ").split(" | ") for line in lines
            if line.startswith("| ") and line[2].isdigit()]
    assert [(int(a), int(b)) for a, b, *_ in rows] == list(WIDTHS)
    for row in rows:
        assert 0 <= float(row[2]) <= int(row[3])            # mean within [0, max]
    widest = rows[-1]
    assert int(widest[4]) <= 1 and int(widest[5]) <= 1     # the bits are not the error
    assert abs(float(widest[2]) - float_mean) < 1          # the float64 lee's error remains
    assert int(rows[0][4]) > int(widest[4])                 # the narrowest widths do cost bits
