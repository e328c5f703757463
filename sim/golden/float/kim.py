"""Kim, Lee and Park 2001 ("A fast and efficient bump mapping algorithm by angular
perturbation"), float64, as far as the Lee paper describes it.

L and H are transformed into the reference space in polar coordinates (the Lee paper
counts 31 multipliers, 6 LUTs and 18 adders for this setup, Table 1), then the dot products
with the perturbed normal (ph_N', th_N') are taken in polar form, Lee eqs (3)-(4):
N'.L = cos th_l cos th_N' + sin th_l sin th_N' cos(ph_l - ph_N')
(6 multipliers, 12 LUTs, 5 adders for both vectors). Exact in float64.
"""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import (
    PixelInputs,
    cartesian_to_polar,
    polar_to_cartesian,
    shade,
    tangent_rotation,
)

__all__ = ["kim", "polar_dot"]


def polar_dot(a_phi, a_theta, b_phi, b_theta):
    """Lee eqs (3)/(4): the dot product of two unit vectors given in polar angles."""
    return (np.cos(a_theta) * np.cos(b_theta)
            + np.sin(a_theta) * np.sin(b_theta) * np.cos(a_phi - b_phi))


def kim(px: PixelInputs, cfg: Config = Config()):
    m = tangent_rotation(px.n_phi, px.n_theta)

    def to_reference_polar(phi, theta):
        return cartesian_to_polar(np.einsum("...ij,...j->...i", m, polar_to_cartesian(phi, theta)))

    l_prime = to_reference_polar(px.l_phi, px.l_theta)
    h_prime = to_reference_polar(px.h_phi, px.h_theta)
    return shade(polar_dot(*l_prime, px.b_phi, px.b_theta),
                 polar_dot(*h_prime, px.b_phi, px.b_theta), cfg, l_prime=l_prime)
