"""Your own map on the command line: ``bumprtl render`` and ``bumprtl emit pipeline|fetch``
with --height-map/--normal-map or a scene TOML, the $readmemh files beside the Verilog,
flags that contradict a TOML, maps too large for the device, bad input (one line, exit 2,
nothing written) and ``recommend`` without a local sweep."""

import json
import re
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from bumprtl.gen.cli.main import main
from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.memories import DEVICE_BRAM, bram_blocks, check_scene_fits, map_blocks
from bumprtl.gen.render import rtl
from bumprtl.gen.render.images import fixed_image
from bumprtl.gen.render.rtl import scene_memories
from bumprtl.gen.report import recommend as rec
from bumprtl.rtl.config import Config
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.golden.common import polar_to_cartesian
from bumprtl.sim.scenes import heightfields
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.scenes.usermap import load_bump_map, normals_to_rgb, write_png

CLI = [sys.executable, "-m", "bumprtl.gen.cli.main"]


def craters(t, n=10):
    """The unseen map of this file: sim/scenes/heightfields.craters, its own seed and radii."""
    return heightfields.craters(t, seed=11, n=n, radius=(0.08, 0.25))


def _png(path, h):
    Image.fromarray(np.rint(h * 255).astype(np.uint8)).save(path)
    return path


def _one_line_exit_2(capsys, argv, *words):
    assert main(argv) == 2, argv
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0], err
    assert all(w in err[0] for w in words), (words, err[0])
    return err[0]


def test_render_height_map_float64_and_fixed(tmp_path, capsys):
    path = _png(tmp_path / "c.png", craters(64))
    out = tmp_path / "f.png"
    assert main(["render", "--height-map", str(path), "--size", "64", "--out", str(out)]) == 0
    img = np.asarray(Image.open(out))
    assert img.shape == (64, 64, 3) and img.std() > 5
    fixed = tmp_path / "x.png"
    assert main(["render", "--height-map", str(path), "--size", "64", "--model", "fixed",
                 "--compare", "--out", str(fixed)]) == 0
    text = capsys.readouterr().out
    assert "exact (fixed)" in text and "PSNR" in text
    scene = load_scene_config("default", {"height_map": str(path)})
    assert scene == load_scene_config("default").replace(height_map=str(path))
    assert (scene.image, scene.texture_size, scene.picture) == (None, 64, str(path))
    want = fixed_image(scene, "exact", 64, light_elevation=45.0, light="directional")
    assert np.array_equal(np.asarray(Image.open(fixed)), want)
    assert not np.array_equal(want, img)                   # fixed point is not float64


def test_render_scene_png_points_to_the_map_flags(tmp_path, capsys):
    path = _png(tmp_path / "my_map.png", craters(32))
    _one_line_exit_2(capsys, ["render", "--scene", str(path), "--out", str(tmp_path / "o.png")],
                     "my_map.png", "--height-map", "--normal-map")
    toml = tmp_path / "s.toml"
    toml.write_text('image = "my_map.npy"\n')
    _one_line_exit_2(capsys, ["emit", "pipeline", "--scene", str(toml), "--out", str(tmp_path / "e")],
                     "image", "my_map.npy", "height_map")
    assert not (tmp_path / "e").exists() and not (tmp_path / "o.png").exists()


def _initial_contents(v_text, mem="fetch.map.mem"):
    pat = re.compile(r"\\" + re.escape(mem) + r" \[(\d+)\] = \d+'h([0-9a-f]+);")
    return {int(a): int(w, 16) for a, w in pat.findall(v_text)}


