"""The SDRAM controller in the Amaranth simulator on the datasheet model (sim/sdram_model.py),
driven by a small AXI manager written here: the fast tier of its tests, and its read
bandwidth (docs/sdram.md).

:func:`run` plays a list of operations (``("w", addr, bytes, strobes)`` and ``("r", addr,
nbytes)``) with every AR issued as soon as the one before is taken (reads overlap), W beats
and B, R under optional random backpressure; it returns the bytes each read returned and
the cycle of each R beat. :func:`bandwidth` measures cycles per 16 bytes of cache-line
reads that hit open rows and that miss them.

``python -m bumprtl.sim.sdram_bench`` prints the bandwidth table of the board's
configuration.
"""

import argparse
import random
from dataclasses import fields

from amaranth.hdl import Module, Signal
from amaranth.sim import Simulator

from bumprtl.rtl.sdram import SdramConfig, SdramController
from bumprtl.sim.sdram_model import SdramModel

__all__ = ["run", "bandwidth", "model_for", "short_config"]


def model_for(cfg: SdramConfig):
    """The datasheet model at the configuration's clock, told its simulation power-up."""
    power = cfg.powerup_cycles
    return SdramModel(cfg.variant, cfg.freq_mhz, log=True,
                      powerup_ns=None if power is None else power * 1000 / cfg.freq_mhz)


class ShortConfig(SdramConfig):
    """A configuration whose conversion gives one timing a cycle short: a broken
    controller (the datasheet model and the formal contract keep the true numbers)."""

    short = "rcd"

    @property
    def cycles(self):
        out = dict(super().cycles)
        out[self.short] -= 1
        return out

    @property
    def refresh_reload(self):
        """The true configuration's: the refresh deadline is not what is broken (a slack
        from the short timing would make the contract's refresh lemma fail first, hiding
        which timer is wrong)."""
        return SdramConfig(**{f.name: getattr(self, f.name) for f in fields(self)}).refresh_reload


def short_config(cfg, timing):
    broken = ShortConfig(**{f.name: getattr(cfg, f.name) for f in fields(cfg)})
    object.__setattr__(broken, "short", timing)
    return broken


