import subprocess
import sys
import types

import numpy as np
import pytest
from PIL import Image

from bumprtl.gen.cli.main import main
from bumprtl.gen.render import images as render
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.models import FLOAT_MODELS
from bumprtl.sim.scenes import load_scene

CLI = [sys.executable, "-m", "bumprtl.gen.cli.main"]
PALETTE_MODULE = "bumprtl.sim.golden.float.palette"


def test_render_compare_writes_panel_and_prints_psnr(tmp_path, run_cli):
    out = tmp_path / "lee.png"                  # in this process (tests/conftest.py run_cli)
    r = run_cli(["render", "--scene", "bumps", "--method", "lee_corrected", "--size", "64",
                 "--out", out, "--compare"])
    assert r.returncode == 0, r.stderr
    assert "PSNR" in r.stdout and "max difference" in r.stdout
    img = np.asarray(Image.open(out))
    panel = np.asarray(Image.open(tmp_path / "lee_compare.png"))
    assert img.shape == (64, 64, 3)
    assert panel.shape == (64, 3 * 64 + 8, 3)
    assert np.array_equal(panel[:, 68:132], img)
    assert panel[:, 136:].any()                         # lee_corrected differs: |diff| is not black


@pytest.mark.parametrize("scene", ["globe", "cylinder"])
def test_render_exact_equals_conventional(tmp_path, scene):
    for method in ("exact", "conventional"):
        assert main(["render", "--scene", scene, "--method", method, "--size", "64",
                     "--light", "point", "--out", str(tmp_path / f"{method}.png")]) == 0
    a, b = (np.asarray(Image.open(tmp_path / f"{m}.png")) for m in ("exact", "conventional"))
    assert np.array_equal(a, b)


def test_shade_scene_chunks_match_one_call():
    """Row chunks (and the progress bar) must not change a pixel."""
    s = load_scene("wood", size=128)
    assert s.size > render.ROWS_PER_CHUNK
    assert np.array_equal(render.shade_scene(s, "conventional", Config()),
                          conventional(s.px, Config()).color)