def test_emit_pipeline_from_a_toml_writes_readmemh_beside_the_verilog(tmp_path):
    """Paths in a TOML are relative to it; the map file is the Verilog's initial contents
    word for word (load initial) or absent from it (load port); lint-clean, deterministic.
    At 10-bit angles, B = 11 (the default widths' ROMs would double the time)."""
    (tmp_path / "maps").mkdir()
    _png(tmp_path / "maps" / "c.png", craters(32))
    toml = tmp_path / "maps" / "scene.toml"
    toml.write_text('height_map = "c.png"\nheight_scale = 3.0\ngeometry = "sphere"\n'
                    'angle_bits = 10\nfrac_bits = 11\n')
    out = tmp_path / "a"
    assert main(["emit", "pipeline", "--scene", str(toml), "--out", str(out)]) == 0
    scene = load_scene_config(toml)
    assert scene.texture_size == 32 and scene.height_map == str(tmp_path / "maps" / "c.png")
    words = scene_memories(scene)[0]
    hexwords = [int(x, 16) for x in (out / "bumprtl_pipeline_map.hex").read_text().split()]
    assert hexwords == words.tolist() and len(hexwords) == 32 * 32
    assert all(len(x) == 5 for x in (out / "bumprtl_pipeline_map.hex").read_text().split())   # 20 bits
    v = (out / "bumprtl_pipeline.v").read_text()
    init = _initial_contents(v)
    assert [init.get(a, 0) for a in range(len(words))] == words.tolist()
    meta = load_sidecar(out / "bumprtl_pipeline.json")
    img = meta.memory_images["map"]
    assert img["file"] == "bumprtl_pipeline_map.hex" and img["load"] == "initial" and img["width"] == 20
    assert "phi in bits [9:0], theta in bits [19:10]" in img["layout"]      # 10-bit angles
    assert "port" not in img and "map_w_en" not in meta.ports   # built in: no write port
    assert meta.scene["geometry"] == "sphere" and meta.scene["height_scale"] == 3.0
    assert meta.block_ram["device"] == "LFE5U-85F"
    assert lint(out / "bumprtl_pipeline.v") == []
    port = tmp_path / "b"
    assert main(["emit", "pipeline", "--scene", str(toml), "--load", "port", "--out", str(port)]) == 0
    pv = (port / "bumprtl_pipeline.v").read_text()
    assert not any(_initial_contents(pv).values())          # no map in the Verilog
    assert pv.splitlines()[0].endswith(f"--scene {toml} --load port")
    assert (port / "bumprtl_pipeline_map.hex").read_text() == (out / "bumprtl_pipeline_map.hex").read_text()
    pmeta = load_sidecar(port / "bumprtl_pipeline.json")
    assert pmeta.memory_images["map"]["port"] == ["map_w_en", "map_w_addr", "map_w_data"]
    assert {"map_w_en", "map_w_addr", "map_w_data"} <= set(pmeta.ports)
    again = tmp_path / "c"
    assert main(["emit", "pipeline", "--scene", str(toml), "--out", str(again)]) == 0
    for name in ("bumprtl_pipeline.v", "bumprtl_pipeline_map.hex"):
        assert (again / name).read_bytes() == (out / name).read_bytes()


def test_emit_fetch_with_a_normal_map_and_flat_fetch_is_one_line(tmp_path, capsys):
    bm = load_bump_map(_png(tmp_path / "c.png", craters(32)), "height")
    write_png(tmp_path / "n.png", normals_to_rgb(polar_to_cartesian(bm.b_phi_map, bm.b_theta_map)))
    assert main(["emit", "fetch", "--normal-map", str(tmp_path / "n.png"), "--out",
                 str(tmp_path / "f")]) == 0
    meta = load_sidecar(tmp_path / "f" / "bumprtl_fetch.json")
    assert "port" not in meta.memory_images["map"] and "w_en" not in meta.ports
    assert len((tmp_path / "f" / "bumprtl_fetch_map.hex").read_text().split()) == 32 * 32
    _one_line_exit_2(capsys, ["emit", "fetch", "--scene", "flat", "--out", str(tmp_path / "g")],
                     "flat", "nothing to fetch")
    assert not (tmp_path / "g").exists()


