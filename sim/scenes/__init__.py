"""Scenes: height fields -> tangent-space bump maps, geometry, lights and viewer.

World frame: x to the right of the screen, z up the screen, the viewer looks along +y from
far away (orthographic), so V = (0, -1, 0). The tangent frame is the one Lee et al.'s two
rotations define (rotate -phi_N about z, then -theta_N about y): its x axis T points along
increasing theta_N and its y axis B along increasing phi_N. Every geometry maps texture
``v`` along T and ``u`` along B, so a bump map built with tangent x = d/dv and
tangent y = d/du lights the same way on every surface.
"""

from dataclasses import dataclass

import numpy as np

from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.common import PixelInputs, cartesian_to_polar
from bumprtl.sim.scenes.heightfields import HEIGHTFIELDS, height_to_normals, resize_field

__all__ = ["SCENES", "GEOMETRIES", "REFERENCE_TEXTURE_SIZE", "Scene", "load_scene",
           "light_direction", "bump_strength", "texel_coordinates"]

GEOMETRIES = ("plane", "sphere", "cylinder")
# The map size the scenes' bump strengths were chosen at (the render default). A larger map
# of the same scene keeps the same slopes: heights are scaled by T / 512 (bump_strength).
REFERENCE_TEXTURE_SIZE = 512

# name -> (height field, geometry, bump strength: texels of relief for height 1.0 at maps up
# to REFERENCE_TEXTURE_SIZE, description)
SCENES = {
    "bricks": ("bricks", "plane", 6.0, "procedural brick wall on a plane (the default)"),
    "wood": ("wood", "plane", 3.0, "wood-grain rings on a plane (like the paper's Fig. 9)"),
    "bumps": ("bumps", "plane", 4.0, "sinusoidal bumps on a plane"),
    "text": ("text", "plane", 6.0, "engraved text on a plane"),
    "brick-photo": ("brick", "plane", 4.0, "scikit-image brick photograph as a height field"),
    "gravel": ("gravel", "plane", 4.0, "scikit-image gravel photograph as a height field"),
    "moon": ("moon", "plane", 4.0, "scikit-image moon photograph as a height field"),
    "globe": ("moon", "sphere", 4.0, "moon relief on a sphere (a globe, like the paper's Fig. 11)"),
    "cylinder": ("bricks", "cylinder", 6.0, "brick wall wrapped on a cylinder"),
}


@dataclass(frozen=True)
class Scene:
    """Everything a renderer needs, per pixel and per texel.

    ``px`` holds per-pixel world N, L, H and the tangent-space N' fetched from the bump map
    (``px.b_phi == b_phi_map[v, u]``); ``mask`` marks the pixels the geometry covers.
    """
    name: str
    geometry: str
    px: PixelInputs
    mask: np.ndarray
    u: np.ndarray
    v: np.ndarray
    height: np.ndarray | None          # None for a user's normal map (no height field)
    b_phi_map: np.ndarray
    b_theta_map: np.ndarray
    albedo: np.ndarray | None

    @property
    def size(self):
        return self.mask.shape[0]

    @property
    def texture_size(self):
        """The map's width W (u runs over it)."""
        return self.b_phi_map.shape[1]

    @property
    def texture_height(self):
        """The map's height H (v runs over it; W for a square map)."""
        return self.b_phi_map.shape[0]


def _power_of_two(name, value, lo, hi):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or \
            not lo <= value <= hi or value & (value - 1):
        raise BumpError(f"{name} must be a power of two in [{lo}, {hi}], got {value!r}")


def light_direction(elevation_deg, azimuth_deg):
    """World light direction from elevation above the screen plane (90 = from the viewer)
    and azimuth in the screen plane (0 = from the right, 90 = from the top)."""
    el, az = np.radians(elevation_deg), np.radians(azimuth_deg)
    right, up, toward_viewer = np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), np.array([0, -1.0, 0])
    return np.cos(el) * np.cos(az) * right + np.cos(el) * np.sin(az) * up + np.sin(el) * toward_viewer


