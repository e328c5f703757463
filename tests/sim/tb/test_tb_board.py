"""The board bench's sync/blanking checker (sim/tb/tb_board.timing_errors) on rasters of the
reduced mode made here from the mode's table: the true raster passes, and each way a
raster can be wrong (frame period, vsync length, active lines, line length, hsync length and
period, horizontal and vertical porches, no vsync at all) is reported by its own message
(make board checks whole 640 x 480 frames through the DVI sink; tests/board/test_board.py
the reduced mode's frames and one wrong porch)."""

import numpy as np
import pytest

from bumprtl.rtl.video import MODES
from bumprtl.sim.tb.tb_board import runs, timing_errors

T = MODES["test"]
ARGS = (T.h_active, T.h_front, T.h_sync, T.h_back, T.v_active, T.v_front, T.v_sync, T.v_back,
        1, 1)
H_SYNC0 = T.h_active + T.h_front                  # first pixel of the hsync pulse
V_SYNC0 = T.v_active + T.v_front                  # first line of the vsync pulse


def raster(frames=3, hsync=T.h_sync, vsync=T.v_sync, line_shift=0, active=T.h_active,
           lines=T.v_active, extra_line_in=None, first_active_line=0, start=0):
    """(de, hsync, vsync) one sample a pixel, sync active low as the mode says; the
    keywords bend one aspect of the table."""
    de, hs, vs = [], [], []
    for frame in range(frames):
        total = T.v_total + (1 if frame == extra_line_in else 0)
        for y in range(total):
            for x in range(T.h_total):
                shift = line_shift if y == 3 else 0
                de.append(int(first_active_line <= y < first_active_line + lines
                              and start <= x < active))
                hs.append(int(not H_SYNC0 + shift <= x < H_SYNC0 + shift + hsync))
                vs.append(int(not V_SYNC0 <= y < V_SYNC0 + vsync))
    return np.array(de), np.array(hs), np.array(vs)


def test_runs_are_value_start_length():
    assert runs([0, 0, 1, 1, 1, 0]) == [(0, 0, 2), (1, 2, 3), (0, 5, 1)]


def test_the_modes_own_raster_passes():
    assert timing_errors(*raster(), ARGS) == []


@pytest.mark.parametrize("bend, message", [
    ({"extra_line_in": 0}, f"frame period {T.h_total * (T.v_total + 1)} pixel clocks, expected "
                           f"{T.h_total * T.v_total}"),
    ({"vsync": T.v_sync + 1}, f"vsync pulse {T.h_total * (T.v_sync + 1)} clocks, expected "
                              f"{T.h_total * T.v_sync} ({T.v_sync} lines)"),
    ({"lines": T.v_active - 1}, f"{T.v_active - 1} active lines a frame, expected {T.v_active}"),
    ({"active": T.h_active - 1}, f"active line lengths [{T.h_active - 1}], expected {T.h_active}"),
    ({"hsync": T.h_sync + 1}, f"hsync pulse lengths [{T.h_sync + 1}], expected {T.h_sync}"),
    ({"line_shift": 1}, "hsync periods"),
    ({"active": T.h_active - 1}, f"horizontal front porch {T.h_front + 1}, expected {T.h_front}"),
    ({"first_active_line": 1}, f"vertical back porch {(T.v_back + 1) * T.h_total} clocks, "
                               f"expected {T.v_back * T.h_total}"),
    ({"lines": T.v_active - 1}, "vertical front porch"),
])
def test_each_way_the_raster_is_wrong_is_named(bend, message):
    errors = timing_errors(*raster(**bend), ARGS)
    assert any(message in e for e in errors), errors


def test_a_line_starting_late_is_a_back_porch_error():
    errors = timing_errors(*raster(start=1), ARGS)       # the same end, one pixel later start
    assert f"horizontal back porch {T.h_back + 1}, expected {T.h_back}" in errors, errors
    assert not any("front porch" in e for e in errors)


def test_no_active_line_is_one_error_and_no_porch_is_judged():
    errors = timing_errors(*raster(lines=0), ARGS)
    assert errors == [f"0 active lines a frame, expected {T.v_active}"]


def test_without_two_vertical_syncs_nothing_else_is_judged():
    de, hs, vs = raster()
    assert timing_errors(de, hs, np.ones_like(vs), ARGS) == \
        ["fewer than two vertical sync pulses seen (0)"]
    assert timing_errors(*raster(frames=1), ARGS) == \
        ["fewer than two vertical sync pulses seen (1)"]
