"""The smaller builders of sim/golden/accuracy.py against the properties their docstrings
claim, computed here from the angles: _tilted/_around put a vector at the stated angle
from N' (its cosine uniform in the stated interval), on_grid is the hardware's view (the
model cannot tell the two apart), the error measures are |fixed - round(255 x float64)|,
the blend reference is its formula, scene_error's PSNR and maximum are those of the
covered pixels, and the crater map's normals are its height field's."""

import numpy as np
import pytest

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.accuracy import (
    _around,
    _tilted,
    crater_scene,
    diffuse_error_lsb,
    grid_errors_lsb,
    on_grid,
    reference_blend,
    scene_error,
    term_errors_lsb,
)
from bumprtl.sim.golden.common import PixelInputs, polar_to_cartesian, shade, to_8bit
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.methods import datapath_fixed, encode_pixels

CFG = Config()
STEP = 2 * np.pi / CFG.full_circle
FIELDS = ("n_phi", "n_theta", "l_phi", "l_theta", "h_phi", "h_theta", "b_phi", "b_theta")


def _units(n, rng):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def test_tilted_puts_the_vector_at_the_angle_asked_and_turns_it_about_the_axis():
    """The result is a unit vector whose cosine with nw is cos_a; turning by t1 and t2
    gives two vectors whose parts perpendicular to nw are t2 - t1 apart; nw = +-z (where
    the helper axis changes) too."""
    rng = np.random.default_rng(1)
    h = np.sqrt(0.5)
    nw = np.concatenate([_units(300, rng), [[0, 0, 1.0], [0, 0, -1.0], [0, 0.3, np.sqrt(0.91)], [h, 0, h], [-h, 0, -h]]])
    n = len(nw)
    a = rng.uniform(0, np.pi, n)
    t1, t2 = rng.uniform(0, 2 * np.pi, (2, n))
    v1 = polar_to_cartesian(*_tilted(nw, np.cos(a), np.sin(a), t1))
    v2 = polar_to_cartesian(*_tilted(nw, np.cos(a), np.sin(a), t2))
    for v in (v1, v2):
        assert np.allclose(np.einsum("ni,ni->n", v, nw), np.cos(a), atol=1e-12)
    p1 = v1 - np.cos(a)[:, None] * nw
    p2 = v2 - np.cos(a)[:, None] * nw
    big = np.sin(a) > 0.1
    cos_turn = np.einsum("ni,ni->n", p1, p2)[big] / np.sin(a[big]) ** 2
    assert np.allclose(cos_turn, np.cos(t2 - t1)[big], atol=1e-9)
    # the turn has a sense: (p1 x p2) points along nw by sin(t2 - t1)
    sin_turn = np.einsum("ni,ni->n", np.cross(p1, p2), nw)[big] / np.sin(a[big]) ** 2
    hand = sin_turn * np.sin(t2 - t1)[big]
    assert np.allclose(np.abs(sin_turn), np.abs(np.sin(t2 - t1)[big]), atol=1e-9)
    assert np.all(hand > -1e-9) or np.all(hand < 1e-9)           # one sense for every nw


@pytest.mark.parametrize("lo, hi", [(0.02, 0.6), (0.75, 1.0), (-0.5, 0.5)])
def test_around_draws_the_cosine_uniformly_in_the_interval(lo, hi):
    """_around: the cosine with nw uniform in [cos_lo, cos_hi] (mean the middle, a quarter
    below the first quarter point), in a uniform direction around it."""
    rng = np.random.default_rng(2)
    nw = _units(20_000, rng)
    v = polar_to_cartesian(*_around(nw, lo, hi, rng))
    c = np.einsum("ni,ni->n", v, nw)
    assert c.min() >= lo - 1e-12 and c.max() <= hi + 1e-12
    assert abs(c.mean() - (lo + hi) / 2) < 0.01 * (hi - lo) + 1e-3
    assert abs(np.mean(c < lo + (hi - lo) / 4) - 0.25) < 0.015