def _geometry(kind, size, tex, tall=None):
    """Per-pixel surface points P, normals N, texel coordinates (u, v) and coverage mask, on a
    map ``tex`` texels wide (u) and ``tall`` (None: ``tex``) high (v): each geometry spans
    the same part of the map whatever its size, u and v wrapping by their own sides."""
    tall = tex if tall is None else tall
    c = (np.arange(size) + 0.5) / size * 2 - 1
    sx, sz = np.meshgrid(c, -c)                    # screen right, screen up
    if kind == "plane":                            # facing the viewer: N = -y
        mask = np.ones((size, size), bool)
        p = np.stack([sx, np.zeros_like(sx), sz], -1)
        n = np.broadcast_to(np.array([0, -1.0, 0]), p.shape).copy()
        u = (sx + 1) / 2 * tex
        v = (1 - sz) / 2 * tall                    # v grows down the screen = along T
    elif kind == "sphere":                         # pole up the screen: phi = longitude
        r2 = sx ** 2 + sz ** 2
        mask = r2 < 1
        p = np.stack([sx, -np.sqrt(np.clip(1 - r2, 0, 1)), sz], -1)
        n = p.copy()
        phi, theta = cartesian_to_polar(np.where(mask[..., None], n, [0, -1.0, 0]))
        u = phi / (2 * np.pi) * tex
        v = theta / np.pi * tall
    elif kind == "cylinder":                       # axis up the screen
        mask = np.abs(sx) < 1
        y = -np.sqrt(np.clip(1 - sx ** 2, 0, 1))
        p = np.stack([sx, y, sz], -1)
        n = np.stack([sx, y, np.zeros_like(sx)], -1)
        phi, _ = cartesian_to_polar(np.where(mask[..., None], n, [0, -1.0, 0]))
        u = phi / (2 * np.pi) * 2 * tex
        v = (1 - sz) / 2 * tall
    else:
        raise BumpError(f"geometry must be one of {', '.join(GEOMETRIES)}, got {kind!r}")
    n = np.where(mask[..., None], n, [0, -1.0, 0])
    to_texel = lambda t, side: np.mod(np.floor(t).astype(np.int64), side)
    return p, n, to_texel(u, tex), to_texel(v, tall), mask


def texel_coordinates(geometry, size, texture_size, texture_height=None):
    """``(u, v, mask)`` of a ``size`` x ``size`` frame of ``geometry`` on a map of width
    ``texture_size`` and height ``texture_height`` (None: square): the texel each pixel
    reads (row-major, screen rows top first) and the pixels the surface covers."""
    _, _, u, v, mask = _geometry(geometry, size, texture_size, texture_height)
    return u, v, mask


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def bump_strength(name, texture_size):
    """Texels of relief for height 1.0 of scene ``name`` on a T x T map: the scene's
    strength up to :data:`REFERENCE_TEXTURE_SIZE`, scaled by T / 512 above it (so that a
    4096^2 map shows the slopes of the 512^2 one instead of an 8x flatter surface)."""
    return SCENES[name][2] * max(1.0, texture_size / REFERENCE_TEXTURE_SIZE)


