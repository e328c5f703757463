"""The shared float64 API: the registry's contract, the Cartesian reference's closed forms,
input validation."""

import numpy as np
import pytest

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.common import PixelInputs, Result, polar_to_cartesian
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.models import FLOAT_MODELS

FIELDS = ("n_phi", "n_theta", "l_phi", "l_theta", "h_phi", "h_theta", "b_phi", "b_theta")


@pytest.mark.parametrize("name", sorted(FLOAT_MODELS))
def test_every_model_keeps_the_input_shape(name):
    """One signature for all: any array shape in, Results of that shape out."""
    px = PixelInputs.random(24, np.random.default_rng(1))
    grid = PixelInputs(**{f: getattr(px, f).reshape(4, 6) for f in FIELDS})
    res = FLOAT_MODELS[name](grid, Config())
    assert isinstance(res, Result)
    for field in ("ndotl", "ndoth", "diffuse", "specular", "color"):
        assert getattr(res, field).shape == (4, 6), field
    flat = FLOAT_MODELS[name](px, Config())
    assert np.array_equal(res.color.ravel(), flat.color, equal_nan=True)


def test_conventional_closed_forms():
    """N' = +z (flat bump): N'.L' is N.L in world space; N = +z: tangent frame = world."""
    px = PixelInputs.random(1000, np.random.default_rng(5))
    flat = PixelInputs(**{**px.__dict__, "b_phi": np.zeros(1000), "b_theta": np.zeros(1000)})
    n, l = polar_to_cartesian(px.n_phi, px.n_theta), polar_to_cartesian(px.l_phi, px.l_theta)
    assert np.allclose(conventional(flat).ndotl, np.einsum("ij,ij->i", n, l), atol=1e-12)
    up = PixelInputs(**{**px.__dict__, "n_phi": np.zeros(1000), "n_theta": np.zeros(1000)})
    b = polar_to_cartesian(px.b_phi, px.b_theta)
    assert np.allclose(conventional(up).ndotl, np.einsum("ij,ij->i", b, l), atol=1e-12)


def test_phong_sum_of_eq_2():
    px = PixelInputs.random(1000, np.random.default_rng(7))
    cfg = Config()
    res = conventional(px, cfg)
    want = np.clip(cfg.ka + cfg.kd * np.maximum(res.ndotl, 0)
                   + cfg.ks * np.maximum(res.ndoth, 0) ** cfg.spec_exponent, 0, 1)
    assert np.allclose(res.color, want, atol=1e-15)
    assert not conventional(px, Config(specular=False)).specular.any()


@pytest.mark.parametrize("field, value, words", [
    ("l_theta", 4.0, ["l_theta = 4 rad", "[0, pi]"]),          # the offending value named
    ("n_phi", -0.1, ["n_phi = -0.1 rad", "[0, 2*pi]"]),
    ("b_phi", np.nan, ["b_phi", "NaN"]),
])
def test_bad_angles_are_named(field, value, words):
    args = {f: np.zeros(3) for f in FIELDS}
    args[field] = np.array([0.0, value, 0.0])
    with pytest.raises(BumpError) as e:
        PixelInputs(**args)
    for w in words:
        assert w in str(e.value)


def test_bad_shapes_and_dtypes_are_named():
    good = {f: np.zeros(3) for f in FIELDS}
    with pytest.raises(BumpError, match="h_theta has shape"):
        PixelInputs(**{**good, "h_theta": np.zeros(4)})
    with pytest.raises(BumpError, match="b_theta must be a real-valued array"):
        PixelInputs(**{**good, "b_theta": np.array(["a", "b", "c"])})
