import re

from bumprtl.gen.cli.main import main
from bumprtl.sim.golden.float.models import FLOAT_MODELS


def table_rows(stdout):
    return {line.split("|")[1].strip(): [c.strip() for c in line.split("|")[2:-1]]
            for line in stdout.splitlines() if line.startswith("| ") and "---" not in line}


def test_bench_float64_prints_every_model(capsys):
    """In process, so that a coverage or mutation run sees the tables' writers (the command
    line's own parsing is tests/test_cli_boundary.py's)."""
    assert main(["bench", "float64", "--samples", "3000", "--seed", "4"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("bumprtl bench float64 --samples 3000 --seed 4\n"
                          "3000 random valid inputs (seed 4); errors against 'conventional'\n")
    rows = table_rows(out)
    assert list(rows)[1:1 + len(FLOAT_MODELS)] == list(FLOAT_MODELS)   # after the header
    for name in FLOAT_MODELS:
        assert len(rows[name]) == 8, name
        assert float(rows[name][-1]) > 0                        # Mpix/s
    assert rows["conventional"][:7] == ["0"] * 7                # against itself
    assert rows["exact"][:3] == ["-"] * 3                       # no L' of its own
    assert float(rows["lee_corrected"][2]) > 10                 # max L' error, degrees
    assert float(rows["exact"][5]) < 1e-9                       # max diffuse error, LSB
    assert int(rows["lee_printed"][6]) > 0                      # the printed form's NaNs
    assert int(rows["lee_corrected"][6]) == 0
    bins = [rows[f"{lo}-{lo + 15}"] for lo in range(0, 180, 15)]
    assert sum(int(b[0]) for b in bins) == 3000                 # every pixel in one bin
    # the bins split the model table's pixels: their worst is its worst, L' and diffuse
    worst = rows["lee_corrected"][2]
    assert max(float(b[3]) for b in bins) == float(worst)
    assert max(float(b[6]) for b in bins) == float(rows["lee_corrected"][5])
    assert float(bins[0][3]) < float(bins[6][3])                # the circle is exact at 0
    assert "closed-form worst case: 8.61 deg" in out
    fixed = re.search(r"theta_N fixed at 0 deg: ([\d.]+) / [\d.]+, 90 deg: ([\d.]+) / "
                      r"[\d.]+, 180 deg: ([\d.]+) / ", out)
    at0, at90, at180 = (float(v) for v in fixed.groups())
    assert at0 <= 8.61 and at180 <= 8.61 < at90                 # the proportion alone at 0, 180
    pixel = re.search(r"lee_corrected worst L' pixel .*: ([\d.]+) deg, ", out)
    assert pixel.group(1) == worst                              # the row's max, at that pixel


def test_bench_float64_bad_samples_exit_2_one_line(capsys):
    """In process (the command line's own parsing is the test above's)."""
    for argv, word in ((["--samples", "0"], "samples"), (["--seed", "-3"], "seed")):
        assert main(["bench", "float64"] + argv) == 2
        err = capsys.readouterr().err
        assert word in err and "Traceback" not in err and len(err.splitlines()) == 1
