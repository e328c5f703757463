"""SdramController: the ULX3S's 16-bit SDR SDRAM behind an AXI4 subordinate port
(docs/sdram.md).

:class:`SdramConfig` is the one place the chip and the controller are described: the
chip's geometry and its datasheet timing in ns (:data:`CHIPS`, one entry per board
variant, selectable by name), the clock, the CAS latency and the burst length. Every
timing in cycles comes from :func:`ns_to_cycles` (``ceil(ns * f)``) through
:meth:`SdramConfig.cycles`; nothing else in the controller is a timing.

The controller is one command scheduler. Each cycle it decides at most one command
(:func:`decide`) from registers only (the bank table, the per-bank and global timers, the
transaction being served, the refresh counter) and registers it onto the pins with its
address and data, so the pins change on the clock edge. The decision itself (the row
comparison, the timers' zero tests, the refresh's, the read credit's) is made a cycle
ahead for a cycle without a command and registered (``go``): a command comes from
registers through one gate, and at least one cycle without a command follows each.
Priorities: the initialisation sequence; a refresh that is due (precharge every open bank,
then AUTO REFRESH); then the transaction taken from AR or AW (round robin), served in
bursts of ``burst`` words, each one READ or WRITE once its bank has its row open
(ACTIVATE when the bank is idle, PRECHARGE first when another row is open: an open-row
policy, rows stay open until a miss in that bank or a refresh).
"""

from dataclasses import dataclass
from fractions import Fraction
from math import ceil
from types import SimpleNamespace

from amaranth.hdl import Cat, Const, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.fifo import SyncFIFOBuffered
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.cache import axi_read_signature
from bumprtl.rtl.config import BumpError, is_pow2

__all__ = ["SdramChip", "CHIPS", "SdramConfig", "ns_to_cycles", "axi_write_signature",
           "sdram_signature", "SdramController", "CMD", "mode_register", "DECISIONS",
           "decide"]


@dataclass(frozen=True)
class SdramChip:
    """One SDR SDRAM part: geometry and datasheet minimums (ns unless named otherwise)."""
    part: str
    rows: int
    cols: int
    banks: int
    t_rcd: float          # ACTIVE -> READ/WRITE, same bank
    t_rp: float           # PRECHARGE -> ACTIVE/REFRESH, same bank
    t_ras: float          # ACTIVE -> PRECHARGE, same bank
    t_rc: float           # ACTIVE -> ACTIVE, same bank (and REFRESH -> REFRESH)
    t_rfc: float          # AUTO REFRESH -> any command
    t_rrd: float          # ACTIVE -> ACTIVE, different banks
    t_wr: float           # last write data in -> PRECHARGE
    t_mrd: float          # MODE REGISTER SET -> any command
    t_refi: float         # average refresh interval: 64 ms / 8192 rows
    t_powerup: float      # power-up wait with NOPs before the first PRECHARGE
    tck_min: tuple        # least clock period (ns) at CAS latency 2 and at 3
    init_refreshes: int   # AUTO REFRESH commands at initialisation

    @property
    def row_bits(self):
        return (self.rows - 1).bit_length()

    @property
    def col_bits(self):
        return (self.cols - 1).bit_length()

    @property
    def bank_bits(self):
        return (self.banks - 1).bit_length()

    @property
    def bytes(self):
        return self.rows * self.cols * self.banks * 2


