import json
import re
import subprocess
import sys

import numpy as np
from PIL import Image

from bumprtl.gen.render.demo import DEMO_SCENES, demo_methods, rtl_mismatch
from bumprtl.sim.golden.float.models import FLOAT_MODELS

CLI = [sys.executable, "-m", "bumprtl.gen.cli.main"]


def _report_rows(text):
    """(scene, method) -> (psnr, max diff, seconds, file) from report.txt's table."""
    rows = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) == 7 and parts[0] in DEMO_SCENES:
            rows[parts[0], parts[1]] = (float(parts[2]), int(parts[3]), float(parts[4]), parts[6])
    return rows


def test_demo_writes_pngs_and_a_report_that_matches_them(tmp_path):
    """Float renders plus the RTL render of the default scene (Icarus here: one small
    build; ``make demo`` uses Verilator)."""
    r = subprocess.run(CLI + ["demo", "--out", str(tmp_path), "--size", "32", "--simulator", "icarus"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    rows = _report_rows((tmp_path / "report.txt").read_text())
    methods = demo_methods()
    assert methods[0] == "conventional" and set(FLOAT_MODELS) <= set(methods)
    assert set(rows) == {(s, m) for s in DEMO_SCENES for m in methods}
    for (scene, method), (db, diff, seconds, name) in rows.items():
        ref = np.asarray(Image.open(tmp_path / f"{scene}_conventional.png"), float)
        img = np.asarray(Image.open(tmp_path / name), float)
        assert img.shape == (32, 32, 3) and seconds >= 0
        mse = np.mean((ref - img) ** 2)                 # PSNR recomputed from the PNGs
        assert diff == np.abs(ref - img).max()
        assert db == float("inf") if mse == 0 else abs(db - 10 * np.log10(255 ** 2 / mse)) < 0.006
        if method != "conventional":
            assert (tmp_path / f"{scene}_{method}_compare.png").exists()
    assert rows["bricks", "exact"][:2] == (float("inf"), 0)
    _check_rtl_section(tmp_path, (tmp_path / "report.txt").read_text())


def _check_rtl_section(out, report):
    rtl, golden, diff = (np.asarray(Image.open(out / f"{n}.png")) for n in ("rtl", "golden", "diff"))
    assert rtl.shape == (32, 32, 3) and rtl.tobytes() == golden.tobytes() and not diff.any()
    assert rtl.std() > 5                                           # a picture, not a blank
    meta = json.loads((out / "pipeline" / "pipeline.json").read_text())
    assert (out / "pipeline" / "pipeline.v").read_text().lstrip().startswith(("//", "/*", "(*", "module"))
    assert [b["unit"] for b in meta["built"]] == ["fetch", "rotation", "illumination"]
    m = re.search(r"(\d+) pixels in (\d+) cycles without stalls = ([\d.]+) cycles per pixel", report)
    pixels, cycles, cpp = int(m[1]), int(m[2]), float(m[3])
    assert pixels == 32 * 32 and pixels < cycles <= pixels + meta["latency"] + 1
    assert abs(cpp - cycles / pixels) < 1e-4
    assert "identical bytes" in report and "multipliers" in report and "RAM bits 98304" in report


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
    from bumprtl.gen.render import demo
    sub = argparse.ArgumentParser().add_subparsers()
    demo.add_parser(sub)
    parser = sub.choices["demo"]
    assert parser.parse_args([]).rtl and parser.parse_args([]).simulator == "verilator"
    assert not parser.parse_args(["--no-rtl"]).rtl


def test_demo_bad_size_exit_2(tmp_path):
    r = subprocess.run(CLI + ["demo", "--out", str(tmp_path), "--size", "48"], capture_output=True, text=True)
    assert r.returncode == 2 and "size" in r.stderr and "Traceback" not in r.stderr
    assert not any(tmp_path.iterdir())
