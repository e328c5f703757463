"""``bumprtl report fpga``: the ECP5 cost of every design against its accuracy.

Places each design's setup and illumination units and their rotation -> illumination
pipeline (the baselines: the pipeline only), then the BumpPipeline of the default scene,
with :mod:`bumprtl.gen.flow.fpga`, and writes ``docs/report.md``: LUT4/FF/DSP/BRAM/Fmax,
the accuracy of each design's bit-exact golden model (:func:`.table1.accuracy`), the
critical paths and a cost-against-error plot.
"""

import json
from dataclasses import dataclass
from pathlib import Path

from bumprtl.gen.flow.fpga import (
    DEVICES,
    NOT_PLACED,
    PACKAGE,
    PRIMITIVES,
    FpgaError,
    Placement,
    check_device,
    edge_component,
    lpf_mhz,
    pipeline_component,
    place_text,
    primitive_component,
)
from bumprtl.gen.flow.units import build_unit
from bumprtl.gen.report.table1 import TABLE1_ORDER, accuracy, check_samples
from bumprtl.gen.tools.docs import made_at
from bumprtl.gen.tools.jobs import Job, Runner, job_name, scheduler_address
from bumprtl.rtl.cache import scene_geometry
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.pipe import ECP5
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.sim.golden.methods import METHODS
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config

__all__ = ["FpgaRun", "fpga_units", "fpga_run", "fpga_report", "place_all", "write_report", "worst_run",
           "AXI_SCENE", "axi_scene"]

# The scene pipeline whose credit edge is placed alone in every run (its cost on its own).
EDGE_SCENE = "default"
# The built-in scene also placed with its map in the user's memory (map_memory = "axi":
# the texel cache and its AXI4 read port in front of the credit edge), row scene_<name>_axi.
AXI_SCENE = "default"


def axi_scene(name):
    """The built-in scene ``name`` with ``map_memory = "axi"`` (the scene's cache keys at
    their defaults)."""
    return load_scene_config({**BUILTIN[name], "map_memory": "axi"})


@dataclass(frozen=True)
class FpgaRun:
    """What a placement run is asked: the ECP5 ``device``, the report ``out``, the
    placement cache ``work``, the accuracy ``samples``, the units placed (``unit``: all
    when empty), the nextpnr ``seeds`` (``scene_seeds`` for the scene pipelines' and the
    default method's pipeline's rows when given), the local ``jobs`` or a ``scheduler`` address, and a ``job_timeout``
    in seconds."""
    device: str = "LFE5U-85F"
    out: Path = Path("docs/report.md")
    work: Path = Path("build/fpga_cache")
    samples: int = 100_000
    unit: tuple = ()
    seeds: tuple = (1,)
    scene_seeds: tuple = ()
    jobs: int = 1
    job_timeout: float | None = None
    scheduler: str | None = None


def fpga_units(cfg):
    """What ``report fpga`` places: our designs' two units and their pipeline, the baselines'
    pipeline (setup -> illumination only: their per-unit numbers are Table 1's Yosys counts,
    and with their pipelined square roots and dividers they are the largest netlists to
    place), then the BumpPipeline of every built-in scene class (row ``scene:<name>``) and
    the :data:`AXI_SCENE` one's with its map behind the texel cache (``scene_axi:<name>``). A
    method whose hardware is another's (Ernst's is Peercy's, rtl/methods.py) is placed once,
    under that other name (the report's notes say so)."""
    rows = lambda d: ("pipeline",) if METHODS[d].baseline else ("setup", "illumination", "pipeline")
    placed = [d for d in TABLE1_ORDER if d not in NOT_PLACED and METHODS[d].hardware_of is None]
    return ([(f"{d}_{row}", d, row) for d in placed for row in rows(d)]
            + [(f"scene_{s.replace('-', '_')}", load_scene_config(s).method, f"scene:{s}")
               for s in BUILTIN]
            + [(f"scene_{AXI_SCENE}_axi", load_scene_config(AXI_SCENE).method,
                f"scene_axi:{AXI_SCENE}")])


