"""Run the formal checks of :mod:`bumprtl.sim.formal.targets` and print the proof table.

``python -m bumprtl.gen.formal.run`` or ``bumprtl formal`` (``make formal`` runs all of it
and writes docs/formal.md). Each (unit, property) is one sby job under ``build/formal/``:
k-induction (``mode prove``) first; a property whose induction does not close at the
induction depth is checked by BMC to ``latency + BMC_MARGIN`` instead (every pixel reaches
the output; not deep enough to spend every credit) and reported as *bounded*. A failed property prints its message and the counterexample trace and the run
exits 1. The broken units of :mod:`bumprtl.sim.formal.mutants` must each fail theirs.
"""

import argparse
import json
import sys
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from bumprtl.gen.formal.doc import table, write_doc
from bumprtl.gen.tools.jobs import Job, Runner, SchedulerError, job_name, scheduler_address
from bumprtl.gen.tools.jobs import add_arguments as add_job_arguments
from bumprtl.gen.tools.sby import run_sby
from bumprtl.sim.formal import axi
from bumprtl.sim.formal.contract import StreamContract
from bumprtl.sim.formal.mutants import MUTANTS
from bumprtl.sim.formal.targets import AXI, SMALL, TARGETS, Config

__all__ = ["Row", "check", "check_mutant", "check_axi", "check_axi_mutant", "formal_job", "run",
           "table", "main", "INDUCTION_DEPTH", "AXI_MUTANT_GEOMETRY"]

INDUCTION_DEPTH = 2          # k of k-induction (the lemmas make every property 1-inductive)
BMC_MARGIN = 6               # cover, BMC depth = latency + this (every pixel reaches the output)
PROVE_TIMEOUT = 600          # seconds of k-induction before falling back to BMC
BANK_MARGIN = 7              # palette bank BMC fallback depth = latency + this (docs/formal.md)
FILL = ("credit",)           # covers that fill the FIFO: depth latency + fifo_depth + BMC_MARGIN
AXI_BMC_DEPTH = 24           # the AXI rules' BMC fallback and broken managers: from reset
AXI_MUTANT_GEOMETRY = "2beats"   # the cache the broken AXI managers are built around


def _fill_depth(dut):
    """BMC depth that spends every credit and fills the FIFO, then drains a pixel."""
    return dut.latency + dut.fifo_depth + BMC_MARGIN + _front(dut)


def _front(dut):
    """Cycles a texel cache in front of a pipeline's edge adds to a first pixel's way out
    (0 without one): its flush after reset (a set a cycle), its hit latency, and a miss's
    AR and line of beats landing."""
    if not getattr(dut, "_front", False):
        return 0
    fetch = dut.units["fetch"]
    return fetch.geom.sets + fetch.latency + fetch.geom.beats + 2


# order reads only the tags: memories mapped to flip-flops and cells split by the bits
# that are used, the payload's datapath (multipliers, tables) leaves the model
ORDER_SCRIPT = ("memory_map", "opt -fast", "splitcells", "opt_clean", "splitcells", "opt_clean")


def _script(prop, dut):
    """Yosys commands after the model is flattened: the bank check reads the table's
    contents, and a texel cache's memories (tags, stamps, lines, queue) in arrays made a
    cover of the cached pipeline run past 9 minutes where as flip-flops it takes seconds:
    their memories become flip-flops. ``order`` reads the tags alone: :data:`ORDER_SCRIPT`
    leaves only their cone (the FIFO's tag bits, not its payload's)."""
    if prop == "order":
        return ORDER_SCRIPT
    return ("memory_map", "opt -fast") if prop == "bank" or _front(dut) else ()


def _cover_depth(dut, margin=BMC_MARGIN):
    """BMC depth of a cover: the chain's latency + ``margin`` (every pixel reaches the
    output) + a texel cache's first miss (:func:`_front`)."""
    return dut.latency + margin + _front(dut)


@dataclass
class Row:
    unit: str
    prop: str
    result: str              # proved | bounded | covered | FAIL | ...
    depth: int
    seconds: float
    latency: int
    lemmas: int = 0
    detail: str = ""
    trace: str = ""

    @property
    def ok(self):
        return self.result in ("proved", "bounded", "covered", "fails as expected")


def _job(top, workdir, name, mode, depth, script=(), timeout=3600):
    return run_sby(top, workdir, name, mode=mode, depth=depth, script=script, timeout=timeout)


