"""Resource counter: what a unit's netlist contains, counted the way Lee et al. Table 1 counts.

The unit's Verilog is synthesized by Yosys at the coarse, technology-independent level
(:data:`SCRIPT`: processes, optimisation, width reduction, ``alumacc``, memories kept as
``$mem_v2``) and the netlist (``write_json``) is classified cell by cell:

* **multipliers**: product terms of ``$macc_v2``/``$mul`` cells whose two operands are both
  signals, listed as ``A_WIDTH x B_WIDTH``. A product with a constant operand is a
  **constant multiplier** (listed by the variable operand's width) unless the constant is
  0 or a power of two, which is a shift and counted as nothing.
* **adders** (adders and subtractors): two-operand additions with both operands signals.
  An ``$alu`` is one adder; a ``$macc_v2`` summing T signal terms (products or addends) is
  T - 1 adders (an adder tree). **constant adders**: additions where one operand is a
  constant: rounding (+half), increments, negation (0 - x), mirrored ROM indices
  (2**k - i); the paper counts none of these. A ``$macc_v2`` with constant addends adds
  one constant adder (Yosys merges all its constants into one).
* **comparators**: an ``$alu`` of which at most the sign bit of the sum is used (the rest
  of the result comes from its carry/sign outputs), i.e. ``<``, ``>=``, clamps.
* **tables**: every ``$mem_v2`` with no write port (a ROM), with depth x width, bits and
  read ports; memories with write ports are listed as RAMs.
* **dividers**: ``$div``/``$divfloor``/``$mod``/``$modfloor`` cells, and instances of a
  submodule whose name ends in ``_div`` (a pipelined divider whose operands are the signals
  ``dividend`` and ``divisor`` inside it, e.g. rtl/baselines/peercy.PeercyDivider; its
  ports may be narrower, Amaranth leaves constant operand bits out of them), by operand
  widths.
* **square roots**: instances of a submodule whose name ends in ``sqrt``.
  Square roots and ``_div`` dividers are kept as black boxes while flattening: their inner
  adders are not counted as adders, their inner registers are counted as register bits.
* **the credit edge** (a unit's submodule ``edge``, rtl/pipe.CreditEdge: credit count and
  output FIFO) is flow control, not the datapath Table 1 counts: kept as a black box too,
  its register bits counted apart (``edge_register_bits``; its FIFO's storage is not a
  table). A design emitted flattened (a scene pipeline) has no such box: its edge is
  counted with the rest.
* **register bits**: the widths of all flip-flop cells (``$dff``, ``$sdffe``, ...).
"""

import copy
import hashlib
import json
import re
from collections import Counter
from dataclasses import asdict, dataclass, field
from pathlib import Path

from amaranth.back import verilog

from bumprtl.gen.flow.units import emit_unit
from bumprtl.gen.tools.toolchain import roms_as_readmemh
from bumprtl.gen.tools.yosys import SynthesisError, binary, run_yosys
from bumprtl.rtl.config import BumpError

__all__ = ["Counts", "SCRIPT", "count_netlist", "count_verilog",
           "count_component", "count_unit", "multiplier_pairs", "yosys_input"]

# The coarse, technology-independent synthesis the counts are taken from (memories kept as
# memories).
SCRIPT = ("proc; opt_expr; opt_clean; setattr -mod -set keep_hierarchy 1 *sqrt *_div *.edge; flatten; "
          "opt; wreduce; alumacc; opt; memory -nomap; opt_clean")

_FF_TYPES = {"$dff", "$dffe", "$adff", "$adffe", "$sdff", "$sdffe", "$sdffce", "$aldff",
             "$aldffe", "$dffsr", "$dffsre"}
_DIV_TYPES = {"$div", "$divfloor", "$mod", "$modfloor"}


