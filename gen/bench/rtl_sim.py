"""``bumprtl bench rtl-sim``: RTL simulation speed, the bulk path against the per-cycle
path, side by side in one run.

The same frame of the same scene goes through the same emitted BumpPipeline several ways:
bulk (sim/tb/bulk.py: arrays in and out, clock inside the simulator) and per-cycle
(sim/tb/tb_pipeline.py: cocotb drives and samples every clock), each on Icarus and
Verilator. On Verilator the bulk path is built several ways (:data:`BULK_BUILDS`): from
the first bulk build (the wrapper's Verilog clock under ``--timing``, ``$fread``/``$fwrite``,
g++ -O2) one change a row to the default (sim/tb/bulk.py ``DEFAULTS``), then the ones that
were tried and not kept. Every output is compared with the golden model. Rates exclude the
build and the emission: ``run`` is the whole simulator run (start-up, files, streaming),
``streaming`` the bulk path's time from start to done (wall and the simulator process's
CPU), on Verilator the best of ``--repeat`` runs (an Icarus run takes a minute: one). The
load average is printed because the machine may be shared. The section goes into
docs/bench.md.
"""

import json
import os
from pathlib import Path

import numpy as np

from bumprtl.gen.render.rtl import run_pipeline, run_pipeline_bulk, scene_stimulus, scene_texels
from bumprtl.gen.tools.docs import write_section
from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.bulk import SIMULATORS, build_options

__all__ = ["BULK_BUILDS", "rtl_sim_rows", "markdown", "rtl_sim_bench"]

# The bulk builds measured per simulator, in order (build options of sim/tb/bulk.py;
# {} = the simulator's default). Verilator: the first bulk build, then one change a row
# (the clock into the C++ main, DPI I/O, g++ -Os = the default), then the options tried
# and not kept (g++ -O3 -march=native; two Verilator threads).
BULK_BUILDS = {
    "icarus": ({},),
    "verilator": ({"clock": "verilog", "io": "file", "opt_fast": "-O2"},
                  {"clock": "cxx", "io": "file", "opt_fast": "-O2"},
                  {"clock": "cxx", "io": "dpi", "opt_fast": "-O2"},
                  {},
                  {"opt_fast": "-O3", "extra": ("-CFLAGS", "-march=native")},
                  {"extra": ("--threads", "2")}),
}


def _same(outs, golden):
    return all(np.array_equal(outs[k], v) for k, v in golden.items())


def _bulk_row(scene, stim, sim, opts, wdir, repeat):
    """The best (least streaming CPU) of ``repeat`` bulk runs: its row and outputs; the
    build time and whether it came from the cache are the first run's."""
    inputs, words, polygon, table, texels = stim
    best, first = None, None
    for _ in range(repeat):
        load = os.getloadavg()[0]
        outs, cycles, r = run_pipeline_bulk(scene, inputs, words, polygon, table, sim, wdir,
                                            texels=texels, **opts)
        row = {"build_s": r.build_s, "cached": r.cached, "run_s": r.run_s,
               "stream_s": r.sim_s["no_stall"], "stream_cpu_s": r.sim_cpu_s["no_stall"],
               "cycles": cycles["no_stall"], "load": load}
        first = first or {"build_s": r.build_s, "cached": r.cached}
        if best is None or row["stream_cpu_s"] < best[0]["stream_cpu_s"]:
            best = {**row, **first}, outs
    return best


def rtl_sim_rows(scene_name, size, simulators, work, quick=False, repeat=3):
    """One row per (simulator, path, build): times, rates, cycles, equal to golden.
    ``quick``: only the default bulk build of each simulator."""
    scene = load_scene_config(scene_name)
    inputs, words, polygon, table, base = scene_stimulus(scene, size)
    texels = scene_texels(scene, base)
    golden = pipeline_fixed(inputs, scene, words, polygon, texels)
    stim = inputs, words, polygon, table, texels
    n, rows = size * size, []
    for sim in simulators:
        builds = ({},) if quick else BULK_BUILDS[sim]
        for given in builds:
            opts = build_options(sim, **given)
            label = build_label(opts)
            print(f"  {sim} bulk ({label}) ...", flush=True)
            row, outs = _bulk_row(scene, stim, sim, opts, Path(work) / _dir(sim, opts),
                                  repeat if sim == "verilator" else 1)
            rows.append({"sim": sim, "path": "bulk", **opts, "extra": list(opts["extra"]),
                         "default": opts == build_options(sim), "pixels": n,
                         "same": _same(outs["no_stall"], golden), **row})
            print(f"    streaming {row['stream_s']:.3f} s = {n / row['stream_s']:,.0f} pix/s "
                  f"(CPU {n / row['stream_cpu_s']:,.0f}); run {row['run_s']:.2f} s", flush=True)
        print(f"  {sim} per-cycle ...", flush=True)
        load = os.getloadavg()[0]
        outs, cycles, run = run_pipeline(scene, inputs, words, polygon, table, sim,
                                         Path(work) / f"{sim}_per-cycle", progress=False,
                                         texels=texels)
        rows.append({"sim": sim, "path": "per-cycle", "clock": "cocotb", "io": "—",
                     "opt_fast": None, "extra": [], "default": False, "pixels": n,
                     "same": _same(outs["no_stall"], golden), "build_s": run.build_s,
                     "cached": False, "run_s": run.run_s, "stream_s": None, "stream_cpu_s": None,
                     "cycles": cycles["no_stall"], "load": load})
        print(f"    run {run.run_s:.2f} s = {n / run.run_s:,.0f} pix/s", flush=True)
    return rows


