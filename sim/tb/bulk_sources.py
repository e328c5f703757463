"""Stimulus generators of the bulk path (sim/tb/bulk.py): stimulus and golden outputs made
chunk by chunk inside the simulator process, so 10^7 vectors never sit in a file or in
memory at once.

A source is ``{"kind": name, ...}`` in the job; :func:`make_source` turns it into
``(setup, chunks)``: host set-up cycles (``[{port: int}]``, driven after reset) and an
iterator of ``(inputs, expected)`` dicts of int64 arrays, ``expected`` None when only
the outputs are wanted. Stimulus arrays from a file are sim/tb/tb_bulk.py's own source;
these generators run under sim/tb/tb_bulk_gen.py, which alone pays for their imports.
"""

import numpy as np

from bumprtl.rtl.bumpfetch import pack_texels
from bumprtl.rtl.config import Config
from bumprtl.rtl.palette import CHANNELS, blend_eq2, index_bits
from bumprtl.rtl.tables import cos_lookup, sin_lookup
from bumprtl.sim.golden.fixed.palette_lut import pack_rgba, unpack_rgba
from bumprtl.sim.golden.fixed.pipeline import (
    corner_inputs,
    corner_texels,
    map_words,
    pipeline_fixed,
    random_inputs,
)
from bumprtl.sim.golden.methods import get, illumination_fixed, rotation_fixed
from bumprtl.sim.golden.stress import stress_codes
from bumprtl.sim.golden.vectors import edge_codes, random_codes, range_corners
from bumprtl.sim.scenes.config import load_scene_config

__all__ = ["make_source", "pipeline_map", "palette_table", "SOURCES"]


def _counts(n, chunk):
    """Chunk lengths covering ``n``."""
    return [min(chunk, n - s) for s in range(0, n, chunk)]


# odd, so k -> k * TAG_STEP is a bijection modulo 2**bits: 2**bits pixels in a row carry
# every tag once, and the tags' high bits toggle from the second pixel on
TAG_STEP = 0x9E37


def _tags(n, start, bits):
    """The tags of pixels ``start`` .. ``start + n - 1``: k * TAG_STEP modulo 2**bits. Counting
    tags (k itself) would leave a 16-bit tag's high bits 0 for the first 2**15 pixels, and
    with them every register and FIFO slice that carries only those bits."""
    return (np.arange(start, start + n, dtype=np.int64) * TAG_STEP) & ((1 << bits) - 1)


def _out_fields(meta):
    return [k for k in meta.output_fields if k != "tag"]


def _datapath(meta, spec, chunk):
    """Rotation or illumination: the edge cases and (exact method) the pixels whose dot
    products sit next to a rounding carry (:func:`rounding_codes`), then random pixels
    (seed + chunk number); golden = the unit's bit-exact model (rtl/methods.py)."""
    cfg = Config(**meta.config)
    unit, outs = meta.unit, _out_fields(meta)
    keys = [k for k in meta.input_fields if k != "tag"]

    def chunks():
        start = 0
        for k, n in enumerate(_counts(int(spec["n"]), chunk)):
            codes = random_codes(n, cfg, seed=int(spec.get("seed", 0)) * 1000 + k)
            if k == 0:          # the edge cases and the rounding carries first
                edges = edge_codes(cfg)
                near = rounding_codes(cfg, int(spec.get("seed", 0)))
                if near is not None:
                    edges = {c: np.concatenate([edges[c], near[c]]) for c in edges}
                m = min(n, len(edges["n.phi"]))
                codes = {c: np.concatenate([edges[c][:m], codes[c][:n - m]]) for c in codes}
            codes = get(cfg.method).from_angle_codes(codes, cfg)   # Cartesian: Peercy, Ernst
            if unit == "rotation":
                inputs, want = codes, rotation_fixed(codes, cfg)
            else:
                inputs = rotation_fixed(codes, cfg)
                want = illumination_fixed(inputs, cfg)
            tag = _tags(n, start, cfg.tag_bits)
            yield ({**{c: np.asarray(inputs[c], np.int64) for c in keys}, "tag": tag},
                   {**{c: np.asarray(want[c], np.int64) for c in outs}, "tag": tag})
            start += n
    return [], chunks()