def check_axi(target, prop, root, induction_depth=INDUCTION_DEPTH):
    """The AXI4 read rules of a texel cache (sim/formal/axi.py, ``target.config``'s
    geometry): ``axi`` every rule by k-induction with the lemmas (BMC to AXI_BMC_DEPTH when
    the induction does not close: *bounded*), ``axi_cover`` every rule's cover."""
    workdir = Path(root) / target.name
    geom = axi.geometry(target.config["geometry"])
    t0 = time.perf_counter()
    if prop == "axi_cover":
        top, res = axi.cover(geom, workdir, axi.cover_depth(geom), name=prop)
        result = "covered" if res.passed else "NOT COVERED" if res.status == "FAIL" else res.status
    else:
        top, res = axi.prove(geom, workdir, name=prop, depth=induction_depth,
                             timeout=PROVE_TIMEOUT)
        result = "proved" if res.passed else res.status
        if res.status == "UNKNOWN" or (res.status == "FAIL" and not res.trace) or res.timed_out:
            top, res = axi.bmc(geom, workdir, AXI_BMC_DEPTH, name=f"{prop}_bmc")
            result = "bounded" if res.passed else res.status
    return _axi_row(target.name, prop, result, res, top, t0)


def _axi_row(unit, prop, result, res, top, t0):
    detail = "; ".join(top.describe(f) for f in res.failed) if not res.passed else ""
    if res.status == "ERROR" and not detail:
        detail = res.log.strip().splitlines()[-1] if res.log.strip() else "sby error"
    return Row(unit, prop, result, res.depth, time.perf_counter() - t0, 0, len(top.lemmas),
               detail, str(res.trace or ""))


def check_axi_mutant(name, root):
    """A broken AXI manager of :data:`bumprtl.sim.formal.axi.MUTANTS` (around the cache of
    AXI_MUTANT_GEOMETRY) against every rule, BMC to AXI_BMC_DEPTH without the lemmas: the
    row says whether it failed (its detail names the rules that failed)."""
    cls, _rule = axi.MUTANTS[name]
    geom = axi.geometry(AXI_MUTANT_GEOMETRY)
    t0 = time.perf_counter()
    top, res = axi.bmc(geom, Path(root) / "mutants", AXI_BMC_DEPTH, name=f"axi_{name}", dut=cls(geom))
    result = "fails as expected" if res.status == "FAIL" and res.trace else \
        ("NOT CAUGHT" if res.passed else res.status)
    row = _axi_row(f"mutant axi_{name}", "axi", result, res, top, t0)
    row.detail = "; ".join(top.describe(f) for f in res.failed)
    return row


def check(target, prop, root, induction_depth=INDUCTION_DEPTH):
    """One (target, property): returns a :class:`Row`."""
    if prop in AXI:
        return check_axi(target, prop, root, induction_depth)
    workdir = Path(root) / target.name
    t0 = time.perf_counter()
    if prop == "cover":
        dut = target.unit()
        top = StreamContract(dut, prop, lemmas=False)
        res = _job(top, workdir, prop, "cover", _cover_depth(dut), script=_script(prop, dut))
        result = "covered" if res.passed else "NOT COVERED" if res.status == "FAIL" else res.status
        return _row(target, prop, result, res, top, dut, t0)
    if prop.endswith("_cover"):     # a property's own covers: it is exercised, not vacuous
        base = prop[:-len("_cover")]
        dut = target.unit()
        top = StreamContract(dut, base, lemmas=False)
        bank = base == "bank"
        depth = _fill_depth(dut) if base in FILL else \
            _cover_depth(dut, BANK_MARGIN + 2 if bank else BMC_MARGIN)
        res = _job(top, workdir, prop, "cover", depth, script=_script(base, dut))
        result = "covered" if res.passed else "NOT COVERED" if res.status == "FAIL" else res.status
        return _row(target, prop, result, res, top, dut, t0)
    margin = BANK_MARGIN if prop == "bank" else BMC_MARGIN
    dut = target.unit()
    script = _script(prop, dut)
    top = StreamContract(dut, prop)
    res = _job(top, workdir, prop, "prove", induction_depth, script=script, timeout=PROVE_TIMEOUT)
    if res.passed:
        return _row(target, prop, "proved", res, top, dut, t0)
    if res.status == "UNKNOWN" or (res.status == "FAIL" and not res.trace) or res.timed_out:
        # induction did not close: fall back to BMC without the lemmas
        dut = target.unit()
        top = StreamContract(dut, prop, lemmas=False)
        res = _job(top, workdir, f"{prop}_bmc", "bmc", _cover_depth(dut, margin), script=script)
        return _row(target, prop, "bounded" if res.passed else res.status, res, top, dut, t0)
    return _row(target, prop, res.status, res, top, dut, t0)


def _row(target, prop, result, res, top, dut, t0):
    detail = "; ".join(top.describe(f) for f in res.failed) if not res.passed else ""
    if res.status == "ERROR" and not detail:
        detail = res.log.strip().splitlines()[-1] if res.log.strip() else "sby error"
    return Row(target.name, prop, result, res.depth, time.perf_counter() - t0, dut.latency,
               top.lemma_count, detail, str(res.trace or ""))


