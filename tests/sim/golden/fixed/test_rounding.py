"""Every rounding point of the datapaths is unbiased: the mean signed error of the rounded
value against the float64 value it rounds (in units of its own LSB, i.e. 2**-B for the dot
products) is near 0.

The bit-exact tests cannot see a rounding that the RTL and the golden model both get wrong
(truncation instead of round-to-nearest keeps the maximum error within 1 LSB but moves the
mean by -1/2 LSB), so each rounding point is checked here against float64 computed from the
values it is fed (the outputs of the stage before it, read from the golden model).

Tolerance: the errors of n independent samples lie in an interval of width w, so by
Hoeffding's inequality their mean is within t = w sqrt(ln(2 / delta) / (2 n)) of its
expectation except with probability delta = 1e-9 (the samples are seeded: the test is
deterministic, the bound says how far chance alone can move the mean). Round-to-nearest of a
uniformly distributed discarded fraction has expectation 0 once exact ties (a discarded
fraction of exactly one half, which round_shift sends up) count as 0; each point also checks
|error| <= 1/2 where the error is the rounding alone.
"""

import math

import numpy as np
import pytest

from bumprtl.rtl.baselines import kim as kim_rtl
from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import Q
from bumprtl.rtl.lee import asin_address, prop_address, theta_from_prop
from bumprtl.rtl.palette import mul8
from bumprtl.rtl.tables import (
    SPEC_FRAC_BITS,
    blend_coefficients,
    cos_lookup,
    lee_asin_index_bits,
    lee_prop_index_bits,
    phong_coefficients,
)
from bumprtl.rtl.texture import texture_blend
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.fixed import exact as fixed_exact
from bumprtl.sim.golden.fixed import lee as fixed_lee
from bumprtl.sim.golden.fixed import peercy as fixed_peercy
from bumprtl.sim.golden.fixed.common import angle_codes, quantize_pixels, shade_fixed
from bumprtl.sim.golden.fixed.pipeline import combine_lights_fixed
from bumprtl.sim.scenes.config import load_scene_config

N = 200_000
DELTA = 1e-9
CFG = Config()


def hoeffding(n, width=1.0, delta=DELTA):
    """Half-width of the interval around its expectation that holds the mean of ``n``
    independent samples of range ``width`` except with probability ``delta``."""
    return width * math.sqrt(math.log(2 / delta) / (2 * n))


def assert_rounds_to_nearest(got, exact, where):
    """``got`` (integers) rounds ``exact`` (float64, in units of got's LSB): |error| <= 1/2,
    ties up, and the mean error (ties as 0) within the Hoeffding bound of 0."""
    err = np.asarray(got, np.float64) - np.asarray(exact, np.float64)
    assert err.size >= 1000, where
    assert np.abs(err).max() <= 0.5, (where, err.min(), err.max())
    tie = np.abs(err) == 0.5
    assert np.all(err[tie] > 0), f"{where}: a tie rounded down"
    mean = np.where(tie, 0.0, err).mean()
    assert abs(mean) <= hoeffding(err.size), (where, mean, hoeffding(err.size))


def assert_unbiased(err, width, where):
    """A composite error (more than one rounding, range ``width``): mean within the bound."""
    err = np.asarray(err, np.float64)
    assert np.abs(err).max() <= width / 2, (where, err.min(), err.max())
    assert abs(err.mean()) <= hoeffding(err.size, width), (where, err.mean())


@pytest.fixture(scope="module")
def codes():
    return quantize_pixels(PixelInputs.random(N, np.random.default_rng(21)), CFG)


# --- dot products (units of 2**-B) ------------------------------------------------------------

