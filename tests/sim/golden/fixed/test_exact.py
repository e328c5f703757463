"""Accuracy of the fixed-point exact model against float64 on unquantized inputs (apart
from bit-exactness, which tests/rtl checks). The bound comes from the unit's sidecar."""

import numpy as np
import pytest

from bumprtl.gen.flow.units import build_unit
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.accuracy import adversarial_pixels, diffuse_error_lsb
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.methods import METHODS

exact_fixed = METHODS["exact"].datapath_fixed       # rotation then illumination, bit-exact


def sidecar_bound(cfg):
    return build_unit("illumination", cfg)[1].error_bounds.lsb_per_channel["diffuse"]


@pytest.fixture(scope="module")
def default_errors():
    cfg = Config()
    random = diffuse_error_lsb(exact_fixed, PixelInputs.random(1_000_000, np.random.default_rng(11)), cfg)
    adversarial = diffuse_error_lsb(exact_fixed, adversarial_pixels(cfg), cfg)
    return cfg, random, adversarial


def test_default_config_within_1_lsb_on_1e6_random(default_errors):
    cfg, random, _ = default_errors
    assert random.max() <= 1
    assert random.max() <= sidecar_bound(cfg)


def test_default_config_within_1_lsb_under_adversarial_search(default_errors):
    cfg, random, adversarial = default_errors
    assert adversarial.max() <= 1
    assert adversarial.max() <= sidecar_bound(cfg)
    # the search works: its inputs are far worse on average than random ones
    assert adversarial.mean() > 5 * random.mean()


@pytest.mark.parametrize("angle_bits, frac_bits", [(8, 9), (10, 13), (11, 13), (13, 15)])
def test_measured_error_never_exceeds_predicted_bound(angle_bits, frac_bits):
    cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
    worst = diffuse_error_lsb(exact_fixed, adversarial_pixels(cfg, candidates=50_000, keep=300), cfg).max()
    assert worst <= sidecar_bound(cfg)


def test_k9_cannot_reach_1_lsb():
    """The angle grid alone costs more than 1 LSB at k = 9, whatever B."""
    cfg = Config(angle_bits=11, frac_bits=20)
    assert diffuse_error_lsb(exact_fixed, adversarial_pixels(cfg, candidates=50_000, keep=300), cfg).max() >= 2
