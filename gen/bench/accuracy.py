"""``bumprtl bench accuracy``: the fixed-point golden model against float64, per output
channel (diffuse, specular, colour), on random inputs and on the adversarial searches aimed
at each channel, beside the proven bound of each channel (the sidecar's ``error_bounds_lsb``).

A measured error above its bound is a failure: the offending input is printed and the
command exits 1.
"""

from dataclasses import fields

import numpy as np

from bumprtl.rtl.config import BumpError, Config, ConfigError
from bumprtl.rtl.methods import METHODS, datapath_fixed, encode_pixels
from bumprtl.sim.golden.accuracy import (CHANNELS, adversarial_pixels, arithmetic_pixels,
                                         scene_error, term_errors_lsb)
from bumprtl.sim.golden.common import PixelInputs, to_8bit
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.scenes import SCENES, load_scene
from bumprtl.gen.flow.units import build_unit

__all__ = ["measure", "run", "add_parser"]


def _stats(err):
    return {"max": int(err.max()), "mean": float(err.mean()), "worst": int(np.argmax(err))}


def measure(cfg: Config, px: PixelInputs):
    """Per channel: the errors (8-bit LSB) on the random pixels ``px``, on the adversarial
    search aimed at that channel, and on the arithmetic search (specular and colour); the
    bound; and the pixel sets, so that a failure can be shown."""
    sets = {"random": px}
    out = {}
    arith = arithmetic_pixels(datapath_fixed, cfg)
    for channel in CHANNELS:
        sets[f"adversarial {channel}"] = adversarial_pixels(cfg, channel=channel)
    bounds = build_unit("illumination", cfg)[1]["error_bounds_lsb"]
    errors = {name: term_errors_lsb(datapath_fixed, p, cfg) for name, p in sets.items()}
    errors["arithmetic"] = term_errors_lsb(datapath_fixed, arith, cfg)
    sets["arithmetic"] = arith
    for channel in CHANNELS:
        out[channel] = {"random": _stats(errors["random"][channel]),
                        "adversarial": _stats(errors[f"adversarial {channel}"][channel]),
                        "arithmetic": _stats(errors["arithmetic"][channel]),
                        "bound": bounds[channel],
                        "sets": {"random": "random", "adversarial": f"adversarial {channel}",
                                 "arithmetic": "arithmetic"}}
    return out, sets


def _failure(cfg, channel, kind, row, sets):
    """One line per failure: the set, the measured and bound, and the offending pixel."""
    px = sets[row["sets"][kind]]
    i = row[kind]["worst"]
    one = px.subset(slice(i, i + 1))
    angles = ", ".join(f"{f.name}={float(getattr(one, f.name)[0])!r}" for f in fields(one))
    got = datapath_fixed(encode_pixels(one, cfg), cfg)[channel][0]
    want = to_8bit(getattr(conventional(one, cfg), channel))[0]
    return (f"FAIL {cfg.method} angle_bits={cfg.angle_bits} frac_bits={cfg.frac_bits} "
            f"spec_exponent={cfg.spec_exponent} {channel} ({kind}): error {row[kind]['max']} LSB > "
            f"bound {row['bound']} at pixel ({angles}) [radians]: fixed {int(got)}, float64 {int(want)}")