def run(cfg: SdramConfig, ops, r_stall=0.0, seed=0, limit=200_000):
    """Play ``ops`` through a controller built from ``cfg``. Returns ``(reads, beats,
    model)``: the bytes of each read in order, the cycle of every R beat taken (with its
    RLAST), and the model (its command log). A cycle is a clock edge's number, read from a
    counter register sampled at that edge by the process that saw the handshake (a
    counting process of its own would run before or after the others at the same edge,
    as the simulator orders them, and move the numbers by one from run to run)."""
    dut = SdramController(cfg)
    model = model_for(cfg)
    nbytes = cfg.data_bits // 8
    rng = random.Random(seed)
    reads, beats, state = [], [], {"ar": []}
    top = Module()
    top.submodules.dut = dut
    cycle = Signal(32, name="cycle")
    top.d.sync += cycle.eq(cycle + 1)
    sim = Simulator(top)
    sim.add_clock(1e-6 / cfg.freq_mhz)

    async def chip(ctx):
        await model.process(ctx, dut.sdram)

    async def r_channel(ctx):
        rd, data, pending = dut.rd, bytearray(), [op for op in ops if op[0] == "r"]
        while pending:
            ctx.set(rd.rready, rng.random() >= r_stall)
            _, _, valid, ready, word, last, now = await ctx.tick().sample(
                rd.rvalid, rd.rready, rd.rdata, rd.rlast, cycle)
            if valid and ready:
                data += word.to_bytes(nbytes, "little")
                beats.append((now, last))
                if len(data) == pending[0][2]:
                    assert last, f"RLAST missing at the end of read {len(reads)}"
                    reads.append(bytes(data))
                    data, pending = bytearray(), pending[1:]
                else:
                    assert not last, f"RLAST early in read {len(reads)}"

    async def manager(ctx):
        rd, wr = dut.rd, dut.wr
        for op in ops:
            if op[0] == "r":
                _, addr, n = op
                ctx.set(rd.araddr, addr)
                ctx.set(rd.arlen, n // nbytes - 1)
                ctx.set(rd.arsize, nbytes.bit_length() - 1)
                ctx.set(rd.arburst, 1)
                ctx.set(rd.arvalid, 1)
                now, _ = await ctx.tick().sample(cycle, rd.arready).until(rd.arready)
                state["ar"].append(now)
                ctx.set(rd.arvalid, 0)
                continue
            _, addr, data, strobes = op
            n = len(data) // nbytes
            ctx.set(wr.awaddr, addr)
            ctx.set(wr.awlen, n - 1)
            ctx.set(wr.awsize, nbytes.bit_length() - 1)
            ctx.set(wr.awburst, 1)
            ctx.set(wr.awvalid, 1)
            await ctx.tick().until(wr.awready)
            ctx.set(wr.awvalid, 0)
            for k in range(n):
                ctx.set(wr.wdata, int.from_bytes(data[k * nbytes:(k + 1) * nbytes], "little"))
                ctx.set(wr.wstrb, strobes[k])
                ctx.set(wr.wlast, k == n - 1)
                ctx.set(wr.wvalid, 1)
                await ctx.tick().until(wr.wready)
            ctx.set(wr.wvalid, 0)
            ctx.set(wr.bready, 1)
            await ctx.tick().until(wr.bvalid)
            ctx.set(wr.bready, 0)
        while len(reads) < sum(op[0] == "r" for op in ops):
            await ctx.tick()
            assert ctx.get(cycle) < limit, f"only {len(reads)} reads answered in {limit} cycles"

    sim.add_process(chip)
    sim.add_process(r_channel)
    sim.add_testbench(manager)
    sim.run()
    if model.error is not None:
        raise model.error
    model.ar_cycles = state["ar"]
    return reads, beats, model


def bandwidth(cfg: SdramConfig, lines=16, line_bytes=64):
    """Cycles per 16 bytes of ``lines`` cache-line reads (``line_bytes`` each, ARs
    back to back, RREADY high): consecutive lines of one row (open-row hits) and lines in
    different rows of one bank (every line a row miss: PRECHARGE, ACTIVE, then its READs),
counted on the SDRAM's data bus from the first READ to the end of the last burst. Also the cycles from
    the first AR handshake to its first R beat (``*_latency``; the row closed)."""
    row_stride = cfg.chip.cols * 2 * cfg.chip.banks        # next row, same bank
    out = {}
    for name, stride in (("hit", line_bytes), ("miss", row_stride)):
        ops = [("r", 0x10000 + k * stride, line_bytes) for k in range(lines)]
        _, beats, model = run(cfg, ops)
        reads = [c for c, cmd, *_ in model.log if cmd == "READ"]
        span = reads[-1] + cfg.burst - reads[0]          # the bursts on DQ, first to last
        out[name] = span * 16 / (lines * line_bytes)
        out[f"{name}_latency"] = beats[0][0] - model.ar_cycles[0]
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", default="32mb")
    ap.add_argument("--freq-mhz", type=float, default=100.0)
    ap.add_argument("--cas-latency", type=int, default=2)
    ap.add_argument("--burst", type=int, default=8)
    args = ap.parse_args(argv)
    cfg = SdramConfig(args.variant, args.freq_mhz, args.cas_latency, burst=args.burst,
                      powerup_cycles=20)
    got = bandwidth(cfg)
    print(f"{cfg.chip.part}, {cfg.freq_mhz} MHz, CL {cfg.cas_latency}, burst {cfg.burst} words, "
          f"{cfg.data_bits}-bit AXI, 16 lines of 64 bytes:")
    print(f"  lines in one open row:        {got['hit']:.2f} cycles per 16 bytes")
    print(f"  each line in a new row (miss): {got['miss']:.2f} cycles per 16 bytes")
    print(f"  first AR to its first R beat: {got['hit_latency']} cycles (its row closed)")


if __name__ == "__main__":
    main()
