"""Error statistics of the float64 models against ``conventional`` (the Cartesian reference)."""

import numpy as np

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.common import PixelInputs, polar_to_cartesian
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.models import FLOAT_MODELS

__all__ = ["angle_error_deg", "compare", "error_stats", "error_by_theta_n", "error_at_theta_n",
           "proportion_worst_case_deg", "random_pixels", "worst_pixel"]


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


def random_pixels(n, seed):
    """``n`` random valid inputs (:meth:`PixelInputs.random`) from ``seed``."""
    if not isinstance(n, (int, np.integer)) or n < 1:
        raise BumpError(f"samples = {n!r} is out of range: allowed integers >= 1")
    if not isinstance(seed, (int, np.integer)) or seed < 0:
        raise BumpError(f"seed = {seed!r} is out of range: allowed integers >= 0")
    return PixelInputs.random(int(n), np.random.default_rng(seed))


def _errors(res, ref):
    """Per-pixel errors of ``res`` against ``ref``: diffuse in 8-bit LSB, and the L' angle
    in degrees when ``res`` computes L'."""
    out = {"diffuse_lsb": np.abs(res.diffuse - ref.diffuse) * 255.0}
    if res.l_prime is not None:
        out["l_prime_deg"] = angle_error_deg(res.l_prime, ref.l_prime)
    return out


def compare(res, ref):
    """Mean, p99 and max of the L' angle error (degrees, when ``res`` has L') and of the
    diffuse error in 8-bit LSB of ``res`` against ``ref``; NaNs are counted, not averaged."""
    return {k: _summary(v) for k, v in _errors(res, ref).items()}


def error_stats(method, n=100_000, seed=1, cfg=Config()):
    """:func:`compare` of ``method`` against ``conventional`` on ``n`` random valid inputs."""
    px = random_pixels(n, seed)
    return {"method": method, "n": n, **compare(FLOAT_MODELS[method](px, cfg), conventional(px, cfg))}


def error_by_theta_n(method="lee_corrected", n=100_000, seed=1, step_deg=15, cfg=Config()):
    """Errors of ``method`` binned by th_N: where the rigid-circle approximation of Lee
    Sec. 3.1.2 (exact at th_N = 0) costs most. Rows (lo_deg, hi_deg, count, summaries)."""
    if not isinstance(step_deg, int) or step_deg < 1 or 180 % step_deg:
        raise BumpError(f"step_deg = {step_deg!r} is out of range: allowed divisors of 180")
    px = random_pixels(n, seed)
    err = _errors(FLOAT_MODELS[method](px, cfg), conventional(px, cfg))
    bins = np.minimum(np.degrees(px.n_theta) // step_deg, 180 // step_deg - 1)   # 180 -> last
    return [(lo * step_deg, (lo + 1) * step_deg, int((bins == lo).sum()),
             {k: _summary(v[bins == lo]) for k, v in err.items()})
            for lo in range(180 // step_deg) if (bins == lo).any()]


def error_at_theta_n(method, n_theta, n=50_000, seed=12, cfg=Config()):
    """:func:`compare` on random inputs with th_N replaced by ``n_theta`` (radians); pixels
    whose light is no longer above the surface (N.L <= 0.02) are dropped."""
    px = random_pixels(n, seed)
    px = PixelInputs(**{**px.__dict__, "n_theta": np.full(px.shape, float(n_theta))})
    px = px.subset(conventional(px, cfg).l_prime[1] < np.arccos(0.02))
    return compare(FLOAT_MODELS[method](px, cfg), conventional(px, cfg))


def proportion_worst_case_deg(steps=1801):
    """Worst case (degrees) of Lee's linear proportion, eq 13: th = th_xz + th_prop (90 -
    th_xz) with th_prop = th_yz / 90, against the exact cos th = cos th_xz cos th_yz, over
    a grid of th_xz, th_yz in [0, 90] degrees."""
    a, b = np.meshgrid(np.linspace(0, np.pi / 2, steps), np.linspace(0, np.pi / 2, steps))
    linear = a + (np.pi / 2 - a) * b / (np.pi / 2)
    return float(np.degrees(np.max(np.abs(linear - np.arccos(np.cos(a) * np.cos(b))))))


def worst_pixel(method, n=100_000, seed=1, cfg=Config()):
    """The random valid input where ``method``'s L' is farthest from the reference: the
    input angles, both L' (all in degrees) and the L' and diffuse errors there."""
    px = random_pixels(n, seed)
    res, ref = FLOAT_MODELS[method](px, cfg), conventional(px, cfg)
    err = _errors(res, ref)
    i = int(np.nanargmax(err["l_prime_deg"]))
    deg = lambda pair: tuple(float(np.degrees(v[i])) for v in pair)
    return {"N": deg((px.n_phi, px.n_theta)), "L": deg((px.l_phi, px.l_theta)),
            "D": float(np.degrees(np.mod(px.l_phi[i] - px.n_phi[i], 2 * np.pi))),
            "l_prime_ref": deg(ref.l_prime), "l_prime": deg(res.l_prime),
            "l_prime_deg": float(err["l_prime_deg"][i]), "diffuse_lsb": float(err["diffuse_lsb"][i])}
