"""Peercy (Cartesian TBN + normalization) and Kim (polar dot products, Lee eqs 3-4):
both exact in float64, so both must equal the Cartesian reference to rounding."""

import numpy as np
import pytest

from bumprtl.sim.golden.common import PixelInputs, polar_to_cartesian, tangent_rotation
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.kim import kim, polar_dot
from bumprtl.sim.golden.float.peercy import peercy, tbn_frame
from bumprtl.sim.golden.measure import angle_error_deg


@pytest.fixture(scope="module")
def random_pixels():
    return PixelInputs.random(100_000, np.random.default_rng(2025))


@pytest.mark.parametrize("model", [peercy, kim])
def test_agrees_with_conventional_on_1e5_random(model, random_pixels):
    ref, res = conventional(random_pixels), model(random_pixels)
    for field in ("ndotl", "ndoth", "diffuse", "specular", "color"):
        assert np.max(np.abs(getattr(res, field) - getattr(ref, field))) < 1e-9, field
    assert np.max(angle_error_deg(res.l_prime, ref.l_prime)) < 1e-6


def test_tbn_rows_are_the_tangent_frame():
    """T, B, N are the rows of M = R_y(-th_N) R_z(-ph_N); N is the world normal itself."""
    rng = np.random.default_rng(4)
    phi, theta = rng.uniform(0, 2 * np.pi, 1000), rng.uniform(0, np.pi, 1000)
    t, b, n = tbn_frame(phi, theta)
    assert np.allclose(np.stack([t, b, n], -2), tangent_rotation(phi, theta), atol=1e-15)
    assert np.allclose(n, polar_to_cartesian(phi, theta), atol=1e-15)


def test_peercy_normalizes_the_transformed_vectors(monkeypatch):
    """The normalization step matters only when the transformed vector is not unit: scale
    the frame by 2 and the shading must not change."""
    from bumprtl.sim.golden.float import peercy as module
    monkeypatch.setattr(module, "tbn_frame", lambda p, t: tuple(2.0 * r for r in tbn_frame(p, t)))
    px = PixelInputs.random(1000, np.random.default_rng(6))
    assert np.max(np.abs(module.peercy(px).ndotl - conventional(px).ndotl)) < 1e-12


def test_polar_dot_is_the_cartesian_dot_product():
    """Lee eqs (3)-(4) / (22)-(23): cos th_a cos th_b + sin th_a sin th_b cos(ph_a - ph_b)."""
    rng = np.random.default_rng(8)
    a_phi, b_phi = rng.uniform(0, 2 * np.pi, (2, 1000))
    a_theta, b_theta = rng.uniform(0, np.pi, (2, 1000))
    want = np.einsum("...i,...i", polar_to_cartesian(a_phi, a_theta), polar_to_cartesian(b_phi, b_theta))
    assert np.max(np.abs(polar_dot(a_phi, a_theta, b_phi, b_theta) - want)) < 1e-14
