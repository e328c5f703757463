"""Bit-exact int64 model of the ``kim`` baseline datapath (rtl/baselines/kim.py), vectorized.

Kim et al. 2001 as the Lee paper summarizes it (Table 1; eqs (3)/(4)); the datapath choices
the paper leaves open are documented in rtl/baselines/kim.py. Every step below is one of that
module's helpers, applied here to int64 arrays and there to Amaranth values. Angles are
binary-angle codes (full circle 2**(k+2)); values carry B = frac_bits fractional bits.

Setup, per vector A in {L, H} (``rotate_fixed``):
  (x, y, z) = (sin th cos ph, sin th sin ph, cos th)            polar -> Cartesian
  (x', y', z') = M (x, y, z),  M = R_y(-th_N) R_z(-ph_N)        clamped to [-1, 1]
  ph_A' = atan2(y', x') by octant: a0 = atan(min / max) through 1/max (reciprocal ROM)
  rho = max cos a0 + min sin a0 = sin th_A'
  th_A' = asin(rho) if rho <= |z'| else 90 - asin(|z'|); 180 - th_A' if z' < 0
Illumination: N'.A' = cos th_A' cos th_N' + sin th_A' sin th_N' cos(ph_A' - ph_N')  eqs (3)/(4).
"""

import numpy as np

from bumprtl.rtl.baselines.kim import (
    asin_address,
    cartesian,
    dot_sum,
    dot_terms,
    matrix_entries,
    normalize,
    octant,
    phi_from_octant,
    ratio_of,
    reciprocal_address,
    rho_of,
    theta_from_octant,
    theta_select,
    transform,
)
from bumprtl.rtl.config import Config
from bumprtl.rtl.lee import ratio_index
from bumprtl.rtl.tables import (
    cos_lookup,
    kim_reciprocal_bits,
    kim_reciprocal_table,
    lee_asin_index_bits,
    lee_asin_table,
    lee_atan_mantissa_bits,
    lee_atan_table,
    sin_lookup,
)
from bumprtl.sim.golden.fixed.common import (
    channel_bound,
    input_angle_error,
    polar_illumination_fixed,
    polar_rotation_fixed,
)

__all__ = ["rotate_fixed", "to_polar_fixed", "illuminate_fixed", "rotation_fixed", "illumination_fixed",
           "predicted_error_bound_lsb", "direction_error_bound"]


def _sincos(angle, cfg: Config):
    """(sin, cos) of binary angles as int64, bit-exact with the quarter-wave ROM reads."""
    angle = np.asarray(angle, dtype=np.int64)
    return sin_lookup(cfg, angle).astype(np.int64), cos_lookup(cfg, angle).astype(np.int64)


def _frame(n_phi, n_theta, cfg: Config):
    """((m00, m01, m20, m21), (st, ct, sp, cp)) of N: the matrix M's product entries."""
    st, ct = _sincos(n_theta, cfg)
    sp, cp = _sincos(n_phi, cfg)
    return matrix_entries(st, ct, sp, cp, cfg), (st, ct, sp, cp)


def rotate_fixed(a_phi, a_theta, n_phi, n_theta, cfg: Config):
    """(ph_A', th_A') codes of one vector A in the reference frame of N."""
    mat, n = _frame(n_phi, n_theta, cfg)
    st, ct = _sincos(a_theta, cfg)
    sp, cp = _sincos(a_phi, cfg)
    return to_polar_fixed(*transform(mat, n, (*cartesian(st, sp, cp, cfg), ct), cfg), cfg)


def to_polar_fixed(xp, yp, zp, cfg: Config):
    """(ph, th) codes of a Cartesian vector (x', y', z'), B fractional bits, |.| <= 1: the
    back-to-polar half of the setup (octant atan, rho, octant asin)."""
    xp, yp, zp = (np.asarray(c, dtype=np.int64) for c in (xp, yp, zp))
    swap, p, q = octant(xp, yp)
    pn, qn = normalize(p, q, cfg)
    recip = kim_reciprocal_table(cfg)[reciprocal_address(pn, cfg)]
    a0 = lee_atan_table(cfg)[ratio_index(ratio_of(qn * recip, cfg), cfg)]
    phi = phi_from_octant(a0, swap, xp < 0, yp < 0, cfg)
    sa0, ca0 = _sincos(a0, cfg)
    use_rho, z_negative, v = theta_select(rho_of(p, q, ca0, sa0, cfg), zp, cfg)
    asin = lee_asin_table(cfg)[asin_address(v, cfg)]
    return phi, theta_from_octant(asin, use_rho, z_negative, cfg)


def illuminate_fixed(a_phi, a_theta, b_phi, b_theta, cfg: Config):
    """N'.A' (signed, B fractional bits) by eq. (3)/(4), rounded as the RTL rounds."""
    st_a, ct_a = _sincos(a_theta, cfg)
    st_n, ct_n = _sincos(b_theta, cfg)
    _, cphi = _sincos(np.asarray(a_phi, dtype=np.int64) - np.asarray(b_phi, dtype=np.int64), cfg)
    cc, ss = dot_terms(st_a, ct_a, st_n, ct_n, cfg)
    return dot_sum(cc, ss, cphi, cfg)


