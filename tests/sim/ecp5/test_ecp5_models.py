"""The ECP5 form simulated (sim/ecp5): the MULT18X18D model against plain products in every
register mode, the DP16KD model's widths and write modes, and rtl/pipe.py's RegisteredROM
(every word, the spill word included) and RegisteredProduct in their ECP5 form (DP16KD /
MULT18X18D instances) bit-exact against the generic form and the golden values under a
random enable (Icarus)."""

import numpy as np
import pytest
from amaranth.hdl import signed, unsigned

from bumprtl.rtl.config import Config
from bumprtl.rtl.pipe import (
    ECP5,
    PRODUCT_LATENCY,
    ROM_LATENCY,
    RegisteredProduct,
    RegisteredROM,
    fits_dsp,
)
from bumprtl.rtl.tables import quarter_sine
from bumprtl.sim.ecp5 import ecp5_lockstep, enabled_delay, model_sources, run_vectors

GROUPS = ("INPUTA", "INPUTB", "PIPELINE", "OUTPUT")


def _mult_top(build_dir, regs, signed_a, signed_b, resetmode="SYNC"):
    """A wrapper around one MULT18X18D, CLK0..3 all on ``clk``: ``regs`` maps each register
    group in use to its (CE index, RST index), e.g. {"OUTPUT": (2, 1)} is REG_OUTPUT on
    CLK0 / CE2 / RST1; the others are bypassed (REG_*_CLK = "NONE")."""
    params = ", ".join(f'.REG_{r}_CLK("CLK0"), .REG_{r}_CE("CE{c}"), .REG_{r}_RST("RST{x}")'
                       for r, (c, x) in regs.items())
    bit = lambda p, n: ", ".join(f".{p}{i}({p.lower()}[{i}])" for i in range(n))
    text = f"""module mult_top(input clk, input rst, input [17:0] a, input [17:0] b, input [3:0] ce,
                input [3:0] reset, output [35:0] p);
  MULT18X18D #({params}{", " if regs else ""}.RESETMODE("{resetmode}")) m (
    {bit("A", 18)}, {bit("B", 18)}, {", ".join(f".C{i}(1'b0)" for i in range(18))},
    .SIGNEDA(1'b{int(signed_a)}), .SIGNEDB(1'b{int(signed_b)}), .SOURCEA(1'b0), .SOURCEB(1'b0),
    .CLK0(clk), .CLK1(clk), .CLK2(clk), .CLK3(clk), .CE0(ce[0]), .CE1(ce[1]), .CE2(ce[2]),
    .CE3(ce[3]), .RST0(reset[0]), .RST1(reset[1]), .RST2(reset[2]), .RST3(reset[3]), {bit("P", 36)});
endmodule
"""
    path = build_dir / "mult_top.v"
    path.write_text(text)
    return path


def _mult_reference(regs, a, b, ce, reset, signed_a, signed_b):
    """P after each rising edge, register by register: INPUTA/B take A/B, PIPELINE the
    product of the (registered or not) operands, OUTPUT the (registered or not) product;
    a group's reset (its RSTn) clears it and wins over its enable (its CEn)."""
    val = lambda x, s: x - (1 << 18) if s and x >> 17 else x
    prod = lambda x, y: (val(int(x), signed_a) * val(int(y), signed_b)) & ((1 << 36) - 1)
    state = dict.fromkeys(regs, 0)

    def path(k):
        av = state.get("INPUTA", a[k])
        bv = state.get("INPUTB", b[k])
        m_in = prod(av, bv)
        mv = state.get("PIPELINE", m_in)
        return m_in, mv, state.get("OUTPUT", mv)

    out = []
    for k in range(len(a)):
        m_in, mv, _ = path(k)
        d = {"INPUTA": a[k], "INPUTB": b[k], "PIPELINE": m_in, "OUTPUT": mv}
        state = {g: 0 if reset[k] >> x & 1 else d[g] if ce[k] >> c & 1 else state[g]
                 for g, (c, x) in regs.items()}
        out.append(path(k)[2])
    return out


