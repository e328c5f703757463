"""Byte-identity check of the registered elements' forms across a refactoring of the targets
(not part of make test): the RTLIL text of every element of rtl/targets.py and rtl/lee.py's
BlockROM, built with ``target=ECP5()`` and with the generic target, at sizes that take every
branch of the lowering (a product in one MULT18X18D, split into limbs, by a constant; ROMs
in each DP16KD mode, with the spill word, with more ports than a block has, too big for
the blocks; RAMs in each mode, without a write port, too deep), written one file per case::

    .venv/bin/python tests/tools/target_identity.py build/targets/before
    .venv/bin/python tests/tools/target_identity.py build/targets/after --compare build/targets/before

``--compare DIR`` exits 1 naming each case whose text differs from ``DIR``'s (or is missing
on one side). tests/tools/emit_identity.py checks the whole units; this checks the elements
alone, in seconds.
"""

import argparse
import sys
from pathlib import Path

import numpy as np
from amaranth.back import rtlil
from amaranth.hdl import signed, unsigned

from bumprtl.rtl.lee import BlockROM
from bumprtl.rtl.targets import ECP5, RegisteredProduct, RegisteredRAM, RegisteredROM, WideProduct

PRODUCTS = [(signed(18), signed(18), None), (unsigned(17), signed(12), None),
            (signed(25), signed(18), None), (signed(20), unsigned(30), None),
            (signed(16), unsigned(9), 255), (signed(30), unsigned(9), 300)]
WIDE = [(signed(30), unsigned(20)), (unsigned(40), signed(18))]
# (depth, width, ports, spill word: word 0 is 0 and the last word every bit set)
ROMS = [(300, 18, 1, False), (1024, 18, 2, False), (1025, 18, 2, True), (1025, 18, 1, True),
        (2049, 18, 1, True), (1500, 17, 2, False), (700, 12, 4, False), (512, 24, 1, False),
        (8193, 17, 2, True), (16385, 17, 2, True), (600, 10, 3, False)]
BLOCK_ROMS = [(1025, 17, 4, True), (2049, 17, 4, True), (1025, 24, 1, True), (300, 12, 1, False),
              (513, 16, 3, True), (4097, 20, 2, False)]
# (depth, width, init, writable)
RAMS = [(4096, 24, True, True), (5120, 24, True, True), (1024, 18, True, True), (300, 5, True, True),
        (2048, 9, True, False), (1024, 18, False, True), (20000, 4, False, True)]


def _table(depth, width, spill, seed):
    rng = np.random.default_rng(seed)
    init = rng.integers(0, 1 << width, depth).tolist()
    if spill:
        init[0], init[-1] = 0, (1 << width) - 1
    return init


def cases():
    """``{case name: function(target) -> elaboratable}``."""
    out = {}
    for n, (a, b, const) in enumerate(PRODUCTS):
        out[f"product{n}"] = lambda t, a=a, b=b, c=const: RegisteredProduct(a, b, "p", b_const=c, target=t)
    for n, (a, b) in enumerate(WIDE):
        out[f"wide{n}"] = lambda t, a=a, b=b: WideProduct(a, b, "w", target=t)
    for kind, rows in (("rom", ROMS), ("block_rom", BLOCK_ROMS)):
        cls = RegisteredROM if kind == "rom" else BlockROM
        for n, (depth, width, ports, spill) in enumerate(rows):
            init = _table(depth, width, spill, n)
            out[f"{kind}{n}"] = lambda t, c=cls, i=init, w=width, p=ports: c(i, unsigned(w), p, "r", target=t)
    for n, (depth, width, init, writable) in enumerate(RAMS):
        words = _table(depth, width, False, 100 + n) if init else None
        out[f"ram{n}"] = lambda t, d=depth, w=width, i=words, wr=writable: RegisteredRAM(
            d, unsigned(w), "m", init=i, target=t, writable=wr)
    return out


def _ports(unit):
    if isinstance(unit, (RegisteredProduct, WideProduct)):
        return [unit.a, *([] if unit.b.__class__.__name__ == "Const" else [unit.b]), unit.en, unit.p]
    if isinstance(unit, RegisteredRAM):
        return [unit.en, unit.r_addr, unit.r_data, unit.w_en, unit.w_addr, unit.w_data]
    return [unit.en, *(s for p in unit.ports for s in (p.addr, p.data))]


def write_all(out):
    out.mkdir(parents=True, exist_ok=True)
    names = []
    for name, make in cases().items():
        for label, target in (("ecp5", ECP5()), ("generic", None)):
            unit = make(target)
            text = rtlil.convert(unit, name=name, ports=_ports(unit), emit_src=False)
            (out / f"{name}-{label}.il").write_text(text)
            names.append(f"{name}-{label}.il")
    return names


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", type=Path, help="output directory (e.g. build/targets/after)")
    p.add_argument("--compare", type=Path, default=None, metavar="DIR",
                   help="a previous output directory: exit 1 if any case's text differs")
    args = p.parse_args(argv)
    names = write_all(args.out)
    print(f"{len(names)} element forms written to {args.out}")
    if args.compare is None:
        return 0
    before = {q.name for q in args.compare.glob("*.il")}
    differ = sorted(n for n in before | set(names)
                    if not (args.compare / n).exists() or not (args.out / n).exists()
                    or (args.compare / n).read_bytes() != (args.out / n).read_bytes())
    for n in differ:
        print(f"differs: {n}")
    print(f"identity: {len(before)} forms before, {len(names)} after, {len(differ)} differ")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
