"""A target added without editing an element: :class:`RegisteredGeneric`, defined here as a
subclass of rtl/targets.Generic, lowers the product and the ROM its own way (the same
registers moved: the product registered twice after the multiply, the ROM read
asynchronously from a registered address) and leaves the RAM to the generic form; every
element (a product, a constant product, a wide product, a ROM, a RAM, rtl/lee.py's
BlockROM), built with ``target=RegisteredGeneric()``, keeps its contract under a random
enable. The elements themselves hold no target's code (read from their source)."""

import ast
import inspect
import textwrap

import numpy as np
import pytest
from amaranth.back import rtlil
from amaranth.hdl import Const, Signal, signed, unsigned
from amaranth.lib.memory import Memory
from amaranth.sim import Simulator

from bumprtl.rtl.config import Config
from bumprtl.rtl.lee import BlockROM, LeeRotation
from bumprtl.rtl.targets import (
    PRODUCT_LATENCY,
    RAM_LATENCY,
    ROM_LATENCY,
    WIDE_PRODUCT_LATENCY,
    Generic,
    RegisteredProduct,
    RegisteredRAM,
    RegisteredROM,
    WideProduct,
)
from bumprtl.sim.ecp5 import enabled_delay


class RegisteredGeneric(Generic):
    """The generic forms with their registers moved to the outputs: a product multiplied
    from the operands and registered twice (``p0``, then ``p``); a ROM read asynchronously
    from a registered address (``addr{n}``), then its output register. The RAM is the
    generic form (an asynchronous read from a registered address would see a write of the
    same cycle, which the RAM's contract excludes)."""

    def product(self, m, unit):
        p0 = Signal.like(unit.p, name="p0")
        with m.If(unit.en):
            m.d.sync += [p0.eq(unit.a * unit.b), unit.p.eq(p0)]

    def rom(self, m, rom):
        m.submodules.mem = mem = Memory(shape=rom.shape, depth=rom.depth, init=rom.init)
        for n, port in enumerate(rom.ports):
            addr = Signal.like(port.addr, name=f"addr{n}")
            read = mem.read_port(domain="comb")
            m.d.comb += read.addr.eq(addr)
            with m.If(rom.en):
                m.d.sync += [addr.eq(port.addr), port.data.eq(read.data)]


TARGET = RegisteredGeneric()


def _value(shape, rng):
    lo = -(1 << (shape.width - 1)) if shape.signed else 0
    return int(rng.integers(lo, lo + (1 << shape.width)))


def _table(depth, width, seed):
    return np.random.default_rng(seed).integers(0, 1 << width, depth).tolist()


def _product(make, latency):
    """(unit, drive, sample, reference, latency) of a product ``make(target)``."""
    def case(target):
        unit = make(target)
        const = isinstance(unit.b, Const)

        def drive(ctx, rng):
            a = _value(unit.a.shape(), rng)
            b = unit.b.value if const else _value(unit.b.shape(), rng)
            ctx.set(unit.a, a)
            if not const:
                ctx.set(unit.b, b)
            return a * b
        return unit, drive, lambda ctx: ctx.get(unit.p), latency
    return case


def _rom(cls, depth, width, ports):
    table = _table(depth, width, depth + ports)

    def case(target):
        unit = cls(table, unsigned(width), ports, "t", target=target)

        def drive(ctx, rng):
            addrs = [int(rng.integers(0, depth)) for _ in unit.ports]
            for port, addr in zip(unit.ports, addrs, strict=True):
                ctx.set(port.addr, addr)
            return tuple(table[a] for a in addrs)
        return unit, drive, lambda ctx: tuple(ctx.get(p.data) for p in unit.ports), ROM_LATENCY
    return case


def _ram(depth, width):
    init = _table(depth, width, depth)

    def case(target):
        unit = RegisteredRAM(depth, unsigned(width), "m", init, target=target)
        mem = list(init)

        def drive(ctx, rng):
            r_addr, w_addr = int(rng.integers(0, depth)), int(rng.integers(0, depth))
            w_en, w_data = bool(rng.random() < 0.3), int(rng.integers(0, 1 << width))
            for sig, v in ((unit.r_addr, r_addr), (unit.w_addr, w_addr), (unit.w_en, w_en),
                           (unit.w_data, w_data)):
                ctx.set(sig, v)
            old = mem[r_addr]               # a read in the cycle of a write: the old word
            if w_en:
                mem[w_addr] = w_data
            return old
        return unit, drive, lambda ctx: ctx.get(unit.r_data), RAM_LATENCY
    return case


