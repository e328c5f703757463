"""The bit-exact lee model (sim/golden/fixed/lee.py) against the float64 lee_corrected (the same
method, errata repaired) and against the exact reference: it tracks the former within a few
LSB and, at every width, stays far (max) from the latter (the error is in the geometry).

How closely the integer model tracks lee_corrected has no derived bound (the asin and T_prop
lookups are steep near 1 and feed a chain of further ROMs; test_light_equal_to_normal bounds
one link), so those numbers are regression pins (:data:`PINS`), the values measured by
``.venv/bin/python tests/sim/golden/fixed/test_lee.py``; re-measure them with it when a change
moves them on purpose.
"""

import json

import numpy as np
import pytest

from bumprtl.rtl.config import Config
from bumprtl.rtl.tables import lee_asin_index_bits, lee_prop_index_bits
from bumprtl.sim.golden.common import PixelInputs, to_8bit
from bumprtl.sim.golden.fixed.common import quantize_pixels
from bumprtl.sim.golden.fixed.lee import illuminate_fixed, rotate_fixed
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.lee import lee_corrected
from bumprtl.sim.golden.methods import METHODS, datapath_fixed
from bumprtl.sim.golden.vectors import TINY

CFG = Config(method="lee", angle_bits=12, frac_bits=13)   # k = 10, B = 13: the pins below
lee_fixed_model = METHODS["lee"].datapath_fixed     # rotation then illumination, bit-exact


def dequantize(codes, cfg):
    step = 2 * np.pi / cfg.full_circle
    return PixelInputs(**{f"{k[0]}_{k[2:]}": codes[k] * step for k in codes})


def steep_bound(cfg, index_bits):
    """Worst angle error (steps) of an asin or acos-like ROM lookup where it is steepest: an
    argument within ds of 1, ds = half an ulp of B bits plus half an address step, moves the
    angle by acos(1 - ds); plus one step for the table's and the result's roundings."""
    ds = 2.0 ** -(cfg.frac_bits + 1) + 2.0 ** -(index_bits + 1)
    return np.arccos(1 - ds) / (2 * np.pi / cfg.full_circle) + 1


def lsb_errors(fixed, result):
    return {f: np.abs(fixed[f] - to_8bit(getattr(result, f)).astype(np.int64))
            for f in ("diffuse", "specular", "color")}


def make_sample():
    px = PixelInputs.random(100_000, np.random.default_rng(2))
    codes = quantize_pixels(px, CFG)
    return px, codes, lee_fixed_model(codes, CFG)


@pytest.fixture(scope="module")
def sample():
    return make_sample()


WIDTHS = [(10, 9), (12, 13), (14, 18), (16, 24)]


def width_errors(angle_bits, frac_bits):
    """Max diffuse error (8-bit LSB) of the lee and exact datapaths and of float64
    lee_corrected against the exact reference, 20 000 random valid inputs (seed 3)."""
    px = PixelInputs.random(20_000, np.random.default_rng(3))
    reference = to_8bit(conventional(px, CFG).diffuse).astype(np.int64)
    errors = {}
    for method in ("lee", "exact"):
        cfg = CFG.replace(method=method, angle_bits=angle_bits, frac_bits=frac_bits)
        errors[method] = int(np.abs(datapath_fixed(quantize_pixels(px, cfg), cfg)["diffuse"]
                                    - reference).max())
    errors["float_lee"] = int(np.abs(to_8bit(lee_corrected(px, CFG).diffuse).astype(np.int64)
                                     - reference).max())
    return errors


def measure(sample=None):
    """Every pinned number of this file, as :data:`PINS` holds them."""
    px, codes, fixed = sample or make_sample()
    same = lsb_errors(fixed, lee_corrected(dequantize(codes, CFG), CFG))
    unq = lsb_errors(fixed, lee_corrected(px, CFG))["diffuse"]
    off = codes["l.theta"] != 1 << CFG.k
    return {"same_angles": {f: int(same[f].max()) for f in ("diffuse", "specular", "color")},
            "same_angles_diffuse_p99.9": float(np.percentile(same["diffuse"], 99.9)),
            "unquantized_off_horizon": int(unq[off].max()),
            "widths": {f"{a}-{b}": width_errors(a, b) for a, b in WIDTHS}}


