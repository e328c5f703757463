"""Step 8 of tests/mutants/netlist.py's equivalence check (``pdr``): the mutant's miter proved
by property-directed reachability (IC3/PDR), which finds the inductive strengthening itself.

The cut step (netlist_cone.py) looks for an invariant of one form only, "every register bit
equal in design and mutant but a set R, some bits at their initial value". Some survivors
need another: a relational one ("these registers differ only while the stage's valid bit is
0") or a range ("this operand stays below 1.0, so its bit 16 is never set"). PDR finds such
clauses on its own; this step builds the product machine of design and mutant, bit-level,
and gives it to z3's Spacer (its IC3/PDR engine for constrained Horn clauses).

The product machine. The mutation is applied as the simulation applies it (``mutate -ctrl
mutsel 1 1 ...`` on ``prepped.il``: mutsel = 0 the design, 1 the mutant). Every net that can
differ descends from ``mutsel`` (followed as in netlist_cone.reach, conservatively); a cell
with a differing input is there twice, the design's copy (mutsel = 0) and the mutant's
(mutsel = 1), every other cell once, shared: so the registers outside the mutation's cone
are one state, not two. The memories are cut out:

* a memory's contents are the same in both copies as long as its writes are: every write
  port input that can differ is compared (enable bits always; data bits where enabled;
  address while any bit is enabled), a difference there is a failure;
* a read port's data is a free input each cycle, one for both copies (any contents, any
  value: this drops constraints and adds none); where the read address can differ, the
  mutant's read data is the design's when the two addresses are equal and a second free
  input when not (the same contents read at the same address give the same word).

The property: no output port bit differs (with ``stream``, a payload ``X__payload`` only
while ``X__valid`` is high: netlist.py's STREAM_DONT_CARE), no memory write input differs. The
initial state is the one netlist's (its registers' init values, the same in both copies).
Yosys bit-blasts the product (``techmap; aigmap; write_aiger``), and Spacer proves "no
reachable state fails" (an inductive invariant, its own clauses) or finds a path to one.

Localization: a shared register whose value a proof does not need may be left free (its Q a
free input each cycle, one for both copies: again fewer constraints, never more). The step
starts with the duplicated registers and the shared registers ``depth`` register stages
behind them kept, and deepens: a counterexample of an abstraction that leaves some register
free proves nothing and the next depth runs; one of the whole design (no register left
free) is a real difference of design and mutant under any memory contents: *not
equivalent* only if the memories did not matter, so it is reported as a counterexample of
the cut-memory model, never as a kill. A proof at any depth is sound: the abstraction
over-approximates the design.
"""

import json
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import netlist_cone as nc  # noqa: E402

DEPTHS = (1, 2, 4, 8, None)     # the register stages kept behind the duplicated registers
# arithmetic cells whose two copies are modelled as one unknown function of their operands
ARITH = {"$mul", "$add", "$sub", "$neg", "$shl", "$shr", "$sshl", "$sshr", "$shift", "$shiftx",
         "$div", "$mod", "$divfloor", "$modfloor", "$pow", "$macc", "$alu"}


def _w(p, key):
    v = p.get(key, 0)
    return int(v, 2) if isinstance(v, str) else int(v)


def _diff(net):
    """The nets that can differ in the product (from mutsel: comb cells as netlist_cone.step,
    a register's D bit to its Q bit, its other inputs to all of Q; a memory's read address to
    that port's data only, its write ports to nothing: they are compared instead)."""
    diff, todo, differs = nc.worklist()
    differs(net.ctrl)
    while todo:
        n = todo.pop()
        for cell, port, i in net.readers.get(n, []):
            c = net.cells[cell]
            k = net.kind(cell)
            if k == "comb":
                for q, j in net.step(cell, port, i):
                    differs(c["connections"][q][j])
            elif k == "ff":
                if port == "D":
                    differs(c["connections"]["Q"][i])
                elif port not in ("CLK", "C"):
                    for b in c["connections"]["Q"]:
                        differs(b)
            elif k == "mem":
                if c["type"] != "$mem_v2":
                    raise nc.Undecided(f"memory cell {cell} of type {c['type']}")
                p = c["parameters"]
                if port == "RD_ADDR":
                    w = _w(p, "WIDTH")
                    k_ = i // _w(p, "ABITS")
                    for b in c["connections"]["RD_DATA"][k_ * w:(k_ + 1) * w]:
                        differs(b)
                elif port.startswith("RD_") and port != "RD_CLK":
                    raise nc.Undecided(f"memory {cell}: its {port} can differ")
            else:
                raise nc.Undecided(f"cell {cell} of type {c['type']} in the cone")
    return diff


