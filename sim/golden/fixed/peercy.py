"""Bit-exact int64 model of the Peercy baseline (rtl/baselines/peercy.py), vectorized.

Codes are Cartesian (the RTL's input): keys ``"t.x" ... "n.z"`` (frame rows T, B, N),
``"l.x" ...``, ``"h.x" ...`` (with specular) and ``"np.x" ...`` (the perturbed normal N'),
signed integers with B = frac_bits fractional bits. :func:`encode` makes them from float64
:class:`PixelInputs` (round to nearest), :func:`from_angle_codes` from the binary-angle
codes of ``sim/golden/vectors.py`` (so the polar edge cases drive this datapath too).

Per vector A (all integers, B fractional bits unless said):
  a_t = round((row . A) / 2**B)               row in (T, B, N)           transform
  s   = x**2 + y**2 + z**2                    2B fractional bits
  r   = isqrt(4 s)                            B + 1 fractional bits      square root
  q   = floor(|a_t| 2**(B+2) / r)  (0 if r = 0), q' = (q + 1) >> 1, sign of a_t   division
  N'.A_n = round((N' . A_n) / 2**B)           then the shared back end (fixed_common).
"""

import numpy as np

from bumprtl.rtl.baselines.peercy import AXES, FRAME, vectors
from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import Q, round_shift
from bumprtl.sim.golden.common import PixelInputs, polar_to_cartesian
from bumprtl.sim.golden.fixed.common import channel_bound, shade_fixed
from bumprtl.sim.golden.float.peercy import tbn_frame

__all__ = ["rotation_fixed", "illumination_fixed", "encode",
           "from_angle_codes", "isqrt", "input_keys", "predicted_error_bound_lsb"]


def input_keys(cfg: Config):
    """Flattened names of the setup unit's input payload (without the tag)."""
    return [f"{name}.{a}" for name in (*FRAME, *vectors(cfg), "np") for a in AXES]


def _quantize_vectors(vecs, cfg: Config):
    """{name: float array (..., 3)} -> codes, each component rounded to nearest, saturated
    to the signed(B + 2) input format."""
    q = Q(1, cfg.frac_bits)
    return {f"{name}.{a}": q.quantize(v[..., i]) for name, v in vecs.items()
            for i, a in enumerate(AXES)}


def _vectors_from_angles(n_phi, n_theta, l, h, b):
    t_row, b_row, n_row = tbn_frame(n_phi, n_theta)
    return {"t": t_row, "b": b_row, "n": n_row, "l": polar_to_cartesian(*l),
            "h": polar_to_cartesian(*h), "np": polar_to_cartesian(*b)}


def encode(px: PixelInputs, cfg: Config):
    """Float64 pixels -> Cartesian input codes: T, B, N from (ph_N, th_N) (the frame of
    ``conventional``), L, H and N' from their angles, each component rounded to nearest.
    This is what a Cartesian rasterizer would interpolate; use it, not ``quantize_pixels``,
    to measure this datapath against float64."""
    vecs = _vectors_from_angles(px.n_phi, px.n_theta, (px.l_phi, px.l_theta),
                                (px.h_phi, px.h_theta), (px.b_phi, px.b_theta))
    return {k: v for k, v in _quantize_vectors(vecs, cfg).items() if k in input_keys(cfg)}


def from_angle_codes(codes, cfg: Config):
    """Binary-angle codes (``"n.phi"``, ... ``"b.theta"``, as in sim/golden/vectors.py) ->
    Cartesian input codes of the same directions (for the shared edge-case stimulus)."""
    rad = {k: np.asarray(v, dtype=np.float64) * (2 * np.pi / cfg.full_circle)
           for k, v in codes.items()}
    h = (rad["h.phi"], rad["h.theta"]) if "h.phi" in rad else (rad["l.phi"], rad["l.theta"])
    vecs = _vectors_from_angles(rad["n.phi"], rad["n.theta"], (rad["l.phi"], rad["l.theta"]),
                                h, (rad["b.phi"], rad["b.theta"]))
    return {k: v for k, v in _quantize_vectors(vecs, cfg).items() if k in input_keys(cfg)}


def isqrt(x):
    """floor(sqrt(x)) of non-negative int64 (< 2**62), exact: float64 estimate, then fixed
    up by whole steps (the RTL's PeercySqrt is checked against math.isqrt separately)."""
    x = np.asarray(x, dtype=np.int64)
    r = np.floor(np.sqrt(x.astype(np.float64))).astype(np.int64)
    for _ in range(3):
        r = np.where(r * r > x, r - 1, r)
        r = np.where((r + 1) * (r + 1) <= x, r + 1, r)
    return r


