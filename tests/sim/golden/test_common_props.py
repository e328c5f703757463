"""The shared float64 signature (sim/golden/common.py) against its docstrings: PixelInputs
refuses exactly what it says (every range end accepted, one float step past refused, the
field named), random valid pixels lie where the docstring puts them, the polar/Cartesian
conversions invert each other, the Phong back end clamps as eq. 2 says, to_8bit rounds
to nearest with NaN black."""

import numpy as np
import pytest

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.common import (
    PixelInputs,
    cartesian_to_polar,
    polar_to_cartesian,
    shade,
    tangent_rotation,
    to_8bit,
    world_bump_normal,
)

FIELDS = ("n_phi", "n_theta", "l_phi", "l_theta", "h_phi", "h_theta", "b_phi", "b_theta")


def _pixels(**changes):
    return PixelInputs(**{**{f: np.zeros(3) for f in FIELDS}, **changes})


@pytest.mark.parametrize("field", FIELDS)
def test_each_angle_range_end_is_accepted_and_one_step_past_refused(field):
    """theta in [0, pi], phi in [0, 2 pi], both ends inclusive; the next float past either
    end is refused, the message naming the field, the value and the allowed range."""
    hi, label = (np.pi, "pi") if field.endswith("theta") else (2 * np.pi, "2*pi")
    ok = _pixels(**{field: np.array([0.0, hi, hi / 2])})
    assert getattr(ok, field).tolist() == [0.0, hi, hi / 2]
    for bad in (np.nextafter(hi, 10.0), np.nextafter(0.0, -1.0), -1.0, hi + 1):
        with pytest.raises(BumpError) as e:
            _pixels(**{field: np.array([0.0, bad, 0.0])})
        assert str(e.value) == f"{field} = {bad:.6g} rad is out of range: allowed [0, {label}]"


def test_a_value_out_of_range_at_both_ends_names_the_negative_one():
    """Both ends broken at once: the message names the minimum (below 0) first."""
    with pytest.raises(BumpError, match=r"l_theta = -0\.5 rad"):
        _pixels(l_theta=np.array([-0.5, 4.0, 1.0]))


@pytest.mark.parametrize("bad, word", [(np.inf, "infinity"), (-np.inf, "infinity"), (np.nan, "NaN")])
def test_non_finite_angles_are_refused_by_name(bad, word):
    with pytest.raises(BumpError, match="h_phi contains NaN or infinity"):
        _pixels(h_phi=np.array([0.0, bad, 0.0]))


def test_integer_and_unsigned_arrays_become_float64_and_others_are_refused():
    """Real-valued arrays (float, int, unsigned) are stored as float64; bool, complex and
    strings are refused, naming the field and the dtype."""
    px = _pixels(n_phi=np.array([0, 1, 2], np.int32), n_theta=np.array([0, 1, 3], np.uint8),
                 b_theta=np.array([0.5, 1, 1.5], np.float32))
    for f in FIELDS:
        assert getattr(px, f).dtype == np.float64, f
    assert px.n_phi.tolist() == [0.0, 1.0, 2.0] and px.b_theta.tolist() == [0.5, 1.0, 1.5]
    for bad, dtype in ((np.array([True, False, True]), "bool"),
                       (np.array([0j, 1j, 0j]), "complex128")):
        with pytest.raises(BumpError) as e:
            _pixels(l_phi=bad)
        assert str(e.value) == f"l_phi must be a real-valued array, got dtype {dtype}"


def test_a_shape_unlike_n_phis_is_refused_naming_both():
    with pytest.raises(BumpError) as e:
        _pixels(b_phi=np.zeros((3, 1)))
    assert str(e.value) == "b_phi has shape (3, 1), expected (3,) like n_phi"


def test_empty_pixels_are_valid_and_scalars_too():
    """No pixel is no error (nothing out of range); 0-d arrays are one pixel."""
    empty = PixelInputs(**{f: np.zeros(0) for f in FIELDS})
    assert len(empty) == 0 and empty.shape == (0,)
    one = PixelInputs(**{f: 0.25 for f in FIELDS})
    assert one.shape == () and len(one) == 1


