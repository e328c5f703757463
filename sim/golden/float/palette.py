"""The palette method of Tarini et al. (quantized normal maps), float64 golden model.

Preprocessing (once per map): displacement -> normal map by a least-squares plane fit
(Sec. 4.1), quantization to ``sN`` normals (Sec. 4, :mod:`.palette_quantize`), optionally
dithered, giving an index map and a normal table; mipmaps of index maps (Sec. 5.2).
Per frame: shade the ``sN`` table normals into a colour table (Sec. 5.1, several lighting
models, materials of Sec. 6); per pixel only a table lookup remains. Colour tables are
stored with ``cfg.color_bits`` per channel, RGBA: RGB the colour, alpha the Lambert
intensity that the blending equations of Sec. 7 need (:mod:`.palette_lut`).

Directions are world (object) space unit vectors. Light and viewer are at infinity and
constant over the object for one frame (Sec. 5.1, Sec. 9: "both light position and view
position are considered to be constant all over the object").
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.common import (
    Result,
    cartesian_to_polar,
    polar_to_cartesian,
    shade,
    tangent_rotation,
    to_8bit,
)
from bumprtl.sim.golden.float.palette_quantize import (
    QUANTIZERS,
    bayer_offsets,
    check_palette_size,
    distinct,
    nearest,
    stores_every_normal,
)

__all__ = ["LIGHTING_MODELS", "Material", "QuantizedNormalMap", "displacement_to_normals",
           "check_normal_map", "quantize_normal_map", "mipmap_indices", "lookup",
           "color_table", "world_normal_map", "distinct_normals", "render_palette", "palette_rgb"]

LIGHTING_MODELS = ("lambert", "phong", "chrome", "toon")
MATERIAL_SCALE = 4.0     # > 2 = the sphere's diameter: a material step outweighs any normal
CROSS = ((0, 0), (0, 1), (0, -1), (1, 0), (-1, 0))     # t and its q = 4 neighbours (Sec. 4.1)


def displacement_to_normals(height, scale=1.0, offsets=CROSS):
    """Sec. 4.1: per texel, the plane ``a . (x, y, 1) = z`` fitted by least squares to the
    (scaled) displacements of the texel and its neighbours ``offsets`` (row, col; wrapping);
    the normal is ``normalize(-a0, -a1, 1)``. x runs along rows (tangent x = d/dv) and y
    along columns, the convention of :mod:`bumprtl.sim.scenes`. Returns ``(H, W, 3)`` for
    an ``(H, W)`` map (square or not: the fit wraps each axis by its own length)."""
    h = np.asarray(height, dtype=np.float64)
    if h.ndim != 2 or h.size == 0:
        raise BumpError(f"height must be a non-empty 2-D map, got shape {h.shape}")
    if not np.all(np.isfinite(h)):
        raise BumpError("height contains NaN or infinity")
    x = np.array([[dr, dc, 1.0] for dr, dc in offsets])
    solve = np.linalg.pinv(x)                  # (3, q+1): a = pinv(X) d, the LMS solution
    d = np.stack([scale * np.roll(h, (-dr, -dc), axis=(0, 1)) for dr, dc in offsets], -1)
    a = d @ solve.T
    n = np.stack([-a[..., 0], -a[..., 1], np.ones_like(h)], -1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def check_normal_map(normals, name="normals"):
    """A non-empty square ``(T, T, 3)`` map of finite, non-zero vectors -> unit vectors."""
    n = np.asarray(normals, dtype=np.float64)
    if n.ndim != 3 or n.shape[2] != 3 or n.shape[0] != n.shape[1] or n.shape[0] == 0:
        raise BumpError(f"{name} must be a non-empty square (T, T, 3) map, got shape {n.shape}")
    if not np.all(np.isfinite(n)):
        raise BumpError(f"{name} contains NaN or infinity")
    length = np.linalg.norm(n, axis=-1)
    if np.any(length < 1e-12):
        r, c = np.argwhere(length < 1e-12)[0]
        raise BumpError(f"{name} has a zero-length normal at texel ({r}, {c})")
    return n / length[..., None]


@dataclass(frozen=True)
class QuantizedNormalMap:
    """``indices (T, T)`` into ``table (sN, 3)``; with materials, ``materials (sN,)`` gives
    each entry's material and the table is sorted by material (Sec. 6). ``distinct``: the
    number of distinct (normal, material) vectors the used texels had; when the palette
    size was at least that, ``exact`` is True and the table is those vectors themselves
    (fewer rows than the palette size: the rest of a hardware table is unused)."""
    indices: np.ndarray
    table: np.ndarray
    materials: np.ndarray | None = None
    distinct: int | None = None
    exact: bool = False

    @property
    def size(self):
        return len(self.table)


def _vectors(normals, materials):
    if materials is None:
        return normals
    m = np.asarray(materials)
    if m.shape != normals.shape[:2] or m.dtype.kind not in "iu" or m.min() < 0:
        raise BumpError(f"materials must be a (T, T) map of non-negative integers like the "
                        f"normals, got shape {m.shape} dtype {m.dtype}")
    return np.concatenate([normals, MATERIAL_SCALE * m[..., None].astype(np.float64)], -1)


def _dithered(vectors, table):
    """Ordered dithering (Sec. 4, Fig. 4): move each normal by a Bayer offset scaled by the
    spacing of the table around its nearest entry, then re-pick the nearest entry."""
    flat = vectors.reshape(-1, vectors.shape[-1])
    idx = nearest(flat, table)
    spacing = nearest_spacing(table)[idx].reshape(vectors.shape[:2] + (1,))
    moved = vectors.copy()
    moved[..., :3] += spacing * bayer_offsets(vectors.shape[:2])
    moved[..., :3] /= np.linalg.norm(moved[..., :3], axis=-1, keepdims=True)
    return nearest(moved.reshape(flat.shape), table)


def nearest_spacing(table):
    """Distance from every table entry to its nearest other entry (the local cell size)."""
    dist, _ = cKDTree(table).query(table, k=2)
    return dist[:, 1]


def quantize_normal_map(normals, palette_size, quantizer="median-cut", dither=False,
                        weights=None, materials=None, seed=0):
    """Sec. 4: replace each normal of a ``(T, T, 3)`` map by the index of one of
    ``palette_size`` representatives. ``weights (T, T)``: texel use counts (0 = unused,
    does not shape the table but still gets an index); ``materials (T, T)``: Sec. 6.
    A ``palette_size`` at least the number of distinct normals of the used texels is valid
    and exact: the table is those normals (``exact`` = True, ``len(table)`` = their number),
    each used texel indexes its own normal, and dithering is not applied."""
    if quantizer not in QUANTIZERS:
        raise BumpError(f"quantizer must be one of {', '.join(QUANTIZERS)}, got {quantizer!r}")
    n = check_normal_map(normals)
    vectors = _vectors(n, materials)
    w = None if weights is None else np.asarray(weights, dtype=np.float64).ravel()
    points, counts = distinct(vectors.reshape(-1, vectors.shape[-1]), w)
    check_palette_size(palette_size)
    exact = stores_every_normal(palette_size, len(points))
    if exact:       # every distinct vector its own entry: the table is the vectors, unchanged
        table = points
    else:
        kwargs = {"seed": seed} if quantizer == "kmeans" else {}
        table = QUANTIZERS[quantizer](points, counts, palette_size, **kwargs)
    if materials is not None:     # Sec. 6: sort by material, keep only the intervals
        table = table[np.lexsort((np.arange(len(table)), table[:, 3]))]
    flat = vectors.reshape(-1, vectors.shape[-1])
    idx = _dithered(vectors, table) if dither and not exact else nearest(flat, table)
    mats = None if materials is None else np.rint(table[:, 3] / MATERIAL_SCALE).astype(np.int64)
    return QuantizedNormalMap(idx.reshape(n.shape[:2]), table[:, :3].copy(), mats, len(points), exact)


def mipmap_indices(qmap: QuantizedNormalMap):
    """Sec. 5.2: index maps cannot be averaged; level ``k+1`` holds, per 2x2 block, the
    index of the table normal nearest to the (renormalized) mean of the four normals.
    Returns ``[level0, level1, ...]`` down to 1x1 (or to the first odd size)."""
    table = qmap.table if qmap.materials is None else \
        np.concatenate([qmap.table, MATERIAL_SCALE * qmap.materials[:, None]], -1)
    levels = [qmap.indices]
    while levels[-1].shape[0] > 1 and levels[-1].shape[0] % 2 == 0:
        t = levels[-1].shape[0] // 2
        mean = table[levels[-1]].reshape(t, 2, t, 2, -1).mean(axis=(1, 3))
        mean[..., :3] /= np.maximum(np.linalg.norm(mean[..., :3], axis=-1, keepdims=True), 1e-12)
        levels.append(nearest(mean.reshape(-1, table.shape[1]), table).reshape(t, t))
    return levels


def lookup(indices, table):
    """Per-pixel table lookup (step 2 of Sec. 5); an index outside the table is an error."""
    idx = np.asarray(indices)
    if idx.dtype.kind not in "iu":
        raise BumpError(f"indices must be integers, got dtype {idx.dtype}")
    if idx.size and (idx.min() < 0 or idx.max() >= len(table)):
        bad = idx.min() if idx.min() < 0 else idx.max()
        raise BumpError(f"index {bad} is outside the table: allowed [0, {len(table) - 1}]")
    return np.asarray(table)[idx]


@dataclass(frozen=True)
class Material:
    """Per-material lighting parameters (Sec. 6) and base colour (Sec. 7.3)."""
    ka: float = 0.1
    kd: float = 0.7
    ks: float = 0.2
    spec_exponent: int = 16
    color: tuple = (1.0, 1.0, 1.0)

    @classmethod
    def from_config(cls, cfg: Config):
        return cls(cfg.ka, cfg.kd, cfg.ks if cfg.specular else 0.0, cfg.spec_exponent)


def _unit(v):
    v = np.atleast_2d(np.asarray(v, dtype=np.float64))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _phong(normals, lights, view, mat: Material):
    """Lambert intensity (ambient + diffuse, every light) and specular sum (Sec. 5.1 items
    1-2, eq. 2 of Lee et al. per light: H = normalize(L + V))."""
    nl = normals @ lights.T                                  # (sN, lights)
    nh = normals @ _unit(lights + view).T
    lambert = mat.ka + mat.kd * np.clip(nl, 0, 1).sum(-1)
    spec = mat.ks * (np.clip(nh, 0, 1) ** mat.spec_exponent).sum(-1)
    return lambert, spec


def _environment(r):
    """A landscape for the chrome effect (Fig. 7: brown below, blue above the horizon);
    world z is up."""
    z = r[:, 2:3]
    sky = np.array([0.35, 0.55, 0.95]) + (1 - z) * np.array([0.4, 0.3, 0.05])
    ground = np.array([0.45, 0.3, 0.15]) * (1 + z)
    return np.where(z >= 0, sky, ground)


def _shade_rgb(normals, model, lights, view, mat: Material):
    """RGB of one material's table entries and their Lambert intensity (alpha)."""
    lambert, spec = _phong(normals, lights, view, mat)
    base = np.asarray(mat.color, dtype=np.float64)
    if model == "lambert":
        rgb = lambert[:, None] * base
    elif model == "phong":
        rgb = lambert[:, None] * base + spec[:, None]
    elif model == "chrome":                   # Sec. 5.1 item 6: reflect V about N
        r = 2 * (normals @ view.T) * normals - view
        rgb = _environment(r) * base
    else:                                     # toon (item 4): 3 bands and a hard highlight
        bands = np.digitize(np.clip(lambert, 0, 1), [0.35, 0.65]) / 2 * 0.7 + 0.2
        rgb = np.where(spec[:, None] > 0.5 * mat.ks, 1.0, bands[:, None] * base)
    return np.clip(rgb, 0, 1), np.clip(lambert, 0, 1)


