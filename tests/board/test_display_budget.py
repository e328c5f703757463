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


def _burst_misses(n):
    """A frame of 720p whose line 300 misses at n pixels in a row from column 400."""
    miss = np.zeros((MODE.v_active, MODE.h_active), bool)
    miss[300, 400:400 + n] = True
    return miss


@pytest.mark.parametrize("burst", [0, 3, 40, 200])
def test_the_display_buffer_is_the_least_power_of_two_that_holds(monkeypatch, burst):
    from bumprtl.gen.flow import board
    misses = _burst_misses(burst)
    monkeypatch.setattr(board, "frames_misses", lambda *a, **k: [misses, misses])
    entries, budgets = board.display_buffer(_globe(64, 32), MODE, line_cost=LINE_COST,
                                            fill_clocks=FILL)
    assert all(b.holds for b in budgets) and len(budgets) == 2
    if burst == 0:                   # no miss: the crossing's 16 entries alone hold
        assert entries is None and _budget(misses).holds
        return
    assert entries >= 16 and entries & (entries - 1) == 0
    # by the budget itself: with these entries ahead of the crossing's 16 every miss has a
    # line's pipe clocks to spare, with half as many (or, at the least, 16, none) not
    line = 1650 * 1.25

    def spare(b):                    # every miss a line to spare (or none past the steady's)
        return b.worst is None or b.slack >= line
    assert spare(_budget(misses, cdc=16 + entries))
    assert not spare(_budget(misses, cdc=16 + (entries // 2 if entries > 16 else 0)))
    # a burst of n line reads outlasts its n pixels by n (35.75 - 1.25) pipe clocks: the
    # buffer must hold about that many pixels' time (1.25 pipe clocks a pixel) ahead
    assert entries + 60 >= burst * (LINE_COST - 1.25) / 1.25 - 60


def test_the_display_buffer_search_stops_at_its_most(monkeypatch):
    from bumprtl.gen.flow import board
    misses = np.zeros((MODE.v_active, MODE.h_active), bool)
    misses[300:310] = True                                      # ten lines, every pixel a miss
    monkeypatch.setattr(board, "frames_misses", lambda *a, **k: [misses, misses])
    monkeypatch.setattr(board, "MAX_DISPLAY_BUFFER", 256)
    entries, budgets = board.display_buffer(_globe(64, 32), MODE, line_cost=LINE_COST,
                                            fill_clocks=FILL)
    assert entries == 256 and not any(b.holds for b in budgets)


def test_the_display_buffer_searches_frame_0_cold_and_frame_1_warm(monkeypatch):
    from bumprtl.gen.flow import board
    calls = []

    def misses(scene, mode, count):
        calls.append(count)
        # frame 0 (cold) has the burst, frame 1 none: the buffer must still cover it
        return [_burst_misses(200), _burst_misses(0)]
    monkeypatch.setattr(board, "frames_misses", misses)
    entries, budgets = board.display_buffer(_globe(64, 32), MODE, line_cost=LINE_COST,
                                            fill_clocks=FILL)
    assert calls == [2]
    assert entries == board.display_buffer(_globe(64, 32), MODE, line_cost=LINE_COST,
                                           fill_clocks=FILL)[0] >= 16
    assert budgets[0].misses.sum() == 200 and budgets[1].misses.sum() == 0


def test_one_run_over_frames_gives_each_frames_misses():
    # frames 0 (cold) and 1 (warm) of one run equal frame_misses' separate runs, on a
    # turning globe whose frame 1 misses neither as frame 0 nor as frame 1 from cold do
    from bumprtl.gen.flow.board import frames_misses
    scene = _globe(256, 128)
    mode = MODES["test"]
    got = frames_misses(scene, mode, 2)
    assert len(got) == 2 and got[0].shape == (mode.v_active, mode.h_active)
    assert np.array_equal(got[0], frame_misses(scene, mode, 0, warm=False))
    assert np.array_equal(got[1], frame_misses(scene, mode, 1))
    assert not np.array_equal(got[1], got[0])
    assert not np.array_equal(got[1], frame_misses(scene, mode, 1, warm=False))


def test_board_core_takes_the_display_buffer_ahead_of_the_crossing():
    from bumprtl.gen.flow.board import board_core
    from bumprtl.rtl.config import BumpError
    scene = load_scene_config("default", {"texture_size": 16, "angle_bits": 10})
    mode = MODES["test"]
    core = board_core(scene, mode, pipe_hz=2 * mode.pixel_hz)
    assert core.display_buffer is None
    for bad in (3, 0, 1, True, 48.0):
        with pytest.raises(BumpError) as e:
            board_core_with(scene, mode, bad)
        assert e.value.field == "display_buffer" and "power of two >= 2" in str(e.value)
    with pytest.raises(BumpError) as e:          # no pipe domain: no crossing to be ahead of
        board_core_with(scene, mode, 64, pipe_hz=None)
    assert e.value.field == "display_buffer"


def board_core_with(scene, mode, entries, pipe_hz=True):
    from bumprtl.gen.flow.board import board_data
    from bumprtl.rtl.board import BoardCore
    words, texels, constants, table = board_data(scene)
    return BoardCore(scene.hardware, mode, words, constants, table[:2], texels,
                     pipe_hz=2 * mode.pixel_hz if pipe_hz else None, display_buffer=entries)


def _model(miss, rows, ahead, queue):
    """The documented model written out pixel by pixel (display_budget's docstring):
    every pixel's entry and exit, not only the misses'."""
    r, after = 1.25, 36 - 12 + 4 + 5 * 1.25
    flat = miss.ravel()
    n = len(flat)
    k = np.arange(n)
    shown = r * ((rows.start + k // MODE.h_active) * MODE.h_total + k % MODE.h_active)
    leave, served, slack = np.zeros(n), -np.inf, r * ahead - 36 - after - 12
    for p in range(n):
        e = shown[p - ahead] if p >= ahead else -np.inf
        if queue is not None and p >= queue:        # its slot frees the cycle after
            e = max(e, leave[p - queue] + 1)
        if flat[p]:
            served = max(served + LINE_COST, e + FILL)
            leave[p] = served
            slack = min(slack, shown[p] - (served + after))
        else:                                 # a hit: a clock after the pixel before
            leave[p] = max(e + 12, leave[p - 1] + 1 if p else -np.inf)
    return slack


@pytest.mark.parametrize("queue", [None, 64])
def test_the_budget_is_the_documented_model_with_the_caches_queue(queue):
    # random misses (5 % of ten lines), the buffers 244 pixels: display_budget against the
    # model written out pixel by pixel above
    rows = range(100, 110)
    miss = np.random.default_rng(0).random((10, MODE.h_active)) < 0.05
    got = display_budget(miss, MODE, PIPE_HZ, 36, 44, 200, LINE_COST, FILL, rows, queue)
    assert got.slack == pytest.approx(_model(miss, rows, 244, queue))
    if queue is not None:                     # a miss further ahead waits: later still
        free = display_budget(miss, MODE, PIPE_HZ, 36, 44, 200, LINE_COST, FILL, rows)
        assert got.slack < free.slack - 100