ROUNDING_POOL = 1 << 14      # random pixels searched for the dot products' rounding carries
ROUNDING_PIXELS = 64         # pixels kept a dot product (L's, and H's with specular)


def rounding_codes(cfg, seed=0, pool=ROUNDING_POOL, count=ROUNDING_PIXELS, lit=False, fixed=None):
    """Angle codes of pixels whose exact-method dot products sit next to their one rounding
    (rtl/exact.py: ``(pair + zz_half) >> (B + 3)``, the rounding half in ``zz_half``): of
    ``pool`` random pixels (ROUNDING_POOL), the ``count`` per dot (ROUNDING_PIXELS) whose
    sum lies nearest to a
    carry into bit B + 3, either side (a few hundred LSBs at most), so a wrong low bit of
    either adder operand moves the dot. Random pixels reach such a sum about once in a
    thousand. ``lit``: only pixels whose dot is positive (a negative one is clamped to 0
    before any output shows it). ``fixed``: codes every pixel of the pool shares (a flat
    map's N and N', searched over the lights alone). None for the other methods (other dot
    products)."""
    if cfg.method != "exact":
        return None
    codes = random_codes(pool, cfg, seed=seed)
    codes.update({k: np.full(pool, int(v), np.int64) for k, v in (fixed or {}).items()})
    rot = rotation_fixed(codes, cfg)
    shift = cfg.frac_bits + 3
    picks = []
    for v in ("l", "h") if cfg.specular else ("l",):
        w = lambda k: np.asarray(rot[k], np.int64)
        acc = (w("n.x4") * w(f"{v}.p2") + 2 * w("n.y2") * w(f"{v}.y2")
               + 2 * w("n.z4") * w(f"{v}.z"))
        d = (acc + (1 << (shift - 1))) & ((1 << shift) - 1)
        dist = np.minimum(d, (1 << shift) - d)
        if lit:
            dist = np.where(acc > 0, dist, 1 << shift)
        picks.append(np.argsort(dist, kind="stable")[:count])
    keep = np.concatenate(picks)
    return {k: np.asarray(c)[keep] for k, c in codes.items()}


def _sincos(meta, spec, chunk):
    """Every quadrant boundary and its neighbours, then random angles; golden = the tables."""
    cfg = Config(**meta.config)

    def chunks():
        start = 0
        for k, n in enumerate(_counts(int(spec["n"]), chunk)):
            rng = np.random.default_rng(int(spec.get("seed", 0)) * 1000 + k)
            a = rng.integers(0, cfg.full_circle, n)
            if k == 0:
                edges = np.array([(q << cfg.k) + d for q in range(4) for d in (-1, 0, 1)]) % cfg.full_circle
                a[:min(n, len(edges))] = edges[:n]
            tag = _tags(n, start, cfg.tag_bits)
            yield ({"angle": a, "tag": tag},
                   {"sin": sin_lookup(cfg, a), "cos": cos_lookup(cfg, a), "tag": tag})
            start += n
    return [], chunks()


def palette_table(cfg, seed):
    """A random colour table (packed RGBA words) of ``cfg.palette_size`` entries."""
    rng = np.random.default_rng(seed)
    return pack_rgba(rng.integers(0, 256, (cfg.palette_size, 4)), cfg)


def _palette(meta, spec, chunk):
    """PaletteLUT: a decoy table written to the back bank and swapped in, then the random
    table written to the other bank and swapped in (set-up: two swaps, so a swap that does
    not alternate the banks reads the decoy), then the corners (the index and every base
    channel at both ends, together and alone) and random indices over the whole index
    range (out-of-range ones read as zero, oor = 1) with random base colours; golden = the
    table lookup and Tarini eq. 2."""
    cfg = Config(**meta.config)
    seed = int(spec.get("seed", 0))
    table = palette_table(cfg, seed)
    setup = []
    for t in (palette_table(cfg, seed + 1), table):
        setup += [{"w_en": 1, "w_addr": a, "w_data": int(w)} for a, w in enumerate(t.tolist())]
        setup.append({"swap": 1})
    top = 1 << index_bits(cfg)

    def chunks():
        start = 0
        for k, n in enumerate(_counts(int(spec["n"]), chunk)):
            rng = np.random.default_rng(seed * 1000 + k + 1)
            index = rng.integers(0, top, n)
            base = {c: rng.integers(0, 256, n) for c in CHANNELS}
            if k == 0:          # the corners first: index and base channels at both ends
                corners = range_corners({"index": (0, top - 1), **{c: (0, 255) for c in CHANNELS}})
                m = min(n, len(corners["index"]))
                for c, col in (("index", index), *base.items()):
                    col[:m] = corners[c][:m]
            oor = index >= cfg.palette_size
            entry = unpack_rgba(np.where(oor, 0, table[np.minimum(index, cfg.palette_size - 1)]), cfg)
            inputs = {"index": index}
            if cfg.palette_blend:
                entry = blend_eq2(entry, base, cfg)
                inputs.update({f"base.{c}": base[c] for c in CHANNELS})
            tag = _tags(n, start, cfg.tag_bits)
            inputs["tag"] = tag
            want = {**{f"color.{c}": np.asarray(entry[c], np.int64) for c in CHANNELS},
                    "oor": oor.astype(np.int64), "tag": tag}
            yield inputs, want
            start += n
    return setup, chunks()