def color_table(table, model, lights, view, cfg: Config = Config(), materials=None,
                material_params=None, blend=False):
    """Sec. 5.1: the colour table C of one frame, ``(sN, 4)`` floats in [0, 1].

    ``lights (k, 3)`` and ``view (3,)`` are unit vectors toward light and viewer.
    RGBA = colour, Lambert intensity. ``blend=True`` gives the layout of Sec. 7.1/7.2:
    alpha the Lambert intensity, RGB the specular colour only. ``materials (sN,)`` with
    ``material_params`` (one :class:`Material` per id) shades each interval with its own
    parameters (Sec. 6, Sec. 7.3 colour as material); else every entry uses ``cfg``.
    """
    if model not in LIGHTING_MODELS:
        raise BumpError(f"lighting must be one of {', '.join(LIGHTING_MODELS)}, got {model!r}")
    normals, lights, view = _unit(table), _unit(lights), _unit(view)
    mats = np.zeros(len(normals), np.int64) if materials is None else np.asarray(materials)
    params = [Material.from_config(cfg)] if material_params is None else list(material_params)
    if mats.max() >= len(params):
        raise BumpError(f"material {mats.max()} has no parameters: allowed [0, {len(params) - 1}]")
    out = np.zeros((len(normals), 4))
    for m in np.unique(mats):
        sel = mats == m
        if blend:
            lambert, spec = _phong(normals[sel], lights, view, params[m])
            rgb, alpha = np.repeat(np.clip(spec, 0, 1)[:, None], 3, 1), np.clip(lambert, 0, 1)
        else:
            rgb, alpha = _shade_rgb(normals[sel], model, lights, view, params[m])
        out[sel] = np.concatenate([rgb, alpha[:, None]], -1)
    return out