def test_exact_dot_product(codes):
    """N'.A' = (x4 p2 + 2 y2 y2 + 2 z4 z) / 2**(B+3), rounded once (rtl/exact.py's two
    carry-chain stages, sim/golden/fixed/exact.dot_fixed)."""
    rot = fixed_exact.rotation_fixed(codes, CFG)
    for v in ("l", "h"):
        w = {k: rot[k].astype(np.float64) for k in rot}
        acc = w["n.x4"] * w[f"{v}.p2"] + 2 * w["n.y2"] * w[f"{v}.y2"] + 2 * w["n.z4"] * w[f"{v}.z"]
        assert np.abs(acc).max() < 2.0 ** 53                     # float64 holds it exactly
        assert_rounds_to_nearest(fixed_exact.dot_fixed(rot, v, CFG), acc / 2 ** (CFG.frac_bits + 3),
                                 f"exact dot {v}")


def test_lee_dot_product():
    """Eq. 24 with erratum 2: ((c- + c+) 2**B + (c- - c+) c_phi) / 2**(B+1), rounded once."""
    cfg = CFG.replace(method="lee")
    rng = np.random.default_rng(22)
    a_phi, b_phi = rng.integers(0, cfg.full_circle, (2, N))
    a_theta, b_theta = rng.integers(0, (1 << (cfg.k + 1)) + 1, (2, N))
    cos = lambda a: cos_lookup(cfg, a).astype(np.float64)
    c_plus, c_minus, c_phi = cos(a_theta + b_theta), cos(a_theta - b_theta), cos(a_phi - b_phi)
    exact = ((c_minus + c_plus) * cfg.one + (c_minus - c_plus) * c_phi) / 2 ** (cfg.frac_bits + 1)
    assert_rounds_to_nearest(fixed_lee.illuminate_fixed(a_phi, a_theta, b_phi, b_theta, cfg), exact,
                             "lee dot")


def test_peercy_dot_product():
    """N'.A_n = (N' . A_n) / 2**B, rounded once (Peercy's and Ernst's illumination)."""
    cfg = CFG.replace(method="peercy")
    rng = np.random.default_rng(23)
    rot = {f"{v}.{a}": rng.integers(-cfg.one, cfg.one + 1, N) for v in ("l", "h", "np") for a in "xyz"}
    out = fixed_peercy.illumination_fixed(rot, cfg)
    for v, key in (("l", "ndotl"), ("h", "ndoth")):
        acc = sum(rot[f"np.{a}"].astype(np.float64) * rot[f"{v}.{a}"] for a in "xyz")
        assert_rounds_to_nearest(out[key], acc / cfg.one, f"peercy dot {v}")


# --- the shared back end (8-bit LSB; the table index in its own LSB) -------------------------

@pytest.fixture(scope="module")
def shaded():
    rng = np.random.default_rng(24)
    cfg = CFG.replace(spec_index_bits=6, spec_exponent=1)      # a strictly increasing table
    ndotl, ndoth = rng.integers(0, CFG.one + 1, (2, N))
    return cfg, ndotl, ndoth, shade_fixed(ndotl, ndoth, cfg)


def test_shade_diffuse(shaded):
    """diffuse = 255 N'.L / 2**B, rounded (rtl/shade.py's (d << 8) - d, then round_shift)."""
    cfg, ndotl, _, out = shaded
    assert_rounds_to_nearest(out["diffuse"], 255 * ndotl / cfg.one, "diffuse")


def test_shade_specular_output(shaded):
    """The 8-bit specular port = specular_fine / 2**F, rounded (the interpolated cos^n term
    itself is checked against float64 in tests/sim/golden/fixed/test_channels.py)."""
    cfg, _, _, out = shaded
    assert_rounds_to_nearest(out["specular"], out["specular_fine"] / 2 ** SPEC_FRAC_BITS,
                             "specular")


def phong_exact(ka, kd, ks, d, s, cfg):
    """The Phong sum the colour rounds, in 8-bit LSB: (KA + floor(KD d / 2**B) + floor(KS s /
    2**16)) / 2**G (the products' floors are part of the value, their error is in the bound)."""
    return (ka + np.floor(kd * d / 2 ** cfg.frac_bits) + np.floor(ks * s / 2 ** 16)) / 2 ** 9


