"""``bumprtl bench sweep``: error against cost against run time for every method and width.

For each method (``exact`` and ``lee`` over a grid of angle bits and value bits,
``palette`` over palette sizes, the Table 1 baselines) one *point* records

* **error** against float64 (``conventional``): max / mean LSB of the bit-exact model's
  diffuse, specular and colour outputs on random valid vectors and on the adversarial
  search aimed at each channel (unquantized inputs), and PSNR / max LSB of the shaded
  image (eq. 2's 8-bit colour) on the maps (``--maps NAME:SIZE``: a scene of
  sim/scenes at SIZE x SIZE texels, drawn at one pixel per texel). ``error_lsb`` = the
  worst max LSB of the colour over all of them: the number ``bumprtl recommend
  --max-error-lsb`` compares. The output records each map's name, size and number of
  distinct normals, and marks each palette measurement whose palette held every distinct
  normal of the map (``quantized: false``: nothing was quantized there);
* **cost** from the Yosys netlist of the method's per-pixel units (gen/flow/resources.py:
  multipliers, ROM bits, RAM bits, adders) and, with ``--fpga``, ECP5 LUT4/FF/DSP/BRAM and
  Fmax of the unit(s) placed by gen/flow/fpga.py;
* **speed**: golden-model Mpix/s (numpy, best of 3, measured in this run), cocotb
  simulation pixels/s with ``--sim`` and hardware pixels/s = Fmax x 1 pixel/clock with
  ``--fpga``.

A width the Config rejects is recorded as ``invalid`` with the Config's message; a method
whose model or RTL is missing as ``not available`` with the reason. Nothing is estimated.
Output: ``build/bench/sweep.json`` (``--out``), Pareto plots and a markdown table.
"""

import hashlib
import json
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from bumprtl.gen.bench.golden import unit_sim_rate
from bumprtl.gen.flow.fpga import (
    NOT_PLACED,
    FpgaError,
    Placement,
    check_device,
    pipeline_component,
    place_text,
)
from bumprtl.gen.flow.resources import count_verilog
from bumprtl.gen.flow.units import build_unit, emit_unit
from bumprtl.gen.tools.docs import write_section
from bumprtl.gen.tools.jobs import Job, Runner, job_name, scheduler_address
from bumprtl.gen.tools.yosys import SynthesisError
from bumprtl.rtl.config import BumpError, Config, ConfigError
from bumprtl.rtl.pipe import ECP5
from bumprtl.sim.golden.accuracy import CHANNELS, adversarial_pixels, scene_error, term_errors_lsb
from bumprtl.sim.golden.common import PixelInputs, to_8bit
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.palette import (
    distinct_normals,
    palette_rgb,
    quantize_normal_map,
    world_normal_map,
)
from bumprtl.sim.golden.methods import BASELINES, PER_PIXEL, datapath_fixed, encode_pixels, get
from bumprtl.sim.scenes import SCENES, load_scene
from bumprtl.sim.scenes.imaging import max_diff, psnr

__all__ = ["GRIDS", "Grid", "pareto_front", "error_lsb", "cost_key", "sweep", "SweepOptions", "sweep_bench", "markdown", "plot",
           "parse_maps", "map_key", "MAP_SIZES"]


@dataclass(frozen=True)
class Grid:
    angle_bits: tuple
    frac_bits: tuple
    palette_sizes: tuple
    samples: int          # random vectors per point
    maps: tuple           # (scene name, size): a size x size map drawn at size x size pixels
    adversarial: int = 200_000   # candidates of each adversarial search (the 1 / 200 kept)


# Maps with many more texels (and distinct normals) than the largest palette, the photo-derived
# scenes among them: a palette holding every normal of a map quantizes nothing there.
DEFAULT_MAPS = (("bricks", 512), ("brick-photo", 512), ("moon", 512), ("globe", 512), ("gravel", 1024))
GRIDS = {
    "quick": Grid((10, 12), (11, 13), (16, 256), 20_000, (("bricks", 64),)),
    "default": Grid((8, 10, 12, 13, 14), (9, 11, 13, 15, 16), (16, 64, 256, 1024, 4096, 16384),
                    100_000, DEFAULT_MAPS),
}
MAP_SIZES = (16, 2048)      # --maps sizes: powers of two in this range


