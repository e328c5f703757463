"""bumprtl bench accuracy: one row per channel beside its bound; an error above a bound is a
failure (exit 1) that prints the offending input, which reproduces the error."""

import dataclasses
import re

import numpy as np
import pytest

from bumprtl.gen.bench import accuracy
from bumprtl.gen.cli.main import main
from bumprtl.rtl.config import TWO_LIGHT_WIDTHS, Config
from bumprtl.sim.golden.common import PixelInputs, to_8bit
from bumprtl.sim.golden.fixed.exact import faithful_widths
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.methods import datapath_fixed, encode_pixels

DEFAULT = Config()
ARGS = ["bench", "accuracy", "--samples", "3000", "--angle-bits", str(DEFAULT.angle_bits),
        "--frac-bits", str(DEFAULT.frac_bits), "--scene-size", "16"]


@pytest.fixture
def small_searches(monkeypatch):
    """The searches on a few hundred pixels (their own tests are in sim/golden)."""
    real_adv, real_arith = accuracy.adversarial_pixels, accuracy.arithmetic_pixels
    real_worst = accuracy.worst_case_pixels
    monkeypatch.setattr(accuracy, "adversarial_pixels",
                        lambda cfg, channel: real_adv(cfg, candidates=4000, keep=30, channel=channel))
    monkeypatch.setattr(accuracy, "arithmetic_pixels",
                        lambda model, cfg: real_arith(model, cfg, candidates=4000, keep=20, reach=1))
    monkeypatch.setattr(accuracy, "worst_case_pixels",
                        lambda model, cfg, channel: real_worst(model, cfg, channel, candidates=3000,
                                                               keep=10))


ROW = rf"\| {DEFAULT.angle_bits} \| {DEFAULT.frac_bits} \| 16 \| {{}} \| (\d+) / [\d.]+ \| (\d+) / [\d.]+ \| (\d+) \| (\d+) \| (.+?) \| (\d+) \|"


def test_rows_per_channel_within_the_bounds(small_searches, capsys):
    """Both measures per channel at the default: a proven bound of 1 on every channel, the
    end-to-end error of every set (the worst-case search included) within it, and the
    arithmetic alone (float64 on the received angles) within 1 LSB on every channel."""
    assert main(ARGS) == 0
    out = capsys.readouterr().out
    for channel in ("diffuse", "specular", "color"):
        row = re.search(ROW.format(channel), out)
        assert row and int(row.group(6)) == 1, (channel, out)
        assert max(int(g) for g in row.groups()[:4]) <= 1, (channel, row.group(0))
        arithmetic = [int(v) for v in row.group(5).split(" / ")]
        assert len(arithmetic) == 4 and max(arithmetic) <= 1, (channel, row.group(0))
    summary = re.search(rf"angle bits {DEFAULT.angle_bits}, frac bits {DEFAULT.frac_bits}, n = 16: arithmetic max diffuse (\d), "
                        r"specular (\d), color (\d) LSB; end-to-end max diffuse (\d), specular "
                        r"(\d), color (\d) LSB \(end to end adds the inputs' rounding to the "
                        rf"{DEFAULT.angle_bits}-bit angle grid, which alone the proof bounds by "
                        r"diffuse ([\d.]+), specular ([\d.]+) LSB before any arithmetic\)", out)
    assert summary and max(int(g) for g in summary.groups()[:6]) <= 1, out
    assert float(summary.group(7)) < 0.5 and float(summary.group(8)) < 1, out
    assert "FAIL" not in out
    assert re.search(r"\| bricks \| [\d.]+ / \d \| [\d.]+ / \d \|", out)      # colour and the blend
    assert re.search(r"\| moon \| [\d.]+ / \d \| — \|", out)                  # no colour texture
    assert re.search(r"\| craters \| [\d.]+ / \d \| — \|", out)               # the unseen map


