"""One line means one line: a refusal of a bench, report or formal command (a misspelled or
unreachable ``--scheduler``, a bad value) is exactly one line on stderr and exit 2, with
nothing before it: the tool-log banner of quiet_commands is not printed on a refusal.

capfd, not capsys: quiet.tool_log writes its banner to a duplicate of file descriptor 2,
which capsys never sees.
"""

import socket

import pytest

from bumprtl.gen.cli.main import main
from bumprtl.gen.flow.quiet import tool_log
from bumprtl.gen.tools import jobs


def _one_line(capfd):
    out, err = capfd.readouterr()
    lines = err.splitlines()
    assert len(lines) == 1, err
    return lines[0]


def _closed_port():
    """A local TCP port with nothing listening on it."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("argv", [["report", "fpga"], ["report", "table1"],
                                  ["bench", "sweep", "--fpga"], ["formal"]])
def test_a_misspelled_scheduler_is_one_line(argv, capfd, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    assert main([*argv, "--scheduler", "tpc://127.0.0.1:8786"]) == 2
    line = _one_line(capfd)
    assert "--scheduler must be tcp://HOST:PORT" in line and "'tpc://127.0.0.1:8786'" in line


@pytest.mark.parametrize("argv", [["report", "fpga", "--unit", "scene_palette"],
                                  ["formal", "sincos", "--prop", "order", "--no-mutants"]])
def test_an_unreachable_scheduler_is_one_line(argv, capfd, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(jobs, "CONNECT_TIMEOUT", 1)
    address = f"tcp://127.0.0.1:{_closed_port()}"
    out = ["--out", str(tmp_path / ("r.md" if argv[0] == "report" else "f"))]
    work = ["--work", str(tmp_path / "c")] if argv[0] == "report" else []
    assert main([*argv, *out, *work, "--scheduler", address]) == 2
    line = _one_line(capfd)
    assert f"--scheduler {address}: cannot reach the scheduler" in line


@pytest.mark.parametrize("argv, names", [
    (["report", "fpga", "--device", "LFE5U-12F"], "LFE5U-12F"),
    (["report", "table1", "--samples", "0"], "samples"),
    (["bench", "sweep", "--fpga", "--device", "LFE5U-12F"], "LFE5U-12F")])
def test_a_bad_value_of_a_quiet_command_is_one_line(argv, names, capfd, monkeypatch, tmp_path):
    """bench and report kinds run inside quiet.tool_log: their refusals too."""
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    line = _one_line(capfd)
    assert line.startswith("bumprtl: error: ") and names in line


def test_a_quiet_command_names_its_log_after_it_succeeds(capfd, tmp_path):
    """The banner moved after the work: a successful run still says where the tools'
    output went."""
    with tool_log(tmp_path / "k.log", "report k", python=True):
        pass
    _, err = capfd.readouterr()
    assert err == f"report k: tool output in {tmp_path / 'k.log'}\n"


@pytest.mark.parametrize("argv", [["render", "--rtl", "--size", "16", "--out", "r.png"],
                                  ["demo", "--size", "16", "--out", "demo"]])
def test_a_missing_simulator_is_one_line_before_any_work(argv, capfd, monkeypatch, tmp_path):
    """Icarus not on PATH: render --rtl and demo refuse before the tool log's banner, the
    emit and the golden renders (nothing written)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bin").mkdir()
    monkeypatch.setenv("PATH", str(tmp_path / "bin"))
    assert main([*argv, "--simulator", "icarus"]) == 2
    line = _one_line(capfd)
    assert line.startswith("bumprtl: error: iverilog not found; install it with:"), line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bin"]