MULT_MODES = {
    "comb": {},
    "in": {"INPUTA": (0, 0), "INPUTB": (0, 0)},
    "in_out": {"INPUTA": (0, 0), "INPUTB": (0, 0), "OUTPUT": (0, 0)},        # rtl/pipe.py's
    "in_pipe_out": dict.fromkeys(GROUPS, (0, 0)),
    "out": {"OUTPUT": (0, 0)},
    "pipe": {"PIPELINE": (0, 0)},
    "a_only": {"INPUTA": (0, 0)},
    "own_ce_rst": {"INPUTA": (1, 2), "INPUTB": (2, 3), "PIPELINE": (3, 0), "OUTPUT": (0, 1)},
}


@pytest.mark.parametrize("mode", MULT_MODES)
@pytest.mark.parametrize("signed_a, signed_b", [(1, 1), (0, 0), (1, 0)])
def test_mult18x18d_model_products(mode, signed_a, signed_b, build_dir):
    """P = A x B (18-bit operands, signed or unsigned per SIGNEDA/B, 36-bit P) through each
    register mode (input, pipeline, output registers; each on its own CE/RST in
    own_ce_rst), cycle by cycle against plain products under random CE and RST."""
    regs = MULT_MODES[mode]
    rng = np.random.default_rng(sorted(MULT_MODES).index(mode) * 7 + signed_a * 2 + signed_b)
    n = 400
    a = rng.integers(0, 1 << 18, n)
    b = rng.integers(0, 1 << 18, n)
    a[:4], b[:4] = [0x20000, 0x1FFFF, 0x3FFFF, 0], [0x20000, 0x20000, 0x3FFFF, 5]   # extremes
    ce = rng.integers(0, 16, n) | np.where(rng.random(n) < 0.5, 15, 0)     # CEn each ~3/4 on
    reset = np.where(rng.random(n) < 0.03, rng.integers(1, 16, n), 0)
    top = _mult_top(build_dir, regs, signed_a, signed_b, "ASYNC" if mode == "pipe" else "SYNC")
    out = run_vectors([top, *model_sources()], "mult_top",
                      {"a": (18, a), "b": (18, b), "ce": (4, ce), "reset": (4, reset)},
                      {"p": 36}, build_dir)["p"]
    want = _mult_reference(regs, a, b, ce, reset, signed_a, signed_b)
    assert out == want
    val = lambda x, s: int(x) - (1 << 18) if s and x >> 17 else int(x)
    prod = lambda x, y: (val(x, signed_a) * val(y, signed_b)) & ((1 << 36) - 1)
    # and directly: with every enable on and no reset, P sampled after the edge that takes
    # operand k is the plain product of the operands r - 1 edges back, r the registers on
    # each operand's path (0 registers: the same cycle)
    lag_a = max(0, sum(g in regs for g in ("INPUTA", "PIPELINE", "OUTPUT")) - 1)
    lag_b = max(0, sum(g in regs for g in ("INPUTB", "PIPELINE", "OUTPUT")) - 1)
    lag = max(lag_a, lag_b)
    steady = [k for k in range(lag, n)
              if all(ce[j] == 15 and reset[j] == 0 for j in range(k - lag, k + 1))]
    assert len(steady) > 20
    for k in steady:
        assert out[k] == prod(a[k - lag_a], b[k - lag_b]), (mode, k)


def _rom_lockstep(init, nports, build_dir, n, seed, sweep=True):
    rng = np.random.default_rng(seed)
    depth = len(init)
    abits = max(1, (depth - 1).bit_length())
    en = (rng.random(n) < 0.6).astype(int)
    addrs = []
    for p in range(nports):
        # port 0 walks every word (each held until the enable takes it), the others are random
        if p == 0 and sweep:
            a, w = [], 0
            for e in en:
                a.append(w % depth)
                w += int(e)
            addrs.append(np.array(a))
        else:
            addrs.append(rng.integers(0, depth, n))
    make = lambda t: RegisteredROM(init, unsigned(18) if max(init) < 1 << 18 else unsigned(20),
                                   nports, "rom", target=t)
    ports = lambda u: [u.en, *[x for port in u.ports for x in (port.addr, port.data)]]
    inputs = {"rom_en": (1, en), **{f"rom_p{p}_addr": (abits, addrs[p]) for p in range(nports)}}
    outputs = {f"rom_p{p}_data": make(None).width for p in range(nports)}
    generic, ecp5 = ecp5_lockstep(make, inputs, outputs, build_dir, ports=ports)
    return en, addrs, generic, ecp5


