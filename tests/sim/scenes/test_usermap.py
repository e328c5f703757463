"""A user's height or normal map (sim/scenes/usermap.py): decoding, the two green-channel
conventions, resampling, every bad input refused with one line naming the file, and the
normal-map round trip held to a bound derived from the PNG's 8-bit quantization."""

import os

import numpy as np
import pytest
from PIL import Image

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.common import polar_to_cartesian
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.palette import displacement_to_normals
from bumprtl.sim.scenes import load_scene
from bumprtl.sim.scenes.imaging import compose
from bumprtl.sim.scenes.usermap import (
    load_bump_map,
    map_size,
    nearest_allowed_size,
    normals_to_rgb,
    read_height,
    read_normals,
    write_png,
)


def hex_tiles(t, seed=3, tiles=6):
    """An unseen height map: hexagonal tiles of random heights with bevelled grout."""
    rng = np.random.default_rng(seed)
    y, x = (np.mgrid[0:t, 0:t] + 0.5) / t * tiles
    r = np.array([1.0, np.sqrt(3)])
    p = np.stack([x, y], -1)
    a, b = np.mod(p, r) - r / 2, np.mod(p - r / 2, r) - r / 2
    g = np.where(((a ** 2).sum(-1) < (b ** 2).sum(-1))[..., None], a, b)
    q = np.abs(g)
    edge = np.maximum(q[..., 0] * 0.5 + q[..., 1] * np.sqrt(3) / 2, q[..., 0])
    keys = np.round((p - g) * 1000).astype(np.int64)
    _, tile = np.unique(keys[..., 0] * 10 ** 7 + keys[..., 1], return_inverse=True)
    top = rng.uniform(0.5, 1.0, tile.max() + 1)[tile.reshape(t, t)]
    return top * np.clip((0.5 - edge) / 0.1, 0, 1)


def _grey_png(path, h, bits=8):
    scale = 255 if bits == 8 else 65535
    Image.fromarray(np.rint(h * scale).astype(np.uint8 if bits == 8 else np.uint16)).save(path)
    return path


def test_height_map_png_8_and_16_bit_and_npy_give_the_plane_fit(tmp_path):
    h = hex_tiles(64)
    for path, q in ((_grey_png(tmp_path / "h8.png", h), 255), (_grey_png(tmp_path / "h16.png", h, 16), 65535)):
        got = read_height(path)
        assert np.array_equal(got, np.rint(h * q) / q)
    np.save(tmp_path / "h.npy", h)
    bm = load_bump_map(tmp_path / "h.npy", "height", height_scale=3.0)
    want = displacement_to_normals(h, 3.0)                      # Tarini Sec. 4.1
    assert np.allclose(polar_to_cartesian(bm.b_phi_map, bm.b_theta_map), want, atol=1e-12)
    assert bm.size == 64 and bm.kind == "height" and np.array_equal(bm.height, h)


def test_normal_map_axes_and_conventions(tmp_path):
    """A texel whose normal leans to the right of the image (red > 128) and up the image
    (green > 128 in OpenGL) is N' = (-up, right, z) in the bump map's frame (tangent x down
    the rows); DirectX's green points down, so the flipped file decodes to the same map."""
    rng = np.random.default_rng(5)
    n = rng.normal(size=(32, 32, 3))
    n[..., 2] = np.abs(n[..., 2]) + 0.5
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    rgb = normals_to_rgb(n, "opengl")
    write_png(tmp_path / "gl.png", rgb)
    write_png(tmp_path / "dx.png", np.stack([rgb[..., 0], 255 - rgb[..., 1], rgb[..., 2]], -1))
    gl = read_normals(tmp_path / "gl.png", "opengl")
    assert np.allclose(gl, read_normals(tmp_path / "dx.png", "directx"), atol=1e-15, rtol=0)
    assert np.abs(normals_to_rgb(n, "directx").astype(int) - rgb * [1, -1, 1] - [0, 255, 0]).max() <= 1
    assert not np.allclose(gl, read_normals(tmp_path / "dx.png", "opengl"))   # the flag matters
    rgb = np.asarray(Image.open(tmp_path / "gl.png"), float)
    right, up = 2 * rgb[..., 0] / 255 - 1, 2 * rgb[..., 1] / 255 - 1
    assert np.all(np.sign(gl[..., 1]) == np.sign(right)) and np.all(np.sign(gl[..., 0]) == -np.sign(up))
    assert np.allclose(np.linalg.norm(gl, axis=-1), 1, atol=1e-12)             # re-normalized


