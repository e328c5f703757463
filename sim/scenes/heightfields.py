"""Height fields (T x T, values in [0, 1]; :func:`resize_field` to W x H) and displacement ->
tangent-space normals."""

import numpy as np
import skimage.data
from PIL import Image, ImageDraw, ImageFilter, ImageFont

from bumprtl.rtl.config import BumpError

__all__ = ["HEIGHTFIELDS", "craters", "height_to_normals", "normals_from_gradient", "resize_field",
           "smooth_noise"]


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


BRICK_COURSES, BRICKS_PER_COURSE = 8, 4
BRICK_BEVEL = 0.12          # width of a groove's bevel, in sixteenths of the map (T/16 texels)


def brick_lines(t):
    """Where the mortar lines of :func:`bricks` lie on a T x T map, in texel coordinates
    (texel centres at integers): course lines at rows k T/8 - 1/2 (between two texel rows)
    and, in course k, joints at columns (j + k/2) T/4 - 1/2; on a narrow map (the bevel
    at most half a texel, T <= 64) every line sits half a texel further, on a texel row or
    column (k T/8, (j + k/2) T/4). Returns ``(rows, joints)``: the 8 row positions and per
    course the 4 joint positions."""
    offset = 0.0 if _narrow(t) else -0.5
    rows = [k * t / BRICK_COURSES + offset for k in range(BRICK_COURSES)]
    joints = [[((j + 0.5 * (k % 2)) * t / BRICKS_PER_COURSE + offset) % t
               for j in range(BRICKS_PER_COURSE)] for k in range(BRICK_COURSES)]
    return rows, joints


def _narrow(t):
    """The bevel is at most half a texel wide: texel centres (half a texel either side of a
    line between two texels) would miss the groove entirely."""
    return BRICK_BEVEL * t / 16 <= 0.5


def bricks(t):
    """Running-bond bricks: 8 courses of 4 bricks, mortar grooves with bevelled edges,
    slightly rough faces (so that the map has many distinct normals, as a real one has).

    The bevel is 0.12 / 16 of the map wide (3.8 texels at 512). On a map where that is at
    most half a texel (T <= 64) every texel centre would miss the groove and the wall would
    show no bricks, so there the lines move half a texel onto texel centres and the bevel
    widens to one texel: every allowed size shows its 8 courses (:func:`brick_lines`)."""
    if _narrow(t):
        c = np.arange(t) / t                         # texel centres on the lines
        u, v = np.meshgrid(c, c)
        bevel = 16 / t                               # one texel, in sixteenths of the map
    else:
        (u, v), bevel = _grid(t), BRICK_BEVEL
    row = np.floor(v * BRICK_COURSES)
    fu = np.mod(u * BRICKS_PER_COURSE + 0.5 * (row % 2), 1.0)
    fv = np.mod(v * BRICK_COURSES, 1.0)
    edge = np.minimum(np.minimum(fu, 1 - fu) * 4, np.minimum(fv, 1 - fv) * 2)
    face = np.clip(edge / bevel, 0, 1)           # 0 in the mortar, 1 on the brick face
    return np.clip(face * (0.9 + 0.03 * smooth_noise(t)), 0, 1)


SMALLEST_DRAWN = 64         # finer fields are drawn at this size and box-filtered down


def _band_limited(draw):
    """``draw(t)`` for t >= SMALLEST_DRAWN; below, ``draw(SMALLEST_DRAWN)`` averaged over
    blocks of (64 / t)^2 texels, so that detail finer than a texel of the small map is
    averaged out instead of aliasing into a pattern the scene does not have."""
    def field(t):
        if t >= SMALLEST_DRAWN:
            return draw(t)
        k = SMALLEST_DRAWN // t
        return draw(SMALLEST_DRAWN).reshape(t, k, t, k).mean(axis=(1, 3))
    field.__name__, field.__doc__ = draw.__name__, draw.__doc__
    return field


@_band_limited
def wood(t):
    """Wood-grain rings: concentric rings around an off-centre axis, slightly wavy."""
    u, v = _grid(t)
    r = np.hypot(u - 0.3, (v - 1.4) * 0.35) * 28 + 0.6 * np.sin(u * 9 * np.pi)
    return 0.5 + 0.5 * np.sin(r * np.pi)


def craters(t, seed, n, radius=(0.1, 0.3)):
    """An unseen height map, as a user would bring one: ``n`` random craters (a bowl and a
    rim each; radius a random fraction in ``radius`` of T) with a fixed ``seed``, tiling."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:t, 0:t] + 0.5
    h = np.zeros((t, t))
    for _ in range(n):
        cx, cy = rng.uniform(0, t, 2)
        r = rng.uniform(*radius) * t
        d = np.hypot((x - cx + t / 2) % t - t / 2, (y - cy + t / 2) % t - t / 2) / r
        h += np.where(d < 1, d ** 2 - 1, 0.3 * np.exp(-((d - 1) / 0.3) ** 2))
    return (h - h.min()) / np.ptp(h)


def bumps(t):
    """Sinusoidal bumps: an egg-crate of 6 x 6 periods (exact central-difference check)."""
    u, v = _grid(t)
    return 0.5 + 0.5 * np.sin(2 * np.pi * 6 * u) * np.sin(2 * np.pi * 6 * v)


@_band_limited
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


def resize_field(height, width, tall):
    """A ``width`` x ``width`` height field resampled to ``width`` x ``tall`` (rows ``tall``;
    Lanczos, as a user's map is resampled): the picture of a square field on a non-square
    map. ``tall == width``: the field itself, untouched."""
    if tall == width:
        return height
    img = Image.fromarray(np.asarray(height, np.float32), "F")
    return np.asarray(img.resize((width, tall), Image.Resampling.LANCZOS), np.float64)


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
    if h.ndim != 2 or h.size == 0:
        raise BumpError(f"height map must be a non-empty 2-D array, got shape {h.shape}")
    if isinstance(strength, bool) or not isinstance(strength, (int, float)) or \
            not 0 < strength < np.inf:
        raise BumpError(f"strength must be a positive finite number, got {strength!r}")
    h = h.astype(np.float64)
    if not np.all(np.isfinite(h)):
        raise BumpError("height map contains NaN or infinity")
    dh_du = strength * (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) / 2
    dh_dv = strength * (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) / 2
    return normals_from_gradient(dh_dv, dh_du)
