"""The bulk wrapper's Verilog template (sim/tb/bulk_wrapper.v), linted on its own and as
sim/tb/bulk_wrapper.py fills it in, with Verilator -Wall and the project's waivers, in
each build the bulk path uses (own clock on Icarus, C++ clock with file or DPI I/O on
Verilator)."""

import subprocess

import pytest

from bumprtl.gen.flow.units import emit_unit
from bumprtl.gen.render.rtl import emit_pipeline, scene_memories
from bumprtl.gen.tools.toolchain import VERILATOR_WAIVERS, require, tool_env
from bumprtl.rtl.config import Config
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.bulk_wrapper import HOOK, TEMPLATE, TOP, host_fields, wrapper_verilog

BUILDS = {"own clock": ["-DBULK_OWN_CLOCK"], "cxx clock, file": [],
          "cxx clock, dpi": ["-DBUMPRTL_BULK_DPI"]}


def _lint(wrapper, unit_v, parameters, defines):
    argv = [require("verilator"), "--lint-only", "-Wall", "--timing",
            *[f"-Wno-{w}" for w in VERILATOR_WAIVERS], "--top-module", TOP,
            *[f"-D{k}={v}" for k, v in defines.items()],
            *[f"-G{k}={v}" for k, v in parameters.items()], str(wrapper), str(unit_v)]
    out = subprocess.run(argv, capture_output=True, text=True, env=tool_env())
    lines = [ln for ln in (out.stdout + out.stderr).splitlines() if ln.startswith("%")]
    return lines or ([f"verilator exited with {out.returncode}"] if out.returncode else [])


def _unit(name, cfg, build_dir):
    v, j = emit_unit(name, cfg, build_dir)
    return v, load_sidecar(j)


@pytest.mark.parametrize("build", BUILDS)
def test_template_as_it_stands_is_lint_clean(build, build_dir):
    """The .v file itself, hook unfilled, around a unit without host ports."""
    v, meta = _unit("sincos", Config(angle_bits=10, frac_bits=11), build_dir)
    params = {"IW": meta.port("i__payload").width,
              "OW": meta.port("o__payload").width, "DEPTH": 64}
    defines = {"BULK_UNIT": meta.unit}
    defines.update({d[2:]: 1 for d in BUILDS[build]})
    assert _lint(TEMPLATE, v, params, defines) == []


@pytest.mark.parametrize("build", BUILDS)
def test_filled_wrapper_with_host_ports_is_lint_clean(build, build_dir):
    """The palette: host write ports (played from the set-up word) and an extra output."""
    v, meta = _unit("palette", Config(palette_size=16), build_dir)
    assert host_fields(meta)[1] > 0
    top, text, params, defines = wrapper_verilog(meta, "BULK_OWN_CLOCK" in str(BUILDS[build]),
                                                 64)
    assert HOOK not in text and ".w_en(host_q[" in text.replace(".lut_w_en", ".w_en")
    path = build_dir / f"{top}.v"
    path.write_text(text)
    defines.update({d[2:]: 1 for d in BUILDS[build]})
    assert _lint(path, v, params, defines) == []


@pytest.mark.parametrize("build", BUILDS)
def test_filled_wrapper_with_an_axi_memory_is_lint_clean(build, build_dir):
    """A map_memory = "axi" palette pipeline: the AXI port on the wrapper's memory model
    (BULK_AXI), not on the set-up word; the LUT's host ports on the set-up word."""
    scene = load_scene_config({"shading": "palette", "texture_size": 16, "tag_bits": 6,
                               "map_memory": "axi"})
    words, _, table = scene_memories(scene)
    v, j = emit_pipeline(scene, words, None, build_dir, None, table)
    meta = load_sidecar(j)
    top, text, params, defines = wrapper_verilog(meta, "BULK_OWN_CLOCK" in str(BUILDS[build]),
                                                 64)
    assert defines["BULK_AXI"] == 1 and ".axi__rdata(ax_rdata)" in text
    assert not any(name.startswith("axi__") for name in host_fields(meta)[0])
    path = build_dir / f"{top}.v"
    path.write_text(text)
    defines.update({d[2:]: 1 for d in BUILDS[build]})
    assert _lint(path, v, params, defines) == []


def test_lint_catches_a_planted_width_error(build_dir):
    """The check can fail: the output payload connected one bit narrow is reported."""
    v, meta = _unit("sincos", Config(angle_bits=10, frac_bits=11), build_dir)
    bad = build_dir / "bad" / f"{TOP}.v"
    bad.parent.mkdir(exist_ok=True)
    bad.write_text(TEMPLATE.read_text().replace(".o__payload(out_payload)",
                                                ".o__payload(out_payload[OW-2:0])"))
    params = {"IW": meta.port("i__payload").width,
              "OW": meta.port("o__payload").width, "DEPTH": 64}
    problems = _lint(bad, v, params, {"BULK_UNIT": meta.unit})
    assert any("out_payload" in line for line in problems), problems