# The ULX3S's SDRAM. Each number is the larger of two sources for parts of that
# organisation, -7 speed grade (143 MHz at CL 3, 100 MHz at CL 2):
#  [A] Alliance Memory AS4C16M16SA-C&I, Rev. 3.0 (Mar. 2015), Table 16 (A.C. operating
#      conditions), -7 column; 256 Mb, 4 banks x 8192 rows x 512 columns x 16 bits, the
#      organisation of the IS42S16160G on 32 MB boards.
#  [B] Alliance Memory AS4C32M16SB, Table 16, -7 column; 512 Mb, 4 banks x 8192 rows x
#      1024 columns x 16 bits (the 64 MB boards' part).
#  [L] LiteDRAM litedram/modules.py, IS42S16160 and IS42S16320 (tRP = tRCD = tWR = 20,
#      tRFC = 70, tREFI = 64 ms / 8192).
#  [J] the JEDEC SDR power-up rule the ISSI and Alliance sheets share: 200 us of NOPs,
#      PRECHARGE ALL, >= 2 AUTO REFRESH (8 here: some sheets ask for 8), MODE REGISTER SET.
CHIPS = {
    "32mb": SdramChip(
        part="IS42S16160G-7 (32 MB)", rows=8192, cols=512, banks=4,
        t_rcd=21.0,       # [A] 21 ([L] 20)
        t_rp=21.0,        # [A] 21 ([L] 20)
        t_ras=42.0,       # [A] 42 (max 120 us: a refresh closes every row long before)
        t_rc=63.0,        # [A] 63
        t_rfc=70.0,       # [L] 70 ([A] 63)
        t_rrd=14.0,       # [A] 14
        t_wr=20.0,        # [L] 20 ([A] 14)
        t_mrd=14.0,       # [A] 14
        t_refi=7812.5,    # [A] 7.8 us, [L] 64 ms / 8192
        t_powerup=200_000.0,   # [J] 200 us
        tck_min=(10.0, 7.0),   # [A] tCK at CL 2: 10 ns, at CL 3: 7 ns
        init_refreshes=8),     # [J]
    "64mb": SdramChip(
        part="AS4C32M16SB-7 (64 MB)", rows=8192, cols=1024, banks=4,
        t_rcd=21.0,       # [B] 21 ([L] 20)
        t_rp=21.0,        # [B] 21 ([L] 20)
        t_ras=42.0,       # [B] 42
        t_rc=63.0,        # [B] 63
        t_rfc=70.0,       # [L] 70 ([B] 63)
        t_rrd=14.0,       # [B] 14
        t_wr=20.0,        # [L] 20 ([B] 14)
        t_mrd=14.0,       # [B] 14
        t_refi=7812.5,    # [B] 7.8 us, [L] 64 ms / 8192
        t_powerup=200_000.0,   # [J]
        tck_min=(10.0, 7.0),   # [B]
        init_refreshes=8),     # [J]
}

# Command truth table (CS#, RAS#, CAS#, WE#), from the datasheets' command table.
CMD = {"nop": 0b0111, "active": 0b0011, "read": 0b0101, "write": 0b0100,
       "precharge": 0b0010, "refresh": 0b0001, "mode": 0b0000}
DQ_BITS = 16
ADDR_PINS = 13                       # A0..A12 on the ULX3S
DATA_BITS = (32, 64)


def ns_to_cycles(ns, freq_mhz):
    """Least whole cycles at ``freq_mhz`` covering ``ns``: ceil(ns * f), exactly."""
    return ceil(Fraction(str(ns)) * Fraction(str(freq_mhz)) / 1000)


def mode_register(burst, cas_latency):
    """The mode register word: burst length (A2:A0 = log2), sequential (A3 = 0), CAS
    latency (A6:A4), standard operation (A8:A7 = 0), programmed burst writes (A9 = 0)."""
    return (burst.bit_length() - 1) | (cas_latency << 4)


