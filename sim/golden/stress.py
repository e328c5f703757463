"""Stress cases for the golden models: degenerate geometry, saturation, extreme configs.

Shared by the Hypothesis properties (tests/sim/golden/test_stability.py) and
``bumprtl bench stress`` (docs/stability.md). Each case builds L, H and N' in the tangent
frame of a random world N (Lee Sec. 3.1.1: M = R_y(-th_N) R_z(-ph_N) takes N to +z, so a
tangent-frame vector ``a`` is ``M^T a`` in the world) and returns world :class:`PixelInputs`.
The checks (:func:`check_fixed`, :func:`float_stats`) are the same for tests and bench.
"""

from dataclasses import fields

import numpy as np

from bumprtl.rtl.bumpfetch import pack_texels
from bumprtl.rtl.config import Config
from bumprtl.rtl.layouts import layout_fields, shade_layout
from bumprtl.sim.golden.common import (
    PixelInputs,
    cartesian_to_polar,
    polar_to_cartesian,
    tangent_rotation,
    to_8bit,
)
from bumprtl.sim.golden.fixed.common import quantize_pixels
from bumprtl.sim.golden.fixed.pipeline import map_words
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.methods import encode_pixels, get

__all__ = ["CASES", "STRESS_CONFIGS", "stress_case", "rotate_azimuth", "check_fixed",
           "float_stats", "payload_fields"]

TWO_PI = 2 * np.pi
EPS = 1e-9          # "just above 0" / "just below 2 pi" in radians (far below one angle step)


def _dirs(rng, n, theta_lo=0.0, theta_hi=np.pi):
    """Uniform directions with theta in [theta_lo, theta_hi] as (n, 3) unit vectors."""
    z = rng.uniform(np.cos(theta_hi), np.cos(theta_lo), n)
    return polar_to_cartesian(rng.uniform(0, TWO_PI, n), np.arccos(np.clip(z, -1, 1)))


def _world(n_phi, n_theta, local):
    """Tangent-frame vectors (n, 3) -> world (phi, theta) for per-pixel N."""
    m = tangent_rotation(n_phi, n_theta)
    return cartesian_to_polar(np.einsum("pji,pj->pi", m, local))


def _assemble(n_phi, n_theta, l_local, h_local, b_local):
    l_phi, l_theta = _world(n_phi, n_theta, l_local)
    h_phi, h_theta = _world(n_phi, n_theta, h_local)
    b_phi, b_theta = cartesian_to_polar(b_local)
    return PixelInputs(n_phi, n_theta, l_phi, l_theta, h_phi, h_theta, b_phi, b_theta)


def _random_n(rng, n):
    return rng.uniform(0, TWO_PI, n), np.arccos(rng.uniform(-1, 1, n))


def _case_random(rng, n):
    return PixelInputs.random(n, rng)


def _case_theta_n_zero(rng, n):
    """N = +z: the rigid circle of Lee Sec. 3.1.2 is exact, ph_N is meaningless."""
    n_phi = rng.uniform(0, TWO_PI, n)
    return _assemble(n_phi, np.zeros(n), _dirs(rng, n, 0, np.pi / 2),
                     _dirs(rng, n, 0, np.pi / 2), _dirs(rng, n, 0, np.pi / 2))


def _case_theta_180(rng, n):
    """N = -z (theta = 180 deg): the other pole of the polar parametrization."""
    n_phi = rng.uniform(0, TWO_PI, n)
    return _assemble(n_phi, np.full(n, np.pi), _dirs(rng, n, 0, np.pi / 2),
                     _dirs(rng, n, 0, np.pi / 2), _dirs(rng, n, 0, np.pi / 2))


def _case_l_equals_n(rng, n):
    """L = N: eq. 9's 0/0 (sin Z = 0 and y = 0) and the unbounded 1/sin Z table."""
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    return _assemble(*_random_n(rng, n), up, _dirs(rng, n, 0, np.pi / 2), _dirs(rng, n, 0, np.pi / 2))


def _case_grazing(rng, n):
    """L in the tangent plane (N.L = 0): the clamp edge of the diffuse term."""
    return _assemble(*_random_n(rng, n), _dirs(rng, n, np.pi / 2, np.pi / 2),
                     _dirs(rng, n, 0, np.pi / 2), _dirs(rng, n, 0, np.pi / 2))


