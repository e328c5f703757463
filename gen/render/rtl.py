"""Rendering through the RTL (``bumprtl render --rtl``): emit the scene's pipeline, stream
every pixel through it with cocotb (Icarus or Verilator), collect the image.

The same stimulus gives the fixed-point golden render (sim/golden/fixed/pipeline.py); the
two must agree byte for byte. Per pixel the stimulus carries the texel coordinates (u, v),
world N, L and H as binary angles and a tag (the pixel index); the bump map (N' angles of
every texel, or palette indices) is the fetch unit's block-RAM initial contents (or, with
``load = "port"``, written through its host write port before the first pixel), and with
``texture = true`` the scene's albedo (8-bit RGB per texel, :func:`scene_texels`) is the
colour texture's; the pipeline then outputs RGB itself. The bump map is the scene's
procedural image or the user's map file (``height_map``/``normal_map``, sim/scenes/usermap.py).
"""

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bumprtl.gen.flow.memories import (
    DEFAULT_DEVICE,
    check_scene_fits,
    emit_scene_unit,
    host_writes,
    memory_images,
)
from bumprtl.gen.flow.quiet import tool_log
from bumprtl.gen.flow.resources import count_unit
from bumprtl.gen.tools.docs import made_at, write_section
from bumprtl.gen.tools.toolchain import require
from bumprtl.rtl.bumpfetch import pack_rgb, pack_texels
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.layouts import light_keys
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.golden.common import to_8bit
from bumprtl.sim.golden.fixed.common import angle_codes, quantize_pixels
from bumprtl.sim.golden.fixed.palette_lut import pack_rgba, palette_colors
from bumprtl.sim.golden.fixed.pipeline import map_words, pipeline_fixed, polygon_fixed
from bumprtl.sim.golden.float.palette import (
    color_table,
    frame_directions,
    mipmap_indices,
    quantize_normal_map,
    world_normal_map,
)
from bumprtl.sim.scenes import SCENES, load_scene
from bumprtl.sim.scenes.config import BUILTIN, SceneConfig, load_scene_config
from bumprtl.sim.scenes.imaging import compose, save_png
from bumprtl.sim.scenes.usermap import load_bump_map

__all__ = ["RtlRender", "scene_stimulus", "scene_texels", "scene_memories", "golden_render",
           "render_rtl", "sim_scene"]

LIGHT_AZIMUTH_STEP = 120.0        # light j sits 120 degrees further round than light j - 1


@dataclass
class RtlRender:
    image: np.ndarray              # 8-bit (H, W, 3) image through the RTL
    golden: np.ndarray             # the fixed-point golden render of the same stimulus
    cycles: int
    seconds: float                 # wall time of the simulation run (not the build)
    build_seconds: float
    stream_seconds: float = None   # bulk path: wall time streaming the pixels (no start-up)
    cached: bool = False           # bulk path: the simulator build came from build/sim_cache


def sim_scene(scene: SceneConfig, size, azimuth=30.0, **light):
    """The sim scene (bumprtl.sim.scenes.Scene) of ``scene`` at ``size`` x ``size`` pixels:
    its procedural image or its user map, on its geometry, at its map's width and height."""
    bump = None
    if scene.map_file is not None:
        key, path = scene.map_file
        bump = load_bump_map(path, "height" if key == "height_map" else "normal",
                             scene.normal_convention, scene.height_scale, scene.texture_size,
                             scene.resample, scene.map_height)
    return load_scene(scene.image, size=size, texture_size=scene.texture_size,
                      texture_height=scene.map_height, light_azimuth=azimuth, bump=bump,
                      geometry=scene.geometry, **light)


def _levels(level0, scene):
    """Mip levels of a word map: point-sampled (every 2**l-th texel); renders read level 0."""
    return [level0[::1 << n, ::1 << n] for n in range(scene.mip_levels)]