def build_label(opts):
    """A build's options in one line: clock, io, g++ flags, extra arguments."""
    return ", ".join([f"clock {opts['clock']}", f"io {opts['io']}",
                      *([f"g++ {opts['opt_fast']}"] if opts["opt_fast"] else []),
                      *([" ".join(opts["extra"])] if opts["extra"] else [])])


def _dir(sim, opts):
    parts = [sim, opts["clock"], opts["io"], opts["opt_fast"] or "", *opts["extra"]]
    return "_".join(p.strip("-").replace("=", "") for p in parts if p)


def _rate(n, s):
    return f"{n / s:,.0f}" if s else "—"


def markdown(rows, command, scene, size, repeat):
    lines = ["## RTL simulation: bulk against per-cycle", "",
             f"Generated by `{command}`: one {size}x{size} frame of scene class `{scene}` "
             f"({size * size} pixels, no stalls) through its emitted BumpPipeline, measured in "
             "one run. **bulk**: sim/tb/bulk.py (stimulus and outputs as arrays through a "
             "simulation-only Verilog wrapper, the clock inside the simulator, cocotb wakes "
             "a few times per chunk), built as the columns say: clock `verilog` = the "
             "wrapper's own delay loop (`--timing` on Verilator), `cxx` = toggled by the "
             "C++ main of the Verilator build (sim/tb/bulk_main.cpp), `cocotb` = cocotb's "
             "Clock; io `file` = `$fread`/`$fwrite` in the wrapper, `dpi` = the same files "
             "through DPI-C (sim/tb/bulk_dpi.cpp); g++ = OPT_FAST, the optimisation of the "
             "per-cycle C++; **per-cycle**: sim/tb/tb_pipeline.py (cocotb drives and samples "
             "every clock). Build and emission excluded; `run` = the whole simulator run "
             "(start-up, files, checks), `streaming` = start to done of the bulk wrapper "
             "(wall; CPU = the simulator process's CPU time, less sensitive to a shared "
             f"machine's load), the Verilator bulk rows the best of {repeat} runs. `= golden`: every "
             "output field equals sim/golden/fixed/pipeline.py. **bold**: the default build.",
             "",
             "| simulator | path | clock | io | g++ | extra | build s | run s | pix/s (run) "
             "| streaming s | pix/s (streaming) | pix/s (streaming, CPU) | cycles | = golden "
             "| load avg |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        build = f"{r['build_s']:.1f}" + (" (cached)" if r["cached"] else "")
        stream = "—" if r["stream_s"] is None else f"{r['stream_s']:.3f}"
        cells = [r["sim"], r["path"], r["clock"], r["io"], r["opt_fast"] or "—",
                 " ".join(r["extra"]) or "—"]
        if r["default"]:
            cells = [f"**{c}**" for c in cells]
        lines.append(f"| {' | '.join(cells)} | {build} | {r['run_s']:.2f} "
                     f"| {_rate(r['pixels'], r['run_s'])} | {stream} "
                     f"| {_rate(r['pixels'], r['stream_s'])} "
                     f"| {_rate(r['pixels'], r['stream_cpu_s'])} | {r['cycles']} "
                     f"| {'yes' if r['same'] else '**no**'} | {r['load']:.1f} |")
    lines.append("")
    for sim in dict.fromkeys(r["sim"] for r in rows):
        bulk = [r for r in rows if r["sim"] == sim and r["path"] == "bulk"]
        default = next((r for r in bulk if r["default"]), None)
        per = next((r for r in rows if r["sim"] == sim and r["path"] == "per-cycle"), None)
        if default and per:
            lines.append(f"- {sim}: default bulk / per-cycle = "
                         f"{per['run_s'] / default['run_s']:.1f}x (whole runs), "
                         f"{per['run_s'] / default['stream_s']:.1f}x (bulk streaming against "
                         "the per-cycle run)")
        if default and bulk and bulk[0] is not default:
            first = bulk[0]
            lines.append(f"- {sim}: default bulk build / first row = "
                         f"{first['stream_s'] / default['stream_s']:.2f}x (streaming wall), "
                         f"{first['stream_cpu_s'] / default['stream_cpu_s']:.2f}x "
                         "(streaming CPU)")
    return "\n".join(lines)


def rtl_sim_bench(*, simulators, docs, repeat, scene, size, work, quick):
    """``bumprtl bench rtl-sim``: the arguments are its flags' (gen/cli/bench.py);
    returns the exit status."""
    sims = simulators
    if repeat < 1:
        raise BumpError(f"--repeat must be >= 1, got {repeat}")
    command = f"bumprtl bench rtl-sim --size {size} --scene {scene}" + \
        (f" --simulators {' '.join(sims)}" if list(sims) != list(SIMULATORS) else "") + \
        (" --quick" if quick else "") + \
        (f" --repeat {repeat}" if repeat != 3 else "")
    print(command, flush=True)
    rows = rtl_sim_rows(scene, size, sims, work, quick, repeat)
    (Path(work) / "rows.json").write_text(json.dumps(rows, indent=1) + "\n")
    text = markdown(rows, command, scene, size, repeat)
    if docs:
        write_section(docs, "rtl-sim", text)
        print(f"wrote {docs}")
    print(text)
    return 0 if all(r["same"] for r in rows) else 1
