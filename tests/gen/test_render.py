import subprocess
import sys

import numpy as np
from PIL import Image

CLI = [sys.executable, "-m", "bumprtl.gen.cli"]


def test_render_compare_writes_panel_and_prints_psnr(tmp_path):
    out = tmp_path / "lee.png"
    r = subprocess.run(CLI + ["render", "--scene", "bumps", "--method", "lee_fixed", "--size", "64",
                              "--out", str(out), "--compare"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "PSNR" in r.stdout and "max difference" in r.stdout
    img = np.asarray(Image.open(out))
    panel = np.asarray(Image.open(tmp_path / "lee_compare.png"))
    assert img.shape == (64, 64, 3)
    assert panel.shape == (64, 3 * 64 + 8, 3)
    assert panel[:, 136:].any()                         # lee_fixed differs: |diff| is not black


def test_render_exact_equals_conventional(tmp_path):
    for method in ("exact", "conventional"):
        r = subprocess.run(CLI + ["render", "--scene", "globe", "--method", method, "--size", "64",
                                  "--out", str(tmp_path / f"{method}.png")], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
    a, b = (np.asarray(Image.open(tmp_path / f"{m}.png")) for m in ("exact", "conventional"))
    assert np.array_equal(a, b)


def test_render_bad_input_exit_2_one_line(tmp_path):
    for argv, word in ((["--scene", "marble"], "--scene"), (["--size", "100"], "size"),
                       (["--method", "cordic"], "--method"), (["--light-elevation", "100"], "light_elevation"),
                       (["--kd", "2"], "kd")):
        r = subprocess.run(CLI + ["render", "--out", str(tmp_path / "x.png")] + argv,
                           capture_output=True, text=True)
        assert r.returncode == 2, (argv, r.stderr)
        assert word in r.stderr and "Traceback" not in r.stderr


def test_demo_writes_pngs_and_report(tmp_path):
    r = subprocess.run(CLI + ["demo", "--out", str(tmp_path), "--size", "32"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    report = (tmp_path / "report.txt").read_text()
    assert "bricks" in report and "lee_fixed" in report
    assert (tmp_path / "bricks_exact.png").exists() and (tmp_path / "globe_lee_fixed_compare.png").exists()
