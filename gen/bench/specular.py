"""``bumprtl bench specular``: the candidates for eq. 2's (N'.H)^n term, measured side by
side on the same dot products (the exact datapath's N'.H', bit-exact golden model).

* ``nearest 2^s``: the cos^n table of 2^s + 1 8-bit words read at N'.H rounded to s bits
  (the design before this one; s = 10 is one block RAM, s = 12 four times the words);
* ``interpolated``: 2^10 + 1 words of 17 bits (8 + 9 fractional) over [0, 1], linear
  interpolation with the bits of N'.H below the step (one small multiplier);
* ``interpolated, finer near 1``: the same table over [x0, 1] with the finest step at which
  cos^n below x0 rounds to 0 (rtl/tables.specular_step_bits; the design kept);
* ``repeated squaring``: x^n by squaring and multiplying, each product rounded to B
  fractional bits, no table (floor(log2 n) + popcount(n) - 1 multipliers).

Per exponent: the term's own error against 255 x^n over every N'.H on the B-bit grid
(exhaustive), and the 8-bit specular output against float64 on random and adversarial
inputs (unquantized; sim/golden/accuracy.py). Cost: words x width and DP16KD count
(1024 x 18 or 2048 x 9 words a block; a 2^s + 1-th word in flip-flops), multipliers.
"""


import numpy as np

from bumprtl.gen.flow.resources import count_unit
from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.tables import SPEC_FRAC_BITS, specular_index_bits, specular_step_bits
from bumprtl.sim.golden.accuracy import adversarial_pixels
from bumprtl.sim.golden.common import PixelInputs, to_8bit
from bumprtl.sim.golden.fixed.common import specular_fine_fixed
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.methods import datapath_fixed, encode_pixels

__all__ = ["CANDIDATES", "candidate_fine", "specular_bench"]

F = SPEC_FRAC_BITS


def _nearest(bits):
    def fine(h, cfg):
        s = min(cfg.frac_bits, bits)
        table = np.rint(255.0 * (np.arange((1 << s) + 1) / (1 << s)) ** cfg.spec_exponent)
        return table.astype(np.int64)[round_shift(h, cfg.frac_bits - s)] << F
    return fine


def _squaring(h, cfg):
    """x^n by binary exponentiation, every product rounded to B fractional bits."""
    b, n = cfg.frac_bits, cfg.spec_exponent
    result, base = None, np.asarray(h, np.int64)
    while n:
        if n & 1:
            result = base if result is None else round_shift(result * base, b)
        n >>= 1
        if n:
            base = round_shift(base * base, b)
    return round_shift(255 * result << F, b)


CANDIDATES = {
    "nearest 2^10 (before)": _nearest(10),
    "nearest 2^12": _nearest(12),
    "interpolated": lambda h, cfg: specular_fine_fixed(h, cfg, specular_index_bits(cfg)),
    "interpolated, finer near 1 (kept)": specular_fine_fixed,
    "repeated squaring": _squaring,
}


def candidate_fine(name, h, cfg):
    """255 h^n with F fractional bits by candidate ``name`` (h: clamp(N'.H), B bits)."""
    return CANDIDATES[name](np.asarray(h, np.int64), cfg)


def _cost(name, cfg):
    n = cfg.spec_exponent
    if name.startswith("nearest"):
        s = min(cfg.frac_bits, 10 if "10" in name else 12)
        words, width, mults = (1 << s) + 1, 8, 0
    elif name.startswith("interpolated"):
        words, width, mults = (1 << specular_index_bits(cfg)) + 1, 8 + F, 1
    else:
        return "none", 0, n.bit_length() - 1 + bin(n).count("1") - 1
    per_block = 1024 if width > 9 else 2048
    blocks = -(-(words - 1) // per_block)
    return f"{words} x {width}", blocks, mults


def specular_bench(*, spec_exponent, samples, work):
    """``bumprtl bench specular``: the arguments are its flags' (gen/cli/bench.py);
    returns the exit status."""
    print(f"bumprtl bench specular --samples {samples} --spec-exponent "
          f"{' '.join(map(str, spec_exponent))}")
    print(f"\nspecular term and 8-bit specular output against float64, 8-bit LSB, at angle bits "
          f"{Config().angle_bits}, B = {Config().frac_bits}: 'term' = max |fine / 2^F - 255 x^n| over every N'.H on the B-bit grid; "
          f"random = {samples} random valid pixels (seed 11), adversarial = the search "
          f"aimed at the specular term (seed 7)\n")
    print("| n | candidate | table (words x bits) | DP16KD | multipliers | term max | random max / mean "
          "| adversarial max / mean |")
    print("|---|---|---|---|---|---|---|---|")
    px = PixelInputs.random(samples, np.random.default_rng(11))
    for n in spec_exponent:
        cfg = Config(spec_exponent=n)
        grid = np.arange(cfg.one + 1)
        exact = 255.0 * (grid / cfg.one) ** n
        sets = {"random": px, "adversarial": adversarial_pixels(cfg, channel="specular")}
        dots = {k: np.clip(datapath_fixed(encode_pixels(p, cfg), cfg)["ndoth"], 0, cfg.one)
                for k, p in sets.items()}
        refs = {k: to_8bit(conventional(p, cfg).specular).astype(np.int64) for k, p in sets.items()}
        for name in CANDIDATES:
            term = np.abs(candidate_fine(name, grid, cfg) / (1 << F) - exact).max()
            errs = {k: np.abs(round_shift(candidate_fine(name, dots[k], cfg), F) - refs[k])
                    for k in sets}
            words, blocks, mults = _cost(name, cfg)
            print(f"| {n} | {name} | {words} | {blocks} | {mults} | {term:.3f} | "
                  f"{errs['random'].max()} / {errs['random'].mean():.4f} | "
                  f"{errs['adversarial'].max()} / {errs['adversarial'].mean():.4f} |", flush=True)
    print("\nstep of the kept table (2^-t) per n: "
          + ", ".join(f"n={n}: t={specular_step_bits(Config(spec_exponent=n))}" for n in spec_exponent))
    counts = count_unit("illumination", Config(), work).summary()
    print("\nIllumination at the default widths, Yosys coarse netlist (gen/flow/resources.py): "
          + ", ".join(f"{k} {counts[k]}" for k in ("multipliers", "const_multipliers", "tables",
                                                   "table_bits", "table_reads", "adders",
                                                   "register_bits")))
    return 0
