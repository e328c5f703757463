"""The proven bounds of the exact, kim and lee models as their docstrings state them, term
by term (delta = pi / 2**(k+2) half an angle step, u = 2**-B), and measured against the
datapaths: the arithmetic errors reach a good part of their bounds, so a loosened or a
tightened formula fails one side or the other."""

import numpy as np
import pytest

from bumprtl.rtl.config import Config, ConfigError
from bumprtl.rtl.tables import kim_reciprocal_bits, lee_asin_index_bits, lee_atan_mantissa_bits
from bumprtl.sim.golden.common import PixelInputs, polar_to_cartesian
from bumprtl.sim.golden.fixed import exact as fixed_exact
from bumprtl.sim.golden.fixed import kim as fixed_kim
from bumprtl.sim.golden.fixed import lee as fixed_lee
from bumprtl.sim.golden.fixed.common import channel_bounds_lsb, quantize_pixels

WIDTHS = [(8, 9), (11, 12), (14, 15), (16, 24)]
CHANNELS = ("specular", "color", "blend")


def _du(cfg):
    return np.pi / (1 << (cfg.k + 2)), 2.0 ** -cfg.frac_bits


@pytest.mark.parametrize("widths", WIDTHS)
def test_exact_bound_is_the_back_ends_for_2_sqrt5_delta_and_the_dot_error(widths):
    """dot_error_bound = (1.5 + sqrt 3 / 2 + 1/2 + 1.3 u) u; every channel's bound is the
    back end's for the angle 2 sqrt 5 delta and that additive error, summed over lights."""
    cfg = Config(angle_bits=widths[0], frac_bits=widths[1])
    delta, u = _du(cfg)
    e = (1.5 + np.sqrt(3) / 2 + 0.5 + 1.3 * u) * u
    assert fixed_exact.dot_error_bound(cfg) == pytest.approx(e, rel=1e-12)
    for lights in (1, 2):
        want = channel_bounds_lsb(cfg, 2 * np.sqrt(5) * delta, e, lights)
        for c in ("diffuse",) + CHANNELS:
            assert fixed_exact.predicted_error_bound_lsb(cfg, c, lights) == want[c], (c, lights)


@pytest.mark.parametrize("widths", WIDTHS)
def test_kim_bound_is_its_docstrings_sum(widths):
    """direction = d_th + 2 e + e_atan with e = (sqrt 10 + sqrt 4.75 + sqrt 3 / 2) u,
    e_atan = (2**-(R+1) + u) / 2 + 2**-(M+2) + delta, d_th = 1.5 (e + 1.21 u + e_atan**2 / 2
    + 2**-(a+1)) + delta; diffuse floor(255 (2 sqrt 5 delta + 14 delta**2 + direction +
    (sqrt 2 + 1.5) u)) + 1; the other channels the back end's for 2 sqrt 5 delta and
    direction + (sqrt 2 + 1.5) u."""
    cfg = Config(method="kim", angle_bits=widths[0], frac_bits=widths[1])
    delta, u = _du(cfg)
    r, m, a = kim_reciprocal_bits(cfg), lee_atan_mantissa_bits(cfg), lee_asin_index_bits(cfg)
    e = (np.sqrt(10) + np.sqrt(4.75) + np.sqrt(3) / 2) * u
    e_atan = (2.0 ** -(r + 1) + u) / 2 + 2.0 ** -(m + 2) + delta
    d_th = 1.5 * (e + 1.21 * u + e_atan ** 2 / 2 + 2.0 ** -(a + 1)) + delta
    direction = d_th + 2 * e + e_atan
    assert fixed_kim.direction_error_bound(cfg) == pytest.approx(direction, rel=1e-12)
    before = 2 * np.sqrt(5) * delta + 14 * delta ** 2 + direction + (np.sqrt(2) + 1.5) * u
    assert fixed_kim.predicted_error_bound_lsb(cfg) == int(np.floor(255 * before)) + 1
    for lights in (1, 2):
        want = channel_bounds_lsb(cfg, 2 * np.sqrt(5) * delta, direction + (np.sqrt(2) + 1.5) * u, lights)
        for c in CHANNELS:
            assert fixed_kim.predicted_error_bound_lsb(cfg, c, lights) == want[c], (c, lights)
    assert fixed_kim.predicted_error_bound_lsb(cfg, "diffuse", 2) == \
        channel_bounds_lsb(cfg, 2 * np.sqrt(5) * delta, direction + (np.sqrt(2) + 1.5) * u, 2)["diffuse"]
    with pytest.raises(ConfigError):
        fixed_kim.predicted_error_bound_lsb(cfg, "alpha")


