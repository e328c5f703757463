"""Two equivalence steps of tests/mutants/netlist.py for invariants the cut step
(netlist_cone.py) cannot state and Spacer (netlist_pdr.py) does not find in its time on a
scene pipeline. Both search an inductive invariant among candidate clauses, as Houdini does,
with z3 on the bit-blasted AIGER of a model Yosys builds (no ABC in this environment), and
both are proofs, never a guess:

``never`` (cnot0 / cnot1 mutations): such a mutant equals the design in every cycle in which
its control bit has the inactive value (0 for cnot1, 1 for cnot0). The step proves, on the
UNMUTATED design alone (one copy, no miter: mutsel tied to 0), that the control bit has the
inactive value in every reachable state; then design and mutant compute the same in every
cycle (every register, memory and output), so the mutant is equivalent. The model: the
whole design with the memories cut (a read port's data is a free input each cycle), and an
invariant of upper bounds "register (word, unsigned) <= b_r", "every word of memory m <=
b_m" searched as abstract interpretation does, ascending: every bound starts at the initial
value, then b_r becomes the largest value of r's next state that sat finds under the bounds
of the registers and memories it reads (a memory's next contents: the written word where a
write port's enable is set, the old contents, at most b_m, where not), over and over, the
registers farthest from the control bit first, until no bound grows (a bound that grew
three times is widened to all ones; a bound sat cannot decide in its time is all ones too:
every widening is weaker, so still sound). Only the registers ``depth`` register stages
behind the control bit get a bound, the others none (free: fewer constraints, never more),
with ``depth`` 4, 8, 16, 32 and every register. At the fixpoint each bound holds initially
and in the next state of every state within the bounds: an inductive invariant; the step
proves the mutant equivalent when sat shows the control bit inactive in every state within
it. A cnot mutation of a range's bit (a bit 16 of a value at most 1.0) is the case it is
for.

``rel``: the relational clauses of the stream contract. On the product machine of
netlist_pdr.py (design and mutant, the cells a difference reaches twice, every register
kept, the memories cut to free read data, the arithmetic the difference reaches one
unknown function of its operands), the candidates are: every bit of a duplicated register
equal in the two copies; "register r equal in the two copies OR v = 0" for every duplicated
register r (its whole word) and every shared 1-bit register v whose name marks it as a valid
bit (``valid`` in the wire's name: a pipeline stage's, a unit's output's); every shared
register bit at its initial value. Houdini: every candidate holds in the initial state (the
two copies start equal); sat looks for a state satisfying the surviving candidates whose
next state breaks one, drops what breaks and repeats until none breaks: the survivors are an
inductive invariant (a generous candidate set is sound, only weaker). The product's
property (no output differs, payloads masked by valid with ``stream``; no memory write
input differs) must hold in every state satisfying it; sat finding a state that breaks it
ends the step undecided.
"""

import itertools
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import netlist_cone as nc  # noqa: E402
import netlist_pdr as npdr  # noqa: E402

NEVER_DEPTHS = (4, 8, 16, 32, None)
WIDEN_AFTER = 3          # a bound that grew this many times becomes all ones
MAX_QUERY_MS = 20000     # sat's time for one query of the bound search (then: all ones)


def _bv(z3, bits):
    """An unsigned bit-vector of Bool expressions, bit 0 first."""
    one, zero = z3.BitVecVal(1, 1), z3.BitVecVal(0, 1)
    parts = [z3.If(b, one, zero) for b in reversed(bits)]
    return parts[0] if len(parts) == 1 else z3.Concat(*parts)


# --- never: the control bit of a cnot mutation inactive in every reachable state -----------

def _mutation(line):
    a = line.split()
    get = lambda k: a[a.index(k) + 1] if k in a else None
    return get("-mode"), get("-cell"), get("-port"), get("-portbit"), get("-ctrlbit")


