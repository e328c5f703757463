"""Bad input to the ``bumprtl bench`` kinds make test does not otherwise start: one stderr
line naming the flag and the allowed range, exit 2, before any table or file is written
(but the kind's empty tool log)."""

import pytest

CASES = [
    (["float64", "--samples", "0"], "--samples must be >= 1, got 0"),
    (["lee-widths", "--samples", "-5"], "--samples must be >= 1, got -5"),
    (["golden", "--pixels", "0"], "--pixels must be >= 1, got 0"),
    (["golden", "--sim-samples", "-1"], "--sim-samples must be >= 0, got -1"),
    (["specular", "--samples", "0"], "--samples must be >= 1, got 0"),
    (["specular", "--spec-exponent", "16", "0"], "spec_exponent = 0 is out of range"),
    (["palette", "--what", "speed", "images", "--sizes", "8", "0"], "--sizes must be >= 1, got 0"),
    (["palette", "--what", "speed", "images", "--palettes", "-2"],
     "--palettes must be >= 1, got -2"),
]


@pytest.mark.parametrize("argv, message", CASES, ids=[" ".join(a) for a, _ in CASES])
def test_bad_bench_input_is_one_line_exit_2_nothing_written(argv, message, tmp_path, run_cli,
                                                            monkeypatch):
    monkeypatch.chdir(tmp_path)
    extra = ["--images-dir", tmp_path / "img"] if argv[0] == "palette" else []
    extra += ["--work", tmp_path / "work"] if argv[0] == "specular" else []
    r = run_cli(["bench", *argv, *extra])
    assert r.returncode == 2
    assert r.stderr.strip().splitlines() == [f"bumprtl: error: {r.stderr.split('error: ')[1].strip()}"]
    assert message in r.stderr and "Traceback" not in r.stderr
    assert r.stdout == ""
    # only the tools' log of the kind (gen/cli/quiet.py), which holds nothing here
    written = [p for p in tmp_path.rglob("*") if p.is_file()]
    assert written in ([], [tmp_path / "build" / "bench" / f"{argv[0]}.log"]), written
    assert all(p.read_text() == "" for p in written)