def test_lee_bound_is_the_whole_range_on_every_channel_and_names_a_bad_one():
    for cfg in (Config(method="lee"), Config(method="lee", angle_bits=16, frac_bits=24)):
        for c in ("diffuse",) + CHANNELS:
            assert fixed_lee.predicted_error_bound_lsb(cfg, c) == 255
            assert fixed_lee.predicted_error_bound_lsb(cfg, c, lights=2) == 255
    with pytest.raises(ConfigError, match="channel must be one of"):
        fixed_lee.predicted_error_bound_lsb(Config(method="lee"), "alpha")


@pytest.mark.parametrize("widths", [(8, 9), (12, 13)])
def test_kims_directions_reach_a_quarter_of_their_bound(widths):
    """On quantized inputs the setup's L' is within direction_error_bound of the exact
    M L of the same angles, and some pixel comes within a factor 4 of it."""
    cfg = Config(method="kim", angle_bits=widths[0], frac_bits=widths[1])
    px = PixelInputs.random(20_000, np.random.default_rng(7), valid=False)
    codes = quantize_pixels(px, cfg)
    step = 2 * np.pi / cfg.full_circle
    phi, theta = fixed_kim.rotate_fixed(codes["l.phi"], codes["l.theta"], codes["n.phi"], codes["n.theta"], cfg)
    got = polar_to_cartesian(phi * step, theta * step)
    from bumprtl.sim.golden.common import tangent_rotation
    m = tangent_rotation(codes["n.phi"] * step, codes["n.theta"] * step)
    want = np.einsum("pij,pj->pi", m, polar_to_cartesian(codes["l.phi"] * step, codes["l.theta"] * step))
    err = np.linalg.norm(got - want, axis=-1)
    bound = fixed_kim.direction_error_bound(cfg)
    assert bound / 4 <= err.max() <= bound, (err.max(), bound)


@pytest.mark.parametrize("widths", [(8, 9), (10, 11), (14, 15)])
def test_exacts_dot_error_reaches_half_its_bound(widths):
    """The exact datapath's N'.A' against the exact dot of the same (rounded) angles:
    within dot_error_bound, and some pixel comes within a factor 2 of it."""
    cfg = Config(angle_bits=widths[0], frac_bits=widths[1])
    px = PixelInputs.random(20_000, np.random.default_rng(8), valid=False)
    codes = quantize_pixels(px, cfg)
    step = 2 * np.pi / cfg.full_circle
    rot = fixed_exact.rotation_fixed(codes, cfg)
    got = fixed_exact.dot_fixed(rot, "l", cfg) / cfg.one
    from bumprtl.sim.golden.common import world_bump_normal
    ang = {k: np.asarray(v) * step for k, v in codes.items()}
    nw = world_bump_normal(ang["n.phi"], ang["n.theta"], ang["b.phi"], ang["b.theta"])
    want = np.einsum("pi,pi->p", nw, polar_to_cartesian(ang["l.phi"], ang["l.theta"]))
    err = np.abs(got - want).max()
    bound = fixed_exact.dot_error_bound(cfg)
    assert bound / 2 <= err <= bound, (err, bound)
