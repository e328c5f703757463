"""Error statistics of the float64 models against ``conventional`` (the Cartesian reference)."""

import numpy as np

from ...rtl.config import Config
from .common import PixelInputs, polar_to_cartesian
from .conventional import conventional
from .models import FLOAT_MODELS

__all__ = ["angle_error_deg", "error_stats"]


def angle_error_deg(a, b):
    """Angle in degrees between direction arrays given as (phi, theta) pairs."""
    va, vb = polar_to_cartesian(*a), polar_to_cartesian(*b)
    # atan2(|a x b|, a.b): accurate for tiny angles, where arccos(a.b) loses half the bits.
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(va, vb), axis=-1),
                                 np.einsum("...i,...i", va, vb)))


def _summary(err):
    finite = err[np.isfinite(err)]
    if finite.size == 0:
        return {"mean": float("nan"), "p99": float("nan"), "max": float("nan"),
                "nan": int(err.size)}
    return {"mean": float(finite.mean()), "p99": float(np.percentile(finite, 99)),
            "max": float(finite.max()), "nan": int(err.size - finite.size)}


def error_stats(method, n=100_000, seed=1, cfg=Config()):
    """Mean, p99 and max of the L' angle error (degrees, when the method computes L') and
    of the diffuse error in 8-bit LSB, on ``n`` random valid inputs; NaN counts too."""
    px = PixelInputs.random(n, np.random.default_rng(seed))
    ref = conventional(px, cfg)
    res = FLOAT_MODELS[method](px, cfg)
    out = {"method": method, "n": n,
           "diffuse_lsb": _summary(np.abs(res.diffuse - ref.diffuse) * 255.0)}
    if res.l_prime is not None:
        out["l_prime_deg"] = _summary(angle_error_deg(res.l_prime, ref.l_prime))
    return out
