"""SdramController (rtl/sdram.py) in the Amaranth simulator on the datasheet model
(sim/sdram_model.py, which raises on any illegal command or timing violation): reads
return what was written (with WSTRB masks), overlapping reads stream a word a cycle on
open rows; the configuration's conversion of the datasheet table and its refusals; the
model catches a controller built with a timing one cycle short."""

import random
from dataclasses import replace
from fractions import Fraction

import pytest
from hypothesis import given
from hypothesis import strategies as st

from bumprtl.rtl.config import BumpError
from bumprtl.rtl.sdram import CHIPS, SdramConfig, ns_to_cycles
from bumprtl.sim.sdram_bench import bandwidth, run, short_config
from bumprtl.sim.sdram_model import SdramViolation

FAST = SdramConfig(powerup_cycles=20, init_refreshes=2)


@given(ns=st.integers(1, 100_000).map(lambda k: k / 4),
       mhz=st.integers(1, 143))
def test_cycles_cover_the_time_and_no_more(ns, mhz):
    """ceil(ns * f): the cycles last at least ``ns``, one fewer would not."""
    c = ns_to_cycles(ns, mhz)
    period = Fraction(1000, mhz)
    assert c * period >= Fraction(str(ns)) > (c - 1) * period


@pytest.mark.parametrize("variant", CHIPS)
def test_every_timing_converts_from_the_table(variant):
    cfg = SdramConfig(variant, 133, 3)
    chip = cfg.chip
    for name, cycles in cfg.cycles.items():
        if name in ("refi", "powerup"):
            continue
        assert cycles == max(1, ns_to_cycles(getattr(chip, f"t_{name}"), 133)), name
    # the refresh interval is never rounded up: the deadline is tREFI or sooner
    assert cfg.cycles["refi"] * Fraction(1000, 133) <= Fraction(str(chip.t_refi))


@pytest.mark.parametrize("field,value,allowed", [
    ("variant", "16mb", "one of 32mb, 64mb"),
    ("cas_latency", 1, "2 or 3"),
    ("freq_mhz", 101, "[1, 100]"),          # tCK at CL 2 is 10 ns
    ("freq_mhz", 0.5, "[1, 100]"),
    ("burst", 3, "power of two in [1, 8]"),
    ("burst", 16, "power of two in [1, 8]"),
    ("data_bits", 16, "32 or 64"),
    ("addr_bits", 24, "[25, 64]"),         # the 32 MB chip has 25 byte-address bits
    ("read_fifo", 12, "power of two"),
    ("init_refreshes", 1, "[2, 16]"),
    ("init_refreshes", 17, "[2, 16]"),
    ("powerup_cycles", 0, "[1,"),
    ("powerup_cycles", (1 << 20) + 1, "[1, 1048576]"),
    ("pin_cycles", 5, "[0, 4]"),
    ("pin_cycles", -1, "[0, 4]"),
    ("pin_cycles", True, "[0, 4]"),
    ("addr_bits", 65, "[25, 64]"),
    ("read_fifo", 512, "256]"),
    ("cas_latency", 4, "2 or 3"),
])
def test_bad_parameters_are_refused_in_one_line(field, value, allowed):
    with pytest.raises(BumpError) as e:
        SdramConfig(**{field: value})
    msg = str(e.value)
    assert e.value.field == field and "\n" not in msg
    assert msg.startswith(field) and allowed in msg, msg


@pytest.mark.parametrize("field,value", [("init_refreshes", 2), ("init_refreshes", 16),
                                         ("powerup_cycles", 1), ("powerup_cycles", 1 << 20),
                                         ("pin_cycles", 0), ("pin_cycles", 4),
                                         ("addr_bits", 25), ("addr_bits", 64),
                                         ("read_fifo", 256), ("burst", 1), ("burst", 8),
                                         ("freq_mhz", 100)])
def test_each_range_end_is_accepted(field, value):
    assert getattr(SdramConfig(**{field: value}), field) == value


def test_cas_latency_3_allows_a_faster_clock():
    assert SdramConfig(freq_mhz=142, cas_latency=3).cycles["rcd"] == 3
    with pytest.raises(BumpError, match="freq_mhz"):
        SdramConfig(freq_mhz=143, cas_latency=3)         # 1000 / 7 = 142.86


def _strobes(rng, beats, nbytes, masked):
    full = (1 << nbytes) - 1
    return [rng.randrange(1 << nbytes) if masked else full for _ in range(beats)]


@pytest.mark.parametrize("cfg", [FAST, replace(FAST, variant="64mb", freq_mhz=133,
                                               cas_latency=3, burst=4, data_bits=64),
                                 replace(FAST, burst=2, data_bits=64)],
                         ids=["32mb_cl2_bl8_32bit", "64mb_cl3_bl4_64bit",
                              "32mb_cl2_bl2_64bit_writes_back_to_back"])
def test_random_traffic_reads_what_was_written(cfg):
    rng = random.Random(3)
    nbytes, unit = cfg.data_bits // 8, 2 * cfg.burst
    step = max(nbytes, unit)
    memory, ops, expect = {}, [], []
    row = cfg.chip.cols * 2
    for k in range(40):
        bank, r = rng.randrange(4), rng.randrange(3)
        length = step * rng.randint(1, 4)
        addr = (r * 4 + bank) * row + rng.randrange(0, row - length + 1, step)
        if k % 2 == 0:
            data = rng.randbytes(length)
            strobes = _strobes(rng, length // nbytes, nbytes, masked=k % 4 == 0)
            ops.append(("w", addr, data, strobes))
            for i, b in enumerate(data):
                if strobes[i // nbytes] >> (i % nbytes) & 1:
                    memory[addr + i] = b
        else:
            ops.append(("r", addr, length))
            expect.append(bytes(memory.get(addr + i, 0) for i in range(length)))
    reads, _beats, model = run(cfg, ops, r_stall=0.3, seed=1)
    assert reads == expect
    assert {"ACT", "PRE", "READ", "WRITE", "REF"} <= set(model.commands)


def test_open_row_reads_stream_a_word_a_cycle():
    """Lines of one open row, ARs back to back: one 16-bit word a cycle (8 cycles per 16
    bytes, the bus's limit) but for the first ACTIVE's wait; a new row per line costs more."""
    got = bandwidth(FAST)
    assert 8 <= got["hit"] < 8.1
    assert got["miss"] > got["hit"] + 1


@pytest.mark.parametrize("timing", ["rcd", "rp"])
def test_the_model_catches_a_timing_one_cycle_short(timing):
    """The controller built with one datasheet timing a cycle short: the model raises on
    the first command that comes too soon. (tRAS and tWR never bind on this traffic, the
    next transaction's turnaround hides them, tRC is tRAS + tRP: the formal contract
    catches those,
    tests/sim/formal/test_sdram_formal.py.)"""
    rng = random.Random(5)
    cfg = replace(FAST, burst=1)    # single-word bursts: the row timings are on the path
    row = cfg.chip.cols * 2 * 4     # the next row of the same bank
    ops = []
    for _ in range(4):              # every access a row miss
        ops += [("w", 0, rng.randbytes(4), [0xF]), ("w", row, rng.randbytes(4), [0xF]),
                ("r", 0, 4), ("r", row, 4)]
    run(cfg, ops)                   # the true controller passes
    with pytest.raises(SdramViolation, match=f"t{timing.upper()}"):
        run(short_config(cfg, timing), ops)
