"""Bit-exact int64 model of BumpMapFetch and of the BumpPipeline a SceneConfig builds.

It skips the same work the generator skips: no H terms without specular, the N' rotation
once per polygon for a flat bump map, m lights dotted with one rotated normal, only a table
lookup with palette shading. Inputs and outputs are dicts of arrays keyed like the flattened
payloads (``"u"``, ``"n.phi"``, ``"extra_lights.0.l.theta"``, ...; each light's keys:
``rtl/layouts.light_keys``).

Several lights (eq. 2 of Lee et al. summed over lights): each light j gives the unrounded
terms d_j = clamp(N'.L_j) and s_j = 255 (N'.H_j)^n with F fractional bits
(rtl/shade.shade_stages' diffuse_fine, specular_fine); with D = sum d_j, S = sum s_j the
pipeline outputs
  diffuse  = min(255, round(255 D)),  specular = min(255, round(S / 2**F)),
  color    = the Phong sum of D and S rounded once (common.phong_sum_fixed).

Colour texture (``texture = true``): the RGB texel at the same (u, v, level) as the bump map
(``texels``: the texture memory) and :func:`rtl.texture.texture_blend`, the very function the
RTL's TextureBlend elaborates: per channel
  color.c  = clamp(tex_c min(1, ka + kd sum d_j) + ks sum s_j)   (rounded as in rtl/texture.py);
palette shading returns the texel word beside the index (PaletteLUT's eq. 2 base colour).
"""

import numpy as np

from bumprtl.rtl.bumpfetch import (
    coord_bits,
    has_map,
    level_bases,
    level_bits,
    memory_depth,
    pack_texels,
    texel_address,
)
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.layouts import light_keys
from bumprtl.rtl.palette import index_bits
from bumprtl.rtl.tables import SPEC_FRAC_BITS
from bumprtl.rtl.texture import RGB, texture_blend
from bumprtl.sim.golden.fixed import exact
from bumprtl.sim.golden.fixed.common import phong_sum_fixed
from bumprtl.sim.golden.methods import illumination_fixed, rotation_fixed
from bumprtl.sim.golden.vectors import corner_codes, random_codes
from bumprtl.sim.scenes.config import SceneConfig

# The outputs of one Illumination unit (rtl/layouts.shade_layout) a single-light pipeline has.
SHADE_OUTPUTS = ("diffuse", "specular", "color", "diffuse_fine", "specular_fine")

__all__ = ["SHADE_OUTPUTS", "fetch_fixed", "unpack_texels", "map_words", "pipeline_fixed",
           "polygon_fixed", "combine_lights_fixed", "random_map", "random_texture",
           "corner_inputs", "corner_texels", "random_inputs", "as_payload_list", "unpack_rgb"]


def unpack_rgb(words):
    """Texture words (r low) -> {r, g, b} 8-bit arrays."""
    w = np.asarray(words, np.int64)
    return {c: (w >> (8 * n)) & 0xFF for n, c in enumerate(RGB)}


def fetch_fixed(u, v, level, words, scene: SceneConfig):
    """BumpMapFetch: the stored word of each (u, v, level); levels past the last read the
    last (``level`` None means level 0)."""
    u, v = np.asarray(u, np.int64), np.asarray(v, np.int64)
    level = np.zeros_like(u) if level is None else np.minimum(np.asarray(level), scene.mip_levels - 1)
    addr = np.zeros_like(u)
    for n in range(scene.mip_levels):
        addr = np.where(level == n, texel_address(u, v, n, scene), addr)
    return np.asarray(words, np.int64)[addr]


def unpack_texels(words, scene: SceneConfig):
    """Texel words -> ``{"b.phi", "b.theta"}`` angle codes, or ``{"index"}``."""
    w = np.asarray(words, np.int64)
    if scene.shading == "palette":
        return {"index": w}
    mask = (1 << scene.angle_bits) - 1
    return {"b.phi": w & mask, "b.theta": (w >> scene.angle_bits) & mask}


def map_words(levels, scene: SceneConfig):
    """The memory image: per-level (H_l, W_l) word maps, row v, column u, one after the
    other at :func:`level_bases`."""
    if len(levels) != scene.mip_levels:
        raise ValueError(f"{len(levels)} levels given, the scene has {scene.mip_levels}")
    words = np.concatenate([np.asarray(lv, np.int64).ravel() for lv in levels])
    assert len(words) == level_bases(scene)[-1] + levels[-1].size
    return words


