"""The texel cache's AXI4 read manager port against the AXI4 read-channel rules, for
SymbiYosys (docs/formal.md, The cache's AXI4 port).

:class:`AxiReadContract` wraps a :class:`~bumprtl.rtl.cache.TextureCache` whose pixel
input (``i.valid``, ``i.payload``), output ``o.ready`` and reset are free, and whose AXI
subordinate side (ARREADY, RVALID, RDATA, RLAST, RRESP, RID) is free but constrained by
``Assume``s of the subordinate's rules (:data:`ASSUMED`): RVALID, RDATA and RLAST held
until RREADY; no R beat before its burst's AR handshake (RVALID only while a burst is
accepted and not finished); RLAST exactly on beat ARLEN of a burst. ARREADY is never
constrained: the subordinate may stall the AR channel for ever.

A monitor counts the bursts accepted (AR handshakes) and not finished (RLAST taken) and
the beats taken of the oldest one; each manager-side rule of :data:`RULES` is an
``Assert`` with a ``Cover`` that shows the situation it constrains occurs. The beats of a
burst: the subordinate is assumed to end a burst with RLAST on beat ARLEN; the manager
does not check RLAST (it ends the line on RLAST) but counts the beats itself, and
``r_beats`` asserts that its count is the port's, so beat k of a burst lands in word k of
its line and the line ends on beat ARLEN + 1.

Lemmas tie the cache's control registers (``TextureCache.regs``) to the monitor: the
bursts it counts outstanding are the AR it holds plus the bursts accepted and not
finished, its beat counter is the monitor's, its fill queue's pointers are that many
entries apart. With them the rules are 2-inductive: :func:`prove` runs k-induction at depth
2. :func:`cover` runs the covers, :func:`bmc` bounded model checking from reset (the broken
managers of :data:`MUTANTS`, whose failure must be the rule itself, without lemmas).
"""

from amaranth.hdl import (
    Assert,
    Assume,
    Cat,
    Module,
    Signal,
)
from amaranth.lib import wiring
from amaranth.lib.wiring import Out

from bumprtl.gen.tools.sby import run_sby
from bumprtl.rtl.cache import ARBURST_INCR, CacheGeometry, TextureCache, scene_geometry
from bumprtl.sim.formal.rules import RuleContract
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config

__all__ = ["RULES", "ASSUMED", "AxiReadContract", "FORMAL_GEOMETRIES", "MUTANTS", "prove", "bmc",
           "cover", "geometry", "PROVE_ONLY", "cover_depth", "ArvalidDropper", "LongBurst", "BeyondImage"]

RULES = {
    "ar_hold": "ARVALID fell, or ARADDR/ARLEN/ARSIZE/ARBURST changed, before ARREADY",
    "ar_burst": "ARLEN/ARSIZE/ARBURST/ARID are not one line's INCR burst (ARLEN = beats - 1, "
                "ARSIZE = log2 of the data bytes, ARBURST = INCR, ARID = 0)",
    "ar_addr": "ARADDR not aligned to a line or outside the map's image",
    "r_beats": "a beat taken as another word of its line than its place in the burst "
               "(the manager's beat count is not the port's)",
    "r_ready": "RREADY low while a burst is accepted and not finished, or high with no "
               "burst issued",
    "outstanding": "more bursts issued and not finished than the cache's limit (misses)",
    "r_orphan": "an R beat taken with no burst accepted and not finished",
}

ASSUMED = {
    "r_hold": "RVALID, RDATA and RLAST held until RREADY",
    "r_after_ar": "no RVALID without a burst accepted and not finished",
    "r_last": "RLAST exactly on beat ARLEN of the burst (the line's ARLEN, which ar_burst "
              "asserts every AR carries)",
}