def test_progress_bar_on_long_renders(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(render, "PROGRESS_PIXELS", 64 * 64)
    assert main(["render", "--size", "64", "--out", str(tmp_path / "a.png")]) == 0
    assert "pix" in capsys.readouterr().err               # tqdm's unit on stderr
    monkeypatch.setattr(render, "PROGRESS_PIXELS", 64 * 64 + 1)
    assert main(["render", "--size", "64", "--out", str(tmp_path / "b.png")]) == 0
    assert "pix" not in capsys.readouterr().err


def test_palette_flags_reach_render_palette(tmp_path, monkeypatch):
    """--method palette calls sim.golden.palette.render_palette(scene, cfg, palette_size=...,
    quantizer=..., lighting=...) and writes its .color (a stand-in module here)."""
    calls = []

    def render_palette(scene, cfg, **kwargs):
        calls.append((scene.name, cfg.kd, kwargs))
        return types.SimpleNamespace(color=np.full(scene.mask.shape, 0.5))

    stand_in = types.SimpleNamespace(render_palette=render_palette,
                                     distinct_normals=lambda scene: scene.mask.size)
    monkeypatch.setitem(sys.modules, PALETTE_MODULE, stand_in)
    out = tmp_path / "p.png"
    assert main(["render", "--scene", "moon", "--method", "palette", "--size", "32", "--kd", "0.5",
                 "--palette-size", "64", "--quantizer", "kmeans", "--lighting", "lambert",
                 "--out", str(out)]) == 0
    assert calls == [("moon", 0.5, {"palette_size": 64, "quantizer": "kmeans", "lighting": "lambert"})]
    assert np.all(np.asarray(Image.open(out)) == 128)     # 0.5 -> 127.5 -> 128


def test_palette_holding_every_normal_renders_with_a_one_line_note(tmp_path, capsys):
    """A palette at least as large as the map's distinct normals is valid: the render runs,
    prints one line saying every normal has its own entry, and equals the reference within
    the colour table's 8-bit rounding (a plane, one directional light); one entry fewer
    quantizes and prints no such line."""
    def render(size, *extra):
        out = tmp_path / f"p{size}.png"
        assert main(["render", "--scene", "moon", "--method", "palette", "--size", "32",
                     "--palette-size", str(size), "--out", str(out), *extra]) == 0
        return [line for line in capsys.readouterr().out.splitlines()
                if "every normal has its own entry" in line], out
    notes, _ = render(16384)
    assert len(notes) == 1
    n = int(notes[0].split("the map's ")[1].split()[0])
    assert 16 < n <= 32 * 32 and "sN = 16384" in notes[0]
    notes, out = render(n, "--compare")
    assert len(notes) == 1
    ref, img = (np.asarray(Image.open(out.with_name(out.stem + "_compare.png")))[:, c:c + 32]
                for c in (0, 36))
    assert np.abs(ref.astype(int) - img.astype(int)).max() <= 1
    assert render(n - 1)[0] == []
    notes, out = render(16384, "--model", "fixed", "--compare")     # the hardware's table too
    assert len(notes) == 1 and f"the map's {n} distinct normals" in notes[0]
    ref, img = (np.asarray(Image.open(out.with_name(out.stem + "_compare.png")))[:, c:c + 32]
                for c in (0, 36))
    assert np.abs(ref.astype(int) - img.astype(int)).max() <= 1


def test_palette_missing_is_a_clear_error(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, PALETTE_MODULE, None)    # import fails
    assert main(["render", "--method", "palette", "--size", "16", "--out", str(tmp_path / "p.png")]) == 2
    err = capsys.readouterr().err
    assert "palette" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_methods_are_the_registry_plus_palette():
    assert render.render_methods() == [*FLOAT_MODELS, "palette"]


@pytest.mark.parametrize("argv, word", [
    (["--scene", "marble"], "--scene"),
    (["--size", "100"], "size"),
    (["--size", "8192"], "size"),
    (["--texture-size", "24"], "texture_size"),
    (["--method", "cordic"], "--method"),
    (["--light-elevation", "100"], "light_elevation"),
    (["--light-azimuth", "-400"], "light_azimuth"),
    (["--light", "spot"], "--light"),
    (["--kd", "2"], "kd"),
    (["--palette-size", "8", "--method", "palette"], "palette_size"),
    (["--quantizer", "kmeans"], "--quantizer"),
    (["--quantizer", "octree", "--method", "palette"], "--quantizer"),
    (["--lighting", "sunset", "--method", "palette", "--size", "32"], "lighting"),
])
def test_render_bad_input_exit_2_one_line(tmp_path, argv, word, run_cli):
    # the first case through a real process, the others in this one (tests/conftest.py)
    args = ["render", "--out", str(tmp_path / "x.png")] + argv
    real = argv == ["--scene", "marble"]
    r = subprocess.run(CLI + args, capture_output=True, text=True) if real else run_cli(args)
    assert r.returncode == 2, (argv, r.stderr)
    assert word in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "x.png").exists()


def test_a_table1_baseline_renders_with_its_fixed_point_model(tmp_path, run_cli):
    """``--model fixed --method kim``: a baseline's bit-exact model (no hardware pipeline of
    its own) draws the picture: within an 8-bit step or two of its float64 model's, and not
    that picture itself."""
    pictures = {}
    for model in ("fixed", "float64"):
        out = tmp_path / f"kim_{model}.png"
        r = run_cli(["render", "--model", model, "--method", "kim", "--size", "32", "--out", out])
        assert r.returncode == 0, r.stderr
        assert "kim" in r.stdout
        pictures[model] = np.asarray(Image.open(out), dtype=np.int64)
    assert pictures["fixed"].shape[:2] == (32, 32) == pictures["float64"].shape[:2]
    diff = np.abs(pictures["fixed"] - pictures["float64"])
    assert diff.max() <= 2 and diff.any(), diff.max()