def test_on_grid_moves_each_angle_at_most_half_a_step_and_the_model_cannot_tell():
    """The angles the hardware receives: each on the grid (code x step), within half a
    step of the input (theta clipped to [0, pi]); the fixed-point model gives the same
    outputs on both."""
    px = PixelInputs.random(3000, np.random.default_rng(3))
    g = on_grid(px, CFG)
    for f in FIELDS:
        x, y = getattr(px, f), getattr(g, f)
        k = y / STEP
        assert np.allclose(k, np.rint(k), atol=1e-9), f
        d = np.abs(x - y)
        if f.endswith("phi"):
            d = np.minimum(d, 2 * np.pi - d)
        assert d.max() <= STEP / 2 + 1e-12, f
    a, b = datapath_fixed(encode_pixels(px, CFG), CFG), datapath_fixed(encode_pixels(g, CFG), CFG)
    for k in ("diffuse", "specular", "color", "ndotl", "ndoth"):
        assert np.array_equal(a[k], b[k]), k
    ends = PixelInputs(**{f: np.array([0.0, np.pi if f.endswith("theta") else 2 * np.pi]) for f in FIELDS})
    e = on_grid(ends, CFG)
    assert e.n_theta.tolist() == [0.0, np.pi] and e.n_phi.tolist() == [0.0, 0.0]


def test_error_measures_are_the_distance_to_float64_rounded_to_8_bits():
    """term_errors_lsb: |fixed - round(255 x float64)| per channel on the inputs given,
    diffuse_error_lsb its diffuse part; grid_errors_lsb the same on on_grid's angles, and
    None for the Cartesian methods."""
    px = PixelInputs.random(2000, np.random.default_rng(4))
    out = datapath_fixed(encode_pixels(px, CFG), CFG)
    ref = conventional(px, CFG)
    got = term_errors_lsb(datapath_fixed, px, CFG)
    assert sorted(got) == ["color", "diffuse", "specular"]
    for k in got:
        want = np.abs(out[k].astype(int) - to_8bit(getattr(ref, k)).astype(int))
        assert np.array_equal(got[k], want), k
        assert want.max() == 1, k                # the default is faithful and not exact
    assert np.array_equal(diffuse_error_lsb(datapath_fixed, px, CFG), got["diffuse"])
    grid = grid_errors_lsb(datapath_fixed, px, CFG)
    gref = conventional(on_grid(px, CFG), CFG)
    for k in grid:
        want = np.abs(out[k].astype(int) - to_8bit(getattr(gref, k)).astype(int))
        assert np.array_equal(grid[k], want), k
    assert not np.array_equal(grid["diffuse"], got["diffuse"])
    for method in ("peercy", "ernst"):
        assert grid_errors_lsb(datapath_fixed, px, Config(method=method)) is None


def test_reference_blend_is_the_lit_texel_plus_the_highlight():
    """255 clamp(tex / 255 min(1, ka + kd sum d_j) + ks sum s_j), rounded, d_j =
    clamp(N'.L_j): worked here for two lights, and without specular (ks not added)."""
    cfg = Config(ka=0.25, kd=0.5, ks=0.5, spec_exponent=2)
    r1 = shade(np.array([0.5, -0.2, 1.0, 0.9]), np.array([0.5, 0.0, 1.0, -1.0]), cfg)
    r2 = shade(np.array([0.1, 0.4, 1.0, 0.9]), np.array([0.0, 0.2, 1.0, 0.0]), cfg)
    tex = {"r": np.array([255, 100, 10, 200]), "g": np.array([0, 51, 0, 255]), "b": np.array([128, 128, 128, 128])}
    lit = np.array([0.25 + 0.5 * 0.6, 0.25 + 0.5 * 0.4, 1.0, 1.0])          # min(1, ...)
    spec = np.array([0.25, 0.04, 2.0, 0.0])                                 # sum h**2
    got = reference_blend([r1, r2], tex, cfg)
    for c in "rgb":
        want = np.rint(255 * np.clip(tex[c] / 255 * lit + 0.5 * spec, 0, 1))
        assert got[c].tolist() == want.tolist(), c
    plain = Config(ka=0.25, kd=0.5, ks=0.5, specular=False)
    got = reference_blend([shade(r1.ndotl, r1.ndoth, plain)], tex, plain)
    assert got["r"].tolist() == np.rint(tex["r"] * np.minimum(1, 0.25 + 0.5 * np.clip(r1.ndotl, 0, 1))).tolist()