def map_key(name, size):
    """How a map is named in the sweep's per-map results: ``gravel 1024²``."""
    return f"{name} {size}\N{SUPERSCRIPT TWO}"


def parse_maps(specs):
    """``["gravel:1024", ...]`` -> ``(("gravel", 1024), ...)``; a bad entry is a BumpError
    naming ``--maps`` and what is allowed."""
    lo, hi = MAP_SIZES
    out = []
    for spec in specs:
        name, _, size = str(spec).partition(":")
        ok = name in SCENES and size.isdigit() and lo <= int(size) <= hi and not int(size) & (int(size) - 1)
        if not ok:
            raise BumpError(f"--maps must be NAME:SIZE with NAME one of {', '.join(SCENES)} and SIZE a "
                            f"power of two in [{lo}, {hi}], got {spec!r}")
        if (name, int(size)) in out:
            raise BumpError(f"--maps names {spec!r} twice: each map once")
        out.append((name, int(size)))
    return tuple(out)
# PER_PIXEL and BASELINES (Lee Table 1's designs as RTL, rtl/baselines/) come from the
# method registry, rtl/methods.py.
COST_FIELDS = ("multipliers", "const_multipliers", "dividers", "sqrts", "adders", "table_bits", "ram_bits",
               "register_bits")


def _best_time(fn, repeats=3):
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def error_lsb(point):
    """Worst max LSB of the colour (what a pixel shows) over every error set the point
    measured: random, adversarial and the scenes (None if it measured none). Points without
    per-channel data (older sweeps) fall back to their diffuse sets."""
    err = point.get("error") or {}
    sets = err.get("channels", {}).get("color", err)
    maxima = [sets[k]["max"] for k in ("random", "adversarial") if k in sets]
    maxima += [s["max_lsb"] for s in err.get("scenes", {}).values() if "max_lsb" in s]
    return max(maxima) if maxima else None


def cost_key(point, device=None):
    """What "cheaper" means: on ``device`` (FPGA numbers) DSP, block RAM, then LUT4;
    otherwise the arithmetic units (multipliers + dividers + square roots), then ROM+RAM
    bits, then adders: a divider or a multiplier costs more than a few kbit of table."""
    cost = point["cost"]
    if device:
        f = cost["fpga"]
        return (f["DSP"], f["BRAM"], f["LUT4"])
    units = cost["multipliers"] + cost.get("dividers", 0) + cost.get("sqrts", 0)
    return (units, cost["table_bits"] + cost["ram_bits"], cost["adders"])


def pareto_front(points, x, y):
    """Indices of the points no other point beats in both ``x(p)`` and ``y(p)`` (both
    minimized; ties kept once, the first). Points where either is None are skipped."""
    vals = [(i, x(p), y(p)) for i, p in enumerate(points)]
    vals = [(i, a, b) for i, a, b in vals if a is not None and b is not None]
    front = []
    for i, a, b in vals:
        dominated = any((a2 <= a and b2 <= b) and ((a2, b2) != (a, b) or j < i)
                        for j, a2, b2 in vals if j != i)
        if not dominated:
            front.append(i)
    return front


# ---------------------------------------------------------------- measurement context

