"""The globe unit's models (rtl/globe.py, docs/globe.md): the bit-exact integer model the RTL
equals bit for bit (:func:`globe_fixed`), the float64 reference (:func:`globe_float`) and the
derived bound between their angles (:func:`error_bound_rad`).

``python -m bumprtl.sim.golden.globe`` measures the model against float64 over every pixel of
the disc (and the rim's neighbours) at a few rotations and prints the bound beside it; with
``--mip-levels`` L > 1 the mip level too (``--square`` for a W = H map).
"""

import argparse
import math

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.rtl.globe import (
    GlobeConfig,
    cordic_angles,
    level_of,
    level_thresholds,
    level_y_table,
    level_y_used,
    phi_offset,
    theta_table,
    v_table,
)
from bumprtl.rtl.pipe import EDGE_LATENCY, min_fifo_depth
from bumprtl.sim.golden.common import cartesian_to_polar
from bumprtl.sim.golden.fixed.common import angle_codes

__all__ = ["isqrt", "cordic", "globe_fixed", "globe_float", "footprints", "error_bound_rad",
           "check_against_float", "disc_pixels", "main"]


def isqrt(n):
    """``floor(sqrt(n))`` of non-negative int64 ``n`` (< 2**62), exactly: the restoring
    digit-by-digit root, one bit at a time from the top."""
    n = np.asarray(n, np.int64)
    root = np.zeros_like(n)
    for bit in range(30, -1, -1):
        trial = root | np.int64(1 << bit)
        root = np.where(trial * trial <= n, trial, root)
    return root


def cordic(x, y, acc, gcfg: GlobeConfig):
    """CORDIC vectoring on int64 (x, y) with truncating shifts; ``acc`` (binary angles of
    ``angle_frac_bits``) plus the turn that brings (x, y) to the +x axis, modulo 2**P."""
    x, y, acc = (np.asarray(v, np.int64).copy() for v in (x, y, acc))
    for i, a in enumerate(cordic_angles(gcfg)):
        up = y >= 0
        xs, ys = x >> i, y >> i
        x, y = np.where(up, x + ys, x - ys), np.where(up, y - xs, y + xs)
        acc = np.where(up, acc + a, acc - a)
    return acc & ((1 << gcfg.angle_frac_bits) - 1)


def _inputs(x, y, rotation):
    x, y, rotation = np.broadcast_arrays(*(np.asarray(v, np.int64) for v in (x, y, rotation)))
    return x, y, rotation


def globe_fixed(x, y, rotation, gcfg: GlobeConfig, fine=False):
    """The unit's output fields (int64 arrays keyed like the flattened payload: ``inside``,
    ``n.phi``, ``n.theta``, ``u``, ``v``, and ``level`` when ``mip_levels > 1``) of pixels
    (x, y) (y up) at ``rotation`` (codes).
    ``fine``: also ``phi_fine`` and ``lambda_fine``, the angle sums before their rounding
    (full circle = 2**P; phi's without the half code step its codes round with; valid
    inside only)."""
    x, y, rotation = _inputs(x, y, rotation)
    R, F, P, A = gcfg.radius, gcfg.fraction_bits, gcfg.angle_frac_bits, gcfg.angle_bits
    full, half = 1 << P, 1 << (P - A - 1)
    rot = rotation & ((1 << A) - 1)
    r2 = x * x + y * y
    inside = r2 < R * R
    z = isqrt(np.where(inside, R * R - r2, 0) << (2 * F))
    xi = np.where(inside, x, 0)                                  # outside: any, masked
    lam = cordic(z, xi << F, rot << (P - A), gcfg)
    x_zero = xi == 0
    lam = np.where(x_zero, rot << (P - A), lam)                  # atan2(0, z) = 0 exactly
    phi = (lam + phi_offset(gcfg, rot)) % full                   # + 3/4 turn - rotation + half
    rows = np.asarray(y, np.int64) & ((2 << gcfg.int_bits) - 1)
    zero = np.zeros_like(x)
    out = {"inside": inside.astype(np.int64),
           "n.phi": np.where(inside, np.where(x_zero, 3 << (A - 2), phi >> (P - A)), zero),
           "n.theta": np.where(inside, np.asarray(theta_table(gcfg), np.int64)[rows], zero),
           "u": np.where(inside, lam >> (P - gcfg.u_bits), zero),
           "v": np.where(inside, np.asarray(v_table(gcfg), np.int64)[rows], zero)}
    if gcfg.mip_levels > 1:
        # the x part: how many thresholds the root is at or below; the y part from its table
        level = sum(((z <= t).astype(np.int64) for t in level_thresholds(gcfg)), zero)
        if level_y_used(gcfg):
            level = np.maximum(level, np.asarray(level_y_table(gcfg), np.int64)[rows])
        out["level"] = np.where(inside, level, zero)
    if fine:
        out.update(phi_fine=np.where(x_zero, 3 << (P - 2), (phi - half) % full),
                   lambda_fine=lam)
    return out


