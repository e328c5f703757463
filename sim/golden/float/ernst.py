"""Ernst, Russeler, Schulz and Wittig 1998 ("Gouraud Bump Mapping"), float64.

The fourth column of Lee et al. Table 1. Per pixel Ernst does what Peercy does: L and H
are transformed into the tangent space by the 3x3 matrix (T; B; N) (18 multipliers, 12
adders), normalized (9 multipliers, 3 square roots, 9 division units, 6 adders in the
paper's count) and dotted with the stored perturbed normal N' in a straightforward Phong
(7 multipliers, 5 adders, one power table for (N'.H)^n). Ernst's change is in building the
bump map (Peercy's perturbation constant k fixed to -1, Lee Sec. 2), which happens before
the per-pixel stage: given the same N' the result is Peercy's, and in float64 with exact
inputs both equal ``conventional`` up to rounding.
"""

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.float.peercy import peercy

__all__ = ["ernst"]


def ernst(px: PixelInputs, cfg: Config = Config()):
    """Ernst's per-pixel shading of ``px``: Peercy's setup and a straightforward Phong."""
    return peercy(px, cfg)
