"""The coverage frame of a scene's pipeline on the bulk path (sim/tb/bulk.py): few pixels,
each chosen to move a part of the datapath a rendered frame leaves still.

A rendered 16 x 16 frame of a built-in scene has one world normal, one light and one
halfway vector for every pixel, reads 256 of the map's texels (none of them past the map's
edge, all at level 0) and tags 0..255: most of the rotation, the dot products, the cos^n
table and the address logic never see a second value. This frame keeps the scene's
pipeline as it is emitted (its map, colour texture and tables built in) and, per pixel:

* texel coordinates over the whole signed port range (wrap or clamp, both sides of the
  map), levels over the whole level port (past the last level too); a third of the pixels
  on the scene's steepest and flattest texels, a third on words the host wrote through the
  map's (and the colour texture's) write port before the stream: N' at the poles, at
  90 degrees, at every quadrant's edge and random, random palette indices and RGB words;
* world N over the whole sphere and at its poles and quadrant edges (varying map); a flat
  map's polygon registers hold a tilted N' (every n'' term non-zero);
* for every light, L and H each drawn from a mix: the whole sphere (both signs of every dot
  product), theta at or next to 0 and 180 degrees, phi next to 0 / 360, and directions
  within a few degrees of the bumped normal N'' and of -N'' (N''.L and N''.H near +-1,
  where cos^n is steepest) and of its tangent plane (N''.L near 0: the clamp's edge);
* (exact method) 28 pixels whose positive dot products sit within 2 LSBs of their rounding
  carry (the nearest of CARRY_POOL random pixels), with a varying map their N' written into
  the map, with a flat map searched over the lights alone (N and N' the polygon's), every
  light given the same L and H there (each light's illumination unit its own carries): a
  wrong low bit of a product moves the dot, which random pixels show about once in ten
  thousand;
* (exact method) the table-sensitivity pixels, after the ``n`` others: a wrong low bit of a
  quarter-wave sine/cosine ROM word moves a dot product by a fraction of an LSB, which a
  rendered frame practically never shows. Every ROM read the golden rotation makes
  (sim/golden/fixed/exact.rotation_fixed, found through its TABLE_READ hook in call order;
  one read per light, or one for all lights where its angle is the same for every light:
  n'', computed once) is flipped in turn in each of its word's TABLE_BITS = 4 low bits (the
  word's magnitude as the ROM holds it, an error of 1 to 8 LSBs, + or - as the bit was clear
  or set, on a positive or negative sine as the angle's quadrant gives it), on TABLE_POOL =
  2^15 seeded random pixels (sim/golden/fixed/pipeline.random_inputs) through the memories
  as the host left them; of the pixels on which the flip changes some output, the frame
  keeps TABLE_QUOTA = 3 for each read, bit and value of that bit (fewer where the pool has
  fewer), chosen greedily so that one pixel serves every read it moves: about 60 pixels for
  the reads of two lights, fewer for the default scene's (whose unrounded outputs show
  most flips);
* (exact method, per-pixel shading) the dot-sensitivity pixels, after those: a wrong bit
  of a product or partial sum moves a dot's unrounded sum by 2^k, which a rendered frame
  shows only where the sum sits within 2^k of its rounding carry and the 8-bit shading is
  steep there. Each light's L and H sums of DOT_POOL = 2^18 seeded random pixels are
  recorded (sim/golden/fixed/exact.DOT_SUM); for every bit k up to the rounding point and
  either sign, the pixels whose rounded dot the move of 2^k changes (at most DOT_CAP of
  them) run with it, and the frame keeps DOT_QUOTA = 3 whose output changes (greedily, one
  pixel serving every move it shows; fewer where the pool has fewer). A wrong bit moves the sum
  up where the bit should be 0 and down where it should be 1 (or only while an operand is
  negative): each kept pixel shows it with even odds, so three a move leave about one
  chance in 64 that neither direction's pixels do;
* tags random over the whole tag range (0 and the largest tag included);
* the map's (and texture's) word 0 written with every bit a word may set and read back (the
  write ports idle at address 0 during the stream);
* a palette scene's colour table random, read from bank 1 with decoy tables around it
  (:meth:`CoverageFrame.setup`), and from each bank in turn in the runs after the first,
  a decoy in the other (:meth:`CoverageFrame.between`).

The golden outputs are sim/golden/fixed/pipeline.py's on the memories as the host left
them. Deterministic in ``seed``: make test's bulk pipeline test and the netlist mutants of
tests/mutants/netlist.py run the same frame (:data:`PIXELS`, :data:`SEED`).
"""