def scene_stimulus(scene: SceneConfig, size, azimuth=30.0, **light):
    """Per-pixel input arrays, memory words, polygon registers and palette table (or None)
    of one frame of ``scene`` at ``size`` x ``size``; and the sim scene. Light 0 sits at
    ``azimuth`` degrees, light j LIGHT_AZIMUTH_STEP * j further round."""
    cfg = scene.config
    base = sim_scene(scene, size, azimuth, **light)
    inputs, words, polygon, table = {}, None, None, None
    if scene.bump_map == "varying" or scene.shading == "palette" or scene.texture:
        inputs["u"], inputs["v"] = base.u, base.v
        if scene.mip_levels > 1:
            inputs["level"] = np.zeros_like(base.u)
    if scene.shading == "palette":
        words, table = _palette_maps(base, scene)
    else:
        codes = quantize_pixels(base.px, cfg)
        if scene.bump_map == "varying":
            inputs["n.phi"], inputs["n.theta"] = codes["n.phi"], codes["n.theta"]
            words = _bump_words(base, scene)
        else:
            if np.ptp(codes["n.phi"]) or np.ptp(codes["n.theta"]):
                raise BumpError(f"bump_map = 'flat' renders one polygon: {scene.picture!r} is "
                                f"not on a plane (its normal varies); use a plane scene")
            polygon = polygon_fixed(codes["n.phi"].flat[0], codes["n.theta"].flat[0], 0, 0, scene)
        for j, keys in enumerate(light_keys(cfg)):
            turn = azimuth if j == 0 else (azimuth + LIGHT_AZIMUTH_STEP * j) % 360
            lit = quantize_pixels(sim_scene(scene, size, turn, **light).px, cfg)
            inputs.update({key: lit[own] for own, key in keys.items()})
    inputs = {k: np.asarray(v, np.int64).ravel() for k, v in inputs.items()}
    inputs["tag"] = np.arange(size * size, dtype=np.int64) & ((1 << scene.tag_bits) - 1)
    return inputs, words, polygon, table, base


def _bump_words(base, scene):
    """The bump vector map memory: N' of every texel as binary angles, levels point-sampled."""
    cfg = scene.config
    level0 = pack_texels(scene, angle_codes(base.b_phi_map, cfg), angle_codes(base.b_theta_map, cfg))
    return map_words(_levels(level0, scene), scene)


MEMORY_FRAME_MAX = 1024


def scene_memories(scene):
    """``(map words, texture words, palette table)`` (each None when the scene has no such
    memory) of ``scene``'s pipeline, as ``bumprtl emit`` writes them. The bump map and the
    texture depend on the map only; the palette's index map and colour table on a frame too:
    the default light, T x T pixels (at most MEMORY_FRAME_MAX^2)."""
    scene = load_scene_config(scene)
    palette = scene.shading == "palette"
    base = sim_scene(scene, min(scene.texture_size, MEMORY_FRAME_MAX) if palette else 16)
    words, table = None, None
    if palette:
        words, table = _palette_maps(base, scene)
    elif scene.bump_map == "varying":
        words = _bump_words(base, scene)
    return words, scene_texels(scene, base), table


def scene_texels(scene: SceneConfig, base):
    """The colour-texture memory of a textured scene (None without a texture): the sim
    scene's albedo as 8-bit RGB words, mip levels point-sampled like the bump map."""
    if not scene.texture:
        return None
    if base.albedo is None:
        have = [n for n, v in SCENES.items() if v[0] in ("bricks", "wood")]
        raise BumpError(f"texture = true needs an image with a colour texture ({', '.join(have)}), "
                        f"got {'image ' if scene.map_file is None else ''}{scene.picture!r}")
    return map_words(_levels(pack_rgb(to_8bit(base.albedo)), scene), scene)


def _palette_maps(base, scene):
    """Index map words (mip levels by Tarini Sec. 5.2) and the 8-bit RGBA colour table."""
    normals, counts = world_normal_map(base)
    qmap = quantize_normal_map(normals, scene.palette_size, weights=counts)
    l, v = frame_directions(base)
    table8 = to_8bit(color_table(qmap.table, "phong", l, v, scene.config))
    levels = mipmap_indices(qmap)[:scene.mip_levels]
    return map_words(levels, scene), pack_rgba(table8, scene.config)


def _image(base, pixels, scene):
    """Output fields (flat arrays) -> 8-bit RGB image: grey shading times the albedo, or the
    pipeline's own RGB (palette colour, or the colour-texture blend); black outside the
    geometry."""
    size = base.size
    if "color.r" in pixels:
        rgb = np.stack([pixels[f"color.{c}"] for c in "rgb"], -1).reshape(size, size, 3)
        return np.where(base.mask[..., None], rgb, 0).astype(np.uint8)
    return compose(base, np.asarray(pixels["color"]).reshape(size, size) / 255.0)


def golden_render(scene, size, **light):
    """The fixed-point golden image of ``scene``: 8-bit RGB."""
    scene = load_scene_config(scene)
    inputs, words, polygon, table, base = scene_stimulus(scene, size, **light)
    return _golden_image(scene, inputs, words, polygon, table, base, scene_texels(scene, base))