def product(net, stream, depth):
    """The product machine as Yosys JSON text (module ``product``, output ``bad``), the
    number of shared registers left free, and the number of compared bits."""
    diff = _diff(net)
    bits = nc.CopyBits(net, diff)
    off, new, gold_in, gate_in = bits.off, bits.new, bits.gold_in, bits.gate_in

    def shared_in(b):
        return new() if b == "x" else b

    P = lambda **kw: {k: format(v, "032b") for k, v in kw.items()}
    cells, names, cmp_g, cmp_t, mask = {}, {}, [], [], []

    def cell(name, type_, params, dirs, con):
        cells[name] = {"type": type_, "parameters": params, "port_directions": dirs,
                       "connections": con}

    def inputs_differ(c):
        return any(b in diff for q, bits in c["connections"].items()
                   if c["port_directions"].get(q) != "output" and q not in ("CLK", "C")
                   for b in nc._ints(bits))

    # which shared registers are kept: `depth` register stages behind what the product reads
    ff_cells = [n for n in net.cells if net.kind(n) == "ff"]
    dup = {n for n in net.cells if net.kind(n) in ("comb", "ff") and inputs_differ(net.cells[n])}
    keep = set(n for n in ff_cells if n in dup)
    if depth is None:
        keep = set(ff_cells)
    else:
        seen, frontier = set(), [b for n in dup for b in nc._input_bits(net.cells[n])]
        frontier += [b for p, d in net.ports.items() if d["direction"] == "output"
                     for b in nc._ints(d["bits"])]
        for _ in range(depth):
            regs, stack = set(), list(frontier)
            while stack:
                b = stack.pop()
                if b in seen:
                    continue
                seen.add(b)
                d = net.driver.get(b)
                if not d:
                    continue
                k = net.kind(d[0])
                if k == "ff":
                    regs.add(d[0])
                elif k == "comb" or k == "mem":
                    stack += list(nc._input_bits(net.cells[d[0]]))
            keep |= regs
            frontier = [b for r in regs for b in nc._input_bits(net.cells[r])]
    free = sum(1 for n in ff_cells if n not in keep)

    for name, c in net.cells.items():
        k = net.kind(name)
        if k == "ff" and name not in keep:
            continue                      # its Q a free input, one for both copies
        if k == "comb" and name in dup and c["type"] in ARITH:
            # the two copies as one function of their operands: the design's result free,
            # the mutant's the same where the operands are the same and free where not
            dirs, con = c["port_directions"], c["connections"]
            ins = [b for q, bits in sorted(con.items()) if dirs.get(q) != "output" for b in bits]
            eq = new()
            cell(f"ufeq:{name}", "$eq", P(A_SIGNED=0, B_SIGNED=0, A_WIDTH=len(ins),
                                          B_WIDTH=len(ins), Y_WIDTH=1),
                 {"A": "input", "B": "input", "Y": "output"},
                 {"A": [gold_in(b) for b in ins], "B": [gate_in(b) for b in ins], "Y": [eq]})
            for q, bits in sorted(con.items()):
                if dirs.get(q) == "output":
                    cell(f"ufmux:{name}:{q}", "$mux", P(WIDTH=len(bits)),
                         {"A": "input", "B": "input", "S": "input", "Y": "output"},
                         {"A": [new() for _ in bits],
                          "B": [b + off if isinstance(b, int) else b for b in bits],
                          "S": [eq], "Y": list(bits)})
            continue
        if k in ("comb", "ff"):
            dirs = c["port_directions"]
            copies = ((("gold", gold_in, lambda b: b + off if isinstance(b, int) else b),
                       ("gate", gate_in, lambda b: b)) if name in dup else
                      (("shared", shared_in, lambda b: b),))
            for tag, fin, fout in copies:
                con = {q: [fout(b) if dirs.get(q) == "output" else fin(b) for b in bits]
                       for q, bits in c["connections"].items()}
                cell(f"{tag}:{name}", c["type"], c["parameters"], dirs, con)
                if k == "ff":
                    q = [b for b in con["Q"]]
                    init = "".join(net.init.get(b, "x") for b in reversed(c["connections"]["Q"]))
                    if set(init) != {"x"}:
                        names[f"{tag}:{name}:Q"] = {"bits": q, "attributes": {"init": init}}
        elif k == "mem":
            p, con = c["parameters"], c["connections"]
            w, ab = _w(p, "WIDTH"), _w(p, "ABITS")
            if any(ch == "1" for ch in str(p.get("RD_CLK_ENABLE", "0"))):
                raise nc.Undecided(f"memory {name}: a synchronous read port")
            for k_ in range(_w(p, "RD_PORTS")):
                addr = con["RD_ADDR"][k_ * ab:(k_ + 1) * ab]
                data = con["RD_DATA"][k_ * w:(k_ + 1) * w]
                if not any(b in diff for b in nc._ints(addr)):
                    continue              # shared data: free, undriven
                eq = new()
                cell(f"rdeq:{name}:{k_}", "$eq", P(A_SIGNED=0, B_SIGNED=0, A_WIDTH=ab,
                                                    B_WIDTH=ab, Y_WIDTH=1),
                     {"A": "input", "B": "input", "Y": "output"},
                     {"A": [gold_in(b) for b in addr], "B": [gate_in(b) for b in addr],
                      "Y": [eq]})
                cell(f"rdmux:{name}:{k_}", "$mux", P(WIDTH=w),
                     {"A": "input", "B": "input", "S": "input", "Y": "output"},
                     {"A": [new() for _ in data], "B": [gold_in(b) for b in data],
                      "S": [eq], "Y": list(data)})
            for k_ in range(_w(p, "WR_PORTS")):
                en = con["WR_EN"][k_ * w:(k_ + 1) * w]
                addr = con["WR_ADDR"][k_ * ab:(k_ + 1) * ab]
                data = con["WR_DATA"][k_ * w:(k_ + 1) * w]
                if not any(b in diff for b in nc._ints(en + addr + data)):
                    continue
                eg = [gold_in(b) for b in en]
                anyen = new()
                cell(f"wren:{name}:{k_}", "$reduce_or", P(A_SIGNED=0, A_WIDTH=w, Y_WIDTH=1),
                     {"A": "input", "Y": "output"}, {"A": eg, "Y": [anyen]})
                cmp_g += eg
                cmp_t += [gate_in(b) for b in en]
                mask += ["1"] * w
                cmp_g += [gold_in(b) for b in data]
                cmp_t += [gate_in(b) for b in data]
                mask += eg
                cmp_g += [gold_in(b) for b in addr]
                cmp_t += [gate_in(b) for b in addr]
                mask += [anyen] * ab
        else:
            raise nc.Undecided(f"cell {name} of type {c['type']}")
    for p, d in sorted(net.ports.items()):
        if d["direction"] != "output":
            continue
        valid = None
        if stream and p.endswith("__payload"):
            v = net.ports.get(p[:-len("payload")] + "valid")
            if v and v["direction"] == "output":
                valid = gate_in(v["bits"][0])
        for b in d["bits"]:
            if b in diff:
                cmp_g.append(gold_in(b))
                cmp_t.append(gate_in(b))
                mask.append(valid if valid is not None else "1")
    n = len(cmp_g)
    if not n:
        return None, free, 0
    x, y, bad = [new() for _ in range(n)], [new() for _ in range(n)], new()
    two = {"A": "input", "B": "input", "Y": "output"}
    cell("pdr:cmp", "$xor", P(A_SIGNED=0, B_SIGNED=0, A_WIDTH=n, B_WIDTH=n, Y_WIDTH=n), two,
         {"A": cmp_g, "B": cmp_t, "Y": x})
    cell("pdr:mask", "$and", P(A_SIGNED=0, B_SIGNED=0, A_WIDTH=n, B_WIDTH=n, Y_WIDTH=n), two,
         {"A": x, "B": mask, "Y": y})
    cell("pdr:bad", "$reduce_or", P(A_SIGNED=0, A_WIDTH=n, Y_WIDTH=1),
         {"A": "input", "Y": "output"}, {"A": y, "Y": [bad]})
    driven, read = set(), set()
    for c in cells.values():
        for q, bits in c["connections"].items():
            (driven if c["port_directions"].get(q) == "output" else read).update(nc._ints(bits))
    clk = set()
    for c in cells.values():
        for q in ("CLK", "C"):
            clk.update(nc._ints(c["connections"].get(q, [])))
    ports = {f"n{b}": {"direction": "input", "bits": [b]} for b in sorted(read - driven)}
    ports["bad"] = {"direction": "output", "bits": [bad]}
    mod = {"attributes": {}, "ports": ports, "cells": cells, "netnames": names}
    return json.dumps({"modules": {"product": mod}}), free, n