@dataclass
class Counts:
    """The resources of one unit (see the module docstring for every category)."""
    multipliers: list = field(default_factory=list)       # ["16x15", ...]
    const_multipliers: list = field(default_factory=list)  # widths of the variable operand
    adders: list = field(default_factory=list)             # result widths
    const_adders: list = field(default_factory=list)
    comparators: list = field(default_factory=list)
    dividers: list = field(default_factory=list)           # ["30/16", ...]
    sqrts: int = 0
    tables: list = field(default_factory=list)             # {name, depth, width, bits, read_ports}
    rams: list = field(default_factory=list)
    register_bits: int = 0
    edge_register_bits: int = 0                            # the credit edge's, apart
    cells: dict = field(default_factory=dict)              # raw cell-type histogram

    @property
    def table_bits(self):
        return sum(t["bits"] for t in self.tables)

    def summary(self):
        """Numbers only: the columns of docs/table1.md."""
        return {"multipliers": len(self.multipliers), "const_multipliers": len(self.const_multipliers),
                "adders": len(self.adders), "const_adders": len(self.const_adders),
                "comparators": len(self.comparators), "dividers": len(self.dividers),
                "sqrts": self.sqrts, "tables": len(self.tables), "table_bits": self.table_bits,
                "table_reads": sum(t["read_ports"] for t in self.tables),
                "register_bits": self.register_bits}

    def to_dict(self):
        return {**asdict(self), "summary": self.summary()}

    def __add__(self, other):
        out = Counts()
        for f in ("multipliers", "const_multipliers", "adders", "const_adders", "comparators",
                  "dividers", "tables", "rams"):
            setattr(out, f, getattr(self, f) + getattr(other, f))
        out.sqrts = self.sqrts + other.sqrts
        out.register_bits = self.register_bits + other.register_bits
        out.edge_register_bits = self.edge_register_bits + other.edge_register_bits
        out.cells = dict(Counter(self.cells) + Counter(other.cells))
        return out


def multiplier_pairs(multipliers):
    """``Counts.multipliers`` (``"AxB"`` strings) as sorted ``(narrower, wider)`` operand-width
    pairs: a multiset that does not depend on which operand Yosys put first."""
    return sorted(tuple(sorted(int(w) for w in m.split("x"))) for m in multipliers)


def _int(param):
    return int(param, 2) if isinstance(param, str) else int(param)


def _widths(param, n):
    """Unpack a $macc_v2 width list: ``n`` 16-bit fields, entry 0 in the low bits."""
    value = _int(param) if n else 0
    return [(value >> (16 * i)) & 0xFFFF for i in range(n)]


def _constant(bits):
    """The integer value of a port whose bits are all constants, else None."""
    if any(b not in ("0", "1") for b in bits):
        return None
    return sum(1 << i for i, b in enumerate(bits) if b == "1")


def _split(bits, widths):
    out, pos = [], 0
    for w in widths:
        out.append(bits[pos:pos + w])
        pos += w
    return out


def _count_product(counts, a, b):
    ca, cb = _constant(a), _constant(b)
    if ca is not None and cb is not None:
        return False
    const = ca if ca is not None else cb
    if const is None:
        counts.multipliers.append(f"{len(a)}x{len(b)}")
        return True
    if const & (const - 1):                     # not 0 and not a power of two
        counts.const_multipliers.append(len(b) if ca is not None else len(a))
        return True
    return const != 0                          # a shift: a signal term, no multiplier


def _count_macc(counts, cell):
    p, conn = cell["parameters"], cell["connections"]
    n_products, n_addends = _int(p["NPRODUCTS"]), _int(p["NADDENDS"])
    a = _split(conn.get("A", []), _widths(p["A_WIDTHS"], n_products))
    b = _split(conn.get("B", []), _widths(p["B_WIDTHS"], n_products))
    c = _split(conn.get("C", []), _widths(p["C_WIDTHS"], n_addends))
    terms = sum(_count_product(counts, x, y) for x, y in zip(a, b, strict=False))
    terms += sum(_constant(x) is None for x in c)
    width = _int(p["Y_WIDTH"])
    counts.adders += [width] * max(terms - 1, 0)
    if any(_constant(x) not in (None, 0) for x in c):
        counts.const_adders.append(width)