def fpga_run(cfg, run: FpgaRun):
    """``bumprtl report fpga``: refuses a bad device, scheduler address, sample count or unit
    name (BumpError, one line), then places the units of ``run`` (all when ``run.unit`` is
    empty) and writes the report (:func:`fpga_report`); returns 0."""
    check_device(run.device)
    scheduler_address(run.scheduler)            # a malformed address: one line, exit 2
    check_samples(run.samples)
    names = [n for n, _, _ in fpga_units(cfg)]
    for unit in run.unit or ():
        if unit not in names:
            raise BumpError(f"unit must be one of {', '.join(names)}, got {unit!r}")
    fpga_report(cfg, run, [u for u in fpga_units(cfg) if not run.unit or u[0] in run.unit])
    return 0


def _component(design, row, cfg):
    """The ECP5 form (``target=ECP5()``) of row ``row`` of ``design`` (a method name)."""
    target = ECP5()
    if row.startswith("primitive:"):   # one registered primitive alone: the ceiling
        return primitive_component(row.split(":", 1)[1])
    if row.startswith("edge:"):        # a scene pipeline's credit edge alone: its cost
        pipeline = BumpPipeline(load_scene_config(row.split(":", 1)[1]).hardware, target=target)
        for unit in (pipeline, *pipeline.units.values()):
            unit._MustUse__silence = True          # read for its ports and latency only
        return edge_component(pipeline.o.payload.shape(), pipeline.latency, pipeline.fifo_depth)
    if row.startswith("scene_axi:"):  # the same with the map in the user's memory (AXI4)
        return BumpPipeline(axi_scene(row.split(":", 1)[1]).hardware, target=target)
    if row.startswith("scene:"):     # the drop-in BumpPipeline of a built-in scene class
        return BumpPipeline(load_scene_config(row.split(":", 1)[1]).hardware, target=target)
    cfg = cfg.replace(method=design)
    if row == "pipeline":
        return pipeline_component(cfg, target)
    return build_unit({"setup": "rotation", "illumination": "illumination"}[row], cfg, target)[0]


def fpga_report(cfg, run: FpgaRun, units):
    """Place ``units`` ((label, design, row) triples of :func:`fpga_units`) on ``run.device``
    and write ``run.out`` (markdown table + cost-against-error plot). Each placement not in
    the cache (``run.work``, by Verilog digest) is a job of gen/tools/jobs.py: a local cluster of
    ``run.jobs`` workers, or ``run.scheduler``'s."""
    prims = [(f"{k}_alone", None, f"primitive:{k}") for k in PRIMITIVES]   # small: always
    edge_row = ("credit_edge_alone", None, f"edge:{EDGE_SCENE}")          # small: always
    # placed in this order, the baselines (the largest netlists) last: a run stopped early
    # keeps what it placed (the cache), so the rows the target is about come first
    order = prims + [edge_row] + [u for u in units if not _baseline(u)] + [u for u in units if _baseline(u)]
    placed = place_all(cfg, run, [(u, seed) for u in order for seed in _row_seeds(run, u)])
    ceilings = {}
    for label, design, row in prims:
        ok = [r for s in _row_seeds(run, (label, design, row))
              if "error" not in (r := placed[((label, design, row), s)])]
        if ok:
            ceilings[row.split(":", 1)[1]] = {**worst_run(ok),
                                              "fmax_by_seed": {r["seed"]: r["fmax_mhz"] for r in ok}}
    rows = []
    for label, design, row in units:
        runs = [placed[((label, design, row), s)] for s in _row_seeds(run, (label, design, row))]
        ok = [r for r in runs if "error" not in r]
        if not ok:
            rows.append({"unit": label, "design": design, "row": row, "error": runs[0]["error"]})
        else:
            worst = worst_run(ok)
            rows.append({**worst, "unit": label, "design": design, "row": row,
                         "fmax_by_seed": {r["seed"]: r["fmax_mhz"] for r in ok}})
        print(f"{label}: {rows[-1]}", flush=True)
    edge = [r for s in _row_seeds(run, edge_row)
            if "error" not in (r := placed[(edge_row, s)])]
    acc = {d: accuracy(d, cfg, run.samples) for d in {r["design"] for r in rows}}
    write_report(run, rows, acc, cfg, ceilings, edge)


