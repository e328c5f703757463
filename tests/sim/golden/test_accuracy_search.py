"""The accuracy searches (sim/golden/accuracy.py) keep what their docstrings promise, on
small sets: where they put H and L (angles between vectors computed here from the polar
angles), how far off the angle grid each angle sits, and how many pixels of which kind
they return. The channel tests only check that the errors found stay under the bound, which
a weaker search passes too."""

import numpy as np
import pytest

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.accuracy import (
    ANGLES_OF,
    adversarial_pixels,
    arithmetic_pixels,
    highlight_pixels,
    steep_pixels,
    unrounded_lsb,
    worst_case_pixels,
)
from bumprtl.sim.golden.methods import datapath_fixed

CFG = Config()
STEP = 2 * np.pi / CFG.full_circle


def _unit(phi, theta):
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1)


def _world_bump(px):
    """N' turned out of N's tangent frame: R_z(ph_N) R_y(th_N) b."""
    b = _unit(px.b_phi, px.b_theta)
    ct, st, cp, sp = np.cos(px.n_theta), np.sin(px.n_theta), np.cos(px.n_phi), np.sin(px.n_phi)
    x = ct * b[:, 0] + st * b[:, 2]
    z = -st * b[:, 0] + ct * b[:, 2]
    return np.stack([cp * x - sp * b[:, 1], sp * x + cp * b[:, 1], z], -1)


def _cos(px, v):
    return np.einsum("ni,ni->n", _world_bump(px), _unit(getattr(px, f"{v}_phi"), getattr(px, f"{v}_theta")))


def _off_grid(x):
    """Distance of each angle from its nearest grid point, in grid steps."""
    return np.abs(x / STEP - np.rint(x / STEP))


def _interior(name, x):
    hi = np.pi if name.endswith("theta") else 2 * np.pi
    return (x > STEP) & (x < hi - STEP)


def test_highlight_pixels_put_h_within_4_over_sqrt_n_of_n_prime():
    n = 4000
    px = highlight_pixels(n, np.random.default_rng(1), CFG)
    angle = np.arccos(np.clip(_cos(px, "h"), -1, 1))
    limit = 4 / np.sqrt(CFG.spec_exponent)                   # 1 rad at n = 16
    assert angle.max() <= limit + 1e-9
    assert angle.max() > 0.98 * limit and abs(angle.mean() - limit / 2) < 0.03 * limit
    # L stays a random direction above the tangent plane (not moved with H)
    assert np.mean(_cos(px, "l") < 0.5) > 0.3
    wide = highlight_pixels(n, np.random.default_rng(1), Config(spec_exponent=2))
    assert np.arccos(np.clip(_cos(wide, "h"), -1, 1)).max() <= np.pi / 2 + 1e-9


@pytest.mark.parametrize("channel", ["diffuse", "specular", "color"])
def test_steep_pixels_place_l_and_h_where_the_slope_is_largest(channel):
    px = steep_pixels(3000, np.random.default_rng(2), CFG, channel)
    random = steep_pixels(3000, np.random.default_rng(2), CFG, "none")
    ch, cl = _cos(px, "h"), _cos(px, "l")
    if channel in ("specular", "color"):
        lo = 1 - 4 / CFG.spec_exponent
        assert ch.min() >= lo - 1e-9 and ch.max() <= 1 + 1e-9
        assert np.quantile(ch, 0.05) < lo + 0.02 and np.quantile(ch, 0.95) > 1 - 0.02
    else:
        assert np.mean(ch < 0.7) > 0.3                         # H left random
    if channel in ("diffuse", "color"):
        assert cl.min() >= 0.02 - 1e-9 and cl.max() <= 0.6 + 1e-9
        assert abs(np.mean(cl) - 0.31) < 0.02                  # cosine uniform in [0.02, 0.6]
    else:
        assert np.mean(cl > 0.6) > 0.2
    assert np.array_equal(px.n_phi, random.n_phi) and np.array_equal(px.b_theta, random.b_theta)