class Context:
    """Inputs shared by every point of one run (same vectors, same scenes)."""

    def __init__(self, grid, seed, work):
        self.grid, self.work = grid, Path(work)
        self.px = PixelInputs.random(grid.samples, np.random.default_rng(seed))
        self.scenes = {map_key(name, size): load_scene(name, size=size) for name, size in grid.maps}
        self.refs = {name: to_8bit(conventional(s.px, Config()).color) for name, s in self.scenes.items()}
        self.maps = [map_record(name, size, self.scenes[map_key(name, size)]) for name, size in grid.maps]
        self._adversarial = {}
        self.pending = []          # (point, Placement) placed as jobs after the points

    def adversarial(self, cfg, channel="diffuse"):
        """Adversarial vectors depend on the angle grid (and the exponent) only: one set per
        angle_bits and channel."""
        key = (cfg.angle_bits, cfg.spec_exponent, channel)
        if key not in self._adversarial:
            self._adversarial[key] = adversarial_pixels(
                cfg, candidates=self.grid.adversarial, keep=max(20, self.grid.adversarial // 200),
                channel=channel)
        return self._adversarial[key]


def map_record(name, size, scene):
    """What the sweep says about a map it measured on: name, size, geometry, texels (all /
    used by some pixel) and distinct normals (object-space, of the used texels: a palette of
    at least that many entries stores every one and quantizes nothing)."""
    used = int(np.count_nonzero(np.bincount((scene.v * scene.texture_size + scene.u)[scene.mask],
                                            minlength=scene.texture_size ** 2)))
    return {"key": map_key(name, size), "name": name, "size": size, "geometry": scene.geometry,
            "texels": scene.texture_size ** 2, "texels_used": used,
            "distinct_normals": int(distinct_normals(scene))}


def _stats(err):
    return {"max": int(err.max()), "mean": round(float(err.mean()), 5), "n": int(err.size)}


def _scene_stats(ctx, name, intensity8):
    """PSNR / max of an 8-bit shaded intensity against float64's over the scene's geometry
    (the measure of sim/golden/accuracy.scene_error)."""
    m = ctx.scenes[name].mask
    ref, img = ctx.refs[name][m], np.asarray(intensity8)[m]
    p = psnr(ref, img)
    return {"psnr_db": None if p == float("inf") else round(p, 2), "max_lsb": max_diff(ref, img)}


def perpixel_error(ctx, cfg):
    """Per channel: random and adversarial (the search aimed at that channel) max / mean;
    the diffuse sets also at the top level (older readers); the scenes' colour image."""
    random = term_errors_lsb(datapath_fixed, ctx.px, cfg)
    channels = {c: {"random": _stats(random[c]),
                    "adversarial": _stats(term_errors_lsb(datapath_fixed, ctx.adversarial(cfg, c), cfg)[c])}
                for c in CHANNELS}
    out = {**channels["diffuse"], "channels": channels, "scenes": {}}
    for name, scene in ctx.scenes.items():
        out["scenes"][name] = scene_error(scene, cfg, datapath_fixed)
    return out


def perpixel_speed(ctx, cfg):
    codes = encode_pixels(ctx.px, cfg)
    return {"golden_mpix_s": round(len(ctx.px) / _best_time(lambda: datapath_fixed(codes, cfg)) / 1e6, 3)}


def cached_json(path, compute):
    """The JSON value stored at ``path``, else ``compute()`` stored there and returned."""
    if path.is_file():
        return json.loads(path.read_text())
    value = compute()
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(value, indent=1))
    return value


def _tag(cfg):
    return f"{cfg.method}_a{cfg.angle_bits}_b{cfg.frac_bits}_p{cfg.palette_size}_s{int(cfg.specular)}"


def _summary(counts):
    s = counts.summary()
    return {**{k: s[k] for k in COST_FIELDS if k in s}, "ram_bits": sum(r["bits"] for r in counts.rams)}


def text_digest(*texts):
    """Cache key of generated Verilog: a changed datapath never reuses an old count."""
    h = hashlib.sha256()
    for t in texts:
        h.update(t.encode())
    return h.hexdigest()[:12]


def unit_cost(units, cfg, work):
    """Yosys counts of ``units`` (gen/flow/units.py names) summed, cached per emitted Verilog."""
    paths = {u: emit_unit(u, cfg, work / "netlists" / _tag(cfg) / u)[0] for u in units}

    def compute():
        total = None
        for u, v in paths.items():
            c = count_verilog(v, u, v.parent)
            total = c if total is None else total + c
        return _summary(total)

    key = text_digest(*(v.read_text() for v in paths.values()))
    return cached_json(work / "cost" / f"{_tag(cfg)}_{'+'.join(units)}_{key}.json", compute)


