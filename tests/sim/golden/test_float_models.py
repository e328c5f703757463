"""Float64 references checked against each other and against closed forms."""

import numpy as np
import pytest
from hypothesis import given, strategies as st

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.common import PixelInputs, polar_to_cartesian
from bumprtl.sim.golden.conventional import conventional
from bumprtl.sim.golden.models import FLOAT_MODELS

EXACT_MODELS = ["exact", "peercy", "kim"]   # exact in float64: must equal the reference


@pytest.fixture(scope="module")
def random_pixels():
    return PixelInputs.random(100_000, np.random.default_rng(2024))


@pytest.mark.parametrize("method", EXACT_MODELS)
def test_agrees_with_conventional_on_1e5_random(method, random_pixels):
    ref = conventional(random_pixels)
    res = FLOAT_MODELS[method](random_pixels)
    assert np.max(np.abs(res.ndotl - ref.ndotl)) < 1e-9
    assert np.max(np.abs(res.ndoth - ref.ndoth)) < 1e-9
    assert np.max(np.abs(res.color - ref.color)) < 1e-9


def test_conventional_closed_forms():
    """N' = +z (flat bump): N'.L' is N.L in world space; N = +z: tangent frame = world."""
    rng = np.random.default_rng(5)
    px = PixelInputs.random(1000, rng)
    flat = PixelInputs(**{**px.__dict__, "b_phi": np.zeros(1000), "b_theta": np.zeros(1000)})
    n, l = polar_to_cartesian(px.n_phi, px.n_theta), polar_to_cartesian(px.l_phi, px.l_theta)
    assert np.allclose(conventional(flat).ndotl, np.einsum("ij,ij->i", n, l), atol=1e-12)
    up = PixelInputs(**{**px.__dict__, "n_phi": np.zeros(1000), "n_theta": np.zeros(1000)})
    b = polar_to_cartesian(px.b_phi, px.b_theta)
    assert np.allclose(conventional(up).ndotl, np.einsum("ij,ij->i", b, l), atol=1e-12)


angle = st.floats(0.0, 2 * np.pi)
polar = st.floats(0.0, np.pi)
edge_theta = st.sampled_from([0.0, np.pi / 2, np.pi, 1e-9, np.pi - 1e-9])


@st.composite
def edge_pixels(draw):
    """Inputs on the edges: th_N = 0, L = N, grazing light, light below the world horizon,
    D = ph_A - ph_N wrapping past 360 degrees, theta = 180 degrees."""
    n_phi, n_theta = draw(angle), draw(st.one_of(edge_theta, polar))
    kind = draw(st.sampled_from(["l_eq_n", "grazing", "below", "wrap", "any"]))
    l_phi, l_theta = draw(angle), draw(st.one_of(edge_theta, polar))
    if kind == "l_eq_n":
        l_phi, l_theta = n_phi, n_theta
    elif kind == "grazing":
        l_theta = np.pi / 2
    elif kind == "below":
        l_theta = draw(st.floats(np.pi / 2, np.pi))
    elif kind == "wrap":
        n_phi, l_phi = draw(st.floats(6.0, 2 * np.pi)), draw(st.floats(0.0, 0.3))
    b_phi, b_theta = draw(angle), draw(st.one_of(edge_theta, polar))
    one = lambda v: np.array([v])
    return PixelInputs(one(n_phi), one(n_theta), one(l_phi), one(l_theta),
                       one(draw(angle)), one(draw(st.one_of(edge_theta, polar))),
                       one(b_phi), one(b_theta))


@given(edge_pixels())
def test_exact_equals_conventional_on_edges(px):
    ref, res = conventional(px), FLOAT_MODELS["exact"](px)
    assert np.all(np.isfinite(res.ndotl)) and np.all(np.isfinite(res.ndoth))
    assert abs(res.ndotl[0] - ref.ndotl[0]) < 1e-9
    assert abs(res.ndoth[0] - ref.ndoth[0]) < 1e-9


@pytest.mark.parametrize("field, value, words", [
    ("l_theta", 4.0, ["l_theta", "[0, pi]"]),
    ("n_phi", -0.1, ["n_phi", "[0, 2*pi]"]),
    ("b_phi", np.nan, ["b_phi", "NaN"]),
])
def test_bad_angles_are_named(field, value, words):
    args = {f: np.zeros(3) for f in ("n_phi", "n_theta", "l_phi", "l_theta", "h_phi",
                                     "h_theta", "b_phi", "b_theta")}
    args[field] = np.array([0.0, value, 0.0])
    with pytest.raises(BumpError) as e:
        PixelInputs(**args)
    for w in words:
        assert w in str(e.value)


def test_bad_shapes_and_dtypes_are_named():
    good = {f: np.zeros(3) for f in ("n_phi", "n_theta", "l_phi", "l_theta", "h_phi",
                                     "h_theta", "b_phi", "b_theta")}
    with pytest.raises(BumpError, match="h_theta has shape"):
        PixelInputs(**{**good, "h_theta": np.zeros(4)})
    with pytest.raises(BumpError, match="b_theta must be a real-valued array"):
        PixelInputs(**{**good, "b_theta": np.array(["a", "b", "c"])})


def test_specular_off_gives_zero_specular(random_pixels):
    res = conventional(random_pixels, Config(specular=False))
    assert not res.specular.any()
