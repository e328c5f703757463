import re

import numpy as np
from PIL import Image

from bumprtl.gen.flow.memories import bram_blocks
from bumprtl.gen.render.demo import DEMO_SCENES, demo_map_size, demo_methods, rtl_mismatch
from bumprtl.gen.render.images import FIXED_METHODS, float_image
from bumprtl.rtl.config import Config
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.golden.float.models import FLOAT_MODELS
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.scenes.heightfields import brick_lines


def _report_rows(text):
    """(scene, method) -> (psnr, max diff, fixed psnr, fixed max, seconds, file) from
    report.txt's table ('-' fixed columns: None)."""
    rows = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) == 9 and parts[0] in DEMO_SCENES:
            fixed = (None, None) if parts[4] == "-" else (float(parts[4]), int(parts[5]))
            rows[parts[0], parts[1]] = (float(parts[2]), int(parts[3]), *fixed, float(parts[6]),
                                        parts[8])
    return rows


def _psnr(ref, img):
    mse = np.mean((ref - img) ** 2)
    return float("inf") if mse == 0 else 10 * np.log10(255 ** 2 / mse)


def test_demo_writes_pngs_and_a_report_that_matches_them(tmp_path, run_cli):
    """Float renders plus the RTL render of the default scene (Icarus here: one small
    build; ``make demo`` uses Verilator). In this process (tests/conftest.py run_cli: its
    output captured at the file descriptors, the simulator's included), not a second
    interpreter importing numpy, Amaranth and the package again; tests/gen/render/test_render.py
    and tests/board/test_board.py keep a bumprtl command through a real process."""
    r = run_cli(["demo", "--out", tmp_path, "--size", "32", "--simulator", "icarus"])
    assert r.returncode == 0, r.stderr
    rows = _report_rows((tmp_path / "report.txt").read_text())
    methods = demo_methods()
    assert methods[0] == "conventional" and set(FLOAT_MODELS) <= set(methods)
    assert set(rows) == {(s, m) for s in DEMO_SCENES for m in methods}
    for (scene, method), (db, diff, fdb, fdiff, seconds, name) in rows.items():
        ref = np.asarray(Image.open(tmp_path / f"{scene}_conventional.png"), float)
        img = np.asarray(Image.open(tmp_path / name), float)
        assert img.shape == (32, 32, 3) and seconds >= 0
        assert diff == np.abs(ref - img).max()           # recomputed from the PNGs
        assert db == _psnr(ref, img) or abs(db - _psnr(ref, img)) < 0.006
        if method != "conventional":
            assert (tmp_path / f"{scene}_{method}_compare.png").exists()
        assert (fdb is None) == (method not in FIXED_METHODS), method
        if fdb is not None:                              # the fixed-point render's PNG
            fixed = np.asarray(Image.open(tmp_path / f"{scene}_{method}_fixed.png"), float)
            assert fdiff == np.abs(ref - fixed).max()
            assert fdb == _psnr(ref, fixed) or abs(fdb - _psnr(ref, fixed)) < 0.006   # inf: identical
    assert rows["bricks", "exact"][:2] == (float("inf"), 0)
    assert rows["bricks", "exact"][3] <= 2 and rows["globe", "exact"][3] <= 2
    _check_rtl_section(tmp_path, (tmp_path / "report.txt").read_text())
    # quiet: the table with its header, the RTL summary; the simulator's output in the log
    shown = r.stdout.splitlines() + r.stderr.splitlines()
    assert len(shown) < 30, shown
    assert shown[0].split()[:3] == ["scene", "method", "PSNR"], shown[0]
    assert not any("g++" in line or "cocotb" in line.lower() for line in shown), shown
    log = tmp_path / "sim" / "tools.log"
    assert f"tool output: {log}" in r.stderr and log.stat().st_size > 0
    pic = np.asarray(Image.open(tmp_path / "rtl_vs_float64.png"))
    assert pic.shape == (256, 2 * 256 + 8, 3)


