import subprocess
import sys

from bumprtl.sim.golden.float.models import FLOAT_MODELS

CLI = [sys.executable, "-m", "bumprtl.gen.cli.main"]


def table_rows(stdout):
    return {line.split("|")[1].strip(): [c.strip() for c in line.split("|")[2:-1]]
            for line in stdout.splitlines() if line.startswith("| ") and "---" not in line}


def test_bench_float64_prints_every_model():
    r = subprocess.run(CLI + ["bench", "float64", "--samples", "3000", "--seed", "4"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    rows = table_rows(r.stdout)
    for name in FLOAT_MODELS:
        assert len(rows[name]) == 8, name
        assert float(rows[name][-1]) > 0                        # Mpix/s
    assert float(rows["lee_corrected"][2]) > 10                     # max L' error, degrees
    assert float(rows["exact"][5]) < 1e-9                       # max diffuse error, LSB
    assert int(rows["lee_printed"][6]) > 0                      # the printed form's NaNs
    assert sum(int(rows[f"{lo}-{lo + 15}"][0]) for lo in range(0, 180, 15)) == 3000
    assert "closed-form worst case: 8.61 deg" in r.stdout


def test_bench_float64_bad_samples_exit_2_one_line():
    for argv, word in ((["--samples", "0"], "samples"), (["--seed", "-3"], "seed")):
        r = subprocess.run(CLI + ["bench", "float64"] + argv, capture_output=True, text=True)
        assert r.returncode == 2, r.stderr
        assert word in r.stderr and "Traceback" not in r.stderr and len(r.stderr.splitlines()) == 1
