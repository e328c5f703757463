"""``bumprtl bench accuracy``: the fixed-point golden model against float64, per output
channel (diffuse, specular, colour), on random inputs and on the adversarial searches aimed
at each channel, beside the proven bound of each channel (the sidecar's ``error_bounds.lsb_per_channel``).

Two measures per channel, on the same pixels:

* **end-to-end**: float64 on the unquantized inputs (what the bound is about): the input
  rounding to the angle grid plus the datapath's arithmetic;
* **arithmetic**: float64 on the angles the hardware receives (the inputs rounded to the
  grid, sim/golden/accuracy.on_grid): the datapath's own error, without the input rounding.
  Not for the Cartesian-input methods (Peercy, Ernst): printed as "—".

A measured error (either measure) above its bound is a failure: the offending input is
printed and the command exits 1.
"""

from dataclasses import dataclass, fields, replace

import numpy as np

from bumprtl.gen.flow.units import build_unit, error_bounds
from bumprtl.rtl.config import TWO_LIGHT_WIDTHS, BumpError, Config, ConfigError
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.tables import SPEC_FRAC_BITS, specular_table_error_lsb
from bumprtl.rtl.texture import RGB, texture_blend
from bumprtl.sim.golden.accuracy import (
    CHANNELS,
    adversarial_pixels,
    arithmetic_pixels,
    crater_scene,
    grid_errors_lsb,
    on_grid,
    reference_blend,
    scene_error,
    term_errors_lsb,
    worst_case_pixels,
)
from bumprtl.sim.golden.common import PixelInputs, to_8bit
from bumprtl.sim.golden.fixed.common import input_angle_error, phong_sum_fixed, term_bounds_lsb
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.methods import datapath_fixed, encode_pixels, get
from bumprtl.sim.scenes import SCENES, load_scene

__all__ = ["AccuracyOptions", "measure", "light_sums", "accuracy_bench"]


@dataclass(frozen=True)
class AccuracyOptions:
    """What ``bumprtl bench accuracy`` measures (its flags of the same names): ``method`` at
    every (``angle_bits``, ``frac_bits``, ``spec_exponent``) of the grid, or with
    ``faithful_widths`` each exponent at the widths its bound proves within 1 LSB, over
    ``samples`` random pixels; the light-sum, blend and scene tables at ``scene_widths``
    (angle bits, frac bits; None: Config's) and the scenes at ``scene_size`` (0: none)."""
    method: str = "exact"
    samples: int = 1_000_000
    angle_bits: tuple = (12, 13, 14, 15)
    frac_bits: tuple = (13, 15, 16)
    spec_exponent: tuple = (16,)
    spec_index_bits: int = 10
    faithful_widths: bool = False
    scene_size: int = 128
    scene_widths: tuple | None = None


def _stats(err):
    return {"max": int(err.max()), "mean": float(err.mean()), "worst": int(np.argmax(err))}


KINDS = ("random", "adversarial", "search", "worst")   # the pixel sets of a channel's row


def measure(cfg: Config, px: PixelInputs):
    """Per channel, on the random pixels ``px``, on the adversarial search aimed at that
    channel, on the search aimed at the dot product's arithmetic error (``search``) and on
    the search aimed at the proof's worst case for that channel (``worst``,
    sim/golden/accuracy.worst_case_pixels): the end-to-end errors (8-bit LSB) and the
    arithmetic errors (``grid``: {kind: stats}, None for a Cartesian-input method); the
    bound; and the pixel sets, so that a failure can be shown."""
    sets = {"random": px, "search": arithmetic_pixels(datapath_fixed, cfg)}
    for channel in CHANNELS:
        sets[f"adversarial {channel}"] = adversarial_pixels(cfg, channel=channel)
        sets[f"worst {channel}"] = worst_case_pixels(datapath_fixed, cfg, channel)
    bounds = build_unit("illumination", cfg)[1].error_bounds.lsb_per_channel
    errors = {name: term_errors_lsb(datapath_fixed, p, cfg) for name, p in sets.items()}
    grid = {name: grid_errors_lsb(datapath_fixed, p, cfg) for name, p in sets.items()}
    out = {}
    for channel in CHANNELS:
        names = {"random": "random", "adversarial": f"adversarial {channel}", "search": "search",
                 "worst": f"worst {channel}"}
        out[channel] = {**{k: _stats(errors[names[k]][channel]) for k in KINDS},
                        "grid": None if grid["random"] is None else
                        {k: _stats(grid[names[k]][channel]) for k in KINDS},
                        "bound": bounds[channel], "sets": names}
    return out, sets


