"""Ernst, Russeler, Schulz and Wittig 1998 ("Gouraud Bump Mapping") in hardware: the
fourth column of Lee et al. Table 1. Bit-exact with ``sim/golden/fixed/ernst.py``.

Ernst differs from Peercy in how the bump map is built (the constant k of Peercy's normal
perturbation fixed to -1, Lee Sec. 2), which is preprocessing: the per-pixel setup is the
same reference-space transform and normalization of L and H, and Table 1 gives both the same
setup counts (27 multipliers, 9 division units, 3 SQRts, 18 adders). So :class:`ErnstRotation` is
Peercy's (rtl/baselines/peercy.py, where our 24/6/2/16 against the paper's 27/9/3/18 is
explained). Illumination is Ernst's "straightforward Phong" (Table 1: 7 multipliers, 1 power
table, 5 adders): N'.L_n and N'.H_n with 6 multipliers and 4 adders, then eq. (2) with the
cos^n power table; Peercy's datapath already is exactly that, so :class:`ErnstIllumination` is
it too. Yosys counts 8 multipliers and 6 adders for it (tests/rtl/test_baselines_cartesian.py):
the 6 dot-product multipliers plus the shared back end's kd and ks weights (registered
products, rtl/shade.py), 4 dot adders plus the back end's Phong sum, against the
paper's 7 and 5.
"""

from bumprtl.rtl.baselines.peercy import PeercyIllumination, PeercyRotation

__all__ = ["ErnstRotation", "ErnstIllumination"]


class ErnstRotation(PeercyRotation):
    """Setup datapath, Ernst: Peercy's transform and normalization of L and H (same
    layouts, latency ``peercy.rotation_latency(cfg)``)."""


class ErnstIllumination(PeercyIllumination):
    """Illumination datapath, Ernst: straightforward Phong, N'.L_n, N'.H_n, cos^n table."""
