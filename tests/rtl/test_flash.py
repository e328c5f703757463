"""FlashLoader (rtl/flash.py) in the Amaranth simulator: the flash model of sim/flash_model.py
(written from the JEDEC READ command) on its SPI pins, an AXI4 write subordinate written
here on its AXI port (random AWREADY, WREADY and B delays), which checks the channel rules
and stores the bytes. The memory must end equal to the flash's bytes, in one READ, with no
rule broken on either side; the configuration's errors name their parameter."""

import numpy as np
import pytest
from amaranth.sim import Simulator

from bumprtl.rtl.config import BumpError, ConfigError
from bumprtl.rtl.flash import FlashConfig, FlashLoader
from bumprtl.sim.flash_model import READ, SpiFlash


class AxiWriteMemory:
    """An AXI4 write subordinate stepped once a clock: ``ready`` decides AWREADY and
    WREADY, B follows a burst's last beat after ``b_delay`` clocks. ``errors`` lists every
    rule broken: AWVALID or WVALID dropped, or their payload changed, before the handshake;
    a W beat before its burst's AW; WLAST not on exactly the beat AWLEN says; a strobe not
    all ones; a burst not INCR or of another beat size; BREADY low with a response."""

    def __init__(self, size, data_bits, ready, b_delay, aw_ready=None):
        self.mem = bytearray(size)
        self.wb = data_bits // 8
        self.ready, self.b_delay = ready, b_delay
        self.aw_ready = aw_ready or ready
        self.errors, self.bursts = [], []           # bursts: [address, beats left]
        self.pending_b, self.held = [], {}
        self.awready = self.wready = 0
        self.bvalid = 0

    def _held(self, ch, valid, payload):
        if ch in self.held and not valid:
            self.errors.append(f"{ch}VALID dropped before {ch}READY")
        if ch in self.held and valid and self.held[ch] != payload:
            self.errors.append(f"{ch} payload changed while waiting")

    def step(self, now, p):
        """``p``: the manager's outputs this clock; returns the subordinate's, this clock's."""
        # this clock's AWREADY, WREADY, BVALID, decided before the handshakes they make
        self.awready, self.wready = int(self.aw_ready()), int(self.ready())
        self.bvalid = int(bool(self.pending_b) and self.pending_b[0] <= now)
        if self.bvalid:
            self.pending_b.pop(0)
            if not p["bready"]:
                self.errors.append("BREADY low with a response")
        aw = (p["awaddr"], p["awlen"], p["awsize"], p["awburst"])
        w = (p["wdata"], p["wstrb"], p["wlast"])
        self._held("AW", p["awvalid"], aw)
        self._held("W", p["wvalid"], w)
        if p["awvalid"] and self.awready:
            self.held.pop("AW", None)
            if p["awburst"] != 1 or p["awsize"] != (self.wb - 1).bit_length():
                self.errors.append(f"burst type {p['awburst']}, size {p['awsize']}")
            self.bursts.append([p["awaddr"], p["awlen"] + 1])
        elif p["awvalid"]:
            self.held["AW"] = aw
        if p["wvalid"] and self.wready:
            self.held.pop("W", None)
            open_bursts = [b for b in self.bursts if b[1] > 0]
            if not open_bursts:
                self.errors.append("a W beat before its burst's AW")
            else:
                b = open_bursts[0]
                b[1] -= 1
                if p["wlast"] != (b[1] == 0):
                    self.errors.append(f"WLAST {p['wlast']} with {b[1]} beats left")
                if p["wstrb"] != (1 << self.wb) - 1:
                    self.errors.append(f"WSTRB {p['wstrb']:#x}")
                self.mem[b[0]:b[0] + self.wb] = int(p["wdata"]).to_bytes(self.wb, "little")
                b[0] += self.wb
                if b[1] == 0:
                    self.pending_b.append(now + 1 + self.b_delay())
        elif p["wvalid"]:
            self.held["W"] = w
        return {"awready": self.awready, "wready": self.wready, "bvalid": self.bvalid}


