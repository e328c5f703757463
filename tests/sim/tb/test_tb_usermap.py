"""An unseen user map (random craters, fixed seed: sim/scenes/heightfields.craters) through
every method's golden models, the fixed-point render and the RTL on both simulators: the
map is written through the pipeline's host write port, and the RTL image equals the
fixed-point render (and the golden render) byte for byte."""

import re

import numpy as np
import pytest
from PIL import Image

from bumprtl.gen.render.images import FIXED_METHODS, fixed_image, float_image, render_methods
from bumprtl.gen.render.rtl import render_rtl
from bumprtl.sim.scenes import heightfields
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.scenes.imaging import max_diff, psnr

SIZE = 32                           # map and image: small, so make test stays fast
EXACT_COLOUR_LSB = 2                # exact at the default widths: worst colour error, docs/bench.md


def craters(t):
    """The unseen map of this file: sim/scenes/heightfields.craters, its own seed."""
    return heightfields.craters(t, seed=2024, n=9)


@pytest.fixture(scope="module")
def crater_scene(tmp_path_factory):
    path = tmp_path_factory.mktemp("map") / "craters.png"
    Image.fromarray(np.rint(craters(SIZE) * 255).astype(np.uint8)).save(path)
    return load_scene_config("default", {"height_map": str(path)})


def psnr_table(scene, size=SIZE):
    """{method: (float64 PSNR, max, fixed PSNR or None, max or None)} against float64
    conventional, and the fixed-point images."""
    ref, _ = float_image(scene, "conventional", size, progress=False)
    rows, fixed = {}, {}
    for method in render_methods():
        img, _ = float_image(scene, method, size, progress=False)
        f = None
        if method in FIXED_METHODS:
            fixed[method] = f = fixed_image(scene, method, size)
        rows[method] = (psnr(ref, img), max_diff(ref, img),
                        None if f is None else psnr(ref, f), None if f is None else max_diff(ref, f))
    return rows, fixed


def test_every_method_renders_the_unseen_map(crater_scene):
    rows, fixed = psnr_table(crater_scene)
    print("\nmethod         float64 PSNR / max   fixed PSNR / max   (vs float64 conventional, "
          f"{SIZE}x{SIZE} craters)")
    for m, (fp, fm, xp, xm) in rows.items():
        print(f"{m:<14} {fp:>8.2f} / {fm:<4d}    " +
              ("-" if xp is None else f"{xp:>8.2f} / {xm}"))
    for m in ("conventional", "exact", "peercy", "kim"):     # Ernst's model is Peercy's
        assert rows[m][:2] == (float("inf"), 0), m            # float64: the same picture
    assert rows["exact"][3] <= EXACT_COLOUR_LSB
    for m in FIXED_METHODS:
        assert fixed[m].shape == (SIZE, SIZE, 3) and fixed[m].std() > 3, m   # a picture
    assert rows["lee_corrected"][2] < 40 and rows["palette"][0] > 25


@pytest.mark.parametrize("sim", ["icarus", pytest.param("verilator", marks=pytest.mark.regress)])
def test_rtl_render_of_a_map_written_through_the_host_port(sim, crater_scene, build_dir):
    """The Verilog holds no map (load = port): cocotb writes the crater map through
    map_w_en/map_w_addr/map_w_data, then streams the pixels; the image equals the
    fixed-point render (``bumprtl render --model fixed``) byte for byte."""
    r = render_rtl(crater_scene, SIZE, sim, build_dir, progress=False, load="port")
    want = fixed_image(crater_scene, "exact", SIZE)
    assert r.image.tobytes() == r.golden.tobytes() == want.tobytes()
    assert len(np.unique(r.image)) > 20                      # the craters show
    text = (build_dir / "rtl" / "pipeline.v").read_text()
    init = re.findall(r"\\fetch\.map\.mem \[\d+\] = \d+'h([0-9a-f]+);", text)
    assert not any(int(w, 16) for w in init)                 # loaded through the port only
    words = [int(w, 16) for w in (build_dir / "rtl" / "pipeline_map.hex").read_text().split()]
    assert len(words) == SIZE * SIZE and any(words)
