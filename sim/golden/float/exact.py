"""The exact angular method (docs/architecture.md), float64.

Instead of rotating L and H into the tangent frame (Lee Sec. 3.1), rotate N' once per
pixel: N'.(M A) = (R_y(th_N) n') . A_z, where A_z = R_z(-ph_N) A. Everything is sums of
sin/cos of angle sums (product-to-sum), no division and no inverse trig.
"""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import PixelInputs, shade

__all__ = ["exact", "rotated_normal", "vector_terms"]


def rotated_normal(n_theta, b_phi, b_theta):
    """n'' = R_y(th_N) n' by product-to-sum, with a = th_N' + ph_N', b = th_N' - ph_N'."""
    s, c = np.sin, np.cos
    a, b, t = b_theta + b_phi, b_theta - b_phi, n_theta
    nx = 0.25 * (s(a + t) + s(a - t) + s(b + t) + s(b - t)) + 0.5 * (s(t + b_theta) + s(t - b_theta))
    ny = 0.5 * (c(b) - c(a))
    nz = -0.25 * (c(a - t) - c(a + t) + c(b - t) - c(b + t)) + 0.5 * (c(b_theta - t) + c(b_theta + t))
    return nx, ny, nz


def vector_terms(a_phi, a_theta, n_phi):
    """A_z = R_z(-ph_N) A as (p, y, cos th_A): D = ph_A - ph_N, X = th_A + D, Y = th_A - D,
    p = (sin X + sin Y)/2 = sin th cos D, y = (cos Y - cos X)/2 = sin th sin D."""
    d = a_phi - n_phi
    x, y = a_theta + d, a_theta - d
    return 0.5 * (np.sin(x) + np.sin(y)), 0.5 * (np.cos(y) - np.cos(x)), np.cos(a_theta)


def exact(px: PixelInputs, cfg: Config = Config()):
    """N'.L' and N'.H' by the exact angular method, then Phong (eq. 2)."""
    n = rotated_normal(px.n_theta, px.b_phi, px.b_theta)

    def dot(phi, theta):
        p, y, z = vector_terms(phi, theta, px.n_phi)
        return n[0] * p + n[1] * y + n[2] * z

    return shade(dot(px.l_phi, px.l_theta), dot(px.h_phi, px.h_theta), cfg)