def rotation_fixed(codes, cfg: Config):
    """VectorRotation (kim): the output payload fields L', H' and the passed-through N'."""
    return polar_rotation_fixed(rotate_fixed, codes, cfg)


def illumination_fixed(rot, cfg: Config):
    """Illumination (kim): ndotl, ndoth and the 8-bit diffuse, specular and color."""
    return polar_illumination_fixed(illuminate_fixed, rot, cfg)


def predicted_error_bound_lsb(cfg: Config, channel="diffuse", lights=1):
    """Worst-case |diffuse8 - round(255 * clamp(N'.L))| of the kim datapath, in 8-bit LSB,
    against float64 on unquantized inputs; for ``channel`` = ``specular``, ``color`` or
    ``blend`` the shared back end's bound (common.channel_bounds_lsb) for a dot product
    within the input angle error 2 sqrt(5) delta and then direction_error_bound +
    (sqrt(2) + 1.5) u (the two arithmetic items below) of the true one.

    With delta = pi / 2**(k+2) rad (half an angle step), u = 2**-B, a = lee_asin_index_bits,
    R = kim_reciprocal_bits and M = lee_atan_mantissa_bits; first order, a few u**2 ignored:

    * input rounding: the same N'.A' on quantized angles moves by at most
      2 sqrt(5) delta + 14 delta**2 (exact.predicted_error_bound_lsb's argument: it is a
      property of the inputs, not of the method);
    * A' = M A: the ROM values are off by u/2; the four product entries of M and x, y by
      u/2 + u/2 + u/2 = 1.5 u, so |dM|_F <= sqrt(4 (1.5u)**2 + 4 (u/2)**2) = sqrt(10) u and
      |dA| <= sqrt(2 (1.5u)**2 + (u/2)**2) = sqrt(4.75) u; with the final rounding of the
      three coordinates (sqrt(3)/2 u) |dA'| <= e = (sqrt(10) + sqrt(4.75) + sqrt(3)/2) u
      (the clamp to [-1, 1] only moves A' toward the true vector);
    * ph_A': the azimuth of the perturbed (x', y') is within a chord of 2 e / sin th_A of the
      true one (distance of rho e^(i ph') from rho e^(i ph) <= 2 |d(x', y')|); the octant
      angle a0 is off by e_atan = (2**-(R+1) + u) / 2 (the reciprocal ROM's middle-of-interval
      divisor and rounding, a relative error of q/p, times d atan(t)/dt * t <= 1/2) plus
      2**-(M+2) (lee atan ROM address) plus delta (the ROM's rounded codes);
    * th_A': asin is read at v = min(rho, |z'|) <= 1/sqrt(2) (+ e), where its slope is below
      1.5; v is off by e (z') or e + (sqrt(2)/2 + 1/2) u + e_atan**2 / 2 (rho = p cos a0 +
      q sin a0: two ROM values, one rounding, the second-order loss of a wrong a0), the ROM
      address by 2**-(a+1), and the ROM's code by delta:
      d_th = 1.5 (e + 1.21 u + e_atan**2 / 2 + 2**-(a+1)) + delta;
    * so the output direction (th_A', ph_A') is within d_th + 2 e + e_atan of the true A'
      (move th first, then ph along the true parallel of radius sin th_A), and so is
      N'.A' computed exactly from it;
    * eqs (3)/(4): four ROM values (|cos| + |sin| <= sqrt(2) per angle) and cos(dph) off by
      u/2, the rounding of sin sin and of the sum: (sqrt(2) + 1.5) u;
    * the 8-bit rounding turns an error E before it into at most floor(255 E) + 1 after it.
    Measured maxima stay under the bound (tests/sim/golden/fixed/test_kim.py).
    """
    delta = np.pi / (1 << (cfg.k + 2))
    u = 2.0 ** -cfg.frac_bits
    if channel != "diffuse" or lights != 1:
        return channel_bound(cfg, channel, input_angle_error(cfg),
                             direction_error_bound(cfg) + (np.sqrt(2) + 1.5) * u, lights)
    before = (2 * np.sqrt(5) * delta + 14 * delta ** 2 + direction_error_bound(cfg)
              + (np.sqrt(2) + 1.5) * u)
    return int(np.floor(255.0 * before)) + 1


def direction_error_bound(cfg: Config):
    """|A'_out - A'| (Euclidean, unit vectors) of the setup on quantized inputs: the output
    codes (ph_A', th_A') against the exact M A of the same angles;
    d_th + 2 e + e_atan of :func:`predicted_error_bound_lsb`."""
    delta = np.pi / (1 << (cfg.k + 2))
    u = 2.0 ** -cfg.frac_bits
    e = (np.sqrt(10) + np.sqrt(4.75) + np.sqrt(3) / 2) * u
    e_atan = ((2.0 ** -(kim_reciprocal_bits(cfg) + 1) + u) / 2
              + 2.0 ** -(lee_atan_mantissa_bits(cfg) + 2) + delta)
    d_th = 1.5 * (e + 1.21 * u + e_atan ** 2 / 2 + 2.0 ** -(lee_asin_index_bits(cfg) + 1)) + delta
    return d_th + 2 * e + e_atan