def test_cartesian_inputs_have_no_arithmetic_measure(small_searches, capsys):
    assert main(ARGS[:2] + ["--method", "peercy"] + ARGS[2:-2] + ["--scene-size", "0"]) == 0
    out = capsys.readouterr().out
    for channel in ("diffuse", "specular", "color"):
        assert re.search(ROW.format(channel).replace("(.+?)", "—"), out), (channel, out)
    assert "Cartesian inputs: no arithmetic-only measure" in out


def _tighten(monkeypatch, channel):
    real = accuracy.build_unit

    def tight(unit, cfg):
        dut, sidecar, command = real(unit, cfg)
        bounds = sidecar.error_bounds
        tight = dataclasses.replace(bounds, lsb_per_channel={**bounds.lsb_per_channel, channel: 0})
        return dut, sidecar.replace(error_bounds=tight), command
    monkeypatch.setattr(accuracy, "build_unit", tight)


def _angles(text):
    return PixelInputs(**{k: np.array([float(v)]) for k, v in
                          re.findall(r"\b([nlhb]_(?:phi|theta))=([\d.e+-]+)", text)})


def test_an_error_above_its_bound_exits_1_with_the_input(small_searches, monkeypatch, capsys):
    _tighten(monkeypatch, "diffuse")
    assert main(ARGS) == 1
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("FAIL")]
    assert lines and all(" diffuse (" in ln for ln in lines)
    line = lines[0]
    assert "(random, end-to-end)" in line
    px = _angles(line)
    cfg = DEFAULT
    got = int(datapath_fixed(encode_pixels(px, cfg), cfg)["diffuse"][0])
    want = int(to_8bit(conventional(px, cfg).diffuse)[0])
    assert f"fixed {got}, float64 {want}" in line and got != want       # the input reproduces it
    assert re.search(rf"error {abs(got - want)} LSB > bound 0", line)


def test_an_arithmetic_error_above_its_bound_prints_the_received_angles(small_searches, monkeypatch,
                                                                          capsys):
    """The arithmetic measure is checked against the bound too; its line gives the input and
    the grid angles float64 was given, and those reproduce the error."""
    _tighten(monkeypatch, "specular")
    assert main(ARGS) == 1
    lines = [ln for ln in capsys.readouterr().out.splitlines()
             if ln.startswith("FAIL") and ", arithmetic)" in ln]
    assert lines and all(" specular (" in ln for ln in lines)
    given, received = lines[0].split("; float64 on the received angles")
    px, grid = _angles(given), _angles(received)
    cfg = DEFAULT
    got = int(datapath_fixed(encode_pixels(px, cfg), cfg)["specular"][0])
    want = int(to_8bit(conventional(grid, cfg).specular)[0])
    assert f"fixed {got}, float64 {want}" in lines[0] and got != want
    assert int(datapath_fixed(encode_pixels(grid, cfg), cfg)["specular"][0]) == got


LIGHT_ROW = (r"\| {} \| {} \| {} \| {} \| (\d+) / [\d.]+ \| (\d+) / [\d.]+ \| (\d+) \| "
             r"(\d+) / (\d+) / (\d+) \| (\d+) \| [\d.]+ \|")


def test_light_sums_and_blend_rows(small_searches, capsys):
    """The outputs over one and two lights and the texture blend: at the default widths
    every bound is 1 but two lights' specular sum (2: their specular terms add), and at the
    two-light scenes' widths every bound is 1; every measure within its bound, and the
    arithmetic within 1 LSB."""
    assert main(ARGS[:-1] + ["0"]) == 0
    out = capsys.readouterr().out
    a, b = DEFAULT.angle_bits, DEFAULT.frac_bits
    rows = [(a, b, m, o, 2 if (m, o) == (2, "specular") else 1)
            for m in (1, 2) for o in ("diffuse", "specular", "colour", "blend")]
    rows += [(*TWO_LIGHT_WIDTHS, 2, o, 1) for o in ("diffuse", "specular", "colour", "blend")]
    for angle_bits, frac_bits, lights, output, bound in rows:
        row = re.search(LIGHT_ROW.format(angle_bits, frac_bits, lights, output), out)
        assert row, (angle_bits, frac_bits, lights, output, out)
        *measured, got_bound = (int(g) for g in row.groups())
        assert got_bound == bound and max(measured[:3]) <= bound and max(measured[3:]) <= 1, row.group(0)


