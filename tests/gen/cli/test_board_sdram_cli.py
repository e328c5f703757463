"""``bumprtl board ulx3s`` with the map in the SDRAM (``--map-memory axi``; gen/cli/board.py,
gen/flow/board.board_memory), the bitstream flow stood in: the flash image it writes is the
texel cache's tiled image of the scene's map (rtl/cache.tiled_image, computed here from the
map's words; its size and a few texels' bytes at the documented layout's offsets), the
FlashConfig copies exactly those bytes from the flash offset, the programming commands are
printed, and every bad input (an unknown SDRAM variant, a map larger than the SDRAM, a
flash offset inside the bitstream or off a sector, a pipe clock above the SDRAM's, the
SDRAM flags on a map in block RAM, a frame check the bench cannot do) is one line, exit 2,
nothing written."""

import json

import numpy as np
import pytest

from bumprtl.gen.cli import board as cli_board
from bumprtl.gen.flow.board import BITSTREAM_BYTES, FLASH_SECTOR, board_data
from bumprtl.rtl.cache import scene_geometry, scene_levels, tiled_image
from bumprtl.sim.scenes.config import load_scene_config

AXI = ["--texture-size", "16", "--map-memory", "axi"]


def _no(*args, **kw):
    raise AssertionError("not to be called here")


