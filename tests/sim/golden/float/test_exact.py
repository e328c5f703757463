"""The exact angular method (docs/architecture.md): every identity against explicit 3x3 rotation
matrices, agreement with the Cartesian reference on 10^5 random inputs and on the edges."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from bumprtl.sim.golden.common import PixelInputs, polar_to_cartesian, tangent_rotation
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.exact import exact, rotated_normal, vector_terms

N = 10_000


@pytest.fixture(scope="module")
def angles():
    rng = np.random.default_rng(11)
    return {k: rng.uniform(0, hi, N) for k, hi in
            (("n_phi", 2 * np.pi), ("n_theta", np.pi), ("a_phi", 2 * np.pi), ("a_theta", np.pi),
             ("b_phi", 2 * np.pi), ("b_theta", np.pi))}


def rot_y(t):
    """Rotation by +t about y, built entry by entry (independent of common.py)."""
    c, s, z, o = np.cos(t), np.sin(t), np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rot_z(t):
    c, s, z, o = np.cos(t), np.sin(t), np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def apply(m, v):
    return np.einsum("...ij,...j->...i", m, v)


def test_tangent_frame_is_ry_minus_theta_times_rz_minus_phi(angles):
    m = rot_y(-angles["n_theta"]) @ rot_z(-angles["n_phi"])
    assert np.allclose(tangent_rotation(angles["n_phi"], angles["n_theta"]), m, atol=1e-15)
    n = polar_to_cartesian(angles["n_phi"], angles["n_theta"])
    assert np.allclose(apply(m, n), [0, 0, 1], atol=1e-12)                  # M N = +z


def test_rotated_normal_is_ry_theta_n_applied_to_n_prime(angles):
    """n'' by product-to-sum (a = th_N' + ph_N', b = th_N' - ph_N') equals R_y(th_N) n'."""
    want = apply(rot_y(angles["n_theta"]), polar_to_cartesian(angles["b_phi"], angles["b_theta"]))
    got = np.stack(rotated_normal(angles["n_theta"], angles["b_phi"], angles["b_theta"]), -1)
    assert np.max(np.abs(got - want)) < 1e-14


def test_vector_terms_are_rz_minus_phi_n_applied_to_a(angles):
    """(p, y, cos th_A) with X = th_A + D, Y = th_A - D equals R_z(-ph_N) A."""
    want = apply(rot_z(-angles["n_phi"]), polar_to_cartesian(angles["a_phi"], angles["a_theta"]))
    got = np.stack(vector_terms(angles["a_phi"], angles["a_theta"], angles["n_phi"]), -1)
    assert np.max(np.abs(got - want)) < 1e-14


def test_dot_product_moves_the_rotation_onto_n_prime(angles):
    """N'.(M A) = (R_y(th_N) n').(R_z(-ph_N) A): the identity the method rests on."""
    b = polar_to_cartesian(angles["b_phi"], angles["b_theta"])
    a = polar_to_cartesian(angles["a_phi"], angles["a_theta"])
    lhs = np.einsum("...i,...i", b, apply(tangent_rotation(angles["n_phi"], angles["n_theta"]), a))
    rhs = np.einsum("...i,...i", apply(rot_y(angles["n_theta"]), b), apply(rot_z(-angles["n_phi"]), a))
    assert np.max(np.abs(lhs - rhs)) < 1e-14


def test_exact_agrees_with_conventional_on_1e5_random():
    px = PixelInputs.random(100_000, np.random.default_rng(2024))
    ref, res = conventional(px), exact(px)
    for field in ("ndotl", "ndoth", "diffuse", "specular", "color"):
        assert np.max(np.abs(getattr(res, field) - getattr(ref, field))) < 1e-9, field


def test_exact_agrees_with_conventional_on_invalid_inputs_too():
    """No valid-input assumption is hidden in the method: lights below the surface and N'
    in the lower hemisphere give the same signed dot products."""
    px = PixelInputs.random(20_000, np.random.default_rng(9), valid=False)
    ref, res = conventional(px), exact(px)
    assert np.max(np.abs(res.ndotl - ref.ndotl)) < 1e-9
    assert np.max(np.abs(res.ndoth - ref.ndoth)) < 1e-9


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
    ref, res = conventional(px), exact(px)
    assert np.all(np.isfinite(res.ndotl)) and np.all(np.isfinite(res.ndoth))
    assert abs(res.ndotl[0] - ref.ndotl[0]) < 1e-9
    assert abs(res.ndoth[0] - ref.ndoth[0]) < 1e-9
