"""Bit-exact integer model of the PaletteLUT unit and of the colour blending of Sec. 7.

The blend arithmetic (:func:`mul8`, :func:`blend_eq1`, :func:`blend_eq2`) lives in
``rtl/palette.py`` and runs, operation for operation, on Amaranth values there and on
int64 arrays here.

Out-of-range indices (``index >= palette_size``, possible when ``palette_size`` is not a
power of two): the entry reads as all zeros (transparent black) and ``oor`` is 1. Host
writes to such addresses are ignored.
"""

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.rtl.palette import CHANNELS, blend_eq1, blend_eq2, index_bits, mul8

__all__ = ["index_bits", "mul8", "blend_eq1", "blend_eq2", "pack_rgba", "unpack_rgba", "palette_colors",
           "PaletteLUTModel", "CHANNELS", "host_op"]

def pack_rgba(rgba, cfg: Config = Config()):
    """``(..., 4)`` 8-bit RGBA -> one int per entry, r in the low bits (the table word)."""
    v = np.asarray(rgba, dtype=np.int64)
    return sum(v[..., n] << (n * cfg.color_bits) for n in range(4))


def unpack_rgba(word, cfg: Config = Config()):
    w = np.asarray(word, dtype=np.int64)
    mask = (1 << cfg.color_bits) - 1
    return {c: (w >> (n * cfg.color_bits)) & mask for n, c in enumerate(CHANNELS)}


def palette_colors(out, table, scene):
    """The colour a palette scene's pipeline sends (``out``: :func:`pipeline.pipeline_fixed`'s
    ``index`` and ``texel``; ``table``: the packed colour table): each pixel's table entry,
    blended with its texel by Tarini eq. 2 when the scene has a colour texture."""
    entry = unpack_rgba(np.asarray(table)[out["index"]], scene.config)
    if scene.texture:
        entry = blend_eq2(entry, unpack_rgba(out["texel"] | (255 << 24), scene.config), scene.config)
    return {f"color.{c}": np.asarray(entry[c], np.int64) for c in CHANNELS}


class PaletteLUTModel:
    """Cycle-level model of PaletteLUT's double-buffered table.

    A pixel accepted in a cycle reads the front bank as it was in that cycle; host writes
    go to the back bank; a swap strobe exchanges the banks at the end of its cycle (a write
    in the same cycle lands in the bank being published). It models the palette scene
    pipeline too, with "accepted" meaning at the pipeline's input and ``clock``'s
    ``write`` the writes the pipeline took (``lut_w_en & lut_w_ready``).
    """

    def __init__(self, cfg: Config):
        self.cfg = cfg
        self.banks = np.zeros((2, cfg.palette_size), dtype=np.int64)
        self.front = 0

    def lookup(self, index, base=None, blend=False):
        oor = int(index) >= self.cfg.palette_size
        word = 0 if oor else int(self.banks[self.front, index])
        entry = {c: int(v) for c, v in unpack_rgba(word, self.cfg).items()}
        color = blend_eq2(entry, base, self.cfg) if blend else entry
        return {**{f"color.{c}": int(v) for c, v in color.items()}, "oor": int(oor)}

    def clock(self, write=None, swap=False):
        if write is not None and write[0] < self.cfg.palette_size:
            self.banks[1 - self.front, write[0]] = write[1]
        if swap:
            self.front ^= 1


def host_op(rng, cfg: Config, write_p=0.5, swap_p=0.03):
    """Random host traffic for one cycle (testbenches): ``(write or None, swap)``; writes
    also hit addresses >= sN, which the unit must ignore."""
    write = None
    if rng.random() < write_p:
        word = int(pack_rgba([rng.randrange(256) for _ in range(4)], cfg))
        write = (rng.randrange(1 << index_bits(cfg)), word)
    return write, rng.random() < swap_p