def world_normal_map(scene):
    """Object-space normal map of a scene: per pixel the tangent-space N' turned to world by
    the inverse tangent rotation of the pixel's N (M^T N'), averaged per texel. Returns
    ``(normals (T, T, 3), counts (T, T))``; texels no pixel uses get N' turned by the mean
    frame and count 0 (they get an index but do not shape the table)."""
    px, t = scene.px, scene.texture_size
    mask = scene.mask
    m = tangent_rotation(px.n_phi[mask], px.n_theta[mask])
    world = np.einsum("pji,pj->pi", m, polar_to_cartesian(px.b_phi[mask], px.b_theta[mask]))
    flat = (scene.v * t + scene.u)[mask]
    counts = np.bincount(flat, minlength=t * t)
    sums = np.stack([np.bincount(flat, weights=world[:, d], minlength=t * t) for d in range(3)], -1)
    n_mean = _unit(polar_to_cartesian(px.n_phi[mask], px.n_theta[mask]).mean(0))[0]
    mean_frame = tangent_rotation(*cartesian_to_polar(n_mean))
    fallback = polar_to_cartesian(scene.b_phi_map, scene.b_theta_map) @ mean_frame
    normals = np.where(counts.reshape(t, t)[..., None] > 0, sums.reshape(t, t, 3), fallback)
    return normals, counts.reshape(t, t)


