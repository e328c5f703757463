"""The bulk path's stimulus generators (sim/tb/bulk_sources.py) outside the simulator, at
tiny sizes: the chunks cover ``n`` with tags counting on across them (k * TAG_STEP), each source puts
what its docstring promises first (quadrant edges, the edge cases and rounding carries,
the palette's corners and a decoy table swapped out, the pipeline's corners), and the
expected outputs are the golden model's on exactly those inputs. make regress streams 10^7
of them through the simulators."""

import numpy as np
import pytest

from bumprtl.gen.flow.units import build_unit
from bumprtl.rtl.config import Config
from bumprtl.rtl.tables import cos_lookup, sin_lookup
from bumprtl.sim.golden.fixed.palette_lut import unpack_rgba
from bumprtl.sim.golden.fixed.pipeline import (
    corner_inputs,
    corner_texels,
    pipeline_fixed,
    random_inputs,
)
from bumprtl.sim.golden.methods import illumination_fixed, rotation_fixed
from bumprtl.sim.golden.vectors import edge_codes, random_codes
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.bulk_sources import (
    SOURCES,
    TAG_STEP,
    make_source,
    palette_table,
    pipeline_map,
    rounding_codes,
)

SMALL = Config(angle_bits=10, frac_bits=11, tag_bits=4)
ROT_IN = ["n.phi", "n.theta", "l.phi", "l.theta", "h.phi", "h.theta", "b.phi", "b.theta", "tag"]
ROT_OUT = ["n.x4", "n.y2", "n.z4", "l.p2", "l.y2", "l.z", "h.p2", "h.y2", "h.z", "tag"]


def _meta(unit, cfg):
    if unit in ("sincos", "palette"):                  # cheap to build: the real sidecar
        dut, sidecar, _ = build_unit(unit, cfg)
        dut._MustUse__silence = True                     # built for its sidecar only
        return sidecar
    from types import SimpleNamespace
    outs = ["diffuse", "specular", "color", "diffuse_fine", "specular_fine", "tag"]
    return SimpleNamespace(unit=unit, config=cfg.to_dict(),
                           input_fields=ROT_IN if unit == "rotation" else ROT_IN[2:],
                           output_fields=ROT_OUT if unit == "rotation" else outs)


def _all(meta, spec, chunk):
    setup, chunks = make_source(meta, spec, chunk)
    return setup, list(chunks)


def _tags_count_on(chunks, n, bits):
    """Pixel k's tag is k * TAG_STEP modulo 2**bits across the chunks: every tag once in a
    run of 2**bits pixels, the top bit set among the first few."""
    tags = np.concatenate([i["tag"] for i, _ in chunks])
    assert np.array_equal(tags, (np.arange(n) * TAG_STEP) % (1 << bits))
    assert np.any(tags[:4] >> (bits - 1)), tags[:4]
    if n >= 1 << bits:
        assert len(set(tags[:1 << bits].tolist())) == 1 << bits
    for inputs, want in chunks:
        if want is not None:
            assert np.array_equal(want["tag"], inputs["tag"])


def test_an_unknown_kind_is_refused_naming_the_kinds():
    with pytest.raises(ValueError, match="bulk source must be one of " + ", ".join(SOURCES)
                       + ", got 'nosuch'"):
        make_source(None, {"kind": "nosuch", "n": 1}, 8)


def test_sincos_edges_first_then_random_angles_with_the_tables(monkeypatch):
    cfg = SMALL
    setup, chunks = _all(_meta("sincos", cfg), {"kind": "sincos", "n": 37, "seed": 2}, 16)
    assert setup == [] and [len(i["angle"]) for i, _ in chunks] == [16, 16, 5]
    _tags_count_on(chunks, 37, cfg.tag_bits)
    quarter, full = 1 << cfg.k, cfg.full_circle
    edges = [(q * quarter + d) % full for q in range(4) for d in (-1, 0, 1)]
    assert chunks[0][0]["angle"][:12].tolist() == edges
    angles = np.concatenate([i["angle"] for i, _ in chunks])
    assert angles.min() >= 0 and angles.max() < full and len(np.unique(angles[12:])) > 15
    for inputs, want in chunks:
        assert np.array_equal(want["sin"], sin_lookup(cfg, inputs["angle"]))
        assert np.array_equal(want["cos"], cos_lookup(cfg, inputs["angle"]))
        # against the closed form: within an LSB of B-bit sin / cos
        x = 2 * np.pi * inputs["angle"] / full
        assert np.abs(want["sin"] / 2 ** cfg.frac_bits - np.sin(x)).max() <= 2.0 ** -cfg.frac_bits
    again = _all(_meta("sincos", cfg), {"kind": "sincos", "n": 37, "seed": 2}, 16)[1]
    other = _all(_meta("sincos", cfg), {"kind": "sincos", "n": 37, "seed": 3}, 16)[1]
    assert np.array_equal(again[1][0]["angle"], chunks[1][0]["angle"])      # the seed decides
    assert not np.array_equal(other[1][0]["angle"], chunks[1][0]["angle"])


@pytest.mark.parametrize("unit, method", [("rotation", "exact"), ("illumination", "lee")])
def test_datapath_edge_cases_first_and_the_units_golden_outputs(unit, method):
    cfg = SMALL.replace(method=method)
    meta = _meta(unit, cfg)
    n, chunk = 900, 800                 # the edge cases (656) and the carries fit the first
    _, chunks = _all(meta, {"kind": "datapath", "n": n, "seed": 1}, chunk)
    assert [len(i["tag"]) for i, _ in chunks] == [800, 100]
    _tags_count_on(chunks, n, cfg.tag_bits)
    edges = edge_codes(cfg)
    m = len(edges["n.phi"])
    if unit == "illumination":          # its inputs: the rotation of the edge cases
        edges = rotation_fixed(edges, cfg)
    first = chunks[0][0]
    for k in meta.input_fields:
        if k != "tag" and k in edges:
            assert np.array_equal(first[k][:m], edges[k]), k
    for inputs, want in chunks:
        codes = {k: v for k, v in inputs.items() if k != "tag"}
        if unit == "rotation":
            gold = rotation_fixed(codes, cfg)
        else:
            gold = illumination_fixed(codes, cfg)
        for k in meta.output_fields:
            if k != "tag":
                assert np.array_equal(want[k], gold[k]), k