def test_normal_map_matches_the_height_map_lighting(tmp_path):
    """Height rising to the right (dh/du > 0) leans the normal left: an OpenGL normal map of
    that surface has red < 128 and renders like the height map (sign conventions agree)."""
    t = 32
    h = np.tile(np.arange(t) / t, (t, 1))
    n = displacement_to_normals(h, 4.0)
    rgb = normals_to_rgb(n)
    assert rgb[5, 5, 0] < 128 and abs(int(rgb[5, 5, 1]) - 128) <= 1


def test_power_of_two_refused_with_nearest_size_or_resampled(tmp_path):
    h = hex_tiles(96)                       # 96 x 96: not a power of two
    path = _grey_png(tmp_path / "h96.png", h)
    with pytest.raises(BumpError, match=r"h96\.png: 96x96 .*nearest allowed size is 128x128"):
        read_height(path)
    with pytest.raises(BumpError, match="nearest allowed size is 128x128"):
        map_size(path)
    assert map_size(path, resample=True) == 128
    got = read_height(path, resample=True)
    assert got.shape == (128, 128)                          # resampled, never cropped
    assert abs(got.mean() - h.mean()) < 0.01
    wide = _grey_png(tmp_path / "wide.png", hex_tiles(64)[:, :48])
    with pytest.raises(BumpError, match="48x64 .*nearest allowed size is 64x64"):
        read_height(wide)
    assert nearest_allowed_size(2800) == 2048 and nearest_allowed_size(3000) == 4096   # by ratio
    assert nearest_allowed_size(5) == 16 and nearest_allowed_size(9000) == 4096
    with pytest.raises(BumpError, match="texture_size = 32"):
        map_size(_grey_png(tmp_path / "h64.png", hex_tiles(64)), texture_size=32)


