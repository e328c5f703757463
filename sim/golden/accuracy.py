"""Accuracy of the fixed-point golden models against float64 on unquantized inputs:
random valid inputs, and an adversarial search for the worst case."""

from dataclasses import fields

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import PixelInputs, to_8bit
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.rtl.methods import encode_pixels

__all__ = ["diffuse_error_lsb", "term_errors_lsb", "adversarial_pixels", "ANGLES_OF_NDOTL"]

# The six input angles N'.L' depends on.
ANGLES_OF_NDOTL = ("n_phi", "n_theta", "l_phi", "l_theta", "b_phi", "b_theta")


def diffuse_error_lsb(model, px: PixelInputs, cfg: Config):
    """|fixed diffuse8 - round(255 clamp(N'.L'))| per pixel, with the float64 reference on
    the unquantized inputs. ``model(codes, cfg)`` is a fixed-point golden model."""
    fixed = model(encode_pixels(px, cfg), cfg)["diffuse"]
    return np.abs(fixed.astype(np.int64) - to_8bit(conventional(px, cfg).diffuse).astype(np.int64))


def term_errors_lsb(model, px: PixelInputs, cfg: Config):
    """Per-pixel |fixed - round(255 x float64)| of diffuse, specular and colour (8-bit)."""
    fixed = model(encode_pixels(px, cfg), cfg)
    ref = conventional(px, cfg)
    return {k: np.abs(fixed[k].astype(np.int64) - to_8bit(getattr(ref, k)).astype(np.int64))
            for k in ("diffuse", "specular", "color")}


def _with(px, **changes):
    return PixelInputs(**{**{f.name: getattr(px, f.name) for f in fields(px)}, **changes})


def _clip_angles(name, x):
    hi = np.pi if name.endswith("theta") else 2 * np.pi
    return np.clip(x, 0.0, hi)


def adversarial_pixels(cfg: Config, candidates=200_000, keep=1_000, seed=7):
    """Inputs that push the quantized datapath hardest.

    1. Start where 255 N'.L' is most sensitive to the input angles: among ``candidates``
       random valid pixels with 0 < N'.L' < 1 (unclamped), keep the ``keep`` with the
       largest sum of |d(255 N'.L')/d angle| (central differences).
    2. Put each of the six angles half a grid step off on the worse side: at the grid point
       plus 0.4999 step times the sign of its derivative, so rounding to the grid moves every
       angle against the output at once.
    3. Scan neighbouring grid points: the same construction around the grid point one step
       below and above in each angle in turn (1 + 2 x 6 variants per pixel).
    Returns PixelInputs of keep x 13 pixels.
    """
    rng = np.random.default_rng(seed)
    px = PixelInputs.random(candidates, rng)
    base = conventional(px, cfg).ndotl
    px = px.subset((base > 0.02) & (base < 0.98))
    step = 2 * np.pi / cfg.full_circle
    h = 1e-6
    grads = {}
    for name in ANGLES_OF_NDOTL:
        x = getattr(px, name)
        up = conventional(_with(px, **{name: _clip_angles(name, x + h)}), cfg).ndotl
        dn = conventional(_with(px, **{name: _clip_angles(name, x - h)}), cfg).ndotl
        grads[name] = 255 * (up - dn) / (2 * h)
    sensitivity = sum(np.abs(g) for g in grads.values())
    px = px.subset(np.argsort(sensitivity)[-keep:])
    grads = {k: g[np.argsort(sensitivity)[-keep:]] for k, g in grads.items()}
    variants = [(None, 0)] + [(name, d) for name in ANGLES_OF_NDOTL for d in (-1, 1)]
    out = []
    for moved, delta in variants:
        changes = {}
        for name in ANGLES_OF_NDOTL:
            grid = np.rint(getattr(px, name) / step) + (delta if name == moved else 0)
            # rounding back to `grid` moves the angle by -0.4999 step * sign(grad): worst side
            changes[name] = _clip_angles(name, (grid + 0.4999 * np.sign(grads[name])) * step)
        out.append(_with(px, **changes))
    return PixelInputs(**{f.name: np.concatenate([getattr(p, f.name) for p in out])
                          for f in fields(px)})
