"""Accuracy of the fixed-point golden models against float64 on unquantized inputs:
random valid inputs, and an adversarial search for the worst case."""

import itertools
from dataclasses import fields, replace

import numpy as np

from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.tables import SPEC_FRAC_BITS
from bumprtl.rtl.texture import texture_blend
from bumprtl.sim.golden.common import PixelInputs, cartesian_to_polar, to_8bit, world_bump_normal
from bumprtl.sim.golden.fixed.common import angle_codes
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.methods import encode_pixels, get
from bumprtl.sim.scenes import load_scene
from bumprtl.sim.scenes.heightfields import height_to_normals

__all__ = ["diffuse_error_lsb", "term_errors_lsb", "on_grid", "grid_errors_lsb",
           "adversarial_pixels", "arithmetic_pixels", "worst_case_pixels", "steep_pixels",
           "unrounded_lsb",
           "highlight_pixels", "reference_blend", "scene_error", "crater_scene", "ANGLES_OF_NDOTL", "ANGLES_OF",
           "CHANNELS"]

# The six input angles N'.L' depends on.
ANGLES_OF_NDOTL = ("n_phi", "n_theta", "l_phi", "l_theta", "b_phi", "b_theta")
# The output channels and the input angles each depends on.
CHANNELS = ("diffuse", "specular", "color")
ANGLES_OF = {"diffuse": ANGLES_OF_NDOTL,
             "specular": ("n_phi", "n_theta", "h_phi", "h_theta", "b_phi", "b_theta"),
             "color": ANGLES_OF_NDOTL + ("h_phi", "h_theta")}


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


def on_grid(px: PixelInputs, cfg: Config):
    """The angles the hardware receives: each angle of ``px`` rounded to the binary-angle
    grid (sim/golden/fixed/common.angle_codes, what ``encode_pixels`` does) and back to
    radians. The fixed-point model gives the same outputs on ``px`` and on these."""
    step = 2 * np.pi / cfg.full_circle
    return PixelInputs(**{f.name: _clip_angles(f.name, angle_codes(getattr(px, f.name), cfg) * step)
                          for f in fields(px)})


def grid_errors_lsb(model, px: PixelInputs, cfg: Config):
    """The arithmetic error alone: per pixel |fixed - round(255 x float64)| of diffuse,
    specular and colour with float64 on the angles the hardware receives (:func:`on_grid`),
    so the input rounding is not in it (:func:`term_errors_lsb` is the end-to-end error).
    None for a method whose inputs are Cartesian components (Peercy, Ernst): their
    quantized T, B, N frame is no set of angles float64 could be given."""
    if get(cfg.method).cartesian:
        return None
    return term_errors_lsb(model, on_grid(px, cfg), cfg)


def reference_blend(refs, texel, cfg: Config):
    """float64 of the texture blend (rtl/texture.py) for lights ``refs`` (float64 Results)
    and 8-bit texels {r, g, b}: 255 clamp(tex / 255 min(1, ka + kd sum d_j) + ks sum s_j),
    rounded to 8 bits."""
    d = sum(np.clip(r.ndotl, 0.0, 1.0) for r in refs)
    s = sum(r.specular for r in refs)
    lit = np.minimum(1.0, cfg.ka + cfg.kd * d)
    ks = cfg.ks if cfg.specular else 0.0
    return {c: to_8bit(np.clip(np.asarray(texel[c], np.float64) / 255 * lit + ks * s, 0.0, 1.0))
            for c in texel}


