import numpy as np
from PIL import Image

from bumprtl.sim.scenes import load_scene
from bumprtl.sim.scenes.imaging import compose, max_diff, panel, psnr, save_png


def test_psnr_and_max_diff_closed_forms():
    a = np.full((8, 8, 3), 100, np.uint8)
    b = a.copy()
    assert psnr(a, b) == float("inf") and max_diff(a, b) == 0
    b[...] = 101                                    # MSE 1 -> 20 log10(255)
    assert abs(psnr(a, b) - 20 * np.log10(255)) < 1e-12
    b[0, 0, 0] = 0                                  # uint8 must not wrap in the difference
    assert max_diff(a, b) == 100 and max_diff(b, a) == 100


def test_panel_layout():
    ref = np.zeros((4, 5, 3), np.uint8)
    img = ref.copy()
    img[1, 2] = 3
    img[2, 2] = 40                                  # x10 saturates at 255
    p = panel(ref, img)
    assert p.shape == (4, 3 * 5 + 8, 3)
    assert np.all(p[:, 5:9] == 255) and np.all(p[:, 14:18] == 255)   # gutters
    assert np.array_equal(p[:, 9:14], img)
    assert np.all(p[1, 20] == 30) and np.all(p[2, 20] == 255) and p[0, 18:].max() == 0


def test_compose_albedo_and_background():
    s = load_scene("globe", size=32)
    assert s.albedo is None
    img = compose(s, np.ones(s.mask.shape))
    assert np.all(img[s.mask] == 255) and np.all(img[~s.mask] == 0)
    b = load_scene("bricks", size=32)
    img = compose(b, np.ones(b.mask.shape))
    want = np.clip(np.rint(b.albedo[b.v, b.u] * 255), 0, 255)
    assert np.array_equal(img, want)


def test_save_png_round_trip(tmp_path):
    img = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    path = save_png(tmp_path / "sub" / "x.png", img)
    assert np.array_equal(np.asarray(Image.open(path)), img)
