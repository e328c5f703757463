"""`bumprtl report timing`: the WaveDrom diagrams come from a real trace of the default
pipeline, and the trace shows what the diagrams say."""

import json
from pathlib import Path

from bumprtl.gen.cli.main import main
from bumprtl.gen.report.timing import _bit, _bus


def test_timing_report_from_the_default_pipeline(tmp_path, capsys):
    assert main(["report", "timing", "--out", str(tmp_path)]) == 0
    for name in ("handshake", "stall", "latency"):
        assert (tmp_path / f"{name}.svg").read_text().startswith("<svg")
        src = json.loads((tmp_path / f"{name}.json").read_text())
        assert [s["name"] for s in src["signal"]][:3] == ["clk", "i.valid", "i.ready"]
    lat = json.loads((tmp_path / "latency.json").read_text())
    waves = {s["name"]: s for s in lat["signal"]}
    latency = int(lat["head"]["text"].split(": ")[1].split()[0])
    assert waves["i.valid"]["wave"].index("1") + latency == waves["o.valid"]["wave"].index("1")
    assert lat["edge"] == [f"a~>b {latency} cycles"]
    stall = {s["name"]: s for s in json.loads((tmp_path / "stall.json").read_text())["signal"]}
    o_ready, o_tag = stall["o.ready"]["wave"], stall["o.tag"]["wave"]
    low = o_ready.index("0")
    high = o_ready.index("1", low)
    assert set(o_tag[low + 1:high + 1]) == {"."}            # o.tag held through the stall
    # at the least FIFO depth (rtl/pipe.min_fifo_depth) every credit is in the loop at full
    # rate: each cycle the consumer takes nothing, no credit comes back and i.ready is low the
    # cycle after (the credit count is a register); back the cycle after o.ready rises
    i_ready = _expand(stall["i.ready"]["wave"])
    assert i_ready[low] == "1" and set(i_ready[low + 1:high + 1]) == {"0"}
    assert i_ready[high + 1] == "1"
    hs = {s["name"]: s for s in json.loads((tmp_path / "handshake.json").read_text())["signal"]}
    assert hs["o.tag"]["data"] == [str(n) for n in range(6)]    # in order, each once
    assert f"default pipeline latency: {latency} cycles" in capsys.readouterr().out
    # the committed diagrams are this run's, byte for byte: docs/timing.md shows them
    docs = Path(__file__).resolve().parents[3] / "docs" / "timing"
    assert sorted(p.name for p in docs.iterdir()) == sorted(p.name for p in tmp_path.iterdir())
    for name in sorted(p.name for p in docs.iterdir()):
        assert (docs / name).read_bytes() == (tmp_path / name).read_bytes(), \
            f"docs/timing/{name} is stale: bumprtl report timing"


def _expand(wave):
    """A WaveDrom bit wave with its '.' repeats written out, one character per cycle."""
    out = []
    for c in wave:
        out.append(out[-1] if c == "." else c)
    return out


def test_wave_encoding():
    assert _bit([0, 0, 1, 1, 0]) == "0.1.0"
    assert _bus([5, 5, 6, 6], [1, 1, 0, 1]) == ("=.x=", ["5", "6"])


def test_the_stall_facts_are_the_cycles_its_trace_holds_o_ready_low():
    """scenarios()'s facts name what each diagram shows: the stall's are the cycles the
    trace holds o.ready low (4 in a row, after the first pixel is out), the latency's the
    cycle the first pixel leaves."""
    from bumprtl.gen.report.timing import scenarios

    facts = {name: info for name, (_src, info) in scenarios().items()}
    stall, lat = facts["stall"], facts["latency"]
    tr = stall["trace"]
    low = [n for n, r in enumerate(tr["o.ready"]) if not r and n > 0]
    assert stall["stall"] == low and len(low) == 4 and low == list(range(low[0], low[0] + 4))
    assert tr["o.valid"][low[0]] == 1                          # a pixel is waiting when it starts
    assert lat["trace"]["o.valid"].index(1) == lat["first_out"] == 1 + lat["latency"]
