"""A cycle model of the ULX3S's SDR SDRAM, written from the datasheets' command truth
table and A.C. timing table, for testbenches: it stores data, returns READ bursts after
the CAS latency and takes WRITE bursts with their DQM masks, as the mode register says,
and raises :class:`SdramViolation` on any illegal command or timing violation.

It shares nothing with the controller (rtl/sdram.py): its own copy of the datasheet
numbers in ns, its own command decoding, and it measures time in ns (cycles x the clock
period, exact fractions), never in cycles rounded by the controller's conversion.

Stricter than a chip in two ways, both documented: a READ or WRITE may not interrupt a
burst still under way, and consecutive AUTO REFRESH commands may never be further apart
than tREFI (the datasheet allows 8192 in any 64 ms).

The model sees the pins of one cycle at a time (:meth:`SdramModel.cycle`: the values the
chip samples at the clock edge ending that cycle) and answers what it drives on DQ in the
next cycle. :meth:`SdramModel.process` runs it in the Amaranth simulator; the cocotb
benches call :meth:`cycle` from their own coroutine (sim/tb/tb_sdram.py).
"""

from dataclasses import dataclass
from fractions import Fraction

__all__ = ["SdramViolation", "DATASHEET", "SdramModel"]


class SdramViolation(AssertionError):
    """An illegal command or a timing violation, with the cycle and the rule broken."""


@dataclass(frozen=True)
class Datasheet:
    rows: int
    cols: int
    banks: int
    ns: dict               # minimum spacings in ns
    tck_min: dict          # CAS latency -> least clock period (ns)


# Both parts' -7 columns (Alliance AS4C16M16SA and AS4C32M16SB, Table 16), the larger
# where LiteDRAM's IS42S16160/IS42S16320 entries ask for more (tRFC 70, tWR 20).
_NS = {"RCD": 21, "RP": 21, "RAS": 42, "RC": 63, "RFC": 70, "RRD": 14, "WR": 20, "MRD": 14,
       "REFI": Fraction(64_000_000, 8192), "POWERUP": 200_000}
DATASHEET = {
    "32mb": Datasheet(rows=8192, cols=512, banks=4, ns=_NS, tck_min={2: 10, 3: 7}),
    "64mb": Datasheet(rows=8192, cols=1024, banks=4, ns=_NS, tck_min={2: 10, 3: 7}),
}

# (CS#, RAS#, CAS#, WE#) -> command, the datasheets' truth table (CKE high throughout).
TRUTH = {(0, 1, 1, 1): "NOP", (0, 0, 1, 1): "ACT", (0, 1, 0, 1): "READ", (0, 1, 0, 0): "WRITE",
         (0, 0, 1, 0): "PRE", (0, 0, 0, 1): "REF", (0, 0, 0, 0): "MRS", (0, 1, 1, 0): "BST"}
NEVER = Fraction(-10 ** 12)


