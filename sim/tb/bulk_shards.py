"""A bulk regression split into shards, each a job of gen/tools/jobs.py (Dask).

``run_bulk_shards`` streams ``source["n"]`` vectors per traffic pattern like
:func:`bumprtl.sim.tb.bulk.run_bulk`, split into ``shards`` runs of about ``n / shards``
vectors each; shard ``i`` draws its stimulus with seed ``seed * 1000 + i`` (shard 0 keeps
``seed``, so one shard is the unsharded run). A shard job carries the emitted files (the
Verilog, its sidecar and whatever was emitted beside them) as text, runs the simulator in a
temporary directory of its worker (the build cached there by the Verilog's digest, in
``$BUMPRTL_SIM_CACHE`` or the worker's ``build/sim_cache``) and returns the run's counts.
"""

import tempfile
from pathlib import Path

from bumprtl.gen.tools.jobs import Job, Runner, job_name, scheduler_address
from bumprtl.rtl.config import BumpError
from bumprtl.sim.tb.bulk import run_bulk

__all__ = ["bulk_shard", "run_bulk_shards", "shard_sources"]


def shard_sources(source, shards):
    """The per-shard sources: ``n`` split as evenly as possible, seeds as the module says."""
    if not isinstance(shards, int) or shards < 1:
        raise BumpError(f"shards = {shards!r} is out of range: allowed integers >= 1")
    n, seed = int(source["n"]), int(source.get("seed", 1))
    sizes = [n // shards + (i < n % shards) for i in range(shards)]
    return [{**source, "n": size, "seed": seed if i == 0 else seed * 1000 + i}
            for i, size in enumerate(sizes) if size]


def bulk_shard(sim, files, v_name, j_name, patterns, source, chunk_kw):
    """One shard (a job): ``files`` {name: text} written to a temporary directory, then
    :func:`run_bulk` with ``source``; returns its pixels, cycles, checked flag and times."""
    with tempfile.TemporaryDirectory(prefix="bumprtl-bulk-") as tmp:
        for name, text in files.items():
            (Path(tmp) / name).write_text(text)
        r = run_bulk(sim, Path(tmp) / v_name, Path(tmp) / j_name, Path(tmp) / "run",
                     patterns=tuple(patterns), source=source, keep=False, **chunk_kw)
    return {"pixels": r.pixels, "cycles": r.cycles, "checked": r.checked, "sim_s": r.sim_s,
            "build_s": r.build_s, "cached": r.cached, "source": source}


def run_bulk_shards(sim, v_path, j_path, patterns, source, shards, scheduler=None, jobs=None,
                    **run_kw):
    """``source`` through the unit ``v_path`` (sidecar ``j_path``) in ``shards`` jobs: a
    local cluster of ``jobs`` workers (default: one per shard, at most 2) or ``scheduler``'s
    (default ``$BUMPRTL_SCHEDULER``). Returns ``{"pixels": {pattern: total}, "checked": all
    shards checked, "shards": [each shard's result]}``; a failed shard raises AssertionError
    naming it and why."""
    v_path, j_path = Path(v_path), Path(j_path)
    files = {p.name: p.read_text() for p in v_path.parent.iterdir()
             if p.is_file() and p.suffix in (".v", ".sv", ".json", ".hex", ".mem")}
    parts = shard_sources(source, shards)
    address = scheduler_address(scheduler)
    names = [job_name("bulk", sim, v_path.stem, source.get("kind", "src"), f"shard{i}")
             for i in range(len(parts))]
    with Runner(address, jobs or min(2, len(parts))) as runner:
        out = runner.run([Job(n, bulk_shard, (sim, files, v_path.name, j_path.name, patterns, s, run_kw))
                          for n, s in zip(names, parts, strict=False)], desc="bulk")
    bad = [f"{n}: {out[n].error}" for n in names if not out[n].ok]
    if bad:
        raise AssertionError("bulk shards failed: " + "; ".join(bad))
    results = [out[n].value for n in names]
    return {"pixels": {p: sum(r["pixels"][p] for r in results) for p in patterns},
            "checked": all(r["checked"] for r in results), "shards": results}
