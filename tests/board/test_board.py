"""The board top (rtl/board.py, docs/board.md): TMDS words decoded by cocotbext-dvi's own
tables, the sync/blanking checker, the reduced-mode frames through the whole top captured
by cocotbext-dvi's DVISink and compared with the golden frames, and bad input.

The frame check here runs the reduced mode (32 x 24, short blanking) on a scene with
10-bit angles and a 16 x 16 map (the default's 14-bit angles make 12 sine ROMs of 4097
words whose Verilator build takes minutes); ``make board`` checks whole 640 x 480 frames of
the default scene.
"""

import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cocotbext.dvi.tmds import TMDS

from bumprtl.gen.flow.board import board_data, board_memory, check_board, check_frames
from bumprtl.rtl.tmds import CONTROL
from bumprtl.rtl.video import MODES
from bumprtl.sim.golden.board import golden_frame, light_table
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.tb_board import timing_errors
from tests.rtl.test_tmds import encode_rtl

SMALL = {"angle_bits": 10, "texture_size": 16}


def test_tmds_words_decode_with_cocotbext_tables_and_stay_dc_balanced():
    rng = np.random.default_rng(1)
    data = [int(x) for x in rng.integers(0, 256, 2000)] + [0, 255] * 50 + [0x10] * 40
    values = [(v, 1, 0, 0) for v in data]
    values += [(0, 0, c & 1, c >> 1) for c in range(4)]
    words = encode_rtl([v if d else (c1, c0) for v, d, c0, c1 in values])
    dec = TMDS()
    disparity, worst = 0, 0
    for (v, d, c0, c1), w in zip(values, words, strict=False):
        out, de, vs, hs = dec.decode(w)
        if d:
            assert de == 1 and out == v, f"{v:#04x} -> {w:#05x} decoded {out:#04x}"
            ones = bin(w).count("1")
            disparity += ones - (10 - ones)
            worst = max(worst, abs(disparity))
        else:
            assert w == CONTROL[c1 << 1 | c0] and (de, hs, vs) == (0, c0, c1)
    assert worst <= 20, f"running disparity reached {worst}: no DC balance"


def test_timing_checker_catches_a_wrong_porch():
    t = MODES["test"]
    args = (t.h_active, t.h_front, t.h_sync, t.h_back, t.v_active, t.v_front, t.v_sync,
            t.v_back, 1, 1)

    def raster(hb):
        de, hs, vs = [], [], []
        for _frame in range(3):
            for y in range(t.v_total):
                for x in range(t.h_total):
                    de.append(int(x < t.h_active and y < t.v_active))
                    hs.append(int(not (t.h_active + t.h_front <= x < t.h_active + t.h_front + t.h_sync)))
                    vs.append(int(not (t.v_active + t.v_front <= y < t.v_active + t.v_front + t.v_sync)))
        return de, hs, vs

    assert timing_errors(*raster(t.h_back), args) == []
    de, hs, vs = raster(t.h_back)
    de = de[1:] + [0]                           # active video one pixel early
    assert any("porch" in e for e in timing_errors(de, hs, vs, args))


def test_reduced_mode_frames_match_the_golden_frames_through_the_dvi_sink(build_dir):
    """The source and pipeline in their own clock domain, 1.3 x the pixel clock, behind the
    asynchronous FIFO (rtl/board.cdc_depth); ``make board`` checks whole 640 x 480 frames
    with one clock."""
    scene = load_scene_config("default", SMALL)
    mode = MODES["test"]
    r = check_frames(scene, mode, build_dir / "board", frames=2, opt_fast="-O0",   # a cocotb-paced run
                     pipe_hz=1.3 * mode.pixel_hz)
    assert (build_dir / "board" / "board_sim.v").read_text().count("pipe_clk") >= 2
    assert r["timing_errors"] == []
    assert r["underflow"] == 0 and r["order_error"] == 0
    for k, (c, g) in enumerate(zip(r["captured"], r["golden"], strict=False)):
        assert c.shape == g.shape == (mode.v_active, mode.h_active, 3), k
        assert np.array_equal(c, g), f"frame {k}: {np.count_nonzero(np.any(c != g, -1))} pixels differ"
    # the light turns: consecutive frames differ, so the comparison sees the light step
    assert not np.array_equal(r["golden"][0], r["golden"][1])


