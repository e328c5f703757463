"""A user's map (sim/scenes/usermap.py) against its module docstring: the channel decoding
2 c / 255 - 1 and the frame N' = (-up, right, out), the allowed sizes and the nearest one by
ratio, the header-only sizing, and every refusal's one line naming the file and the problem."""

import struct
import zlib

import numpy as np
import pytest
from PIL import Image

from bumprtl.sim.golden.common import polar_to_cartesian
from bumprtl.sim.golden.float.palette import displacement_to_normals
from bumprtl.sim.scenes.usermap import (
    DEFAULT_HEIGHT_SCALE,
    MAX_SIZE,
    MIN_SIZE,
    MapError,
    check_height_scale,
    load_bump_map,
    map_size,
    nearest_allowed_size,
    normals_to_rgb,
    read_height,
    read_normals,
    write_png,
)

SIG = b"\x89PNG\r\n\x1a\n"


def _header(width, height, depth=8, ctype=0, tag=b"IHDR"):
    """The signature and IHDR chunk of a PNG (33 bytes): all map_size needs to size it."""
    data = struct.pack(">IIBBBBB", width, height, depth, ctype, 0, 0, 0)
    return SIG + struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))


def _file(tmp_path, name, raw):
    (tmp_path / name).write_bytes(raw)
    return tmp_path / name


def _refusal(fn, *args, **kw):
    with pytest.raises(MapError) as e:
        fn(*args, **kw)
    msg = str(e.value)
    assert "\n" not in msg
    return msg


def _ramp(rows, cols=None):
    cols = rows if cols is None else cols
    return np.add.outer(np.arange(rows) / rows, np.sin(np.arange(cols) / 3.0))


# --- the allowed sizes ----------------------------------------------------------------------

def test_nearest_allowed_size_is_by_ratio_of_the_larger_side():
    """The allowed side nearest by ratio: the geometric midpoint 2^(k + 1/2) divides them
    (16 sqrt 2 = 22.6, 32 sqrt 2 = 45.3, 2048 sqrt 2 = 2896.3); the larger side counts."""
    for side, want in ((22, 16), (23, 32), (45, 32), (46, 64), (2896, 2048), (2897, 4096),
                       (16, 16), (4096, 4096), (1, 16), (0, 16), (10 ** 6, 4096)):
        assert nearest_allowed_size(side) == want, side
    assert nearest_allowed_size(20, 100) == nearest_allowed_size(100, 20) == 128
    assert nearest_allowed_size(64, None) == 64


@pytest.mark.parametrize("side", [MIN_SIZE, 32, 1024, MAX_SIZE])
def test_map_size_accepts_every_power_of_two_side_from_16_to_4096(tmp_path, side):
    """map_size reads only a PNG's header: a 33-byte file (signature + IHDR) is sized."""
    path = _file(tmp_path, "m.png", _header(side, side))
    assert map_size(path) == side and map_size(path, kind="height") == side


@pytest.mark.parametrize("w, h, nearest", [(8, 8, 16), (15, 15, 16), (48, 48, 64), (8192, 8192, 4096),
                                           (4097, 4097, 4096), (32, 16, 32), (16, 64, 64)])
def test_map_size_refuses_other_sides_naming_the_nearest(tmp_path, w, h, nearest):
    """Not square, or a side that is no power of two in [16, 4096]: refused naming the file,
    its size (width x height) and the nearest allowed size; with resample, that size."""
    path = _file(tmp_path, "odd.png", _header(w, h))
    msg = _refusal(map_size, path)
    assert msg.startswith(f"{path}: {w}x{h} texels; a map must be square with a power-of-two "
                          f"side in [16, 4096]; the nearest allowed size is {nearest}x{nearest}")
    assert "--resample" in msg
    assert map_size(path, resample=True) == nearest