def _count_alu(counts, cell, used):
    conn = cell["connections"]
    y_used = sum(bit in used for bit in conn["Y"])
    width = len(conn["Y"])
    if y_used <= 1 and (y_used == 0 or conn["Y"][-1] in used):
        counts.comparators.append(width)
    elif _constant(conn["A"]) is not None or _constant(conn["B"]) is not None:
        counts.const_adders.append(width)
    else:
        counts.adders.append(width)


def _count_memory(counts, name, cell):
    p = cell["parameters"]
    depth, width = _int(p["SIZE"]), _int(p["WIDTH"])
    entry = {"name": p.get("MEMID", name).lstrip("\\"), "depth": depth, "width": width,
             "bits": depth * width, "read_ports": _int(p["RD_PORTS"])}
    (counts.tables if _int(p["WR_PORTS"]) == 0 else counts.rams).append(entry)


def _read_registers(module):
    """Bits of the registered read ports of the memories of one netlist module that
    something reads (the FIFO's output register: flip-flops once placed, its storage LUT
    RAM; a port that reads a slice of the word, rtl/pipe.CreditFIFO's, counts that slice)."""
    bits, used = 0, _used_bits(module)
    for c in module["cells"].values():
        if c["type"] == "$mem_v2":
            p = c["parameters"]
            width, enable = _int(p["WIDTH"]), _int(p["RD_CLK_ENABLE"])
            data = c["connections"]["RD_DATA"]
            for port in range(_int(p["RD_PORTS"])):
                if enable >> port & 1:
                    bits += sum(1 for b in data[port * width:(port + 1) * width] if b in used)
    return bits


def _register_bits(module):
    """Flip-flop bits of the cells of one netlist module."""
    return sum(_int(c["parameters"]["WIDTH"]) for c in module["cells"].values()
               if c["type"] in _FF_TYPES)


def _used_bits(module):
    """Net bits that something reads: a cell input or a module output."""
    used = set()
    for cell in module["cells"].values():
        dirs = cell.get("port_directions", {})
        for port, bits in cell["connections"].items():
            if dirs.get(port, "input") != "output":
                used.update(b for b in bits if isinstance(b, int))
    for port in module["ports"].values():
        if port["direction"] != "input":
            used.update(b for b in port["bits"] if isinstance(b, int))
    return used


def count_netlist(netlist, top):
    """:class:`Counts` of module ``top`` in a Yosys ``write_json`` netlist (a dict)."""
    modules = netlist["modules"]
    if top not in modules:
        raise SynthesisError(f"top module {top!r} not in the netlist (modules: {', '.join(modules)})")
    module = modules[top]
    used, counts = _used_bits(module), Counts()
    for name, cell in module["cells"].items():
        kind = cell["type"]
        counts.cells[kind] = counts.cells.get(kind, 0) + 1
        if kind in ("$macc", "$macc_v2") and "NPRODUCTS" in cell["parameters"]:
            _count_macc(counts, cell)
        elif kind == "$mul":
            _count_product(counts, cell["connections"]["A"], cell["connections"]["B"])
        elif kind == "$alu":
            _count_alu(counts, cell, used)
        elif kind == "$mem_v2":
            _count_memory(counts, name, cell)
        elif kind in _DIV_TYPES:
            counts.dividers.append(f"{len(cell['connections']['A'])}/{len(cell['connections']['B'])}")
        elif kind in _FF_TYPES:
            counts.register_bits += _int(cell["parameters"]["WIDTH"])
        elif kind in modules and kind.endswith("sqrt"):
            counts.sqrts += 1
            counts.register_bits += _register_bits(modules[kind])
        elif kind in modules and kind.endswith(".edge"):
            counts.edge_register_bits += _register_bits(modules[kind]) + _read_registers(modules[kind])
        elif kind in modules and kind.endswith("_div"):
            a, b = (len(modules[kind]["netnames"][n]["bits"]) for n in ("dividend", "divisor"))
            counts.dividers.append(f"{a}/{b}")
            counts.register_bits += _register_bits(modules[kind])
    # Cell names (and so the order of the cells) depend on the Yosys front end; the counts
    # do not: widest first.
    for f in ("multipliers", "const_multipliers", "dividers"):
        setattr(counts, f, sorted(getattr(counts, f),
                                  key=lambda s: [-int(w) for w in re.split("[x/]", str(s))]))
    for f in ("adders", "const_adders", "comparators"):
        setattr(counts, f, sorted(getattr(counts, f), reverse=True))
    return counts


