"""The SDRAM cycle model (sim/sdram_model.py) driven command by command, without the
controller: a legal initialisation, a WRITE with its byte masks read back after the CAS
latency, and each rule of the datasheet it promises to enforce broken once, the violation
naming the rule (the controller's traffic never breaks them: tests/rtl/test_sdram.py)."""

import math

import pytest

from bumprtl.sim.sdram_model import TRUTH, SdramModel, SdramViolation

PINS = {name: pins for pins, name in TRUTH.items()}
A10 = 1 << 10


class Chip:
    """A model at 25 MHz (40 ns a cycle), the power-up wait skipped, and commands by name."""

    def __init__(self, cl=2, bl_code=1, freq_mhz=25, refreshes=2):
        self.m = SdramModel("32mb", freq_mhz, powerup_ns=0, init_refreshes=refreshes, log=True)
        self.cl, self.bl_code = cl, bl_code

    def cmd(self, name="NOP", ba=0, a=0, dq=0, oe=0, dqm=0, cke=1):
        cs, ras, cas, we = PINS[name] if name != "DESELECT" else (1, 1, 1, 1)
        return self.m.cycle(cs, ras, cas, we, ba, a, dqm, dq, oe, cke)

    def nop(self, n=1):
        return [self.cmd() for _ in range(n)]

    def init(self):
        self.cmd("PRE", a=A10)
        self.nop(math.ceil(21 / self.m.tck))             # tRP 21 ns
        for _ in range(2):
            self.cmd("REF")
            self.nop(math.ceil(70 / self.m.tck))         # tRFC 70 ns
        self.cmd("MRS", a=self.cl << 4 | self.bl_code)
        self.nop()
        return self


def _violates(fn, words):
    with pytest.raises(SdramViolation) as e:
        fn()
    msg = str(e.value)
    assert msg.startswith("cycle "), msg
    for w in words if isinstance(words, (list, tuple)) else [words]:
        assert w in msg, msg


def test_a_write_with_byte_masks_reads_back_after_the_cas_latency():
    c = Chip(cl=2, bl_code=1).init()                     # bursts of 2
    assert (c.m.state, c.m.cl, c.m.bl) == ("ready", 2, 2)
    c.cmd("ACT", ba=1, a=77)
    c.cmd("WRITE", ba=1, a=5, dq=0x1234, oe=1)           # columns 5, then 4 (wrap in the pair)
    c.cmd(dq=0xABCD, oe=1, dqm=0b10)                     # high byte masked
    c.nop(2)                                             # tWR 20 ns
    c.cmd("WRITE", ba=1, a=4, dq=0xFFFF, oe=1, dqm=0b11)  # both bytes masked: kept
    c.cmd(dq=0x5A5A, oe=1, dqm=0b01)                     # low byte masked
    c.nop(2)
    assert c.cmd("READ", ba=1, a=4) == (False, 0)        # each call: DQ in the next cycle
    assert c.cmd() == (True, 0x00CD)                     # column 4, CL = 2 cycles after READ
    assert c.cmd() == (True, 0x5A34)                     # column 5
    assert c.cmd() == (False, 0)
    assert [e[1] for e in c.m.log[:5]] == ["PRE", "REF", "REF", "MRS", "ACT"]


def test_cas_latency_3_answers_one_cycle_later():
    c = Chip(cl=3, bl_code=0).init()
    c.cmd("ACT", a=1)
    c.cmd("WRITE", a=9, dq=0xBEEF, oe=1)
    c.nop(2)
    assert c.cmd("READ", a=9) == (False, 0)
    assert [c.cmd() for _ in range(3)] == [(False, 0), (True, 0xBEEF), (False, 0)]


