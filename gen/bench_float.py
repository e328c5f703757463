"""``bumprtl bench float64``: error of every float64 model against conventional, and speed."""

import time

import numpy as np


def run(args):
    from ..rtl.config import Config
    from ..sim.golden.common import PixelInputs
    from ..sim.golden.measure import error_stats
    from ..sim.golden.models import FLOAT_MODELS
    cfg = Config()
    print(f"bumprtl bench float64 --samples {args.samples} --seed {args.seed}")
    print(f"{args.samples} random valid inputs (seed {args.seed}); errors against 'conventional'\n")
    print("| method | L' err mean (deg) | p99 | max | diffuse err mean (LSB) | p99 | max | NaN | Mpix/s |")
    print("|---|---|---|---|---|---|---|---|---|")
    px = PixelInputs.random(args.samples, np.random.default_rng(args.seed))
    for name, model in FLOAT_MODELS.items():
        s = error_stats(name, n=args.samples, seed=args.seed, cfg=cfg)
        t0 = time.perf_counter()
        model(px, cfg)                                   # timed side by side, same inputs
        rate = args.samples / (time.perf_counter() - t0) / 1e6
        lp = s.get("l_prime_deg")
        lcols = f"{lp['mean']:.3g} | {lp['p99']:.3g} | {lp['max']:.3g}" if lp else "- | - | -"
        d = s["diffuse_lsb"]
        print(f"| {name} | {lcols} | {d['mean']:.3g} | {d['p99']:.3g} | {d['max']:.3g} | "
              f"{d['nan']} | {rate:.2f} |")
    return 0


def add_parser(sub):
    p = sub.add_parser("float64", help="error and speed of the float64 golden models",
                       description="Mean, p99 and max of the L' angle error (degrees) and of the "
                                   "diffuse error (8-bit LSB) of every float64 model against the "
                                   "Cartesian reference, and each model's speed, in one run.")
    p.add_argument("--samples", type=int, default=100_000, help="random valid inputs (default: 100000)")
    p.add_argument("--seed", type=int, default=1)
    p.set_defaults(func=run)