@pytest.mark.regress
@pytest.mark.parametrize("scene_name", ["default", "globe"])
def test_reduced_mode_frames_with_the_map_in_sdram_through_the_dvi_sink(scene_name, build_dir,
                                                                        tmp_path):
    """The map in the SDRAM (``map_memory = "axi"``): the testbench runs the SDRAM's
    datasheet model and the flash model, the loader copies the map's image from the flash
    offset into the SDRAM, the texel cache reads it; the frames from the display's second
    on equal the golden frames 1, 2. The same top with one texel's bytes changed in the
    flash shows a different frame (so the frames come from the SDRAM's copy). About 100 s
    of CPU a scene (Verilator build, then the run; the second run reuses the build)."""
    if scene_name == "globe":
        (tmp_path / "globe.toml").write_text('image = "globe"\n')
        scene_name = str(tmp_path / "globe.toml")
    scene = load_scene_config(scene_name, {**SMALL, "map_memory": "axi"})
    mode = MODES["test"]
    memory = board_memory(scene, mode)
    out = build_dir / f"board_axi_{Path(scene_name).stem}"
    r = check_frames(scene, mode, out, frames=2, memory=memory)
    assert r["first"] == 1 and r["timing_errors"] == []
    assert r["underflow"] == 0 and r["order_error"] == 0
    for k, (c, g) in enumerate(zip(r["captured"], r["golden"], strict=True)):
        assert c.shape == g.shape == (mode.v_active, mode.h_active, 3), k
        assert np.array_equal(c, g), f"frame {k}: {np.count_nonzero(np.any(c != g, -1))} pixels differ"
    image = bytearray(memory.image)
    for at in range(0, len(image), 4):          # every texel's first byte
        image[at] ^= 0x5A
    bad = check_frames(scene, mode, out, frames=2,
                       memory=dataclasses.replace(memory, image=bytes(image)))
    assert bad["build_s"] < 1.0                 # the same Verilog: the build was reused
    assert not all(bad["same"])


@pytest.mark.regress
def test_reduced_mode_frames_with_the_map_preloaded_in_sdram(build_dir, tmp_path):
    """``preload``: no flash loader in the simulated top, the SDRAM's model holding the
    map's image as the loader would have written it (gen/flow/board.sdram_preload); the
    globe's frames equal the golden frames 1, 2, and with every texel's first byte changed
    in the image the frames differ (the pixels come from the preloaded words)."""
    (tmp_path / "globe.toml").write_text('image = "globe"\n')
    scene = load_scene_config(str(tmp_path / "globe.toml"), {**SMALL, "map_memory": "axi"})
    mode = MODES["test"]
    memory = board_memory(scene, mode)
    out = build_dir / "board_axi_preloaded"
    r = check_frames(scene, mode, out, frames=2, memory=memory, preload=True)
    assert "spi_" not in (out / "board_sim.v").read_text()      # no flash pins, no loader
    assert r["first"] == 1 and r["timing_errors"] == []
    assert r["underflow"] == 0 and r["order_error"] == 0
    assert all(r["same"]), r["same"]
    image = bytearray(memory.image)
    for at in range(0, len(image), 4):
        image[at] ^= 0x5A
    bad = check_frames(scene, mode, out, frames=2, preload=True,
                       memory=dataclasses.replace(memory, image=bytes(image)))
    assert bad["build_s"] < 1.0
    assert not all(bad["same"])


def test_golden_frames_follow_the_light_table():
    scene = load_scene_config("default", SMALL)
    table = light_table(scene)
    assert len({tuple(sorted(t.items())) for t in table}) > len(table) // 2
    words, texels, _, table = board_data(scene)
    a = golden_frame(scene, MODES["test"], 0, table, words)
    b = golden_frame(scene, MODES["test"], len(table), table, words)
    assert np.array_equal(a, b)                 # one turn later: the same light


@pytest.mark.parametrize("argv, word", [
    (["board", "nosuch"], "board must be one of"),
    (["board", "ulx3s", "--mode", "1024x768"], "mode must be one of"),
    (["board", "ulx3s", "--scene", "palette"], "scene 'palette'"),
    (["board", "ulx3s", "--texture-size", "4096"], "block RAM"),
    (["board", "ulx3s", "--check-frames", "1", "--preload-sdram"],
     "--preload-sdram applies to a map in the SDRAM"),
    (["board", "ulx3s", "--map-memory", "axi", "--preload-sdram"], "needs --check-frames"),
])
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, argv, word, run_cli):
    out = tmp_path / "out"
    if argv == ["board", "nosuch"]:             # once through a real process (tests/conftest.py)
        r = subprocess.run([sys.executable, "-m", "bumprtl.gen.cli.main", *argv, "--out", str(out)],
                           capture_output=True, text=True)
    else:
        r = run_cli([*argv, "--out", out])
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and word in lines[0], r.stderr
    assert not out.exists()


def test_check_board_names_the_block_ram_overrun():
    scene = load_scene_config("default", {"texture_size": 1024})
    with pytest.raises(Exception) as e:
        check_board("ulx3s", "640x480", scene)
    assert "too many" in str(e.value) and "DP16KD" in str(e.value)


def test_check_board_refuses_a_surface_other_than_the_plane_or_the_sphere():
    with pytest.raises(Exception) as e:
        check_board("ulx3s", "640x480", load_scene_config("default", {"geometry": "cylinder"}))
    assert "geometry 'cylinder'" in str(e.value) and e.value.field == "geometry"
    check_board("ulx3s", "640x480", load_scene_config("default"))
    check_board("ulx3s", "640x480", load_scene_config("default", {"geometry": "sphere"}))
