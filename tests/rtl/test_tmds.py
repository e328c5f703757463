"""rtl/tmds.TMDSEncoder against the DVI 1.0 standard itself, not against a decoder: a
decoder (cocotbext-dvi's DVISink, a monitor's receiver) reads bit 9 and bit 8 of each word
and forgives a word sent with the wrong one of its two forms, so an encoder whose running
disparity drifts still decodes; a real link, AC-coupled, does not forgive the drift.

:func:`dvi_encode` is the encoding flow chart of DVI 1.0 (section 3.3.1, figure 3-5) written
out here: q_m by XOR or XNOR (XNOR when N1{D} > 4 or N1{D} = 4 and D[0] = 0), then the
three branches on the running disparity ``cnt`` (cnt = 0 or N1{q_m[0:7]} = N0{q_m[0:7]};
cnt > 0 and N1 > N0 or cnt < 0 and N0 > N1; otherwise) with their q_out and cnt updates;
during blanking the four control symbols and cnt = 0. The RTL encoder is driven, in the
Amaranth simulator, through every (reachable disparity, 8-bit value) pair the flow chart
allows and must send the flow chart's word each time; the running disparity of the words
it sends (counted from the words, ones minus zeros) must stay within the flow chart's
bound over random and drift-maximising sequences.
"""

from collections import deque

import numpy as np
from amaranth.sim import Simulator

from bumprtl.rtl.tmds import TMDSEncoder

# DVI 1.0 section 3.3.1: (C1, C0) -> q_out[9:0] during blanking
CONTROL_SYMBOLS = {(0, 0): 0b1101010100, (0, 1): 0b0010101011, (1, 0): 0b0101010100,
                   (1, 1): 0b1010101011}


def _n1(value, bits):
    return bin(value & ((1 << bits) - 1)).count("1")


def dvi_encode(cnt, d):
    """One step of the flow chart: (word q_out[9:0], the next cnt) for data ``d`` sent
    with running disparity ``cnt``."""
    xnor = _n1(d, 8) > 4 or (_n1(d, 8) == 4 and not d & 1)
    q_m = d & 1
    for i in range(1, 8):
        bit = ((q_m >> (i - 1)) ^ (d >> i)) & 1
        q_m |= (bit ^ xnor) << i
    q_m |= (not xnor) << 8
    q_m8 = q_m >> 8
    ones = _n1(q_m, 8)
    zeros = 8 - ones
    low, inv = q_m & 0xFF, ~q_m & 0xFF
    if cnt == 0 or ones == zeros:
        word = (1 - q_m8) << 9 | q_m8 << 8 | (low if q_m8 else inv)
        cnt += (ones - zeros) if q_m8 else (zeros - ones)
    elif (cnt > 0 and ones > zeros) or (cnt < 0 and zeros > ones):
        word = 1 << 9 | q_m8 << 8 | inv
        cnt += 2 * q_m8 + (zeros - ones)
    else:
        word = q_m8 << 8 | low
        cnt += -2 * (1 - q_m8) + (ones - zeros)
    return word, cnt


def reachable():
    """The running disparities the flow chart reaches from cnt = 0 (the value after blanking)."""
    seen, todo = {0}, deque([0])
    while todo:
        c = todo.popleft()
        for d in range(256):
            _, nxt = dvi_encode(c, d)
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen


BOUND = max(abs(c) for c in reachable())
STEP = {(c, d): dvi_encode(c, d) for c in reachable() for d in range(256)}


def covering_walk():
    """A data sequence (after blanking) that applies every value of 0..255 in every
    reachable disparity: from the current cnt, the shortest way (breadth first) to a
    (cnt, value) pair not yet applied."""
    todo = {(c, d) for c in reachable() for d in range(256)}
    seq, cnt = [], 0
    while todo:
        prev, queue = {cnt: None}, deque([cnt])
        while queue:
            c = queue.popleft()
            d = next((d for d in range(256) if (c, d) in todo), None)
            if d is not None:
                break
            for x in range(256):
                nxt = STEP[c, x][1]
                if nxt not in prev:
                    prev[nxt] = (c, x)
                    queue.append(nxt)
        path = []
        while prev[c] is not None:
            c, x = prev[c]
            path.append(x)
        seq += path[::-1] + [d]
        for x in path[::-1] + [d]:
            todo.discard((cnt, x))
            cnt = STEP[cnt, x][1]
    return seq


