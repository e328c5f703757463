"""The ULX3S top with the map in the SDRAM (rtl/board.ULX3STop, ULX3SSdramIO; docs/sdram.md,
The pins on the ULX3S), without running the tools:

* elaborated on ``ULX3S_85F_Platform`` (``platform.prepare``: the RTLIL and the LPF, no
  Yosys), its netlist holds the ``USRMCLK`` instance, the SDRAM's and the flash's pins at
  the board's sites, the SDRAM clock from an ODDRX1F sending 0 then 1 (the pipe clock
  inverted), DQ's output and enable registers, the PLL's CLKOS3 half a pipe period after
  CLKOS2; a top with the map in block RAM has none of them;
* the PLL's pipe clock is never above the clock the SdramConfig was made for, in every
  mode and for every bound asked, and a core whose SdramConfig is not the PLL's clock or
  lacks the top's ``pin_cycles`` is refused;
* the controller's read-latency constant with the top's I/O registers (SDRAM_PIN_CYCLES):
  the controller, its pins registered once more and DQ registered once more on the way
  back (what the top's I/O cells and capture flip-flop add, in whole cycles), reads what it
  wrote on the datasheet model; one cycle fewer or more does not;
* the register slice between the source and the texel cache (rtl/board.register_slice):
  order and rate kept, its upstream ready a register.
"""

import random
import re
from dataclasses import replace

import pytest
from amaranth.hdl import Module, Signal
from amaranth.lib import wiring
from amaranth.sim import Simulator
from amaranth_boards.ulx3s import ULX3S_85F_Platform

from bumprtl.gen.flow.board import DEFAULT_PIPE_MHZ, board_core, board_memory
from bumprtl.rtl.board import (
    SDRAM_PIN_CYCLES,
    ULX3STop,
    pll_params,
    pll_pipe_divider,
    register_slice,
    sdram_clock,
)
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.pipe import ECP5
from bumprtl.rtl.sdram import SdramConfig, SdramController
from bumprtl.rtl.video import MODES
from bumprtl.sim import sdram_bench
from bumprtl.sim.scenes.config import load_scene_config

SMALL = {"angle_bits": 10, "texture_size": 16}
# amaranth-boards' ULX3S sdram and spi_flash resources: the sites the LPF must place
SDRAM_SITES = {"clk": ["F19"], "clk_en": ["F20"], "cs": ["P20"], "we": ["T20"], "cas": ["T19"],
               "ras": ["R20"], "dqm": ["U19", "E20"], "ba": ["P19", "N20"],
               "a": "M20 M19 L20 L19 K20 K19 K18 J20 J19 H20 N19 G20 G19".split(),
               "dq": "J16 L18 M18 N18 P18 T18 T17 U20 E19 D20 D19 C20 E18 F18 J18 J17".split()}
FLASH_SITES = {"cs": ["R2"], "copi": ["W2"], "cipo": ["V2"], "hold": ["W1"], "wp": ["Y2"]}


def _plan(map_memory):
    scene = load_scene_config("default", {**SMALL, "map_memory": map_memory})
    mode = MODES["640x480"]
    memory = board_memory(scene, mode) if map_memory == "axi" else None
    top = ULX3STop(board_core(scene, mode, ECP5(), memory=memory))
    plan = ULX3S_85F_Platform().prepare(top, name="top")
    return plan.files["top.il"], plan.files["top.lpf"], memory


def _modules(il):
    """RTLIL text -> {module name: its text}."""
    return {m.group(1): m.group(0) for m in
            re.finditer(r"^module (\S+)$.*?^end$", il, re.MULTILINE | re.DOTALL)}


def _cells(text, kind):
    return re.findall(rf"^\s*cell \\{kind} (\S+)$(.*?)^\s*end$", text, re.MULTILINE | re.DOTALL)


def _sites(lpf, port):
    """The LPF's sites of resource port ``port`` (``sdram_0__dq``), bit order."""
    found = re.findall(rf'LOCATE COMP "{port}__io(?:\[(\d+)\])?" SITE "(\w+)";', lpf)
    return [site for _, site in sorted(found, key=lambda f: int(f[0] or 0))]


@pytest.fixture(scope="module")
def axi_top():
    return _plan("axi")