def blast(text, work, yosys_run, timeout, name, opt=True):
    """The Yosys JSON ``text`` (module ``product``) as ASCII AIGER and its map (``<name>.aag``
    and ``<name>.aim`` in ``work``; None on the time limit). Without ``opt`` for the bounds
    of netlist_rel's never: it merges registers of the same next state (the operand
    registers of three products of one value), and a register whose latches the map no
    longer names gets no bound (only a weaker invariant, never a wrong one)."""
    (work / f"{name}.json").write_text(text)
    out = yosys_run([f"read_json {name}.json", "hierarchy -top product", "async2sync",
                     "dffunmap", "techmap", *(["opt -fast"] if opt else []), "dffunmap",
                     "setundef -undriven -anyseq", "aigmap", "opt_clean",
                     f"write_aiger -ascii -zinit -map {name}.aim {name}.aag"],
                    work, timeout=timeout)
    return None if out is None else (work / f"{name}.aag", work / f"{name}.aim")


class AigerError(ValueError):
    """An AIGER file or Yosys map this module cannot read: the message names the line."""


# The sections of an AIGER 1.9 file after its header "aag M I L O A [B C J F]", in order,
# and the letter of each in the symbol table ("i0 name", "l3 name", "b0 name", ...)
SECTIONS = ("i", "l", "o", "b", "c", "j", "f")