@pytest.mark.parametrize("depth, nports", [(1025, 2), (1025, 1), (1024, 2), (300, 1), (2049, 2), (1500, 1)])
def test_registered_rom_ecp5_form_every_word(depth, nports, build_dir):
    """Every word (1025, 2049: the spill word in its flip-flop; 2049, 1500: two x9 blocks side
    by side) read through the DP16KD model equals the generic form and the table,
    ROM_LATENCY enabled clocks after its address."""
    rng = np.random.default_rng(depth + nports)
    init = [0] + rng.integers(0, 1 << 18, depth - 1).tolist()
    if depth in (1025, 2049):
        init[-1] = (1 << 18) - 1                 # the spill word: every bit set
    assert ECP5().rom_mode(RegisteredROM(init, unsigned(18), nports, "rom")) is not None
    n = int(depth / 0.6) + 200
    en, addrs, generic, ecp5 = _rom_lockstep(init, nports, build_dir, n, seed=depth)
    for p in range(nports):
        key = f"rom_p{p}_data"
        want = enabled_delay([init[a] for a in addrs[p]], en, ROM_LATENCY - 1)
        filled = [k for k in range(n) if want[k] is not None]
        assert [ecp5[key][k] for k in filled] == [want[k] for k in filled], p
        assert [generic[key][k] for k in filled] == [want[k] for k in filled], p
    seen = {addrs[0][k] for k in range(n) if en[k]}
    assert seen == set(range(depth))             # every word, the 1025th included


def test_quarter_sine_table_ecp5_form(build_dir):
    """The real quarter-wave table of the default Config (2**k + 1 words, word 0 = 0)."""
    init = quarter_sine(Config())
    n = 2000
    en, addrs, generic, ecp5 = _rom_lockstep(init, 2, build_dir, n, seed=3)
    for key in generic:
        want = enabled_delay([init[a] for a in addrs[int(key[5])]], en, ROM_LATENCY - 1)
        filled = [k for k in range(n) if want[k] is not None]
        assert [ecp5[key][k] for k in filled] == [generic[key][k] for k in filled] == [want[k] for k in filled]


@pytest.mark.parametrize("a_shape, b_shape", [(signed(18), signed(16)), (unsigned(17), unsigned(9)),
                                              (signed(5), unsigned(9))])
def test_registered_product_ecp5_form(a_shape, b_shape, build_dir):
    """RegisteredProduct as a MULT18X18D (REG_INPUTA/B, REG_OUTPUT on CLK0/CE0) equals the
    generic form and a x b, PRODUCT_LATENCY enabled clocks later, under a random enable."""
    assert fits_dsp(a_shape, b_shape)
    rng = np.random.default_rng(a_shape.width * 31 + b_shape.width)
    n = 600
    lo = lambda s: -(1 << (s.width - 1)) if s.signed else 0
    hi = lambda s: (1 << (s.width - 1)) if s.signed else (1 << s.width)
    a = rng.integers(lo(a_shape), hi(a_shape), n)
    b = rng.integers(lo(b_shape), hi(b_shape), n)
    a[:2], b[:2] = [lo(a_shape), hi(a_shape) - 1], [lo(b_shape), hi(b_shape) - 1]
    en = (rng.random(n) < 0.6).astype(int)
    make = lambda t: RegisteredProduct(a_shape, b_shape, "m", target=t)
    pw = make(None).p.shape().width
    generic, ecp5 = ecp5_lockstep(make, {"m_a": (a_shape.width, a), "m_b": (b_shape.width, b),
                                         "m_en": (1, en)}, {"m": pw}, build_dir,
                                  ports=lambda u: [u.a, u.b, u.en, u.p])
    want = enabled_delay([(int(x) * int(y)) & ((1 << pw) - 1) for x, y in zip(a, b, strict=False)], en,
                         PRODUCT_LATENCY - 1)
    filled = [k for k in range(n) if want[k] is not None]
    assert [ecp5["m"][k] for k in filled] == [want[k] for k in filled]
    assert [generic["m"][k] for k in filled] == [want[k] for k in filled]