def test_a_map_too_large_for_the_device_says_bits_needed_and_available(tmp_path, capsys):
    """A 512^2 map of two angles (2 x 14 bits a texel at the default) needs 112 x 4 DP16KD
    (16384 x 1 ... 4096 x 4 tiles) beside the tables: over the LFE5U-85F's 208; 256^2 (112
    blocks) fits beside the twelve 4097-word sine ROMs (four x4 blocks each, the last word in
    a flip-flop) and the cos^n table (one x18 block), but not in the LFE5U-25F's 56."""
    bits = 2 * Config().angle_bits
    path = _png(tmp_path / "big.png", craters(512, n=40))
    line = _one_line_exit_2(capsys, ["emit", "pipeline", "--height-map", str(path), "--out",
                                     str(tmp_path / "o")],
                            "big.png", f"{512 * 512 * bits:,} bits", f"{bram_blocks(512 * 512, bits)} DP16KD",
                            "LFE5U-85F has 208 DP16KD of 18 kbit")
    assert "3,833,856 bits" in line and bram_blocks(512 * 512, bits) == 448
    small = _png(tmp_path / "s.png", craters(256, n=20))
    _one_line_exit_2(capsys, ["render", "--rtl", "--height-map", str(small), "--device", "LFE5U-25F",
                              "--out", str(tmp_path / "r.png")], "s.png", f"{256 * 256 * bits:,} bits",
                     "LFE5U-25F has 56 DP16KD")
    assert not (tmp_path / "o").exists() and not (tmp_path / "r.png").exists()
    scene = load_scene_config("default", {"height_map": str(small)})
    assert check_scene_fits(scene, "LFE5U-85F") == (112 + 12 * 4 + 1, 208)
    assert bram_blocks(4096, 24) == 6 and bram_blocks(1025, 14) == 2 and bram_blocks(512, 36) == 1


def test_flags_that_contradict_the_toml_name_both(tmp_path, capsys):
    toml = tmp_path / "wood.toml"
    toml.write_text('image = "wood"\ntexture_size = 32\nangle_bits = 12\n')
    out = str(tmp_path / "x.png")
    _one_line_exit_2(capsys, ["render", "--rtl", "--pipeline", str(toml), "--scene", "bricks",
                              "--out", out], "--scene bricks", "image = 'wood'", "wood.toml")
    _one_line_exit_2(capsys, ["render", "--rtl", "--pipeline", str(toml), "--texture-size", "64",
                              "--out", out], "--texture-size 64", "texture_size = 32")
    _one_line_exit_2(capsys, ["render", "--rtl", "--pipeline", str(toml), "--height-map", "x.png",
                              "--out", out], "--height-map x.png", "image = 'wood'")
    _one_line_exit_2(capsys, ["emit", "pipeline", "--scene", str(toml), "--angle-bits", "10",
                              "--out", str(tmp_path / "e")], "--angle-bits 10", "angle_bits = 12")
    _one_line_exit_2(capsys, ["emit", "pipeline", "--scene", str(toml), "--out-bits", "8",
                              "--out", str(tmp_path / "e")], "--out-bits", "does not apply")
    assert not (tmp_path / "e").exists() and not (tmp_path / "x.png").exists()


def test_render_rtl_uses_the_toml(tmp_path, monkeypatch):
    """The TOML's image and map size reach the RTL render; a flag it does not set applies."""
    toml = tmp_path / "wood.toml"
    toml.write_text('image = "wood"\ntexture_size = 32\n')
    seen = []

    def fake_render(scene, size, simulator, build_dir, **kw):
        seen.append((scene, size, kw["load"], kw["azimuth"]))
        img = np.zeros((size, size, 3), np.uint8)
        return rtl.RtlRender(img, img, size * size, 1.0, 1.0)

    monkeypatch.setattr(rtl, "render_rtl", fake_render)
    assert main(["render", "--rtl", "--pipeline", str(toml), "--size", "16", "--light-azimuth",
                 "60", "--kd", "0.5", "--load", "port", "--out", str(tmp_path / "r.png")]) == 0
    scene, size, load, azimuth = seen[0]
    assert (scene.image, scene.texture_size, scene.kd, size, load, azimuth) == \
        ("wood", 32, 0.5, 16, "port", 60.0)
    assert main(["render", "--rtl", "--scene", str(toml), "--size", "16",
                 "--out", str(tmp_path / "s.png")]) == 0
    assert seen[1][0].image == "wood" and seen[1][2] == "initial"