def parse_aag(text):
    """An ASCII AIGER file (format 1.9, "aag M I L O A [B C J F]") as a dict: ``header``
    (the ten counts, absent ones 0), ``i`` (input literals), ``l`` ([literal, next,
    reset], reset 0, 1 or None for uninitialized: the latch's own literal in the file),
    ``o``, ``b`` (bad states), ``c`` (invariant constraints), ``j`` (each justice property:
    its literals), ``f`` (fairness), ``and`` ([lhs, rhs0, rhs1]), ``symbols`` ({(letter,
    index): name}: a name is the rest of its line and may hold spaces and brackets) and
    ``comment`` (the lines after a line ``c``). Raises AigerError naming the line on
    anything else."""
    lines = text.splitlines()
    pos = [0]

    def take(what):
        if pos[0] >= len(lines):
            raise AigerError(f"aag: the file ends before {what} (line {pos[0] + 1})")
        pos[0] += 1
        return lines[pos[0] - 1]

    def ints(line, n_min, n_max, what):
        try:
            vals = [int(x) for x in line.split()]
        except ValueError:
            raise AigerError(f"aag line {pos[0]}: {what} is not numbers: {line[:60]!r}") from None
        if not n_min <= len(vals) <= n_max or any(v < 0 for v in vals):
            raise AigerError(f"aag line {pos[0]}: {what} takes {n_min}"
                             f"{'' if n_min == n_max else f' to {n_max}'} numbers: {line[:60]!r}")
        return vals

    head = take("the header").split()
    if not head or head[0] != "aag" or len(head) not in (6, 7, 8, 9, 10):
        raise AigerError(f"aag line 1: not an ASCII AIGER header: {' '.join(head)[:60]!r}")
    counts = ints(" ".join(head[1:]), 5, 9, "the header")
    counts += [0] * (9 - len(counts))
    M, I, L, O, A, B, C, J, F = counts
    g = {"header": dict(zip("MILOABCJF", counts, strict=True))}
    g["i"] = [ints(take("an input"), 1, 1, "an input")[0] for _ in range(I)]
    g["l"] = []
    for _ in range(L):
        lat = ints(take("a latch"), 2, 3, "a latch")
        reset = lat[2] if len(lat) == 3 else 0
        if reset not in (0, 1, lat[0]):
            raise AigerError(f"aag line {pos[0]}: a latch's reset is 0, 1 or its own literal, "
                             f"got {reset}")
        g["l"].append([lat[0], lat[1], None if reset == lat[0] and reset > 1 else reset])
    for key, n, what in (("o", O, "an output"), ("b", B, "a bad state"),
                         ("c", C, "an invariant constraint")):
        g[key] = [ints(take(what), 1, 1, what)[0] for _ in range(n)]
    sizes = [ints(take("a justice size"), 1, 1, "a justice size")[0] for _ in range(J)]
    g["j"] = [[ints(take("a justice literal"), 1, 1, "a justice literal")[0] for _ in range(k)]
              for k in sizes]
    g["f"] = [ints(take("a fairness literal"), 1, 1, "a fairness literal")[0] for _ in range(F)]
    g["and"] = [ints(take("an and gate"), 3, 3, "an and gate") for _ in range(A)]
    defined = [x for x in g["i"]] + [l[0] for l in g["l"]] + [a[0] for a in g["and"]]
    if any(x & 1 or not 2 <= x <= 2 * M for x in defined) or len(set(defined)) != len(defined):
        raise AigerError("aag: an input, latch or and gate literal is odd, 0, past M or "
                         "defined twice")
    g["symbols"], g["comment"] = {}, []
    limit = {"i": I, "l": L, "o": O, "b": B, "c": C, "j": J, "f": F}
    while pos[0] < len(lines):
        line = take("a symbol")
        if line == "c" or line.startswith("c ") and not line[1:].strip():
            g["comment"] = lines[pos[0]:]
            break
        if not line.strip():
            continue
        letter, _, rest = line.partition(" ")
        kind, idx = letter[:1], letter[1:]
        if kind not in SECTIONS or not idx.isdigit() or not rest:
            raise AigerError(f"aag line {pos[0]}: not a symbol (i/l/o/b/c/j/f, an index, a "
                             f"name) nor the comment's 'c': {line[:60]!r}")
        if int(idx) >= limit[kind]:
            raise AigerError(f"aag line {pos[0]}: symbol {letter} past the {limit[kind]} "
                             f"of its section")
        g["symbols"][(kind, int(idx))] = rest
    return g