def check_mutant(name, root, cfg=None):
    """A broken unit against the property it breaks (BMC to ``latency + fifo_depth`` + the
    margin: every credit spent, the FIFO filled): the row says whether it failed."""
    cls, prop = MUTANTS[name]
    cfg = cfg or Config(**SMALL)
    dut = cls(cfg)
    top = StreamContract(dut, prop, lemmas=False)
    t0 = time.perf_counter()
    depth = _fill_depth(dut) + (BANK_MARGIN - BMC_MARGIN if prop == "bank" else 0)
    script = ("memory_map", "opt -fast") if prop == "bank" else ()
    res = run_sby(top, Path(root) / "mutants", name, mode="bmc", depth=depth, script=script)
    result = "fails as expected" if res.status == "FAIL" and res.trace else \
        ("NOT CAUGHT" if res.passed else res.status)
    detail = "; ".join(top.describe(f) for f in res.failed)
    return Row(f"mutant {name}", prop, result, depth, time.perf_counter() - t0, dut.latency,
               0, detail, str(res.trace or ""))


def formal_job(kind, name, prop):
    """One check as a job (gen/tools/jobs.py): ``kind`` "target" (``name`` of :data:`TARGETS`),
    "mutant" (of :data:`MUTANTS`) or "axi_mutant" (of sim/formal/axi.MUTANTS), checked in a
    temporary directory of the worker. Returns
    ``{"row": Row as a dict, "files": {path under the work root: text} (each sby run's
    log and the counterexample trace), "log": the sby logs}``; the client writes the files
    under its ``--out`` and points ``trace`` at its copy."""
    with tempfile.TemporaryDirectory(prefix=f"bumprtl-formal-{name}-") as tmp:
        row = check(TARGETS[name], prop, tmp) if kind == "target" else \
            check_axi_mutant(name, tmp) if kind == "axi_mutant" else check_mutant(name, tmp)
        root = Path(tmp).resolve()
        keep = [p for p in root.rglob("*") if p.is_file() and
                (p.name == "logfile.txt" or (row.trace and p.resolve() == Path(row.trace).resolve()))]
        files = {str(p.relative_to(root)): p.read_text(errors="replace") for p in keep}
        if row.trace:
            row.trace = str(Path(row.trace).resolve().relative_to(root))
    log = "\n".join(f"==== {n}\n{t}" for n, t in sorted(files.items()) if n.endswith("logfile.txt"))
    return {"row": asdict(row), "files": files, "log": log}


def run(names=None, props=None, mutants=True, root="build/formal", jobs=1, log=print, save=None,
        scheduler=None, timeout=None):
    """Every requested check; returns the rows (in order). Each check is a job of
    gen/tools/jobs.py: a local cluster of ``jobs`` worker processes, or ``scheduler``'s workers.
    ``save(rows_so_far)`` is called after each check (results.json is written as the run
    goes). A check that raises (a unit that does not elaborate), a tool missing on a worker
    or a ``timeout`` is an ERROR row, not the end of the run."""
    names = list(names or TARGETS)
    jobs_list = []
    for name in names:
        for prop in TARGETS[name].props:
            if props is None or prop in props:
                jobs_list.append((name, prop, ("target", name, prop)))
    if mutants:
        for name, (_cls, prop) in MUTANTS.items():
            if props is None or prop in props:
                jobs_list.append((f"mutant {name}", prop, ("mutant", name, prop)))
        for name in axi.MUTANTS:
            if props is None or "axi" in props:
                jobs_list.append((f"mutant axi_{name}", "axi", ("axi_mutant", name, "axi")))
    root = Path(root)
    order = {job_name("formal", unit, prop): n for n, (unit, prop, _) in enumerate(jobs_list)}
    units = {job_name("formal", unit, prop): (unit, prop) for unit, prop, _ in jobs_list}
    done = {}

    def finished(outcome):
        unit, prop = units[outcome.name]
        if outcome.ok:
            row = Row(**outcome.value["row"])
            for rel, text in outcome.value["files"].items():
                (root / rel).parent.mkdir(parents=True, exist_ok=True)
                (root / rel).write_text(text)
            if row.trace:
                row.trace = str((root / row.trace).resolve())
        else:
            row = Row(unit, prop, "ERROR", 0, outcome.seconds, 0, 0, outcome.error)
        log(f"{row.unit:<24} {row.prop:<10} {row.result:<18} depth {row.depth:<3} "
            f"{row.seconds:6.1f} s {row.detail}")
        done[order[outcome.name]] = row
        if save is not None:
            save([done[k] for k in sorted(done)])

    with Runner(scheduler, jobs) as runner:
        runner.run((Job(name, formal_job, args, timeout) for name, (_u, _p, args)
                    in zip(order, jobs_list, strict=False)), desc="formal", on_done=finished)
    return [done[k] for k in sorted(done)]


