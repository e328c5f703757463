"""SinCos in the Amaranth simulator: exhaustive over every angle, bit-exact with the table."""

import pytest

from bumprtl.rtl.config import Config
from bumprtl.rtl.sincos import SinCos, near_sine, sine_line, sine_rom_table, spread_sine
from bumprtl.rtl.tables import cos_lookup, sin_lookup
from bumprtl.rtl.targets import NEAR_BLOCKS, rom_blocks
from bumprtl.sim.amaranth_stream import simulate_stream
from bumprtl.sim.traffic import PATTERNS


def _check_exhaustive(cfg, pattern):
    dut = SinCos(cfg)
    angles = list(range(cfg.full_circle))
    tags = [(a * 7) % (1 << cfg.tag_bits) for a in angles]
    out, cycles = simulate_stream(dut, [{"angle": a, "tag": t} for a, t in zip(angles, tags, strict=False)], pattern,
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
    """Every angle of the default, one a clock (the traffic patterns: the 8-bit test above,
    whose handshake is the same CreditEdge)."""
    dut_latency = SinCos(Config()).port_latency
    assert _check_exhaustive(Config(), "no_stall") == Config().full_circle + dut_latency


def test_one_angle_per_clock_without_stalls():
    cfg = Config(angle_bits=8, frac_bits=8, tag_bits=8)
    dut = SinCos(cfg)
    _, cycles = simulate_stream(dut, [{"angle": a, "tag": 0} for a in range(200)], "no_stall")
    assert cycles == 200 + dut.port_latency


def test_exhaustive_sine_above_line():
    """13-bit angles at B = 11: the ROM holds the sine above its line (one 2048 x 9 block
    instead of two), and every angle still reads the table's sine and cosine."""
    cfg = Config(angle_bits=13, frac_bits=11, tag_bits=8)
    assert sine_line(cfg) and sine_rom_table(cfg)[1] == 9
    _check_exhaustive(cfg, "both")


@pytest.mark.parametrize("angle_bits, frac_bits, line, width, blocks", [
    (14, 15, False, 16, 4),     # 4096 x 4 blocks: 13 bits above the line are still four
    (15, 16, True, 14, 7),      # 8192 x 2 blocks: 17 bits are nine, 14 bits seven
    (13, 11, True, 9, 1),       # 2048 x 9: 12 bits are two blocks, 9 bits one
    (12, 13, False, 14, 1),     # 1025 words: one x18 block either way (the spill word aside)
    (16, 16, True, 14, 14)])    # 16384 x 1: seventeen blocks or fourteen
def test_sine_line_where_it_saves_block_rams(angle_bits, frac_bits, line, width, blocks):
    """DP16KD holds 1024 x 18 ... 16384 x 1 (18 Kbit): the ROM stores the sine above its line
    (B - 2 bits) only where that takes fewer blocks side by side than the sine (B + 1); more
    than NEAR_BLOCKS (none: every ROM) take a near address register (one more stage), more
    than eight an enable of their own."""
    cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
    assert sine_line(cfg) is line
    assert sine_rom_table(cfg)[1] == width
    assert rom_blocks(1 << cfg.k, width) == blocks
    assert spread_sine(cfg) == (blocks > 8)
    assert near_sine(cfg) == (blocks > NEAR_BLOCKS)
    assert SinCos(cfg).latency == 8 + near_sine(cfg)
