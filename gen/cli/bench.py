"""``bumprtl bench KIND``: benchmarks (speed is measured here, never asserted in tests).

Each kind lives in its own module with ``add_parser(subparsers)``; register it in BENCHES.
"""

from bumprtl.gen.bench import (
    accuracy,
    float64,
    golden,
    lee_widths,
    palette,
    rtl_sim,
    skip,
    specular,
    stress,
    sweep,
)
from bumprtl.gen.flow.quiet import quiet_commands

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
    quiet_commands(kinds, "build/bench")      # the tools' output to build/bench/KIND.log
