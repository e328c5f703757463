"""Command-line refusals and branches that no other test reached (docs/coverage.md's
per-branch list): each bad combination of flags is one line ``bumprtl: error: ...`` naming
the flags, exit status 2, nothing written but a bench command's log; ``bumprtl doctor`` exits 1 and names what is
missing when an installed extra lacks a package or a tool."""

import pytest

from bumprtl.gen.bench.memory import memory_rows
from bumprtl.gen.cli import doctor
from bumprtl.rtl.config import BumpError


@pytest.mark.parametrize("argv, words", [
    (["render", "--model", "fixed", "--scene", "a.toml", "--pipeline", "b.toml"],
     ["--scene a.toml", "--pipeline b.toml"]),
    (["render", "--rtl", "--method", "kim"], ["--method kim", "--rtl"]),
    (["render", "--rtl", "--model", "fixed"], ["--rtl", "--model"]),
    (["render", "--pipeline", "b.toml"], ["--pipeline", "--model fixed"]),
    (["report", "fpga", "--seeds", "0"], ["--seeds", "positive", "'0'"]),
    (["report", "fpga", "--seeds", "1,,2"], ["--seeds", "'1,,2'"]),
    (["vectors", "--geometry", "sphere", "--source", "random"], ["--geometry", "--source random"]),
    (["vectors", "--palette-size", "16"], ["--palette-size", "per-pixel"]),
    (["emit", "pipeline", "--map-memory", "axi", "--interface", "axis"],
     ["--map-memory axi", "--interface stream"]),
    (["emit", "pipeline", "--map-memory", "axi", "--load", "port"], ["--load", "bram"]),
    (["bench", "memory", "--rows", "0"], ["rows", "got 0"]),
])
def test_bad_flag_combination_is_one_line_exit_2_nothing_written(argv, words, tmp_path,
                                                                  monkeypatch, run_cli):
    monkeypatch.chdir(tmp_path)
    r = run_cli(argv)
    assert r.returncode == 2, (argv, r.stdout, r.stderr)
    [line] = r.stderr.strip().splitlines()
    assert line.startswith("bumprtl: error: ") and all(w in line for w in words), line
    written = [p for p in tmp_path.rglob("*") if p.is_file() and p.suffix != ".log"]
    assert not written, written           # (a bench command keeps its tool log)


def test_memory_rows_refuses_an_unknown_cache():
    """The command line offers the caches as choices; the library call names the field."""
    with pytest.raises(BumpError) as e:
        memory_rows(scenes=["globe"], caches=["512x1 4x4"])
    assert e.value.field == "cache" and "'512x1 4x4'" in str(e.value)


def _doctor(monkeypatch, capsys, gone_package=None, gone_tool=None):
    real_installed, real_which = doctor._installed, doctor.shutil.which
    monkeypatch.setattr(doctor, "_installed",
                        lambda name: None if name == gone_package else real_installed(name))
    monkeypatch.setattr(doctor.shutil, "which",
                        lambda name, path=None: None if name == gone_tool else real_which(name, path=path))
    code = doctor.run(None)
    return code, capsys.readouterr().out


def test_doctor_names_a_missing_package_of_an_installed_extra(monkeypatch, capsys):
    sim = [n for n, _ in doctor.requirements()["sim"]]
    assert "cocotb" in sim and len(sim) > 1
    code, out = _doctor(monkeypatch, capsys, gone_package="cocotb")
    assert code == 1
    missing = out.split("\nmissing:\n", 1)[1]
    assert "[sim]: cocotb: install with: pip install 'bumprtl[sim]'" in missing


def test_doctor_names_a_missing_tool_of_an_installed_extra(monkeypatch, capsys):
    code, out = _doctor(monkeypatch, capsys, gone_tool="iverilog")
    assert code == 1
    missing = out.split("\nmissing:\n", 1)[1]
    assert missing.strip().startswith("iverilog: install with:") and "apt" in missing
