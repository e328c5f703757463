"""A user's own bump map: a height map or a tangent-space normal map from a file, checked
and turned into the bump vector map (Lee Sec. 2: per texel N' as polar angles).

Files:

* height map: an 8- or 16-bit greyscale PNG (heights value / 255 or value / 65535, so
  white = 1.0) or a ``.npy`` 2-D array of real numbers (heights as they are). Height 1.0
  rises ``height_scale`` texels. Normals come from Tarini et al.'s least-squares plane fit
  (Sec. 4.1, :func:`bumprtl.sim.golden.float.palette.displacement_to_normals`).
* normal map: an 8-bit RGB PNG (RGBA with an opaque alpha is read as RGB) or a ``.npy``
  ``(T, T, 3)`` array of vectors. A PNG channel c encodes the component 2 c / 255 - 1; red
  is +x to the right of the image, green +y up the image (``opengl``, the default) or down
  the image (``directx``), blue +z out of the surface. Every vector is re-normalized; one
  pointing into the surface (z <= 0) is refused.

The bump map's tangent frame (bumprtl.sim.scenes): tangent x along texel rows v (down the
image), tangent y along columns u (to the right). So an OpenGL normal (r, g, b) is
N' = (-g, r, b) and a DirectX one N' = (g, r, b).

A map must be square with a power-of-two side in [16, 4096] (texel addressing by bit
slicing, rtl/bumpfetch.py), or W x H with ``texture_size`` W and ``texture_height`` H given
(powers of two, 16 <= H <= W <= 4096). Any other size is refused with the nearest allowed
size named, or resampled to it on request (``resample``: to W x H, each axis on its own);
a map is never cropped. Every problem raises a
:class:`BumpError` whose one line names the file.
"""

import functools
import io
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image

from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.common import cartesian_to_polar
from bumprtl.sim.golden.float.palette import displacement_to_normals

__all__ = ["KINDS", "CONVENTIONS", "MIN_SIZE", "MAX_SIZE", "DEFAULT_HEIGHT_SCALE", "MapError",
           "BumpMap", "check_height_scale", "nearest_allowed_size", "map_size", "load_bump_map", "read_height",
           "read_normals", "normals_to_rgb", "write_png"]

KINDS = ("height", "normal")
CONVENTIONS = ("opengl", "directx")       # green channel: +Y up (OpenGL) or down (DirectX)
MIN_SIZE, MAX_SIZE = 16, 4096
DEFAULT_HEIGHT_SCALE = 4.0                # texels of relief for height 1.0 (a white texel)
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PNG_CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}          # IHDR colour type -> channels
_PNG_KIND = {0: "greyscale", 2: "RGB", 3: "indexed-colour", 4: "greyscale + alpha", 6: "RGBA"}


class MapError(BumpError):
    """A user map that cannot be used; the message names the file and the problem."""


@dataclass(frozen=True)
class BumpMap:
    """A bump vector map from a user's file: N' per texel as polar angles (radians).

    ``height`` is the height field (heights as read, scaled by nothing) for a height map,
    None for a normal map; ``label`` names the file for messages and images."""
    label: str
    kind: str
    b_phi_map: np.ndarray
    b_theta_map: np.ndarray
    height: np.ndarray | None

    @property
    def size(self):
        """The map's width W (u runs over it)."""
        return self.b_phi_map.shape[1]

    @property
    def texture_height(self):
        """The map's height H (v runs over it; W for a square map)."""
        return self.b_phi_map.shape[0]


def nearest_allowed_size(width, height=None):
    """The allowed map side (a power of two in [16, 4096]) nearest to the larger side, by
    ratio (ties go up)."""
    side = max(int(width), int(height if height is not None else width), 1)
    exp = int(np.clip(np.round(np.log2(side) + 1e-9), np.log2(MIN_SIZE), np.log2(MAX_SIZE)))
    return 1 << exp


def _allowed(n):
    return MIN_SIZE <= n <= MAX_SIZE and n & (n - 1) == 0


def _png_header(path, raw):
    """(width, height, bit depth, colour type) from a PNG's IHDR chunk."""
    if raw[:8] != _PNG_SIGNATURE:
        raise MapError(f"{path}: not a PNG file (no PNG signature)")
    if len(raw) < 33 or raw[12:16] != b"IHDR":
        raise MapError(f"{path}: truncated or corrupt PNG (no IHDR header)")
    width, height, depth, ctype = struct.unpack(">IIBB", raw[16:26])
    if ctype not in _PNG_CHANNELS:
        raise MapError(f"{path}: corrupt PNG (colour type {ctype})")
    return width, height, depth, ctype