def test_the_top_with_the_map_in_sdram_has_its_pins_the_flash_clock_and_the_ddr_clock(axi_top):
    il, lpf, memory = axi_top
    mods = _modules(il)
    # every SDRAM and flash pin at the board's site
    for name, sites in SDRAM_SITES.items():
        assert _sites(lpf, f"sdram_0__{name}") == sites, name
    for name, sites in FLASH_SITES.items():
        assert _sites(lpf, f"spi_flash_0__{name}") == sites, name
    # the flash clock through USRMCLK, driven (not tied) and never tristated
    [(_, usr)] = [c for t in mods.values() for c in _cells(t, "USRMCLK")]
    assert re.search(r"connect \\USRMCLKTS 1'0", usr)
    assert not re.search(r"connect \\USRMCLKI \d+'[01]+$", usr, re.MULTILINE)
    # the SDRAM clock: an ODDRX1F sending o[0] = 0 (pipe clock high) then o[1] = 1 (low),
    # not inverted on the way (the clk pin is Pins, not PinsN), the pin's only driver
    [clk_mod] = [t for n, t in mods.items() if n.endswith("memory_pins.sdram_clk")]
    [(_, oddr)] = _cells(clk_mod, "ODDRX1F")
    assert re.search(r"connect \\D0 \\o0_inv", oddr) and re.search(r"connect \\D1 \\o1_inv", oddr)
    assert re.search(r"connect \\SCLK \\pipe_clk", oddr)
    for k in (0, 1):
        assert re.search(rf"connect \\A \\o \[{k}\]\n    connect \\B 1'0\n    connect \\Y \\o{k}_inv",
                         clk_mod)
    [pins] = [t for n, t in mods.items() if n.endswith("memory_pins")]
    [(_, clk_cell)] = _cells(pins, r"top\.memory_pins\.sdram_clk")
    wire = re.search(r"connect \\o (\\\S+) \[1:0\]$", clk_cell, re.MULTILINE).group(1)
    assert f"assign {wire} [0] 1'0\n" in pins and f"assign {wire} [1] 1'1\n" in pins
    # DQ: 16 output and 16 output-enable registers in the I/O cells, 16 bidirectional buffers
    assert len(_cells(pins, "OFS1P3DX")) == 32 and len(_cells(pins, "BB")) == 16
    # the PLL: CLKOS3 at CLKOS2's divider, half of its period later
    [(_, pll)] = [c for t in mods.values() for c in _cells(t, "EHXPLLL")]

    def param(name):
        m = re.search(rf'parameter \\{name} (?:"(\w+)"|(\d+))', pll)
        return m.group(1) or int(m.group(2))

    div = param("CLKOS2_DIV")
    assert param("CLKOS3_ENABLE") == "ENABLED" and param("CLKOS3_DIV") == div
    half_eighths = 8 * (param("CLKOS3_CPHASE") - param("CLKOS2_CPHASE")) \
        + param("CLKOS3_FPHASE") - param("CLKOS2_FPHASE")
    assert half_eighths == 4 * div                         # div / 2 VCO cycles, in eighths
    vco = 25e6 / param("CLKI_DIV") * param("CLKFB_DIV") * param("CLKOP_DIV")
    assert vco / div == memory.pipe_hz


def test_the_top_with_the_map_in_block_ram_has_none_of_them():
    il, lpf, _ = _plan("bram")
    mods = _modules(il)
    assert "sdram_0" not in lpf and "spi_flash_0" not in lpf
    assert not any(_cells(t, "USRMCLK") for t in mods.values())
    assert sum(len(_cells(t, "ODDRX1F")) for t in mods.values()) == 4       # the HDMI lanes
    assert "CLKOS3_ENABLE" not in il


def _driver(text, wire):
    """The $dff cell of ``text`` whose Q is ``wire`` (RTLIL, a whole wire): (its D, its
    clock), or None."""
    for body in re.findall(r"^\s*cell \$dff \S+$(.*?)^\s*end$", text, re.MULTILINE | re.DOTALL):
        if re.search(rf"connect \\Q {re.escape(wire)}$", body, re.MULTILINE):
            d = re.search(r"connect \\D (.+)$", body, re.MULTILINE).group(1)
            clk = re.search(r"connect \\CLK (.+)$", body, re.MULTILINE).group(1)
            return d, clk
    return None


