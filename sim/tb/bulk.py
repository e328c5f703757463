"""Bulk RTL simulation: stimulus and results travel as arrays, the clock loop stays in the
simulator.

A simulation-only Verilog wrapper (sim/tb/bulk_wrapper.v, filled in from the unit's JSON
sidecar by sim/tb/bulk_wrapper.py: every width comes from its ``ports`` and payload
``fields``) sits around the emitted unit. Per chunk of up to :data:`CHUNK` pixels it reads
the stimulus words (payload with its tag) into a memory with ``$fread``, offers them with
input gaps and takes outputs under backpressure drawn from two xorshift32 generators whose
seeds and densities are wrapper inputs, writes every output word with ``$fwrite("%u")``
(on Verilator both through DPI-C) and raises ``done``; a run that stops producing outputs
for ``idle_limit`` cycles ends with ``timed_out`` instead of hanging. cocotb, started by
``cocotb_tools.runner`` as everywhere in this project (sim/tb/tb_bulk.py), writes the
stimulus file, sets the traffic, sleeps on a Timer until ``done``, reads the outputs back
as arrays and compares them with the golden model: Python wakes a few times per chunk,
never per clock.

The concerns live apart: the wrapper and the host set-up words in sim/tb/bulk_wrapper.py,
the payload codec in sim/tb/bulk_codec.py, the simulator options and the cached build in
sim/tb/bulk_build.py (with the measured reasons for each default), the run here.
"""

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bumprtl.rtl.config import BumpError
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.tb.bulk_build import (
    CLOCKS,
    DEFAULTS,
    IOS,
    SIMULATORS,
    TIMESCALE,
    build,
    build_args,
    build_options,
    cache_root,
    locked,
    runners,
    tool_environ,
)
from bumprtl.sim.tb.bulk_codec import check_stimulus, decode_words, encode_words
from bumprtl.sim.tb.bulk_wrapper import (
    AXI_FILE,
    DENSITY_BITS,
    PERIOD,
    has_axi,
    host_fields,
    setup_arrays,
    setup_writes,
    wrapper_verilog,
)
from bumprtl.sim.traffic import PATTERNS as TRAFFIC

__all__ = ["CHUNK", "IDLE_LIMIT", "TRAFFIC", "SIMULATORS", "CLOCKS", "IOS", "PERIOD",
           "DEFAULTS", "SimulationTimeout", "BulkResult", "wrapper_verilog", "host_fields",
           "setup_arrays", "check_stimulus", "encode_words", "decode_words", "setup_writes",
           "build_options", "build_args", "build", "cache_root", "run_bulk", "density",
           "AXI_LATENCY"]

CHUNK = 1 << 18                         # stimulus memory depth: one 512 x 512 frame
IDLE_LIMIT = 1 << 14                    # cycles without an output before the run is a deadlock
AXI_LATENCY = 20                        # cycles from an AR handshake to its first R beat
# TRAFFIC: sim/traffic.py's PATTERNS, name -> (probability of an input gap, probability of
# output backpressure), the numbers of the per-cycle drivers too


class SimulationTimeout(AssertionError):
    """The simulation stopped producing outputs (or never finished a chunk)."""


def density(p):
    """Probability -> the wrapper's density input (out of 2**DENSITY_BITS)."""
    return int(round(p * (1 << DENSITY_BITS)))


@dataclass
class BulkResult:
    outputs: dict            # {pattern: {field: array}} when kept, else {}
    cycles: dict             # {pattern: cycles from start to the last output, over all chunks}
    pixels: dict             # {pattern: pixels streamed and checked or collected}
    sim_s: dict              # {pattern: wall seconds from start to done, summed over chunks}
    sim_cpu_s: dict          # {pattern: the simulator process's CPU seconds over the same}
    run_s: float             # wall time of the whole simulator run (not the build)
    build_s: float           # wall time of the build (when it was made, if cached)
    cached: bool             # the build came from the cache
    checked: bool            # outputs compared with golden outputs inside cocotb
    summary: dict = field(default_factory=dict)


