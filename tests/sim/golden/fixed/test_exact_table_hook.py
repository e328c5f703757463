"""The TABLE_READ hook of sim/golden/fixed/exact.rotation_fixed as its comment states it:
f(k, angle, value) sees the k-th quarter-wave ROM read of one call (k = 0, 1, ... afresh
each call), ``angle`` the sine's binary angle (a cosine's plus a quarter circle), ``value``
the signed word read (so value = sin of that angle from the ROM), and what it returns
replaces the word; a hook returning the word changes nothing."""

import numpy as np
import pytest

from bumprtl.rtl.config import Config
from bumprtl.rtl.tables import sin_lookup
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.fixed import exact as fixed_exact
from bumprtl.sim.golden.fixed.common import quantize_pixels


@pytest.mark.parametrize("specular, reads", [(True, 24), (False, 19)])
def test_the_hook_sees_every_rom_read_numbered_from_0_and_its_word(monkeypatch, specular, reads):
    """n'' takes 6 sines, 2 cosines and 6 cosines (n.x4, n.y2, n.z4), each vector 2 sines
    and 3 cosines (p2, y2, z): 14 + 5 per vector; every read is the ROM's sine of the angle
    the hook is given."""
    cfg = Config(angle_bits=10, frac_bits=11, specular=specular)
    codes = quantize_pixels(PixelInputs.random(64, np.random.default_rng(1)), cfg)
    plain = fixed_exact.rotation_fixed(codes, cfg)
    seen = []

    def hook(k, angle, value):
        seen.append((k, np.array(angle), np.array(value)))
        return value
    monkeypatch.setattr(fixed_exact, "TABLE_READ", hook)
    for _ in range(2):                                     # numbered afresh each call
        hooked = fixed_exact.rotation_fixed(codes, cfg)
        assert sorted(hooked) == sorted(plain)
        for key in plain:
            assert np.array_equal(hooked[key], plain[key]), key
    assert [k for k, _, _ in seen] == list(range(reads)) * 2
    for k, angle, value in seen:
        assert np.array_equal(value, sin_lookup(cfg, angle)), k


def test_what_the_hook_returns_replaces_the_word(monkeypatch):
    """Adding one LSB to read k moves the output that read feeds: read 0 is a sine of n.x4
    (which it enters with weight 1), the last read the cosine of th_A in the last vector's z."""
    cfg = Config(angle_bits=10, frac_bits=11)
    codes = quantize_pixels(PixelInputs.random(64, np.random.default_rng(2)), cfg)
    plain = fixed_exact.rotation_fixed(codes, cfg)
    for target, key in ((0, "n.x4"), (23, "h.z")):
        monkeypatch.setattr(fixed_exact, "TABLE_READ", lambda k, a, v, t=target: v + 1 if k == t else v)
        moved = fixed_exact.rotation_fixed(codes, cfg)
        assert np.array_equal(moved[key], plain[key] + 1), key
        changed = [kk for kk in plain if not np.array_equal(moved[kk], plain[kk])]
        assert changed == [key]
