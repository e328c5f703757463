import numpy as np
import pytest

from bumprtl.rtl.config import Config
from bumprtl.rtl.tables import cos_lookup, quarter_sine, sin_lookup


@pytest.mark.parametrize("angle_bits, frac_bits", [(8, 8), (12, 13), (14, 16)])
def test_rom_within_half_ulp_of_float64(angle_bits, frac_bits):
    cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
    rom = quarter_sine(cfg)
    exact = np.sin(np.arange(cfg.sincos_depth) * (np.pi / 2) / (1 << cfg.k)) * cfg.one
    assert rom.shape == (cfg.sincos_depth,)
    assert np.max(np.abs(rom - exact)) <= 0.5
    assert rom[0] == 0 and rom[-1] == cfg.one


@pytest.mark.parametrize("angle_bits, frac_bits", [(8, 8), (12, 13)])
def test_full_circle_lookup_within_half_ulp(angle_bits, frac_bits):
    """Symmetry done in logic must not add error: every angle of the circle, sin and cos."""
    cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
    a = np.arange(cfg.full_circle)
    rad = a * 2 * np.pi / cfg.full_circle
    assert np.max(np.abs(sin_lookup(cfg, a) - np.sin(rad) * cfg.one)) <= 0.5
    assert np.max(np.abs(cos_lookup(cfg, a) - np.cos(rad) * cfg.one)) <= 0.5


def test_lookup_wraps_like_binary_angles():
    cfg = Config()
    a = np.arange(-5, 5)
    assert np.array_equal(sin_lookup(cfg, a), sin_lookup(cfg, a + 3 * cfg.full_circle))