def test_scene_error_is_psnr_and_max_over_the_covered_pixels():
    """A model equal to float64 rounded gives no PSNR (identical) and 0; one off by 1 LSB
    on every covered pixel gives 10 log10(255**2) dB and 1, whatever it does elsewhere."""
    from bumprtl.sim.scenes import load_scene
    scene = load_scene("bumps", size=32, geometry="sphere")
    ref = to_8bit(conventional(scene.px, CFG).color).astype(np.int64)
    assert scene.mask.any() and not scene.mask.all()
    same = scene_error(scene, CFG, lambda codes, cfg: {"color": np.where(scene.mask, ref, 77)})
    assert same == {"psnr_db": None, "max_lsb": 0}
    sign = np.where(ref[scene.mask] > 0, -1, 1)
    flip = np.zeros_like(ref)
    flip[scene.mask] = sign
    got = scene_error(scene, CFG, lambda codes, cfg: {"color": np.where(scene.mask, ref + flip, 0)})
    assert got == {"psnr_db": round(10 * np.log10(255.0 ** 2), 2), "max_lsb": 1}
    two = scene_error(scene, CFG, lambda codes, cfg: {"color": np.where(scene.mask, ref + 2 * flip, 0)})
    assert two["max_lsb"] == 2 and two["psnr_db"] == pytest.approx(got["psnr_db"] - 20 * np.log10(2), abs=0.01)


def test_crater_scene_is_the_bumps_plane_with_its_own_heights_normals():
    """The bumps scene's N, L, H and coverage; N' fetched from the crater map (px.b ==
    map[v, u]); the map's normals tilt down the height field's central-difference slope,
    all by the same strength per unit of normalized height; the field wraps (a crater
    across an edge goes on at the other), so the seam is no steeper than the inside."""
    from bumprtl.sim.scenes import load_scene
    size = 64
    sc = crater_scene(size=size)
    base = load_scene("bumps", size=size)
    assert sc.name == "craters" and sc.height.shape == (size, size)
    for f in ("n_phi", "n_theta", "l_phi", "l_theta", "h_phi", "h_theta"):
        assert np.array_equal(getattr(sc.px, f), getattr(base.px, f)), f
    assert np.array_equal(sc.mask, base.mask)
    assert np.array_equal(sc.px.b_phi, sc.b_phi_map[sc.v, sc.u])
    assert np.array_equal(sc.px.b_theta, sc.b_theta_map[sc.v, sc.u])
    h = (sc.height - sc.height.min()) / np.ptp(sc.height)
    dh_du = (np.roll(h, -1, 1) - np.roll(h, 1, 1)) / 2
    dh_dv = (np.roll(h, -1, 0) - np.roll(h, 1, 0)) / 2
    n = polar_to_cartesian(sc.b_phi_map, sc.b_theta_map)
    steep = np.hypot(dh_du, dh_dv) > 1e-3
    strength_v = -n[..., 0][steep] / n[..., 2][steep] / np.where(dh_dv[steep] == 0, np.nan, dh_dv[steep])
    strength_u = -n[..., 1][steep] / n[..., 2][steep] / np.where(dh_du[steep] == 0, np.nan, dh_du[steep])
    s = np.concatenate([strength_u, strength_v])
    s = s[np.isfinite(s) & (np.abs(np.concatenate([dh_du[steep], dh_dv[steep]])) > 1e-3)]
    assert s.size > 100 and s.min() > 0 and np.ptp(s) < 1e-6 * s.max()
    inner = max(np.abs(np.diff(sc.height, axis=a)).max() for a in (0, 1))
    seam = max(np.abs(sc.height[0] - sc.height[-1]).max(), np.abs(sc.height[:, 0] - sc.height[:, -1]).max())
    assert seam <= inner
    # a bowl and a rim each: the field goes below and above its zero level
    assert sc.height.min() < 0 < sc.height.max()
    assert not np.array_equal(crater_scene(size=size, seed=1).height, sc.height)


def _sensitivity(px, field, angles):
    """sum over ``angles`` of |d(255 x float64 ``field``)/d angle| (central differences)."""
    keys = {f: getattr(px, f) for f in FIELDS}
    total = 0.0
    for name in angles:
        hi = np.pi if name.endswith("theta") else 2 * np.pi
        up = PixelInputs(**{**keys, name: np.clip(keys[name] + 1e-6, 0, hi)})
        dn = PixelInputs(**{**keys, name: np.clip(keys[name] - 1e-6, 0, hi)})
        total = total + np.abs(getattr(conventional(up, CFG), field) - getattr(conventional(dn, CFG), field)) * 255 / 2e-6
    return total


