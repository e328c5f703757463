"""Every built-in scene and an unseen height map (sim/golden/accuracy.crater_scene) through
the emitted rotation and illumination units (exact, default widths) on the Verilator bulk
path: every output field of both units equals the golden model's (compared in cocotb and
here), and the RTL's own outputs reach >= 58 dB with max 1 LSB against float64
`conventional` on the unquantized inputs: eq. 2's colour, and the texture blend of the
scenes with a colour texture taken from the RTL's unrounded terms (TextureBlend itself is
bit-exact with rtl/texture.texture_blend: tests/rtl/test_texture.py). The 128 x 128
measure of the golden model is tests/sim/golden/fixed/test_channels.py's."""

import numpy as np
import pytest

from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.config import Config
from bumprtl.sim.golden.accuracy import crater_scene, scene_error
from bumprtl.sim.golden.methods import encode_pixels, illumination_fixed, rotation_fixed
from bumprtl.sim.scenes import SCENES, load_scene
from bumprtl.sim.tb.bulk import run_bulk

SIZE = 64                   # 4096 pixels a scene, 10 scenes: a few seconds of Verilator


def _run(unit, inputs, expected, cfg, build_dir):
    v, j = emit_unit(unit, cfg, build_dir / "rtl")
    tag = np.arange(len(next(iter(inputs.values())))) & ((1 << cfg.tag_bits) - 1)
    r = run_bulk("verilator", v, j, build_dir / f"bulk_{unit}",
                 inputs={**inputs, "tag": tag}, expected={**expected, "tag": tag})
    assert r.checked
    out = r.outputs["no_stall"]
    assert np.array_equal(out["tag"], tag), unit
    return out


@pytest.fixture(scope="module")
def scenes_rtl(tmp_path_factory):
    """{name: (scene, the RTL illumination outputs in the scene's shape)}."""
    cfg = Config()
    scenes = [load_scene(name, size=SIZE) for name in SCENES] + [crater_scene(size=SIZE)]
    codes = [encode_pixels(s.px, cfg) for s in scenes]
    codes = {k: np.concatenate([c[k].reshape(-1) for c in codes]).astype(np.int64) for k in codes[0]}
    build = tmp_path_factory.mktemp("bulk_scenes")
    rot_gold = rotation_fixed(codes, cfg)
    rot = _run("rotation", codes, {k: rot_gold[k] for k in rot_gold}, cfg, build)
    rot = {k: v for k, v in rot.items() if k != "tag"}
    shade_gold = illumination_fixed(rot, cfg)
    fields = ("diffuse", "specular", "color", "diffuse_fine", "specular_fine")
    shade = _run("illumination", rot, {k: shade_gold[k] for k in fields}, cfg, build)
    for k in fields:            # the RTL equals the golden model (also checked in cocotb)
        assert np.array_equal(shade[k], shade_gold[k]), k
    out, start = {}, 0
    for s in scenes:
        n = s.px.n_phi.size
        out[s.name] = (s, {k: shade[k][start:start + n].reshape(s.px.shape) for k in fields})
        start += n
    return cfg, out


# Two Verilator builds: make regress (the golden model's 58 dB per scene is in make test,
# tests/sim/golden/fixed/test_channels.py; both units' RTL equals the golden model bit for
# bit in tests/sim/tb/test_tb_datapath.py).
@pytest.mark.regress
@pytest.mark.parametrize("name", list(SCENES) + ["craters"])
def test_scene_through_the_rtl_at_least_58_db_max_1(scenes_rtl, name):
    cfg, out = scenes_rtl
    scene, rtl = out[name]
    model = lambda codes, cfg: rtl          # the RTL's outputs for this scene's pixels
    results = [scene_error(scene, cfg, model)]
    if scene.albedo is not None:
        results.append(scene_error(scene, cfg, model, blend=True))
    for r in results:
        assert r["psnr_db"] >= 58 and r["max_lsb"] <= 1, (name, r)