def load_scene(name, size=512, light_elevation=45.0, light_azimuth=30.0,
               light="directional", texture_size=None, bump=None, geometry=None,
               texture_height=None):
    """Build scene ``name`` at ``size`` x ``size`` pixels (see :data:`SCENES`).

    ``bump``: a user's bump map (:class:`bumprtl.sim.scenes.usermap.BumpMap`) instead of the
    scene's height field (``name`` is then ignored; no colour texture); ``geometry``
    overrides the scene's (a user map defaults to ``plane``). ``texture_size`` is the map's
    width W, ``texture_height`` its height H (a power of two in [16, W]; None: W, or the
    user map's own): a procedural height field is drawn at W x W and resampled to W x H
    (:func:`~bumprtl.sim.scenes.heightfields.resize_field`), the same picture over the
    same part of the surface."""
    if bump is None and name not in SCENES:
        raise BumpError(f"scene must be one of {', '.join(SCENES)}, got {name!r}")
    if geometry is not None and geometry not in GEOMETRIES:
        raise BumpError(f"geometry must be one of {', '.join(GEOMETRIES)}, got {geometry!r}")
    _power_of_two("size", size, 16, 4096)
    tex = (size if bump is None else bump.size) if texture_size is None else texture_size
    _power_of_two("texture_size", tex, 16, 4096)
    if texture_height is None:
        tall = bump.texture_height if bump is not None and tex == bump.size else tex
    else:
        tall = texture_height
    if isinstance(tall, bool) or not isinstance(tall, (int, np.integer)) or not 16 <= tall <= tex \
            or tall & (tall - 1):
        raise BumpError(f"texture_height must be a power of two in [16, {tex}] (at most the "
                        f"width texture_size), got {tall!r}")
    if bump is not None and (tex, tall) != (bump.size, bump.texture_height):
        if bump.size == bump.texture_height and tall == tex:
            raise BumpError(f"texture_size = {tex} but the map {bump.label} has "
                            f"{bump.size}x{bump.size} texels")
        raise BumpError(f"texture_size = {tex}, texture_height = {tall} but the map "
                        f"{bump.label} has {bump.size}x{bump.texture_height} texels")
    for pname, val, lo, hi in (("light_elevation", light_elevation, -90, 90),
                               ("light_azimuth", light_azimuth, -360, 360)):
        if isinstance(val, bool) or not isinstance(val, (int, float, np.integer, np.floating)) \
                or not lo <= val <= hi:            # NaN fails the comparison too
            raise BumpError(f"{pname} must be in [{lo}, {hi}] degrees, got {val!r}")
    if light not in ("directional", "point"):
        raise BumpError(f"light must be directional or point, got {light!r}")

    if bump is None:
        field, own_geometry, _, _ = SCENES[name]
        height = resize_field(HEIGHTFIELDS[field](tex), tex, tall)
        b_phi_map, b_theta_map = height_to_normals(height, bump_strength(name, tex))
    else:
        field, own_geometry, name = None, "plane", bump.label
        height, b_phi_map, b_theta_map = bump.height, bump.b_phi_map, bump.b_theta_map
    geometry = geometry or own_geometry
    p, n, u, v, mask = _geometry(geometry, size, tex, tall)

    ldir = light_direction(light_elevation, light_azimuth)
    if light == "directional":
        l_vec = np.broadcast_to(ldir, p.shape)
    else:                                          # a point light 3 radii away
        l_vec = _unit(3.0 * ldir - p)
    view = np.array([0, -1.0, 0])
    h_vec = _unit(l_vec + view)
    n_phi, n_theta = cartesian_to_polar(n)
    l_phi, l_theta = cartesian_to_polar(l_vec)
    h_phi, h_theta = cartesian_to_polar(h_vec)
    px = PixelInputs(n_phi, n_theta, l_phi, l_theta, h_phi, h_theta,
                     b_phi_map[v, u], b_theta_map[v, u])
    albedo = None
    if field in ("bricks",):
        albedo = _brick_albedo(height)
    elif field == "wood":
        albedo = np.stack([0.75 + 0.2 * height, 0.5 + 0.2 * height, 0.3 + 0.1 * height], -1)
    return Scene(name, geometry, px, mask, u, v, height, b_phi_map, b_theta_map, albedo)


def _brick_albedo(height):
    brick = np.array([0.72, 0.33, 0.24])
    mortar = np.array([0.78, 0.76, 0.72])
    w = np.clip(height, 0, 1)[..., None]
    return w * brick + (1 - w) * mortar
