"""Height fields (T x T, values in [0, 1]) and displacement -> tangent-space normals."""

import numpy as np
import skimage.data
from PIL import Image, ImageDraw, ImageFilter, ImageFont

from bumprtl.rtl.config import BumpError

__all__ = ["HEIGHTFIELDS", "height_to_normals", "normals_from_gradient", "smooth_noise"]


def _grid(t):
    c = (np.arange(t) + 0.5) / t
    return np.meshgrid(c, c)           # (u, v), each in (0, 1)


def smooth_noise(t, cells=16, seed=0):
    """Tileable smooth noise on a T x T grid, zero mean and unit standard deviation: the
    Fourier interpolation of a ``cells`` x ``cells`` grid of Gaussian samples, so the
    pattern is nearly the same at every power-of-two size T >= ``cells``."""
    coarse = np.random.default_rng(seed).standard_normal((cells, cells))
    spec = np.fft.fftshift(np.fft.fft2(coarse))
    pad = (t - cells) // 2
    fine = np.fft.ifft2(np.fft.ifftshift(np.pad(spec, pad))).real
    return (fine - fine.mean()) / fine.std()


def bricks(t):
    """Running-bond bricks: 8 courses, mortar grooves with bevelled edges, slightly rough
    faces (so that the map has many distinct normals, as a real one has)."""
    u, v = _grid(t)
    rows = 8
    row = np.floor(v * rows)
    fu = np.mod(u * 4 + 0.5 * (row % 2), 1.0)
    fv = np.mod(v * rows, 1.0)
    edge = np.minimum(np.minimum(fu, 1 - fu) * 4, np.minimum(fv, 1 - fv) * 2)
    face = np.clip(edge / 0.12, 0, 1)            # 0 in the mortar, 1 on the brick face
    return np.clip(face * (0.9 + 0.03 * smooth_noise(t)), 0, 1)


def wood(t):
    """Wood-grain rings: concentric rings around an off-centre axis, slightly wavy."""
    u, v = _grid(t)
    r = np.hypot(u - 0.3, (v - 1.4) * 0.35) * 28 + 0.6 * np.sin(u * 9 * np.pi)
    return 0.5 + 0.5 * np.sin(r * np.pi)


def bumps(t):
    """Sinusoidal bumps: an egg-crate of 6 x 6 periods (exact central-difference check)."""
    u, v = _grid(t)
    return 0.5 + 0.5 * np.sin(2 * np.pi * 6 * u) * np.sin(2 * np.pi * 6 * v)


def text(t):
    """Engraved text: 'BUMP RTL' cut into a flat face, edges softened by a small blur."""
    img = Image.new("L", (t, t), 255)
    draw = ImageDraw.Draw(img)
    try:
        font = ImageFont.load_default(size=max(8, t // 5))
    except TypeError:
        font = ImageFont.load_default()
    for n, word in enumerate(("BUMP", "RTL")):
        draw.text((t // 10, t // 8 + n * t // 2.6), word, fill=0, font=font)
    img = img.filter(ImageFilter.GaussianBlur(radius=max(1, t // 128)))
    return np.asarray(img, dtype=np.float64) / 255.0


def _skimage(name):
    def load(t):
        img = getattr(skimage.data, name)()
        if img.ndim == 3:
            img = img[..., :3].mean(axis=-1)
        side = min(img.shape)
        img = Image.fromarray(np.asarray(img[:side, :side], dtype=np.uint8))
        img = img.resize((t, t), Image.Resampling.LANCZOS)
        return np.asarray(img, dtype=np.float64) / 255.0
    load.__doc__ = f"scikit-image's '{name}' image (shipped inside the wheel) as heights."
    return load


HEIGHTFIELDS = {"bricks": bricks, "wood": wood, "bumps": bumps, "text": text,
                "brick": _skimage("brick"), "gravel": _skimage("gravel"), "moon": _skimage("moon")}


def normals_from_gradient(dh_dv, dh_du):
    """Tangent-space normals (phi, theta) of a surface with the given height slopes.

    Tangent x is along v and tangent y along u (see the scene module), so
    n' = normalize(-dh/dv, -dh/du, 1); phi = atan2(n'y, n'x) in [0, 2pi), theta = acos(n'z).
    """
    nx, ny = -np.asarray(dh_dv, float), -np.asarray(dh_du, float)
    nz = np.ones_like(nx)
    norm = np.sqrt(nx ** 2 + ny ** 2 + nz ** 2)
    phi = np.mod(np.arctan2(ny, nx), 2 * np.pi)
    return phi, np.arccos(nz / norm)


def height_to_normals(height, strength=1.0):
    """Displacement -> normal map by central differences (wrapping at the edges).

    The slope per texel step is ``strength * (h[i+1] - h[i-1]) / 2`` (heights in [0, 1]
    times ``strength`` texels). Returns the ``(phi, theta)`` maps.
    """
    h = np.asarray(height)
    if h.dtype.kind not in "fiu":
        raise BumpError(f"height map must be a real-valued array, got dtype {h.dtype}")
    if h.ndim != 2 or h.shape[0] != h.shape[1] or h.size == 0:
        raise BumpError(f"height map must be a non-empty square 2-D array, got shape {h.shape}")
    if isinstance(strength, bool) or not isinstance(strength, (int, float)) or \
            not 0 < strength < np.inf:
        raise BumpError(f"strength must be a positive finite number, got {strength!r}")
    h = h.astype(np.float64)
    if not np.all(np.isfinite(h)):
        raise BumpError("height map contains NaN or infinity")
    dh_du = strength * (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) / 2
    dh_dv = strength * (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) / 2
    return normals_from_gradient(dh_dv, dh_du)