def scene_error(scene, cfg: Config, model, blend=False):
    """PSNR (dB, None when identical) and max |difference| (8-bit LSB) over the pixels the
    geometry covers of a scene's shading by ``model`` (a fixed-point golden model, e.g.
    rtl/methods.datapath_fixed) against float64 ``conventional`` on the unquantized inputs.

    The image is what the datapath outputs, eq. 2's 8-bit colour; with ``blend`` (a scene
    with a colour texture) the texture blend of rtl/texture.py on the scene's 8-bit albedo
    texels, against :func:`reference_blend` of the same texels. (Multiplying the 8-bit
    colour by the albedo in float afterwards would round twice on the measuring side: the
    exact colour rounded to 8 bits then reaches only about 57 dB.)"""
    ref = conventional(scene.px, cfg)
    out = model(encode_pixels(scene.px, cfg), cfg)
    m = scene.mask
    if blend:
        tex = {c: to_8bit(scene.albedo[scene.v, scene.u][..., n]).astype(np.int64)
               for n, c in enumerate("rgb")}
        got = texture_blend([out["diffuse_fine"]], [out["specular_fine"]], tex, cfg)[0]
        want = reference_blend([ref], tex, cfg)
        got = np.stack([got[c][m] for c in "rgb"]).astype(np.float64)
        want = np.stack([want[c][m] for c in "rgb"]).astype(np.float64)
    else:
        got, want = out["color"][m].astype(np.float64), to_8bit(ref.color)[m].astype(np.float64)
    mse = float(np.mean((got - want) ** 2))
    return {"psnr_db": None if mse == 0 else round(float(10 * np.log10(255.0 ** 2 / mse)), 2),
            "max_lsb": int(np.abs(got - want).max())}


def crater_scene(size=128, seed=1234, count=60):
    """An unseen height map for the scene measures: ``count`` random craters (a bowl and a
    raised rim each) with a fixed seed, on the plane of the bumps scene (its N, L, H per
    pixel)."""
    rng = np.random.default_rng(seed)
    c = (np.arange(size) + 0.5) / size
    u, v = np.meshgrid(c, c)
    height = np.zeros((size, size))
    for _ in range(count):
        cx, cy, r = rng.uniform(0, 1), rng.uniform(0, 1), rng.uniform(0.02, 0.12)
        dx = np.minimum(np.abs(u - cx), 1 - np.abs(u - cx))       # wraps like the map
        dy = np.minimum(np.abs(v - cy), 1 - np.abs(v - cy))
        d = np.hypot(dx, dy) / r
        height += r * 4 * (np.where(d < 1, d * d - 1, 0) + 0.4 * np.exp(-((d - 1) / 0.25) ** 2))
    phi, theta = height_to_normals((height - height.min()) / np.ptp(height), 16.0)
    base = load_scene("bumps", size=size)
    px = replace(base.px, b_phi=phi[base.v, base.u], b_theta=theta[base.v, base.u])
    return replace(base, name="craters", px=px, height=height, b_phi_map=phi, b_theta_map=theta)


def _with(px, **changes):
    return PixelInputs(**{**{f.name: getattr(px, f.name) for f in fields(px)}, **changes})


def _clip_angles(name, x):
    hi = np.pi if name.endswith("theta") else 2 * np.pi
    return np.clip(x, 0.0, hi)


def _target(channel, ref):
    """255 x the float64 channel, and where its value is not clamped (its slope is 0 there)."""
    if channel == "diffuse":
        return 255 * ref.ndotl, (ref.ndotl > 0.02) & (ref.ndotl < 0.98)
    value = 255 * getattr(ref, channel)
    return value, (value > 0.5) & (value < 254.5)


def _world_bump_normal(px):
    """N' in world coordinates (common.world_bump_normal of the pixels' angles)."""
    return world_bump_normal(px.n_phi, px.n_theta, px.b_phi, px.b_theta)


def highlight_pixels(n, rng, cfg: Config):
    """``n`` random pixels whose H lies near N' (angle between them uniform in [0, 4 /
    sqrt(exponent)] rad, where cos^n still has a slope), the region random H seldom reaches."""
    px = PixelInputs.random(n, rng)
    nw = _world_bump_normal(px)
    turn = rng.uniform(0, 2 * np.pi, n)
    angle = rng.uniform(0, min(np.pi / 2, 4 / np.sqrt(cfg.spec_exponent)), n)
    h_phi, h_theta = _tilted(nw, np.cos(angle), np.sin(angle), turn)
    return _with(px, h_phi=h_phi, h_theta=h_theta)