def test_subset_and_concat_keep_each_pixels_angles_together():
    rng = np.random.default_rng(3)
    a, b = PixelInputs.random(5, rng), PixelInputs.random(4, rng)
    both = PixelInputs.concat([a, b])
    assert len(both) == 9
    part = both.subset(slice(3, 7))
    for f in FIELDS:
        assert np.array_equal(getattr(part, f), np.concatenate([getattr(a, f)[3:], getattr(b, f)[:2]]))


def _cos(px, a, b):
    va = polar_to_cartesian(getattr(px, f"{a}_phi"), getattr(px, f"{a}_theta"))
    vb = polar_to_cartesian(getattr(px, f"{b}_phi"), getattr(px, f"{b}_theta"))
    return np.einsum("...i,...i", va, vb)


def test_random_valid_pixels_put_l_and_h_above_the_surface_and_n_prime_up():
    """valid: N' in the upper tangent hemisphere (th_N' <= 90 deg, its cosine uniform in
    [0, 1]) and N.L, N.H > 0.02 (the redraw's threshold), each uniform over that cap (the
    cosine uniform in (0.02, 1]: mean 0.51); N uniform on the sphere."""
    n = 20_000
    px = PixelInputs.random(n, np.random.default_rng(11))
    for v in ("l", "h"):
        c = _cos(px, "n", v)
        assert c.min() > 0.02, v
        assert abs(c.mean() - 0.51) < 0.01 and abs(np.mean(c < 0.265) - 0.25) < 0.015, v
    assert px.b_theta.max() <= np.pi / 2
    assert abs(np.cos(px.b_theta).mean() - 0.5) < 0.01
    assert abs(np.cos(px.n_theta).mean()) < 0.015 and abs(np.mean(np.cos(px.n_theta) > 0.5) - 0.25) < 0.015
    for f in ("n_phi", "l_phi", "h_phi", "b_phi"):
        x = getattr(px, f)
        assert x.min() >= 0 and x.max() < 2 * np.pi and abs(x.mean() - np.pi) < 0.05, f


def test_random_invalid_pixels_cover_the_whole_sphere():
    """valid=False: every direction uniform on the sphere (cosines uniform in [-1, 1])."""
    n = 20_000
    px = PixelInputs.random(n, np.random.default_rng(12), valid=False)
    for v in ("l", "h"):
        c = _cos(px, "n", v)
        assert abs(c.mean()) < 0.02 and abs(np.mean(c < 0) - 0.5) < 0.015
    assert abs(np.cos(px.b_theta).mean()) < 0.015 and np.mean(px.b_theta > np.pi / 2) > 0.48


def test_polar_and_cartesian_are_inverse_for_any_length():
    """(phi, theta) -> unit vector -> (phi, theta) is the identity (phi in [0, 2 pi));
    cartesian_to_polar ignores the length."""
    rng = np.random.default_rng(4)
    phi, theta = rng.uniform(0, 2 * np.pi, 2000), rng.uniform(0.01, np.pi - 0.01, 2000)
    v = polar_to_cartesian(phi, theta)
    assert np.allclose(np.linalg.norm(v, axis=-1), 1, atol=1e-15)
    assert np.allclose(v[:, 2], np.cos(theta)) and np.allclose(np.hypot(v[:, 0], v[:, 1]), np.sin(theta))
    for scale in (1.0, 1e-3, 7.5):
        p, t = cartesian_to_polar(scale * v)
        assert np.allclose(t, theta, atol=1e-12)
        d = np.abs(p - phi)
        assert np.all(np.minimum(d, 2 * np.pi - d) < 1e-12)
        assert p.min() >= 0 and p.max() <= 2 * np.pi
    # the axes: +x at phi 0, +y at 90 deg, -y at 270 deg, the poles at theta 0 and pi
    axes = np.array([[1.0, 0, 0], [0, 2.0, 0], [0, -3.0, 0], [0, 0, 4.0], [0, 0, -0.5]])
    p, t = cartesian_to_polar(axes)
    assert np.allclose(p[:3], [0, np.pi / 2, 3 * np.pi / 2]) and np.allclose(t, [np.pi / 2] * 3 + [0, np.pi])