def _read_bytes(path):
    p = Path(path)
    if not p.exists():
        raise MapError(f"{path}: no such file")
    if not p.is_file():
        raise MapError(f"{path}: not a file")
    try:
        return p.read_bytes()
    except OSError as e:
        raise MapError(f"{path}: cannot read ({e.strerror or e})") from None


def _suffix(path):
    suffix = Path(path).suffix.lower()
    if suffix not in (".png", ".npy"):
        raise MapError(f"{path}: a map must be a .png or .npy file, got {suffix or 'no suffix'!r}")
    return suffix


def _load_npy(path, raw):
    try:
        arr = np.load(io.BytesIO(raw), allow_pickle=False)
    except Exception as e:                          # numpy raises several types here
        raise MapError(f"{path}: not a readable .npy array ({type(e).__name__}: {e})") from None
    if arr.dtype.kind not in "fiu" or arr.dtype == np.bool_:
        raise MapError(f"{path}: a map must hold real numbers, got dtype {arr.dtype}")
    return arr.astype(np.float64)


def _decode_png(path, raw):
    try:
        img = Image.open(io.BytesIO(raw))
        img.load()
    except Exception as e:                          # PIL: OSError, SyntaxError, ValueError...
        raise MapError(f"{path}: unreadable or truncated PNG ({type(e).__name__}: {e})") from None
    return img



def _finite(path, arr):
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise MapError(f"{path}: contains NaN or infinity ({int(bad.sum())} values, the first "
                       f"at {idx})")


def _check_shape(path, shape):
    h, w = shape[:2]
    if h == w and _allowed(w):
        return None
    return (f"{path}: {w}x{h} texels; a map must be square with a power-of-two side in "
            f"[{MIN_SIZE}, {MAX_SIZE}]; the nearest allowed size is "
            f"{nearest_allowed_size(w, h)}x{nearest_allowed_size(w, h)}")


def _resize(channels, size, height=None):
    """Resample float maps ``(H, W[, C])`` to ``size`` x ``height`` texels (width x height;
    ``height`` None: ``size``; Lanczos, per channel)."""
    arr = np.asarray(channels, np.float64)
    planes = arr[..., None] if arr.ndim == 2 else arr
    tall = size if height is None else height
    out = np.stack([np.asarray(Image.fromarray(planes[..., c].astype(np.float32), "F")
                               .resize((size, tall), Image.Resampling.LANCZOS), np.float64)
                    for c in range(planes.shape[-1])], -1)
    return out[..., 0] if arr.ndim == 2 else out


def _wanted(size, height):
    """How a message names the size asked for: ``texture_size = T``, or W x H."""
    if height is None or height == size:
        return f"texture_size = {size}"
    return f"texture_size x texture_height = {size} x {height}"


def _sized(path, arr, size, resample, height=None):
    """``arr`` at ``size`` x ``height`` (given; ``height`` None: square) or at its own size;
    otherwise refused or resampled."""
    problem = _check_shape(path, arr.shape)
    if size is None and height is not None and _allowed(arr.shape[1]):
        size = arr.shape[1]              # a non-square map keeps its own width
    if size is None:
        if problem is None:
            return arr
        if not resample:
            raise MapError(f"{problem} (pass --resample / resample = true to resample it)")
        size = nearest_allowed_size(*arr.shape[:2][::-1])
    if not _allowed(size):
        raise MapError(f"{path}: texture_size must be a power of two in [{MIN_SIZE}, "
                       f"{MAX_SIZE}], got {size!r}")
    tall = size if height is None else height
    if arr.shape[:2] == (tall, size):
        return arr
    if not resample:
        h, w = arr.shape[:2]
        raise MapError(f"{path}: {w}x{h} texels but {_wanted(size, height)} (pass --resample / "
                       f"resample = true to resample it, or drop texture_size)")
    return _resize(arr, size, height)


def _check_png(path, kind, depth, ctype):
    """The channel count and bit depth a ``kind`` map's PNG must have."""
    channels = _PNG_CHANNELS[ctype]
    if kind == "height":
        if channels != 1 or ctype == 3:
            hint = " (an RGB normal map goes to --normal-map)" if ctype in (2, 6) else ""
            raise MapError(f"{path}: {_PNG_KIND[ctype]} PNG with {channels} channel(s); a "
                           f"height map is a 1-channel greyscale PNG{hint}")
        if depth not in (8, 16):
            raise MapError(f"{path}: {depth}-bit greyscale PNG; a height map is 8- or 16-bit")
    else:
        if ctype not in (2, 6):
            hint = " (a greyscale height map goes to --height-map)" if ctype in (0, 4) else ""
            raise MapError(f"{path}: {_PNG_KIND[ctype]} PNG with {channels} channel(s); a "
                           f"normal map is an RGB PNG (3 channels){hint}")
        if depth != 8:
            raise MapError(f"{path}: {depth}-bit RGB PNG; a normal map must be 8 bits per "
                           f"channel (save it as 8-bit RGB)")


