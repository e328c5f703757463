"""The Illumination unit (Lee Sec. 3.2, Fig. 8): the rotation unit's output in, 8-bit
shading out, for the method ``cfg.method`` names.

:func:`Illumination` is the entry point the pipeline, the emitter and the tests use: it
builds the method's illumination class from the registry (rtl/methods.py), e.g.
``exact.ExactIllumination`` or ``lee.LeeIllumination``. Every such class is a
``wiring.Component`` on the shared back end of rtl/shade.py.
"""

from bumprtl.rtl.config import Config
from bumprtl.rtl.methods import get

__all__ = ["Illumination"]


def Illumination(cfg: Config, target=None, credit=True, fifo_depth=None):
    """The illumination datapath of ``cfg.method``: an instance of
    ``methods.get(cfg.method).illumination`` (a ``wiring.Component``).

    Input payload: the matching rotation unit's output layout; output payload:
    ``layouts.shade_layout(cfg)`` (diffuse, specular, color and the unrounded diffuse_fine,
    specular_fine, tag). ``latency`` depends on
    the method; 1 pixel per clock. ``target``: None (generic) or ``pipe.ECP5()``.
    """
    return get(cfg.method).illumination(cfg, target=target, credit=credit, fifo_depth=fifo_depth)