def place_pending(ctx, opts, progress=True):
    """The placements the points asked for (``ctx.pending``: (point, Placement)) as jobs of
    gen/tools/jobs.py (a local cluster of ``opts.jobs`` workers, or ``opts.scheduler``'s), one
    job per distinct Verilog; each point gets its row or its ``fpga_error``."""
    by_key = {}
    for point, p in ctx.pending:
        by_key.setdefault(p.key, []).append((point, p))
    if not by_key:
        return
    names = {key: job_name("place", p.device, p.label, key) for key, ((_, p), *_) in by_key.items()}
    with Runner(scheduler_address(getattr(opts, "scheduler", None)),
                getattr(opts, "jobs", None) or 1, progress=progress) as runner:
        out = runner.run((Job(names[key], place_text, group[0][1].args())
                          for key, group in by_key.items()), desc="place")
    for key, group in by_key.items():
        o = out[names[key]]
        for n, (point, p) in enumerate(group):
            if not o.ok:
                point["cost"]["fpga_error"] = o.error[:300]
                continue
            _fill(point, p.store(o.value) if n == 0 else {**o.value["row"], "unit": p.label})


def _pipeline(cfg, target=None):
    return pipeline_component(cfg, target)


def _palette_unit(cfg, target=None):
    return build_unit("palette", cfg, target)[0]


def sim_rate(cfg, work):
    """cocotb pixels/s on Verilator of the rotation and illumination units (scoreboard
    included), the slower of the two (gen/bench/golden.py's measurement)."""
    rates = [unit_sim_rate(cfg, "verilator", u, 2000, work / "sim" / _tag(cfg))[0]
             for u in ("rotation", "illumination")]
    return round(min(rates))


# ---------------------------------------------------------------- points

def _invalid(method, params, e):
    return {"method": method, **params, "status": "invalid", "reason": str(e)}


def perpixel_point(ctx, method, a, b, opts):
    params = {"angle_bits": a, "frac_bits": b}
    try:
        cfg = Config(method=method, angle_bits=a, frac_bits=b)
    except ConfigError as e:
        return _invalid(method, params, e)
    point = {"method": method, **params, "status": "ok", "config": cfg.to_dict(),
             "error": perpixel_error(ctx, cfg), "speed": perpixel_speed(ctx, cfg),
             "cost": {**unit_cost(("rotation", "illumination"), cfg, ctx.work),
                      "map_bits_per_texel": map_bits_per_texel(cfg)}}
    if fpga_selected(ctx.grid, a, b, opts, method):
        _hardware(point, cfg, _pipeline, "pipeline", ctx, opts)
    if opts.sim and (a, b) == (Config().angle_bits, Config().frac_bits):
        point["speed"]["sim_pix_s"] = sim_rate(cfg, ctx.work)
    return point


FPGA_POINTS = ("default", "diagonal", "all")


def fpga_selected(grid, a, b, opts, method="exact"):
    """Which width points ``--fpga`` places: ``all``; ``diagonal`` (the i-th angle width with
    the i-th value width: cost against precision at a quarter of the flow time; baselines
    at the default widths only, their combinational dividers and square roots take
    synth_ecp5 10+ minutes per point); or ``default`` (the default widths of every method,
    the placements ``report fpga`` shares). Palette sizes are always placed."""
    mode = getattr(opts, "fpga_points", "all")
    if mode == "all":
        return True
    if mode == "default" or method in BASELINES:
        return (a, b) == (Config().angle_bits, Config().frac_bits)
    ia, ib = grid.angle_bits.index(a), grid.frac_bits.index(b)
    return ia == ib


def map_bits_per_texel(cfg):
    """Bump-map bits per texel: N' as two binary angles (polar methods) or three signed
    components of B + 2 bits (Peercy, Ernst: Cartesian N')."""
    return 3 * (cfg.frac_bits + 2) if get(cfg.method).cartesian else 2 * cfg.angle_bits


