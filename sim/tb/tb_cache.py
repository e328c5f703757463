"""cocotb testbench for the emitted TextureCache (rtl/cache.py) against a memory we did not
write: cocotbext-axi's ``AxiRamRead`` (the read half of its ``AxiRam``) holds the map's
tiled image (rtl/cache.tiled_image), its AR and R channels paused at random, every burst
delayed by 2, 20 and 60 cycles after its AR handshake (one cocotb test each). Pixels stream in with random
gaps and out under random backpressure (sim/tb/stream.run_stream); every texel is compared
bit for bit with the golden cache model (sim/golden/cache.py), and the AR requests the
memory received with the model's, in order.

Environment: BUMPRTL_CACHE (the CacheGeometry's fields as JSON), BUMPRTL_SAMPLES,
BUMPRTL_PATTERN (a traffic pattern of sim/traffic.py), BUMPRTL_SEED.
"""

import itertools
import json
import os
import random
from types import SimpleNamespace

import cocotb
from cocotb.triggers import ClockCycles
from cocotbext.axi import AxiRamRead, AxiReadBus

from bumprtl.rtl.cache import CacheGeometry, TextureCache, tiled_image
from bumprtl.rtl.layouts import layout_fields
from bumprtl.sim.golden.cache import cache_stimulus, random_levels, run_cache
from bumprtl.sim.tb.stream import run_stream, samples

TAG_BITS = 8
LATENCIES = (2, 20, 60)        # cycles from an AR handshake to its first R beat, at least


def _pauses(rng, p):
    return itertools.cycle([rng.random() < p for _ in range(997)])


class LatentAxiRamRead(AxiRamRead):
    """``AxiRamRead`` whose bursts start ``latency`` cycles after their AR handshake at the
    earliest (the R channel's pauses come on top); ``requests`` lists ``(araddr, arlen)``
    in the order the AR channel took them."""

    def __init__(self, bus, clock, reset, latency, **kwargs):
        super().__init__(bus, clock, reset, **kwargs)
        self.requests = []
        recv = self.ar_channel.recv

        async def delayed():
            ar = await recv()
            self.requests.append((int(ar.araddr), int(ar.arlen)))
            await ClockCycles(clock, latency)
            return ar

        self.ar_channel.recv = delayed



def cache_case():
    """What a cache bench streams, from its environment: ``(geom, n, pattern, seed, levels,
    (u, v, level), golden, meta)``: the geometry (BUMPRTL_CACHE), the pixel count, traffic
    pattern and seed, the random map levels, the stimulus, the golden cache model's run
    and the port layouts (a TextureCache's, for its payloads only)."""
    geom = CacheGeometry(**json.loads(os.environ["BUMPRTL_CACHE"]))
    n = samples(200)
    pattern, seed = os.environ.get("BUMPRTL_PATTERN", "both"), int(os.environ.get("BUMPRTL_SEED", 1))
    levels = random_levels(geom, seed)
    u, v, level = cache_stimulus(geom, n, seed)
    golden = run_cache(geom, u, v, level, levels)
    cache = TextureCache(geom, extra={"tag": TAG_BITS})       # for its payload layouts only
    cache._MustUse__silence = True
    meta = SimpleNamespace(input_fields=layout_fields(cache.i.payload.shape()),
                           output_fields=layout_fields(cache.o.payload.shape()))
    return geom, n, pattern, seed, levels, (u, v, level), golden, meta

@cocotb.test()
@cocotb.parametrize(latency=LATENCIES)
async def cache_matches_golden_against_axi_ram(dut, latency):
    geom, n, pattern, seed, levels, (u, v, level), golden, meta = cache_case()

    image = tiled_image(geom, levels)
    ram = LatentAxiRamRead(AxiReadBus.from_prefix(dut, "axi_"), dut.clk, dut.rst, latency,
                           size=1 << (geom.base + geom.image_bytes - 1).bit_length())
    ram.write(geom.base, image)
    rng = random.Random(seed)
    ram.ar_channel.set_pause_generator(_pauses(rng, 0.3))
    ram.r_channel.set_pause_generator(_pauses(rng, 0.3))

    inputs = [{"u": int(u[k]), "v": int(v[k]), "level": int(level[k]), "tag": k % (1 << TAG_BITS)}
              for k in range(n)]
    index = {id(px): k for k, px in enumerate(inputs)}

    def model(accepted):
        return [{"texel": int(golden.texel[index[id(px)]]), "tag": px["tag"]} for px in accepted]

    await run_stream(dut, meta, inputs, model, pattern, seed,
                     timeout_factor=2 * (latency + 2 * geom.beats + 20))
    assert ram.requests == golden.requests, (
        f"{len(ram.requests)} AR requests, golden {len(golden.requests)}; first differing: "
        f"{next((k for k, (a, b) in enumerate(zip(ram.requests, golden.requests, strict=False)) if a != b), None)}")
    dut._log.info("%d pixels bit-exact, %d AR requests as the golden model (hit rate %.3f, "
                  "latency %d)", n, len(golden.requests), golden.hit_rate, latency)
