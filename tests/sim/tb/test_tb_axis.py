"""`bumprtl emit UNIT --interface axis` (rtl/axis.py) under cocotb with cocotbext-axi's
AxiStreamSource/AxiStreamSink, pauses on both sides, on Icarus and Verilator: bit-exact with
the golden model, tlast and tuser on the same pixels. Plus the CLI's refusals."""


import pytest

from bumprtl.gen.cli.main import main
from bumprtl.gen.flow.axis import emit_axis
from bumprtl.gen.flow.memories import memory_images
from bumprtl.gen.render.rtl import scene_memories
from bumprtl.rtl.config import Config
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb

SMALL = Config(angle_bits=8, frac_bits=8, tag_bits=6)
# The default scene at small widths and a 16 x 16 map (its bump map as initial contents).
SCENE = load_scene_config({**BUILTIN["default"], "angle_bits": 8, "frac_bits": 8, "tag_bits": 6,
                           "texture_size": 16})


# make test: rotation and illumination on Icarus, the scene pipeline on both (below); make
# regress: the units on Verilator too (each build is half a minute).
# Verilator's run of this test is in make regress (its Icarus run stays in make test, and
# Verilator's builds of the same units run in the other tests of make test).
ICARUS_HERE = [pytest.param(s, marks=pytest.mark.regress if s == "verilator" else ()) for s in SIMULATORS]


# make test: the wrapper (one generic gasket, gen/flow/axis.py) around the illumination here and
# around a scene pipeline below; around the rotation in make regress.
@pytest.mark.parametrize("sim,unit", [pytest.param("icarus", "rotation", marks=pytest.mark.regress),
                                      pytest.param("verilator", "rotation",
                                                   marks=pytest.mark.regress),
                                      ("icarus", "illumination"),
                                      pytest.param("verilator", "illumination",
                                                   marks=pytest.mark.regress)])
def test_axis_cocotb_bit_exact_with_pauses(sim, unit, build_dir):
    v, j, _ = emit_axis(unit, SMALL, build_dir / "rtl")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_axis", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 40})
    assert (run.tests, run.failures) == (1, 0)


def _scene_axis(scene, out):
    images = memory_images("pipeline", scene, *scene_memories(scene))
    return emit_axis("pipeline", scene, out, images=images)


@pytest.mark.parametrize("sim", ICARUS_HERE)
def test_axis_scene_pipeline_bit_exact_with_pauses(sim, build_dir):
    """The default scene's pipeline (bump map in initial contents, no host writes) in
    AXI4-Stream ports: bit-exact against the golden pipeline, tlast/tuser on their pixels."""
    v, j, hexes = _scene_axis(SCENE, build_dir / "rtl")
    assert [h.name for h in hexes] == ["pipeline_axis_map.hex"]
    meta = load_sidecar(j)
    assert meta.memory_images["map"]["file"] == "pipeline_axis_map.hex"
    assert meta.command.startswith("bumprtl emit pipeline --scene default")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_axis", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 21})
    assert (run.tests, run.failures) == (1, 0)


@pytest.mark.regress
@pytest.mark.parametrize("sim", SIMULATORS)
@pytest.mark.parametrize("scene", ["default", "two-lights"])
def test_axis_scene_pipeline_volume(sim, scene, build_dir):
    """More pixels through more scenes' pipelines at the default widths (make regress)."""
    cfg = load_scene_config({**BUILTIN[scene], "texture_size": 64})
    v, j, _ = _scene_axis(cfg, build_dir / "rtl")
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_axis", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 3000})
    assert (run.tests, run.failures) == (1, 0)


def test_axis_ports_and_byte_aligned_packing(tmp_path):
    v, j, _ = emit_axis("rotation", SMALL, tmp_path)
    meta = load_sidecar(j)
    ports, axis = meta.ports, meta.axis
    for p in ("aclk", "aresetn", "s_axis_tdata", "s_axis_tvalid", "s_axis_tready", "s_axis_tuser",
              "s_axis_tlast", "m_axis_tdata", "m_axis_tvalid", "m_axis_tready", "m_axis_tuser",
              "m_axis_tlast"):
        assert p in ports, p
    assert "clk" not in ports and "i__valid" not in ports
    assert axis["tdata_width"] % 8 == 0 and axis["tdata_width"] >= axis["m_axis_tdata_bits"]
    assert ports["s_axis_tdata"].width == axis["tdata_width"] and ports["m_axis_tuser"].width == 6
    fields = sorted(axis["s_axis_tdata_fields"].values())          # packed from bit 0, no gaps
    assert fields[0][0] == 0 and all(a[0] + a[1] == b[0] for a, b in zip(fields, fields[1:], strict=False))
    assert meta.config["tag_bits"] == 6 and meta.command.endswith("--interface axis")
    assert "tag" not in axis["s_axis_tdata_fields"]


def test_too_narrow_tdata_is_refused_in_one_line(tmp_path, capsys):
    rc = main(["emit", "rotation", "--interface", "axis", "--tdata-width", "16", "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1
    assert "tdata_width = 16 is too narrow" in err[0] and f"s_axis_tdata needs {8 * Config().angle_bits} bits" in err[0]
    assert not list(tmp_path.iterdir())
    rc = main(["emit", "sincos", "--interface", "axis", "--tdata-width", "20", "--out", str(tmp_path)])
    assert rc == 2 and "multiple of 8" in capsys.readouterr().err