def _hardware(point, cfg, component_fn, label, ctx, opts):
    if not opts.fpga:
        return
    if point["method"] in NOT_PLACED:
        point["cost"]["fpga_error"] = NOT_PLACED[point["method"]]
        return
    try:
        p = Placement(component_fn(cfg, ECP5()), f"{point['method']}_{label}", opts.device)
    except (FpgaError, SynthesisError) as e:      # e.g. does not fit: recorded, not fatal
        point["cost"]["fpga_error"] = str(e).splitlines()[0][:300]
        return
    if p.cached is None:
        ctx.pending.append((point, p))            # placed as a job after the points
    else:
        _fill(point, p.cached)


def _fill(point, row):
    point["cost"]["fpga"] = row
    if row.get("fmax_mhz"):
        point["speed"]["hw_pix_s"] = row["fmax_mhz"] * 1e6     # 1 pixel per clock (docs/architecture.md, Interfaces)


def palette_point(ctx, size, opts):
    """The palette of ``size`` entries on every map. Per map ``quantized``: False when the
    palette held each of the map's distinct normals (quantize_normal_map's exact table), so
    that map measured no quantization; the point's ``quantizes`` is False when no map did."""
    cfg = Config(palette_size=size)
    scenes, speeds = {}, []
    for name, scene in ctx.scenes.items():
        normals, counts = world_normal_map(scene)
        qmap = quantize_normal_map(normals, size, "median-cut", weights=counts)
        rgb, _ = palette_rgb(scene, cfg, qmap=qmap)
        scenes[name] = {**_scene_stats(ctx, name, to_8bit(rgb.mean(-1))), "quantized": not qmap.exact,
                        "distinct_normals": qmap.distinct}
        speeds.append(scene.mask.size / _best_time(lambda scene=scene, qmap=qmap: palette_rgb(scene, cfg, qmap=qmap)))
    exact = [name for name, s in scenes.items() if not s["quantized"]]
    point = {"method": "palette", "palette_size": size, "status": "ok", "config": cfg.to_dict(),
             "quantizes": len(exact) < len(scenes), "stores_every_normal_of": exact,
             "error": {"scenes": scenes, "note": "a palette shades a normal map: scenes only, "
                                                  "no independent random/adversarial vectors"},
             "speed": {"golden_mpix_s": round(min(speeds) / 1e6, 3),
                       "golden_note": "per frame: colour table of sN normals + per-pixel lookup"},
             "cost": {**unit_cost(("palette",), cfg, ctx.work),
                      "map_bits_per_texel": (size - 1).bit_length()}}   # a palette index
    _hardware(point, cfg, _palette_unit, "palette", ctx, opts)
    return point


def sweep(grid, opts, work, seed=11, progress=True):
    """Every point of ``grid``; ``opts`` has ``fpga``, ``device``, ``sim``, ``methods``."""
    ctx = Context(grid, seed, work)
    methods = [m for m in PER_PIXEL if m in opts.methods]
    methods += list(BASELINES) if "baselines" in opts.methods else []
    jobs = [(perpixel_point, (m, a, b, opts)) for m in methods
            for a in grid.angle_bits for b in grid.frac_bits]
    if "palette" in opts.methods:
        jobs += [(palette_point, (s, opts)) for s in grid.palette_sizes]
    points = []
    with tqdm(jobs, desc="sweep", unit="point", disable=not progress, file=sys.stderr) as bar:
        for fn, args in bar:
            bar.set_postfix_str(" ".join(map(str, args[:-1])))
            points.append(fn(ctx, *args))
    place_pending(ctx, opts, progress)
    reference = len(ctx.px) / _best_time(lambda: _conventional(ctx)) / 1e6
    return {"grid": grid.__dict__, "maps": ctx.maps, "seed": seed,
            "float64_conventional_mpix_s": round(reference, 3), "points": points}


