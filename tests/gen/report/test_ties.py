"""Every ranking breaks its ties by the rule its docstring states, whatever the order of its
input: ``bumprtl recommend`` (gen/report/recommend.rank_key: cost, then error, then the
narrower widths, then the method name) and the sweep's Pareto front (gen/bench/sweep.
pareto_front: of points tied in both coordinates the first is kept) and the seed a
``report fpga`` row reports (gen/report/fpga.worst_run: the lowest Fmax, then the lowest
seed)."""

import json

import pytest

from bumprtl.gen.bench.sweep import pareto_front
from bumprtl.gen.cli.main import main
from bumprtl.gen.report.fpga import worst_run
from bumprtl.gen.report.recommend import recommend

DEVICE = "LFE5U-25F"


def _point(method="exact", angle_bits=12, frac_bits=13, err=1, mult=6, rom=1000, lut=900):
    return {"method": method, "angle_bits": angle_bits, "frac_bits": frac_bits, "status": "ok",
            "config": {"method": method, "angle_bits": angle_bits, "frac_bits": frac_bits},
            "error": {"random": {"max": err, "mean": 0.1, "n": 10}},
            "cost": {"multipliers": mult, "adders": 30, "table_bits": rom, "ram_bits": 0,
                     "map_bits_per_texel": 24,
                     "fpga": {"device": DEVICE, "LUT4": lut, "DSP": 4, "BRAM": 2, "fmax_mhz": 100.0,
                              "available": {"LUT4": 24000, "DSP": 28, "BRAM": 56}}},
            "speed": {"golden_mpix_s": 1.0}}


def _both_orders(points, bound=1, device=None):
    """recommend's (best, candidates) on ``points`` and on them reversed: the same answer."""
    best, meeting = recommend({"points": points}, bound, device)
    best_r, meeting_r = recommend({"points": points[::-1]}, bound, device)
    assert best is best_r and [id(p) for p in meeting] == [id(p) for p in meeting_r]
    return best, meeting


def _palette_point(**kw):
    """A point whose widths are only in its configuration, as a palette point's are (the
    sweep records palette_size at the top, angle and fraction bits in ``config``)."""
    point = _point(method="palette", **kw)
    del point["angle_bits"], point["frac_bits"]
    return point


# Each case: points tied on cost (generic and on the device), and the one the rule picks.
CASES = {
    "widths read from the configuration: fewer angle bits": (
        [_palette_point(), _palette_point(angle_bits=11)], 1),
    "equal cost: the smaller error": ([_point(err=1), _point(angle_bits=11, err=0)], 1),
    "equal cost and error: fewer angle bits": ([_point(), _point(angle_bits=11)], 1),
    "equal cost, error, angle bits: fewer fraction bits": ([_point(), _point(frac_bits=12)], 1),
    "everything equal but the method: its name": ([_point(method="lee"), _point(method="exact")], 1),
}


@pytest.mark.parametrize("device", [None, DEVICE])
@pytest.mark.parametrize("case", list(CASES))
def test_recommend_breaks_a_cost_tie_by_the_stated_rule_in_either_order(case, device):
    points, want = CASES[case]
    best, meeting = _both_orders(points, device=device)
    assert best is points[want] and len(meeting) == 2


def test_cost_still_comes_before_the_tie_break():
    """The tie-break never overrides cost: the wider, worse point wins when it is cheaper."""
    cheap = _point(angle_bits=14, err=1, mult=5, lut=800)
    for device in (None, DEVICE):
        assert _both_orders([_point(angle_bits=8, err=0), cheap], device=device)[0] is cheap


def test_the_command_names_the_same_configuration_in_either_order(tmp_path, capsys):
    """``bumprtl recommend`` on a sweep file with a tie, the points in both orders."""
    points = [_point(angle_bits=12, frac_bits=13), _point(angle_bits=12, frac_bits=12)]
    lines = []
    for order in (points, points[::-1]):
        path = tmp_path / "sweep.json"
        path.write_text(json.dumps({"command": "toy", "points": order}))
        assert main(["recommend", "--max-error-lsb", "1", "--sweep", str(path)]) == 0
        lines.append([ln for ln in capsys.readouterr().out.splitlines() if "--angle-bits" in ln])
    assert lines[0] == lines[1] == ["  exact a12 b12: --method exact --angle-bits 12 --frac-bits 12"]


def test_pareto_front_keeps_the_first_of_an_exact_tie_in_either_order():
    """Tied in both coordinates: one of them is on the front, the first; reversed, the
    front holds the same values (and again the first of the tie)."""
    pts = [{"x": 3, "y": 1}, {"x": 1, "y": 2}, {"x": 1, "y": 2}, {"x": 2, "y": 2}]
    x, y = (lambda p: p["x"]), (lambda p: p["y"])
    front = pareto_front(pts, x, y)
    back = pareto_front(pts[::-1], x, y)
    assert sorted(front) == [0, 1]
    assert sorted(back) == [1, 3]          # reversed: the tie at indices 1, 2 -> the first, 1
    values = lambda ps, idx: sorted((ps[i]["x"], ps[i]["y"]) for i in idx)
    assert values(pts, front) == values(pts[::-1], back)


def test_fpga_row_reports_the_worst_seed_and_the_lowest_seed_of_a_tie():
    """report fpga's row is the seed with the lowest Fmax (a failed timing lowest of all);
    of seeds tied on it, the lowest seed, whatever the order of --seeds."""
    runs = [{"seed": 3, "fmax_mhz": 90.0, "LUT4": 1}, {"seed": 1, "fmax_mhz": 90.0, "LUT4": 2},
            {"seed": 2, "fmax_mhz": 120.0, "LUT4": 3}]
    for order in (runs, runs[::-1], runs[1:] + runs[:1]):
        assert worst_run(order)["seed"] == 1
    assert worst_run([*runs, {"seed": 9, "fmax_mhz": None}])["seed"] == 9