MAP_KINDS = ("input", "init", "output", "latch", "invlatch", "wire")


def parse_map(text):
    """Yosys's ``write_aiger -map`` file as [(kind, index, bit, name)]: kind one of
    MAP_KINDS (``wire`` from ``-vmap``: its index is the literal), the name the rest of the
    line; a ``ninitff N`` line (the latch Yosys adds for the registers without an initial
    value under ``-zinit``) as ("ninitff", N, 0, ""). Raises AigerError naming the line."""
    out = []
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        parts = line.split(" ", 3)
        try:
            if parts[0] == "ninitff" and len(parts) == 2:
                out.append(("ninitff", int(parts[1]), 0, ""))
                continue
            if parts[0] in MAP_KINDS and len(parts) == 4 and parts[3]:
                out.append((parts[0], int(parts[1]), int(parts[2]), parts[3]))
                continue
        except ValueError:
            pass
        raise AigerError(f"map line {n}: not '<{'|'.join(MAP_KINDS)}> <index> <bit> <name>' "
                         f"nor 'ninitff <latch>': {line[:60]!r}")
    return out


class Aig:
    """An ASCII AIGER file and Yosys's map of it, as z3 expressions over one frame: a latch
    is a Bool variable (its current value), an input another; ``next`` is a latch's
    next-state function of the current frame. ``outs`` are the outputs and the bad-state
    properties (each a failure when true: the product's ``bad`` is one output), ``constraints``
    the invariant constraints (a state outside them is not reachable); a justice or fairness
    property (liveness) is refused with AigerError, which the steps report as undecided."""

    def __init__(self, aag, aim=None):
        import z3
        self.z3 = z3
        g = parse_aag(Path(aag).read_text())
        if g["j"] or g["f"]:
            raise AigerError("aag: justice or fairness properties (liveness): no safety "
                             "engine here proves them")
        self.symbols = g["symbols"]
        ins = g["i"]
        self.outs = g["o"] + g["b"]
        self.constraints = g["c"]
        self.defs = {x >> 1: (a, b) for x, a, b in g["and"]}
        self.var = {}
        for k, v in enumerate(ins):
            self.var[v >> 1] = z3.Bool(f"i{k}")
        self.ins = ins
        self.latch = [l[0] for l in g["l"]]
        self.next_lit = [l[1] for l in g["l"]]
        self.init = [l[2] for l in g["l"]]          # 0, 1 or None (uninitialized)
        for k, l in enumerate(self.latch):
            self.var[l >> 1] = z3.Bool(f"l{k}")
        # the map (``aim``, Yosys's write_aiger -map): (kind, name) -> {bit: literal}
        self.sig = {}
        for kind, idx, bit, name in (parse_map(Path(aim).read_text()) if aim else ()):
            inv = kind == "invlatch"
            kind = "latch" if inv else kind
            table = {"input": ins, "latch": self.latch, "output": self.outs}.get(kind)
            if table is None:
                continue                  # init inputs, the initstate latch, wires: not named
            if not 0 <= idx < len(table):
                raise AigerError(f"map: {kind} {idx} ({name}) past the {len(table)} of the aag")
            self.sig.setdefault((kind, name), {})[bit] = table[idx] ^ int(inv)
            if kind == "latch":
                self.sig.setdefault(("latchidx", name), {})[bit] = (idx, int(inv))

    def lit(self, x):
        """The z3 expression of literal ``x`` in the current frame (built once)."""
        z3 = self.z3
        v = x >> 1
        if v == 0:
            e = z3.BoolVal(False)
        else:
            stack = [v]
            while stack:
                u = stack[-1]
                if u in self.var:
                    stack.pop()
                    continue
                a, b = self.defs[u]
                pend = [w >> 1 for w in (a, b) if (w >> 1) and (w >> 1) not in self.var]
                if pend:
                    stack += pend
                    continue
                ops = []
                for w in (a, b):
                    ew = z3.BoolVal(False) if not (w >> 1) else self.var[w >> 1]
                    ops.append(z3.Not(ew) if w & 1 else ew)
                self.var[u] = z3.And(*ops)
                stack.pop()
            e = self.var[v]
        return z3.Not(e) if x & 1 else e

    def latch_bits(self, name, width):
        """[(latch index, inverted)] of the register word ``name`` (None: a bit not kept)."""
        m = self.sig.get(("latchidx", name), {})
        return [m.get(i) for i in range(width)]

    def cur(self, li):
        idx, inv = li
        e = self.var[self.latch[idx] >> 1]
        return self.z3.Not(e) if inv else e

    def nxt(self, li):
        idx, inv = li
        e = self.lit(self.next_lit[idx])
        return self.z3.Not(e) if inv else e

    def init_of(self, li):
        """The initial value of a latch bit, None when it has none (any value)."""
        idx, inv = li
        return None if self.init[idx] is None else bool(self.init[idx]) ^ bool(inv)

    def support(self, lits):
        """The latch indices the literals ``lits`` read (through the and gates) and the input
        variables."""
        seen, stack, latches, inputs = set(), [x >> 1 for x in lits], set(), set()
        lvars = {l >> 1: k for k, l in enumerate(self.latch)}
        ivars = {v >> 1 for v in self.ins}
        while stack:
            v = stack.pop()
            if v in seen or not v:
                continue
            seen.add(v)
            if v in lvars:
                latches.add(lvars[v])
            elif v in ivars:
                inputs.add(v)
            elif v in self.defs:
                stack += [w >> 1 for w in self.defs[v]]
        return latches, inputs