def _golden_image(scene, inputs, words, polygon, table, base, texels):
    """:func:`golden_render` of stimulus already made (:func:`scene_stimulus`)."""
    out = pipeline_fixed(inputs, scene, words, polygon, texels)
    if scene.shading == "palette":
        out = palette_colors(out, table, scene)
    return _image(base, out, scene)


def write_stimulus(path, inputs, polygon, table, setup=()):
    """The npz tb_pipeline.py reads; ``setup``: host cycles (``{port: value}`` per clock,
    e.g. the map written through its port) as ``setup.<port>`` arrays, one entry a clock."""
    arrays = {f"in.{k}": v for k, v in inputs.items()}
    arrays.update({f"polygon.{k}": np.array(v) for k, v in (polygon or {}).items()})
    if table is not None:
        arrays["lut"] = np.asarray(table, np.int64)
    for port in sorted({p for cycle in setup for p in cycle}):
        arrays[f"setup.{port}"] = np.array([c.get(port, 0) for c in setup], np.int64)
    np.savez(path, **arrays)


def run_pipeline(scene, inputs, words, polygon, table, simulator, build_dir, patterns=("no_stall",),
                 progress=True, texels=None, rtl_dir=None, load="initial"):
    """Emit BumpPipeline(scene) with ``words`` in its map (and ``texels`` in its colour
    texture), run ``inputs`` through it under each traffic pattern; returns
    ({pattern: {field: array}}, {pattern: cycles}, run), ``run`` the :class:`CocotbRun` with
    the build and run wall times. The Verilog goes to ``rtl_dir`` (default ``<build_dir>/rtl``).
    ``load = "port"``: the memories start at zero and the host writes them before the pixels."""
    build_dir = Path(build_dir).resolve()      # the simulator runs in its own directory
    v, j, writes = _emit_and_writes(scene, words, texels, table, build_dir, rtl_dir, load)
    return run_pipeline_emitted(v, j, inputs, polygon, table, simulator, build_dir, patterns,
                                progress, writes)


def run_pipeline_emitted(v, j, inputs, polygon, table, simulator, build_dir,
                         patterns=("no_stall",), progress=True, setup=()):
    """:func:`run_pipeline` on a pipeline already emitted (``v``, ``j``): ``setup`` the host
    cycles (``{port: value}`` per clock) played before the pixels, e.g. map words written
    through the host port."""
    build_dir = Path(build_dir).resolve()
    build_dir.mkdir(parents=True, exist_ok=True)
    stim, result = build_dir / "stimulus.npz", build_dir / "result.npz"
    write_stimulus(stim, inputs, polygon, table, setup)
    from bumprtl.sim.tb.runner import run_cocotb  # optional dependency: the [sim] extra
    run = run_cocotb(simulator, v, "bumprtl.sim.tb.tb_pipeline", build_dir / simulator,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_STIMULUS": stim, "BUMPRTL_RESULT": result,
                      "BUMPRTL_PATTERNS": ",".join(patterns), "BUMPRTL_PROGRESS": int(progress)})
    res = dict(np.load(result))
    outs = {p: {k[len(p) + 1:]: v for k, v in res.items() if k.startswith(p + ".") and
                not k.endswith(".cycles")} for p in patterns}
    return outs, {p: int(res[f"{p}.cycles"]) for p in patterns}, run


def emit_pipeline(scene, words, texels, build_dir, rtl_dir, table=None, load="initial",
                  write_port=None):
    """Write pipeline.v, pipeline.json and the $readmemh files of its memories
    (gen/flow/memories.py); ``load``: the contents built in (``initial``) or left to the
    host write port (``port``). ``write_port = True`` with ``initial``: the contents built
    in and the host write port too (a bench that overwrites part of the map; default: the
    port only with ``port``). Returns the .v and .json paths."""
    images = memory_images("pipeline", scene, words, texels, table, load)
    rtl_dir = Path(build_dir) / "rtl" if rtl_dir is None else Path(rtl_dir).resolve()
    v, j, _ = emit_scene_unit("pipeline", scene, rtl_dir, images, device=None,
                              write_port=write_port)
    return v, j


def _emit_and_writes(scene, words, texels, table, build_dir, rtl_dir, load):
    """emit_pipeline, plus the host cycles that load the memories when ``load = "port"``."""
    v, j = emit_pipeline(scene, words, texels, build_dir, rtl_dir, table, load)
    images = memory_images("pipeline", scene, words, texels, None, load)
    return v, j, host_writes(images, load_sidecar(j))


