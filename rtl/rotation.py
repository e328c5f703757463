"""Vector rotation unit (Lee Sec. 3.1, Fig. 7), method chosen by ``cfg.method``."""

from bumprtl.rtl.illumination import MethodUnit

__all__ = ["VectorRotation"]


class VectorRotation(MethodUnit):
    """Per-pixel rotation into the tangent frame of N.

    ``exact`` (rtl/exact.py) rotates the bump normal N' once per pixel and prepares the
    terms of L and H (DESIGN §3); ``lee`` (rtl/lee.py) rotates L and H by the paper's
    angular method (eqs 5-21, errata fixed). Input payload: ``layouts.pixel_layout(cfg)``
    (world N, L, H and tangent-space N' as binary angles, plus the tag).
    Throughput 1 pixel per clock; ``latency`` depends on the method.
    """

    _unit = "Rotation"
