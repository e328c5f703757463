"""The coverage frame (sim/tb/bulk_frame.py) through the pipelines of the built-in scenes,
on Icarus under the four traffic patterns, every output field against the golden model:
``diffuse`` (no specular term), ``flat`` (no map: the polygon registers), ``textured`` (the
colour texture blended with the shading), ``two-lights`` (two illumination units and their
sum), ``full`` (both, with two mip levels) and the palette scenes. The default scene
streams it in tests/sim/tb/test_bulk.py (before its rendered frame), the full scene also in
tests/sim/tb/test_tb_pipeline.py (every cycle from cocotb, make regress). This is the frame and the four traffic patterns the netlist mutants of
these scenes run (tests/mutants/netlist.py), so a mutant that frame kills is killed by
make test."""


import numpy as np
import pytest

from bumprtl.gen.render.rtl import emit_pipeline, scene_stimulus, scene_texels
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.bulk import run_bulk
from bumprtl.sim.tb.bulk_frame import coverage_frame
from bumprtl.sim.traffic import PATTERNS

TRAFFIC = tuple(PATTERNS)


def _scene_frame(scene, build_dir):
    """The scene's pipeline emitted with its memories, its coverage frame and the golden
    outputs of the frame: (verilog, sidecar, frame, golden)."""
    _, words, _, _, base = scene_stimulus(scene, 16)
    texels = scene_texels(scene, base)
    v, j = emit_pipeline(scene, words, texels, build_dir, None, write_port=True)
    meta = load_sidecar(j)
    frame = coverage_frame(scene, words, texels)
    return v, j, meta, frame, frame.expected(meta)


def _stream(v, j, meta, frame, golden, work):
    """The frame through the build: each pixel once, in order, every field the golden one."""
    r = run_bulk("icarus", v, j, work, TRAFFIC, inputs=frame.inputs, expected=golden,
                 setup=frame.setup(meta), between=frame.between(meta))
    assert r.checked
    for pattern in TRAFFIC:
        assert r.pixels[pattern] == len(frame.inputs["tag"]), pattern
        assert np.array_equal(r.outputs[pattern]["tag"], frame.inputs["tag"]), pattern
        for field, want in golden.items():
            assert np.array_equal(r.outputs[pattern][field], want), (pattern, field)


# textured and two-lights in make regress: make test streams the full scene's coverage
# frame here, whose datapath is two-lights' with textured's colour texture and the mip
# levels added (its per-cycle cocotb run is make regress's, tests/sim/tb/test_tb_pipeline.py).
# diffuse (no H path) too: make test holds that pipeline to the golden model in the Amaranth
# simulator, specular off in every switch pair (tests/rtl/test_pipeline.py).
@pytest.mark.parametrize("name", ["flat", "full",
                                  pytest.param("diffuse", marks=pytest.mark.regress),
                                  pytest.param("textured", marks=pytest.mark.regress),
                                  pytest.param("two-lights", marks=pytest.mark.regress)])
def test_scene_coverage_frame_equals_golden(name, build_dir):
    v, j, meta, frame, golden = _scene_frame(load_scene_config(name), build_dir)
    assert set(golden) == set(meta.output_fields)      # every output
    _stream(v, j, meta, frame, golden, build_dir / "bulk")


# The palette scenes: the built-in one (table entry only) and one with a colour texture
# (the entry blended with the texel by Tarini eq. 2), each channel of the colour its own field.
PALETTE_SCENES = {"palette": "palette",
                  "palette-textured": {"name": "palette-textured", "shading": "palette",
                                       "texture": True, "image": "bricks"}}