def _baseline(unit):
    """A (label, design, row) of a baseline method's pipeline."""
    return unit[1] in METHODS and METHODS[unit[1]].baseline


def worst_run(runs):
    """The placement a row reports: the lowest Fmax over the seeds (a failed timing, Fmax
    None, lowest of all); a tie goes to the lowest seed, whatever the order of ``--seeds``."""
    return min(runs, key=lambda r: (r["fmax_mhz"] or 0, r["seed"]))


def place_all(cfg, run: FpgaRun, tasks):
    """``{(unit, seed): row or {"error": reason, "seed": seed}}`` for ``tasks``: the cached
    rows read here, the others placed as jobs (one job per distinct Verilog: Ernst's
    pipeline is Peercy's hardware and is placed once). The client elaborates each design
    and submits it at once, so elaboration overlaps the placements already running."""
    placed, waiting = {}, {}           # waiting: job name -> [(task, Placement)]
    timeout = run.job_timeout

    def jobs():
        by_key = {}
        for task in tasks:
            (label, design, row), seed = task
            try:
                p = Placement(_component(design, row, cfg), label, run.device, run.work, seed=seed)
            except FpgaError as e:
                placed[task] = {"error": str(e), "seed": seed}
                continue
            if p.cached is not None:
                placed[task] = {**p.cached, "seed": seed}
                continue
            name = job_name("place", run.device, label, f"seed{seed}")
            if p.key in by_key:                     # the same hardware: placed once
                waiting[by_key[p.key]].append((task, p))
                continue
            by_key[p.key] = name
            waiting[name] = [(task, p)]
            yield Job(name, place_text, p.args(), timeout)

    def done(outcome):              # stored as each ends: a run stopped early keeps them
        for n, (task, p) in enumerate(waiting[outcome.name]):
            seed = task[1]
            if not outcome.ok:
                placed[task] = {"error": outcome.error, "seed": seed}
            elif n == 0:
                placed[task] = {**p.store(outcome.value), "seed": seed}
            else:
                placed[task] = {**outcome.value["row"], "unit": p.label, "seed": seed}

    with Runner(scheduler_address(run.scheduler), run.jobs or 1) as runner:
        runner.run(jobs(), desc="place", on_done=done)
    return placed


def goal_row(unit):
    """The rows the 200 MHz goal is about: every scene pipeline and the default method's
    pipeline (``unit`` is a (label, design, row) triple of :func:`fpga_units`)."""
    _, design, row = unit
    return row.startswith(("scene:", "scene_axi:")) or (row == "pipeline" and design == Config().method)


def _row_seeds(run, unit):
    """The nextpnr seeds of a row: ``run.scene_seeds`` for the :func:`goal_row` rows when
    given, else ``run.seeds``."""
    seeds = list(run.seeds or [1])
    scene = run.scene_seeds
    return list(scene) if scene and goal_row(unit) else seeds