def test_map_size_with_a_texture_size(tmp_path):
    """Given texture_size: the map's own size must equal it, unless resample."""
    path = _file(tmp_path, "m.png", _header(32, 32))
    assert map_size(path, texture_size=32) == 32
    assert map_size(path, resample=True, texture_size=64) == 64
    msg = _refusal(map_size, path, texture_size=64)
    assert msg.startswith(f"{path}: 32x32 texels but texture_size = 64 (pass --resample")


def test_map_size_checks_the_png_kind_only_when_asked(tmp_path):
    """Without a kind an RGB PNG is sized; as a height map it is refused."""
    path = _file(tmp_path, "rgb.png", _header(16, 16, 8, 2))
    assert map_size(path) == 16 and map_size(path, kind="normal") == 16
    assert "a height map is a 1-channel greyscale PNG" in _refusal(map_size, path, kind="height")


@pytest.mark.parametrize("size", [8, 48, 8192, 0])
def test_a_texture_size_outside_the_allowed_sides_is_refused(tmp_path, size):
    np.save(tmp_path / "h.npy", _ramp(16))
    msg = _refusal(read_height, tmp_path / "h.npy", size=size, resample=True)
    assert msg == f"{tmp_path / 'h.npy'}: texture_size must be a power of two in [16, 4096], got {size}"


# --- PNG headers ----------------------------------------------------------------------------

def test_a_png_cut_inside_its_header_or_without_ihdr_is_refused(tmp_path):
    """33 bytes hold the whole IHDR chunk; one byte less, or a first chunk that is not IHDR,
    is a truncated or corrupt PNG."""
    raw = _header(16, 16)
    assert len(raw) == 33
    assert "truncated or corrupt PNG (no IHDR header)" in _refusal(
        map_size, _file(tmp_path, "cut.png", raw[:32]))
    assert "no IHDR header" in _refusal(map_size, _file(tmp_path, "x.png", _header(16, 16, tag=b"IHDX")))
    assert "no PNG signature" in _refusal(map_size, _file(tmp_path, "sig.png", b"\x88" + raw[1:]))


@pytest.mark.parametrize("ctype", [1, 5, 7])
def test_an_unknown_colour_type_is_a_corrupt_png(tmp_path, ctype):
    path = _file(tmp_path, "c.png", _header(16, 16, 8, ctype))
    assert _refusal(map_size, path) == f"{path}: corrupt PNG (colour type {ctype})"


# a height map is 8- or 16-bit greyscale, a normal map 8-bit RGB: every other header is
# refused with what it is and, where it would fit, the flag of the other kind
@pytest.mark.parametrize("kind, depth, ctype, words, absent", [
    ("height", 8, 3, ["indexed-colour PNG with 1 channel(s)", "1-channel greyscale"], "--normal-map"),
    ("height", 8, 4, ["greyscale + alpha PNG with 2 channel(s)"], "--normal-map"),
    ("height", 8, 2, ["RGB PNG with 3 channel(s)", "(an RGB normal map goes to --normal-map)"], None),
    ("height", 8, 6, ["RGBA PNG with 4 channel(s)", "--normal-map"], None),
    ("height", 1, 0, ["1-bit greyscale PNG; a height map is 8- or 16-bit"], None),
    ("height", 4, 0, ["4-bit greyscale PNG"], None),
    ("normal", 8, 0, ["greyscale PNG with 1 channel(s)", "an RGB PNG (3 channels)", "--height-map"], None),
    ("normal", 8, 4, ["greyscale + alpha PNG with 2 channel(s)", "--height-map"], None),
    ("normal", 8, 3, ["indexed-colour PNG with 1 channel(s)"], "--height-map"),
    ("normal", 16, 2, ["16-bit RGB PNG; a normal map must be 8 bits per channel"], None),
    ("normal", 16, 6, ["16-bit RGB PNG"], None),
])
def test_a_png_of_the_wrong_kind_is_refused_with_what_it_is(tmp_path, kind, depth, ctype, words, absent):
    path = _file(tmp_path, f"{kind[0]}.png", _header(16, 16, depth, ctype))
    msg = _refusal(map_size, path, kind=kind)
    assert msg.startswith(f"{path}: ") and all(w in msg for w in words), msg
    assert absent is None or absent not in msg


