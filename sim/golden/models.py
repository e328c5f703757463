"""Registry of the float64 golden models: name -> fn(px: PixelInputs, cfg: Config) -> Result."""

from .conventional import conventional
from .ernst import ernst
from .exact import exact
from .kim import kim
from .lee import lee_fixed, lee_printed
from .peercy import peercy

__all__ = ["FLOAT_MODELS"]

FLOAT_MODELS = {
    "conventional": conventional,
    "peercy": peercy,
    "kim": kim,
    "ernst": ernst,
    "lee_printed": lee_printed,
    "lee_fixed": lee_fixed,
    "exact": exact,
}
