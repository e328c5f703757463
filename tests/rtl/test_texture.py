"""The colour-texture blend (rtl/texture.py): the integer blend of the unrounded terms
against float64 within its stated bound, and the TextureBlend unit bit for bit against it
under stalls."""

import numpy as np
import pytest
from amaranth.hdl import Fragment, Instance

from bumprtl.rtl.config import Config
from bumprtl.rtl.pipe import ECP5
from bumprtl.rtl.tables import SPEC_FRAC_BITS
from bumprtl.rtl.texture import RGB, TextureBlend, blend_error_bound_lsb, texture_blend
from bumprtl.sim.amaranth_stream import assert_bit_exact, simulate_stream
from bumprtl.sim.golden.vectors import range_corners
from bumprtl.sim.traffic import PATTERNS


def float_blend(d, s, tex, cfg):
    """float64: out_c = clamp(tex_c min(1, ka + kd D) + ks S, 0, 255), D = sum d_j / 2**B,
    S = sum s_j / 2**F (the unrounded terms: clamp(N'.L) and 255 cos^n)."""
    D = sum(np.asarray(x, float) for x in d) / (1 << cfg.frac_bits)
    S = sum(np.asarray(x, float) for x in s) / (1 << SPEC_FRAC_BITS)
    lit = np.minimum(1.0, cfg.ka + cfg.kd * D)
    ks = cfg.ks if cfg.specular else 0.0
    return {c: np.clip(np.asarray(tex[c], float) * lit + ks * S, 0, 255) for c in RGB}


def random_terms(rng, cfg, lights, n):
    """Light j's diffuse_fine in [0, 2**B] and specular_fine in [0, 255 2**F]."""
    d = [rng.integers(0, cfg.one + 1, n) for _ in range(lights)]
    s = [rng.integers(0, 255 * (1 << SPEC_FRAC_BITS) + 1, n) for _ in range(lights)]
    return d, s


@pytest.mark.parametrize("lights", [1, 2, 3])
@pytest.mark.parametrize("k", [(0.1, 0.7, 0.2), (0.33, 0.45, 0.61), (0.0, 1.0, 0.0)])
def test_blend_within_its_bound_of_float64(lights, k):
    """One rounding at the end: within 1/2 LSB plus the coefficients' quantization."""
    cfg = Config(ka=k[0], kd=k[1], ks=k[2], lights=lights)
    rng = np.random.default_rng(lights)
    n = 200_000
    d, s = random_terms(rng, cfg, lights, n)
    tex = {c: rng.integers(0, 256, n) for c in RGB}
    got, dsum, ssum = texture_blend(d, s, tex, cfg)
    want = float_blend(d, s, tex, cfg)
    bound = blend_error_bound_lsb(cfg, lights)
    assert bound < 0.52
    for c in RGB:
        assert got[c].min() >= 0 and got[c].max() <= 255
        assert np.abs(got[c] - want[c]).max() <= bound, c
    D, S = sum(d) / cfg.one, sum(s) / (1 << SPEC_FRAC_BITS)
    assert np.abs(dsum - np.minimum(255 * D, 255)).max() <= 0.5
    assert np.abs(ssum - np.minimum(S, 255)).max() <= 0.5


def test_white_texel_gives_the_grey_shade_black_gives_the_highlight():
    cfg = Config()
    d = np.arange(256) * cfg.one // 255
    s = np.arange(256)[::-1] << SPEC_FRAC_BITS
    white = texture_blend([d], [s], {c: np.full(256, 255) for c in RGB}, cfg)[0]
    black = texture_blend([d], [s], {c: np.zeros(256, int) for c in RGB}, cfg)[0]
    grey = np.floor(0.1 * 255 + 0.7 * 255 * d / cfg.one + 0.2 * np.arange(256)[::-1] + 0.5)
    assert np.abs(white["r"] - np.clip(grey, 0, 255)).max() <= 1
    assert np.abs(black["g"] - 0.2 * np.arange(256)[::-1]).max() <= 0.51
    assert black["g"][0] > 40 and black["g"][-1] == 0          # only the highlight is left


def _unit_bit_exact(cfg, lights, pattern, n):
    """The corners of every term (range_corners: every light's d at 2**B and s at 255 2**F
    with white texels, all at 0, each alone), then ``n`` random pixels."""
    rng = np.random.default_rng(9)
    ranges = {**{f"d.{j}": (0, cfg.one) for j in range(lights)},
              **{f"s.{j}": (0, 255 << SPEC_FRAC_BITS) for j in range(lights)},
              **{f"texel.{c}": (0, 255) for c in RGB}}
    corners = range_corners(ranges)
    inputs = [{k: int(v[i]) for k, v in corners.items()} for i in range(len(corners["texel.r"]))]
    inputs += [{**{f"d.{j}": int(rng.integers(cfg.one + 1)) for j in range(lights)},
                **{f"s.{j}": int(rng.integers(255 << SPEC_FRAC_BITS)) for j in range(lights)},
                **{f"texel.{c}": int(rng.integers(256)) for c in RGB}} for _ in range(n)]
    inputs = [{**p, "tag": t % (1 << cfg.tag_bits)} for t, p in enumerate(inputs)]
    col = lambda k: np.array([p[k] for p in inputs])
    color, d, s = texture_blend([col(f"d.{j}") for j in range(lights)],
                                [col(f"s.{j}") for j in range(lights)],
                                {c: col(f"texel.{c}") for c in RGB}, cfg)
    golden = {"diffuse": d, "specular": s, **{f"color.{c}": color[c] for c in RGB}}
    dut = TextureBlend(cfg, lights)
    out, cycles = simulate_stream(dut, inputs, pattern, seed=2, pipe_handshake=True)
    assert_bit_exact(out, golden, inputs)
    return dut, cycles, len(inputs)


@pytest.mark.parametrize("pattern", list(PATTERNS))
def test_unit_bit_exact(pattern):
    dut, cycles, n = _unit_bit_exact(Config(lights=2), 2, pattern, 300)
    if pattern == "no_stall":
        assert cycles <= n + dut.port_latency + 1


@pytest.mark.parametrize("frac_bits, lights", [(13, 1), (13, 2), (16, 1), (16, 3)])
def test_unit_bit_exact_split_and_fabric_products(frac_bits, lights):
    """The light sums' products one DSP per sum (B = 13), one per light (B = 16, 2 lights:
    the test above) or one fabric product of the whole sum (3 lights at B = 16)."""
    _unit_bit_exact(Config(frac_bits=frac_bits, lights=lights), lights, "both", 120)


def _instances(fragment):
    if isinstance(fragment, Instance):
        yield fragment.type
    for sub, *_ in fragment.subfragments:
        yield from _instances(sub)


@pytest.mark.parametrize("frac_bits, lights, dsps", [(13, 1, 5), (13, 2, 6), (13, 8, 4),
                                                     (16, 2, 7), (16, 3, 3)])
def test_ecp5_products_are_dsp_blocks(frac_bits, lights, dsps):
    """On ECP5 kd D, ks S and the three tex_c lit are MULT18X18D blocks with their registers
    (rtl/texture.sum_product's widths): D split by lights only where the sum is too wide for
    one operand, the 17-bit specular terms one block a light, fabric beyond MAX_SPLIT."""
    cfg = Config(frac_bits=frac_bits, lights=lights)
    fragment = Fragment.get(TextureBlend(cfg, lights, target=ECP5()), None)
    assert list(_instances(fragment)) == ["MULT18X18D"] * dsps
