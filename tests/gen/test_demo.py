import subprocess
import sys

import numpy as np
from PIL import Image

from bumprtl.gen.demo import DEMO_SCENES, demo_methods
from bumprtl.sim.golden.models import FLOAT_MODELS

CLI = [sys.executable, "-m", "bumprtl.gen.cli"]


def _report_rows(text):
    """(scene, method) -> (psnr, max diff, seconds, file) from report.txt's table."""
    rows = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) == 7 and parts[0] in DEMO_SCENES:
            rows[parts[0], parts[1]] = (float(parts[2]), int(parts[3]), float(parts[4]), parts[6])
    return rows


def test_demo_writes_pngs_and_a_report_that_matches_them(tmp_path):
    r = subprocess.run(CLI + ["demo", "--out", str(tmp_path), "--size", "32"], capture_output=True, text=True)
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


def test_demo_bad_size_exit_2(tmp_path):
    r = subprocess.run(CLI + ["demo", "--out", str(tmp_path), "--size", "48"], capture_output=True, text=True)
    assert r.returncode == 2 and "size" in r.stderr and "Traceback" not in r.stderr
    assert not any(tmp_path.iterdir())