def map_size(path, resample=False, texture_size=None, kind=None, texture_height=None):
    """The width the map at ``path`` will have (reading only the header when it can): its
    own, ``texture_size`` when given, or the nearest allowed size with ``resample``; its
    height is ``texture_height`` when given (the width given or its own: a W x H file with
    ``texture_height`` H needs no ``texture_size``), else the width. With ``kind`` (height or
    normal) a PNG's channels and bit depth are checked too."""
    suffix = _suffix(path)
    raw = _read_bytes(path)
    if suffix == ".png":
        w, h, depth, ctype = _png_header(path, raw)
        if kind is not None:
            _check_png(path, kind, depth, ctype)
    else:
        shape = _load_npy(path, raw).shape
        if len(shape) < 2:
            raise MapError(f"{path}: a map must be a 2-D array (or (T, T, 3) vectors), got "
                           f"shape {shape}")
        h, w = shape[:2]
    if texture_size is None and texture_height is not None and _allowed(w):
        texture_size = w                  # a non-square map keeps its own width
    if texture_size is not None:
        tall = texture_size if texture_height is None else texture_height
        if (w, h) != (texture_size, tall) and not resample:
            raise MapError(f"{path}: {w}x{h} texels but {_wanted(texture_size, texture_height)} "
                           f"(pass --resample / resample = true to resample it, or drop "
                           f"texture_size)")
        return texture_size
    problem = _check_shape(path, (h, w))
    if problem is None:
        return w
    if not resample:
        raise MapError(f"{problem} (pass --resample / resample = true to resample it)")
    return nearest_allowed_size(w, h)


def read_height(path, size=None, resample=False, height=None):
    """Heights of a greyscale PNG (8-bit: /255, 16-bit: /65535) or a 2-D ``.npy``, at
    ``size`` x ``height`` (width x height; ``height`` None: square; or the file's own size),
    float64."""
    suffix, raw = _suffix(path), _read_bytes(path)
    if suffix == ".npy":
        h = _load_npy(path, raw)
        if h.ndim != 2:
            raise MapError(f"{path}: a height map must be a 2-D array, got shape {h.shape}")
    else:
        w, hh, depth, ctype = _png_header(path, raw)
        _check_png(path, "height", depth, ctype)
        img = _decode_png(path, raw)
        h = np.asarray(img, dtype=np.float64) / (255.0 if depth == 8 else 65535.0)
        if h.shape != (hh, w):
            raise MapError(f"{path}: decoded {h.shape} texels, the header says {hh}x{w}")
    if h.size == 0:
        raise MapError(f"{path}: empty map")
    _finite(path, h)
    if np.ptp(h) == 0:
        raise MapError(f"{path}: every texel has the same height ({h.flat[0]:g}): an all-flat "
                       f"map has no bumps (a scene with one normal per polygon is "
                       f"bump_map = 'flat')")
    return _sized(path, h, size, resample, height)