def test_a_light_sum_above_its_bound_exits_1(small_searches, monkeypatch, capsys):
    real = accuracy.error_bounds
    monkeypatch.setattr(accuracy, "error_bounds", lambda cfg, lights=1, texture=False: (
        {**real(cfg, lights, texture), "color": 0} if lights == 2 and texture else real(cfg, lights, texture)))
    assert main(ARGS[:-1] + ["0"]) == 1
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("FAIL")]
    assert lines and all("lights=2 blend (" in ln for ln in lines)
    assert "light 2: n_phi=" in lines[0] and ", texel (" in lines[0]


@pytest.mark.parametrize("flag, value, name", [("--spec-exponent", "2000", "spec_exponent"),
                                               ("--scene-size", "100", "scene_size")])
def test_bad_input_is_one_line_exit_2(capsys, flag, value, name):
    assert main(ARGS + [flag, value]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert name in err and len(err.splitlines()) == 1 and "|" not in captured.out


def test_scene_widths_set_the_light_table_widths(small_searches, capsys):
    """``--scene-widths 13 16`` (the old default): the light-sum table is measured there, each
    row under the proven bound of those widths (two lights' specular sum: 3), and the
    two-light scenes' widths keep their own rows."""
    args = ["bench", "accuracy", "--samples", "3000", "--angle-bits", "13", "--frac-bits", "16",
            "--scene-size", "0", "--scene-widths", "13", "16"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "--scene-widths 13 16" in out
    old = Config(angle_bits=13, frac_bits=16)
    for lights in (1, 2):
        bounds = accuracy.error_bounds(old, lights)
        for output, key in (("diffuse", "diffuse"), ("specular", "specular"), ("colour", "color")):
            row = re.search(LIGHT_ROW.format(13, 16, lights, output), out)
            assert row and int(row.group(7)) == bounds[key], (lights, output, out)
            assert max(int(g) for g in row.groups()[:3]) <= bounds[key]
    assert accuracy.error_bounds(old, 2)["specular"] == 3
    assert re.search(LIGHT_ROW.format(*TWO_LIGHT_WIDTHS, 2, "specular"), out)


def test_bad_scene_widths_is_one_line_exit_2(capsys):
    assert main(["bench", "accuracy", "--scene-widths", "3", "16", "--scene-size", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert "angle_bits" in err and "[4, 16]" in err and len(err.splitlines()) == 1


def test_faithful_widths_measure_each_exponent_at_its_proven_widths(small_searches, capsys):
    """``--faithful-widths``: each n at the narrowest widths whose bound is 1 LSB on every
    channel (the sidecar's), measured within it; an n with none says so in one line; a
    method that searches none is refused in one line."""
    args = ["bench", "accuracy", "--samples", "2000", "--faithful-widths", "--spec-exponent",
            "64", "1024", "--scene-size", "0"]
    assert main(args) == 0
    out = capsys.readouterr().out
    a, b = faithful_widths(Config(spec_exponent=64))
    assert "--faithful-widths --spec-exponent 64 1024" in out
    for channel in ("diffuse", "specular", "color"):
        row = re.search(rf"\| {a} \| {b} \| 64 \| {channel} \| (\d+) / [\d.]+ \| (\d+) / [\d.]+ "
                        r"\| (\d+) \| .+? \| (\d+) \|", out)
        assert row and max(int(g) for g in row.groups()[:3]) <= 1 == int(row.group(4)), (channel, out)
    assert "n = 1024: no widths in the Config's range prove every channel within 1 LSB" in out
    assert "| 1024 |" not in out
    assert main(args[:-2] + ["--method", "lee", "--scene-size", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert "faithful" in err and "lee" in err and len(err.splitlines()) == 1
