"""``bumprtl bench skip``: what scene skipping saves, per scene class (docs/architecture.md,
"Scenes decide what is built").

For each built-in scene class (sim/scenes/config.py BUILTIN) two pipelines, side by side in one run:

* **on**: the scene as it is: BumpPipeline builds only what the scene needs and the golden
  model (sim/golden/fixed/pipeline.py) skips the same work;
* **off**: the same scene with nothing skipped: per-pixel shading with a per-pixel bump map
  and the H path + specular table (lights and widths unchanged). A scene without specular
  gets ks = 0, a flat map becomes a map of the same constant N', so the off pipeline
  computes the same image the long way; ``same image`` says whether it did. A textured
  scene keeps its colour texture (and blend) in both.

Golden-model time (best of 3, one frame) and Yosys cost (gen/flow/resources.py) of each. The
section goes into docs/bench.md.
"""

import time

import numpy as np
from amaranth.back import verilog

from bumprtl.gen.bench.sweep import cached_json, text_digest
from bumprtl.gen.flow.resources import count_verilog
from bumprtl.gen.render.rtl import scene_stimulus, scene_texels
from bumprtl.gen.tools.docs import write_section
from bumprtl.rtl.bumpfetch import pack_texels
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.sim.golden.fixed.pipeline import map_words, pipeline_fixed
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config

__all__ = ["unskipped", "skip_rows", "markdown", "skip_bench"]


def unskipped(scene):
    """The scene with nothing skipped (see module docstring)."""
    changes = {"specular": True, "bump_map": "varying", "shading": "per-pixel"}
    if not scene.specular:
        changes["ks"] = 0.0
    return scene.replace(**changes)


def _stimulus(scene, size, flat_like=None):
    """scene_stimulus; for the off-version of a flat scene, the map holds the flat N'."""
    inputs, words, polygon, _, base = scene_stimulus(scene, size)
    texels = scene_texels(scene, base)
    if flat_like is not None:
        sizes = [scene.level_size(n) for n in range(scene.mip_levels)]
        zeros = [np.zeros((h, w), np.int64) for w, h in sizes]  # N' = +z, as polygon_fixed(.., 0, 0)
        words = map_words([pack_texels(scene, z, z) for z in zeros], scene)
    return inputs, words, polygon, texels


def _golden(scene, size, flat_like=None):
    inputs, words, polygon, texels = _stimulus(scene, size, flat_like)
    out = pipeline_fixed(inputs, scene, words, polygon, texels)
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        pipeline_fixed(inputs, scene, words, polygon, texels)
        best = min(best, time.perf_counter() - t0)
    return out, best


def _cost(scene, work):
    """Yosys counts of the scene's BumpPipeline, cached by the digest of its Verilog (a
    changed datapath is counted anew)."""
    text = verilog.convert(BumpPipeline(scene.hardware), name="pipeline", emit_src=False)
    digest = text_digest(text)
    netlist = work / "netlist" / scene.name

    def compute():
        netlist.mkdir(parents=True, exist_ok=True)
        (netlist / "pipeline.v").write_text(text)
        c = count_verilog(netlist / "pipeline.v", "pipeline", netlist)
        s = c.summary()
        return {**{k: s[k] for k in ("multipliers", "adders", "table_bits", "register_bits")},
                "ram_bits": sum(r["bits"] for r in c.rams)}

    return cached_json(work / "cost" / f"{scene.name}_{digest}.json", compute)


def skip_rows(names, size, work):
    """One row per scene class: golden time and cost with skipping on and off."""
    return [_row(name, size, work) for name in names]


def _skipped(scene):
    """The units the scene's pipeline skips (asked of a pipeline that is never elaborated)."""
    pipeline = BumpPipeline(scene.hardware)
    for unit in (pipeline, *pipeline.units.values()):
        unit._MustUse__silence = True
    return [s["unit"] for s in pipeline.skipped if s["unit"] != "colour-texture blend"]


def _row(name, size, work):
    scene = load_scene_config(name)
    off = unskipped(scene).replace(name=f"{name}-noskip")
    try:
        skipped = _skipped(scene)
    except BumpError as e:
        return {"scene": name, "status": "not available", "reason": str(e)}
    on_out, on_t = _golden(scene, size)
    off_out, off_t = _golden(off, size, flat_like=scene if scene.bump_map == "flat" else None)
    colors = [k for k in on_out if k.startswith("color")]      # grey, or color.r/g/b
    same = scene.shading == "per-pixel" and all(np.array_equal(on_out[k], off_out[k]) for k in colors)
    return {"scene": name, "status": "ok", "skipped": skipped,
            "on": {"golden_s": on_t, **_cost(scene, work)},
            "off": {"golden_s": off_t, **_cost(off, work)}, "same_image": same}


def _ratio(a, b):
    return f"{a / b:.2f}x" if b else "—"


def markdown(rows, command, size):
    lines = ["## Scene skipping", "",
             f"Generated by `{command}`: per scene class (sim/scenes/config.py BUILTIN), the pipeline as "
             "generated (**on**) beside the same scene with nothing skipped (**off**: per-pixel "
             "shading, per-pixel bump map, H path + specular table; ks = 0 when the scene has no "
             "specular, the flat N' stored in the map), measured in one run. Golden = "
             f"sim/golden/fixed/pipeline.py on one {size}x{size} frame (numpy, best of 3). Cost = "
             "Yosys coarse netlist of BumpPipeline (gen/flow/resources.py). `same image`: the off "
             "pipeline produced identical colour outputs (palette shading cannot: it quantizes normals). "
             "The palette's golden time covers the index fetch only (the per-frame colour table "
             "and lookup are in the sweep above). Where on and off build the same pipeline (nothing "
             "skipped but the unused extra-light units), the speed-up column shows this run's "
             "timing noise.", "",
             "| scene | skipped | golden ms on / off | speed-up | mult on / off | adders on / off "
             "| ROM bits on / off | RAM bits on / off | register bits on / off | same image |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"| {r['scene']} | **{r['status']}**: {r['reason']} | | | | | | | | |")
            continue
        on, off = r["on"], r["off"]
        pair = lambda k, on=on, off=off: f"{on[k]} / {off[k]}"
        lines.append(f"| {r['scene']} | {'; '.join(r['skipped']) or '—'} "
                     f"| {on['golden_s'] * 1e3:.2f} / {off['golden_s'] * 1e3:.2f} "
                     f"| {_ratio(off['golden_s'], on['golden_s'])} | {pair('multipliers')} "
                     f"| {pair('adders')} | {pair('table_bits')} | {pair('ram_bits')} "
                     f"| {pair('register_bits')} | {'yes' if r['same_image'] else 'no'} |")
    return "\n".join(lines)


def skip_bench(*, docs, size, work, scenes):
    """``bumprtl bench skip``: the arguments are its flags' (gen/cli/bench.py);
    returns the exit status."""
    command = f"bumprtl bench skip --size {size}"
    print(command)
    rows = skip_rows(scenes or list(BUILTIN), size, work)
    text = markdown(rows, command, size)
    if docs:
        write_section(docs, "skip", text)
        print(f"wrote {docs}")
    else:
        print(text)
    return 0