def globe_float(x, y, rotation, gcfg: GlobeConfig):
    """The float64 reference: ``inside``, the codes ``n.phi``, ``n.theta`` of the normal
    ``(x, -z, y) / R`` in the scenes' world frame made as the board makes N's
    (sim/golden/common.cartesian_to_polar, sim/golden/fixed/common.angle_codes), ``u``,
    ``v``, ``level`` when ``mip_levels > 1`` (``level_of(max(du/dx, dv/dy))`` from float64
    z and s, :func:`footprints`); and the angles ``phi`` (radians) and ``lambda_turns`` (the
    longitude in turns, [0, 1): the rotation added in turns, exactly)."""
    x, y, rotation = _inputs(x, y, rotation)
    R, W, H = float(gcfg.radius), gcfg.map_width, gcfg.map_height
    xf, yf = x.astype(np.float64), y.astype(np.float64)
    r2 = xf * xf + yf * yf
    inside = r2 < R * R
    z = np.sqrt(np.where(inside, R * R - r2, 0.0))
    phi, _ = cartesian_to_polar(np.stack([xf, -z, yf], -1))
    # theta = acos(N.z / |N|) = acos(y / R): taken from y alone, as it is exactly
    theta = np.arccos(np.clip(np.where(inside, yf, 0.0) / R, -1.0, 1.0))
    lam_turns = np.mod(np.arctan2(xf, z) / (2 * np.pi) + rotation / (1 << gcfg.angle_bits), 1.0)
    v = np.clip(np.floor(theta / np.pi * H), 0, H - 1).astype(np.int64)
    zero = np.zeros_like(x)
    out = {"inside": inside.astype(np.int64),
           "n.phi": np.where(inside, angle_codes(phi, gcfg.pipeline), zero),
           "n.theta": np.where(inside, angle_codes(theta, gcfg.pipeline), zero),
           "u": np.where(inside, np.floor(lam_turns * W).astype(np.int64) % W, zero),
           "v": np.where(inside, v, zero), "phi": phi, "lambda_turns": lam_turns}
    if gcfg.mip_levels > 1:
        d = footprints(x, y, gcfg)
        rho = np.maximum(d["du_dx"], d["dv_dy"])
        out["level"] = np.where(inside, level_of(rho, gcfg.mip_levels), zero)
    return out


def footprints(x, y, gcfg: GlobeConfig):
    """The exact screen-space derivatives of the texel (float64, texels a pixel) at pixels
    (x, y) inside (1 where outside): ``du_dx = W / (2 pi z)``, ``dv_dy = H / (pi s)`` with
    ``s = sqrt(R**2 - y**2)``, and the cross term the level leaves out, ``du_dy = W x y /
    (2 pi z s**2)`` (dv/dx is 0)."""
    x, y, _ = _inputs(x, y, 0)
    R, W, H = float(gcfg.radius), gcfg.map_width, gcfg.map_height
    xf, yf = x.astype(np.float64), y.astype(np.float64)
    inside = xf * xf + yf * yf < R * R
    z = np.sqrt(np.where(inside, R * R - xf * xf - yf * yf, 1.0))
    s = np.sqrt(np.where(inside, R * R - yf * yf, 1.0))
    return {"du_dx": np.where(inside, W / (2 * np.pi * z), 1.0),
            "dv_dy": np.where(inside, H / (np.pi * s), 1.0),
            "du_dy": np.where(inside, W * xf * yf / (2 * np.pi * z * s * s), 0.0)}