# Regression pins (module docstring), measured by `.venv/bin/python tests/sim/golden/fixed/test_lee.py`.
PINS = {"same_angles": {"diffuse": 4, "specular": 9, "color": 3},
        "same_angles_diffuse_p99.9": 1.0,
        "unquantized_off_horizon": 7,
        "widths": {"10-9": {"lee": 203, "exact": 3, "float_lee": 202},
                   "12-13": {"lee": 202, "exact": 1, "float_lee": 202},
                   "14-18": {"lee": 202, "exact": 1, "float_lee": 202},
                   "16-24": {"lee": 202, "exact": 1, "float_lee": 202}}}


def test_tracks_float_lee_on_the_same_angles(sample):
    """10^5 random valid inputs, k = 10, B = 13, float64 lee_corrected evaluated at the angles the
    hardware sees: the maxima (diffuse, specular, whose cos^16 amplifies, and color) and the
    99.9th percentile of the diffuse error are regression pins (:data:`PINS`)."""
    _, codes, fixed = sample
    err = lsb_errors(fixed, lee_corrected(dequantize(codes, CFG), CFG))
    assert {f: int(err[f].max()) for f in PINS["same_angles"]} == PINS["same_angles"]
    assert np.percentile(err["diffuse"], 99.9) == PINS["same_angles_diffuse_p99.9"]


def test_tracks_float_lee_on_unquantized_inputs(sample):
    """Against lee_corrected on the unrounded inputs: the diffuse maximum is a regression pin
    (:data:`PINS`; rounding an input by half a step moves L' most where asin and T_prop are
    steepest), except where th_L rounds to exactly 90 deg. There the method itself is discontinuous (erratum 6's branch: the
    rigid circle meets the xz-plane at z = +-sqrt(1 - s^2) and th_L = 90 deg picks +), so
    rounding the input across it moves L' by tens of degrees in float64 as well."""
    px, codes, fixed = sample
    err = lsb_errors(fixed, lee_corrected(px, CFG))["diffuse"]
    on_horizon = codes["l.theta"] == 1 << CFG.k
    assert err[~on_horizon].max() == PINS["unquantized_off_horizon"]
    assert on_horizon.mean() < 1e-3 and err[on_horizon].max() > 50
    edge = px.subset(on_horizon).__dict__
    below, above = (PixelInputs(**{**edge, "l_theta": np.full_like(edge["l_theta"], np.pi / 2 + e)})
                    for e in (1e-9, -1e-9))
    jump = np.abs(to_8bit(lee_corrected(below, CFG).diffuse).astype(int)
                  - to_8bit(lee_corrected(above, CFG).diffuse).astype(int))
    assert jump.max() > 50                                  # the float64 method jumps too


@pytest.mark.parametrize("angle_bits, frac_bits", WIDTHS)
def test_no_width_removes_the_geometric_error(angle_bits, frac_bits):
    """At every width the lee datapath's distance from the exact reference (max diffuse) is
    float64 lee_corrected's, give or take its rounding: both are regression pins
    (:data:`PINS`), while the exact datapath at the same width stays within its derived
    bound (sim/golden/fixed/exact.predicted_error_bound_lsb)."""
    errors = width_errors(angle_bits, frac_bits)
    exact_cfg = CFG.replace(method="exact", angle_bits=angle_bits, frac_bits=frac_bits)
    assert errors["exact"] <= METHODS["exact"].predicted_error_bound_lsb(exact_cfg)
    assert errors == PINS["widths"][f"{angle_bits}-{frac_bits}"]


def test_rotation_depends_on_the_azimuth_difference_only():
    """k = 2, all 16^4 inputs: (ph_A', th_A') is a function of (ph_A - ph_N, th_A, th_N)
    (what lets tests/rtl/test_lee.py walk 16^3 classes in make test)."""
    cfg = TINY.replace(method="lee")
    idx = np.arange(16 ** 4)
    a_phi, a_theta, n_phi, n_theta = ((idx >> (4 * j)) & 15 for j in range(4))
    full = rotate_fixed(a_phi, a_theta, n_phi, n_theta, cfg)
    moved = rotate_fixed((a_phi - n_phi) & 15, a_theta, 0, n_theta, cfg)
    assert all(np.array_equal(f, g) for f, g in zip(full, moved, strict=False))


