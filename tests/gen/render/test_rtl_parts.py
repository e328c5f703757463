"""gen/render/rtl.py's parts around the simulation, the simulator stood in: ``render --rtl``'s
report line and exit status (identical bytes or not), its refusals before any build, the
tag-order check of render_rtl, the stimulus refusals (a textured scene without a colour
texture, a flat scene that is not a plane), and the docs/scenes.md table."""

import numpy as np
import pytest
from PIL import Image

from bumprtl.gen.render import rtl
from bumprtl.rtl.config import BumpError
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config

SMALL = {"texture_size": 16, "angle_bits": 10, "frac_bits": 11}


def _render(same, cached, stream_s):
    image = np.full((8, 8, 3), 7, np.uint8)
    golden = image if same else image + 1
    return rtl.RtlRender(image, golden, cycles=80, seconds=0.5, build_seconds=12.0,
                         stream_seconds=stream_s, cached=cached)


@pytest.mark.parametrize("same, cached, stream_s", [(True, True, 0.25), (False, False, None)])
def test_render_png_reports_the_run_and_fails_on_different_bytes(same, cached, stream_s,
                                                                 tmp_path, monkeypatch, capsys):
    seen = {}

    def fake(scene, size, simulator, build_dir, progress, per_cycle, load, **light):
        seen.update(size=size, sim=simulator, build_dir=build_dir, per_cycle=per_cycle,
                    load=load, light=light)
        return _render(same, cached, stream_s)

    monkeypatch.setattr(rtl, "render_rtl", fake)
    monkeypatch.setattr(rtl, "require_sim", lambda sim: None)
    monkeypatch.chdir(tmp_path)
    scene = load_scene_config("default", SMALL)
    out = tmp_path / "o" / "r.png"
    status = rtl.rtl_render_png(scene, 8, out, "icarus", per_cycle=not cached, azimuth=10.0)
    assert status == (0 if same else 1)
    assert np.array_equal(np.asarray(Image.open(out)), np.full((8, 8, 3), 7, np.uint8))
    assert seen["build_dir"] == rtl.Path("build/render_rtl/default") and seen["size"] == 8
    assert seen["light"] == {"azimuth": 10.0, "light_elevation": 45.0, "light": "directional"}
    line, verdict = capsys.readouterr().out.splitlines()
    path = "per-cycle cocotb" if not cached else "bulk"
    assert line.startswith(f"rtl (icarus, {path}, map load initial): 8x8 ")
    assert "80 cycles" in line and "simulation 0.50 s = 128 pix/s" in line
    assert ("build cached (took 12.0 s once)" in line) == cached
    assert ("build 12.0 s;" in line) == (not cached)
    assert ("streaming 0.25 s = 256 pix/s" in line) == (stream_s is not None)
    assert line.endswith(f"-> {out}")
    assert verdict == "vs fixed-point golden render: " + ("identical bytes" if same else "DIFFERENT")


@pytest.mark.parametrize("kw, flag", [({"per_cycle": True}, "--per-cycle"),
                                      ({"load": "port"}, "--load")])
def test_a_map_in_axi_memory_refuses_the_per_cycle_and_port_paths(kw, flag, tmp_path,
                                                                   monkeypatch):
    monkeypatch.setattr(rtl, "render_rtl", lambda *a, **k: pytest.fail("rendered"))
    scene = load_scene_config("default", {**SMALL, "map_memory": "axi"})
    with pytest.raises(BumpError) as e:
        rtl.rtl_render_png(scene, 8, tmp_path / "r.png", **kw)
    assert str(e.value).startswith(f"{flag} applies to map_memory = 'bram'")
    assert e.value.field == "map_memory" and not (tmp_path / "r.png").exists()