def error_bound_rad(gcfg: GlobeConfig):
    """The largest ``|fine angle - float64 angle|`` (radians) of phi and of the longitude at
    any pixel inside (one CORDIC chain gives both; proof in docs/globe.md, Error):

    ``atan(2**-(n-1)) + n pi / 2**P + (n - 1) asin(1 / (M - n)) + asin(sqrt 2 / M_true)``

    with n the iterations, P the angle bits of the sum: the residual angle of n vectoring
    steps, the n rounded constants (half a step each), and the truncation of the shifts
    (under one unit in each of X, Y at steps 1 .. n-1, none at step 0, on a vector never
    shorter than sqrt(2) (M - n) units after step 0); M_true = sqrt(2R - 1) 2**F is the
    shortest input vector in units of 2**-F pixel (x**2 + z**2 = R**2 - y**2 >= 2R - 1
    inside), M = M_true - sqrt 2 the shortest after the root's truncation (under one unit),
    whose own error is the last term."""
    n, P, F, R = gcfg.cordic_iterations, gcfg.angle_frac_bits, gcfg.fraction_bits, gcfg.radius
    true = math.sqrt(2 * R - 1) * 2.0 ** F
    m = true - math.sqrt(2)
    if m - n <= 1:
        return math.pi
    return (math.atan(2.0 ** -(n - 1)) + n * math.pi / 2 ** P
            + (n - 1) * math.asin(1 / (m - n)) + math.asin(min(1.0, math.sqrt(2) / true)))


def _turn_diff(a, b):
    """Signed difference of angles in turns, in [-1/2, 1/2)."""
    return np.mod(a - b + 0.5, 1.0) - 0.5


