"""``bumprtl bench KIND``: benchmarks (speed is measured here, never asserted in tests).

Each kind lives in its own module with ``add_parser(subparsers)``; register it in BENCHES.
"""

import functools
from pathlib import Path

from bumprtl.gen.bench import (accuracy, float64, golden, lee_widths, palette, rtl_sim, skip,
                                specular, stress, sweep)
from bumprtl.gen.flow.quiet import tool_log

# kind -> module of gen/bench/ providing add_parser(subparsers); each benchmark module adds
# its own line here.
BENCHES = {
    "float64": float64,
    "golden": golden,
    "accuracy": accuracy,
    "specular": specular,
    "lee-widths": lee_widths,
    "palette": palette,
    "sweep": sweep,
    "stress": stress,
    "skip": skip,
    "rtl-sim": rtl_sim,
}


def add_parser(sub):
    p = sub.add_parser("bench", help="benchmarks: speed against error",
                       description="Benchmarks. Ratios are measured side by side in one run.")
    kinds = p.add_subparsers(dest="kind", metavar="KIND")
    kinds.required = True
    for module in BENCHES.values():
        module.add_parser(kinds)
    for kind, parser in kinds.choices.items():       # quiet: the tools' output to a log
        parser.add_argument("--verbose", action="store_true",
                            help="let the simulators' and Yosys' output through (by default it "
                                 f"goes to build/bench/{kind}.log, shown in full on a failure)")
        parser.set_defaults(func=_quiet(parser.get_default("func"), kind))


def _quiet(func, kind):
    """``func`` with the child processes' output (Verilator's make and g++, cocotb, Yosys)
    in build/bench/KIND.log; the bench's own table and progress bars reach the terminal."""
    @functools.wraps(func)
    def run(args):
        if args.verbose:
            return func(args)
        with tool_log(Path("build/bench") / f"{kind}.log", f"bench {kind}", python=True):
            return func(args)
    return run