def test_8_and_16_bit_grey_and_8_bit_rgba_headers_are_accepted(tmp_path):
    assert map_size(_file(tmp_path, "g16.png", _header(64, 64, 16, 0)), kind="height") == 64
    assert map_size(_file(tmp_path, "rgba.png", _header(64, 64, 8, 6)), kind="normal") == 64


# --- files and arrays -----------------------------------------------------------------------

def test_the_suffix_decides_the_format_in_any_case(tmp_path):
    """.png or .npy (any letter case); any other suffix, or none, is refused naming it."""
    np.save(tmp_path / "h.npy", _ramp(16))
    (tmp_path / "h.npy").rename(tmp_path / "H.NPY")
    assert read_height(tmp_path / "H.NPY").shape == (16, 16)
    (tmp_path / "plain").write_bytes(b"x")
    assert _refusal(read_height, tmp_path / "plain").endswith("a map must be a .png or .npy file, got 'no suffix'")
    (tmp_path / "h.tiff").write_bytes(b"x")
    assert _refusal(read_height, tmp_path / "h.tiff").endswith("got '.tiff'")


def test_a_directory_is_not_a_map(tmp_path):
    (tmp_path / "d.png").mkdir()
    assert _refusal(map_size, tmp_path / "d.png") == f"{tmp_path / 'd.png'}: not a file"


def test_a_npy_map_must_hold_real_numbers(tmp_path):
    """Integers and floats are read as float64; strings, booleans and objects are refused."""
    np.save(tmp_path / "i.npy", np.arange(256, dtype=np.uint8).reshape(16, 16))
    got = read_height(tmp_path / "i.npy")
    assert got.dtype == np.float64 and np.array_equal(got, np.arange(256).reshape(16, 16))
    np.save(tmp_path / "s.npy", np.full((16, 16), "a"))
    assert "real numbers, got dtype <U1" in _refusal(read_height, tmp_path / "s.npy")
    np.save(tmp_path / "o.npy", np.full((16, 16), None, object), allow_pickle=True)
    msg = _refusal(read_height, tmp_path / "o.npy")
    assert msg.startswith(f"{tmp_path / 'o.npy'}: not a readable .npy array (ValueError")


def test_a_npy_map_needs_two_dimensions(tmp_path):
    np.save(tmp_path / "v.npy", np.arange(16.0))
    assert "a map must be a 2-D array (or (T, T, 3) vectors), got shape (16,)" in \
        _refusal(map_size, tmp_path / "v.npy")
    np.save(tmp_path / "c.npy", np.zeros((16, 16, 3)))
    assert _refusal(read_height, tmp_path / "c.npy") == \
        f"{tmp_path / 'c.npy'}: a height map must be a 2-D array, got shape (16, 16, 3)"
    np.save(tmp_path / "e.npy", np.zeros((0, 0)))
    assert _refusal(read_height, tmp_path / "e.npy") == f"{tmp_path / 'e.npy'}: empty map"


def test_non_finite_values_are_counted_and_the_first_named(tmp_path):
    h = _ramp(16)
    h[9, 1] = np.inf
    h[2, 7] = np.nan
    np.save(tmp_path / "h.npy", h)
    assert "contains NaN or infinity (2 values, the first at (2, 7))" in \
        _refusal(read_height, tmp_path / "h.npy")


def test_a_flat_height_map_names_its_one_height(tmp_path):
    np.save(tmp_path / "h.npy", np.full((16, 16), 0.25))
    assert "every texel has the same height (0.25): an all-flat map" in \
        _refusal(read_height, tmp_path / "h.npy")


# --- heights ---------------------------------------------------------------------------------

