"""Shared pieces of the bit-exact (int64) golden models: input quantization and the
illumination back end, mirrored operation for operation by ``rtl/shade.py``."""

from dataclasses import fields

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.rtl.exact import vectors
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.tables import phong_coefficients, specular_index_bits, specular_table
from bumprtl.sim.golden.common import PixelInputs

__all__ = ["angle_codes", "quantize_pixels", "shade_fixed", "polar_rotation_fixed",
           "polar_illumination_fixed"]


def angle_codes(angle_rad, cfg: Config):
    """Radians -> binary-angle codes of ``angle_bits`` bits, rounded to nearest (docs/architecture.md, Number formats);
    the full circle wraps to 0. int32 (angle sums of a few codes never overflow it)."""
    steps = np.rint(np.asarray(angle_rad, dtype=np.float64) * (cfg.full_circle / (2 * np.pi)))
    return steps.astype(np.int32) & np.int32(cfg.full_circle - 1)


def quantize_pixels(px: PixelInputs, cfg: Config):
    """Float inputs -> dict of int32 angle codes keyed like the flattened payload
    (``"n.phi"``, ``"n.theta"``, ``"l.phi"``, ... ``"b.theta"``)."""
    return {f"{f.name[0]}.{f.name[2:]}": angle_codes(getattr(px, f.name), cfg)
            for f in fields(px)}


def shade_fixed(ndotl, ndoth, cfg: Config):
    """Dot products (signed, ``frac_bits`` fractional bits) -> 8-bit diffuse, specular, color.

    diffuse = round(255 * clamp(N'.L, 0, 1))            (a constant multiply, Fig. 8's diffuse table)
    specular = cos^n table at round(clamp(N'.H) * 2**s)  (eq. 2's (N'.H)^n)
    color = clamp(round((KA + KD diffuse + KS specular) / 256), 0, 255)   (eq. 2)
    """
    one = cfg.one
    d = np.clip(np.asarray(ndotl, np.int64), 0, one)
    diffuse = round_shift(d * 255, cfg.frac_bits)
    if cfg.specular:
        s_bits = specular_index_bits(cfg)
        h = np.clip(np.asarray(ndoth, np.int64), 0, one)
        specular = specular_table(cfg)[round_shift(h, cfg.frac_bits - s_bits)]
    else:
        specular = np.zeros_like(diffuse)
    ka, kd, ks = phong_coefficients(cfg)
    color = np.clip(round_shift(ka + kd * diffuse + ks * specular, 8), 0, 255)
    return {"diffuse": diffuse, "specular": specular, "color": color}


def polar_rotation_fixed(rotate, codes, cfg: Config):
    """The rotation unit of a polar method (lee, kim): ``rotate(a_phi, a_theta, n_phi,
    n_theta, cfg) -> (ph_A', th_A')`` for L (and H with specular), N' passed through."""
    out = {}
    for v in vectors(cfg):
        out[f"{v}.phi"], out[f"{v}.theta"] = rotate(
            codes[f"{v}.phi"], codes[f"{v}.theta"], codes["n.phi"], codes["n.theta"], cfg)
    out["b.phi"] = np.asarray(codes["b.phi"], dtype=np.int64)
    out["b.theta"] = np.asarray(codes["b.theta"], dtype=np.int64)
    return out


def polar_illumination_fixed(illuminate, rot, cfg: Config):
    """The illumination unit of a polar method: ``illuminate(a_phi, a_theta, b_phi, b_theta,
    cfg) -> N'.A'`` per vector, then the shared back end (ndotl, ndoth, 8-bit shades)."""
    dots = {v: illuminate(rot[f"{v}.phi"], rot[f"{v}.theta"], rot["b.phi"], rot["b.theta"], cfg)
            for v in vectors(cfg)}
    ndotl = dots["l"]
    ndoth = dots.get("h", np.zeros_like(ndotl))
    return {"ndotl": ndotl, "ndoth": ndoth, **shade_fixed(ndotl, ndoth, cfg)}
