"""bumprtl recommend on toy sweep data: the cheapest point meeting the bound, with evidence;
exit 2 with a one-line message when none does."""

import json

import pytest

from bumprtl.gen.cli.main import main
from bumprtl.gen.report.recommend import recommend
from bumprtl.rtl.config import BumpError


def _point(name, err, rom, mult=6, adders=30, fpga=None):
    cost = {"multipliers": mult, "adders": adders, "table_bits": rom, "ram_bits": 0,
            "map_bits_per_texel": 24}
    if fpga:
        cost["fpga"] = fpga
    a, b = name
    return {"method": "exact", "angle_bits": a, "frac_bits": b, "status": "ok",
            "config": {"method": "exact", "angle_bits": a, "frac_bits": b},
            "error": {"random": {"max": err, "mean": 0.1, "n": 10},
                      "adversarial": {"max": err - 1, "mean": 0.5, "n": 13}},
            "cost": cost, "speed": {"golden_mpix_s": 10.0}}


def _fpga(lut, dsp, bram, device="LFE5U-25F", avail=(24000, 28, 56)):
    return {"device": device, "LUT4": lut, "DSP": dsp, "BRAM": bram, "fmax_mhz": 100.0,
            "available": dict(zip(("LUT4", "DSP", "BRAM"), avail, strict=False))}


TOY = {"command": "bumprtl bench sweep --toy", "points": [
    _point((12, 13), 1, 180_000),
    _point((12, 11), 1, 150_000),
    _point((10, 11), 4, 45_000),
    _point((14, 16), 1, 900_000),
    {"method": "exact", "angle_bits": 14, "frac_bits": 9, "status": "invalid", "reason": "frac_bits"},
]}


def test_picks_cheapest_meeting_bound():
    best, meeting = recommend(TOY, 1)
    assert (best["angle_bits"], best["frac_bits"]) == (12, 11)
    assert len(meeting) == 3
    assert recommend(TOY, 4)[0]["angle_bits"] == 10


def test_arithmetic_units_before_memory():
    data = {"points": [_point((12, 13), 1, 1000, mult=8), _point((12, 12), 1, 1000, mult=6)]}
    assert recommend(data, 1)[0]["frac_bits"] == 12
    divider_heavy = _point((8, 9), 1, 4_000, mult=30)
    divider_heavy["cost"].update(dividers=6, sqrts=2)
    data = {"points": [divider_heavy, _point((12, 13), 1, 180_000, mult=6)]}
    assert recommend(data, 1)[0]["angle_bits"] == 12      # 6 multipliers beat 30 + 6 + 2


def _channels_point(name, diffuse, color, mult):
    """A sweep point with per-channel sets (``bumprtl bench sweep``): its diffuse and colour
    maxima differ."""
    p = _point(name, max(diffuse, color), 1000, mult=mult)
    sets = lambda m: {"random": {"max": m, "mean": 0.1, "n": 10},
                      "adversarial": {"max": m, "mean": 0.5, "n": 13}}
    p["error"] = {**sets(diffuse), "channels": {"diffuse": sets(diffuse), "specular": sets(3),
                                                 "color": sets(color)},
                  "scenes": {"bricks": {"psnr_db": 59.0, "max_lsb": color}}}
    return p


def test_ranks_on_the_colour_not_the_diffuse(tmp_path, capsys):
    """What a pixel shows is the colour: a cheap point whose diffuse misses 1 LSB but whose
    colour meets it wins over a dearer one whose diffuse meets it and colour does not."""
    data = {"points": [_channels_point((10, 13), diffuse=3, color=1, mult=4),
                       _channels_point((12, 13), diffuse=1, color=2, mult=8)]}
    best, meeting = recommend(data, 1)
    assert (best["angle_bits"], len(meeting)) == (10, 1)
    data["points"][0]["error"]["scenes"]["bricks"] = {"psnr_db": None, "max_lsb": 0}
    path = tmp_path / "sweep.json"
    path.write_text(json.dumps(data))
    assert main(["recommend", "--max-error-lsb", "1", "--sweep", str(path)]) == 0
    out = capsys.readouterr().out
    assert "worst colour 1" in out and "color random: max 1" in out and "diffuse random: max 3" in out
    assert "scene bricks: PSNR inf (identical), max 0" in out
    with pytest.raises(BumpError, match=r"smallest measured error is 1 LSB"):
        recommend(data, 0.5)


def test_none_meets_bound_names_smallest_error():
    with pytest.raises(BumpError, match=r"smallest measured error is 1 LSB"):
        recommend(TOY, 0.5)


def test_device_ranking_uses_fpga_and_capacity():
    data = {"points": [
        _point((12, 13), 1, 100, fpga=_fpga(3000, 8, 25)),
        _point((12, 11), 1, 50, fpga=_fpga(2000, 40, 10)),       # 40 DSP > 28: does not fit
        _point((11, 11), 1, 900, fpga=_fpga(9000, 2, 30)),
    ]}
    best, meeting = recommend(data, 1, "LFE5U-25F")
    assert (best["angle_bits"], best["frac_bits"]) == (11, 11)       # fewest DSP among those that fit
    assert all(p["cost"]["fpga"]["DSP"] <= 28 for p in meeting)
    with pytest.raises(BumpError, match="no FPGA numbers for device LFE5U-85F"):
        recommend(data, 1, "LFE5U-85F")


