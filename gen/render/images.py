"""The pictures of ``bumprtl render`` (gen/cli/render.py): a scene (a procedural image or
your own height or normal map) shaded by one method's float64 model or by the bit-exact
fixed-point model of the hardware (the picture the RTL makes, without a simulator)."""

import importlib

import numpy as np
from tqdm import tqdm

from bumprtl.gen.render.rtl import golden_render, scene_stimulus, sim_scene
from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.fixed.palette_lut import unpack_rgba
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.golden.float.models import FLOAT_MODELS
from bumprtl.sim.golden.methods import METHODS, PER_PIXEL, datapath_fixed, encode_pixels
from bumprtl.sim.scenes.config import SceneConfig
from bumprtl.sim.scenes.imaging import compose

__all__ = ["PALETTE", "MODELS", "QUANTIZERS", "FIXED_METHODS", "render_methods", "shade_scene",
           "palette_note", "fixed_image", "float_image"]

ROWS_PER_CHUNK = 32
PROGRESS_PIXELS = 1 << 20          # show a progress bar from 1024 x 1024 pixels on
PALETTE = "palette"                # Tarini et al.'s quantized normal map (sim/golden/float/palette.py)
QUANTIZERS = ("median-cut", "kmeans")
MODELS = ("float64", "fixed")
# render method -> the registry method (rtl/methods.py) whose bit-exact model renders it with
# --model fixed: the float64 model that is a method's ``reference``; palette: the pipeline's
# PaletteLUT. conventional and lee_printed have no hardware.
_FLOAT_NAMES = {model: name for name, model in FLOAT_MODELS.items()}
FIXED_METHODS = {**{_FLOAT_NAMES[m.reference]: m.name for m in METHODS.values()
                    if m.reference in _FLOAT_NAMES and m.hardware_of is None}, PALETTE: PALETTE}


def render_methods():
    """Every method ``render`` accepts: the float64 golden models, then ``palette``."""
    return [*FLOAT_MODELS, PALETTE]


def _render_palette(scene, cfg, palette_opts):
    try:
        palette = importlib.import_module("bumprtl.sim.golden.float.palette")
    except ImportError as e:
        raise BumpError(f"method palette needs bumprtl.sim.golden.float.palette, which this "
                        f"checkout does not have ({e})") from None
    return np.asarray(palette.render_palette(scene, cfg, palette_size=cfg.palette_size,
                                             **palette_opts).color, dtype=np.float64)


def palette_note(scene, cfg):
    """The line ``render`` prints when the palette holds every distinct normal of the map
    (``cfg.palette_size`` >= their number: each normal its own entry, nothing quantized),
    else None."""
    palette = importlib.import_module("bumprtl.sim.golden.float.palette")
    n = palette.distinct_normals(scene)
    if cfg.palette_size < n:
        return None
    return (f"palette: sN = {cfg.palette_size} >= the map's {n} distinct normals: every normal "
            f"has its own entry (no quantization)")


def shade_scene(scene, method, cfg, progress=True, **palette_opts):
    """Per-pixel float intensity of ``scene`` by ``method``.

    A float64 model renders in row chunks of ``ROWS_PER_CHUNK`` with a progress bar on long
    renders; ``palette`` shades the whole bump map at once (``palette_opts``: ``quantizer``,
    ``lighting``, passed through to ``render_palette``).
    """
    if method == PALETTE:
        return _render_palette(scene, cfg, palette_opts)
    if method not in FLOAT_MODELS:
        raise BumpError(f"method must be one of {', '.join(render_methods())}, got {method!r}")
    model, size = FLOAT_MODELS[method], scene.size
    out = np.zeros((size, size))
    with tqdm(total=size * size, unit="pix", unit_scale=True, desc=method, leave=False,
              disable=not progress or size * size < PROGRESS_PIXELS) as bar:
        for r0 in range(0, size, ROWS_PER_CHUNK):
            rows = slice(r0, min(size, r0 + ROWS_PER_CHUNK))
            out[rows] = model(scene.px.subset(rows), cfg).color
            bar.update(out[rows].size)
    return out


def float_image(scene: SceneConfig, method, size, progress=True, azimuth=30.0, **light):
    """8-bit image of ``scene`` at ``size`` x ``size`` by the float64 model ``method`` (or the
    float palette); returns ``(image, sim scene)``."""
    base = sim_scene(scene, size, azimuth, **light)
    return compose(base, shade_scene(base, method, scene.config, progress)), base


def fixed_image(scene: SceneConfig, method, size, azimuth=30.0, **light):
    """8-bit image of ``scene`` by the bit-exact fixed-point model of ``method`` (a key of
    :data:`FIXED_METHODS`): for exact and lee the pipeline's golden render (byte for byte the
    RTL's picture, gen/render/rtl.golden_render); for the Table 1 baselines their datapath's
    model on the same pixels; for palette the pipeline's PaletteLUT colour (the mean of its
    RGB, shown like the float64 palette: times the scene's albedo)."""
    if method not in FIXED_METHODS:
        raise BumpError(f"--method {method} has no fixed-point model; with --model fixed the "
                        f"method must be one of {', '.join(FIXED_METHODS)}")
    name = FIXED_METHODS[method]
    if name in PER_PIXEL:
        return golden_render(scene.replace(method=name), size, azimuth=azimuth, **light)
    if name == PALETTE:
        s = scene.replace(shading="palette")
        if s.texture:
            return golden_render(s, size, azimuth=azimuth, **light)
        inputs, words, polygon, table, base = scene_stimulus(s, size, azimuth, **light)
        rgba = unpack_rgba(table[pipeline_fixed(inputs, s, words, polygon)["index"]], s.config)
        grey = (rgba["r"] + rgba["g"] + rgba["b"]) / 3.0
        return compose(base, grey.reshape(size, size) / 255.0)
    base = sim_scene(scene, size, azimuth, **light)          # a Table 1 baseline datapath
    cfg = scene.config.replace(method=name)
    color = datapath_fixed(encode_pixels(base.px, cfg), cfg)["color"]
    return compose(base, np.asarray(color, np.float64).reshape(size, size) / 255.0)