def single(net, target):
    """The unmutated design (mutsel = 0) as Yosys JSON (module ``product``): every register
    named ``ff:CELL`` with its init, the memories cut (each read port's data an input
    ``rd:MEM:K``, each write port's enable and data outputs ``wen:MEM:K``, ``wdata:MEM:K``),
    the output ``target`` the net ``target``. Also {memory: (width, [read data bit lists],
    [(enable bits, data bits)], init words)}."""
    bits = nc.CopyBits(net, ())                  # the design's copy alone: nothing moves
    _new, fin = bits.new, bits.gold_in

    cells, names, ports, mems = {}, {}, {}, {}
    for name, c in net.cells.items():
        k = net.kind(name)
        dirs = c["port_directions"]
        if k in ("comb", "ff"):
            con = {q: [b if dirs.get(q) == "output" else fin(b) for b in bits]
                   for q, bits in c["connections"].items()}
            cells[name] = {"type": c["type"], "parameters": c["parameters"],
                           "port_directions": dirs, "connections": con}
            if k == "ff":
                q = c["connections"]["Q"]
                init = "".join(net.init.get(b, "0") for b in reversed(q))
                names[f"ff:{name}"] = {"bits": q, "attributes": {"init": init}}
        elif k == "mem":
            if c["type"] != "$mem_v2":
                raise nc.Undecided(f"memory cell {name} of type {c['type']}")
            p, con = c["parameters"], c["connections"]
            w, _ab = npdr._w(p, "WIDTH"), npdr._w(p, "ABITS")
            if any(ch == "1" for ch in str(p.get("RD_CLK_ENABLE", "0"))):
                raise nc.Undecided(f"memory {name}: a synchronous read port")
            rd = []
            for k_ in range(npdr._w(p, "RD_PORTS")):
                data = con["RD_DATA"][k_ * w:(k_ + 1) * w]
                ports[f"rd:{name}:{k_}"] = {"direction": "input", "bits": data}
                rd.append(f"rd:{name}:{k_}")
            wr = []
            for k_ in range(npdr._w(p, "WR_PORTS")):
                en = [fin(b) for b in con["WR_EN"][k_ * w:(k_ + 1) * w]]
                data = [fin(b) for b in con["WR_DATA"][k_ * w:(k_ + 1) * w]]
                ports[f"wen:{name}:{k_}"] = {"direction": "output", "bits": en}
                ports[f"wdata:{name}:{k_}"] = {"direction": "output", "bits": data}
                wr.append((f"wen:{name}:{k_}", f"wdata:{name}:{k_}"))
            init = p.get("INIT", "")
            words = []
            if isinstance(init, str) and set(init) <= set("01xz") and init:
                words = [int(init[len(init) - (i + 1) * w:len(init) - i * w].replace("x", "1")
                             .replace("z", "1"), 2)
                         for i in range(len(init) // w)]
            mems[name] = (w, rd, wr, words)
        else:
            raise nc.Undecided(f"cell {name} of type {c['type']}")
    ports["target"] = {"direction": "output", "bits": [fin(target)]}
    driven = set()
    for c in cells.values():
        for q, bits in c["connections"].items():
            if c["port_directions"].get(q) == "output":
                driven.update(nc._ints(bits))
    for d in ports.values():
        if d["direction"] == "input":
            driven.update(nc._ints(d["bits"]))
    read = set()
    for c in cells.values():
        for q, bits in c["connections"].items():
            if c["port_directions"].get(q) != "output":
                read.update(nc._ints(bits))
    for d in ports.values():
        if d["direction"] == "output":
            read.update(nc._ints(d["bits"]))
    for b in sorted(read - driven):
        ports[f"n{b}"] = {"direction": "input", "bits": [b]}
    mod = {"attributes": {}, "ports": ports, "cells": cells, "netnames": names}
    return json.dumps({"modules": {"product": mod}}), mems


def never(net, line, rtl, yosys_run, timeout, log=None, detail=None, depths=NEVER_DEPTHS):
    """("equivalent", how) | ("undecided", why) | (None, why) for a mutation that is no
    cnot0 / cnot1."""
    import z3
    mode, cell, port, bit, ctrl = _mutation(line)
    if mode not in ("cnot0", "cnot1") or ctrl is None:
        return None, "never: not a cnot mutation"
    t0 = time.monotonic()
    c = net.cells.get(cell)
    if c is None:
        return "undecided", f"never: no cell {cell}"
    target = c["connections"][port][int(ctrl)]
    if target in ("0", "1"):
        ok = target == ("0" if mode == "cnot1" else "1")
        return ("equivalent", "the control bit is a constant") if ok else \
            ("undecided", "never: the control bit is the active constant")
    active = mode == "cnot1"
    text, mems = single(net, target)
    work = Path(rtl)
    got = npdr.blast(text, work, yosys_run, int(timeout) + 1, "never_design", opt=False)
    if got is None:
        return "undecided", f"never: no proof within {timeout} s (bit-blasting)"
    aig = npdr.Aig(*got)
    head = got[0].read_text().split("\n", 1)[0].split()
    size = f"{head[3]} latches, {head[5]} and gates"
    tgt = aig.lit(aig.sig[("output", "target")][0])
    # the words: registers (their latch bits) and memories (their read data)
    words = {}
    for (kind, name), m in aig.sig.items():
        if kind == "latchidx" and name.startswith("ff:"):
            w = 1 + max(m)
            words[name] = [m.get(i) for i in range(w)]
    {n: [aig.latch[li[0]] for li in bits if li] for n, bits in words.items()}
    # the support of each word's next state, and of the target, as words
    word_of_latch = {li[0]: n for n, bits in words.items() for li in bits if li}
    in_word = {}
    for m, (_w, rd, _wr, _) in mems.items():
        for r in rd:
            for x in aig.sig.get(("input", r), {}).values():
                in_word[x >> 1] = m

    def deps(lits):
        lat, ins = aig.support(lits)
        return ({word_of_latch[k] for k in lat if k in word_of_latch}
                | {in_word[v] for v in ins if v in in_word})

    next_lits = {n: [aig.next_lit[li[0]] for li in bits if li] for n, bits in words.items()}
    for m, (_w, _rd, wr, _) in mems.items():
        next_lits[m] = [x for en, da in wr for s in (en, da)
                        for x in aig.sig.get(("output", s), {}).values()]
    dep_cache = {}

    def dep(n):
        if n not in dep_cache:
            dep_cache[n] = deps(next_lits[n])
        return dep_cache[n]

    start = deps([aig.sig[("output", "target")][0]])
    dist, frontier, d = {n: 0 for n in start}, sorted(start), 0
    while frontier:
        d += 1
        nxt = []
        for n in frontier:
            for m in sorted(dep(n)):
                if m not in dist:
                    dist[m] = d
                    nxt.append(m)
        frontier = nxt
    z = z3

    def width(n):
        return mems[n][0] if n in mems else len(words[n])

    def cur_vals(n):
        """The bit-vectors a bound on n constrains: a register's value, a memory's read data."""
        if n in mems:
            return [_bv(z, [aig.lit(aig.sig[("input", r)][i]) for i in range(mems[n][0])])
                    for r in mems[n][1]]
        return [_bv(z, [aig.cur(li) if li else z.Bool(f"free:{n}:{i}")
                        for i, li in enumerate(words[n])])]     # a bit not kept: free

    def next_val(n, old):
        """The next value of n (a memory's: each port's written word where enabled, ``old``
        elsewhere, one port at a time: the largest of them)."""
        if n in mems:
            w = mems[n][0]
            out = []
            for en, da in mems[n][2]:
                e = [aig.lit(aig.sig[("output", en)][i]) for i in range(w)]
                x = [aig.lit(aig.sig[("output", da)][i]) for i in range(w)]
                out.append(_bv(z, [z.If(e[i], x[i], z.Extract(i, i, old) == 1)
                                   for i in range(w)]))
            return out
        return [_bv(z, [aig.nxt(li) if li else z.Bool(f"freen:{n}:{i}")
                        for i, li in enumerate(words[n])])]

    def init_bound(n):
        if n in mems:
            return max(mems[n][3], default=0) if len(mems[n][3]) else (1 << mems[n][0]) - 1
        return sum(1 << i for i, li in enumerate(words[n]) if li and aig.init_of(li))

    last = ""
    for depth in depths:
        tracked = sorted((n for n, k in dist.items() if (depth is None or k <= depth)
                          and width(n) > 1), key=lambda n: (-dist[n], n))
        top = {n: (1 << width(n)) - 1 for n in tracked}
        bound = {n: init_bound(n) for n in tracked}
        grew = {n: 0 for n in tracked}
        queries, changed, passes = 0, True, 0
        while changed:
            changed = False
            passes += 1
            for n in tracked:
                if bound[n] == top[n]:
                    continue
                if time.monotonic() - t0 > timeout:
                    return "undecided", f"never: no proof within {timeout} s ({last or size})"
                s = z.Solver()
                s.set("timeout", MAX_QUERY_MS)
                for m in sorted(dep(n)):
                    if m in bound and bound[m] < top[m]:
                        for v in cur_vals(m):
                            s.add(z.ULE(v, bound[m]))
                old = z.BitVec(f"old:{n}", width(n))
                if n in mems:
                    s.add(z.ULE(old, bound[n]))
                best = bound[n]
                for v in next_val(n, old):
                    for i in reversed(range(width(n))):
                        t = ((best >> i) | 1) << i
                        if best >= t:
                            continue
                        s.push()
                        s.add(z.UGE(v, t))
                        r = s.check()
                        queries += 1
                        if r == z.sat:
                            best = max(best, s.model().eval(v, model_completion=True).as_long())
                        s.pop()
                        if r == z.unknown:
                            best = top[n]
                            break
                if best > bound[n]:
                    grew[n] += 1
                    bound[n] = top[n] if grew[n] >= WIDEN_AFTER else best
                    changed = True
        # the target under the bounds
        s = z.Solver()
        s.set("timeout", MAX_QUERY_MS * 3)
        for m in sorted(start):
            if m in bound and bound[m] < top[m]:
                for v in cur_vals(m):
                    s.add(z.ULE(v, bound[m]))
        s.add(tgt if active else z.Not(tgt))
        r = s.check()
        kept = sum(1 for n in tracked if bound[n] < top[n])
        last = (f"depth {'all' if depth is None else depth}: {len(tracked)} words, {kept} "
                f"bounded, {queries} sat queries, {passes} passes")
        if log:
            log(f"    never {last}: {r} ({time.monotonic() - t0:.0f} s)")
        if detail:
            for n in tracked:
                detail(f"      {dist[n]:3d} {n} w{width(n)} <= {bound[n]:#x} (grew {grew[n]})")
        if r == z.unsat:
            shown = ", ".join(f"{nc.names(net, [(n[3:], 0)])[0].split('[')[0] if n.startswith('ff:') else n}"
                              f" <= {bound[n]:#x}" for n in sorted(start, key=str)
                              if n in bound and bound[n] < top[n])[:300]
            return "equivalent", (f"the control bit is {'0' if active else '1'} (inactive) in "
                                  f"every reachable state of the design: z3 proves upper "
                                  f"bounds inductive, {last}; {size}; at the control bit: {shown}")
        if depth is None or all(k <= depth for k in dist.values()):
            break
    said = f"never: the bounds do not show the control bit inactive ({last})"
    left = timeout - (time.monotonic() - t0)
    try:
        verdict, how = reach(text, active, work, yosys_run, left)
    except nc.Undecided as e:
        return "undecided", f"{said}; reach: {e}"
    if verdict == "equivalent":
        return "equivalent", how
    return "undecided", f"{said}; {how}"


# --- reach: every reachable state of a small cone, enumerated ------------------------------

REACH_LATCHES = 32       # the largest cone reach enumerates (REACH_STATES bounds the visit)
REACH_INPUTS = 12        # 2**12 input vectors a state at most
REACH_STATES = 1 << 18   # states visited before the step gives up


def reach(text, active, work, yosys_run, timeout):
    """The control bit's cone of the design alone (``text``, :func:`single`'s JSON with its
    output ``target``), every reachable state enumerated: ``("equivalent", how)`` when
    ``target`` is never ``active`` in any of them under any input, else ``("undecided",
    why)``. Yosys keeps only the cone of ``target`` (``opt -fast``; ``opt_clean``), so a
    counter bounded only by its relation to other registers (a FIFO's count by the credits
    it shares with the pipe's valid bits) is decided exactly where inductive upper bounds
    cannot state it. The memories' read data are free inputs each cycle (any contents) and
    so are ``rst`` and every other port: a state reached here may be unreachable in the
    design, never the other way round, so "never active" is a proof and "active" is not a
    kill. The enumeration starts from the cone's one initial state (Yosys's ``-zinit``
    resets every latch to 0); a latch the AIGER leaves without a reset value leaves the
    step undecided."""
    d = json.loads(text)
    mod = d["modules"]["product"]
    mod["ports"] = {k: v for k, v in mod["ports"].items()
                    if v["direction"] == "input" or k == "target"}
    t0 = time.monotonic()
    got = npdr.blast(json.dumps(d), Path(work), yosys_run, max(1, int(timeout)) + 1, "reach_cone")
    if got is None:
        return "undecided", f"reach: no proof within {timeout:.0f} s (bit-blasting)"
    aig = npdr.Aig(got[0])
    ands, (out,) = aig.defs, aig.outs
    support = sorted(aig.support([out, *aig.next_lit])[1])
    size = f"{len(aig.latch)} latches, {len(support)} inputs, {len(ands)} and gates"
    if len(aig.latch) > REACH_LATCHES or len(support) > REACH_INPUTS:
        return "undecided", f"reach: the cone is too large to enumerate ({size})"
    order = sorted(ands)                 # AIGER numbers an and gate after its operands

    def step(state, vector):
        val = {0: False}
        val.update((lat >> 1, b) for lat, b in zip(aig.latch, state, strict=True))
        val.update(zip(support, vector, strict=True))

        def lit(x):
            return val[x >> 1] ^ bool(x & 1)
        for v in order:
            a, b = ands[v]
            val[v] = lit(a) and lit(b)
        return tuple(lit(x) for x in aig.next_lit), lit(out)

    # under -zinit (npdr.blast) Yosys resets every latch to 0 and gives a register without an
    # initial value its first value from an input: one initial state
    if None in aig.init:
        return "undecided", f"reach: a latch without a reset value ({size})"
    start = {tuple(bool(r) for r in aig.init)}
    vectors = list(itertools.product((False, True), repeat=len(support)))
    reached, frontier = set(start), list(start)
    while frontier:
        nxt = []
        for state in frontier:
            if time.monotonic() - t0 > timeout:
                return "undecided", (f"reach: no proof within {timeout:.0f} s ({len(reached)} "
                                     f"states so far; {size})")
            for vector in vectors:
                new, bit = step(state, vector)
                if bit == active:
                    return "undecided", (f"reach: the control bit is {int(active)} (active) "
                                         f"in a reachable state of its cone with the memories' "
                                         f"read data free ({size})")
                if new not in reached:
                    if len(reached) >= REACH_STATES:
                        return "undecided", f"reach: more than {REACH_STATES} states ({size})"
                    reached.add(new)
                    nxt.append(new)
        frontier = nxt
    return "equivalent", (f"the control bit is {int(not active)} (inactive) in every "
                          f"reachable state of the design: reach enumerated all {len(reached)} "
                          f"reachable states of its cone ({size}; the memories' read data and "
                          f"every input free)")


# --- rel: Houdini with relational clauses on the product machine ---------------------------

def rel(net, rtl, yosys_run, timeout, stream, log=None):
    """("equivalent", how) | ("undecided", why)."""
    import z3
    t0 = time.monotonic()
    text, free, n = npdr.product(net, stream, None)
    if text is None:
        return "equivalent", "no output or memory input can differ"
    # name every kept register (product names only those with an init value)
    mod = json.loads(text)
    m = mod["modules"]["product"]
    for cname, c in m["cells"].items():
        if "Q" in c["connections"] and c["type"] in nc.FF_TYPES:
            nm = cname + ":Q"
            if nm not in m["netnames"]:
                m["netnames"][nm] = {"bits": c["connections"]["Q"],
                                     "attributes": {"init": "0" * len(c["connections"]["Q"])}}
    work = Path(rtl)
    got = npdr.blast(json.dumps(mod), work, yosys_run, int(timeout) + 1, "rel_product")
    if got is None:
        return "undecided", f"rel: no proof within {timeout} s (bit-blasting)"
    aig = npdr.Aig(*got)
    head = got[0].read_text().split("\n", 1)[0].split()
    size = f"{head[3]} latches, {head[5]} and gates, {n} compared bits"
    bad = z3.Or(*[aig.lit(x) for x in aig.sig[("output", "bad")].values()])
    regs = {}
    for (kind, name), mp in aig.sig.items():
        if kind == "latchidx":
            tag, cell = name.split(":", 1)
            regs.setdefault(cell[:-2], {})[tag] = mp
    cands = {}                              # key -> (cur expr, next expr)
    eqw = {}
    for cell, copies in sorted(regs.items()):
        if "gold" in copies and "gate" in copies:
            g, t = copies["gold"], copies["gate"]
            bits = sorted(set(g) & set(t))
            for i in bits:
                if aig.init_of(g[i]) != aig.init_of(t[i]):
                    continue
                cands[("eq", cell, i)] = (aig.cur(g[i]) == aig.cur(t[i]),
                                          aig.nxt(g[i]) == aig.nxt(t[i]))
            if bits:
                eqw[cell] = (z3.And(*[aig.cur(g[i]) == aig.cur(t[i]) for i in bits]),
                             z3.And(*[aig.nxt(g[i]) == aig.nxt(t[i]) for i in bits]))
    one = sorted(cell for cell, copies in regs.items() if set(copies) == {"shared"}
                 and list(copies["shared"]) == [0] and cell in net.cells)
    valid = [(cell, nm, regs[cell]["shared"][0])
             for cell, nm in zip(one, nc.names(net, [(cell, 0) for cell in one]), strict=False)
             if "valid" in nm]
    for cell, copies in sorted(regs.items()):
        if "shared" in copies:
            for i, li in copies["shared"].items():
                v = aig.init_of(li)
                if v is None:
                    continue                # no initial value: no candidate
                cands[("const", cell, i)] = (aig.cur(li) == v, aig.nxt(li) == v)
    # a register's valid-bit candidates: those of its own unit (the first part of the wire
    # name, "terms" of terms.h_cx_data), or all of them for a register of the top module
    unit = lambda nm: nm.split(".", 1)[0] if "." in nm else None
    cells_w = sorted(c for c in eqw if c in net.cells)
    own = dict(zip(cells_w, (unit(nm) for nm in nc.names(net, [(c, 0) for c in cells_w])), strict=False))
    for cell, (ec, en) in eqw.items():
        for vc, vn, li in valid:
            if own.get(cell) and unit(vn) and own[cell] != unit(vn):
                continue
            cands[("rel", cell, vc)] = (z3.Or(ec, z3.Not(aig.cur(li))),
                                        z3.Or(en, z3.Not(aig.nxt(li))))
    if log:
        log(f"    rel: {len(cands)} candidates ({len(eqw)} duplicated registers, {len(valid)} "
            f"valid bits), {size} ({time.monotonic() - t0:.0f} s)")
    # one incremental SAT solver: a selector literal per candidate (its clause assumed in
    # the current state), the next-state value of each, and per round an activation
    # literal for "the property fails or a surviving clause breaks"
    s = z3.SolverFor("QF_FD")
    sel, nx = {}, {}
    for k, (key, (c, nxt)) in enumerate(cands.items()):
        sel[key] = z3.Bool(f"a{k}")
        nx[key] = z3.Bool(f"b{k}")
        s.add(z3.Implies(sel[key], c))
        s.add(nx[key] == nxt)
    alive, rounds = set(cands), 0
    while True:
        left = timeout - (time.monotonic() - t0)
        if left <= 1:
            return "undecided", f"rel: no invariant within {timeout} s ({len(alive)} clauses left)"
        s.set("timeout", int(left * 1000))
        act = z3.Bool(f"round{rounds}")
        s.add(z3.Implies(act, z3.Or(bad, *[z3.Not(nx[k]) for k in alive])))
        r = s.check(act, *[sel[k] for k in alive])
        s.add(z3.Not(act))
        rounds += 1
        if r == z3.unsat:
            held = sum(1 for k in alive if k[0] == "rel")
            return "equivalent", (f"Houdini: {len(alive)} of {len(cands)} candidate clauses "
                                  f"inductive ({held} of the form 'r equal or valid v = 0'), "
                                  f"{rounds} rounds; {size}")
        if r != z3.sat:
            return "undecided", f"rel: no invariant within {timeout} s ({len(alive)} clauses left)"
        mdl = s.model()
        if z3.is_true(mdl.eval(bad, model_completion=True)):
            return "undecided", "rel: the candidate invariant does not imply the property"
        drop = {k for k in alive if z3.is_false(mdl.eval(nx[k], model_completion=True))}
        if not drop:
            return "undecided", "rel: no clause dropped by a counterexample"
        alive -= drop
        if log and rounds % 10 == 1:
            log(f"    rel round {rounds}: {len(drop)} dropped, {len(alive)} left "
                f"({time.monotonic() - t0:.0f} s)")