@pytest.mark.parametrize("name", PALETTE_SCENES)
def test_bulk_palette_frame_equals_golden(name, build_dir):
    """A palette scene's coverage frame: a random colour table read from bank 1 between
    decoy tables, then from bank 0 and bank 1 in turn with a decoy in the other bank (one
    traffic pattern a bank: a bank stuck at either value shows), random indices written
    through the map's host port, and (textured) random texels. Every channel of the colour (r, g, b, a each a field of its own) equals
    the golden model's, so the RTL and the model cannot agree on a channel mix-up of the
    table entry or of eq. 2 unless both make it; the colours depend on the channel (a test
    whose every channel carried the same value could not see one swapped)."""
    v, j, meta, frame, golden = _scene_frame(load_scene_config(PALETTE_SCENES[name]), build_dir)
    channels = [f for f in golden if f.startswith("color.")]
    assert len(channels) == 4, sorted(golden)
    stacked = np.stack([golden[c] for c in channels])
    assert (stacked != stacked[:1]).any(axis=0).mean() > 0.9     # channels differ
    _stream(v, j, meta, frame, golden, build_dir / "bulk")


def _dot_residues(rot, n_terms, v, shift):
    """Distance of each pixel's exact-method dot sum n''.v'' (rtl/exact.py: x4 p2 + 2 y2 y2 +
    2 z4 z, rounded once at ``shift`` bits) to its rounding carry, and whether the sum is
    positive; ``n_terms`` the n'' terms, ``rot`` the rotated vector terms."""
    acc = (n_terms["n.x4"] * rot[f"{v}.p2"] + 2 * n_terms["n.y2"] * rot[f"{v}.y2"]
           + 2 * n_terms["n.z4"] * rot[f"{v}.z"])
    d = (acc + (1 << (shift - 1))) & ((1 << shift) - 1)
    return np.minimum(d, (1 << shift) - d), acc > 0


def test_a_flat_maps_frame_holds_dots_next_to_their_rounding_carry():
    """A flat map's N and N' are its polygon's, so its frame's near-carry pixels are searched
    over the lights: at least CARRY_PIXELS of them have a positive L (and H) dot sum within 2
    LSBs of the carry, where a wrong low bit of a product moves the dot; random lights put
    one there about once in ten thousand. Computed here from the frame's own codes and the
    polygon's n'' terms (rtl/exact.py's sum), not by the frame's search."""
    from bumprtl.sim.golden.fixed.exact import rotation_fixed
    from bumprtl.sim.tb.bulk_frame import CARRY_PIXELS, PIXELS
    scene = load_scene_config("flat")
    cfg = scene.config
    _, words, _, _, base = scene_stimulus(scene, 16)
    frame = coverage_frame(scene, words, scene_texels(scene, base))
    codes = {k: np.asarray(frame.inputs[k][:PIXELS], np.int64)
             for k in ("l.phi", "l.theta", "h.phi", "h.theta")}
    # the plane faces +z (theta_N = 0) at the polygon's phi_N; its n'' terms are registers
    codes["n.phi"] = np.full(PIXELS, frame.polygon["n_phi"], np.int64)
    codes["n.theta"] = codes["b.phi"] = codes["b.theta"] = np.zeros(PIXELS, np.int64)
    rot = {k: np.asarray(v, np.int64) for k, v in rotation_fixed(codes, cfg).items()}
    for v in ("l", "h") if cfg.specular else ("l",):
        dist, lit = _dot_residues(rot, frame.polygon, v, cfg.frac_bits + 3)
        assert np.count_nonzero((dist <= 2) & lit) >= CARRY_PIXELS, v


@pytest.fixture(scope="module")
def two_lights_frame():
    scene = load_scene_config("two-lights")
    _, words, _, _, base = scene_stimulus(scene, 16)
    return scene, coverage_frame(scene, words, scene_texels(scene, base))


