"""``bumprtl bench float64``: error of every float64 model against conventional, and speed."""

import time

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.float.models import FLOAT_MODELS
from bumprtl.sim.golden.measure import (
    compare,
    error_at_theta_n,
    error_by_theta_n,
    proportion_worst_case_deg,
    random_pixels,
    worst_pixel,
)


def _cols(s):
    return f"{s['mean']:.3g} | {s['p99']:.3g} | {s['max']:.3g}"


def _model_table(px, cfg):
    print("| method | L' err mean (deg) | p99 | max | diffuse err mean (LSB) | p99 | max | NaN | Mpix/s |")
    print("|---|---|---|---|---|---|---|---|---|")
    ref = FLOAT_MODELS["conventional"](px, cfg)
    for name, model in FLOAT_MODELS.items():
        t0 = time.perf_counter()
        res = model(px, cfg)                             # timed side by side, same inputs
        rate = len(px) / (time.perf_counter() - t0) / 1e6
        s = compare(res, ref)
        lcols = _cols(s["l_prime_deg"]) if "l_prime_deg" in s else "- | - | -"
        print(f"| {name} | {lcols} | {_cols(s['diffuse_lsb'])} | {s['diffuse_lsb']['nan']} | {rate:.2f} |")


def _theta_n_table(samples, seed, cfg):
    print("\nlee_corrected by theta_N (the rigid circle of Lee Sec. 3.1.2 is exact at theta_N = 0)\n")
    print("| theta_N (deg) | pixels | L' err mean (deg) | p99 | max | diffuse err mean (LSB) | p99 | max |")
    print("|---|---|---|---|---|---|---|---|")
    for lo, hi, count, s in error_by_theta_n("lee_corrected", samples, seed, 15, cfg):
        print(f"| {lo}-{hi} | {count} | {_cols(s['l_prime_deg'])} | {_cols(s['diffuse_lsb'])} |")


def _approximations(samples, seed, cfg):
    at = {deg: error_at_theta_n("lee_corrected", np.radians(deg), samples, seed, cfg)
          for deg in (0, 90, 180)}
    print(f"\nlinear proportion (eqs 10-13) alone, closed-form worst case: "
          f"{proportion_worst_case_deg():.3g} deg")
    print("lee_corrected max L' error (deg) / max diffuse error (LSB) with theta_N fixed at "
          + ", ".join(f"{deg} deg: {s['l_prime_deg']['max']:.3g} / {s['diffuse_lsb']['max']:.3g}"
                      for deg, s in at.items()))
    w = worst_pixel("lee_corrected", samples, seed, cfg)
    pair = lambda key: f"({w[key][0]:.1f}, {w[key][1]:.1f})"
    print(f"lee_corrected worst L' pixel (phi, theta in deg): N {pair('N')}, L {pair('L')}, D = {w['D']:.1f}; "
          f"L' {pair('l_prime_ref')}, lee_corrected gives {pair('l_prime')}: {w['l_prime_deg']:.3g} deg, "
          f"{w['diffuse_lsb']:.3g} LSB")


def float64_bench(*, samples, seed):
    """``bumprtl bench float64``: the arguments are its flags' (gen/cli/bench.py);
    returns the exit status."""
    cfg = Config()
    px = random_pixels(samples, seed)
    print(f"bumprtl bench float64 --samples {samples} --seed {seed}")
    print(f"{samples} random valid inputs (seed {seed}); errors against 'conventional'\n")
    _model_table(px, cfg)
    _theta_n_table(samples, seed, cfg)
    _approximations(samples, seed, cfg)
    return 0