def test_power_up_and_initialisation_order():
    _violates(lambda: Chip().cmd("ACT"), "ACT before the power-up PRECHARGE ALL")
    _violates(lambda: Chip().cmd("PRE"), "PRE before the power-up PRECHARGE ALL")
    slow = SdramModel("32mb", 25)                        # the datasheet's 200 us power-up
    _violates(lambda: slow.cycle(0, 0, 1, 0, 0, A10, 0, 0, 0), "tPOWERUP")
    c = Chip()
    c.cmd("PRE", a=A10)
    c.nop()
    _violates(lambda: c.cmd("ACT"), "ACT before initialisation")
    c = Chip()
    c.cmd("PRE", a=A10)
    c.nop()
    c.cmd("REF")
    c.nop(2)
    _violates(lambda: c.cmd("MRS", a=0x21), "MODE REGISTER SET after 1 AUTO REFRESH, 2 required")


@pytest.mark.parametrize("mode, words", [
    (0x24, "only BL 1-8"),                               # BL code 4
    (0x29, "only BL 1-8"),                               # interleaved
    (0x221, "only BL 1-8"),                              # single-word writes
    (0x11, "CAS latency 1"),
])
def test_the_mode_register_takes_only_what_the_controller_sets(mode, words):
    c = Chip()
    c.cmd("PRE", a=A10)
    c.nop()
    for _ in range(2):
        c.cmd("REF")
        c.nop(2)
    _violates(lambda: c.cmd("MRS", a=mode), words)


def test_the_clock_may_not_be_faster_than_tck_at_the_latency():
    c = Chip(cl=2, freq_mhz=125)                         # 8 ns < 10 ns at CL 2
    with pytest.raises(SdramViolation, match="clock period 8 ns < tCK 10 ns at CL 2"):
        c.m.ns.update(RP=0, RFC=0)                       # the refreshes' spacing not at issue
        c.init()


def test_row_rules():
    c = Chip().init()
    _violates(lambda: c.cmd("READ", ba=2, a=0), "READ to bank 2 with no open row")
    _violates(lambda: Chip().init().cmd("ACT", a=8192), "ACTIVE row 8192 beyond the chip's 8192 rows")
    c = Chip().init()
    c.cmd("ACT", ba=3, a=1)
    _violates(lambda: c.cmd("ACT", ba=3, a=2), "ACTIVE to bank 3 with row 1 open")
    c = Chip().init()
    c.cmd("ACT", ba=0, a=1)
    _violates(lambda: c.cmd("READ", a=A10 | 3), "READ with auto precharge (A10)")
    c = Chip().init()
    c.cmd("ACT", ba=0, a=1)
    _violates(lambda: c.cmd("PRE", ba=0), "tRAS")                  # 40 ns < 42 ns
    c = Chip().init()
    c.cmd("ACT", ba=0, a=1)
    c.cmd("ACT", ba=1, a=1)                              # another bank: tRRD 14 ns < 40 ns
    assert c.m.row[:2] == [1, 1]
    c = Chip().init()
    c.cmd("ACT", ba=0, a=1)
    c.nop()
    _violates(lambda: c.cmd("REF"), "AUTO REFRESH with bank 0 open")
    c = Chip().init()
    c.cmd("ACT", ba=0, a=1)
    c.nop()
    _violates(lambda: c.cmd("MRS", a=0x21), "MODE REGISTER SET with a bank open")