def test_every_lights_dots_sit_next_to_their_rounding_carry(two_lights_frame):
    """Each light has its own illumination unit, so each light's L and H dots need pixels
    near their rounding carry: the two-light scene's frame has at least CARRY_PIXELS for
    each light's L and H within 8 LSBs of it (the nearest of CARRY_POOL random pixels at
    this scene's widths), its N' the texel each pixel fetches (the golden fetch)."""
    from bumprtl.rtl.layouts import light_keys
    from bumprtl.sim.golden.fixed.exact import rotation_fixed
    from bumprtl.sim.golden.fixed.pipeline import fetch_fixed, unpack_texels
    from bumprtl.sim.tb.bulk_frame import CARRY_PIXELS, PIXELS
    scene, frame = two_lights_frame
    cfg = scene.config
    ins = {k: np.asarray(v[:PIXELS], np.int64) for k, v in frame.inputs.items()}
    b = unpack_texels(fetch_fixed(ins["u"], ins["v"], ins.get("level"), frame.words, scene), scene)
    keys = light_keys(cfg)
    assert len(keys) == 2
    for light in keys:
        codes = {"n.phi": ins["n.phi"], "n.theta": ins["n.theta"],
                 "b.phi": np.asarray(b["b.phi"], np.int64),
                 "b.theta": np.asarray(b["b.theta"], np.int64),
                 **{own: ins[key] for own, key in light.items()}}
        rot = {k: np.asarray(v, np.int64) for k, v in rotation_fixed(codes, cfg).items()}
        for v in ("l", "h"):
            dist, lit = _dot_residues(rot, rot, v, cfg.frac_bits + 3)
            assert np.count_nonzero((dist <= 8) & lit) >= CARRY_PIXELS, (light[f"{v}.phi"], v)


def test_a_move_of_each_dot_sum_by_a_few_bits_below_its_lsb_shows(two_lights_frame):
    """A wrong bit k of a product or a partial sum moves a dot's unrounded sum by 2**k. On
    the two-light scene's frame (its dot-sensitivity pixels included) every light's L and H
    sum moved by +2**k or by -2**k, for every k from 5 bits below the dot's rounding point
    up, changes some output of the golden model on DOT_QUOTA pixels or more (a mutant's
    move has the sign of the bit it breaks, which each pixel shows with even odds); the
    frame's pixels before the
    dot-sensitivity ones (the rendered-like, near-carry and table-sensitivity pixels) leave
    some of those moves unseen. The moves are made through the golden model's DOT_SUM hook
    on the frame's own inputs, not by the frame's search."""
    from bumprtl.sim.golden.fixed import exact
    from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
    scene, frame = two_lights_frame
    cfg = scene.config
    shift = cfg.frac_bits + 3
    ins = {k: np.asarray(v, np.int64) for k, v in frame.inputs.items() if k != "tag"}

    from bumprtl.sim.tb.bulk_frame import DOT_QUOTA

    def unseen(px, need=1):
        """The moves that change an output on fewer than ``need`` pixels of ``px``."""
        sums, site = [], {"at": None, "delta": 0}

        def hook(v, acc):
            if v == "l":
                sums.append(v)
            return acc + site["delta"] if site["at"] == (len(sums) - 1, v) else acc
        saved, exact.DOT_SUM = exact.DOT_SUM, hook
        try:
            base = pipeline_fixed(px, scene, frame.words, frame.polygon, frame.texels)
            lights = len(sums)
            out = []
            for at in [(j, v) for j in range(lights) for v in ("l", "h")]:
                for k in range(shift - 5, shift + 2):
                    for delta in (1 << k, -(1 << k)):
                        sums.clear()
                        site.update(at=at, delta=delta)
                        got = pipeline_fixed(px, scene, frame.words, frame.polygon, frame.texels)
                        shown = np.zeros(len(px["u"]), bool)
                        for f in base:
                            shown |= np.asarray(got[f]) != np.asarray(base[f])
                        if np.count_nonzero(shown) < need:
                            out.append((at, k, delta))
            return lights, out
        finally:
            exact.DOT_SUM = saved
    lights, missed = unseen(ins, DOT_QUOTA)
    assert lights == 2 and DOT_QUOTA >= 3
    assert missed == [], f"moves fewer than {DOT_QUOTA} pixels show: {missed}"
    from bumprtl.sim.tb.bulk_frame import SEED, _dot_sensitive
    dots = _dot_sensitive(scene, frame.words, frame.polygon, frame.texels, SEED, list(ins))
    first = len(frame.inputs["tag"]) - len(dots["u"])          # they end the frame
    _, before = unseen({k: v[:first] for k, v in ins.items()})
    assert before, "the frame's other pixels show every move already: the test sees nothing"