_ZERO_INIT = re.compile(r"^ *initial begin\n(?: *\\?[\w$.]+ *\[\d+\] = \d+'[dh]0+;\n)+ *end\n", re.M)


def strip_zero_init(text):
    """Drop memory ``initial`` blocks that only write zeros (a RAM filled by its host port,
    e.g. the palette's colour table): Yosys's front end is slow on tens of thousands of such
    lines and a zero-initialised RAM costs the same hardware. Non-zero ROM contents stay."""
    return _ZERO_INIT.sub("", text)


def yosys_input(v_path, work_dir, top):
    """Write ``v_path`` into ``work_dir`` as ``<top>.in.v``, the file Yosys reads (YoWASP only
    sees its working directory): zero-only memory inits dropped (:func:`strip_zero_init`) and
    ROM contents moved to ``$readmemh`` files (:func:`roms_as_readmemh`), the same memories
    either way. Returns the file's name."""
    src = f"{top}.in.v"
    (Path(work_dir) / src).write_text(roms_as_readmemh(strip_zero_init(Path(v_path).read_text()),
                                                       work_dir, top))
    return src


# Counts of this process by the digest of the Verilog without its header comments (the command
# that made it) and the top: a design emitted twice, e.g. Ernst's setup, which is Peercy's, is
# synthesized once.
_COUNTED = {}


def count_verilog(v_path, top, work_dir=None):
    """Synthesize ``v_path`` (top module ``top``) with :data:`SCRIPT` and count it."""
    v_path = Path(v_path)
    if not v_path.is_file():
        raise BumpError(f"Verilog file {v_path} does not exist")
    binary()                                  # a missing tool is reported even when counted
    text = v_path.read_text()
    body = "\n".join(line for line in text.splitlines() if not line.startswith("//"))
    key = hashlib.sha256(f"{top}\n{body}".encode()).hexdigest()
    if key not in _COUNTED:
        work_dir = Path(work_dir or v_path.parent).resolve()
        work_dir.mkdir(parents=True, exist_ok=True)
        src = yosys_input(v_path, work_dir, top)
        run_yosys(f"read_verilog {src}; hierarchy -check -top {top}; {SCRIPT}; "
                  f"write_json {top}.coarse.json", f"{top}.coarse.log", work_dir)
        _COUNTED[key] = count_netlist(json.loads((work_dir / f"{top}.coarse.json").read_text()), top)
    return copy.deepcopy(_COUNTED[key])


def count_component(component, name, work_dir):
    """Convert an Amaranth component to Verilog under ``work_dir`` and count it."""
    work_dir = Path(work_dir)
    work_dir.mkdir(parents=True, exist_ok=True)
    v_path = work_dir / f"{name}.v"
    v_path.write_text(verilog.convert(component, name=name, emit_src=False))
    return count_verilog(v_path, name, work_dir)


def count_unit(name, cfg, work_dir):
    """Emit unit ``name`` of gen/flow/units.py with ``cfg`` and count it."""
    v_path, _ = emit_unit(name, cfg, work_dir)
    return count_verilog(v_path, name, work_dir)
