"""Registry of the float64 golden models: name -> fn(px: PixelInputs, cfg: Config) -> Result."""

from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.ernst import ernst
from bumprtl.sim.golden.float.exact import exact
from bumprtl.sim.golden.float.kim import kim
from bumprtl.sim.golden.float.lee import lee_corrected, lee_printed
from bumprtl.sim.golden.float.peercy import peercy

__all__ = ["FLOAT_MODELS"]

FLOAT_MODELS = {
    "conventional": conventional,
    "peercy": peercy,
    "kim": kim,
    "ernst": ernst,
    "lee_printed": lee_printed,
    "lee_corrected": lee_corrected,
    "exact": exact,
}
