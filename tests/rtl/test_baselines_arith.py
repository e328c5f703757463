"""The Peercy/Ernst setup's pipelined square root and divider (rtl/baselines/peercy.py) in the
Amaranth simulator against math.isqrt and Python's // (x // 0 = 0): edge cases (0, the
largest operands, a zero divisor, around perfect squares), exhaustive small widths and random
operands, one operand a clock, with and without ``en`` stalls."""

import math
import random

import pytest
from amaranth.sim import Simulator

from bumprtl.rtl.baselines.peercy import (
    PeercyDivider,
    PeercySqrt,
    quotient_bits,
    sqrt_stages,
    square_bits,
)
from bumprtl.rtl.config import Config


def stream(dut, inputs, outputs, values, stall=0.0, seed=0):
    """Present ``values`` (tuples for the ``inputs`` signals) one a cycle, ``en`` low with
    probability ``stall`` (the value is then presented again). After every clock edge the
    ``outputs`` signals must hold the result of the value that entered ``dut.stages`` enabled
    edges before, and hold it through a stall; returns the results in input order."""
    rng = random.Random(seed)
    got = []

    async def testbench(ctx):
        entered = 0
        pending = list(values)
        while len(got) < len(values):
            en = rng.random() >= stall
            if pending:
                for sig, v in zip(inputs, pending[0], strict=False):
                    ctx.set(sig, v)
            ctx.set(dut.en, en)
            await ctx.tick()
            if en:
                if pending:
                    pending.pop(0)
                entered += 1
                if entered >= dut.stages:
                    got.append(tuple(ctx.get(s) for s in outputs))
            elif got:          # a stall holds the output
                assert tuple(ctx.get(s) for s in outputs) == got[-1]

    sim = Simulator(dut)
    sim.add_clock(1e-6)
    sim.add_testbench(testbench)
    sim.run()
    return got


def sqrt_results(width, values, stall=0.0):
    dut = PeercySqrt(width)
    assert dut.stages == (width + 1) // 2
    return [r for r, in stream(dut, [dut.radicand], [dut.root], [(v,) for v in values], stall)]


def div_results(n_bits, d_bits, pairs, q_bits=None, stall=0.0):
    dut = PeercyDivider(n_bits, d_bits, q_bits)
    return [q for q, in stream(dut, [dut.dividend, dut.divisor], [dut.quotient], pairs, stall)]


def floor_div(n, d):
    return n // d if d else 0                   # Amaranth's x // 0 = 0, the golden model's too


# --- square root ----------------------------------------------------------------------------

@pytest.mark.parametrize("width", [1, 2, 7, 10])
def test_sqrt_exhaustive_small_widths(width):
    values = list(range(1 << width))
    assert sqrt_results(width, values, stall=0.3 if width == 7 else 0.0) == \
        [math.isqrt(v) for v in values]


def test_sqrt_edges_and_random_at_the_setup_width():
    """The default setup's radicand 4 s (2B + 11 bits, B + 6 stages): 0, the largest value,
    around perfect squares and random, under stalls."""
    cfg = Config(method="peercy")
    width = square_bits(cfg) + 2
    assert (width + 1) // 2 == sqrt_stages(cfg)
    rng = random.Random(6)
    roots = [rng.randrange(1, 1 << (width // 2)) for _ in range(150)] + [(1 << (width // 2)) - 1]
    values = [0, 1, 2, 3, (1 << width) - 1, (1 << width) - 2]
    values += [r * r + e for r in roots for e in (-1, 0, 1)]
    values += [rng.randrange(1 << width) for _ in range(300)]
    assert sqrt_results(width, values, stall=0.25) == [math.isqrt(v) for v in values]


# --- divider --------------------------------------------------------------------------------

def test_divider_exhaustive_small_widths_every_quotient_bit():
    """quotient_bits = the dividend's width: exact for every operand pair, divisor 0 included."""
    pairs = [(n, d) for n in range(1 << 6) for d in range(1 << 4)]
    assert div_results(6, 4, pairs, stall=0.2) == [floor_div(n, d) for n, d in pairs]


def test_divider_edges_and_random_full_quotient():
    rng = random.Random(7)
    n_bits, d_bits = 24, 11
    top_n, top_d = (1 << n_bits) - 1, (1 << d_bits) - 1
    pairs = [(0, 0), (top_n, 0), (0, 1), (top_n, 1), (top_n, top_d), (0, top_d), (top_d, top_d),
             (top_d - 1, top_d), (top_n, 2), (1, 0)]
    pairs += [(rng.randrange(1 << n_bits), rng.randrange(1 << d_bits)) for _ in range(300)]
    pairs += [(rng.randrange(1 << n_bits), rng.randrange(4)) for _ in range(30)]
    assert div_results(n_bits, d_bits, pairs) == [floor_div(n, d) for n, d in pairs]


def test_divider_at_the_setup_widths():
    """The setup's dividers: |a| 2**(B+2) (2B + 6 bits) by r (B + 6 bits), B + 2 quotient
    bits, exact because r = isqrt(4 s) >= 2 |a|; r = 0 only for the zero vector. Edges: the
    largest quotient 2**(B+1) (r = 2|a|), r = 0 with any |a|, the largest operands, and random
    components with their r."""
    cfg = Config(method="peercy")
    b, nq = cfg.frac_bits, quotient_bits(cfg)
    n_bits, d_bits = 2 * b + 6, b + 6
    mag_max = (1 << (b + 4)) - 1
    rng = random.Random(8)
    mags = [(0, 0, 0), (1, 0, 0), (mag_max, 0, 0), (mag_max, mag_max, mag_max), (0, 0, 1)]
    mags += [tuple(rng.randrange(mag_max + 1) >> rng.randrange(b + 4) for _ in range(3))
             for _ in range(200)]
    pairs = [(0, 0), (mag_max << (b + 2), 0), (1 << (b + 2), 1 << (d_bits - 1))]
    for x, y, z in mags:
        r = math.isqrt(4 * (x * x + y * y + z * z))
        pairs += [(a << (b + 2), r) for a in (x, y, z)]
    assert all(d == 0 or n < d << nq for n, d in pairs)
    got = div_results(n_bits, d_bits, pairs, nq, stall=0.2)
    assert got == [floor_div(n, d) for n, d in pairs]
    assert max(got) == 1 << (b + 1)                 # the largest quotient is reached
