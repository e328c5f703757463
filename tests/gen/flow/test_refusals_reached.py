"""Refusals of gen/flow that no other test reached (docs/coverage.md's per-branch list): a
pixel file that cannot be read, an unknown unit, load or device, an LPF without its clock,
a netlist without its top. Each is a BumpError (one line at the command line) naming what
was given."""

import numpy as np
import pytest

from bumprtl.gen.flow.axis import build_axis
from bumprtl.gen.flow.fpga import elaborate, lpf_mhz
from bumprtl.gen.flow.memories import check_fits, memory_images
from bumprtl.gen.flow.resources import count_netlist
from bumprtl.gen.flow.units import build_unit
from bumprtl.gen.flow.vectors import pixel_columns, read_user_pixels, unit_vectors, write_vectors
from bumprtl.gen.tools.yosys import SynthesisError
from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.scenes.config import load_scene_config

SCENE = load_scene_config("default")
NEED = [c for c in pixel_columns(SCENE) if c != "tag"]
ROW = "0,0,0.5,0.5,0.5,0.5,0.5,0.5"


def _refused(path, *words):
    with pytest.raises(BumpError) as e:
        read_user_pixels(path, SCENE)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_a_good_csv_reads(tmp_path):
    f = tmp_path / "px.csv"
    f.write_text(",".join(NEED) + "\n" + ROW + "\n" + ROW + "\n")
    table = read_user_pixels(f, SCENE)
    assert set(table) == set(NEED) and len(table["u"]) == 2


def test_pixel_file_of_another_kind_is_refused(tmp_path):
    f = tmp_path / "px.txt"
    f.write_text(",".join(NEED) + "\n" + ROW + "\n")
    _refused(f, "--source", ".csv or .npy", "px.txt")


def test_empty_csv_is_refused(tmp_path):
    f = tmp_path / "px.csv"
    f.write_text("\n \n")
    _refused(f, str(f), "empty file")


def test_csv_of_a_header_only_is_refused(tmp_path):
    f = tmp_path / "px.csv"
    f.write_text(",".join(NEED) + "\n")
    _refused(f, str(f), "no pixels")


def test_csv_line_shorter_than_the_header_is_refused(tmp_path):
    f = tmp_path / "px.csv"
    f.write_text(",".join(NEED) + "\n" + ROW + "\n0,0,0.5\n")
    _refused(f, "line 3", "3 values", f"header {len(NEED)}")


def test_npy_of_three_dimensions_is_refused(tmp_path):
    f = tmp_path / "px.npy"
    np.save(f, np.zeros((2, len(NEED), 1)))
    _refused(f, "2-D", str((2, len(NEED), 1)))


def test_npy_with_the_wrong_number_of_columns_is_refused(tmp_path):
    f = tmp_path / "px.npy"
    np.save(f, np.zeros((4, len(NEED) - 1)))
    _refused(f, f"{len(NEED) - 1} columns", f"takes {len(NEED)}")
    np.save(f, np.zeros((4, len(NEED) + 1)))                 # with the optional tag: read
    assert len(read_user_pixels(f, SCENE)["tag"]) == 4


def test_unknown_unit_load_or_device_is_refused(tmp_path):
    with pytest.raises(BumpError, match="--unit must be one of .*got 'shade'"):
        unit_vectors("shade", Config())
    with pytest.raises(BumpError, match="--load must be one of initial, port, got 'rom'"):
        write_vectors(None, tmp_path, load="rom")
    with pytest.raises(BumpError, match="unit must be one of .*got 'shade'"):
        build_unit("shade", Config())
    with pytest.raises(BumpError, match="unit must be one of .*got 'shade'"):
        build_axis("shade", Config())
    with pytest.raises(BumpError, match="device must be one of .*got 'LFE5U-12F'"):
        check_fits({}, "LFE5U-12F", "the map")
    with pytest.raises(BumpError, match="load must be one of initial, port, got 'rom'"):
        memory_images("pipeline", SCENE, None, load="rom")
    assert not any(tmp_path.iterdir())


def test_a_map_of_the_wrong_length_is_refused():
    with pytest.raises(BumpError, match="map has 3 words, the memory holds"):
        memory_images("pipeline", SCENE, [0, 1, 2])


def test_lpf_without_a_clock_line_is_refused(tmp_path):
    lpf = tmp_path / "x.lpf"
    lpf.write_text('FREQUENCY PORT "clk" 62.5 MHZ;\n')
    assert lpf_mhz(lpf) == 62.5
    lpf.write_text('LOCATE COMP "clk" SITE "G2";\n')
    with pytest.raises(BumpError, match='x.lpf has no FREQUENCY PORT "clk"'):
        lpf_mhz(lpf)


def test_elaborate_for_placement_needs_the_ecp5_target():
    component, _, _ = build_unit("rotation", Config())          # the generic form
    with pytest.raises(ValueError, match="rot: build the component with target=ECP5()"):
        elaborate(component, "rot")


def test_count_netlist_without_its_top_is_refused():
    with pytest.raises(SynthesisError, match="top module 'top' not in the netlist .*other"):
        count_netlist({"modules": {"other": {"cells": {}}}}, "top")
