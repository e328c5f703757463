import subprocess
import sys

from bumprtl.gen.cli.main import main
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


def test_bench_float64_bad_samples_exit_2_one_line(capsys):
    """In process (the command line's own parsing is the test above's)."""
    for argv, word in ((["--samples", "0"], "samples"), (["--seed", "-3"], "seed")):
        assert main(["bench", "float64"] + argv) == 2
        err = capsys.readouterr().err
        assert word in err and "Traceback" not in err and len(err.splitlines()) == 1