def _case_below_horizon(rng, n):
    """L below the surface (N.L < 0) and N' tilted toward it: only the bump may light it."""
    return _assemble(*_random_n(rng, n), _dirs(rng, n, np.pi / 2 + 0.01, np.pi),
                     _dirs(rng, n, np.pi / 2 + 0.01, np.pi), _dirs(rng, n, 0, np.pi / 2))


def _case_azimuth_wrap(rng, n):
    """ph_N just below 360 deg and ph_L, ph_H, ph_N' just above 0, and the reverse: D wraps."""
    px = PixelInputs.random(n, rng)
    lo = rng.uniform(0, 0.02, (4, n))
    flip = rng.random(n) < 0.5
    near0, near360 = lo, TWO_PI - EPS - lo
    pick = lambda i, low: np.where(flip ^ low, near0[i], near360[i])
    return PixelInputs(pick(0, False), px.n_theta, pick(1, True), px.l_theta,
                       pick(2, True), px.h_theta, pick(3, True), px.b_theta)


def _case_saturation(rng, n):
    """N' = +z and L = H = N: N'.L = N'.H = 1 exactly, the full-scale end of every dot,
    diffuse table, specular table and Phong sum; half the pixels with L = H = -N (-1)."""
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    sign = np.where(rng.random(n) < 0.5, 1.0, -1.0)[:, None]
    return _assemble(*_random_n(rng, n), up * sign, up * sign, up)


def _case_grid_extremes(rng, n):
    """Every angle at 0, 90, 180, 270 deg or the circle's end (phi = 2 pi, theta = pi):
    the largest binary-angle codes and the quarter-wave mirror points."""
    pick = lambda hi: rng.choice(np.array([0, 0.25, 0.5, 0.75, 1.0]) * hi, n)
    return PixelInputs(**{f.name: pick(np.pi if f.name.endswith("theta") else TWO_PI)
                          for f in fields(PixelInputs)})


# name -> (generator(rng, n) -> PixelInputs, description for docs/stability.md)
CASES = {
    "random": (_case_random, "random valid inputs (PixelInputs.random)"),
    "theta_n_zero": (_case_theta_n_zero, "th_N = 0 (N = +z)"),
    "theta_180": (_case_theta_180, "th_N = 180 deg (N = -z)"),
    "l_equals_n": (_case_l_equals_n, "L = N (eq. 9's 0/0, 1/sin Z unbounded)"),
    "grazing": (_case_grazing, "grazing light, N.L = 0"),
    "below_horizon": (_case_below_horizon, "light and H below the horizon, N.L < 0"),
    "azimuth_wrap": (_case_azimuth_wrap, "ph_N near 360 deg, ph_L/ph_H/ph_N' near 0 and reverse"),
    "saturation": (_case_saturation, "N' = +z, L = H = +-N: every dot at +-1.0"),
    "grid_extremes": (_case_grid_extremes, "all angles at 0/90/180/270/360 deg (largest codes)"),
}

# The extreme configurations: narrowest and widest widths, extreme specular exponents.
STRESS_CONFIGS = {
    "default": Config(),
    "narrowest": Config(angle_bits=4, frac_bits=4),
    "widest": Config(angle_bits=16, frac_bits=24, spec_index_bits=16),
    "spec_n=1": Config(spec_exponent=1),
    "spec_n=1024": Config(spec_exponent=1024),
}


def stress_case(name, n, seed=0):
    """``n`` pixels of stress case ``name`` (a key of :data:`CASES`)."""
    return CASES[name][0](np.random.default_rng(seed), n)


def rotate_azimuth(px: PixelInputs, delta):
    """The scene turned by ``delta`` radians about world z: ph_N, ph_L, ph_H shift, N' (in
    the tangent frame, which turns with N) does not."""
    turn = lambda phi: np.mod(phi + delta, TWO_PI)
    return PixelInputs(turn(px.n_phi), px.n_theta, turn(px.l_phi), px.l_theta,
                       turn(px.h_phi), px.h_theta, px.b_phi, px.b_theta)


