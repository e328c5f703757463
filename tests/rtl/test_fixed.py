"""The Q helper gives the same integers in Amaranth and numpy, and rounds to nearest."""

import numpy as np
from amaranth.hdl import Module, Signal, signed
from amaranth.sim import Simulator
from hypothesis import given
from hypothesis import strategies as st

from bumprtl.rtl.fixed import Q, mul_round, round_shift, saturate


def test_round_shift_is_round_half_up():
    x = np.array([-6, -5, -3, -1, 0, 1, 3, 5, 6])
    assert round_shift(x, 1).tolist() == [-3, -2, -1, 0, 0, 1, 2, 3, 3]
    assert np.all(np.abs(round_shift(x, 2) - x / 4) <= 0.5)


def test_saturate_numpy():
    q = Q(1, 4)
    assert saturate(np.array([-100, -32, 0, 31, 100]), q).tolist() == [-32, -32, 0, 31, 31]


@given(st.lists(st.tuples(st.integers(-2**15, 2**15 - 1), st.integers(-2**15, 2**15 - 1)),
                min_size=1, max_size=40), st.integers(0, 12))
def test_hdl_and_numpy_agree(pairs, n):
    q = Q(3, 8)
    a, b = Signal(signed(16)), Signal(signed(16))
    y = Signal(q.shape)
    m = Module()
    m.d.comb += y.eq(saturate(mul_round(a, b, n), q))
    got = []

    async def tb(ctx):
        for x1, x2 in pairs:
            ctx.set(a, x1)
            ctx.set(b, x2)
            got.append(ctx.get(y))

    sim = Simulator(m)
    sim.add_testbench(tb)
    sim.run()
    arr = np.array(pairs, dtype=np.int64)
    assert got == saturate(mul_round(arr[:, 0], arr[:, 1], n), q).tolist()