def test_png_heights_make_white_one(tmp_path):
    """8-bit heights value / 255 and 16-bit value / 65535: black 0.0, white exactly 1.0."""
    g8 = np.zeros((16, 16), np.uint8)
    g8[:, 8:] = 255
    g8[3, 3] = 51
    write_png(tmp_path / "g8.png", g8)
    h = read_height(tmp_path / "g8.png")
    assert h.dtype == np.float64 and h.max() == 1.0 and h.min() == 0.0 and h[3, 3] == 51 / 255
    g16 = g8.astype(np.int64) * 257
    g16[3, 3] = 1
    write_png(tmp_path / "g16.png", g16, bit_depth=16)
    h = read_height(tmp_path / "g16.png")
    assert h.max() == 1.0 and h[3, 3] == 1 / 65535


def test_a_map_at_its_own_size_is_returned_unresampled(tmp_path):
    h = _ramp(32)
    np.save(tmp_path / "h.npy", h)
    assert np.array_equal(read_height(tmp_path / "h.npy", size=32), h)
    msg = _refusal(read_height, tmp_path / "h.npy", size=16)
    assert msg == (f"{tmp_path / 'h.npy'}: 32x32 texels but texture_size = 16 (pass --resample / "
                   f"resample = true to resample it, or drop texture_size)")


def test_resampling_keeps_a_smooth_map_and_its_orientation(tmp_path):
    """A smooth map resampled (Lanczos) from 32 to 64 texels is the same surface sampled at
    the new texel centres: a slope along columns stays along columns, one along rows along
    rows (texel i of N covers [i, i + 1) N' / N of the other map)."""
    def surface(n):
        c = (np.arange(n) + 0.5) / n
        return np.add.outer(0.3 * np.cos(2 * np.pi * c), np.sin(2 * np.pi * c))   # rows, columns
    np.save(tmp_path / "h.npy", surface(32))
    got = read_height(tmp_path / "h.npy", size=64, resample=True)
    assert got.shape == (64, 64)
    inner = (slice(8, -8), slice(8, -8))                  # away from the edge's clamping
    assert np.abs(got - surface(64))[inner].max() < 0.01
    np.save(tmp_path / "wide.npy", surface(64)[:48])     # 64 wide, 48 high: resampled to 64
    assert read_height(tmp_path / "wide.npy", resample=True).shape == (64, 64)


# --- normals ---------------------------------------------------------------------------------