def failures(rows):
    return [r for r in rows if not r.ok]


def report_failures(rows, out=None):
    out = out or sys.stderr
    bad = failures(rows)
    for r in bad:
        print(f"FAILED: {r.unit} property {r.prop}: {r.result}"
              + (f" ({r.detail})" if r.detail else ""), file=out)
        if r.trace:
            print(f"  counterexample: {r.trace}", file=out)
    return bad


def _ordered(rows):
    """Rows in table order: the targets as :data:`TARGETS` lists them, each with its
    properties in order, then the broken units as :data:`MUTANTS` lists them."""
    units = list(TARGETS) + [f"mutant {n}" for n in MUTANTS] + [f"mutant axi_{n}" for n in axi.MUTANTS]

    def key(r):
        n = units.index(r.unit) if r.unit in units else len(units)
        props = TARGETS[r.unit].props if r.unit in TARGETS else ()
        return n, props.index(r.prop) if r.prop in props else len(props), r.unit

    return sorted(rows, key=key)


def add_arguments(p):
    p.add_argument("units", nargs="*", metavar="UNIT",
                   help=f"targets to check (default: all): {', '.join(TARGETS)}")
    p.add_argument("--prop", action="append", dest="props", metavar="PROP",
                   help="only these properties (repeatable)")
    p.add_argument("--no-mutants", dest="mutants", action="store_false",
                   help="skip the broken units that must fail")
    p.add_argument("--quick", action="store_true", help="leave out the slow targets (baselines, pipelines)")
    p.add_argument("-j", "--jobs", type=int, default=1,
                   help="local worker processes, one sby job each at a time (default 1; "
                        "ignored with --scheduler)")
    p.add_argument("--job-timeout", type=float, default=None, metavar="SECONDS",
                   help="a check running longer is an ERROR row naming the timeout (default: none)")
    add_job_arguments(p)
    p.add_argument("--out", type=Path, default=Path("build/formal"), help="work directory")
    p.add_argument("--merge", action="store_true",
                   help="update the rows of OUT/results.json that this run checked, keep the rest")
    p.add_argument("--from-results", action="store_true",
                   help="do not run: reprint (and --doc) the table of OUT/results.json")
    p.add_argument("--doc", type=Path, default=None,
                   help="write the table into this Markdown file (docs/formal.md)")


def execute(*, units=(), props=None, mutants=True, quick=False, jobs=1, job_timeout=None,
            scheduler=None, out=Path("build/formal"), merge=False, from_results=False, doc=None):
    """Check ``units`` (default: every target; with ``quick`` not the slow ones), their
    ``props`` (default: all) and, with ``mutants``, the broken units; rows kept in
    ``out``/results.json (``merge``: the rows not re-checked kept; ``from_results``: nothing
    run). Prints the table, writes it into ``doc`` when given; returns 0, 1 on a failed
    check, 2 on a bad target or scheduler address (one line on stderr)."""
    unknown = [u for u in units if u not in TARGETS]
    if unknown:
        print(f"error: unknown formal target {unknown[0]!r}: allowed {', '.join(TARGETS)}",
              file=sys.stderr)
        return 2
    try:
        address = scheduler_address(scheduler)
    except SchedulerError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    names = units or [n for n, t in TARGETS.items() if not (quick and t.slow)]
    t0 = time.perf_counter()
    results = out / "results.json"
    base = [Row(**r) for r in json.loads(results.read_text())] \
        if (merge or from_results) and results.exists() else []

    def merged(rows):
        new = {(r.unit, r.prop): r for r in rows}
        return _ordered([new.pop((r.unit, r.prop), r) for r in base] + list(new.values()))

    def save(rows):
        out.mkdir(parents=True, exist_ok=True)
        results.write_text(json.dumps([asdict(r) for r in merged(rows)], indent=1) + "\n")

    ran = None
    if from_results:
        rows = base
    else:
        try:
            ran = run(names, props, mutants, out, jobs, save=save, scheduler=address,
                      timeout=job_timeout)
            rows = merged(ran)
        except SchedulerError as e:             # unreachable: one line, exit 2
            print(f"error: {e}", file=sys.stderr)
            return 2
    print()
    print(table(rows))
    seconds = time.perf_counter() - t0
    print(f"\n{len(rows)} checks in {seconds:.0f} s")
    if doc is not None:
        write_doc(doc, rows, " ".join(sys.argv[1:]),
                  None if ran is None else seconds, None if ran is None else len(ran))
        print(f"wrote {doc}")
    return 1 if report_failures(rows) else 0


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m bumprtl.gen.formal.run", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    add_arguments(p)
    return execute(**vars(p.parse_args(argv)))


if __name__ == "__main__":
    sys.exit(main())
