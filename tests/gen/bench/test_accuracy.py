"""bumprtl bench accuracy: one row per channel beside its bound; an error above a bound is a
failure (exit 1) that prints the offending input, which reproduces the error."""

import re

import numpy as np
import pytest

from bumprtl.gen.bench import accuracy
from bumprtl.gen.cli.main import main
from bumprtl.rtl.config import Config
from bumprtl.rtl.methods import datapath_fixed, encode_pixels
from bumprtl.sim.golden.common import PixelInputs, to_8bit
from bumprtl.sim.golden.float.conventional import conventional

ARGS = ["bench", "accuracy", "--samples", "3000", "--angle-bits", "12", "--frac-bits", "13",
        "--scene-size", "16"]


@pytest.fixture
def small_searches(monkeypatch):
    """The searches on a few hundred pixels (their own tests are in sim/golden)."""
    real_adv, real_arith = accuracy.adversarial_pixels, accuracy.arithmetic_pixels
    monkeypatch.setattr(accuracy, "adversarial_pixels",
                        lambda cfg, channel: real_adv(cfg, candidates=4000, keep=30, channel=channel))
    monkeypatch.setattr(accuracy, "arithmetic_pixels",
                        lambda model, cfg: real_arith(model, cfg, candidates=4000, keep=20, reach=1))


def test_rows_per_channel_within_the_bounds(small_searches, capsys):
    assert main(ARGS) == 0
    out = capsys.readouterr().out
    for channel, bound in (("diffuse", 1), ("specular", 4), ("color", 2)):
        row = re.search(rf"\| 12 \| 13 \| 16 \| {channel} \| (\d+) / [\d.]+ \| (\d+) / [\d.]+ \| (\d+) \| (\d+) \|", out)
        assert row and int(row.group(4)) == bound, (channel, out)
        assert max(int(g) for g in row.groups()[:3]) <= bound
    assert "FAIL" not in out
    assert re.search(r"\| bricks \| [\d.]+ / \d \| [\d.]+ / \d \|", out)      # colour and the blend
    assert re.search(r"\| moon \| [\d.]+ / \d \| — \|", out)                  # no colour texture


def test_an_error_above_its_bound_exits_1_with_the_input(small_searches, monkeypatch, capsys):
    real = accuracy.build_unit

    def tight(unit, cfg):
        dut, sidecar, command = real(unit, cfg)
        return dut, {**sidecar, "error_bounds_lsb": {**sidecar["error_bounds_lsb"], "diffuse": 0}}, command
    monkeypatch.setattr(accuracy, "build_unit", tight)
    assert main(ARGS) == 1
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("FAIL")]
    assert lines and all(" diffuse (" in ln for ln in lines)
    line = lines[0]
    angles = dict(re.findall(r"\b([nlhb]_(?:phi|theta))=([\d.e+-]+)", line))
    assert len(angles) == 8
    px = PixelInputs(**{k: np.array([float(v)]) for k, v in angles.items()})
    cfg = Config()
    got = int(datapath_fixed(encode_pixels(px, cfg), cfg)["diffuse"][0])
    want = int(to_8bit(conventional(px, cfg).diffuse)[0])
    assert f"fixed {got}, float64 {want}" in line and got != want       # the input reproduces it
    assert re.search(rf"error {abs(got - want)} LSB > bound 0", line)


@pytest.mark.parametrize("flag, value, name", [("--spec-exponent", "2000", "spec_exponent"),
                                               ("--scene-size", "100", "scene_size")])
def test_bad_input_is_one_line_exit_2(capsys, flag, value, name):
    assert main(ARGS + [flag, value]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert name in err and len(err.splitlines()) == 1 and "|" not in captured.out
