"""``bumprtl bench golden``: fixed-point golden model and cocotb simulation throughput."""

import tempfile
import time
from pathlib import Path

from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.methods import datapath_fixed
from bumprtl.sim.golden.vectors import edge_codes, random_codes
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb


def _golden_rate(cfg, n, repeats=3):
    codes = random_codes(n, cfg, seed=5)
    datapath_fixed({k: v[:16] for k, v in codes.items()}, cfg)        # warm the table caches
    best = min(_timed(lambda: datapath_fixed(codes, cfg)) for _ in range(repeats))
    return n / best


def _timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def unit_sim_rate(cfg, sim, unit, samples, work):
    work = Path(work).resolve()          # cocotb runs in its build directory
    v, j = emit_unit(unit, cfg, work / "rtl")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_datapath", work / f"{sim}_{unit}",
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": samples},
                     opt_fast=None)              # the build and rate as Verilator makes them
    pixels = 4 * (samples + len(edge_codes(cfg)["n.phi"]))          # 4 traffic patterns
    return pixels / run.run_s, run.build_s


def golden_bench(*, methods, pixels, sim_samples):
    """``bumprtl bench golden``: the arguments are its flags' (gen/cli/bench.py);
    returns the exit status."""
    print(f"bumprtl bench golden --pixels {pixels} --sim-samples {sim_samples}")
    print("\nFixed-point golden model (numpy, one process, best of 3):\n")
    print("| method | pixels | Mpix/s |")
    print("|---|---|---|")
    methods = [m for m in methods]
    for method in methods:
        cfg = Config(method=method)
        try:
            rate = _golden_rate(cfg, pixels)
        except ImportError as e:
            print(f"| {method} | - | not available ({e}) |")
            continue
        print(f"| {method} | {pixels} | {rate / 1e6:.2f} |", flush=True)
    if not sim_samples:                 # --sim-samples 0: the golden model only
        return 0
    print("\ncocotb simulation of the emitted Verilog (scoreboard included), side by side:\n")
    print("| method | unit | simulator | pixels/s | build s |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="bumprtl-bench-") as tmp:
        for method in methods:
            for unit in ("rotation", "illumination"):
                for sim in SIMULATORS:
                    rate, build = unit_sim_rate(Config(method=method), sim, unit, sim_samples,
                                            Path(tmp) / method)
                    print(f"| {method} | {unit} | {sim} | {rate:,.0f} | {build:.1f} |", flush=True)
    return 0