def test_unrounded_lsb_is_each_channel_before_its_rounding():
    cfg = Config(ka=0.25, kd=0.5, ks=0.125)
    out = {"diffuse_fine": np.array([cfg.one // 2, cfg.one]), "specular_fine": np.array([1 << 16, 0])}
    d = unrounded_lsb(out, cfg, "diffuse")
    assert d == pytest.approx([127.5, 255.0])
    from bumprtl.rtl.tables import SPEC_FRAC_BITS
    s = unrounded_lsb(out, cfg, "specular")
    assert s == pytest.approx([2.0 ** (16 - SPEC_FRAC_BITS), 0.0])
    assert unrounded_lsb(out, cfg, "color") == pytest.approx(255 * 0.25 + 0.5 * d + 0.125 * s)
    assert unrounded_lsb(out, Config(ka=0.25, kd=0.5, ks=0.125, specular=False), "color") == \
        pytest.approx(255 * 0.25 + 0.5 * d)


@pytest.mark.parametrize("channel", ["diffuse", "specular"])
def test_adversarial_pixels_sit_half_a_step_off_the_grid_in_variants(channel):
    keep, angles = 30, ANGLES_OF[channel]
    px = adversarial_pixels(CFG, candidates=3000, keep=keep, seed=4, channel=channel)
    variants = 1 + 2 * len(angles)
    assert len(px) == keep * variants
    for name in angles:
        x = getattr(px, name)
        inside = _interior(name, x)
        assert np.allclose(_off_grid(x[inside]), 0.4999, atol=1e-6), name
    # block 0 is the grid point itself; block 1 + 2k + (d > 0) moves angle k by d steps
    base = {n: np.rint(getattr(px, n)[:keep] / STEP) for n in angles}
    for k, name in enumerate(angles):
        for j, d in enumerate((-1, 1)):
            blk = slice((1 + 2 * k + j) * keep, (2 + 2 * k + j) * keep)
            for other in angles:
                got = np.rint(getattr(px, other)[blk] / STEP)
                want = base[other] + (d if other == name else 0)
                ok = _interior(other, getattr(px, other)[blk])
                assert np.array_equal(got[ok], want[ok]), (name, d, other)
    if channel == "specular":
        # half the candidates near the highlight: the kept ones sit mostly there
        assert np.mean(_cos(px.subset(slice(0, keep)), "h") > 0.75) > 0.5
    with pytest.raises(BumpError):
        adversarial_pixels(CFG, candidates=100, keep=5, channel="alpha")


def test_worst_case_pixels_are_the_largest_errors_then_their_neighbours():
    keep, channel = 20, "diffuse"
    angles = ANGLES_OF[channel]
    px = worst_case_pixels(datapath_fixed, CFG, channel, candidates=2000, keep=keep, seed=6)
    n = len(angles)
    assert len(px) == keep * (1 + 2 * n * (n + 1))
    top = px.subset(slice(0, keep))
    for name in angles:
        x = getattr(top, name)
        inside = _interior(name, x)
        assert np.allclose(_off_grid(x[inside]), 0.4999, atol=1e-6), name
    cl = _cos(top, "l")
    assert cl.min() >= 0.02 - 1e-6 and cl.max() <= 0.6 + 1e-6       # steep_pixels' L
    # the kept ones have the largest errors before the 8-bit rounding: above nine tenths of
    # the same kind of pixels (steep, every angle 0.4999 step off) with random sides
    from bumprtl.sim.golden.common import PixelInputs
    from bumprtl.sim.golden.float.conventional import conventional
    from bumprtl.sim.golden.methods import encode_pixels

    def err(p):
        got = unrounded_lsb(datapath_fixed(encode_pixels(p, CFG), CFG), CFG, channel)
        return np.abs(got - 255 * conventional(p, CFG).diffuse)
    rng = np.random.default_rng(9)
    ref = steep_pixels(2000, rng, CFG, channel)
    keys = {k: getattr(ref, k) for k in ref.__dataclass_fields__}
    for name in angles:
        x = keys[name]
        keys[name] = np.clip((np.rint(x / STEP) + 0.4999 * rng.choice([-1, 1], len(x))) * STEP,
                             0, np.pi if name.endswith("theta") else 2 * np.pi)
    ref = PixelInputs(**keys)
    assert np.median(err(top)) > np.quantile(err(ref), 0.9)
    # every further block is the top moved by one step in one or two angles (the same angle
    # twice: two steps, or none when the two moves cancel)
    seen = set()
    for b in range(1, 1 + 2 * n * (n + 1)):
        blk = px.subset(slice(b * keep, (b + 1) * keep))
        moved = [np.max(np.abs(getattr(blk, a) - getattr(top, a))) / STEP for a in angles]
        assert sum(m > 0.5 for m in moved) <= 2 and max(moved) <= 2 + 1e-6, b
        assert all(abs(m - round(m)) < 1e-6 for m in moved), b
        seen |= {(a, round(m)) for a, m in zip(angles, moved, strict=False) if m > 0.5}
    assert seen == {(a, k) for a in angles for k in (1, 2)}
    with pytest.raises(BumpError):
        worst_case_pixels(datapath_fixed, CFG, "alpha", candidates=10, keep=2)


def test_arithmetic_pixels_grid_then_shifted_with_l_equal_to_h():
    keep, reach = 10, 1
    px = arithmetic_pixels(datapath_fixed, CFG, candidates=2000, keep=keep, seed=3, reach=reach)
    m = keep * (2 * reach + 1) ** 2
    assert len(px) == 2 * m
    grid, shifted = px.subset(slice(0, m)), px.subset(slice(m, None))
    for p in (grid, shifted):
        assert np.array_equal(p.l_phi, p.h_phi) and np.array_equal(p.l_theta, p.h_theta)
    for name in ANGLES_OF["specular"]:
        g = getattr(grid, name)
        assert np.allclose(_off_grid(g), 0, atol=1e-9), name
        s = getattr(shifted, name)
        inside = _interior(name, s)
        assert np.allclose(_off_grid(s[inside]), 0.4999, atol=1e-6), name
        assert np.allclose(np.abs(s - g)[inside] / STEP, 0.4999, atol=1e-6), name
    # H is the grid point nearest world N' or within `reach` steps of it: N'.H near 1
    assert _cos(grid.subset(slice(0, keep)), "h").min() > np.cos(3 * STEP)
    assert _cos(grid, "h").min() > np.cos(4 * reach * STEP)


def _central_slope(keys, name, field):
    """float64 ``field`` (ndotl or ndoth) of the pixels ``keys`` with angle ``name`` moved
    1e-7 up, minus with it moved 1e-7 down (the sign of its partial derivative)."""
    from bumprtl.sim.golden.common import PixelInputs
    from bumprtl.sim.golden.float.conventional import conventional
    x = keys[name]
    up = getattr(conventional(PixelInputs(**{**keys, name: x + 1e-7}), CFG), field)
    dn = getattr(conventional(PixelInputs(**{**keys, name: x - 1e-7}), CFG), field)
    return up - dn


def test_adversarial_pixels_sit_on_the_side_that_moves_the_channel_most():
    """Step 2's 'worse side': each angle sits 0.4999 step off its grid point in the direction
    its partial derivative points (d(255 N'.L')/d angle by central differences here), so the
    rounding to the grid moves every angle against the output."""

    keep = 40
    px = adversarial_pixels(CFG, candidates=3000, keep=keep, seed=11, channel="diffuse").subset(slice(0, keep))
    keys = {k: getattr(px, k) for k in px.__dataclass_fields__}
    agree = total = 0
    for name in ANGLES_OF["diffuse"]:
        x = keys[name]
        slope = _central_slope(keys, name, "ndotl")
        grad = np.sign(slope)
        side = np.sign(x / STEP - np.rint(x / STEP))
        ok = _interior(name, x) & (np.abs(slope) > 1e-9)
        agree += int(np.sum(side[ok] == grad[ok]))
        total += int(ok.sum())
    assert total > 150 and agree >= 0.95 * total, (agree, total)


def test_the_search_targets_only_channel_values_inside_the_clamps():
    """The searches aim at outputs whose slope is not 0: N'.L strictly inside (0.02, 0.98)
    for diffuse, 255 x the channel strictly inside (0.5, 254.5) for the others (0 and 255,
    where the channel is clamped, are left out)."""
    from types import SimpleNamespace

    from bumprtl.sim.golden.accuracy import _target
    v = np.array([0.0, 0.001, 0.3, 0.999, 1.0])
    ref = SimpleNamespace(ndotl=v, specular=v, color=v)
    want = np.array([False, False, True, False, False])
    for channel in ("diffuse", "specular", "color"):
        value, inside = _target(channel, ref)
        assert np.allclose(value, 255 * v) and np.array_equal(inside, want), channel


def test_arithmetic_pixels_shift_each_angle_the_way_the_arithmetic_error_goes():
    """Step 3: every angle of N'.H' sits off its grid point on the side where the true N'.H'
    is below the grid's when the model's N'.H' is above the float64 one (and above when
    below), so that rounding to the grid adds to the arithmetic error: the sign of the side
    is -sign(error) x sign(d N'.H' / d angle) (central differences here)."""
    from bumprtl.sim.golden.float.conventional import conventional
    from bumprtl.sim.golden.methods import encode_pixels

    keep, reach = 10, 1
    px = arithmetic_pixels(datapath_fixed, CFG, candidates=2000, keep=keep, seed=3, reach=reach)
    m = keep * (2 * reach + 1) ** 2
    grid, shifted = px.subset(slice(0, m)), px.subset(slice(m, None))
    error = np.sign(datapath_fixed(encode_pixels(grid, CFG), CFG)["ndoth"] / CFG.one
                    - conventional(grid, CFG).ndoth)
    keys = {k: getattr(grid, k) for k in grid.__dataclass_fields__}
    agree = total = 0
    for name in ANGLES_OF["specular"]:
        x = keys[name]
        slope = _central_slope(keys, name, "ndoth")
        side = np.sign(getattr(shifted, name) - x)
        ok = _interior(name, x) & (np.abs(slope) > 1e-14) & (error != 0)
        agree += int(np.sum(side[ok] == -error[ok] * np.sign(slope)[ok]))
        total += int(ok.sum())
    assert total > 200 and agree >= 0.95 * total, (agree, total)