def _truncated(tmp_path):
    good = _grey_png(tmp_path / "good.png", hex_tiles(64))
    raw = good.read_bytes()
    (tmp_path / "cut.png").write_bytes(raw[:len(raw) // 2])
    return tmp_path / "cut.png"


def _bad_inputs(tmp_path):
    """(function, args, words in the message) of every bad input."""
    h = hex_tiles(32)
    rgb = normals_to_rgb(displacement_to_normals(h, 4.0))
    (tmp_path / "junk.png").write_bytes(b"not a png at all")
    nan = h.copy()
    nan[3, 4] = np.nan
    np.save(tmp_path / "nan.npy", nan)
    inf = h.copy()
    inf[0, 0] = np.inf
    np.save(tmp_path / "inf.npy", inf)
    np.save(tmp_path / "flat.npy", np.full((32, 32), 0.5))
    write_png(tmp_path / "rgb16.png", rgb.astype(np.uint16) * 257, bit_depth=16)
    write_png(tmp_path / "rgb.png", rgb)
    Image.fromarray(np.rint(h * 255).astype(np.uint8)).convert("LA").save(tmp_path / "la.png")
    _grey_png(tmp_path / "grey.png", h)
    write_png(tmp_path / "flatn.png", np.full((32, 32, 3), [128, 128, 255], np.uint8))
    inward = rgb.copy()
    inward[7, 9] = [128, 128, 20]
    write_png(tmp_path / "inward.png", inward)
    (tmp_path / "h.txt").write_text("1 2 3")
    np.save(tmp_path / "cplx.npy", h.astype(complex))
    return [
        ("missing.png", "height", ["missing.png", "no such file"]),
        ("junk.png", "height", ["junk.png", "not a PNG"]),
        (_truncated(tmp_path).name, "height", ["cut.png", "truncated"]),
        ("rgb.png", "height", ["rgb.png", "3 channel", "greyscale", "--normal-map"]),
        ("la.png", "height", ["la.png", "2 channel"]),
        ("grey.png", "normal", ["grey.png", "1 channel", "RGB", "--height-map"]),
        ("rgb16.png", "normal", ["rgb16.png", "16-bit", "8 bits"]),
        ("nan.npy", "height", ["nan.npy", "NaN", "(3, 4)"]),
        ("inf.npy", "height", ["inf.npy", "infinity"]),
        ("flat.npy", "height", ["flat.npy", "all-flat"]),
        ("flatn.png", "normal", ["flatn.png", "all-flat"]),
        ("inward.png", "normal", ["inward.png", "into the surface", "row 7, column 9"]),
        ("h.txt", "height", ["h.txt", ".png or .npy"]),
        ("cplx.npy", "height", ["cplx.npy", "complex"]),
    ]


def test_every_bad_map_is_one_line_naming_the_file(tmp_path):
    for name, kind, words in _bad_inputs(tmp_path):
        with pytest.raises(BumpError) as e:
            load_bump_map(tmp_path / name, kind)
        msg = str(e.value)
        assert "\n" not in msg and all(w in msg for w in words), (name, msg)
    with pytest.raises(BumpError, match="height_scale"):
        load_bump_map(tmp_path / "grey.png", "height", height_scale=-1)


def test_user_map_scene_uses_its_map_and_geometry(tmp_path):
    h = hex_tiles(64)
    bm = load_bump_map(_grey_png(tmp_path / "h.png", h), "height")
    s = load_scene(None, size=32, bump=bm, geometry="sphere")
    assert s.geometry == "sphere" and s.texture_size == 64 and s.albedo is None
    assert np.array_equal(s.px.b_phi, bm.b_phi_map[s.v, s.u])
    assert load_scene(None, size=32, bump=bm).geometry == "plane"
    with pytest.raises(BumpError, match="texture_size = 32"):
        load_scene(None, size=32, bump=bm, texture_size=32)


def _round_trip_bound(cfg):
    """The largest 8-bit difference between renders of the same normals, one decoded from an
    8-bit normal-map PNG. Each stored component c in [-1, 1] becomes round((c + 1) 255 / 2),
    decoded as 2 q / 255 - 1: off by at most 1/255 per component, |dn| <= sqrt(3)/255, so
    after re-normalizing the direction turns by alpha <= asin(sqrt(3)/255). The angle of N'
    to L (and to H) then changes by at most alpha: diffuse cos changes by at most alpha, the
    specular cos^p by at most alpha * max|d cos^p/d theta| = alpha sqrt(p) ((p-1)/p)^((p-1)/2)
    (at tan^2 theta = 1/(p-1)); clamping to [0, 1] and the albedo (<= 1) only shrink it. So the
    colour moves by delta <= (kd + ks g(p)) alpha, and two 8-bit roundings by at most
    floor(255 delta + 1)."""
    alpha = np.arcsin(np.sqrt(3) / 255)
    p = cfg.spec_exponent
    g = np.sqrt(p) * ((p - 1) / p) ** ((p - 1) / 2) if p > 1 else 1.0
    return int(np.floor(255 * (cfg.kd + cfg.ks * g) * alpha + 1))


def test_normal_map_round_trip_within_the_png_quantization(tmp_path):
    """height map -> normals (plane fit) -> 8-bit normal-map PNG -> --normal-map renders the
    height map's picture within the derived bound; the measured error is printed."""
    cfg = Config()
    bound = _round_trip_bound(cfg)
    assert bound == 3                                        # for the default Config
    h = hex_tiles(64)
    hmap = load_bump_map(_grey_png(tmp_path / "h.png", h), "height", height_scale=4.0)
    n = polar_to_cartesian(hmap.b_phi_map, hmap.b_theta_map)
    write_png(tmp_path / "n.png", normals_to_rgb(n))
    nmap = load_bump_map(tmp_path / "n.png", "normal")
    worst = 0
    for geometry in ("plane", "sphere"):
        for az in (30.0, 200.0):
            a, b = (load_scene(None, size=128, bump=m, geometry=geometry, light_azimuth=az)
                    for m in (hmap, nmap))
            ia, ib = (compose(s, conventional(s.px, cfg).color).astype(int) for s in (a, b))
            worst = max(worst, int(np.abs(ia - ib).max()))
    print(f"normal-map round trip: max |difference| {worst} LSB (bound {bound})")
    assert 0 < worst <= bound


@pytest.mark.parametrize("bad, where", [((0.6, 0.8, 0.0), "in the surface"),
                                        ((0.6, 0.8, -0.0), "in the surface, -0.0"),
                                        ((0.2, -0.1, -0.5), "below the surface"),
                                        ((0.0, 0.0, 0.0), "no direction")])
def test_npy_normal_in_or_below_the_surface_is_refused(tmp_path, bad, where):
    """A (T, T, 3) .npy normal map with one texel whose z <= 0 (or of length 0) is refused
    with one line naming the file and the texel, as a PNG's blue < 128 is; a texel just
    above the surface is accepted."""
    n = displacement_to_normals(hex_tiles(32), 4.0)          # x right, y up, z out: rgb order
    n[5, 11] = bad
    np.save(tmp_path / "bad.npy", n)
    with pytest.raises(BumpError) as e:
        load_bump_map(tmp_path / "bad.npy", "normal")
    msg = str(e.value)
    assert "\n" not in msg and all(w in msg for w in ("bad.npy", "into the surface",
                                                      "row 5, column 11")), (where, msg)
    n[5, 11] = (0.6, 0.8, 1e-6)
    np.save(tmp_path / "ok.npy", n)
    assert read_normals(tmp_path / "ok.npy")[5, 11, 2] > 0


def test_npy_normal_below_the_surface_exits_2_in_one_line(tmp_path, capsys):
    from bumprtl.gen.cli.main import main
    n = displacement_to_normals(hex_tiles(16), 4.0)
    n[2, 3] = (0.0, 0.6, -0.8)
    np.save(tmp_path / "under.npy", n)
    rc = main(["emit", "pipeline", "--normal-map", str(tmp_path / "under.npy"),
               "--out", str(tmp_path / "rtl")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "under.npy" in err[0] and "into the surface" in err[0], err


def test_map_size_of_a_2d_npy_height_map_and_a_3d_normal_map(tmp_path):
    np.save(tmp_path / "h.npy", hex_tiles(32))
    np.save(tmp_path / "n.npy", displacement_to_normals(hex_tiles(64), 4.0))
    assert map_size(tmp_path / "h.npy") == 32 and map_size(tmp_path / "n.npy", kind="normal") == 64


def test_a_nan_in_a_npy_normal_map_names_the_file(tmp_path):
    n = displacement_to_normals(hex_tiles(32), 4.0)
    n[4, 6, 1] = np.nan
    np.save(tmp_path / "nan_normals.npy", n)
    with pytest.raises(BumpError) as e:
        load_bump_map(tmp_path / "nan_normals.npy", "normal")
    msg = str(e.value)
    assert "\n" not in msg and "nan_normals.npy" in msg and "NaN" in msg, msg


def test_write_png_16_bit_round_trip(tmp_path):
    """The test helper writes 16-bit samples as 16 bits (the 16-bit refusals rest on it)."""
    grey = np.arange(32 * 32, dtype=np.int64).reshape(32, 32) * 61
    write_png(tmp_path / "g16.png", grey, bit_depth=16)
    img = Image.open(tmp_path / "g16.png")
    assert img.mode.startswith("I") and np.array_equal(np.asarray(img, dtype=np.int64), grey)


def test_map_size_refuses_every_bad_png_header_naming_the_file(tmp_path):
    """map_size reads only the header (the CLI sizes a map before loading it): a bad
    signature, a truncated header or channels that do not fit the map kind are refused there
    already, in one line naming the file, as load_bump_map refuses them."""
    header_problems = ("no such file", "not a PNG", "channel", "16-bit")
    cases = [(name, kind, words) for name, kind, words in _bad_inputs(tmp_path)
             if name.endswith(".png") and any(h in w for w in words for h in header_problems)]
    raw = (tmp_path / "grey.png").read_bytes()
    (tmp_path / "head.png").write_bytes(raw[:20])           # the signature, IHDR cut short
    cases.append(("head.png", "height", ["head.png", "truncated"]))
    assert len(cases) == 7
    for name, kind, words in cases:
        with pytest.raises(BumpError) as e:
            map_size(tmp_path / name, kind=kind)
        msg = str(e.value)
        assert "\n" not in msg and all(w in msg for w in words), (name, msg)


def test_a_rewritten_map_file_is_read_again(tmp_path):
    """load_bump_map caches by path, modification time and arguments: the same file loaded
    twice is one map, but a file rewritten in place (a user editing the map between two
    renders) is read again, not served from the cache."""
    path = tmp_path / "h.png"
    _grey_png(path, hex_tiles(32, seed=1))
    first = load_bump_map(path, "height")
    assert load_bump_map(path, "height") is first
    _grey_png(path, hex_tiles(32, seed=2))
    stamp = path.stat().st_mtime_ns + 10 ** 9           # a later time, whatever the clock's grain
    os.utime(path, ns=(stamp, stamp))
    second = load_bump_map(path, "height")
    assert not np.array_equal(second.b_phi_map, first.b_phi_map)
    fresh = load_bump_map(_grey_png(tmp_path / "copy.png", hex_tiles(32, seed=2)), "height")
    assert np.array_equal(second.b_phi_map, fresh.b_phi_map)


def test_load_bump_map_resamples_to_the_size_asked_for(tmp_path):
    """load_bump_map at size T gives a T x T map (resampled with resample, refused without);
    without a size, the file's own size."""
    from bumprtl.sim.scenes.usermap import MapError, load_bump_map

    path = tmp_path / "h.npy"
    y, x = np.mgrid[0:16, 0:16]
    np.save(path, np.sin(2 * np.pi * x / 16) * np.cos(2 * np.pi * y / 16))
    assert load_bump_map(path, "height").size == 16
    got = load_bump_map(path, "height", size=32, resample=True)
    assert got.size == 32 and got.b_phi_map.shape == got.b_theta_map.shape == (32, 32)
    with pytest.raises(MapError, match="texture_size = 32"):
        load_bump_map(path, "height", size=32)


def test_an_rgba_normal_map_is_read_only_when_opaque(tmp_path):
    from PIL import Image

    from bumprtl.sim.scenes.usermap import MapError, read_normals

    rgba = np.zeros((16, 16, 4), np.uint8)
    rgba[..., :3] = (128, 128, 255)                      # +z everywhere
    rgba[..., 3] = 255
    rgba[3, 4, :3] = (200, 128, 230)
    Image.fromarray(rgba, "RGBA").save(tmp_path / "opaque.png")
    n = read_normals(tmp_path / "opaque.png")
    assert n.shape == (16, 16, 3) and np.allclose(np.linalg.norm(n, axis=-1), 1)
    rgba[7, 2, 3] = 254                                   # one texel not opaque
    Image.fromarray(rgba, "RGBA").save(tmp_path / "alpha.png")
    with pytest.raises(MapError) as e:
        read_normals(tmp_path / "alpha.png")
    assert "alpha.png" in str(e.value) and "alpha" in str(e.value).split("alpha.png", 1)[1]


def test_normals_to_rgb_rounds_float32_normals_as_given():
    """A float32 normal map (a user's .npy) is rounded to 8 bits from its values as given,
    exactly as the same values in float64 (float32 arithmetic would round some texels at a
    half step the other way)."""
    rng = np.random.default_rng(0)
    n = rng.normal(size=(256, 256, 3))
    n[..., 2] = np.abs(n[..., 2])
    n32 = (n / np.linalg.norm(n, axis=-1, keepdims=True)).astype(np.float32)
    assert np.array_equal(normals_to_rgb(n32), normals_to_rgb(n32.astype(np.float64)))


def test_resampling_interpolates_unit_normals(tmp_path):
    """A normal map resampled to another size interpolates each texel's unit normal, then
    normalises: the 8-bit texels' own lengths (each a little off 1) must not weight the
    interpolation."""
    from bumprtl.sim.scenes.usermap import _resize
    rng = np.random.default_rng(4)
    n = rng.normal(size=(64, 64, 3))
    n[..., 2] = np.abs(n[..., 2]) + 0.5
    path = tmp_path / "normals.png"
    write_png(path, normals_to_rgb(n / np.linalg.norm(n, axis=-1, keepdims=True)))
    unit = read_normals(path)                                   # 64 x 64, each texel unit
    want = _resize(unit, 32)
    want /= np.linalg.norm(want, axis=-1, keepdims=True)
    assert np.allclose(read_normals(path, size=32, resample=True), want, rtol=0, atol=1e-6)


def test_written_pngs_pass_a_decoders_check(tmp_path):
    """write_png's files pass Pillow's own check of the chunks (each chunk's CRC, IEND last),
    greyscale and RGB, 8 and 16 bits."""
    rng = np.random.default_rng(2)
    for name, pixels, depth in (("g8", rng.integers(0, 256, (5, 7)), 8),
                                ("g16", rng.integers(0, 65536, (5, 7)), 16),
                                ("rgb8", rng.integers(0, 256, (5, 7, 3)), 8),
                                ("rgb16", rng.integers(0, 65536, (5, 7, 3)), 16)):
        path = tmp_path / f"{name}.png"
        write_png(path, pixels, bit_depth=depth)
        Image.open(path).verify()


def test_map_size_of_a_bad_npy_names_the_file(tmp_path):
    """map_size reads a .npy's shape only, but a file that is no array, or an array of
    booleans, is still one line naming the file."""
    (tmp_path / "junk.npy").write_bytes(b"not an array")
    np.save(tmp_path / "bits.npy", np.zeros((32, 32), bool))
    for name, words in (("junk.npy", "not a readable .npy"), ("bits.npy", "real numbers")):
        with pytest.raises(BumpError) as e:
            map_size(tmp_path / name)
        assert str(e.value).startswith(str(tmp_path / name) + ": ") and words in str(e.value)


def _lanczos_matrix(n_in, n_out):
    """Written here: the (n_out, n_in) weights of a Lanczos-3 resampling of one axis, as an
    image resize computes it (output texel i centred at (i + 0.5) n_in / n_out input texels,
    the kernel sinc(x) sinc(x / 3) on |x| < 3 stretched by the scale when shrinking, its
    window cut at the edges and the weights normalised to sum 1)."""
    scale = n_in / n_out
    stretch = max(scale, 1.0)
    support = 3.0 * stretch
    m = np.zeros((n_out, n_in))
    for i in range(n_out):
        centre = (i + 0.5) * scale
        lo, hi = max(int(centre - support + 0.5), 0), min(int(centre + support + 0.5), n_in)
        x = (np.arange(lo, hi) - centre + 0.5) / stretch
        w = np.where(np.abs(x) < 3, np.sinc(x) * np.sinc(x / 3), 0.0)
        m[i, lo:hi] = w / w.sum()
    return m


@pytest.mark.parametrize("shape, size, height", [((96, 80), 64, 32), ((40, 24), 32, 16),
                                                 ((16, 48), 64, 16)])
def test_a_non_square_resampled_map_is_the_independent_resampling(tmp_path, shape, size, height):
    """A height map resampled to texture_size x texture_height (W x H): each axis on its
    own, the rows to H and the columns to W (a transposed or squared resampling differs);
    the heights equal a separable Lanczos-3 resampling written here, and the scene's bump
    map is the plane fit of those heights."""
    rng = np.random.default_rng(shape[0])
    h = rng.random(shape)
    path = tmp_path / "h.npy"
    np.save(path, h)
    want = _lanczos_matrix(shape[0], height) @ h @ _lanczos_matrix(shape[1], size).T
    got = read_height(path, size, resample=True, height=height)
    assert got.shape == (height, size)
    assert np.allclose(got, want, rtol=0, atol=2e-5), np.abs(got - want).max()
    from bumprtl.gen.render.rtl import sim_scene
    from bumprtl.sim.scenes.config import load_scene_config
    scene = load_scene_config({"height_map": str(path), "texture_size": size,
                               "texture_height": height, "resample": True})
    assert (scene.texture_size, scene.map_height) == (size, height)
    base = sim_scene(scene, 16)
    assert base.b_phi_map.shape == (height, size)
    assert np.allclose(polar_to_cartesian(base.b_phi_map, base.b_theta_map),
                       displacement_to_normals(want, scene.height_scale), rtol=0, atol=1e-4)


def test_a_w_by_h_map_is_its_own_size_with_texture_height(tmp_path):
    """A 64 x 32 PNG with texture_height = 32 is read as it is (its width the texture_size),
    no resampling; without texture_height it is refused (not square), and with a height
    that is not its own it needs resample, the message naming both sides."""
    from bumprtl.sim.scenes.config import load_scene_config
    from bumprtl.sim.scenes.usermap import MapError
    h = hex_tiles(64)[:32]
    path = _grey_png(tmp_path / "wide.png", h)
    assert map_size(path, texture_height=32) == 64
    scene = load_scene_config({"height_map": str(path), "texture_height": 32})
    assert (scene.texture_size, scene.texture_height) == (64, 32)
    bm = load_bump_map(path, "height", size=64, height=32)
    assert (bm.size, bm.texture_height) == (64, 32)
    assert np.allclose(read_height(path, 64, height=32), np.rint(h * 255) / 255)
    with pytest.raises(MapError, match="64x32 texels; a map must be square"):
        load_scene_config({"height_map": str(path)})
    with pytest.raises(MapError, match="64x32 texels but texture_size x texture_height = 64 x 16"):
        load_scene_config({"height_map": str(path), "texture_height": 16})


@pytest.mark.parametrize("size, height", [(None, 16), (32, 16), (64, 16)])
def test_a_non_square_normal_map_keeps_its_shape_and_content(tmp_path, size, height):
    """A 32 x 16 normal map read at ``height`` 16 (its own width, or resampled to 64 wide)
    keeps its aspect: the result is ``height`` rows of ``size`` texels, each the unit
    normal of the file's texel there (resampled: the per-channel Lanczos of the unit
    normals, normalised, as a square map is)."""
    from bumprtl.sim.scenes.usermap import _resize
    rng = np.random.default_rng(5)
    n = rng.normal(size=(16, 32, 3))
    n[..., 2] = np.abs(n[..., 2]) + 0.5
    path = tmp_path / "wide.png"
    write_png(path, normals_to_rgb(n / np.linalg.norm(n, axis=-1, keepdims=True)))
    own = read_normals(path, height=16)
    assert own.shape == (16, 32, 3)
    got = read_normals(path, size=size, height=height, resample=True)
    width = size or 32
    assert got.shape == (height, width, 3)
    want = own if width == 32 else _resize(own, width, height)
    want = want / np.linalg.norm(want, axis=-1, keepdims=True)
    assert np.allclose(got, want, rtol=0, atol=1e-6)
    assert np.allclose(np.linalg.norm(got, axis=-1), 1)