def payload_fields(cfg: Config):
    """``{field: (width, signed)}`` of the rotation unit's output and the illumination
    unit's output for ``cfg.method``: the widths every model value must fit in."""
    out = {}
    for layout in (get(cfg.method).rotated_layout(cfg), shade_layout(cfg)):
        out.update({k: (w, s) for k, (_, w, s) in layout_fields(layout).items() if k != "tag"})
    return out


def _fits(values, width, signed):
    v = np.asarray(values, dtype=np.int64)
    lo, hi = (-(1 << (width - 1)), (1 << (width - 1)) - 1) if signed else (0, (1 << width) - 1)
    return (v >= lo) & (v <= hi)


def check_fixed(model, px: PixelInputs, cfg: Config):
    """Run a bit-exact model on ``px`` quantized for ``cfg``: per pixel the diffuse and
    colour error against float64 (8-bit LSB), and the overflow count (pixels with some
    field outside its payload width, :func:`payload_fields`; fields per name)."""
    out = model(encode_pixels(px, cfg), cfg)
    ref = conventional(px, cfg)
    overflow = {k: int((~_fits(out[k], w, s)).sum()) for k, (w, s) in payload_fields(cfg).items()
                if k in out}
    err = {k: np.abs(np.asarray(out[k], np.int64) - to_8bit(getattr(ref, k)).astype(np.int64))
           for k in ("diffuse", "color")}
    return {"diffuse_lsb": err["diffuse"], "color_lsb": err["color"], "overflow": overflow}


def float_stats(result, ref):
    """NaN count, out-of-range count (diffuse/specular/colour outside [0, 1] or infinite
    dots) and max diffuse/colour error in 8-bit LSB of a float64 Result against ``ref``
    (errors over the finite pixels; NaN pixels counted, not averaged)."""
    nan = np.zeros(result.diffuse.shape, bool)
    for k in ("ndotl", "ndoth", "diffuse", "specular", "color"):
        nan |= np.isnan(getattr(result, k))
    bad = np.zeros_like(nan)
    for k in ("diffuse", "specular", "color"):
        v = getattr(result, k)
        bad |= ~nan & ((v < 0) | (v > 1))
    for k in ("ndotl", "ndoth"):
        bad |= np.isinf(getattr(result, k))
    ok = ~nan
    lsb = lambda k: np.abs(to_8bit(getattr(result, k)[ok]).astype(int) - to_8bit(getattr(ref, k)[ok]).astype(int))
    dl, cl = lsb("diffuse"), lsb("color")
    return {"nan": int(nan.sum()), "overflow": int(bad.sum()),
            "diffuse_max_lsb": int(dl.max()) if dl.size else None,
            "color_max_lsb": int(cl.max()) if cl.size else None}


def stress_codes(n, cfg: Config, seed=0):
    """``n`` pixels cycling through every case of :data:`CASES`, quantized for ``cfg``."""
    per = -(-n // len(CASES))
    parts = [quantize_pixels(stress_case(name, per, seed + i), cfg) for i, name in enumerate(CASES)]
    order = np.arange(per * len(CASES)).reshape(len(CASES), per).T.ravel()[:n]   # interleave
    return {k: np.concatenate([p[k] for p in parts])[order] for k in parts[0]}


def pipeline_stimulus(scene, n, seed=0):
    """Stress vectors for BumpPipeline(scene) (varying map, per-pixel shading): ``(inputs,
    words)``. Pixel i reads texel i mod W H (W x H the map, W = H = T square), and the map
    holds the N' of the first W H stress pixels, so every case's N' reaches the datapath
    through the fetch unit."""
    t, h = scene.texture_size, scene.map_height
    codes = stress_codes(max(n, t * h), scene.config, seed)
    texel = np.arange(n) % (t * h)
    inputs = {"u": texel % t, "v": texel // t}
    inputs.update({k: codes[k][:n] for k in ("n.phi", "n.theta", "l.phi", "l.theta")})
    if scene.specular:
        inputs.update({k: codes[k][:n] for k in ("h.phi", "h.theta")})
    inputs["tag"] = np.arange(n) & ((1 << scene.tag_bits) - 1)
    level0 = pack_texels(scene, codes["b.phi"][:t * h].reshape(h, t), codes["b.theta"][:t * h].reshape(h, t))
    return {k: np.asarray(v, np.int64) for k, v in inputs.items()}, map_words([level0], scene)