def run_pipeline_bulk(scene, inputs, words, polygon, table, simulator, build_dir,
                      patterns=("no_stall",), texels=None, rtl_dir=None, expected=None,
                      load="initial", **build):
    """:func:`run_pipeline` on the bulk path (sim/tb/bulk.py): the pixels travel as arrays
    and the clock runs in the simulator; the build is cached under build/sim_cache by the
    Verilog's digest. ``expected`` (golden output arrays) makes cocotb compare every pixel.
    ``build``: the bulk build's ``clock``, ``io``, ``opt_fast``, ``extra``
    (sim/tb/bulk.build_options; by default the simulator's fastest), e.g. ``clock="verilog"``
    runs the wrapper's own Verilog clock on Verilator. ``load = "port"``: the memories are written
    through the host ports in the set-up.
    Returns ({pattern: {field: array}}, {pattern: cycles}, :class:`BulkResult`)."""
    build_dir = Path(build_dir).resolve()
    v, j, writes = _emit_and_writes(scene, words, texels, table, build_dir, rtl_dir, load)
    meta = load_sidecar(j)
    from bumprtl.sim.tb.bulk import run_bulk, setup_writes  # optional dependency: [sim]
    r = run_bulk(simulator, v, j, build_dir / f"bulk_{simulator}", patterns, inputs=inputs,
                 expected=expected, setup=writes + setup_writes(meta, polygon, table), **build)
    return r.outputs, r.cycles, r


def render_rtl(scene, size, simulator="verilator", build_dir="build/render_rtl", progress=True,
               rtl_dir=None, per_cycle=False, load="initial", **light):
    """Render ``scene`` (SceneConfig, name or TOML path) through the emitted RTL; returns an
    :class:`RtlRender` with the RTL image and the golden image of the same stimulus. The
    bulk path by default; ``per_cycle`` drives every pixel from cocotb (tb_pipeline.py).
    ``load = "port"``: the Verilog has no map contents; the host write port loads them."""
    scene = load_scene_config(scene)
    inputs, words, polygon, table, base = scene_stimulus(scene, size, **light)
    texels = scene_texels(scene, base)
    if per_cycle:
        outs, cycles, run = run_pipeline(scene, inputs, words, polygon, table, simulator,
                                         build_dir, progress=progress, texels=texels,
                                         rtl_dir=rtl_dir, load=load)
        times = (run.run_s, run.build_s, None, False)
    else:
        outs, cycles, run = run_pipeline_bulk(scene, inputs, words, polygon, table, simulator,
                                              build_dir, texels=texels, rtl_dir=rtl_dir,
                                              load=load)
        times = (run.run_s, run.build_s, run.sim_s["no_stall"], run.cached)
    pixels = outs["no_stall"]
    if not np.array_equal(pixels["tag"], inputs["tag"]):
        raise AssertionError("RTL render: pixel tags out of order (lost or duplicated pixels)")
    return RtlRender(_image(base, pixels, scene),
                     _golden_image(scene, inputs, words, polygon, table, base, texels),
                     cycles["no_stall"], *times)


def require_sim(simulator=None):
    """Import the simulator path (cocotb, the [sim] extra) before any work: without it the
    ImportError reaches gen/cli/main.py, which names the extra in one line. ``simulator``
    (``icarus`` / ``verilator``): its binary too (ToolMissing, one line), before the tool
    log's banner and the emit."""
    import cocotb_tools.runner  # noqa: F401  # optional dependency: [sim]

    if simulator is not None:
        require({"icarus": "iverilog", "verilator": "verilator"}[simulator])