def _vec(codes, name):
    return [np.asarray(codes[f"{name}.{a}"], dtype=np.int64) for a in AXES]


def normalize_fixed(at, cfg: Config):
    """A_t (three int64 arrays, B fractional bits) -> A_n = A_t / |A_t| (B fractional bits):
    r = isqrt(4 s), q = floor(|a| 2**(B+2) / r), rounded half up, sign put back."""
    b = cfg.frac_bits
    s = at[0] * at[0] + at[1] * at[1] + at[2] * at[2]
    r = isqrt(4 * s)
    out = []
    for a in at:
        num = np.abs(a) << (b + 2)
        q = np.where(r > 0, num // np.maximum(r, 1), 0)         # Amaranth: x // 0 == 0
        q = round_shift(q, 1)
        out.append(np.where(a < 0, -q, q))
    return out


def rotation_fixed(codes, cfg: Config):
    """Setup: L_n (and H_n) in tangent space, N' passed through."""
    b = cfg.frac_bits
    frame = [_vec(codes, row) for row in FRAME]
    out = {}
    for v in vectors(cfg):
        a = _vec(codes, v)
        at = [round_shift(r[0] * a[0] + r[1] * a[1] + r[2] * a[2], b) for r in frame]
        for axis, value in zip(AXES, normalize_fixed(at, cfg), strict=False):
            out[f"{v}.{axis}"] = value
    for axis, value in zip(AXES, _vec(codes, "np"), strict=False):
        out[f"np.{axis}"] = value
    return out


def illumination_fixed(rot, cfg: Config):
    """N'.L_n, N'.H_n (rounded to B bits) and 8-bit diffuse, specular, color."""
    n = _vec(rot, "np")
    dots = {}
    for v in vectors(cfg):
        a = _vec(rot, v)
        dots[v] = round_shift(n[0] * a[0] + n[1] * a[1] + n[2] * a[2], cfg.frac_bits)
    ndotl = dots["l"]
    ndoth = dots.get("h", np.zeros_like(ndotl))
    return {"ndotl": ndotl, "ndoth": ndoth, **shade_fixed(ndotl, ndoth, cfg)}


def predicted_error_bound_lsb(cfg: Config, channel="diffuse", lights=1):
    """Worst-case |diffuse8 - round(255 clamp(N'.L'))| against float64 ``conventional`` on
    unquantized inputs (:func:`encode`), in 8-bit LSB; for ``channel`` = ``specular``,
    ``color`` or ``blend`` the shared back end's bound (common.channel_bounds_lsb) for a dot
    product within e (below) of the true one. With u = 2**-B, to first order:

    * inputs: every component is rounded to nearest, so |dL|, |dN'| <= (sqrt 3 / 2) u and the
      frame matrix M = (T; B; N) is off by at most 3/2 u in Frobenius norm;
    * transform: |d(M L)| <= |dM| |L| + |M| |dL| (M orthonormal) + the rounding of the three
      components, so |dL_t| <= (3/2 + sqrt 3 / 2 + sqrt 3 / 2) u = (3/2 + sqrt 3) u;
    * normalization: dividing by |L_t| ~ 1 does not grow the error in L_t (it only removes
      the radial part); r is floored to B + 1 fractional bits (relative error < u/2, a
      vector error < u/2) and each quotient is rounded (sqrt 3 / 2 u);
    * dot: |dN'| + |dL_n| (both unit vectors) plus its rounding u/2.
    Total e = (3/2 + sqrt 3 + 1/2 + sqrt 3 / 2 + sqrt 3 / 2 + 1/2) u = (5/2 + 2 sqrt 3) u
    (+ 2 u**2 for the second-order terms); the 8-bit rounding of both sides turns an error
    e before it into at most floor(255 e) + 1 after it. Measured maxima stay under it
    (tests/sim/golden/fixed/test_cartesian.py).
    """
    u = 2.0 ** -cfg.frac_bits
    e = (2.5 + 2 * np.sqrt(3)) * u + 2 * u * u
    if channel != "diffuse" or lights != 1:
        return channel_bound(cfg, channel, 0.0, e, lights)
    return int(np.floor(255.0 * e)) + 1