def solve(aag):
    """Spacer on the AIGER file: prints ``proved``, ``cex`` or ``unknown`` (run in a child
    process, so that a time limit can stop it)."""
    aig = Aig(aag)
    z3 = aig.z3
    cur = [aig.var[l >> 1] for l in aig.latch]
    nxt = [aig.lit(x) for x in aig.next_lit]
    init = [z3.BoolVal(bool(r)) if r in (0, 1) else cur[k] for k, r in enumerate(aig.init)]
    bad = z3.Or(*[aig.lit(o) for o in aig.outs]) if aig.outs else z3.BoolVal(False)
    # invariant constraints: a state (with its inputs) outside them has no successor and
    # is never a failure
    ok = z3.And(*[aig.lit(c) for c in aig.constraints]) if aig.constraints else z3.BoolVal(True)
    fp = z3.Fixedpoint()
    fp.set(engine="spacer")
    inv = z3.Function("inv", *([z3.BoolSort()] * len(cur)), z3.BoolSort())
    fp.register_relation(inv)
    fp.declare_var(*cur, *[aig.var[v >> 1] for v in aig.ins])
    fp.rule(inv(*init))
    fp.rule(inv(*nxt), z3.And(inv(*cur), ok))
    r = fp.query(z3.And(inv(*cur), ok, bad))
    print("proved" if r == z3.unsat else "cex" if r == z3.sat else "unknown", flush=True)