def distinct_normals(scene):
    """Number of distinct object-space normals among the texels some pixel of ``scene`` uses:
    the palette size from which on :func:`quantize_normal_map` stores every normal."""
    normals, counts = world_normal_map(scene)
    return len(distinct(check_normal_map(normals).reshape(-1, 3), counts.ravel())[0])


def frame_directions(scene):
    """The per-frame light and view of a scene: L and H averaged over the covered pixels
    (exact for directional light), V the reflection of L about H."""
    px, mask = scene.px, scene.mask
    l = _unit(polar_to_cartesian(px.l_phi[mask], px.l_theta[mask]).mean(0))
    h = _unit(polar_to_cartesian(px.h_phi[mask], px.h_theta[mask]).mean(0))
    return l, _unit(2 * (l @ h.T) * h - l)


def palette_rgb(scene, cfg: Config = Config(), palette_size=None, quantizer="median-cut",
                lighting="phong", dither=False, qmap=None):
    """Per-pixel RGB (float, from the 8-bit colour table) and the quantized map used."""
    if qmap is None:
        normals, counts = world_normal_map(scene)
        qmap = quantize_normal_map(normals, cfg.palette_size if palette_size is None else palette_size,
                                   quantizer, dither, weights=counts)
    l, v = frame_directions(scene)
    table8 = to_8bit(color_table(qmap.table, lighting, l, v, cfg))
    idx = qmap.indices[scene.v, scene.u]
    return lookup(idx, table8)[..., :3] / 255.0, qmap


def render_palette(scene, cfg: Config = Config(), palette_size=None, quantizer="median-cut",
                   lighting="phong", dither=False):
    """Render ``scene`` by the palette method; ``Result.color`` is the per-pixel intensity
    (mean of the 8-bit table's RGB), ndotl/ndoth those of the palette normals."""
    rgb, qmap = palette_rgb(scene, cfg, palette_size, quantizer, lighting, dither)
    l, v = frame_directions(scene)
    n = qmap.table[qmap.indices[scene.v, scene.u]]
    ndotl, ndoth = n @ l[0], n @ _unit(l + v)[0]
    ref = shade(ndotl, ndoth, cfg)
    return Result(ndotl, ndoth, ref.diffuse, ref.specular, rgb.mean(-1))