def _light_codes(codes, keys):
    """The codes of one light (``keys``: one entry of ``light_keys``) under the ``l``/``h``
    keys the unit models read."""
    out = {k: codes[k] for k in ("n.phi", "n.theta", "b.phi", "b.theta") if k in codes}
    out.update({own: codes[key] for own, key in keys.items()})
    return out


def polygon_fixed(n_phi, n_theta, b_phi, b_theta, scene: SceneConfig):
    """The once-per-polygon rotation of a flat bump map's N' (polygon normal N): the n''
    terms x4, y2, z4 and ph_N (``n_phi``), which the per-pixel vector terms need; keyed
    like the pipeline's ``poly`` port."""
    codes = {"n.phi": n_phi, "n.theta": n_theta, "b.phi": b_phi, "b.theta": b_theta,
             "l.phi": 0, "l.theta": 0, "h.phi": 0, "h.theta": 0}
    rot = exact.rotation_fixed({k: np.asarray(c, np.int64) for k, c in codes.items()}, scene.config)
    return {"n_phi": int(n_phi), **{k: int(rot[k]) for k in ("n.x4", "n.y2", "n.z4")}}


def combine_lights_fixed(shades, scene: SceneConfig):
    """Several lights' unrounded terms -> the pipeline output (module docstring)."""
    cfg = scene.config
    d = sum(np.asarray(s["diffuse_fine"], np.int64) for s in shades)
    s = sum(np.asarray(s["specular_fine"], np.int64) for s in shades)
    return {"diffuse": np.minimum(round_shift(255 * d, cfg.frac_bits), 255),
            "specular": np.minimum(round_shift(s, SPEC_FRAC_BITS), 255),
            "color": phong_sum_fixed(d, s, cfg)}


def pipeline_fixed(inputs, scene: SceneConfig, words=None, polygon=None, texels=None):
    """The outputs of BumpPipeline(scene) for the input payload arrays ``inputs``.

    ``words``: the bump map memory (varying map); ``polygon``: the per-polygon n'' terms
    (flat map, :func:`polygon_fixed`); ``texels``: the colour-texture memory (texture =
    true). Palette shading returns the ``index`` of each pixel (and the ``texel`` word with
    a texture); the colour is :class:`~bumprtl.sim.golden.fixed.palette_lut.PaletteLUTModel`'s
    lookup of that index in the cycle the *pipeline* accepted the pixel (the bank then in
    front, with the host writes the pipeline took, ``lut_w_en & lut_w_ready``): the
    pipeline carries the bank through the fetch and holds back writes to a bank a pixel in
    flight still reads, so the table a pixel sees is fixed when it enters.
    """
    cfg = scene.config
    codes = dict(inputs)
    fetch = lambda mem: fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"), mem, scene)
    if has_map(scene):
        codes.update(unpack_texels(fetch(words), scene))
    tex = fetch(texels) if scene.texture else None
    if scene.shading == "palette":
        return {"index": codes["index"], **({"texel": tex} if scene.texture else {})}
    shades = []
    for keys in light_keys(cfg):
        light = _light_codes(codes, keys)
        if polygon is None:
            rot = rotation_fixed(light, cfg)
        else:                                      # n'' once per polygon, terms per pixel
            shape = light["l.phi"].shape
            poly = {k: np.full(shape, v, np.int64) for k, v in polygon.items()}
            zero = np.zeros(shape, np.int64)
            rot = {**exact.rotation_fixed({**light, "n.phi": poly.pop("n_phi"), "n.theta": zero,
                                             "b.phi": zero, "b.theta": zero}, cfg), **poly}
        shades.append(illumination_fixed(rot, cfg))
    if scene.texture:
        color, d, s = texture_blend([sh["diffuse_fine"] for sh in shades],
                                    [sh["specular_fine"] for sh in shades], unpack_rgb(tex), cfg)
        return {"diffuse": d, "specular": s, **{f"color.{c}": color[c] for c in RGB}}
    if len(shades) == 1:
        return {k: shades[0][k] for k in SHADE_OUTPUTS}
    return combine_lights_fixed(shades, scene)


def corner_texels(scene):
    """Word addresses of the first and the last texel of every level: where the corners of
    :func:`corner_inputs` read (their coordinates wrap or clamp to one of the two)."""
    ends = []
    for base, n in zip(level_bases(scene), range(scene.mip_levels), strict=True):
        width, height = scene.level_size(n)
        ends += [base, base + width * height - 1]
    return np.array(ends, np.int64)