@dataclass(frozen=True)
class SdramConfig:
    """The SDRAM, the clock and the controller's sizes.

    Parameters
    ----------
    variant : str
        A key of :data:`CHIPS` ("32mb", "64mb").
    freq_mhz : float
        The controller's (and the SDRAM's) clock; at most 1000 / tCK_min at the CAS latency.
    cas_latency : int
        2 or 3 (written to the mode register; the read data path waits as long).
    burst : int
        Words (16 bits) a READ or WRITE moves: the mode register's burst length, 1, 2, 4 or
        8. An AXI burst must be a whole number of these, aligned to ``2 * burst`` bytes.
    data_bits : int
        AXI data width, 32 or 64 (the cache's).
    addr_bits : int
        AXI address width; addresses wrap modulo the chip's size.
    read_fifo : int
        AXI beats of read data buffered (a power of two): READs are issued only while the
        data they return has room, so RREADY may stall without losing data.
    powerup_cycles : int or None
        For simulations and proofs only: replaces the datasheet's power-up wait.
    init_refreshes : int or None
        AUTO REFRESH commands at initialisation (None: the chip's; at least 2).
    pin_cycles : int
        Clock cycles the board's I/O registers add to a READ's round trip, 0 .. 4: 0 where
        the controller's ``sdram`` port is the chip's pins (simulation); the ULX3S top
        registers the commands once more in the I/O cells and captures DQ half a cycle
        late, then re-registers it: 2 (rtl/board.SDRAM_PIN_CYCLES, docs/sdram.md).
    """

    variant: str = "32mb"
    freq_mhz: float = 100.0
    cas_latency: int = 2
    burst: int = 8
    data_bits: int = 32
    addr_bits: int = 32
    read_fifo: int = 16
    powerup_cycles: int | None = None
    init_refreshes: int | None = None
    pin_cycles: int = 0

    def __post_init__(self):
        if self.variant not in CHIPS:
            raise BumpError(f"variant must be one of {', '.join(CHIPS)}, got {self.variant!r}",
                            "variant")
        if self.cas_latency not in (2, 3):
            raise BumpError(f"cas_latency must be 2 or 3, got {self.cas_latency!r}", "cas_latency")
        fmax = Fraction(1000) / Fraction(str(self.chip.tck_min[self.cas_latency - 2]))
        if not isinstance(self.freq_mhz, (int, float)) or isinstance(self.freq_mhz, bool) \
                or not 1 <= Fraction(str(self.freq_mhz)) <= fmax:
            raise BumpError(f"freq_mhz must be in [1, {float(fmax):g}] for cas_latency "
                            f"{self.cas_latency} ({self.chip.part}), got {self.freq_mhz!r}",
                            "freq_mhz")
        if not is_pow2(self.burst) or self.burst > 8:
            raise BumpError(f"burst must be a power of two in [1, 8], got {self.burst!r}", "burst")
        if self.data_bits not in DATA_BITS:
            raise BumpError(f"data_bits must be 32 or 64, got {self.data_bits!r}",
                            "data_bits")
        need = self.chip_addr_bits
        if not isinstance(self.addr_bits, int) or not need <= self.addr_bits <= 64:
            raise BumpError(f"addr_bits must be an integer in [{need}, 64], got "
                            f"{self.addr_bits!r}", "addr_bits")
        least = max(2, 2 * self.burst_beats)
        if not is_pow2(self.read_fifo) or not least <= self.read_fifo <= 256:
            raise BumpError(f"read_fifo must be a power of two in [{least}, 256], got "
                            f"{self.read_fifo!r}", "read_fifo")
        if self.powerup_cycles is not None and (
                not isinstance(self.powerup_cycles, int) or not 1 <= self.powerup_cycles <= 1 << 20):
            raise BumpError(f"powerup_cycles must be None or an integer in [1, {1 << 20}], got "
                            f"{self.powerup_cycles!r}", "powerup_cycles")
        if self.init_refreshes is not None and (
                not isinstance(self.init_refreshes, int) or not 2 <= self.init_refreshes <= 16):
            raise BumpError(f"init_refreshes must be None or an integer in [2, 16], got "
                            f"{self.init_refreshes!r}", "init_refreshes")
        if isinstance(self.pin_cycles, bool) or not isinstance(self.pin_cycles, int) \
                or not 0 <= self.pin_cycles <= 4:
            raise BumpError(f"pin_cycles must be an integer in [0, 4], got {self.pin_cycles!r}",
                            "pin_cycles")
        if self.refresh_reload < 1:
            raise BumpError(f"freq_mhz must be in [1, {float(fmax):g}]: at {self.freq_mhz} MHz "
                            f"a refresh cannot be scheduled within tREFI", "freq_mhz")

    @property
    def chip(self):
        return CHIPS[self.variant]

    @property
    def chip_addr_bits(self):
        """Byte address bits of the chip."""
        return (self.chip.bytes - 1).bit_length()

    @property
    def words_per_beat(self):
        return self.data_bits // DQ_BITS

    @property
    def burst_beats(self):
        """AXI beats one SDRAM burst fills (at least 1)."""
        return max(1, self.burst // self.words_per_beat)

    @property
    def cycles(self):
        """Every datasheet timing in cycles at ``freq_mhz`` (:func:`ns_to_cycles`), at least 1."""
        c, f = self.chip, self.freq_mhz
        out = {name: max(1, ns_to_cycles(getattr(c, f"t_{name}"), f))
               for name in ("rcd", "rp", "ras", "rc", "rfc", "rrd", "wr", "mrd")}
        out["refi"] = int(Fraction(str(c.t_refi)) * Fraction(str(f)) / 1000)    # floor: never late
        out["powerup"] = (self.powerup_cycles if self.powerup_cycles is not None
                          else ns_to_cycles(c.t_powerup, f))
        return out

    @property
    def refreshes(self):
        return self.init_refreshes if self.init_refreshes is not None else self.chip.init_refreshes

    @property
    def pre_wait(self):
        """Most cycles a bank may have to stay open: tRAS, a write's data and tWR, a READ's
        burst."""
        t, bl = self.cycles, self.burst
        return max(t["ras"], bl - 1 + t["wr"], bl)

    @property
    def act_wait(self):
        """Most cycles an idle bank may have to wait for ACTIVE or AUTO REFRESH."""
        t = self.cycles
        return max(t["rp"], t["rc"], t["rfc"], t["mrd"])

    @property
    def refresh_slack(self):
        """Most cycles from a refresh falling due to its AUTO REFRESH on the pins: every
        open bank's wait (:attr:`pre_wait`, or a command's tRFC/tMRD), PRECHARGE ALL, the
        idle banks' wait (:attr:`act_wait`), and the decision's register stage."""
        return max(self.pre_wait, self.act_wait) + self.act_wait + 3

    @property
    def refresh_reload(self):
        """Cycles from an AUTO REFRESH until the next falls due, so that consecutive ones are
        never more than tREFI apart."""
        return self.cycles["refi"] - self.refresh_slack

    @property
    def timer_max(self):
        t, bl = self.cycles, self.burst
        return max(t["rcd"], t["rp"], t["ras"], t["rc"], t["rfc"], t["rrd"], t["mrd"],
                   bl - 1 + t["wr"], self.cas_latency + bl + 1)


def axi_write_signature(addr_bits, data_bits):
    """An AXI4 write manager port (AW, W, B; the manager's view) with one ID."""
    return wiring.Signature({
        "awid": Out(1), "awaddr": Out(addr_bits), "awlen": Out(8), "awsize": Out(3),
        "awburst": Out(2), "awvalid": Out(1), "awready": In(1),
        "wdata": Out(data_bits), "wstrb": Out(data_bits // 8), "wlast": Out(1),
        "wvalid": Out(1), "wready": In(1),
        "bid": In(1), "bresp": In(2), "bvalid": In(1), "bready": Out(1)})


def sdram_signature(cfg: SdramConfig):
    """The SDRAM pins (the controller's view): commands, address, data out with its enable,
    data in (to be registered in the I/O cell)."""
    return wiring.Signature({
        "cke": Out(1), "cs_n": Out(1), "ras_n": Out(1), "cas_n": Out(1), "we_n": Out(1),
        "ba": Out(cfg.chip.bank_bits), "a": Out(ADDR_PINS), "dqm": Out(DQ_BITS // 8),
        "dq_o": Out(DQ_BITS), "dq_oe": Out(1), "dq_i": In(DQ_BITS)})


# The commands the scheduler decides, in priority order (at most one is true).
DECISIONS = ("pre_all", "ref", "mode", "read", "write", "pre", "act")
SERVED = ("read", "write", "pre", "act")           # the transaction's: they read cur_addr


def decide(cfg: SdramConfig, r, quiet=False, flow=True):
    """Which command the scheduler may issue (docs/sdram.md, The scheduler): a dict of
    DECISIONS to expressions over the controller's registers ``r``
    (:attr:`SdramController.regs`), true for at most one. With ``quiet`` the decision of the
    *next* cycle if this one issues no command and takes no transaction: a timer at 0 then
    is one at most 1 now, the refresh is due then if ``ref_cnt`` is at most 1 now, and
    the read credit and the write buffer only grow. The controller registers the quiet
    decision (``go``) and issues from it; the formal contract states it equals the decision
    of the registers themselves (``quiet=False``) whenever ``fresh``. Without ``flow`` READ
    and WRITE leave out the read credit and the write buffer's count (the data's gates, no
    timing's: what the contract checks the command stream's rules with)."""
    nb, bl = cfg.chip.banks, cfg.burst
    col_bits, bank_bits = cfg.chip.col_bits, cfg.chip.bank_bits

    def zero(timer):
        return (timer <= 1) if quiet else (timer == 0)

    cur_bank = r.cur_addr[col_bits:col_bits + bank_bits]
    cur_row = r.cur_addr[col_bits + bank_bits:]
    bank_is = Const(1, nb) << cur_bank              # one-hot by a shift: lint-clean Verilog
    hit = Cat(*[r.open[b] & (r.rows[b] == cur_row) for b in range(nb)])
    ref_due = (r.ref_cnt <= 1) if quiet else r.ref_due
    idle = zero(r.cmd_t)
    all_act = Cat(*[zero(t) for t in r.act_t]).all()
    all_pre = Cat(*[~r.open[b] | zero(r.pre_t[b]) for b in range(nb)]).all()
    bank_hit = (hit & bank_is).any()                # and-or selects: no case statements
    bank_open = (r.open & bank_is).any()

    def bank_ready(timers):
        return (Cat(*[zero(t) for t in timers]) & bank_is).any()

    col_ready = idle & bank_ready(r.rcd_t) & Mux(
        r.cur_write, zero(r.wr_t) & ((r.wcount >= bl) if flow else 1),
        zero(r.rd_t) & ((r.credit >= bl) if flow else 1))
    init_go = ~r.run & idle & all_act
    served = r.run & ~ref_due & r.cur_valid
    return {
        "pre_all": (init_go & r.init_pre & ref_due)
        | (r.run & ref_due & r.open.any() & idle & all_pre),
        "ref": (init_go & ~r.init_pre & r.init_refs.any())
        | (r.run & ref_due & ~r.open.any() & idle & all_act),
        "mode": init_go & ~r.init_pre & ~r.init_refs.any(),
        "read": served & bank_hit & col_ready & ~r.cur_write,
        "write": served & bank_hit & col_ready & r.cur_write,
        "pre": served & ~bank_hit & bank_open & idle & bank_ready(r.pre_t),
        "act": served & ~bank_open & idle & bank_ready(r.act_t) & zero(r.rrd_t)}


class SdramController(wiring.Component):
    """AXI4 reads and writes served from an SDR SDRAM.

    Parameters
    ----------
    cfg : SdramConfig

    Members
    -------
    rd : In(axi_read_signature(addr_bits, data_bits))
        Read bursts, connectable to :class:`~bumprtl.rtl.cache.TextureCache`'s ``axi``:
        INCR, ARSIZE the bus width (ARSIZE, ARBURST and ARID are not read), a whole number
        of SDRAM bursts aligned to ``2 * burst`` bytes; R beats in AR order, RID 0, RRESP
        OKAY, RLAST on each burst's last beat.
    wr : In(axi_write_signature(addr_bits, data_bits))
        Write bursts on the same terms; WSTRB becomes DQM; one B response (BID 0, OKAY) per
        burst once its last WRITE is issued; one write burst at a time.
    sdram : Out(sdram_signature(cfg))
        Every output is a register (CKE is tied high). A READ on the pins in cycle n returns its first word
        on ``dq_i`` in cycle n + CL + ``pin_cycles`` (sampled by the chip's clock edges),
        which the controller registers once.

    One command every other cycle at most; a burst's READs (WRITEs) follow each other every
    ``max(burst, 2)`` cycles while its row is open and the read FIFO has room (the write buffer
    holds the burst's data). Initialisation, timers and refresh: docs/sdram.md.
    """

    def __init__(self, cfg: SdramConfig):
        self.cfg = cfg
        nb, tw, t = cfg.chip.banks, cfg.timer_max.bit_length(), cfg.cycles
        # The scheduler's registers, here so that the formal contract (sim/formal/sdram.py)
        # can state its lemmas about them.
        self.regs = SimpleNamespace(
            cmd=Signal(4, init=CMD["nop"], name="cmd"),
            open=Signal(nb, name="open"),
            act_t=[Signal(tw, name=f"act_t{b}") for b in range(nb)],   # ACT/REF allowed at 0
            rcd_t=[Signal(tw, name=f"rcd_t{b}") for b in range(nb)],   # READ/WRITE allowed at 0
            pre_t=[Signal(tw, name=f"pre_t{b}") for b in range(nb)],   # PRECHARGE allowed at 0
            rrd_t=Signal(tw, name="rrd_t"), rd_t=Signal(tw, name="rd_t"),
            wr_t=Signal(tw, name="wr_t"), cmd_t=Signal(tw, name="cmd_t"),
            ref_cnt=Signal(range(max(t["powerup"], cfg.refresh_reload) + 1),
                           init=t["powerup"], name="ref_cnt"),
            ref_due=Signal(name="ref_due"),             # ref_cnt == 0, as a register
            init_pre=Signal(init=1, name="init_pre"),
            init_refs=Signal(range(cfg.refreshes + 1), init=cfg.refreshes, name="init_refs"),
            run=Signal(name="run"),
            rows=[Signal(cfg.chip.row_bits, name=f"row{b}") for b in range(nb)],
            cur_valid=Signal(name="cur_valid"), cur_write=Signal(name="cur_write"),
            # the word address of the transaction's next SDRAM burst
            cur_addr=Signal(cfg.chip.col_bits + cfg.chip.bank_bits + cfg.chip.row_bits,
                            name="cur_addr"),
            # words the read FIFO can still take; words in the write buffer
            credit=Signal(range(cfg.read_fifo * cfg.words_per_beat + 1),
                          init=cfg.read_fifo * cfg.words_per_beat, name="credit"),
            wcount=Signal(range(max(cfg.burst, cfg.words_per_beat) + 1), name="wcount"),
            # the decision, a cycle ahead: go[k] is decide(regs, quiet=True)[k] of the
            # cycle before; fresh: that cycle issued no command, took: it took a
            # transaction; so go[k] is decide(regs)[k] of this one while fresh (and not
            # took, for the transaction's commands; READ and WRITE: or more cautious)
            go={k: Signal(name=f"go_{k}") for k in DECISIONS},
            fresh=Signal(name="fresh"), took=Signal(name="took"))
        super().__init__({"rd": In(axi_read_signature(cfg.addr_bits, cfg.data_bits)),
                          "wr": In(axi_write_signature(cfg.addr_bits, cfg.data_bits)),
                          "sdram": Out(sdram_signature(cfg))})

    def elaborate(self, platform):
        m = Module()
        cfg, chip, t = self.cfg, self.cfg.chip, self.cfg.cycles
        bl, wpb, nb = cfg.burst, cfg.words_per_beat, chip.banks
        pins, rd, wr = self.sdram, self.rd, self.wr
        r = self.regs
        col_bits, bank_bits, row_bits = chip.col_bits, chip.bank_bits, chip.row_bits
        word_bits = col_bits + bank_bits + row_bits

        def count_down(sig):
            m.d.sync += sig.eq(Mux(sig.any(), sig - 1, 0))

        def at_least(sig, cycles):
            """``sig`` becomes max(sig - 1, cycles - 1): the next command it gates may be
            decided ``cycles`` cycles after this one at the earliest."""
            v = max(0, cycles - 1)
            m.d.sync += sig.eq(Mux(sig > v + 1, sig - 1, v))

        # --- registered pins ---
        cmd = r.cmd
        m.d.comb += [pins.cs_n.eq(cmd[3]), pins.ras_n.eq(cmd[2]), pins.cas_n.eq(cmd[1]),
                     pins.we_n.eq(cmd[0])]
        m.d.comb += pins.cke.eq(1)                  # no power-down, no self refresh
        nxt_cmd = Signal(4)
        nxt_ba, nxt_a = Signal(bank_bits), Signal(ADDR_PINS)
        m.d.sync += [cmd.eq(nxt_cmd), pins.ba.eq(nxt_ba), pins.a.eq(nxt_a)]

        # --- bank table and timers ---
        open_ = r.open
        rows = r.rows
        act_t, rcd_t, pre_t = r.act_t, r.rcd_t, r.pre_t
        rrd_t, rd_t, wr_t, cmd_t = r.rrd_t, r.rd_t, r.wr_t, r.cmd_t
        timers = [*act_t, *rcd_t, *pre_t, rrd_t, rd_t, wr_t, cmd_t]

        # --- the transaction being served ---
        cur_valid, cur_write = r.cur_valid, r.cur_write
        cur_addr = r.cur_addr                        # word address of the next SDRAM burst
        cur_left = Signal(range(256 * 4 // bl + 1))  # SDRAM bursts left after this one
        cur_col = cur_addr[:col_bits]
        cur_bank = cur_addr[col_bits:col_bits + bank_bits]
        cur_row = cur_addr[col_bits + bank_bits:]
        last_burst = ~cur_left.any()
        bank_is = Signal(nb)                         # one-hot by a shift: lint-clean Verilog
        m.d.comb += bank_is.eq(Const(1, nb) << cur_bank)

        # --- refresh ---
        ref_cnt, ref_due = r.ref_cnt, r.ref_due
        m.d.sync += [ref_cnt.eq(Mux(ref_cnt.any(), ref_cnt - 1, 0)), ref_due.eq(ref_cnt <= 1)]

        # --- initialisation: power-up wait (ref_cnt), PRECHARGE ALL, refreshes, MRS ---
        init_pre, init_refs, run = r.init_pre, r.init_refs, r.run

        # --- write data buffer: max(burst, words a beat) words, loaded a beat at a time ---
        cap = max(bl, wpb)
        wbuf = [Signal(DQ_BITS, name=f"wbuf{k}") for k in range(cap)]
        wmask = [Signal(2, name=f"wmask{k}") for k in range(cap)]
        wcount = r.wcount
        wsend = Signal(range(bl))                    # words of the WRITE still to send
        bvalid = Signal()

        # --- read path credit (words the read FIFO can still take) ---
        credit = r.credit

        # The decision, a cycle ahead: each cycle registers what the next may issue if
        # this one issues nothing and takes no transaction (decide's ``quiet``); ``fresh``
        # says it issued nothing, ``took`` that it took a transaction (which only the
        # transaction's commands read). So a command comes from three registers through
        # one gate, and a cycle without a command follows each command.
        go, fresh, took = r.go, r.fresh, r.took
        issue = {k: Signal(name=f"issue_{k}") for k in DECISIONS}
        m.d.sync += [go[k].eq(v) for k, v in decide(cfg, r, quiet=True).items()]
        m.d.comb += [issue[k].eq(fresh & go[k] & (~took if k in SERVED else 1))
                     for k in DECISIONS]
        m.d.sync += fresh.eq(~Cat(*issue.values()).any())
        # the command, its bank and address: one expression each (a continuous assignment
        # in the Verilog, defined from time 0 in every simulator)
        a10 = 1 << 10
        column = issue["read"] | issue["write"]
        m.d.comb += [
            nxt_cmd.eq(Mux(issue["pre_all"] | issue["pre"], CMD["precharge"],
                           Mux(issue["ref"], CMD["refresh"], Mux(issue["mode"], CMD["mode"],
                           Mux(issue["act"], CMD["active"], Mux(issue["read"], CMD["read"],
                           Mux(issue["write"], CMD["write"], CMD["nop"]))))))),
            nxt_ba.eq(Mux(issue["act"] | issue["pre"] | column, cur_bank, 0)),
            nxt_a.eq(Mux(issue["pre_all"], a10, Mux(issue["mode"], mode_register(bl, cfg.cas_latency),
                     Mux(issue["act"], cur_row, Mux(column, cur_col, 0)))))]

        for sig in timers:
            count_down(sig)
        with m.If(issue["pre_all"]):
            m.d.sync += [open_.eq(0), init_pre.eq(0)]
            for b in range(nb):
                at_least(act_t[b], t["rp"])
        with m.If(issue["ref"]):
            m.d.sync += [ref_cnt.eq(cfg.refresh_reload), ref_due.eq(0)]
            with m.If(~run):
                m.d.sync += init_refs.eq(init_refs - 1)
                with m.If(init_refs != 1):             # the next one as soon as tRFC allows
                    m.d.sync += [ref_cnt.eq(0), ref_due.eq(1)]
            at_least(cmd_t, t["rfc"])
            for b in range(nb):
                at_least(act_t[b], max(t["rfc"], t["rc"]))
        with m.If(issue["mode"]):
            m.d.sync += run.eq(1)
            at_least(cmd_t, t["mrd"])
        with m.If(issue["act"]):
            at_least(rrd_t, t["rrd"])
            for b in range(nb):
                with m.If(bank_is[b]):
                    m.d.sync += [open_[b].eq(1), rows[b].eq(cur_row)]
                    at_least(act_t[b], t["rc"])
                    at_least(rcd_t[b], t["rcd"])
                    at_least(pre_t[b], t["ras"])
        with m.If(issue["pre"]):
            for b in range(nb):
                with m.If(bank_is[b]):
                    m.d.sync += open_[b].eq(0)
                    at_least(act_t[b], t["rp"])
        with m.If(issue["read"] | issue["write"]):
            m.d.sync += [cur_addr.eq(cur_addr + bl), cur_left.eq(cur_left - 1)]
            with m.If(last_burst):
                m.d.sync += cur_valid.eq(0)
        with m.If(issue["read"]):
            at_least(rd_t, bl)
            at_least(wr_t, cfg.cas_latency + bl + 1)     # the read data off the bus first
            for b in range(nb):
                with m.If(bank_is[b]):
                    at_least(pre_t[b], bl)
        with m.If(issue["write"]):
            at_least(rd_t, bl)
            at_least(wr_t, bl)
            with m.If(last_burst):
                m.d.sync += bvalid.eq(1)
            for b in range(nb):
                with m.If(bank_is[b]):
                    at_least(pre_t[b], bl - 1 + t["wr"])

        # --- AR / AW: a new transaction when none is served (round robin) ---
        prefer_w = Signal()
        take_w, take_r = Signal(), Signal()
        w_ok = wr.awvalid & ~bvalid
        m.d.comb += [take_w.eq(run & ~cur_valid & w_ok & (prefer_w | ~rd.arvalid)),
                     take_r.eq(run & ~cur_valid & rd.arvalid & ~take_w),
                     wr.awready.eq(take_w), rd.arready.eq(take_r)]
        shift = (bl // wpb).bit_length() - 1 if bl >= wpb else -((wpb // bl).bit_length() - 1)

        def bursts(axlen):
            n = axlen + 1
            return (n >> shift if shift >= 0 else n << -shift) - 1

        with m.If(take_w | take_r):
            m.d.sync += [cur_valid.eq(1), cur_write.eq(take_w), prefer_w.eq(take_r)]
        m.d.sync += took.eq(take_w | take_r)
        with m.If(take_w):
            m.d.sync += [cur_addr.eq(wr.awaddr[1:1 + word_bits]), cur_left.eq(bursts(wr.awlen))]
        with m.If(take_r):
            m.d.sync += [cur_addr.eq(rd.araddr[1:1 + word_bits]), cur_left.eq(bursts(rd.arlen))]

        # --- write data: W beats into the buffer's tail; a WRITE sends its front ---
        # ``drop`` (a register) is high the cycle after each word went to the pins: the
        # buffer lets that word go then, so its shift enable comes from registers, not
        # from the decision; meanwhile the next word is the buffer's second.
        drop = Signal()
        m.d.comb += wr.wready.eq((wcount <= cap - wpb) & ~wsend.any() & ~drop)
        take_beat = wr.wvalid & wr.wready
        sending = issue["write"] | wsend.any()
        m.d.sync += drop.eq(sending)
        with m.If(take_beat):
            for k in range(cap):
                src = k + wpb
                if src < cap:
                    m.d.sync += [wbuf[k].eq(wbuf[src]), wmask[k].eq(wmask[src])]
                else:
                    j = src - cap
                    m.d.sync += [wbuf[k].eq(wr.wdata.word_select(j, DQ_BITS)),
                                 wmask[k].eq(~wr.wstrb.word_select(j, 2))]
            m.d.sync += wcount.eq(wcount + wpb)
        with m.Elif(drop):
            for k in range(cap - 1):
                m.d.sync += [wbuf[k].eq(wbuf[k + 1]), wmask[k].eq(wmask[k + 1])]
        with m.If(issue["write"]):
            m.d.sync += [wcount.eq(wcount - bl), wsend.eq(bl - 1)]
        with m.Elif(wsend.any()):
            m.d.sync += wsend.eq(wsend - 1)
        m.d.sync += [pins.dq_oe.eq(sending), pins.dq_o.eq(Mux(drop, wbuf[1], wbuf[0])),
                     pins.dqm.eq(Mux(sending, Mux(drop, wmask[1], wmask[0]), 0))]
        m.d.comb += [wr.bid.eq(0), wr.bresp.eq(0), wr.bvalid.eq(bvalid)]
        with m.If(bvalid & wr.bready):
            m.d.sync += bvalid.eq(0)

        # --- read data: a word flag per cycle of each READ, delayed to its dq_i register ---
        rsend = Signal(range(bl))
        rlast = Signal()                              # the READ being sent ends its AXI burst
        with m.If(issue["read"]):
            m.d.sync += [rsend.eq(bl - 1), rlast.eq(last_burst)]
        with m.Elif(rsend != 0):
            m.d.sync += rsend.eq(rsend - 1)
        word_valid = issue["read"] | (rsend != 0)
        word_last = Mux(issue["read"], last_burst if bl == 1 else 0, rlast & (rsend == 1))
        # decision -> pins -> chip -> dq_i register, and the board's I/O registers
        delay = cfg.cas_latency + 2 + cfg.pin_cycles
        sr_v = [Signal(name=f"rd_valid{k}") for k in range(delay)]
        sr_l = [Signal(name=f"rd_last{k}") for k in range(delay)]
        m.d.sync += [sr_v[0].eq(word_valid), sr_l[0].eq(word_last)]
        m.d.sync += [sr_v[k].eq(sr_v[k - 1]) for k in range(1, delay)]
        m.d.sync += [sr_l[k].eq(sr_l[k - 1]) for k in range(1, delay)]
        dq_in = Signal(DQ_BITS)
        m.d.sync += dq_in.eq(pins.dq_i)                # the I/O cell's input register

        m.submodules.rfifo = rfifo = SyncFIFOBuffered(width=cfg.data_bits + 1,
                                                      depth=cfg.read_fifo)
        if wpb == 1:
            beat = dq_in
            beat_done = sr_v[-1]
        else:
            part = Signal(DQ_BITS * (wpb - 1))
            wcnt = Signal(range(wpb))
            with m.If(sr_v[-1]):
                m.d.sync += [part.eq(Cat(part[DQ_BITS:], dq_in)), wcnt.eq(wcnt + 1)]
            beat = Cat(part, dq_in)
            beat_done = sr_v[-1] & (wcnt == wpb - 1)
        m.d.comb += [rfifo.w_data.eq(Cat(beat, sr_l[-1])), rfifo.w_en.eq(beat_done),
                     rd.rdata.eq(rfifo.r_data[:cfg.data_bits]),
                     rd.rlast.eq(rfifo.r_data[cfg.data_bits]), rd.rvalid.eq(rfifo.r_rdy),
                     rfifo.r_en.eq(rd.rready), rd.rid.eq(0), rd.rresp.eq(0)]
        r_done = rd.rvalid & rd.rready
        m.d.sync += credit.eq(credit - Mux(issue["read"], bl, 0) + Mux(r_done, wpb, 0))
        return m
