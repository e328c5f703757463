"""``bumprtl bench KIND``: benchmarks (speed is measured here, never asserted in tests).

Each kind lives in its own module with ``add_parser(subparsers)``; register it in BENCHES.
"""

import importlib

# kind -> module (relative to bumprtl.gen) providing add_parser(subparsers); each
# benchmark module adds its own line here.
BENCHES = {
    "float64": "bench_float",
    "golden": "bench_golden",
    "accuracy": "bench_accuracy",
    "lee-widths": "bench_lee",
    "palette": "bench_palette",
    "sweep": "bench_sweep",
    "stress": "bench_stress",
    "skip": "bench_skip",
}


def add_parser(sub):
    p = sub.add_parser("bench", help="benchmarks: speed against error",
                       description="Benchmarks. Ratios are measured side by side in one run.")
    kinds = p.add_subparsers(dest="kind", metavar="KIND")
    kinds.required = True
    for module in BENCHES.values():
        importlib.import_module(f"{__package__}.{module}").add_parser(kinds)