def _conventional(ctx):
    return conventional(ctx.px, Config())


# ---------------------------------------------------------------- output

def ok_points(data):
    return [p for p in data["points"] if p["status"] == "ok"]


def maps_of(data):
    """The maps a sweep measured on: its ``maps`` records; for a sweep made before they were
    recorded, the grid's scenes at its size (distinct normals None: not recorded)."""
    if data.get("maps"):
        return data["maps"]
    g = data.get("grid") or {}
    size = g.get("size")
    return [{"key": n, "name": n, "size": size, "texels": size * size if size else None,
             "distinct_normals": None} for n in g.get("scenes", ())]


def describe_map(m):
    """``gravel (1024², 82838 distinct normals)``."""
    size = f"{m['size']}\N{SUPERSCRIPT TWO}" if m.get("size") else "size not recorded"
    n = m.get("distinct_normals")
    return f"{m['name']} ({size}, {'distinct normals not recorded' if n is None else f'{n} distinct normals'})"


def unquantized_maps(point, data):
    """Keys of the maps on which palette ``point`` held every distinct normal, so quantized
    nothing: as the sweep recorded it per map; for an older sweep without that record, where
    the palette has at least as many entries as the map has texels (more distinct normals
    than texels there cannot be). Empty for the per-pixel methods."""
    if point.get("method") != "palette":
        return []
    maps = {m["key"]: m for m in maps_of(data)}
    out = []
    for key, s in point.get("error", {}).get("scenes", {}).items():
        if "max_lsb" not in s:
            continue
        if "quantized" in s:
            exact = not s["quantized"]
        else:
            m = maps.get(key, {})
            bound = m.get("distinct_normals") or m.get("texels")
            exact = bound is not None and point["palette_size"] >= bound
        if exact:
            out.append(key)
    return out


def measured_maps(point):
    """Keys of the maps a point has a scene measurement on."""
    return [k for k, s in point.get("error", {}).get("scenes", {}).items() if "max_lsb" in s]


def _ns_per_pixel(p):
    return 1e3 / p["speed"]["golden_mpix_s"]


def _memory_bits(p):
    return p["cost"]["table_bits"] + p["cost"]["ram_bits"]


def point_label(p):
    if p["method"] == "palette":
        return f"palette sN={p['palette_size']}"
    return f"{p['method']} a{p['angle_bits']} b{p['frac_bits']}" if "angle_bits" in p else p["method"]


def _fmt(x, spec="{}"):
    return "—" if x is None else spec.format(x)


def _row(p, front):
    err, cost, speed = p.get("error", {}), p.get("cost", {}), p.get("speed", {})
    scenes = [s for s in err.get("scenes", {}).values() if "max_lsb" in s]
    psnrs = [s["psnr_db"] for s in scenes]
    psnr = None if not scenes else ("inf" if all(v is None for v in psnrs) else
                                    f"{min(v for v in psnrs if v is not None):.1f}")
    f = cost.get("fpga", {})
    hw = speed.get("hw_pix_s")
    channels = err.get("channels", {})

    def cell(c):
        sets = channels.get(c, {})
        rnd, adv = sets.get("random"), sets.get("adversarial")
        return f"{_fmt(rnd and rnd['max'])} / {_fmt(adv and adv['max'])}"
    return (f"| {point_label(p)} | {cell('diffuse')} | {cell('specular')} | {cell('color')} "
            f"| {_fmt(psnr)} / {_fmt(max((s['max_lsb'] for s in scenes), default=None))} "
            f"| **{error_lsb(p)}** | {cost['multipliers']} | {cost.get('dividers', 0)} / {cost.get('sqrts', 0)} "
            f"| {cost['adders']} | {cost['table_bits']} "
            f"| {cost['ram_bits']} | {cost['map_bits_per_texel']} | {_fmt(f.get('LUT4'))} | {_fmt(f.get('DSP'))} | {_fmt(f.get('BRAM'))} "
            f"| {_fmt(f.get('fmax_mhz'))} | {speed['golden_mpix_s']:.2f} | {_fmt(speed.get('sim_pix_s'), '{:,}')} "
            f"| {_fmt(hw and hw / 1e6, '{:.1f}')} | {'yes' if id(p) in front else ''} |")