def _failure(cfg, channel, kind, row, sets, grid=False):
    """One line per failure: the set, the measure, the measured and bound, and the
    offending pixel (and, for the arithmetic measure, the angles float64 was given)."""
    px = sets[row["sets"][kind]]
    stats = row["grid"][kind] if grid else row[kind]
    i = stats["worst"]
    one = px.subset(slice(i, i + 1))
    ref = on_grid(one, cfg) if grid else one
    angles = lambda p: ", ".join(f"{f.name}={float(getattr(p, f.name)[0])!r}" for f in fields(p))
    got = datapath_fixed(encode_pixels(one, cfg), cfg)[channel][0]
    want = to_8bit(getattr(conventional(ref, cfg), channel))[0]
    where = f"; float64 on the received angles ({angles(ref)})" if grid else ""
    return (f"FAIL {cfg.method} angle_bits={cfg.angle_bits} frac_bits={cfg.frac_bits} "
            f"spec_exponent={cfg.spec_exponent} {channel} ({kind}, "
            f"{'arithmetic' if grid else 'end-to-end'}): error {stats['max']} LSB > "
            f"bound {row['bound']} at pixel ({angles(one)}) [radians]{where}: "
            f"fixed {int(got)}, float64 {int(want)}")


def _grid_cell(row):
    g = row["grid"]
    return "—" if g is None else " / ".join(str(g[k]["max"]) for k in KINDS)


def _width_points(opts):
    """The Configs to measure: every valid (angle bits, frac bits, n) of the grid, or with
    ``--faithful-widths`` each n at the widths the method's bound proves within 1 LSB (the
    sidecar's ``faithful_widths``; a line saying so for an n that has none)."""
    base = Config(method=opts.method, spec_index_bits=opts.spec_index_bits)
    if opts.faithful_widths:
        rule = get(opts.method).faithful_widths
        if rule is None:
            raise BumpError(f"--faithful-widths: method {opts.method} has no faithful widths "
                            f"(only exact searches them)")
        points = []
        for n in opts.spec_exponent:
            widths = rule(base.replace(spec_exponent=n))
            points.append(f"n = {n}: no widths in the Config's range prove every channel within "
                          f"1 LSB" if widths is None else
                          base.replace(angle_bits=widths[0], frac_bits=widths[1], spec_exponent=n))
        return points
    points = []
    for a in opts.angle_bits:
        for b in opts.frac_bits:
            for n in opts.spec_exponent:
                try:
                    points.append(base.replace(angle_bits=a, frac_bits=b, spec_exponent=n))
                except ConfigError:
                    continue
    return points