def adversarial_pixels(cfg: Config, candidates=200_000, keep=1_000, seed=7, channel="diffuse"):
    """Inputs that push the quantized datapath hardest on one output ``channel``.

    1. Start where 255 x the channel (N'.L' for diffuse, cos^n N'.H' for specular, eq. 2's
       colour) is most sensitive to the input angles it depends on (:data:`ANGLES_OF`):
       among ``candidates`` random valid pixels (for specular and colour half of them with H
       near N', :func:`highlight_pixels`) where it is not clamped, keep the ``keep`` with the
       largest sum of |d(255 channel)/d angle| (central differences).
    2. Put each of those angles half a grid step off on the worse side: at the grid point
       plus 0.4999 step times the sign of its derivative, so rounding to the grid moves every
       angle against the output at once.
    3. Scan neighbouring grid points: the same construction around the grid point one step
       below and above in each angle in turn (1 + 2 x len(angles) variants per pixel).
    Returns PixelInputs of keep x (1 + 2 x len(angles)) pixels.
    """
    if channel not in CHANNELS:
        raise BumpError(f"channel must be one of {', '.join(CHANNELS)}, got {channel!r}")
    angles = ANGLES_OF[channel]
    rng = np.random.default_rng(seed)
    px = PixelInputs.random(candidates, rng)
    if channel != "diffuse":
        near = highlight_pixels(candidates // 2, rng, cfg)
        px = PixelInputs.concat([px.subset(slice(candidates // 2, None)), near])
    px = px.subset(_target(channel, conventional(px, cfg))[1])
    step = 2 * np.pi / cfg.full_circle
    h = 1e-6
    grads = {}
    for name in angles:
        x = getattr(px, name)
        up = _target(channel, conventional(_with(px, **{name: _clip_angles(name, x + h)}), cfg))[0]
        dn = _target(channel, conventional(_with(px, **{name: _clip_angles(name, x - h)}), cfg))[0]
        grads[name] = (up - dn) / (2 * h)
    sensitivity = sum(np.abs(g) for g in grads.values())
    top = np.argsort(sensitivity)[-keep:]
    px = px.subset(top)
    grads = {k: g[top] for k, g in grads.items()}
    variants = [(None, 0)] + [(name, d) for name in angles for d in (-1, 1)]
    out = []
    for moved, delta in variants:
        changes = {}
        for name in angles:
            grid = np.rint(getattr(px, name) / step) + (delta if name == moved else 0)
            # rounding back to `grid` moves the angle by -0.4999 step * sign(grad): worst side
            changes[name] = _clip_angles(name, (grid + 0.4999 * np.sign(grads[name])) * step)
        out.append(_with(px, **changes))
    return PixelInputs.concat(out)


def _tilted(nw, cos_a, sin_a, turn):
    """(phi, theta) of the unit vectors at the angle of cosine ``cos_a`` and sine ``sin_a``
    from ``nw`` (unit, world coordinates), turned by ``turn`` radians around it."""
    helper = np.where(np.abs(nw[..., 2:3]) < 0.9, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    e1 = np.cross(nw, helper)
    e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
    e2 = np.cross(nw, e1)
    c, s, turn = (np.asarray(x)[:, None] for x in (cos_a, sin_a, turn))
    return cartesian_to_polar(c * nw + s * (np.cos(turn) * e1 + np.sin(turn) * e2))


def _around(nw, cos_lo, cos_hi, rng):
    """Unit vectors at a random angle from ``nw`` whose cosine is uniform in [cos_lo,
    cos_hi], in a random direction around it: (phi, theta)."""
    c = rng.uniform(cos_lo, cos_hi, len(nw))
    return _tilted(nw, c, np.sqrt(1 - c * c), rng.uniform(0, 2 * np.pi, len(nw)))


# Where each channel's slope is largest: the cosine of the angle between N' and L (diffuse:
# 255 cos, steepest near cos = 0 where it is not yet clamped) and between N' and H (specular:
# 255 cos^n, steepest at sin = 1 / sqrt(n), i.e. cos in [1 - 4 / n, 1] for n >= 4).
STEEP_DIFFUSE = (0.02, 0.6)


def steep_pixels(n, rng, cfg: Config, channel):
    """``n`` random valid pixels with L (diffuse, colour) and H (specular, colour) placed
    where the channel's slope is largest (:data:`STEEP_DIFFUSE`; N'.H in [1 - 4 / n, 1])."""
    px = PixelInputs.random(n, rng)
    nw = _world_bump_normal(px)
    changes = {}
    if channel in ("specular", "color"):
        changes["h_phi"], changes["h_theta"] = _around(nw, max(0.0, 1 - 4 / cfg.spec_exponent), 1.0, rng)
    if channel in ("diffuse", "color"):
        changes["l_phi"], changes["l_theta"] = _around(nw, *STEEP_DIFFUSE, rng)
    return _with(px, **changes)


def unrounded_lsb(out, cfg: Config, channel):
    """A fixed-point model's channel before its 8-bit rounding, in 8-bit LSB: 255 clamp(N'.L)
    (diffuse), 255 cos^n (specular), eq. 2 of the two (colour)."""
    d = 255.0 * np.asarray(out["diffuse_fine"]) / cfg.one
    s = np.asarray(out["specular_fine"]) / 2.0 ** SPEC_FRAC_BITS
    return {"diffuse": d, "specular": s,
            "color": 255 * cfg.ka + cfg.kd * d + (cfg.ks if cfg.specular else 0.0) * s}[channel]


def worst_case_pixels(model, cfg: Config, channel="specular", candidates=100_000, keep=2_000,
                      seed=3):
    """The search aimed at the proof's worst case (predicted_error_bound_lsb): the inputs'
    rounding to the angle grid and the datapath's arithmetic error at their largest and in
    the same direction, where the channel's slope is largest.

    1. ``candidates`` pixels where the slope is largest (:func:`steep_pixels`).
    2. Every angle the channel depends on (:data:`ANGLES_OF`) put 0.4999 of a grid step off
       its grid point, on the side its partial derivative points, in both polarities (all
       angles with the derivative, all against it): the rounding then moves the output by
       about the sum of |slope| x half a step, up in one copy and down in the other.
    3. The model on those inputs (the same grid point in both copies, so the same
       arithmetic error) against float64 before the 8-bit rounding (:func:`unrounded_lsb`):
       the copy where the arithmetic error adds to the rounding's has the larger error; keep
       the ``keep`` largest.
    4. Each of those moved by one grid step in one or two of its angles (each sign), so the
       same near-worst error falls at many fractional positions of float64's value: where it
       sits just above a half, an error above 1 before the rounding of both sides is 2 after.
    ``model(codes, cfg)`` is a fixed-point golden model (rtl/methods.datapath_fixed).
    Returns PixelInputs of keep x (1 + 2 n (n + 1)) pixels, n = len(ANGLES_OF[channel])."""
    if channel not in CHANNELS:
        raise BumpError(f"channel must be one of {', '.join(CHANNELS)}, got {channel!r}")
    angles = ANGLES_OF[channel]
    rng = np.random.default_rng(seed)
    step = 2 * np.pi / cfg.full_circle
    px = steep_pixels(candidates, rng, cfg, channel)
    value = lambda p: 255 * getattr(conventional(p, cfg), channel)
    side = {}
    for name in angles:
        x = getattr(px, name)
        side[name] = np.sign(value(_with(px, **{name: _clip_angles(name, x + 1e-6)}))
                             - value(_with(px, **{name: _clip_angles(name, x - 1e-6)})))
    grid = {name: np.rint(getattr(px, name) / step) for name in angles}
    both = [_with(px, **{name: _clip_angles(name, (grid[name] + 0.4999 * pol * side[name]) * step)
                         for name in angles}) for pol in (1, -1)]
    both = PixelInputs.concat(both)
    error = np.abs(unrounded_lsb(model(encode_pixels(both, cfg), cfg), cfg, channel) - value(both))
    top = both.subset(np.argsort(error)[-keep:])
    out = [top]
    for i, j in itertools.combinations_with_replacement(range(len(angles)), 2):
        for di, dj in itertools.product((-1, 1), repeat=2):
            move = {angles[i]: di * step}
            move[angles[j]] = move.get(angles[j], 0.0) + dj * step
            out.append(_with(top, **{k: _clip_angles(k, getattr(top, k) + d) for k, d in move.items()}))
    return PixelInputs.concat(out)


def arithmetic_pixels(model, cfg: Config, candidates=400_000, keep=2_000, seed=5, reach=3):
    """Inputs where the datapath's own arithmetic error in N'.H' is largest near N'.H' = 1,
    where the specular slope 255 n is steepest, with the input rounding added on top: the
    search aimed at the specular term's arithmetic part.

    1. ``candidates`` random N, N' on the angle grid with H the grid point nearest N' in
       world coordinates and its four neighbours; the model's N'.H' against float64 of the
       same angles; keep the ``keep`` with the largest mean error over the five (the error
       of this N' that stays whatever H: its ROM errors adding up along N').
    2. For those, every H within ``reach`` grid steps in theta and phi ((2 reach + 1)**2
       variants), where N'.H' runs from 1 down the highlight's slope.
    3. Each of those again with its six angles of N'.H' put 0.4999 step off the grid on the
       side where rounding moves N'.H' the same way as the arithmetic error (the sign of
       the model's error times the sign of d N'.H' / d angle), so both add up.
    ``model(codes, cfg)`` is a fixed-point golden model (rtl/methods.datapath_fixed).
    Returns PixelInputs: the on-grid set of step 2, then the shifted set of step 3 (L = H)."""
    rng = np.random.default_rng(seed)
    full = cfg.full_circle
    step = 2 * np.pi / full
    codes = {"n_phi": rng.integers(0, full, candidates), "n_theta": rng.integers(0, full // 2 + 1, candidates),
             "b_phi": rng.integers(0, full, candidates), "b_theta": rng.integers(0, full // 4 + 1, candidates)}
    px = PixelInputs(**{k: v * step for k, v in codes.items()},
                     **{f"{v}_{a}": np.zeros(candidates) for v in "lh" for a in ("phi", "theta")})
    h_phi, h_theta = cartesian_to_polar(_world_bump_normal(px))
    codes["h_phi"], codes["h_theta"] = np.rint(h_phi / step) % full, np.rint(h_theta / step)

    def on_grid(c):
        ang = {k: np.clip(v * step, 0, np.pi if k.endswith("theta") else 2 * np.pi) for k, v in c.items()}
        return PixelInputs(**ang, l_phi=ang["h_phi"], l_theta=ang["h_theta"])

    def dot_error(p):
        return model(encode_pixels(p, cfg), cfg)["ndoth"] / cfg.one - conventional(p, cfg).ndoth

    # the error that stays when H moves (N''s ROM errors), not one H's luck: the mean over H
    # and its four grid neighbours
    moves = ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1))
    persistent = sum(dot_error(on_grid(dict(codes, h_theta=np.clip(codes["h_theta"] + dt, 0, full // 2),
                                            h_phi=(codes["h_phi"] + dp) % full))) for dt, dp in moves)
    worst = np.argsort(np.abs(persistent))[-keep:]
    codes = {k: v[worst] for k, v in codes.items()}
    grid = []
    for dt in range(-reach, reach + 1):
        for dp in range(-reach, reach + 1):
            grid.append(on_grid(dict(codes, h_theta=np.clip(codes["h_theta"] + dt, 0, full // 2),
                                     h_phi=(codes["h_phi"] + dp) % full)))
    grid = PixelInputs.concat(grid)
    sign = np.sign(dot_error(grid))
    shifted = {}
    for name in ANGLES_OF["specular"]:
        x = getattr(grid, name)
        up = conventional(_with(grid, **{name: _clip_angles(name, x + 1e-6)}), cfg).ndoth
        dn = conventional(_with(grid, **{name: _clip_angles(name, x - 1e-6)}), cfg).ndoth
        # the true angle on the side where N'.H' is off from the grid's by -sign: rounding
        # then moves it by +sign, the way the arithmetic already does
        shifted[name] = _clip_angles(name, x - 0.4999 * step * sign * np.sign(up - dn))
    shifted = _with(grid, **shifted, l_phi=shifted["h_phi"], l_theta=shifted["h_theta"])
    return PixelInputs.concat([grid, shifted])
