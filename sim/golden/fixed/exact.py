"""Bit-exact int64 model of the ``exact`` datapath (rtl/exact.py), vectorized.

Scales (all integers carry ``frac_bits`` = B fractional bits; no rounding until the dot):
  n.x4 = 4 n''x, n.y2 = 2 n''y, n.z4 = 4 n''z     (product-to-sum sums, docs/architecture.md)
  a.p2 = 2 p, a.y2 = 2 y, a.z = cos th_A          per vector A in {L, H}
  N'.A' = (n.x4 a.p2 + 2 n.y2 a.y2 + 2 n.z4 a.z) / 8, one rounding back to B bits.
"""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.rtl.exact import vectors          # L, and H with specular: the RTL's own list
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.tables import cos_lookup, sin_lookup
from bumprtl.sim.golden.fixed.common import shade_fixed

__all__ = ["rotation_fixed", "illumination_fixed", "dot_fixed", "vectors",
           "predicted_error_bound_lsb"]


def rotation_fixed(codes, cfg: Config):
    """VectorRotation (exact): n'' of the bump normal and p, y, cos th of L and H."""
    s, c = (lambda a: sin_lookup(cfg, a)), (lambda a: cos_lookup(cfg, a))
    t, bt, bp = codes["n.theta"], codes["b.theta"], codes["b.phi"]
    a, b = bt + bp, bt - bp                   # a = th_N' + ph_N', b = th_N' - ph_N'
    out = {
        "n.x4": s(a + t) + s(a - t) + s(b + t) + s(b - t) + 2 * (s(t + bt) + s(t - bt)),
        "n.y2": c(b) - c(a),
        "n.z4": -(c(a - t) - c(a + t) + c(b - t) - c(b + t)) + 2 * (c(bt - t) + c(bt + t)),
    }
    for v in vectors(cfg):
        th, d = codes[f"{v}.theta"], codes[f"{v}.phi"] - codes["n.phi"]
        x, y = th + d, th - d                 # X = th_A + D, Y = th_A - D (binary angles wrap)
        out[f"{v}.p2"] = s(x) + s(y)
        out[f"{v}.y2"] = c(y) - c(x)
        out[f"{v}.z"] = c(th)
    return out


def dot_fixed(rot, v, cfg: Config):
    """N'.A' with B fractional bits: (x4 p2 + 2 y2 y2 + 2 z4 z) / 8 / 2**B, rounded once."""
    wide = lambda key: rot[key].astype(np.int64)          # products need up to 2B + 8 bits
    acc = (wide("n.x4") * rot[f"{v}.p2"] + 2 * wide("n.y2") * rot[f"{v}.y2"]
           + 2 * wide("n.z4") * rot[f"{v}.z"])
    return round_shift(acc, cfg.frac_bits + 3)


def illumination_fixed(rot, cfg: Config):
    """Illumination (exact): ndotl, ndoth and 8-bit diffuse, specular, color."""
    ndotl = dot_fixed(rot, "l", cfg)
    ndoth = dot_fixed(rot, "h", cfg) if cfg.specular else np.zeros_like(ndotl)
    return {"ndotl": ndotl, "ndoth": ndoth, **shade_fixed(ndotl, ndoth, cfg)}


def predicted_error_bound_lsb(cfg: Config):
    """Worst-case |diffuse8 - round(255 * clamp(N'.L))| of the exact datapath, in 8-bit LSB,
    against float64 on unquantized inputs.

    With delta = pi / 2**(k+2) rad (half an angle step) and u = 2**-B:
    * input rounding: N' moves by at most sqrt(5) delta (th_N, th_N', ph_N' through
      Cauchy-Schwarz) and A by at most sqrt(5) delta (th_A, and ph_A, ph_N which move it
      along one direction, worth 2 sin th_A), so N'.A' moves by at most 2 sqrt(5) delta to
      first order, plus at most 14 delta**2;
    * arithmetic: the ROM values are off by at most u/2 each, so n'' (4 values / 4 + 2 / 2,
      2 / 2, 4 / 4 + 2 / 2) is off by at most sqrt(1 + 1/4 + 1) u = 1.5 u, the vector terms
      (p, y, cos th_A) by sqrt(3)/2 u, and the dot's final rounding adds u/2 (1.3 u**2 covers
      the product of the two errors);
    * the 8-bit rounding turns an error e before it into at most floor(e) + 1 after it.
    Measured maxima stay under the bound (tests/sim/golden/fixed/test_exact.py).
    """
    delta = np.pi / (1 << (cfg.k + 2))
    u = 2.0 ** -cfg.frac_bits
    before = 255.0 * (2 * np.sqrt(5) * delta + 14 * delta ** 2
                      + (1.5 + np.sqrt(3) / 2 + 0.5 + 1.3 * u) * u)
    return int(np.floor(before)) + 1