def rtl_render_png(scene, size, out, simulator="verilator", *, device=DEFAULT_DEVICE,
                   per_cycle=False, load="initial", verbose=False, azimuth=30.0,
                   light_elevation=45.0, light="directional"):
    """``bumprtl render --rtl``: ``scene`` rendered through its emitted pipeline at ``size``
    x ``size`` pixels on ``simulator``; writes the RTL image to ``out``, prints one line of
    counts and one of the comparison with the golden render, and returns 0 when the two are
    the same bytes, else 1. A map that does not fit ``device``'s block RAM is refused before
    anything is built; so is ``per_cycle`` or ``load = "port"`` with a map in AXI memory
    (the bulk wrapper holds that memory; the map is its ``_map.bin``)."""
    if scene.map_memory == "axi" and (per_cycle or load != "initial"):
        flag = "--per-cycle" if per_cycle else "--load"
        raise BumpError(f"{flag} applies to map_memory = 'bram': a map in AXI memory is "
                        f"rendered on the bulk path, whose wrapper holds the memory", "map_memory")
    check_scene_fits(scene, device)
    light = {"azimuth": azimuth, "light_elevation": light_elevation, "light": light}
    require_sim(simulator)
    t0 = time.perf_counter()
    build_dir = Path("build/render_rtl") / _dir_name(scene)
    with tool_log(build_dir / "tools.log", f"rtl: {size}x{size} through the "
                  f"{scene.name} pipeline on {simulator}", verbose):
        r = render_rtl(scene, size, simulator, build_dir, progress=verbose,
                       per_cycle=per_cycle, load=load, **light)
    out = save_png(out, r.image)
    same = r.image.tobytes() == r.golden.tobytes()
    n = size ** 2
    path = "per-cycle cocotb" if per_cycle else "bulk"
    build = (f"build {r.build_seconds:.1f} s" if not r.cached else
             f"build cached (took {r.build_seconds:.1f} s once)")
    stream = "" if r.stream_seconds is None else \
        f"; streaming {r.stream_seconds:.2f} s = {n / r.stream_seconds:,.0f} pix/s"
    print(f"rtl ({simulator}, {path}, map load {load}): {size}x{size} "
          f"{scene.picture} ({scene.map_label} map) with pipeline {scene.name}: {r.cycles} "
          f"cycles; {build}; simulation {r.seconds:.2f} s = {n / r.seconds:,.0f} pix/s{stream}; "
          f"total {time.perf_counter() - t0:.1f} s -> {out}")
    print(f"vs fixed-point golden render: {'identical bytes' if same else 'DIFFERENT'}")
    return 0 if same else 1


def _dir_name(scene):
    """A build directory name for ``scene`` (a TOML path's stem, not its directories)."""
    return Path(scene.name).stem or "scene"


SCENES_TABLE_SIZE = 256


def _built_units(scene):
    dut = BumpPipeline(scene.hardware)
    for unit in (dut, *dut.units.values()):        # only the plan is read, never elaborated
        unit._MustUse__silence = True
    return ", ".join(u["unit"] for u in dut.built)


def scenes_table(work_dir="build/scenes"):
    """The table of docs/scenes.md: per built-in scene class, the units
    built, multipliers, ROM and RAM bits and adders of the emitted pipeline (Yosys netlist,
    gen/flow/resources.py) and the golden render time at SCENES_TABLE_SIZE^2."""
    rows = ["| scene class | units built | multipliers | ROM bits | RAM bits | adders | "
            f"golden render {SCENES_TABLE_SIZE}² (s) | command |", "|---" * 8 + "|"]
    for name in BUILTIN:
        scene = load_scene_config(name)
        netlist = count_unit("pipeline", scene, Path(work_dir) / name)
        counts, ram = netlist.summary(), sum(r["bits"] for r in netlist.rams)
        t0 = time.perf_counter()
        golden_render(scene, SCENES_TABLE_SIZE)
        seconds = time.perf_counter() - t0
        rows.append(f"| {name} | {_built_units(scene)} | {counts['multipliers']} | "
                    f"{counts['table_bits']} | {ram} | {counts['adders']} | {seconds:.2f} | "
                    f"`bumprtl emit pipeline --scene {name}` |")
    return "\n".join(rows)


def write_scenes_doc(path="docs/scenes.md", work_dir="build/scenes"):
    """Write :func:`scenes_table` into ``path`` between its markers, with its record."""
    text = (f"Produced by `.venv/bin/python -m bumprtl.gen.render.rtl --doc {path}` in one run. "
            + made_at(Config(), "the default; each scene at its own widths, "
                                "sim/scenes/config.BUILTIN") + ".\n\n" + scenes_table(work_dir))
    write_section(path, "scenes table", text)


if __name__ == "__main__":    # python -m bumprtl.gen.render.rtl [--doc docs/scenes.md]
    import argparse
    ap = argparse.ArgumentParser(prog="python -m bumprtl.gen.render.rtl",
                                 description="the table of docs/scenes.md (printed, or --doc)")
    ap.add_argument("--doc", type=Path, help="write the table into this page (docs/scenes.md)")
    args = ap.parse_args()
    if args.doc:
        write_scenes_doc(args.doc)
        print(f"wrote {args.doc}")
    else:
        print(scenes_table())