def test_every_hdmi_lane_passes_the_same_registers_to_its_oddr():
    # each lane's two bits, the clock lane's too, reach their ODDRX1F through PIN_STAGES
    # shift-domain registers from the serializer's output (the core's o0, o1), so the
    # lanes leave in step
    from bumprtl.rtl.board import PIN_STAGES
    il, _, _ = _plan("bram")
    [top] = [t for t in _modules(il).values() if _cells(t, "ODDRX1F")]
    lanes = {name: body for name, body in _cells(top, "ODDRX1F")}
    assert sorted(lanes) == ["\\hdmi_clk_ddr0", "\\hdmi_d_ddr0", "\\hdmi_d_ddr1", "\\hdmi_d_ddr2"]
    core_out = {}
    cells = re.findall(r"^\s*cell (\S+) (\S+)$(.*?)^\s*end$", top, re.MULTILINE | re.DOTALL)
    [core] = [body for kind, _, body in cells if kind.endswith(".core")]
    for port in ("o0", "o1"):
        core_out[port] = re.search(rf"connect \\{port} (\S+)", core).group(1)
    for name, body in lanes.items():
        for port in ("D0", "D1"):
            wire, bit = re.search(rf"connect \\{port} (\S+) \[(\d+)\]", body).groups()
            stages = 0
            while wire != core_out["o0" if port == "D0" else "o1"]:
                driver = _driver(top, wire)
                assert driver is not None, (name, port, wire)
                wire = driver[0].split(" [")[0]
                assert driver[1].startswith("\\shift_clk"), (name, port, driver)
                stages += 1
            assert stages == PIN_STAGES, (name, port, stages)
            lane = 3 if "clk" in name else int(name[-1])
            assert int(bit) == lane, (name, port, bit)


@pytest.mark.parametrize("name", [n for n in MODES])
def test_the_pipe_clock_is_never_above_the_sdram_configs(name):
    mode = MODES[name]
    scene = load_scene_config("default", {**SMALL, "map_memory": "axi"})
    for bound_mhz in (None, 100, 99.9, 90, 75, 60, 40):
        if bound_mhz is not None and bound_mhz * 1e6 < mode.pixel_hz:
            continue
        bound = None if bound_mhz is None else bound_mhz * 1e6
        try:
            memory = board_memory(scene, mode, pipe_hz=bound)
        except BumpError as e:           # no PLL clock in [pixel clock, bound]
            assert e.field == "pipe_hz" and bound is not None
            continue
        p = pll_params(mode.pixel_hz, pipe_hz=memory.pipe_hz, sdram=True)
        vco = 25e6 / p["p_CLKI_DIV"] * p["p_CLKFB_DIV"] * p["p_CLKOP_DIV"]
        pll_hz = vco / p["p_CLKOS2_DIV"]
        limit = DEFAULT_PIPE_MHZ * 1e6 if bound is None else bound
        assert pll_hz <= memory.sdram.freq_mhz * 1e6 * (1 + 1e-12), (name, bound_mhz)
        assert abs(pll_hz - memory.sdram.freq_mhz * 1e6) <= 1e-6 * pll_hz
        assert mode.pixel_hz <= pll_hz <= limit and vco / (p["p_CLKOS2_DIV"] - 1) > limit
        assert memory.sdram.pin_cycles == SDRAM_PIN_CYCLES and memory.sdram.cas_latency == 2


def test_the_at_most_divider_never_exceeds_what_was_asked():
    pixel = MODES["640x480"].pixel_hz
    for mhz in range(25, 401):
        div, hz = pll_pipe_divider(pixel, mhz * 1e6, at_most=True)
        assert hz <= mhz * 1e6 < (hz * div / (div - 1) if div > 1 else float("inf"))
        # a clock the PLL gives exactly keeps its divider, both ways
        assert pll_pipe_divider(pixel, hz, at_most=True) == pll_pipe_divider(pixel, hz) == (div, hz)
    assert sdram_clock(pixel, 100e6) == 625e6 / 7


def test_a_core_whose_sdram_config_is_not_the_plls_clock_is_refused():
    mode = MODES["640x480"]
    scene = load_scene_config("default", {**SMALL, "map_memory": "axi"})
    made = board_memory(scene, mode)
    for field, sdram in (("freq_mhz", SdramConfig(**{**_fields(made.sdram), "freq_mhz": 100})),
                         ("pin_cycles", SdramConfig(**{**_fields(made.sdram), "pin_cycles": 0}))):
        core = board_core(scene, mode, memory=replace(made, sdram=sdram))
        with pytest.raises(BumpError) as e:
            ULX3STop(core)
        assert e.value.field == field and "\n" not in str(e.value)
        _silence(core)


def _fields(cfg):
    return {k: getattr(cfg, k) for k in cfg.__dataclass_fields__}


def _silence(core):
    for obj in (core, core.pipeline, core.source, core.timing, core.controller, core.loader,
                *core.pipeline.units.values()):
        obj._MustUse__silence = True


