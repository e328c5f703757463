"""The bit-exact kim baseline model (sim/golden/fixed/kim.py) against float64: the diffuse
error stays within the derived bound (predicted_error_bound_lsb) on random valid, adversarial
and stress inputs; the rotated directions stay within direction_error_bound of the float64
Kim model; the polar recovery is exact on the axes and at the poles (where ph is undefined
and must come out as 0)."""

import numpy as np
import pytest

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.accuracy import adversarial_pixels, diffuse_error_lsb
from bumprtl.sim.golden.common import PixelInputs, polar_to_cartesian
from bumprtl.sim.golden.fixed.common import quantize_pixels
from bumprtl.sim.golden.fixed.kim import (
    direction_error_bound,
    predicted_error_bound_lsb,
    rotate_fixed,
    to_polar_fixed,
)
from bumprtl.sim.golden.float.kim import kim
from bumprtl.sim.golden.methods import METHODS
from bumprtl.sim.golden.stress import CASES, stress_case

CFG = Config(method="kim")
kim_fixed = METHODS["kim"].datapath_fixed           # rotation then illumination, bit-exact


def dequantize(codes, cfg):
    step = 2 * np.pi / cfg.full_circle
    return PixelInputs(**{f"{k[0]}_{k[2:]}": np.asarray(codes[k]) * step for k in codes})


def directions(phi_codes, theta_codes, cfg):
    step = 2 * np.pi / cfg.full_circle
    return polar_to_cartesian(np.asarray(phi_codes) * step, np.asarray(theta_codes) * step)


def test_diffuse_error_within_bound_on_20000_random_valid():
    """20 000 random valid pixels at the default widths stay within the predicted bound."""
    px = PixelInputs.random(20_000, np.random.default_rng(11))
    err = diffuse_error_lsb(kim_fixed, px, CFG)
    bound = predicted_error_bound_lsb(CFG)
    assert err.max() <= bound, (err.max(), bound)


@pytest.mark.parametrize("widths", [(8, 9), (10, 9), (12, 11), (12, 13), (16, 24)])
def test_diffuse_error_within_bound_adversarial_and_stress(widths):
    """The bound is a worst case: it must also hold where the datapath is pushed hardest
    (accuracy.adversarial_pixels) and on every stress case (poles, grazing, L = N, ...)."""
    cfg = Config(method="kim", angle_bits=widths[0], frac_bits=widths[1])
    bound = predicted_error_bound_lsb(cfg)
    worst = diffuse_error_lsb(kim_fixed, adversarial_pixels(cfg, candidates=20_000, keep=200), cfg).max()
    for name in CASES:
        worst = max(worst, diffuse_error_lsb(kim_fixed, stress_case(name, 400, seed=5), cfg).max())
    assert worst <= bound, (worst, bound)


def test_bound_tightens_with_width():
    """More bits, smaller bound: the bound is a function of the widths, not a constant."""
    bounds = [predicted_error_bound_lsb(Config(method="kim", angle_bits=a, frac_bits=a + 1))
              for a in (8, 10, 12, 14)]
    assert bounds == sorted(bounds, reverse=True) and bounds[0] > bounds[-1]


@pytest.mark.parametrize("widths", [(8, 9), (12, 13), (16, 24)])
def test_rotated_directions_within_bound_of_float64(widths):
    """L' and H' from the setup against float64 Kim on the same (quantized) angles."""
    cfg = Config(method="kim", angle_bits=widths[0], frac_bits=widths[1])
    rng = np.random.default_rng(3)
    codes = quantize_pixels(PixelInputs.random(5_000, rng, valid=False), cfg)
    ref = kim(dequantize(codes, cfg), cfg)
    got_phi, got_theta = rotate_fixed(codes["l.phi"], codes["l.theta"], codes["n.phi"],
                                      codes["n.theta"], cfg)
    err = np.linalg.norm(directions(got_phi, got_theta, cfg) - polar_to_cartesian(*ref.l_prime), axis=-1)
    assert err.max() <= direction_error_bound(cfg), (err.max(), direction_error_bound(cfg))


@pytest.mark.parametrize("widths", [None, (13, 16)])
def test_polar_recovery_on_the_axes_and_poles(widths):
    """Exact answers where geometry gives them: the six axes (ph' = 0 at the poles, where
    the azimuth is undefined) and the diagonals of the xy-plane. On a diagonal the ratio
    y / x = 1 goes through the reciprocal and atan tables, whose roundings land exactly on
    45 degrees at 13 / 16 and one angle step above it at the 14 / 15 default."""
    cfg = CFG if widths is None else CFG.replace(angle_bits=widths[0], frac_bits=widths[1])
    one = cfg.one
    q = cfg.full_circle // 4                       # 90 degrees
    cases = {(one, 0, 0): (0, q), (0, one, 0): (q, q), (-one, 0, 0): (2 * q, q),
             (0, -one, 0): (3 * q, q), (0, 0, one): (0, 0), (0, 0, -one): (0, 2 * q),
             (0, 0, 0): (0, 0)}
    for (x, y, z), expected in cases.items():
        phi, theta = to_polar_fixed(np.array([x]), np.array([y]), np.array([z]), cfg)
        assert (int(phi[0]), int(theta[0])) == expected, (x, y, z)
    h = int(round(one / np.sqrt(2)))
    for sx, sy, octant in ((1, 1, 1), (-1, 1, 3), (-1, -1, 5), (1, -1, 7)):
        phi, theta = to_polar_fixed(np.array([sx * h]), np.array([sy * h]), np.array([0]), cfg)
        slack = 0 if widths else 1
        assert abs(int(phi[0]) - octant * q // 2) <= slack and int(theta[0]) == q


def test_polar_recovery_random_unit_vectors():
    """Cartesian -> polar alone: rounded unit vectors come back within the direction bound."""
    cfg = CFG
    rng = np.random.default_rng(9)
    v = rng.normal(size=(20_000, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    xyz = np.rint(v * cfg.one).astype(np.int64)
    phi, theta = to_polar_fixed(xyz[:, 0], xyz[:, 1], xyz[:, 2], cfg)
    err = np.linalg.norm(directions(phi, theta, cfg) - v, axis=1)
    assert err.max() <= direction_error_bound(cfg)


@pytest.mark.parametrize("n_theta", [0, "pole"])
def test_light_at_the_pole_of_the_frame(n_theta):
    """N at +z or -z and L at +z or -z for every azimuth of N and L: A' lies exactly on a
    pole, x' = y' = 0, so ph' must be 0 and th' exactly 0 or 180 degrees."""
    cfg = CFG
    half = cfg.full_circle // 2
    th_n = 0 if n_theta == 0 else half
    phis = np.arange(0, cfg.full_circle, 37)
    n_phi, l_phi = (a.ravel() for a in np.meshgrid(phis, phis))
    for l_theta in (0, half):
        phi, theta = rotate_fixed(l_phi, np.full_like(l_phi, l_theta), n_phi,
                                  np.full_like(n_phi, th_n), cfg)
        up = (l_theta == 0) == (th_n == 0)
        assert np.all(phi == 0) and np.all(theta == (0 if up else half))
