"""The board's read-address queue (rtl/board.ar_queue) between the texel cache and the SDRAM
controller: the manager's bursts are taken while the queue has room even when the
subordinate takes none, reach the subordinate in order with every AR field intact, and the
R channel passes straight through, both ways."""

from amaranth.hdl import Elaboratable, Module
from amaranth.sim import Simulator

from bumprtl.rtl.board import ar_queue
from bumprtl.rtl.cache import axi_read_signature


class Joined(Elaboratable):
    def __init__(self, depth):
        self.depth = depth
        self.mgr = axi_read_signature(24, 32).create(path=("mgr",))
        self.sub = axi_read_signature(24, 32).create(path=("sub",))

    def elaborate(self, platform):
        m = Module()
        ar_queue(m, self.mgr, self.sub, self.depth)
        return m


def test_bursts_queue_in_order_and_r_passes_through():
    dut = Joined(4)
    mgr, sub = dut.mgr, dut.sub
    sent = [(0x1000 + 64 * k, 15, 2, 1) for k in range(6)]
    taken, seen = [], []

    async def bench(ctx):
        ctx.set(sub.arready, 0)
        for n, (addr, length, size, burst) in enumerate(sent):
            ctx.set(mgr.araddr, addr)
            ctx.set(mgr.arlen, length)
            ctx.set(mgr.arsize, size)
            ctx.set(mgr.arburst, burst)
            ctx.set(mgr.arvalid, 1)
            for _ in range(3):
                await ctx.delay(1e-9)
                if ctx.get(mgr.arready):
                    break
                await ctx.tick()
            else:
                break                              # the queue is full
            taken.append(n)
            await ctx.tick()
        ctx.set(mgr.arvalid, 0)
        # the subordinate takes them now, one every other cycle
        for _ in range(20):
            ctx.set(sub.arready, 1)
            await ctx.delay(1e-9)
            if ctx.get(sub.arvalid):
                seen.append((ctx.get(sub.araddr), ctx.get(sub.arlen), ctx.get(sub.arsize),
                             ctx.get(sub.arburst)))
            await ctx.tick()
            ctx.set(sub.arready, 0)
            await ctx.tick()
        # R, both ways
        ctx.set(sub.rdata, 0xDEADBEEF)
        ctx.set(sub.rvalid, 1)
        ctx.set(sub.rlast, 1)
        ctx.set(sub.rresp, 2)
        ctx.set(mgr.rready, 1)
        await ctx.delay(1e-9)
        assert (ctx.get(mgr.rdata), ctx.get(mgr.rvalid), ctx.get(mgr.rlast),
                ctx.get(mgr.rresp), ctx.get(sub.rready)) == (0xDEADBEEF, 1, 1, 2, 1)

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()
    # the subordinate took none meanwhile: the queue's depth of bursts taken back to back
    assert taken == list(range(4))
    assert seen == sent[:4]
