"""An AXI4 read-only memory for the Amaranth simulator: the subordinate side of
rtl/cache.axi_read_signature, written here so that a unit test needs no HDL simulator (the
cocotb benches use cocotbext-axi's AxiRam instead, sim/tb/tb_cache.py).

It serves INCR bursts in order, each beat ``latency`` cycles after its AR handshake at the
earliest, with random ARREADY and RVALID stalls, and checks the manager's side of the AXI4
rules every cycle: ARVALID held until ARREADY with a stable payload, INCR bursts of the
data width, no burst crossing 4 KiB, RREADY never needed for RVALID.
"""

import random

from bumprtl.sim.amaranth_stream import Drive, Sampled

__all__ = ["AxiReadMemory"]


class AxiReadMemory:
    """``image`` (bytes, its first byte at ``base``) behind ``port`` (an AXI read port of a
    component, the manager's view). ``requests`` collects every AR handshake as
    ``(araddr, arlen)``. ``ar_stall``, ``r_stall``: probability of ARREADY low and of RVALID
    held back in a cycle; ``latency``: least cycles from AR handshake to its first beat."""

    def __init__(self, port, image, data_bits, base=0, latency=2, ar_stall=0.0, r_stall=0.0,
                 seed=0):
        self.port, self.image, self.base = port, bytes(image), base
        self.bytes = data_bits // 8
        self.latency, self.ar_stall, self.r_stall = latency, ar_stall, r_stall
        self.rng = random.Random(seed)
        self.requests = []
        # ARREADY, RVALID, RDATA and RLAST in one set a cycle (wired into the top by
        # simulate_stream when this model is one of its ``models``); RDATA and RLAST hold the
        # last beat's while none is presented
        self.drive = Drive({"arready": port.arready, "rvalid": port.rvalid,
                            "rdata": port.rdata, "rlast": port.rlast})

    def _beats(self, addr, arlen, ready_at):
        off = addr - self.base
        assert 0 <= off and off + (arlen + 1) * self.bytes <= len(self.image), (
            f"burst at {addr:#x} of {arlen + 1} beats outside the image")
        assert addr // 4096 == (addr + (arlen + 1) * self.bytes - 1) // 4096, (
            f"burst at {addr:#x} crosses a 4 KiB boundary")
        return [(ready_at, int.from_bytes(self.image[off + k * self.bytes:
                                                     off + (k + 1) * self.bytes], "little"),
                 k == arlen) for k in range(arlen + 1)]

    async def process(self, ctx):
        p = self.port
        cycle, beats, held_ar, presenting = 0, [], None, None
        drive = self.drive
        # the port's read-side signals sampled as one value a cycle
        port = Sampled({n: getattr(p, n) for n in ("arvalid", "arready", "araddr", "arlen",
                                                   "arsize", "arburst", "rvalid", "rready")})
        while True:
            drive["arready"] = self.rng.random() >= self.ar_stall
            if presenting is None and beats and beats[0][0] <= cycle \
                    and self.rng.random() >= self.r_stall:
                presenting = beats.pop(0)
                drive["rdata"], drive["rlast"] = presenting[1], presenting[2]
            drive["rvalid"] = presenting is not None
            drive.set(ctx)
            _, _, bits = await ctx.tick().sample(port.value)
            arvalid, arready, araddr, arlen, arsize, arburst, rvalid, rready = port.cut(bits)
            ar = (araddr, arlen, arsize, arburst)
            if held_ar is not None:
                assert arvalid and ar == held_ar, (
                    f"cycle {cycle}: AR withdrawn or changed before ARREADY: {held_ar} -> "
                    f"{ar if arvalid else None}")
            held_ar = ar if arvalid and not arready else None
            if arvalid and arready:
                assert arburst == 1 and 1 << arsize == self.bytes, f"AR {ar}: not INCR of the bus"
                self.requests.append((araddr, arlen))
                beats += self._beats(araddr, arlen, cycle + self.latency)
            if rvalid and rready:
                presenting = None
            cycle += 1