def markdown(data, command, plot_paths=()):
    """The sweep section of docs/bench.md."""
    pts = ok_points(data)
    front = {id(pts[i]) for i in pareto_front(pts, _memory_bits, error_lsb)}
    g = data["grid"]
    lines = [f"Generated by `{command}` (grid: angle bits {tuple(g['angle_bits'])}, frac bits "
             f"{tuple(g['frac_bits'])}, palette sizes {tuple(g['palette_sizes'])}; {g['samples']} random valid "
             f"vectors, seed {data['seed']}; adversarial vectors of sim/golden/accuracy.py per "
             f"angle width; maps (scenes of sim/scenes, one pixel per texel; distinct normals = "
             f"object-space normals of the texels the geometry uses): "
             f"{', '.join(describe_map(m) for m in maps_of(data))}).", "",
             "Errors are 8-bit LSB against float64 `conventional` on unquantized inputs: per "
             "output channel, max on the random vectors / max on the adversarial search aimed at "
             "that channel; eq. 2's colour image on the maps, PSNR (worst map, dB) / max LSB "
             "over the pixels the geometry covers. **error** = the worst colour max over all "
             "sets (what `bumprtl recommend` ranks on). "
             "Cost: Yosys coarse netlist of the per-pixel units (rotation + illumination, or the "
             "palette LUT; gen/flow/resources.py); the bump map itself is not in it: `map bits` per texel is "
             "2 x angle bits for N' angles, 3 x (frac bits + 2) for Peercy's and Ernst's Cartesian N', "
             "log2 sN for a palette index. Speed: golden model Mpix/s in this run (numpy, best "
             f"of 3; float64 `conventional` ran at {data['float64_conventional_mpix_s']:.2f} Mpix/s "
             "on the same vectors). `pareto` = on the front of error against ROM+RAM bits.", "",
             "| point | diffuse rnd / adv | specular rnd / adv | colour rnd / adv | maps PSNR / max "
             "| error | mult | div / sqrt | adders | ROM bits | RAM bits | map bits | LUT4 | DSP | BRAM "
             "| Fmax MHz | golden Mpix/s | sim pix/s | hw Mpix/s | pareto |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += [_row(p, front) for p in pts]
    other = [p for p in data["points"] if p["status"] != "ok"]
    if other:
        lines += ["", "Not measured:", ""]
        lines += [f"- {point_label(p)}: **{p['status']}** — {p['reason']}" for p in other]
    exact = [(p, unquantized_maps(p, data)) for p in pts]
    exact = [(p, keys) for p, keys in exact if keys]
    if exact:
        by_key = {m["key"]: m for m in maps_of(data)}
        lines += ["", "Palette points that held every distinct normal of a map quantized nothing "
                      "there (the error on that map is the colour table's rounding only); "
                      "`bumprtl recommend` does not count a point that quantized on no map:", ""]
        for p, keys in exact:
            everywhere = len(keys) == len(measured_maps(p))
            lines.append(f"- {point_label(p)}: every normal of "
                         f"{', '.join(describe_map(by_key[k]) if k in by_key else k for k in keys)}"
                         f"{' (every map measured: not evidence of quantization)' if everywhere else ''}")
    failed = [p for p in pts if p["cost"].get("fpga_error")]
    if failed:
        lines += ["", "FPGA flow failed (the point keeps its other columns):", ""]
        lines += [f"- {point_label(p)}: {p['cost']['fpga_error']}" for p in failed]
    lines += [""] + [f"![{name}](img/{Path(path).name})" for name, path in plot_paths]
    return "\n".join(lines)


def plot(data, path):
    """Two panels: error against ROM+RAM bits and against golden-model ns/pixel, each
    with its Pareto front."""
    import matplotlib  # optional dependency: [bench]

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # optional dependency: [bench]

    pts = ok_points(data)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, x, xlabel in ((axes[0], _memory_bits, "ROM + RAM bits"),
                          (axes[1], _ns_per_pixel, "golden model ns / pixel (numpy)")):
        for n, method in enumerate(sorted({p["method"] for p in pts})):
            sel = [p for p in pts if p["method"] == method]
            ax.scatter([x(p) for p in sel], [max(error_lsb(p), 0.5) for p in sel], label=method,
                       color=f"C{n}")
        front = sorted((x(pts[i]), max(error_lsb(pts[i]), 0.5)) for i in pareto_front(pts, x, error_lsb))
        if front:
            ax.step(*zip(*front, strict=False), where="post", color="k", lw=0.8, label="Pareto front")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("worst error, 8-bit LSB (0 shown as 0.5)")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def command_line(opts):
    """The ``bumprtl bench sweep`` command line that makes ``opts``' sweep."""
    parts = ["bumprtl bench sweep"] + (["--quick"] if opts.quick else [])
    if set(opts.methods) != set(METHOD_CHOICES):
        parts += ["--methods", *opts.methods]
    if opts.maps:
        parts += ["--maps", *opts.maps]
    if opts.fpga:
        parts += ["--fpga", "--device", opts.device, "--fpga-points", opts.fpga_points]
    if opts.sim:
        parts.append("--sim")
    return " ".join(parts)


METHOD_CHOICES = (*PER_PIXEL, "palette", "baselines")


@dataclass(frozen=True)
class SweepOptions:
    """What ``bumprtl bench sweep`` measures and writes (its flags of the same names): the
    ``quick`` grid or the default one, the ``methods`` (METHOD_CHOICES), the scene ``maps``
    ("NAME:SIZE"; None: the grid's), ECP5 placements (``fpga`` on ``device``, the
    ``fpga_points``, ``jobs`` local workers or a ``scheduler``), cocotb speed (``sim``);
    the JSON to ``out``, the cache under ``work``, the section of the page ``docs`` (and
    the JSON copied to ``data_copy``)."""
    quick: bool = False
    methods: tuple = METHOD_CHOICES
    maps: tuple | None = None
    fpga: bool = False
    device: str = "LFE5U-85F"
    fpga_points: str = "default"
    sim: bool = False
    jobs: int = 1
    scheduler: str | None = None
    out: Path = Path("build/bench/sweep.json")
    work: Path = Path("build/bench/sweep")
    docs: Path | None = None
    data_copy: Path | None = None
    no_progress: bool = False


def sweep_bench(opts: SweepOptions):
    """``bumprtl bench sweep``: writes the JSON and the table (or the page's section);
    returns 0."""
    if opts.fpga:
        check_device(opts.device)
        scheduler_address(opts.scheduler)        # a malformed address: one line, exit 2
    elif opts.scheduler is not None:             # accepted, it would change nothing
        raise BumpError("--scheduler applies to --fpga (the placements are its jobs), not to a "
                        "sweep without it")
    grid = GRIDS["quick" if opts.quick else "default"]
    if opts.maps:
        grid = replace(grid, maps=parse_maps(opts.maps))
    command = command_line(opts)
    print(command)
    data = sweep(grid, opts, opts.work, progress=not opts.no_progress)
    data["command"] = command
    opts.out.parent.mkdir(parents=True, exist_ok=True)
    opts.out.write_text(json.dumps(data, indent=1))
    print(f"wrote {opts.out}")
    if opts.docs:
        img = opts.docs.parent / "img"
        plots = [("error against cost and run time", plot(data, img / "bench_pareto.png"))]
        write_section(opts.docs, "sweep", "## Error, cost and speed sweep\n\n" + markdown(data, command, plots))
        if opts.data_copy:
            opts.data_copy.parent.mkdir(parents=True, exist_ok=True)
            opts.data_copy.write_text(json.dumps(data, indent=1))
        print(f"wrote {opts.docs}")
    else:
        print(markdown(data, command))
    return 0
