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


def _unit(phi_deg, theta_deg):
    p, t = np.radians(phi_deg), np.radians(theta_deg)
    return np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])


@pytest.mark.parametrize("method", ["lee_corrected", "lee_printed"])
def test_worst_pixel_is_the_largest_l_prime_error_of_the_sample(method):
    """worst_pixel's answer against its own sample recomputed here: the pixel it names is in
    the sample, its reference L' is L turned into N's tangent frame (R_y(-th_N) R_z(-ph_N),
    built here), its error the angle between the two L' it reports, and no pixel of the
    sample has a larger one; D = ph_L - ph_N mod 360."""
    from bumprtl.sim.golden.float.models import FLOAT_MODELS
    from bumprtl.sim.golden.measure import worst_pixel

    n, seed = 3000, 2
    w = worst_pixel(method, n=n, seed=seed)
    px = random_pixels(n, seed)
    i = np.flatnonzero(np.isclose(np.degrees(px.n_phi), w["N"][0], atol=1e-9)
                       & np.isclose(np.degrees(px.l_theta), w["L"][1], atol=1e-9))
    assert len(i) == 1
    i = int(i[0])
    assert w["N"] == pytest.approx((np.degrees(px.n_phi[i]), np.degrees(px.n_theta[i])), abs=1e-9)
    assert w["L"] == pytest.approx((np.degrees(px.l_phi[i]), np.degrees(px.l_theta[i])), abs=1e-9)
    assert w["D"] == pytest.approx((w["L"][0] - w["N"][0]) % 360, abs=1e-9)
    pn, tn = np.radians(w["N"])
    rz = np.array([[np.cos(pn), np.sin(pn), 0], [-np.sin(pn), np.cos(pn), 0], [0, 0, 1]])
    ry = np.array([[np.cos(tn), 0, -np.sin(tn)], [0, 1, 0], [np.sin(tn), 0, np.cos(tn)]])
    assert ry @ rz @ _unit(*w["L"]) == pytest.approx(_unit(*w["l_prime_ref"]), abs=1e-9)
    a, b = _unit(*w["l_prime"]), _unit(*w["l_prime_ref"])
    angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b))
    assert w["l_prime_deg"] == pytest.approx(angle, abs=1e-6) and angle > 0
    res = FLOAT_MODELS[method](px, Config())
    got = np.stack([np.sin(res.l_prime[1]) * np.cos(res.l_prime[0]),
                    np.sin(res.l_prime[1]) * np.sin(res.l_prime[0]), np.cos(res.l_prime[1])], -1)
    lx = np.stack([np.sin(px.l_theta) * np.cos(px.l_phi), np.sin(px.l_theta) * np.sin(px.l_phi),
                   np.cos(px.l_theta)], -1)
    ref = np.einsum("nij,nj->ni", np.stack([
        np.stack([np.cos(px.n_theta) * np.cos(px.n_phi), np.cos(px.n_theta) * np.sin(px.n_phi), -np.sin(px.n_theta)], -1),
        np.stack([-np.sin(px.n_phi), np.cos(px.n_phi), np.zeros(n)], -1),
        np.stack([np.sin(px.n_theta) * np.cos(px.n_phi), np.sin(px.n_theta) * np.sin(px.n_phi), np.cos(px.n_theta)], -1)],
        1), lx)
    err = np.degrees(np.arctan2(np.linalg.norm(np.cross(got, ref), axis=-1), np.einsum("ni,ni->n", got, ref)))
    assert np.nanmax(err) == pytest.approx(w["l_prime_deg"], abs=1e-6)
    b = np.array([np.sin(px.b_theta[i]) * np.cos(px.b_phi[i]), np.sin(px.b_theta[i]) * np.sin(px.b_phi[i]),
                  np.cos(px.b_theta[i])])                      # the bump normal N'
    assert w["diffuse_lsb"] == pytest.approx(255 * abs(res.diffuse[i] - np.clip(b @ ref[i], 0, 1)), abs=1e-6)
