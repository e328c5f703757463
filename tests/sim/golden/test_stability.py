"""Numerical stability of the golden models under stress (sim/golden/stress.py): no NaN, no
overflow of any payload field, error bounds held on degenerate geometry, and symmetry: the
scene turned in azimuth shades the same."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import to_8bit
from bumprtl.sim.golden.fixed.common import quantize_pixels
from bumprtl.sim.golden.fixed.exact import predicted_error_bound_lsb
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.exact import exact
from bumprtl.sim.golden.float.lee import lee_corrected, lee_printed
from bumprtl.sim.golden.methods import PER_PIXEL, datapath_fixed
from bumprtl.sim.golden.stress import (
    CASES,
    check_fixed,
    float_stats,
    payload_fields,
    rotate_azimuth,
    stress_case,
)
from bumprtl.sim.traffic import PATTERNS

N = 400
cases = st.sampled_from(sorted(CASES))
seeds = st.integers(0, 2**32 - 1)
exponents = st.sampled_from([1, 2, 16, 255, 1024])
FEW = settings(max_examples=40)


def _outputs8(result):
    return np.stack([to_8bit(getattr(result, k)).astype(np.int64) for k in ("diffuse", "specular", "color")])


def test_cases_are_what_they_say():
    """The generators build the geometry they name (checked in world Cartesian terms)."""
    from bumprtl.sim.golden.common import polar_to_cartesian
    dot = lambda a, b: np.einsum("...i,...i", polar_to_cartesian(*a), polar_to_cartesian(*b))
    px = stress_case("l_equals_n", 200)
    assert np.allclose(dot((px.l_phi, px.l_theta), (px.n_phi, px.n_theta)), 1)
    px = stress_case("grazing", 200)
    assert np.allclose(dot((px.l_phi, px.l_theta), (px.n_phi, px.n_theta)), 0, atol=1e-12)
    px = stress_case("below_horizon", 200)
    assert (dot((px.l_phi, px.l_theta), (px.n_phi, px.n_theta)) < 0).all()
    assert (stress_case("theta_n_zero", 50).n_theta == 0).all()
    assert (stress_case("theta_180", 50).n_theta == np.pi).all()
    res = conventional(stress_case("saturation", 200), Config())
    assert set(np.round(res.ndotl, 12)) == {-1.0, 1.0}
    wrap = stress_case("azimuth_wrap", 200)
    assert (np.abs(np.sin(wrap.n_phi)) < 0.03).all() and (np.abs(np.sin(wrap.l_phi)) < 0.03).all()


def test_cases_keep_n_prime_a_bump_normal():
    """N' is a bump normal: every case but grid_extremes (all angles at the grid's ends, on
    purpose) draws it in the upper tangent hemisphere (th_N' <= 90 deg), as a bump map holds
    it; and the cases that put H above the surface (all but below_horizon and saturation's
    -N half) keep N.H >= 0 with it, so each case stresses only the one edge it names."""
    from bumprtl.sim.golden.common import polar_to_cartesian
    dot = lambda a, b: np.einsum("...i,...i", polar_to_cartesian(*a), polar_to_cartesian(*b))
    for name in sorted(CASES):
        px = stress_case(name, 300, seed=5)
        if name != "grid_extremes":
            assert px.b_theta.max() <= np.pi / 2 + 1e-12, name
        if name not in ("grid_extremes", "below_horizon", "saturation"):
            assert dot((px.h_phi, px.h_theta), (px.n_phi, px.n_theta)).min() >= -1e-12, name


@given(case=cases, seed=seeds, n=exponents)
def test_exact_and_conventional_never_nan_or_out_of_range(case, seed, n):
    cfg = Config(spec_exponent=n)
    px = stress_case(case, N, seed)
    ref = conventional(px, cfg)
    for model in (conventional, exact, lee_corrected):
        stats = float_stats(model(px, cfg), ref)
        assert stats["nan"] == 0 and stats["overflow"] == 0, (model.__name__, stats)


@given(case=cases, seed=seeds, n=exponents)
def test_float_exact_matches_reference_within_1_lsb(case, seed, n):
    cfg = Config(spec_exponent=n)
    px = stress_case(case, N, seed)
    assert np.abs(_outputs8(exact(px, cfg)) - _outputs8(conventional(px, cfg))).max() <= 1


@given(case=cases, seed=seeds, delta=st.floats(0, 2 * np.pi))
def test_azimuth_rotation_changes_exact_by_at_most_1_lsb(case, seed, delta):
    cfg = Config()
    px = stress_case(case, N, seed)
    diff = _outputs8(exact(rotate_azimuth(px, delta), cfg)) - _outputs8(exact(px, cfg))
    assert np.abs(diff).max() <= 1


@FEW
@given(case=cases, seed=seeds, steps=st.integers(0, 4095), method=st.sampled_from(PER_PIXEL))
def test_azimuth_rotation_by_whole_steps_is_bit_exact_invariant(case, seed, steps, method):
    """Only D = ph_A - ph_N enters (eqs 5-6): turning every azimuth by whole angle steps
    must leave every output bit of the fixed-point models unchanged."""
    cfg = Config(method=method)
    px = stress_case(case, N, seed)
    turned = rotate_azimuth(px, steps * 2 * np.pi / cfg.full_circle)
    a = datapath_fixed(quantize_pixels(px, cfg), cfg)
    b = datapath_fixed(quantize_pixels(turned, cfg), cfg)
    for k in ("diffuse", "specular", "color"):
        assert np.array_equal(a[k], b[k]), k


@FEW
@given(case=cases, seed=seeds, n=exponents)
def test_fixed_exact_no_overflow_and_within_bound(case, seed, n):
    cfg = Config(spec_exponent=n)
    res = check_fixed(datapath_fixed, stress_case(case, N, seed), cfg)
    assert sum(res["overflow"].values()) == 0, res["overflow"]
    assert res["diffuse_lsb"].max() <= predicted_error_bound_lsb(cfg)


@FEW
@given(case=cases, seed=seeds)
def test_fixed_lee_no_overflow(case, seed):
    """lee's error is geometric (erratum 7), but no field may leave its width."""
    res = check_fixed(datapath_fixed, stress_case(case, N, seed), Config(method="lee"))
    assert sum(res["overflow"].values()) == 0, res["overflow"]
    assert res["diffuse_lsb"].max() <= 255


@pytest.mark.parametrize("method", PER_PIXEL)
def test_overflow_check_can_fail(method):
    """check_fixed flags a value outside its payload width (a model that overflows)."""
    cfg = Config(method=method)
    name, (width, signed) = next(iter(payload_fields(cfg).items()))

    def broken(codes, cfg):
        out = datapath_fixed(codes, cfg)
        out[name] = out[name] + (1 << width)
        return out

    res = check_fixed(broken, stress_case("random", 50), cfg)
    assert res["overflow"][name] == 50


def test_printed_lee_nan_is_counted():
    """The printed equations (errata 3, 4) give NaN; float_stats counts, not hides, them."""
    px = stress_case("below_horizon", 500)
    res = lee_printed(px, Config())
    stats = float_stats(res, conventional(px, Config()))
    assert stats["nan"] >= int(np.isnan(res.ndotl).sum()) > 0


def test_pipeline_stimulus_reaches_the_datapath():
    """The pipeline golden model on the stress stimulus equals the datapath model on the
    same codes: every N' went through the map to its pixel."""
    from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
    from bumprtl.sim.golden.stress import pipeline_stimulus, stress_codes
    from bumprtl.sim.scenes.config import load_scene_config
    scene = load_scene_config("default")
    n = scene.texture_size ** 2 + 100
    inputs, words = pipeline_stimulus(scene, n, seed=2)
    codes = stress_codes(n, scene.config, seed=2)
    texel = np.arange(n) % scene.texture_size ** 2
    codes = {**codes, "b.phi": codes["b.phi"][texel], "b.theta": codes["b.theta"][texel]}
    want = datapath_fixed(codes, scene.config)
    got = pipeline_fixed(inputs, scene, words)
    for k in ("diffuse", "specular", "color"):
        assert np.array_equal(got[k], want[k]), k


@pytest.mark.regress
def test_pipeline_1e6_stress_vectors_verilator(build_dir):
    """10^6 stress vectors (all cases) through the emitted pipeline on Verilator, 250k per
    traffic pattern, bit-exact against the pipeline golden model, in order (bulk path)."""
    from bumprtl.gen.render.rtl import run_pipeline_bulk
    from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
    from bumprtl.sim.golden.stress import pipeline_stimulus
    from bumprtl.sim.scenes.config import load_scene_config
    scene = load_scene_config("default")
    inputs, words = pipeline_stimulus(scene, 250_000, seed=9)
    patterns = list(PATTERNS)
    outs, _, _ = run_pipeline_bulk(scene, inputs, words, None, None, "verilator", build_dir,
                                   patterns=patterns)
    want = pipeline_fixed(inputs, scene, words)
    for pattern in patterns:
        assert np.array_equal(outs[pattern]["tag"], inputs["tag"]), pattern
        for k, v in want.items():
            assert np.array_equal(outs[pattern][k], v), (pattern, k)
