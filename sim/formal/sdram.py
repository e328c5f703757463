"""The SDRAM controller's command stream against the JEDEC rules, for SymbiYosys
(docs/sdram.md).

:class:`SdramCommandContract` wraps an :class:`~bumprtl.rtl.sdram.SdramController` whose
AXI ports and DQ input are free (the solver drives them as it likes, AXI rules or not)
and watches its registered pins: a command is on the pins for one cycle and the chip takes
it at the edge ending that cycle. Per bank the monitor keeps whether a row is open and the
cycles since that bank's last ACTIVE, PRECHARGE, READ and WRITE; globally since the last
ACTIVE, AUTO REFRESH and MODE REGISTER SET (counters saturating one past the largest
bound). Each rule is an assertion (:data:`RULES` names them) with a cover showing the
command pair it constrains does occur. The minimums are the configuration's cycles
(``SdramConfig.cycles``, the datasheet's ns at the clock); the power-up wait is the
configuration's ``powerup_cycles``.

Lemmas tie the controller's registers (``SdramController.regs``) to the monitor: each timer
holds the rest of its command's wait, the bank table is the pins' next, the refresh
counter plus the cycles since the last AUTO REFRESH is the reload value, and a refresh
that is due comes within the slack the configuration reserved
(``SdramConfig.refresh_slack``). With them the rules are 2-inductive: :func:`prove` runs
k-induction at depth 2 (seconds; without them the refresh deadline would need a depth of
tREFI). :func:`cover` runs the covers, :func:`bmc` bounded model checking from reset.
"""

from amaranth.hdl import (
    Assert,
    Cat,
    Const,
    Module,
    Mux,
    Signal,
)

from bumprtl.gen.tools.sby import run_sby
from bumprtl.rtl.sdram import DECISIONS, SERVED, SdramConfig, SdramController, decide
from bumprtl.sim.formal.rules import RuleContract

__all__ = ["RULES", "SdramCommandContract", "FORMAL_CONFIGS", "prove", "bmc", "cover"]

RULES = {
    "rcd": "READ/WRITE sooner than tRCD after ACTIVE of its bank",
    "rp": "ACTIVE or AUTO REFRESH sooner than tRP after PRECHARGE of the bank",
    "ras": "PRECHARGE sooner than tRAS after ACTIVE of the bank",
    "rc": "ACTIVE sooner than tRC after ACTIVE of the same bank",
    "rrd": "ACTIVE sooner than tRRD after ACTIVE of another bank",
    "rfc": "a command sooner than tRFC after AUTO REFRESH",
    "wr": "PRECHARGE sooner than tWR after a WRITE burst's last word",
    "mrd": "a command sooner than tMRD after MODE REGISTER SET",
    "refi": "AUTO REFRESH later than tREFI after the previous one",
    "open": "READ/WRITE to a bank with no open row",
    "closed": "ACTIVE to a bank with a row open",
    "idle": "AUTO REFRESH or MODE REGISTER SET with a bank open",
    "burst": "PRECHARGE truncating a READ burst, or READ/WRITE interrupting a burst",
    "bus": "WRITE data on DQ while READ data is due",
    "powerup": "a command other than NOP before the power-up wait ended",
}

# The proofs' configurations: the board's (100 MHz, CL 2, bursts of 8 words, the 32 MB
# part) and the 64 MB part at CL 3 with bursts of 4 at 133 MHz; the initialisation short
# (2 cycles of power-up, 2 refreshes) so that BMC and covers reach the traffic.
FORMAL_CONFIGS = {
    "32mb_100mhz_cl2": SdramConfig("32mb", 100, 2, burst=8, powerup_cycles=2, init_refreshes=2),
    "64mb_133mhz_cl3": SdramConfig("64mb", 133, 3, burst=4, powerup_cycles=2, init_refreshes=2),
    # slow clocks, every timing one cycle: the covers' traces are short
    "32mb_10mhz_cl2": SdramConfig("32mb", 10, 2, burst=8, powerup_cycles=2, init_refreshes=2),
    # tREFI of 7 cycles: refreshes back to back, the deadline's tightest case
    "32mb_1mhz_bl1": SdramConfig("32mb", 1, 2, burst=1, powerup_cycles=2, init_refreshes=2),
    # tREFI of 15 cycles: a refresh falls due within a cover's depth, and between two
    # refreshes there is room for a transaction (at 1 MHz a READ never comes: the next
    # refresh falls due before the cycle after its ACTIVE's gap)
    "32mb_2mhz_bl1": SdramConfig("32mb", 2, 2, burst=1, powerup_cycles=2, init_refreshes=2),
}


