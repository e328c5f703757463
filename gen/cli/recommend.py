"""``bumprtl recommend``: the flags; the ranking and its evidence are gen/report/recommend.py's."""

from pathlib import Path

from bumprtl.gen.report.recommend import LOCAL_SWEEP, recommend_report

__all__ = ["run", "add_parser"]


def run(args):
    return recommend_report(args.max_error_lsb, args.device, args.sweep)


def add_parser(sub):
    p = sub.add_parser("recommend", help="cheapest configuration meeting an error bound (from the sweep)",
                       description="Reads the `bumprtl bench sweep` JSON and prints the cheapest "
                                   "configuration whose worst measured colour error is within the bound, "
                                   "with the evidence. Exits 2 when none meets it.")
    p.add_argument("--max-error-lsb", type=float, required=True, help="bound on the worst colour error, 8-bit LSB")
    p.add_argument("--device", default=None, help="rank by ECP5 cost on this device (needs sweep --fpga)")
    p.add_argument("--sweep", type=Path, default=None,
                   help=f"sweep JSON (default: {LOCAL_SWEEP}, else the sweep shipped in "
                        f"docs/data/sweep.json)")
    p.set_defaults(func=run)