# Small caches (the rules are about the port; the sizes only change the counts): two sets
# of two ways (a flush of two cycles after reset), lines of two beats or one, or the
# default scene's lines (4 x 4 texels of 4 bytes: 16 beats of 32 bits), two bursts
# outstanding or four; and the default scene's own cache (rtl/scene.CACHE_DEFAULTS: 64 sets,
# 64 bursts outstanding). The last two are proved only: the default scene's covers need
# its 64-cycle flush and 64 misses in flight (a BMC that had reached 17 of its 174 steps
# after 4 minutes), the 16-beat lines' two bursts of beats (25 of 50 steps after 9
# minutes); the covers of the two small caches reach every rule.
def _scene_default():
    return scene_geometry(load_scene_config({**BUILTIN["default"], "map_memory": "axi"}).hardware)


FORMAL_GEOMETRIES = {
    "2beats": lambda: CacheGeometry(16, 1, 12, sets=2, ways=2, block=2, data_bits=32, queue=4,
                                    misses=2, base=0x40),
    "1beat_4out": lambda: CacheGeometry(16, 1, 12, sets=2, ways=2, block=2, data_bits=64,
                                        queue=8, misses=4, base=0x1000, addr_bits=16,
                                        stamp_bits=8),
    "16beats": lambda: CacheGeometry(64, 1, 28, sets=2, ways=2, block=4, data_bits=32,
                                     queue=8, misses=4),
    "scene_default": _scene_default,
}
PROVE_ONLY = ("16beats", "scene_default")     # no cover run (above)


def geometry(name):
    """The :class:`CacheGeometry` of :data:`FORMAL_GEOMETRIES` ``name``."""
    return FORMAL_GEOMETRIES[name]()


def cover_depth(geom):
    """BMC depth of the covers: the flush (one set a cycle), a miss a cycle up to the
    limit of bursts outstanding, two bursts' beats and a pixel out."""
    return geom.sets + geom.misses + 2 * geom.beats + 12


