"""The stress cases (sim/golden/stress.py) in the detail their docstrings give: the ranges
each draws from, the halves of the two-sided cases, the grid's five angles; and
stress_codes' interleaving of the cases."""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.fixed.common import angle_codes
from bumprtl.sim.golden.stress import CASES, EPS, stress_case, stress_codes


def _vec(phi, theta):
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1)


def _dot(px, a, b):
    return np.einsum("ni,ni->n", _vec(getattr(px, f"{a}_phi"), getattr(px, f"{a}_theta")),
                     _vec(getattr(px, f"{b}_phi"), getattr(px, f"{b}_theta")))


N = 2000


def test_hemisphere_cases_draw_uniform_directions_above_the_surface():
    """Uniform on the upper hemisphere: the cosine to N uniform in [0, 1] (mean 1/2, a
    quarter of them above 3/4)."""
    for name in ("theta_n_zero", "theta_180"):
        px = stress_case(name, N, seed=1)
        for v in ("l", "h"):
            c = _dot(px, v, "n")
            assert c.min() >= -1e-12 and abs(c.mean() - 0.5) < 0.03 and abs(np.mean(c > 0.75) - 0.25) < 0.03
        assert abs(np.cos(px.b_theta).mean() - 0.5) < 0.03
    zero = stress_case("theta_n_zero", N, seed=1)
    assert zero.n_phi.min() >= 0 and zero.n_phi.max() < 2 * np.pi and np.ptp(zero.n_phi) > 6
    # N itself uniform on the sphere where the case leaves it random
    n = stress_case("grazing", N, seed=1)
    assert abs(np.cos(n.n_theta).mean()) < 0.04 and abs(np.mean(np.cos(n.n_theta) > 0.5) - 0.25) < 0.03


def test_below_horizon_keeps_l_and_h_at_least_0_01_rad_under_the_surface():
    px = stress_case("below_horizon", N, seed=2)
    for v in ("l", "h"):
        c = _dot(px, v, "n")
        assert c.max() <= -np.sin(0.01) + 1e-12 and c.min() >= -1 - 1e-12 and c.mean() < -0.45


def test_l_equals_n_and_saturation_put_n_prime_on_the_normal():
    px = stress_case("l_equals_n", N, seed=3)
    assert np.allclose(_dot(px, "l", "n"), 1)
    assert _dot(px, "h", "n").min() >= -1e-12 and px.b_theta.max() <= np.pi / 2
    sat = stress_case("saturation", N, seed=3)
    assert np.all(sat.b_theta == 0)
    s = _dot(sat, "l", "n")
    assert np.allclose(np.abs(s), 1) and abs(np.mean(s > 0) - 0.5) < 0.05
    assert np.allclose(_dot(sat, "h", "n"), s)                      # H = L


def test_azimuth_wrap_puts_each_azimuth_within_0_02_of_the_seam_on_opposite_sides():
    px = stress_case("azimuth_wrap", N, seed=4)
    low = lambda phi: phi <= 0.02
    high = lambda phi: (phi >= 2 * np.pi - EPS - 0.02) & (phi <= 2 * np.pi - EPS)
    n_low = low(px.n_phi)
    assert np.all(n_low | high(px.n_phi)) and abs(n_low.mean() - 0.5) < 0.05
    for v in ("l_phi", "h_phi", "b_phi"):
        x = getattr(px, v)
        assert np.all(np.where(n_low, high(x), low(x))), v
    assert np.ptp(px.n_theta) > 2.5 and px.b_theta.max() <= np.pi / 2


def test_grid_extremes_use_the_five_grid_angles_of_each_range():
    px = stress_case("grid_extremes", N, seed=5)
    for name in ("n_phi", "l_phi", "h_phi", "b_phi", "n_theta", "l_theta", "h_theta", "b_theta"):
        hi = np.pi if name.endswith("theta") else 2 * np.pi
        values = set(np.round(getattr(px, name) / hi, 12))
        assert values == {0.0, 0.25, 0.5, 0.75, 1.0}, name


def test_stress_codes_interleave_the_cases():
    cfg = Config(angle_bits=10)
    n = 3 * len(CASES) + 4
    codes = stress_codes(n, cfg, seed=7)
    per = -(-n // len(CASES))
    for i in range(n):
        name = list(CASES)[i % len(CASES)]
        px = stress_case(name, per, 7 + i % len(CASES))
        assert codes["n.theta"][i] == angle_codes(px.n_theta[i // len(CASES)], cfg), i
        assert codes["l.phi"][i] == angle_codes(px.l_phi[i // len(CASES)], cfg), i
    assert all(len(v) == n for v in codes.values())


def test_check_fixed_reports_diffuse_and_colour_errors_and_overflow_per_field():
    """check_fixed's errors recomputed here: |model - round(255 x float64)| of diffuse and
    colour per pixel, within the default's proven 1 LSB; no field overflows."""
    from bumprtl.sim.golden.common import to_8bit
    from bumprtl.sim.golden.float.conventional import conventional
    from bumprtl.sim.golden.methods import datapath_fixed, encode_pixels
    from bumprtl.sim.golden.stress import check_fixed

    cfg = Config()
    px = stress_case("random", 300, seed=8)
    got = check_fixed(datapath_fixed, px, cfg)
    assert sorted(got) == ["color_lsb", "diffuse_lsb", "overflow"]
    out, ref = datapath_fixed(encode_pixels(px, cfg), cfg), conventional(px, cfg)
    for key, channel in (("diffuse_lsb", "diffuse"), ("color_lsb", "color")):
        want = np.abs(out[channel].astype(int) - to_8bit(getattr(ref, channel)).astype(int))
        assert np.array_equal(got[key], want) and want.max() <= 1 and want.max() > 0, key
    assert got["overflow"] and set(got["overflow"].values()) == {0}


def test_angle_codes_round_float32_angles_as_given():
    """Angles given in float32 (a user's array) are quantized from their values as given,
    exactly as the same values in float64: float32 arithmetic would put some on the
    neighbouring code."""
    cfg = Config()
    a = np.random.default_rng(0).uniform(0, 2 * np.pi, 100_000).astype(np.float32)
    assert np.array_equal(angle_codes(a, cfg), angle_codes(a.astype(np.float64), cfg))


def test_to_8bit_rounds_float32_intensities_as_given():
    """Intensities given in float32 become 8-bit codes from their values as given, exactly
    as the same values in float64: float32 arithmetic would round some 255 x near a half
    the other way."""
    from bumprtl.sim.golden.common import to_8bit
    x = np.random.default_rng(0).uniform(0, 1, 100_000).astype(np.float32)
    assert np.array_equal(to_8bit(x), to_8bit(x.astype(np.float64)))