class SdramModel:
    """The chip ``variant`` ("32mb", "64mb") clocked at ``freq_mhz``.

    ``powerup_ns`` replaces the datasheet's 200 us power-up wait (a simulation's shortcut,
    said by the bench); ``init_refreshes``: AUTO REFRESH commands required before the mode
    register is set. ``log``: commands seen, as (cycle, name, bank, address). ``preload``:
    the words the memory holds at power-on, indexed ``[bank, row, column]`` (an array of
    the chip's banks x rows x columns; None: zeros); a word written since reads back as
    written.
    """

    def __init__(self, variant, freq_mhz, powerup_ns=None, init_refreshes=2, log=False,
                 preload=None):
        self.sheet = DATASHEET[variant]
        self.tck = Fraction(1000) / Fraction(str(freq_mhz))
        self.ns = dict(self.sheet.ns)
        if powerup_ns is not None:
            self.ns["POWERUP"] = Fraction(powerup_ns)
        self.init_refreshes = init_refreshes
        self.mem = {}
        shape = (self.sheet.banks, self.sheet.rows, self.sheet.cols)
        if preload is not None and tuple(preload.shape) != shape:
            raise ValueError(f"preload must be an array of shape {shape} (banks, rows, "
                             f"columns), got {tuple(preload.shape)}")
        self.preload = preload
        self.log = [] if log else None
        self.error = None             # the first violation seen by :meth:`process`
        self.reset()

    def reset(self):
        """Power on: nothing initialised, every bank idle (the memory keeps its words)."""
        banks = self.sheet.banks
        self.n = 0
        self.row = [None] * banks
        self.last = {k: [NEVER] * banks for k in ("ACT", "PRE", "WDATA", "READ_END")}
        self.last_any_act = self.last_ref = self.last_mrs = NEVER
        self.state = "powerup"        # powerup -> precharged -> refreshing -> ready
        self.refs = 0
        self.cl = self.bl = None
        self.reads = {}               # cycle -> (bank, row, col) driven in that cycle
        self.writes = {}              # cycle -> (bank, row, col) sampled in that cycle
        self.busy_until = -1          # last cycle of the burst under way
        self.commands = {}

    def _t(self, cycle):
        return cycle * self.tck

    def _fail(self, msg):
        raise SdramViolation(f"cycle {self.n}: {msg}")

    def _since(self, when, key, what):
        """At least tKEY ns from ``when`` (a time) to now."""
        need = self.ns[key]
        gap = self._t(self.n) - when
        if gap < need:
            self._fail(f"{what}: {float(gap):g} ns < t{key} = {float(need):g} ns")

    # --- the pins of one cycle ---
    def cycle(self, cs_n, ras_n, cas_n, we_n, ba, a, dqm, dq_o, dq_oe, cke=1):
        """The pins sampled at the edge ending cycle ``self.n``; returns ``(drive, value)``,
        the DQ the chip drives in the next cycle."""
        if not cke:
            self._fail("CKE low (power-down and self refresh are not used)")
        drives = self.n in self.reads
        if drives and dq_oe:
            self._fail("DQ driven by the controller while the chip drives read data")
        name = "DESELECT" if cs_n else TRUTH[(0, ras_n, cas_n, we_n)]
        if name not in ("NOP", "DESELECT"):
            self._command(name, ba, a)
        if self.n in self.writes:           # a WRITE's first word comes with the command
            bank, row, col = self.writes.pop(self.n)
            if not dq_oe:
                self._fail("write data not driven during a WRITE burst")
            word = self.word((bank, row, col))
            for byte in range(2):
                if not dqm >> byte & 1:
                    mask = 0xFF << 8 * byte
                    word = (word & ~mask) | (dq_o & mask)
            self.mem[(bank, row, col)] = word
            self.last["WDATA"][bank] = self._t(self.n)
        self.reads.pop(self.n, None)
        self._refresh_deadline()
        self.n += 1
        nxt = self.reads.get(self.n)
        if nxt is None:
            return False, 0
        return True, self.word(nxt)

    def word(self, where):
        """The word at ``where`` = (bank, row, column): the last written, else the
        preload's, else 0."""
        word = self.mem.get(where)
        if word is None:
            return 0 if self.preload is None else int(self.preload[where])
        return word

    def _refresh_deadline(self):
        if self.state == "ready" or (self.state == "refreshing" and self.refs):
            late = self._t(self.n) - self.last_ref
            if late > self.ns["REFI"]:
                self._fail(f"no AUTO REFRESH for {float(late):g} ns > tREFI = "
                           f"{float(self.ns['REFI']):g} ns")

    def _command(self, name, ba, a):
        if self.log is not None:
            self.log.append((self.n, name, ba, a))
        self.commands[name] = self.commands.get(name, 0) + 1
        now = self._t(self.n)
        banks = range(self.sheet.banks)
        if self.last_mrs > NEVER:
            self._since(self.last_mrs, "MRD", f"{name} after MODE REGISTER SET")
        if self.last_ref > NEVER:
            self._since(self.last_ref, "RFC", f"{name} after AUTO REFRESH")
        if self.state == "powerup":
            if name != "PRE" or not a >> 10 & 1:
                self._fail(f"{name} before the power-up PRECHARGE ALL")
            self._since(Fraction(0), "POWERUP", "PRECHARGE ALL after power-up")
        elif self.state != "ready" and name in ("ACT", "READ", "WRITE"):
            self._fail(f"{name} before initialisation (refreshes, MODE REGISTER SET) ended")
        if name == "BST":
            self._fail("BURST TERMINATE is not expected")
        if name in ("READ", "WRITE") and self.n <= self.busy_until:
            self._fail(f"{name} interrupts the burst under way (until cycle {self.busy_until})")
        getattr(self, f"_{name.lower()}")(ba, a, now, banks)

    def _act(self, ba, a, now, banks):
        if self.row[ba] is not None:
            self._fail(f"ACTIVE to bank {ba} with row {self.row[ba]} open")
        if a >= self.sheet.rows:
            self._fail(f"ACTIVE row {a} beyond the chip's {self.sheet.rows} rows")
        self._since(self.last["PRE"][ba], "RP", f"ACTIVE bank {ba} after PRECHARGE")
        self._since(self.last["ACT"][ba], "RC", f"ACTIVE bank {ba} after ACTIVE")
        self._since(self.last_any_act, "RRD", f"ACTIVE bank {ba} after ACTIVE of another bank")
        self.row[ba] = a
        self.last["ACT"][ba] = self.last_any_act = now

    def _column(self, name, ba, a):
        if self.row[ba] is None:
            self._fail(f"{name} to bank {ba} with no open row")
        if a >> 10 & 1:
            self._fail(f"{name} with auto precharge (A10) is not expected")
        self._since(self.last["ACT"][ba], "RCD", f"{name} bank {ba} after ACTIVE")
        col = a & ((1 << 10) - 1) & (self.sheet.cols - 1)
        base = col & ~(self.bl - 1)
        # sequential burst: the columns wrap inside the burst's aligned block
        return [(ba, self.row[ba], base | ((col + k) & (self.bl - 1))) for k in range(self.bl)]

    def _read(self, ba, a, now, banks):
        cols = self._column("READ", ba, a)
        for k, where in enumerate(cols):
            cyc = self.n + self.cl + k
            if cyc in self.writes:
                self._fail("READ data would meet WRITE data on DQ")
            self.reads[cyc] = where
        self.busy_until = self.n + self.bl - 1
        self.last["READ_END"][ba] = self._t(self.n + self.bl)

    def _write(self, ba, a, now, banks):
        cols = self._column("WRITE", ba, a)
        for k, where in enumerate(cols):
            if self.n + k in self.reads:
                self._fail("WRITE data would meet READ data on DQ")
            self.writes[self.n + k] = where
        self.busy_until = self.n + self.bl - 1

    def _pre(self, ba, a, now, banks):
        which = list(banks) if a >> 10 & 1 else [ba]
        for b in which:
            if self.row[b] is not None:
                self._since(self.last["ACT"][b], "RAS", f"PRECHARGE bank {b} after ACTIVE")
                self._since(self.last["WDATA"][b], "WR", f"PRECHARGE bank {b} after write data")
                if now < self.last["READ_END"][b]:
                    self._fail(f"PRECHARGE bank {b} truncates a READ burst")
                if any(w[0] == b for w in self.writes.values()):
                    self._fail(f"PRECHARGE bank {b} during its WRITE burst")
            self.row[b] = None
            self.last["PRE"][b] = now
        if self.state == "powerup":
            self.state = "precharged"

    def _ref(self, ba, a, now, banks):
        for b in banks:
            if self.row[b] is not None:
                self._fail(f"AUTO REFRESH with bank {b} open")
            self._since(self.last["PRE"][b], "RP", "AUTO REFRESH after PRECHARGE")
            self._since(self.last["ACT"][b], "RC", "AUTO REFRESH after ACTIVE")
        if self.state == "precharged":
            self.state = "refreshing"
        if self.state == "refreshing":
            self.refs += 1
        self.last_ref = now

    def _mrs(self, ba, a, now, banks):
        if any(r is not None for r in self.row):
            self._fail("MODE REGISTER SET with a bank open")
        for b in banks:
            self._since(self.last["PRE"][b], "RP", "MODE REGISTER SET after PRECHARGE")
        if self.state != "refreshing" or self.refs < self.init_refreshes:
            self._fail(f"MODE REGISTER SET after {self.refs} AUTO REFRESH, "
                       f"{self.init_refreshes} required")
        bl_code, seq, cl, op, wb = a & 7, a >> 3 & 1, a >> 4 & 7, a >> 7 & 3, a >> 9 & 1
        if bl_code > 3 or seq or op or wb or a >> 10 or ba:
            self._fail(f"mode register {a:#x} (bank {ba}): only BL 1-8, sequential, standard "
                       f"operation, burst writes expected")
        if cl not in (2, 3):
            self._fail(f"CAS latency {cl} in the mode register")
        if self.tck < self.sheet.tck_min[cl]:
            self._fail(f"clock period {float(self.tck):g} ns < tCK {self.sheet.tck_min[cl]} ns at CL {cl}")
        self.cl, self.bl = cl, 1 << bl_code
        self.state = "ready"
        self.last_mrs = now

    # --- running it ---
    async def process(self, ctx, pins, domain="sync"):
        """An Amaranth simulator process on ``pins`` (the controller's ``sdram`` interface),
        clocked by ``domain``, whose reset resets the model too. The first violation is kept in
        ``error`` (the model stops there and the simulation runs on: an exception thrown
        out of a simulator process leaves its other coroutines half closed); the caller
        raises it once the simulation has ended."""
        drive, value = False, 0
        while True:
            ctx.set(pins.dq_i, value if drive else 0)
            _, rst, *vals = await ctx.tick(domain).sample(
                pins.cs_n, pins.ras_n, pins.cas_n, pins.we_n, pins.ba, pins.a, pins.dqm,
                pins.dq_o, pins.dq_oe, pins.cke)
            if self.error is not None:
                continue
            if rst:
                self.reset()
                drive = False
                continue
            try:
                drive, value = self.cycle(*vals)
            except SdramViolation as e:
                self.error, drive = e, False
