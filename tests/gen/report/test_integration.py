"""``bumprtl report integration``: docs/integration.md's generated blocks from the sidecar
of a pipeline emitted with named ports, and the page's Amaranth example."""

import json
import re
from pathlib import Path

import pytest
from amaranth.hdl import Fragment

from bumprtl.gen.report.integration import blocks, emit_for_integration, write_doc
from bumprtl.rtl.config import BumpError
from bumprtl.sim.scenes.config import load_scene_config
from tests.conftest import masked_numbers

ROOT = Path(__file__).resolve().parents[3]
DOC = ROOT / "docs" / "integration.md"


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    return emit_for_integration("default", tmp_path_factory.mktemp("integration"),
                                flags=["--texture-size", "16", "--angle-bits", "10",
                                       "--frac-bits", "11"])


def test_blocks_cover_every_port_field_and_unit(small):
    out = blocks(small)
    assert out["made-at"].startswith("Made at: angle_bits=10, frac_bits=11 ")
    rows = [r for r in out["ports"].splitlines()[2:]]
    named = small.named_ports.ports
    assert len(rows) == len(named)
    for field, (off, width, _) in small.input_fields.items():
        port = "in_" + re.sub(r"\W", "_", field)
        assert any(r.startswith(f"| `{port}` | in | {width} | `i__payload[{off + width - 1}:{off}]`")
                   for r in rows), port
    for field, (off, width, _) in small.output_fields.items():
        assert f"`o__payload[{off + width - 1}:{off}]`" in out["ports"], field
    assert "see rtl/layouts.py" not in out["ports"]          # every port has its meaning
    for b in small.built:
        assert f'{b["unit"]}: {b["class"]}<br/>latency {b["latency"]}' in out["diagram"]
    assert f"**{small.latency} cycles**" in out["timing"]
    assert all(f".{p}" in out["verilog"] for p in named)
    assert "$readmemh(\"my_bump_map.hex\"" in out["load"]
    assert "--texture-size 16" in out["made-at"] and "--name my_bump" in out["made-at"]


def test_the_sidecar_block_tables_every_key_of_the_file(small):
    """Each key of the emitted sidecar (and of a payload field) has its row, the version
    is the file's."""
    out = blocks(small)["sidecar"]
    for key in json.loads(small.dumps()):
        assert f"| `{key}` |" in out, key
    assert "| `ports.NAME.fields` |" in out
    assert f"has `schema_version` **{small.schema_version}**" in out


def test_write_doc_rewrites_only_the_blocks(small, tmp_path):
    doc = tmp_path / "page.md"
    text = "intro\n" + "".join(f"<!-- generated: {n} -->\nOLD-BODY\n<!-- end: {n} -->\nprose {n}\n"
                               for n in blocks(small))
    doc.write_text(text)
    write_doc(doc, blocks(small))
    once = doc.read_text()
    assert "OLD-BODY" not in once and all(f"prose {n}" in once for n in blocks(small))
    write_doc(doc, blocks(small))
    assert doc.read_text() == once                        # idempotent
    doc.write_text("no blocks here\n")
    with pytest.raises(BumpError, match="has no '<!-- generated: made-at -->' block"):
        write_doc(doc, blocks(small))


def test_the_page_has_every_block_filled():
    text = DOC.read_text()
    for name in ("made-at", "diagram", "ports", "timing", "example", "load", "verilog", "sidecar"):
        body = re.search(rf"<!-- generated: {name} -->\n(.*?)<!-- end: {name} -->", text, re.S)
        assert body and body.group(1).strip(), name
    assert "bumprtl report integration" in text


def test_the_pages_amaranth_example_elaborates():
    code = re.search(r"## Instantiation in Amaranth.*?```python\n(.*?)```", DOC.read_text(), re.S).group(1)
    scope = {}
    exec(compile(code, str(DOC), "exec"), scope)
    bump = scope["bump"]
    assert len(scope["shade"]) == 8
    Fragment.get(scope["m"], None)
    assert bump.i.payload.shape().size == 0 or len(bump.i.payload.as_value()) > 0


def test_the_latency_the_page_states_is_the_simulated_one():
    """A pixel taken at edge t leaves at edge t + latency with out_ready high (Amaranth
    simulator on a small pipeline of the default scene class)."""
    from amaranth.sim import Simulator

    from bumprtl.rtl.pipeline import BumpPipeline
    scene = load_scene_config("default", {"texture_size": 16, "angle_bits": 10, "frac_bits": 11})
    dut, seen = BumpPipeline(scene.hardware), {}

    async def bench(ctx):
        ctx.set(dut.o.ready, 1)
        await ctx.tick()
        seen["reset"] = (ctx.get(dut.i.ready), ctx.get(dut.o.valid))
        ctx.set(dut.i.valid, 1)
        ctx.set(dut.i.payload.tag, 5)
        await ctx.tick()                               # edge t: the pixel is taken
        ctx.set(dut.i.valid, 0)
        edges = 0
        while True:
            valid = ctx.get(dut.o.valid)
            await ctx.tick()                           # the consumer takes it at this edge
            edges += 1
            if valid:
                break
        seen["edges"] = edges
    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()
    assert seen["reset"] == (1, 0)                     # after reset: in_ready high, out_valid low
    assert seen["edges"] == dut.port_latency


def test_the_page_is_what_the_report_writes_but_for_numbers_and_the_small_flags(small, tmp_path):
    """Every generated block of docs/integration.md, written again from this module's small
    pipeline (10/11-bit widths, a 16-texel map), is the committed block with its numbers and
    hex constants masked and the small run's own flags taken out of its command lines: the
    port table's rows, the timing, the example, the load and sidecar blocks are the
    writer's."""
    import shutil

    page = tmp_path / "integration.md"
    shutil.copy(DOC, page)
    write_doc(page, blocks(small))

    def masked(text):
        text = text.replace("--texture-size 16 --angle-bits 10 --frac-bits 11 ", "")
        text = text.replace(", {'texture_size': 16, 'angle_bits': 10, 'frac_bits': 11})", ")")
        return masked_numbers(text)
    assert masked(page.read_text()) == masked(DOC.read_text())


def test_report_integration_emits_the_scene_asked_and_writes_the_doc_given(small, tmp_path,
                                                                           monkeypatch, capsys):
    """``bumprtl report integration --scene --out --name --doc``: the emission gets the
    scene, directory and port prefix asked for (the emission itself is the fixture's, the
    Verilator build shared), the page given gets the blocks of what was emitted, and one
    line names it with the record of its widths."""
    import shutil

    from bumprtl.gen.cli.main import main
    from bumprtl.gen.report import integration

    seen = {}

    def emit(scene, out, name):
        seen.update(scene=scene, out=out, name=name)
        return small
    monkeypatch.setattr(integration, "emit_for_integration", emit)
    page = tmp_path / "page.md"
    shutil.copy(DOC, page)
    argv = ["report", "integration", "--scene", "palette", "--out", str(tmp_path / "o"),
            "--doc", str(page), "--name", "shade"]
    assert main(argv) == 0
    assert seen == {"scene": "palette", "out": tmp_path / "o", "name": "shade"}
    expected = tmp_path / "expected.md"
    shutil.copy(DOC, expected)
    write_doc(expected, blocks(small))
    assert page.read_text() == expected.read_text() != DOC.read_text()
    assert capsys.readouterr().out == f"wrote {page} ({blocks(small)['made-at']})\n"