def _palette(size, scenes):
    """A palette sweep point measured on ``scenes``: {map key: (max LSB, quantized)}."""
    return {"method": "palette", "palette_size": size, "status": "ok",
            "config": {"palette_size": size},
            "error": {"scenes": {k: {"psnr_db": None if m == 0 else 50.0, "max_lsb": m, "quantized": q}
                                 for k, (m, q) in scenes.items()}},
            "cost": {"multipliers": 0, "adders": 2, "table_bits": 0, "ram_bits": 32 * size,
                     "map_bits_per_texel": 14},
            "speed": {"golden_mpix_s": 3.0}}


MAPS = [{"key": "gravel 1024\u00b2", "name": "gravel", "size": 1024, "texels": 1 << 20,
         "distinct_normals": 82838},
        {"key": "moon 512\u00b2", "name": "moon", "size": 512, "texels": 1 << 18,
         "distinct_normals": 8328}]


def test_names_the_maps_and_does_not_count_a_palette_that_quantized_nowhere(tmp_path, capsys):
    """A palette holding every distinct normal of every map measured (error 0, and cheapest)
    is no evidence for a larger map: not a candidate, named as not counted; the evidence
    line names each map with its size and distinct normals."""
    exact_everywhere = _palette(16384, {"moon 512\u00b2": (0, False)})
    data = {"command": "bumprtl bench sweep --toy", "maps": MAPS[1:],
            "points": [exact_everywhere, _point((12, 13), 1, 180_000)]}
    best, meeting = recommend(data, 1)
    assert best["method"] == "exact" and len(meeting) == 1
    path = tmp_path / "sweep.json"
    path.write_text(json.dumps(data))
    assert main(["recommend", "--max-error-lsb", "1", "--sweep", str(path)]) == 0
    out = capsys.readouterr().out
    assert "evidence: maps moon (512\u00b2, 8328 distinct normals)" in out
    assert "not counted: palette sN=16384" in out
    with pytest.raises(BumpError, match="not counted.*palette sN=16384"):
        recommend({"maps": MAPS[1:], "points": [exact_everywhere]}, 1)


def test_a_palette_that_quantized_on_some_maps_counts_and_says_where(tmp_path, capsys):
    partly = _palette(16384, {"gravel 1024\u00b2": (1, True), "moon 512\u00b2": (0, False)})
    data = {"command": "toy", "maps": MAPS, "points": [partly, _point((12, 13), 1, 180_000)]}
    assert recommend(data, 1)[0] is partly                     # 0 multipliers: cheapest
    path = tmp_path / "sweep.json"
    path.write_text(json.dumps(data))
    assert main(["recommend", "--max-error-lsb", "1", "--sweep", str(path)]) == 0
    out = capsys.readouterr().out
    assert "evidence: maps gravel (1024\u00b2, 82838 distinct normals), moon (512\u00b2, 8328 distinct normals)" in out
    assert "held every distinct normal of moon 512\u00b2" in out and "comes from gravel 1024\u00b2" in out
    assert "not counted" not in out


def test_an_older_sweep_without_map_records_is_judged_by_texels(capsys):
    """Sweeps made before the maps were recorded: a palette with at least as many entries as
    a map has texels held every normal of it."""
    old = lambda size: {**_palette(size, {}), "error": {"scenes": {"bricks": {"psnr_db": None, "max_lsb": 0}}}}
    data = {"grid": {"scenes": ["bricks"], "size": 128}, "points": [old(16384), old(4096)]}
    best, meeting = recommend(data, 1)
    assert [p["palette_size"] for p in meeting] == [4096]
    from bumprtl.gen.report.recommend import evidence_line
    assert evidence_line(data) == "evidence: maps bricks (128\u00b2, distinct normals not recorded)"


@pytest.mark.parametrize("bad", [-1, True, "1"])
def test_bad_bound(bad):
    with pytest.raises(BumpError, match="max_error_lsb"):
        recommend(TOY, bad)


def test_cli_prints_evidence(tmp_path, capsys):
    path = tmp_path / "sweep.json"
    path.write_text(json.dumps(TOY))
    assert main(["recommend", "--max-error-lsb", "1", "--sweep", str(path)]) == 0
    out = capsys.readouterr().out
    assert "--angle-bits 12 --frac-bits 11" in out
    assert "adversarial: max 0" in out and "150000 ROM bits" in out
    assert "bumprtl bench sweep --toy" in out


@pytest.mark.parametrize("content, message", [
    (json.dumps(TOY), "no configuration in the sweep meets"),
    ("{not json", "not valid JSON"),
    ("[1, 2]", "no 'points' list"),
    (None, "does not exist"),
])
def test_cli_exits_2_with_one_line(tmp_path, capsys, content, message):
    path = tmp_path / "sweep.json"
    if content is not None:
        path.write_text(content)
    assert main(["recommend", "--max-error-lsb", "0", "--sweep", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


def test_without_a_local_or_shipped_sweep_the_command_says_how_to_make_one(tmp_path, capsys,
                                                                           monkeypatch):
    from bumprtl.gen.report import recommend as rec
    monkeypatch.chdir(tmp_path)                           # no build/bench/sweep.json here
    monkeypatch.setattr(rec, "SHIPPED_SWEEP", tmp_path / "docs" / "data" / "sweep.json")
    assert rec.sweep_path() == (rec.LOCAL_SWEEP, None)
    assert main(["recommend", "--max-error-lsb", "1"]) == 2
    [line] = capsys.readouterr().err.strip().splitlines()
    assert str(rec.LOCAL_SWEEP) in line and "bumprtl bench sweep" in line
