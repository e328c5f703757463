"""Example: the bump-mapping pipeline inside an Amaranth design.

``BumpTop`` is a ``wiring.Component`` with one stream in (``i``: the pipeline's pixel
payload) and one stream out (``o``: the shaded pixel). Inside: ``BumpPipeline`` (built for
the host write port, no map contents in it) and a small loader that copies the bump map
from a ROM through the pipeline's host write port (``map_w_en``, ``map_w_addr``,
``map_w_data``) after reset, one word a clock, holding ``i.ready`` low until the map is in.
The ROM stands in for whatever brings the map in your system (a host bus, a flash reader).

Running this file simulates ``BumpTop`` in the Amaranth simulator with a handful of random
pixels and checks every output field against the bit-exact golden model, the same
expected words ``bumprtl vectors`` writes for a Verilog bench:

    .venv/bin/python docs/examples/amaranth_top.py --pixels 8

prints ``PASS 8`` (or the first mismatch, and exits 1).
"""

import argparse
import sys

from amaranth import Module, Signal
from amaranth.lib import memory, stream, wiring
from amaranth.lib.wiring import In, Out
from amaranth.sim import Simulator

from bumprtl.gen.flow.vectors import pipeline_vectors
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.sim.amaranth_stream import flatten_payload
from bumprtl.sim.scenes.config import load_scene_config


class BumpTop(wiring.Component):
    """The pipeline of ``scene`` with its map ``words`` loaded through the host port.

    Members
    -------
    i : In(stream.Signature(pixel layout))
        Pixels in; ``ready`` stays low until the map is loaded.
    o : Out(stream.Signature(shaded layout))
        Shaded pixels out, in order, the pipeline's own stream.
    loaded : Out(1)
        High once every map word is written.
    """

    def __init__(self, scene, words):
        self._bump = BumpPipeline(scene.hardware)  # no init: the map comes through the port
        self._words = [int(w) for w in words]
        super().__init__({"i": In(stream.Signature(self._bump.i.payload.shape())),
                          "o": Out(stream.Signature(self._bump.o.payload.shape())),
                          "loaded": Out(1)})

    def elaborate(self, platform):
        m = Module()
        m.submodules.bump = bump = self._bump
        depth = len(self._words)
        m.submodules.rom = rom = memory.Memory(shape=bump.map_w_data.shape(), depth=depth,
                                               init=self._words)
        read = rom.read_port()                    # synchronous: the word a clock later
        addr = Signal(range(depth + 1))
        # the write trails the read by one clock: address and enable registered with it
        m.d.comb += read.addr.eq(addr)
        m.d.sync += [bump.map_w_en.eq(~self.loaded & (addr < depth)),
                     bump.map_w_addr.eq(addr)]
        m.d.comb += bump.map_w_data.eq(read.data)
        with m.If(~self.loaded):
            with m.If(addr < depth):
                m.d.sync += addr.eq(addr + 1)
            with m.Else():                         # the last word is written this clock
                m.d.sync += self.loaded.eq(1)
        # pixels only once the map is in (valid never waits on ready: both gated alike)
        m.d.comb += [bump.i.payload.eq(self.i.payload),
                     bump.i.valid.eq(self.i.valid & self.loaded),
                     self.i.ready.eq(bump.i.ready & self.loaded)]
        wiring.connect(m, bump.o, wiring.flipped(self.o))
        return m


def simulate(pixels=8, seed=1, scene=None):
    """``(got, expected)``: ``pixels`` random pixels through ``BumpTop`` in the Amaranth
    simulator, and the golden model's outputs of them (lists of ``{field: int}``)."""
    scene = scene or load_scene_config("default", {"texture_size": 16})
    vec = pipeline_vectors(scene, "random", pixels, seed)
    dut = BumpTop(scene, vec.words)
    ins, outs = flatten_payload(dut.i.payload), flatten_payload(dut.o.payload)
    mask = {k: (1 << len(v)) - 1 for k, v in ins.items()}
    got = []

    async def bench(ctx):
        for n in range(pixels):
            ctx.set(dut.i.valid, 1)
            for k, v in ins.items():
                ctx.set(v, int(vec.inputs[k][n]) & mask[k])
            while True:                            # held until taken
                ctx.set(dut.o.ready, 1)
                _, _, ready, valid, *vals = await ctx.tick().sample(
                    dut.i.ready, dut.o.valid, *outs.values())
                if valid:
                    got.append(dict(zip(outs, (int(x) for x in vals), strict=True)))
                if ready:
                    break
        ctx.set(dut.i.valid, 0)
        for _ in range(200):                       # drain: the pipeline's latency and more
            if len(got) == pixels:
                break
            _, _, valid, *vals = await ctx.tick().sample(dut.o.valid, *outs.values())
            if valid:
                got.append(dict(zip(outs, (int(x) for x in vals), strict=True)))

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()
    expected = [{k: int(vec.expected[k][n]) for k in outs} for n in range(pixels)]
    return got, expected


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pixels", type=int, default=8)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    got, expected = simulate(args.pixels, args.seed)
    for n, want in enumerate(expected):
        have = got[n] if n < len(got) else None
        bad = [k for k in want if have is None or have[k] != want[k]]
        if bad:
            print(f"FAIL pixel {n} field {bad[0]}: got {None if have is None else have[bad[0]]}, "
                  f"expected {want[bad[0]]}")
            return 1
    print(f"PASS {len(expected)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