class SdramCommandContract(RuleContract):
    """The controller built from ``cfg`` and the monitor of its pins (module docstring)."""

    RULES = RULES

    def __init__(self, cfg: SdramConfig, dut=None):
        super().__init__(dut if dut is not None else SdramController(cfg))
        self.cfg = cfg

    def _lemma(self, m, what, test, src_loc_at=1):
        """An assertion about the controller's registers that makes the rules inductive
        (proved with them)."""
        check = Assert(test, what, src_loc_at=src_loc_at)
        self.messages[f"{check.src_loc[0]}:{check.src_loc[1]}"] = f"lemma: {what}"
        self.lemmas.append(what)
        m.d.comb += check

    def _timer(self, m, timer, now, since, gap):
        """``timer`` gates a command that must come ``gap`` cycles after the command ``now``
        is on the pins (``since`` cycles ago): the timer holds the rest of the wait."""
        if gap <= 1:
            return
        what = f"{timer.name} holds the {gap} cycles after {since.name[6:]}"
        self._lemma(m, what, ~now | (timer >= gap - 1), src_loc_at=2)
        self._lemma(m, what, now | (since >= gap) | (timer + since >= gap - 1), src_loc_at=2)

    def elaborate(self, platform):
        m = Module()
        m.submodules.dut = dut = self.dut
        self.lemmas = []
        cfg, t, bl, cl = self.cfg, self.cfg.cycles, self.cfg.burst, self.cfg.cas_latency
        p, r = dut.sdram, dut.regs
        banks = cfg.chip.banks
        wr_need = bl - 1 + t["wr"]            # WRITE command -> PRECHARGE
        near = max(t["rcd"], t["rp"], t["ras"], t["rc"], t["rfc"], t["rrd"], t["mrd"],
                   wr_need, cl + bl + 1) + 1

        def since(name, cap=near):
            sig = Signal(range(cap + 1), init=cap, name=f"since_{name}")
            sig.cap = cap
            return sig

        def tick(sig, event):
            m.d.sync += sig.eq(Mux(event, 1, Mux(sig >= sig.cap, sig.cap, sig + 1)))

        code = Signal(4)
        m.d.comb += code.eq(Cat(p.we_n, p.cas_n, p.ras_n, p.cs_n))
        is_ = {name: Signal(name=f"is_{name}") for name in
               ("act", "read", "write", "pre", "ref", "mrs", "other")}
        m.d.comb += [is_["act"].eq(code == 0b0011), is_["read"].eq(code == 0b0101),
                     is_["write"].eq(code == 0b0100), is_["pre"].eq(code == 0b0010),
                     is_["ref"].eq(code == 0b0001), is_["mrs"].eq(code == 0b0000),
                     is_["other"].eq(code == 0b0110)]
        any_cmd = Signal()
        m.d.comb += any_cmd.eq(Cat(*is_.values()).any())
        all_banks = p.a[10]

        opened, opened_next = Signal(banks), Signal(banks)   # the monitor's own bank table
        s_act = [since(f"act{b}") for b in range(banks)]
        s_pre = [since(f"pre{b}") for b in range(banks)]
        s_rd = [since(f"read{b}") for b in range(banks)]
        s_wr = [since(f"write{b}") for b in range(banks)]
        s_any_act, s_mrs, s_col, s_read = since("any_act"), since("mrs"), since("column"), \
            since("read")
        s_ref = since("ref", t["refi"] + 1)
        s_reset = Signal(range(t["powerup"] + 2), name="since_reset")       # 0 at reset
        m.d.sync += s_reset.eq(Mux(s_reset > t["powerup"], s_reset, s_reset + 1))
        refreshed = Signal()
        with m.If(is_["ref"]):
            m.d.sync += refreshed.eq(1)
        here = [p.ba == b for b in range(banks)]
        pre_b = [is_["pre"] & (here[b] | all_banks) for b in range(banks)]
        for b in range(banks):
            tick(s_act[b], is_["act"] & here[b])
            tick(s_pre[b], pre_b[b])
            tick(s_rd[b], is_["read"] & here[b])
            tick(s_wr[b], is_["write"] & here[b])
            m.d.comb += opened_next[b].eq(Mux(is_["act"] & here[b], 1,
                                              Mux(pre_b[b], 0, opened[b])))
        m.d.sync += opened.eq(opened_next)
        tick(s_any_act, is_["act"])
        tick(s_ref, is_["ref"])
        tick(s_mrs, is_["mrs"])
        tick(s_col, is_["read"] | is_["write"])
        tick(s_read, is_["read"])

        # --- the rules ---
        self._check(m, "powerup", ~any_cmd | (s_reset >= t["powerup"]))
        self._check(m, "rfc", ~any_cmd | (s_ref >= t["rfc"]))
        self._check(m, "mrd", ~any_cmd | (s_mrs >= t["mrd"]))
        self._check(m, "refi", ~refreshed | (s_ref <= t["refi"]))
        self._check(m, "idle", ~(is_["ref"] | is_["mrs"]) | (opened == 0))
        self._check(m, "burst", ~(is_["read"] | is_["write"]) | (s_col >= bl))
        self._check(m, "bus", ~is_["write"] | (s_read >= cl + bl + 1))
        self._check(m, "rrd", ~is_["act"] | (s_any_act >= t["rrd"]))
        for b in range(banks):
            act, col = is_["act"] & here[b], (is_["read"] | is_["write"]) & here[b]
            pre = pre_b[b] & opened[b]
            self._check(m, "closed", ~act | ~opened[b])
            self._check(m, "open", ~col | opened[b])
            self._check(m, "rcd", ~col | (s_act[b] >= t["rcd"]))
            self._check(m, "rp", ~(act | is_["ref"]) | (s_pre[b] >= t["rp"]))
            self._check(m, "rc", ~(act | is_["ref"]) | (s_act[b] >= t["rc"]))
            self._check(m, "ras", ~pre | (s_act[b] >= t["ras"]))
            self._check(m, "wr", ~pre | (s_wr[b] >= wr_need))
            self._check(m, "burst", ~pre | (s_rd[b] >= bl))

        # --- lemmas: the controller's registers against the monitor's ---
        for b in range(banks):
            act_b = is_["act"] & here[b]
            self._timer(m, r.rcd_t[b], act_b, s_act[b], t["rcd"])
            self._timer(m, r.act_t[b], act_b, s_act[b], t["rc"])
            self._timer(m, r.act_t[b], pre_b[b], s_pre[b], t["rp"])
            self._timer(m, r.act_t[b], is_["ref"], s_ref, max(t["rfc"], t["rc"]))
            self._timer(m, r.pre_t[b], act_b, s_act[b], t["ras"])
            self._timer(m, r.pre_t[b], is_["read"] & here[b], s_rd[b], bl)
            self._timer(m, r.pre_t[b], is_["write"] & here[b], s_wr[b], wr_need)
            self._lemma(m, "act_t within its range", r.act_t[b] <= cfg.act_wait - 1)
            self._lemma(m, "pre_t within its range", r.pre_t[b] <= cfg.pre_wait - 1)
        self._timer(m, r.rrd_t, is_["act"], s_any_act, t["rrd"])
        self._timer(m, r.cmd_t, is_["ref"], s_ref, t["rfc"])
        self._timer(m, r.cmd_t, is_["mrs"], s_mrs, t["mrd"])
        self._timer(m, r.rd_t, is_["read"] | is_["write"], s_col, bl)
        self._timer(m, r.wr_t, is_["read"], s_read, cl + bl + 1)
        self._timer(m, r.wr_t, is_["read"] | is_["write"], s_col, bl)
        self._lemma(m, "cmd_t within its range", r.cmd_t <= cfg.act_wait - 1)
        self._lemma(m, "the controller's banks are the pins' next", r.open == opened_next)
        self._lemma(m, "no bank open before the mode is set", r.run | (r.open == 0))
        self._lemma(m, "the mode is set after a refresh", ~r.run | refreshed)
        self._lemma(m, "init refreshes counted", (r.init_refs == cfg.refreshes)
                    | refreshed | is_["ref"])
        self._lemma(m, "the power-up PRECHARGE comes first",
                    ~r.init_pre | (~r.run & (r.init_refs == cfg.refreshes) & ~any_cmd
                                   & (r.cmd_t == 0) & (r.open == 0) & ~refreshed
                                   & (Cat(*r.act_t) == 0)))
        self._lemma(m, "the power-up wait is counted",
                    ~r.init_pre | (r.ref_cnt + s_reset == t["powerup"])
                    | ((r.ref_cnt == 0) & (s_reset >= t["powerup"])))
        self._lemma(m, "the power-up wait is over", r.init_pre | (s_reset >= t["powerup"]))
        self._lemma(m, "ref_due is ref_cnt == 0", r.ref_due == (r.ref_cnt == 0))
        reload, refi = cfg.refresh_reload, t["refi"]
        counting = refreshed & ~is_["ref"] & ~r.init_pre
        self._lemma(m, "the refresh counter counts from the last AUTO REFRESH",
                    ~counting | (r.ref_cnt == 0) | (s_ref + r.ref_cnt == reload))

        initialising = ~r.run & ~r.init_pre & refreshed & ~is_["ref"]
        self._lemma(m, "the refresh counter starts at the last initialisation refresh",
                    ~initialising | Mux(r.init_refs == 0, s_ref + r.ref_cnt == reload,
                                        r.ref_cnt == 0))

        def biggest(values):
            out = values[0]
            for v in values[1:]:
                out = Mux(v > out, v, out)
            return out

        m_act = biggest([*r.act_t, r.cmd_t])
        m_pre = biggest([Mux(r.open[b], r.pre_t[b], 0) for b in range(banks)] + [r.cmd_t])
        m_idle = biggest([*r.act_t, Const(max(0, t["rp"] - 1), len(r.act_t[0]))])
        # a cycle after a command or a transaction taken issues nothing (not ``fresh``)
        stale = ~r.fresh
        self._lemma(m, "initialisation's refreshes follow each other",
                    ~initialising | (s_ref + m_act + stale <= cfg.act_wait + 1))
        self._lemma(m, "no refresh before the initialisation's",
                    (r.init_refs != cfg.refreshes) | ~refreshed)
        self._lemma(m, "init_refs within its range",
                    (r.init_refs <= cfg.refreshes) & (~r.run | (r.init_refs == 0)))
        due = counting & (r.ref_cnt == 0)
        self._lemma(m, "a due refresh with every bank idle comes in time",
                    ~due | (r.open != 0) | (s_ref + m_act + stale <= refi - 1))
        self._lemma(m, "a due refresh with a bank open comes in time",
                    ~due | (r.open == 0) | (s_ref + m_pre + m_idle + 2 + stale <= refi - 1))
        # the decision registered a cycle ahead is the registers' own while fresh; READ
        # and WRITE imply it without the read credit and the write buffer's count (they
        # only grow meanwhile, and gate the data, not the command stream's rules)
        now, timing = decide(cfg, r), decide(cfg, r, flow=False)
        for k in DECISIONS:
            if k in ("read", "write"):
                self._lemma(m, "go_read or go_write implies the decision of the registers",
                            ~r.fresh | r.took | ~r.go[k] | timing[k])
            elif k in SERVED:
                self._lemma(m, "go_pre or go_act is the decision of the registers",
                            ~r.fresh | r.took | (r.go[k] == now[k]))
            else:
                self._lemma(m, "go of the initialisation or refresh is the registers'",
                            ~r.fresh | (r.go[k] == now[k]))

        # --- covers: each rule's command pair occurs (in bank 0, where traffic starts) ---
        # within the rules' longest spacing, plus the registered decision's gaps: the cycle
        # after a command and the one after a transaction is taken issue nothing, so at
        # one-cycle timings ACTIVE, READ, (AR taken), PRECHARGE, ACTIVE spans 7 cycles
        near_ = near + 3
        self._cover(m, "rcd: READ after ACTIVE", is_["read"] & here[0] & (s_act[0] < near_))
        self._cover(m, "rcd: WRITE after ACTIVE", is_["write"] & here[0] & (s_act[0] < near_))
        self._cover(m, "rp/rc: ACTIVE after PRECHARGE of an open row",
                    is_["act"] & here[0] & (s_pre[0] < near_) & (s_act[0] < near_))
        self._cover(m, "ras/burst: PRECHARGE after READ",
                    pre_b[0] & opened[0] & (s_rd[0] < near_))
        self._cover(m, "wr: PRECHARGE after WRITE", pre_b[0] & opened[0] & (s_wr[0] < near_))
        self._cover(m, "rrd: ACTIVE after ACTIVE of another bank",
                    is_["act"] & here[1] & (s_any_act < near_))
        self._cover(m, "rfc: ACTIVE after AUTO REFRESH", is_["act"] & (s_ref < near_))
        self._cover(m, "mrd: ACTIVE after MODE REGISTER SET", is_["act"] & (s_mrs < near_))
        self._cover(m, "bus: WRITE after READ", is_["write"] & (s_read < near_))
        self._cover(m, "burst: READ after READ", is_["read"] & (s_col < near_))
        self._cover(m, "refi/idle: AUTO REFRESH after the mode is set", is_["ref"] & r.run)
        return m


def _sby(top, workdir, name, mode, depth, engine="smtbmc z3", timeout=1800):
    return run_sby(top, workdir, name, mode=mode, depth=depth, engine=engine,
                   script=("memory_map", "opt -fast"), timeout=timeout)


def prove(cfg, workdir, name="prove", depth=2, timeout=1800, dut=None):
    """Every rule for all time: k-induction with the lemmas. ``dut``: a controller built
    otherwise (a broken one) checked against ``cfg``'s rules."""
    top = SdramCommandContract(cfg, dut)
    return top, _sby(top, workdir, name, "prove", depth, timeout=timeout)


def bmc(cfg, workdir, depth, name="bmc"):
    """Every rule in the first ``depth`` cycles from reset."""
    top = SdramCommandContract(cfg)
    return top, _sby(top, workdir, name, "bmc", depth)


def cover(cfg, workdir, depth, name="cover"):
    """Every cover reached within ``depth`` cycles."""
    top = SdramCommandContract(cfg)
    return top, _sby(top, workdir, name, "cover", depth)
