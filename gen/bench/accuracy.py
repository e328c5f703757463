"""``bumprtl bench accuracy``: fixed-point golden model against float64, random and adversarial."""

import numpy as np

from bumprtl.rtl.config import Config, ConfigError
from bumprtl.sim.golden.accuracy import adversarial_pixels, diffuse_error_lsb, term_errors_lsb
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.rtl.methods import PER_PIXEL, datapath_fixed
from bumprtl.gen.flow.units import build_unit


def run(args):
    print(f"bumprtl bench accuracy --method {args.method} --samples {args.samples} "
          f"--angle-bits {' '.join(map(str, args.angle_bits))} --frac-bits {' '.join(map(str, args.frac_bits))} "
          f"--spec-index-bits {args.spec_index_bits}")
    print(f"\ndiffuse error in 8-bit LSB against float64 on unquantized inputs "
          f"({args.samples} random valid pixels, seed 11; adversarial search, seed 7)\n")
    print("| angle bits (k+2) | frac bits B | random max | random mean | adversarial max | adversarial mean "
          "| sidecar bound | specular max (random) | colour max (random) |")
    print("|---|---|---|---|---|---|---|---|---|")
    px = PixelInputs.random(args.samples, np.random.default_rng(11))
    for a in args.angle_bits:
        for b in args.frac_bits:
            try:
                cfg = Config(method=args.method, angle_bits=a, frac_bits=b,
                             spec_index_bits=args.spec_index_bits)
            except ConfigError:
                continue
            rnd = diffuse_error_lsb(datapath_fixed, px, cfg)
            adv = diffuse_error_lsb(datapath_fixed, adversarial_pixels(cfg), cfg)
            bound = build_unit("illumination", cfg)[1]["error_bound_lsb"]
            other = term_errors_lsb(datapath_fixed, px, cfg)
            print(f"| {a} | {b} | {rnd.max()} | {rnd.mean():.4f} | {adv.max()} | {adv.mean():.4f} | "
                  f"{bound} | {other['specular'].max()} | {other['color'].max()} |", flush=True)
    return 0


def add_parser(sub):
    p = sub.add_parser("accuracy", help="fixed-point error against float64 over widths",
                       description="Max and mean diffuse error (8-bit LSB) of the bit-exact golden "
                                   "model against float64 on random and adversarial inputs, beside "
                                   "the sidecar's predicted bound.")
    p.add_argument("--method", default="exact", choices=PER_PIXEL)
    p.add_argument("--samples", type=int, default=1_000_000)
    p.add_argument("--angle-bits", type=int, nargs="+", default=[10, 11, 12, 13])
    p.add_argument("--frac-bits", type=int, nargs="+", default=[10, 13, 16])
    p.add_argument("--spec-index-bits", type=int, default=10, help="specular table address bits (default: 10)")
    p.set_defaults(func=run)