def read_normals(path, convention="opengl", size=None, resample=False, height=None):
    """Unit tangent-space normals ``(H, W, 3)`` in the bump map's frame (tangent x along
    rows, y along columns, z out) of an 8-bit RGB PNG or a ``(H, W, 3)`` ``.npy``, at
    ``size`` x ``height`` as :func:`read_height`."""
    if convention not in CONVENTIONS:
        raise MapError(f"normal_convention must be one of {', '.join(CONVENTIONS)}, "
                       f"got {convention!r}")
    suffix, raw = _suffix(path), _read_bytes(path)
    if suffix == ".npy":
        img = _load_npy(path, raw)
        if img.ndim != 3 or img.shape[2] != 3:
            raise MapError(f"{path}: a normal map array must have shape (T, T, 3), got {img.shape}")
        _finite(path, img)
        right, up, out = img[..., 0], img[..., 1], img[..., 2]
    else:
        w, hh, depth, ctype = _png_header(path, raw)
        _check_png(path, "normal", depth, ctype)
        channels = _PNG_CHANNELS[ctype]
        rgb = np.asarray(_decode_png(path, raw), dtype=np.float64)
        if rgb.shape != (hh, w, channels):
            raise MapError(f"{path}: decoded {rgb.shape} texels, the header says {hh}x{w}x{channels}")
        if channels == 4:
            if np.any(rgb[..., 3] != 255):
                raise MapError(f"{path}: RGBA PNG with a non-opaque alpha channel; a normal map "
                               f"is RGB (alpha must be 255 everywhere or absent)")
            rgb = rgb[..., :3]
        right, up, out = (2 * rgb[..., c] / 255.0 - 1 for c in range(3))
    if convention == "directx":                     # green is +Y down the image
        up = -up
    n = np.stack([-up, right, out], -1)             # tangent x = down the image (rows)
    length = np.linalg.norm(n, axis=-1)
    inward = (n[..., 2] <= 0) | (length == 0)
    if inward.any():
        r, c = (int(i) for i in np.argwhere(inward)[0])
        raise MapError(f"{path}: {int(inward.sum())} texels point into the surface (z <= 0, "
                       f"blue < 128), the first at row {r}, column {c}: not a tangent-space "
                       f"normal map")
    n = n / length[..., None]
    if np.ptp(n.reshape(-1, 3), axis=0).max() == 0:
        raise MapError(f"{path}: every texel has the same normal: an all-flat map has no bumps "
                       f"(a scene with one normal per polygon is bump_map = 'flat')")
    n = _sized(path, n, size, resample, height)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


@functools.lru_cache(maxsize=8)
def _cached(path, stamp, kind, convention, height_scale, size, resample, height):
    if kind == "height":
        h = read_height(path, size, resample, height)
        n = displacement_to_normals(h, height_scale)        # Tarini Sec. 4.1
    else:
        h, n = None, read_normals(path, convention, size, resample, height)
    phi, theta = cartesian_to_polar(n)
    for a in (phi, theta, h):
        if a is not None:
            a.setflags(write=False)
    return BumpMap(str(path), kind, phi, theta, h)


def load_bump_map(path, kind, convention="opengl", height_scale=DEFAULT_HEIGHT_SCALE,
                  size=None, resample=False, height=None) -> BumpMap:
    """The bump vector map of a height map (``kind = "height"``) or a normal map
    (``"normal"``) file, at ``size`` x ``height`` texels (width x height; ``height`` None:
    ``size``; default: the file's own size). Cached by path, modification time and
    arguments."""
    if kind not in KINDS:
        raise MapError(f"map kind must be one of {', '.join(KINDS)}, got {kind!r}")
    check_height_scale(height_scale)
    p = Path(path)
    stamp = p.stat().st_mtime_ns if p.is_file() else None
    return _cached(str(path), stamp, kind, convention, float(height_scale), size, bool(resample),
                   height)


def check_height_scale(value):
    """``height_scale`` must be a positive finite number (texels of relief for height 1.0)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not 0 < value < np.inf:
        raise MapError(f"height_scale must be a positive finite number (texels of relief for "
                       f"height 1.0), got {value!r}")
    return float(value)


def normals_to_rgb(normals, convention="opengl"):
    """Unit normals in the bump map's frame ``(T, T, 3)`` -> the 8-bit RGB of a normal-map
    PNG (the inverse of :func:`read_normals`, rounded to nearest)."""
    n = np.asarray(normals, np.float64)
    up = -n[..., 0] if convention == "opengl" else n[..., 0]
    comps = np.stack([n[..., 1], up, n[..., 2]], -1)
    return np.clip(np.rint((comps + 1) * 255.0 / 2), 0, 255).astype(np.uint8)


def write_png(path, pixels, bit_depth=8):
    """A PNG of ``pixels`` ``(H, W)`` (greyscale) or ``(H, W, 3)`` (RGB) at 8 or 16 bits
    per channel, written directly (Pillow cannot write 16-bit RGB)."""
    a = np.asarray(pixels)
    ctype = 0 if a.ndim == 2 else 2
    dt = np.dtype(">u2") if bit_depth == 16 else np.uint8
    rows = a.astype(dt).reshape(a.shape[0], -1)
    body = b"".join(b"\0" + r.tobytes() for r in rows)

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    ihdr = struct.pack(">IIBBBBB", a.shape[1], a.shape[0], bit_depth, ctype, 0, 0, 0)
    Path(path).write_bytes(_PNG_SIGNATURE + chunk(b"IHDR", ihdr) +
                           chunk(b"IDAT", zlib.compress(body)) + chunk(b"IEND", b""))
    return Path(path)