def _run_job(sim, top, bdir, work, j_path, patterns, inputs, expected, setup, source, keep,
             clock, chunk, idle_limit, seed, traffic, axi_latency, between=()):
    """Write the job (and the stimulus arrays), run the cocotb test, read the summary and
    the outputs: ``(summary, outputs, run seconds)``."""
    module = "bumprtl.sim.tb.tb_bulk_gen"
    if inputs is not None:
        arrays = {f"in.{k}": np.asarray(v, np.int64).reshape(-1) for k, v in inputs.items()}
        arrays.update({f"expect.{k}": np.asarray(v, np.int64).reshape(-1)
                       for k, v in (expected or {}).items()})
        np.savez(work / "bulk_arrays.npz", **arrays)
        source, module = {"kind": "arrays", "path": str(work / "bulk_arrays.npz")}, \
            "bumprtl.sim.tb.tb_bulk"
    summary_path = work / "bulk_summary.json"
    job = {"sidecar": str(Path(j_path).resolve()), "patterns": list(patterns),
           "traffic": {p: [density(g), density(b)] for p, (g, b) in traffic.items()},
           "setup": list(setup), "source": source, "keep": bool(keep), "clock": clock,
           "chunk": chunk, "idle_limit": idle_limit, "seed": seed,
           "result": str(work / "bulk_result.npz"), "summary": str(summary_path),
           "axi_latency": axi_latency, "between": list(between)}
    (work / "bulk_job.json").write_text(json.dumps(job, indent=1))
    summary_path.unlink(missing_ok=True)
    t0 = time.perf_counter()
    try:
        with tool_environ():
            results = runners()[sim]().test(
                hdl_toplevel=top, hdl_toplevel_lang="verilog", test_module=module,
                build_dir=bdir, test_dir=work, results_xml=str(work / "results.xml"),
                extra_env={"BUMPRTL_BULK_JOB": str(work / "bulk_job.json")}, timescale=TIMESCALE)
    except SystemExit:                     # the runner exits under pytest when a test failed
        results = None
    run_s = time.perf_counter() - t0
    summary = json.loads(summary_path.read_text()) if summary_path.exists() else {}
    if summary.get("error"):
        exc = SimulationTimeout if summary.get("timeout") else AssertionError
        raise exc(f"bulk run on {sim}: {summary['error']}")
    from cocotb_tools.runner import get_results  # optional dependency: [sim]

    tests, failures = get_results(results) if results is not None else (0, 1)
    if tests == 0 or failures or not summary.get("finished"):
        raise AssertionError(f"bulk cocotb run on {sim} failed (no summary); see {work}")
    outputs = {}
    if keep:
        res = dict(np.load(work / "bulk_result.npz"))
        outputs = {p: {k[len(p) + 1:]: v for k, v in res.items() if k.startswith(p + ".")}
                   for p in patterns}
    return summary, outputs, run_s


def run_bulk(sim, v_path, j_path, work_dir, patterns=("no_stall",), inputs=None, expected=None,
             setup=(), source=None, widths=None, keep=True, clock=None, chunk=CHUNK,
             idle_limit=IDLE_LIMIT, seed=1, cache=None, traffic=None, io=None, opt_fast=None,
             extra=None, axi_latency=AXI_LATENCY, between=()):
    """Stream stimulus through the emitted unit ``v_path`` (sidecar ``j_path``) on ``sim``
    under each traffic pattern, in bulk.

    Either ``inputs`` (``{field: array}``, checked against the sidecar before the build;
    ``expected`` ``{field: array}`` makes cocotb compare every output bit for bit, else
    only the tags are checked, each once and in order) or ``source`` (``{"kind": name, "n":
    count, "seed": s}`` of sim/tb/bulk_sources.py: stimulus and golden outputs made and
    checked chunk by chunk inside the simulator process). ``setup``: host cycles
    (:func:`setup_writes`) after reset; ``between``: host cycles before every run of a
    chunk under a pattern but the first (the pipeline drained). ``traffic`` adds or
    overrides patterns (``{name: (gap probability, stall probability)}``). ``keep=False``
    drops the outputs (regressions). ``clock``, ``io``, ``opt_fast``, ``extra``: the build
    (:func:`build_options`; None: the simulator's fastest, :data:`DEFAULTS`). A unit with
    an AXI4 read port (``map_memory = "axi"``) reads its ``_map.bin`` (beside the sidecar)
    from the wrapper's memory model, each burst ``axi_latency`` cycles after its AR
    handshake; the summary's patterns then carry ``ar`` (AR requests) and ``ar_sum`` (the
    sum of their addresses). Returns a :class:`BulkResult`; raises
    :class:`SimulationTimeout` when the unit stopped producing outputs and AssertionError
    on a mismatch.
    """
    opts = build_options(sim, clock, io, opt_fast, extra)
    meta = load_sidecar(j_path)
    traffic = {**TRAFFIC, **(traffic or {})}
    for p in patterns:
        if p not in traffic:
            raise BumpError(f"traffic pattern must be one of {', '.join(traffic)}, got {p!r}")
    if (inputs is None) == (source is None):
        raise BumpError("run_bulk takes stimulus inputs or a source, not both")
    if inputs is not None:
        check_stimulus(meta, inputs, widths)          # before the build
        outs = meta.output_fields
        for name in expected or {}:
            if name not in outs:
                raise BumpError(f"expected field {name!r} is not an output field of "
                                f"{meta.unit}.json (o__payload fields: {', '.join(outs)})")
    if isinstance(axi_latency, bool) or not isinstance(axi_latency, int) \
            or not 1 <= axi_latency < 1 << 16:
        raise BumpError(f"axi_latency must be an integer in [1, 65535], got {axi_latency!r}",
                        "axi_latency")
    work = Path(work_dir).resolve()
    work.mkdir(parents=True, exist_ok=True)
    axi = has_axi(meta)
    if axi:                              # the memory model's image: the unit's _map.bin
        image = Path(j_path).parent / meta.memory_images["map"]["file"]
        (work / AXI_FILE).write_bytes(image.read_bytes())
    bdir, top, build_s, cached = build(sim, v_path, meta, chunk, cache=cache, **opts)
    with locked(work / "bulk.lock"):    # one run at a time in a work directory
        summary, outputs, run_s = _run_job(sim, top, bdir, work, j_path, patterns, inputs,
                                           expected, setup, source, keep, opts["clock"], chunk,
                                           idle_limit, seed, traffic,
                                           axi_latency if axi else None, between)
    pats = summary["patterns"]
    per = lambda key: {p: pats[p][key] for p in patterns}
    return BulkResult(outputs, per("cycles"), per("pixels"), per("sim_s"), per("sim_cpu_s"),
                      run_s, build_s, cached, summary.get("checked", False), summary)
