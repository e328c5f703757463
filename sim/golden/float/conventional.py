"""The Cartesian reference: explicit rotation matrices and dot products (float64)."""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import (
    PixelInputs,
    cartesian_to_polar,
    polar_to_cartesian,
    shade,
    tangent_rotation,
)

__all__ = ["conventional"]


def conventional(px: PixelInputs, cfg: Config = Config()):
    """Transform L and H into the tangent frame of N with M = R_y(-th_N) R_z(-ph_N) and
    take their dot products with N' (the conventional reference-space method, Peercy-style
    but exact and without quantization)."""
    m = tangent_rotation(px.n_phi, px.n_theta)
    l_t = np.einsum("...ij,...j->...i", m, polar_to_cartesian(px.l_phi, px.l_theta))
    h_t = np.einsum("...ij,...j->...i", m, polar_to_cartesian(px.h_phi, px.h_theta))
    b = polar_to_cartesian(px.b_phi, px.b_theta)
    ndotl = np.einsum("...i,...i", b, l_t)
    ndoth = np.einsum("...i,...i", b, h_t)
    return shade(ndotl, ndoth, cfg, l_prime=cartesian_to_polar(l_t))