def test_shade_phong_sum(shaded):
    """color = the Phong sum of the unrounded terms, rounded once (eq. 2), where it is not
    clamped at 255."""
    cfg, _, _, out = shaded
    ka, kd, ks = phong_coefficients(cfg)
    exact = phong_exact(ka, kd, ks, out["diffuse_fine"], out["specular_fine"], cfg)
    keep = exact < 255
    assert_rounds_to_nearest(out["color"][keep], exact[keep], "phong sum")


def test_light_sum_phong():
    """LightSum (several lights): color = the Phong sum of sum d_j and sum s_j, rounded;
    diffuse = 255 sum d_j / 2**B and specular = sum s_j / 2**F, rounded."""
    scene = load_scene_config({"name": "t", "lights": 2})
    cfg = scene.config
    rng = np.random.default_rng(25)
    shades = [{"diffuse_fine": rng.integers(0, cfg.one + 1, N),
               "specular_fine": rng.integers(0, 255 << SPEC_FRAC_BITS, N)} for _ in range(2)]
    out = combine_lights_fixed(shades, scene)
    ka, kd, ks = phong_coefficients(cfg)
    d = shades[0]["diffuse_fine"] + shades[1]["diffuse_fine"]
    s = shades[0]["specular_fine"] + shades[1]["specular_fine"]
    exact = phong_exact(ka, kd, ks, d, s, cfg)
    keep = exact < 255
    assert_rounds_to_nearest(out["color"][keep], exact[keep], "light sum")
    for key, value in (("diffuse", 255 * d / cfg.one), ("specular", s / 2 ** SPEC_FRAC_BITS)):
        keep = value < 255
        assert_rounds_to_nearest(out[key][keep], value[keep], f"light sum {key}")


@pytest.mark.parametrize("term", ["lit", "spec"])
def test_texture_blend_intensities(term):
    """texture_blend's out = (tex lit + spec) / 2**16 rounded once, with lit = min(2**16, KA +
    floor(KD d / 2**B)) and spec = floor(KS s / 2**9): read through a white texel with the
    other term's coefficients 0."""
    coeffs = {"lit": {"ka": 0.1, "kd": 0.7, "ks": 0.0}, "spec": {"ka": 0.0, "kd": 0.0, "ks": 0.83}}[term]
    cfg = CFG.replace(**coeffs)
    rng = np.random.default_rng(26)
    d = rng.integers(0, cfg.one + 1, N)
    s = rng.integers(0, 255 << SPEC_FRAC_BITS, N)
    white = {c: np.full(N, 255) for c in "rgb"}
    out, _, _ = texture_blend([d], [s], white, cfg)
    ka, kd, ks = blend_coefficients(cfg)
    lit = np.minimum(ka + np.floor(kd * d / 2 ** cfg.frac_bits), 2 ** 16)
    exact = (255 * lit + np.floor(ks * s / 2 ** 9)) / 2 ** 16
    keep = exact < 255
    assert_rounds_to_nearest(out["g"][keep], exact[keep], f"texture {term}")


def test_mul8_product_over_255():
    """The blends' x a / 255 (palette eq. 1 and 2, texture), rounded: every pair."""
    x, a = np.meshgrid(np.arange(256), np.arange(256))
    assert_rounds_to_nearest(mul8(x.ravel(), a.ravel()), x.ravel() * a.ravel() / 255, "mul8")


# --- the lee rotation ---------------------------------------------------------------------------

def test_lee_prop_address():
    """T_prop address |y_k| = |y2| (1/|cos Z|) / 2**(2B+1-p), rounded, below the clamp."""
    cfg = CFG.replace(method="lee")
    p = lee_prop_index_bits(cfg)
    shift = 2 * cfg.frac_bits + 1 - p
    product = np.random.default_rng(27).integers(0, 1 << (p + shift), N)
    assert_rounds_to_nearest(prop_address(product, cfg), product / 2 ** shift, "lee prop address")


