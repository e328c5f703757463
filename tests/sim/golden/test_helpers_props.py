"""The golden helpers' contracts from their docstrings: measure.py's validators (each
boundary accepted, one past refused, the parameter named), its summaries and the
proportion's worst case as the maximum of the stated function; stress.py's payload-width
check at both ends of a signed and an unsigned field, float_stats' counts, the azimuth turn;
vectors.py's edge rows; the method registry's lookups; Peercy's isqrt against math.isqrt."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bumprtl.rtl.config import BumpError, Config, ConfigError
from bumprtl.sim.golden.common import PixelInputs, shade
from bumprtl.sim.golden.float.conventional import conventional

# --- measure.py --------------------------------------------------------------------------------

def test_random_pixels_takes_integers_from_1_and_seeds_from_0():
    from bumprtl.sim.golden.measure import random_pixels
    assert len(random_pixels(1, 0)) == 1 and len(random_pixels(np.int64(3), np.int64(0))) == 3
    a, b = random_pixels(5, 7), PixelInputs.random(5, np.random.default_rng(7))
    assert np.array_equal(a.l_theta, b.l_theta) and np.array_equal(a.n_phi, b.n_phi)
    for n, msg in ((0, "samples = 0 is out of range: allowed integers >= 1"),
                   (2.0, "samples = 2.0 is out of range: allowed integers >= 1"),
                   (-3, "samples = -3 is out of range: allowed integers >= 1")):
        with pytest.raises(BumpError) as e:
            random_pixels(n, 1)
        assert str(e.value) == msg
    for seed in (-1, 1.0):
        with pytest.raises(BumpError) as e:
            random_pixels(3, seed)
        assert str(e.value) == f"seed = {seed!r} is out of range: allowed integers >= 0"


def test_theta_bins_take_exactly_the_divisors_of_180():
    """step_deg: an integer dividing 180 (1 and 180 included); 180 is one bin of every pixel,
    1 degree 180 bins, each pixel in the bin of its th_N."""
    from bumprtl.sim.golden.measure import error_by_theta_n, random_pixels
    rows = error_by_theta_n("lee_corrected", n=400, seed=4, step_deg=180)
    assert [(r[0], r[1], r[2]) for r in rows] == [(0, 180, 400)]
    rows = error_by_theta_n("lee_corrected", n=400, seed=4, step_deg=1)
    deg = np.degrees(random_pixels(400, 4).n_theta)
    for lo, hi, count, _ in rows:
        assert hi == lo + 1 and count == int(np.sum((deg >= lo) & (deg < hi))) > 0
    assert sum(r[2] for r in rows) == 400
    for bad in (0, 7, 360, 30.0, -30):
        with pytest.raises(BumpError) as e:
            error_by_theta_n(n=10, step_deg=bad)
        assert str(e.value) == f"step_deg = {bad!r} is out of range: allowed divisors of 180"


def test_summaries_count_nan_and_take_mean_p99_max_of_the_rest():
    from bumprtl.sim.golden.measure import compare
    cfg = Config()
    ref = shade(np.full(101, 0.5), np.zeros(101), cfg)
    x = 0.5 + np.arange(101) / 255.0
    x[3] = np.nan
    s = compare(shade(np.minimum(x, 1.0), np.zeros(101), cfg), ref)["diffuse_lsb"]
    finite = np.delete(np.minimum(x, 1.0), 3)
    err = np.abs(finite - 0.5) * 255
    assert s["nan"] == 1 and s["max"] == pytest.approx(err.max()) and s["mean"] == pytest.approx(err.mean())
    assert s["p99"] == pytest.approx(np.percentile(err, 99))
    allnan = compare(shade(np.full(4, np.nan), np.zeros(4), cfg), shade(np.zeros(4), np.zeros(4), cfg))
    assert allnan["diffuse_lsb"]["nan"] == 4 and math.isnan(allnan["diffuse_lsb"]["max"])


def test_proportion_worst_case_is_the_maximum_of_the_linear_proportions_error():
    """max over th_xz, th_yz in [0, 90] of |th_xz + (90 - th_xz) th_yz / 90 - acos(cos th_xz
    cos th_yz)| (degrees): no random point exceeds it, and a finer grid only adds a little;
    it is 0 on the edges (th_yz = 0 or th_xz = 90, where the proportion is exact)."""
    from bumprtl.sim.golden.measure import proportion_worst_case_deg
    f = lambda a, b: np.degrees(np.abs(a + (np.pi / 2 - a) * b / (np.pi / 2) - np.arccos(np.cos(a) * np.cos(b))))
    worst = proportion_worst_case_deg()
    rng = np.random.default_rng(1)
    a, b = rng.uniform(0, np.pi / 2, (2, 200_000))
    assert f(a, b).max() <= worst + 1e-6
    assert worst - 1e-3 <= f(a, b).max()
    coarse = proportion_worst_case_deg(steps=181)
    assert coarse <= worst and worst - coarse < 0.01
    edge = np.linspace(0, np.pi / 2, 50)
    assert f(edge, 0 * edge).max() < 1e-12 and f(np.pi / 2 + 0 * edge, edge).max() < 1e-12


def test_error_at_theta_n_drops_the_pixels_whose_light_is_under_the_surface():
    """th_N replaced, then only the pixels with N.L' > 0.02 kept: at th_N = 0 that is
    cos th_L > 0.02."""
    from bumprtl.sim.golden.measure import error_at_theta_n, random_pixels
    out = error_at_theta_n("lee_corrected", 0.0, n=2000, seed=3)
    keep = int(np.sum(np.cos(random_pixels(2000, 3).l_theta) > 0.02))
    # at th_N = 0 Lee's rigid circle is exact: the L' error is the proportion's alone
    from bumprtl.sim.golden.measure import proportion_worst_case_deg
    assert out["l_prime_deg"]["nan"] == 0
    assert 0.9 * proportion_worst_case_deg() <= out["l_prime_deg"]["max"] <= proportion_worst_case_deg() + 1e-6
    from bumprtl.sim.golden import measure
    sizes = []
    real = measure.compare
    try:
        measure.compare = lambda res, ref: sizes.append(res.diffuse.size) or real(res, ref)
        measure.error_at_theta_n("lee_corrected", 0.0, n=2000, seed=3)
    finally:
        measure.compare = real
    assert sizes == [keep]


# --- stress.py ---------------------------------------------------------------------------------

def test_payload_width_check_accepts_both_ends_and_refuses_one_past():
    """A signed field of width w holds [-2**(w-1), 2**(w-1) - 1], an unsigned one
    [0, 2**w - 1]: check_fixed counts exactly the pixels one past either end."""
    from bumprtl.sim.golden.methods import datapath_fixed
    from bumprtl.sim.golden.stress import check_fixed, payload_fields
    cfg = Config()
    fields = payload_fields(cfg)
    signed = next(k for k, (w, s) in fields.items() if s)
    unsigned = next(k for k, (w, s) in fields.items() if not s)
    px = PixelInputs.random(6, np.random.default_rng(2))
    for name in (signed, unsigned):
        w, s = fields[name]
        lo, hi = (-(1 << (w - 1)), (1 << (w - 1)) - 1) if s else (0, (1 << w) - 1)

        def model(codes, cfg, name=name, lo=lo, hi=hi):
            out = datapath_fixed(codes, cfg)
            out[name] = np.array([lo, hi, lo - 1, hi + 1, hi + 1, 0])
            return out
        got = check_fixed(model, px, cfg)["overflow"]
        assert got[name] == 3, name
        assert sum(got.values()) == 3


def test_float_stats_counts_nan_and_out_of_range_and_measures_the_rest():
    """NaN pixels (any field NaN) are counted and left out of the errors; a diffuse,
    specular or colour outside [0, 1], or an infinite dot, counts as out of range."""
    from bumprtl.sim.golden.common import Result
    from bumprtl.sim.golden.stress import float_stats
    z = np.zeros(6)
    ref = Result(z, z, np.full(6, 0.5), z, np.full(6, 0.5))
    diffuse = np.array([0.5, np.nan, 1.5, 0.5 + 3 / 255, 0.5, 0.5])
    ndoth = np.array([0, 0, 0, 0, np.inf, 0.0])
    color = np.array([0.5, 0.5, 0.5, 0.5, 0.5, -0.2])
    res = Result(z, ndoth, diffuse, z, color)
    s = float_stats(res, ref)
    assert s["nan"] == 1 and s["overflow"] == 3
    assert s["diffuse_max_lsb"] == 127 and s["color_max_lsb"] == 128
    allnan = float_stats(Result(z, z, np.full(6, np.nan), z, z), ref)
    assert allnan["nan"] == 6 and allnan["diffuse_max_lsb"] is None and allnan["color_max_lsb"] is None


def test_turning_the_scene_in_azimuth_moves_n_l_h_and_keeps_n_prime():
    from bumprtl.sim.golden.stress import rotate_azimuth
    px = PixelInputs.random(500, np.random.default_rng(3))
    for delta in (0.3, -1.0, 2 * np.pi):
        t = rotate_azimuth(px, delta)
        for v in ("n", "l", "h"):
            got, was = getattr(t, f"{v}_phi"), getattr(px, f"{v}_phi")
            d = np.mod(got - was - delta + np.pi, 2 * np.pi) - np.pi
            assert np.allclose(d, 0, atol=1e-12) and got.min() >= 0 and got.max() < 2 * np.pi
            assert np.array_equal(getattr(t, f"{v}_theta"), getattr(px, f"{v}_theta"))
        assert np.array_equal(t.b_phi, px.b_phi) and np.array_equal(t.b_theta, px.b_theta)
        assert np.allclose(conventional(t).ndotl, conventional(px).ndotl, atol=1e-12)


# --- vectors.py --------------------------------------------------------------------------------

def test_edge_rows_hold_l_equal_to_n_grazing_and_h_half_way():
    """Each (N, N') combination gets L = N, L at 90 degrees azimuth on the equator
    (grazing), and H the code half way between L and N; N' azimuth 7 ph_N + th_N' mod full
    (after the corners, which lead)."""
    from bumprtl.sim.golden.vectors import corner_codes, edge_codes
    cfg = Config(angle_bits=10)
    c, corners = edge_codes(cfg), corner_codes(cfg)
    m = len(corners["n.phi"])
    assert all(np.array_equal(c[k][:m], v) for k, v in corners.items())
    c = {k: v[m:] for k, v in c.items()}
    full, q = cfg.full_circle, cfg.full_circle // 4
    n = len(c["n.phi"])
    assert n == 6 * 7 * 3 * 5 and all(len(v) == n and v.dtype == np.int32 for v in c.values())
    rows = np.arange(n).reshape(-1, 5)
    same = rows[:, 0]
    assert np.array_equal(c["l.phi"][same], c["n.phi"][same]) and np.array_equal(c["l.theta"][same], c["n.theta"][same])
    graze = rows[:, 1]
    assert np.all(c["l.theta"][graze] == q) and np.array_equal(c["l.phi"][graze], (c["n.phi"][graze] + q) % full)
    assert np.array_equal(c["h.theta"], (c["l.theta"] + c["n.theta"]) // 2)
    assert np.array_equal(c["h.phi"], (c["l.phi"] + c["n.phi"]) // 2 % full)
    assert np.array_equal(c["b.phi"], (c["n.phi"] * 7 + c["b.theta"]) % full)
    assert set(c["b.theta"].tolist()) == {0, q // 3, q - 1}


def test_payloads_take_the_keys_asked_and_a_zero_bit_tag():
    from bumprtl.sim.golden.vectors import as_payloads, random_codes
    cfg = Config(tag_bits=0)
    codes = random_codes(5, cfg, seed=3)
    p = as_payloads(codes, cfg, keys=["l.phi", "h.theta"])
    assert [sorted(x) for x in p] == [["h.theta", "l.phi", "tag"]] * 5
    assert [x["tag"] for x in p] == [0] * 5 and [x["l.phi"] for x in p] == codes["l.phi"].tolist()


# --- methods.py --------------------------------------------------------------------------------

def test_the_registry_names_an_unknown_method_and_hides_no_dunder():
    from bumprtl.sim.golden.methods import MODELS, get
    with pytest.raises(ConfigError) as e:
        get("phong")
    assert "method" in str(e.value) and "phong" in str(e.value)
    m = get("exact")
    assert m is MODELS["exact"] and m.title == __import__("bumprtl.rtl.methods", fromlist=["get"]).get("exact").title
    assert not hasattr(m, "__no_such_thing__")


# --- fixed/peercy.py: isqrt --------------------------------------------------------------------

@settings(max_examples=300, deadline=None)
@given(st.integers(0, (1 << 62) - 1))
def test_isqrt_is_math_isqrt_below_2_62(x):
    """floor(sqrt(x)) exactly: x, and the square of its root and the last integer below
    the next square (the two ends where the float64 estimate may be off by one)."""
    from bumprtl.sim.golden.fixed.peercy import isqrt
    r = math.isqrt(x)
    xs = [x, r * r, min((r + 1) ** 2 - 1, (1 << 62) - 1)]
    assert isqrt(np.array(xs)).tolist() == [math.isqrt(v) for v in xs]


def test_isqrt_at_the_top_of_its_range_and_every_small_value():
    """Exact at the squares nearest 2**62 (where float64 cannot hold x) and for every
    x below 2**16."""
    from bumprtl.sim.golden.fixed.peercy import isqrt
    top = (1 << 31) - 1
    x = np.array([top * top - 1, top * top, top * top + 1, (1 << 62) - 1, (1 << 62) - 2])
    assert isqrt(x).tolist() == [math.isqrt(int(v)) for v in x]
    small = np.arange(1 << 16)
    assert isqrt(small).tolist() == [math.isqrt(int(v)) for v in small]


# --- every refusal's whole message ---------------------------------------------------------------

def test_refusals_name_the_parameter_the_value_and_what_is_allowed():
    """The searches' channel, the quantizer, the palette size and the memory image's level
    count: each message whole (a regex match would let text be added around it)."""
    from bumprtl.sim.golden.accuracy import adversarial_pixels, worst_case_pixels
    from bumprtl.sim.golden.fixed.pipeline import map_words
    from bumprtl.sim.golden.float.palette import quantize_normal_map
    from bumprtl.sim.golden.float.palette_quantize import check_palette_size
    from bumprtl.sim.golden.methods import datapath_fixed
    from bumprtl.sim.scenes.config import load_scene_config
    cfg = Config()
    for call in (lambda: adversarial_pixels(cfg, candidates=10, keep=2, channel="blend"),
                 lambda: worst_case_pixels(datapath_fixed, cfg, "blend", candidates=10, keep=2)):
        with pytest.raises(BumpError) as e:
            call()
        assert str(e.value) == "channel must be one of diffuse, specular, color, got 'blend'"
    normals = np.tile([0.0, 0.0, 1.0], (4, 4, 1))
    with pytest.raises(BumpError) as e:
        quantize_normal_map(normals, 16, "octree")
    assert str(e.value) == "quantizer must be one of median-cut, kmeans, got 'octree'"
    for size in (15, 16385, 16.0, False):
        with pytest.raises(BumpError) as e:
            check_palette_size(size)
        assert str(e.value) == f"palette_size must be an integer in [16, 16384], got {size!r}"
    scene = load_scene_config("default", {"texture_size": 16, "mip_levels": 2})
    with pytest.raises(ValueError) as e:
        map_words([np.zeros((16, 16))], scene)
    assert str(e.value) == "1 levels given, the scene has 2"


def test_stress_directions_are_uniform_in_azimuth_and_drawn_apart():
    """The hemisphere cases' uniform directions: N' (drawn in the tangent frame) has its
    azimuth uniform over the circle; the azimuth-wrap case draws ph_L, ph_H and ph_N' each
    on its own (different offsets from the seam)."""
    from bumprtl.sim.golden.stress import stress_case
    for name in ("theta_n_zero", "grazing", "below_horizon", "l_equals_n"):
        px = stress_case(name, 4000, seed=3)
        b = px.b_phi
        assert abs(np.mean(np.cos(b))) < 0.05 and abs(np.mean(np.sin(b))) < 0.05, name
        assert abs(np.mean(b < np.pi / 2) - 0.25) < 0.03, name
    w = stress_case("azimuth_wrap", 2000, seed=4)
    seam = lambda phi: np.minimum(phi, 2 * np.pi - phi)
    offsets = [seam(getattr(w, f)) for f in ("l_phi", "h_phi", "b_phi")]
    for i in range(3):
        for j in range(i + 1, 3):
            assert abs(np.corrcoef(offsets[i], offsets[j])[0, 1]) < 0.1, (i, j)
