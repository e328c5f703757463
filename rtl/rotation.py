"""The vector rotation unit (Lee Sec. 3.1, Fig. 7), or a baseline's setup, for the method
``cfg.method`` names.

:func:`VectorRotation` is the entry point the pipeline, the emitter and the tests use: it
builds the method's rotation class from the registry (rtl/methods.py), e.g.
``exact.ExactRotation`` or ``lee.LeeRotation``; every such class is a ``wiring.Component``.
"""

from bumprtl.rtl.config import Config
from bumprtl.rtl.methods import get

__all__ = ["VectorRotation"]


def VectorRotation(cfg: Config, target=None, credit=True, fifo_depth=None):
    """Per-pixel rotation into the tangent frame of N: an instance of
    ``methods.get(cfg.method).rotation`` (a ``wiring.Component``).

    ``exact`` (rtl/exact.py) rotates the bump normal N' once per pixel and prepares the
    terms of L and H (docs/architecture.md, The exact angular method); ``lee`` (rtl/lee.py)
    rotates L and H by the paper's angular method (eqs 5-21, errata fixed); the baselines
    (rtl/baselines/) build Table 1's setup. Input payload: ``layouts.pixel_layout(cfg)``
    for the polar methods (world N, L, H and tangent-space N' as binary angles, plus the
    tag), Cartesian vectors for Peercy and Ernst. ``latency`` depends on the method;
    1 pixel per clock. ``target``: None (generic) or ``pipe.ECP5()``.
    """
    return get(cfg.method).rotation(cfg, target=target, credit=credit, fifo_depth=fifo_depth)