def test_lee_theta_from_prop():
    """Eq. 19: th' = |Z| + (90 deg - |Z|) theta_prop, the product rounded to the angle grid."""
    cfg = CFG.replace(method="lee")
    rng = np.random.default_rng(28)
    abs_z, prop = rng.integers(0, (1 << cfg.k) + 1, N), rng.integers(0, cfg.one + 1, N)
    exact = abs_z + ((1 << cfg.k) - abs_z) * prop / cfg.one
    assert_rounds_to_nearest(theta_from_prop(abs_z, prop, cfg), exact, "lee theta_from_prop")


def test_lee_asin_address():
    """Eq. 7's asin address |s| = |sin X + sin Y| / 2 to a fractional bits, rounded (the
    helper the RTL and the golden model share)."""
    cfg = CFG.replace(method="lee")
    shift = cfg.frac_bits + 1 - lee_asin_index_bits(cfg)
    s2 = np.random.default_rng(29).integers(-2 * cfg.one, 2 * cfg.one + 1, N)
    assert_rounds_to_nearest(asin_address(s2, cfg), np.abs(s2) / 2 ** shift, "lee asin address")


# --- the kim baseline's helpers (B fractional bits) ------------------------------------------

def test_kim_products():
    """Each helper's product or sum of products / 2**B, rounded (the clamps not reached)."""
    cfg = CFG.replace(method="kim")
    b = cfg.frac_bits
    rng = np.random.default_rng(30)
    u = lambda: rng.integers(-cfg.one, cfg.one + 1, N)
    pos = lambda: rng.integers(0, cfg.one + 1, N)
    st, ct, sp, cp = u(), u(), u(), u()
    f = lambda *xs: [x.astype(np.float64) for x in xs]
    fst, fct, fsp, fcp = f(st, ct, sp, cp)
    entries = kim_rtl.matrix_entries(st, ct, sp, cp, cfg)
    for got, (x, y) in zip(entries, ((fct, fcp), (fct, fsp), (fst, fcp), (fst, fsp)), strict=False):
        assert_rounds_to_nearest(got, x * y / cfg.one, "kim matrix entries")
    for got, x in zip(kim_rtl.cartesian(st, sp, cp, cfg), (fst * fcp, fst * fsp), strict=False):
        assert_rounds_to_nearest(got, x / cfg.one, "kim cartesian")
    half = lambda: rng.integers(-cfg.one // 2, cfg.one // 2 + 1, N)   # |sums| < 1: no clamp
    mat, x, y, z = (half(), half(), half(), half()), half(), half(), half()
    got = kim_rtl.transform(mat, (st // 2, ct // 2, sp // 2, cp // 2), (x, y, z), cfg)
    fm, (fx, fy, fz) = f(*mat), f(x, y, z)
    fs, fc, fp, fq = f(st // 2, ct // 2, sp // 2, cp // 2)
    exact = ((fm[0] * fx + fm[1] * fy - fs * fz), (fq * fy - fp * fx), (fm[2] * fx + fm[3] * fy + fc * fz))
    for g, e in zip(got, exact, strict=False):
        assert_rounds_to_nearest(g, e / cfg.one, "kim transform")
    p, q, ca, sa = pos(), pos(), pos(), pos()
    assert_rounds_to_nearest(kim_rtl.rho_of(p, q, ca, sa, cfg),
                             (p.astype(np.float64) * ca + q.astype(np.float64) * sa) / cfg.one, "kim rho")
    a = lee_asin_index_bits(cfg)
    v = pos()
    assert_rounds_to_nearest(kim_rtl.asin_address(v, cfg), v / 2 ** (b - a), "kim asin address")
    cc, ss = kim_rtl.dot_terms(st, ct, sp, cp, cfg)
    assert np.array_equal(cc, ct * cp)
    assert_rounds_to_nearest(ss, fst * fsp / cfg.one, "kim sin th sin th")
    cphi = u()
    assert_rounds_to_nearest(kim_rtl.dot_sum(cc, ss, cphi, cfg),
                             (cc.astype(np.float64) + ss * cphi.astype(np.float64)) / cfg.one, "kim dot")


# --- the peercy baseline ----------------------------------------------------------------------

def test_peercy_normalization_quotient():
    """A_n = a_t 2**(B+2) / r / 2 rounded half up from the floored quotient, r = isqrt(4 s)
    (recomputed here with math.isqrt): |A_n| within half an LSB of |a_t| 2**(B+1) / r."""
    cfg = CFG.replace(method="peercy")
    rng = np.random.default_rng(31)
    at = [rng.integers(-cfg.one, cfg.one + 1, N // 4) for _ in range(3)]
    got = fixed_peercy.normalize_fixed(at, cfg)
    s = sum(0 + a.astype(object) * a for a in at)
    r = np.array([math.isqrt(4 * int(x)) for x in s], dtype=np.float64)
    keep = r > 0
    for a, g in zip(at, got, strict=False):
        exact = np.abs(a[keep]).astype(np.float64) * 2 ** (cfg.frac_bits + 1) / r[keep]
        assert np.array_equal(np.sign(g[keep]), np.sign(a[keep]))
        assert_rounds_to_nearest(np.abs(g[keep]), exact, "peercy quotient")


def test_peercy_transform():
    """a_t = (row . A) / 2**B rounded, seen through the normalization: A_n against the float64
    normalization of the unrounded a_t, component by component. Its error is the transform's
    rounding (at most half an LSB of a_t, moving A_n by at most that over |a_t|), the square
    root's floor (|A_n| a little long: a bias with the sign of the component) and the
    quotient's rounding; with L and H uniform over the sphere every component is as often
    negative as positive, so the signed mean is 0 unless a rounding is biased."""
    cfg = CFG.replace(method="peercy")
    px = PixelInputs.random(N // 4, np.random.default_rng(32), valid=False)
    enc = fixed_peercy.encode(px, cfg)
    rot = fixed_peercy.rotation_fixed(enc, cfg)
    errors = []
    for v in ("l", "h"):
        a = np.stack([enc[f"{v}.{c}"] for c in "xyz"]).astype(np.float64)
        at = np.stack([sum(enc[f"{row}.{c}"].astype(np.float64) * a[i] for i, c in enumerate("xyz"))
                       for row in ("t", "b", "n")]) / cfg.one
        norm = np.sqrt((at ** 2).sum(axis=0))
        exact = at / norm * cfg.one
        got = np.stack([rot[f"{v}.{c}"] for c in "xyz"])
        errors.append((got - exact).ravel())
    err = np.concatenate(errors)
    assert_unbiased(err, 4.0, "peercy transform + normalization")


# --- inputs -----------------------------------------------------------------------------------

def test_input_angle_codes():
    """Radians -> binary angles, rounded to nearest (sim/golden/fixed/common.angle_codes)."""
    rad = np.random.default_rng(33).uniform(0, 2 * np.pi - 1e-3, N)
    exact = rad * CFG.full_circle / (2 * np.pi)
    assert_rounds_to_nearest(angle_codes(rad, CFG), exact, "angle codes")


def test_input_cartesian_components():
    """Cartesian components -> B fractional bits, rounded to nearest (Q.quantize)."""
    x = np.random.default_rng(34).uniform(-1, 1, N)
    assert_rounds_to_nearest(Q(1, CFG.frac_bits).quantize(x), x * CFG.one, "Q.quantize")


def test_shade_without_specular_is_zero_in_every_pixel():
    """Without the specular term the specular outputs are 0 in every pixel (the shape of
    the dots given) and the colour is the Phong sum of ambient and diffuse alone."""
    cfg = CFG.replace(specular=False)
    rng = np.random.default_rng(26)
    ndotl, ndoth = rng.integers(0, cfg.one + 1, (2, 40, 50))
    out = shade_fixed(ndotl, ndoth, cfg)
    for key in ("specular", "specular_fine"):
        assert out[key].shape == ndotl.shape and np.issubdtype(out[key].dtype, np.integer)
        assert not out[key].any(), key
    ka, kd, ks = phong_coefficients(cfg)
    exact = phong_exact(ka, kd, ks, out["diffuse_fine"], 0, cfg)
    assert out["color"].shape == ndotl.shape
    assert_rounds_to_nearest(out["color"], exact, "phong sum without specular")