def _ceiling_lines(rows, ceilings):
    """The section on the primitives placed alone, and how far each row under its target
    is from the lower of their Fmax."""
    if not ceilings:
        return []
    lines = ["", "## The primitives' own ceiling", "",
             "Each registered primitive placed alone between flip-flops, same flow and seeds "
             "(`gen/flow/fpga.primitive_component`): the Fmax nextpnr's timing model gives a "
             "design of these primitives that has no fan-out, no logic and no distance.", "",
             "| primitive | placed alone | Fmax (MHz) | Fmax by seed | path |", "|---|---|---|---|---|"]
    for kind, r in ceilings.items():
        lines.append(f"| {kind.upper()} | {PRIMITIVES[kind]} | {r['fmax_mhz']} | "
                     + ", ".join(f"{k}: {v}" for k, v in sorted(r["fmax_by_seed"].items()))
                     + f" | {r['critical_path']} |")
    low = min(ceilings.values(), key=lambda r: r["fmax_mhz"] or 0)
    under = [r for r in rows if "error" not in r and not r["met"]]
    if under and low["fmax_mhz"]:
        lines += ["", f"Rows under the target, as a share of the lower ceiling "
                  f"({low['unit']}, {low['fmax_mhz']} MHz): "
                  + "; ".join(f"{r['unit']} {r['fmax_mhz']} MHz "
                              f"({100 * r['fmax_mhz'] / low['fmax_mhz']:.0f} %)" for r in under)
                  + ". What binds each is its critical path above."]
    return lines


def _edge_lines(edge):
    """The section on the default scene's credit edge placed alone (its placements, one per
    seed): what the free-running datapath's flow control costs."""
    if not edge:
        return []
    worst = worst_run(edge)
    return ["", "## The credit edge on its own", "",
            f"The `{EDGE_SCENE}` scene pipeline's credit edge (`rtl/pipe.CreditEdge`: its "
            "credit count and its LUT-RAM FIFO with the banks' prefetch registers and the output register, at "
            "that pipeline's payload width, latency and FIFO depth) placed alone between "
            "flip-flops (`gen/flow/fpga.edge_component`), same flow and seeds: what the flow "
            "control adds to a pipeline's row above.", "",
            "| design | LUT4 | FF | DSP | BRAM | Fmax (MHz) | Fmax by seed | path |",
            "|---|---|---|---|---|---|---|---|",
            f"| credit_edge_alone | {worst['LUT4']} | {worst['FF']} | {worst['DSP']} | "
            f"{worst['BRAM']} | {worst['fmax_mhz']} | "
            + ", ".join(f"{r['seed']}: {r['fmax_mhz']}" for r in sorted(edge, key=lambda r: r["seed"]))
            + f" | {worst['critical_path']} |"]