def run(args):
    for n in args.spec_exponent:                 # a bad exponent is an error, not a skipped row
        Config(spec_exponent=n, spec_index_bits=args.spec_index_bits)
    size = args.scene_size
    if size and not (16 <= size <= 4096 and size & (size - 1) == 0):
        raise BumpError(f"scene_size must be 0 or a power of two in [16, 4096], got {size}")
    print(f"bumprtl bench accuracy --method {args.method} --samples {args.samples} "
          f"--angle-bits {' '.join(map(str, args.angle_bits))} --frac-bits {' '.join(map(str, args.frac_bits))} "
          f"--spec-exponent {' '.join(map(str, args.spec_exponent))} --spec-index-bits {args.spec_index_bits} "
          f"--scene-size {args.scene_size}")
    print(f"\nerror in 8-bit LSB against float64 on unquantized inputs, per output channel: "
          f"{args.samples} random valid pixels (seed 11); the adversarial search aimed at the "
          f"channel (seed 7); the arithmetic search (on-grid N', H near N', seed 5). "
          f"bound = the sidecar's error_bounds_lsb (proof: predicted_error_bound_lsb)\n")
    print("| angle bits | frac bits | n | channel | random max / mean | adversarial max / mean "
          "| arithmetic max | bound | worst / bound |")
    print("|---|---|---|---|---|---|---|---|---|")
    px = PixelInputs.random(args.samples, np.random.default_rng(11))
    failures = []
    for a in args.angle_bits:
        for b in args.frac_bits:
            for n in args.spec_exponent:
                try:
                    cfg = Config(method=args.method, angle_bits=a, frac_bits=b, spec_exponent=n,
                                 spec_index_bits=args.spec_index_bits)
                except ConfigError:
                    continue
                result, sets = measure(cfg, px)
                for channel, row in result.items():
                    top = max(row[k]["max"] for k in ("random", "adversarial", "arithmetic"))
                    ratio = f"{top / row['bound']:.2f}" if row["bound"] else "—"
                    print(f"| {a} | {b} | {n} | {channel} | {row['random']['max']} / "
                          f"{row['random']['mean']:.4f} | {row['adversarial']['max']} / "
                          f"{row['adversarial']['mean']:.4f} | {row['arithmetic']['max']} | "
                          f"{row['bound']} | {ratio} |", flush=True)
                    failures += [_failure(cfg, channel, k, row, sets)
                                 for k in ("random", "adversarial", "arithmetic")
                                 if row[k]["max"] > row["bound"]]
    if args.scene_size:
        _scenes(args)
    for line in failures:
        print(line)
    return 1 if failures else 0


def _scenes(args):
    """Every built-in scene shaded at the default widths of ``args.method``: eq. 2's colour
    image and, where the scene has a colour texture, the texture blend on its 8-bit albedo
    (sim/golden/accuracy.scene_error), over the pixels the geometry covers."""
    cfg = Config(method=args.method, spec_index_bits=args.spec_index_bits)
    print(f"\nscenes at {args.scene_size}x{args.scene_size} (angle bits {cfg.angle_bits}, frac bits "
          f"{cfg.frac_bits}, n = {cfg.spec_exponent}): PSNR (dB) / max LSB against float64 "
          f"`conventional` on the unquantized inputs\n")
    print("| scene | colour (eq. 2) | texture blend |")
    print("|---|---|---|")
    for name in SCENES:
        scene = load_scene(name, size=args.scene_size)
        rows = [scene_error(scene, cfg, datapath_fixed)]
        if scene.albedo is not None:
            rows.append(scene_error(scene, cfg, datapath_fixed, blend=True))
        cells = [f"{r['psnr_db']} / {r['max_lsb']}" for r in rows] + ["—"] * (2 - len(rows))
        print(f"| {name} | {' | '.join(cells)} |", flush=True)


def add_parser(sub):
    p = sub.add_parser("accuracy", help="fixed-point error against float64 per channel, over widths",
                       description="Max and mean error (8-bit LSB) of the diffuse, specular and "
                                   "colour outputs of the bit-exact golden model against float64 "
                                   "on random inputs and on adversarial searches aimed at each, "
                                   "beside the proven bound of each. Exits 1, printing the "
                                   "offending input, if an error exceeds its bound.")
    p.add_argument("--method", default="exact", choices=tuple(METHODS))
    p.add_argument("--samples", type=int, default=1_000_000)
    p.add_argument("--angle-bits", type=int, nargs="+", default=[10, 11, 12, 13])
    p.add_argument("--frac-bits", type=int, nargs="+", default=[10, 13, 16])
    p.add_argument("--spec-exponent", type=int, nargs="+", default=[16],
                   help="Phong exponents n (default: 16)")
    p.add_argument("--spec-index-bits", type=int, default=10, help="specular table address bits (default: 10)")
    p.add_argument("--scene-size", type=int, default=128,
                   help="also shade every built-in scene at this size, default widths (0: no scenes)")
    p.set_defaults(func=run)