class AxiReadContract(RuleContract):
    """The cache built from ``geom`` (or ``dut``, a broken one with the same ports and
    ``regs``) and the monitor of its AXI port (module docstring)."""

    RULES = RULES

    def __init__(self, geom: CacheGeometry, dut=None, lemmas=True):
        super().__init__(dut if dut is not None else TextureCache(geom))
        self.geom, self.lemmas_on = geom, lemmas
        self.lemmas = []
        self.assumed = []

    def _assume(self, m, rule, test):
        self.assumed.append(rule)
        m.d.comb += Assume(test, ASSUMED[rule], src_loc_at=1)


    def _lemma(self, m, what, test):
        if not self.lemmas_on:
            return
        check = Assert(test, what, src_loc_at=1)
        self.messages[f"{check.src_loc[0]}:{check.src_loc[1]}"] = f"lemma: {what}"
        self.lemmas.append(what)
        m.d.comb += check

    def elaborate(self, platform):
        m = Module()
        m.submodules.dut = dut = self.dut
        g, ax, r = self.geom, dut.axi, dut.regs
        arlen, arsize = g.beats - 1, (g.data_bits // 8).bit_length() - 1
        ar_take = ax.arvalid & ax.arready
        r_take = ax.rvalid & ax.rready
        # --- the monitor: bursts accepted and not finished, beats taken of the oldest ---
        accepted = Signal(range(g.misses + 2), name="mon_accepted")
        mbeat = Signal(range(g.beats + 1), name="mon_beat")
        done = r_take & ax.rlast
        m.d.sync += accepted.eq(accepted + ar_take - done)
        with m.If(done):
            m.d.sync += mbeat.eq(0)
        with m.Elif(r_take):
            m.d.sync += mbeat.eq(mbeat + 1)
        issued = Signal(range(g.misses + 3), name="mon_issued")   # accepted + the AR held
        m.d.comb += issued.eq(accepted + ax.arvalid)
        # the last cycle's AR and R channels (reset with the cache: a reset clears the rules)
        ar_wait, r_wait = Signal(name="past_ar_wait"), Signal(name="past_r_wait")
        ar_payload = Cat(ax.araddr, ax.arlen, ax.arsize, ax.arburst)
        r_payload = Cat(ax.rdata, ax.rlast)
        ar_was = Signal(len(ar_payload), name="past_ar")
        r_was = Signal(len(r_payload), name="past_r")
        m.d.sync += [ar_wait.eq(ax.arvalid & ~ax.arready), ar_was.eq(ar_payload),
                     r_wait.eq(ax.rvalid & ~ax.rready), r_was.eq(r_payload)]

        # --- the subordinate follows the rules ---
        self._assume(m, "r_hold", ~r_wait | (ax.rvalid & (r_payload == r_was)))
        self._assume(m, "r_after_ar", ~ax.rvalid | (accepted != 0))
        self._assume(m, "r_last", ~ax.rvalid | (ax.rlast == (mbeat == arlen)))

        # --- the manager's rules ---
        self._check(m, "ar_hold", ~ar_wait | (ax.arvalid & (ar_payload == ar_was)))
        self._cover(m, "ar_hold: an AR held through a stall is taken", ar_wait & ar_take)
        self._check(m, "ar_burst", ~ax.arvalid | ((ax.arlen == arlen) & (ax.arsize == arsize)
                                                  & (ax.arburst == ARBURST_INCR) & (ax.arid == 0)))
        self._cover(m, "ar_burst: an AR taken", ar_take)
        end = g.base + g.image_bytes
        self._check(m, "ar_addr", ~ax.arvalid | ((ax.araddr[:g.line_bytes.bit_length() - 1] == 0)
                                                 & (ax.araddr >= g.base) & (ax.araddr < end)))
        self._cover(m, "ar_addr: the image's last line asked for",
                    ax.arvalid & (ax.araddr == end - g.line_bytes))
        self._check(m, "r_beats", ~r_take | (r.beat == mbeat))
        self._cover(m, "r_beats: a burst's last beat taken", done)
        self._check(m, "r_ready", (ax.rready | (accepted == 0)) & (~ax.rready | (issued != 0)))
        self._cover(m, "r_ready: RREADY high with the burst's AR still waiting",
                    ax.rready & ax.arvalid & ~ax.arready & (accepted == 0))
        self._check(m, "outstanding", issued <= g.misses)
        self._cover(m, "outstanding: the limit reached", accepted == g.misses)
        self._check(m, "r_orphan", ~r_take | (accepted != 0))
        self._cover(m, "r_orphan: a beat taken with the next burst accepted too",
                    r_take & (accepted > 1))
        self._cover(m, "a pixel that missed leaves the cache", dut.o.valid & dut.o.ready & (r.landed != 0))

        # --- lemmas: the cache's registers against the monitor ---
        self._lemma(m, "the cache's bursts outstanding = accepted + the AR held",
                    r.fills == issued)
        self._lemma(m, "the cache's beat counter = the monitor's", r.beat == mbeat)
        self._lemma(m, "RREADY while a burst is outstanding", r.fills_any == (r.fills != 0))
        self._lemma(m, "a burst in progress is accepted", (mbeat == 0) | (accepted != 0))
        self._lemma(m, "the beats of a burst are fewer than a line's", mbeat < g.beats)
        if g.misses > 1:
            ptr = (r.f_in - r.f_out)[:len(r.f_in)]
            self._lemma(m, "the fill queue's pointers are its bursts apart",
                        (ptr == r.fills) | ((r.fills == g.misses) & (ptr == 0)))
        self._lemma(m, "no burst outstanding while flushing", ~r.flushing | (r.fills == 0))
        self._lemma(m, "a miss may go: ARVALID low, fewer bursts than the most",
                    r.miss_ok == (~ax.arvalid & (r.fills != g.misses)))
        self._lemma(m, "no pixel while flushing",
                    ~r.flushing | ~(r.in_valid | r.rw_valid | r.sk_valid | r.ws_valid
                                    | r.ds_valid | r.look_valid))
        self._lemma(m, "the lookup may go: not flushing, a pixel, a free queue entry",
                    r.go == (~r.flushing & r.look_valid & ~r.count[-1]))
        self._lemma(m, "the queue holds at most its entries", r.count <= g.queue)
        self._lemma(m, "the lookup's go and hit, go and miss_ok in registers of their own",
                    (r.go_hit == (r.go & r.look_hit)) & (r.go_miss == (r.go & r.miss_ok)))
        read = r.q_f0 + r.q_f1 + r.q_v2 + r.q_v1
        self._lemma(m, "the queue's head may leave as its registers say", r.head_ok == r.pop_ok)
        self._lemma(m, "the head register waits behind its full read and skid registers",
                    r.hd_stall == (r.hd_valid & r.wd_valid & r.o_skid))
        self._lemma(m, "the queue's entries read and the ones unread are its queued ones",
                    read + r.q_unread == r.count)
        self._lemma(m, "the queue has an entry to read", r.q_avail == (r.q_unread != 0))
        self._lemma(m, "the queue's read is enabled", r.q_en == ~(r.q_f1 & r.q_v2))
        self._lemma(m, "the queue's fabric registers fill in order", ~r.q_f1 | r.q_f0)
        self._lemma(m, "the queue's ring writes past its entries",
                    r.q_wr == r.q_rd ^ (r.q_f0 & ~r.q_f1))
        return m


class _Broken(wiring.Component):
    """A TextureCache with its AXI port passed through; subclasses break one rule."""

    def __init__(self, geom):
        self.inner, self.geom = TextureCache(geom), geom
        self.regs = self.inner.regs
        super().__init__(dict(self.inner.signature.members))

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = self.inner
        wiring.connect(m, wiring.flipped(self.i), inner.i)
        wiring.connect(m, inner.o, wiring.flipped(self.o))
        for name, member in self.axi.signature.members.items():
            ours, theirs = getattr(self.axi, name), getattr(inner.axi, name)
            m.d.comb += (ours.eq(theirs) if member.flow == Out else theirs.eq(ours))
        self.brk(m, inner.axi)
        return m


class ArvalidDropper(_Broken):
    """Drops ARVALID after one cycle of waiting for ARREADY (and takes the AR as given):
    breaks ``ar_hold``."""

    def brk(self, m, ax):
        waited = Signal(name="waited")
        m.d.sync += waited.eq(ax.arvalid & ~self.axi.arready)
        m.d.comb += [self.axi.arvalid.eq(ax.arvalid & ~waited),
                     ax.arready.eq(self.axi.arready | waited)]


class LongBurst(_Broken):
    """Asks for one beat more than a line (ARLEN = beats): breaks ``ar_burst``."""

    def brk(self, m, ax):
        m.d.comb += self.axi.arlen.eq(ax.arlen + 1)


class BeyondImage(_Broken):
    """Adds the image's size to ARADDR (the line after the map's end): breaks ``ar_addr``."""

    def brk(self, m, ax):
        m.d.comb += self.axi.araddr.eq(ax.araddr + self.geom.image_bytes)


# broken manager -> the rule it must fail
MUTANTS = {"arvalid_drop": (ArvalidDropper, "ar_hold"), "long_burst": (LongBurst, "ar_burst"),
           "beyond_image": (BeyondImage, "ar_addr")}


def _sby(top, workdir, name, mode, depth, timeout=1800):
    return run_sby(top, workdir, name, mode=mode, depth=depth, timeout=timeout)


def prove(geom, workdir, name="prove", depth=2, timeout=1800, dut=None):
    """Every rule for all time: k-induction with the lemmas. ``dut``: a cache built
    otherwise (a broken one) checked against ``geom``'s rules."""
    top = AxiReadContract(geom, dut)
    return top, _sby(top, workdir, name, "prove", depth, timeout=timeout)


def bmc(geom, workdir, depth, name="bmc", dut=None):
    """Every rule in the first ``depth`` cycles from reset, without the lemmas."""
    top = AxiReadContract(geom, dut, lemmas=False)
    return top, _sby(top, workdir, name, "bmc", depth)


def cover(geom, workdir, depth, name="cover"):
    """Every cover reached within ``depth`` cycles."""
    top = AxiReadContract(geom, lemmas=False)
    return top, _sby(top, workdir, name, "cover", depth)