def encode_rtl(symbols):
    """TMDSEncoder's words for ``symbols``: an int (data, de high) or a (c1, c0) tuple
    (blanking); word k answers symbol k."""
    enc = TMDSEncoder()
    words = []
    tail = [(0, 0)] * enc.latency

    async def bench(ctx):
        for s in symbols + tail:
            if isinstance(s, tuple):
                ctx.set(enc.de, 0)
                ctx.set(enc.c1, s[0])
                ctx.set(enc.c0, s[1])
            else:
                ctx.set(enc.de, 1)
                ctx.set(enc.data, s)
            await ctx.tick()
            words.append(ctx.get(enc.q))

    sim = Simulator(enc)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    return words[enc.latency - 1:enc.latency - 1 + len(symbols)]


def encode_standard(symbols):
    out, cnt = [], 0
    for s in symbols:
        if isinstance(s, tuple):
            out.append(CONTROL_SYMBOLS[s])
            cnt = 0
        else:
            word, cnt = dvi_encode(cnt, s)
            out.append(word)
    return out


def disparities(words, symbols):
    """The running disparity (ones minus zeros sent, counted from the words) after each
    data word; blanking restarts it, as the flow chart does."""
    out, run = [], 0
    for w, s in zip(words, symbols, strict=True):
        if isinstance(s, tuple):
            run = 0
        else:
            run += 2 * _n1(w, 10) - 10
            out.append(run)
    return out


def _mismatch(symbols, got, want):
    k = next(k for k, (g, w) in enumerate(zip(got, want, strict=True)) if g != w)
    return f"symbol {k} ({symbols[k]!r}): sent {got[k]:#012b}, DVI 1.0 says {want[k]:#012b}"


def test_flow_chart_model_reaches_a_bounded_disparity():
    """The model's own sanity: cnt stays even and bounded, and each word's disparity is
    the cnt step the flow chart books (cnt is the running disparity of the words)."""
    states = reachable()
    assert states == set(range(-BOUND, BOUND + 1, 2)) and 0 < BOUND <= 10
    for c in states:
        for d in range(256):
            word, nxt = dvi_encode(c, d)
            assert nxt - c == 2 * _n1(word, 10) - 10


def test_encoder_sends_the_standards_word_for_every_value_in_every_disparity():
    walk = covering_walk()
    pairs, cnt = set(), 0
    for d in walk:
        pairs.add((cnt, d))
        cnt = dvi_encode(cnt, d)[1]
    assert len(pairs) == 256 * len(reachable())
    # the walk, then each control symbol after data sent in each disparity sign (blanking
    # restarts the disparity: the next data word is the one of cnt = 0)
    symbols = [(0, 0), *walk]
    for c in CONTROL_SYMBOLS:
        symbols += [0x00, 0x00, c, 0x10, 0xFF, 0xFF, c, 0x10]
    got, want = encode_rtl(symbols), encode_standard(symbols)
    assert got == want, _mismatch(symbols, got, want)


def _drift_sequence(n, sign):
    """Data that pushes the running disparity to ``sign`` x its bound and keeps it there:
    each step the value whose flow-chart word moves cnt furthest that way (ties: the
    smallest value)."""
    seq, cnt = [], 0
    for _ in range(n):
        d = max(range(256), key=lambda x: (sign * STEP[cnt, x][1], -x))
        seq.append(d)
        cnt = STEP[cnt, d][1]
    return seq


def test_running_disparity_stays_within_the_bound_on_random_and_adversarial_data():
    rng = np.random.default_rng(7)
    sequences = [
        [int(x) for x in rng.integers(0, 256, 2000)],
        _drift_sequence(400, +1),
        _drift_sequence(400, -1),
        [0x00] * 300, [0xFF] * 300, [0x10, 0xEF] * 150,     # one value held, a value and its complement
        [int(x) for x in rng.choice([0x00, 0x01, 0x03, 0x07, 0xFF, 0xFE, 0xFC], 1000)],
    ]
    symbols = [s for seq in sequences for s in ((0, 0), *seq)]      # one run, blanking between
    words = encode_rtl(symbols)
    assert words == encode_standard(symbols), _mismatch(symbols, words, encode_standard(symbols))
    run = disparities(words, symbols)
    assert max(abs(r) for r in run) <= BOUND, f"running disparity {max(run, key=abs)}"
    # the drift sequences do reach the bound: the check above is at its edge
    assert max(disparities(encode_standard(_drift_sequence(50, +1)), _drift_sequence(50, +1))) == BOUND