def test_a_palette_scenes_colour_table_is_shaded_with_the_scenes_coefficients():
    """The palette scene's colour table (gen/render/rtl._palette_maps, what render --rtl
    writes into the LUT) is Tarini's Sec. 5.1 table shaded with the scene's own ka, kd, ks
    and exponent: a scene with other coefficients gets another table, entry by entry the
    8-bit colour_table of its Config."""
    from bumprtl.gen.render.rtl import _palette_maps, sim_scene
    from bumprtl.sim.golden.common import to_8bit
    from bumprtl.sim.golden.fixed.palette_lut import pack_rgba
    from bumprtl.sim.golden.float.palette import (
        color_table,
        frame_directions,
        quantize_normal_map,
        world_normal_map,
    )
    from bumprtl.sim.scenes.config import load_scene_config

    tables = []
    for keys in ({}, {"kd": 0.4, "ks": 0.5, "ka": 0.05}):
        scene = load_scene_config({"name": "palette", **keys}) if keys else load_scene_config("palette")
        base = sim_scene(scene, 32)
        _, table = _palette_maps(base, scene)
        normals, counts = world_normal_map(base)
        qmap = quantize_normal_map(normals, scene.palette_size, weights=counts)
        l, v = frame_directions(base)
        want = pack_rgba(to_8bit(color_table(qmap.table, "phong", l, v, scene.config)), scene.config)
        assert np.array_equal(np.asarray(table), np.asarray(want))
        tables.append(np.asarray(table))
    assert not np.array_equal(tables[0], tables[1])


@pytest.mark.parametrize("toml, flags, message", [
    ('shading = "per-pixel"', ["--method", "palette"],
     "--method palette contradicts shading = 'per-pixel'"),
    ('method = "lee_corrected"', ["--method", "exact"],
     "--method exact contradicts method = 'lee_corrected'"),
    ('image = "bricks"', ["--scene", "wood"], "--scene wood contradicts image = 'bricks'"),
])
def test_a_render_flag_that_contradicts_the_scene_file_is_named(tmp_path, run_cli, toml, flags,
                                                                message):
    """render sets a scene's shading and method from --method and its image from --scene:
    against a scene file that sets the key otherwise, the one line names the flag the user
    typed (not the scene key behind it), exit 2, nothing written."""
    scene = tmp_path / "s.toml"
    scene.write_text(f'name = "s"\n{toml}\n')
    where = ["--pipeline", str(scene)] if flags[0] == "--scene" else ["--scene", str(scene)]
    r = run_cli(["render", *where, *flags, "--model", "fixed", "--out", tmp_path / "x.png"])
    assert r.returncode == 2 and not (tmp_path / "x.png").exists()
    assert r.stderr == f"bumprtl: error: {message} in scene file {scene}: drop one\n"


def test_fixed_palette_of_a_textured_scene_is_the_pipelines_golden_render(tmp_path, run_cli):
    """``render --model fixed --method palette`` of a scene with a colour texture: the palette
    pipeline's golden render at the size asked (the RTL's picture byte for byte), where an
    untextured scene shows the LUT colour's grey."""
    from bumprtl.gen.render.rtl import golden_render
    from bumprtl.sim.scenes.config import load_scene_config

    out = tmp_path / "p.png"
    r = run_cli(["render", "--pipeline", "textured", "--model", "fixed", "--method", "palette",
                 "--size", "32", "--out", out])
    assert r.returncode == 0, r.stderr
    img = np.asarray(Image.open(out))
    # render's map is as large as its image unless the scene says otherwise
    scene = load_scene_config("textured", defaults={"texture_size": 32})
    want = golden_render(scene.replace(shading="palette"), 32)
    assert img.shape[:2] == (32, 32) and np.array_equal(img, want)