from dataclasses import dataclass

import numpy as np

from bumprtl.rtl.bumpfetch import (
    coord_bits,
    has_map,
    level_bases,
    level_bits,
    memory_depth,
    pack_texels,
)
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.layouts import light_keys
from bumprtl.rtl.palette import index_bits
from bumprtl.sim.golden.common import cartesian_to_polar, world_bump_normal
from bumprtl.sim.golden.fixed import exact
from bumprtl.sim.golden.fixed.common import angle_codes
from bumprtl.sim.golden.fixed.palette_lut import pack_rgba, palette_colors
from bumprtl.sim.golden.fixed.pipeline import (
    fetch_fixed,
    pipeline_fixed,
    polygon_fixed,
    random_inputs,
    unpack_texels,
)
from bumprtl.sim.tb.bulk_sources import rounding_codes
from bumprtl.sim.tb.bulk_wrapper import setup_writes

__all__ = ["PIXELS", "SEED", "CoverageFrame", "coverage_frame"]

PIXELS = 256                 # make test's frame (Icarus): as many pixels as the 16 x 16 frame
                             # (and the table-sensitivity pixels after them)
SEED = 1
WRITTEN = 32                 # map (and texture) words the host writes before the stream
TWO_PI = 2 * np.pi


@dataclass
class CoverageFrame:
    inputs: dict             # {field: int64 array}, the i__payload fields
    words: np.ndarray        # the map after the host's writes (None without one)
    texels: np.ndarray       # the colour texture after the host's writes (None without one)
    writes: list             # host cycles before the stream: map / texture words
    polygon: dict            # a flat map's polygon registers (None otherwise)
    table: np.ndarray        # a palette scene's colour table (None otherwise)
    decoys: list             # palette tables written around ``table`` (see :meth:`setup`)
    golden: dict             # {field: int64 array}: every output field the model gives

    def setup(self, meta):
        """The host cycles of the run (``meta``: the emitted pipeline's sidecar)."""
        cycles = list(self.writes)
        if not self.decoys:
            return cycles + setup_writes(meta, self.polygon, self.table)
        # palette: decoy, swap, decoy, swap, table, swap, decoy (front bank 0 after reset):
        # the table is read from bank 1, two swaps before it must each toggle the bank, the
        # last decoy must go to the back bank, and a write to bank 1 held back by a wrong
        # count of the pixels in flight loses the table
        first, second, last = self.decoys
        for t in (first, second, self.table):
            cycles += setup_writes(meta, None, t)
        cycles += setup_writes(meta, None, last)[:-1]          # written, not swapped in
        return cycles + setup_writes(meta, self.polygon, None)

    def between(self, meta):
        """The host cycles before every run but the first (run_bulk's ``between``). A
        palette scene's: the table written into the back bank and swapped in, then a decoy
        written behind it, so the runs read the table from bank 1, bank 0, bank 1, ... with
        the other bank holding a decoy (a pixel that reads the wrong bank shows it, in
        either direction). Nothing for other scenes."""
        if not self.decoys:
            return []
        return setup_writes(meta, None, self.table) + setup_writes(meta, None, self.decoys[-1])[:-1]

    def expected(self, meta):
        """The golden outputs of the pipeline's output fields, the tag included."""
        outs = meta.output_fields
        return {k: np.asarray(v, np.int64) for k, v in self.golden.items() if k in outs}


def _dirs(rng, n):
    """Uniform directions over the whole sphere: (phi, theta) radians."""
    return rng.uniform(0, TWO_PI, n), np.arccos(rng.uniform(-1, 1, n))