class _BoardPins(wiring.Component):
    """The controller as the ULX3S top wires it, in whole pipe cycles: every pin output
    registered once more (the I/O cells' registers) and DQ registered once more on its way
    back (the capture half a cycle late, then the controller's own ``dq_i`` register half a
    cycle on: one cycle more than the pins being the chip's)."""

    def __init__(self, cfg):
        self.inner = SdramController(cfg)
        super().__init__(dict(self.inner.signature.members))

    def elaborate(self, platform):
        m, c = Module(), self.inner
        m.submodules.controller = c
        wiring.connect(m, wiring.flipped(self.rd), c.rd)
        wiring.connect(m, wiring.flipped(self.wr), c.wr)
        idle = {"cke": 1, "cs_n": 1, "ras_n": 1, "cas_n": 1, "we_n": 1}    # deselected at reset
        for name in ("cke", "cs_n", "ras_n", "cas_n", "we_n", "ba", "a", "dqm", "dq_o", "dq_oe"):
            reg = Signal.like(getattr(c.sdram, name), init=idle.get(name, 0), name=f"io_{name}")
            m.d.sync += reg.eq(getattr(c.sdram, name))
            m.d.comb += getattr(self.sdram, name).eq(reg)
        m.d.sync += c.sdram.dq_i.eq(self.sdram.dq_i)
        return m


@pytest.mark.parametrize("pin_cycles", [SDRAM_PIN_CYCLES - 1, SDRAM_PIN_CYCLES,
                                        SDRAM_PIN_CYCLES + 1])
def test_the_read_latency_with_the_tops_io_registers_points_at_the_right_word(pin_cycles,
                                                                             monkeypatch):
    monkeypatch.setattr(sdram_bench, "SdramController", _BoardPins)
    cfg = SdramConfig(freq_mhz=625 / 7, powerup_cycles=20, init_refreshes=2,
                      pin_cycles=pin_cycles)
    data = [bytes((17 * k + j) % 256 for j in range(64)) for k in range(3)]
    ops = [("w", 64 * k, data[k], [0xF] * 16) for k in range(3)]
    ops += [("r", 64 * k, 64) for k in (2, 0, 1)]
    try:
        reads, _, _ = sdram_bench.run(cfg, ops, limit=20_000)
    except AssertionError:             # RLAST early or late: the word count is off
        reads = None
    if pin_cycles == SDRAM_PIN_CYCLES:
        assert reads == [data[2], data[0], data[1]]
    else:
        assert reads != [data[2], data[0], data[1]]


class _Slice(wiring.Component):
    """register_slice between two 8-bit streams, as the board puts it after the source."""

    def __init__(self):
        from amaranth.lib import stream
        super().__init__({"i": wiring.In(stream.Signature(8)), "o": wiring.Out(stream.Signature(8))})

    def elaborate(self, platform):
        m = Module()
        register_slice(m, self.i, self.o)
        return m


@pytest.mark.parametrize("seed", range(3))
def test_the_register_slice_keeps_order_and_rate_with_a_registered_ready(seed):
    """Random offers and random ready downstream: what leaves is what came, in order, none
    lost or doubled; ``i.ready`` never follows ``o.ready`` within a cycle (it is a
    register); with ``o.ready`` high throughout a word passes every cycle."""
    rng = random.Random(seed)
    dut = _Slice()
    sent, got = [], []
    ready_p = 0.3 + 0.2 * seed

    async def bench(ctx):
        k = 0
        for cycle in range(600):
            full_rate = cycle >= 500
            offer = full_rate or rng.random() < 0.7
            ctx.set(dut.i.valid, offer)
            ctx.set(dut.i.payload, k % 256)
            ctx.set(dut.o.ready, 0)
            before = ctx.get(dut.i.ready)
            ctx.set(dut.o.ready, 1)
            assert ctx.get(dut.i.ready) == before
            ctx.set(dut.o.ready, full_rate or rng.random() < ready_p)
            if offer and ctx.get(dut.i.ready):
                sent.append(k % 256)
                k += 1
            if ctx.get(dut.o.valid) and ctx.get(dut.o.ready):
                got.append((ctx.get(dut.o.payload), cycle))
            await ctx.tick()

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()
    words = [w for w, _ in got]
    assert words == sent[:len(words)] and len(sent) - len(words) <= 2
    late = [c for _, c in got if c >= 510]
    assert late == list(range(510, 600))
