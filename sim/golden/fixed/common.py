"""Shared pieces of the bit-exact (int64) golden models: input quantization and the
illumination back end, mirrored operation for operation by ``rtl/shade.py``."""

import functools
from dataclasses import fields

import numpy as np

from bumprtl.rtl.config import Config, ConfigError
from bumprtl.rtl.exact import vectors
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.tables import (
    COLOR_FRAC_BITS,
    KD_FRAC_BITS,
    KS_FRAC_BITS,
    SPEC_FRAC_BITS,
    coefficient_error_lsb,
    phong_coefficients,
    specular_base,
    specular_index_bits,
    specular_step_bits,
    specular_table,
    specular_table_error_lsb,
)
from bumprtl.sim.golden.common import PixelInputs

__all__ = ["angle_codes", "quantize_pixels", "shade_fixed", "specular_fine_fixed",
           "phong_sum_fixed", "CHANNELS", "BOUND_CHANNELS", "check_channel", "term_bounds_lsb",
           "channel_bounds_lsb", "channel_bound",
           "input_angle_error", "polar_rotation_fixed",
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


def specular_fine_fixed(h, cfg: Config, step_bits=None):
    """255 h**n with SPEC_FRAC_BITS fractional bits for h = clamp(N'.H) (B fractional bits):
    the cos^n table (rtl/tables.py) read at words j, j + 1 of h - x0 = j 2**r + f and
    interpolated, T[j] + floor((T[j+1] - T[j]) f / 2**r); 0 below x0 (word 0).
    ``step_bits``: another table step than the RTL's (``bumprtl bench specular``)."""
    t = specular_step_bits(cfg) if step_bits is None else step_bits
    table = specular_table(cfg, t)
    s_bits, r = specular_index_bits(cfg), cfg.frac_bits - t
    x0 = specular_base(cfg, t)
    above = np.where(h < x0, 0, h - x0)
    j = above >> r
    t0 = table[j]
    if not r:
        return t0
    t1 = table[(j & ((1 << s_bits) - 1)) + 1]
    return t0 + (((t1 - t0) * (above & ((1 << r) - 1))) >> r)


def phong_sum_fixed(d, s, cfg: Config):
    """Eq. 2's colour from the unrounded terms, rounded once: d = sum of clamp(N'.L_j) (B
    fractional bits), s = sum of specular_fine_j; min(255, round((KA + floor(KD d / 2**B) +
    floor(KS s / 2**16)) / 2**G)) (rtl/shade.py, rtl/pipeline.LightSum)."""
    g = COLOR_FRAC_BITS
    ka, kd, ks = phong_coefficients(cfg)
    terms = ((kd * np.asarray(d, np.int64)) >> (KD_FRAC_BITS + cfg.frac_bits - g)) + \
        ((ks * np.asarray(s, np.int64)) >> (KS_FRAC_BITS + SPEC_FRAC_BITS - g))
    return np.minimum((terms + (ka + (1 << (g - 1)))) >> g, 255)


def shade_fixed(ndotl, ndoth, cfg: Config):
    """Dot products (signed, ``frac_bits`` fractional bits) -> the back end's outputs
    (rtl/shade.shade_stages):

    diffuse_fine = clamp(N'.L, 0, 1) (B fractional bits); specular_fine = 255 cos^n with F
    fractional bits (:func:`specular_fine_fixed`, eq. 2's (N'.H)^n);
    diffuse = round(255 diffuse_fine), specular = round(specular_fine / 2**F)   (8-bit ports)
    color = :func:`phong_sum_fixed` of the unrounded terms                     (eq. 2)
    """
    one = cfg.one
    d = np.clip(np.asarray(ndotl, np.int64), 0, one)
    diffuse = round_shift(d * 255, cfg.frac_bits)
    if cfg.specular:
        fine = specular_fine_fixed(np.clip(np.asarray(ndoth, np.int64), 0, one), cfg)
    else:
        fine = np.zeros_like(d)
    return {"diffuse": diffuse, "specular": round_shift(fine, SPEC_FRAC_BITS),
            "color": phong_sum_fixed(d, fine, cfg), "diffuse_fine": d, "specular_fine": fine}


CHANNELS = ("diffuse", "specular", "color")


def input_angle_error(cfg: Config):
    """2 sqrt(5) delta, delta = pi / 2**(k+2) (half an angle step): how far rounding the
    eight input angles to the grid can move the angle between N' and A (A = L or H), exactly
    (not only to first order). In the frame turned by ph_N, N' = R_y(th_N) n'(ph', th') moves
    with speed |(e_N cos ph' + e_th', e_ph' sin th' - e_N cos th' sin ph')| <= sqrt(3 + 2
    |cos ph'|) delta <= sqrt(5) delta for angle errors |e| <= delta, and A, whose azimuth
    relative to N is off by at most 2 delta, with speed sqrt(e_th**2 + sin**2 th e_ph**2) <=
    sqrt(5) delta; so along the straight path from the true angles to the rounded ones each
    moves by at most sqrt(5) delta on the sphere, and the angle between them by at most the
    sum (the triangle inequality of the great-circle distance)."""
    return 2 * np.sqrt(5) * np.pi / (1 << (cfg.k + 2))


@functools.lru_cache(maxsize=256)
def _term_bounds(exponent, angle, additive, grid=1 << 16):
    """max over alpha of |f(x_c) - f(cos alpha)| in 8-bit LSB for f = 255 clamp(x) and
    255 clamp(x)**n, where x_c is anywhere in [cos(alpha + angle) - additive,
    cos(alpha - angle) + additive] (angles clipped to [0, pi]). Rigorous over the whole
    interval: on each of ``grid`` pieces [a0, a1] of [0, pi] the true x lies in
    [cos a1, cos a0] and x_c in [cos(a1 + angle) - additive, cos(a0 - angle) + additive], and
    f is increasing, so f(hi_c) - f(lo) and f(hi) - f(lo_c) bound the difference there."""
    a = np.linspace(0.0, np.pi, grid + 1)
    lo, hi = np.cos(a[1:]), np.cos(a[:-1])
    lo_c = np.cos(np.minimum(a[1:] + angle, np.pi)) - additive
    hi_c = np.cos(np.maximum(a[:-1] - angle, 0.0)) + additive
    out = []
    for n in (1, exponent):
        f = lambda x, n=n: 255.0 * np.clip(x, 0.0, 1.0) ** n
        out.append(float(np.maximum(f(hi_c) - f(lo), f(hi) - f(lo_c)).max()))
    return tuple(out)


def term_bounds_lsb(cfg: Config, angle, additive):
    """Bounds (8-bit LSB, before the output rounding) on the unrounded diffuse and specular
    terms of the back end against float64 ``255 clamp(N'.A)``, ``255 clamp(N'.H)**n``, for a
    method whose computed dot product x_c lies within ``angle`` (radians, of the angle between
    N' and A) and then ``additive`` of the true one: {diffuse, specular}. The specular term
    adds the table's own error (rtl/tables.specular_table_error_lsb)."""
    diffuse, specular = _term_bounds(cfg.spec_exponent, float(angle), float(additive))
    out = {"diffuse": diffuse, "specular": 0.0}
    if cfg.specular:
        out["specular"] = specular + specular_table_error_lsb(cfg)
    return out


def channel_bounds_lsb(cfg: Config, angle, additive, lights=1):
    """Proven per-channel bounds (8-bit LSB) of the shared back end (rtl/shade.py, and
    rtl/pipeline.LightSum / rtl/texture.TextureBlend for ``lights`` > 1 or the blend) against
    float64 on unquantized inputs, for a dot product within ``angle`` and ``additive`` of the
    true one (:func:`term_bounds_lsb`):

    * diffuse = round(255 sum d_j): the m terms' errors, then the 8-bit rounding (the
      reference is rounded too, so an error e before it is at most floor(e) + 1 after it);
    * specular = round(sum s_j / 2**F): likewise, with the table's error;
    * color = round of the Phong sum (eq. 2) of the unrounded terms: kd and ks times the
      terms' errors, the coefficients' quantization and floors
      (rtl/tables.coefficient_error_lsb), one rounding;
    * blend: the texture blend (rtl/texture.py), whose texel scales the diffuse part by at
      most 1: the same with the blend's coefficients.
    The clamps (to 1 in lit, to 255) are 1-Lipschitz and do not add."""
    t = term_bounds_lsb(cfg, angle, additive)
    ks = cfg.ks if cfg.specular else 0.0
    terms = lights * (cfg.kd * t["diffuse"] + ks * t["specular"])
    before = {"diffuse": lights * t["diffuse"], "specular": lights * t["specular"],
              "color": terms + coefficient_error_lsb(cfg, lights),
              "blend": terms + coefficient_error_lsb(cfg, lights, blend=True)}
    return {k: min(int(np.floor(v)) + 1, 255) for k, v in before.items()}


BOUND_CHANNELS = CHANNELS + ("blend",)


def check_channel(channel):
    """A :class:`ConfigError` naming ``channel`` and the allowed ones unless it is one."""
    if channel not in BOUND_CHANNELS:
        raise ConfigError(f"channel must be one of {', '.join(BOUND_CHANNELS)}, got {channel!r}")


def channel_bound(cfg: Config, channel, angle, additive, lights=1):
    """One channel of :func:`channel_bounds_lsb` (a ConfigError for an unknown channel)."""
    check_channel(channel)
    return channel_bounds_lsb(cfg, angle, additive, lights)[channel]


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