def test_render_rtl_refuses_outputs_whose_tags_are_out_of_order(monkeypatch, tmp_path):
    def bulk(scene, inputs, words, polygon, table, sim, build_dir, texels, rtl_dir, load):
        outs = {"color": np.zeros(len(inputs["tag"]), np.int64), "tag": inputs["tag"][::-1]}
        run = type("Run", (), {"run_s": 1.0, "build_s": 2.0, "sim_s": {"no_stall": 0.5},
                               "cached": True})
        return {"no_stall": outs}, {"no_stall": 99}, run

    monkeypatch.setattr(rtl, "run_pipeline_bulk", bulk)
    with pytest.raises(AssertionError, match="pixel tags out of order"):
        rtl.render_rtl(load_scene_config("diffuse", SMALL), 16, build_dir=tmp_path)


def test_a_textured_scene_needs_an_image_with_a_colour_texture():
    scene = load_scene_config({"name": "t", "texture": True, "image": "bumps", **SMALL})
    with pytest.raises(BumpError, match=r"texture = true needs an image with a colour texture "
                                        r"\(.*bricks.*\), got image 'bumps'"):
        rtl.scene_texels(scene, rtl.sim_scene(scene, 16))


def test_a_flat_scene_must_be_a_plane():
    with pytest.raises(BumpError, match="bump_map = 'flat' renders one polygon: 'globe' is not "
                                        "on a plane"):
        rtl.scene_stimulus(load_scene_config("flat", {"image": "globe"}), 16)


def test_scenes_table_one_row_per_builtin_with_its_counts(monkeypatch, tmp_path):
    class Counts:
        def __init__(self, scene):
            self.rams = [{"bits": 100}, {"bits": 28}]
            self.mult = len(scene.name)

        def summary(self):
            return {"multipliers": self.mult, "table_bits": 4096, "adders": 9}

    work = []
    monkeypatch.setattr(rtl, "count_unit", lambda unit, scene, w: work.append((unit, w))
                        or Counts(scene))
    monkeypatch.setattr(rtl, "golden_render", lambda scene, size: None)
    doc = tmp_path / "scenes.md"
    rtl.write_scenes_doc(doc, tmp_path / "w")
    text = doc.read_text()
    assert "Produced by `.venv/bin/python -m bumprtl.gen.render.rtl --doc " in text
    assert "Made at: angle_bits=" in text
    rows = [line for line in text.splitlines() if line.startswith("| ") and "`bumprtl" in line]
    assert [r.split(" | ")[0][2:] for r in rows] == list(BUILTIN)
    for name, r in zip(BUILTIN, rows, strict=True):
        cells = r.split(" | ")
        assert cells[2:6] == [str(len(name)), "4096", "128", "9"], r
        assert r.endswith(f"`bumprtl emit pipeline --scene {name}` |")
        assert rtl._built_units(load_scene_config(name)) == cells[1]
    assert work == [("pipeline", tmp_path / "w" / n) for n in BUILTIN]
    assert "| scene class | units built | multipliers | ROM bits | RAM bits | adders | golden " \
           "render 256² (s) | command |" in text


def test_the_golden_render_of_a_palette_scene_shows_only_its_table_colours():
    """The palette scene's golden image (what render --rtl compares the hardware's with):
    every pixel is an entry of the scene's colour table, and the frame shows several."""
    from bumprtl.gen.render.rtl import golden_render, scene_stimulus
    from bumprtl.sim.golden.fixed.palette_lut import unpack_rgba
    from bumprtl.sim.scenes.config import load_scene_config

    scene = load_scene_config("palette")
    assert scene.shading == "palette"
    img = golden_render(scene, 32)
    table = scene_stimulus(scene, 32)[3]
    rgba = unpack_rgba(np.asarray(table), scene.config)
    entries = set(zip(rgba["r"].tolist(), rgba["g"].tolist(), rgba["b"].tolist(), strict=True))
    shown = {tuple(int(x) for x in c) for c in img.reshape(-1, 3)}
    assert img.shape == (32, 32, 3) and len(shown) > 8
    assert shown <= entries