def pipeline_map(scene, seed):
    """The bump-map words of the pipeline regression: the N' of T^2 stress pixels (every
    stress case) at level 0, the other levels from the same texels; the first and the last
    texel of every level N' = N (theta_A = 0), where the corners of the first chunk
    (sim/golden/fixed/pipeline.corner_inputs) read. Emit the pipeline with these words as
    its map (``BumpPipeline(scene, init=...)``)."""
    t, h = scene.texture_size, scene.map_height
    codes = stress_codes(t * h, scene.config, seed)
    level0 = pack_texels(scene, codes["b.phi"].reshape(h, t), codes["b.theta"].reshape(h, t))
    words = map_words([level0[::1 << n, ::1 << n] for n in range(scene.mip_levels)], scene)
    words[corner_texels(scene)] &= (1 << scene.angle_bits) - 1          # theta_A = 0
    return words


def _pipeline(meta, spec, chunk):
    """BumpPipeline of a varying-map, per-pixel scene with :func:`pipeline_map` in its map:
    the corners first (sim/golden/fixed/pipeline.corner_inputs: every light head-on or
    behind at once, coordinates and levels at both ends), then chunks alternate stress vectors (every case of sim/golden/stress.py; texels in order)
    and random payloads over the whole port ranges (wrap/clamp, levels past the last);
    golden = sim/golden/fixed/pipeline.py."""
    scene = load_scene_config(meta.scene)
    seed = int(spec.get("seed", 0))
    words = pipeline_map(scene, int(spec.get("map_seed", 0)))
    keys = list(meta.input_fields)
    t = scene.texture_size

    def chunks():
        start = 0
        for k, n in enumerate(_counts(int(spec["n"]), chunk)):
            rng = np.random.default_rng(seed * 1000 + k)
            codes = stress_codes(n, scene.config, seed * 1000 + k) if k % 2 == 0 else {}
            texel = (np.arange(start, start + n)) % (t * scene.map_height)
            inputs = {"u": texel % t, "v": texel // t, "level": rng.integers(0, scene.mip_levels, n),
                      "tag": None, **codes}
            if any(c not in inputs for c in keys):      # more lights than the stress cases
                inputs = random_inputs(scene, n, rng)
            inputs["tag"] = _tags(n, start, scene.tag_bits)
            inputs = {c: np.asarray(inputs[c], np.int64) for c in keys}
            if k == 0:
                corners = corner_inputs(scene)
                m = min(n, len(corners["u"]))
                inputs.update({c: np.concatenate([v[:m], inputs[c][m:]]) for c, v in corners.items()})
            want = pipeline_fixed(inputs, scene, words)
            yield inputs, {**{c: np.asarray(v, np.int64) for c, v in want.items()},
                           "tag": inputs["tag"]}
            start += n
    return [], chunks()


SOURCES = {"datapath": _datapath, "sincos": _sincos, "palette": _palette,
           "pipeline": _pipeline}


def make_source(meta, spec, chunk):
    """``(setup cycles, iterator of (inputs, expected))`` of source ``spec``."""
    if spec["kind"] not in SOURCES:
        raise ValueError(f"bulk source must be one of {', '.join(SOURCES)}, got {spec['kind']!r}")
    return SOURCES[spec["kind"]](meta, spec, chunk)
