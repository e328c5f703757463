"""Refusals of rtl/ that no other test reached (docs/coverage.md's per-branch list): each
bad value raises the error the docstrings promise, naming the parameter and the value."""

import json

import numpy as np
import pytest
from amaranth.hdl import Module, Signal

from bumprtl.gen.flow.units import build_unit
from bumprtl.rtl import sidecar
from bumprtl.rtl.cache import CacheGeometry, tiled_image
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.fixed import Q, round_shift
from bumprtl.rtl.pipe import Pipe


@pytest.mark.parametrize("kw, field, shown", [
    ({"mip_levels": 0}, "mip_levels", "got 0"),
    ({"mip_levels": 8}, "mip_levels", "got 8"),            # a 64-texel map has 7 levels
    ({"texel_bits": 33, "data_bits": 32}, "texel_bits", "got 33"),
    ({"base": 4}, "base", "got 4"),                         # not on a line
    ({"base": -64}, "base", "got -64"),
    ({"addr_bits": 11}, "addr_bits", "got 11"),
    ({"addr_bits": 65}, "addr_bits", "got 65"),
])
def test_cache_geometry_refuses_each_field_out_of_range(kw, field, shown):
    args = {"texture_size": 64, "mip_levels": 1, "texel_bits": 28, **kw}
    with pytest.raises(BumpError) as e:
        CacheGeometry(**args)
    assert e.value.field == field and shown in str(e.value)


def test_tiled_image_refuses_a_level_of_the_wrong_shape_or_a_word_too_wide():
    g = CacheGeometry(16, 2, 8)
    good = [np.zeros((16, 16), np.int64), np.zeros((8, 8), np.int64)]
    assert len(tiled_image(g, good)) > 0
    with pytest.raises(BumpError, match="level 1 must be 8 x 8") as e:
        tiled_image(g, [good[0], np.zeros((16, 16), np.int64)])
    assert e.value.field == "levels"
    wide = [good[0].copy(), good[1]]
    wide[0][3, 3] = 1 << 8                                   # a 9-bit word in 8-bit texels
    with pytest.raises(BumpError, match="level 0 has words outside"):
        tiled_image(g, wide)
    negative = [good[0], good[1].copy()]
    negative[1][0, 0] = -1
    with pytest.raises(BumpError, match="level 1 has words outside"):
        tiled_image(g, negative)


@pytest.mark.parametrize("int_bits, frac_bits", [(-1, 4), (4, -1), (32, 32)])
def test_q_refuses_negative_parts_and_formats_over_63_bits(int_bits, frac_bits):
    with pytest.raises(ValueError, match=rf"Q\({int_bits}, {frac_bits}\) is not a supported"):
        Q(int_bits, frac_bits)
    Q(31, 31)                                                 # 63 bits with the sign: fine


def test_round_shift_refuses_a_negative_shift():
    assert round_shift(np.array([5]), 1).tolist() == [3]     # 2.5 rounds half up
    with pytest.raises(ValueError, match="shift must be >= 0, got -1"):
        round_shift(np.array([5]), -1)


def test_pipe_refuses_depth_zero():
    m = Module()
    with pytest.raises(ValueError, match="pipeline depth must be >= 1, got 0"):
        Pipe(m, Signal(), Signal(), 0)


def _sidecar_dict():
    _, meta, _ = build_unit("rotation", Config())
    return json.loads(meta.dumps())


def test_sidecar_refuses_a_key_that_is_not_an_object():
    d = _sidecar_dict()
    sidecar.loads(json.dumps(d))                              # the unit's own reads back
    d["error_bounds"] = [d["error_bounds"]]
    with pytest.raises(BumpError, match="sidecar key 'error_bounds' must be an object, got list"):
        sidecar.loads(json.dumps(d))


def test_sidecar_refuses_a_fact_its_schema_has_no_place_for():
    with pytest.raises(BumpError, match="sidecar fact 'colour' has no place in schema_version"):
        sidecar.from_facts("rotation", "bumprtl emit rotation", {}, {"latency": 3, "colour": 1})


def test_sdram_clock_too_slow_to_refresh_in_time_is_refused():
    from bumprtl.rtl.sdram import SdramConfig

    assert SdramConfig(freq_mhz=2).refresh_reload >= 1
    with pytest.raises(BumpError, match="at 1 MHz a refresh cannot be scheduled within tREFI") as e:
        SdramConfig(freq_mhz=1)
    assert e.value.field == "freq_mhz"


def test_a_unit_inside_a_chain_refuses_a_fifo_depth_of_its_own():
    from bumprtl.rtl.illumination import Illumination

    assert Illumination(Config(), credit=True, fifo_depth=None).fifo_depth >= 1
    with pytest.raises(BumpError, match="fifo_depth is given but credit=False"):
        Illumination(Config(), credit=False, fifo_depth=8)


def test_a_pipe_clock_of_zero_or_below_the_pixel_clock_is_refused():
    """No divider gives a clock of 0 Hz; the SDRAM's clock bound below the pixel clock
    leaves the pipeline slower than the display: both name ``pipe_hz``."""
    from bumprtl.rtl.board import pll_pipe_divider, sdram_clock
    from bumprtl.rtl.video import MODES

    pixel = MODES["1280x720"].pixel_hz
    with pytest.raises(BumpError, match=r"^pipe clock must be in \[.*got 0 MHz$") as e:
        pll_pipe_divider(pixel, 0)
    assert e.value.field == "pipe_hz"
    assert sdram_clock(pixel, 100e6) >= pixel
    with pytest.raises(BumpError, match=r"below the pixel clock 74\.2\d* MHz; it must be in "
                                        r"\[74\.2\d*, 70\] MHz$") as e:
        sdram_clock(pixel, 70e6)
    assert e.value.field == "pipe_hz"