def test_adversarial_pixels_keep_the_most_sensitive_unclamped_candidates():
    """Step 1: the kept pixels are where 255 N'.L' is not clamped (N'.L' in (0.02, 0.98),
    up to the half step they moved) and most sensitive to its six angles: their summed
    |slope| beats 95 % of random valid unclamped pixels."""
    from bumprtl.sim.golden.accuracy import ANGLES_OF, adversarial_pixels
    keep = 20
    px = adversarial_pixels(CFG, candidates=4000, keep=keep, seed=12, channel="diffuse").subset(slice(0, keep))
    d = conventional(px, CFG).ndotl
    assert d.min() > 0.02 - 0.01 and d.max() < 0.98 + 0.01
    ref = PixelInputs.random(4000, np.random.default_rng(13))
    r = conventional(ref, CFG).ndotl
    ref = ref.subset((r > 0.02) & (r < 0.98))
    angles = ANGLES_OF["diffuse"]
    assert np.median(_sensitivity(px, "ndotl", angles)) > np.quantile(_sensitivity(ref, "ndotl", angles), 0.95)


def test_adversarial_specular_pixels_sit_inside_the_highlight_slope():
    """For specular the kept pixels have 255 cos^n strictly inside (0.5, 254.5) (up to the
    half step they moved) and N'.H' close to 1 (cos^n has a slope only there)."""
    from bumprtl.sim.golden.accuracy import adversarial_pixels
    keep = 20
    px = adversarial_pixels(CFG, candidates=4000, keep=keep, seed=14, channel="specular").subset(slice(0, keep))
    s = 255 * conventional(px, CFG).specular
    assert s.min() > 0.3 and s.max() < 254.7
    assert conventional(px, CFG).ndoth.min() > 1 - 4 / CFG.spec_exponent


