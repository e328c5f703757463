"""Peercy, Airey and Cabral 1997 ("Efficient Bump Mapping Hardware"), float64.

The reference-space method the Lee paper compares against (Table 1, first column): per
pixel, L and H are transformed into the tangent space by a 3x3 matrix whose rows are the
tangent T, binormal B and normal N (18 multipliers, 12 adders for both vectors), then
normalized (squares, square root, division: 9 multipliers, 3 square roots, 9 dividers,
6 adders in the paper's count), and dotted with the stored perturbed normal N'.
In float64 with exact per-pixel inputs it equals ``conventional`` up to rounding; its
cost, not its accuracy, is what distinguishes it.
"""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import PixelInputs, cartesian_to_polar, polar_to_cartesian, shade

__all__ = ["peercy", "tbn_frame"]


def tbn_frame(n_phi, n_theta):
    """Rows T, B, N of the tangent frame (the frame of Lee Sec. 3.1.1's two rotations)."""
    cp, sp, ct, st = np.cos(n_phi), np.sin(n_phi), np.cos(n_theta), np.sin(n_theta)
    t = np.stack([ct * cp, ct * sp, -st], -1)
    b = np.stack([-sp, cp, np.zeros_like(cp)], -1)
    n = np.stack([st * cp, st * sp, ct], -1)
    return t, b, n


def peercy(px: PixelInputs, cfg: Config = Config()):
    t, b, n = tbn_frame(px.n_phi, px.n_theta)
    nb = polar_to_cartesian(px.b_phi, px.b_theta)

    def to_tangent(phi, theta):
        v = polar_to_cartesian(phi, theta)
        vt = np.stack([np.einsum("...i,...i", r, v) for r in (t, b, n)], -1)  # 3x3 transform
        return vt / np.linalg.norm(vt, axis=-1, keepdims=True)                 # normalization

    lt, ht = to_tangent(px.l_phi, px.l_theta), to_tangent(px.h_phi, px.h_theta)
    return shade(np.einsum("...i,...i", nb, lt), np.einsum("...i,...i", nb, ht), cfg,
                 l_prime=cartesian_to_polar(lt))
