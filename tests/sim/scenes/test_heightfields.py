"""The crater height map (sim/scenes/heightfields.craters, the "unseen map" of the channel
tests) against its closed form: a crater of radius r centred at c is d^2 - 1 inside (d =
|p - c| / r, wrapped round the tile) and a rim 0.3 exp(-((d - 1) / 0.3)^2) outside, the
sum scaled to [0, 1]."""

import numpy as np
import pytest

from bumprtl.sim.scenes.heightfields import craters


def _wrapped(a, c, t):
    return (a - c + t / 2) % t - t / 2


@pytest.mark.parametrize("seed", [1, 7])
def test_one_crater_is_a_bowl_and_a_rim_scaled_to_unit_range(seed):
    t, frac = 64, 0.2
    h = craters(t, seed, 1, radius=(frac, frac))
    assert h.shape == (t, t) and h.min() == 0.0 and h.max() == 1.0
    r = frac * t
    # the bowl's bottom: the centre within one texel of the lowest texel centre
    iy, ix = np.unravel_index(np.argmin(h), h.shape)
    y, x = np.mgrid[0:t, 0:t] + 0.5
    best = None
    for cy in np.linspace(iy, iy + 1, 11):            # search the centre on a 0.1-texel grid
        for cx in np.linspace(ix, ix + 1, 11):
            d = np.hypot(_wrapped(x, cx, t), _wrapped(y, cy, t)) / r
            raw = np.where(d < 1, d ** 2 - 1, 0.3 * np.exp(-((d - 1) / 0.3) ** 2))
            want = (raw - raw.min()) / np.ptp(raw)
            ok = np.abs(d - 1) > 0.02                  # the rim's step (0 inside, 0.3 out)
            err = np.abs(h - want)[ok].max()
            best = err if best is None else min(best, err)
    # 0.05 texel from the true centre moves d by 0.05 / r, the height by at most ~2 d' / 1.3
    assert best < 0.02, best


def test_craters_tile():
    t = 64
    one, many = craters(t, 3, 1), craters(t, 3, 12)
    for h in (one, many):
        assert h.min() == 0.0 and h.max() == 1.0
        # tiling: the wrapped neighbour across each edge is as close as neighbours inside
        inside = max(np.abs(np.diff(h, axis=0)).max(), np.abs(np.diff(h, axis=1)).max())
        assert np.abs(h[0] - h[-1]).max() <= inside and np.abs(h[:, 0] - h[:, -1]).max() <= inside
    assert not np.array_equal(one, many)


def test_the_seed_fixes_the_map():
    assert np.array_equal(craters(32, 5, 4), craters(32, 5, 4))
    assert not np.array_equal(craters(32, 5, 4), craters(32, 6, 4))


def test_small_wood_and_text_are_the_64_texel_fields_averaged_over_blocks():
    """Below 64 texels wood and text are drawn at 64 and box-filtered down (the mean of each
    (64 / T)**2 block), so detail finer than a texel averages out instead of aliasing."""
    from bumprtl.sim.scenes.heightfields import HEIGHTFIELDS
    for name in ("wood", "text"):
        fine = HEIGHTFIELDS[name](64)
        for t in (16, 32):
            k = 64 // t
            want = np.array([[fine[i * k:(i + 1) * k, j * k:(j + 1) * k].mean() for j in range(t)]
                             for i in range(t)])
            assert np.allclose(HEIGHTFIELDS[name](t), want, rtol=0, atol=1e-12), (name, t)


def test_band_limiting_averages_detail_finer_than_a_texel():
    """A field drawn through _band_limited below 64 texels is the mean of each block of the
    64-texel drawing: a one-texel checkerboard (detail no smaller map can hold) becomes a
    flat 0.5 instead of aliasing, and a linear ramp stays the ramp at the blocks' centres."""
    from bumprtl.sim.scenes.heightfields import _band_limited

    def checker_and_ramp(t):
        i, j = np.mgrid[0:t, 0:t]
        return (i + j) % 2 + (j + 0.5) / t

    field = _band_limited(checker_and_ramp)
    assert np.array_equal(field(64), checker_and_ramp(64)) and field.__name__ == "checker_and_ramp"
    for t in (16, 32):
        ramp = (np.arange(t) + 0.5) / t
        assert np.allclose(field(t), 0.5 + ramp[None, :], rtol=0, atol=1e-12), t