def test_the_flash_image_is_the_caches_tiled_image_of_the_map(tmp_path, monkeypatch, run_cli):
    seen = {}

    def build(scene, mode, out, board, seeds, pipe_hz=None, memory=None):
        seen.update(memory=memory, scene=scene, files=sorted(p.name for p in out.iterdir()))
        return [{"seed": 1, "seconds": 1.0, "resources": {"LUT4": (1, 2)},
                 "fmax": {"pipe": (90.0, 89.3)}}]
    monkeypatch.setattr(cli_board, "build_bitstream", build)
    out = tmp_path / "b"
    r = run_cli(["board", "ulx3s", *AXI, "--out", out, "--flash-offset", "0x300000",
                 "--sdram", "64mb"])
    assert r.returncode == 0, r.stderr
    image = (out / "ulx3s_85f_map.bin").read_bytes()
    assert seen["files"] == ["ulx3s_85f_map.bin"]           # written before the build
    # the same bytes, independently: the scene's map words tiled by rtl/cache.tiled_image
    scene = load_scene_config("default", {"texture_size": 16, "map_memory": "axi"})
    geom = scene_geometry(scene.hardware)
    words = np.asarray(board_data(scene)[0], np.int64)
    assert image == tiled_image(geom, scene_levels(scene.hardware, words))
    assert len(image) == geom.image_bytes == geom.lines * geom.line_bytes
    # a few texels of level 0 at the documented layout's byte (docs/memory.md, the sidecar):
    # base + line * line_bytes + ((v mod B) * B + (u mod B)) * slot_bytes,
    # line = (v div B) * (T / B) + (u div B), little-endian in the slot
    T, B, slot = 16, geom.block, geom.slot_bytes
    for u, v in ((0, 0), (1, 0), (0, 1), (B, 0), (0, B), (5, 11), (T - 1, T - 1)):
        line = (v // B) * (T // B) + u // B
        at = geom.base + line * geom.line_bytes + ((v % B) * B + u % B) * slot
        assert int.from_bytes(image[at:at + slot], "little") == words[v * T + u], (u, v)
    # what the flash loader copies: these bytes, from the offset, to the cache's base
    mem = seen["memory"]
    assert (mem.flash.offset, mem.flash.length, mem.flash.base) == (0x300000, len(image), geom.base)
    assert mem.image == image and mem.sdram.variant == "64mb"
    assert mem.flash.data_bits == mem.sdram.data_bits == geom.data_bits
    assert f"openFPGALoader --board ulx3s -f -o 0x300000 {out / 'ulx3s_85f_map.bin'}" in r.stdout
    assert f"openFPGALoader --board ulx3s -f {out / 'ulx3s_85f.bit'}" in r.stdout
    summary = json.loads((out / "summary_640x480.json").read_text())
    assert (summary["map_memory"], summary["sdram"], summary["flash_offset"]) == ("axi", "64mb", 0x300000)
    assert summary["pipe_mhz"] == pytest.approx(625 / 7)          # at or below 100 MHz


def _first_free_sector():
    return -(-BITSTREAM_BYTES["LFE5U-85F"] // FLASH_SECTOR) * FLASH_SECTOR


@pytest.mark.parametrize("flags, message", [
    (["--sdram", "16mb"], "--sdram must be one of 32mb, 64mb"),
    (["--sdram", "16mb", "--no-bitstream"], "--sdram must be one of 32mb, 64mb"),
    (["--texture-size", "4096"], "texture_size 4096: the map's tiled image ends at byte "
                                 "67,108,864, beyond the 32mb SDRAM's 33,554,432 bytes"),
    (["--texture-size", "2048"], "texture_size 2048: the map's tiled image is 16,777,216 bytes, "
                                 "more than the 14,680,064 bytes of flash from 0x200000"),
    (["--flash-offset", "0"], "--flash-offset must be a multiple of 0x10000"),
    (["--flash-offset", hex(_first_free_sector() - FLASH_SECTOR)],
     f"in [0x{_first_free_sector():x}, "),
    (["--flash-offset", hex(_first_free_sector() + 0x1000)], "a 64 KiB sector"),
    (["--flash-offset", "0xfff0000"], "within the 24-bit READ address"),
    (["--flash-offset", "2M"], "--flash-offset must be an integer byte offset"),
    (["--pipe-mhz", "120"], "pipe clock must be at most 100 MHz with the map in the SDRAM "
                            "(CAS latency 2: tCK >= 10 ns"),
    (["--pipe-mhz", "20"], "pipe clock must be at least the pixel clock"),
])
def test_bad_input_with_the_map_in_sdram_one_line_exit_2_nothing_written(flags, message,
                                                                          board_refusal):
    line = board_refusal([*AXI, *flags])
    assert message in line, line


@pytest.mark.parametrize("flag", [["--sdram", "32mb"], ["--flash-offset", "0x200000"]])
def test_the_sdram_flags_on_a_map_in_block_ram_are_refused(flag, board_refusal):
    assert board_refusal(["--texture-size", "16", *flag]) == (
        f"bumprtl: error: {flag[0]} applies to a map in the SDRAM (--map-memory axi), the "
        f"scene's map_memory is 'bram'")


def test_a_bitstream_reaching_past_the_map_is_an_error_after_the_build(tmp_path, monkeypatch,
                                                                        run_cli):
    """The refusal before the build bounds the bitstream by the uncompressed size; the .bit
    the flow wrote is checked against the offset too (exit 1, the error named)."""
    def build(scene, mode, out, board, seeds, pipe_hz=None, memory=None):
        with open(out / "ulx3s_85f.bit", "wb") as f:       # sparse: its size is what counts
            f.truncate(size)
        return [{"seed": 1, "seconds": 1.0, "resources": {}, "fmax": {}}]
    monkeypatch.setattr(cli_board, "build_bitstream", build)
    for size, status in ((0x200000, 0), (0x200001, 1)):
        out = tmp_path / f"b{size}"
        r = run_cli(["board", "ulx3s", *AXI, "--out", out])
        assert r.returncode == status, r.stderr
        assert ("the bitstream's 2,097,153 bytes reach past the map's flash offset 0x200000"
                in r.stderr) == bool(status)


def test_a_2_to_1_map_image_is_tiled_by_its_width_and_height(tmp_path, run_cli):
    """A 32 x 16 globe map (texture_height 16, W = 2H: equirectangular) in the SDRAM: the
    board run without a bitstream writes its tiled image, (32 x 16) / (4 x 4) lines of 64
    bytes; texels of level 0 sit at the documented layout's byte with a line W / B blocks
    long (computed here), each the scene's word at row v, column u of the W x H map."""
    scene_file = tmp_path / "globe.toml"
    scene_file.write_text('image = "globe"\ntexture_size = 32\ntexture_height = 16\n'
                          'map_memory = "axi"\n')
    out = tmp_path / "b"
    r = run_cli(["board", "ulx3s", "--scene", scene_file, "--out", out, "--no-bitstream"])
    assert r.returncode == 0, r.stderr
    image = (out / "ulx3s_85f_map.bin").read_bytes()
    W, H, B, slot = 32, 16, 4, 4
    assert len(image) == (W // B) * (H // B) * B * B * slot == 2048
    scene = load_scene_config(str(scene_file))
    words = np.asarray(board_data(scene)[0], np.int64)
    assert len(words) == W * H
    for u, v in ((0, 0), (1, 0), (0, 1), (B, 0), (0, B), (29, 13), (W - 1, H - 1), (W - 1, 0)):
        at = ((v // B) * (W // B) + u // B) * B * B * slot + ((v % B) * B + u % B) * slot
        assert int.from_bytes(image[at:at + slot], "little") == words[v * W + u], (u, v)


def test_the_2048_by_1024_globe_map_fits_the_flash_and_2048_square_does_not():
    """The ULX3S globe at 1280 x 720 with a 2048 x 1024 map in the SDRAM passes the board's
    checks (its tiled image 2048 x 1024 texels of 4 bytes: 8,388,608 bytes, within the
    14,680,064 bytes of flash after the bitstream); texture_height = 512 is refused for the
    globe (a latitude-longitude map is W = 2H or square), naming texture_height."""
    from bumprtl.gen.flow.board import check_board
    from bumprtl.rtl.config import BumpError
    keys = {"image": "globe", "texture_size": 2048, "texture_height": 1024, "map_memory": "axi"}
    scene = load_scene_config(keys)
    assert check_board("ulx3s", "1280x720", scene)[1] == "LFE5U-85F"
    assert scene_geometry(scene.hardware).image_bytes == 2048 * 1024 * 4 == 8_388_608
    with pytest.raises(BumpError, match="16,777,216 bytes, more than the 14,680,064") as e:
        check_board("ulx3s", "1280x720", load_scene_config({**keys, "texture_height": None}))
    assert e.value.field == "texture_size"
    with pytest.raises(BumpError, match="texture_height = texture_size / 2 = 1024") as e:
        check_board("ulx3s", "1280x720", load_scene_config({**keys, "texture_height": 512}))
    assert e.value.field == "texture_height"


def _budgets(holds):
    from types import SimpleNamespace
    return [SimpleNamespace(holds=holds, slack=5.0 if holds else -7.0, worst=(12, 34),
                            misses=np.array([1, 2])) for _ in range(2)]


def test_the_display_buffer_goes_to_the_design_with_its_prediction(tmp_path, monkeypatch,
                                                                   run_cli):
    """The FIFO ahead of the clock crossing the prediction derives reaches the design
    (BoardMemory), is counted in the block-RAM budget, and a prediction that starves is a warning, not an
    error; a buffer larger than the block RAM is refused before anything is written."""
    seen = {}

    def build(scene, mode, out, board, seeds, pipe_hz=None, memory=None):
        seen["memory"] = memory
        return [{"seed": 1, "seconds": 1.0, "resources": {}, "fmax": {}}]
    monkeypatch.setattr(cli_board, "build_bitstream", build)
    monkeypatch.setattr(cli_board, "display_buffer", lambda *a, **k: (4096, _budgets(False)))
    r = run_cli(["board", "ulx3s", *AXI, "--out", tmp_path / "a"])
    assert r.returncode == 0, r.stderr
    assert seen["memory"].display_buffer == 4096
    assert "display buffer: 4096 entries" in r.stdout and "3 / 3 texel cache misses" in r.stdout
    assert r.stderr.startswith("bumprtl: warning: the display is predicted to starve even "
                               "with 4096 entries ahead of the clock crossing (first late "
                               "pixel at line 12, column 34)")
    # none needed: the design as it was
    monkeypatch.setattr(cli_board, "display_buffer", lambda *a, **k: (None, _budgets(True)))
    r = run_cli(["board", "ulx3s", *AXI, "--out", tmp_path / "b"])
    assert r.returncode == 0 and "warning" not in r.stderr
    assert "display buffer: none (ahead of the clock crossing" in r.stdout
    assert seen["memory"].display_buffer is None
    # 2**20 entries of 8 + 16 bits: more block RAM than the device has
    monkeypatch.setattr(cli_board, "display_buffer", lambda *a, **k: (1 << 20, _budgets(True)))
    out = tmp_path / "c"
    r = run_cli(["board", "ulx3s", *AXI, "--out", out])
    assert r.returncode == 2 and not out.exists()
    assert r.stderr.strip().startswith("bumprtl: error: block RAM: the board needs")
    assert "display buffer" in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_the_display_buffer_is_not_predicted_without_a_design(tmp_path, monkeypatch, run_cli):
    monkeypatch.setattr(cli_board, "display_buffer", _no)
    r = run_cli(["board", "ulx3s", *AXI, "--out", tmp_path / "a", "--no-bitstream"])
    assert r.returncode == 0, r.stderr
