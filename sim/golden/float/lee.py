"""Lee, Park, Lee, Han and Yang 2003, float64: the printed equations and the corrected ones.

Vector rotation (Sec. 3.1, eqs 5-21) turns a world vector A = (ph_A, th_A) into the
tangent frame of N = (ph_N, th_N) by angles alone; illumination (Sec. 3.2, eqs 22-25)
takes N'.A' by the law of cosines. ``lee_printed`` follows the equations exactly as
printed; ``lee_corrected`` repairs errata 1-6 (docs/architecture.md) and keeps the two geometric
approximations that are the method itself (the "rigid circle" of Sec. 3.1.2 and the
linear "proportion" of eqs 10-13).

:func:`rotate` and :func:`illuminate` take the set of errata to repair, so a test can
repair all but one and show what that one erratum does.
"""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import PixelInputs, shade

__all__ = ["ALL_ERRATA", "rotate", "illuminate", "lee_printed", "lee_corrected"]

ALL_ERRATA = frozenset({1, 2, 3, 4, 5, 6})
QUARTER = np.pi / 2        # the papers' "90" (degrees) in radians
TWO_PI = 2 * np.pi


def rotate(a_phi, a_theta, n_phi, n_theta, fixed=ALL_ERRATA):
    """L' or H' = (ph_A', th_A') in the tangent frame of N (eqs 5-21).

    Errata repaired when listed in ``fixed``:
    1. eqs 5-6: X = th_A + D, Y = th_A - D (the printed /2 is spurious);
    3. eq 9: atan2 with the sign of sin Z (the quadrant), and 0/0 (L' = N) gives 0;
    4. eqs 21, 26-27: y_k = (cos Y - cos X) / (2 cos Z) taken as |y_k|, clamped to [0, 1];
    5. eq 19: |Z| (the sign of Z is carried by ph_A' through erratum 3's atan2);
    6. eq 7: the asin branch is wrong when A is below the world xy-plane (cos th_A < 0);
       the repaired th_x lies in (90, 270) degrees there, so Z is wrapped into [-180, 180).
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        d = a_phi - n_phi
        if 1 in fixed:
            d = np.mod(d, TWO_PI)
            x, y = a_theta + d, a_theta - d                      # eq 6, repaired
        else:
            x, y = (a_theta + d) / 2, (a_theta - d) / 2          # eq 6 as printed
        s = (np.sin(x) + np.sin(y)) / 2                          # x coordinate of A_z
        theta_x = np.arcsin(s)                                   # eq 7
        if 6 in fixed:
            # The circle through A_z parallel to the yz-plane meets the xz-plane on the
            # side of A_z: z = sign(cos th_A) sqrt(1 - s^2).
            theta_x = np.where(np.cos(a_theta) < 0, np.pi - theta_x, theta_x)
        z = theta_x - n_theta                                    # Z = th_x - th_N
        if 6 in fixed:
            z = np.mod(z + np.pi, TWO_PI) - np.pi                # an angle: wrap to [-pi, pi)
        y_num = (np.cos(y) - np.cos(x)) / 2                      # = sin th_A sin D
        if 3 in fixed:
            phi = np.arctan2(y_num, np.sin(z))                   # eq 9 with quadrant
            phi = np.where((y_num == 0) & (np.sin(z) == 0), 0.0, phi)
        else:
            phi = np.arctan(y_num / np.sin(z))                   # eq 9 as printed
        y_k = y_num / np.cos(z)                                  # eq 27
        if 4 in fixed:
            y_k = np.clip(np.abs(np.nan_to_num(y_k, nan=0.0, posinf=1.0, neginf=1.0)), 0.0, 1.0)
        theta_prop = 1 - np.arccos(y_k) / QUARTER                # eqs 21 / 26
        z_used = np.abs(z) if 5 in fixed else z
        theta = z_used + (QUARTER - z_used) * theta_prop         # eq 19
    return np.mod(phi, TWO_PI), theta


def illuminate(a_phi, a_theta, b_phi, b_theta, fixed=ALL_ERRATA):
    """N'.A' by the law of cosines, eqs 24-25 (erratum 2: the second bracket's sign).

    cos a cos b = [cos(a-b) + cos(a+b)]/2 and sin a sin b = [cos(a-b) - cos(a+b)]/2;
    the paper prints cos(a+b) - cos(a-b) in the second bracket, which is N' turned 180
    degrees in azimuth (bump lighting mirrored).
    """
    plus, minus = np.cos(a_theta + b_theta), np.cos(a_theta - b_theta)
    second = (minus - plus) if 2 in fixed else (plus - minus)
    return 0.5 * (plus + minus) + 0.5 * second * np.cos(a_phi - b_phi)


def _lee(px, cfg, fixed):
    l_phi, l_theta = rotate(px.l_phi, px.l_theta, px.n_phi, px.n_theta, fixed)
    h_phi, h_theta = rotate(px.h_phi, px.h_theta, px.n_phi, px.n_theta, fixed)
    with np.errstate(invalid="ignore"):
        ndotl = illuminate(l_phi, l_theta, px.b_phi, px.b_theta, fixed)
        ndoth = illuminate(h_phi, h_theta, px.b_phi, px.b_theta, fixed)
        return shade(ndotl, ndoth, cfg, l_prime=(l_phi, l_theta))


def lee_printed(px: PixelInputs, cfg: Config = Config()):
    """The Lee equations exactly as printed (NaN where the printed form has no value)."""
    return _lee(px, cfg, frozenset())


def lee_corrected(px: PixelInputs, cfg: Config = Config()):
    """Errata 1-6 repaired; the rigid-circle and proportion approximations kept."""
    return _lee(px, cfg, ALL_ERRATA)