def test_burst_and_data_bus_rules():
    c = Chip(bl_code=2).init()                           # bursts of 4
    c.cmd("ACT", a=1)
    c.cmd("READ", a=0)
    _violates(lambda: c.cmd("READ", a=4), "READ interrupts the burst under way (until cycle")
    c = Chip(bl_code=2).init()
    c.cmd("ACT", a=1)
    c.cmd("READ", a=0)
    c.nop(2)                                             # the burst's last cycle is next
    _violates(lambda: c.cmd("PRE"), "PRECHARGE bank 0 truncates a READ burst")
    c = Chip(bl_code=2).init()
    c.cmd("ACT", a=1)
    c.cmd("READ", a=0)
    c.nop()
    _violates(lambda: c.cmd(dq=1, oe=1), "DQ driven by the controller while the chip drives")
    c = Chip(bl_code=1).init()
    c.cmd("ACT", a=1)
    c.cmd("WRITE", a=0, dq=1, oe=1)
    _violates(lambda: c.cmd(oe=0), "write data not driven during a WRITE burst")
    c = Chip(bl_code=1, freq_mhz=100).init()             # 10 ns a cycle
    c.cmd("ACT", a=1)
    c.nop(2)                                             # tRCD 21 ns
    c.cmd("WRITE", a=0, dq=1, oe=1)
    c.cmd(dq=1, oe=1)
    _violates(lambda: c.cmd("PRE"), "PRECHARGE bank 0 after write data: 10 ns < tWR = 20 ns")
    c = Chip(bl_code=0, cl=3).init()
    c.cmd("ACT", a=1)
    c.cmd("READ", a=0)
    c.nop(2)
    _violates(lambda: c.cmd("WRITE", a=1), "WRITE data would meet READ data on DQ")
    c = Chip(bl_code=2, cl=2).init()
    c.cmd("ACT", a=1)
    c.cmd("WRITE", a=0, dq=1, oe=1)
    for _ in range(3):
        c.cmd(dq=1, oe=1)
    c.cmd("READ", a=0)                                   # data in 2 cycles: no clash
    c = Chip(bl_code=0, cl=3).init()
    c.cmd("ACT", a=1)
    c.m.busy_until = -1
    c.m.writes[c.m.n + 3] = (0, 1, 5)                    # a write word due when the data comes
    _violates(lambda: c.cmd("READ", a=0), "READ data would meet WRITE data on DQ")
    c = Chip(bl_code=2).init()
    c.cmd("ACT", a=1)
    c.m.ns["RAS"] = c.m.ns["WR"] = 0
    c.cmd("WRITE", a=0, dq=1, oe=1)
    _violates(lambda: c.cmd("PRE", dq=1, oe=1), "PRECHARGE bank 0 during its WRITE burst")


def test_other_pins_and_commands_refused():
    _violates(lambda: Chip().init().cmd(cke=0), "CKE low")
    _violates(lambda: Chip().init().cmd("BST"), "BURST TERMINATE is not expected")
    c = Chip().init()
    c.cmd("DESELECT")
    assert c.m.commands == {"PRE": 1, "REF": 2, "MRS": 1}


def test_refresh_timing():
    c = Chip()
    c.cmd("PRE", a=A10)
    c.nop()
    c.cmd("REF")
    _violates(lambda: c.cmd("REF"), "tRFC")                          # 40 ns < 70 ns
    c = Chip().init()
    refi = c.m.ns["REFI"]                                # 7812.5 ns: 195 cycles of 40 ns
    c.nop(int(refi // 40) - 6)
    _violates(lambda: c.nop(5), ["no AUTO REFRESH for", "tREFI = 7812.5 ns"])
    c = Chip().init()
    c.nop(150)
    c.cmd("REF")
    c.nop(150)                                           # a refresh in time resets the clock
    assert c.m.state == "ready"


@pytest.mark.parametrize("first", ["READ", "WRITE"])
@pytest.mark.parametrize("bl_code, beats", [(1, 2), (2, 4), (3, 8)])
def test_a_column_command_may_follow_a_burst_exactly_when_it_ends(first, bl_code, beats):
    """A READ or WRITE burst of BL beats holds the bus through its last beat: a column
    command in that cycle interrupts it, one in the next cycle (BL after the first) is
    legal."""
    def start():
        c = Chip(bl_code=bl_code, cl=2).init()
        c.cmd("ACT", a=1)
        c.cmd(first, a=0, dq=1, oe=int(first == "WRITE"))
        return c

    def data(c):
        return {"dq": 1, "oe": 1} if first == "WRITE" else {}
    c = start()
    for _ in range(beats - 2):
        c.cmd(**data(c))
    _violates(lambda: c.cmd(first, a=0, dq=1, oe=int(first == "WRITE")),
              f"{first} interrupts the burst under way (until cycle")
    c = start()
    for _ in range(beats - 1):
        c.cmd(**data(c))
    c.cmd(first, a=0, dq=1, oe=int(first == "WRITE"))      # the cycle after its last beat