def run(cfg, image, seed, ready_p=0.5, max_delay=6, limit=200000, aw_p=None, delay=None):
    """The loader with ``image`` in the flash, AWREADY high with probability ``aw_p``
    (None: ``ready_p``), WREADY with ``ready_p``; the flash's MISO ``delay`` clocks after
    SCLK falls (None: ``half_period - 1``, the most the loader allows); returns (flash,
    memory, clocks to done)."""
    rng = np.random.default_rng(seed)
    dut = FlashLoader(cfg)
    flash = SpiFlash(image, min_phase=cfg.half_period,
                     delay=cfg.half_period - 1 if delay is None else delay)
    mem = AxiWriteMemory(1 << cfg.addr_bits if cfg.addr_bits <= 20 else cfg.base + cfg.length,
                         cfg.data_bits, lambda: rng.random() < ready_p,
                         lambda: int(rng.integers(0, max_delay + 1)),
                         None if aw_p is None else lambda: rng.random() < aw_p)
    outs = ["awaddr", "awlen", "awsize", "awburst", "awvalid", "wdata", "wstrb", "wlast",
            "wvalid", "bready"]
    result = {}

    async def bench(ctx):
        for now in range(limit):
            spi = dut.spi
            ctx.set(spi.miso, flash.step(ctx.get(spi.cs_n), ctx.get(spi.sclk), ctx.get(spi.mosi)))
            got = mem.step(now, {k: ctx.get(getattr(dut.axi, k)) for k in outs})
            for k, v in got.items():
                ctx.set(getattr(dut.axi, k), v)
            ctx.set(dut.axi.bresp, 0)
            if ctx.get(dut.done) and "done" not in result:
                result["done"] = now
            if "done" in result and now > result["done"] + 8 * cfg.half_period:
                break
            await ctx.tick()
        result["error"] = ctx.get(dut.error)
        result["cs_n"] = ctx.get(dut.spi.cs_n)

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()
    return flash, mem, result


@pytest.mark.parametrize("data_bits, burst, half_period, ready_p, seed", [
    (16, 8, 2, 0.5, 1), (16, 1, 2, 0.2, 2), (32, 4, 3, 0.9, 3), (8, 16, 2, 0.05, 4),
    (64, 2, 2, 0.5, 5)])
def test_the_memory_ends_equal_to_the_flash(data_bits, burst, half_period, ready_p, seed):
    rng = np.random.default_rng(seed)
    image = rng.integers(0, 256, 4096, dtype=np.uint8).tobytes()
    wb = data_bits // 8
    length = 3 * burst * wb
    offset = 4096 - length - 5                    # near the end of the array, not aligned
    cfg = FlashConfig(offset=offset, length=length, base=2 * burst * wb, addr_bits=12,
                      data_bits=data_bits, burst=burst, half_period=half_period)
    flash, mem, res = run(cfg, image, seed, ready_p)
    assert flash.errors == [] and mem.errors == []
    assert "done" in res and res["error"] == 0 and res["cs_n"] == 1
    assert flash.reads == [(offset, length)]                   # one READ, every byte once
    assert bytes(mem.mem[cfg.base:cfg.base + length]) == image[offset:offset + length]
    assert not any(mem.mem[:cfg.base]) and not any(mem.mem[cfg.base + length:])


def test_no_w_beat_leads_its_aw_when_awready_is_slow():
    """AWREADY rare, WREADY always: each burst's beats wait for its AW (the checker fails a W
    beat with no burst announced), and the copy still completes."""
    cfg = FlashConfig(offset=3, length=64, addr_bits=12, data_bits=8, burst=4, half_period=2)
    image = bytes(range(256))
    flash, mem, res = run(cfg, image, 11, ready_p=1.0, aw_p=0.01)
    assert mem.errors == [] and flash.errors == [] and "done" in res
    assert bytes(mem.mem[:64]) == image[3:67]


def test_the_loader_keeps_the_flash_at_full_rate_when_the_memory_keeps_up():
    """With AWREADY and WREADY always high, SCLK never pauses: the copy takes the READ's
    bits at two phases of half_period clocks each, plus a few clocks at each end."""
    cfg = FlashConfig(offset=16, length=64, addr_bits=12, data_bits=16, burst=4, half_period=2)
    image = bytes(range(256)) * 2
    _, mem, res = run(cfg, image, 9, ready_p=1.0, max_delay=0)
    bits = 32 + 8 * cfg.length
    assert bits * 2 * cfg.half_period <= res["done"] <= (bits + 6) * 2 * cfg.half_period
    assert bytes(mem.mem[:64]) == image[16:80]


@pytest.mark.parametrize("half_period", [2, 4])
def test_a_flash_slower_than_half_period_minus_one_clocks_is_read_wrong(half_period):
    """The margin is what the docstring says: MISO that takes half_period clocks after SCLK
    falls is sampled a bit late, and the copy differs (so the tests above, run at
    half_period - 1, are at the limit)."""
    cfg = FlashConfig(offset=0, length=32, addr_bits=12, data_bits=16, burst=4,
                      half_period=half_period)
    image = bytes(range(1, 65))
    _, mem, res = run(cfg, image, 3, ready_p=1.0, max_delay=0, delay=half_period)
    assert "done" in res and bytes(mem.mem[:32]) != image[:32]