def test_light_equal_to_normal():
    """L = N for every (ph, th) with th in [0, 180] deg: y = 0, so ph' is 0 or 180 deg (erratum
    3's 0/0 and the sign of Z) and th' = |Z| (erratum 5) is only asin's rounding error, also
    above 90 deg (erratum 6). That error peaks where asin is steepest: s within ds of 1, ds =
    half an ulp of s plus half an asin-address step, gives acos(1 - ds) plus half a step."""
    cfg = CFG
    phi, theta = np.meshgrid(np.arange(0, cfg.full_circle, 8), np.arange((1 << (cfg.k + 1)) + 1))
    assert steep_bound(cfg, lee_asin_index_bits(cfg)) < 15     # 1.3 deg at k = 10, B = 13
    out_phi, out_theta = rotate_fixed(phi, theta, phi, theta, cfg)
    assert out_theta.max() <= steep_bound(cfg, lee_asin_index_bits(cfg))
    assert set(np.unique(out_phi)) <= {0, 1 << (cfg.k + 1)}


def test_illumination_is_the_exact_dot_product():
    """Eq. 24 with erratum 2 is an identity: N'.A' equals the Cartesian dot product of the
    two polar directions within 2 LSB of B bits on random codes, and N' = A' gives 1.0."""
    cfg = CFG
    rng = np.random.default_rng(4)
    a_phi, b_phi = rng.integers(0, cfg.full_circle, (2, 10_000))
    a_theta, b_theta = rng.integers(0, (1 << (cfg.k + 1)) + 1, (2, 10_000))
    step = 2 * np.pi / cfg.full_circle

    def unit(phi, theta):
        return np.stack([np.sin(theta * step) * np.cos(phi * step),
                         np.sin(theta * step) * np.sin(phi * step), np.cos(theta * step)])

    dot = np.sum(unit(a_phi, a_theta) * unit(b_phi, b_theta), axis=0)
    assert np.abs(illuminate_fixed(a_phi, a_theta, b_phi, b_theta, cfg) - dot * cfg.one).max() <= 2
    assert np.abs(illuminate_fixed(a_phi, a_theta, a_phi, a_theta, cfg) - cfg.one).max() <= 1


def test_saturated_reciprocal_gives_quarter_turns():
    """N = +z and D = 90 or 270 deg: s = sin th cos D = 0, so Z = 0 while y = sin th sin D != 0.
    1/sin Z saturates near 2**k (erratum 8), so ph' misses D by atan(1 / (2**k sin th)): its
    effect on any dot product, times sin th' = sin th, stays below 2**-k rad plus a step, and
    from th = 45 deg on ph' is D within one step. th' = 90 T_prop[sin th] is th_A within T_prop's
    steep-end bound."""
    cfg = CFG
    q, step = 1 << cfg.k, 2 * np.pi / cfg.full_circle
    theta = np.arange(1, q)
    for d in (q, 3 * q):
        phi, out_theta = rotate_fixed(np.full_like(theta, d), theta, 0, 0, cfg)
        miss = np.abs(phi - d) * step
        assert np.max(miss * np.sin(theta * step)) <= 2.0 ** -cfg.k + step
        assert np.abs(phi - d)[theta >= q // 2].max() <= 1
        assert np.abs(out_theta - theta).max() <= steep_bound(cfg, lee_prop_index_bits(cfg))


if __name__ == "__main__":
    print(json.dumps(measure(), indent=1))


def test_polar_illumination_reports_the_dots_its_shades_come_from():
    """Lee's illumination (the polar back end) reports N'.L and N'.H: the dots its diffuse
    and specular were made from (the back end again on them gives the same shades), and
    N'.H follows float64's N'.H."""
    from bumprtl.sim.golden.fixed.common import shade_fixed
    from bumprtl.sim.golden.methods import encode_pixels
    cfg = Config(method="lee")
    px = PixelInputs.random(5000, np.random.default_rng(3))
    out = datapath_fixed(encode_pixels(px, cfg), cfg)
    again = shade_fixed(out["ndotl"], out["ndoth"], cfg)
    for k in ("diffuse", "specular", "color"):
        assert np.array_equal(again[k], out[k]), k
    assert np.corrcoef(out["ndoth"], conventional(px, cfg).ndoth)[0, 1] > 0.9