def test_a_zero_vector_has_finite_angles_in_range():
    """A zero vector (no direction; cartesian_to_polar divides by the length only where
    it is not 0) gets finite angles in their ranges, which PixelInputs accepts."""
    p, t = cartesian_to_polar(np.zeros((2, 3)))
    assert np.all(np.isfinite(p)) and np.all(np.isfinite(t))
    assert p.min() >= 0 and p.max() < 2 * np.pi and t.min() >= 0 and t.max() <= np.pi


def test_the_tangent_rotation_is_a_rotation_taking_n_to_z_and_world_bump_normal_undoes_it():
    """M is orthonormal with det +1 and M N = +z; world_bump_normal = M^T N' so that
    M (world N') = N'."""
    rng = np.random.default_rng(5)
    px = PixelInputs.random(500, rng)
    m = tangent_rotation(px.n_phi, px.n_theta)
    eye = np.einsum("pij,pkj->pik", m, m)
    assert np.allclose(eye, np.eye(3), atol=1e-14) and np.allclose(np.linalg.det(m), 1)
    n = polar_to_cartesian(px.n_phi, px.n_theta)
    assert np.allclose(np.einsum("pij,pj->pi", m, n), [0, 0, 1], atol=1e-14)
    w = world_bump_normal(px.n_phi, px.n_theta, px.b_phi, px.b_theta)
    assert np.allclose(np.einsum("pij,pj->pi", m, w), polar_to_cartesian(px.b_phi, px.b_theta), atol=1e-14)
    # N' = +z in the tangent frame is N itself in the world
    up = world_bump_normal(px.n_phi, px.n_theta, np.zeros(500), np.zeros(500))
    assert np.allclose(up, n, atol=1e-14)


def test_shade_clamps_each_term_to_0_1_before_eq_2():
    """diffuse = clamp(N'.L, 0, 1), specular = clamp(N'.H, 0, 1)**n, colour = clamp(ka +
    kd diffuse + ks specular, 0, 1); the dots themselves are returned unclamped."""
    dots = np.array([-1.5, -0.2, 0.0, 0.3, 0.9, 1.0, 1.7])
    for cfg in (Config(spec_exponent=3), Config(spec_exponent=16), Config(ka=0.6, kd=0.9, ks=0.8)):
        r = shade(dots, dots[::-1], cfg, l_prime=("p", "t"))
        d, h = np.minimum(np.maximum(dots, 0), 1), np.minimum(np.maximum(dots[::-1], 0), 1)
        assert np.array_equal(r.ndotl, dots) and np.array_equal(r.ndoth, dots[::-1])
        assert np.array_equal(r.diffuse, d)
        assert np.allclose(r.specular, h ** cfg.spec_exponent, rtol=0, atol=0)
        assert np.allclose(r.color, np.minimum(cfg.ka + cfg.kd * d + cfg.ks * h ** cfg.spec_exponent, 1),
                           rtol=0, atol=1e-15)
        assert r.l_prime == ("p", "t")
    cfg = Config(specular=False)
    off = shade(dots, dots, cfg)
    assert np.array_equal(off.specular, np.zeros_like(dots))
    assert np.allclose(off.color, np.minimum(cfg.ka + cfg.kd * np.clip(dots, 0, 1), 1), rtol=0, atol=1e-15)


def test_to_8bit_rounds_every_code_to_nearest_and_clamps():
    """k / 255 -> k for every code, anything within 0.49 LSB of it too; below 0 -> 0,
    above 1 -> 255; NaN -> 0 (black); uint8, shape kept."""
    k = np.arange(256, dtype=np.float64)
    for off in (0.0, 0.49, -0.49):
        x = np.clip((k + off) / 255, -1, 2)
        got = to_8bit(x)
        assert got.dtype == np.uint8
        assert np.array_equal(got, k.astype(np.uint8)), off
    edge = np.array([[-0.3, -7.0, np.nan], [1.2, 9.0, 0.51 / 255]])
    assert to_8bit(edge).tolist() == [[0, 0, 0], [255, 255, 1]]
    assert to_8bit(0.6) == 153 and to_8bit(0.6).shape == ()
