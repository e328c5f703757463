import numpy as np
import pytest

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.common import shade
from bumprtl.sim.golden.measure import angle_error_deg, compare, error_by_theta_n, random_pixels


def test_angle_error_is_accurate_for_tiny_and_large_angles():
    theta = np.array([0.3, 0.3, 0.3])
    other = theta + np.array([1e-9, 0.5, np.pi - 0.6])
    got = angle_error_deg((np.zeros(3), theta), (np.zeros(3), other))
    assert np.allclose(got, np.degrees(other - theta), rtol=1e-6, atol=0)


def test_compare_counts_nan_instead_of_averaging_it():
    cfg = Config()
    ref = shade(np.array([0.5, 0.5, 0.5, 0.5]), np.zeros(4), cfg)
    res = shade(np.array([0.5, np.nan, 0.5 + 2 / 255, 0.5]), np.zeros(4), cfg)
    s = compare(res, ref)["diffuse_lsb"]
    assert s["nan"] == 1 and s["max"] == pytest.approx(2.0) and s["mean"] == pytest.approx(2 / 3)


def test_theta_n_bins_partition_the_pixels():
    rows = error_by_theta_n("lee_corrected", n=5000, seed=3, step_deg=30)
    assert [r[0] for r in rows] == list(range(0, 180, 30))
    assert sum(r[2] for r in rows) == 5000


@pytest.mark.parametrize("call, word", [
    (lambda: random_pixels(0, 1), "samples"),
    (lambda: random_pixels(10, -1), "seed"),
    (lambda: error_by_theta_n(step_deg=7), "step_deg"),
])
def test_bad_parameters_are_named(call, word):
    with pytest.raises(BumpError, match=word):
        call()