def _check_rtl_section(out, report):
    rtl, golden, diff = (np.asarray(Image.open(out / f"{n}.png")) for n in ("rtl", "golden", "diff"))
    assert rtl.shape == (32, 32, 3) and rtl.tobytes() == golden.tobytes() and not diff.any()
    assert rtl.std() > 5                                           # a picture, not a blank
    meta = load_sidecar(out / "pipeline" / "pipeline.json")
    assert (out / "pipeline" / "pipeline.v").read_text().lstrip().startswith(("//", "/*", "(*", "module"))
    assert [b["unit"] for b in meta.built] == ["fetch", "rotation", "illumination"]
    m = re.search(r"(\d+) pixels in (\d+) cycles without stalls = ([\d.]+) cycles per pixel", report)
    pixels, cycles, cpp = int(m[1]), int(m[2]), float(m[3])
    assert pixels == 32 * 32 and pixels < cycles <= pixels + meta.latency + 1
    assert abs(cpp - cycles / pixels) < 1e-4
    t = demo_map_size(32)                                          # the largest that fits: 32
    lines = [int(r) for r in brick_lines(t)[0]]                    # narrow map: on texel rows
    green = rtl[..., 1].astype(float).mean(axis=1)                 # mortar is grey: more green
    assert min(green[lines]) > max(np.delete(green, lines)) + 10   # rtl.png shows the courses
    w = 2 * Config().angle_bits                                    # a map word: phi and theta
    # the map and the credit edge's FIFO storage (rtl/pipe.CreditFIFO: the next power of two
    # words at least fifo_depth) are the RAMs of the flattened pipeline
    fifo = (1 << (meta.fifo_depth - 1).bit_length()) * meta.port("o__payload").width
    assert t == 32 and f"map {t}x{t} x {w} bits" in report and f"RAM bits {t * t * w + fifo}" in report
    assert "identical bytes" in report and "multipliers" in report
    assert (out / "pipeline" / "pipeline_map.hex").read_text().count("\n") == t * t
    ref, _ = float_image(load_scene_config("default").replace(texture_size=t), "conventional", 32,
                         progress=False)
    m = re.search(r"rtl.png vs float64 conventional \(same scene and map\): PSNR ([\d.]+) dB, "
                  r"max difference (\d+)", report)
    assert abs(float(m[1]) - _psnr(ref.astype(float), rtl.astype(float))) < 0.006
    assert int(m[2]) == np.abs(ref.astype(int) - rtl.astype(int)).max() <= 2


def test_demo_map_is_the_largest_that_fits_the_device():
    assert demo_map_size(512) == 256 and demo_map_size(64) == 64
    # the LFE5U-25F's 56 DP16KD: the default's tables take 49 (twelve 4097-word sine ROMs in
    # four x4 blocks each, the cos^n table in one), a 64^2 map of 28-bit texels 7, a 128^2 28
    assert demo_map_size(512, device="LFE5U-25F") == 64
    assert bram_blocks(64 * 64, 28) == 7 and bram_blocks(128 * 128, 28) == 28


def test_rtl_mismatch_names_the_difference():
    a = np.zeros((4, 4, 3), np.uint8)
    assert rtl_mismatch(a, a.copy()) is None
    b = a.copy()
    b[1, 2, 0], b[3, 3, 2] = 7, 1
    assert rtl_mismatch(b, a) == ("RTL image differs from the fixed-point golden image in 2 pixels "
                                  "(max |difference| 7)")
    assert "shape" not in rtl_mismatch(a[:2], a) and "(2, 4, 3)" in rtl_mismatch(a[:2], a)


def test_demo_flags():
    import argparse

    from bumprtl.gen.cli import demo
    sub = argparse.ArgumentParser().add_subparsers()
    demo.add_parser(sub)
    parser = sub.choices["demo"]
    assert parser.parse_args([]).rtl and parser.parse_args([]).simulator == "verilator"
    assert not parser.parse_args(["--no-rtl"]).rtl


def test_demo_bad_size_exit_2(tmp_path, run_cli):
    r = run_cli(["demo", "--out", tmp_path, "--size", "48"])        # in this process
    assert r.returncode == 2 and "size" in r.stderr and "Traceback" not in r.stderr
    assert not any(tmp_path.iterdir())