CASES = {
    "product": _product(lambda t: RegisteredProduct(signed(18), unsigned(12), "p", target=t),
                        PRODUCT_LATENCY),
    "constant product": _product(
        lambda t: RegisteredProduct(signed(9), unsigned(8), "p", b_const=179, target=t),
        PRODUCT_LATENCY),
    "wide product": _product(lambda t: WideProduct(signed(30), unsigned(20), "w", target=t),
                             WIDE_PRODUCT_LATENCY),
    "rom": _rom(RegisteredROM, 300, 11, 2),
    "block rom": _rom(BlockROM, 129, 9, 4),
    "ram": _ram(200, 7),
}


def _run(case, n, seed):
    """Random inputs and a random enable for ``n`` clocks: (sampled, expected) outputs of
    every clock after the pipe has filled."""
    unit, drive, sample, latency = case
    rng = np.random.default_rng(seed)
    refs, ens, got = [], [], []

    async def bench(ctx):
        for _ in range(n):
            en = bool(rng.random() < 0.6)
            refs.append(drive(ctx, rng))
            ens.append(en)
            ctx.set(unit.en, en)
            await ctx.tick()
            got.append(sample(ctx))

    sim = Simulator(unit)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    want = enabled_delay(refs, ens, latency - 1)
    return [(g, w) for g, w in zip(got, want, strict=True) if w is not None]


@pytest.mark.parametrize("name", CASES)
def test_added_target_builds_every_element_to_its_contract(name):
    pairs = _run(CASES[name](TARGET), 400, seed=len(name))
    assert len(pairs) > 150
    assert [g for g, _ in pairs] == [w for _, w in pairs]


def _text(unit):
    """The RTLIL of an element, its ports the signals it holds."""
    ports = [v for v in vars(unit).values() if isinstance(v, Signal)]
    ports += [s for port in getattr(unit, "ports", []) for s in (port.addr, port.data)]
    return rtlil.convert(unit, ports=ports, emit_src=False)


@pytest.mark.parametrize("name", CASES)
def test_added_target_is_what_builds_them(name):
    """The product and the ROMs take the added target's form (its registers by name), the
    RAM the generic form it inherits."""
    text = {t: _text(CASES[name](t)[0]) for t in (TARGET, None)}
    own = {"ram": None}.get(name, "p0" if "product" in name else "addr0")
    if own is None:
        assert text[TARGET] == text[None]
    else:
        assert own in text[TARGET] and own not in text[None]


def test_added_target_reaches_a_units_tables():
    """A whole unit given the target passes it down to every BlockROM it builds."""
    cfg = Config(angle_bits=8, frac_bits=7, method="lee")
    text = rtlil.convert(LeeRotation(cfg, target=TARGET), emit_src=False)
    assert "addr3" in text and "addr3" not in rtlil.convert(LeeRotation(cfg), emit_src=False)


VENDOR = ("dp16kd", "mult18x18d", "ecp5", "instance")


@pytest.mark.parametrize("cls", [RegisteredProduct, WideProduct, RegisteredROM, RegisteredRAM,
                                 BlockROM])
def test_elements_hold_no_target_code(cls):
    """No name or string of an element's code (its docstrings aside) names a vendor
    primitive or a target; an element never compares its target."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    docs = {id(n.body[0].value) for n in ast.walk(tree)
            if isinstance(n, (ast.ClassDef, ast.FunctionDef)) and n.body
            and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
    words = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            words.append(node.id)
        elif isinstance(node, ast.Attribute):
            words.append(node.attr)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            words.append(node.value)
        elif isinstance(node, ast.Compare):
            assert "target" not in ast.unparse(node), ast.unparse(node)
    found = [w for w in words if any(v in w.lower() for v in VENDOR)]
    assert not found, found