def check_against_float(x, y, rotation, gcfg: GlobeConfig):
    """The model against float64 on pixels (x, y, rotation): a dict of measured figures,
    and ``violations``, a list of what breaks the contract: inside, n.theta or v different
    (each comes from y alone, through a ROM of float64 words), a fine angle beyond
    :func:`error_bound_rad`, a code or texel off where the float64 value is further than the
    bound from a rounding boundary (or by more than one plus the bound's whole steps
    anywhere); with ``mip_levels > 1``, a level other than float64's but where the root is
    at a threshold (:func:`_check_level`)."""
    fx, fl = globe_fixed(x, y, rotation, gcfg, fine=True), globe_float(x, y, rotation, gcfg)
    P, A, W = gcfg.angle_frac_bits, gcfg.angle_bits, gcfg.map_width
    inside = fl["inside"].astype(bool)
    bad = [f"{k} differs" for k in ("inside", "n.theta", "v") if not np.array_equal(fx[k], fl[k])]
    out = {"pixels": int(inside.sum())}
    bound = error_bound_rad(gcfg)
    for name, fine, ref, code, steps in (
            ("phi", "phi_fine", fl["phi"] / (2 * np.pi), "n.phi", 1 << A),
            ("lambda", "lambda_fine", fl["lambda_turns"], "u", W)):
        err = np.abs(_turn_diff(fx[fine][inside] / (1 << P), ref[inside])) * 2 * np.pi
        worst = float(err.max()) if err.size else 0.0
        if worst > bound:
            bad.append(f"{name}: fine error {worst:.3g} rad beyond the bound {bound:.3g}")
        diff = np.mod(fx[code][inside] - fl[code][inside] + steps // 2, steps) - steps // 2
        # distance of the float64 value to the nearest rounding (codes) or floor (u) boundary
        scaled = ref[inside] * steps
        frac = scaled - np.floor(scaled)
        edge = np.abs(frac - 0.5) if name != "lambda" else np.minimum(frac, 1 - frac)
        near = edge * 2 * np.pi / steps <= bound
        # |round(t + e) - round(t)| <= floor(|e|) + 1 steps, and 0 unless t is within |e|
        # of a boundary
        most = math.floor(bound * steps / (2 * np.pi)) + 1
        if np.any(np.abs(diff) > most) or np.any((diff != 0) & ~near):
            bad.append(f"{code}: off where the float64 value is clear of a boundary "
                       f"or by more than {most}")
        out[name] = {"max_error_rad": worst, "bound_rad": bound,
                     "max_error_steps": worst * steps / (2 * np.pi),
                     "bound_steps": bound * steps / (2 * np.pi),
                     "codes_differing": int(np.count_nonzero(diff)),
                     "codes_max_diff": int(np.abs(diff).max()) if diff.size else 0}
    if gcfg.mip_levels > 1:
        out["level"] = _check_level(x, y, fx["level"], fl["level"], gcfg, bad)
    out["violations"] = bad
    return out


def _check_level(x, y, fixed, ref, gcfg: GlobeConfig, bad):
    """The level's rule: the model's equals float64's except one coarser, k, where the root
    ``floor(z 2**F)`` (exact) is ``floor(W 2**F / (2 pi 2**(k - 1/2)))`` (the real z within one
    unit above the real threshold; made here from the formula, not taken from the unit's
    :func:`level_thresholds`, so that a wrong constant shows); the y part comes from a table
    of the same float64 values, so no other difference is allowed. Appends to ``bad``;
    returns the figures."""
    x, y, _ = _inputs(x, y, 0)
    R, F, L, W = gcfg.radius, gcfg.fraction_bits, gcfg.mip_levels, gcfg.map_width
    d = R * R - x * x - y * y
    inside = d > 0
    root = isqrt(np.where(inside, d, 0) << (2 * F))
    t = np.floor(W * 2.0 ** F / (2 * np.pi * 2.0 ** (np.arange(L) - 0.5))).astype(np.int64)
    t[0] = -1                                                    # no threshold for level 0
    diff = fixed - ref
    at_threshold = inside & np.isin(root, t[1:])
    allowed = (diff == 0) | ((diff == 1) & (root == t[np.clip(fixed, 0, L - 1)]))
    if np.any(~allowed):
        n = int(np.count_nonzero(~allowed))
        bad.append(f"level: {n} pixels differ from float64 other than one coarser at a "
                   f"threshold")
    fp = footprints(x, y, gcfg)
    # the level with the cross term: the longer of the footprint's x and y derivatives
    across = np.maximum(fp["du_dx"], np.hypot(fp["du_dy"], fp["dv_dy"]))
    cross = np.where(inside, level_of(across, L), 0) - ref
    return {"pixels_at_threshold": int(at_threshold.sum()),
            "differing": int(np.count_nonzero(diff)),
            "per_level": np.bincount(fixed[inside], minlength=L).tolist(),
            "cross_coarser": int(np.count_nonzero(cross)),
            "cross_max": int(cross.max()) if cross.size else 0}


def disc_pixels(radius, margin=2):
    """Every (x, y) with |x|, |y| <= radius + margin: the disc, its rim and a ring outside."""
    c = np.arange(-radius - margin, radius + margin + 1)
    x, y = np.meshgrid(c, c)
    return x.ravel(), y.ravel()


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m bumprtl.sim.golden.globe",
                                 description="the globe model against float64 (docs/globe.md)")
    ap.add_argument("--radius", type=int, default=GlobeConfig().radius)
    ap.add_argument("--angle-bits", type=int, default=Config().angle_bits)
    ap.add_argument("--frac-bits", type=int, default=None,
                    help="F (default: DATAPATH_BITS - 2 - I, rtl/globe.py)")
    ap.add_argument("--guard-bits", type=int, default=GlobeConfig().guard_bits)
    ap.add_argument("--map-width", type=int, default=GlobeConfig().map_width)
    ap.add_argument("--square", action="store_true",
                    help="a square map (map_height = map_width; default: map_width / 2)")
    ap.add_argument("--mip-levels", type=int, default=1,
                    help="L: with L > 1, the level against float64 too")
    ap.add_argument("--rotations", type=int, nargs="*", default=[0, 1, 4095, 16383])
    args = ap.parse_args(argv)
    gcfg = GlobeConfig(radius=args.radius, map_width=args.map_width,
                       map_height=args.map_width if args.square else args.map_width // 2,
                       pipeline=Config(angle_bits=args.angle_bits),
                       frac_bits=args.frac_bits, guard_bits=args.guard_bits,
                       mip_levels=args.mip_levels)
    x, y = disc_pixels(gcfg.radius)
    rots = [r % (1 << gcfg.angle_bits) for r in args.rotations]
    print(f"R = {gcfg.radius}, angle_bits = {gcfg.angle_bits}, W x H = {gcfg.map_width} x "
          f"{gcfg.map_height}, F = {gcfg.fraction_bits}, P = {gcfg.angle_frac_bits}, "
          f"iterations = {gcfg.cordic_iterations}, rotations {rots}")
    print(f"widths: I = {gcfg.int_bits}, root {gcfg.root_bits} bits ({gcfg.root_bits} "
          f"stages), CORDIC X/Y {gcfg.datapath_bits} bits signed, angle sum "
          f"{gcfg.angle_frac_bits} bits, v and theta ROMs "
          f"{2 << gcfg.int_bits} x {gcfg.v_bits + gcfg.level_bits * level_y_used(gcfg)} and "
          f"x {gcfg.angle_bits}; latency "
          f"{gcfg.latency} (+{EDGE_LATENCY} with the unit's credit edge, FIFO depth "
          f"{min_fifo_depth(gcfg.latency)})")
    if gcfg.mip_levels > 1:
        print(f"level: L = {gcfg.mip_levels} ({gcfg.level_bits} bits), thresholds t_k "
              f"{level_thresholds(gcfg)} (z = t_k / 2**F: "
              f"{', '.join(f'{t / (1 << gcfg.fraction_bits):.2f}' for t in level_thresholds(gcfg))}"
              f" pixels), y part "
              + (f"in the v ROM's word ({gcfg.v_bits} + {gcfg.level_bits} bits)"
                 if level_y_used(gcfg) else "not built"))
    b = error_bound_rad(gcfg)
    print(f"bound phi, lambda: {b:.3e} rad = {b * (1 << gcfg.angle_bits) / (2 * math.pi):.4f} "
          f"codes = {b * gcfg.map_width / (2 * math.pi):.4f} texels")
    ok = True
    for rot in rots:
        res = check_against_float(x, y, rot, gcfg)
        print(f"rotation {rot}: {res['pixels']} pixels inside; inside, n.theta and v equal "
              f"float64's everywhere" if not any("differs" in v for v in res["violations"])
              else f"rotation {rot}: {res['pixels']} pixels inside")
        for name in ("phi", "lambda"):
            s = res[name]
            unit = "texels" if name == "lambda" else "codes"
            print(f"  {name:6s} max |error| {s['max_error_rad']:.3e} rad = "
                  f"{s['max_error_steps']:.4f} {unit} (bound {s['bound_rad']:.3e} rad = "
                  f"{s['bound_steps']:.4f}); {s['codes_differing']} pixels off by "
                  f"{s['codes_max_diff']} from float64")
        if "level" in res:
            lv = res["level"]
            print(f"  level  {lv['differing']} pixels differ from float64 (one coarser, at a "
                  f"threshold; {lv['pixels_at_threshold']} pixels have a root on a threshold); "
                  f"pixels per level {lv['per_level']}; with du/dy in the footprint "
                  f"{lv['cross_coarser']} pixels would be coarser, by up to {lv['cross_max']}")
        for v in res["violations"]:
            print("  VIOLATION:", v)
        ok &= not res["violations"]
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
