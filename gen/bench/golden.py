"""``bumprtl bench golden``: fixed-point golden model and cocotb simulation throughput."""

import tempfile
import time
from pathlib import Path

from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.methods import PER_PIXEL, datapath_fixed
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


def run(args):
    print(f"bumprtl bench golden --pixels {args.pixels} --sim-samples {args.sim_samples}")
    print("\nFixed-point golden model (numpy, one process, best of 3):\n")
    print("| method | pixels | Mpix/s |")
    print("|---|---|---|")
    methods = [m for m in args.methods]
    for method in methods:
        cfg = Config(method=method)
        try:
            rate = _golden_rate(cfg, args.pixels)
        except ImportError as e:
            print(f"| {method} | - | not available ({e}) |")
            continue
        print(f"| {method} | {args.pixels} | {rate / 1e6:.2f} |", flush=True)
    print("\ncocotb simulation of the emitted Verilog (scoreboard included), side by side:\n")
    print("| method | unit | simulator | pixels/s | build s |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="bumprtl-bench-") as tmp:
        for method in methods:
            for unit in ("rotation", "illumination"):
                for sim in SIMULATORS:
                    rate, build = unit_sim_rate(Config(method=method), sim, unit, args.sim_samples,
                                            Path(tmp) / method)
                    print(f"| {method} | {unit} | {sim} | {rate:,.0f} | {build:.1f} |", flush=True)
    return 0


def add_parser(sub):
    p = sub.add_parser("golden", help="fixed-point golden model and cocotb simulation throughput",
                       description="Pixels per second of the bit-exact golden model per method, "
                                   "and of cocotb simulation under Icarus and Verilator, in one run.")
    p.add_argument("--pixels", type=int, default=1_000_000, help="golden-model batch (default: 10^6)")
    p.add_argument("--sim-samples", type=int, default=5000,
                   help="random vectors per traffic pattern in the simulations (default: 5000)")
    p.add_argument("--methods", nargs="+", default=list(PER_PIXEL), choices=PER_PIXEL)
    p.set_defaults(func=run)