def accuracy_bench(opts: AccuracyOptions):
    """``bumprtl bench accuracy``: prints the tables; returns 1 when an error exceeds its
    bound (the offending inputs printed), else 0."""
    for n in opts.spec_exponent:                 # a bad exponent is an error, not a skipped row
        Config(spec_exponent=n, spec_index_bits=opts.spec_index_bits)
    _scene_config(opts)                          # bad --scene-widths: one line, exit 2
    size = opts.scene_size
    if size and not (16 <= size <= 4096 and size & (size - 1) == 0):
        raise BumpError(f"scene_size must be 0 or a power of two in [16, 4096], got {size}")
    points = _width_points(opts)
    widths = ("--faithful-widths" if opts.faithful_widths else
              f"--angle-bits {' '.join(map(str, opts.angle_bits))} --frac-bits {' '.join(map(str, opts.frac_bits))}")
    print(f"bumprtl bench accuracy --method {opts.method} --samples {opts.samples} {widths} "
          f"--spec-exponent {' '.join(map(str, opts.spec_exponent))} --spec-index-bits {opts.spec_index_bits} "
          f"--scene-size {opts.scene_size}"
          + (f" --scene-widths {' '.join(map(str, opts.scene_widths))}" if opts.scene_widths else ""))
    print(f"\nerror in 8-bit LSB per output channel, on {opts.samples} random valid pixels (seed "
          f"11), the adversarial search aimed at the channel (seed 7) and the search aimed at "
          f"the dot product's arithmetic error (on-grid N', H near N', seed 5), and the worst-"
          f"case search aimed at the proof's bound (every angle just under half a grid step off on "
          f"its derivative's side where the channel is steepest, the arithmetic adding; seed 3). "
          f"end-to-end = "
          f"against float64 on the unquantized inputs (input rounding + arithmetic); "
          f"arithmetic = against float64 on the angles the hardware receives (the inputs "
          f"rounded to the angle grid; — for Cartesian inputs). bound = the sidecar's "
          f"error_bounds.lsb_per_channel (end-to-end; proof: predicted_error_bound_lsb)\n")
    print("| angle bits | frac bits | n | channel | end-to-end random max / mean "
          "| end-to-end adversarial max / mean | end-to-end search max | end-to-end worst-case max "
          "| arithmetic max (random / adversarial / search / worst-case) | bound | worst / bound |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    px = PixelInputs.random(opts.samples, np.random.default_rng(11))
    failures, summary = [], []
    for cfg in points:
        if isinstance(cfg, str):                 # an exponent without faithful widths
            summary.append(cfg)
            continue
        a, b, n = cfg.angle_bits, cfg.frac_bits, cfg.spec_exponent
        result, sets = measure(cfg, px)
        for channel, row in result.items():
            top = max(row[k]["max"] for k in KINDS)
            if row["grid"] is not None:
                top = max(top, *(row["grid"][k]["max"] for k in KINDS))
            ratio = f"{top / row['bound']:.2f}" if row["bound"] else "—"
            print(f"| {a} | {b} | {n} | {channel} | {row['random']['max']} / "
                  f"{row['random']['mean']:.4f} | {row['adversarial']['max']} / "
                  f"{row['adversarial']['mean']:.4f} | {row['search']['max']} | "
                  f"{row['worst']['max']} | {_grid_cell(row)} | {row['bound']} | {ratio} |", flush=True)
            failures += [_failure(cfg, channel, k, row, sets) for k in KINDS
                         if row[k]["max"] > row["bound"]]
            if row["grid"] is not None:
                failures += [_failure(cfg, channel, k, row, sets, grid=True) for k in KINDS
                             if row["grid"][k]["max"] > row["bound"]]
        summary.append(_summary(cfg, result))
    print("\n" + "\n".join(summary))
    failures += _lights(opts, px)
    if opts.scene_size:
        _scenes(opts)
    for line in failures:
        print(line)
    return 1 if failures else 0


def _summary(cfg, result):
    """One line per Config: the worst end-to-end and arithmetic error of each channel, and
    what the difference is."""
    def worst(row, grid=False):
        return max((row["grid"] if grid else row)[k]["max"] for k in KINDS)
    head = f"angle bits {cfg.angle_bits}, frac bits {cfg.frac_bits}, n = {cfg.spec_exponent}:"
    e2e = ", ".join(f"{c} {worst(r)}" for c, r in result.items())
    if any(r["grid"] is None for r in result.values()):
        return f"{head} end-to-end max {e2e} LSB (Cartesian inputs: no arithmetic-only measure)"
    arith = ", ".join(f"{c} {worst(r, True)}" for c, r in result.items())
    below = [f"{c} measured {worst(r)}, proven {r['bound']}" for c, r in result.items()
             if worst(r) < r["bound"]]
    grid = term_bounds_lsb(cfg, input_angle_error(cfg), 0.0)     # exact dot of rounded angles
    grid["specular"] -= specular_table_error_lsb(cfg) if cfg.specular else 0.0
    return (f"{head} arithmetic max {arith} LSB; end-to-end max {e2e} LSB "
            f"(end to end adds the inputs' rounding to the {cfg.angle_bits}-bit angle grid, "
            f"which alone the proof bounds by diffuse {grid['diffuse']:.3f}, specular "
            f"{grid['specular']:.3f} LSB before any arithmetic)"
            + (f"; below the proven bound: {', '.join(below)}" if below else ""))


def _outputs(pxs, cfg, texels, grid=False):
    """The pipeline's outputs over the lights ``pxs`` (one PixelInputs a light, the same N
    and N'): the summed diffuse and specular ports, eq. 2's colour and the texture blend on
    ``texels`` -- the fixed-point model's (the lights' unrounded terms summed and rounded
    once: LightSum, TextureBlend, sim/golden/fixed/pipeline.combine_lights_fixed) against
    float64's, on the unquantized inputs or (``grid``) on the angles the hardware receives:
    {output: |error| per pixel}."""
    outs = [datapath_fixed(encode_pixels(p, cfg), cfg) for p in pxs]
    refs = [conventional(on_grid(p, cfg) if grid else p, cfg) for p in pxs]
    d, s = sum(o["diffuse_fine"] for o in outs), sum(o["specular_fine"] for o in outs)
    ks = cfg.ks if cfg.specular else 0.0
    want = to_8bit(np.clip(cfg.ka + sum(cfg.kd * np.clip(r.ndotl, 0, 1) + ks * r.specular
                                        for r in refs), 0, 1))
    blend = texture_blend([o["diffuse_fine"] for o in outs], [o["specular_fine"] for o in outs],
                          texels, cfg)[0]
    want_blend = reference_blend(refs, texels, cfg)
    err = lambda a, b: np.abs(np.asarray(a, np.int64) - np.asarray(b, np.int64))
    ports = {"diffuse": np.minimum(round_shift(255 * d, cfg.frac_bits), 255),
             "specular": np.minimum(round_shift(s, SPEC_FRAC_BITS), 255)}
    return {"diffuse": err(ports["diffuse"], to_8bit(np.clip(sum(np.clip(r.ndotl, 0, 1)
                                                                 for r in refs), 0, 1))),
            "specular": err(ports["specular"], to_8bit(np.clip(sum(r.specular for r in refs), 0, 1))),
            "color": err(phong_sum_fixed(d, s, cfg), want),
            "blend": np.max([err(blend[c], want_blend[c]) for c in RGB], axis=0)}


LIGHT_OUTPUTS = ("diffuse", "specular", "color", "blend")
LIGHT_KINDS = ("random", "adversarial", "worst")


def light_sums(cfg: Config, px: PixelInputs, lights=(1, 2)):
    """The outputs summed over m lights (m in ``lights``) and the texture blend (random
    texels, seed 3): {(m, output): {random, adversarial, worst, grid: {kind} | None, bound,
    sets}}. Random: ``px`` and, for further lights, L and H of other random pixels (seed 12)
    on the same N and N'. Adversarial: the search aimed at the colour; worst: the searches
    aimed at the proof's worst case of the specular term and of the colour; in both every
    light is the same (the lights' errors then add up). The bounds are the pipeline
    sidecar's (error_bounds with ``lights`` and ``texture``)."""
    other = PixelInputs.random(len(px), np.random.default_rng(12))
    other = replace(other, n_phi=px.n_phi, n_theta=px.n_theta, b_phi=px.b_phi, b_theta=px.b_theta)
    adv = adversarial_pixels(cfg, channel="color")
    worst = [worst_case_pixels(datapath_fixed, cfg, c) for c in ("specular", "color")]
    worst = PixelInputs.concat(worst)
    rng = np.random.default_rng(3)
    out = {}
    for m in lights:
        sets = {"random": ([px] + [other] * (m - 1)), "adversarial": [adv] * m, "worst": [worst] * m}
        texels = {k: {c: rng.integers(0, 256, len(p[0])) for c in RGB} for k, p in sets.items()}
        e2e = {k: _outputs(p, cfg, texels[k]) for k, p in sets.items()}
        grid = (None if get(cfg.method).cartesian else
                {k: _outputs(p, cfg, texels[k], grid=True) for k, p in sets.items()})
        for output in LIGHT_OUTPUTS:
            bounds = error_bounds(cfg, m, texture=output == "blend")
            bound = bounds["color" if output == "blend" else output]
            out[(m, output)] = {**{k: _stats(e2e[k][output]) for k in sets},
                                "grid": None if grid is None else
                                {k: _stats(grid[k][output]) for k in sets},
                                "bound": bound, "sets": sets, "texels": texels}
    return out


def _lights(opts, px):
    """The light-sum and blend table: one and two lights at the default widths of
    ``opts.method`` (or ``--scene-widths``), and two lights at the two-light scenes' widths
    (rtl/config.TWO_LIGHT_WIDTHS); returns the failure lines."""
    cfg = _scene_config(opts)
    two = cfg.replace(angle_bits=TWO_LIGHT_WIDTHS[0], frac_bits=TWO_LIGHT_WIDTHS[1])
    print(f"\nthe outputs summed over m lights (LightSum) and the texture blend (TextureBlend, "
          f"random texels), rounded once, n = {cfg.spec_exponent}: random = the {len(px)} pixels "
          f"(a further light: random L, H on the same N, N', seed 12); adversarial = the search "
          f"aimed at the colour, worst-case = the searches aimed at the proof's worst case of "
          f"the specular term and the colour, every light the same; bound = the pipeline "
          f"sidecar's error_bounds.lsb_per_channel of an m-light (textured) scene\n")
    print("| angle bits | frac bits | lights | output | end-to-end random max / mean "
          "| end-to-end adversarial max / mean | end-to-end worst-case max "
          "| arithmetic max (random / adversarial / worst-case) | bound | worst / bound |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    failures = []
    points = [(cfg, (1, 2))] + ([(two, (2,))] if (two.angle_bits, two.frac_bits) !=
                                (cfg.angle_bits, cfg.frac_bits) else [])
    for c, lights in points:
        for (m, output), row in light_sums(c, px, lights).items():
            failures += _light_row(c, m, output, row)
    return failures


def _light_row(cfg, m, output, row):
    """Print one row of the light-sum table; its failure lines."""
    grid = row["grid"]
    top = max([row[k]["max"] for k in LIGHT_KINDS] +
              ([grid[k]["max"] for k in LIGHT_KINDS] if grid else []))
    cell = "—" if grid is None else " / ".join(str(grid[k]["max"]) for k in LIGHT_KINDS)
    ratio = f"{top / row['bound']:.2f}" if row["bound"] else "—"
    name = {"color": "colour"}.get(output, output)
    print(f"| {cfg.angle_bits} | {cfg.frac_bits} | {m} | {name} | {row['random']['max']} / "
          f"{row['random']['mean']:.4f} | {row['adversarial']['max']} / "
          f"{row['adversarial']['mean']:.4f} | {row['worst']['max']} | {cell} | {row['bound']} | "
          f"{ratio} |", flush=True)
    failures = []
    for k in LIGHT_KINDS:
        for measure, stats in (("end-to-end", row[k]), ("arithmetic", grid and grid[k])):
            if stats and stats["max"] > row["bound"]:
                i = stats["worst"]
                lights = "; ".join(
                    f"light {j + 1}: " + ", ".join(f"{f.name}={float(getattr(p, f.name)[i])!r}"
                                                   for f in fields(p))
                    for j, p in enumerate(row["sets"][k]))
                tex = (f", texel {tuple(int(row['texels'][k][c][i]) for c in RGB)}"
                       if output == "blend" else "")
                failures.append(f"FAIL {cfg.method} angle_bits={cfg.angle_bits} frac_bits="
                                f"{cfg.frac_bits} lights={m} {output} ({k}, {measure}): "
                                f"error {stats['max']} LSB > bound {row['bound']} at pixel "
                                f"{i} ({lights}) [radians]{tex}")
    return failures


def _scene_config(opts):
    """The Config of the light-sum, blend and scene tables: ``--scene-widths`` (angle bits,
    frac bits) when given, else Config's default widths."""
    widths = dict(zip(("angle_bits", "frac_bits"), opts.scene_widths or (), strict=False))
    return Config(method=opts.method, spec_index_bits=opts.spec_index_bits, **widths)


def _scenes(opts):
    """Every built-in scene and the unseen crater map (sim/golden/accuracy.crater_scene)
    shaded at the default widths of ``opts.method``: eq. 2's colour image and, where the
    scene has a colour texture, the texture blend on its 8-bit albedo
    (sim/golden/accuracy.scene_error), over the pixels the geometry covers."""
    cfg = _scene_config(opts)
    print(f"\nscenes at {opts.scene_size}x{opts.scene_size} (angle bits {cfg.angle_bits}, frac bits "
          f"{cfg.frac_bits}, n = {cfg.spec_exponent}): PSNR (dB) / max LSB against float64 "
          f"`conventional` on the unquantized inputs\n")
    print("| scene | colour (eq. 2) | texture blend |")
    print("|---|---|---|")
    for name in (*SCENES, "craters"):
        scene = (crater_scene(size=opts.scene_size) if name == "craters" else
                 load_scene(name, size=opts.scene_size))
        rows = [scene_error(scene, cfg, datapath_fixed)]
        if scene.albedo is not None:
            rows.append(scene_error(scene, cfg, datapath_fixed, blend=True))
        cells = [f"{r['psnr_db']} / {r['max_lsb']}" for r in rows] + ["—"] * (2 - len(rows))
        print(f"| {name} | {' | '.join(cells)} |", flush=True)