def test_rotation_source_puts_the_rounding_carries_after_the_edge_cases():
    cfg = SMALL
    _, chunks = _all(_meta("rotation", cfg), {"kind": "datapath", "n": 900, "seed": 0}, 900)
    m = len(edge_codes(cfg)["n.phi"])
    near = rounding_codes(cfg, 0)
    count = len(near["n.phi"])
    assert m + count < 900
    for k in near:
        assert np.array_equal(chunks[0][0][k][m:m + count], near[k]), k


def _carry_distance(codes, cfg, v):
    """|dot-product sum - nearest carry into bit B + 3| (rtl/exact.py's one rounding)."""
    rot = {k: np.asarray(x, np.int64) for k, x in rotation_fixed(codes, cfg).items()}
    acc = rot["n.x4"] * rot[f"{v}.p2"] + 2 * rot["n.y2"] * rot[f"{v}.y2"] + 2 * rot["n.z4"] * rot[f"{v}.z"]
    step = 1 << (cfg.frac_bits + 3)
    d = (acc + step // 2) % step
    return np.minimum(d, step - d), acc


def test_rounding_codes_sit_next_to_a_carry_far_nearer_than_random_pixels():
    cfg = SMALL
    picks = rounding_codes(cfg, seed=3, pool=4096, count=16)
    assert len(picks["n.phi"]) == 32                     # 16 for L, 16 for H (specular)
    rand = random_codes(4096, cfg, seed=99)
    for v, rows in (("l", slice(0, 16)), ("h", slice(16, 32))):
        near, _ = _carry_distance({k: c[rows] for k, c in picks.items()}, cfg, v)
        typical, _ = _carry_distance(rand, cfg, v)
        assert near.max() * 20 < np.median(typical), v
    lit = rounding_codes(cfg, seed=3, pool=4096, count=16, lit=True)
    _, acc = _carry_distance({k: c[:16] for k, c in lit.items()}, cfg, "l")
    assert (acc > 0).all()
    diffuse = rounding_codes(cfg.replace(specular=False), seed=3, pool=1024, count=8)
    assert len(diffuse["n.phi"]) == 8                    # no H without specular
    assert rounding_codes(cfg.replace(method="lee")) is None


@pytest.mark.parametrize("blend", [False, True])
def test_palette_decoy_swapped_out_corners_first_and_out_of_range_reads_zero(blend):
    cfg = Config(palette_size=20, palette_blend=blend, tag_bits=8)
    meta = _meta("palette", cfg)
    setup, chunks = _all(meta, {"kind": "palette", "n": 150, "seed": 4}, 100)
    table, decoy = palette_table(cfg, 4), palette_table(cfg, 5)
    assert not np.array_equal(table, decoy)
    writes = lambda part: [(w["w_addr"], w["w_data"]) for w in part]
    size = cfg.palette_size
    assert writes(setup[:size]) == list(enumerate(decoy.tolist())) and setup[size] == {"swap": 1}
    assert writes(setup[size + 1:2 * size + 1]) == list(enumerate(table.tolist()))
    assert setup[2 * size + 1:] == [{"swap": 1}]
    _tags_count_on(chunks, 150, 8)
    top = int(max(i["index"].max() for i, _ in chunks))
    first = chunks[0][0]["index"]
    assert first.min() == 0 and 0 in first[:4] and top in first[:4] and top >= size
    assert ("base.r" in chunks[0][0]) == blend
    for inputs, want in chunks:
        oor = inputs["index"] >= size
        assert np.array_equal(want["oor"], oor.astype(np.int64)) and oor.any()
        if not blend:                # the table entry itself, zero out of range
            entry = unpack_rgba(table[np.minimum(inputs["index"], size - 1)], cfg)
            for c in ("r", "g", "b", "a"):
                assert np.array_equal(want[f"color.{c}"], np.where(oor, 0, entry[c])), c


def test_pipeline_map_corners_point_straight_up_and_the_chunks_are_golden():
    scene = load_scene_config("default", {"texture_size": 16, "angle_bits": 10,
                                          "frac_bits": 11})
    words = pipeline_map(scene, 0)
    ends = corner_texels(scene)
    assert (words[ends] >> scene.angle_bits == 0).all()          # theta_A = 0 there
    assert (words >> scene.angle_bits != 0).sum() > len(words) // 2
    fields = list(random_inputs(scene, 1, np.random.default_rng(0))) + ["tag"]
    from types import SimpleNamespace
    meta = SimpleNamespace(scene=scene.to_dict(), input_fields=fields)
    _, chunks = _all(meta, {"kind": "pipeline", "n": 90, "seed": 1, "map_seed": 0}, 40)
    assert [len(i["tag"]) for i, _ in chunks] == [40, 40, 10]
    _tags_count_on(chunks, 90, scene.tag_bits)
    corners = corner_inputs(scene)
    m = min(40, len(corners["u"]))
    for k, v in corners.items():
        assert np.array_equal(chunks[0][0][k][:m], v[:m]), k
    for inputs, want in chunks:
        gold = pipeline_fixed(inputs, scene, words)
        assert set(gold) <= set(want)
        for k, v in gold.items():
            assert np.array_equal(want[k], v), k