def _expected(right, up, out, convention="opengl"):
    """N' = (-up, right, out) normalized; DirectX's up is the negative (module docstring)."""
    up = up if convention == "opengl" else -up
    n = np.stack([-up, right, out], -1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


@pytest.mark.parametrize("convention", ["opengl", "directx"])
def test_a_png_normal_decodes_channel_by_channel(tmp_path, convention):
    """Channel c encodes 2 c / 255 - 1: red right, green up (OpenGL) or down (DirectX),
    blue out; the frame's x runs down the image, so N' = (-up, right, out), normalized."""
    rng = np.random.default_rng(11)
    rgb = rng.integers(0, 256, (16, 16, 3))
    rgb[..., 2] = rng.integers(129, 256, (16, 16))
    write_png(tmp_path / "n.png", rgb.astype(np.uint8))
    got = read_normals(tmp_path / "n.png", convention)
    r, g, b = (2 * rgb[..., c] / 255 - 1 for c in range(3))
    assert got.shape == (16, 16, 3) and got.dtype == np.float64
    assert np.allclose(got, _expected(r, g, b, convention), rtol=0, atol=1e-12)


@pytest.mark.parametrize("convention", ["opengl", "directx"])
def test_a_npy_normal_is_right_up_out(tmp_path, convention):
    """A (T, T, 3) .npy holds (right, up, out) vectors of any length: re-normalized."""
    rng = np.random.default_rng(12)
    v = rng.normal(size=(16, 16, 3))
    v[..., 2] = np.abs(v[..., 2]) + 0.1
    v *= rng.uniform(0.5, 3.0, (16, 16, 1))
    np.save(tmp_path / "n.npy", v)
    got = read_normals(tmp_path / "n.npy", convention)
    assert np.allclose(got, _expected(v[..., 0], v[..., 1], v[..., 2], convention), rtol=0, atol=1e-12)


def test_normals_to_rgb_encodes_the_axes():
    """The inverse of the decoding, rounded: out = blue 255, a flat texel (128, 128, 255);
    x (down the image) is green 0 in OpenGL and 255 in DirectX; y (right) red 255; values
    past [-1, 1] clip to [0, 255]; uint8."""
    n = np.array([[[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0],
                   [0.0, 2.0, -3.0], [-1.0, 0.0, 0.0]]])
    gl = normals_to_rgb(n)
    assert gl.dtype == np.uint8
    assert gl[0].tolist() == [[128, 128, 255], [128, 0, 128], [255, 128, 128], [0, 128, 128],
                              [255, 128, 0], [128, 255, 128]]
    dx = normals_to_rgb(n, "directx")
    assert dx[0, 1].tolist() == [128, 255, 128] and dx[0, 5].tolist() == [128, 0, 128]
    assert np.array_equal(dx[..., [0, 2]], gl[..., [0, 2]])


@pytest.mark.parametrize("convention", ["opengl", "directx"])
def test_normals_survive_a_png_within_half_a_step(tmp_path, convention):
    """normals -> normals_to_rgb -> PNG -> read_normals: each component within the 8-bit
    step's half (1/255) before re-normalizing, so the direction within asin(sqrt(3)/255)."""
    rng = np.random.default_rng(13)
    n = rng.normal(size=(32, 32, 3))
    n[..., 2] = np.abs(n[..., 2]) + 0.3
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    write_png(tmp_path / "n.png", normals_to_rgb(n, convention))
    back = read_normals(tmp_path / "n.png", convention)
    cos = np.clip(np.sum(back * n, -1), -1, 1)
    assert np.arccos(cos).max() <= np.arcsin(np.sqrt(3) / 255) + 1e-12


def test_a_map_whose_normals_differ_in_one_component_only_has_bumps(tmp_path):
    """Only an all-equal map is all-flat: normals that differ in y alone are bumps."""
    v = np.zeros((16, 16, 3))
    v[..., 0] = np.where(np.arange(16) % 2, 0.6, -0.6)[None, :]     # right: +-0.6
    v[..., 2] = 0.8
    np.save(tmp_path / "n.npy", v)
    got = read_normals(tmp_path / "n.npy")
    assert np.allclose(got[0, 1], [0, 0.6, 0.8]) and np.allclose(got[0, 0], [0, -0.6, 0.8])


def test_texels_into_the_surface_are_counted(tmp_path):
    v = np.zeros((16, 16, 3))
    v[..., 2] = 1.0
    v[4, 5] = (0.3, 0.0, 0.9)
    v[6, 2] = (0.0, 0.6, -0.8)
    v[9, 9] = (0.8, 0.0, 0.0)
    np.save(tmp_path / "n.npy", v)
    msg = _refusal(read_normals, tmp_path / "n.npy")
    assert "2 texels point into the surface (z <= 0, blue < 128), the first at row 6, column 2" in msg


def test_a_normal_map_array_must_be_t_by_t_by_3(tmp_path):
    np.save(tmp_path / "n4.npy", np.ones((16, 16, 4)))
    assert _refusal(read_normals, tmp_path / "n4.npy").endswith(
        "a normal map array must have shape (T, T, 3), got (16, 16, 4)")
    np.save(tmp_path / "n2.npy", np.ones((16, 16)))
    assert "(T, T, 3)" in _refusal(read_normals, tmp_path / "n2.npy")


def test_an_unknown_convention_is_refused():
    assert _refusal(read_normals, "any.png", "vulkan") == \
        "normal_convention must be one of opengl, directx, got 'vulkan'"


def test_a_resampled_normal_map_is_unit_length(tmp_path):
    rng = np.random.default_rng(14)
    v = rng.normal(size=(16, 16, 3))
    v[..., 2] = np.abs(v[..., 2]) + 1.0
    np.save(tmp_path / "n.npy", v)
    got = read_normals(tmp_path / "n.npy", size=32, resample=True)
    assert got.shape == (32, 32, 3) and np.allclose(np.linalg.norm(got, axis=-1), 1, atol=1e-12)


# --- the bump map ------------------------------------------------------------------------------

def test_load_bump_map_defaults_and_labels(tmp_path):
    """A height map at the default height_scale (4 texels for height 1.0) is the plane fit
    of its heights; a normal map has no height field; label is the file's path."""
    h = _ramp(16)
    np.save(tmp_path / "h.npy", h)
    bm = load_bump_map(tmp_path / "h.npy", "height")
    want = displacement_to_normals(h, DEFAULT_HEIGHT_SCALE)
    assert DEFAULT_HEIGHT_SCALE == 4.0
    assert np.allclose(polar_to_cartesian(bm.b_phi_map, bm.b_theta_map), want, atol=1e-12)
    assert bm.label == str(tmp_path / "h.npy") and bm.kind == "height" and bm.size == 16
    np.save(tmp_path / "n.npy", np.dstack([np.zeros((16, 16)), _ramp(16) / 4, np.ones((16, 16))]))
    nm = load_bump_map(tmp_path / "n.npy", "normal")
    assert nm.kind == "normal" and nm.height is None and nm.size == 16
    assert np.allclose(polar_to_cartesian(nm.b_phi_map, nm.b_theta_map),
                       read_normals(tmp_path / "n.npy"), atol=1e-12)


def test_load_bump_map_passes_the_convention_on(tmp_path):
    v = np.dstack([np.zeros((16, 16)), _ramp(16) / 4, np.ones((16, 16))])
    np.save(tmp_path / "n.npy", v)
    gl, dx = (load_bump_map(tmp_path / "n.npy", "normal", c) for c in ("opengl", "directx"))
    assert np.allclose(polar_to_cartesian(dx.b_phi_map, dx.b_theta_map),
                       read_normals(tmp_path / "n.npy", "directx"), atol=1e-12)
    assert not np.allclose(gl.b_phi_map, dx.b_phi_map)


def test_a_cached_bump_map_is_read_only(tmp_path):
    """load_bump_map shares one cached map between callers: its arrays cannot be written."""
    np.save(tmp_path / "h.npy", _ramp(16))
    bm = load_bump_map(tmp_path / "h.npy", "height", height_scale=2)
    for a in (bm.b_phi_map, bm.b_theta_map, bm.height):
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a[0, 0] = 1.0


def test_an_unknown_map_kind_is_refused():
    assert _refusal(load_bump_map, "m.png", "bump") == "map kind must be one of height, normal, got 'bump'"


def test_check_height_scale_takes_positive_finite_numbers():
    """Python and numpy numbers in (0, inf), returned as float; bools, strings, zero,
    negatives, infinity and NaN refused naming height_scale."""
    for value in (1, 0.5, np.float32(2.5), np.int64(3), 1e-300):
        got = check_height_scale(value)
        assert type(got) is float and got == float(value)
    for value in (True, "4", None, 0, 0.0, -1, np.inf, np.nan, np.float64(-2)):
        msg = _refusal(check_height_scale, value)
        assert msg == (f"height_scale must be a positive finite number (texels of relief for "
                       f"height 1.0), got {value!r}")


def test_write_png_writes_rgb_16_bit_and_the_header(tmp_path):
    """write_png's IHDR: width, height, bit depth and colour type (0 grey, 2 RGB)."""
    rgb = (np.arange(5 * 7 * 3).reshape(5, 7, 3) * 997) % 65536
    path = write_png(tmp_path / "c.png", rgb, bit_depth=16)
    raw = path.read_bytes()
    assert raw[:8] == SIG and raw[12:16] == b"IHDR"
    assert struct.unpack(">IIBB", raw[16:26]) == (7, 5, 16, 2)
    grey = write_png(tmp_path / "g.png", np.arange(35, dtype=np.uint8).reshape(5, 7)).read_bytes()
    assert struct.unpack(">IIBB", grey[16:26]) == (7, 5, 8, 0)
    assert np.array_equal(np.asarray(Image.open(tmp_path / "g.png")), np.arange(35).reshape(5, 7))


# --- resampling, sizes given, and what counts as flat -----------------------------------------

def _lanczos_matrix(n_in, n_out):
    """Lanczos-3 weights (sinc(x) sinc(x / 3), |x| < 3, widened by the ratio when shrinking)
    from n_in texel centres to n_out, each row normalized, the window cut at the edges."""
    scale = n_in / n_out
    widen = max(scale, 1.0)
    w = np.zeros((n_out, n_in))
    for i in range(n_out):
        centre = (i + 0.5) * scale
        lo, hi = max(int(centre - 3 * widen + 0.5), 0), min(int(centre + 3 * widen + 0.5), n_in)
        x = (np.arange(lo, hi) + 0.5 - centre) / widen
        k = np.where(np.abs(x) < 3, np.sinc(x) * np.sinc(x / 3), 0.0)
        w[i, lo:hi] = k / k.sum()
    return w


@pytest.mark.parametrize("side, size", [(16, 32), (64, 16)])
def test_resampling_is_lanczos(tmp_path, side, size):
    """The module resamples with Lanczos (a = 3), rows and columns separately: a random map
    resampled is the separable Lanczos-3 filter of it (float32 precision)."""
    rng = np.random.default_rng(15)
    h = rng.uniform(size=(side, side))
    np.save(tmp_path / "h.npy", h)
    got = read_height(tmp_path / "h.npy", size=size, resample=True)
    w = _lanczos_matrix(side, size)
    assert np.abs(got - w @ h @ w.T).max() < 1e-5


def test_a_tall_map_is_resampled_to_the_size_of_its_longer_side(tmp_path):
    """Not square: the nearest allowed size to the larger side (40 rows -> 32, not 16)."""
    np.save(tmp_path / "tall.npy", _ramp(40, 16))
    assert read_height(tmp_path / "tall.npy", resample=True).shape == (32, 32)
    v = np.dstack([np.zeros((40, 16)), _ramp(40, 16) / 4, np.ones((40, 16))])
    np.save(tmp_path / "tall_n.npy", v)
    assert read_normals(tmp_path / "tall_n.npy", resample=True).shape == (32, 32, 3)


def test_a_normal_map_at_an_odd_size_is_resampled_to_the_nearest(tmp_path):
    v = np.dstack([np.zeros((24, 24)), _ramp(24) / 4, np.ones((24, 24))])
    np.save(tmp_path / "n.npy", v)
    assert "nearest allowed size is 32x32" in _refusal(read_normals, tmp_path / "n.npy")
    got = read_normals(tmp_path / "n.npy", resample=True)
    assert got.shape == (32, 32, 3) and np.allclose(np.linalg.norm(got, axis=-1), 1, atol=1e-12)


def test_a_normal_map_at_the_size_asked_for_is_kept_and_another_refused(tmp_path):
    v = np.dstack([np.zeros((16, 16)), _ramp(16) / 4, np.ones((16, 16))])
    np.save(tmp_path / "n.npy", v)
    assert np.array_equal(read_normals(tmp_path / "n.npy", size=16), read_normals(tmp_path / "n.npy"))
    assert _refusal(read_normals, tmp_path / "n.npy", size=32).startswith(
        f"{tmp_path / 'n.npy'}: 16x16 texels but texture_size = 32 (pass --resample")


def test_vectors_of_one_direction_are_flat_whatever_their_lengths(tmp_path):
    """Every vector is re-normalized, so (0, 0, 1) and (0, 0, 2) are the same normal: a map
    of them has no bumps."""
    v = np.zeros((16, 16, 3))
    v[..., 2] = 1.0
    v[::2, :, 2] = 2.0
    np.save(tmp_path / "n.npy", v)
    assert "every texel has the same normal" in _refusal(read_normals, tmp_path / "n.npy")


def test_a_single_texel_map_is_flat(tmp_path):
    np.save(tmp_path / "one.npy", np.full((1, 1), 0.75))
    assert "every texel has the same height (0.75)" in _refusal(read_height, tmp_path / "one.npy")


@pytest.mark.parametrize("kind, ctype, ending", [
    ("height", 2, "a height map is a 1-channel greyscale PNG (an RGB normal map goes to --normal-map)"),
    ("height", 3, "a height map is a 1-channel greyscale PNG"),
    ("normal", 0, "a normal map is an RGB PNG (3 channels) (a greyscale height map goes to --height-map)"),
    ("normal", 3, "a normal map is an RGB PNG (3 channels)"),
])
def test_a_wrong_kind_of_png_ends_with_the_hint_or_nothing(tmp_path, kind, ctype, ending):
    path = _file(tmp_path, "m.png", _header(16, 16, 8, ctype))
    assert _refusal(map_size, path, kind=kind).endswith(ending)


def test_an_unreadable_file_is_named_with_the_reason(tmp_path):
    """A file that exists but cannot be read: the OS's reason, in one line."""
    link = tmp_path / "mem.png"
    link.symlink_to("/proc/self/mem")                   # a file whose read fails (EIO)
    with pytest.raises(OSError) as e:                 # Linux: EIO at offset 0
        link.read_bytes()
    reason = e.value.strerror
    assert _refusal(map_size, link) == f"{link}: cannot read ({reason})"


def _chunks(raw):
    """(tag, data) of every chunk of a PNG, each chunk's CRC checked (PNG spec: CRC-32 of the
    tag and the data)."""
    out, pos = [], 8
    while pos < len(raw):
        (length,) = struct.unpack(">I", raw[pos:pos + 4])
        tag, data = raw[pos + 4:pos + 8], raw[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", raw[pos + 8 + length:pos + 12 + length])
        assert crc == zlib.crc32(tag + data), tag
        out.append((tag, data))
        pos += 12 + length
    return out


@pytest.mark.parametrize("shape, depth, ctype", [((5, 7), 8, 0), ((5, 7, 3), 16, 2), ((3, 9, 3), 8, 2)])
def test_write_png_is_ihdr_idat_iend(tmp_path, shape, depth, ctype):
    """PNG structure: the signature, then IHDR (width, height, depth, colour type, and 0 for
    compression, filter and interlace), one IDAT of filter-0 rows, an empty IEND."""
    rng = np.random.default_rng(16)
    pixels = rng.integers(0, 2 ** depth, shape)
    raw = write_png(tmp_path / "p.png", pixels, bit_depth=depth).read_bytes()
    assert raw[:8] == SIG
    chunks = _chunks(raw)
    assert [t for t, _ in chunks] == [b"IHDR", b"IDAT", b"IEND"] and chunks[2][1] == b""
    assert struct.unpack(">IIBBBBB", chunks[0][1]) == (shape[1], shape[0], depth, ctype, 0, 0, 0)
    rows = zlib.decompress(chunks[1][1])
    stride = 1 + shape[1] * (3 if ctype == 2 else 1) * depth // 8
    assert len(rows) == shape[0] * stride and all(rows[i * stride] == 0 for i in range(shape[0]))
    body = b"".join(rows[i * stride + 1:(i + 1) * stride] for i in range(shape[0]))
    back = np.frombuffer(body, ">u2" if depth == 16 else np.uint8).reshape(shape)
    assert np.array_equal(back, pixels)