def _perpendicular(rng, axis):
    """Random unit vectors perpendicular to the unit vectors ``axis`` (n, 3)."""
    helper = np.where(np.abs(axis[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(axis, e1)
    turn = rng.uniform(0, TWO_PI, len(axis))[:, None]
    return np.cos(turn) * e1 + np.sin(turn) * e2


def _near(rng, axis, spread):
    """Unit vectors within ``spread`` radians of the unit vectors ``axis`` (n, 3): the
    angle uniform in [0, spread] (exactly 0 for about one in seven), its direction random."""
    n = len(axis)
    tilt = rng.uniform(0, spread, n)
    tilt[rng.random(n) < 0.15] = 0.0
    side = _perpendicular(rng, axis)
    return np.cos(tilt)[:, None] * axis + np.sin(tilt)[:, None] * side


def _codes(phi, theta, cfg):
    return angle_codes(phi, cfg).astype(np.int64), angle_codes(theta, cfg).astype(np.int64)


def _edge_angles(rng, n, cfg, theta_top):
    """Angle codes at the edges: theta at or next to 0 and ``theta_top``, phi at or next to
    0 / 360 and the quadrant boundaries."""
    full, q = cfg.full_circle, cfg.full_circle // 4
    thetas = np.array([0, 1, 2, q - 1, q, q + 1, theta_top - 2, theta_top - 1, theta_top])
    phis = np.array([0, 1, full - 1, full - 2, q - 1, q, 2 * q, 2 * q + 1, 3 * q, 3 * q - 1])
    return rng.choice(phis, n), rng.choice(thetas, n)


def _light(rng, n, cfg, axis):
    """L or H of one light for ``n`` pixels whose bumped normal is ``axis`` (world, (n, 3)):
    each pixel from one of six kinds (module docstring)."""
    full, half = cfg.full_circle, cfg.full_circle // 2
    kind = rng.integers(0, 6, n)
    phi, theta = _codes(*_dirs(rng, n), cfg)                              # 0: whole sphere
    e_phi, e_theta = _edge_angles(rng, n, cfg, half)                      # 1: poles, edges
    sign = np.where(rng.random(n) < 0.75, 1.0, -1.0)[:, None]
    steep = _codes(*cartesian_to_polar(sign * _near(rng, axis, 0.35)), cfg)      # 2: +-N''
    close = _codes(*cartesian_to_polar(sign * _near(rng, axis, 0.03)), cfg)      # 3: +-N''
    graze = _codes(*cartesian_to_polar(_near(rng, _perpendicular(rng, axis), 0.05)), cfg)  # 4
    w_phi = (rng.integers(-3, 4, n)) % full                                       # 5: phi wrap
    for k, (p, t) in enumerate([(e_phi, e_theta), steep, close, graze, (w_phi, theta)], 1):
        phi, theta = np.where(kind == k, p, phi), np.where(kind == k, t, theta)
    return phi, theta


def _texel_writes(scene, rng, words, texels):
    """``WRITTEN`` map addresses (over the whole memory), the words written there (N' at the
    edges of its range, or random palette indices) and random texture words."""
    cfg = scene.config
    depth = memory_depth(scene)
    # address 0 first, with every bit a word may set: the write ports idle at address 0,
    # data 0 during the stream, so a write enable that fires while idle clears it
    rest = rng.choice(np.arange(1, depth), min(WRITTEN, depth) - 1, replace=False)
    addr = np.concatenate([[0], rest])
    m = len(addr)
    new_words = new_texels = None
    if words is not None:
        if scene.shading == "palette":
            word = pack_texels(scene, index=rng.integers(0, 1 << index_bits(cfg), m))
            word[0] = (1 << index_bits(cfg)) - 1
        else:
            full, q = cfg.full_circle, cfg.full_circle // 4
            phi = rng.choice(np.array([0, 1, q - 1, q, 2 * q - 1, 2 * q, 3 * q, full - 1]), m)
            phi = np.where(rng.random(m) < 0.3, rng.integers(0, full, m), phi)
            theta = rng.choice(np.array([0, 1, q // 2, q - 2, q - 1, q]), m)
            theta = np.where(rng.random(m) < 0.3, rng.integers(0, q + 1, m), theta)
            phi[0], theta[0] = full - 1, q - 1
            word = pack_texels(scene, phi=phi, theta=theta)
        new_words = np.asarray(words, np.int64).copy()
        new_words[addr] = word
    if texels is not None:
        new_texels = np.asarray(texels, np.int64).copy()
        new_texels[addr] = np.concatenate([[(1 << 24) - 1], rng.integers(0, 1 << 24, m - 1)])
    writes = []
    for _k, a in enumerate(addr.tolist()):
        cycle = {}
        if new_words is not None:
            cycle.update({"map_w_en": 1, "map_w_addr": a, "map_w_data": int(new_words[a])})
        if new_texels is not None:
            cycle.update({"tex_w_en": 1, "tex_w_addr": a, "tex_w_data": int(new_texels[a])})
        writes.append(cycle)
    return addr, new_words, new_texels, writes


def _address_coords(scene, addr, rng):
    """Level-0 texel coordinates (u, v) and the level that read word ``addr``."""
    bases = level_bases(scene)
    level = np.searchsorted(bases, addr, side="right") - 1
    size = scene.texture_size >> level                # the level's width: rows of it
    local = addr - np.asarray(bases)[level]
    u, v = (local % size) << level, (local // size) << level
    u = u + rng.integers(0, 1 << level)           # the dropped low bits of floor(u / 2**l)
    v = v + rng.integers(0, 1 << level)
    if scene.addressing == "wrap":                # a map width (height) further, either side
        u = u + scene.texture_size * rng.integers(-2, 2, len(u))
        v = v + scene.map_height * rng.integers(-2, 2, len(v))
    return u, v, level


def _texel_inputs(scene, n, rng, words, addr):
    """u, v (and level) of ``n`` pixels: the whole port range, the written words, the
    scene's steepest and flattest texels (level 0)."""
    half = 1 << (coord_bits(scene) - 1)
    out = {"u": rng.integers(-half, half, n), "v": rng.integers(-half, half, n)}
    lb = level_bits(scene)
    level = rng.integers(0, 1 << lb, n) if lb else np.zeros(n, np.int64)
    kind = np.arange(n) % 3
    pick = np.nonzero(kind == 1)[0]
    wu, wv, wl = _address_coords(scene, addr[np.arange(len(pick)) % len(addr)], rng)
    out["u"][pick], out["v"][pick], level[pick] = wu, wv, wl
    pick = np.nonzero(kind == 2)[0]
    if len(pick) and words is not None and scene.shading != "palette":
        t, n0 = scene.texture_size, scene.texture_size * scene.map_height     # level 0
        theta = (np.asarray(words[:n0], np.int64) >> scene.angle_bits)
        order = np.argsort(theta, kind="stable")
        ends = np.concatenate([order[::-1][:(len(pick) + 1) // 2], order[:len(pick) // 2]])
        out["u"][pick], out["v"][pick], level[pick] = ends % t, ends // t, 0
    elif len(pick) and words is not None:        # palette: every index the map holds
        t, n0 = scene.texture_size, scene.texture_size * scene.map_height
        first = np.unique(np.asarray(words[:n0]), return_index=True)[1]
        texel = rng.choice(first, len(pick), replace=len(first) < len(pick))
        out["u"][pick], out["v"][pick], level[pick] = texel % t, texel // t, 0
    if lb:
        out["level"] = level
    return out


# Random pixels searched for the rounding carries of the frame: the sum has 2**(B + 3)
# residues (2**18 at the default), so 2**20 pixels put the 14 nearest a carry within a
# couple of LSBs of it, where a wrong bit 0 of a product (one LSB of the sum) moves the dot.
CARRY_POOL = 1 << 20
CARRY_PIXELS = 14            # kept a dot product (positive dots only)


def _near_carry(scene, seed, fixed=None):
    """Angle codes (N, N', L, H of light 0) of a few pixels whose exact-method dot products
    sit within a few LSBs of their rounding carry (sim/tb/bulk_sources.py's rounding_codes
    over CARRY_POOL pixels), or None (another method or palette shading): a wrong low bit of
    a product moves their dot. ``fixed``: a flat map's N and N' codes (its polygon's), the
    search then over the lights alone."""
    if scene.shading != "per-pixel" or (scene.bump_map != "varying" and fixed is None):
        return None
    return rounding_codes(scene.config, seed, pool=CARRY_POOL, count=CARRY_PIXELS, lit=True,
                          fixed=fixed)


# The table-sensitivity pixels: random pixels searched (a flipped bit 0 of one read's word
# changes an output on a small fraction of random pixels, so the pool must be large enough to
# find a few for nearly every read; one golden run of the pool per read and bit), the
# low bits of a word flipped (errors of 1 to 8 LSBs) and the pixels kept for each read, bit and
# value of that bit.
TABLE_POOL = 1 << 15
TABLE_BITS = 4
TABLE_QUOTA = 3


class _TableReads:
    """The hook of sim/golden/fixed/exact.rotation_fixed (TABLE_READ): records every
    quarter-wave ROM read of a golden run, or flips bit ``bit`` of one read's word."""

    def __init__(self, cfg):
        self.cfg, self.site, self.bit, self.calls = cfg, None, 0, []

    def __call__(self, k, angle, value):
        if k == 0:
            self.calls.append([])
        if self.site is None:                 # recording
            angle = np.asarray(angle, np.int64) & (self.cfg.full_circle - 1)
            self.calls[-1].append((angle, np.abs(np.asarray(value, np.int64))))
            return value
        light, read = self.site
        if k != read or light not in (None, len(self.calls) - 1):
            return value
        word = np.abs(np.asarray(value, np.int64)) ^ (1 << self.bit)   # the ROM word, unsigned
        negative = (np.asarray(angle) & (self.cfg.full_circle - 1)) >> self.cfg.k >= 2
        return np.where(negative, -word, word)                         # quadrants 2, 3

    def run(self, fn, site=None, bit=0):
        saved, exact.TABLE_READ = exact.TABLE_READ, self
        self.site, self.bit, self.calls = site, bit, []
        try:
            return fn()
        finally:
            exact.TABLE_READ = saved


def _table_sensitive(scene, words, polygon, texels, seed, keys):
    """Inputs (``keys``) of the table-sensitivity pixels of ``scene`` (module docstring), or
    None (no quarter-wave ROM read in its golden model: palette shading, another method).

    Every ROM read of the golden rotation (sim/golden/fixed/exact.rotation_fixed, through its
    TABLE_READ hook) is a site: one per light, or one for all lights when its angle is the
    same for every light on every pixel of the pool (n'', which the pipeline computes once).
    For each site and each of its word's TABLE_BITS low bits, the pool's pixels on which
    flipping that bit of the word (as the RTL reads it, the magnitude; its sign from the
    quadrant) changes some output; from those, greedily (fewest pixels, ties in a seeded random
    order), TABLE_QUOTA pixels whose word has the bit clear and TABLE_QUOTA with it set (an
    error of +2**b and of -2**b)."""
    cfg = scene.config
    rng = np.random.default_rng([seed, TABLE_POOL, 2])
    pool = random_inputs(scene, TABLE_POOL, rng)
    golden = lambda: pipeline_fixed(pool, scene, words, polygon, texels)
    hook = _TableReads(cfg)
    base = hook.run(golden)
    calls = hook.calls
    if not calls:
        return None
    shared = [all(np.array_equal(calls[0][k][0], c[k][0]) for c in calls) for k in range(len(calls[0]))]
    sites = [(None, k) for k, one in enumerate(shared) if one]
    sites += [(j, k) for j in range(len(calls)) for k, one in enumerate(shared) if not one]
    groups = []                       # per site, bit and bit value: its sensitive pixels
    for light, k in sites:
        word = calls[light or 0][k][1]
        for b in range(TABLE_BITS):
            out = hook.run(golden, (light, k), b)
            moved = np.zeros(TABLE_POOL, bool)
            for key, want in base.items():
                moved |= np.asarray(out[key]) != np.asarray(want)
            for value in (0, 1):
                groups.append(moved & ((word >> b) & 1 == value))
    cover = np.stack(groups, axis=1)
    cand = np.nonzero(cover.any(axis=1))[0]
    cand = cand[rng.permutation(len(cand))]          # ties go to a seeded random pixel
    pick = np.sort(cand[_greedy_cover(cover[cand], TABLE_QUOTA)])
    assert set(keys) == set(pool) - {"tag"}, (sorted(keys), sorted(pool))
    return {key: pool[key][pick] for key in keys}


def _greedy_cover(cover, quota):
    """Rows of the boolean matrix ``cover`` (candidate pixels x places: a read's bit, a
    dot's move) picked greedily until every place holds ``quota`` of its pixels, or all it
    has: each time the row that fills most unfilled places, the first such row on a tie."""
    cover = cover.astype(np.int32)
    need, pick = np.minimum(cover.sum(axis=0), quota), []
    while need.any():
        best = int(np.argmax(cover @ (need > 0)))
        pick.append(best)
        need = np.maximum(need - cover[best], 0)
        cover[best] = 0
    return np.asarray(pick, np.int64)


# The dot-sensitivity pixels: a wrong bit k of a product or of a partial sum moves a dot's
# unrounded sum by 2**k, which changes the rounded dot only where the sum sits within 2**k of
# its rounding carry, and an 8-bit output only where the shading is steep there too: for
# k below the rounding point random pixels almost never show it. The sums of DOT_POOL seeded
# random pixels are recorded (sim/golden/fixed/exact.DOT_SUM), and for each light, vector
# (L, H), bit k below the rounding point plus the next one and sign, the pixels whose rounded
# dot the move changes (at most DOT_CAP of them, a seeded choice) are run with it; the frame
# keeps DOT_QUOTA of those whose output changes. A mutant's move of 2**k has the sign of the
# bit it breaks (or exists only for one sign of an operand), which the search does not know:
# each kept pixel shows it with even odds, so one a move missed a quarter of them.
DOT_POOL = 1 << 18
DOT_CAP = 2048
DOT_QUOTA = 3


class _DotSums:
    """The hook of sim/golden/fixed/exact.dot_fixed (DOT_SUM): records each light's L and H
    sums of a golden run, or adds ``delta`` to one of them."""

    def __init__(self):
        self.site, self.delta, self.light, self.sums = None, 0, -1, {}

    def __call__(self, v, acc):
        if v == "l":
            self.light += 1
        if self.site is None:
            self.sums[(self.light, v)] = np.array(acc, np.int64)
        elif self.site == (self.light, v):
            return acc + self.delta
        return acc

    def run(self, fn, site=None, delta=0):
        saved, exact.DOT_SUM = exact.DOT_SUM, self
        self.site, self.delta, self.light = site, delta, -1
        try:
            return fn()
        finally:
            exact.DOT_SUM = saved


def _dot_sensitive(scene, words, polygon, texels, seed, keys):
    """Inputs (``keys``) of the dot-sensitivity pixels of ``scene`` (see DOT_POOL), or None
    (no exact-method dot product in its golden model: palette shading, another method)."""
    cfg = scene.config
    if scene.shading != "per-pixel" or cfg.method != "exact":
        return None
    rng = np.random.default_rng([seed, DOT_POOL, 3])
    pool = random_inputs(scene, DOT_POOL, rng)
    golden = lambda px: (lambda: pipeline_fixed(px, scene, words, polygon, texels))
    hook = _DotSums()
    base = hook.run(golden(pool))
    shift = cfg.frac_bits + 3
    groups = []                     # per light, vector, bit and sign: its sensitive pixels
    for site, acc in sorted(hook.sums.items()):
        dot = round_shift(acc, shift)
        for k in range(shift + 1):
            for delta in (1 << k, -(1 << k)):
                cand = np.nonzero(round_shift(acc + delta, shift) != dot)[0]
                if len(cand) > DOT_CAP:
                    cand = np.sort(rng.choice(cand, DOT_CAP, replace=False))
                out = hook.run(golden({key: v[cand] for key, v in pool.items()}), site, delta)
                moved = np.zeros(len(cand), bool)
                for key, want in base.items():
                    moved |= np.asarray(out[key]) != np.asarray(want)[cand]
                groups.append(cand[moved])
    cand = np.unique(np.concatenate(groups))          # ascending: ties go to the lowest pixel
    cover = np.stack([np.isin(cand, g) for g in groups], axis=1)
    pick = np.sort(cand[_greedy_cover(cover, DOT_QUOTA)])
    assert set(keys) == set(pool) - {"tag"}, (sorted(keys), sorted(pool))
    return {key: pool[key][pick] for key in keys}


def _world_normal(n_phi, n_theta, b_phi, b_theta, cfg):
    """The bumped normal N'' in the world (n, 3) from the angle codes."""
    rad = lambda c: np.asarray(c, np.float64) * (TWO_PI / cfg.full_circle)
    return world_bump_normal(rad(n_phi), rad(n_theta), rad(b_phi), rad(b_theta))


def coverage_frame(scene, words, texels, n=PIXELS, seed=SEED):
    """The coverage frame of ``scene``'s pipeline emitted with map ``words`` and colour
    texture ``texels`` (as gen/render/rtl.scene_stimulus gives them; None without one):
    ``n`` pixels, then the table-sensitivity and the dot-sensitivity pixels (none for
    palette shading)."""
    cfg = scene.config
    rng = np.random.default_rng([seed, n])
    inputs, writes, polygon, table, decoys = {}, [], None, None, []
    addr = near = slots = None
    if has_map(scene) or scene.texture:
        addr, words, texels, writes = _texel_writes(scene, rng, words, texels)
        near = _near_carry(scene, seed)
        if near is not None:            # their N' in the written words after word 0
            slots = addr[1:1 + len(near["b.phi"])]
            words[slots] = pack_texels(scene, phi=near["b.phi"], theta=near["b.theta"])
            for k, a in enumerate(slots.tolist(), 1):
                writes[k]["map_w_data"] = int(words[a])
        inputs.update(_texel_inputs(scene, n, rng, words, addr))
    if scene.shading == "palette":
        top = cfg.palette_size
        decoys = [pack_rgba(rng.integers(0, 256, (top, 4)), cfg) for _ in range(3)]
        table = pack_rgba(rng.integers(0, 256, (top, 4)), cfg)
    else:
        if scene.bump_map == "varying":
            fetched = unpack_texels(fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"),
                                                words, scene), scene)
            n_phi, n_theta = _codes(*_dirs(rng, n), cfg)
            e_phi, e_theta = _edge_angles(rng, n, cfg, cfg.full_circle // 2)
            edge = rng.random(n) < 0.4
            n_phi, n_theta = np.where(edge, e_phi, n_phi), np.where(edge, e_theta, n_theta)
            inputs["n.phi"], inputs["n.theta"] = n_phi, n_theta
            b_phi, b_theta = fetched["b.phi"], fetched["b.theta"]
        else:                       # a plane facing +z with a tilted N' in its registers
            q = cfg.full_circle // 4
            n_phi = np.full(n, int(rng.integers(0, cfg.full_circle)))
            n_theta = np.zeros(n, np.int64)
            b_phi = np.full(n, int(rng.integers(0, cfg.full_circle)))
            b_theta = np.full(n, int(rng.integers(q // 3, 2 * q // 3)))
            polygon = polygon_fixed(n_phi[0], 0, b_phi[0], b_theta[0], scene)
            # its pixels next to a rounding carry: the search over the lights alone
            near = _near_carry(scene, seed, {"n.phi": n_phi[0], "n.theta": 0,
                                             "b.phi": b_phi[0], "b.theta": b_theta[0]})
        axis = _world_normal(n_phi, n_theta, b_phi, b_theta, cfg)
        for keys in light_keys(cfg):
            for own, key in keys.items():
                if own.endswith(".phi"):
                    inputs[key], inputs[keys[own[:-4] + ".theta"]] = _light(rng, n, cfg, axis)
    if near is not None:            # the pixels next to a rounding carry
        pick = np.nonzero(np.arange(n) % 3 == 0)[0][:len(near["l.phi"] if slots is None else slots)]
        if slots is not None:       # a varying map: N and the texel of the N' written
            u, v, level = _address_coords(scene, slots[:len(pick)], rng)
            inputs["u"][pick], inputs["v"][pick] = u, v
            if "level" in inputs:
                inputs["level"][pick] = level
            for key in ("n.phi", "n.theta"):
                inputs[key][pick] = near[key][:len(pick)]
        for keys in light_keys(cfg):                    # every light the same L and H
            for own, key in keys.items():
                inputs[key][pick] = near[own][:len(pick)]
    for extra in (_table_sensitive(scene, words, polygon, texels, seed, list(inputs)),
                  _dot_sensitive(scene, words, polygon, texels, seed, list(inputs))):
        if extra is not None:       # after the frame's own pixels
            inputs = {k: np.concatenate([np.asarray(v, np.int64), extra[k]]) for k, v in inputs.items()}
            n += len(next(iter(extra.values())))
    mask = (1 << scene.tag_bits) - 1
    tag = rng.integers(0, mask + 1, n)
    tag[:2] = (0, mask)
    inputs["tag"] = tag
    inputs = {k: np.asarray(v, np.int64) for k, v in inputs.items()}
    golden = pipeline_fixed(inputs, scene, words, polygon, texels)
    if scene.shading == "palette":
        golden = {**golden, **palette_colors(golden, table, scene)}
    golden = {k: np.asarray(v, np.int64) for k, v in golden.items()}
    golden["tag"] = inputs["tag"]
    return CoverageFrame(inputs, words, texels, writes, polygon, table, decoys, golden)
