"""The proven error bounds' building blocks (sim/golden/fixed/common.py) against closed
forms: the input rounding's angle 2 sqrt(5) pi / 2**angle_bits, the diffuse term's 255 x
(the dot's error) and the specular term's largest change of 255 cos^n, each to within the
bound's own grid (pi / 2**16 of alpha times the slope); the channel bounds as floor + 1 of
their sums, capped at 255."""

import numpy as np
import pytest

from bumprtl.rtl.config import Config, ConfigError
from bumprtl.rtl.tables import coefficient_error_lsb, specular_table_error_lsb
from bumprtl.sim.golden.fixed.common import (
    channel_bound,
    channel_bounds_lsb,
    input_angle_error,
    term_bounds_lsb,
)

GRID = np.pi / (1 << 16)


@pytest.mark.parametrize("bits", [8, 14, 16])
def test_input_angle_error_is_2_sqrt5_half_steps(bits):
    cfg = Config(angle_bits=bits)
    half_step = np.pi / (1 << bits)                # 2 pi / 2**bits / 2
    assert input_angle_error(cfg) == pytest.approx(2 * np.sqrt(5) * half_step, rel=1e-12)


@pytest.mark.parametrize("e", [1e-3, 4e-3])
def test_an_additive_error_e_moves_diffuse_255_e_and_specular_255_n_e_at_the_top(e):
    cfg = Config()
    n = cfg.spec_exponent
    t = term_bounds_lsb(cfg, 0.0, e)
    assert 255 * e <= t["diffuse"] <= 255 * (e + GRID) + 1e-9
    spec = t["specular"] - specular_table_error_lsb(cfg)
    want = 255 * (1 - (1 - e) ** n)                  # steepest at x = 1: 1 - (1 - e)**n
    assert want <= spec + 1e-9 and spec <= 255 * (1 - (1 - e - GRID) ** n) + 1e-9


@pytest.mark.parametrize("a", [1e-3, 5e-3])
def test_an_angle_error_a_moves_diffuse_255_a_and_specular_by_the_steepest_slope(a):
    cfg = Config()
    n = cfg.spec_exponent
    t = term_bounds_lsb(cfg, a, 0.0)
    # diffuse: cos moves by at most sin(alpha) a ~ a at alpha = 90 deg
    assert 255 * np.sin(a) * 0.999 <= t["diffuse"] <= 255 * (a + GRID) + 1e-9
    # specular: cos^n is steepest where tan^2 alpha = 1 / (n - 1): slope n cos^(n-1) sin
    s = 1 / np.sqrt(n)
    slope = n * np.sqrt(1 - s * s) ** (n - 1) * s
    spec = t["specular"] - specular_table_error_lsb(cfg)
    assert 255 * slope * a * 0.97 <= spec <= 255 * slope * (a + GRID) * 1.03
    assert term_bounds_lsb(Config(specular=False), a, 0.0)["specular"] == 0.0


def test_channel_bounds_are_floor_plus_one_of_their_sums_capped_at_255():
    cfg = Config()
    a, e = 0.004, 0.002
    t = term_bounds_lsb(cfg, a, e)
    for lights in (1, 2):
        got = channel_bounds_lsb(cfg, a, e, lights)
        terms = lights * (cfg.kd * t["diffuse"] + cfg.ks * t["specular"])
        assert got == {"diffuse": int(np.floor(lights * t["diffuse"])) + 1,
                       "specular": int(np.floor(lights * t["specular"])) + 1,
                       "color": int(np.floor(terms + coefficient_error_lsb(cfg, lights))) + 1,
                       "blend": int(np.floor(terms + coefficient_error_lsb(cfg, lights, blend=True))) + 1}
        for k, v in got.items():
            assert channel_bound(cfg, k, a, e, lights) == v
    nospec = channel_bounds_lsb(Config(specular=False), a, e)
    t0 = term_bounds_lsb(Config(specular=False), a, e)
    assert nospec["color"] == int(np.floor(0.7 * t0["diffuse"] + coefficient_error_lsb(Config(specular=False), 1))) + 1
    assert set(channel_bounds_lsb(cfg, 3.0, 1.0, 2).values()) == {255}       # 2 lights: past 255
    with pytest.raises(ConfigError, match=r"channel must be one of diffuse, specular, color, blend, got 'alpha'"):
        channel_bound(cfg, "alpha", a, e)


def test_peercys_other_channels_are_the_back_ends_bound_for_its_dot_error():
    """Peercy's dot is within e = (5/2 + 2 sqrt 3) u + 2 u^2 (u = 2**-B) of the true one; its
    diffuse bound is floor(255 e) + 1, every other channel (and several lights) the shared
    back end's bound for that e and no angle error."""
    from bumprtl.sim.golden.fixed.peercy import predicted_error_bound_lsb

    for cfg in (Config(method="peercy"), Config(method="peercy", frac_bits=12)):
        u = 2.0 ** -cfg.frac_bits
        e = (2.5 + 2 * np.sqrt(3)) * u + 2 * u * u
        assert predicted_error_bound_lsb(cfg) == int(np.floor(255 * e)) + 1
        for channel in ("specular", "color", "blend"):
            assert predicted_error_bound_lsb(cfg, channel) == channel_bounds_lsb(cfg, 0.0, e)[channel]
        assert predicted_error_bound_lsb(cfg, "diffuse", 2) == channel_bounds_lsb(cfg, 0.0, e, 2)["diffuse"]
        with pytest.raises(ConfigError):
            predicted_error_bound_lsb(cfg, "alpha")
