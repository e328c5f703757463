"""``bumprtl bench lee-widths``: the lee datapath's error against width (docs/lee_method.md).

For each (angle_bits, frac_bits) the bit-exact lee model (sim/golden/fixed/lee.py) and, side
by side, the exact datapath at the same widths are compared with the Cartesian reference on
the same random valid inputs, and the lee model with float64 lee_corrected on the same angles.
"""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import PixelInputs, to_8bit
from bumprtl.sim.golden.fixed.common import quantize_pixels
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.lee import lee_corrected
from bumprtl.sim.golden.methods import datapath_fixed

WIDTHS = ((8, 7), (10, 9), (10, 13), (12, 13), (12, 16), (14, 18), (16, 24))


def lee_widths_bench(*, samples, seed):
    """``bumprtl bench lee-widths``: the arguments are its flags' (gen/cli/bench.py);
    returns the exit status."""
    print(f"bumprtl bench lee-widths --samples {samples} --seed {seed}")
    px = PixelInputs.random(samples, np.random.default_rng(seed))
    reference = to_8bit(conventional(px, Config()).diffuse).astype(np.int64)
    float_lee = np.abs(to_8bit(lee_corrected(px, Config()).diffuse).astype(np.int64) - reference)
    print(f"{samples} random valid inputs (seed {seed}); diffuse error in 8-bit LSB")
    print(f"float64 lee_corrected vs exact: mean {float_lee.mean():.3g}, max {float_lee.max()}\n")
    print("| angle_bits (k+2) | frac_bits B | lee vs exact: mean | max | exact datapath vs exact: max "
          "| lee vs float64 lee_corrected (same angles): max |")
    print("|---|---|---|---|---|---|")
    for angle_bits, frac_bits in WIDTHS:
        cfg = Config(method="lee", angle_bits=angle_bits, frac_bits=frac_bits)
        codes = quantize_pixels(px, cfg)
        lee = datapath_fixed(codes, cfg)["diffuse"]
        exact = datapath_fixed(codes, cfg.replace(method="exact"))["diffuse"]
        step = 2 * np.pi / cfg.full_circle
        same = PixelInputs(**{f"{k[0]}_{k[2:]}": codes[k] * step for k in codes})
        track = np.abs(lee - to_8bit(lee_corrected(same, cfg).diffuse).astype(np.int64)).max()
        err = np.abs(lee - reference)
        print(f"| {angle_bits} | {frac_bits} | {err.mean():.3g} | {err.max()} | "
              f"{np.abs(exact - reference).max()} | {track} |")
    return 0