def pdr(net, rtl, yosys_run, timeout, stream, log=None):
    """("equivalent", how) | ("undecided", why): the product machine at each depth of
    DEPTHS, Spacer within what is left of ``timeout`` seconds."""
    t0 = time.monotonic()
    work = Path(rtl)
    last = "no depth run"
    for depth in DEPTHS:
        left = timeout - (time.monotonic() - t0)
        if left <= 1:
            return "undecided", f"pdr: no proof within {timeout} s ({last})"
        text, free, n = product(net, stream, depth)
        if text is None:
            return "equivalent", "no output or memory input can differ"
        got = blast(text, work, yosys_run, int(left) + 1, "pdr_product")
        if got is None:
            return "undecided", f"pdr: no proof within {timeout} s (bit-blasting)"
        aag = got[0]
        head = aag.read_text().split("\n", 1)[0].split()
        size = f"{head[3]} latches, {head[5]} and gates, {n} compared bits"
        left = timeout - (time.monotonic() - t0)
        try:
            r = subprocess.run([sys.executable, __file__, "solve", str(aag)], capture_output=True,
                               text=True, timeout=max(1, left), start_new_session=True)
            said = (r.stdout.strip().splitlines() or ["error: " + r.stderr.strip()[-200:]])[-1]
        except subprocess.TimeoutExpired:
            return "undecided", (f"pdr: no proof within {timeout} s (depth "
                                 f"{'all' if depth is None else depth}: {size}, {free} registers free)")
        if log:
            log(f"    pdr depth {depth}: {said} ({size}, {free} registers free, "
                f"{time.monotonic() - t0:.0f} s)")
        if said == "proved":
            kept = ("every register kept" if not free else
                    f"{free} shared registers left free, {depth} register stages kept")
            return "equivalent", f"{kept}; {size}"
        if said != "cex":
            return "undecided", f"pdr: {said[:120]}"
        last = f"a counterexample at depth {'all' if depth is None else depth}"
        if not free:
            return "undecided", ("pdr: a counterexample of the whole design with the memories "
                                 "cut (any contents): not a proof, and not a kill either")
    return "undecided", f"pdr: {last}"


if __name__ == "__main__" and sys.argv[1:2] == ["solve"]:
    solve(sys.argv[2])