def test_arithmetic_pixels_put_h_on_the_grid_point_nearest_n_prime_and_its_neighbours():
    """Step 1-2: in the middle block H is the grid point nearest world N' (each of its
    angles within half a step of N''s); block (dt, dp) has H dt steps off in theta and dp in
    phi (theta clipped to [0, pi], phi wrapping); N and N' on the grid with N' in the upper
    tangent hemisphere."""
    from bumprtl.sim.golden.accuracy import arithmetic_pixels
    from bumprtl.sim.golden.common import cartesian_to_polar, world_bump_normal
    keep, reach = 10, 2
    px = arithmetic_pixels(datapath_fixed, CFG, candidates=1000, keep=keep, seed=8, reach=reach)
    side = 2 * reach + 1
    blocks = [px.subset(slice(i * keep, (i + 1) * keep)) for i in range(side * side)]
    mid = blocks[reach * side + reach]
    w_phi, w_theta = cartesian_to_polar(world_bump_normal(mid.n_phi, mid.n_theta, mid.b_phi, mid.b_theta))
    assert np.abs(mid.h_theta - w_theta).max() <= STEP / 2 + 1e-9
    dphi = np.abs(mid.h_phi - w_phi)
    assert np.minimum(dphi, 2 * np.pi - dphi).max() <= STEP / 2 + 1e-9
    for i, blk in enumerate(blocks):
        dt, dp = i // side - reach, i % side - reach
        want_t = np.clip(np.rint(mid.h_theta / STEP) + dt, 0, CFG.full_circle // 2)
        want_p = (np.rint(mid.h_phi / STEP) + dp) % CFG.full_circle
        assert np.array_equal(np.rint(blk.h_theta / STEP), want_t), (dt, dp)
        assert np.array_equal(np.rint(blk.h_phi / STEP), want_p), (dt, dp)
        for f in ("n_phi", "n_theta", "b_phi", "b_theta"):
            assert np.array_equal(getattr(blk, f), getattr(mid, f)), f
    assert px.b_theta.max() <= np.pi / 2


def test_arithmetic_pixels_keep_the_n_prime_whose_error_stays_whatever_h():
    """Step 1: the kept N' have the largest mean model error of N'.H' over H at the grid
    point nearest N' and its four neighbours: larger than that of most random N' so
    placed."""
    from bumprtl.sim.golden.accuracy import arithmetic_pixels
    keep, reach = 10, 1
    px = arithmetic_pixels(datapath_fixed, CFG, candidates=3000, keep=keep, seed=9, reach=reach)
    side = 2 * reach + 1
    m = keep * side * side
    grid = px.subset(slice(0, m))

    def dot_error(p):
        return datapath_fixed(encode_pixels(p, CFG), CFG)["ndoth"] / CFG.one - conventional(p, CFG).ndoth
    err = dot_error(grid).reshape(side, side, keep)
    persistent = np.abs(err[reach, reach] + err[reach - 1, reach] + err[reach + 1, reach]
                        + err[reach, reach - 1] + err[reach, reach + 1])
    # random N, N' on the grid with H the grid point nearest N' and its 4 neighbours
    from bumprtl.sim.golden.common import cartesian_to_polar, world_bump_normal
    rng = np.random.default_rng(10)
    n, full = 3000, CFG.full_circle
    c = {"n_phi": rng.integers(0, full, n), "n_theta": rng.integers(0, full // 2 + 1, n),
         "b_phi": rng.integers(0, full, n), "b_theta": rng.integers(0, full // 4 + 1, n)}
    ang = {k: v * STEP for k, v in c.items()}
    hp, ht = cartesian_to_polar(world_bump_normal(ang["n_phi"], ang["n_theta"], ang["b_phi"], ang["b_theta"]))
    total = 0
    for dt, dp in ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)):
        t = np.clip(np.rint(ht / STEP) + dt, 0, full // 2) * STEP
        p = ((np.rint(hp / STEP) + dp) % full) * STEP
        total = total + dot_error(PixelInputs(**ang, h_phi=p, h_theta=t, l_phi=p, l_theta=t))
    assert np.median(persistent) > np.quantile(np.abs(total), 0.99)


def test_steep_pixels_of_a_small_exponent_keep_h_above_the_bump():
    """n < 4: 1 - 4 / n is below 0, so N'.H is drawn uniformly in [0, 1] (H never below
    N'), L unmoved for the specular channel."""
    from bumprtl.sim.golden.accuracy import steep_pixels
    from bumprtl.sim.golden.common import world_bump_normal
    cfg = Config(spec_exponent=2)
    px = steep_pixels(4000, np.random.default_rng(6), cfg, "specular")
    nw = world_bump_normal(px.n_phi, px.n_theta, px.b_phi, px.b_theta)
    c = np.einsum("ni,ni->n", nw, polar_to_cartesian(px.h_phi, px.h_theta))
    assert c.min() >= -1e-12 and c.max() <= 1 + 1e-12
    assert abs(c.mean() - 0.5) < 0.02 and np.quantile(c, 0.02) < 0.05


def test_a_crater_is_a_continuous_bowl_with_a_raised_rim():
    """One crater (count = 1, the same centre and radius at any size): its height field is
    continuous, so doubling the resolution halves the largest step between neighbouring
    texels; it goes below the plain (the bowl) and above it by a tenth of that depth or
    more (a raised rim)."""
    steps = []
    for size in (64, 128, 256):
        h = crater_scene(size=size, seed=5, count=1).height
        steps.append(max(np.abs(h - np.roll(h, 1, a)).max() for a in (0, 1)))
        assert h.min() < 0 and h.max() > 0.1 * -h.min()
    assert steps[0] / steps[1] > 1.6 and steps[1] / steps[2] > 1.6, steps


def test_a_craters_bowl_is_round_on_the_torus():
    """One crater's bowl (where the height is below the plain) is a disc around its lowest
    point, the map wrapping at its edges: as many rows as columns across (within a texel),
    and the area of a disc of that diameter (within 15 %)."""
    size = 256
    for seed in (5, 6, 7):
        h = crater_scene(size=size, seed=seed, count=1).height
        i, j = np.unravel_index(np.argmin(h), h.shape)
        bowl = np.roll(h, (size // 2 - i, size // 2 - j), axis=(0, 1)) < 0
        rows, cols = np.nonzero(bowl.any(1))[0], np.nonzero(bowl.any(0))[0]
        across_v, across_u = np.ptp(rows) + 1, np.ptp(cols) + 1
        assert abs(across_v - across_u) <= 1, (seed, across_v, across_u)
        assert abs(bowl.sum() / (np.pi * across_u ** 2 / 4) - 1) < 0.15, seed


def test_arithmetic_pixels_keep_errors_of_both_polarities():
    """Step 1 keeps the largest errors by magnitude, so N' whose model overshoots N'.H' and
    N' whose model falls short are both kept (the search aims at the arithmetic error in
    either direction): each polarity is at least a quarter of the kept N'."""
    from bumprtl.sim.golden.accuracy import arithmetic_pixels
    keep = 40
    mid = arithmetic_pixels(datapath_fixed, CFG, candidates=2000, keep=keep, seed=3, reach=0)
    mid = mid.subset(slice(0, keep))
    err = datapath_fixed(encode_pixels(mid, CFG), CFG)["ndoth"] / CFG.one - conventional(mid, CFG).ndoth
    assert np.mean(err < 0) >= 0.25 and np.mean(err > 0) >= 0.25, err
