"""SinCos in the Amaranth simulator: exhaustive over every angle, bit-exact with the table."""

import pytest

from bumprtl.rtl.config import Config
from bumprtl.rtl.sincos import SinCos
from bumprtl.rtl.tables import cos_lookup, sin_lookup
from bumprtl.sim.amaranth_stream import simulate_stream
from bumprtl.sim.traffic import PATTERNS


def _check_exhaustive(cfg, pattern):
    dut = SinCos(cfg)
    angles = list(range(cfg.full_circle))
    tags = [(a * 7) % (1 << cfg.tag_bits) for a in angles]
    out, cycles = simulate_stream(dut, [{"angle": a, "tag": t} for a, t in zip(angles, tags)], pattern,
                                  pipe_handshake=True)
    s, c = sin_lookup(cfg, angles), cos_lookup(cfg, angles)
    assert [o["sin"] for o in out] == s.tolist()
    assert [o["cos"] for o in out] == c.tolist()
    assert [o["tag"] for o in out] == tags
    return cycles


@pytest.mark.parametrize("pattern", list(PATTERNS))
def test_exhaustive_k6(pattern):
    _check_exhaustive(Config(angle_bits=8, frac_bits=8, tag_bits=8), pattern)


def test_exhaustive_k10_default():
    cycles = _check_exhaustive(Config(), "backpressure")
    assert cycles > Config().full_circle   # backpressure really stalled the pipe


def test_one_angle_per_clock_without_stalls():
    cfg = Config(angle_bits=8, frac_bits=8, tag_bits=8)
    dut = SinCos(cfg)
    _, cycles = simulate_stream(dut, [{"angle": a, "tag": 0} for a in range(200)], "no_stall")
    assert cycles == 200 + dut.latency
