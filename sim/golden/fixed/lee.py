"""Bit-exact int64 model of the ``lee`` datapath (rtl/lee.py), vectorized.

Lee et al. 2003, Figs 7 and 8, with errata 1-6 and 8 repaired (docs/architecture.md); the method's
own approximations (rigid circle, linear proportion; erratum 7) are kept, so this model
tracks the float64 ``sim/golden/float/lee.lee_corrected`` and, like it, stays far from the exact
reference at every width (docs/lee_method.md, ``bumprtl bench lee-widths``). Angles are binary-angle codes (full circle 2**(k+2)); values carry B = frac_bits
fractional bits. Per vector A in {L, H} (Fig. 7, ``rotate_fixed``):

  D = ph_A - ph_N, X = th_A + D, Y = th_A - D            eq. 6, erratum 1 (no /2)
  s2 = sin X + sin Y (= 2 s), y2 = cos Y - cos X (= 2 sin th_A sin D)
  th_x = asin(|s2| / 2) signed, 180 - th_x when cos th_A < 0      eq. 7, erratum 6
  Z = th_x - th_N, a signed binary angle in [-180, 180)
  ph_A' = atan2(y2, sin Z) = quadrant(atan(|y2| (1/|sin Z|) / 2))   eq. 9, errata 3 and 8
  y_k = |y2| (1/|cos Z|) / 2 clamped to [0, 1]              eq. 27, errata 4 and 8
  th_A' = |Z| + (90 - |Z|) T_prop[y_k]                     eqs 19, 26, erratum 5

and N'.A' = (1/2)[c(th_A' - th_N') + c(th_A' + th_N')]
          + (1/2)[c(th_A' - th_N') - c(th_A' + th_N')] c(ph_A' - ph_N')   eq. 24, erratum 2.
"""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.lee import (
    asin_address,
    below_horizon,
    magnitude,
    phi_quadrant,
    prop_address,
    quarter_address,
    ratio_index,
    theta_from_prop,
)
from bumprtl.rtl.tables import (
    cos_lookup,
    lee_asin_table,
    lee_atan_table,
    lee_prop_table,
    lee_reciprocal_table,
    sin_lookup,
)
from bumprtl.sim.golden.fixed.common import (
    check_channel,
    polar_illumination_fixed,
    polar_rotation_fixed,
)

__all__ = ["rotate_fixed", "illuminate_fixed", "rotation_fixed", "illumination_fixed",
           "predicted_error_bound_lsb"]


def _reciprocal(angle, cfg: Config):
    """1/|sin angle| from the quarter-wave reciprocal ROM (saturating, erratum 8)."""
    return lee_reciprocal_table(cfg)[quarter_address(np.asarray(angle, dtype=np.int64), cfg)]


def rotate_fixed(a_phi, a_theta, n_phi, n_theta, cfg: Config):
    """(ph_A', th_A') codes of one vector A in the tangent frame of N (Fig. 7)."""
    k, b = cfg.k, cfg.frac_bits
    a_phi, a_theta, n_phi, n_theta = (np.asarray(v, dtype=np.int64)
                                      for v in (a_phi, a_theta, n_phi, n_theta))
    d = a_phi - n_phi
    x, y = a_theta + d, a_theta - d                                    # eq. 6 (erratum 1)
    s2 = sin_lookup(cfg, x).astype(np.int64) + sin_lookup(cfg, y)
    y2 = cos_lookup(cfg, y).astype(np.int64) - cos_lookup(cfg, x)
    asin = lee_asin_table(cfg)[asin_address(s2, cfg)]
    theta_x = np.where(s2 < 0, -asin, asin)                            # eq. 7
    theta_x = np.where(below_horizon(a_theta, cfg), (1 << (k + 1)) - theta_x, theta_x)  # erratum 6
    z = (theta_x - n_theta) & (cfg.full_circle - 1)                    # Z, read as [-180, 180)
    # |y2| x 1/|sin| needs k + 2B + 1 bits (RTL: exact width); past int64, Python ints.
    ay2 = np.abs(y2).astype(np.int64 if k + 2 * b + 2 <= 63 else object)
    ratio = ((ay2 * _reciprocal(z, cfg)) >> (2 * b + 1 - k)).astype(np.int64)  # |eq. 9's argument|
    atan = lee_atan_table(cfg)[ratio_index(ratio, cfg)]
    prop = lee_prop_table(cfg)[prop_address(ay2 * _reciprocal(z + (1 << k), cfg), cfg).astype(np.int64)]
    z_negative, abs_z = magnitude(z, cfg)
    phi = phi_quadrant(atan, z_negative, y2 < 0, cfg)                  # eq. 9, erratum 3
    theta = theta_from_prop(abs_z, prop, cfg)                          # eqs 19, 26, errata 4, 5
    return phi, theta


def illuminate_fixed(a_phi, a_theta, b_phi, b_theta, cfg: Config):
    """N'.A' (signed, B fractional bits) by eq. 24 with erratum 2, rounded once."""
    a_phi, a_theta, b_phi, b_theta = (np.asarray(v, dtype=np.int64)
                                      for v in (a_phi, a_theta, b_phi, b_theta))
    c_plus = cos_lookup(cfg, a_theta + b_theta).astype(np.int64)
    c_minus = cos_lookup(cfg, a_theta - b_theta).astype(np.int64)
    c_phi = cos_lookup(cfg, a_phi - b_phi).astype(np.int64)
    acc = ((c_minus + c_plus) << cfg.frac_bits) + (c_minus - c_plus) * c_phi
    return round_shift(acc, cfg.frac_bits + 1)


def rotation_fixed(codes, cfg: Config):
    """VectorRotation (lee): the output payload fields L', H' and the passed-through N'."""
    return polar_rotation_fixed(rotate_fixed, codes, cfg)


def illumination_fixed(rot, cfg: Config):
    """Illumination (lee): ndotl, ndoth and the 8-bit diffuse, specular and color."""
    return polar_illumination_fixed(illuminate_fixed, rot, cfg)


def predicted_error_bound_lsb(cfg: Config, channel="diffuse", lights=1):
    """The error bound of the lee datapath against float64, in 8-bit LSB, for every channel
    (diffuse, specular, color, blend): the whole 8-bit range (255) at every width. The rigid-circle and proportion approximations are the
    method itself (erratum 7) and are geometric, so no width bounds the error below it; the
    measured maxima are in docs/algorithms.md and docs/lee_method.md (``bumprtl bench
    float64``, ``bench lee-widths``)."""
    check_channel(channel)
    return 255