def random_map(scene: SceneConfig, rng):
    """A random memory image: N' in the upper tangent hemisphere, or palette indices. The
    first and the last texel of every level hold N' = N (theta_A = 0, phi_A 0 and the last
    code), so the corners of :func:`corner_inputs` see every light head-on."""
    n, full = memory_depth(scene), 1 << scene.angle_bits
    if scene.shading == "palette":
        return pack_texels(scene, index=rng.integers(0, 1 << index_bits(scene.config), n))
    phi, theta = rng.integers(0, full, n), rng.integers(0, full // 4 + 1, n)
    ends = corner_texels(scene)
    phi[ends], theta[ends] = np.resize([0, full - 1], len(ends)), 0
    return pack_texels(scene, phi=phi, theta=theta)


def random_texture(scene: SceneConfig, rng):
    """A random colour-texture memory image (24-bit RGB words), or None without a texture;
    the first and the last texel of every level are white (every channel's last code)."""
    if not scene.texture:
        return None
    words = rng.integers(0, 1 << 24, memory_depth(scene))
    words[corner_texels(scene)] = (1 << 24) - 1
    return words


def corner_inputs(scene: SceneConfig):
    """The extreme corners of the pipeline's inputs (dict of arrays, no tag), the rows of
    :func:`~bumprtl.sim.golden.vectors.corner_codes` with every light given the same row
    (so m lights are head-on, or behind, at once: the light sum at its maximum), each row
    at one of the texel coordinates 0, the map's last texel (W - 1, H - 1) and both ends of the
    signed port range, in turn, and at level 0 or the last level code, in turn. Palette
    shading: the coordinate corners alone. Widths from ``scene``."""
    cfg = scene.config
    codes = corner_codes(cfg) if scene.shading == "per-pixel" else {}
    rows = len(next(iter(codes.values()))) if codes else 8
    out = {}
    if has_map(scene) or scene.texture:
        half = 1 << (coord_bits(scene) - 1)
        out["u"], out["v"] = (np.resize([0, last, -half, half - 1], rows)
                              for last in (scene.texture_size - 1, scene.map_height - 1))
        if scene.mip_levels > 1:
            out["level"] = np.resize([0, 0, 0, 0, (1 << level_bits(scene)) - 1], rows)
    if codes:
        for j, keys in enumerate(light_keys(cfg)):
            if j == 0 and scene.bump_map == "varying":
                out["n.phi"], out["n.theta"] = codes["n.phi"], codes["n.theta"]
            out.update({key: codes[own] for own, key in keys.items()})
    return {k: np.asarray(v, np.int64) for k, v in out.items()}


def random_inputs(scene: SceneConfig, n, rng):
    """``n`` input payloads (dict of arrays): the corners first (:func:`corner_inputs`, as
    many as fit in ``n``), then random ones: texel coordinates over the whole signed port
    range (so wrap/clamp are exercised), levels past the last, random angles."""
    out = {}
    if has_map(scene) or scene.texture:
        half = 1 << (coord_bits(scene) - 1)
        out["u"], out["v"] = rng.integers(-half, half, n), rng.integers(-half, half, n)
        if scene.mip_levels > 1:
            out["level"] = rng.integers(0, 1 << level_bits(scene), n)
    if scene.shading == "per-pixel":
        for j, keys in enumerate(light_keys(scene.config)):
            codes = random_codes(n, scene.config, seed=int(rng.integers(1 << 30)))
            if j == 0 and scene.bump_map == "varying":
                out["n.phi"], out["n.theta"] = codes["n.phi"], codes["n.theta"]
            out.update({key: codes[own] for own, key in keys.items()})
    corners = corner_inputs(scene)
    for k, c in corners.items():
        m = min(n, len(c))
        out[k] = np.concatenate([c[:m], np.asarray(out[k])[:n - m]])
    # consecutive tags centred on the middle of the tag range, so the top tag bit (and every
    # bit below it) changes within any run of two or more pixels
    mask = (1 << scene.tag_bits) - 1
    out["tag"] = (np.arange(n) + (mask + 1) // 2 - n // 2) & mask
    return {k: np.asarray(v, np.int64) for k, v in out.items()}


def as_payload_list(inputs):
    """Dict of arrays -> list of payload dicts (for the stream drivers)."""
    cols = {k: np.asarray(v).tolist() for k, v in inputs.items()}
    n = len(next(iter(cols.values())))
    return [{k: c[i] for k, c in cols.items()} for i in range(n)]
