"""docs/fixed_point.md's table of units and latencies states each unit's stages as the
RTL computes them: a stage added or removed fails here until the page says so."""

import re
from pathlib import Path

import pytest

from bumprtl.rtl import methods
from bumprtl.rtl.config import Config
from bumprtl.rtl.pipe import EDGE_LATENCY
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sincos import SinCos
from bumprtl.sim.scenes.config import load_scene_config

PAGE = Path(__file__).resolve().parents[2] / "docs" / "fixed_point.md"


def _silenced(*units):
    for unit in units:
        unit._MustUse__silence = True           # read for its latency only, never elaborated
    return units


def table():
    """{(unit, method): stages} from the page's table."""
    rows = {}
    for line in PAGE.read_text().splitlines():
        m = re.match(r"\| `(\w+)` \| (\w+|—) \| (\d+)\b", line)
        if m:
            rows[(m[1], m[2])] = int(m[3])
    return rows


@pytest.mark.parametrize("method", ["exact", "lee"])
def test_unit_rows_are_the_units_stages(method):
    cfg = Config(method=method)
    rot, ill = _silenced(methods.get(method).rotation(cfg), methods.get(method).illumination(cfg))
    rows = table()
    assert rows[("VectorRotation", method)] == rot.latency
    assert rows[("Illumination", method)] == ill.latency
    assert rot.port_latency == rot.latency + EDGE_LATENCY


def test_sincos_row_and_the_default_pipeline_sentence():
    (sincos,) = _silenced(SinCos(Config()))
    assert table()[("SinCos", "—")] == sincos.latency
    pipeline = BumpPipeline(load_scene_config("default").hardware)
    _silenced(pipeline, *pipeline.units.values())
    u = pipeline.units
    said = (f"has latency {pipeline.latency} (fetch {u['fetch'].latency} + rotation "
            f"{u['rotation'].latency} + illumination {u['illumination'].latency})")
    text = " ".join(PAGE.read_text().split())
    assert said in text
    assert f"EDGE_LATENCY`, {EDGE_LATENCY}: the sidecar's `latency` is {pipeline.port_latency}, " \
           f"its `fifo_depth` {pipeline.fifo_depth})" in text
