"""``bumprtl bench palette`` at tiny sizes: the command it prints, the speed table's
arithmetic (frame = colour table + lookup, ratio = per-pixel / frame), the accuracy table
(a palette holding every normal of the map quantizes nothing), the plot and the images it
names (gen/bench/palette.py)."""

import re

import numpy as np
import pytest
from PIL import Image

from bumprtl.gen.bench import palette
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.float.palette import distinct_normals
from bumprtl.sim.scenes import load_scene


def _rows(text, first):
    return [line for line in text.splitlines() if line.startswith(first)]


def test_speed_rows_add_the_table_and_the_lookup_and_divide(monkeypatch, capsys):
    """With the timer replaced (table 2 ms, lookup 1 ms, per-pixel 9 ms each call), every
    (size, sN) row says frame 3.00 ms and ratio 3.0x, in --sizes x --palettes order; the
    timed functions return what they time (the shaded table, the looked-up image)."""
    seconds = iter([0.002, 0.001, 0.009] * 4)
    shapes = []

    def fake_best(fn, repeats=3):
        shapes.append(np.shape(fn()))
        return next(seconds)

    monkeypatch.setattr(palette, "_best", fake_best)
    palette.speed(Config(), (8, 16), (4, 32))
    rows = _rows(capsys.readouterr().out, "| ")
    assert rows[0].split("|")[1:-1] == [" image ", " sN ", " colour table ms ", " lookup ms ",
                                        " palette frame ms ", " per-pixel ms ", " ratio "]
    body = rows[1:]                     # after the header (the |---| line starts "|-")
    assert [r.split(" | ")[:2] for r in body] == [["| 8²", "4"], ["| 8²", "32"],
                                                 ["| 16²", "4"], ["| 16²", "32"]]
    for r in body:
        assert r.endswith("| 2.00 | 1.00 | 3.00 | 9.0 | 3.0x |"), r
    # per row: colour table (sN shaded colours), lookup (size x size pixels), per-pixel
    assert shapes[0][0] == 4 and shapes[1][:2] == (8, 8) and shapes[2][0] == 64
    assert shapes[9][0] == 32 and shapes[10][:2] == (16, 16) and shapes[11][0] == 256


def test_accuracy_marks_a_palette_that_holds_every_normal(tmp_path, capsys, saved_figures):
    size, palettes = 16, (16, 256)
    plot = tmp_path / "plots" / "acc.png"
    palette.accuracy(Config(), ("wood", "bumps"), palettes, size, plot)
    out = capsys.readouterr().out
    assert "| scene | quantizer | sN=16 | sN=256 |" in out
    rows = _rows(out, "| wood") + _rows(out, "| bumps")
    assert [r.split(" | ")[:2] for r in rows] == [["| wood", "median-cut"], ["| wood", "kmeans"],
                                                 ["| bumps", "median-cut"], ["| bumps", "kmeans"]]
    for r in rows:
        scene = load_scene(r.split(" | ")[0][2:], size=size)
        n = distinct_normals(scene)
        cells = [c.strip() for c in r.split("|")[3:-1]]
        assert len(cells) == len(palettes)
        for sn, cell in zip(palettes, cells, strict=True):
            assert re.fullmatch(r"(inf|\d+\.\d) dB / \d+( \(all \d+ normals\))?", cell), cell
            assert (f"(all {n} normals)" in cell) == (sn >= n), (sn, n, cell)
        # every normal its own entry quantizes nothing: never worse than 16 entries (what
        # remains is the per-frame light and view against the per-pixel ones)
        if palettes[-1] >= n:
            psnr = [float(c.split(" dB")[0]) for c in cells]
            assert psnr[-1] >= psnr[0], r
    assert sum("(all" in r for r in rows) >= 2          # bumps at 16 has fewer than 256
    assert f"plot -> {plot}" in out
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the plot: one curve a (scene, quantizer), labelled so, at the table's PSNRs over sN,
    # one colour a scene, solid k-means and dashed median cut
    (ax,) = saved_figures[0].axes
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    assert sorted(lines) == ["bumps kmeans", "bumps median-cut", "wood kmeans", "wood median-cut"]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == sorted(lines)
    for r in rows:
        name, quantizer = (c.strip() for c in r.split("|")[1:3])
        line = lines[f"{name} {quantizer}"]
        assert list(line.get_xdata()) == list(palettes)
        shown = [f"{y:.1f}" for y in line.get_ydata()]
        assert shown == [c.strip().split(" dB")[0] for c in r.split("|")[3:-1]]
        assert line.get_linestyle() == ("-" if quantizer == "kmeans" else "--")
        assert line.get_color() == lines[f"{name} kmeans"].get_color()
    assert lines["wood kmeans"].get_color() != lines["bumps kmeans"].get_color()
    assert ax.get_title() == f"Palette method accuracy, {size}x{size}"


def test_images_named_by_scene_lighting_size_and_dither(tmp_path, capsys):
    size = 16
    palette.images(Config(), tmp_path, size)
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["palette_bricks_phong_16.png", "palette_globe_chrome_1024.png",
                     "palette_globe_phong_256.png", "palette_globe_phong_64_dither.png",
                     "palette_wood_toon_256.png"]
    out = capsys.readouterr().out
    for name in names:
        assert f"-> {tmp_path / name}" in out
        w, h = Image.open(tmp_path / name).size
        # Phong: reference | palette | difference with two 4-pixel gutters; else the render
        assert (w, h) == ((3 * size + 8, size) if "_phong_" in name else (size, size)), name


@pytest.mark.parametrize("what, words, absent", [
    (["speed"], ["--what speed"], ["--size", "--scenes", "PSNR"]),
    (["accuracy", "images"], ["--what accuracy images --size 16 --scenes bumps", "PSNR"],
     ["Per-frame cost"]),
])
def test_the_printed_command_names_the_flags_that_shaped_the_tables(what, words, absent,
                                                                    tmp_path, run_cli,
                                                                    monkeypatch):
    monkeypatch.chdir(tmp_path)                         # the tools' log: build/bench/palette.log
    r = run_cli(["bench", "palette", "--what", *what, "--sizes", "8", "--palettes", "4",
                 "--size", "16", "--scenes", "bumps", "--images-dir", tmp_path / "img"])
    assert r.returncode == 0, r.stderr
    first = r.stdout.splitlines()[0]
    assert first.startswith("bumprtl bench palette ")
    for w in words:
        assert w in r.stdout
    for w in absent:
        assert w not in r.stdout
    assert (tmp_path / "img").exists() == ("images" in what)
