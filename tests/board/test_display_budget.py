"""The display budget of a map in the SDRAM (gen/flow/board.display_budget and
predict_display, docs/board.md, What holds at 1280 x 720): its arithmetic on made-up
misses, and its verdict on every 720p globe whose whole frame was simulated through the
DVI sink with the SDRAM preloaded (``bumprtl board ulx3s --mode 1280x720 ...
--check-frames 1 --preload-sdram``): the 64 x 32 map's frame equal to the golden frame,
the 128 x 64, 1024 x 1024 and 2048 x 1024 maps' underflowing."""

import numpy as np
import pytest

from bumprtl.gen.flow.board import display_budget, frame_misses, predict_display
from bumprtl.rtl.video import MODES
from bumprtl.sim.scenes.config import load_scene_config

# sim/sdram_bench.bandwidth at the 720p pipe clock (92.86 MHz, docs/board.md): 'miss' 8.9375
# pipe clocks a 16 bytes (a 64-byte line, a new row each: 35.75) and 'miss_latency' 12
# (+ 16 beats + 2: an isolated miss's pixel out of the cache)
LINE_COST, FILL = 35.75, 30
MODE = MODES["1280x720"]
PIPE_HZ = MODE.pixel_hz * 1.25


def _budget(miss, rows=None, latency=36, depth=44, cdc=16):
    return display_budget(miss, MODE, PIPE_HZ, latency, depth, cdc, LINE_COST, FILL, rows)


def test_budget_arithmetic_on_made_up_misses():
    none = _budget(np.zeros((4, MODE.h_active), bool), range(100, 104))
    assert none.line_clocks == pytest.approx(1650 * 1.25)
    assert none.ahead == 60 and none.holds
    # 60 pixels ahead = 75 pipe clocks, less the latency and the crossing (4 pipe, 5 pixel)
    assert none.steady == pytest.approx(75 - 36 - 4 - 5 * 1.25) == none.slack
    miss = np.zeros((4, MODE.h_active), bool)
    miss[2, 600] = True              # one isolated miss mid-line: its fill is hidden
    one = _budget(miss, range(100, 104))
    assert one.holds and one.misses.tolist() == [0, 0, 1, 0] and one.worst_line == 102
    miss[2, 600:610] = True          # ten in a row: ten line reads in ten pixels' time
    ten = _budget(miss, range(100, 104))
    assert not ten.holds and ten.worst == (102, 609)
    assert ten.needed == pytest.approx(10 * LINE_COST)
    # the last of them leaves 9 line reads after the first (its entry + fill), then the
    # rest of the pipeline and the crossing
    enter = 1.25 * (600 - 60)
    assert ten.slack == pytest.approx(1.25 * 609 - (enter + FILL + 9 * LINE_COST + 36 - 12 + 4 + 6.25))
    spread = np.zeros((4, MODE.h_active), bool)
    spread[:, ::40] = True           # 32 a line, one every 40 pixels (50 pipe clocks > 35.75)
    assert _budget(spread, range(100, 104)).holds


def _globe(width, height):
    return load_scene_config({"image": "globe", "texture_size": width,
                              "texture_height": height, "map_memory": "axi"})


def test_the_64_x_32_frame_holds_as_simulated():
    # the whole frame, the cache warm from the frame before: every block is held
    got = predict_display(_globe(64, 32), MODE, line_cost=LINE_COST, fill_clocks=FILL)
    assert got.holds and got.misses.sum() == 0


@pytest.mark.parametrize("width, height, rows", [(128, 64, range(24, 32)),
                                                 (1024, 1024, range(160, 176)),
                                                 (2048, 1024, range(328, 392))])
def test_the_maps_that_underflowed_in_simulation_starve(width, height, rows):
    # lines around the whole-frame prediction's worst (docs/board.md), after 8 lines that
    # warm the cache (each touches most of its 128 lines); the whole frame takes seconds
    scene = _globe(width, height)
    warm = range(rows.start - 8, rows.stop)
    miss = frame_misses(scene, MODE, 1, warm, warm=False)[8:]
    got = display_budget(miss, MODE, PIPE_HZ, 36, 44, 16, LINE_COST, FILL, rows)
    assert not got.holds, (got.slack, got.worst)


def test_the_design_numbers_the_budget_uses():
    # what predict_display reads from the design (BoardCore's pipeline, the crossing)
    got = predict_display(_globe(64, 32), MODE, rows=range(0, 1), line_cost=LINE_COST,
                          fill_clocks=FILL, warm=False)
    assert got.ahead == 44 + 16 and got.line_clocks == pytest.approx(1650 * 1.25)
    assert got.steady == pytest.approx(75 - 36 - 4 - 5 * 1.25)
