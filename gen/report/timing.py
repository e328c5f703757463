"""``bumprtl report timing``: WaveDrom timing diagrams of the default pipeline from a real
simulation trace (the Amaranth simulator on ``BumpPipeline(load_scene_config("default").hardware)``).

Three diagrams, each sampled cycle by cycle (clk, i.valid, i.ready, i.tag, o.valid,
o.ready, o.tag), written as WaveDrom JSON and rendered to SVG with ``yowasp-wavedrom``:

``handshake``  pixels streamed back to back with o.ready high: one pixel per clock;
``stall``      the consumer drops o.ready for a few cycles: o.valid and o.tag are held,
               i.ready falls a cycle later (no credit comes back) and the producer
               holds its pixel;
``latency``    one pixel alone: o.valid rises exactly ``latency`` cycles after i.valid.

docs/timing.md embeds the SVGs and names this command.
"""

import json
from pathlib import Path

from amaranth.sim import Simulator

from bumprtl.gen.tools.docs import made_at, write_section
from bumprtl.rtl.config import Config
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.sim.scenes.config import load_scene_config

__all__ = ["simulate", "wavedrom", "scenarios", "write_timing", "timing_report"]


def simulate(dut, cycles, offer, ready):
    """Run ``dut`` for ``cycles``; ``offer(n)``: is a new pixel offered from cycle ``n`` on
    (a pixel, once offered, stays until taken), ``ready(n)``: o.ready in cycle ``n``.
    Returns per-cycle samples ``{signal: [values]}``; the n-th accepted pixel has tag n."""
    trace = {k: [] for k in ("i.valid", "i.ready", "i.tag", "o.valid", "o.ready", "o.tag")}
    mask = (1 << len(dut.i.payload.tag)) - 1

    async def bench(ctx):
        sent, pending = 0, False
        for n in range(cycles):
            pending = pending or offer(n)
            ctx.set(dut.i.valid, pending)
            ctx.set(dut.i.payload.tag, sent & mask)
            ctx.set(dut.o.ready, ready(n))
            values = {"i.valid": int(pending), "i.ready": ctx.get(dut.i.ready),
                      "i.tag": sent & mask, "o.valid": ctx.get(dut.o.valid),
                      "o.ready": int(ready(n)), "o.tag": ctx.get(dut.o.payload.tag)}
            for k, v in values.items():
                trace[k].append(int(v))
            if pending and values["i.ready"]:
                sent, pending = sent + 1, False
            await ctx.tick()

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()
    return trace


def _bit(values):
    wave, last = "", None
    for v in values:
        wave += "." if v == last else str(v)
        last = v
    return wave


def _bus(values, valid):
    wave, data, last = "", [], None
    for v, ok in zip(values, valid, strict=False):
        key = v if ok else None
        if key == last and wave:
            wave += "."
        elif key is None:
            wave += "x"
        else:
            wave += "="
            data.append(str(v))
        last = key
    return wave, data


def wavedrom(trace, start, stop, title, foot="", nodes=None, edges=()):
    """A WaveDrom source for cycles ``[start, stop)`` of ``trace``; ``nodes``: signal ->
    {cycle: letter} markers for ``edges`` (WaveDrom arrows)."""
    cut = {k: v[start:stop] for k, v in trace.items()}
    signals = [{"name": "clk", "wave": "p" + "." * (stop - start - 1)}]
    for name, bus, valid in (("i.valid", None, None), ("i.ready", None, None),
                             ("i.tag", "i.tag", "i.valid"), ("o.valid", None, None),
                             ("o.ready", None, None), ("o.tag", "o.tag", "o.valid")):
        if bus:
            wave, data = _bus(cut[bus], cut[valid])
            sig = {"name": name, "wave": wave, "data": data}
        else:
            sig = {"name": name, "wave": _bit(cut[name])}
        marks = (nodes or {}).get(name)
        if marks:
            sig["node"] = "".join(marks.get(c + start, ".") for c in range(stop - start))
        signals.append(sig)
    out = {"signal": signals, "head": {"text": title, "tick": start},
           "config": {"hscale": 1}}
    if foot:
        out["foot"] = {"text": foot}
    if edges:
        out["edge"] = list(edges)
    return out


def scenarios(dut_factory=lambda: BumpPipeline(load_scene_config("default").hardware)):
    """``{name: (wavedrom source, facts)}`` of the three diagrams, from real traces."""
    out = {}
    dut = dut_factory()
    lat = dut.port_latency
    # handshake: 6 pixels back to back, o.ready high.
    tr = simulate(dut, lat + 10, offer=lambda n: 1 <= n <= 6, ready=lambda n: 1)
    out["handshake"] = (wavedrom(tr, 0, lat + 10, "Handshake: one pixel per clock, o.ready high",
                                 f"pixel n (tag n) is accepted when i.valid & i.ready and comes "
                                 f"out {lat} cycles later; a transfer is o.valid & o.ready"),
                        {"latency": lat, "trace": tr})
    dut = dut_factory()
    stall = range(lat + 4, lat + 8)
    tr = simulate(dut, lat + 14, offer=lambda n: n >= 1, ready=lambda n: n not in stall)
    out["stall"] = (wavedrom(tr, lat - 1, lat + 12,
                             "Stall: o.ready low for 4 cycles",
                             "o.valid and o.tag are held while o.valid & ~o.ready; the pipe "
                             "never stops: the FIFO takes the pixels still on their way, and at "
                             "the least FIFO depth every credit is in the loop, so i.ready "
                             "falls the cycle after o.ready (no credit came back) and the "
                             "producer holds its pixel; i.ready rises the cycle after o.ready "
                             "does"),
                    {"latency": lat, "stall": list(stall), "trace": tr})
    dut = dut_factory()
    tr = simulate(dut, lat + 5, offer=lambda n: n == 1, ready=lambda n: 1)
    first_out = tr["o.valid"].index(1)
    out["latency"] = (wavedrom(tr, 0, lat + 5, f"Latency of the default pipeline: {lat} cycles",
                               f"i.valid in cycle 1, o.valid in cycle {first_out}",
                               nodes={"i.valid": {1: "a"}, "o.valid": {first_out: "b"}},
                               edges=[f"a~>b {first_out - 1} cycles"]),
                      {"latency": lat, "first_out": first_out, "trace": tr})
    return out


def write_timing(out_dir=Path("docs/timing")):
    """Write ``<name>.json`` (WaveDrom source) and ``<name>.svg`` per diagram; returns
    ``{name: facts}``."""
    from yowasp_wavedrom import render  # optional dependency: [docs]

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    facts = {}
    for name, (source, info) in scenarios().items():
        (out_dir / f"{name}.json").write_text(json.dumps(source, indent=1) + "\n")
        (out_dir / f"{name}.svg").write_text(render(source))
        facts[name] = info
    return facts


def timing_report(out=Path("docs/timing"), doc=None):
    """``bumprtl report timing``: writes the diagrams under ``out`` and, when ``doc`` is an
    existing page, its Made-at record; prints what it wrote and the latency; returns 0."""
    facts = write_timing(out)
    for name in facts:
        print(f"wrote {out / name}.json and .svg")
    if doc is not None and doc.is_file():
        write_section(doc, "made-at", made_at(Config(), f"`bumprtl report timing`: the "
                      f"default pipeline's latency is {facts['latency']['latency']} cycles"))
        print(f"wrote the record of {doc}")
    print(f"default pipeline latency: {facts['latency']['latency']} cycles "
          f"(o.valid in cycle {facts['latency']['first_out']} for i.valid in cycle 1)")
    return 0