def test_a_bad_response_is_sticky_in_error():
    cfg = FlashConfig(offset=0, length=8, addr_bits=12, data_bits=16, burst=4, half_period=2)
    dut = FlashLoader(cfg)
    seen = []

    async def bench(ctx):
        ctx.set(dut.axi.awready, 1)
        ctx.set(dut.axi.wready, 1)
        ctx.set(dut.axi.bresp, 2)                 # SLVERR
        for _ in range(400):
            ctx.set(dut.axi.bvalid, int(ctx.get(dut.axi.wvalid) and ctx.get(dut.axi.wlast)))
            await ctx.tick()
            seen.append((ctx.get(dut.error), ctx.get(dut.done)))

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()
    first = next(n for n, (e, _) in enumerate(seen) if e)
    assert all(e for e, _ in seen[first:]) and seen[-1][1] == 1


@pytest.mark.parametrize("changes, field", [
    ({"offset": -1}, "offset"), ({"offset": (1 << 24) - 15}, "offset"),
    ({"length": 0}, "length"), ({"length": 17}, "length"), ({"length": 1 << 25}, "length"),
    ({"base": 8}, "base"), ({"base": 1 << 25}, "base"), ({"data_bits": 24}, "data_bits"),
    ({"burst": 3}, "burst"), ({"burst": 512}, "burst"), ({"half_period": 1}, "half_period"),
    ({"addr_bits": 7}, "addr_bits")])
def test_config_errors_name_the_parameter(changes, field):
    kw = {"offset": 0, "length": 16, "burst": 8, "data_bits": 16, **changes}
    with pytest.raises(ConfigError) as e:
        FlashConfig(**kw)
    assert e.value.field == field and field in str(e.value) and isinstance(e.value, BumpError)


def test_the_model_catches_what_a_flash_refuses():
    """The model is not forgiving: another opcode, SCLK high at CS#'s edges, a phase too
    short, CS# raised inside the command."""
    f = SpiFlash(bytes(16), min_phase=2)
    seq = [(1, 0, 0), (0, 0, 0)]
    for bit in "00000010":                        # opcode 0x02 (page program)
        seq += [(0, 0, int(bit)), (0, 0, int(bit)), (0, 1, int(bit)), (0, 1, int(bit))]
    seq += [(0, 1, 0), (1, 1, 0), (1, 0, 0), (0, 0, 0), (0, 1, 0), (0, 0, 0), (1, 0, 0)]
    for pins in seq:
        f.step(*pins)
    text = " | ".join(f.errors)
    assert "opcode 0x02" in text and "SCLK high" in text and "shorter than 2" in text
    assert "inside the command" in text


def _read_pins(addr, nbytes, phase=2):
    """The pins of one READ of ``nbytes`` from ``addr`` in mode 0, each SCLK phase
    ``phase`` clocks: CS# high, low, opcode and address MSB first, then the data clocks."""
    word = READ << 24 | addr
    seq = [(1, 0, 0)] * phase + [(0, 0, 0)] * phase
    for k in range(32 + 8 * nbytes):
        mosi = word >> (31 - k) & 1 if k < 32 else 0
        seq += [(0, 0, mosi)] * phase + [(0, 1, mosi)] * phase
    return seq + [(0, 0, 0)] * phase + [(1, 0, 0)] * phase


def _bytes_read(seq, miso, after):
    """The bytes MISO carries ``after`` steps from each SCLK fall that sends a data bit (the
    fall after the 32nd rise, the last address bit, sends the first)."""
    rises, bits = 0, []
    for i in range(1, len(seq)):
        (cs_n, sclk, _), prev = seq[i], seq[i - 1][1]
        rises += not cs_n and sclk and not prev
        if not cs_n and prev and not sclk and rises >= 32 and len(bits) < 8 * 3:
            bits.append(miso[i + after])
    return bytes(int("".join(map(str, bits[k:k + 8])), 2) for k in range(0, len(bits), 8))


@pytest.mark.parametrize("delay", [0, 1, 2])
def test_the_model_sends_the_array_msb_first_after_its_delay(delay):
    """A READ returns the array from its address on, MSB first; each bit reaches MISO
    ``delay`` steps after the step that sees SCLK fall (0: in that step), and not before."""
    image = bytes([0xA5, 0x3C, 0x81, 0x7E])
    f = SpiFlash(image, min_phase=3, delay=delay)
    seq = _read_pins(1, 3, phase=3)
    miso = [f.step(*pins) for pins in seq]
    assert _bytes_read(seq, miso, delay) == image[1:4]
    if delay:
        assert _bytes_read(seq, miso, delay - 1) != image[1:4]
    assert f.errors == [] and f.reads == [(1, 3)]


def test_the_model_keeps_the_first_twenty_errors():
    """A run of broken commands records its first 20 errors, then no more (a bench that
    went wrong prints a bounded list)."""
    f = SpiFlash(bytes(4))
    for _ in range(10):                            # CS# toggled with SCLK high: one error each
        f.step(1, 1, 0)
        f.step(0, 1, 0)
    first = list(f.errors)
    assert len(first) == 20 and sum("SCLK high" in e for e in first) >= 19
    for _ in range(10):
        f.step(1, 1, 0)
        f.step(0, 1, 0)
    assert f.errors == first