def test_bad_maps_on_the_command_line_one_line_exit_2_nothing_written(tmp_path, capsys):
    (tmp_path / "junk.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"\0" * 5)
    nan = craters(32)
    nan[1, 2] = np.nan
    np.save(tmp_path / "nan.npy", nan)
    np.save(tmp_path / "flat.npy", np.zeros((32, 32)))
    _png(tmp_path / "odd.png", craters(40))
    cases = [(["--height-map", str(tmp_path / "none.png")], ["none.png", "no such file"]),
             (["--height-map", str(tmp_path / "junk.png")], ["junk.png", "truncated"]),
             (["--height-map", str(tmp_path / "nan.npy")], ["nan.npy", "NaN"]),
             (["--height-map", str(tmp_path / "flat.npy")], ["flat.npy", "all-flat"]),
             (["--height-map", str(tmp_path / "odd.png")], ["odd.png", "32x32", "--resample"]),
             (["--normal-map", str(tmp_path / "odd.png")], ["odd.png", "RGB"]),
             (["--height-map", str(_png(tmp_path / "ok.png", craters(32))), "--height-scale", "-1"],
              ["height_scale"])]
    for n, (flags, words) in enumerate(cases):
        for cmd in (["render"], ["render", "--model", "fixed"], ["render", "--rtl"],
                    ["emit", "pipeline"]):
            out = tmp_path / "out"
            argv = [*cmd, *flags, "--out", str(out if cmd[0] == "emit" else out / "x.png")]
            if n == 0 and cmd == ["render"]:              # once through a real process
                r = subprocess.run(CLI + argv, capture_output=True, text=True)
                assert r.returncode == 2 and "Traceback" not in r.stderr
                assert r.stderr.count("\n") == 1 and all(w in r.stderr for w in words)
            else:
                _one_line_exit_2(capsys, argv, *words)
            assert not out.exists(), argv


def test_recommend_without_a_local_sweep_reads_the_shipped_one(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["recommend", "--max-error-lsb", "2"]) == 0
    text = capsys.readouterr().out
    assert "no local sweep" in text and "docs/data/sweep.json" in text
    assert rec.SHIPPED_SWEEP.is_file()
    local = tmp_path / "build" / "bench" / "sweep.json"
    local.parent.mkdir(parents=True)
    local.write_text(json.dumps({"command": "toy", "points": []}))
    assert main(["recommend", "--max-error-lsb", "2"]) == 2          # the local one, empty
    assert "no local sweep" not in capsys.readouterr().out


def test_device_block_ram_counts_are_nextpnrs():
    """DEVICE_BRAM against the DP16KD count nextpnr-ecp5 reported in the shipped sweep."""
    data = json.loads(rec.SHIPPED_SWEEP.read_text())
    seen = {p["cost"]["fpga"]["device"]: p["cost"]["fpga"]["available"]["BRAM"]
            for p in data["points"] if p.get("cost", {}).get("fpga", {}).get("available")}
    assert seen and all(DEVICE_BRAM[d] == n for d, n in seen.items())


@pytest.mark.parametrize("name, placed", [("full", 148), ("two-lights", 129)])
def test_block_ram_count_is_what_nextpnr_places(name, placed):
    """The fit check counts each memory as the ECP5 form lays it out. The numbers are
    nextpnr-ecp5's DP16KD utilisation of the built-in scenes at their 15 / 16 widths
    (`bumprtl report fpga --device LFE5U-85F --unit scene_full --unit scene_two_lights
    --seeds 1,2,3`): `full`'s 5120-word map and texture sit in x2 blocks side by side (15 +
    12 blocks), not in the cheapest tiling of their bits (10 + 9), which undercounted by 8;
    each quarter-wave ROM of the sine above its line is seven 8192 x 2 blocks."""
    assert check_scene_fits(load_scene_config(name), "LFE5U-85F") == (placed, 208)
    assert map_blocks(5120, 30) == 15 and map_blocks(5120, 24) == 12
    assert map_blocks(512 * 512, 28) == bram_blocks(512 * 512, 28)   # deeper than any mode