def write_report(run: FpgaRun, rows, acc, cfg, ceilings=None, edge=None):
    out = Path(run.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    plot = out.parent / "img" / "cost_vs_error.png"
    seeds = list(run.seeds or [1])
    scene_seeds = list(run.scene_seeds or [])
    command = (f"bumprtl report fpga --device {run.device} --samples {run.samples}"
               + (f" --seeds {','.join(map(str, seeds))}" if seeds != [1] else "")
               + (f" --scene-seeds {','.join(map(str, scene_seeds))}" if scene_seeds else "")
               + "".join(f" --unit {u}" for u in run.unit or ()))
    seed_text = ", ".join(map(str, seeds)) + (
        f" (scene pipelines and the {Config().method} pipeline: {', '.join(map(str, scene_seeds))})"
        if scene_seeds else "")
    lines = ["# FPGA cost of every design", "",
             f"Generated by `{command}`: Yosys `synth_ecp5`, then `nextpnr-ecp5` "
             f"{DEVICES[run.device]} --package {PACKAGE} --out-of-context with "
             f"`constraints/ecp5.lpf` ({lpf_mhz():g} MHz clock target), nextpnr seed(s) "
             f"{seed_text}: Fmax is the minimum over a row's seeds (each seed's in the last "
             "column); every design takes 1 pixel per clock, so Mpixel/s = Fmax. LUT4 = "
             "TRELLIS_COMB (LUT halves incl. carry chains), DSP = MULT18X18D, BRAM = DP16KD. "
             "Accuracy: diffuse error of the design's bit-exact golden model against float64, "
             f"8-bit LSB, {run.samples} random valid pixels (seed 11).", "",
             made_at(cfg, _scene_widths(rows)), "",
             "| unit | LUT4 | FF | DSP | BRAM | Fmax (MHz) = Mpixel/s | target met | max LSB | mean LSB | Fmax by seed |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        a = acc[r["design"]]
        if "error" in r:
            lines.append(f"| {r['unit']} | not placed: {r['error']} | | | | | | {a['max']} | {a['mean']:.4f} | |")
            continue
        lines.append(f"| {r['unit']} | {r['LUT4']} | {r['FF']} | {r['DSP']} | {r['BRAM']} | "
                     f"{r['fmax_mhz']} | {'yes' if r['met'] else 'no'} | {a['max']} | {a['mean']:.4f} | "
                     + ", ".join(f"{k}: {v}" for k, v in sorted(r.get("fmax_by_seed", {}).items()))
                     + " |")
    if _plot(rows, acc, plot):
        lines += ["", f"![LUT4 of the pipeline against diffuse error](img/{plot.name})"]
    lines += ["", "## Critical paths", "",
              "nextpnr's worst register-to-register path of each unit (start -> end cell.port):", ""]
    lines += [f"- {r['unit']}: {r['critical_path']}" for r in rows if "error" not in r]
    lines += _ceiling_lines(rows, ceilings or {})
    lines += _edge_lines(edge or [])
    target = [r for r in rows if r["unit"] == "exact_pipeline"]
    lines += ["", "## Notes", ""]
    if target:
        r = target[0]
        lines += [f"- Target: the default exact pipeline at >= {r['target_mhz']:g} MHz "
                  f"and 1 pixel per clock: {'met' if r['met'] else 'not met'} "
                  f"({r['fmax_mhz']} MHz, speed grade 6, out of context)."]
    skipped = [d for d in NOT_PLACED if d in TABLE1_ORDER]
    if skipped:
        lines += [f"- {', '.join(skipped)}: {NOT_PLACED[skipped[0]]}."]
    lines += [f"- {d}: {METHODS[d].hardware_of}'s hardware (rtl/methods.py), placed once as "
              f"{METHODS[d].hardware_of}." for d in TABLE1_ORDER if METHODS[d].hardware_of]
    lines += [_axi_note(r) for r in rows if r["row"].startswith("scene_axi:")]
    out.write_text("\n".join(lines) + "\n" + FPGA_NOTES)
    print(f"wrote {out}")
    data = out.parent / "data" / "fpga.json"         # read by report table1
    data.parent.mkdir(parents=True, exist_ok=True)
    data.write_text(json.dumps({"command": command, "device": run.device, "rows": rows,
                                "accuracy": acc}, indent=1, sort_keys=True) + "\n")


def _axi_note(row):
    """The note line of a ``scene_axi:<name>`` row: what it places."""
    name = row["row"].split(":", 1)[1]
    g = scene_geometry(axi_scene(name).hardware)
    return (f"- {row['unit']}: the `{name}` scene's BumpPipeline with `map_memory = \"axi\"`: "
            f"its bump map in the user's memory behind the texel cache (`rtl/cache.TextureCache`: "
            f"{g.sets} sets x {g.ways} ways of {g.block} x {g.block}-texel lines, a queue of "
            f"{g.queue} pixels, {g.misses} bursts outstanding) in front of the credit edge, "
            f"its AXI4 read port (AR and R, {g.data_bits}-bit RDATA, one INCR burst of "
            f"{g.beats} beats a miss) as top-level ports; the cache's tag, data, stamp and "
            f"queue memories replace scene_{name}'s map block RAM.")


def _scene_widths(rows):
    """The scene rows placed at widths of their own (the built-in scenes' TOML decides)."""
    own = []
    for r in rows:
        if r["row"].startswith(("scene:", "scene_axi:")):
            sc = load_scene_config(r["row"].split(":", 1)[1])
            own.append(f"{r['unit']} at {sc.angle_bits} / {sc.frac_bits}")
    return "the scene rows at their scenes' widths: " + ", ".join(own) if own else ""


def _plot(rows, acc, path):
    """LUT4 of each design's pipeline (or its units' sum) against its max and mean error."""
    cost = {}
    for r in rows:
        if r["row"] == "pipeline" and "error" not in r:
            cost[r["design"]] = r["LUT4"]
    if not cost:
        return False
    import matplotlib  # optional dependency: [fpga]

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # optional dependency: [fpga]

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
  (a, b, D), every read angle, each read's index folded for its quadrant (`i ^ q0`, a
  register per read: a sine and a cosine of one angle would otherwise share the register
  that reaches both ROMs) and every ROM address are registered, so the angle adders, the
  route from a shared angle, the mirrored quarter-wave address `2**k - i`
  (`rtl/sincos.sine_read`) and the route to the block RAM's address pins each have a
  cycle of their own; the block RAMs use their
  own output registers (`rtl/pipe.RegisteredROM`: on ECP5 a DP16KD with REGMODE OUTREG,
  about 1 ns clock-to-out instead of 5.8 ns; the last word of a 2^n + 1-word table is kept
  in a flip-flop, so the specular table is one 1024 x 18 block and each quarter-wave
  table of the default 14-bit angles four 4096 x 4 blocks side by side (15-bit angles at
  B = 16: seven 8192 x 2 blocks of the sine above its line, next bullet but one), whose word
  gets a data register of its own
  before the sign: the route from two blocks side by side ended the exact pipeline's cycle
  at 146.7 MHz at 13-bit angles); every product uses the DSP's input and output registers
  (`rtl/pipe.RegisteredProduct`: MULT18X18D with REG_INPUTA/B and REG_OUTPUT, about 3.9 ns
  of DSP delay taken out of the cycle), and a product whose operands are wider than one
  18-bit DSP input (the exact illumination's n''x4 p2 at B = 15: 20 x 18 bits) is split
  into 17-bit limbs, one registered MULT18X18D per pair, their sum registered in a stage of
  its own (`rtl/pipe.WideProduct`); the n'' sums are two registered adder levels; the dot N'.A' and the Phong
  sum of eq. 2 each run as two 2-operand carry-chain stages (the rounding half is folded
  into an operand); 255 x diffuse is a shift-and-subtract.
- Yosys `synth_ecp5` infers neither block-RAM output registers nor DSP registers, so
  `report fpga` elaborates with the `rtl.pipe.ECP5` hint, which instantiates DP16KD and
  MULT18X18D with those registers; every simulator (and `bumprtl emit`) runs the generic
  form with the same registers. The ECP5 form is simulated too: `sim/ecp5/dp16kd.v` and
  `sim/ecp5/mult18x18d.v` are behavioural models written from Lattice's memory and sysDSP
  usage guides (Yosys ships DP16KD as a blackbox and no MULT18X18D model);
  `tests/sim/ecp5/` runs RegisteredROM (every word, the spill word included),
  RegisteredProduct and RegisteredRAM in their ECP5 form against the generic form under a
  random enable, and (`make fpga`) checks that Yosys' own block-RAM mapping reads back
  through the DP16KD model (x4, x9, x2 modes) and simulates the `synth_ecp5` netlists of the
  exact pipeline and of the default scene's BumpPipeline with Yosys' `cells_sim.v` and the
  two models, bit-exact against the golden model on 10^4 pixels under random
  backpressure and input gaps. Both pass under cocotb on Icarus; `make fpga
  PYTEST_ARGS="tests/sim/ecp5/test_postsynth.py -k bit_exact -s"` prints the wall times
  (2 x 10^4 pixels each, measured at the earlier 13 / 16 default, 2 cores shared with two nextpnr runs and
  then the formal proofs): exact pipeline synthesis 24.3 s, Icarus build 13.3 s, simulation
  1076 s; scene_default 19.1 s, 8.5 s, 629 s (`make fpga PYTEST_ARGS=
  "tests/sim/ecp5/test_postsynth.py -s"`: 5 passed in 30 min 22 s). Verilator lints the exact
  pipeline's netlist, but its C++ (81 MB, 93 classes) had 7 classes compiled after 14
  minutes, longer than the whole Icarus run. The MULT18X18D model is tested alone
  against plain products in eight register modes (none, input, input + output, input +
  pipeline + output, output, pipeline, A only, each group on its own CE/RST) under random
  CE and RST.
- What limits Fmax now is in the critical-path list above (nextpnr reports the worst
  path only; the next ones are not listed).
- scene_* rows are the drop-in `BumpPipeline` of each built-in scene class (fetch ->
  rotation -> illumination, 64^2 bump map in block RAM). The bump-map and colour-texture
  reads are registered like the ROMs (`rtl/pipe.RegisteredRAM`: DP16KD blocks with the
  write port on port A and REGMODE OUTREG on the read port; the fetch's latency is 3).
  The units of a BumpPipeline run free: no register, DSP or block RAM has a clock enable
  (`tests/rtl/test_no_clock_enable.py`), a valid bit rides with each pixel, and flow
  control is one credit edge (`rtl/pipe.CreditEdge`: a credit count at the input, a
  LUT-RAM FIFO behind the last unit, docs/architecture.md, The credit loop). Before, a
  registered lock-step enable, one copy per unit, still reached the CE pin of every
  register, DSP and DP16KD, and the output buffer's count -> an output entry's CE held
  scene_default and the exact pipeline near 154 MHz; before that, `adv = ~o.valid |
  o.ready` fanned out from the last unit's `o.valid` to every clock enable and held
  scene_full at 97.8 MHz. The blend registers `lit` before its
  albedo products, the light sum registers the Phong terms' sum before the rounding and
  clamp, and the palette table's read is registered (each one more stage).
- A memory more than eight DP16KD wide (`rtl/targets.SPREAD_BLOCKS`: the full scene's
  15-block map and 12-block texture) is spread over the die: its reads take a second
  address register, a plain copy the placer puts beside the blocks
  (`rtl/bumpfetch.BumpMapFetch`): one more stage in the fetch.
- At 15-bit angles and B = 16 (scene_full, scene_two_lights) each quarter-wave ROM stores
  the sine minus the line under it, `floor(i * 2**B / 2**k)`, in 14 bits instead of 17
  (`rtl/sincos.sine_line`, `rtl/tables.quarter_sine_above_line`): seven 8192 x 2 blocks
  instead of nine, 148 and 129 DP16KD instead of 182 and 163. The read adds the line, a
  shift of the address, back in one carry chain: the quadrant's sign is folded into the
  word's data register and into the line a stage ahead (`-(a + b) = ~a + ~b + 2`); with
  the sign still in the sum's stage the data register -> sum route held scene_two_lights
  at 144.3 MHz (seed 2; docs/fixed_point.md has the table).
- For 200 MHz (seed 1 placements of single rows, `bumprtl report fpga --device LFE5U-85F
  --unit <row> --seeds 1`, each step measured after the one before): the edge's LUT-RAM
  FIFO has one read pointer per 16 bits of the pixel (`rtl/pipe.READ_SLICE`), where one
  pointer's fan-out to every bit held exact_pipeline, scene_default, scene_diffuse and
  scene_flat near 188 MHz (`edge.fifo_read -> o__payload`); every sine read registers the
  ROM's word twice, beside the block RAM and beside the adder (the word's route to the
  sign's sum held exact_pipeline at 188.9 MHz), and takes the near address register
  (`rtl/targets.NEAR_BLOCKS` = 0: every sine ROM; the angle -> mirrored address route held
  scene_default at 195.6 and scene_diffuse at 194.3 MHz); a cosine adds its quarter turn
  to the two quadrant bits after the angle register instead of to the angle before it
  (two carry chains in a cycle held scene_default at 204.0 and scene_full at 182.0 MHz);
  the exact rotation's n'' sums are registered once more before they fan out to every
  light's products (the sums' route held scene_full at 157.2 and scene_two_lights at
  174.9 MHz); the light sum and the blend register 255 D before its rounding
  (scene_textured at 188.8 MHz). Each adds a stage where it sits: the exact sine reads two
  (Lee's and Kim's one),
  the rotation one more; the blend and light-sum latencies are unchanged. Then the edge's
  FIFO reads its LUT RAM into a prefetch register beside it, which feeds the output
  register (`rtl/pipe.CreditFIFO`; the LUT-RAM read into the output register, 1.25 ns of
  logic and 3.9-5.3 ns of routing, held exact_pipeline at 188.9, scene_default at 182.4,
  scene_diffuse at 153.4 and scene_textured at 194.6 MHz: `EDGE_LATENCY` 3, the least
  depth L + 4), each 16 bits of the pixel with a copy of the FIFO's control (the prefetch
  register's load, fanned out to every read pointer and every bit's enable, then held
  exact_pipeline at 193.1 MHz); and `pipe.WideProduct` holds each limb product in a
  fabric register before the pair sums (the DSP output into the pair sum held scene_full
  at 167.8 and scene_two_lights at 166.7 MHz: `WIDE_PRODUCT_LATENCY` one more). Last,
  the FIFO's memory is cut into banks of 16 words, one LUT RAM deep
  (`rtl/pipe.BANK_BITS`), each read into a prefetch register of its own, and the bank
  multiplexer moved behind those registers (the LUT-RAM read through the multiplexer of
  four banks into the one prefetch register, 1.25 ns of logic and 3.6-4.2 ns of routing,
  held exact_pipeline at 195.8, scene_default at 183.2 and the edge alone at 205.5 MHz,
  min over seeds 1-3; latency and least depth unchanged); a FIFO wider than
  `rtl/pipe.BANKED_WIDTH_MAX` bits keeps one prefetch register (with four banks'
  registers the 180-bit FIFO of exact_setup spread so far that its control's fan-out held
  it at 178.0 MHz, seed 1).
- The primitives' own ceiling above is nextpnr's timing model of one DP16KD or
  MULT18X18D between flip-flops; Lattice's datasheet figures for the primitives are not
  in that model and not quoted here.
- The `<method>_pipeline` rows chain the method's two units the same way, free-running
  behind one credit edge (`gen/flow/fpga.pipeline_component`); with `wiring.connect`
  each unit's `adv = ~o.valid | o.ready` once chained through both, and where
  a unit carries thousands of delay-line flip-flops (the baselines' N', tag and |a| riding
  through the square root and divider) that fan-out was their limit (lee 132.8, Kim 117.3,
  Peercy and Ernst 122.1 MHz at 12-bit angles, B = 13). Lee and Kim are pipelined with registers only (`rtl/lee.py`,
  `rtl/baselines/kim.py`: every table read registered before and after its block RAM,
  long mux chains cut); Peercy and Ernst with a pipelined restoring square root and
  divider, one bit per stage (`rtl/baselines/peercy.py`). Every product of Lee, Peercy and
  Ernst whose operands outgrow one DSP input (at B = 15 or 16: lee's eq. 24 product, Peercy's
  squares; `rtl/pipe.product_latency`) is a `pipe.WideProduct` like the exact
  illumination's, its limbs' sum in registers of its own: summed in the cycle after the
  DSP blocks (`RegisteredProduct`'s ECP5 form, one stage less) it held lee at 108.7 and
  Peercy and Ernst at 103.1 MHz. Kim's products still sum their limbs in that cycle; its
  limit is elsewhere (the critical-path list). What stopped the baselines short of 150 MHz
  before the free-running datapath is named here; the critical-path list has today's: Peercy's divider's last quotient bit into the rounded, signed output;
  in lee's pipeline the proportional table's address after l_y_k (6.4 ns of routing: at
  14-bit angles its tables take 153 DP16KD, 75 at 13 / 16), in lee's setup alone the
  atan-table address after the reciprocal product; Kim's l_p -> l_qn stage.
- Units are placed out of context: no I/O buffers, ports are internal nets, so paths
  from a unit's input ports are not timed (the pipelines time them between units).
"""
