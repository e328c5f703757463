"""The pages `bumprtl report integration` and `bumprtl report timing` generate state the
default pipeline's latency and FIFO depth as the RTL computes them: a stage added to a unit
fails here until the pages are generated again (both commands take seconds)."""

import json
import re
from pathlib import Path

from bumprtl.rtl import methods
from bumprtl.rtl.config import Config
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.sim.scenes.config import load_scene_config

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _silenced(*units):
    for unit in units:
        unit._MustUse__silence = True          # read for its latency only, never elaborated
    return units


def default_pipeline():
    pipeline = BumpPipeline(load_scene_config("default").hardware)
    _silenced(pipeline, *pipeline.units.values())
    return pipeline


def test_integration_page_states_the_default_pipelines_latency_and_depth():
    p = default_pipeline()
    text = (DOCS / "integration.md").read_text()
    assert f"* Latency: **{p.port_latency} cycles**" in text
    assert f"This design's sidecar: latency {p.port_latency}, FIFO depth {p.fifo_depth}," in text
    assert f'BUF["FIFO<br/>{p.fifo_depth} entries"]' in text
    rot = p.units["rotation"]
    assert re.search(rf"rotation: \w+<br/>latency {rot.latency}<br/>", text)


def test_timing_page_and_its_figure_state_the_latency():
    p = default_pipeline()
    assert f"the default pipeline's latency is {p.port_latency} cycles" in (DOCS / "timing.md").read_text()
    latency = json.loads((DOCS / "timing" / "latency.json").read_text())
    assert latency["head"]["text"] == f"Latency of the default pipeline: {p.port_latency} cycles"


def test_hand_written_latencies_are_the_rtls():
    """The hand-written pages that quote a latency at today's default say what the RTL
    computes: Lee's two units (docs/lee_method.md) and the default pipeline's sidecar
    (docs/scenes.md)."""
    cfg = Config(method="lee")
    rot, ill = _silenced(methods.get("lee").rotation(cfg), methods.get("lee").illumination(cfg))
    lee = " ".join((DOCS / "lee_method.md").read_text().split())
    assert f"Latency {rot.latency} + {ill.latency} cycles at the default widths" in lee
    scenes = " ".join((DOCS / "scenes.md").read_text().split())
    assert f"{default_pipeline().port_latency} at today's default, the `latency` of" in scenes
